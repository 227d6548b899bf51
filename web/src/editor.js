// A small G-code editor: a textarea over a highlighted copy of its text (comments, G/M codes,
// axis words, E/F/S/P/R words), a line-number gutter, `check` errors marked at their lines, and
// the line the running job is on (setCurrent).
const esc = (s) => s.replace(/[&<>]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;' }[c]));

function highlightLine(line) {
  let out = '';
  let i = 0;
  while (i < line.length) {
    const c = line[i];
    if (c === ';') { out += `<span class="g-cmt">${esc(line.slice(i))}</span>`; break; }
    if (c === '(') {
      const j = line.indexOf(')', i);
      const end = j < 0 ? line.length : j + 1;
      out += `<span class="g-cmt">${esc(line.slice(i, end))}</span>`;
      i = end;
      continue;
    }
    const m = /^([A-Za-z])\s*([-+]?[0-9]*\.?[0-9]*)/.exec(line.slice(i));
    if (m && m[0].length > 0) {
      const L = m[1].toUpperCase();
      const cls = L === 'G' || L === 'M' ? 'g-code'
        : 'XYZIJK'.includes(L) ? 'g-axis'
        : L === 'N' ? 'g-num'
        : L === 'E' ? 'g-cond' : 'g-word';
      out += `<span class="${cls}">${esc(m[0])}</span>`;
      i += m[0].length;
      continue;
    }
    out += esc(c);
    i++;
  }
  return out;
}

export class Editor {
  constructor(root) {
    root.classList.add('editor');
    this.gutter = document.createElement('pre');
    this.gutter.className = 'gutter';
    const wrap = document.createElement('div');
    wrap.className = 'code';
    this.hl = document.createElement('pre');
    this.hl.className = 'hl';
    this.ta = document.createElement('textarea');
    this.ta.spellcheck = false;
    this.ta.id = 'program';
    this.ta.setAttribute('aria-label', 'part program');
    wrap.append(this.hl, this.ta);
    root.append(this.gutter, wrap);
    this.errors = new Map();
    this.current = 0; // the running job's line (0: none)
    this.ta.addEventListener('input', () => { this.errors.clear(); this.render(); this.onEdit?.(); });
    this.ta.addEventListener('scroll', () => {
      this.hl.scrollTop = this.ta.scrollTop;
      this.hl.scrollLeft = this.ta.scrollLeft;
      this.gutter.scrollTop = this.ta.scrollTop;
    });
    this.render();
  }

  get text() { return this.ta.value; }
  set text(v) { this.ta.value = v; this.errors.clear(); this.render(); this.onEdit?.(); }
  set readOnly(v) { this.ta.readOnly = v; }

  /** errors: [{line, col, message}] */
  setErrors(errors) {
    this.errors = new Map();
    for (const e of errors) {
      if (!this.errors.has(e.line)) this.errors.set(e.line, []);
      this.errors.get(e.line).push(e);
    }
    this.render();
  }

  goto(line) {
    const lines = this.ta.value.split('\n');
    let pos = 0;
    for (let i = 0; i < line - 1 && i < lines.length; i++) pos += lines[i].length + 1;
    this.ta.focus();
    this.ta.setSelectionRange(pos, pos + (lines[line - 1] ?? '').length);
    const lh = parseFloat(getComputedStyle(this.ta).lineHeight) || 18;
    this.ta.scrollTop = Math.max(0, (line - 4) * lh);
  }

  /** Marks the running job's line (0: none) and scrolls it into view unless the operator types. */
  setCurrent(line) {
    if (line === this.current) return;
    this.current = line;
    this.render();
    if (line > 0 && document.activeElement !== this.ta) {
      const lh = parseFloat(getComputedStyle(this.ta).lineHeight) || 18;
      const top = (line - 1) * lh;
      const h = this.ta.clientHeight;
      if (top < this.ta.scrollTop || top + lh > this.ta.scrollTop + h) {
        this.ta.scrollTop = Math.max(0, top - h / 3);
      }
    }
  }

  render() {
    const lines = this.ta.value.split('\n');
    this.hl.innerHTML = lines.map((l, i) => {
      const errs = this.errors.get(i + 1);
      const body = highlightLine(l) || ' ';
      if (errs) {
        return `<span class="err-line" data-line="${i + 1}" title="${esc(errs.map((e) => `${e.col}: ${e.message}`).join('\n'))}">${body}</span>`;
      }
      return i + 1 === this.current ? `<span class="cur-line" data-line="${i + 1}">${body}</span>` : body;
    }).join('\n') + '\n';
    this.gutter.innerHTML = lines.map((_, i) => {
      if (this.errors.has(i + 1)) return `<span class="err-mark" data-line="${i + 1}">${i + 1}</span>`;
      return i + 1 === this.current ? `<span class="cur-mark" data-line="${i + 1}">${i + 1}</span>` : String(i + 1);
    }).join('\n') + '\n';
  }
}
