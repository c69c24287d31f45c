// app.js — the Sightline page: connects (protocol.js), draws frames on the
// canvas with createImageBitmap (interactive frames, smaller, stretched to the
// canvas), acks them, wires camera input (camera.js),
// schema-generated parameter controls (controls.js), dataset/technique
// pickers, views, snapshots, sharing, control requests, camera keyframes
// recorded into a video on the server (flight.js), the progress bar of
// long loads and prepares (progress.js) and the status line (fps, latency,
// size, and the load, prepare, render and encode ms separately).
// The session id and token live in the URL fragment (#session=..&token=..),
// so a reload or a shared link joins the same session (the id also rides in
// the WebSocket URL's query for a balancer, protocol.js).
// window.sightline exposes read-only counters (and the messages the page
// sent, acks aside) for the browser test.

import { Connection } from './protocol.js';
import { CameraControl } from './camera.js';
import { ParamControls } from './controls.js';
import { HeldParams } from './held_params.js';
import { ProgressOverlay } from './progress.js';
import { FlightPanel } from './flight.js';

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const ctx2d = canvas.getContext('2d');
const progress = new ProgressOverlay($('progress'));

const frag = new URLSearchParams(location.hash.slice(1));
const conn = new Connection({
  session: frag.get('session'),
  token: frag.get('token'),
  width: 640,
  height: 480,
});

// Every message but `ack` the page sends, newest 1000 (window.sightline.sent, for the browser test).
const sentLog = [];
{
  const send = conn.send.bind(conn);
  conn.send = (msg) => {
    if (msg.type !== 'ack') { sentLog.push(msg); if (sentLog.length > 1000) sentLog.shift(); }
    return send(msg);
  };
}

const app = {
  state: null,
  techniques: [],
  datasets: [],
  clientId: 0,
  frames: 0,
  lastFrame: null,
  frameTimes: [],
  sentAt: new Map(),   // camera seq -> send time (ms)
  latencyMs: null,
  seq: 0,
  decoding: false,
  pendingFrame: null,
};
window.sightline = {
  get frames() { return app.frames; },
  get lastFrame() { return app.lastFrame; },
  get state() { return app.state; },
  get techniques() { return app.techniques; },
  get datasets() { return app.datasets; },
  get sent() { return sentLog; },
  get clientId() { return app.clientId; },
  get cameraSeq() { return app.seq; },
  get cameraLimits() { return { maxElevation: camera.maxElevation, defaults: camera.defaults }; },
  get stateVersion() { return app.stateVersion; },
  get connected() { return conn.ws?.readyState === WebSocket.OPEN; },
  get wsUrl() { return conn.ws?.url; },
  get progressStage() { return progress.stage; },
  get timings() { return progress.timings; },
  get recording() { return flight.lastJob; },
  get playback() { return flight.lastPlayback; },
};
const flight = new FlightPanel($('flight'), {
  send: (msg) => conn.send(msg),
  token: () => conn.token,
  camera: () => app.state?.camera,
});

const camera = new CameraControl(canvas, (phase, cam) => {
  const seq = ++app.seq;
  app.sentAt.set(seq, performance.now());
  if (app.sentAt.size > 256) app.sentAt.delete(app.sentAt.keys().next().value);
  conn.send({ type: 'camera', seq, phase, camera: cam });
});

$('params').addEventListener('submit', (e) => e.preventDefault());
const held = new HeldParams();   // own edits not yet echoed (held_params.js)
const params = new ParamControls($('params'), (name, value) => {
  held.hold(name, value);
  conn.send({ type: 'set', params: { [name]: value } });
});

function isController() {
  return app.state && app.state.controller === app.clientId;
}

function refreshRole() {
  const ctl = isController();
  $('role').textContent = ctl ? 'controller' : 'viewer';
  $('control').hidden = ctl;
  camera.enabled = ctl;
  params.setEnabled(ctl);
  $('dataset').disabled = !ctl;
  $('technique').disabled = !ctl;
  $('load-view').disabled = !ctl;
  $('save-view').disabled = !ctl;
  flight.setEnabled(ctl);
}

function techniqueByName(name) {
  return app.techniques.find((t) => t.name === name);
}

function datasetByName(name) {
  return app.datasets.find((d) => d.name === name);
}

// The dataset's attribute names, the options of 'attribute' parameters
// (null until the catalog has described the dataset, e.g. a built-in not made yet).
function attributeNames() {
  const names = datasetByName(app.state?.dataset)?.attributes;
  return Array.isArray(names) ? names : null;
}

// What the controls may know of the dataset beyond its attributes.
function datasetContext() {
  const c = datasetByName(app.state?.dataset)?.counts || {};
  const list = (x) => (Array.isArray(x) ? x : null);
  return { valueRange: list(c.value_range), histogram: list(c.histogram), autoOpacity: list(c.auto_opacity),
    autoIsovalue: Number.isFinite(c.auto_isovalue) ? c.auto_isovalue : null };
}

function buildParams() {
  const t = techniqueByName(app.state?.technique);
  if (!t) return;
  params.build(t.params || [], attributeNames(), datasetContext());
  params.update(app.state.params);
}

// The techniques whose dataset_kinds accept a dataset kind, in the server's order.
function techniquesFor(kind) {
  return app.techniques.filter((t) => (t.dataset_kinds || []).includes(kind));
}

// The dataset picker lists the catalog (a dataset no technique renders is
// disabled); the technique picker only the techniques that accept the
// session's dataset. Called again to show the session's choice after a refusal.
function fillPickers() {
  const dsSel = $('dataset'), tSel = $('technique');
  dsSel.replaceChildren(...app.datasets.map((d) => {
    const o = new Option(`${d.name} (${d.kind})`, d.name);
    o.title = d.description || (d.source === 'file' ? `file, ${d.file_size ?? '?'} bytes` : 'generated');
    if (!techniquesFor(d.kind).length) {
      o.disabled = true;
      o.title = `no technique renders ${d.kind} datasets`;
    }
    return o;
  }));
  const kind = datasetByName(app.state?.dataset)?.kind;
  tSel.replaceChildren(...app.techniques
    .filter((t) => !kind || (t.dataset_kinds || []).includes(kind))
    .map((t) => { const o = new Option(t.name, t.name); o.title = t.description || ''; return o; }));
  if (app.state) { dsSel.value = app.state.dataset; tSel.value = app.state.technique; }
}

function applyState(patch) {
  const techniqueChanged = patch.technique && patch.technique !== app.state?.technique;
  const datasetChanged = patch.dataset && patch.dataset !== app.state?.dataset;
  app.state = { ...(app.state || {}), ...patch };
  if (techniqueChanged || datasetChanged || !isController()) held.release();
  if (techniqueChanged || datasetChanged || !params.inputs.size) buildParams();
  else params.update(held.shown(app.state.params));
  // A dataset just loaded (new bounds) that the catalog had not described
  // yet (or described before it kept histograms): ask again, so its attribute
  // names and histogram reach the controls.
  const listed = datasetByName(app.state.dataset);
  if ('bounds' in patch && (!Array.isArray(listed?.attributes) || (listed?.kind === 'volume' && !listed?.counts?.histogram))) {
    conn.send({ type: 'list_datasets' });
  }
  if (techniqueChanged || datasetChanged) fillPickers();
  // The controller's own camera is authoritative locally; it adopts only
  // cameras it did not send (scene, load_view) and new bounds.
  if ('camera' in patch && (!isController() || !('camera_seq' in patch))) camera.adopt(patch.camera, app.state.bounds || null);
  else if ('bounds' in patch) camera.adopt(null, app.state.bounds || null);
  refreshRole();
}

function setBanner(text) {
  const b = $('banner');
  b.textContent = text || '';
  b.hidden = !text;
}

function updateShareLink() {
  const url = new URL(location.href);
  url.hash = `session=${encodeURIComponent(conn.session)}&token=${encodeURIComponent(conn.token)}`;
  history.replaceState(null, '', url);
  $('share-link').value = url.toString();
}

// The scale an interactive frame used (the server picks it, proto/PROTOCOL.md):
// its width over the session's, as 1/2, 1/4 ... when it is one of those.
function scaleLabel(width) {
  const full = app.state?.width;
  if (!full) return '';
  const s = width / full;
  const k = Math.round(Math.log2(1 / s));
  return Math.abs(s * 2 ** k - 1) < 0.02 ? (k ? `1/${2 ** k}` : '1') : s.toFixed(2);
}

function updateStatus() {
  const f = app.lastFrame;
  const now = performance.now();
  app.frameTimes = app.frameTimes.filter((t) => now - t < 1000);
  const parts = [`${app.frameTimes.length} fps`];
  if (app.latencyMs !== null) parts.push(`latency ${app.latencyMs.toFixed(0)} ms`);
  if (f) {
    parts.push(`${f.width}×${f.height} ${(f.bytes / 1024).toFixed(1)} KiB`);
    const t = progress.timings;
    if (t) parts.push(`load ${t.loadMs.toFixed(0)} ms`, `prepare ${t.prepareMs.toFixed(0)} ms`);
    if (t && t.backend) parts.push(`backend ${t.backend}`);
    parts.push(`render ${f.renderMs.toFixed(1)} ms`, `encode ${f.encodeMs.toFixed(1)} ms`);
    parts.push(f.interactive ? `interactive ${scaleLabel(f.width)}` : 'still');
    parts.push(`frame ${f.frameId}`);
  }
  $('status').textContent = parts.join(' · ');
}
setInterval(updateStatus, 500);

// Draws the newest frame; frames arriving during a decode replace each other (newest wins).
async function drawFrame(header, payload) {
  if (app.decoding) { app.pendingFrame = { header, payload }; return; }
  app.decoding = true;
  try {
    const bitmap = await createImageBitmap(new Blob([payload], { type: 'image/jpeg' }));
    if (app.state) {
      if (canvas.width !== app.state.width || canvas.height !== app.state.height) {
        canvas.width = app.state.width;
        canvas.height = app.state.height;
      }
    }
    ctx2d.imageSmoothingEnabled = true;
    ctx2d.drawImage(bitmap, 0, 0, canvas.width, canvas.height);
    bitmap.close();
    app.frames++;
    app.frameTimes.push(performance.now());
    app.lastFrame = { ...header, bytes: payload.byteLength };
    const sent = app.sentAt.get(header.cameraSeq);
    if (sent !== undefined) {
      app.latencyMs = performance.now() - sent;
      app.sentAt.delete(header.cameraSeq);
    }
    updateStatus();
  } catch (e) {
    console.warn('frame decode failed', e);
  } finally {
    app.decoding = false;
    conn.send({ type: 'ack', frame: header.frameId });
    if (app.pendingFrame) {
      const next = app.pendingFrame;
      app.pendingFrame = null;
      drawFrame(next.header, next.payload);
    }
  }
}

function downloadSnapshot(payload) {
  const url = URL.createObjectURL(new Blob([payload], { type: 'image/png' }));
  const a = document.createElement('a');
  a.href = url;
  a.download = `sightline-${app.state?.dataset || 'view'}-${Date.now()}.png`;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

conn.addEventListener('message', (ev) => {
  const msg = ev.detail;
  switch (msg.type) {
    case 'welcome':
      app.clientId = msg.client;
      app.techniques = msg.techniques || [];
      app.datasets = msg.datasets || [];
      app.state = null;
      held.release();
      params.schemaKey = '';
      camera.configure(msg.camera_default, msg.limits.max_elevation);
      applyState(msg.state);
      app.stateVersion = msg.state.version;
      fillPickers();
      camera.adopt(msg.state.camera, msg.state.bounds || null);
      updateShareLink();
      setBanner('');
      progress.hide();
      conn.send({ type: 'list_views' });
      conn.send({ type: 'list_paths' });
      break;
    case 'state':
      applyState(msg.patch || {});
      app.stateVersion = msg.version;
      break;
    case 'datasets':
      app.datasets = msg.datasets || [];
      fillPickers();
      buildParams();
      break;
    case 'views':
      $('views').replaceChildren(...(msg.views || []).map((v) => new Option(`${v.name} — ${v.dataset}/${v.technique}`, v.name)));
      break;
    case 'view_saved':
      conn.send({ type: 'list_views' });
      break;
    case 'control_request': {
      $('requests').hidden = false;
      const b = document.createElement('button');
      b.type = 'button';
      b.textContent = `Grant control to client ${msg.client}`;
      b.addEventListener('click', () => {
        conn.send({ type: 'control', action: 'grant', client: msg.client });
        b.remove();
        if (!$('request-list').children.length) $('requests').hidden = true;
      });
      $('request-list').append(b);
      break;
    }
    case 'progress':
      progress.update(msg);
      break;
    case 'recording':
      flight.update(msg);
      break;
    case 'playback':
      flight.playback(msg);
      break;
    case 'paths':
      flight.listed(msg.paths || []);
      break;
    case 'path_saved':
      conn.send({ type: 'list_paths' });
      break;
    case 'path':
      flight.loaded(msg);
      break;
    case 'error':
      if (msg.code === 'draining') {   // this node is shutting down; the connection retries (protocol.js)
        setBanner('This server is shutting down — reconnecting to another one…');
        break;
      }
      if (msg.code === 'load_failed') progress.hide();
      if (held.size) {   // a refused set: show the server's values again
        held.release();
        if (app.state?.params) params.update(app.state.params);
      }
      if (msg.field === 'dataset' || msg.field === 'technique') fillPickers();   // back to the session's pair
      setBanner(`${msg.code}: ${msg.message}${msg.field ? ` (${msg.field})` : ''}`);
      setTimeout(() => { if ($('banner').textContent.startsWith(msg.code)) setBanner(''); }, 4000);
      break;
    default:
      break;
  }
});

conn.addEventListener('frame', (ev) => {
  const { header, payload } = ev.detail;
  if (header.kind === 'png') downloadSnapshot(payload);
  else drawFrame(header, payload);
});

conn.addEventListener('disconnect', () => {
  setBanner('Disconnected from the server — reconnecting to the same session…');
});

// A dataset of a kind the current technique does not render brings the
// first technique that does, in the same scene message: the server never
// sees an unfit pair from the page. The new dataset is framed: same viewing
// direction, default distance, no pan (camera.framed).
$('dataset').addEventListener('change', (e) => {
  const kind = datasetByName(e.target.value)?.kind;
  const current = techniqueByName(app.state?.technique);
  const msg = { type: 'scene', dataset: e.target.value };
  const framed = camera.framed();
  if (framed) msg.camera = framed;
  if (kind && !(current?.dataset_kinds || []).includes(kind)) {
    const t = techniquesFor(kind)[0];
    if (!t) { fillPickers(); setBanner(`no technique renders ${kind} datasets`); return; }
    msg.technique = t.name;
  }
  conn.send(msg);
});
$('technique').addEventListener('change', (e) => conn.send({ type: 'scene', technique: e.target.value }));
$('control').addEventListener('click', () => conn.send({ type: 'control', action: 'request' }));
$('snapshot').addEventListener('click', () => conn.send({ type: 'snapshot' }));
$('save-view').addEventListener('click', () => {
  const name = $('view-name').value.trim();
  if (name) conn.send({ type: 'save_view', name });
});
$('load-view').addEventListener('click', () => {
  const name = $('views').value;
  if (name) conn.send({ type: 'load_view', name });
});
$('share').addEventListener('click', async () => {
  updateShareLink();
  const link = $('share-link').value;
  try {
    await navigator.clipboard.writeText(link);
    setBanner('Share link copied');
  } catch {
    $('share-link').select();
    setBanner('Copy the share link from the field');
  }
  setTimeout(() => setBanner(''), 2000);
});

// Keep the session's image size matched to the stage (controller only), debounced.
let resizeTimer = null;
new ResizeObserver(() => {
  clearTimeout(resizeTimer);
  resizeTimer = setTimeout(() => {
    if (!isController()) return;
    const stage = $('stage');
    // Even sizes: a recording's video (4:2:0 colour) needs them.
    const w = Math.max(64, Math.min(1920, Math.round(stage.clientWidth))) & ~1;
    const h = Math.max(48, Math.min(1080, Math.round(stage.clientHeight))) & ~1;
    if (app.state && (w !== app.state.width || h !== app.state.height)) conn.send({ type: 'resize', width: w, height: h });
  }, 250);
}).observe($('stage'));

{
  const stage = $('stage');
  conn.width = Math.max(64, Math.min(1920, Math.round(stage.clientWidth || 640))) & ~1;
  conn.height = Math.max(48, Math.min(1080, Math.round(stage.clientHeight || 480))) & ~1;
}
conn.open();
