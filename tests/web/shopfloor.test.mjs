// The page on a production shift (issue 33): the running job's panel (the line highlighted, an
// ETA, the depth bar), a program started from the command line shown as loaded elsewhere, the
// feed override's readback, a dry run's report labelled as one, the Variables tab (parameters
// written, pins forced with a badge), the conditions table, the dark theme and the inch display.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { spawn } from 'node:child_process';
import { startStack, stopStack, launchBrowser, login, artifacts, ROOT, BUILD } from './harness.mjs';

const T = 30000;
const demo = readFileSync(join(ROOT, 'examples/parts/demo.nc'), 'utf8');
let stack; let browser; let page; let out;
const state = () => page.locator('#state');

async function upload(text = demo) {
  await page.locator('#program').fill(text);
  await page.locator('#part-name').fill('demo.nc');
  await page.locator('#btn-upload').click();
  await page.locator('#check-result').filter({ hasText: 'uploaded' }).waitFor({ timeout: T });
}

before(async () => {
  out = artifacts();
  stack = await startStack();
  browser = await launchBrowser();
  page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await login(page, stack.url, stack.tokens.operator);
  await state().filter({ hasText: 'READY' }).waitFor({ timeout: T });
});

after(async () => {
  if (browser) await browser.close();
  if (stack) stopStack(stack);
});

test('the conditions (E) table from machine.info: the fields drill-sim lets operators edit', async () => {
  await page.locator('#conditions tr[data-e="1"]').waitFor({ timeout: T });
  assert.match(await page.locator('#conditions tr[data-e="1"]').textContent(), /drill-rough/);
  assert.match(await page.locator('#conditions-note').textContent(), /editable: on_time_us/);
  // machine.condition_edit: on, off, Tdr and servo reference; nothing else has an input.
  assert.equal(await page.locator('#conditions tr[data-e="1"] input').count(), 4);
  const tdr = page.locator('#conditions tr[data-e="1"] input[data-field="tdr_us"]');
  await tdr.fill('-3');
  await tdr.dispatchEvent('change');
  await page.locator('#conditions-note').filter({ hasText: 'must be > 0' }).waitFor({ timeout: T });
  await tdr.fill('9.5');
  await tdr.dispatchEvent('change');
  await page.locator('#conditions-note').filter({ hasText: 'E1 tdr_us set to 9.5' }).waitFor({ timeout: T });
});

test('the feed override as the machine has it, beside the control', async () => {
  await page.locator('#override-readback[data-percent="100"]').waitFor({ timeout: T });
  await page.locator('#override-pct').fill('60');
  await page.locator('#override-set').click();
  await page.locator('#override-readback[data-percent="60"]').waitFor({ timeout: T });
  assert.equal(await page.locator('#job-override').textContent(), '60 %');
  await page.locator('#override-pct').fill('100');
  await page.locator('#override-set').click();
  await page.locator('#override-readback[data-percent="100"]').waitFor({ timeout: T });
});

test('variables: a parameter is written, never forced; a forced pin has a badge', async () => {
  await page.locator('.tabs button[data-tab="vars"]').click();
  await page.locator('#var-prefix').fill('io.electrode_length_mm');
  await page.locator('#btn-var-list').click();
  await page.locator('#var-list li[data-var="io.electrode_length_mm"]').click();
  const param = page.locator('#watch tr[data-var="io.electrode_length_mm"]');
  await param.waitFor({ timeout: T });
  assert.equal(await param.locator('.var-write').count(), 1);
  assert.equal(await param.locator('.var-force, .var-unforce').count(), 0, 'a parameter offered Force');
  // A pin of the job that nothing reads while READY.
  await page.locator('#var-prefix').fill('cnc.job.n_open');
  await page.locator('#btn-var-list').click();
  await page.locator('#var-list li[data-var="cnc.job.n_open"]').click();
  const pin = page.locator('#watch tr[data-var="cnc.job.n_open"]');
  await pin.locator('input').fill('5');
  await pin.locator('.var-force').click();
  await page.locator('#confirm-yes').click();
  await page.locator('#watch tr.forced[data-var="cnc.job.n_open"] .forced-badge').waitFor({ timeout: T });
  await page.locator('#var-list li[data-var="cnc.job.n_open"]').waitFor({ timeout: T });
  await page.locator('#watch tr[data-var="cnc.job.n_open"] .var-unforce').click();
  await page.waitForFunction(() => !document.querySelector('#watch tr[data-var="cnc.job.n_open"]')?.classList.contains('forced'),
    null, { timeout: T });
  await page.locator('.tabs button[data-tab="stats"]').click();
});

test('the dark theme is remembered across a reload', async () => {
  const before = await page.evaluate(() => document.documentElement.dataset.theme);
  await page.locator('#btn-theme').click();
  const dark = before === 'dark' ? 'light' : 'dark';
  assert.equal(await page.evaluate(() => document.documentElement.dataset.theme), dark);
  await page.reload();
  await page.locator('#app').waitFor({ state: 'visible', timeout: T });
  assert.equal(await page.evaluate(() => document.documentElement.dataset.theme), dark);
  if (dark === 'dark') await page.screenshot({ path: join(out, 'dark.png') });
  await page.locator('#btn-theme').click();
});

test('inches on display, mm to the machine', async () => {
  await page.locator('#btn-units').click();
  await page.waitForFunction(() => {
    const d = document.getElementById('dro-x');
    return d.dataset.mm !== '' && d.textContent === (Number(d.dataset.mm) / 25.4).toFixed(4);
  }, null, { timeout: T, polling: 50 });
  assert.equal(await page.locator('#offsets-unit').textContent(), 'in');
  await page.locator('#off-G55-X').fill('1');
  await page.locator('#off-set-G55').click();
  await page.waitForFunction(() => Math.abs((window.edm.offsets?.frames?.G55?.x ?? 0) - 25.4) < 1e-9,
    null, { timeout: T });
  assert.equal(await page.locator('#off-G55-X').inputValue(), '1.00000');
  await page.locator('#btn-units').click();
  await page.waitForFunction(() => document.getElementById('off-G55-X').value === '25.4000', null, { timeout: T });
  await page.reload(); // remembered
  await page.locator('#app').waitFor({ state: 'visible', timeout: T });
  assert.equal(await page.locator('#btn-units').textContent(), 'unit: mm');
});

test('a dry run is labelled as one, its report gives no depth error', async () => {
  await upload();
  await page.locator('#dry-run').check();
  await page.locator('#btn-start').click();
  await page.locator('#confirm-yes').click();
  await page.locator('#job-dry').waitFor({ state: 'visible', timeout: T });
  await page.locator('#job-report').filter({ hasText: 'outcome' }).waitFor({ timeout: 60000 });
  const report = await page.locator('#job-report').textContent();
  assert.match(report, /^DRY RUN/);
  assert.match(report, /outcome\s+finished \(dry run\)/);
  assert.doesNotMatch(report, /error [+−-]/);
  await page.locator('#dry-run').uncheck();
  await state().filter({ hasText: 'READY' }).waitFor({ timeout: T });
});

test('a running job: its line highlighted, an ETA, the depth against the target', async () => {
  await upload();
  await page.evaluate(() => document.activeElement?.blur());
  await page.locator('#btn-start').click();
  await page.locator('#confirm-yes').click();
  await state().filter({ hasText: 'RUNNING' }).waitFor({ timeout: T });
  const drillLine = demo.split('\n').findIndex((l) => l.startsWith('G01 Z-12')) + 1;
  await page.locator(`#editor .cur-line[data-line="${drillLine}"]`).waitFor({ timeout: 60000 });
  await page.waitForFunction(() => Number(document.getElementById('depth-bar').dataset.depth) > 1,
    null, { timeout: 60000, polling: 100 });
  assert.equal(Number(await page.locator('#depth-bar').getAttribute('data-target')), 12);
  assert.match(await page.locator('#depth-text').textContent(), new RegExp(`/ 12\\.000 mm \\(line ${drillLine}\\)`));
  await page.locator('#job-eta').filter({ hasText: '≈' }).waitFor({ timeout: T });
  assert.match(await page.locator('#job-eta').textContent(), /left \(the drilling rate so far\)/);
  await page.screenshot({ path: join(out, 'job-running.png') });
  // An edited copy in the editor: nothing highlighted, and the panel says why.
  await page.locator('#program').fill(`${demo}\n; edited`);
  await page.locator('#job-note').filter({ hasText: 'edited copy' }).waitFor({ timeout: T });
  assert.equal(await page.locator('#editor .cur-line').count(), 0);
  await page.locator('#btn-stop').click();
  await page.locator('#confirm-yes').click();
  await state().filter({ hasText: 'READY' }).waitFor({ timeout: T });
});

test('a job started from the command line is shown as loaded elsewhere', async () => {
  const file = join(stack.dir, 'cli.nc');
  writeFileSync(file, demo);
  // The stopped job has ended (READY shows while a job may still be ending).
  await page.waitForFunction(() => window.edm.status?.state === 'READY'
    && window.edm.status.job.outcome !== 'running', null, { timeout: T, polling: 50 });
  const cli = spawn(join(BUILD, 'bin/edmhmi'), ['--port', String(stack.bridgePort), '--token-file',
    stack.op, 'run', '--dry-run', '--quiet', file], { stdio: ['ignore', 'pipe', 'pipe'] });
  stack.procs.push(cli);
  let said = '';
  cli.stdout.on('data', (d) => { said += d; });
  cli.stderr.on('data', (d) => { said += d; });
  await page.locator('#job-foreign').waitFor({ state: 'visible', timeout: T })
    .catch((e) => { throw new Error(`no "loaded elsewhere"; edmhmi run said: ${said}`, { cause: e }); });
  assert.match(await page.locator('#job-part').textContent(), /a program loaded elsewhere \(generation \d+, \d+ blocks\)/);
  assert.match(await page.locator('#job-note').textContent(), /not what this page uploaded/);
  assert.equal(await page.locator('#editor .cur-line').count(), 0);
  await state().filter({ hasText: 'READY' }).waitFor({ timeout: 60000 }).catch(async (e) => {
    const seen = await page.evaluate(() => JSON.stringify({ state: window.edm.status?.state,
      job: window.edm.status?.job, alarms: (window.edm.alarms || []).slice(-3).map((a) => `${a.code} ${a.source}: ${a.text}`) }));
    throw new Error(`not READY again: ${seen}; edmhmi run said: ${said}`, { cause: e });
  });
  assert.ok(await page.locator('#btn-start').isDisabled(), 'Start offered for the program loaded elsewhere');
  await new Promise((resolve) => { if (cli.exitCode !== null) resolve(); else cli.on('exit', resolve); });
  // Uploading from the page makes it the page's program again.
  await upload();
  await page.locator('#job-foreign').waitFor({ state: 'hidden', timeout: T });
  await page.waitForFunction(() => !document.getElementById('btn-start').disabled, null, { timeout: T });
});
