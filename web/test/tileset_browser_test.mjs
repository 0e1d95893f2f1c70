// Browser test of the viewer's tileset view: headless Chromium (Debian's /usr/bin/chromium) driven
// by playwright-core opens `tailor view OUTDIR/tileset.json` with 3d-tiles-renderer's error target
// at 0 (every leaf wanted) and checks:
//   - no console errors, no uncaught page errors, no tile that failed to load;
//   - every leaf tile of the tileset (the nodes without children) was loaded;
//   - the picture shows the textured scan: the model covers part of the canvas, and its pixels vary
//     as a texture does (a blank or untextured model would not);
//   - with the default error target and the whole model in view, fewer tiles are loaded than exist.
// Usage: node web/test/tileset_browser_test.mjs URL TILESET_JSON [--screenshot FILE]
// Exits 0 on success, 1 with a FAIL line otherwise.
import { chromium } from 'playwright-core';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const [url, tilesetPath] = process.argv.slice(2, 4);
const shotIndex = process.argv.indexOf('--screenshot');
const shot = shotIndex > 0 ? process.argv[shotIndex + 1] : null;
if (!url || !tilesetPath) {
  console.error('usage: node tileset_browser_test.mjs URL TILESET_JSON [--screenshot FILE]');
  process.exit(2);
}

const kArgs = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];
const kTimeoutMs = 90000;
const kBackground = [236, 238, 242];  // the viewer's clear colour
const kMinCoverage = 0.02;            // share of thumbnail cells that show the model (the root sphere is framed)
const kMinModelDeviation = 6;         // RGB standard deviation over the model's cells: a texture, not a flat colour

function fail(message) {
  console.log(`FAIL: ${message}`);
  process.exitCode = 1;
}

const leaves = [];
const all = [];
(function walk(node) {
  if (node.content) all.push(node.content.uri);
  if (!node.children || node.children.length === 0) {
    if (node.content) leaves.push(node.content.uri);
    return;
  }
  node.children.forEach(walk);
})(JSON.parse(fs.readFileSync(tilesetPath, 'utf8')).root);

async function open(context, query) {
  const page = await context.newPage();
  const errors = [];
  page.on('console', (msg) => { if (msg.type() === 'error') errors.push(`console: ${msg.text()}`); });
  page.on('pageerror', (err) => errors.push(`page: ${err.message}`));
  await page.goto(url + query, { waitUntil: 'load' });
  await page.waitForFunction(() => window.tailorTiles && window.tailorTiles.ready && window.tailorTiles.frames > 0,
    null, { timeout: kTimeoutMs });
  return { page, errors };
}

const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'tailor-chromium-'));
let context;
try {
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium', headless: true, args: kArgs, viewport: { width: 800, height: 600 },
  });
  const { page, errors } = await open(context, '?errorTarget=0');
  const loadedAll = await page.waitForFunction((wanted) => {
    const loaded = new Set(window.tailorTiles.loaded);
    return wanted.every((uri) => loaded.has(uri)) || window.tailorTiles.errors.length > 0;
  }, leaves, { timeout: kTimeoutMs }).then(() => true, () => false);
  const loaded = await page.evaluate(() => window.tailorTiles.loaded);
  const missing = leaves.filter((uri) => !loaded.includes(uri));
  console.log(`tileset: ${all.length} tiles, ${leaves.length} leaves; loaded ${loaded.length}, leaves missing ${missing.length}`);
  if (!loadedAll || missing.length) fail(`leaf tiles not loaded: ${missing.slice(0, 5).join(', ')}`);
  const tileErrors = await page.evaluate(() => window.tailorTiles.errors);
  if (tileErrors.length) fail(`tiles failed to load: ${tileErrors.slice(0, 3).join('; ')}`);
  // A few frames after the last tile, then the picture.
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const stats = await page.evaluate(() => window.tailorTiles.pixelStats());
  if (shot) await page.screenshot({ path: shot });
  const cells = stats.grid.length / 3;
  const model = [];
  for (let cell = 0; cell < cells; ++cell) {
    const rgb = [0, 1, 2].map((c) => stats.grid[3 * cell + c]);
    if (!rgb.every((v, c) => Math.abs(v - kBackground[c]) < 3)) model.push(rgb);
  }
  const coverage = model.length / cells;
  const mean = [0, 1, 2].map((c) => model.reduce((s, v) => s + v[c], 0) / Math.max(model.length, 1));
  const deviation = Math.sqrt(model.reduce((s, v) => s + [0, 1, 2].reduce((t, c) => t + (v[c] - mean[c]) ** 2, 0), 0)
    / Math.max(3 * model.length, 1));
  console.log(`picture: model on ${(100 * coverage).toFixed(1)} % of the canvas, RGB deviation ${deviation.toFixed(1)}`);
  if (!(coverage > kMinCoverage)) fail(`the model covers ${(100 * coverage).toFixed(1)} % of the canvas`);
  if (!(deviation > kMinModelDeviation)) fail(`the model looks untextured (deviation ${deviation.toFixed(1)})`);
  for (const e of errors) fail(e);
  await page.close();

  // The default error target with the whole model in view: the coarse levels suffice.
  if (all.length > leaves.length) {
    const far = await open(context, '');
    await far.page.waitForFunction(() => window.tailorTiles.loaded.length > 0, null, { timeout: kTimeoutMs });
    await far.page.waitForTimeout(2000);
    const count = (await far.page.evaluate(() => window.tailorTiles.loaded)).length;
    console.log(`default error target: ${count} of ${all.length} tiles loaded`);
    if (!(count < all.length)) fail('every tile was loaded for a view of the whole model');
    for (const e of far.errors) fail(e);
  }
} catch (e) {
  fail(e.message);
} finally {
  if (context) await context.close();
  fs.rmSync(userDataDir, { recursive: true, force: true });
}
if (!process.exitCode) console.log('tileset browser test: ok');
