// test_browser.cjs — end-to-end: Debian's Chromium (headless, playwright-core)
// against a private sightline-server on a free loopback port.
//
// Loads the page and sees a still frame with something drawn; drags the
// canvas and sees a new frame showing the new camera (pixels differ); orbits
// up to the elevation limit the server sent (and the server accepts it);
// changes a parameter through its generated control and sees the session
// state and a newer frame; opens the share link in a second page, which
// joins as a viewer and shows the same frame id with identical pixels.
// Screenshots go to <source>/build/ (CI artifact). Prints "N passed, N failed".
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
const T = 30000;

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

async function main() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'sl-browser-test-'));
  let { proc, port } = await startServer(dir);
  const browser = await chromium.launch({
    executablePath: process.env.SIGHTLINE_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
      '--no-first-run'],
  });
  const artifacts = path.join(SRC, 'build');
  fs.mkdirSync(artifacts, { recursive: true });
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
    await page.screenshot({ path: path.join(artifacts, 'browser-test-controller.png') });

    // 3a. The attribute parameter names the dataset's attributes once it is loaded.
    await page.waitForFunction(() => document.querySelectorAll('#params select[name=attribute] option').length > 1,
      null, { timeout: T }).catch(() => {});
    const attrs = await page.$$eval('#params select[name=attribute] option', (os) => os.map((o) => o.textContent));
    check(attrs[0] === 'none' && attrs.length > 1, `attribute control lists the dataset's attributes ${JSON.stringify(attrs)}`);
    // radius_attribute (techniques with per-vertex radii) is a select of the same names.
    const radiusAttrs = await page.$$eval('#params select[name=radius_attribute] option', (os) => os.map((o) => o.textContent));
    const [tech, schemaHasRadiusAttr] = await page.evaluate(() => {
      const t = window.sightline.techniques.find((x) => x.name === window.sightline.state.technique);
      return [t.name, t.params.some((p) => p.name === 'radius_attribute')];
    });
    check(schemaHasRadiusAttr ? JSON.stringify(radiusAttrs) === JSON.stringify(attrs) : radiusAttrs.length === 0,
      `${tech}: radius_attribute control (in schema: ${schemaHasRadiusAttr}) lists ${JSON.stringify(radiusAttrs)}`);

    // 3b. Snapshot button downloads a PNG; a named view is saved and listed.
    const [download] = await Promise.all([page.waitForEvent('download', { timeout: T }), page.click('#snapshot')]);
    const snapPath = path.join(dir, 'snapshot.png');
    await download.saveAs(snapPath);
    const magic = fs.readFileSync(snapPath).subarray(0, 8).toString('hex');
    check(magic === '89504e470d0a1a0a' && download.suggestedFilename().endsWith('.png'), `snapshot is a PNG (${magic})`);
    await page.fill('#view-name', 'browser view');
    await page.click('#save-view');
    await page.waitForFunction(() => [...document.querySelectorAll('#views option')].some((o) => o.value === 'browser view'),
      null, { timeout: T });
    check(true, 'saved view is listed');

    // 4. The share link opens the same session in a second page: same frame, same pixels.
    const link = await page.inputValue('#share-link');
    check(/#session=[0-9a-f]{16}&token=[0-9a-f]{32}$/.test(link), `share link ${link}`);
    const page2 = await browser.newPage({ viewport: { width: 900, height: 600 } });
    page2.on('pageerror', (e) => { failed++; console.error(`page2 error: ${e.message}`); });
    await page2.goto(link);
    await page2.waitForFunction(() => window.sightline && window.sightline.frames > 0, null, { timeout: T });
    check((await page2.textContent('#role')) === 'viewer', 'second page is a viewer');
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
    await page2.screenshot({ path: path.join(artifacts, 'browser-test-viewer.png') });
    await page2.close();

    // 5. Server restart: a clear disconnect message, then automatic reconnect and frames again.
    const framesBefore = await page.evaluate(() => window.sightline.frames);
    proc.kill('SIGTERM');
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
    proc.kill('SIGTERM');
    await new Promise((r) => { proc.on('exit', r); setTimeout(r, 15000); });
    fs.rmSync(dir, { recursive: true, force: true });
  }
  console.log(`${passed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
}

main().catch((e) => { console.error(e); process.exit(1); });
