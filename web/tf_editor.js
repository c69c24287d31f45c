// tf_editor.js — the editor of a transfer_function parameter
// (proto/PROTOCOL.md, "Parameter schemas"): a canvas over the value range
// with the colour ramp and the opacity curve, draggable control points
// (x = value, y = opacity; double-click adds a point, Delete removes the
// selected one), a native colour input for the selected point, and presets
// from the schema's `colormaps`. It keeps the form it was given: the
// colormap form ({colormap, opacity, range?}) while only opacities move —
// then no value range is needed — and the points form ([[value, r, g, b, a],
// ...] in data units) once a point gets a colour of its own, which needs the
// dataset's value range (`context.valueRange`, from the catalog) or a range
// in the value. Behind the curve: the dataset's 256-bin value histogram
// (`context.histogram`, over the value range), log scale. The colormap
// form's "opacity": "auto" shows the ramp the server picked from that
// histogram (`context.autoOpacity`) and becomes an explicit ramp when a point
// moves. Changes are sent throttled (every 100 ms while dragging, the last
// one always).

import { throttle } from './throttle.js';

const W = 256, H = 96, R = 5;   // canvas size (CSS scales it), point radius in canvas pixels
const MAX_POINTS = 64;
const AUTO = '@auto';            // the preset that asks for "opacity": "auto"

const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));
const lerp = (a, b, f) => a + (b - a) * f;

// "#rrggbb" <-> [r, g, b] in 0..1 (native colour inputs; controls.js uses them too).
export function rgbToHex(rgb) {
  return `#${rgb.map((x) => Math.round(clamp(Number(x) || 0, 0, 1) * 255).toString(16).padStart(2, '0')).join('')}`;
}
export function hexToRgb(h) {
  return [1, 3, 5].map((i) => parseInt(h.slice(i, i + 2), 16) / 255);
}
function fmt(v) {
  const s = Number(v).toPrecision(4);
  return s.includes('.') && !s.includes('e') ? s.replace(/0+$/, '').replace(/\.$/, '') : s;
}

export class TransferFunctionEditor {
  // row: the element to fill; def: the parameter's schema entry; onChange(value);
  // context: { valueRange: [lo, hi] | null, histogram: [256 counts] | null,
  // autoOpacity: [[t, alpha], ...] | null } of the session's dataset.
  constructor(row, def, onChange, context = {}) {
    this.def = def;
    this.colormaps = new Map((def.colormaps || []).map((m) => [m.name, m.colors]));
    this.valueRange = Array.isArray(context.valueRange) ? context.valueRange : null;
    this.histogram = Array.isArray(context.histogram) && context.histogram.length ? context.histogram : null;
    this.autoOpacity = Array.isArray(context.autoOpacity) && context.autoOpacity.length ? context.autoOpacity
      : [[0, 0], [1, 0.2]];
    this.points = [];      // { t in 0..1 over the range, rgb: [r, g, b] | null (from the colormap), a }
    this.colormap = null;  // colormap form: its name
    this.auto = false;     // colormap form with "opacity": "auto" (until a point moves)
    this.range = null;     // [lo, hi] in data units, or null (the dataset's, not known here)
    this.selected = -1;
    this.send = throttle(() => onChange(this.value()), 100);

    const box = document.createElement('div');
    box.className = 'tf-editor';
    this.canvas = document.createElement('canvas');
    this.canvas.width = W;
    this.canvas.height = H;
    this.canvas.tabIndex = 0;
    this.canvas.dataset.param = def.name;
    this.canvas.title = 'drag a point: value (x) and opacity (y); double-click adds a point, Delete removes the selected one';
    this.preset = document.createElement('select');
    this.preset.name = `${def.name}.preset`;
    this.preset.append(new Option('points', ''), ...[...this.colormaps.keys()].map((n) => new Option(n, n)),
      new Option('auto opacity', AUTO));
    this.preset.title = 'colormap preset (keeps the opacity curve), or the automatic opacity ramp the server picks from the histogram';
    this.color = document.createElement('input');
    this.color.type = 'color';
    this.color.name = `${def.name}.color`;
    this.color.title = 'colour of the selected point';
    this.info = document.createElement('small');
    this.info.className = 'range';
    const tools = document.createElement('div');
    tools.className = 'tf-tools';
    tools.append(this.preset, this.color);
    box.append(this.canvas, tools, this.info);
    row.append(box);

    this.preset.addEventListener('change', () => this.applyPreset(this.preset.value));
    this.color.addEventListener('input', () => this.recolour(hexToRgb(this.color.value)));
    this.canvas.addEventListener('pointerdown', (e) => this.down(e));
    this.canvas.addEventListener('dblclick', (e) => this.add(e));
    this.canvas.addEventListener('keydown', (e) => {
      if ((e.key === 'Delete' || e.key === 'Backspace') && this.selected >= 0 && this.points.length > 1) {
        this.points.splice(this.selected, 1);
        this.selected = -1;
        this.changed(true);
      }
    });
  }

  // The data range points are placed over: the value's own, else the dataset's.
  span() {
    return this.range || this.valueRange;
  }

  colourAt(t) {
    const c = this.colormaps.get(this.colormap);
    if (c) {
      const x = clamp(t, 0, 1) * (c.length - 1), i = Math.min(c.length - 2, Math.floor(x));
      return [0, 1, 2].map((k) => lerp(c[i][k], c[i + 1][k], x - i));
    }
    const p = this.points;
    if (!p.length) return [0.5, 0.5, 0.5];
    if (t <= p[0].t) return p[0].rgb || [0.5, 0.5, 0.5];
    for (let i = 1; i < p.length; i++) {
      if (t <= p[i].t) {
        const f = p[i].t > p[i - 1].t ? (t - p[i - 1].t) / (p[i].t - p[i - 1].t) : 1;
        return [0, 1, 2].map((k) => lerp(p[i - 1].rgb[k], p[i].rgb[k], f));
      }
    }
    return p[p.length - 1].rgb || [0.5, 0.5, 0.5];
  }

  // Shows a value from the session (welcome or state patch); ignored while dragging
  // and while an edit waits to be sent (throttle.js).
  set(v) {
    if (this.dragging || this.send.pending()) return;
    this.auto = !!(v && v.opacity === 'auto');
    if (Array.isArray(v)) {
      this.colormap = null;
      const lo = v[0][0], hi = v[v.length - 1][0];
      const vr = this.valueRange;
      this.range = vr && vr[1] > vr[0] && lo >= vr[0] && hi <= vr[1] ? vr : (hi > lo ? [lo, hi] : [lo, lo + 1]);
      this.points = v.map((p) => ({ t: (p[0] - this.range[0]) / (this.range[1] - this.range[0]),
        rgb: [p[1], p[2], p[3]], a: p[4] }));
    } else if (v && typeof v === 'object') {
      this.colormap = v.colormap;
      this.range = Array.isArray(v.range) ? v.range : null;
      this.points = this.ramp(v.opacity).map((p) => ({ t: p[0], rgb: null, a: p[1] }));
    }
    this.preset.value = this.colormap || '';
    if (this.selected >= this.points.length) this.selected = -1;
    if (this.selected >= 0 && !this.canvas.disabled) this.syncColour();
    this.draw();
  }

  // A colormap form's opacity ramp; "auto" is the server's ramp over the
  // dataset's value range, re-mapped onto the value's own range if it has one.
  ramp(opacity) {
    if (opacity !== 'auto') return opacity || [[0, 0], [1, 1]];
    const vr = this.valueRange, r = this.range;
    if (!r || !vr || !(r[1] > r[0])) return this.autoOpacity;
    return this.autoOpacity.map(([t, a]) => [clamp((vr[0] + t * (vr[1] - vr[0]) - r[0]) / (r[1] - r[0]), 0, 1), a]);
  }

  // The value to send, in the form the editor holds.
  value() {
    const r4 = (x) => Math.round(x * 1e4) / 1e4;
    if (this.colormap) {
      const v = { colormap: this.colormap, opacity: this.auto ? 'auto' : this.points.map((p) => [r4(p.t), r4(p.a)]) };
      if (this.range) v.range = this.range;
      return v;
    }
    const [lo, hi] = this.span();
    return this.points.map((p) => [lo + p.t * (hi - lo), ...p.rgb.map(r4), r4(p.a)]);
  }

  // Colormap form -> points form (each point takes the colormap's colour there); needs a range.
  toPoints() {
    if (!this.colormap) return true;
    if (!this.span()) return false;
    for (const p of this.points) p.rgb = this.colourAt(p.t);
    this.range = this.span();
    this.colormap = null;
    this.preset.value = '';
    return true;
  }

  applyPreset(name) {
    if (name === AUTO) {
      // The automatic ramp spans the dataset's own value range (a range kept
      // from another dataset would misplace it).
      if (!this.colormap) this.colormap = this.colormaps.has('viridis') ? 'viridis' : [...this.colormaps.keys()][0];
      this.range = null;
      this.points = this.ramp('auto').map((p) => ({ t: p[0], rgb: null, a: p[1] }));
      this.auto = true;
      this.preset.value = this.colormap;
      this.changed(true, true);
      return;
    }
    if (!name) { if (!this.toPoints()) this.preset.value = this.colormap; else this.changed(true); return; }
    this.colormap = name;
    for (const p of this.points) p.rgb = null;
    this.changed(true, true);
  }

  recolour(rgb) {
    if (this.selected < 0 || !this.toPoints()) return;
    this.points[this.selected].rgb = rgb;
    this.changed(false);
  }

  // Every edit but a colormap preset makes the ramp explicit.
  changed(final, keepAuto = false) {
    if (!keepAuto) this.auto = false;
    this.draw();
    this.send(final);
  }

  toCanvas(e) {
    const b = this.canvas.getBoundingClientRect();
    return { x: (e.clientX - b.left) * (W / b.width), y: (e.clientY - b.top) * (H / b.height) };
  }

  hit(pos) {
    let best = -1, bd = (2.5 * R) ** 2;
    this.points.forEach((p, i) => {
      const d = (p.t * W - pos.x) ** 2 + ((1 - p.a) * H - pos.y) ** 2;
      if (d < bd) { bd = d; best = i; }
    });
    return best;
  }

  down(e) {
    if (this.canvas.disabled) return;
    const i = this.hit(this.toCanvas(e));
    this.selected = i;
    this.syncColour();
    this.draw();
    if (i < 0) return;
    this.dragging = true;
    this.canvas.setPointerCapture(e.pointerId);
    const move = (ev) => {
      const pos = this.toCanvas(ev);
      const p = this.points[i];
      const lo = i > 0 ? this.points[i - 1].t : 0, hi = i < this.points.length - 1 ? this.points[i + 1].t : 1;
      p.t = clamp(pos.x / W, lo, hi);
      p.a = clamp(1 - pos.y / H, 0, 1);
      this.changed(false);
    };
    const up = () => {
      this.canvas.removeEventListener('pointermove', move);
      this.canvas.removeEventListener('pointerup', up);
      this.canvas.removeEventListener('pointercancel', up);
      this.dragging = false;
      this.changed(true);
    };
    this.canvas.addEventListener('pointermove', move);
    this.canvas.addEventListener('pointerup', up);
    this.canvas.addEventListener('pointercancel', up);
  }

  add(e) {
    const pos = this.toCanvas(e);
    if (this.hit(pos) >= 0 || this.points.length >= MAX_POINTS) return;
    const t = clamp(pos.x / W, 0, 1);
    const p = { t, rgb: this.colormap ? null : this.colourAt(t), a: clamp(1 - pos.y / H, 0, 1) };
    let i = this.points.findIndex((q) => q.t > t);
    if (i < 0) i = this.points.length;
    this.points.splice(i, 0, p);
    this.selected = i;
    this.syncColour();
    this.changed(true);
  }

  syncColour() {
    const p = this.points[this.selected];
    this.color.disabled = !p || (this.colormap && !this.span());
    if (p) this.color.value = rgbToHex(p.rgb || this.colourAt(p.t));
  }

  setEnabled(on) {
    this.canvas.disabled = !on;
    this.preset.disabled = !on;
    this.color.disabled = !on;
  }

  draw() {
    const g = this.canvas.getContext('2d');
    g.clearRect(0, 0, W, H);
    this.drawHistogram(g);
    for (let x = 0; x < W; x++) {   // colour ramp along the bottom, the curve's area above it tinted
      const c = this.colourAt((x + 0.5) / W).map((k) => Math.round(k * 255));
      g.fillStyle = `rgb(${c.join(',')})`;
      g.fillRect(x, H - 8, 1, 8);
    }
    g.strokeStyle = '#d8dae0';
    g.lineWidth = 1.5;
    g.beginPath();
    const pts = this.points;
    if (pts.length) g.moveTo(0, (1 - pts[0].a) * H);
    for (const p of pts) g.lineTo(p.t * W, (1 - p.a) * H);
    if (pts.length) g.lineTo(W, (1 - pts[pts.length - 1].a) * H);
    g.stroke();
    pts.forEach((p, i) => {
      const c = (p.rgb || this.colourAt(p.t)).map((k) => Math.round(k * 255));
      g.fillStyle = `rgb(${c.join(',')})`;
      g.strokeStyle = i === this.selected ? '#5aa9ff' : '#000';
      g.lineWidth = i === this.selected ? 2.5 : 1;
      g.beginPath();
      g.arc(p.t * W, (1 - p.a) * H, R, 0, 2 * Math.PI);
      g.fill();
      g.stroke();
    });
    const s = this.span();
    const sel = pts[this.selected];
    const at = sel ? ` · point ${this.selected}: ${s ? fmt(s[0] + sel.t * (s[1] - s[0])) : `t ${fmt(sel.t)}`}, α ${fmt(sel.a)}` : '';
    this.info.textContent = `${s ? `${fmt(s[0])} … ${fmt(s[1])} ${this.def.unit || ''}` : 'the dataset\'s value range'}${at}`;
  }

  // The histogram's bins (over the dataset's value range) as grey bars of
  // height log(1 + count) / log(1 + largest count), placed over the span.
  drawHistogram(g) {
    const h = this.histogram, vr = this.valueRange, s = this.span();
    if (!h || !vr || !s || !(s[1] > s[0])) return;
    const top = Math.log1p(Math.max(...h));
    if (!(top > 0)) return;
    const x = (v) => ((v - s[0]) / (s[1] - s[0])) * W;
    const bin = (vr[1] - vr[0]) / h.length;
    g.fillStyle = 'rgba(160, 165, 180, 0.35)';
    h.forEach((c, k) => {
      if (!c) return;
      const x0 = x(vr[0] + k * bin), x1 = bin > 0 ? x(vr[0] + (k + 1) * bin) : x0 + W / h.length;
      const y = (Math.log1p(c) / top) * (H - 8);
      g.fillRect(x0, H - 8 - y, Math.max(1, x1 - x0), y);
    });
  }
}
