// Browser test of the tailor web viewer: headless Chromium (Debian's /usr/bin/chromium) driven by
// playwright-core opens the viewer served by `tailor view`, waits for the first frame, and checks:
//   - no console errors and no uncaught page errors;
//   - the canvas is not blank (luminance variance);
//   - the patches, distortion and checker views change the picture (clicked in the panel);
//   - with --variants: the variant controls are shown and toggling them changes the picture.
// Usage: node web/test/viewer_browser_test.mjs URL [--variants] [--screenshots DIR]
// Exits 0 on success, 1 with a FAIL line otherwise.
import { chromium } from 'playwright-core';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const url = process.argv[2];
const expectVariants = process.argv.includes('--variants');
// --screenshots DIR: also save a PNG of each view there (for looking at, not for judging).
const shotIndex = process.argv.indexOf('--screenshots');
const shotDir = shotIndex > 0 ? process.argv[shotIndex + 1] : null;
if (!url) {
  console.error('usage: node viewer_browser_test.mjs URL [--variants]');
  process.exit(2);
}

// Without the background-networking flags Chromium keeps calling home, which floods a closed network.
const kArgs = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  // WebGL on the CPU (SwiftShader): --disable-gpu leaves WebGL to it, recent Chromium wants it explicit.
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];
const kFrameTimeoutMs = 60000;
const kMinVariance = 50;   // luminance variance of a textured mesh on a plain background is in the hundreds
const kMinChange = 8;      // mean absolute difference (0..255) of the 100x75 RGB thumbnails, over the model

function fail(message) {
  console.log(`FAIL: ${message}`);
  process.exitCode = 1;
}

// The viewer's clear colour: thumbnail cells of this colour in both pictures are background.
const kBackground = [236, 238, 242];

/** Mean absolute RGB difference over the thumbnail cells that show the model in either picture. */
function signatureDistance(a, b) {
  const isBackground = (grid, cell) => [0, 1, 2].every((c) => Math.abs(grid[3 * cell + c] - kBackground[c]) < 3);
  let sum = 0;
  let cells = 0;
  for (let cell = 0; cell < a.grid.length / 3; ++cell) {
    if (isBackground(a.grid, cell) && isBackground(b.grid, cell)) continue;
    for (let c = 0; c < 3; ++c) sum += Math.abs(a.grid[3 * cell + c] - b.grid[3 * cell + c]);
    cells += 1;
  }
  return cells > 0 ? sum / (3 * cells) : 0;
}

const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'tailor-chromium-'));
let context;
try {
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: kArgs,
    viewport: { width: 800, height: 600 },
  });
  const page = context.pages()[0] || (await context.newPage());
  const errors = [];
  page.on('console', (msg) => { if (msg.type() === 'error') errors.push(`console: ${msg.text()}`); });
  page.on('pageerror', (err) => errors.push(`page: ${err.message}`));

  await page.goto(url, { waitUntil: 'load' });
  await page.waitForFunction(() => window.tailorViewer && window.tailorViewer.ready && window.tailorViewer.frames > 0,
    null, { timeout: kFrameTimeoutMs });
  const info = await page.evaluate(() => ({ stats: window.tailorViewer.stats, text: document.getElementById('info').textContent }));
  console.log(`viewer: ${info.text}`);
  if (!(info.stats.faces > 0)) fail('the viewer reports no faces');

  const texture = await page.evaluate(() => window.tailorViewer.pixelStats());
  if (shotDir) await page.screenshot({ path: path.join(shotDir, 'viewer_texture.png') });
  console.log(`texture view: ${texture.width}x${texture.height}, mean ${texture.mean.toFixed(1)}, variance ${texture.variance.toFixed(1)}`);
  if (!(texture.variance > kMinVariance)) fail(`the canvas looks blank (variance ${texture.variance.toFixed(1)})`);

  const views = {};
  for (const view of ['patches', 'distortion', 'checker']) {
    await page.click(`input[name=view][value=${view}]`);
    views[view] = await page.evaluate(() => window.tailorViewer.pixelStats());
    if (shotDir) await page.screenshot({ path: path.join(shotDir, `viewer_${view}.png`) });
    const change = signatureDistance(texture, views[view]);
    console.log(`${view} view: variance ${views[view].variance.toFixed(1)}, change from texture ${change.toFixed(1)}`);
    if (!(change > kMinChange)) fail(`switching to the ${view} view did not change the picture`);
    if (!(views[view].variance > kMinVariance)) fail(`the ${view} view looks blank`);
  }
  const legendShown = await page.evaluate(() => {
    window.tailorViewer.setView('distortion');
    return getComputedStyle(document.getElementById('legend')).display !== 'none';
  });
  if (!legendShown) fail('the distortion legend is not shown');

  await page.click('input[name=view][value=texture]');
  await page.click('#wireframe');
  const wire = await page.evaluate(() => window.tailorViewer.pixelStats());
  if (!(signatureDistance(texture, wire) > 1)) fail('the wireframe toggle did not change the picture');
  await page.click('#wireframe');

  if (expectVariants) {
    const visible = await page.isVisible('#variant-controls');
    if (!visible) fail('variant controls are hidden although variants were given');
    const withVariants = await page.evaluate(() => window.tailorViewer.pixelStats());
    await page.click('#variants');
    const without = await page.evaluate(() => window.tailorViewer.pixelStats());
    const change = signatureDistance(withVariants, without);
    console.log(`variants on/off: change ${change.toFixed(2)}`);
    if (!(change > 0.2)) fail('turning the tile variants off did not change the picture');
    if (!(withVariants.variance > kMinVariance)) fail('the variant texture view looks blank');
  }

  // Let pending work (late console errors) surface before judging.
  await page.waitForTimeout(200);
  for (const e of errors) fail(e);
  if (process.exitCode !== 1) console.log('PASS: viewer renders, switches views, no console errors');
} catch (e) {
  fail(e && e.message ? e.message.split('\n')[0] : String(e));
} finally {
  if (context) await context.close().catch(() => {});
  fs.rmSync(userDataDir, { recursive: true, force: true });
}
