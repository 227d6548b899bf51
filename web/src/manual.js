// The operator functions of issue 21 (docs/web.md "Operator functions"): reference, jog,
// touch-off, the work-offset table, and the work-coordinate readout. Everything acts through
// `edmhmi serve`, which owns the machine's side: a held jog is refreshed by the server while this
// page keeps saying "held" — a page that sleeps, closes or loses its network stops the axis.
// The keyboard's held jog (keyjog.js) goes through the same startHold().
import { units } from './prefs.js';

const $ = (id) => document.getElementById(id);
const fmt = (v, d = 3) => (typeof v === 'number' && Number.isFinite(v) ? v.toFixed(d) : '—');
const el = (tag, props = {}, ...children) => {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
};

export const FRAMES = ['G54', 'G55', 'G56', 'G57', 'G58', 'G59'];
const AXES = ['X', 'Y', 'Z'];
const STEPS = ['cont', '0.001', '0.01', '0.1', '1', '10'];
const TOUCH = [['z', 'Z surface (−Z)'], ['x+', 'X edge, moving +X'], ['x-', 'X edge, moving −X'],
  ['y+', 'Y edge, moving +Y'], ['y-', 'Y edge, moving −Y'], ['center', 'centre of a bore']];

/** "touch z ok: Z 0.0012" — what the last manual operation did (manual.status result). */
export function describeResult(r) {
  if (!r) return '';
  let s = `${r.op}${r.target ? ` ${r.target}` : ''} ${r.ok ? 'ok' : `failed: ${r.error}`}`;
  if (r.ok) {
    const t = r.target || '';
    const parts = [];
    if (r.op !== 'touch' || t.startsWith('x') || t === 'center') parts.push(`X ${fmt(r.x, 4)}`);
    if (r.op !== 'touch' || t.startsWith('y') || t === 'center') parts.push(`Y ${fmt(r.y, 4)}`);
    if (r.op !== 'touch' || t === 'z') parts.push(`Z ${fmt(r.z, 4)}`);
    if (t === 'center' && typeof r.size === 'number') parts.push(`Ø ${fmt(r.size, 4)}`);
    s += `: ${parts.join(' ')} (machine)`;
  }
  return s;
}

/**
 * The work frame the readout subtracts: during a job, the frame of the block being run (the
 * program's frame runs, G92 included); otherwise the frame chosen in the offset table.
 * Returns {name, offset: [x, y, z]} or null when the machine has no work offsets.
 */
export function activeFrame(status, job, offsets, chosen) {
  const j = status?.job;
  if (j && j.outcome === 'running' && job && job.generation === j.generation && job.frames?.length) {
    let run = job.frames[0];
    for (const r of job.frames) if (r[0] <= j.block) run = r;
    return { name: `${FRAMES[run[1]] ?? 'G5?'} (job)`, offset: [run[2], run[3], run[4]] };
  }
  const f = offsets?.frames?.[chosen];
  if (!f) return null;
  return { name: chosen, offset: [f.x ?? 0, f.y ?? 0, f.z ?? 0] };
}

export class OperatorPanel {
  constructor(conn, confirm) {
    this.conn = conn;
    this.confirm = confirm;
    this.caps = {};
    this.step = '1';
    this.frame = 'G54'; // the readout's frame when no job runs
    this.offsets = null;
    this.manual = null;
    this.state = null;
    this.release = null; // stops the held jog, if any
    this.keysEnabled = true; // the keyboard's held jog (keyjog.js)
    this.isOperator = false;
    // A page that is hidden or loses focus lets go of a held jog at once (the server would stop
    // it anyway when "held" stops coming).
    document.addEventListener('visibilitychange', () => { if (document.hidden) this.letGo(); });
    window.addEventListener('blur', () => this.letGo());
    window.addEventListener('pagehide', () => this.letGo());
  }

  letGo() { if (this.release) this.release(); }

  /** Builds the panel for this machine; each function says why when it is not there. */
  render(caps, isOperator) {
    this.caps = caps || {};
    this.isOperator = isOperator;
    const body = $('opfun-body');
    body.replaceChildren();
    if (!isOperator) return;
    const why = (key) => this.caps.why?.[key] ?? 'not supported by this edmplc';
    const section = (key, title, build) => {
      const div = el('div', { className: 'opfun' });
      div.dataset.fn = key;
      div.append(el('b', { textContent: title }));
      if (this.caps[key]) build(div); else div.append(el('span', { className: 'na', textContent: ` ${why(key)}` }));
      body.append(div);
    };
    section('reference', 'Reference', (d) => this.buildReference(d));
    section('jog', 'Jog', (d) => this.buildJog(d));
    section('touch', 'Touch-off', (d) => this.buildTouch(d));
    section('override', 'Feed override', (d) => this.buildOverride(d));
    this.markStep();
    this.buildOffsets(isOperator);
    for (const id of ['from-row', 'mdi-row']) {
      const row = $(id);
      const key = row.dataset.fn;
      row.classList.toggle('unsupported', !this.caps[key]);
      row.title = this.caps[key] ? '' : why(key);
    }
    $('from-go').disabled = !this.caps.run_from;
    $('mdi-go').disabled = !this.caps.mdi;
    $('dry-run-label').hidden = !this.caps.dry_run;
    $('from-go').onclick = () => this.startFrom();
    $('mdi-go').onclick = () => this.mdi();
    $('mdi-line').onkeydown = (e) => { if (e.key === 'Enter') this.mdi(); };
    this.updateEnabled();
  }

  buildReference(div) {
    const row = el('div', { className: 'btns' });
    const all = el('button', { id: 'home-all', textContent: 'Home all' });
    all.onclick = () => this.home('');
    row.append(all);
    for (const a of AXES) {
      const b = el('button', { id: `home-${a}`, textContent: a });
      b.onclick = () => this.home(a);
      row.append(b);
    }
    div.append(row);
  }

  async home(axes) {
    const which = axes || (this.caps.manual?.home_order ?? 'all axes');
    if (!(await this.confirm(`Home ${axes || 'all axes'}? ${axes || 'Each axis'} moves to its reference switch.`))) return;
    const r = await this.conn.cmd('home', axes ? { axes } : {});
    this.note(r.ok ? `home ${r.body.axes ?? which}: started` : `home refused: ${r.message || r.code}`);
  }

  buildJog(div) {
    const steps = el('div', { className: 'btns steps' });
    for (const s of STEPS) {
      const b = el('button', { className: 'jog-step', textContent: s === 'cont' ? 'hold' : s });
      b.dataset.step = s;
      b.title = s === 'cont' ? 'continuous: moves while the button is held' : `one step of ${s} mm per click`;
      b.onclick = () => { this.step = s; this.markStep(); };
      steps.append(b);
    }
    const m = this.caps.manual || {};
    const vmax = typeof m.jog_v_max_mm_s === 'number' ? m.jog_v_max_mm_s : 5;
    const speed = el('select', { id: 'jog-speed', title: 'continuous jog speed' });
    for (const f of [1, 0.25, 0.05]) speed.append(el('option', { value: String(vmax * f), textContent: `${+(vmax * f).toFixed(3)} mm/s` }));
    steps.append(speed);
    const grid = el('div', { className: 'jog-grid' });
    const layout = [['', 'Y+', '', 'Z+'], ['X-', '', 'X+', ''], ['', 'Y-', '', 'Z-']];
    for (const rowDef of layout) {
      for (const cell of rowDef) {
        if (!cell) { grid.append(el('span')); continue; }
        const axis = cell[0];
        const dir = cell[1] === '+' ? 1 : -1;
        const b = el('button', { className: 'jog', textContent: cell.replace('-', '−') });
        b.id = `jog-${axis}-${dir > 0 ? 'plus' : 'minus'}`;
        b.dataset.axis = axis;
        this.wireJog(b, axis, dir);
        grid.append(b);
      }
    }
    const keys = el('label', { className: 'keys-hint', title: 'jog while a key is held: ← → X, ↑ ↓ Y, PgUp PgDn Z (not while typing in a field); released on key-up or when the page loses focus' });
    const box = el('input', { type: 'checkbox', id: 'jog-keys', checked: this.keysEnabled });
    box.onchange = () => { this.keysEnabled = box.checked; if (!box.checked) this.letGo(); };
    keys.append(box, ' keys: ← → X · ↑ ↓ Y · PgUp PgDn Z (held, at the speed above)');
    div.append(steps, grid, keys);
  }

  markStep() {
    for (const b of document.querySelectorAll('.jog-step')) b.classList.toggle('active', b.dataset.step === this.step);
  }

  /** A jog button: one step per click, or (step "hold") a continuous jog while it is held. */
  wireJog(button, axis, dir) {
    button.addEventListener('click', async () => {
      if (this.step === 'cont') return;
      const r = await this.conn.cmd('jog', { axis, distance: dir * Number(this.step) });
      if (!r.ok) this.note(`jog refused: ${r.message || r.code}`);
    });
    button.addEventListener('pointerdown', async (e) => {
      if (this.step === 'cont' && e.button === 0) await this.hold(button, e.pointerId, axis, dir);
    });
  }

  /** A pointer held on a jog button: the jog runs until the pointer lets go. */
  async hold(button, pointerId, axis, dir) {
    const stop = this.startHold(axis, dir, button);
    try { button.setPointerCapture(pointerId); } catch { /* a synthetic event */ }
    for (const ev of ['pointerup', 'pointercancel', 'lostpointercapture']) {
      button.addEventListener(ev, stop, { once: true });
    }
  }

  /**
   * Starts a continuous jog of `axis` in `dir` at the chosen speed (jog.hold, then "held" every
   * held_ms while it lasts) and returns the function that lets go (jog.release). One jog at a
   * time: a new one lets the last go first. blur, hidden and pagehide let go too (constructor).
   */
  startHold(axis, dir, button = null) {
    this.letGo();
    let timer = null;
    let held = true;
    const stop = () => {
      if (!held) return;
      held = false;
      if (timer) clearInterval(timer);
      button?.classList.remove('held');
      if (this.release === stop) this.release = null;
      this.conn.cmd('jog.release');
    };
    this.release = stop;
    button?.classList.add('held');
    const velocity = dir * Number($('jog-speed')?.value ?? 1);
    this.conn.cmd('jog.hold', { axis, velocity }).then((r) => {
      if (!r.ok) {
        this.note(`jog refused: ${r.message || r.code}`);
        stop();
        return;
      }
      if (!held) return; // let go before the server answered: it has stopped the jog
      timer = setInterval(() => this.conn.send({ t: 'held' }), Math.max(20, r.body.held_ms || 100));
    });
    return stop;
  }

  /** Whether a continuous jog may start now (an operator, the function there, READY). */
  canJog() {
    return !!this.caps.jog && this.isOperator && this.state === 'READY'
      && !(this.manual?.busy && this.manual?.mode !== 'jog');
  }

  buildTouch(div) {
    const target = el('select', { id: 'touch-target' });
    for (const [v, label] of TOUCH) target.append(el('option', { value: v, textContent: `${v} — ${label}` }));
    const set = el('select', { id: 'touch-set', title: 'put the result into this work frame' });
    set.append(el('option', { value: '', textContent: 'no offset' }));
    for (const f of FRAMES) set.append(el('option', { value: f, textContent: `set ${f}` }));
    const go = el('button', { id: 'touch-go', textContent: 'Touch' });
    go.onclick = () => this.touch(target.value, set.value);
    div.append(el('div', { className: 'btns' }, target, set, go), el('div', { id: 'touch-set-result', className: 'result' }));
  }

  async touch(target, frame) {
    const into = frame ? ` and set ${frame} from the result` : '';
    if (!(await this.confirm(`Touch ${target}${into}? The electrode moves toward the work in touch mode until it meets it.`))) return;
    const r = await this.conn.cmd('touch', frame ? { target, set: frame } : { target });
    this.note(r.ok ? `touch ${target}: started` : `touch refused: ${r.message || r.code}`);
  }

  buildOverride(div) {
    const input = el('input', { id: 'override-pct', type: 'number', min: '0', max: '150', step: '5', value: '100' });
    const set = el('button', { id: 'override-set', textContent: 'Set %' });
    const out = el('span', { id: 'override-result' });
    const back = el('span', { id: 'override-readback', className: 'readback', title: 'the feed override the machine runs with (its variable)' });
    set.onclick = async () => {
      const r = await this.conn.cmd('feed.override', { percent: Number(input.value) });
      out.textContent = r.ok ? ` ${r.body.percent} %` : ` refused: ${r.message || r.code}`;
    };
    div.append(el('span', { className: 'btns' }, input, set, out, back));
  }

  /** The override as the machine has it (a ratio, 0 … 1.5), from the status stream. */
  showOverride(ratio) {
    const text = typeof ratio === 'number' && Number.isFinite(ratio) ? `${Math.round(ratio * 100)} %` : '—';
    const b = $('override-readback');
    if (b) { b.textContent = ` machine: ${text}`; b.dataset.percent = text === '—' ? '' : String(Math.round(ratio * 100)); }
    return text;
  }

  buildOffsets(isOperator) {
    const panel = $('offsets-panel');
    const t = $('offsets');
    t.replaceChildren();
    if (!this.caps.offsets) {
      t.append(el('caption', { className: 'na', textContent: this.caps.why?.offsets ?? 'not supported by this edmplc' }));
      return;
    }
    const head = t.insertRow();
    for (const h of ['', '', 'X', 'Y', 'Z', '']) head.append(el('th', { textContent: h }));
    for (const f of FRAMES) {
      const tr = t.insertRow();
      tr.dataset.frame = f;
      const radio = el('input', { type: 'radio', name: 'readout-frame', value: f, checked: f === this.frame, title: 'work coordinates of the readout in this frame' });
      radio.onchange = () => { this.frame = f; this.onFrame?.(); };
      tr.insertCell().append(radio);
      tr.insertCell().textContent = f;
      const inputs = AXES.map((a) => {
        const i = el('input', { type: 'number', step: 'any', className: 'off' });
        i.dataset.axis = a.toLowerCase();
        i.id = `off-${f}-${a}`;
        tr.insertCell().append(i);
        return i;
      });
      const set = el('button', { className: 'small', id: `off-set-${f}`, textContent: 'Set', disabled: !isOperator });
      set.onclick = () => this.setOffset(f, inputs);
      tr.insertCell().append(set);
    }
    this.showOffsets(this.offsets);
    panel.hidden = false;
  }

  async setOffset(frame, inputs) {
    const params = { frame };
    for (const i of inputs) {
      const cur = this.offsets?.frames?.[frame]?.[i.dataset.axis] ?? 0;
      const v = Number(i.value);
      // Unchanged: the text shown for the current value (inches are converted back to mm).
      if (i.value !== '' && Number.isFinite(v) && i.value !== units.fmt(cur, 4)) {
        params[i.dataset.axis] = Math.round(units.toMm(v) * 1e6) / 1e6;
      }
    }
    if (Object.keys(params).length === 1) { $('offsets-result').textContent = `${frame}: nothing changed`; return; }
    const r = await this.conn.cmd('offset.set', params);
    $('offsets-result').textContent = r.ok
      ? `${frame} set: X ${units.fmt(r.body.x, 4)} Y ${units.fmt(r.body.y, 4)} Z ${units.fmt(r.body.z, 4)} ${units.mode} (generation ${r.body.generation})`
      : `${frame} refused: ${r.message || r.code}`;
  }

  /** offset.get's frames, from the welcome or a frame; an input being edited keeps its text. */
  showOffsets(o) {
    if (o) this.offsets = o;
    if (!this.offsets) return;
    for (const f of FRAMES) {
      const v = this.offsets.frames?.[f] || {};
      for (const a of AXES) {
        const i = $(`off-${f}-${a}`);
        if (i && document.activeElement !== i) i.value = units.fmt(v[a.toLowerCase()] ?? 0, 4);
      }
    }
    $('offsets-unit').textContent = units.mode;
    const t = $('offsets');
    if (t) t.dataset.generation = String(this.offsets.generation ?? '');
  }

  /** manual.status as the server follows it: mode, referenced axes, the last result. */
  showManual(m) {
    if (!m) return;
    this.manual = m;
    const ref = m.referenced || {};
    for (const a of AXES) {
      const c = $(`ref-${a}`);
      if (!c) continue;
      const known = typeof ref[a] === 'boolean';
      c.textContent = known ? (ref[a] ? 'ref' : 'not ref') : '';
      c.className = `ref ${known ? (ref[a] ? 'yes' : 'no') : ''}`;
      c.title = known ? (ref[a] ? 'referenced (homed)' : 'not referenced: home this axis') : '';
    }
    const jog = m.jog || {};
    let s = m.error ? `manual.status: ${m.error}` : `mode ${m.mode ?? '?'}${m.busy ? ' · busy' : ''}`;
    if (jog.held) s += ` · jogging ${jog.axis} at ${fmt(jog.velocity, 3)} mm/s`;
    if (m.may_run_programs === false) s += ' · programs refused until every axis is referenced';
    $('manual-status').textContent = s;
    const res = $('manual-result');
    res.textContent = [describeResult(m.result), jog.error].filter(Boolean).join(' · ');
    res.dataset.seq = String(m.result?.seq ?? '');
    res.className = `result ${m.result && !m.result.ok ? 'bad' : ''}`;
    const ts = $('touch-set-result');
    if (ts) {
      const t = m.touch_set;
      ts.textContent = !t ? '' : t.pending ? `touch ${t.target}: ${t.frame} waits for the result…` : t.message;
      ts.className = `result ${t && t.ok === false ? 'bad' : ''}`;
    }
    this.updateEnabled();
  }

  setState(state) { this.state = state; this.updateEnabled(); }

  /** Manual motion needs READY and no manual operation running (a jog may replace a jog). */
  updateEnabled() {
    const ready = this.state === 'READY';
    const busy = !!this.manual?.busy && this.manual?.mode !== 'jog';
    for (const b of document.querySelectorAll('#opfun [data-fn="reference"] button, #touch-go')) b.disabled = !ready || busy;
    for (const b of document.querySelectorAll('#opfun button.jog')) b.disabled = !ready || busy;
    if (!ready) this.letGo();
  }

  async startFrom() {
    $('from-result').textContent = '';
    const line = Number($('from-line').value);
    if (!Number.isInteger(line) || line < 1) { $('from-result').textContent = 'give a line number'; return; }
    const depthText = $('from-depth').value.trim();
    const dry = $('dry-run').checked;
    if (!(await this.confirm(`Start the loaded program from line ${line}${dry ? ' as a dry run' : ''}? The electrode rapids up to the clearance, over and down to that block, then the program runs on.`))) return;
    const params = { line, dry_run: dry };
    if (depthText !== '') params.depth_done = Number(depthText);
    $('from-result').textContent = 'interpreting…';
    const r = await this.conn.cmd('start_from', params);
    $('from-result').textContent = r.ok
      ? `started at line ${r.line} (block ${r.first_block}, ${r.prologue} re-approach blocks, depth done ${fmt(r.depth_done_mm, 3)} mm: ${r.depth_from})`
      : `refused: ${r.message || r.code}${(r.errors || []).map((e) => ` · line ${e.line}: ${e.message}`).join('')}`;
  }

  async mdi() {
    $('mdi-result').textContent = '';
    const line = $('mdi-line').value.trim();
    if (!line) return;
    if (!(await this.confirm(`Run the MDI line "${line}"? The axes may move.`))) return;
    $('mdi-result').textContent = 'interpreting…';
    const r = await this.conn.cmd('mdi', { line });
    $('mdi-result').textContent = r.ok ? `started (${r.blocks} blocks)` : `refused: ${r.message || r.code}`;
  }

  note(text) { $('manual-result').textContent = text; }
}
