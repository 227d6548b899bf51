// Hostile HTTP and WebSocket input against `edmhmi serve`, on raw sockets (no browser): path
// traversal, oversized requests, wrong methods, cross-origin upgrades, no log-in, huge messages,
// and the attacks of issue 31 on the page server: DNS rebinding (item 1), messages that crashed it
// (2), sockets that ask and never read (3), descriptor exhaustion (4), a log-in flood (5), a start
// before edmplc (startup), and slowloris, many sockets, binary/fragmented frames, ping floods.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import net from 'node:net';
import { randomBytes } from 'node:crypto';
import { readFileSync } from 'node:fs';
import { startStack, stopStack, startPlc, startServe, makeMachine, freePort } from './harness.mjs';
import { wsConnect, wsLogin, frame as wsFrame } from './wsclient.mjs';

let stack; let host; let port;

before(async () => {
  stack = await startStack();
  const u = new URL(stack.url);
  host = u.hostname;
  port = Number(u.port);
});
after(() => stopStack(stack));

/** Sends raw bytes; resolves with what came back and whether the server ended the connection
 *  (end, reset or a refused write) within 15 s. */
function rawConn(bytes) {
  return new Promise((resolve) => {
    const s = net.connect(port, host);
    let got = Buffer.alloc(0);
    const done = (closed) => { clearTimeout(timer); s.destroy(); resolve({ text: got.toString('latin1'), closed }); };
    const timer = setTimeout(() => done(false), 15000);
    s.on('data', (d) => { got = Buffer.concat([got, d]); });
    s.on('end', () => done(true));
    s.on('error', () => done(true));
    s.write(bytes);
  });
}
const raw = async (bytes) => (await rawConn(bytes)).text;
const get = (target, extra = '') => raw(`GET ${target} HTTP/1.1\r\nHost: ${host}:${port}\r\nConnection: close\r\n${extra}\r\n`);
const status = (r) => Number(/^HTTP\/1\.1 (\d+)/.exec(r)?.[1]);
const upgrade = (extra = `Origin: http://${host}:${port}\r\n`) => `GET /ws HTTP/1.1\r\nHost: ${host}:${port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n`
  + `Sec-WebSocket-Key: ${randomBytes(16).toString('base64')}\r\nSec-WebSocket-Version: 13\r\n${extra}\r\n`;

/** A masked client text frame (RFC 6455) with a 64-bit length. */
function frame(payload) {
  const mask = randomBytes(4);
  const head = Buffer.alloc(14);
  head[0] = 0x81; head[1] = 0x80 | 127;
  head.writeBigUInt64BE(BigInt(payload.length), 2);
  mask.copy(head, 10);
  const body = Buffer.from(payload);
  for (let i = 0; i < body.length; i++) body[i] ^= mask[i % 4];
  return Buffer.concat([head, body]);
}

test('index.html: type, no-cache, nosniff, CSP', async () => {
  const r = await get('/');
  assert.equal(status(r), 200);
  assert.match(r, /Content-Type: text\/html; charset=utf-8/i);
  assert.match(r, /Cache-Control: no-cache/i);
  assert.match(r, /X-Content-Type-Options: nosniff/i);
  assert.match(r, /Content-Security-Policy: default-src 'self'/i);
});

test('traversal outside the web root is refused', async () => {
  for (const t of ['/../../../../etc/passwd', '/%2e%2e/%2e%2e/etc/passwd', '/assets/..%2f..%2f..%2fetc/passwd', '/..\\..\\etc\\passwd']) {
    const r = await get(t);
    assert.ok([400, 404].includes(status(r)), `${t}: ${status(r)}`);
    assert.doesNotMatch(r, /root:/);
  }
});

test('other methods, oversized headers and bodies are refused', async () => {
  assert.equal(status(await raw(`DELETE / HTTP/1.1\r\nHost: ${host}:${port}\r\nConnection: close\r\n\r\n`)), 405);
  assert.equal(status(await get('/', `X-Big: ${'a'.repeat(20000)}\r\n`)), 413);
  const body = 'b'.repeat(100000);
  assert.equal(status(await raw(`POST / HTTP/1.1\r\nHost: x\r\nContent-Length: ${body.length}\r\n\r\n${body}`)), 413);
});

test('a cross-origin WebSocket upgrade is refused', async () => {
  const r = await raw(upgrade('Origin: http://evil.example\r\n'));
  assert.equal(status(r), 403);
});

test('a WebSocket that sends no log-in is closed; so is one over the message limit', async () => {
  const noLogin = await rawConn(upgrade());
  assert.match(noLogin.text, /^HTTP\/1\.1 101/);
  assert.ok(noLogin.closed, 'still open 15 s after the upgrade without a log-in');
  const big = await rawConn(Buffer.concat([Buffer.from(upgrade()), frame('x'.repeat(3 * 1024 * 1024))]));
  assert.ok(big.closed, 'a 3 MiB message did not close the socket');
});

// ---- issue 31: the page server under attack ------------------------------------------------

const until = async (cond, timeoutMs, what) => {
  const end = performance.now() + timeoutMs;
  for (;;) {
    const v = await cond();
    if (v) return v;
    if (performance.now() > end) throw new Error(`${what}: not within ${timeoutMs} ms`);
    await new Promise((r) => { setTimeout(r, 50); });  // polling an external process
  }
};
/** VmRSS / VmHWM of a process, kB. */
function memory(pid) {
  const s = readFileSync(`/proc/${pid}/status`, 'utf8');
  return { rss: Number(/VmRSS:\s+(\d+)/.exec(s)[1]), hwm: Number(/VmHWM:\s+(\d+)/.exec(s)[1]) };
}
/** CPU time of a process (user + system), s. */
function cpuSeconds(pid) {
  const f = readFileSync(`/proc/${pid}/stat`, 'utf8').split(') ')[1].split(' ');
  return (Number(f[11]) + Number(f[12])) / 100;  // utime, stime in clock ticks (USER_HZ 100)
}
const alive = (child) => child.exitCode === null && child.signalCode === null;
const hostGet = (p, hostHeader, extra = '') => raw2(p, `GET / HTTP/1.1\r\nHost: ${hostHeader}\r\nConnection: close\r\n${extra}\r\n`);
function raw2(p, bytes, localAddress) {
  return new Promise((resolve) => {
    const s = net.connect({ port: p, host: '127.0.0.1', localAddress });
    let got = '';
    const done = () => { clearTimeout(t); s.destroy(); resolve(got); };
    const t = setTimeout(done, 15000);
    s.on('data', (d) => { got += d.toString('latin1'); });
    s.on('end', done); s.on('error', done);
    s.write(bytes);
  });
}

test('issue 31 item 1: a foreign Host gets neither the page nor the socket (DNS rebinding)', async () => {
  for (const h of [`evil.example:${port}`, 'evil.example', `localhost.evil.example:${port}`, `127.0.0.1.nip.io:${port}`]) {
    const r = await hostGet(port, h);
    assert.equal(status(r), 421, `${h}: ${r.slice(0, 80)}`);
    assert.doesNotMatch(r, /<!doctype|<html|<script/i, `${h}: the page was served`);
  }
  assert.equal(status(await raw(`GET / HTTP/1.1\r\nConnection: close\r\n\r\n`)), 421, 'no Host');
  assert.equal(status(await raw(`GET / HTTP/1.1\r\nHost: ${host}:${port}\r\nHost: evil.example\r\nConnection: close\r\n\r\n`)), 421, 'two Hosts');
  // The probe of the issue: Host and Origin both evil.example — same origin by string.
  const probe = await wsConnect(port, { hostHeader: `evil.example:${port}`, origin: `http://evil.example:${port}` });
  assert.equal(probe.status, 421);
  assert.equal((await wsConnect(port, { origin: `http://evil.example:${port}` })).status, 403);
  assert.equal((await wsConnect(port, { origin: null })).status, 403, 'an upgrade without Origin');
  assert.equal((await wsConnect(port, { origin: 'null' })).status, 403);
  assert.equal((await wsConnect(port, { hostHeader: `localhost:${port}`, origin: 'http://localhost:3000' })).status, 403,
    'another local page');
  assert.equal((await wsConnect(port, { origin: `https://${host}:${port}` })).status, 403, 'another scheme');
  // Loopback names with the page's own origin are served.
  for (const hh of [`localhost:${port}`, `127.0.0.1:${port}`, `LOCALHOST:${port}`]) {
    assert.equal(status(await hostGet(port, hh)), 200, hh);
    const ok = await wsConnect(port, { hostHeader: hh, origin: `http://${hh.toLowerCase()}` });
    assert.equal(ok.status, 101, hh);
    ok.ws.destroy();
  }
});

test('issue 31 item 1: --allow-host and $EDM_WEB_ALLOW_HOSTS names are served, no others', async () => {
  const s2 = await startServe(stack, { args: ['--allow-host', 'hmi.test', '--allow-host', 'cell.test:8443'],
    env: { EDM_WEB_ALLOW_HOSTS: 'bay3.test, bay4.test' } });
  try {
    assert.equal(status(await hostGet(s2.port, `hmi.test:${s2.port}`)), 200);
    assert.equal(status(await hostGet(s2.port, `bay4.test:${s2.port}`)), 200);
    assert.equal(status(await hostGet(s2.port, `cell.test:${s2.port}`)), 421, 'cell.test only on 8443');
    assert.equal(status(await hostGet(s2.port, `evil.test:${s2.port}`)), 421);
    const ws = await wsConnect(s2.port, { hostHeader: `hmi.test:${s2.port}`, origin: 'https://hmi.test' });
    assert.equal(ws.status, 101, 'a configured name behind a TLS proxy');
    ws.ws.destroy();
  } finally { s2.child.kill('SIGINT'); }
});

test('issue 31 item 2: wrong types and 400,000-deep arrays are error replies; edmhmi lives', async () => {
  const { ws, welcome } = await wsLogin(port, stack.tokens.operator);
  assert.ok(welcome, 'log-in');
  ws.send({ t: 'cmd', id: 1, op: 'check', text: 'M30', name: 1 });
  ws.send({ t: 'cmd', id: 2, op: 'start', dry_run: 'yes' });
  const deep = '['.repeat(400000) + ']'.repeat(400000);
  ws.send(`{"t":"cmd","id":3,"op":"job","x":${deep}}`);
  ws.send(`{"t":"cmd","id":4,"op":"var.read","names":${deep}}`);
  ws.send({ t: 'cmd', id: 5, op: 'var.read', names: 'io.z_mm' });
  ws.send({ t: 'cmd', id: 6, op: 'job', op2: 1 });
  ws.send({ t: 'cmd', id: 7, op: 'job' });
  const r7 = await ws.next((m) => m.t === 'reply' && m.id === 7, 20000);
  assert.ok(r7?.ok, `a good command after the bad ones: ${JSON.stringify(r7)}`);
  const reply = (id) => ws.messages.find((m) => m.t === 'reply' && m.id === id);
  assert.match(reply(1).message, /'name'/);
  assert.match(reply(2).message, /'dry_run' must be true or false/);
  for (const id of [1, 2, 5, 6]) {
    assert.equal(reply(id).ok, false, JSON.stringify(reply(id)));
    assert.equal(reply(id).code, 'bad_request', JSON.stringify(reply(id)));
  }
  const deepErrors = ws.messages.filter((m) => m.t === 'error' && m.code === 'bad_json');
  assert.equal(deepErrors.length, 2, JSON.stringify(deepErrors));
  assert.match(deepErrors[0].message, /nested deeper than 32/);
  assert.ok(alive(stack.serve), 'edmhmi serve ended');
  ws.destroy();
});

test('issue 31 item 3: 8 sockets that ask for the 2 MiB job and never read stay within 160 MB', async () => {
  const pad = `(${'p'.repeat(98)})\n`;
  const text = `G90 G00 Z5\n${pad.repeat(Math.floor((2 * 1024 * 1024 - 64) / pad.length))}M30\n`;
  const { ws } = await wsLogin(port, stack.tokens.operator);
  ws.send({ t: 'cmd', id: 1, op: 'upload', name: 'big.nc', text });
  const up = await ws.next((m) => m.t === 'reply' && m.id === 1, 60000);
  assert.ok(up?.ok, `upload: ${JSON.stringify(up)}`);
  const pid = stack.serve.pid;
  const before = memory(pid);
  const slow = [];
  for (let i = 0; i < 8; i++) {
    const s = await wsLogin(port, stack.tokens.operator, { localAddress: `127.0.1.${i + 1}` });
    assert.ok(s.welcome);
    s.ws.socket.pause();  // never reads again
    slow.push(s.ws);
  }
  let id = 0;
  const t0 = performance.now();
  while (performance.now() - t0 < 3000) {
    for (const s of slow) for (let k = 0; k < 4; k++) s.send({ t: 'cmd', id: ++id, op: 'job' });
    await new Promise((r) => { setTimeout(r, 100); });  // the attacker's pace
  }
  // The server closes them: every one's reply overflowed its queue (or its frames stalled).
  ws.send({ t: 'cmd', id: 2, op: 'stats' });
  const st = await until(async () => {
    ws.send({ t: 'cmd', id: 3, op: 'stats' });
    const r = await ws.next((m) => m.t === 'reply' && m.id === 3 && m.web.slow_disconnects >= 8, 1000, ws.messages.length);
    return r;
  }, 20000, 'the 8 non-reading sockets closed');
  const after = memory(pid);
  const growthMb = (after.hwm - before.rss) / 1024;
  console.log(`# item 3: RSS ${(before.rss / 1024).toFixed(1)} MB before, peak ${(after.hwm / 1024).toFixed(1)} MB `
    + `(+${growthMb.toFixed(1)} MB), ${st.web.reply_overflows} reply overflows, ${st.web.slow_disconnects} slow disconnects`);
  assert.ok(growthMb < 160, `edmhmi grew by ${growthMb.toFixed(1)} MB`);
  for (const s of slow) s.destroy();
  ws.destroy();
});

test('issue 31 item 4: out of descriptors, accept backs off (10 ms to 1 s) and logs once', async () => {
  const s4 = await startServe(stack, { nofile: 40 });
  const conns = [];
  try {
    for (let i = 0; i < 60; i++) {
      const c = net.connect({ port: s4.port, host: '127.0.0.1', localAddress: `127.0.2.${1 + (i % 3)}` });
      c.on('error', () => {});
      conns.push(c);
    }
    await until(() => /Too many open files/.test(s4.stderr()), 15000, 'EMFILE');
    const err0 = s4.stderr().length;
    const cpu0 = cpuSeconds(s4.child.pid);
    await new Promise((r) => { setTimeout(r, 2000); });  // the measurement window
    const cpu = cpuSeconds(s4.child.pid) - cpu0;
    const logged = s4.stderr().length - err0;
    console.log(`# item 4: at EMFILE, ${cpu.toFixed(2)} s of CPU in 2 s, ${logged} bytes logged`);
    assert.ok(cpu < 0.4, `${cpu} s of CPU in 2 s at EMFILE`);
    assert.ok(logged < 512, `${logged} bytes logged in 2 s at EMFILE`);
    for (const c of conns) c.destroy();
    await until(async () => status(await hostGet(s4.port, `127.0.0.1:${s4.port}`)) === 200, 10000, 'accepting again');
    assert.match(s4.stderr(), /accepting again after \d+ failed accepts/);
    assert.equal((s4.stderr().match(/Too many open files/g) || []).length, 1, s4.stderr());
  } finally {
    for (const c of conns) c.destroy();
    s4.child.kill('SIGINT');
  }
});

test('issue 31 item 5: 40 wrong log-ins from one browser do not keep another one out', async () => {
  // 40 sockets from one address: the per-address cap (32 connections) already drops some.
  const tries = await Promise.all(Array.from({ length: 40 }, () => wsConnect(port, { localAddress: '127.0.3.1' })));
  const flood = tries.filter((r) => r.ws);
  assert.ok(flood.length >= 30 && flood.length <= 32, `${flood.length} of 40 sockets opened`);
  const t0 = performance.now();
  for (const r of flood) r.ws.send({ t: 'login', token: `wrong-${randomBytes(12).toString('hex')}` });
  const b = await wsLogin(port, stack.tokens.operator, { localAddress: '127.0.3.2', timeoutMs: 30000 });
  const ms = performance.now() - t0;
  const refused = flood.filter((r) => r.ws.messages.some((m) => m.t === 'login_failed')).length;
  console.log(`# item 5: the other browser logged in ${ms.toFixed(0)} ms after the flood; ${refused} of ${flood.length} checked by then`);
  assert.ok(b.welcome, `the right token from another browser: ${JSON.stringify(b.reply)}`);
  assert.ok(ms < 3000, `the right token waited ${ms.toFixed(0)} ms`);
  // The flooding address itself is throttled: 250 ms, 500 ms, 1 s, … between its checks.
  await new Promise((r) => { setTimeout(r, 1600 - (performance.now() - t0)); });
  const checked = flood.filter((r) => r.ws.messages.some((m) => m.t === 'login_failed')).length;
  assert.ok(checked >= 1 && checked <= 4, `${checked} of the ${flood.length} wrong tokens checked in 1.6 s`);
  for (const r of flood) r.ws.destroy();
  // Its right token is delayed (by what it earned), not refused.
  const a = await wsLogin(port, stack.tokens.operator, { localAddress: '127.0.3.1', timeoutMs: 20000 });
  assert.ok(a.welcome, `the flooder's own right token: ${JSON.stringify(a.reply)}`);
  a.ws.destroy(); b.ws.destroy();
});

test('startup: serve before edmplc waits and says so, logs in when it comes, and after a restart', async () => {
  const m = makeMachine();
  m.bridgePort = await freePort();
  try {
    const s = await startServe(m);  // nothing listens at the bridge port yet
    assert.equal(status(await hostGet(s.port, `127.0.0.1:${s.port}`)), 200, 'the page is served');
    const r = await wsConnect(s.port);
    assert.equal(r.status, 101);
    r.ws.send({ t: 'login', token: m.tokens.operator });
    const waiting = await r.ws.next((x) => x.t === 'bridge' && x.up === false);
    assert.match(waiting.message, new RegExp(`waiting for edmplc at 127\\.0\\.0\\.1:${m.bridgePort}`));
    // Its log line may reach this process after the socket's message: wait for it on its pipe.
    await new Promise((res, rej) => {
      const timer = setTimeout(() => rej(new Error(`no 'waiting for edmplc at' in: ${s.stderr()}`)), 10000);
      const check = () => {
        if (!/waiting for edmplc at/.test(s.stderr())) return;
        clearTimeout(timer); s.child.stderr.off('data', check); res();
      };
      s.child.stderr.on('data', check);
      check();
    });
    assert.ok(alive(s.child), 'serve exited');
    await startPlc(m);
    const w = await r.ws.next((x) => x.t === 'welcome', 30000);
    assert.ok(w, 'the waiting log-in is answered once edmplc is there');
    assert.equal(w.role, 'operator');
    // edmplc restarts: the page is told, and serve follows it.
    const mark = r.ws.messages.length;
    m.plc.kill('SIGTERM');
    await new Promise((res) => { m.plc.once('exit', res); });
    const down = await r.ws.next((x) => (x.t === 'bridge' && x.up === false) || (x.t === 'frame' && x.bridge === false), 15000, mark);
    assert.ok(down, 'the page is told edmplc went away');
    await startPlc(m);
    const up = await r.ws.next((x) => x.t === 'bridge' && x.up === true, 30000, mark);
    assert.ok(up, 'and that it is back');
    assert.ok(alive(s.child));
    const again = await wsLogin(s.port, m.tokens.operator);
    assert.ok(again.welcome);
    again.ws.destroy(); r.ws.destroy();
  } finally { stopStack(m); }
});

// ---- beyond the inputs -------------------------------------------------------------

test('slowloris: one address trickling headers holds at most 32 connections; others are served', async () => {
  const held = [];
  let dropped = 0;
  for (let i = 0; i < 50; i++) {
    const c = net.connect({ port, host: '127.0.0.1', localAddress: '127.0.4.1' });
    c.on('error', () => {});
    c.on('close', () => { dropped++; });
    c.write('GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-a: ');
    held.push(c);
  }
  try {
    await until(() => dropped >= 18, 10000, 'connections over the per-address cap dropped');
    const r = await raw2(port, `GET / HTTP/1.1\r\nHost: ${host}:${port}\r\nConnection: close\r\n\r\n`, '127.0.4.2');
    assert.equal(status(r), 200, 'another address is served');
  } finally { for (const c of held) c.destroy(); }
});

test('many sockets: upgrades past 64 get 503', async () => {
  const socks = [];
  try {
    let refused = 0;
    for (let i = 0; i < 70; i++) {
      const r = await wsConnect(port, { localAddress: `127.0.5.${1 + (i % 5)}` });
      if (r.ws) socks.push(r.ws); else if (r.status === 503) refused++;
    }
    assert.ok(socks.length <= 64, `${socks.length} sockets open`);
    assert.ok(refused >= 6, `${refused} refused`);
  } finally { for (const s of socks) s.destroy(); }
  // Their slots come back: a browser gets in again.
  await until(async () => {
    const r = await wsConnect(port);
    if (r.ws) r.ws.destroy();
    return r.status === 101;
  }, 15000, 'a socket after the flood');
});

test('binary and fragmented frames, ping floods', async () => {
  const bin = await wsConnect(port);
  bin.ws.sendRaw(wsFrame(Buffer.from('{"t":"login","token":""}'), { opcode: 2 }));
  assert.ok(await bin.ws.waitClosed(10000), 'a binary message closes the socket');
  // A log-in in three fragments is one message.
  const frag = await wsConnect(port);
  const login = JSON.stringify({ t: 'login', token: stack.tokens.viewer });
  frag.ws.sendRaw(Buffer.concat([wsFrame(login.slice(0, 5), { fin: false }),
    wsFrame(login.slice(5, 12), { opcode: 0, fin: false }), wsFrame(login.slice(12), { opcode: 0 })]));
  const w = await frag.ws.next((m) => m.t === 'welcome');
  assert.equal(w?.role, 'viewer');
  // 20,000 pings from a socket that does not read the pongs: nothing grows, others are served.
  const before = memory(stack.serve.pid).rss;
  frag.ws.socket.pause();
  const ping = wsFrame(Buffer.alloc(125, 1), { opcode: 9 });
  for (let i = 0; i < 20000; i++) frag.ws.sendRaw(ping);
  const other = await wsLogin(port, stack.tokens.viewer);
  assert.ok(other.welcome, 'another browser during the ping flood');
  const grown = (memory(stack.serve.pid).rss - before) / 1024;
  assert.ok(grown < 50, `+${grown.toFixed(1)} MB during the ping flood`);
  other.ws.destroy(); frag.ws.destroy();
  assert.ok(alive(stack.serve));
});
