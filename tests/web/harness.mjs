// Starts what the browser tests need: edmplc (drill-sim.yaml with an operator and a viewer token,
// virtual clock paced to 10x, free ports, nothing retained), `edmhmi serve`, and Debian's
// Chromium through playwright-core (no browser download). Every wait is on a condition with a
// timeout.
//
// The jog dead-man (job.manual.deadman) counts machine time: on the clock paced 10x its default
// 500 ms is 50 ms of wall time, finer than a browser's timers. The tests set DEADMAN_MS = 5 s of
// machine time: 500 ms of wall time, what the default is on a real clock, and the figure the
// dead-man tests measure against.
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync, chmodSync, mkdirSync, symlinkSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import net from 'node:net';
import { randomBytes } from 'node:crypto';
import { createRequire } from 'node:module';

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
export const BUILD = process.env.EDM_BUILD_DIR || join(ROOT, 'build');
export const OUT = process.env.EDM_WEB_ARTIFACTS || join(ROOT, 'out/web');
// playwright-core is a dev dependency of web/ (pinned in web/package.json, installed by npm ci).
const { chromium } = createRequire(join(ROOT, 'web/package.json'))('playwright-core');
export const CHROMIUM = process.env.EDM_CHROMIUM || '/usr/bin/chromium';

export const SPEED = 10;
export const DEADMAN_MS = 5000;

export function freePort() {
  return new Promise((res, rej) => {
    const s = net.createServer();
    s.on('error', rej);
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => res(port)); });
  });
}

/** Resolves with the first match of `re` in the child's output, rejects on exit or timeout. */
export function waitForOutput(child, re, what, timeoutMs = 20000) {
  return new Promise((res, rej) => {
    let seen = '';
    const timer = setTimeout(() => rej(new Error(`${what}: no '${re}' within ${timeoutMs} ms:\n${seen}`)), timeoutMs);
    const on = (d) => {
      seen += d.toString();
      const m = re.exec(seen);
      if (m) { clearTimeout(timer); res(m); }
    };
    child.stdout.on('data', on);
    child.stderr.on('data', on);
    child.on('exit', (code) => { clearTimeout(timer); rej(new Error(`${what} exited (${code}):\n${seen}`)); });
  });
}

/** A private directory with an operator and a viewer token and drill-sim's config using them;
 *  `edit` may change the config's text first (each edit must change it). */
export function makeMachine({ edit = null } = {}) {
  const dir = mkdtempSync(join(tmpdir(), 'edm-web-'));
  const op = join(dir, 'operator.token');
  const vw = join(dir, 'viewer.token');
  const tokens = { operator: randomBytes(16).toString('hex'), viewer: randomBytes(16).toString('hex') };
  writeFileSync(op, `${tokens.operator}\n`); chmodSync(op, 0o600);
  writeFileSync(vw, `${tokens.viewer}\n`); chmodSync(vw, 0o600);
  // EDM_WEB_MACHINE_CONFIG: another drill-sim-like config (e.g. one that matches an older edmplc).
  const base = readFileSync(process.env.EDM_WEB_MACHINE_CONFIG
    || join(ROOT, 'config/machines/drill-sim.yaml'), 'utf8');
  const config = join(dir, 'drill-sim-tokens.yaml');
  const withTokens = base.replace(/^bridge:.*$/m,
    `bridge:\n  token_file: ${op}\n  viewer_token_file: ${vw}`);
  if (withTokens === base) throw new Error('drill-sim.yaml has no bridge: section');
  const withDeadman = withTokens.replace('manual: {}', `manual: {deadman: ${DEADMAN_MS}ms}`);
  if (withDeadman === withTokens) throw new Error('drill-sim.yaml has no EdmJob manual: {}');
  const edited = edit ? edit(withDeadman) : withDeadman;
  if (edit && edited === withDeadman) throw new Error('the config edit changed nothing');
  writeFileSync(config, edited);
  // The copy includes the machines' fragments (docs/config.md "Fragments"): link them beside it.
  symlinkSync(join(ROOT, 'config/machines/fragments'), join(dir, 'fragments'));
  return { dir, tokens, op, vw, config, procs: [] };
}

/** Starts edmplc of `stack` on `stack.bridgePort` and waits until its bridge listens. */
export async function startPlc(stack, { speed = String(SPEED) } = {}) {
  const plc = spawn(join(BUILD, 'bin/edmplc'), ['--config', stack.config, '--clock', 'virtual',
    '--speed', speed, '--bridge-port', String(stack.bridgePort), '--state-dir', join(stack.dir, 'state')],
  { stdio: ['ignore', 'pipe', 'pipe'] });
  stack.procs.push(plc);
  stack.plc = plc;
  await waitForOutput(plc, /bridge: listening on/, 'edmplc');
  return plc;
}

/** Starts `edmhmi serve` for `stack` (`args` after `serve`; `nofile`: its descriptor limit) and
 *  waits until it listens; resolves {child, url, port, stderr()}. */
export async function startServe(stack, { args = [], nofile = 0, env = {} } = {}) {
  const argv = ['--port', String(stack.bridgePort), '--token-file', stack.op,
    'serve', '--listen', '127.0.0.1:0', '--web-root', join(BUILD, 'web'), ...args];
  const bin = join(BUILD, 'bin/edmhmi');
  const child = nofile > 0
    ? spawn('sh', ['-c', `ulimit -n ${nofile} && exec "$0" "$@"`, bin, ...argv],
      { stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, ...env } })
    : spawn(bin, argv, { stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, ...env } });
  stack.procs.push(child);
  let err = '';
  child.stderr.on('data', (d) => { err += d.toString(); });
  const m = await waitForOutput(child, /listening on (http:\/\/[0-9.:]+\/)/, 'edmhmi serve');
  const url = m[1];
  return { child, url, port: Number(new URL(url).port), stderr: () => err };
}

export async function startStack({ speed = String(SPEED), edit = null } = {}) {
  const stack = makeMachine({ edit });
  stack.bridgePort = await freePort();
  try {
    await startPlc(stack, { speed });
    const serve = await startServe(stack);
    stack.serve = serve.child;
    stack.url = serve.url;
  } catch (e) {
    stopStack(stack);
    throw e;
  }
  return stack;
}

export function stopStack(stack) {
  for (const p of [...stack.procs].reverse()) {
    if (p.exitCode === null && p.signalCode === null) p.kill('SIGINT');
  }
}

// playwright's launch() gives Chromium a new empty profile directory of its own every time (it
// refuses a --user-data-dir argument), which is the fresh --user-data-dir the flags below expect.
export async function launchBrowser() {
  return chromium.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
}

export function artifacts() {
  mkdirSync(OUT, { recursive: true });
  return OUT;
}

export async function login(page, url, token) {
  await page.goto(url);
  await page.locator('#token').fill(token);
  await page.locator('#login-btn').click();
  await page.locator('#app').waitFor({ state: 'visible', timeout: 10000 });
}
