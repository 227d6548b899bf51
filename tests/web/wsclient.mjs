// A minimal WebSocket client on raw sockets (RFC 6455) for the hostile-client tests: any Host and
// Origin header (or none), a chosen local address (127.0.0.x: another "browser"), reading that
// can be paused (a client that never reads), fragmented server messages reassembled.
import net from 'node:net';
import { randomBytes } from 'node:crypto';

/** A masked client frame. */
export function frame(payload, { opcode = 1, fin = true } = {}) {
  const body = Buffer.isBuffer(payload) ? Buffer.from(payload) : Buffer.from(payload);
  const mask = randomBytes(4);
  let head;
  if (body.length < 126) {
    head = Buffer.alloc(6); head[1] = 0x80 | body.length; mask.copy(head, 2);
  } else if (body.length < 65536) {
    head = Buffer.alloc(8); head[1] = 0x80 | 126; head.writeUInt16BE(body.length, 2); mask.copy(head, 4);
  } else {
    head = Buffer.alloc(14); head[1] = 0x80 | 127; head.writeBigUInt64BE(BigInt(body.length), 2); mask.copy(head, 10);
  }
  head[0] = (fin ? 0x80 : 0) | opcode;
  for (let i = 0; i < body.length; i++) body[i] ^= mask[i % 4];
  return Buffer.concat([head, body]);
}

export class Ws {
  constructor(socket) {
    this.socket = socket;
    this.messages = [];
    this.waiters = [];
    this.closed = false;
    this.buf = Buffer.alloc(0);
    this.parts = [];
    this.closedPromise = new Promise((res) => { this.onClosed = res; });
  }

  feed(d) {
    this.buf = Buffer.concat([this.buf, d]);
    for (;;) {
      if (this.buf.length < 2) return;
      const op = this.buf[0] & 0x0f; const fin = (this.buf[0] & 0x80) !== 0;
      let len = this.buf[1] & 0x7f; let off = 2;
      if (len === 126) { if (this.buf.length < 4) return; len = this.buf.readUInt16BE(2); off = 4; }
      else if (len === 127) { if (this.buf.length < 10) return; len = Number(this.buf.readBigUInt64BE(2)); off = 10; }
      if (this.buf.length < off + len) return;
      const payload = this.buf.subarray(off, off + len);
      this.buf = this.buf.subarray(off + len);
      if (op === 9) { this.socket.write(frame(payload, { opcode: 10 })); continue; }
      if (op === 8) { this.end(); continue; }
      if (op === 0 || op === 1 || op === 2) {
        this.parts.push(Buffer.from(payload));
        if (!fin) continue;
        const text = Buffer.concat(this.parts).toString('utf8');
        this.parts = [];
        let m; try { m = JSON.parse(text); } catch { m = { unparsed: text }; }
        this.messages.push(m);
        this.waiters = this.waiters.filter((w) => { if (w.pred(m)) { w.resolve(m); return false; } return true; });
      }
    }
  }

  end() {
    if (this.closed) return;
    this.closed = true;
    for (const w of this.waiters) w.resolve(null);
    this.waiters = [];
    this.onClosed();
  }

  send(m) { this.socket.write(frame(typeof m === 'string' ? m : JSON.stringify(m))); }
  sendRaw(bytes) { this.socket.write(bytes); }

  /** The first message (seen from index `from` on, or to come) matching `pred`; null when the
   *  socket closes first or after `timeoutMs`. */
  next(pred, timeoutMs = 15000, from = 0) {
    const seen = this.messages.slice(from).find(pred);
    if (seen) return Promise.resolve(seen);
    if (this.closed) return Promise.resolve(null);
    return new Promise((resolve) => {
      const w = { pred, resolve: (m) => { clearTimeout(t); resolve(m); } };
      const t = setTimeout(() => { this.waiters = this.waiters.filter((x) => x !== w); resolve(null); }, timeoutMs);
      this.waiters.push(w);
    });
  }

  /** Resolves true when the server ends the connection within `timeoutMs`. */
  async waitClosed(timeoutMs = 15000) {
    let t;
    const r = await Promise.race([this.closedPromise.then(() => true),
      new Promise((res) => { t = setTimeout(() => res(false), timeoutMs); })]);
    clearTimeout(t);
    return r;
  }

  destroy() { this.socket.destroy(); this.end(); }
}

/** Opens /ws; resolves {status, head, ws} (ws only for a 101). */
export function wsConnect(port, { host = '127.0.0.1', hostHeader, origin, localAddress, extra = '' } = {}) {
  const hh = hostHeader ?? `${host}:${port}`;
  const org = origin === undefined ? `http://${hh}` : origin;
  return new Promise((resolve) => {
    const socket = net.connect({ port, host, localAddress });
    let head = Buffer.alloc(0);
    let ws = null;
    const timer = setTimeout(() => { socket.destroy(); resolve({ status: 0, head: head.toString('latin1') }); }, 15000);
    socket.on('data', (d) => {
      if (ws) { ws.feed(d); return; }
      head = Buffer.concat([head, d]);
      const end = head.indexOf('\r\n\r\n');
      if (end < 0) return;
      clearTimeout(timer);
      const text = head.subarray(0, end).toString('latin1');
      const status = Number(/^HTTP\/1\.1 (\d+)/.exec(text)?.[1]);
      if (status !== 101) { resolve({ status, head: head.toString('latin1') }); socket.destroy(); return; }
      ws = new Ws(socket);
      const rest = head.subarray(end + 4);
      resolve({ status, head: text, ws });
      if (rest.length) ws.feed(rest);
    });
    socket.on('close', () => { clearTimeout(timer); if (ws) ws.end(); else resolve({ status: 0, head: head.toString('latin1') }); });
    socket.on('error', () => {});
    socket.write(`GET /ws HTTP/1.1\r\nHost: ${hh}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n`
      + `Sec-WebSocket-Key: ${randomBytes(16).toString('base64')}\r\nSec-WebSocket-Version: 13\r\n`
      + (org === null ? '' : `Origin: ${org}\r\n`) + `${extra}\r\n`);
  });
}

/** A logged-in socket: the welcome (or the refusal) and the socket. */
export async function wsLogin(port, token, opts = {}) {
  const r = await wsConnect(port, opts);
  if (!r.ws) throw new Error(`upgrade refused: ${r.status}\n${r.head}`);
  r.ws.send({ t: 'login', token });
  const m = await r.ws.next((x) => x.t === 'welcome' || x.t === 'login_failed', opts.timeoutMs ?? 15000);
  return { ws: r.ws, welcome: m?.t === 'welcome' ? m : null, reply: m };
}
