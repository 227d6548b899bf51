// 2-D toolpath preview: the program's path from the server (points in machine coordinates) in a
// top view (XY) and a side view (XZ), with the electrode's current position as a red dot.
export class Toolpath {
  constructor(xy, xz) {
    this.views = [{ el: xy, a: 0, b: 1, name: 'XY' }, { el: xz, a: 0, b: 2, name: 'XZ' }];
    this.points = [];
    this.pos = null;
    this.pending = false;
  }

  setPath(points) { this.points = points || []; this.request(); }
  setPosition(p) { this.pos = p; this.request(); }

  request() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.draw(); });
  }

  draw() {
    const css = getComputedStyle(document.documentElement);
    const path = css.getPropertyValue('--muted').trim() || '#94a3b8';
    for (const v of this.views) {
      const c = v.el;
      const w = c.clientWidth || 240;
      const h = c.clientHeight || 180;
      if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
      const g = c.getContext('2d');
      g.clearRect(0, 0, w, h);
      const pts = this.points.map((p) => [p[v.a], p[v.b]]);
      if (this.pos) pts.push([this.pos[v.a], this.pos[v.b]]);
      if (pts.length === 0) continue;
      let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
      for (const [x, y] of pts) { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); }
      const span = Math.max(x1 - x0, y1 - y0, 1);
      const s = Math.min((w - 20) / span, (h - 20) / span);
      const cx = (x0 + x1) / 2; const cy = (y0 + y1) / 2;
      const X = (x) => w / 2 + (x - cx) * s;
      const Y = (y) => h / 2 - (y - cy) * s;
      g.strokeStyle = path;
      g.lineWidth = 1;
      g.beginPath();
      this.points.forEach((p, i) => (i ? g.lineTo(X(p[v.a]), Y(p[v.b])) : g.moveTo(X(p[v.a]), Y(p[v.b]))));
      g.stroke();
      if (this.pos) {
        g.fillStyle = '#dc2626';
        g.beginPath();
        g.arc(X(this.pos[v.a]), Y(this.pos[v.b]), 4, 0, 2 * Math.PI);
        g.fill();
      }
      g.fillStyle = path;
      g.font = '11px sans-serif';
      g.fillText(v.name, 4, 12);
    }
  }
}
