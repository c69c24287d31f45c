// camera.js — orbit / pan / zoom from mouse, wheel and touch, sent as `camera`
// messages at most ~30 per second (the newest pose wins; start/end always go).
// The camera is an orbit about the dataset's bounds centre (the same formula
// as renderer/core/sl_camera.c); once the bounds are known and the user pans,
// it is sent as eye/target/up so the target can leave the centre.
// It holds no camera numbers of its own: the default camera and the
// elevation limit come from the server's welcome (configure), and input is
// ignored until then.

const DEG = Math.PI / 180;

export class CameraControl {
  constructor(canvas, send) {
    this.canvas = canvas;
    this.send = send;              // (phase, cameraObject) => void
    this.defaults = null;          // welcome.camera_default: {orbit: {azimuth, elevation, distance}, fov_y}
    this.maxElevation = 0;         // welcome.limits.max_elevation, degrees
    this.orbit = null;             // {azimuth, elevation, distance}; null until configured
    this.fov = 0;
    this.pan = [0, 0, 0];          // world offset of the target from the bounds centre
    this.bounds = null;            // [[x,y,z],[x,y,z]]
    this.enabled = true;
    this.pointers = new Map();
    this.pending = null;           // newest unsent move
    this.lastSent = 0;
    this.timer = null;
    this.wheelTimer = null;
    this.dragging = false;
    this.attach();
  }

  // Takes the server's default camera and elevation limit (from welcome).
  configure(cameraDefault, maxElevation) {
    this.defaults = cameraDefault;
    this.maxElevation = maxElevation;
    if (!this.orbit) {
      this.orbit = { ...cameraDefault.orbit };
      this.fov = cameraDefault.fov_y;
    }
  }

  // Adopts a camera object from the session state (when someone else moved it).
  // The server sends complete cameras; a key it left out keeps the default.
  adopt(cam, bounds) {
    if (bounds) this.bounds = bounds;
    if (!cam || this.dragging || !this.defaults) return;
    if (cam.fov_y) this.fov = cam.fov_y;
    if (cam.orbit) {
      this.orbit = { ...this.defaults.orbit, ...cam.orbit };
      this.pan = [0, 0, 0];
    } else if (cam.eye && cam.target && this.bounds) {
      const c = this.centre(), r = this.radius();
      const d = cam.eye.map((e, i) => e - cam.target[i]);
      const len = Math.hypot(...d) || 1;
      this.orbit = {
        azimuth: Math.atan2(d[0], d[2]) / DEG,
        elevation: Math.asin(Math.max(-1, Math.min(1, d[1] / len))) / DEG,
        distance: len / r,
      };
      this.pan = cam.target.map((t, i) => t - c[i]);
    }
  }

  // The camera for a newly chosen dataset: the same viewing direction, the
  // default distance, no pan (an eye/target of another dataset's coordinates
  // would put the view anywhere). Taken over locally at once.
  framed() {
    if (!this.orbit || !this.defaults) return null;
    this.orbit = { ...this.orbit, distance: this.defaults.orbit.distance };
    this.pan = [0, 0, 0];
    return { orbit: { ...this.orbit }, fov_y: this.fov };
  }

  centre() {
    const [lo, hi] = this.bounds;
    return lo.map((l, i) => (l + hi[i]) / 2);
  }

  radius() {
    const [lo, hi] = this.bounds;
    const r = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2;
    return r > 0 ? r : 1;
  }

  // The camera object of the protocol (proto/scene.md): orbit form unless panned.
  cameraObject() {
    const panned = this.pan.some((p) => p !== 0);
    if (!panned || !this.bounds) {
      return { orbit: { ...this.orbit }, fov_y: this.fov };
    }
    const c = this.centre(), r = this.radius();
    const az = this.orbit.azimuth * DEG, el = this.orbit.elevation * DEG;
    const dir = [Math.cos(el) * Math.sin(az), Math.sin(el), Math.cos(el) * Math.cos(az)];
    const target = c.map((x, i) => x + this.pan[i]);
    const eye = target.map((t, i) => t + dir[i] * this.orbit.distance * r);
    return { eye, target, up: [0, 1, 0], fov_y: this.fov };
  }

  emit(phase) {
    if (phase === 'move') {
      this.pending = true;
      const now = performance.now();
      const wait = 33 - (now - this.lastSent);
      if (wait <= 0) {
        this.flush();
      } else if (!this.timer) {
        this.timer = setTimeout(() => { this.timer = null; this.flush(); }, wait);
      }
      return;
    }
    if (this.timer) { clearTimeout(this.timer); this.timer = null; }
    this.pending = null;
    this.lastSent = performance.now();
    this.send(phase, this.cameraObject());
  }

  flush() {
    if (!this.pending) return;
    this.pending = null;
    this.lastSent = performance.now();
    this.send('move', this.cameraObject());
  }

  rotate(dx, dy) {
    this.orbit.azimuth -= dx * 0.4;
    const lim = this.maxElevation;
    this.orbit.elevation = Math.max(-lim, Math.min(lim, this.orbit.elevation + dy * 0.4));
  }

  panBy(dx, dy) {
    if (!this.bounds) return;
    const r = this.radius() * this.orbit.distance;
    const s = (2 * r * Math.tan(this.fov * DEG / 2)) / this.canvas.clientHeight;
    const az = this.orbit.azimuth * DEG, el = this.orbit.elevation * DEG;
    const right = [Math.cos(az), 0, -Math.sin(az)];
    const up = [-Math.sin(el) * Math.sin(az), Math.cos(el), -Math.sin(el) * Math.cos(az)];
    for (let i = 0; i < 3; i++) this.pan[i] += (-dx * right[i] + dy * up[i]) * s;
  }

  zoom(factor) {
    this.orbit.distance = Math.max(0.05, Math.min(100, this.orbit.distance * factor));
  }

  attach() {
    const cv = this.canvas;
    cv.style.touchAction = 'none';
    cv.addEventListener('contextmenu', (e) => e.preventDefault());
    cv.addEventListener('pointerdown', (e) => {
      if (!this.enabled || !this.orbit) return;
      cv.setPointerCapture(e.pointerId);
      this.pointers.set(e.pointerId, { x: e.clientX, y: e.clientY, button: e.button, shift: e.shiftKey });
      if (this.pointers.size === 1) { this.dragging = true; this.emit('start'); }
    });
    cv.addEventListener('pointermove', (e) => {
      const p = this.pointers.get(e.pointerId);
      if (!p || !this.enabled || !this.orbit) return;
      const dx = e.clientX - p.x, dy = e.clientY - p.y;
      if (this.pointers.size === 2) {
        const [a, b] = [...this.pointers.values()];
        const before = Math.hypot(a.x - b.x, a.y - b.y);
        p.x = e.clientX; p.y = e.clientY;
        const after = Math.hypot(a.x - b.x, a.y - b.y);
        if (before > 0 && after > 0) this.zoom(before / after);
        this.panBy(dx / 2, dy / 2);
      } else {
        p.x = e.clientX; p.y = e.clientY;
        if (p.button === 2 || p.shift) this.panBy(dx, dy); else this.rotate(dx, dy);
      }
      this.emit('move');
    });
    const up = (e) => {
      if (!this.pointers.delete(e.pointerId)) return;
      if (this.pointers.size === 0) { this.dragging = false; this.emit('end'); }
    };
    cv.addEventListener('pointerup', up);
    cv.addEventListener('pointercancel', up);
    cv.addEventListener('wheel', (e) => {
      if (!this.enabled || !this.orbit) return;
      e.preventDefault();
      this.zoom(Math.exp(e.deltaY * 0.001));
      this.emit('move');
      clearTimeout(this.wheelTimer);
      this.wheelTimer = setTimeout(() => this.emit('end'), 150);
    }, { passive: false });
  }
}
