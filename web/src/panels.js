// The side panels: alarms with acknowledge, task statistics, the conditions (E) table. The
// variable watch is in vars.js, the operator functions of issue 21 in manual.js.
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
  $('alarms-none').hidden = alarms.length > 0;
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

/** machine.info's conditions (the E table the programs select). Read-only unless the machine
 *  config lets operators edit some fields (machine.condition_edit, docs/config.md): an operator
 *  then edits those cells, each change sent as condition.set and checked by edmplc against the
 *  config's ranges; the table shown is the one edmplc gives back. */
const CONDITION_COLUMNS = [
  ['E', 'E', 0], ['name', 'name', null], ['polarity', 'polarity', null],
  ['open_voltage_v', 'U₀ V', 1], ['peak_current_a', 'Î A', 1], ['on_time_us', 'on µs', 1],
  ['off_time_us', 'off µs', 1], ['tdr_us', 'Tdr µs', 1], ['servo_ref_v', 'servo V', 1],
  ['wear_ratio', 'wear', 4], ['area_ratio', 'A ratio', 4],
];
export function renderConditions(conditions, { edit = [], operator = false, conn = null } = {}) {
  const t = $('conditions');
  t.replaceChildren();
  const list = Array.isArray(conditions) ? conditions : [];
  const editable = operator && conn ? new Set(Array.isArray(edit) ? edit : []) : new Set();
  $('conditions-note').textContent = !list.length ? 'this edmplc sends none'
    : (editable.size ? `editable: ${[...editable].join(', ')} (machine.condition_edit)`
      : 'read-only: set in the machine config');
  if (!list.length) return;
  const head = t.insertRow();
  for (const [, label] of CONDITION_COLUMNS) {
    const th = document.createElement('th');
    th.textContent = label;
    head.append(th);
  }
  for (const c of list) {
    const tr = t.insertRow();
    tr.dataset.e = String(c.E);
    for (const [key, , d] of CONDITION_COLUMNS) {
      const v = c[key];
      const cell = tr.insertCell();
      if (editable.has(key) && typeof v === 'number') {
        const input = document.createElement('input');
        input.type = 'number';
        input.step = 'any';
        input.value = String(v);
        input.className = 'cond-edit';
        input.dataset.field = key;
        input.setAttribute('aria-label', `E${c.E} ${key}`);
        input.onchange = async () => {
          const r = await conn.cmd('condition.set', { E: c.E, field: key, value: Number(input.value) });
          if (r.ok) {
            const said = `E${c.E} ${key} set to ${input.value}${r.body.retained ? '' : ' (not retained)'}`;
            renderConditions(r.body.conditions, { edit, operator, conn });
            $('conditions-note').textContent = said;
          } else {
            $('conditions-note').textContent = `${r.code}: ${r.message}`;
            input.value = String(v);
          }
        };
        cell.append(input);
      } else {
        cell.textContent = d === null ? String(v ?? '') : (typeof v === 'number' ? (d ? fmt(v, d) : String(v)) : '—');
      }
    }
  }
}
