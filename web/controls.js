// controls.js — parameter controls generated from a technique's schema
// (sl_params_schema_json: name, type, min, max, default, choices, unit,
// description). float/int -> slider + value with unit, or a number field
// when the schema's range is too wide for a slider (max - min > 1e6:
// `radius` 0 … 1e9, `scalar_min` ±1e30) — a slider over the dataset's value
// range instead when the unit is "data" and a volume's range is known
// (`isovalue`); bool -> checkbox; enum -> select
// (colormaps too); vec3 with unit "rgb" -> a native colour input, any other
// vec3 (directions, clip corners) -> three number fields clamped to
// [min, max]; attribute -> select of the dataset's attribute names ("none" =
// -1 when min is -1); transfer_function -> the editor of tf_editor.js;
// int with unit "sets" (a bit mask, bit k = set k) -> check boxes "set 0" …
// "set 3"; values (0 … max_count numbers, [] = auto) -> a text field of
// comma-separated numbers, checked against the schema range before it is
// sent; transfer_2d -> the editor of tf2d_editor.js, its preview over the
// first "rgb" vec3 of the schema (particles: set 0's ink).
// Descriptions become tooltips; sliders and number fields also show their
// range and unit ("0 … 1000 world"). Knows no technique or parameter by
// name: the schema's type, range and unit alone pick the control.

import { TransferFunctionEditor, rgbToHex, hexToRgb } from './tf_editor.js';
import { throttle } from './throttle.js';
import { Tf2dEditor } from './tf2d_editor.js';

// A schema range wider than this is typed, not slid.
export const WIDE_RANGE = 1e6;

function fmt(v, type) {
  if (type === 'int') return String(Math.round(v));
  const s = Number(v).toPrecision(4);
  // Trim zeros after a decimal point only ("0.2500" -> "0.25", "1000" stays, "1.000e+9" stays).
  return s.includes('.') && !s.includes('e') ? s.replace(/0+$/, '').replace(/\.$/, '') : s;
}

// Slider position <-> value; wide ranges (max/min > 1000, min >= 0) are logarithmic,
// from min (or 1e-4 when min is 0) to max, so a tolerance of [1e-12, 1] slides over
// every decade.
function scaleFor(def) {
  const lo = def.min, hi = def.max;
  if (def.type === 'float' && lo >= 0 && hi > 1000 * Math.max(lo, 1e-6)) {
    const floor = lo > 0 ? lo : 1e-4;
    const l0 = Math.log10(floor), l1 = Math.log10(hi);
    return {
      toSlider: (v) => (v <= 0 ? 0 : (Math.log10(Math.max(v, floor)) - l0) / (l1 - l0)),
      fromSlider: (s) => (s <= 0 ? lo : 10 ** (l0 + s * (l1 - l0))),
      step: 'any', min: 0, max: 1,
    };
  }
  return {
    toSlider: (v) => v, fromSlider: (s) => Number(s),
    step: def.type === 'int' ? 1 : (hi - lo) / 200, min: lo, max: hi,
  };
}

const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));

// Check boxes of an int with unit "sets": 4, or fewer when max has fewer bits.
export function setCount(def) {
  return Math.max(1, Math.min(4, Math.floor(Math.log2(Math.max(1, def.max))) + 1));
}

// Text of a 'values' field -> { values } or { error }: comma-separated
// numbers, empty = [] (auto), at most def.max_count (4), each in [min, max].
export function parseValueList(text, def) {
  const trimmed = String(text).trim();
  if (trimmed === '') return { values: [] };
  const parts = trimmed.split(',').map((t) => t.trim());
  const most = def.max_count || 4;
  if (parts.length > most) return { error: `at most ${most} values, got ${parts.length}` };
  const values = [];
  for (const [k, t] of parts.entries()) {
    const v = t === '' ? NaN : Number(t);
    if (!Number.isFinite(v)) return { error: `value ${k}: '${t}' is not a number` };
    if (v < def.min || v > def.max) return { error: `value ${k}: ${t} is outside ${fmt(def.min)} … ${fmt(def.max)}` };
    values.push(v);
  }
  return { values };
}

// The dataset's value range within the schema's, when the dataset is known and not constant.
function dataRange(context, def) {
  const r = context && context.valueRange;
  if (!Array.isArray(r) || !(r[1] > r[0])) return null;
  const lo = Math.max(r[0], def.min), hi = Math.min(r[1], def.max);
  return hi > lo ? [lo, hi] : null;
}


// A select of attribute names for one 'attribute' parameter; returns its
// set(value). Names not known yet: only "none" and the current index, until
// build() is called again with the names. A value the dataset lacks (the
// default 0 on a dataset without attributes, which renders as none) shows
// as "none" when there is one.
function attributeSelect(row, def, names, onChange) {
  const sel = document.createElement('select');
  sel.name = def.name;
  sel.dataset.type = 'attribute';
  const known = Array.isArray(names);
  if (def.min < 0) sel.append(new Option('none', '-1'));
  if (known) names.forEach((label, i) => { if (i <= def.max) sel.append(new Option(label, String(i))); });
  else sel.title = 'attribute names arrive once the dataset has loaded';
  sel.addEventListener('change', () => onChange(Number(sel.value)));
  row.append(sel);
  return (v) => {
    const want = String(v < 0 ? -1 : v);
    if (!known && v >= 0 && ![...sel.options].some((o) => o.value === want)) sel.append(new Option(`#${v}`, want));
    sel.value = want;
    if (sel.value !== want && def.min < 0) sel.value = '-1';
  };
}

export class ParamControls {
  // onChange(name, value) is called when the user changes a control.
  constructor(form, onChange) {
    this.form = form;
    this.onChange = onChange;
    this.inputs = new Map();   // name -> { def, set(value) }
    this.schemaKey = '';
  }

  // attributes: the dataset's per-vertex attribute names in index order
  // (null while the catalog does not know them yet), the options of every
  // parameter of type 'attribute'.
  // context: what the controls may know of the dataset, { valueRange: [lo, hi] | null,
  // histogram, autoOpacity } (a volume's value range, histogram and automatic
  // opacity ramp, for transfer-function editors).
  build(schema, attributes = null, context = {}) {
    const key = JSON.stringify([schema.map((d) => [d.name, d.type]), attributes, context.valueRange || null,
      context.histogram || null, context.autoOpacity || null, context.autoIsovalue ?? null]);
    if (key === this.schemaKey) return;
    this.schemaKey = key;
    // A rebuild (the catalog told more of the dataset, say) keeps what the
    // user selected in an editor: a colour picked next applies to that point.
    const selections = new Map([...this.inputs].filter(([, e]) => e.editor).map(([n, e]) => [n, e.editor.selected]));
    this.form.replaceChildren();
    this.inputs.clear();
    this.inkName = null;
    this.context = context;
    for (const def of schema) {
      // A label forwards clicks to its first input: not for the editors'
      // canvases, nor for a group of check boxes (each has its own label).
      const grouped = def.type === 'transfer_function' || def.type === 'transfer_2d' ||
        (def.type === 'int' && def.unit === 'sets');
      const row = document.createElement(grouped ? 'div' : 'label');
      row.className = 'param';
      row.title = def.description || '';
      const name = document.createElement('span');
      name.className = 'name';
      // In full, wrapped at the underscores (the control's name stays def.name).
      def.name.split('_').forEach((part, k) => {
        if (k) name.append('_', document.createElement('wbr'));
        name.append(part);
      });
      row.append(name);
      let entry;
      if (def.type === 'int' && def.unit === 'sets') {
        // A bit mask over the technique's sets: one box per bit.
        const boxes = [];
        for (let k = 0; k < setCount(def); k++) {
          const label = document.createElement('label');
          label.className = 'set';
          const box = document.createElement('input');
          box.type = 'checkbox';
          box.name = def.name; // update() leaves a focused control alone, by name
          box.dataset.bit = String(k);
          box.addEventListener('change', () => {
            const mask = boxes.reduce((m, b, i) => m | (b.checked ? 1 << i : 0), 0);
            this.onChange(def.name, clamp(mask, def.min, def.max));
          });
          label.append(box, ` set ${k}`);
          boxes.push(box);
        }
        const group = document.createElement('span');
        group.className = 'sets';
        group.append(...boxes.map((b) => b.parentElement));
        row.append(group);
        entry = { def, set: (v) => { boxes.forEach((b, i) => { b.checked = ((Number(v) >> i) & 1) === 1; }); } };
      } else if (def.type === 'values') {
        const f = document.createElement('input');
        f.type = 'text';
        f.name = def.name;
        f.className = 'list';
        f.placeholder = 'auto';
        const hint = `up to ${def.max_count || 4} of ${fmt(def.min, 'float')} … ${fmt(def.max, 'float')}` +
          `${def.unit ? ` ${def.unit}` : ''}, comma-separated; empty = auto`;
        const range = document.createElement('small');
        range.className = 'range';
        range.textContent = hint;
        f.title = `${def.description ? `${def.description}. ` : ''}${hint}`;
        const mark = (error) => {
          f.setCustomValidity(error || '');
          f.classList.toggle('invalid', !!error);
          range.textContent = error ? `not sent: ${error}` : hint;
        };
        f.addEventListener('change', () => {
          const r = parseValueList(f.value, def);
          mark(r.error);
          if (!r.error) this.onChange(def.name, r.values);
        });
        row.append(f, range);
        entry = { def, set: (v) => { f.value = Array.isArray(v) ? v.join(', ') : ''; mark(null); } };
      } else if (def.type === 'attribute') {
        entry = { def, set: attributeSelect(row, def, attributes, (v) => this.onChange(def.name, v)) };
      } else if (def.type === 'float' && def.max - def.min > WIDE_RANGE && def.unit === 'data' &&
                 dataRange(this.context, def)) {
        // A value in data units: a slider over the dataset's own value range.
        const [lo, hi] = dataRange(this.context, def);
        const slider = document.createElement('input');
        slider.type = 'range';
        slider.name = def.name;
        slider.min = lo; slider.max = hi; slider.step = 'any';
        slider.dataset.over = 'dataset';
        const out = document.createElement('output');
        const range = document.createElement('small');
        range.className = 'range';
        range.textContent = `${fmt(lo, 'float')} … ${fmt(hi, 'float')} data (the dataset's range)`;
        slider.title = `${def.description ? `${def.description}. ` : ''}Range ${range.textContent}`;
        slider.addEventListener('input', () => { out.textContent = fmt(slider.value, 'float'); });
        slider.addEventListener('change', () => this.onChange(def.name, Number(slider.value)));
        row.append(slider, out, range);
        // "auto" (a schema default of "auto"): the value the server picks for
        // this dataset when the catalog says it, the slider put there.
        const autoValue = Number.isFinite(this.context.autoIsovalue) ? this.context.autoIsovalue : null;
        if (def.default === 'auto') {
          const back = document.createElement('button');
          back.type = 'button';
          back.className = 'auto';
          back.name = `${def.name}.auto`;
          back.textContent = 'auto';
          back.title = 'back to the value the server picks for this dataset';
          back.addEventListener('click', (e) => { e.preventDefault(); this.onChange(def.name, 'auto'); });
          range.append(' ', back);
        }
        entry = { def, set: (v) => {
          if (v === 'auto') {
            if (autoValue !== null) slider.value = autoValue;
            out.textContent = autoValue !== null ? `auto ${fmt(autoValue, 'float')}` : 'auto';
            slider.dataset.auto = '1';
            return;
          }
          delete slider.dataset.auto;
          slider.value = v;
          out.textContent = fmt(v, 'float');
        } };
      } else if ((def.type === 'float' || def.type === 'int') && def.max - def.min > WIDE_RANGE) {
        const f = document.createElement('input');
        f.type = 'number';
        f.name = def.name;
        f.step = def.type === 'int' ? '1' : 'any';
        f.min = def.min; f.max = def.max;
        f.className = 'num';
        const unit = document.createElement('span');
        unit.className = 'unit';
        unit.textContent = def.unit || '';
        const range = document.createElement('small');
        range.className = 'range';
        range.textContent = `${fmt(def.min, def.type)} … ${fmt(def.max, def.type)}${def.unit ? ` ${def.unit}` : ''}`;
        f.title = `${def.description ? `${def.description}. ` : ''}Range ${range.textContent}`;
        if (def.default === 'auto') f.placeholder = 'auto';
        f.addEventListener('change', () => {
          if (f.value === '' && def.default === 'auto') { this.onChange(def.name, 'auto'); return; }
          if (f.value === '' || !Number.isFinite(Number(f.value))) return;
          let v = clamp(Number(f.value), def.min, def.max);
          if (def.type === 'int') v = Math.round(v);
          f.value = v;
          this.onChange(def.name, v);
        });
        row.append(f, unit, range);
        entry = { def, set: (v) => { f.value = v === 'auto' ? '' : v; } };
      } else if (def.type === 'float' || def.type === 'int') {
        const sc = scaleFor(def);
        const slider = document.createElement('input');
        slider.type = 'range';
        slider.name = def.name;
        slider.min = sc.min; slider.max = sc.max; slider.step = sc.step;
        const out = document.createElement('output');
        const unit = def.unit ? ` ${def.unit}` : '';
        const range = document.createElement('small');
        range.className = 'range';
        range.textContent = `${fmt(def.min, def.type)} … ${fmt(def.max, def.type)}${unit}`;
        slider.title = `${def.description ? `${def.description}. ` : ''}Range ${range.textContent}`;
        slider.addEventListener('input', () => { out.textContent = fmt(sc.fromSlider(slider.value), def.type) + unit; });
        slider.addEventListener('change', () => {
          let v = sc.fromSlider(slider.value);
          if (def.type === 'int') v = Math.round(v);
          this.onChange(def.name, v);
        });
        row.append(slider, out, range);
        entry = { def, set: (v) => { slider.value = sc.toSlider(v); out.textContent = fmt(v, def.type) + unit; } };
      } else if (def.type === 'bool') {
        const box = document.createElement('input');
        box.type = 'checkbox';
        box.name = def.name;
        box.addEventListener('change', () => this.onChange(def.name, box.checked));
        row.append(box);
        entry = { def, set: (v) => { box.checked = !!v; } };
      } else if (def.type === 'enum') {
        const sel = document.createElement('select');
        sel.name = def.name;
        for (const c of def.choices || []) sel.append(new Option(c, c));
        sel.addEventListener('change', () => this.onChange(def.name, sel.value));
        row.append(sel);
        entry = { def, set: (v) => { sel.value = v; } };
      } else if (def.type === 'vec3' && def.unit === 'rgb') {
        const pick = document.createElement('input');
        pick.type = 'color';
        pick.name = def.name;
        pick.className = 'rgb';
        const send = throttle(() => this.onChange(def.name, hexToRgb(pick.value)), 100);
        pick.addEventListener('input', () => send());
        pick.addEventListener('change', () => send(true));
        row.append(pick);
        entry = { def, set: (v) => { if (Array.isArray(v)) pick.value = rgbToHex(v); } };
      } else if (def.type === 'transfer_function') {
        const ed = new TransferFunctionEditor(row, def, (v) => this.onChange(def.name, v), this.context);
        if (selections.has(def.name)) ed.selected = selections.get(def.name);
        row.classList.add('tf');
        entry = { def, set: (v) => ed.set(v), editor: ed };
      } else if (def.type === 'transfer_2d') {
        const ink = schema.find((d) => d.type === 'vec3' && d.unit === 'rgb');
        this.inkName = ink ? ink.name : null;
        const ed = new Tf2dEditor(row, def, (v) => this.onChange(def.name, v), ink ? ink.default : undefined);
        if (selections.has(def.name)) ed.selected = selections.get(def.name);
        row.classList.add('tf');
        entry = { def, set: (v) => ed.set(v), editor: ed };
      } else if (def.type === 'vec3') {
        const fields = [0, 1, 2].map(() => {
          const f = document.createElement('input');
          f.type = 'number';
          f.name = def.name; // update() leaves a focused control alone, by name
          f.step = 'any';
          f.min = def.min; f.max = def.max;
          f.className = 'vec';
          return f;
        });
        for (const f of fields) {
          f.addEventListener('change', () => {
            const v = fields.map((x) => clamp(Number(x.value) || 0, def.min, def.max));
            fields.forEach((x, i) => { x.value = v[i]; });
            this.onChange(def.name, v);
          });
          row.append(f);
        }
        entry = { def, set: (v) => { fields.forEach((f, i) => { f.value = Array.isArray(v) ? v[i] : 0; }); } };
      } else {
        continue;
      }
      this.inputs.set(def.name, entry);
      this.form.append(row);
    }
  }

  // Shows the session's values (after a welcome or a state patch).
  update(values) {
    for (const [name, v] of Object.entries(values || {})) {
      const e = this.inputs.get(name);
      if (e && document.activeElement?.name !== name) e.set(v);
    }
    const ink = this.inkName && values ? values[this.inkName] : undefined;
    if (ink) for (const e of this.inputs.values()) if (e.editor && e.editor.setInk) e.editor.setInk(ink);
  }

  setEnabled(on) {
    for (const el of this.form.querySelectorAll('input, select, textarea')) el.disabled = !on;
    for (const e of this.inputs.values()) if (e.editor) e.editor.setEnabled(on);
  }
}
