// flight.js — the page's "Flight" panel: camera keyframes and recording them
// into a video on the server (`record`, `recording`, proto/PROTOCOL.md
// "Recordings"; paths as in proto/scene.md "Paths").
// "Add view" appends the session's current camera as a keyframe, `step`
// seconds after the last one; each key's time can be edited or the key
// deleted; "Record" sends the keys as a smooth path at the chosen frame rate
// and format. Every client of the session sees the job's progress; when it is
// done the panel offers the one-time download link (the session token in its
// query). Interpolation happens on the server only (renderer/core
// camera_path.c), so there is no second copy of it here. Sends nothing
// unless a button is used.

export class FlightPanel {
  // root: the panel's section; send(msg): the connection's send; token(): the session token;
  // camera(): the session's current camera object (state.camera).
  constructor(root, { send, token, camera }) {
    this.root = root;
    this.send = send;
    this.token = token;
    this.camera = camera;
    this.keys = [];             // {t, camera}
    this.step = 2;              // seconds between a new key and the last
    this.list = root.querySelector('.keys');
    this.status = root.querySelector('.record-status');
    this.link = root.querySelector('.record-link');
    this.lastJob = null;        // the newest `recording` message
    root.querySelector('.add-key').addEventListener('click', () => this.addKey());
    root.querySelector('.clear-keys').addEventListener('click', () => { this.keys = []; this.render(); });
    root.querySelector('.record').addEventListener('click', () => this.record());
    root.querySelector('.record-cancel').addEventListener('click', () => this.send({ type: 'record_cancel' }));
    this.render();
  }

  addKey() {
    const cam = this.camera();
    if (!cam) return;
    const t = this.keys.length ? this.keys[this.keys.length - 1].t + this.step : 0;
    this.keys.push({ t, camera: JSON.parse(JSON.stringify(cam)) });
    this.render();
  }

  // The path of scene.md from the keys (sorted by time), or null with fewer than two.
  path() {
    const keys = [...this.keys].sort((a, b) => a.t - b.t);
    if (keys.length < 2) return null;
    const fps = Number(this.root.querySelector('.fps').value) || 24;
    return { fps, interpolation: 'smooth', keyframes: keys.map((k) => ({ t: k.t, camera: k.camera })) };
  }

  record() {
    const path = this.path();
    if (!path) { this.status.textContent = 'add at least two keyframes'; return; }
    this.send({ type: 'record', path, format: this.root.querySelector('.format').value });
  }

  // A `recording` message from the server (any client of the session may have started the job).
  update(msg) {
    this.lastJob = msg;
    const n = `${msg.frame ?? 0} of ${msg.frames} frames`;
    const texts = {
      queued: `job ${msg.id}: queued (${msg.frames} frames)`,
      running: `job ${msg.id}: ${n}, about ${Math.round(msg.eta_s ?? 0)} s left`,
      done: `job ${msg.id}: done, ${msg.frames} frames, ${(msg.seconds ?? 0).toFixed(1)} s of ${msg.codec}, ${Math.round((msg.bytes ?? 0) / 1024)} KiB`,
      cancelled: `job ${msg.id}: cancelled`,
      failed: `job ${msg.id}: failed — ${msg.message ?? ''}`,
    };
    this.status.textContent = texts[msg.state] || msg.state;
    this.link.hidden = msg.state !== 'done';
    if (msg.state === 'done') {
      this.link.href = `${msg.url}?token=${encodeURIComponent(this.token())}`;
      this.link.download = `sightline-${msg.id}.${msg.codec === 'VP9' ? 'webm' : 'mp4'}`;
    }
  }

  render() {
    const rows = this.keys.map((k, i) => {
      const row = document.createElement('div');
      row.className = 'row key';
      const label = document.createElement('span');
      label.textContent = `${i + 1}`;
      const t = document.createElement('input');
      t.type = 'number';
      t.min = '0';
      t.step = '0.5';
      t.value = String(k.t);
      t.title = 'time of this keyframe, seconds';
      t.addEventListener('change', () => { k.t = Math.max(0, Number(t.value) || 0); });
      const del = document.createElement('button');
      del.type = 'button';
      del.textContent = '×';
      del.title = 'delete this keyframe';
      del.addEventListener('click', () => { this.keys.splice(i, 1); this.render(); });
      row.append(label, t, del);
      return row;
    });
    this.list.replaceChildren(...rows);
  }
}
