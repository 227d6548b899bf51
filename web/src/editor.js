// A small G-code editor: a textarea over a highlighted copy of its text (comments, G/M codes,
// axis words, E/F/S/P/R words), a line-number gutter, and `check` errors marked at their lines.
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
    this.ta.addEventListener('input', () => { this.errors.clear(); this.render(); });
    this.ta.addEventListener('scroll', () => {
      this.hl.scrollTop = this.ta.scrollTop;
      this.hl.scrollLeft = this.ta.scrollLeft;
      this.gutter.scrollTop = this.ta.scrollTop;
    });
    this.render();
  }

  get text() { return this.ta.value; }
  set text(v) { this.ta.value = v; this.errors.clear(); this.render(); }
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

  render() {
    const lines = this.ta.value.split('\n');
    this.hl.innerHTML = lines.map((l, i) => {
      const errs = this.errors.get(i + 1);
      const body = highlightLine(l) || ' ';
      return errs
        ? `<span class="err-line" data-line="${i + 1}" title="${esc(errs.map((e) => `${e.col}: ${e.message}`).join('\n'))}">${body}</span>`
        : body;
    }).join('\n') + '\n';
    this.gutter.innerHTML = lines.map((_, i) => (this.errors.has(i + 1)
      ? `<span class="err-mark" data-line="${i + 1}">${i + 1}</span>` : String(i + 1))).join('\n') + '\n';
  }
}
