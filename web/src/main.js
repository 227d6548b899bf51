// The operator's screen (docs/web.md). State lives in edmhmi serve and edmplc; this page only
// shows it and sends commands, so a reload, a sleeping tablet or a second browser changes nothing.
import './style.css';
import { Connection } from './connection.js';
import { Charts } from './charts.js';
import { Editor } from './editor.js';
import { Toolpath } from './toolpath.js';
import { renderAlarms, renderStats, renderConditions } from './panels.js';
import { VarPanel } from './vars.js';
import { OperatorPanel, activeFrame } from './manual.js';
import { KeyJog } from './keyjog.js';
import { JobPanel } from './job.js';
import { setupPrefs, units } from './prefs.js';
import { ShiftPanel } from './shift.js';

const $ = (id) => document.getElementById(id);
const STALE_MS = 1000;
const t0 = performance.now();

const ui = {
  role: null,
  alarms: [],
  lastStatusAt: 0,
  status: null,
  job: null,
  firstRender: null,
};
window.edm = ui; // read by the end-to-end tests (first render time, state, manual, offsets)

const charts = new Charts();
const editor = new Editor($('editor'));
const toolpath = new Toolpath($('tp-xy'), $('tp-xz'));
const jobPanel = new JobPanel(editor, toolpath);

function confirmDialog(text) {
  const d = $('confirm');
  $('confirm-text').textContent = text;
  d.showModal();
  return new Promise((resolve) => {
    d.onclose = () => resolve(d.returnValue === 'ok');
  });
}

const conn = new Connection({
  state: (s) => { $('conn').textContent = s; },
  // "waiting for edmplc at H:P": before a log-in the log-in screen says why nothing comes.
  bridge: (m) => {
    $('conn').textContent = m.up ? 'online' : m.message;
    if (ui.role === null && !m.up) {
      $('login').hidden = false;
      $('login-error').textContent = m.message;
    }
  },
  loginFailed: (message) => {
    $('app').hidden = true;
    $('login').hidden = false;
    $('login-error').textContent = `log-in refused: ${message}`;
  },
  welcome: (m) => {
    ui.role = m.role;
    document.body.dataset.role = m.role;
    $('login').hidden = true;
    $('app').hidden = false;
    $('role').textContent = m.role;
    $('machine-name').textContent = m.machine?.name ?? '?';
    editor.readOnly = m.role !== 'operator';
    charts.setup(m.series || []);
    if (m.history) charts.push(m.history, true);
    renderConditions(m.machine?.conditions,
      { edit: m.machine?.condition_edit, operator: m.role === 'operator', conn });
    ui.caps = m.caps || {};
    ops.render(ui.caps, m.role === 'operator');
    ui.offsets = m.offsets; ui.manual = m.manual;
    ops.showOffsets(m.offsets);
    ops.showManual(m.manual);
    ui.alarms = m.alarms || [];
    renderAlarms(ui.alarms, m.role === 'operator');
    vars.isOperator = m.role === 'operator';
    vars.renderWatch();
    showJob(m.job, true);
    shift.active = true;
    shift.showQueue(m.queue);
    shift.refreshElectrode();
    if (m.status && Object.keys(m.status).length) showStatus(m.status, false);
    refreshStats();
    if (ui.firstRender === null) {
      requestAnimationFrame(() => { ui.firstRender = performance.now() - t0; });
    }
  },
  frame: (f) => {
    if (f.offsets) { ui.offsets = f.offsets; ops.showOffsets(f.offsets); }
    if (f.manual) { ui.manual = f.manual; ops.showManual(f.manual); }
    if (f.status) showStatus(f.status, true);
    else if (f.offsets) showPosition(ui.status);
    if (f.rows) { charts.push(f.rows); showOverride(); }
    if (f.alarms) {
      ui.alarms = ui.alarms.concat(f.alarms).slice(-200);
      renderAlarms(ui.alarms, ui.role === 'operator');
      // An alarm that came with the end of the job belongs to its report: fetch it again.
      if (ui.job && ui.job.report) conn.cmd('job').then((r) => { if (r.ok) showJob(r.body, false); });
    }
    if (f.queue) shift.showQueue(f.queue);
    if (f.bridge === false) $('conn').textContent = 'edmhmi online, edmplc unreachable';
  },
  alarms: (a) => { ui.alarms = a; renderAlarms(a, ui.role === 'operator'); },
  job: (j) => showJob(j, false),
});
const vars = new VarPanel(conn, confirmDialog);
const ops = new OperatorPanel(conn, confirmDialog);
const shift = new ShiftPanel(conn, confirmDialog, editor);
ui.shift = shift;
ops.onFrame = () => showPosition(ui.status);
ui.keyJog = new KeyJog(ops);
setupPrefs({
  themeButton: $('btn-theme'),
  unitsButton: $('btn-units'),
  onTheme: () => { charts.restyle(); toolpath.request(); },
  onUnits: () => { ops.showOffsets(); if (ui.status) showStatus(ui.status, false); },
});

/** The feed override as the machine runs it (the series "override": the drill's input). */
function showOverride() {
  const t = ops.showOverride(charts.latest.override);
  $('job-override').textContent = t;
}

function statusVar(s, suffix) {
  const v = s.vars || {};
  for (const k of Object.keys(v)) if (k === suffix || k.endsWith(`.${suffix}`)) return v[k];
  return undefined;
}
const fmt = (v, d = 3) => (typeof v === 'number' && Number.isFinite(v) ? v.toFixed(d) : '—');

function showStatus(s, fresh) {
  ui.status = s;
  if (fresh) ui.lastStatusAt = performance.now();
  $('state').textContent = s.state;
  $('state').dataset.state = s.state;
  ops.setState(s.state);
  const [x, y, z] = showPosition(s);
  $('val-depth').textContent = `${units.fmt(statusVar(s, 'io.depth_mm'))} ${units.mode}`;
  $('val-electrode').textContent = `${units.fmt(statusVar(s, 'io.electrode_mm'), 2)} ${units.mode}`;
  const job = s.job || {};
  $('job-outcome').textContent = job.outcome ?? '—';
  $('job-block').textContent = job.blocks ? `${Math.min(job.block + 1, job.blocks)} / ${job.blocks}` : '—';
  $('job-line').textContent = job.line || '—';
  const t = statusVar(s, 'job_time_s');
  $('job-time').textContent = typeof t === 'number' ? `${t.toFixed(1)} s` : '—';
  $('job-progress').value = job.blocks ? (job.outcome === 'finished' ? 1 : job.block / job.blocks) : 0;
  jobPanel.update(s, ui.job, charts.latest);
  if (x !== undefined) toolpath.setPosition([x ?? 0, y ?? 0, z ?? 0]);
  updateButtons();
  if (job.outcome === 'finished' || job.outcome === 'aborted') {
    // Only the loaded program's end (an MDI line runs under a generation of its own).
    if (ui.job && ui.job.started && !ui.job.report && !ui.reportAsked && job.generation === ui.job.generation) {
      ui.reportAsked = true;
      conn.cmd('job').then((r) => { ui.reportAsked = false; if (r.ok) showJob(r.body, false); });
    }
  }
}

/** Machine coordinates from the status, work = machine − the active frame's offset. */
function showPosition(s) {
  if (!s) return [];
  const m = [statusVar(s, 'io.x_mm'), statusVar(s, 'io.y_mm'), statusVar(s, 'io.z_mm')];
  const f = ui.caps?.work_coordinates ? activeFrame(s, ui.job, ops.offsets, ops.frame) : null;
  ['x', 'y', 'z'].forEach((a, i) => {
    $(`dro-${a}`).textContent = units.fmt(m[i]);
    $(`dro-${a}`).dataset.mm = typeof m[i] === 'number' ? String(m[i]) : '';
    const w = $(`wrk-${a}`);
    w.textContent = f && typeof m[i] === 'number' ? units.fmt(m[i] - f.offset[i]) : '—';
    w.classList.toggle('na', !f);
  });
  $('wrk-head').textContent = f ? `work ${f.name}` : 'work';
  $('coord-note').textContent = ui.caps?.work_coordinates ? '' : 'work coordinates: not supported by this edmplc';
  $('units-note').textContent = units.mode === 'in' ? 'inch' : 'mm';
  return m;
}

function showJob(j, initial) {
  ui.job = j;
  if (!j) return;
  jobPanel.pathShown = true;
  toolpath.setPath(j.toolpath || []);
  if (initial && j.text && !editor.text) { editor.text = j.text; $('part-name').value = j.part; }
  $('job-report').hidden = !j.report;
  // A dry run says so above its report (the report's own rows say it too).
  $('job-report').textContent = j.report
    ? `${j.dry_run ? 'DRY RUN: the motion only, the generator off; nothing was drilled.\n' : ''}${j.report.text}` : '';
  jobPanel.update(ui.status, j, charts.latest);
  updateButtons();
}

function updateButtons() {
  const st = ui.status?.state;
  const loaded = ui.job && ui.job.blocks > 0;
  // The machine's loaded program is not the page's (edmhmi run loaded another): upload first.
  const elsewhere = jobPanel.owner === 'elsewhere';
  $('btn-start').disabled = !(st === 'READY' && loaded) || elsewhere;
  $('btn-start').title = elsewhere ? 'the machine holds a program loaded elsewhere: upload this one first' : '';
  $('btn-hold').disabled = st !== 'RUNNING';
  $('btn-resume').disabled = st !== 'HOLD';
  $('btn-stop').disabled = !(st === 'RUNNING' || st === 'HOLD');
  $('btn-reset').disabled = !(st === 'ESTOP' || st === 'FAULT');
  $('btn-upload').disabled = st === 'RUNNING' || st === 'HOLD';
}

// Stale: no status from the machine for more than a second (server gone, edmplc gone, network).
setInterval(() => {
  const stale = ui.role !== null && performance.now() - ui.lastStatusAt > STALE_MS;
  $('stale').hidden = !stale;
  document.body.classList.toggle('is-stale', stale);
}, 200);

async function machine(op, question, params = {}) {
  if (question && !(await confirmDialog(question))) return;
  const r = await conn.cmd(op, params);
  if (!r.ok) flash(`${op}: ${r.code}: ${r.message}`);
}
function flash(text) { $('check-result').textContent = text; }

$('btn-start').onclick = () => {
  const dry = ui.caps?.dry_run && $('dry-run').checked;
  const what = dry ? 'The axes will move; the generator stays off (dry run: drilling and orbit blocks are skipped).' : 'The axes will move and the generator will fire.';
  machine('start', `Start ${ui.job?.part ?? 'the program'}${dry ? ' as a dry run' : ''} on ${$('machine-name').textContent}? ${what}`, dry ? { dry_run: true } : {});
};
$('btn-hold').onclick = () => machine('cycle.hold');
$('btn-resume').onclick = () => machine('cycle.resume', 'Resume the job?');
$('btn-stop').onclick = () => machine('cycle.stop', 'Stop the job? It cannot be resumed from here.');
$('btn-reset').onclick = () => machine('reset', 'Reset the machine out of its safe state? Make sure the cause is cleared.');
$('btn-estop').onclick = () => machine('estop'); // never behind a confirmation
$('btn-ack').onclick = async () => {
  const seq = ui.alarms.reduce((m, a) => Math.max(m, a.seq || 0), 0);
  await conn.cmd('ack', { seq });
};

function showCheck(r) {
  const errs = r.errors || [];
  editor.setErrors(errs);
  $('check-errors').replaceChildren(...errs.map((e) => {
    const li = document.createElement('li');
    li.textContent = `${$('part-name').value}:${e.line}:${e.col}: ${e.message}`;
    li.dataset.line = e.line;
    li.onclick = () => editor.goto(e.line);
    return li;
  }));
}
$('btn-check').onclick = async () => {
  const r = await conn.cmd('check', { name: $('part-name').value, text: editor.text });
  showCheck(r);
  flash(r.ok ? `ok: ${r.blocks} blocks, ${r.drill_blocks} drilling, ${fmt(r.drill_depth_mm)} mm` : (r.message || `${(r.errors || []).length} error(s)`));
};
$('btn-upload').onclick = async () => {
  const r = await conn.cmd('upload', { name: $('part-name').value, text: editor.text });
  showCheck(r);
  flash(r.ok ? `uploaded: ${r.blocks} blocks (program ${r.generation})` : r.message);
};
$('file').onchange = async (e) => {
  const f = e.target.files[0];
  if (!f) return;
  if (f.size > 2 * 1024 * 1024) { flash('file larger than 2 MiB'); return; }
  editor.text = await f.text();
  $('part-name').value = f.name;
};

async function refreshStats() {
  if ($('tab-stats').hidden || ui.role === null) return;
  renderStats(await conn.cmd('stats'));
}
setInterval(refreshStats, 2000);
for (const b of document.querySelectorAll('.tabs button')) {
  b.onclick = () => {
    for (const o of document.querySelectorAll('.tabs button')) o.classList.toggle('active', o === b);
    $('tab-stats').hidden = b.dataset.tab !== 'stats';
    $('tab-vars').hidden = b.dataset.tab !== 'vars';
    $('tab-log').hidden = b.dataset.tab !== 'log';
    if (b.dataset.tab === 'log') shift.refreshLog();
    refreshStats();
  };
}

// The charts follow their containers by themselves (ResizeObserver); the canvases here.
window.addEventListener('resize', () => toolpath.request());
$('login-form').onsubmit = (e) => {
  e.preventDefault();
  $('login-error').textContent = '';
  conn.login($('token').value.trim());
};

if (conn.hasToken()) conn.open(); else $('login').hidden = false;
