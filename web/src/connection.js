// The page's one WebSocket to `edmhmi serve`: log-in with a token (sent in a message, never in a
// URL), commands with replies matched by id, and reconnection with back-off. The token stays in
// sessionStorage so a reload logs in again; closing the tab forgets it.
export class Connection {
  constructor(handlers) {
    this.handlers = handlers; // {welcome, frame, alarms, job, loginFailed, state, bridge}
    this.nextId = 1;
    this.pending = new Map();
    this.ws = null;
    this.retryMs = 250;
    this.token = sessionStorage.getItem('edm.token');
  }

  hasToken() { return this.token !== null; }

  login(token) {
    this.token = token;
    sessionStorage.setItem('edm.token', token);
    this.open();
  }

  logout() {
    sessionStorage.removeItem('edm.token');
    this.token = null;
    if (this.ws) this.ws.close();
  }

  open() {
    const url = new URL('ws', location.href);
    url.protocol = location.protocol === 'https:' ? 'wss:' : 'ws:';
    const ws = new WebSocket(url);
    this.ws = ws;
    this.handlers.state('connecting…');
    ws.onopen = () => {
      ws.send(JSON.stringify({ t: 'login', token: this.token ?? '' }));
    };
    ws.onmessage = (e) => this.onMessage(JSON.parse(e.data));
    ws.onclose = () => {
      for (const [, p] of this.pending) p.resolve({ ok: false, code: 'transport', message: 'connection closed' });
      this.pending.clear();
      if (this.ws !== ws) return;
      this.ws = null;
      if (this.token === null) return;
      this.handlers.state('offline — reconnecting');
      setTimeout(() => this.open(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, 5000);
    };
  }

  onMessage(m) {
    switch (m.t) {
      case 'welcome':
        this.retryMs = 250;
        this.handlers.state('online');
        this.handlers.welcome(m);
        break;
      case 'login_failed':
        this.token = null;
        sessionStorage.removeItem('edm.token');
        this.handlers.loginFailed(m.message);
        break;
      case 'reply': {
        const p = this.pending.get(m.id);
        if (p) { this.pending.delete(m.id); p.resolve(m); }
        break;
      }
      case 'bridge': this.handlers.bridge(m); break; // edmplc there or not (waiting for it)
      case 'frame': this.handlers.frame(m); break;
      case 'alarms': this.handlers.alarms(m.alarms); break;
      case 'job': this.handlers.job(m.job); break;
      default: break;
    }
  }

  /** Sends a message that wants no reply (the held jog's "held"); dropped when offline. */
  send(message) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(message));
  }

  /** Sends a command; resolves with the server's reply ({ok, body|code, message, …}). */
  cmd(op, params = {}) {
    if (!this.ws || this.ws.readyState !== WebSocket.OPEN) {
      return Promise.resolve({ ok: false, code: 'transport', message: 'not connected' });
    }
    const id = this.nextId++;
    return new Promise((resolve) => {
      this.pending.set(id, { resolve });
      this.ws.send(JSON.stringify({ t: 'cmd', id, op, ...params }));
    });
  }
}
