// Loads a meshclash HTML report from disk in headless Chromium and checks it, with no library:
// the DevTools protocol over --remote-debugging-pipe (fds 3 and 4, NUL-separated JSON), and a
// small PNG decoder on Node's zlib.
//
//   node tests/browser/driver.mjs REPORT.html OVERVIEW.png CLASH.png [--rows N] [--text S]
//   node tests/browser/driver.mjs --glb SCENE.glb OVERVIEW.png CLASH.png
//
// Fails (exit 1, a line on stderr) unless: the page reaches WebGL ready; the overview frame and
// the frame after clicking the first clash row both contain the A colour (orange) and the B
// colour (blue) in the canvas, and the selected frame the contact colour (magenta) when that row
// has contact segments; the page made no request other than the report file itself; the console
// and the log have no error and no exception was thrown. `--rows N` also asserts the table rows, `--text S` that the clash table shows S.
//
// With --glb: the GLB is embedded in tests/browser/glb_viewer.html (a minimal viewer written for
// this test) and drawn through the file's own cameras: `camera overview` on white and on a dark
// background must show part A (orange) and part B (blue); `camera #1` must show the first clash's
// contact lines and marker (magenta) and both parts.
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { inflateSync } from 'node:zlib';

const glbMode = process.argv[2] === '--glb';
const args = process.argv.slice(glbMode ? 3 : 2);
const [htmlPath, overviewPng, clashPng] = args;
const rowsIdx = args.indexOf('--rows');
const wantRows = rowsIdx >= 0 ? Number(args[rowsIdx + 1]) : null;
const textIdx = args.indexOf('--text');
const wantText = textIdx >= 0 ? args[textIdx + 1] : null;
if (!htmlPath || !overviewPng || !clashPng) {
  console.error('usage: driver.mjs REPORT.html OVERVIEW.png CLASH.png [--rows N] [--text S]');
  process.exit(2);
}
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const WIDTH = 1200, HEIGHT = 760;

const fail = (msg) => { console.error(`browser test FAILED (${htmlPath}): ${msg}`); cleanup(); process.exit(1); };
const profile = mkdtempSync(join(tmpdir(), 'meshclash-chromium-'));
const chrome = spawn(CHROMIUM, [
  '--headless', '--no-sandbox', '--disable-gpu', '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
  '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update',
  '--disable-sync', '--disable-extensions', '--mute-audio', '--hide-scrollbars',
  `--user-data-dir=${profile}`, '--remote-debugging-pipe', `--window-size=${WIDTH},${HEIGHT}`, 'about:blank',
], { stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe'] });
let chromeErr = '';
chrome.stderr.on('data', (d) => { chromeErr += d; });
chrome.on('exit', (code) => { if (!done) fail(`chromium exited (${code}): ${chromeErr.slice(-2000)}`); });
let done = false;
function cleanup() {
  done = true;
  try { chrome.kill('SIGKILL'); } catch (_) { /* gone */ }
  try { rmSync(profile, { recursive: true, force: true }); } catch (_) { /* best effort */ }
}
const guard = setTimeout(() => fail('no answer from chromium within 90 s'), 90_000);

// ---------- CDP over the pipe ----------
const toChrome = chrome.stdio[3], fromChrome = chrome.stdio[4];
let nextId = 1, buf = Buffer.alloc(0);
const pending = new Map(), listeners = [];
fromChrome.on('data', (chunk) => {
  buf = Buffer.concat([buf, chunk]);
  let end;
  while ((end = buf.indexOf(0)) >= 0) {
    const msg = JSON.parse(buf.subarray(0, end).toString('utf8'));
    buf = buf.subarray(end + 1);
    if (msg.id && pending.has(msg.id)) {
      const { ok, ko } = pending.get(msg.id);
      pending.delete(msg.id);
      if (msg.error) ko(new Error(`${msg.error.message} ${msg.error.data || ''}`)); else ok(msg.result);
    } else if (msg.method) {
      listeners.forEach((l) => l(msg));
    }
  }
});
function send(method, params = {}, sessionId) {
  const id = nextId++;
  const msg = { id, method, params };
  if (sessionId) msg.sessionId = sessionId;
  toChrome.write(JSON.stringify(msg) + '\0');
  return new Promise((ok, ko) => pending.set(id, { ok, ko }));
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// ---------- PNG ----------
function decodePng(bytes) {
  let p = 8, w = 0, h = 0, type = 0;
  const idat = [];
  while (p < bytes.length) {
    const len = bytes.readUInt32BE(p), kind = bytes.toString('ascii', p + 4, p + 8), d = bytes.subarray(p + 8, p + 8 + len);
    if (kind === 'IHDR') {
      w = d.readUInt32BE(0); h = d.readUInt32BE(4); type = d[9];
      if (d[8] !== 8 || (type !== 2 && type !== 6) || d[12] !== 0) throw new Error('unsupported PNG layout');
    } else if (kind === 'IDAT') idat.push(d);
    p += 12 + len;
  }
  const bpp = type === 6 ? 4 : 3, stride = w * bpp, raw = inflateSync(Buffer.concat(idat));
  const out = Buffer.alloc(h * stride);
  for (let y = 0; y < h; y++) {
    const f = raw[y * (stride + 1)], src = y * (stride + 1) + 1, dst = y * stride;
    for (let x = 0; x < stride; x++) {
      const a = x >= bpp ? out[dst + x - bpp] : 0, b = y ? out[dst - stride + x] : 0;
      const c = x >= bpp && y ? out[dst - stride + x - bpp] : 0;
      let v = raw[src + x];
      if (f === 1) v += a;
      else if (f === 2) v += b;
      else if (f === 3) v += (a + b) >> 1;
      else if (f === 4) {
        const pa = Math.abs(b - c), pb = Math.abs(a - c), pc = Math.abs(a + b - 2 * c);
        v += pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
      }
      out[dst + x] = v & 255;
    }
  }
  return { w, h, bpp, px: out };
}
// Pixels of the A (orange), B (blue) and contact (magenta) hues inside rect.
// `hues`: the A, B and contact windows (degrees); the GLB check blends several translucent
// layers, which pulls a tint's hue a little towards its neighbours', so it passes wider ones.
const HUES = { a: [15, 45], b: [195, 225], seg: [300, 340] };
function colourCounts(img, rect, hues = HUES) {
  const n = { a: 0, b: 0, seg: 0 };
  for (let y = Math.max(0, rect.y | 0); y < Math.min(img.h, (rect.y + rect.height) | 0); y++) {
    for (let x = Math.max(0, rect.x | 0); x < Math.min(img.w, (rect.x + rect.width) | 0); x++) {
      const i = (y * img.w + x) * img.bpp, r = img.px[i], g = img.px[i + 1], b = img.px[i + 2];
      const max = Math.max(r, g, b), min = Math.min(r, g, b);
      if (max < 50 || (max - min) / max < 0.45) continue;
      let hue;
      if (max === r) hue = (60 * (g - b) / (max - min) + 360) % 360;
      else if (max === g) hue = 60 * (b - r) / (max - min) + 120;
      else hue = 60 * (r - g) / (max - min) + 240;
      const inside = (w) => hue >= w[0] && hue <= w[1];
      if (inside(hues.a)) n.a++;
      else if (inside(hues.b)) n.b++;
      else if (inside(hues.seg)) n.seg++;
    }
  }
  return n;
}

// ---------- the test ----------
async function main() {
  let page = resolve(htmlPath);
  if (glbMode) {
    const viewer = readFileSync(join(dirname(fileURLToPath(import.meta.url)), 'glb_viewer.html'), 'utf8');
    page = resolve(overviewPng.replace(/\.png$/, '') + '.view.html');
    writeFileSync(page, viewer.replace('%GLB%', readFileSync(htmlPath).toString('base64')));
  }
  const url = pathToFileURL(page).href;
  const requests = [], errors = [];
  const { targetId } = await send('Target.createTarget', { url: 'about:blank' });
  const { sessionId } = await send('Target.attachToTarget', { targetId, flatten: true });
  const s = (m, p) => send(m, p, sessionId);
  let loaded = false;
  listeners.push((m) => {
    if (m.sessionId !== sessionId) return;
    if (m.method === 'Network.requestWillBeSent') requests.push(m.params.request.url);
    else if (m.method === 'Runtime.exceptionThrown') errors.push(`exception: ${JSON.stringify(m.params.exceptionDetails).slice(0, 500)}`);
    else if (m.method === 'Runtime.consoleAPICalled' && (m.params.type === 'error' || m.params.type === 'assert'))
      errors.push(`console.${m.params.type}: ${m.params.args.map((a) => a.value ?? a.description).join(' ')}`);
    else if (m.method === 'Log.entryAdded' && m.params.entry.level === 'error')
      errors.push(`log: ${m.params.entry.text} ${m.params.entry.url || ''}`);
    else if (m.method === 'Page.loadEventFired') loaded = true;
  });
  await s('Page.enable'); await s('Runtime.enable'); await s('Log.enable'); await s('Network.enable');
  await s('Emulation.setDeviceMetricsOverride', { width: WIDTH, height: HEIGHT, deviceScaleFactor: 1, mobile: false });
  await s('Page.navigate', { url });
  const evaluate = async (expr) => (await s('Runtime.evaluate', { expression: expr, returnByValue: true })).result.value;
  for (let i = 0; !loaded; i++) { if (i > 600) fail('no load event'); await sleep(50); }
  let ready;
  for (let i = 0; !(ready = await evaluate('document.body.dataset.ready')); i++) { if (i > 600) fail('page never ready'); await sleep(50); }
  if (glbMode) return glbChecks(s, evaluate, requests, errors, url);
  if (ready !== 'webgl') fail(`page ready without WebGL (${ready})`);
  const rows = await evaluate('document.querySelectorAll("#clashes tbody tr").length');
  if (wantRows !== null && rows !== wantRows) fail(`${rows} table rows, expected ${wantRows}`);
  if (rows < 1) fail('the clash table is empty');
  if (wantText !== null) {
    const table = await evaluate('document.querySelector("#clashes tbody").textContent');
    if (!String(table).includes(wantText)) fail(`the clash table does not show "${wantText}": ${table}`);
  }
  const rect = await evaluate('(() => { const r = document.getElementById("gl").getBoundingClientRect(); return {x: r.x, y: r.y, width: r.width, height: r.height}; })()');
  const shot = async (file) => {
    await evaluate('new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))');
    const { data } = await s('Page.captureScreenshot', { format: 'png' });
    const png = Buffer.from(data, 'base64');
    writeFileSync(file, png);
    return colourCounts(decodePng(png), rect);
  };
  const over = await shot(overviewPng);
  if (over.a < 200 || over.b < 200) fail(`overview: A/B colours missing (orange ${over.a}, blue ${over.b} px)`);
  const frames = await evaluate('Number(document.body.dataset.frames)');
  const segs = await evaluate('(() => { const tr = document.querySelector("#clashes tbody tr"); tr.click(); return JSON.parse(document.getElementById("meshclash-data").textContent).rows[Number(tr.dataset.row)].segments.length; })()');
  for (let i = 0; (await evaluate('Number(document.body.dataset.frames)')) <= frames; i++) { if (i > 200) fail('no frame after selecting a clash'); await sleep(50); }
  const sel = await evaluate('document.body.dataset.selected');
  if (!sel) fail('clicking a row selected nothing');
  const clash = await shot(clashPng);
  if (clash.a < 200 || clash.b < 200) fail(`selected clash ${sel}: A/B colours missing (orange ${clash.a}, blue ${clash.b} px)`);
  if (segs > 0 && clash.seg < 5) fail(`selected clash ${sel}: contact segments not drawn (${clash.seg} magenta px)`);
  const foreign = requests.filter((u) => u !== url);
  if (foreign.length) fail(`network requests: ${foreign.join(', ')}`);
  if (errors.length) fail(`console errors:\n  ${errors.join('\n  ')}`);
  console.log(`ok ${htmlPath}: ${rows} rows; overview orange ${over.a} blue ${over.b} px; ` +
    `clash ${sel}: orange ${clash.a} blue ${clash.b} magenta ${clash.seg} px; requests ${requests.length} (the file); no console errors`);
  await send('Browser.close').catch(() => {});
  clearTimeout(guard);
  cleanup();
}
// The --glb checks, once the viewer page is ready.
async function glbChecks(s, evaluate, requests, errors, url) {
  const rect = { x: 0, y: 0, width: 1000, height: 700 };
  const view = async (camera, bg, file) => {
    await evaluate(`window.glbView(${JSON.stringify(camera)}, ${JSON.stringify(bg)})`);
    await evaluate('new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))');
    const { data } = await s('Page.captureScreenshot', { format: 'png' });
    const png = Buffer.from(data, 'base64');
    if (file) writeFileSync(file, png);
    return colourCounts(decodePng(png), rect, { a: [10, 50], b: [190, 250], seg: [295, 345] });
  };
  if (errors.length) fail(`console errors:\n  ${errors.join('\n  ')}`);
  // All three views first (the screenshots are there to look at when a check fails).
  const white = await view('camera overview', [1, 1, 1], overviewPng);
  const dark = await view('camera overview', [0.08, 0.08, 0.1], overviewPng.replace(/\.png$/, '-dark.png'));
  const clash = await view('camera #1', [1, 1, 1], clashPng);
  if (white.a < 200 || white.b < 200) fail(`overview on white: A/B tints missing (orange ${white.a}, blue ${white.b} px)`);
  if (dark.a < 200 || dark.b < 200) fail(`overview on dark: A/B tints missing (orange ${dark.a}, blue ${dark.b} px)`);
  if (clash.seg < 5) fail(`camera #1: the clash's lines and marker are not in view (${clash.seg} magenta px)`);
  if (clash.a < 200 || clash.b < 200) fail(`camera #1: A/B tints missing (orange ${clash.a}, blue ${clash.b} px)`);
  const foreign = requests.filter((u) => u !== url);
  if (foreign.length) fail(`network requests: ${foreign.join(', ')}`);
  if (errors.length) fail(`console errors:\n  ${errors.join('\n  ')}`);
  console.log(`ok ${htmlPath}: overview white orange ${white.a} blue ${white.b} px, dark orange ${dark.a} blue ${dark.b} px; ` +
    `camera #1 orange ${clash.a} blue ${clash.b} magenta ${clash.seg} px; no requests, no console errors`);
  await send('Browser.close').catch(() => {});
  clearTimeout(guard);
  cleanup();
}

main().catch((e) => fail(e.stack || String(e)));
