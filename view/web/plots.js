// Time series beside the scene (view/README.md, "Time series"): a few canvas panels over the
// trace's whole time, a cursor line at the timeline's tick, a click on a panel seeks there.
// Each panel's curves are drawn once per size into the canvas (min and max per pixel column,
// so a 100 s trace's 50 000 rows cost one pass); the cursor is a separate canvas on top.
import { valueAt } from './series.js';
import { STATE_COLOURS } from './draw.js';

const HEIGHT = 120;    // px: one panel's plot area
const MARGIN = 44;     // px: left, for the y labels

function number(x) {
  if (x === 0) return '0';
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e4) ? x.toExponential(2) : x.toFixed(a < 0.1 ? 4 : 3);
}

// One panel. `panel`: { title, kind: 'lines' | 'bands', lines: [{ label, colour, dash, series,
// ghost }] } (bands: one row per line, coloured by its value 0, 1, 2 with STATE_COLOURS).
class Panel {
  constructor(parent, panel, range, onSeek) {
    this.panel = panel;
    this.range = range;
    this.root = document.createElement('div');
    this.root.className = 'panel';
    this.head = document.createElement('div');
    this.head.className = 'panel-head';
    this.box = document.createElement('div');
    this.box.className = 'panel-box';
    this.curves = document.createElement('canvas');
    this.cursor = document.createElement('canvas');
    this.box.append(this.curves, this.cursor);
    this.root.append(this.head, this.box);
    parent.appendChild(this.root);
    this.cursor.addEventListener('click', (e) => {
      const r = this.cursor.getBoundingClientRect();
      onSeek(this.tickAt(e.clientX - r.left));
    });
    const shown = panel.lines.filter((l) => !l.ghost);
    if (panel.kind === 'bands') this.lo = 0, this.hi = shown.length;
    else {
      let lo = 0, hi = 0;
      for (const l of panel.lines) for (const v of l.series.values) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
      const pad = 0.05 * (hi - lo || 1);
      this.lo = lo - (lo < 0 ? pad : 0); this.hi = hi + pad;
    }
  }

  // Servo tick at x px from the panel's left (the time axis spans the plot area right of MARGIN).
  tickAt(x) {
    const [a, b] = this.range;
    return Math.round(a + Math.max(0, Math.min(1, (x - MARGIN) / (this.width - MARGIN))) * (b - a));
  }
  xOf(tick) {
    const [a, b] = this.range;
    return MARGIN + (b > a ? (tick - a) / (b - a) : 0) * (this.width - MARGIN);
  }
  yOf(v) { return HEIGHT - 4 - (v - this.lo) / (this.hi - this.lo || 1) * (HEIGHT - 8); }

  layout(width) {
    this.width = width;
    const dpr = window.devicePixelRatio || 1;
    for (const c of [this.curves, this.cursor]) {
      c.width = Math.round(width * dpr); c.height = Math.round(HEIGHT * dpr);
      c.style.width = `${width}px`; c.style.height = `${HEIGHT}px`;
      c.getContext('2d').setTransform(dpr, 0, 0, dpr, 0, 0);
    }
    this.drawCurves();
  }

  drawCurves() {
    const g = this.curves.getContext('2d');
    g.clearRect(0, 0, this.width, HEIGHT);
    g.fillStyle = '#fff';
    g.fillRect(MARGIN, 0, this.width - MARGIN, HEIGHT);
    g.font = '10px system-ui, sans-serif';
    g.fillStyle = '#555';
    if (this.panel.kind === 'bands') {
      const rows = this.panel.lines.filter((l) => !l.ghost), h = (HEIGHT - 8) / rows.length;
      rows.forEach((l, r) => {
        const y = 4 + r * h;
        g.fillStyle = '#555';
        g.fillText(l.label, 2, y + h / 2 + 3);
        const { ticks, values } = l.series;
        for (let k = 0; k < ticks.length; k++) {
          const x0 = this.xOf(ticks[k]), x1 = k + 1 < ticks.length ? this.xOf(ticks[k + 1]) : this.width;
          if (x1 - x0 < 0.01 && k > 0 && values[k] === values[k - 1]) continue;
          g.fillStyle = STATE_COLOURS[values[k]] ?? '#000';
          g.fillRect(x0, y + 1, Math.max(x1 - x0, 0.5), h - 2);
        }
      });
      return;
    }
    // y axis: 0 and the top value.
    g.strokeStyle = '#ddd';
    for (const v of [this.lo, 0, this.hi]) {
      g.beginPath(); g.moveTo(MARGIN, this.yOf(v)); g.lineTo(this.width, this.yOf(v)); g.stroke();
      g.fillText(number(v), 2, this.yOf(v) + 3);
    }
    for (const l of this.panel.lines) {
      g.strokeStyle = l.colour;
      g.globalAlpha = l.ghost ? 0.35 : 1;
      g.setLineDash(l.dash ?? []);
      g.lineWidth = 1.3;
      g.beginPath();
      // Per pixel column: the first, lowest, highest and last value of the rows it holds.
      const { ticks, values } = l.series;
      let col = -1, first = 0, lo = 0, hi = 0, last = 0, started = false;
      const flush = () => {
        if (col < 0) return;
        for (const v of [first, lo, hi, last]) {
          const y = this.yOf(v);
          if (started) g.lineTo(col, y); else { g.moveTo(col, y); started = true; }
        }
      };
      for (let k = 0; k < ticks.length; k++) {
        const x = Math.round(this.xOf(ticks[k])), v = values[k];
        if (x !== col) { flush(); col = x; first = lo = hi = last = v; }
        else { lo = Math.min(lo, v); hi = Math.max(hi, v); last = v; }
      }
      flush();
      g.stroke();
    }
    g.globalAlpha = 1;
    g.setLineDash([]);
  }

  // The cursor line (and the divergence marker) and the values at the cursor in the head.
  drawCursor(tick, marker) {
    const g = this.cursor.getContext('2d');
    g.clearRect(0, 0, this.width, HEIGHT);
    if (marker !== null) {
      g.strokeStyle = '#c0392b'; g.setLineDash([3, 3]);
      g.beginPath(); g.moveTo(this.xOf(marker), 0); g.lineTo(this.xOf(marker), HEIGHT); g.stroke();
      g.setLineDash([]);
    }
    g.strokeStyle = '#111';
    g.beginPath(); g.moveTo(this.xOf(tick), 0); g.lineTo(this.xOf(tick), HEIGHT); g.stroke();
    const parts = this.panel.lines.filter((l) => !l.ghost).map((l) => {
      const v = valueAt(l.series, tick);
      const text = this.panel.kind === 'bands' ? ['free', 'stick', 'slip'][v] ?? String(v) : number(v);
      return `<span style="color:${l.colour}">${l.label} ${text}</span>`;
    });
    this.head.innerHTML = `<b>${this.panel.title}</b> ${parts.join(' ')}`;
  }
}

export class Plots {
  // `range`: [first, last] servo tick; `onSeek(tick)` is called on a click.
  constructor(container, panels, range, onSeek) {
    this.container = container;
    this.panels = panels.map((p) => new Panel(container, p, range, onSeek));
    this.marker = null;
    this.tick = null;
    this.resize();
    new ResizeObserver(() => this.resize()).observe(container);
  }
  resize() {
    const w = Math.max(this.container.clientWidth - 12, 120);
    for (const p of this.panels) p.layout(w);
    if (this.tick !== null) this.setCursor(this.tick, true);
  }
  setMarker(tick) { this.marker = tick; }
  setCursor(tick, force = false) {
    if (tick === this.tick && !force) return;
    this.tick = tick;
    for (const p of this.panels) p.drawCursor(tick, this.marker);
  }
}
