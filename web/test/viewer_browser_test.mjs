// Browser test of the tailor web viewer: headless Chromium (Debian's /usr/bin/chromium) driven by
// playwright-core opens the viewer served by `tailor view`, waits for the first frame, and checks:
//   - no console errors and no uncaught page errors;
//   - the canvas is not blank (luminance variance);
//   - the patches, distortion and checker views change the picture (clicked in the panel);
//   - with --variants: the variant controls are shown and toggling them changes the picture;
//   - the seams view (key 5, the radio button, the test hook): red lines for visible seams (and
//     with --expect-invisible green ones for invisible seams) and the seam legend;
//   - with --eval FILE (the output of `tailor eval MODEL --json`): the viewer's visible seam share
//     of edge length and invisible share of seam length agree with eval's figures.
// Usage: node web/test/viewer_browser_test.mjs URL [--variants] [--expect-invisible] [--normal-map] [--eval FILE]
//        [--screenshots DIR]
// Exits 0 on success, 1 with a FAIL line otherwise.
import { chromium } from 'playwright-core';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const url = process.argv[2];
const expectVariants = process.argv.includes('--variants');
const expectInvisible = process.argv.includes('--expect-invisible');
const expectNormalMap = process.argv.includes('--normal-map');
const evalIndex = process.argv.indexOf('--eval');
const evaluation = evalIndex > 0 ? JSON.parse(fs.readFileSync(process.argv[evalIndex + 1], 'utf8')) : null;
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
// Pixels of a seam line colour the seams view must show beyond the texture view's: red lines are
// thousands of pixels on the test models, green ones (short invisible seams) a few dozen on the horse.
const kMinVisibleSeamPixels = 100;
const kMinInvisibleSeamPixels = 10;
const kRatioTolerance = 1e-6;  // viewer's seam figures against eval's (the same definition, in doubles)

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

  if (expectNormalMap) {
    // `tailor map --material`: the file's normal map and tangents shade the texture view.
    if (!(await page.evaluate(() => window.tailorViewer.hasNormalMap))) fail('the file\'s normal map is not used');
    const flat = await page.evaluate(() => { window.tailorViewer.setNormalMapping(false); return window.tailorViewer.pixelStats(); });
    await page.evaluate(() => window.tailorViewer.setNormalMapping(true));
    const change = signatureDistance(texture, flat);
    console.log(`normal map: change when turned off ${change.toFixed(1)}`);
    if (!(change > 1)) fail('turning the normal map off did not change the picture');
  } else if (await page.evaluate(() => window.tailorViewer.hasNormalMap)) {
    fail('a normal map is used for a file without one');
  }

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

  // The seams view: key 5, then the radio button and the hook agree.
  await page.keyboard.press('5');
  const seamsState = await page.evaluate(() => ({
    view: window.tailorViewer.state.view,
    radio: document.querySelector('input[name=view][value=seams]').checked,
    legend: getComputedStyle(document.getElementById('seam-legend')).display !== 'none',
  }));
  if (seamsState.view !== 'seams' || !seamsState.radio) fail(`key 5 did not switch to the seams view (${JSON.stringify(seamsState)})`);
  if (!seamsState.legend) fail('the seam legend is not shown in the seams view');
  const seams = await page.evaluate(() => window.tailorViewer.pixelStats());
  if (shotDir) await page.screenshot({ path: path.join(shotDir, 'viewer_seams.png') });
  const seamChange = signatureDistance(texture, seams);
  console.log(`seams view: variance ${seams.variance.toFixed(1)}, change from texture ${seamChange.toFixed(1)}, ` +
    `red pixels ${seams.seamPixels.visible} (texture view ${texture.seamPixels.visible}), ` +
    `green ${seams.seamPixels.invisible} (texture view ${texture.seamPixels.invisible})`);
  if (!(seamChange > kMinChange)) fail('switching to the seams view did not change the picture');
  if (!(seams.seamPixels.visible > texture.seamPixels.visible + kMinVisibleSeamPixels)) fail('no red (visible seam) lines in the seams view');
  if (expectInvisible && !(seams.seamPixels.invisible > texture.seamPixels.invisible + kMinInvisibleSeamPixels)) {
    fail('no green (invisible seam) lines in the seams view');
  }
  await page.click('input[name=view][value=texture]');
  const viaRadio = await page.evaluate(async () => {
    document.querySelector('input[name=view][value=seams]').click();
    const a = window.tailorViewer.state.view;
    window.tailorViewer.setView('texture');
    const b = window.tailorViewer.state.view;
    window.tailorViewer.setView('seams');
    return [a, b, window.tailorViewer.state.view];
  });
  if (viaRadio.join() !== 'seams,texture,seams') fail(`the seams radio button / hook did not switch views: ${viaRadio}`);
  const seamsAgain = await page.evaluate(() => window.tailorViewer.pixelStats());
  if (signatureDistance(seams, seamsAgain) > 0.5) fail('the seams view drawn twice differs');
  await page.click('input[name=view][value=texture]');

  if (evaluation) {
    const stats = await page.evaluate(() => window.tailorViewer.stats);
    console.log(`seam figures: visible ${stats.visibleSeamRatio} (eval ${evaluation.visible_seam_ratio}), ` +
      `invisible ${stats.seamInvisibleRatio} (eval ${evaluation.seam_invisible_ratio}), seam edges ${stats.seams.seamEdges} (eval ${evaluation.seam_edges})`);
    if (!(Math.abs(stats.visibleSeamRatio - evaluation.visible_seam_ratio) < kRatioTolerance)) fail('visible seam ratio differs from tailor eval');
    if (!(Math.abs(stats.seamInvisibleRatio - evaluation.seam_invisible_ratio) < kRatioTolerance)) fail('invisible seam ratio differs from tailor eval');
    if (stats.seams.seamEdges !== evaluation.seam_edges) fail('seam edge count differs from tailor eval');
    if (!info.text.includes('visible seams')) fail(`the stats line has no seam figures: ${info.text}`);
  }

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
