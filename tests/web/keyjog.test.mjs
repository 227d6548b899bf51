// The keyboard's held jog and its dead-man (issue 33), on the machine's position: an arrow key
// held jogs X or Y (PageUp/PageDown Z) for as long as it is held — longer than the dead-man, so
// the server's refresh is what keeps it going — and the axis stops on key-up, on the window's
// blur and when the page is hidden; a key typed into a field never jogs. Every wait is on the
// machine's position or state (the page's last status), never a sleep.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';
import {
  startStack, stopStack, launchBrowser, login, artifacts, SPEED, DEADMAN_MS,
} from './harness.mjs';

const T = 30000;
const WALL_DEADMAN_MS = DEADMAN_MS / SPEED;
let stack; let browser; let page; let out;
const metrics = {};

const pos = (axis) => page.evaluate((a) => window.edm.status?.vars?.[`io.${a}_mm`], axis);
const held = () => page.evaluate(() => window.edm.manual?.jog?.held === true);

/** Waits until `axis` has moved more than `mm` from `from` in the direction `dir`. */
function waitMoved(axis, from, mm, dir) {
  return page.waitForFunction(([a, x0, d, s]) => {
    const v = window.edm.status?.vars?.[`io.${a}_mm`];
    return typeof v === 'number' && s * (v - x0) > d;
  }, [axis, from, mm, dir], { timeout: T, polling: 20 });
}

/** Polls until `axis` has not moved by 1 µm for `quietMs`; when it last moved (page clock). */
function waitStill(axis, quietMs = 400) {
  return page.evaluate(([a, quiet, limit]) => new Promise((resolve, reject) => {
    const v = () => window.edm.status?.vars?.[`io.${a}_mm`];
    let last = v(); let changed = performance.now(); const t0 = changed;
    const timer = setInterval(() => {
      const now = performance.now(); const x = v();
      if (Math.abs(x - last) > 0.001) { last = x; changed = now; }
      if (now - changed > quiet) { clearInterval(timer); resolve({ stopped_at: changed, at: x }); }
      if (now - t0 > limit) { clearInterval(timer); reject(new Error(`${a} still moving after ${limit} ms`)); }
    }, 20);
  }), [axis, quietMs, T]);
}

const now = () => page.evaluate(() => performance.now());

/** Holds `key` until the axis has run `mm` (more than the dead-man's worth), returns the start. */
async function holdKey(key, axis, dir, mm) {
  const from = await pos(axis);
  await page.keyboard.down(key);
  await waitMoved(axis, from, mm, dir);
  await page.waitForFunction((a) => window.edm.manual?.jog?.held === true
    && window.edm.manual.jog.axis === a, axis.toUpperCase(), { timeout: T, polling: 20 });
  return from;
}

before(async () => {
  out = artifacts();
  stack = await startStack();
  browser = await launchBrowser();
  page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await login(page, stack.url, stack.tokens.operator);
  await page.locator('#state').filter({ hasText: 'READY' }).waitFor({ timeout: T });
  await page.locator('#jog-speed').selectOption({ index: 1 }); // a quarter of jog_v_max
  await page.locator('#p-position h2').click(); // the focus on the page, in no field
});

after(async () => {
  writeFileSync(join(out, 'keyjog-metrics.json'), `${JSON.stringify(metrics, null, 2)}\n`);
  if (browser) await browser.close();
  if (stack) stopStack(stack);
});

test('→ held jogs +X past the dead-man; key-up stops it', async () => {
  const v = Number(await page.locator('#jog-speed').inputValue()) * SPEED; // mm per wall s
  // 1.5 dead-men's worth of travel: the jog outlived the runtime's dead-man, refreshed.
  const mm = 1.5 * v * WALL_DEADMAN_MS / 1000;
  const from = await holdKey('ArrowRight', 'x', 1, mm);
  assert.equal(await page.locator('#jog-X-plus').getAttribute('class'), 'jog held');
  const t = await now();
  await page.keyboard.up('ArrowRight');
  const still = await waitStill('x');
  metrics.keyup_stop_ms = still.stopped_at - t;
  metrics.keyup_travel_mm = still.at - from;
  assert.ok(still.stopped_at - t < WALL_DEADMAN_MS, `stopped ${still.stopped_at - t} ms after key-up`);
  await page.waitForFunction(() => window.edm.manual?.jog?.held === false, null, { timeout: T });
  assert.equal(await page.evaluate(() => window.edm.keyJog.active), null);
});

test('↑ jogs +Y and PageUp +Z; each stops on key-up', async () => {
  for (const [key, axis] of [['ArrowUp', 'y'], ['PageUp', 'z']]) {
    await holdKey(key, axis, 1, 0.3);
    const t = await now();
    await page.keyboard.up(key);
    const still = await waitStill(axis);
    metrics[`keyup_stop_${axis}_ms`] = still.stopped_at - t;
    assert.ok(still.stopped_at - t < WALL_DEADMAN_MS, `${key}: stopped ${still.stopped_at - t} ms after key-up`);
    await page.waitForFunction(() => window.edm.manual?.jog?.held === false, null, { timeout: T });
  }
});

test('← held, then the window loses focus: the jog stops without a key-up', async () => {
  await holdKey('ArrowLeft', 'x', -1, 0.3);
  const t = await now();
  await page.evaluate(() => window.dispatchEvent(new Event('blur')));
  const still = await waitStill('x');
  metrics.blur_stop_ms = still.stopped_at - t;
  assert.ok(still.stopped_at - t < WALL_DEADMAN_MS, `stopped ${still.stopped_at - t} ms after the blur`);
  await page.waitForFunction(() => window.edm.manual?.jog?.held === false, null, { timeout: T });
  assert.equal(await page.evaluate(() => window.edm.keyJog.active), null);
  await page.keyboard.up('ArrowLeft'); // the late key-up changes nothing
  assert.equal(await held(), false);
});

test('↓ held, then the page is hidden: the jog stops', async () => {
  await holdKey('ArrowDown', 'y', -1, 0.3);
  const t = await now();
  // What a tablet's browser does when it is put away: document.hidden and visibilitychange.
  await page.evaluate(() => {
    Object.defineProperty(document, 'hidden', { value: true, configurable: true });
    document.dispatchEvent(new Event('visibilitychange'));
  });
  const still = await waitStill('y');
  metrics.hidden_stop_ms = still.stopped_at - t;
  assert.ok(still.stopped_at - t < WALL_DEADMAN_MS, `stopped ${still.stopped_at - t} ms after hiding`);
  await page.evaluate(() => { delete document.hidden; });
  await page.keyboard.up('ArrowDown');
  await page.waitForFunction(() => window.edm.manual?.jog?.held === false, null, { timeout: T });
});

test('keys typed in a field never jog (the editor, MDI, an offset)', async () => {
  for (const id of ['#program', '#mdi-line', '#off-G54-X']) {
    await page.locator(id).focus();
    const before = { x: await pos('x'), t: await page.evaluate(() => window.edm.status.t_s) };
    await page.keyboard.down('ArrowRight');
    assert.equal(await page.evaluate(() => window.edm.keyJog.active), null, `${id}: a jog began`);
    // A second of machine time of status later, nothing moved and nothing is held.
    await page.waitForFunction((t0) => window.edm.status.t_s > t0 + 1, before.t, { timeout: T, polling: 20 });
    assert.equal(await held(), false, `${id}: a jog is held`);
    assert.ok(Math.abs(await pos('x') - before.x) < 0.0005, `${id}: X moved`);
    await page.keyboard.up('ArrowRight');
  }
  await page.locator('#p-position h2').click();
});
