// Live charts with uPlot (bundled from node_modules by Vite). Each chart keeps a fixed window of
// WINDOW rows in preallocated columns that are shifted in place, so memory stays flat however
// long the page runs; charts are redrawn at most every REDRAW_MS, not per frame.
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';

const WINDOW = 1500;
const REDRAW_MS = 100;

const DEFS = [
  { el: 'chart-z', title: 'Z and depth (mm)', series: [
    { key: 'z', label: 'Z', stroke: '#2563eb' },
    { key: 'depth', label: 'hole depth', stroke: '#16a34a', dash: [6, 3] },
    { key: 'depth_est', label: 'depth (est.)', stroke: '#ea580c' }] },
  { el: 'chart-td', title: 'Td vs Tdr (µs)', series: [
    { key: 'td', label: 'Td', stroke: '#7c3aed' },
    { key: 'tdr', label: 'Tdr', stroke: '#dc2626', dash: [4, 4] }] },
  { el: 'chart-feed', title: 'Z feed (mm/s)', series: [
    { key: 'feed', label: 'feed', stroke: '#0891b2' }] },
  { el: 'chart-ratio', title: 'short / arc ratios', series: [
    { key: 'short', label: 'short', stroke: '#dc2626' },
    { key: 'arc_t', label: 'trans. arc', stroke: '#f59e0b' },
    { key: 'arc_s', label: 'stable arc', stroke: '#78350f' }] },
];

export class Charts {
  constructor() {
    this.charts = [];
    this.columns = {}; // series key → column of the server's rows (1-based after t)
    this.dirty = false;
    this.last = 0;
    this.count = 0;
  }

  /** series: [{key, var}] as the server chose them for this machine. */
  setup(series) {
    for (const c of this.charts) c.plot.destroy();
    this.charts = [];
    this.columns = {};
    series.forEach((s, i) => { this.columns[s.key] = i + 1; });
    this.count = 0;
    for (const def of DEFS) {
      const el = document.getElementById(def.el);
      el.replaceChildren();
      const present = def.series.filter((s) => this.columns[s.key] !== undefined);
      const data = [new Float64Array(WINDOW), ...present.map(() => new Float64Array(WINDOW))];
      const opts = {
        title: def.title,
        width: Math.max(200, el.clientWidth || 400),
        height: 118,
        scales: { x: { time: false } },
        legend: { live: false },
        cursor: { drag: { x: false, y: false } },
        series: [{ label: 't (s)' }, ...present.map((s) => ({
          label: s.label, stroke: s.stroke, width: 1.5, dash: s.dash, spanGaps: true }))],
      };
      const plot = new uPlot(opts, [[], ...present.map(() => [])], el);
      el.dataset.points = '0';
      this.charts.push({ def, present, data, plot, el });
    }
    this.resize();
  }

  resize() {
    for (const c of this.charts) {
      c.plot.setSize({ width: Math.max(200, c.el.clientWidth), height: 118 });
    }
  }

  /** rows: [[t, v0, v1, …], …] from one frame. */
  push(rows, redraw = false) {
    for (const row of rows) {
      const n = this.count < WINDOW ? this.count : WINDOW;
      for (const c of this.charts) {
        const cols = c.data;
        if (n === WINDOW) for (const col of cols) col.copyWithin(0, 1);
        const at = n === WINDOW ? WINDOW - 1 : n;
        cols[0][at] = row[0];
        c.present.forEach((s, i) => {
          const v = row[this.columns[s.key]];
          cols[i + 1][at] = v === null || v === undefined ? NaN : v;
        });
      }
      if (this.count < WINDOW) this.count++;
    }
    this.dirty = rows.length > 0 || this.dirty;
    const now = performance.now();
    if (this.dirty && (redraw || now - this.last >= REDRAW_MS)) {
      this.last = now;
      this.dirty = false;
      this.draw();
    }
  }

  draw() {
    for (const c of this.charts) {
      // Views over the filled part of the fixed columns: no copy, no growth.
      const d = c.data.map((col) => col.subarray(0, this.count));
      c.plot.setData(d.map((a, i) => (i === 0 ? a : Array.from(a, (v) => (Number.isNaN(v) ? null : v)))));
      c.el.dataset.points = String(this.count);
      if (this.count > 0) {
        const last = c.data.map((col) => col[this.count - 1]);
        c.el.dataset.last = JSON.stringify(Object.fromEntries(c.present.map((s, i) => [s.key, last[i + 1]])));
      }
    }
  }
}
