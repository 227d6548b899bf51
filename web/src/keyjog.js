// Keyboard jog with a dead-man (issue 33): while an arrow key is held, X (← →) or Y (↑ ↓) jogs;
// PageUp / PageDown jog Z. The jog is the held jog of the buttons (OperatorPanel.startHold: the
// server refreshes it while the page says "held"), so it stops on key-up, when the window loses
// focus or is hidden (the panel lets go on blur / visibilitychange / pagehide), and — should the
// page go silent — when the server's hold window passes. Never while the focus is in a field
// that takes text: the editor, MDI, the offsets, a select.
const KEYS = {
  ArrowRight: ['X', 1], ArrowLeft: ['X', -1],
  ArrowUp: ['Y', 1], ArrowDown: ['Y', -1],
  PageUp: ['Z', 1], PageDown: ['Z', -1],
};

/** True when keys typed now belong to a field (or a dialog), not to the machine. */
export function typingInField(target) {
  const t = target instanceof Element ? target : document.activeElement;
  if (!t) return false;
  if (t.closest('dialog[open]')) return true;
  if (t.isContentEditable) return true;
  const tag = t.tagName;
  if (tag === 'TEXTAREA' || tag === 'SELECT') return true;
  if (tag === 'INPUT') return !['checkbox', 'radio', 'button', 'submit', 'range'].includes(t.type);
  return false;
}

export class KeyJog {
  constructor(ops) {
    this.ops = ops;
    this.key = null;   // the key whose jog runs
    this.stop = null;  // lets that jog go
    window.addEventListener('keydown', (e) => this.down(e));
    window.addEventListener('keyup', (e) => this.up(e));
    // The panel lets go of any held jog on blur and when hidden; forget the key with it.
    window.addEventListener('blur', () => this.release());
    document.addEventListener('visibilitychange', () => { if (document.hidden) this.release(); });
  }

  /** What the tests read: the key held and its axis, or null. */
  get active() { return this.key ? { key: this.key, axis: KEYS[this.key][0] } : null; }

  down(e) {
    const def = KEYS[e.key];
    if (!def || e.altKey || e.ctrlKey || e.metaKey) return;
    if (typingInField(e.target)) return;
    if (!this.ops.keysEnabled || !this.ops.canJog()) return;
    e.preventDefault(); // no scrolling while the key jogs
    if (e.repeat || this.key === e.key) return; // the key's auto-repeat: the jog already runs
    const [axis, dir] = def;
    const button = document.getElementById(`jog-${axis}-${dir > 0 ? 'plus' : 'minus'}`);
    this.key = e.key;
    const stop = this.ops.startHold(axis, dir, button);
    this.stop = stop;
    // The panel may let go by itself (not READY, another jog, blur): the key no longer jogs.
    const check = setInterval(() => {
      if (this.ops.release !== stop) {
        clearInterval(check);
        if (this.stop === stop) { this.key = null; this.stop = null; }
      }
    }, 50);
  }

  up(e) {
    if (e.key !== this.key) return;
    e.preventDefault();
    this.release();
  }

  release() {
    const stop = this.stop;
    this.key = null;
    this.stop = null;
    if (stop) stop();
  }
}
