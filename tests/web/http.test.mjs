// Hostile HTTP and WebSocket input against `edmhmi serve`, on raw sockets (no browser): path
// traversal, oversized requests, wrong methods, cross-origin upgrades, no log-in, huge messages.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import net from 'node:net';
import { randomBytes } from 'node:crypto';
import { startStack, stopStack } from './harness.mjs';

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
const upgrade = (extra = '') => `GET /ws HTTP/1.1\r\nHost: ${host}:${port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n`
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
  assert.equal(status(await raw(`DELETE / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n`)), 405);
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
