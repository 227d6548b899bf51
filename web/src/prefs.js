// The operator's display preferences, remembered in localStorage (this browser, every tab): the
// theme (dark for dim shops; without a choice the system's prefers-color-scheme) and the unit of
// lengths shown (mm or inch). Only the display changes: every value sent to the machine is mm.
const MM_PER_IN = 25.4;
const THEME_KEY = 'edm.theme';
const UNITS_KEY = 'edm.units';

function stored(key) {
  try { return localStorage.getItem(key); } catch { return null; }
}
function store(key, value) {
  try { localStorage.setItem(key, value); } catch { /* private mode: not remembered */ }
}

export const units = {
  mode: stored(UNITS_KEY) === 'in' ? 'in' : 'mm',
  get label() { return this.mode; },
  /** A length in mm shown in the chosen unit: `d` decimals in mm, one more in inches. */
  fmt(mm, d = 3) {
    if (typeof mm !== 'number' || !Number.isFinite(mm)) return '—';
    return this.mode === 'in' ? (mm / MM_PER_IN).toFixed(d + 1) : mm.toFixed(d);
  },
  /** What the operator typed, in the chosen unit, as mm for the machine. */
  toMm(v) { return this.mode === 'in' ? v * MM_PER_IN : v; },
  fromMm(mm) { return this.mode === 'in' ? mm / MM_PER_IN : mm; },
};

const media = window.matchMedia?.('(prefers-color-scheme: dark)');

export function currentTheme() {
  const t = stored(THEME_KEY);
  if (t === 'dark' || t === 'light') return t;
  return media?.matches ? 'dark' : 'light';
}

function applyTheme() {
  document.documentElement.dataset.theme = currentTheme();
}
applyTheme(); // before the first paint of the app

/**
 * Wires the two header toggles. onTheme: redraw what paints with theme colours (charts, toolpath);
 * onUnits: show every length again.
 */
export function setupPrefs({ themeButton, unitsButton, onTheme, onUnits }) {
  const label = () => {
    const dark = currentTheme() === 'dark';
    themeButton.textContent = dark ? 'theme: dark' : 'theme: light';
    themeButton.setAttribute('aria-pressed', String(dark));
    unitsButton.textContent = units.mode === 'in' ? 'unit: inch' : 'unit: mm';
    unitsButton.setAttribute('aria-pressed', String(units.mode === 'in'));
  };
  themeButton.onclick = () => {
    store(THEME_KEY, currentTheme() === 'dark' ? 'light' : 'dark');
    applyTheme();
    label();
    onTheme();
  };
  unitsButton.onclick = () => {
    units.mode = units.mode === 'in' ? 'mm' : 'in';
    store(UNITS_KEY, units.mode);
    label();
    onUnits();
  };
  // No choice made: follow the system when it changes (a shop PC's night mode).
  media?.addEventListener?.('change', () => {
    if (stored(THEME_KEY) === null) { applyTheme(); label(); onTheme(); }
  });
  label();
}
