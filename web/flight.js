// flight.js — the page's "Flight" panel: camera keyframes, played live in the
// session, scrubbed on a timeline and recorded into a video on the server
// (`play_path`, `play_stop`, `path_seek`, `playback`, `record`, `recording`:
// proto/PROTOCOL.md "Playback" and "Recordings"; paths as in proto/scene.md).
// "Add view" appends the session's current camera as a keyframe, `step`
// seconds after the last one; each key's time can be edited, the key moved
// up or down, or deleted. Moving a key swaps its camera with its neighbour's
// and leaves the times where they were (times belong to the positions), so
// the path stays in ascending time. The timeline spans [0, last key's t]:
// dragging it sends `path_seek` (throttled) and the server sets the session's
// camera to the path at that t; Play/Stop send `play_path` / `play_stop`, and
// every client's timeline follows the `playback` messages. Paths are saved in
// the server's catalog by name (`save_path`; `list_paths`, `load_path` bring
// one back as keyframes, its fps too). Interpolation
// happens on the server only (renderer/core/camera_path.c), so there is no
// second copy of it here. Sends nothing unless a control is used.

import { throttle } from './throttle.js';

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
    this.interpolation = 'smooth'; // a loaded path's, else smooth
    this.list = root.querySelector('.keys');
    this.status = root.querySelector('.record-status');
    this.link = root.querySelector('.record-link');
    this.lastJob = null;        // the newest `recording` message
    this.lastPlayback = null;   // the newest `playback` message
    this.timeline = root.querySelector('.timeline');
    this.time = root.querySelector('.time');
    this.playStatus = root.querySelector('.play-status');
    this.seekAt = 0;
    const seek = throttle(() => {
      const path = this.path();
      if (path) this.send({ type: 'path_seek', path, t: this.seekAt });
    }, 50);
    this.timeline.addEventListener('input', () => { this.seekAt = Number(this.timeline.value); this.showTime(this.seekAt); seek(); });
    this.timeline.addEventListener('change', () => { this.seekAt = Number(this.timeline.value); seek(true); });
    root.querySelector('.play').addEventListener('click', () => this.play());
    root.querySelector('.stop').addEventListener('click', () => this.send({ type: 'play_stop' }));
    root.querySelector('.save-path').addEventListener('click', () => {
      const name = root.querySelector('.path-name').value.trim();
      const path = this.path();
      if (!name || !path) { this.playStatus.textContent = 'a path needs a name and two keyframes'; return; }
      this.send({ type: 'save_path', name, path });
    });
    root.querySelector('.load-path').addEventListener('click', () => {
      const name = root.querySelector('.paths').value;
      if (name) this.send({ type: 'load_path', name });
    });
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
    return { fps, interpolation: this.interpolation,
      keyframes: keys.map((k) => ({ t: k.t, camera: k.camera, ...(k.params ? { params: k.params } : {}) })) };
  }

  play() {
    const path = this.path();
    if (!path) { this.playStatus.textContent = 'add at least two keyframes'; return; }
    this.send({ type: 'play_path', path, loop: this.root.querySelector('.loop').checked });
  }

  duration() {
    return this.keys.length ? Math.max(...this.keys.map((k) => k.t)) : 0;
  }

  showTime(t) {
    this.time.textContent = `${t.toFixed(2)} / ${this.duration().toFixed(2)} s`;
  }

  // A `playback` message (any client of the session may have started it).
  playback(msg) {
    this.lastPlayback = msg;
    this.timeline.max = String(Math.max(this.duration(), msg.duration));
    this.timeline.value = String(msg.t);
    this.time.textContent = `${msg.t.toFixed(2)} / ${msg.duration.toFixed(2)} s`;
    this.playStatus.textContent = msg.state === 'playing' ? `playing frame ${msg.frame + 1} of ${msg.frames}`
      : `stopped (${msg.reason})`;
  }

  // Viewers watch a playing path (their timeline follows it) but cannot play,
  // stop, seek, record or save one: the server would refuse it.
  setEnabled(on) {
    for (const sel of ['.play', '.stop', '.timeline', '.record', '.record-cancel', '.save-path']) {
      this.root.querySelector(sel).disabled = !on;
    }
  }

  // A `paths` reply: the catalog's saved paths.
  listed(paths) {
    this.root.querySelector('.paths').replaceChildren(
      ...paths.map((p) => new Option(`${p.name} — ${p.keys} keys, ${p.duration} s`, p.name)));
  }

  // A `path` reply: the saved path becomes the keyframes (times, cameras; keyed params are kept).
  loaded(msg) {
    this.keys = msg.path.keyframes.map((k) => ({ t: k.t, camera: k.camera, ...(k.params ? { params: k.params } : {}) }));
    this.root.querySelector('.fps').value = String(msg.path.fps);
    this.interpolation = msg.path.interpolation || 'smooth';
    this.playStatus.textContent = `loaded path ${msg.name}`;
    this.render();
  }

  // Swaps the cameras of keys i and j; the times stay with the positions.
  move(i, j) {
    if (j < 0 || j >= this.keys.length) return;
    const a = this.keys[i], b = this.keys[j];
    [a.camera, b.camera] = [b.camera, a.camera];
    [a.params, b.params] = [b.params, a.params];
    this.render();
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
      t.addEventListener('change', () => { k.t = Math.max(0, Number(t.value) || 0); this.render(); });
      const up = document.createElement('button');
      up.type = 'button';
      up.className = 'up';
      up.textContent = '↑';
      up.title = 'move this view one key earlier (times stay in place)';
      up.addEventListener('click', () => this.move(i, i - 1));
      const down = document.createElement('button');
      down.type = 'button';
      down.className = 'down';
      down.textContent = '↓';
      down.title = 'move this view one key later (times stay in place)';
      down.addEventListener('click', () => this.move(i, i + 1));
      const del = document.createElement('button');
      del.type = 'button';
      del.textContent = '×';
      del.title = 'delete this keyframe';
      del.className = 'del';
      del.addEventListener('click', () => { this.keys.splice(i, 1); this.render(); });
      row.append(label, t, up, down, del);
      return row;
    });
    this.list.replaceChildren(...rows);
    this.timeline.max = String(this.duration());
    this.showTime(Math.min(Number(this.timeline.value), this.duration()));
  }
}
