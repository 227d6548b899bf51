// Live charts with uPlot (bundled from node_modules by Vite). Each chart keeps a fixed window of
// WINDOW rows in preallocated columns that are shifted in place, so memory stays flat however
// long the page runs; charts are redrawn at most every REDRAW_MS, not per frame. Each chart
// follows its container's width (a ResizeObserver: a rotated tablet, a column that narrows), and
// takes its axis colours from the theme (restyle()).
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
    this.series = [];
    this.latest = {}; // series key → its value in the last row (also the ones not drawn)
    // A chart is as wide as its container, whatever made the container change.
    this.observer = new ResizeObserver((entries) => {
      for (const e of entries) {
        const c = this.charts.find((x) => x.el === e.target);
        if (c) this.fit(c);
      }
    });
  }

  /** series: [{key, var}] as the server chose them for this machine. */
  setup(series) {
    this.series = series;
    this.columns = {};
    series.forEach((s, i) => { this.columns[s.key] = i + 1; });
    this.count = 0;
    this.latest = {};
    this.build(null);
  }

  /** The theme changed: the plots again with the new colours, the data kept. */
  restyle() {
    if (this.charts.length) this.build(this.charts.map((c) => c.data));
  }

  build(keep) {
    for (const c of this.charts) { this.observer.unobserve(c.el); c.plot.destroy(); }
    this.charts = [];
    const css = getComputedStyle(document.documentElement);
    const axisStroke = css.getPropertyValue('--chart-axis').trim() || '#334155';
    const gridStroke = css.getPropertyValue('--chart-grid').trim() || '#e2e8f0';
    const axis = { stroke: axisStroke, grid: { stroke: gridStroke }, ticks: { stroke: gridStroke } };
    DEFS.forEach((def, k) => {
      const el = document.getElementById(def.el);
      el.replaceChildren();
      const present = def.series.filter((s) => this.columns[s.key] !== undefined);
      const data = keep?.[k] ?? [new Float64Array(WINDOW), ...present.map(() => new Float64Array(WINDOW))];
      const opts = {
        title: def.title,
        width: this.widthOf(el),
        height: 118,
        axes: [axis, axis],
        scales: { x: { time: false } },
        legend: { live: false },
        cursor: { drag: { x: false, y: false } },
        series: [{ label: 't (s)' }, ...present.map((s) => ({
          label: s.label, stroke: s.stroke, width: 1.5, dash: s.dash, spanGaps: true }))],
      };
      const plot = new uPlot(opts, [[], ...present.map(() => [])], el);
      el.dataset.points = '0';
      const c = { def, present, data, plot, el };
      this.charts.push(c);
      this.observer.observe(el);
    });
    if (keep) this.draw();
  }

  /** The container's content width (never the plot's: it must not hold its column open). */
  widthOf(el) {
    const cs = getComputedStyle(el);
    const w = el.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight);
    return Math.max(120, Math.floor(w || 400));
  }

  fit(c) {
    const width = this.widthOf(c.el);
    if (Math.abs(c.plot.width - width) >= 1) c.plot.setSize({ width, height: 118 });
  }

  resize() { for (const c of this.charts) this.fit(c); }

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
    if (rows.length) {
      const last = rows[rows.length - 1];
      for (const [key, col] of Object.entries(this.columns)) this.latest[key] = last[col];
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
