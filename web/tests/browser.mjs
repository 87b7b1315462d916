// Drives the web viewer in headless Chromium (Playwright, the system's chromium) and writes
// what it saw for the Rust test (crates/illum-viewer/tests/web.rs) to check:
//   <out>/<case>.png     a screenshot of the page's canvas
//   <out>/<case>.status  the page's #illum-status data-* attributes, one "name=value" a line
// Usage: node browser.mjs URL OUT_DIR
// The matrix of scenes and modes comes from the Rust test: <out>/matrix.tsv, one cell a line,
// "name<TAB>query<TAB>expect" with expect one of pathtrace, raster, whitted, refusal; so do the
// files it picks with "Open file...": <out>/mesh.toml and <out>/models/icosphere-0.obj.
// Env: CHROMIUM (default /usr/bin/chromium), WEB_TEST_TIMEOUT_S (per wait, default 300).
// This script waits for the page's state but asserts nothing itself beyond "it got there" (and
// that no renderer reported an error on the way).
import { chromium } from 'playwright-core';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';

const [url, out] = process.argv.slice(2);
if (!url || !out) {
  console.error('usage: node browser.mjs URL OUT_DIR');
  process.exit(2);
}
mkdirSync(out, { recursive: true });
const executablePath = process.env.CHROMIUM || '/usr/bin/chromium';
const timeout = 1000 * Number(process.env.WEB_TEST_TIMEOUT_S || 300);
const matrix = readFileSync(join(out, 'matrix.tsv'), 'utf8').split('\n').filter(Boolean)
  .map((line) => {
    const [name, query, expect] = line.split('\t');
    return { name, query, expect };
  });

// Never reach out to the network, never share a profile (Playwright gives each launch a
// fresh one).
const quiet = ['--no-sandbox', '--disable-dev-shm-usage', '--disable-background-networking', '--disable-component-update',
  '--disable-sync', '--no-first-run', '--disable-quic', '--headless=new'];
// WebGPU on SwiftShader, Chromium's CPU Vulkan: works without a GPU or a display.
const webgpu = ['--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-vulkan=swiftshader',
  '--use-angle=swiftshader'];

async function statusOf(page) {
  return page.evaluate(() => ({ ...document.getElementById('illum-status').dataset }));
}

function save(name, status) {
  const lines = Object.entries(status).map(([k, v]) => `${k}=${String(v).replace(/\n/g, ' ')}`);
  writeFileSync(join(out, `${name}.status`), lines.join('\n') + '\n');
  console.log(`[${name}] ` + JSON.stringify(status));
}

// A renderer's error on the page (what a user would read in its panel), if any: the wait for
// a picture that will never come stops there, naming it.
function rendererError(status) {
  if ((status.pathtraceMessage || '').startsWith('path tracer:')) return status.pathtraceMessage;
  return status.rasterMessage || status.whittedMessage || '';
}

// Waits until `predicate(status)` holds; on a timeout or a renderer's error saves what the page
// had and fails.
async function waitFor(page, name, what, predicate) {
  const started = Date.now();
  for (;;) {
    const status = await statusOf(page);
    if (status.failure) {
      save(name, status);
      throw new Error(`${name}: the viewer failed: ${status.failure}`);
    }
    if (predicate(status)) return status;
    const error = rendererError(status);
    if (error) {
      save(name, status);
      await page.screenshot({ path: join(out, `${name}-error.png`) });
      throw new Error(`${name}: the page shows an error while waiting for ${what}: ${error}`);
    }
    if (Date.now() - started > timeout) {
      save(name, status);
      await page.screenshot({ path: join(out, `${name}-timeout.png`) });
      throw new Error(`${name}: timed out after ${timeout / 1000} s waiting for ${what}`);
    }
    await page.waitForTimeout(250);
  }
}

// Lets the page draw `n` more frames (so the canvas shows the latest state).
async function frames(page, n) {
  await page.evaluate((n) => new Promise((done) => {
    const step = (left) => (left === 0 ? done() : requestAnimationFrame(() => step(left - 1)));
    step(n);
  }), n);
}

async function shoot(page, name, status) {
  await frames(page, 5);
  await page.locator('#illum-canvas').screenshot({ path: join(out, `${name}.png`) });
  save(name, status ?? await statusOf(page));
}

// Clicks like a person: move, press, release a moment later, so that egui (drawing a few
// frames a second here) sees the pointer over the button and the press before the release.
async function click(page, x, y) {
  await page.mouse.move(x, y);
  await page.waitForTimeout(300);
  await page.mouse.down();
  await page.waitForTimeout(300);
  await page.mouse.up();
}

async function open(browser, query) {
  const page = await browser.newPage({ viewport: { width: 960, height: 600 }, deviceScaleFactor: 1 });
  page.on('console', (m) => { if (m.type() === 'error') console.log(`  console: ${m.text()}`); });
  page.on('pageerror', (e) => console.log(`  page error: ${e}`));
  await page.goto(url + query);
  return page;
}

// What each kind of cell waits for before its screenshot.
const done = {
  pathtrace: ['the path tracer to reach its spp', (s) => s.pathtraceStopped === 'spp' && s.pathtraceMean],
  raster: ['raster frames', (s) => Number(s.windowFps) > 0 && s.viewRect],
  whitted: ['a Whitted frame', (s) => Number(s.whittedFrames) >= 1 && s.whittedMean],
  // The mode shows why it cannot render the scene (and draws its own scene meanwhile).
  refusal: ['the refusal and a frame', (s) => s.modeRefusal && Number(s.windowFps) > 0],
};

// The Cornell box's path-tracer page goes on with what a user does next: Save EXR, Denoise,
// and a bad scene file dropped on the window.
async function cornellExtras(page) {
  // Save EXR (the button's place in this 960 x 600 layout, left panel): a download.
  const [download] = await Promise.all([
    page.waitForEvent('download', { timeout }),
    click(page, 118, 558),
  ]);
  await download.saveAs(join(out, 'download.exr'));
  writeFileSync(join(out, 'download.name'), download.suggestedFilename());
  console.log(`[download] ${download.suggestedFilename()}`);

  // Denoise (the checkbox under Error view): the guides and the à-trous filter run on
  // SwiftShader, read back without waiting, and the panel shows the estimated errors.
  await click(page, 15, 237);
  const denoised = await waitFor(page, 'denoise', 'the denoised image',
    (s) => (s.pathtraceDenoise || '').startsWith('estimated error: noisy'));
  await shoot(page, 'denoise', denoised);
  await click(page, 15, 237);

  // A bad scene file dropped on the window: its error shows and the Cornell box stays.
  const transfer = await page.evaluateHandle(() => {
    const t = new DataTransfer();
    t.items.add(new File(['[camera]\nvfov = "wide"\n'], 'bad.toml', { type: 'text/plain' }));
    return t;
  });
  for (const type of ['dragenter', 'dragover', 'drop']) {
    await page.dispatchEvent('#illum-canvas', type, { dataTransfer: transfer });
  }
  const bad = await waitFor(page, 'bad-scene', 'the dropped file\'s error', (s) => s.openError);
  await shoot(page, 'bad-scene', bad);
}

// 1. A browser without WebGPU (no --enable-unsafe-webgpu on Linux): the explanation page.
{
  const browser = await chromium.launch({ executablePath, headless: true, args: quiet });
  const page = await open(browser, '');
  const status = await waitFor(page, 'no-webgpu', 'the WebGPU check', (s) => s.webgpu);
  status.messageVisible = String(await page.locator('#no-webgpu').isVisible());
  status.messageText = (await page.locator('#no-webgpu').innerText()).replace(/\s+/g, ' ');
  save('no-webgpu', status);

  // A browser with no WebGPU API at all (navigator.gpu removed before the page runs).
  const bare = await browser.newPage();
  await bare.addInitScript(() => { delete Navigator.prototype.gpu; });
  await bare.goto(url);
  const noApi = await waitFor(bare, 'no-webgpu-api', 'the WebGPU check', (s) => s.webgpu);
  noApi.messageVisible = String(await bare.locator('#no-webgpu').isVisible());
  save('no-webgpu-api', noApi);
  await browser.close();
}

// 2. With WebGPU (SwiftShader): the matrix of scenes and modes, then opening files.
const browser = await chromium.launch({ executablePath, headless: true, args: [...quiet, ...webgpu] });
try {
  for (const cell of matrix) {
    const started = Date.now();
    const page = await open(browser, cell.query);
    const [what, predicate] = done[cell.expect];
    const status = await waitFor(page, cell.name, what, predicate);
    await shoot(page, cell.name, status);
    console.log(`[${cell.name}] ${cell.query}: ${((Date.now() - started) / 1000).toFixed(1)} s`);
    if (cell.name === 'cornell-pathtrace') await cornellExtras(page);
    await page.close();
  }
  {
    // A scene the page does not have, named in the address: an error, the default scene stays.
    const page = await open(browser, '?scene=scenes/nope.toml');
    const status = await waitFor(page, 'missing-scene', 'the error', (s) => s.openError);
    save('missing-scene', status);

    // "Open file..." (top bar, this layout): the browser's file picker, given the Whitted
    // scene under another name; it opens in its file's mode, the raster.
    const [chooser] = await Promise.all([
      page.waitForEvent('filechooser', { timeout }),
      click(page, 875, 12),
    ]);
    const text = readFileSync(new URL('../../scenes/whitted.toml', import.meta.url));
    await chooser.setFiles({ name: 'picked.toml', mimeType: 'text/plain', buffer: text });
    const picked = await waitFor(page, 'picked-scene', 'the picked scene', (s) => s.scene === 'picked.toml');
    save('picked-scene', picked);

    // A scene that names a mesh file, picked alone: refused, naming the file to pick with it.
    // Then picked together with that file (a page sees no folders: the mesh is found by its
    // file name): it opens in its file's mode, Whitted.
    // The Rust test wrote the scene (<out>/mesh.toml) and its mesh (<out>/models/).
    const meshScene = { name: 'mesh.toml', mimeType: 'text/plain', buffer: readFileSync(join(out, 'mesh.toml')) };
    const pick = async (files) => {
      const [picker] = await Promise.all([page.waitForEvent('filechooser', { timeout }), click(page, 875, 12)]);
      await picker.setFiles(files);
    };
    await pick([meshScene]);
    const alone = await waitFor(page, 'mesh-alone', 'the missing mesh file\'s error',
      (s) => (s.openError || '').includes('icosphere-0.obj'));
    save('mesh-alone', alone);
    const obj = readFileSync(join(out, 'models', 'icosphere-0.obj'));
    await pick([meshScene, { name: 'icosphere-0.obj', mimeType: 'text/plain', buffer: obj }]);
    // Opened, in its mode. Its first frame is not awaited: SwiftShader did not finish building
    // a pipeline that traces triangles in 300 s (docs/web.md), and the hung GPU process blocks
    // screenshots, so this is the page's last step.
    const meshed = await waitFor(page, 'mesh-scene', 'the mesh scene opened',
      (s) => s.scene === 'mesh.toml' && !s.openError && s.mode === 'whitted');
    save('mesh-scene', meshed);
    await page.close();
  }
} finally {
  await browser.close();
}
console.log('browser run complete');
