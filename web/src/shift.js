// The shift (docs/web.md "The shift"): the electrode in the spindle and its table (electrode.get,
// every 2 s), an electrode change and its measurement on the tool setter or the work, the job
// queue that edmhmi serve runs (its snapshot comes with the frames), and the job log (jobs.get,
// also as CSV). Text nodes only: every string here comes from the machine.
const $ = (id) => document.getElementById(id);
const fmt = (v, d = 3) => (typeof v === 'number' && Number.isFinite(v) ? v.toFixed(d) : '—');

function cells(tr, values) {
  for (const v of values) tr.insertCell().textContent = v;
  return tr;
}
function header(table, names) {
  const tr = table.insertRow();
  for (const n of names) {
    const th = document.createElement('th');
    th.textContent = n;
    tr.append(th);
  }
}

const LOG_COLUMNS = ['n', 'end', 'outcome', 'program', 'electrode', 'holes', 'depth_mm', 'wear_mm',
  'time_s', 'alarms'];

export class ShiftPanel {
  constructor(conn, confirm, editor) {
    this.conn = conn;
    this.confirm = confirm;
    this.editor = editor;
    this.electrode = null;
    this.queue = null;
    this.log = [];
    this.active = false; // logged in (main.js)
    $('btn-el-change').onclick = () => this.change();
    $('btn-el-setter').onclick = () => this.measure('setter');
    $('btn-el-work').onclick = () => this.measure('work');
    $('btn-q-add').onclick = () => this.add();
    $('btn-q-start').onclick = () => this.control('queue.start', 'Start the queue? Its programs run one after the other; the generator will fire.');
    $('btn-q-stop').onclick = () => this.control('queue.stop', 'Stop the queue? The job running is stopped.');
    $('btn-q-clear').onclick = () => this.control('queue.clear');
    $('btn-log-refresh').onclick = () => this.refreshLog();
    $('btn-log-csv').onclick = () => this.downloadCsv();
    setInterval(() => this.refreshElectrode(), 2000);
  }

  say(id, text) { $(id).textContent = text; }

  async refreshElectrode() {
    if (!this.active) return;
    const r = await this.conn.cmd('electrode.get');
    if (r.ok) this.showElectrode(r.body);
  }

  showElectrode(e) {
    this.electrode = e;
    const cur = (e.table || []).find((t) => t.id === e.current);
    $('el-current').textContent = e.known
      ? `${e.current ?? '(unnamed)'} · ${fmt(e.length_mm, 3)} mm · ${fmt(e.usable_mm, 3)} mm usable (margin ${fmt(e.margin_mm, 1)})`
      : 'length unknown: no length compensation';
    $('el-unmeasured').hidden = !cur || cur.measured !== false;
    const t = $('el-table');
    t.replaceChildren();
    if (!(e.table || []).length) return;
    header(t, ['id', 'kind', 'size', 'material', 'new', 'now', 'holes', 'wear ratio']);
    for (const x of e.table.slice(-20).reverse()) {
      const ratio = typeof x.wear_ratio === 'number' ? fmt(x.wear_ratio, 4)
        : (typeof x.wear_ratio_estimated === 'number' ? `${fmt(x.wear_ratio_estimated, 4)}~` : '—');
      const tr = cells(t.insertRow(), [x.id, x.kind, fmt(x.size_mm, 3), x.material,
        fmt(x.new_length_mm, 2), fmt(x.length_mm, 3), String(x.holes ?? 0), ratio]);
      tr.dataset.id = x.id;
      if (x.id === e.current) tr.classList.add('current');
    }
  }

  async change() {
    const id = $('el-id').value.trim();
    if (!id) { this.say('el-result', 'give the new electrode an id'); return; }
    const params = { electrode: id, kind: $('el-kind').value, material: $('el-material').value.trim() || 'copper' };
    const size = Number($('el-size').value);
    const len = Number($('el-length').value);
    if ($('el-size').value !== '') params.size_mm = size;
    if ($('el-length').value !== '') params.new_length_mm = len;
    if (!(await this.confirm(`Electrode ${id} is in the spindle now? Measure it before drilling.`))) return;
    const r = await this.conn.cmd('electrode.change', params);
    this.say('el-result', r.ok ? `${id} in the spindle: now measure it` : `${r.code}: ${r.message}`);
    if (r.ok) this.showElectrode(r.body);
  }

  async measure(reference) {
    const q = reference === 'setter' ? 'The electrode moves up and over the tool setter, then touches down on it.'
      : 'The electrode touches down on the work here; the active frame\u2019s Z is the surface.';
    if (!(await this.confirm(`Measure the electrode? ${q}`))) return;
    const r = await this.conn.cmd('electrode.measure', { reference });
    if (!r.ok) this.say('el-result', `${r.code}: ${r.message}`);
  }

  showMeasure(m) {
    if (!m || m.running === undefined) return;
    if (m.running) { this.say('el-result', `measuring on the ${m.reference}: ${m.note || ''}`); return; }
    this.say('el-result', m.ok ? `measured ${fmt(m.length_mm, 4)} mm (the estimate was ${fmt(m.was_mm, 4)} mm)`
      : `measurement failed: ${m.error}`);
    this.refreshElectrode();
  }

  async add() {
    const repeat = Math.trunc(Number($('q-repeat').value) || 1);
    const name = $('part-name').value;
    const stepX = Number($('q-step-x').value) || 0;
    const stepY = Number($('q-step-y').value) || 0;
    const r = await this.conn.cmd('queue.add', { name, text: this.editor.text, repeat, step_x: stepX, step_y: stepY });
    this.say('q-result', r.ok ? `${name} ×${repeat} queued` : `${r.code}: ${r.message}${(r.errors || []).length ? ` (${name}:${r.errors[0].line}:${r.errors[0].col}: ${r.errors[0].message})` : ''}`);
  }

  async control(op, question) {
    if (question && !(await this.confirm(question))) return;
    const r = await this.conn.cmd(op);
    if (!r.ok) this.say('q-result', `${r.code}: ${r.message}`);
  }

  showQueue(q) {
    if (!q) return;
    this.queue = q;
    this.showMeasure(q.measure);
    $('q-items').replaceChildren(...(q.items || []).map((i) => {
      const li = document.createElement('li');
      li.textContent = `${i.name} ×${i.repeat}${i.step_x || i.step_y ? `, each run ${i.step_x}, ${i.step_y} mm further` : ''}`;
      return li;
    }));
    $('q-state').textContent = q.running ? (q.waiting_change ? 'waiting for an electrode change' : 'running')
      : (q.ok === true ? 'done: every job finished' : (q.ok === false ? `ended: ${q.message}` : 'idle'));
    $('q-state').dataset.state = q.running ? (q.waiting_change ? 'wait' : 'run') : (q.ok === false ? 'fail' : 'idle');
    const notes = q.notes || [];
    $('q-change').hidden = !q.waiting_change;
    $('q-change').textContent = q.waiting_change ? notes[notes.length - 1] || 'change the electrode' : '';
    $('q-notes').replaceChildren(...notes.slice(-4).reverse().map((n) => {
      const li = document.createElement('li');
      li.textContent = n;
      return li;
    }));
    const t = $('q-jobs');
    t.replaceChildren();
    const jobs = (q.jobs || []).concat(q.current ? [{ ...q.current, outcome: 'running' }] : []);
    if (jobs.length) header(t, ['#', 'program', 'run', 'outcome', 'holes: depth / target mm', 'time s']);
    jobs.slice(-30).forEach((j, i) => {
      const holes = (j.holes || []).map((h) => `${fmt(h.depth_mm, 4)}/${fmt(h.target_mm, 3)}`).join(' ');
      const part = `${j.part}${j.from_line ? ` from ${j.from_line}` : ''}${j.before_line ? ` to ${j.before_line}` : ''}`;
      const tr = cells(t.insertRow(), [String(i + 1), part, String(j.run), j.outcome, holes, fmt(j.time_s, 1)]);
      tr.dataset.outcome = j.outcome;
    });
    const running = !!q.running;
    $('btn-q-start').disabled = running || !(q.items || []).length;
    $('btn-q-stop').disabled = !running;
    $('btn-q-clear').disabled = running;
    $('btn-q-add').disabled = running;
    if (!running && this.wasRunning) this.refreshLog();
    this.wasRunning = running;
  }

  async refreshLog() {
    const r = await this.conn.cmd('jobs.get', { limit: 200 });
    if (!r.ok) { this.say('log-result', `${r.code}: ${r.message}`); return; }
    this.log = r.body.jobs || [];
    const t = $('job-log');
    t.replaceChildren();
    header(t, LOG_COLUMNS);
    for (const j of this.log.slice().reverse()) {
      const tr = cells(t.insertRow(), [String(j.n), (j.end || '').replace('T', ' ').slice(0, 19),
        j.outcome, `${j.dry_run ? 'dry ' : ''}${j.program} (line ${j.line})`, j.electrode || '—',
        String(j.holes ?? 0), fmt(j.depth_mm, 4), fmt(j.wear_mm, 3), fmt(j.time_s, 1), j.alarms || '']);
      tr.dataset.outcome = j.outcome;
    }
    this.say('log-result', `${r.body.total} jobs logged${r.body.retained ? '' : ' (not retained: no retain file)'}`);
  }

  async downloadCsv() {
    const r = await this.conn.cmd('jobs.get', { limit: 1000, csv: true });
    if (!r.ok || typeof r.body.csv !== 'string') { this.say('log-result', `${r.code ?? 'csv'}: ${r.message ?? 'none'}`); return; }
    const a = document.createElement('a');
    a.href = URL.createObjectURL(new Blob([r.body.csv], { type: 'text/csv' }));
    a.download = 'jobs.csv';
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  }
}
