// tf2d_editor.js — the editor of a transfer_2d parameter (proto/PROTOCOL.md,
// "Parameter schemas"; particles' curvature_tf, renderer/particles/
// particles_tf2d.h): a canvas over the square [-range, range]² of the
// principal curvatures per voxel, k1 across and k2 up, the unreachable half
// k2 > k1 shaded and Kindlmann's regions labelled faintly. Behind the widgets
// a preview of the composite over the ink (tf2dColour: the rule the renderer
// bakes, at the same 64 x 64 texel centres). Each widget is a circle: drag
// its centre (or inside it) to move it, drag the rim handle (right of the
// centre, or left when that is off the square) to change its radius; a colour input and an alpha slider edit the selected one;
// double-click adds one (radius 0.15 range, grey, alpha 1), Delete removes
// the selected one (one always stays); a number field sets the range; the
// presets are the schema's default ("ridges light, valleys dark") and "none"
// (one transparent widget). Changes are sent throttled (every 100 ms while
// dragging, the last one always), like tf_editor.js.

import { throttle } from './throttle.js';
import { rgbToHex, hexToRgb } from './tf_editor.js';

const W = 192, H = 192;  // canvas size (CSS scales it)
const T = 64;            // preview texels per side (the renderer's table size)
const HANDLE = 6;        // hit distance of a centre or rim handle, canvas pixels
const DEFAULT = '@default', NONE = '@none';

const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));
const r4 = (x) => Math.round(x * 1e4) / 1e4;
function fmt(v) {
  const s = Number(v).toPrecision(3);
  return s.includes('.') && !s.includes('e') ? s.replace(/0+$/, '').replace(/\.$/, '') : s;
}

// The composite at (k1, k2) (per voxel) over `ink`: for each widget in order,
// q = distance / radius, w = a max(0, 1 - q²)², c = mix(c, rgb, w). Widgets
// are [k1, k2, radius, r, g, b, a] (the JSON form). particles_tf2d.c bakes
// the same rule; the browser test compares the two at five points.
export function tf2dColour(widgets, ink, k1, k2) {
  const c = [ink[0], ink[1], ink[2]];
  for (const w of widgets) {
    const q2 = ((k1 - w[0]) ** 2 + (k2 - w[1]) ** 2) / (w[2] * w[2]);
    const a = w[6] * (q2 < 1 ? (1 - q2) ** 2 : 0);
    for (let k = 0; k < 3; k++) c[k] += (w[3 + k] - c[k]) * a;
  }
  return c;
}

export class Tf2dEditor {
  // row: the element to fill; def: the schema entry (default, max_widgets,
  // unit); onChange(value); ink: [r, g, b] the preview composites over.
  constructor(row, def, onChange, ink = [1, 1, 1]) {
    this.def = def;
    this.maxWidgets = def.max_widgets || 16;
    this.ink = ink;
    this.range = 0.5;
    this.widgets = [];   // [k1, k2, radius, r, g, b, a]
    this.selected = -1;
    this.send = throttle(() => onChange(this.value()), 100);

    const box = document.createElement('div');
    box.className = 'tf-editor tf2d-editor';
    this.canvas = document.createElement('canvas');
    this.canvas.width = W;
    this.canvas.height = H;
    this.canvas.tabIndex = 0;
    this.canvas.dataset.param = def.name;
    this.canvas.title = 'k1 across, k2 up (per voxel): drag a widget\'s centre to move it, its rim handle to resize it; ' +
      'double-click adds a widget, Delete removes the selected one';
    this.preset = document.createElement('select');
    this.preset.name = `${def.name}.preset`;
    this.preset.append(new Option('widgets', ''), new Option('ridges light, valleys dark', DEFAULT),
      new Option('none', NONE));
    this.preset.title = 'preset: the default (ridges light, valleys dark) or none (the ink everywhere)';
    this.color = document.createElement('input');
    this.color.type = 'color';
    this.color.name = `${def.name}.color`;
    this.color.title = 'colour of the selected widget';
    this.alpha = document.createElement('input');
    this.alpha.type = 'range';
    this.alpha.name = `${def.name}.alpha`;
    this.alpha.min = 0; this.alpha.max = 1; this.alpha.step = 0.01;
    this.alpha.title = 'opacity of the selected widget';
    this.rangeField = document.createElement('input');
    this.rangeField.type = 'number';
    this.rangeField.name = `${def.name}.range`;
    this.rangeField.className = 'num';
    this.rangeField.min = 0; this.rangeField.step = 'any';
    this.rangeField.title = `half width of the square, ${def.unit || ''}`;
    this.info = document.createElement('small');
    this.info.className = 'range';
    const presets = document.createElement('div');
    presets.className = 'tf-tools';
    presets.append(this.preset);
    const tools = document.createElement('div');
    tools.className = 'tf-tools';
    tools.append(this.color, this.alpha, this.rangeField);
    box.append(this.canvas, presets, tools, this.info);
    row.append(box);

    this.preset.addEventListener('change', () => this.applyPreset(this.preset.value));
    this.color.addEventListener('input', () => this.edit((w) => { w.splice(3, 3, ...hexToRgb(this.color.value)); }));
    this.alpha.addEventListener('input', () => this.edit((w) => { w[6] = Number(this.alpha.value); }));
    this.alpha.addEventListener('change', () => this.send(true));
    this.rangeField.addEventListener('change', () => {
      const r = Number(this.rangeField.value);
      if (!(r > 0) || !Number.isFinite(r)) { this.rangeField.value = this.range; return; }
      this.range = r;
      this.changed(true);
    });
    this.canvas.addEventListener('pointerdown', (e) => this.down(e));
    this.canvas.addEventListener('dblclick', (e) => this.add(e));
    this.canvas.addEventListener('keydown', (e) => {
      if ((e.key === 'Delete' || e.key === 'Backspace') && this.selected >= 0 && this.widgets.length > 1) {
        this.widgets.splice(this.selected, 1);
        this.selected = -1;
        this.syncTools();
        this.changed(true);
      }
    });
    this.set(def.default);
  }

  // Shows a value from the session (welcome or state patch); ignored while dragging
  // and while an edit waits to be sent (throttle.js).
  set(v) {
    if (this.dragging || this.send.pending() || !v || !Array.isArray(v.widgets)) return;
    this.range = v.range > 0 ? v.range : this.range;
    this.widgets = v.widgets.map((w) => w.slice(0, 7));
    if (this.selected >= this.widgets.length) this.selected = -1;
    this.rangeField.value = this.range;
    this.syncTools();
    this.draw();
  }

  // The ink of the preview (the first set's colour).
  setInk(rgb) {
    if (!Array.isArray(rgb) || rgb.length !== 3) return;
    this.ink = rgb.map(Number);
    this.draw();
  }

  value() {
    return { range: this.range, widgets: this.widgets.map((w) => w.map(r4)) };
  }

  applyPreset(name) {
    if (name === DEFAULT) {
      const d = this.def.default;
      this.range = d.range;
      this.widgets = d.widgets.map((w) => w.slice(0, 7));
    } else if (name === NONE) {
      this.widgets = [[0, 0, 0.15 * this.range, 0.5, 0.5, 0.5, 0]];
    } else {
      return;
    }
    this.selected = -1;
    this.preset.value = '';
    this.rangeField.value = this.range;
    this.syncTools();
    this.changed(true);
  }

  edit(fn) {
    const w = this.widgets[this.selected];
    if (!w) return;
    fn(w);
    this.changed(false);
  }

  changed(final) {
    this.draw();
    this.send(final);
  }

  // Canvas pixels <-> curvature per voxel.
  px(k1, k2) {
    return { x: ((k1 + this.range) / (2 * this.range)) * W, y: (1 - (k2 + this.range) / (2 * this.range)) * H };
  }
  kappa(x, y) {
    return [(x / W) * 2 * this.range - this.range, (1 - y / H) * 2 * this.range - this.range];
  }
  toCanvas(e) {
    const b = this.canvas.getBoundingClientRect();
    return { x: (e.clientX - b.left) * (W / b.width), y: (e.clientY - b.top) * (H / b.height) };
  }
  // The rim handle: right of the centre, or left when the right one is off the square.
  rimOf(w) {
    return this.px(w[0] + w[2] <= this.range ? w[0] + w[2] : w[0] - w[2], w[1]);
  }

  // { i, part: 'rim' | 'centre' } of the widget under pos, the selected one
  // and later ones (drawn on top) first; null when none.
  hit(pos) {
    const order = this.widgets.map((_, i) => i).reverse();
    if (this.selected >= 0) order.unshift(this.selected);
    const near = (p) => (p.x - pos.x) ** 2 + (p.y - pos.y) ** 2 <= HANDLE * HANDLE;
    for (const i of order) if (near(this.rimOf(this.widgets[i]))) return { i, part: 'rim' };
    for (const i of order) if (near(this.px(this.widgets[i][0], this.widgets[i][1]))) return { i, part: 'centre' };
    for (const i of order) {
      const w = this.widgets[i], [a, b] = this.kappa(pos.x, pos.y);
      if ((a - w[0]) ** 2 + (b - w[1]) ** 2 <= w[2] * w[2]) return { i, part: 'centre' };
    }
    return null;
  }

  down(e) {
    if (this.canvas.disabled) return;
    const pos = this.toCanvas(e);
    const h = this.hit(pos);
    this.selected = h ? h.i : -1;
    this.syncTools();
    this.draw();
    if (!h) return;
    const w = this.widgets[h.i];
    const [a0, b0] = this.kappa(pos.x, pos.y);
    const grab = [w[0] - a0, w[1] - b0];
    this.dragging = true;
    this.canvas.setPointerCapture(e.pointerId);
    const move = (ev) => {
      const p = this.toCanvas(ev);
      const [a, b] = this.kappa(clamp(p.x, 0, W), clamp(p.y, 0, H));
      if (h.part === 'rim') {
        w[2] = Math.max(0.01 * this.range, Math.hypot(a - w[0], b - w[1]));
      } else {
        w[0] = clamp(a + grab[0], -this.range, this.range);
        w[1] = clamp(b + grab[1], -this.range, this.range);
      }
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
    if (this.widgets.length >= this.maxWidgets || (this.hit(pos) && this.hit(pos).part === 'rim')) return;
    const [a, b] = this.kappa(pos.x, pos.y);
    this.widgets.push([a, b, 0.15 * this.range, 0.5, 0.5, 0.5, 1]);
    this.selected = this.widgets.length - 1;
    this.syncTools();
    this.changed(true);
  }

  syncTools() {
    const w = this.widgets[this.selected];
    const off = !w || this.canvas.disabled;
    this.color.disabled = off;
    this.alpha.disabled = off;
    if (w) {
      this.color.value = rgbToHex(w.slice(3, 6));
      this.alpha.value = w[6];
    }
  }

  setEnabled(on) {
    this.canvas.disabled = !on;
    this.preset.disabled = !on;
    this.rangeField.disabled = !on;
    this.syncTools();
  }

  draw() {
    const g = this.canvas.getContext('2d');
    const r = this.range;
    // The preview at the renderer's texel centres; the unreachable half
    // (k2 > k1) holds the diagonal's value there too.
    const img = new ImageData(T, T);
    for (let j = 0; j < T; j++) {
      const k2 = -r + ((j + 0.5) * 2 * r) / T;
      for (let i = 0; i < T; i++) {
        let a = -r + ((i + 0.5) * 2 * r) / T, b = k2;
        if (b > a) a = b = 0.5 * (a + b);
        const c = tf2dColour(this.widgets, this.ink, a, b);
        const o = ((T - 1 - j) * T + i) * 4;
        for (let k = 0; k < 3; k++) img.data[o + k] = Math.round(clamp(c[k], 0, 1) * 255);
        img.data[o + 3] = 255;
      }
    }
    const off = document.createElement('canvas');
    off.width = T; off.height = T;
    off.getContext('2d').putImageData(img, 0, 0);
    g.imageSmoothingEnabled = true;
    g.clearRect(0, 0, W, H);
    g.drawImage(off, 0, 0, W, H);
    // Unreachable half: above the diagonal (top left).
    g.fillStyle = 'rgba(40, 42, 50, 0.6)';
    g.beginPath();
    g.moveTo(0, H); g.lineTo(0, 0); g.lineTo(W, 0);
    g.closePath();
    g.fill();
    // Axes through zero and Kindlmann's regions.
    const o = this.px(0, 0);
    g.strokeStyle = 'rgba(128, 128, 140, 0.5)';
    g.lineWidth = 1;
    g.beginPath();
    g.moveTo(0, o.y); g.lineTo(W, o.y); g.moveTo(o.x, 0); g.lineTo(o.x, H);
    g.stroke();
    g.font = '10px sans-serif';
    g.textAlign = 'center';
    g.textBaseline = 'middle';
    for (const [name, a, b] of [['ridge', 0.7, 0.08], ['valley', 0.12, -0.75], ['cap', 0.75, 0.45],
      ['cup', -0.45, -0.8], ['saddle', 0.6, -0.55]]) {
      const p = this.px(a * r, b * r);
      g.fillStyle = 'rgba(128, 128, 140, 0.7)';
      g.fillText(name, p.x, p.y);
    }
    g.fillText('k2 > k1: unreachable', W * 0.3, H * 0.2);
    // Widgets: circle, centre, rim handle.
    this.widgets.forEach((w, i) => {
      const c = this.px(w[0], w[1]), rim = this.rimOf(w);
      const sel = i === this.selected;
      g.strokeStyle = sel ? '#5aa9ff' : 'rgba(0, 0, 0, 0.8)';
      g.lineWidth = sel ? 2 : 1;
      g.beginPath();
      g.arc(c.x, c.y, (w[2] / (2 * r)) * W, 0, 2 * Math.PI);
      g.stroke();
      g.fillStyle = rgbToHex(w.slice(3, 6));
      for (const [p, rad] of [[c, 4], [rim, 3]]) {
        g.beginPath();
        g.arc(p.x, p.y, rad, 0, 2 * Math.PI);
        g.fill();
        g.stroke();
      }
    });
    const w = this.widgets[this.selected];
    const at = w ? ` · widget ${this.selected}: (${fmt(w[0])}, ${fmt(w[1])}), radius ${fmt(w[2])}, α ${fmt(w[6])}` : '';
    this.info.textContent = `k1, k2 in ${fmt(-r)} … ${fmt(r)} ${this.def.unit || ''}${at}`;
  }
}
