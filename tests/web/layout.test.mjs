// The page's layout on the shop floor (issue 33): at 1280×800 (a desktop, a tablet in landscape),
// at 800×1280 (the tablet upright) and after turning it from one to the other, with a job
// running: no two visible panels' boxes overlap, nothing inside a panel (a chart, a button) sticks
// out of it, each machine action is the control found under its own centre (nothing lies over
// it) and is at least 48×48 px, and the alarms are above the fold at 1280×800. Screenshots go to
// out/web/layout-*.png (docs/img/web-*.png are copies).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { startStack, stopStack, launchBrowser, login, artifacts, ROOT } from './harness.mjs';

const T = 30000;
const demo = readFileSync(join(ROOT, 'examples/parts/demo.nc'), 'utf8');
let stack; let browser; let page; let out;

// Every control that makes the machine do something (or changes what it will do).
export const ACTIONS = ['#btn-start', '#btn-hold', '#btn-resume', '#btn-stop', '#btn-reset',
  '#btn-estop', '#dry-run-label', '#home-all', '#home-X', '#home-Y', '#home-Z', '.jog-step',
  '#jog-speed', 'button.jog', '#touch-target', '#touch-set', '#touch-go', '#override-set',
  '#btn-check', '#btn-upload', '#from-go', '#mdi-go', '[id^="off-set-"]', '#btn-ack',
  '.keys-hint'];

/** Everything the layout test asserts, measured in the page at scroll 0. */
function measure(page, actions) {
  return page.evaluate((selectors) => {
    window.scrollTo(0, 0);
    const visible = (e) => e.getClientRects().length > 0 && getComputedStyle(e).visibility !== 'hidden';
    const box = (e) => {
      const r = e.getBoundingClientRect();
      return { x: r.left + scrollX, y: r.top + scrollY, w: r.width, h: r.height,
        right: r.right + scrollX, bottom: r.bottom + scrollY };
    };
    const name = (e) => e.id || e.className || e.tagName;
    const panels = [document.querySelector('header'), ...document.querySelectorAll('main .panel'),
      document.querySelector('.bottom')].filter((e) => e && visible(e));
    const boxes = panels.map((e) => ({ name: name(e), ...box(e) }));
    const overlaps = [];
    for (let i = 0; i < boxes.length; i++) {
      for (let j = i + 1; j < boxes.length; j++) {
        const a = boxes[i]; const b = boxes[j];
        const w = Math.min(a.right, b.right) - Math.max(a.x, b.x);
        const h = Math.min(a.bottom, b.bottom) - Math.max(a.y, b.y);
        if (w > 0.5 && h > 0.5) overlaps.push(`${a.name} × ${b.name} (${w.toFixed(0)}×${h.toFixed(0)} px)`);
      }
    }
    // Content that sticks out of its panel: charts, canvases, buttons, selects, tables.
    const outside = [];
    panels.forEach((p, i) => {
      const pb = boxes[i];
      for (const e of p.querySelectorAll('.uplot, canvas, button, select, table, .editor')) {
        if (!visible(e) || e.closest('.scroll-x, .report, .alarms, .var-list')) continue;
        const b = box(e);
        if (b.x < pb.x - 1 || b.right > pb.right + 1) {
          outside.push(`${name(e)} in ${pb.name}: ${b.x.toFixed(0)}..${b.right.toFixed(0)} outside ${pb.x.toFixed(0)}..${pb.right.toFixed(0)}`);
        }
      }
    });
    const small = []; const covered = []; let count = 0;
    for (const sel of selectors) {
      for (const e of document.querySelectorAll(sel)) {
        if (!visible(e)) continue;
        count++;
        const r = e.getBoundingClientRect();
        if (r.width < 48 || r.height < 48) small.push(`${sel} "${e.textContent.trim().slice(0, 12)}" ${r.width.toFixed(0)}×${r.height.toFixed(0)}`);
        e.scrollIntoView({ block: 'center', inline: 'center' });
        const c = e.getBoundingClientRect();
        const hit = document.elementFromPoint(c.left + c.width / 2, c.top + c.height / 2);
        if (!hit || !(hit === e || e.contains(hit) || hit.contains(e))) {
          covered.push(`${sel} "${e.textContent.trim().slice(0, 12)}" under ${hit ? name(hit) : 'nothing'}`);
        }
      }
    }
    window.scrollTo(0, 0);
    const alarms = document.getElementById('p-alarms').getBoundingClientRect();
    const charts = [...document.querySelectorAll('.chart')].map((c) => ({
      chart: c.clientWidth, plot: c.querySelector('.uplot')?.getBoundingClientRect().width ?? 0 }));
    return { overlaps, outside, small, covered, count, panels: boxes.length,
      alarmsBottom: alarms.bottom, viewport: innerHeight, charts,
      scrollWidth: document.documentElement.scrollWidth, width: innerWidth };
  }, actions);
}

async function checkLayout(label, { aboveFold = false } = {}) {
  // The charts follow their containers (ResizeObserver): wait until each fits its own.
  await page.waitForFunction(() => [...document.querySelectorAll('.chart')].every((c) => {
    const p = c.querySelector('.uplot');
    return p && p.getBoundingClientRect().width <= c.clientWidth + 1;
  }), null, { timeout: T, polling: 50 });
  const m = await measure(page, ACTIONS);
  assert.deepEqual(m.overlaps, [], `${label}: panels overlap`);
  assert.deepEqual(m.outside, [], `${label}: content outside its panel`);
  assert.deepEqual(m.small, [], `${label}: machine actions under 48×48 px`);
  assert.deepEqual(m.covered, [], `${label}: machine actions covered by something else`);
  assert.ok(m.count >= 30, `${label}: only ${m.count} machine actions found`);
  assert.ok(m.panels >= 10, `${label}: only ${m.panels} panels visible`);
  assert.ok(m.scrollWidth <= m.width, `${label}: the page scrolls sideways (${m.scrollWidth} > ${m.width})`);
  if (aboveFold) assert.ok(m.alarmsBottom <= m.viewport, `${label}: the alarms end at ${m.alarmsBottom} px, below the fold`);
  return m;
}

before(async () => {
  out = artifacts();
  stack = await startStack();
  browser = await launchBrowser();
  page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await login(page, stack.url, stack.tokens.operator);
  await page.locator('#state').filter({ hasText: 'READY' }).waitFor({ timeout: T });
  // A job running, so the charts, the job panel and the editor's line are what a shift sees.
  await page.locator('#program').fill(demo);
  await page.locator('#part-name').fill('demo.nc');
  await page.locator('#btn-upload').click();
  await page.locator('#check-result').filter({ hasText: 'uploaded' }).waitFor({ timeout: T });
  await page.locator('#btn-start').click();
  await page.locator('#confirm-yes').click();
  await page.locator('#state').filter({ hasText: 'RUNNING' }).waitFor({ timeout: T });
  await page.waitForFunction(() => Number(document.getElementById('depth-bar').dataset.depth) > 1,
    null, { timeout: 60000, polling: 100 });
  await page.evaluate(() => document.activeElement?.blur());
});

after(async () => {
  if (browser) await browser.close();
  if (stack) stopStack(stack);
});

test('1280×800: no overlap, 48 px actions, the alarms above the fold', async () => {
  await checkLayout('1280×800', { aboveFold: true });
  await page.screenshot({ path: join(out, 'layout-1280x800.png') });
});

test('800×1280 (the tablet upright): no overlap, 48 px actions', async () => {
  await page.setViewportSize({ width: 800, height: 1280 });
  await checkLayout('800×1280');
  await page.screenshot({ path: join(out, 'layout-800x1280.png') });
});

test('turned from 800×1280 to 1280×800: the charts shrink to their column', async () => {
  await page.setViewportSize({ width: 1280, height: 800 });
  const m = await checkLayout('rotated to 1280×800', { aboveFold: true });
  for (const c of m.charts) assert.ok(c.plot <= c.chart + 1, `a chart ${c.plot} px wide in ${c.chart} px`);
  // Check is where a click lands (the charts once lay over it and Upload; Upload is disabled
  // while the job runs: measure()'s hit test covers it).
  await page.locator('#btn-check').click({ trial: true, timeout: 2000 });
  await page.screenshot({ path: join(out, 'layout-rotated.png') });
});

test('turned back to 800×1280 and a narrow desktop window: still no overlap', async () => {
  await page.setViewportSize({ width: 800, height: 1280 });
  await checkLayout('back to 800×1280');
  await page.setViewportSize({ width: 1024, height: 768 });
  await checkLayout('1024×768');
});
