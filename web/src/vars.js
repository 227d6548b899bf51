// The Variables tab: var.list by prefix, a watch list read every 500 ms. What an operator may do
// follows var.list's fields: a parameter ("kind": "param") is written (var.write), never forced;
// a pin ("input"/"output") may be forced and unforced, and a forced one carries a FORCED badge
// (var.list's "forced", asked again after each force and every 2 s for the watched names).
const $ = (id) => document.getElementById(id);

export const isParam = (v) => v.kind === 'param' || v.kind === 'parameter';
export const isPin = (v) => v.kind === 'input' || v.kind === 'output';

function badge() {
  const b = document.createElement('span');
  b.className = 'forced-badge';
  b.textContent = 'FORCED';
  b.title = 'forced: the program\u2019s value is overridden until unforced (a safe state releases every force)';
  return b;
}

export class VarPanel {
  constructor(conn, confirm) {
    this.conn = conn;
    this.confirm = confirm;
    this.watched = new Map(); // name → var.list entry {name, kind, type, unit, forced}
    this.isOperator = false;
    $('btn-var-list').onclick = () => this.list();
    setInterval(() => this.poll(), 500);
    setInterval(() => this.refreshForced(), 2000);
  }

  async list() {
    const r = await this.conn.cmd('var.list', { prefix: $('var-prefix').value });
    const ul = $('var-list');
    if (!r.ok) {
      const li = document.createElement('li');
      li.textContent = `${r.code}: ${r.message}`;
      ul.replaceChildren(li);
      return;
    }
    ul.replaceChildren(...r.body.vars.slice(0, 500).map((v) => {
      const li = document.createElement('li');
      li.dataset.var = v.name;
      li.textContent = `${v.name} ${v.unit ? `[${v.unit}]` : ''} ${isParam(v) ? 'parameter' : v.kind}`;
      if (v.forced) li.append(badge());
      li.onclick = () => { this.watched.set(v.name, v); this.renderWatch(); };
      return li;
    }));
  }

  /** var.list of each watched name: its "forced" now (a force made elsewhere shows too). */
  async refreshForced() {
    if (this.watched.size === 0 || $('tab-vars').hidden) return;
    let changed = false;
    for (const name of [...this.watched.keys()].slice(0, 32)) {
      const r = await this.conn.cmd('var.list', { prefix: name });
      const v = r.ok ? (r.body.vars || []).find((x) => x.name === name) : null;
      const old = this.watched.get(name);
      if (v && old && v.forced !== old.forced) { this.watched.set(name, v); changed = true; }
    }
    if (changed) this.renderWatch();
  }

  renderWatch() {
    const t = $('watch');
    t.replaceChildren();
    for (const [name, v] of this.watched) {
      const tr = t.insertRow();
      tr.dataset.var = name;
      tr.classList.toggle('forced', !!v.forced);
      const nameCell = tr.insertCell();
      nameCell.textContent = name;
      if (v.forced) nameCell.append(badge());
      const val = tr.insertCell();
      val.className = 'val';
      val.textContent = '…';
      const act = tr.insertCell();
      if (this.isOperator && (isParam(v) || isPin(v))) this.actions(act, name, v);
      const rm = document.createElement('button');
      rm.textContent = '×';
      rm.title = 'stop watching';
      rm.onclick = () => { this.watched.delete(name); this.renderWatch(); };
      act.append(rm);
    }
  }

  actions(act, name, v) {
    const input = document.createElement('input');
    input.size = 8;
    const param = isParam(v);
    const set = document.createElement('button');
    set.textContent = param ? 'Write' : 'Force';
    set.className = param ? 'var-write' : 'var-force';
    const result = document.createElement('span');
    result.className = 'result';
    set.onclick = async () => {
      const value = Number.isNaN(Number(input.value)) || input.value.trim() === '' ? input.value : Number(input.value);
      if (!(await this.confirm(`${param ? 'Write' : 'Force'} ${name} = ${value}?`))) return;
      const r = await this.conn.cmd(param ? 'var.write' : 'var.force', { name, value });
      result.textContent = r.ok ? (param ? ' written' : ' forced') : ` ${r.code}: ${r.message}`;
      result.classList.toggle('bad', !r.ok);
      if (r.ok && !param) await this.markForced(name, true);
    };
    act.append(input, set);
    if (!param) {
      const un = document.createElement('button');
      un.textContent = 'Unforce';
      un.className = 'var-unforce';
      un.disabled = !v.forced;
      un.onclick = async () => {
        const r = await this.conn.cmd('var.unforce', { name });
        if (r.ok) await this.markForced(name, false);
      };
      act.append(un);
    }
    act.append(result);
  }

  /** After a force or unforce: var.list says whether it took; the badge follows. */
  async markForced(name, expected) {
    const r = await this.conn.cmd('var.list', { prefix: name });
    const v = r.ok ? (r.body.vars || []).find((x) => x.name === name) : null;
    const old = this.watched.get(name);
    if (old) this.watched.set(name, v || { ...old, forced: expected });
    this.renderWatch();
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
