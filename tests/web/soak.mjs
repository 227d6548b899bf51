// The page's memory over a long run (issue 22: "the 20 Hz charts keep memory flat"). Not a ctest:
//   cd web && node ../tests/web/soak.mjs [minutes=30] [seconds between samples=60]
// edmplc (drill-sim, virtual clock paced 10x) runs the demo job again and again, started from the
// page; every minute the JS heap is read after a forced garbage collection (CDP) and printed, and
// the series goes to out/web/soak.json.
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { readFileSync } from 'node:fs';
import { startStack, stopStack, launchBrowser, login, artifacts, ROOT } from './harness.mjs';

const minutes = Number(process.argv[2] || 30);
const everyS = Number(process.argv[3] || 60);
const out = artifacts();
const stack = await startStack();
const browser = await launchBrowser();
const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
const cdp = await page.context().newCDPSession(page);
await cdp.send('Performance.enable');
const samples = [];
try {
  await login(page, stack.url, stack.tokens.operator);
  await page.locator('#state').filter({ hasText: 'READY' }).waitFor({ timeout: 30000 });
  await page.locator('#program').fill(readFileSync(join(ROOT, 'examples/parts/demo.nc'), 'utf8'));
  await page.locator('#part-name').fill('demo.nc');
  const t0 = Date.now();
  let jobs = 0;
  let nextSample = t0;
  while (Date.now() - t0 < minutes * 60000) {
    if (Date.now() >= nextSample) {
      await cdp.send('HeapProfiler.collectGarbage');
      const m = await cdp.send('Performance.getMetrics');
      const get = (n) => m.metrics.find((x) => x.name === n)?.value;
      const s = { t_min: (Date.now() - t0) / 60000, heap_used_mb: get('JSHeapUsedSize') / 1048576,
        heap_total_mb: get('JSHeapTotalSize') / 1048576, nodes: get('Nodes'), jobs,
        points: Number(await page.locator('#chart-z').getAttribute('data-points')),
        state: await page.locator('#state').textContent(),
        alarms: await page.locator('#alarms li').count() };
      samples.push(s);
      console.log(JSON.stringify(s));
      nextSample += everyS * 1000;
    }
    // Keep jobs running: upload + start whenever the machine is idle.
    const st = await page.locator('#state').textContent();
    if (st === 'FAULT' || st === 'ESTOP') {  // the demo drilled into its own hole again
      await page.locator('#btn-reset').click();
      await page.locator('#confirm-yes').click();
      await page.locator('#state').filter({ hasText: 'READY' }).waitFor({ timeout: 30000 });
    }
    if ((await page.locator('#state').textContent()) === 'READY') {
      await page.locator('#btn-upload').click();
      await page.locator('#check-result').filter({ hasText: 'uploaded' }).waitFor({ timeout: 30000 });
      await page.locator('#btn-start').click();
      await page.locator('#confirm-yes').click();
      await page.locator('#state').filter({ hasText: 'RUNNING' }).waitFor({ timeout: 30000 });
      jobs++;
    }
    await page.locator('#state').filter({ hasText: 'READY' })
      .waitFor({ timeout: Math.max(1000, nextSample - Date.now()) }).catch(() => {});
  }
} finally {
  await page.screenshot({ path: join(out, 'soak-end.png') }).catch(() => {});
  writeFileSync(join(out, 'soak.json'), `${JSON.stringify(samples, null, 2)}\n`);
  await browser.close();
  stopStack(stack);
}
