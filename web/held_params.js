// held_params.js — the controller's own parameter edits stay on screen until
// the server has them. The page sends `set` for a parameter (a drag sends a
// few, throttled) and the server echoes its state in `state` patches, merged
// and written between frames, so on a busy renderer an echo of an older value
// can arrive after a newer local edit: shown, it would revert the control, and
// the next click (a 2D-editor widget, say) would act on the old value. So a
// parameter the page has set is held: patches do not overwrite its control
// until one carries the value last sent (numbers equal within 1e-6 relative:
// the server stores floats). A refused set (an `error` reply), a new
// technique or dataset, a new welcome, or losing control releases every hold,
// so the server's value shows again. No DOM; any module.

const TOL = 1e-6;

// Deep equality of JSON values, numbers within TOL relative.
export function sameJson(a, b) {
  if (typeof a === 'number' && typeof b === 'number') {
    return a === b || Math.abs(a - b) <= TOL * Math.max(Math.abs(a), Math.abs(b));
  }
  if (Array.isArray(a) || Array.isArray(b)) {
    return Array.isArray(a) && Array.isArray(b) && a.length === b.length && a.every((x, i) => sameJson(x, b[i]));
  }
  if (a && b && typeof a === 'object' && typeof b === 'object') {
    const ka = Object.keys(a), kb = Object.keys(b);
    return ka.length === kb.length && ka.every((k) => k in b && sameJson(a[k], b[k]));
  }
  return a === b;
}

export class HeldParams {
  constructor() { this.sent = new Map(); }

  // The page sent `value` for `name`.
  hold(name, value) { this.sent.set(name, value); }

  release() { this.sent.clear(); }

  // The server's params (a patch's or the whole state's): the ones whose
  // control may show them now. A held name whose value is the one sent is
  // confirmed (released); a held name with another value is left out.
  shown(values) {
    const out = {};
    for (const [name, v] of Object.entries(values || {})) {
      if (this.sent.has(name)) {
        if (!sameJson(v, this.sent.get(name))) continue;
        this.sent.delete(name);
      }
      out[name] = v;
    }
    return out;
  }

  get size() { return this.sent.size; }
}
