// Browser test of `tailor edit`'s page: headless Chromium (Debian's /usr/bin/chromium) driven by
// playwright-core opens the page served by `tailor edit`, and with real mouse events:
//   - loads: the first frame, no console errors, a canvas that is not blank;
//   - paints a stroke of seam faces with the brush: faces are marked, the server holds them, and
//     once settled the patches view changed (pixels differ);
//   - undo (the button) restores the previous corner UVs bit for bit (GET /api/uv), in the page too;
//   - redo, then save (the button): the .glb, seam faces and strokes are written, and replaying the
//     printed `tailor map` command gives the same bytes as the saved .glb and as GET /api/model.glb;
//   - an orientation stroke drawn with the stroke tool reaches the server;
//   - a malformed edit gets 400 and changes nothing.
// With --bench N: only paints N brush strokes, waiting for the settle after each, and prints the
// time from the end of each stroke (pointer up) to the frame that shows its result.
// Usage: node web/test/edit_browser_test.mjs URL TAILOR_BINARY [--screenshots DIR] [--bench N]
// Exits 0 on success, 1 with a FAIL line otherwise.
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const url = process.argv[2];
const tailor = process.argv[3];
const shotIndex = process.argv.indexOf('--screenshots');
const shotDir = shotIndex > 0 ? process.argv[shotIndex + 1] : null;
const benchIndex = process.argv.indexOf('--bench');
const benchStrokes = benchIndex > 0 ? Number(process.argv[benchIndex + 1]) : 0;
if (!url || !tailor) {
  console.error('usage: node edit_browser_test.mjs URL TAILOR_BINARY [--screenshots DIR] [--bench N]');
  process.exit(2);
}

const kArgs = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];
const kLoadTimeoutMs = 120000;
const kSettleTimeoutMs = 120000;
const kMinVariance = 50;
const kMinPatchChange = 0.5;  // mean absolute thumbnail difference (0..255) of the patches view after the stroke
const kBackground = [236, 238, 242];

function fail(message) {
  console.log(`FAIL: ${message}`);
  process.exitCode = 1;
}

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

async function getJson(p) {
  const r = await fetch(new URL(p, url));
  if (!r.ok) throw new Error(`${p}: ${r.status}`);
  return r.json();
}

async function getBytes(p) {
  const r = await fetch(new URL(p, url));
  if (!r.ok) throw new Error(`${p}: ${r.status}`);
  return Buffer.from(await r.arrayBuffer());
}

/** Waits until the page has sent and drawn everything and the server settled. */
async function waitSettled(page) {
  await page.waitForFunction(() => window.tailorEdit.idle && window.tailorEdit.settled, null,
    { timeout: kSettleTimeoutMs, polling: 50 });
}

/** A brush stroke with real mouse events: a horizontal line across the model's middle. */
async function brushStroke(page, box, from, to, y) {
  await page.mouse.move(box.x + from * box.width, box.y + y * box.height);
  await page.mouse.down();
  const steps = 12;
  for (let i = 1; i <= steps; ++i) {
    await page.mouse.move(box.x + (from + ((to - from) * i) / steps) * box.width, box.y + y * box.height);
    await page.waitForTimeout(15);
  }
  await page.mouse.up();
}

const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'tailor-chromium-'));
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tailor-edit-test-'));
let context;
try {
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium', headless: true, args: kArgs, viewport: { width: 800, height: 600 },
  });
  const page = context.pages()[0] || (await context.newPage());
  const errors = [];
  page.on('console', (msg) => { if (msg.type() === 'error') errors.push(`console: ${msg.text()}`); });
  page.on('pageerror', (err) => errors.push(`page: ${err.message}`));

  const loadStart = Date.now();
  await page.goto(url, { waitUntil: 'load' });
  await page.waitForFunction(() => window.tailorEdit && window.tailorEdit.ready && window.tailorEdit.frames > 0, null,
    { timeout: kLoadTimeoutMs });
  const info = await getJson('/api/state');
  console.log(`edit page: ${info.name}, ${info.faces} faces, loaded in ${((Date.now() - loadStart) / 1000).toFixed(2)} s`);
  const box = await page.locator('#view canvas').boundingBox();

  if (benchStrokes > 0) {
    await page.evaluate(() => { window.tailorEdit.setView('patches'); window.tailorEdit.setBrush(12); });
    const latencies = [];
    for (let i = 0; i < benchStrokes; ++i) {
      // Alternately mark a band and erase it again: every stroke changes as many faces.
      const erase = i % 2 === 1;
      await page.evaluate((tool) => window.tailorEdit.setTool(tool), erase ? 'erase' : 'brush');
      const marked = await page.evaluate(() => window.tailorEdit.markedCount);
      await brushStroke(page, box, 0.38, 0.62, 0.45);
      if ((await page.evaluate(() => window.tailorEdit.markedCount)) === marked) throw new Error(`stroke ${i} painted no face`);
      await page.waitForFunction((n) => window.tailorEdit.latencies.length > n, latencies.length, { timeout: kSettleTimeoutMs });
      latencies.push((await page.evaluate(() => window.tailorEdit.latencies)).at(-1));
      const parts = (await page.evaluate(() => window.tailorEdit.latencyParts)).at(-1);
      console.log(`stroke ${i}: ${latencies.at(-1).toFixed(0)} ms (last request: ` +
        Object.entries(parts).filter(([k]) => k.endsWith('Ms')).map(([k, v]) => `${k} ${v.toFixed(0)}`).join(', ') +
        `, ${parts.changed} faces changed)`);
      await waitSettled(page);
    }
    const sorted = [...latencies].sort((a, b) => a - b);
    console.log(`BENCH ${info.name} faces=${info.faces} strokes=${latencies.length} ` +
      `median_ms=${sorted[Math.floor(sorted.length / 2)].toFixed(0)} max_ms=${sorted.at(-1).toFixed(0)} ` +
      `all_ms=${latencies.map((x) => x.toFixed(0)).join(',')}`);
  } else {
    // --- load ---
    const texture = await page.evaluate(() => window.tailorEdit.pixelStats());
    if (!(texture.variance > kMinVariance)) fail(`the canvas looks blank (variance ${texture.variance.toFixed(1)})`);
    if (shotDir) await page.screenshot({ path: path.join(shotDir, 'edit_texture.png') });

    // --- paint a stroke of seam faces ---
    await page.evaluate(() => window.tailorEdit.setView('patches'));
    const before = await page.evaluate(() => window.tailorEdit.pixelStats());
    const start = await getJson('/api/state');
    const v0 = start.version;
    const markedStart = start.seam_faces.length;
    const uvBefore = await getBytes(`/api/uv?version=${v0}`);
    await page.evaluate(() => { window.tailorEdit.setTool('brush'); window.tailorEdit.setBrush(14); });
    await brushStroke(page, box, 0.35, 0.65, 0.5);
    await waitSettled(page);
    const marked = await page.evaluate(() => window.tailorEdit.markedCount);
    const afterState = await getJson('/api/state');
    console.log(`stroke: ${marked} faces marked in the page, ${afterState.seam_faces.length} on the server, ` +
      `version ${v0} -> ${afterState.version}, latency ${(await page.evaluate(() => window.tailorEdit.latencies)).map((x) => x.toFixed(0))} ms`);
    if (!(marked > markedStart)) fail('the brush marked no face');
    if (afterState.seam_faces.length !== marked) fail(`the server holds ${afterState.seam_faces.length} seam faces, the page ${marked}`);
    if (!(afterState.version > v0)) fail('the stroke made no new version');
    // The frame on screen was built by redrawing the touched faces only: it must equal a full frame.
    const partialError = await page.evaluate(() => window.tailorEdit.partialFrameError());
    console.log(`partial redraws: ${partialError} pixels differ from a full frame`);
    if (partialError !== 0) fail(`the frame built by partial redraws differs from a full frame in ${partialError} pixels`);
    const after = await page.evaluate(() => window.tailorEdit.pixelStats());
    const change = signatureDistance(before, after);
    console.log(`patches view: change after the stroke ${change.toFixed(2)}`);
    if (!(change > kMinPatchChange)) fail(`the patches view did not change after the stroke (${change.toFixed(2)})`);
    if (shotDir) {
      await page.screenshot({ path: path.join(shotDir, 'edit_patches.png') });
      await page.evaluate(() => window.tailorEdit.setView('seams'));
      await page.screenshot({ path: path.join(shotDir, 'edit_seams.png') });
      await page.evaluate(() => window.tailorEdit.setView('patches'));
    }
    const uvAfter = await getBytes(`/api/uv?version=${afterState.version}`);
    if (uvAfter.equals(uvBefore)) fail('the stroke did not change the UVs');

    // --- undo: the previous UVs bit for bit ---
    await page.click('#undo');
    await waitSettled(page);
    const vUndo = (await getJson('/api/status')).version;
    const uvUndo = await getBytes(`/api/uv?version=${vUndo}`);
    if (!uvUndo.equals(uvBefore)) fail(`undo did not restore the previous UVs bit for bit (version ${vUndo})`);
    const shown = await page.evaluate(() => window.tailorEdit.shownUvs());
    const shownBytes = Buffer.from(new Float32Array(shown).buffer);
    if (!shownBytes.equals(uvBefore)) fail('the page does not show the restored UVs after undo');
    if ((await page.evaluate(() => window.tailorEdit.markedCount)) !== markedStart) fail('undo did not unmark the stroke\'s faces in the page');
    console.log(`undo: version ${vUndo}, UVs identical to version ${v0}: ${uvUndo.equals(uvBefore)}`);

    // --- redo, an orientation stroke, save and replay ---
    await page.click('#redo');
    await waitSettled(page);
    await page.evaluate(() => window.tailorEdit.setTool('stroke'));
    await brushStroke(page, box, 0.4, 0.6, 0.45);
    await waitSettled(page);
    const strokes = (await getJson('/api/state')).strokes;
    if (strokes.length !== start.strokes.length + 1 || !(strokes.at(-1).points.length >= 2)) {
      fail(`the stroke tool sent ${JSON.stringify(strokes).slice(0, 200)}`);
    }
    if (shotDir) {
      await page.evaluate(() => window.tailorEdit.setView('texture'));
      await page.screenshot({ path: path.join(shotDir, 'edit_stroke.png') });
    }

    // A malformed edit: 400 with one line, nothing changed.
    const vBad = (await getJson('/api/status')).version;
    const bad = await fetch(new URL('/api/edit', url), {
      method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{"add_seam_faces": [-1]}',
    });
    const badText = await bad.text();
    if (bad.status !== 400 || badText.trim().split('\n').length !== 1) fail(`a malformed edit got ${bad.status}: ${badText}`);
    if ((await getJson('/api/status')).version !== vBad) fail('a malformed edit changed the version');

    await page.click('#save');
    await page.waitForFunction(() => document.getElementById('saved').textContent.includes('replay:'), null, { timeout: kSettleTimeoutMs });
    const saved = await page.evaluate(() => document.getElementById('saved').textContent);
    const command = saved.slice(saved.indexOf('replay: ') + 8).trim();
    const glb = fs.readFileSync(afterState.output);
    const model = await getBytes('/api/model.glb');
    if (!model.equals(glb)) fail('GET /api/model.glb differs from the saved .glb');
    const replay = path.join(tmp, 'replay.glb');
    const replayCommand = command.replace(/^tailor /, `'${tailor}' `).replace(/ -o \S+$/, ` -o '${replay}' -q`);
    execFileSync('bash', ['-c', replayCommand], { stdio: 'inherit' });
    const same = fs.readFileSync(replay).equals(glb);
    console.log(`save: ${glb.length} bytes; replay with tailor map: ${same ? 'identical' : 'DIFFERENT'}`);
    if (!same) fail(`replaying '${command}' gave other bytes than the saved .glb`);

    // Thesis mode greys the inputs of the options it does not read (the state's patches_only), no others.
    await page.selectOption('#opt-mode', 'thesis');
    await page.waitForFunction(() => document.getElementById('opt-max_stretch').disabled, null,
      { timeout: kSettleTimeoutMs });
    await waitSettled(page);
    const greyed = await page.evaluate(() =>
      [...document.querySelectorAll('[id^="opt-"]')].filter((e) => e.disabled).map((e) => e.id.slice(4)).sort());
    const expected = ['close_cracks', 'crack_rings', 'field_following', 'max_stretch', 'min_patch_faces', 'shorten_seams'];
    if (greyed.join() !== expected.join()) fail(`thesis mode greyed ${greyed.join(', ')}, not ${expected.join(', ')}`);
  }

  await page.waitForTimeout(200);
  for (const e of errors) fail(e);
  if (process.exitCode !== 1) console.log('PASS: tailor edit page');
} catch (e) {
  fail(e && e.message ? e.message.split('\n')[0] : String(e));
} finally {
  if (context) await context.close().catch(() => {});
  fs.rmSync(userDataDir, { recursive: true, force: true });
  fs.rmSync(tmp, { recursive: true, force: true });
}
