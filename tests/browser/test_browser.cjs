// test_browser.cjs — end-to-end: Debian's Chromium (headless, playwright-core)
// against a private sightline-server on a free loopback port.
//
// Loads the page and sees a still frame with something drawn; drags the
// canvas and sees a new frame showing the new camera (pixels differ); orbits
// up to the elevation limit the server sent (and the server accepts it);
// changes a parameter through its generated control and sees the session
// state and a newer frame; opens the share link in a second page, which
// joins as a viewer and shows the same frame id with identical pixels.
// Every control kind is driven as a user would (click, select, keys, typing)
// and the value that reached the server is read back by an observer: a raw
// WebSocket that joins the session on its own (no app.js) and reads the
// server's full state from `welcome`, polled until it holds the expected
// value (so a wrong value sent by the page times out and fails): checkbox,
// enum, int and float sliders, vec3 fields (clamped to the schema range), a
// colour input (vec3 with unit "rgb"), number fields for ranges too wide for
// a slider, attribute selects (built from the schema type alone; also
// checked on a synthetic schema), "sets" check boxes, value lists and 2D
// transfer functions (on a synthetic schema: no technique uses them yet), technique and dataset pickers (the
// technique picker lists only what renders the dataset's kind; picking a
// volume switches to the first volume technique in one scene message and a
// volume frame arrives), the transfer-function editor (a dragged opacity
// point, throttled; a point's colour; a colormap preset), the 2D curvature
// editor of particles (tf2d_editor.js: its JS rule against the C bake at
// five points, a dragged widget, a resized one, one added and deleted, and
// the new frame), "load view" (the saved view's dataset, technique, params
// and camera come back), and control hand-over to the second page (request,
// grant, the new controller's change reaches the server, the old one's
// controls are disabled), the Flight panel (two keys recorded into a video
// fetched once; Play: `playback` playing then stopped at the end, the frame
// id advancing and the camera on the last key; a drag of the timeline puts
// the server's camera between the keys; the keys saved by name, cleared and
// loaded back). Screenshots go to <source>/build/ (CI artifact).
// Prints "N passed, N failed".
'use strict';

const { chromium } = require('playwright-core');
const { spawn, execFileSync } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

const SRC = process.env.SIGHTLINE_SOURCE_DIR || path.resolve(__dirname, '../..');
const BIN = process.env.SIGHTLINE_BINARY_DIR || path.join(SRC, 'build');
const SERVER = path.join(BIN, 'bin', 'sightline-server');
const TINY = '{"generator":"tornado","lines":40,"points":40,"seed":3}';
const TINY2 = '{"generator":"abc","lines":30,"points":40,"seed":2}';
const T = 30000;
const ARTIFACTS = path.join(SRC, 'build');

let passed = 0, failed = 0;
function check(cond, what) {
  if (cond) passed++;
  else { failed++; console.error(`check failed: ${what}`); }
}

function startServer(dir, port = 0) {
  const db = path.join(dir, 'catalog.db');
  const data = path.join(dir, 'data');
  if (!fs.existsSync(data)) {
    fs.mkdirSync(data);
    execFileSync(SERVER, ['catalog', 'add-generator', 'tiny', TINY, '--db', db, '--data-dir', data], { stdio: 'ignore' });
    execFileSync(SERVER, ['catalog', 'add-generator', 'tiny2', TINY2, '--db', db, '--data-dir', data], { stdio: 'ignore' });
    // The MRI sample, when fetched: <data-dir>/samples is registered at start.
    const mri = path.join(SRC, 'data', 'samples', 'ch2.nii.gz');
    if (fs.existsSync(mri)) {
      fs.mkdirSync(path.join(data, 'samples'));
      fs.copyFileSync(mri, path.join(data, 'samples', 'ch2.nii.gz'));
    }
  }
  const proc = spawn(SERVER, ['--port', String(port), '--db', db, '--data-dir', data, '--web-dir', path.join(SRC, 'web'),
    '--default-dataset', 'tiny'], { stdio: ['ignore', 'pipe', 'inherit'] });
  return new Promise((resolve, reject) => {
    let out = '';
    const timer = setTimeout(() => reject(new Error(`server did not start: ${out}`)), 60000);
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/listening on http:\/\/127\.0\.0\.1:(\d+)\//);
      if (m) { clearTimeout(timer); resolve({ proc, port: Number(m[1]) }); }
    });
    proc.on('exit', (code) => reject(new Error(`server exited ${code}: ${out}`)));
  });
}

// FNV-1a hash of the canvas pixels and the fraction that differs from the corner pixel.
function canvasStats(page) {
  return page.evaluate(() => {
    const c = document.getElementById('view');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let h = 0x811c9dc5, fg = 0;
    for (let i = 0; i < d.length; i++) { h ^= d[i]; h = Math.imul(h, 0x01000193) >>> 0; }
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - d[0]) > 24 || Math.abs(d[i + 1] - d[1]) > 24 || Math.abs(d[i + 2] - d[2]) > 24) fg++;
    }
    return { hash: h, fg: fg / (d.length / 4), width: c.width, height: c.height, pixels: Array.from(d.slice(0, 4096)) };
  });
}

// The session's state as the server holds it: a raw WebSocket in the observer
// page joins the session (hello with id and token), takes `welcome` (state
// and the catalog's datasets) and closes. Independent of app.js.
function observeWelcome(obs, session, token) {
  return obs.evaluate(([sid, tok]) => new Promise((resolve, reject) => {
    const ws = new WebSocket(`ws://${location.host}/ws`, 'sightline.v1');
    const timer = setTimeout(() => { ws.close(); reject(new Error('observer: no welcome in 10 s')); }, 10000);
    ws.onopen = () => ws.send(JSON.stringify({ type: 'hello', version: 1, session: sid, token: tok }));
    ws.onmessage = (ev) => {
      if (typeof ev.data !== 'string') return;
      const m = JSON.parse(ev.data);
      if (m.type !== 'welcome' && m.type !== 'error') return;
      clearTimeout(timer);
      ws.close();
      if (m.type === 'welcome') resolve({ state: m.state, datasets: m.datasets });
      else reject(new Error(`observer: ${m.code}: ${m.message}`));
    };
    ws.onerror = () => { clearTimeout(timer); reject(new Error('observer: WebSocket error')); };
  }), [session, token]);
}

async function observeOnce(obs, session, token) {
  return (await observeWelcome(obs, session, token)).state;
}

// Polls the server's state until pred(state) holds (then returns it) or
// `ms` pass (then returns null and the last state is printed). With
// sess.page, it also waits until that page has received the state patches up
// to the matched version: the page's editors show the echo of what they sent,
// so the next click acts on what the server holds (patches to a client are
// written between frames, which lag on a busy machine), not on an older echo.
async function serverStateWhere(obs, sess, pred, what, ms = 15000) {
  const deadline = Date.now() + ms;
  let st = null;
  for (;;) {
    st = await observeOnce(obs, sess.session, sess.token);
    if (pred(st)) {
      if (sess.page && !sess.page.isClosed()) {
        await sess.page.waitForFunction((v) => window.sightline.stateVersion >= v, st.version, { timeout: T });
      }
      return st;
    }
    if (Date.now() > deadline) break;
    await new Promise((r) => setTimeout(r, 150));
  }
  console.error(`${what}: server state never matched; last: ${JSON.stringify({ dataset: st.dataset,
    technique: st.technique, params: st.params, controller: st.controller })}`);
  return null;
}

// Waits until the page shows a still frame of its newest state version.
function settled(page) {
  return page.waitForFunction(() => window.sightline.lastFrame && !window.sightline.lastFrame.interactive &&
    window.sightline.lastFrame.stateVersion >= window.sightline.stateVersion, null, { timeout: T });
}

const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);

// Every control kind through the page, each value read back from the server.
async function driveControls(page, obs, sess, saved) {
  const schemaOf = (name) => page.evaluate((n) => window.sightline.techniques.find((t) => t.name === n).params, name);
  const banner = async () => ((await page.isHidden('#banner')) ? '' : page.textContent('#banner'));
  let schema = await schemaOf('tubes_mesh');
  let st = await observeOnce(obs, sess.session, sess.token);
  check(st.technique === 'tubes_mesh' && st.dataset === 'tiny', `starts on tiny/tubes_mesh (${st.dataset}/${st.technique})`);

  // Checkbox: a click flips the bool on the server.
  const bool = schema.find((d) => d.type === 'bool');
  const was = st.params[bool.name];
  await page.click(`#params input[type=checkbox][name=${bool.name}]`);
  check(await serverStateWhere(obs, sess, (s) => s.params[bool.name] === !was, `checkbox ${bool.name}`),
    `checkbox ${bool.name}: ${was} -> ${!was} on the server`);

  // Enum: a choice picked in the select is the server's value.
  const en = schema.find((d) => d.type === 'enum');
  const choice = en.choices.find((c) => c !== st.params[en.name] && c !== en.default) || en.choices[0];
  await page.selectOption(`#params select[name=${en.name}]`, choice);
  check(await serverStateWhere(obs, sess, (s) => s.params[en.name] === choice, `enum ${en.name}`),
    `enum ${en.name} = ${choice} on the server`);

  // Int slider by keyboard: End, then one step down = max - 1.
  const int = schema.find((d) => d.type === 'int');
  await page.focus(`#params input[type=range][name=${int.name}]`);
  await page.keyboard.press('End');
  await page.keyboard.press('ArrowLeft');
  check(await serverStateWhere(obs, sess, (s) => s.params[int.name] === int.max - 1, `int slider ${int.name}`),
    `int slider ${int.name} = ${int.max - 1} (max - 1) on the server`);
  // Float slider (linear scale) by keyboard: Home = min exactly.
  const log = (d) => d.min >= 0 && d.max > 1000 * Math.max(d.min, 1e-6);
  const flt = schema.find((d) => d.type === 'float' && !log(d) && d.max - d.min <= 1e6 && d.default !== d.min);
  await page.focus(`#params input[type=range][name=${flt.name}]`);
  await page.keyboard.press('Home');
  check(await serverStateWhere(obs, sess, (s) => s.params[flt.name] === flt.min, `float slider ${flt.name}`),
    `float slider ${flt.name} = ${flt.min} (min) on the server`);

  // Vector (not a colour): three typed components, each committed with Tab;
  // a component beyond the schema's range is clamped to it before it is sent.
  const vec = schema.find((d) => d.type === 'vec3' && d.unit !== 'rgb' && d.min <= 0.25 && d.max >= 0.75);
  const want = [0.25, 0.5, 0.75];
  const fields = page.locator(`#params input.vec[name=${vec.name}]`);
  check((await fields.count()) === 3, `vec3 ${vec.name} has three fields`);
  for (let k = 0; k < 3; k++) {
    await fields.nth(k).fill(String(want[k]));
    await fields.nth(k).press('Tab');
  }
  check(await serverStateWhere(obs, sess, (s) => same(s.params[vec.name], want), `vec3 ${vec.name}`),
    `vec3 ${vec.name} = ${JSON.stringify(want)} on the server`);
  await fields.nth(0).fill(String(vec.max + 4));
  await fields.nth(0).press('Tab');
  const clamped = [vec.max, want[1], want[2]];
  check(await serverStateWhere(obs, sess, (s) => same(s.params[vec.name], clamped), `vec3 ${vec.name} clamped`),
    `vec3 ${vec.name} typed ${vec.max + 4} = ${JSON.stringify(clamped)} (clamped) on the server`);

  // Colour (vec3 with unit "rgb"): a native colour input; #336699 reaches the server as 0x33/255 ...
  const rgb = schema.find((d) => d.type === 'vec3' && d.unit === 'rgb');
  check(rgb && (await page.locator(`#params input[type=color][name=${rgb.name}]`).count()) === 1 &&
    (await page.locator(`#params input.vec[name=${rgb.name}]`).count()) === 0, `${rgb && rgb.name} is a colour input`);
  await page.locator(`#params input[type=color][name=${rgb.name}]`).fill('#336699');
  const wantRgb = [0x33 / 255, 0x66 / 255, 0x99 / 255];
  check(await serverStateWhere(obs, sess, (s) => s.params[rgb.name].every((x, k) => Math.abs(x - wantRgb[k]) < 1e-6),
    `colour ${rgb.name}`), `colour ${rgb.name} #336699 = ${JSON.stringify(wantRgb.map((x) => x.toFixed(3)))} on the server`);

  // A range too wide for a slider (max - min > 1e6) is a number field: every such
  // parameter has one and no slider; a typed value reaches the server as typed.
  const wide = schema.filter((d) => (d.type === 'float' || d.type === 'int') && d.max - d.min > 1e6);
  check(wide.length >= 2, `${schema.length} parameters include wide ranges ${wide.map((d) => d.name)}`);
  for (const d of wide) {
    check((await page.locator(`#params input[type=number][name=${d.name}]`).count()) === 1 &&
      (await page.locator(`#params input[type=range][name=${d.name}]`).count()) === 0,
    `${d.name} (${d.min} … ${d.max}) is a number field, not a slider`);
  }
  const num = wide.find((d) => d.type === 'float' && d.min <= 0.0125 && d.max >= 0.0125);
  await page.fill(`#params input[type=number][name=${num.name}]`, '0.0125');
  await page.press(`#params input[type=number][name=${num.name}]`, 'Enter');
  check(await serverStateWhere(obs, sess, (s) => s.params[num.name] === 0.0125, `number ${num.name}`),
    `number field ${num.name} = 0.0125 on the server`);

  // Attribute selects: built for every 'attribute' parameter, listing the
  // dataset's attribute names (from the server's catalog) after "none".
  const names = (await observeWelcome(obs, sess.session, sess.token)).datasets.find((d) => d.name === 'tiny').attributes;
  check(Array.isArray(names) && names.length >= 1, `the server lists tiny's attributes ${JSON.stringify(names)}`);
  const attrParams = schema.filter((d) => d.type === 'attribute');
  check(attrParams.length >= 2, `tubes_mesh has attribute parameters ${attrParams.map((d) => d.name)}`);
  for (const d of attrParams) {
    const opts = await page.$$eval(`#params select[name=${d.name}] option`, (os) => os.map((o) => o.textContent));
    check(same(opts, ['none', ...names]), `${d.name} select lists none + ${JSON.stringify(names)}: ${JSON.stringify(opts)}`);
  }
  await page.selectOption('#params select[name=attribute]', { label: 'none' });
  check(await serverStateWhere(obs, sess, (s) => s.params.attribute === -1, 'attribute none'), 'attribute "none" = -1 on the server');
  await page.selectOption('#params select[name=radius_attribute]', { label: names[names.length - 1] });
  check(await serverStateWhere(obs, sess, (s) => s.params.radius_attribute === names.length - 1, 'radius_attribute'),
    `radius_attribute "${names[names.length - 1]}" = ${names.length - 1} on the server`);
  await page.selectOption('#params select[name=attribute]', { label: names[0] });
  check(await serverStateWhere(obs, sess, (s) => s.params.attribute === 0, 'attribute 0'), `attribute "${names[0]}" = 0 on the server`);
  await settled(page);
  check((await banner()) === '', `no error after the control changes (${await banner()})`);
  await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-controls.png') });

  // ribbons through the page: a control for every parameter of its schema;
  // its own enum (halo_space) and int (twist_lines) reach the server, and
  // its frame arrives without an error.
  await page.selectOption('#technique', 'ribbons');
  st = await serverStateWhere(obs, sess, (s) => s.technique === 'ribbons', 'technique ribbons');
  check(st, 'technique ribbons on the server');
  await page.waitForFunction(() => window.sightline.state.technique === 'ribbons', null, { timeout: T });
  schema = await schemaOf('ribbons');
  const ribbonControls = await page.$$eval('#params label.param span.name', (xs) => xs.map((x) => x.textContent));
  check(same(ribbonControls, schema.map((d) => d.name)),
    `controls follow the ribbons schema (${ribbonControls.length} of ${schema.length})`);
  await page.selectOption('#params select[name=halo_space]', 'screen');
  check(await serverStateWhere(obs, sess, (s) => s.params.halo_space === 'screen', 'halo_space'),
    'ribbons halo_space = screen on the server');
  await page.focus('#params input[type=range][name=twist_lines]');
  await page.keyboard.press('Home');
  for (let k = 0; k < 3; k++) await page.keyboard.press('ArrowRight');
  check(await serverStateWhere(obs, sess, (s) => s.params.twist_lines === 3, 'twist_lines'),
    'ribbons twist_lines = 3 on the server');
  await settled(page);
  check((await banner()) === '', `no error on ribbons (${await banner()})`);
  await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-ribbons.png') });

  // Flight: two keyframes (the view, then the view after a drag), recorded
  // at 4 frames per second into an MP4 on the server; progress reaches the
  // page, the download link fetches the video once (a second fetch is 410).
  await page.click('#flight .add-key');
  // The camera's heading in degrees about +y, for either camera form.
  const heading = () => page.evaluate(() => {
    const c = window.sightline.state?.camera;
    if (!c) return NaN;
    if (c.orbit) return c.orbit.azimuth;
    return Math.atan2(c.eye[0] - c.target[0], c.eye[2] - c.target[2]) * 180 / Math.PI;
  });
  const az0 = await heading();
  const box0 = await page.locator('#view').boundingBox();
  await page.mouse.move(box0.x + box0.width / 2, box0.y + box0.height / 2);
  await page.mouse.down();
  for (let i = 1; i <= 8; i++) await page.mouse.move(box0.x + box0.width / 2 + 12 * i, box0.y + box0.height / 2);
  await page.mouse.up();
  await settled(page);
  await page.click('#flight .add-key');
  check((await page.$$eval('#flight .keys .key', (ks) => ks.length)) === 2, 'two keyframes listed');
  await page.fill('#flight .fps', '4');
  await page.click('#flight .record');
  await page.waitForFunction(() => ['done', 'failed', 'cancelled'].includes(window.sightline.recording?.state), null,
    { timeout: 60000 });
  const job = await page.evaluate(() => window.sightline.recording);
  check(job.state === 'done' && job.frames === 9, `the flight recorded: ${job.state}, ${job.frames} frames (${job.message || ''})`);
  const fetched = await page.evaluate(async () => {
    const href = document.querySelector('#flight .record-link').href;
    const r1 = await fetch(href);
    const body = await r1.arrayBuffer();
    const r2 = await fetch(href);
    return { first: r1.status, type: r1.headers.get('content-type'), bytes: body.byteLength, second: r2.status };
  });
  check(fetched.first === 200 && fetched.type === 'video/mp4' && fetched.bytes > 1000 && fetched.second === 410,
    `the download link: ${JSON.stringify(fetched)}`);
  await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-flight.png') });

  // Play: the server plays the two keys live (2 s at 4 fps); the frame id
  // advances and the session ends on the last key. Then a drag of the
  // timeline to its middle: the server's camera there lies between the keys.
  const az1 = await heading();
  const playFrom = await page.evaluate(() => window.sightline.lastFrame.frameId);
  await page.click('#flight .play');
  await page.waitForFunction(() => window.sightline.playback?.state === 'playing', null, { timeout: 30000 });
  await page.waitForFunction(() => window.sightline.playback?.state === 'stopped', null, { timeout: 30000 });
  await settled(page);
  const played = await page.evaluate(() => ({ pb: window.sightline.playback, frame: window.sightline.lastFrame.frameId }));
  played.az = await heading();
  check(played.pb.reason === 'end' && played.frame >= playFrom + 3 && Math.abs(played.az - az1) < 1e-3,
    `Play: ${JSON.stringify(played.pb)}, frame ${playFrom} -> ${played.frame}, azimuth ${played.az} (last key ${az1})`);
  const tl = await page.locator('#flight .timeline').boundingBox();
  await page.mouse.move(tl.x + 2, tl.y + tl.height / 2);
  await page.mouse.down();
  for (let i = 1; i <= 6; i++) await page.mouse.move(tl.x + 2 + (tl.width / 2 - 2) * i / 6, tl.y + tl.height / 2);
  await page.mouse.up();
  const lo = Math.min(az0, az1), hi = Math.max(az0, az1);
  let azMid = NaN;
  for (let i = 0; i < 150 && !(azMid > lo + 1e-3 && azMid < hi - 1e-3); i++) {
    await page.waitForTimeout(100);
    azMid = await heading();
  }
  const between = azMid > lo + 1e-3 && azMid < hi - 1e-3;
  check(between && Math.abs(az0 - az1) > 1, `timeline drag: azimuth ${azMid} between the keys' ${az0} and ${az1}`);
  await settled(page);

  // The keys saved as a named path in the catalog, cleared, and loaded back.
  await page.fill('#flight .path-name', 'browser flight');
  await page.click('#flight .save-path');
  await page.waitForFunction(() => [...document.querySelectorAll('#flight .paths option')].some((o) => o.value === 'browser flight'),
    null, { timeout: 15000 });
  await page.click('#flight .clear-keys');
  await page.selectOption('#flight .paths', 'browser flight');
  await page.click('#flight .load-path');
  await page.waitForFunction(() => document.querySelectorAll('#flight .keys .key').length === 2, null, { timeout: 15000 })
    .then(() => {}, () => {});
  check((await page.$$eval('#flight .keys .key', (ks) => ks.length)) === 2, 'the saved path loads back as two keyframes');

  // Technique picker: the server switches, the controls follow the new schema.
  const tech = 'tubes';
  await page.selectOption('#technique', tech);
  st = await serverStateWhere(obs, sess, (s) => s.technique === tech, 'technique');
  check(st, `technique ${tech} on the server`);
  await page.waitForFunction((n) => window.sightline.state.technique === n, tech, { timeout: T });
  schema = await schemaOf(tech);
  const shown = await page.$$eval('#params label.param span.name', (xs) => xs.map((x) => x.textContent));
  check(same(shown, schema.map((d) => d.name)), `controls follow the ${tech} schema (${shown.length} of ${schema.length})`);
  check(st && same(Object.keys(st.params).sort(), schema.map((d) => d.name).sort()), `server params are ${tech}'s`);
  await settled(page);

  // Dataset picker: a second catalog entry; its attributes fill the selects.
  await page.selectOption('#dataset', 'tiny2');
  st = await serverStateWhere(obs, sess, (s) => s.dataset === 'tiny2' && Array.isArray(s.bounds), 'dataset');
  check(st && st.technique === tech, `dataset tiny2 on the server, technique kept (${st && st.technique})`);
  await page.waitForFunction(() => window.sightline.state.dataset === 'tiny2', null, { timeout: T });
  await settled(page);
  check((await banner()) === '', `no error after the dataset switch (${await banner()})`);

  // The technique picker offers only what renders the dataset's kind; a
  // dataset of another kind switches to the first technique that accepts it,
  // in one scene message (no error), and a frame of it arrives.
  await volumeScene(page, obs, sess, banner);
  await firstLook(page, obs, sess, banner);
  await particlesTf2d(page, obs, sess, banner);

  // Load view: the saved view's dataset, technique, params and camera return.
  await page.selectOption('#views', saved.name);
  await page.click('#load-view');
  st = await serverStateWhere(obs, sess, (s) => s.dataset === saved.state.dataset && s.technique === saved.state.technique &&
    same(s.params, saved.state.params) && same(s.camera, saved.state.camera), 'load view');
  check(st, `load view "${saved.name}" restored ${saved.state.dataset}/${saved.state.technique}, params and camera`);
  await settled(page);
}

// Pickers that know what fits, a volume frame, and the transfer-function editor.
async function volumeScene(page, obs, sess, banner) {
  const info = await page.evaluate(() => ({ techniques: window.sightline.techniques.map((t) => ({ name: t.name,
    kinds: t.dataset_kinds })), datasets: window.sightline.datasets.map((d) => ({ name: d.name, kind: d.kind })) }));
  const accepting = (kind) => info.techniques.filter((t) => t.kinds.includes(kind)).map((t) => t.name);
  const options = () => page.$$eval('#technique option', (os) => os.map((o) => o.value));
  const lines = accepting('lines'), volume = accepting('volume');
  check(lines.length && volume.length && !lines.every((n) => volume.includes(n)), `lines ${lines}, volume ${volume}`);
  check(same(await options(), lines), `on a line set the technique picker offers ${JSON.stringify(await options())}`);
  const vds = info.datasets.find((d) => d.name === 'marschner_lobb') || info.datasets.find((d) => d.kind === 'volume');
  const sentBefore = await page.evaluate(() => window.sightline.sent.length);
  await page.selectOption('#dataset', vds.name);
  const st = await serverStateWhere(obs, sess, (s) => s.dataset === vds.name && Array.isArray(s.bounds), 'volume dataset', 60000);
  check(st && st.technique === volume[0], `${vds.name} brought technique ${volume[0]} (${st && st.technique})`);
  const scenes = await page.evaluate((n) => window.sightline.sent.slice(n).filter((m) => m.type === 'scene'), sentBefore);
  check(scenes.length === 1 && scenes[0].dataset === vds.name && scenes[0].technique === volume[0],
    `one scene message with both: ${JSON.stringify(scenes)}`);
  await page.waitForFunction((n) => window.sightline.state.technique === n, volume[0], { timeout: T });
  await page.waitForFunction(() => window.sightline.lastFrame && !window.sightline.lastFrame.interactive &&
    window.sightline.lastFrame.stateVersion >= window.sightline.stateVersion, null, { timeout: 3 * T });
  const fr = await canvasStats(page);
  check(fr.fg > 0.05 && fr.fg < 0.95, `a volume frame arrived (foreground ${fr.fg.toFixed(3)})`);
  check((await banner()) === '', `no error after the switch to ${vds.name} (${await banner()})`);
  check(same(await options(), volume), `on a volume the technique picker offers ${JSON.stringify(await options())}`);

  // A wide float in data units is a slider over the volume's own value range; End = its maximum.
  await page.waitForFunction(() => Array.isArray(window.sightline.datasets.find((d) =>
    d.name === window.sightline.state.dataset)?.counts?.value_range), null, { timeout: T });
  await page.waitForSelector('#params input[type=range][data-over=dataset]', { timeout: 5000 }).catch(() => {});
  const vr = await page.evaluate(() => window.sightline.datasets.find((d) =>
    d.name === window.sightline.state.dataset)?.counts?.value_range);
  const vschema = await page.evaluate((n) => window.sightline.techniques.find((t) => t.name === n).params, volume[0]);
  const dataParam = vschema.find((d) => d.type === 'float' && d.unit === 'data' && d.max - d.min > 1e6);
  const sl = dataParam && await page.$eval(`#params input[type=range][name=${dataParam.name}]`,
    (x) => [Number(x.min), Number(x.max)]).catch(() => null);
  check(Array.isArray(vr) && sl && same(sl, vr), `${dataParam && dataParam.name} slides over the value range ${JSON.stringify(vr)}: ${JSON.stringify(sl)}`);
  if (sl) {
    await page.focus(`#params input[type=range][name=${dataParam.name}]`);
    await page.keyboard.press('End');
    check(await serverStateWhere(obs, sess, (s) => s.params[dataParam.name] === vr[1], `slider ${dataParam.name}`),
      `${dataParam.name} = ${vr[1]} (the value range's maximum) on the server`);
  }

  // Transfer-function editor: drag the last opacity point up to 60 % of the
  // canvas; the server's value keeps the colormap form with that opacity.
  const schema = await page.evaluate((n) => window.sightline.techniques.find((t) => t.name === n).params, volume[0]);
  const tfDef = schema.find((d) => d.type === 'transfer_function');
  const cv = page.locator(`#params canvas[data-param=${tfDef.name}]`);
  check((await cv.count()) === 1, `${tfDef.name} has an editor canvas`);
  await page.waitForFunction(() => Array.isArray(window.sightline.datasets.find((d) =>
    d.name === window.sightline.state.dataset)?.counts?.value_range), null, { timeout: T });
  // The default is the colormap form with "opacity": "auto": the editor shows
  // the ramp the catalog lists for the dataset, over its histogram.
  const tf0 = st.params[tfDef.name];
  const counts = await page.evaluate(() => window.sightline.datasets.find((d) =>
    d.name === window.sightline.state.dataset).counts);
  check(tf0.opacity === 'auto' && Array.isArray(counts.auto_opacity) && counts.auto_opacity.length >= 2,
    `default transfer function ${JSON.stringify(tf0)} with the listed ramp ${JSON.stringify(counts.auto_opacity)}`);
  check(Array.isArray(counts.histogram) && counts.histogram.length === 256, `the catalog lists a 256-bin histogram`);
  const ramp0 = Array.isArray(tf0.opacity) ? tf0.opacity : counts.auto_opacity;
  const histogramPixels = () => page.$eval(`#params canvas[data-param=${tfDef.name}]`, (c) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height - 8).data;
    let n = 0;   // the histogram's grey bars: rgba(160, 165, 180, 0.35) on a clear canvas
    for (let i = 0; i < d.length; i += 4) if (d[i + 3] > 60 && d[i + 3] < 120 && Math.abs(d[i] - 160) < 12) n++;
    return n / (c.width * (c.height - 8));
  });
  const hp = await histogramPixels();
  check(hp > 0.05, `the editor draws the histogram behind the curve (${(100 * hp).toFixed(1)} % of the canvas)`);
  const last = ramp0.length - 1;
  let box = await cv.boundingBox();
  const at = (t, a) => [box.x + Math.min(t * box.width, box.width - 1), box.y + (1 - a) * box.height];
  await page.evaluate(() => { window.sightline.sent.length = 0; });
  const [x0, y0] = at(ramp0[last][0], ramp0[last][1]);
  await page.mouse.move(x0, y0);
  await page.mouse.down();
  for (let i = 1; i <= 20; i++) await page.mouse.move(x0, y0 + (at(1, 0.6)[1] - y0) * i / 20);
  await page.mouse.up();
  const moved = await serverStateWhere(obs, sess, (s) => {
    const v = s.params[tfDef.name];
    return v && v.colormap === tf0.colormap && Array.isArray(v.opacity) && Math.abs(v.opacity[last][1] - 0.6) < 0.03;
  }, 'tf drag');
  check(moved, `dragged point ${last} reached the server: opacity ${JSON.stringify(moved && moved.params[tfDef.name].opacity)}`);
  const tfSets = await page.evaluate((n) => window.sightline.sent.filter((m) => m.type === 'set' && m.params &&
    n in m.params).length, tfDef.name);
  check(tfSets >= 1 && tfSets < 20, `a 20-step drag sent ${tfSets} throttled set messages`);

  // A colour for the selected point: the value becomes points in data units.
  const range = await page.evaluate(() => window.sightline.datasets.find((d) =>
    d.name === window.sightline.state.dataset).counts.value_range);
  box = await cv.boundingBox();
  const canvasBefore = await cv.elementHandle();
  await page.mouse.click(...at(1, 0.6));
  await page.locator(`#params input[type=color][name="${tfDef.name}.color"]`).fill('#ff0000');
  const coloured = await serverStateWhere(obs, sess, (s) => {
    const v = s.params[tfDef.name];
    const p = Array.isArray(v) && v[v.length - 1];
    return p && Math.abs(p[0] - range[1]) <= 0.01 * (range[1] - range[0]) && p[1] === 1 && p[2] === 0 &&
      p[3] === 0 && Math.abs(p[4] - 0.6) < 0.03;
  }, 'tf colour');
  if (!coloured) {
    console.error('tf colour: the page sent', JSON.stringify(await page.evaluate((n) => window.sightline.sent
      .filter((m) => m.type === 'set' && m.params && n in m.params).slice(-4), tfDef.name)),
    'banner', JSON.stringify(await page.textContent('#banner')),
    'editor rebuilt', await canvasBefore.evaluate((c) => !c.isConnected),
    'colour input', JSON.stringify(await page.$eval(`#params input[type=color][name="${tfDef.name}.color"]`,
      (e) => ({ value: e.value, disabled: e.disabled }))));
  }
  check(coloured, `point ${last} coloured #ff0000 at value ${range[1]} on the server`);
  await settled(page);

  // A preset: back to the colormap form with that colormap.
  const preset = tfDef.colormaps.find((m) => m.name !== tf0.colormap).name;
  await page.selectOption(`#params select[name="${tfDef.name}.preset"]`, preset);
  check(await serverStateWhere(obs, sess, (s) => s.params[tfDef.name].colormap === preset, 'tf preset'),
    `preset ${preset} on the server`);
  await settled(page);

  // The Colin27 MRI sample (data/samples, when fetched), back on the
  // automatic opacity (the editor's preset: the session kept the edited
  // transfer function across the dataset switch): the head shows. The
  // screenshot browser-test-volume.png is this frame with its editor.
  const mri = info.datasets.find((d) => d.kind === 'volume' && /ch2/.test(d.name));
  if (!mri) {
    console.log('browser test: the MRI sample ch2.nii.gz is not in the catalog (scripts/fetch-sample-data); no MRI frame');
    await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-volume.png') });
    return;
  }
  await page.selectOption('#dataset', mri.name);
  check(await serverStateWhere(obs, sess, (s) => s.dataset === mri.name && Array.isArray(s.bounds), 'MRI', 60000),
    `${mri.name} loaded`);
  await page.waitForFunction(() => Array.isArray(window.sightline.datasets.find((d) =>
    d.name === window.sightline.state.dataset)?.counts?.auto_opacity), null, { timeout: T });
  await page.selectOption(`#params select[name="${tfDef.name}.preset"]`, '@auto');
  const ms = await serverStateWhere(obs, sess, (s) => s.params[tfDef.name] && s.params[tfDef.name].opacity === 'auto',
    'auto preset');
  check(ms, `the preset asks for the automatic opacity (${JSON.stringify(ms && ms.params[tfDef.name])})`);
  await page.waitForFunction(() => window.sightline.lastFrame && !window.sightline.lastFrame.interactive &&
    window.sightline.lastFrame.stateVersion >= window.sightline.stateVersion, null, { timeout: 3 * T });
  await page.waitForFunction(() => Array.isArray(window.sightline.datasets.find((d) =>
    d.name === window.sightline.state.dataset)?.counts?.histogram), null, { timeout: T });
  const mf = await canvasStats(page);
  check(mf.fg > 0.05 && mf.fg < 0.95, `the MRI head shows (foreground ${mf.fg.toFixed(3)})`);
  await settled(page);
  const mh = await histogramPixels();
  check(mh > 0.05, `the MRI's histogram is behind its editor (${(100 * mh).toFixed(1)} %)`);
  await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-volume.png') });
}

// The first look (issue 31, part 4): the built-in head with volume_dvr on
// its defaults. The automatic opacity ramp and the automatic isovalue the
// page shows lie inside the value range and above the background peak (the
// largest bin of the histogram's lower half: the air around the head), the
// isovalue's "auto" button gives the server "auto" back, and no parameter
// name in the panel is cut (each fits its cell). The screenshot is
// browser-test-first-look.png.
async function firstLook(page, obs, sess, banner) {
  await page.selectOption('#dataset', 'head');
  check(await serverStateWhere(obs, sess, (s) => s.dataset === 'head' && Array.isArray(s.bounds), 'head', 60000),
    'head loaded');
  await page.waitForFunction(() => {
    const c = window.sightline.datasets.find((d) => d.name === 'head')?.counts;
    return c && Array.isArray(c.histogram) && Array.isArray(c.value_range) && Number.isFinite(c.auto_isovalue);
  }, null, { timeout: T });
  const counts = await page.evaluate(() => window.sightline.datasets.find((d) => d.name === 'head').counts);
  const [lo, hi] = counts.value_range;
  const h = counts.histogram;
  let peak = 0;
  for (let k = 1; k < h.length / 2; k++) if (h[k] > h[peak]) peak = k;
  const peakEnd = lo + (peak + 1) / h.length * (hi - lo);   // the upper edge of the background bin
  const schema = await page.evaluate(() => window.sightline.techniques.find((t) => t.name === window.sightline.state.technique).params);
  const iso = schema.find((d) => d.name === 'isovalue');
  check(iso && iso.default === 'auto', `the isovalue's default is "auto" (${iso && JSON.stringify(iso.default)})`);
  const tfDef = schema.find((d) => d.type === 'transfer_function');
  check(tfDef && tfDef.default.opacity === 'auto', `the transfer function's default opacity is "auto"`);
  // Back to the defaults through the page: the isovalue's auto button, the TF's auto preset.
  await page.click(`#params button[name="isovalue.auto"]`);
  await page.selectOption(`#params select[name="${tfDef.name}.preset"]`, '@auto');
  const st = await serverStateWhere(obs, sess, (s) => s.params.isovalue === 'auto' && s.params[tfDef.name].opacity === 'auto',
    'auto isovalue and opacity');
  check(st, `the server has isovalue "auto" and the automatic opacity (${st && JSON.stringify(st.params.isovalue)})`);
  await settled(page);
  const shown = await page.$eval('#params input[type=range][name=isovalue]', (x) => ({ value: Number(x.value),
    out: x.parentElement.querySelector('output').textContent, min: Number(x.min), max: Number(x.max) }));
  const autoIso = counts.auto_isovalue;
  check(shown.out.startsWith('auto') && Math.abs(shown.value - autoIso) <= 1e-6 * (hi - lo),
    `the page shows the automatic isovalue ${autoIso} (slider ${shown.value}, "${shown.out}")`);
  check(autoIso > lo && autoIso < hi && autoIso > peakEnd,
    `the automatic isovalue ${autoIso} lies inside ${lo} … ${hi} and above the background peak (ends at ${peakEnd})`);
  check(shown.min === lo && shown.max === hi, `the isovalue slides over the value range (${shown.min} … ${shown.max})`);
  const ramp = counts.auto_opacity;
  const values = ramp.map(([t]) => lo + t * (hi - lo));
  check(ramp.length >= 2 && values.every((v) => v >= lo && v <= hi) && values[0] > peakEnd && ramp[0][1] === 0 &&
    ramp[ramp.length - 1][1] > 0, `the automatic opacity starts above the background peak and stays in range ` +
    `(${JSON.stringify(ramp)} -> values ${values.map((v) => v.toFixed(1))})`);
  await page.waitForFunction(() => window.sightline.lastFrame && !window.sightline.lastFrame.interactive &&
    window.sightline.lastFrame.stateVersion >= window.sightline.stateVersion, null, { timeout: 3 * T });
  const fr = await canvasStats(page);
  check(fr.fg > 0.05 && fr.fg < 0.95, `the head shows (foreground ${fr.fg.toFixed(3)})`);
  check((await banner()) === '', `no error on the head (${await banner()})`);
  const cut = await page.$$eval('#params .param .name', (ns) => ns.filter((n) => n.scrollWidth > n.clientWidth + 1)
    .map((n) => n.textContent));
  check(cut.length === 0, `no parameter name is cut (${JSON.stringify(cut)})`);
  const vecCut = await page.$$eval('#params input.vec', (fs) => fs.filter((f) => f.scrollWidth > f.clientWidth + 1)
    .map((f) => `${f.name}=${f.value}`));
  check(vecCut.length === 0, `no vector component is cut (${JSON.stringify(vecCut)})`);
  await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-first-look.png') });
}

// particles on Marschner-Lobb: the transfer_2d entry is the 2D editor of
// tf2d_editor.js (a canvas, no JSON field); its JS rule gives the colours
// tests/unit/test_particles_tf2d.c computes with the C bake at five points
// (the only numbers copied from there); with curvature colouring on, a
// dragged widget, a rim drag, a double-click and Delete reach the server as
// the new function, and the frame changes.
async function particlesTf2d(page, obs, sess, banner) {
  await page.selectOption('#dataset', 'marschner_lobb');
  check(await serverStateWhere(obs, sess, (s) => s.dataset === 'marschner_lobb' && Array.isArray(s.bounds), 'ML', 60000),
    'marschner_lobb loaded');
  await page.selectOption('#technique', 'particles');
  let st = await serverStateWhere(obs, sess, (s) => s.technique === 'particles', 'particles', 60000);
  check(st, 'technique particles on the server');
  await page.waitForFunction(() => window.sightline.state.technique === 'particles', null, { timeout: T });
  await page.waitForFunction(() => window.sightline.lastFrame && !window.sightline.lastFrame.interactive &&
    window.sightline.lastFrame.stateVersion >= window.sightline.stateVersion, null, { timeout: 3 * T });
  check((await banner()) === '', `no error on particles (${await banner()})`);
  const schema = await page.evaluate(() => window.sightline.techniques.find((t) => t.name === 'particles').params);
  const def = schema.find((d) => d.type === 'transfer_2d');
  const mask = schema.find((d) => d.unit === 'sets' && /curvature/.test(d.name));
  check(def && mask, `particles has a transfer_2d entry (${def && def.name}) and its mask (${mask && mask.name})`);
  if (!def || !mask) return;
  const cv = page.locator(`#params canvas[data-param=${def.name}]`);
  check((await cv.count()) === 1 && (await page.locator(`#params textarea[name=${def.name}], #params input[type=text][name=${def.name}]`).count()) === 0,
    `${def.name} is the 2D editor's canvas, not a text field`);

  // The JS rule against the C bake (test_particles_tf2d.c, js_expect).
  const expect = [[0.873999834, 0.292935517, 0.161415202], [0.183359193, 0.341679597, 0.895801008],
    [0.341540717, 0.667945805, 0.387048011], [0.508428272, 0.412202012, 0.483200028], [0.5, 0.5, 0.5]];
  const js = await page.evaluate(async () => {
    const { tf2dColour } = await import('/tf2d_editor.js');
    const widgets = [[0.2, 0.0, 0.25, 1.0, 0.2, 0.1, 0.9], [0.0, -0.2, 0.3, 0.1, 0.3, 1.0, 0.8],
      [0.15, -0.1, 0.15, 0.2, 0.9, 0.3, 0.6]];
    const texel = (i) => -0.5 + (i + 0.5) / 64;   // texel centres of range 0.5
    return [[44, 32], [32, 20], [41, 25], [36, 30], [60, 2]].map(([i, j]) =>
      tf2dColour(widgets, [0.5, 0.5, 0.5], texel(i), texel(j)));
  });
  const worst = Math.max(...js.flatMap((c, p) => c.map((x, k) => Math.abs(x - expect[p][k]))));
  check(worst < 1e-6, `the page's rule equals the C bake at 5 points (largest difference ${worst})`);

  // Curvature colouring on for set 0: End on a slider (15), or set 0's check
  // box when the page shows the mask as boxes (input[name=<mask>], bit 0 first).
  const slider = page.locator(`#params input[type=range][name=${mask.name}]`);
  if (await slider.count()) {
    await slider.focus();
    await page.keyboard.press('End');
  } else {
    await page.locator(`#params input[type=checkbox][name=${mask.name}]`).first().check();
  }
  check(await serverStateWhere(obs, sess, (s) => (s.params[mask.name] & 1) === 1, mask.name),
    `${mask.name} has set 0's bit on the server`);
  await settled(page);
  const f0 = await canvasStats(page);
  const id0 = await page.evaluate(() => window.sightline.lastFrame.frameId);

  // Drag widget 1's centre by +range/2 in k1 (20 steps, throttled).
  const v0 = (await observeOnce(obs, sess.session, sess.token)).params[def.name];
  const r = v0.range;
  await cv.scrollIntoViewIfNeeded();
  let box = await cv.boundingBox();
  const at = (k1, k2) => [box.x + ((k1 + r) / (2 * r)) * box.width, box.y + (1 - (k2 + r) / (2 * r)) * box.height];
  const w1 = v0.widgets[1];
  await page.evaluate(() => { window.sightline.sent.length = 0; });
  const [x0, y0] = at(w1[0], w1[1]);
  const [x1] = at(w1[0] + r / 2, w1[1]);
  await page.mouse.move(x0, y0);
  await page.mouse.down();
  for (let i = 1; i <= 20; i++) await page.mouse.move(x0 + (x1 - x0) * i / 20, y0);
  await page.mouse.up();
  const tol = 0.02 * r;
  st = await serverStateWhere(obs, sess, (s) => {
    const w = s.params[def.name].widgets[1];
    return w && Math.abs(w[0] - (w1[0] + r / 2)) < tol && Math.abs(w[1] - w1[1]) < tol && w[2] === w1[2];
  }, 'tf2d drag');
  check(st, `dragged widget 1 reached the server: ${JSON.stringify(st && st.params[def.name].widgets[1])}`);
  const sets = await page.evaluate((n) => window.sightline.sent.filter((m) => m.type === 'set' && m.params &&
    n in m.params).length, def.name);
  check(sets >= 1 && sets < 20, `a 20-step widget drag sent ${sets} throttled set messages`);
  await settled(page);
  const f1 = await canvasStats(page);
  const id1 = await page.evaluate(() => window.sightline.lastFrame.frameId);
  check(id1 > id0 && f1.hash !== f0.hash, `the moved widget changed the frame (${id0} -> ${id1}, pixels differ)`);

  // The rim handle (at k1 + radius, or k1 - radius when that is off the
  // square) of the moved widget: outwards to twice the radius (or the edge).
  const w1b = st.params[def.name].widgets[1];
  await cv.scrollIntoViewIfNeeded();
  box = await cv.boundingBox();
  const right = w1b[0] + w1b[2] <= r;
  const want = right ? Math.min(2 * w1b[2], r - w1b[0]) : Math.min(2 * w1b[2], w1b[0] + r);
  const [rx, ry] = at(w1b[0] + (right ? 1 : -1) * w1b[2], w1b[1]);
  const [rx2] = at(w1b[0] + (right ? 1 : -1) * want, w1b[1]);
  await page.mouse.move(rx, ry);
  await page.mouse.down();
  for (let i = 1; i <= 10; i++) await page.mouse.move(rx + (rx2 - rx) * i / 10, ry);
  await page.mouse.up();
  st = await serverStateWhere(obs, sess, (s) => Math.abs(s.params[def.name].widgets[1][2] - want) < tol, 'tf2d rim');
  check(st, `the rim drag set widget 1's radius to ${want.toFixed(3)}: ${JSON.stringify(st && st.params[def.name].widgets[1])}`);

  // Double-click adds a widget (reachable corner, away from the others); Delete removes it.
  await cv.scrollIntoViewIfNeeded();
  box = await cv.boundingBox();
  const n0 = st ? st.params[def.name].widgets.length : v0.widgets.length;
  await page.mouse.dblclick(...at(0.9 * r, -0.9 * r));
  st = await serverStateWhere(obs, sess, (s) => s.params[def.name].widgets.length === n0 + 1, 'tf2d add');
  const added = st && st.params[def.name].widgets[n0];
  check(added && Math.abs(added[0] - 0.9 * r) < tol && Math.abs(added[1] + 0.9 * r) < tol,
    `double-click added widget ${n0} at (${0.9 * r}, ${-0.9 * r}): ${JSON.stringify(added)}`);
  await page.mouse.click(...at(added ? added[0] : 0.9 * r, added ? added[1] : -0.9 * r));   // selects it
  await page.keyboard.press('Delete');
  check(await serverStateWhere(obs, sess, (s) => s.params[def.name].widgets.length === n0, 'tf2d delete'),
    `Delete removed it (${n0} widgets on the server)`);
  await settled(page);
  check((await banner()) === '', `no error after the 2D editor's changes (${await banner()})`);
  await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-particles.png') });
  await cv.screenshot({ path: path.join(ARTIFACTS, 'browser-test-tf2d-editor.png') });
}

// held_params.js: an older echo of a parameter the page has just set does
// not reach its control; the echo of the value sent does, and releases it.
async function syntheticHeldParams(page) {
  const r = await page.evaluate(async () => {
    const { HeldParams, sameJson } = await import('/held_params.js');
    const h = new HeldParams();
    const w2 = { range: 0.5, widgets: [[0.25, 0, 0.3, 1, 1, 1, 1], [0.1, -0.2, 0.15, 0.5, 0.5, 0.5, 1]] };
    const w3 = { range: 0.5, widgets: [...w2.widgets, [0.45, -0.45, 0.075, 0.5, 0.5, 0.5, 1]] };
    h.hold('tf', w3);
    const stale = h.shown({ tf: w2, other: 7 });
    const echo = h.shown({ tf: JSON.parse(JSON.stringify(w3).replace('0.075', '0.07500000298')), other: 7 });
    const later = h.shown({ tf: w2 });
    h.hold('x', 1);
    h.release();
    return { stale, echo: 'tf' in echo, later: 'tf' in later, released: h.size,
      eq: [sameJson(1, 1 + 1e-9), sameJson(1, 1.001), sameJson([1, 2], [1]), sameJson({ a: 1 }, { b: 1 })] };
  });
  check(!('tf' in r.stale) && r.stale.other === 7, `a stale echo of a held parameter is left out, others shown (${JSON.stringify(r.stale)})`);
  check(r.echo && r.later, 'the echo of the value sent is shown and releases the hold');
  check(r.released === 0, 'release() drops every hold');
  check(same(r.eq, [true, false, false, false]), `sameJson: numbers within 1e-6, shapes exact (${r.eq})`);

  // An edit waiting in the throttle is not replaced by a value from the
  // server (the echo of the previous edit): the colour picked right after a
  // click reaches the server.
  const p = await page.evaluate(async () => {
    const { throttle } = await import('/throttle.js');
    const { TransferFunctionEditor } = await import('/tf_editor.js');
    let calls = 0;
    const t = throttle(() => calls++, 50);
    t(true);
    t();
    const waiting = t.pending(), callsThen = calls;
    await new Promise((res) => setTimeout(res, 120));
    const sent = [];
    const row = document.createElement('div');
    const ed = new TransferFunctionEditor(row, { name: 'zz_tf', default: { colormap: 'viridis', opacity: [[0, 0], [1, 1]] },
      colormaps: [{ name: 'viridis', colors: [[0, 0, 0.3], [1, 1, 0]] }] }, (v) => sent.push(v), { valueRange: [0, 10] });
    ed.set({ colormap: 'viridis', opacity: [[0, 0], [1, 1]] });
    ed.send(true);
    ed.selected = 1;
    ed.recolour([1, 0, 0]);   // waits for its turn
    const pendingEdit = ed.send.pending();
    ed.set({ colormap: 'viridis', opacity: [[0, 0], [1, 1]] });   // the echo of the edit before
    await new Promise((res) => setTimeout(res, 200));
    return { waiting, callsThen, callsAfter: calls, pending: t.pending(), pendingEdit, last: sent[sent.length - 1] };
  });
  check(p.waiting && p.callsThen === 1 && p.callsAfter === 2 && !p.pending,
    `throttle: a call waits for its turn (pending), then runs (${JSON.stringify(p)})`);
  check(p.pendingEdit && Array.isArray(p.last) && p.last[1][1] === 1 && p.last[1][2] === 0 && p.last[1][3] === 0,
    `an echo arriving while a colour edit waits does not replace it: sent ${JSON.stringify(p.last)}`);
}

// The two attribute rules of controls.js on a synthetic schema, so they
// cannot be met by knowing parameter names: an 'attribute' parameter of any
// name becomes a select, an 'int' named "attribute" stays a slider.
async function synthetic(page) {
  const r = await page.evaluate(async () => {
    const { ParamControls } = await import('/controls.js');
    const form = document.createElement('form');
    const sent = [];
    const pc = new ParamControls(form, (n, v) => sent.push([n, v]));
    pc.build([
      { name: 'zz_pick', type: 'attribute', min: -1, max: 31, default: 0, unit: '', description: '' },
      { name: 'zz_strict', type: 'attribute', min: 0, max: 31, default: 0, unit: '', description: '' },
      { name: 'attribute', type: 'int', min: -1, max: 31, default: 0, unit: '', description: '' },
      { name: 'zz_tint', type: 'vec3', min: 0, max: 1, default: [1, 0, 0], unit: 'rgb', description: '' },
      { name: 'zz_dir', type: 'vec3', min: -1, max: 1, default: [0, 0, 1], unit: '', description: '' },
      { name: 'zz_huge', type: 'float', min: -1e30, max: 1e30, default: 0, unit: '', description: '' },
      { name: 'zz_small', type: 'float', min: 0, max: 1e6, default: 0, unit: '', description: '' },
    ], ['p', 'q']);
    pc.update({ zz_dir: [0, 0, 1] });
    const kinds = {
      tint: form.querySelector('input[name=zz_tint]')?.type,
      dir: form.querySelectorAll('input.vec[name=zz_dir]').length,
      huge: form.querySelector('input[name=zz_huge]')?.type,
      small: form.querySelector('input[name=zz_small]')?.type,
    };
    const dir = form.querySelectorAll('input.vec[name=zz_dir]');
    dir[0].value = '7';
    dir[0].dispatchEvent(new Event('change'));
    const huge = form.querySelector('input[name=zz_huge]');
    huge.value = '-3e31';
    huge.dispatchEvent(new Event('change'));
    const controlKinds = { kinds, sent: sent.splice(0) };
    pc.update({ zz_pick: 1, zz_strict: 0, attribute: 3 });
    const pick = form.querySelector('select[name=zz_pick]');
    const strict = form.querySelector('select[name=zz_strict]');
    const opts = (s) => (s ? [...s.options].map((o) => o.textContent) : null);
    const shown = pick && pick.value;
    pick.value = '-1';
    pick.dispatchEvent(new Event('change'));
    strict.value = '1';
    strict.dispatchEvent(new Event('change'));
    return { pick: opts(pick), strict: opts(strict), shown, sent, controlKinds,
      intIsSlider: !!form.querySelector('input[type=range][name=attribute]') };
  });
  check(same(r.pick, ['none', 'p', 'q']) && r.shown === '1', `synthetic attribute select ${JSON.stringify(r)}`);
  check(same(r.strict, ['p', 'q']), `an attribute with min 0 has no "none" ${JSON.stringify(r.strict)}`);
  check(same(r.sent, [['zz_pick', -1], ['zz_strict', 1]]), `attribute selects send indices ${JSON.stringify(r.sent)}`);
  check(r.intIsSlider, 'an int parameter named "attribute" is a slider');
  const ck = r.controlKinds;
  check(same(ck.kinds, { tint: 'color', dir: 3, huge: 'number', small: 'range' }),
    `synthetic rgb / direction / ±1e30 / 0…1e6 controls ${JSON.stringify(ck.kinds)}`);
  check(same(ck.sent, [['zz_dir', [1, 0, 1]], ['zz_huge', -1e30]]), `typed values are clamped ${JSON.stringify(ck.sent)}`);
}

// The controls of the types no registered technique uses yet, on a
// synthetic schema: an int with unit "sets" is 4 check boxes whose bits make
// the value; a 'values' list is a text field whose numbers are sent only
// when each lies in the schema range and there are at most max_count ([] =
// auto). (A 'transfer_2d' is the 2D editor: see the particles section.)
async function syntheticNewTypes(page) {
  const r = await page.evaluate(async () => {
    const { ParamControls } = await import('/controls.js');
    const form = document.createElement('form');
    const sent = [];
    const pc = new ParamControls(form, (n, v) => sent.push([n, v]));
    pc.build([
      { name: 'zz_mask', type: 'int', min: 0, max: 15, default: 1, unit: 'sets', description: '' },
      { name: 'zz_iso', type: 'values', min: 0, max: 255, max_count: 4, default: [], unit: 'data', description: '' },
      { name: 'zz_count', type: 'int', min: 0, max: 15, default: 1, unit: '', description: '' },
    ]);
    pc.update({ zz_mask: 5, zz_iso: [] });
    const boxes = [...form.querySelectorAll('input[type=checkbox][name=zz_mask]')];
    const shownMask = boxes.map((b) => b.checked);
    const labels = boxes.map((b) => b.parentElement.textContent.trim());
    boxes[1].checked = true;
    boxes[1].dispatchEvent(new Event('change'));
    boxes[0].checked = false;
    boxes[0].dispatchEvent(new Event('change'));
    const iso = form.querySelector('input[name=zz_iso]');
    const type = (el, text) => { el.value = text; el.dispatchEvent(new Event('change')); };
    const shownIso = iso.value;
    type(iso, '10, 20.5');
    type(iso, '1, 2, 3, 4, 5');      // a 5th value: not sent
    const fifthInvalid = iso.classList.contains('invalid');
    type(iso, '10, 300');            // out of range: not sent
    type(iso, '10, x');              // not a number: not sent
    type(iso, '');                   // empty = auto
    return { shownMask, labels, shownIso, fifthInvalid, sent,
      countIsSlider: !!form.querySelector('input[type=range][name=zz_count]') };
  });
  check(same(r.shownMask, [true, false, true, false]) && same(r.labels, ['set 0', 'set 1', 'set 2', 'set 3']),
    `"sets" check boxes show mask 5 ${JSON.stringify([r.shownMask, r.labels])}`);
  check(r.countIsSlider, 'an int without unit "sets" stays a slider');
  check(r.shownIso === '' && r.fifthInvalid, `values field: empty = auto, a 5th value marked ${JSON.stringify(r)}`);
  check(same(r.sent, [['zz_mask', 7], ['zz_mask', 6], ['zz_iso', [10, 20.5]], ['zz_iso', []]]),
    `sets / values send only valid values ${JSON.stringify(r.sent)}`);
}

// Control hand-over: the viewer asks, the controller grants, the server says
// so, the new controller's change reaches the server, the old one is a viewer.
async function handOver(page, page2, obs, sess) {
  const id2 = await page2.evaluate(() => window.sightline.clientId);
  check(await page2.isVisible('#control') && (await page2.isDisabled('#technique')), 'viewer: request button, pickers disabled');
  await page2.click('#control');
  const grant = page.locator('#request-list button', { hasText: `client ${id2}` });
  await grant.waitFor({ timeout: T });
  await grant.click();
  check(await serverStateWhere(obs, sess, (s) => s.controller === id2, 'grant'), `controller is client ${id2} on the server`);
  await page2.waitForFunction(() => document.getElementById('role').textContent === 'controller', null, { timeout: T });
  await page.waitForFunction(() => document.getElementById('role').textContent === 'viewer', null, { timeout: T });
  check(await page.isDisabled('#params input[type=checkbox]') && (await page.isDisabled('#dataset')),
    'the old controller\'s controls are disabled');
  const schema = await page2.evaluate(() => window.sightline.techniques.find((t) => t.name === window.sightline.state.technique).params);
  const bool = schema.find((d) => d.type === 'bool');
  const before = (await observeOnce(obs, sess.session, sess.token)).params[bool.name];
  await page2.click(`#params input[type=checkbox][name=${bool.name}]`);
  check(await serverStateWhere(obs, sess, (s) => s.params[bool.name] === !before, 'new controller'),
    `the new controller's ${bool.name} = ${!before} reached the server`);
  await page.waitForFunction(([n, v]) => window.sightline.state.params[n] === v, [bool.name, !before], { timeout: T });
  check(true, 'the old controller (now a viewer) sees the change');
}

async function main() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'sl-browser-test-'));
  let { proc, port } = await startServer(dir);
  const browser = await chromium.launch({
    executablePath: process.env.SIGHTLINE_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
      '--no-first-run'],
  });
  fs.mkdirSync(ARTIFACTS, { recursive: true });
  try {
    const page = await browser.newPage({ viewport: { width: 900, height: 600 } });
    page.on('pageerror', (e) => { failed++; console.error(`page error: ${e.message}`); });
    await page.goto(`http://127.0.0.1:${port}/`);

    // 1. A still frame arrives and shows something.
    // The page resizes the session to its stage right after joining: wait for the frame of the newest state.
    await page.waitForFunction(() => window.sightline && window.sightline.frames > 0 &&
      !window.sightline.lastFrame.interactive && window.sightline.lastFrame.stateVersion >= window.sightline.stateVersion,
    null, { timeout: T });
    const s1 = await canvasStats(page);
    check(s1.fg > 0.01 && s1.fg < 0.95, `first frame foreground fraction ${s1.fg}`);
    check((await page.textContent('#role')) === 'controller', 'first page is the controller');
    await page.waitForFunction(() => /\d+ fps .*still/.test(document.getElementById('status').textContent), null,
      { timeout: 5000 }).catch(() => {});
    check(/\d+ fps .*still/.test(await page.textContent('#status')), 'status line shows fps, size, times, still');

    // 2. Drag the canvas: a new still frame for the newest camera seq, different pixels.
    const box = await page.locator('#view').boundingBox();
    const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) await page.mouse.move(cx + 18 * i, cy + 6 * i);
    await page.mouse.up();
    const seq = await page.evaluate(() => window.sightline.cameraSeq);
    check(seq >= 2, `drag sent camera messages (seq ${seq})`);
    await page.waitForFunction((n) => window.sightline.lastFrame.cameraSeq >= n && !window.sightline.lastFrame.interactive,
      seq, { timeout: T });
    const s2 = await canvasStats(page);
    check(s2.hash !== s1.hash, 'frame after the drag differs');
    await page.waitForFunction(() => /latency \d+ ms/.test(document.getElementById('status').textContent), null,
      { timeout: 5000 }).catch(() => {});
    check(/latency \d+ ms/.test(await page.textContent('#status')), 'status line shows latency');

    // 2a. The page's camera numbers are the server's (welcome): a long upward
    // orbit stops at the server's elevation limit, which the server accepts.
    const lim = await page.evaluate(() => window.sightline.cameraLimits);
    check(lim.maxElevation === 89.9 && lim.defaults && lim.defaults.orbit.distance === 2.5 && lim.defaults.fov_y === 45,
      `camera defaults and elevation limit from welcome ${JSON.stringify(lim)}`);
    const errorsBefore = await page.textContent('#banner');
    for (let k = 0; k < 3; k++) {   // 0.4 degree per pixel: 3 drags of 0.4 x the canvas height pass any limit
      await page.mouse.move(cx, cy - 0.2 * box.height);
      await page.mouse.down();
      for (let i = 1; i <= 8; i++) await page.mouse.move(cx, cy + (0.05 * i - 0.2) * box.height);
      await page.mouse.up();
    }
    await page.waitForFunction((m) => window.sightline.state.camera.orbit &&
      window.sightline.state.camera.orbit.elevation === m && !window.sightline.lastFrame.interactive &&
      window.sightline.lastFrame.cameraSeq >= window.sightline.cameraSeq, lim.maxElevation, { timeout: T });
    check((await page.textContent('#banner')) === errorsBefore, 'the server accepted the clamped elevation');
    await page.mouse.move(cx, cy + 0.25 * box.height);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) await page.mouse.move(cx, cy + (0.25 - 0.05 * i) * box.height);
    await page.mouse.up();
    await page.waitForFunction(() => window.sightline.state.camera.orbit &&
      window.sightline.state.camera.orbit.elevation < 45 && !window.sightline.lastFrame.interactive &&
      window.sightline.lastFrame.cameraSeq >= window.sightline.cameraSeq, null, { timeout: T });

    // 2b. Wheel zooms (orbit distance grows), shift-drag pans (the camera becomes eye/target).
    const dist0 = await page.evaluate(() => window.sightline.state.camera.orbit.distance);
    await page.mouse.move(cx, cy);
    await page.mouse.wheel(0, 400);
    await page.waitForFunction((d) => window.sightline.state.camera.orbit &&
      window.sightline.state.camera.orbit.distance > d * 1.2 && !window.sightline.lastFrame.interactive &&
      window.sightline.lastFrame.cameraSeq >= window.sightline.cameraSeq, dist0, { timeout: T });
    check(true, 'wheel zoom reached the server and rendered');
    await page.waitForFunction(() => Array.isArray(window.sightline.state.bounds), null, { timeout: T });
    await page.keyboard.down('Shift');
    await page.mouse.down();
    for (let i = 1; i <= 5; i++) await page.mouse.move(cx + 10 * i, cy);
    await page.mouse.up();
    await page.keyboard.up('Shift');
    await page.waitForFunction(() => Array.isArray(window.sightline.state.camera.eye) &&
      !window.sightline.lastFrame.interactive && window.sightline.lastFrame.cameraSeq >= window.sightline.cameraSeq,
    null, { timeout: T });
    const cam = await page.evaluate(() => window.sightline.state.camera);
    const bnd = await page.evaluate(() => window.sightline.state.bounds);
    const centre = [0, 1, 2].map((k) => (bnd[0][k] + bnd[1][k]) / 2);
    check(cam.target.some((t, k) => Math.abs(t - centre[k]) > 1e-6), `pan moved the target off the centre ${JSON.stringify(cam.target)}`);

    // 3. Change a parameter through its generated control.
    const before = await page.evaluate(() => ({ v: window.sightline.state.params, id: window.sightline.lastFrame.frameId,
      version: window.sightline.lastFrame.stateVersion }));
    const changed = await page.evaluate(() => {
      const sliders = [...document.querySelectorAll('#params input[type=range]')];
      const s = sliders.find((x) => x.name !== 'radius') || sliders[0];
      if (!s) return null;
      const lo = Number(s.min), hi = Number(s.max);
      s.value = String(Number(s.value) === hi ? lo : hi);
      s.dispatchEvent(new Event('input'));
      s.dispatchEvent(new Event('change'));
      return s.name;
    });
    check(changed !== null, 'a slider was generated from the schema');
    // Every slider shows its schema range and unit beside it.
    const ranges = await page.evaluate(() => {
      const schema = window.sightline.techniques.find((t) => t.name === window.sightline.state.technique).params;
      return [...document.querySelectorAll('#params input[type=range]')].map((s) => {
        const def = schema.find((d) => d.name === s.name);
        const shown = s.parentElement.querySelector('small.range')?.textContent || '';
        return { name: s.name, shown, unit: def.unit || '', min: def.min, max: def.max, type: def.type };
      });
    });
    const fmtNum = (v, type) => {
      if (type === 'int') return String(Math.round(v));
      const t = Number(v).toPrecision(4);
      return t.includes('.') && !t.includes('e') ? t.replace(/0+$/, '').replace(/\.$/, '') : t;
    };
    const badRanges = ranges.filter((r) =>
      r.shown !== `${fmtNum(r.min, r.type)} … ${fmtNum(r.max, r.type)}${r.unit ? ` ${r.unit}` : ''}`);
    check(ranges.length > 0 && badRanges.length === 0, `sliders show min … max and unit (${JSON.stringify(badRanges.slice(0, 3))})`);
    if (changed) {
      await page.waitForFunction(([name, old]) => window.sightline.state.params[name] !== old,
        [changed, before.v[changed]], { timeout: T });
      await page.waitForFunction((v) => window.sightline.lastFrame.stateVersion > v && !window.sightline.lastFrame.interactive,
        before.version, { timeout: T });
      const id = await page.evaluate(() => window.sightline.lastFrame.frameId);
      check(id > before.id, `parameter change rendered a new frame (${before.id} -> ${id})`);
    }
    await page.screenshot({ path: path.join(ARTIFACTS, 'browser-test-controller.png') });

    // 3a. Every 'attribute' parameter is a select of the dataset's attributes once they are known.
    await page.waitForFunction(() => document.querySelectorAll('#params select[name=attribute] option').length > 1,
      null, { timeout: T }).catch(() => {});
    const attrs = await page.$$eval('#params select[name=attribute] option', (os) => os.map((o) => o.textContent));
    check(attrs[0] === 'none' && attrs.length > 1, `attribute control lists the dataset's attributes ${JSON.stringify(attrs)}`);
    const typed = await page.evaluate(() => {
      const t = window.sightline.techniques.find((x) => x.name === window.sightline.state.technique);
      return t.params.filter((p) => p.type === 'attribute').map((p) => p.name);
    });
    const selects = await page.$$eval('#params select[data-type=attribute]', (xs) => xs.map((x) => x.name));
    check(typed.length >= 2 && same(typed, selects), `attribute selects ${JSON.stringify(selects)} = schema's ${JSON.stringify(typed)}`);
    await synthetic(page);
    await syntheticNewTypes(page);
    await syntheticHeldParams(page);

    // 3b. Snapshot button downloads a PNG; a named view is saved and listed.
    const [download] = await Promise.all([page.waitForEvent('download', { timeout: T }), page.click('#snapshot')]);
    const snapPath = path.join(dir, 'snapshot.png');
    await download.saveAs(snapPath);
    const magic = fs.readFileSync(snapPath).subarray(0, 8).toString('hex');
    check(magic === '89504e470d0a1a0a' && download.suggestedFilename().endsWith('.png'), `snapshot is a PNG (${magic})`);
    await page.fill('#view-name', 'browser view');
    const link0 = await page.inputValue('#share-link');
    const sess = { session: decodeURIComponent(link0.match(/session=([^&]+)/)[1]), token: link0.match(/token=([0-9a-f]+)/)[1],
      page };
    const obs = await browser.newPage();
    await obs.goto(`http://127.0.0.1:${port}/healthz`);
    const saved = { name: 'browser view', state: await observeOnce(obs, sess.session, sess.token) };
    await page.click('#save-view');
    await page.waitForFunction(() => [...document.querySelectorAll('#views option')].some((o) => o.value === 'browser view'),
      null, { timeout: T });
    check(true, 'saved view is listed');

    // 3c. Every control kind, each value read back from the server.
    await driveControls(page, obs, sess, saved);

    // 4. The share link opens the same session in a second page: same frame, same pixels.
    const link = await page.inputValue('#share-link');
    check(/#session=[A-Za-z0-9_-]{1,32}\.[0-9a-f]{16}&token=[0-9a-f]{32}$/.test(link), `share link ${link}`);
    const page2 = await browser.newPage({ viewport: { width: 900, height: 600 } });
    page2.on('pageerror', (e) => { failed++; console.error(`page2 error: ${e.message}`); });
    await page2.goto(link);
    await page2.waitForFunction(() => window.sightline && window.sightline.frames > 0, null, { timeout: T });
    check((await page2.textContent('#role')) === 'viewer', 'second page is a viewer');
    // The session id rides in the WebSocket URL's query too, for a balancer (PROTOCOL.md).
    const wsUrl = await page2.evaluate(() => window.sightline.wsUrl);
    check(new URL(wsUrl).searchParams.get('session') === sess.session, `join URL ${wsUrl} names the session`);
    const id1 = await page.evaluate(() => window.sightline.lastFrame.frameId);
    await page2.waitForFunction((n) => window.sightline.lastFrame.frameId === n, id1, { timeout: T });
    const a = await canvasStats(page), b = await canvasStats(page2);
    check(a.width === b.width && a.height === b.height, `canvas sizes ${a.width}x${a.height} vs ${b.width}x${b.height}`);
    check(a.hash === b.hash, 'the shared page shows the same pixels');
    if (changed) {
      const v1 = await page.evaluate((n) => window.sightline.state.params[n], changed);
      const v2 = await page2.evaluate((n) => window.sightline.state.params[n], changed);
      check(v1 === v2, `viewer sees the changed parameter (${v1} vs ${v2})`);
    }
    await page2.screenshot({ path: path.join(ARTIFACTS, 'browser-test-viewer.png') });

    // 4a. Control moves to the second page on request and grant.
    await handOver(page, page2, obs, sess);
    await page2.close();
    await obs.close();

    // 5. Server restart: a clear disconnect message, then automatic reconnect and frames again.
    // SIGINT stops at once (SIGTERM would drain: serve the connected page until it leaves).
    const framesBefore = await page.evaluate(() => window.sightline.frames);
    proc.kill('SIGINT');
    await new Promise((r) => { proc.on('exit', r); setTimeout(r, 15000); });
    await page.waitForFunction(() => !document.getElementById('banner').hidden &&
      /Disconnected/.test(document.getElementById('banner').textContent), null, { timeout: T });
    ({ proc } = await startServer(dir, port));
    await page.waitForFunction((n) => window.sightline.connected && window.sightline.frames > n, framesBefore, { timeout: T });
    check(true, 'reconnected after a server restart');
  } catch (e) {
    failed++;
    console.error(`browser test aborted: ${e.stack || e}`);
  } finally {
    await browser.close();
    proc.kill('SIGINT');
    await new Promise((r) => { proc.on('exit', r); setTimeout(r, 15000); });
    fs.rmSync(dir, { recursive: true, force: true });
  }
  console.log(`${passed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
}

main().catch((e) => { console.error(e); process.exit(1); });
