// The side panels: alarms with acknowledge, task statistics, variable watch and force. The
// operator functions of issue 21 are in manual.js.
const $ = (id) => document.getElementById(id);
const fmt = (v, d = 3) => (typeof v === 'number' && Number.isFinite(v) ? v.toFixed(d) : '—');

export function renderAlarms(alarms, isOperator) {
  const ul = $('alarms');
  // Text nodes only: an alarm's strings come from the machine and are never parsed as HTML.
  const line = (cls, text) => {
    const d = document.createElement('div');
    d.className = cls;
    d.textContent = text;
    return d;
  };
  ul.replaceChildren(...alarms.slice(-50).reverse().map((a) => {
    const li = document.createElement('li');
    li.className = `${a.severity} ${a.acked ? 'acked' : 'new'}`;
    const when = a.wall ? new Date(a.wall).toLocaleTimeString() : '';
    const value = typeof a.value === 'number' ? ` [${fmt(a.value, 4)}]` : '';
    li.append(line('alarm-head', `${a.code} ${a.name} · ${a.source} · ${when} (t ${fmt(a.t_s, 3)} s)`),
      line('alarm-text', `${a.text}${value}`));
    if (a.cause) li.append(line('alarm-cause', `Cause: ${a.cause}`));
    if (a.remedy) li.append(line('alarm-remedy', `Remedy: ${a.remedy}`));
    return li;
  }));
  const open = alarms.filter((a) => !a.acked).length;
  $('alarm-count').hidden = open === 0;
  $('alarm-count').textContent = String(open);
  $('btn-ack').disabled = !isOperator || open === 0;
}

export function renderStats(reply) {
  const t = $('stats');
  if (!reply.ok) { t.innerHTML = `<tr><td>${reply.code}: ${reply.message}</td></tr>`; return; }
  const head = '<tr><th>task</th><th>interval µs</th><th>prio</th><th>cycles</th><th>overruns</th>'
    + '<th>omitted</th><th>exec avg/p99/max µs</th><th>latency avg/p99/max µs</th></tr>';
  const rows = (reply.body.tasks || []).map((k) => `<tr><td>${k.name}</td><td>${k.interval_us}</td>`
    + `<td>${k.priority}</td><td>${k.cycles}</td><td>${k.overruns}</td><td>${k.omitted_cycles}</td>`
    + `<td>${fmt(k.exec_us.avg, 1)} / ${fmt(k.exec_us.p99, 1)} / ${fmt(k.exec_us.max, 1)}</td>`
    + `<td>${fmt(k.latency_us.avg, 1)} / ${fmt(k.latency_us.p99, 1)} / ${fmt(k.latency_us.max, 1)}</td></tr>`);
  t.innerHTML = head + rows.join('');
  const b = reply.body.bridge || {};
  const w = reply.web || {};
  $('web-stats').textContent = `bridge: ${b.sessions_open ?? '?'} sessions, ${b.events_dropped ?? '?'} events dropped · `
    + `web: ${w.browsers ?? '?'} browsers so far, ${w.frames ?? '?'} frames, ${w.frames_dropped ?? '?'} dropped, `
    + `${w.slow_disconnects ?? '?'} slow disconnects`;
}

/** The watch list: names read every 500 ms; operators can write parameters and force pins. */
export class VarPanel {
  constructor(conn, confirm) {
    this.conn = conn;
    this.confirm = confirm;
    this.watched = new Map(); // name → {kind, forced}
    this.isOperator = false;
    $('btn-var-list').onclick = () => this.list();
    setInterval(() => this.poll(), 500);
  }

  async list() {
    const r = await this.conn.cmd('var.list', { prefix: $('var-prefix').value });
    const ul = $('var-list');
    if (!r.ok) { ul.innerHTML = `<li>${r.code}: ${r.message}</li>`; return; }
    ul.replaceChildren(...r.body.vars.slice(0, 500).map((v) => {
      const li = document.createElement('li');
      li.textContent = `${v.name} ${v.unit ? `[${v.unit}]` : ''} ${v.kind}`;
      li.onclick = () => { this.watched.set(v.name, v); this.renderWatch(); };
      return li;
    }));
  }

  renderWatch() {
    const t = $('watch');
    t.replaceChildren();
    for (const [name, v] of this.watched) {
      const tr = t.insertRow();
      tr.dataset.var = name;
      tr.insertCell().textContent = name;
      const val = tr.insertCell();
      val.className = 'val';
      val.textContent = '…';
      const act = tr.insertCell();
      if (this.isOperator) {
        const input = document.createElement('input');
        input.size = 8;
        const param = v.kind === 'parameter';
        const set = document.createElement('button');
        set.textContent = param ? 'Write' : 'Force';
        set.onclick = async () => {
          const value = Number.isNaN(Number(input.value)) ? input.value : Number(input.value);
          if (!(await this.confirm(`${param ? 'Write' : 'Force'} ${name} = ${value}?`))) return;
          const r = await this.conn.cmd(param ? 'var.write' : 'var.force', { name, value });
          if (!r.ok) alert(`${r.code}: ${r.message}`);
        };
        act.append(input, set);
        if (!param) {
          const un = document.createElement('button');
          un.textContent = 'Unforce';
          un.onclick = () => this.conn.cmd('var.unforce', { name });
          act.append(un);
        }
      }
      const rm = document.createElement('button');
      rm.textContent = '×';
      rm.onclick = () => { this.watched.delete(name); this.renderWatch(); };
      act.append(rm);
    }
  }

  async poll() {
    if (this.watched.size === 0 || $('tab-vars').hidden) return;
    const r = await this.conn.cmd('var.read', { names: [...this.watched.keys()] });
    if (!r.ok) return;
    for (const [name, value] of Object.entries(r.body.values || {})) {
      const row = document.querySelector(`#watch tr[data-var="${CSS.escape(name)}"] .val`);
      if (row) row.textContent = typeof value === 'number' ? String(+value.toPrecision(7)) : String(value);
    }
  }
}
