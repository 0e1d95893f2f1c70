// tailor's editing page (`tailor edit`, docs/edit-api.md): the textured mesh of an EditSession with a
// brush that marks and unmarks seam faces, orientation strokes drawn on the surface, the mapping
// options, undo / redo and save. Every edit goes to POST /api/edit while the user paints (at most
// one request in flight, the faces painted meanwhile sent with the next), and the answer's version
// is drawn from GET /api/uv; when the user pauses the server settles to the full map, which the
// page picks up by polling GET /api/status.
// Picking renders face ids into an offscreen buffer once per camera position (gl_VertexID / 3 of the
// unindexed mesh), so a brush of any size costs a lookup per pixel, even on a million faces.
// A test hook (window.tailorEdit) exposes the state, pictures and the stroke-to-frame latency.
import * as THREE from 'three';
import { kViews, kSeamColors, createSurfaceMaterial, updateSurfaceMaterial } from './surface_material.js';
import { createView, prepareTexture, pixelStats } from './scene_tools.js';
import { EditSurface, parseMesh } from './edit_surface.js';

const kSendEveryMs = 100;   // while painting, an edit at most this often
const kStatusPollMs = 200;  // while the server settles, its status this often
const kStrokeStepPx = 6;    // a stroke point every this many screen pixels

const state = {
  view: 'texture', scale: 1, rotationDeg: 0, wireframe: false, seams: true, useVariants: false,
  normalMapping: false, seed: 1, checkerSquares: 8, distortionRange: 2, showMarked: true,
  tool: 'brush', brushPx: 16, reachPercent: 10, showStrokes: true,
};
const textures = { map: null, normalMap: null, variants: [], blank: null };
const session = {
  info: null, surface: null, mesh: null, shownVersion: -1, serverVersion: -1, settled: true,
  inFlight: 0, pendingAdd: new Set(), pendingRemove: new Set(), lastSend: 0, options: {},
};
// The stroke-to-frame latencies, and the parts of the last update (request, server, UV fetch, page update, draw).
const timing = { latencies: [], strokeEnd: 0, measuring: 0, last: {}, parts: [] };
let frames = 0;
let ready = false;

const container = document.getElementById('view');
// No multisampling: software WebGL (no GPU) spends most of a frame on it; the shader's lines are smooth anyway.
const view = createView(container, () => { redrawAll(); pickStale = true; }, { antialias: false });
const { renderer, scene, camera, controls } = view;
const material = createSurfaceMaterial();
// Strokes are drawn over the surface, in their own scene (not picked, not in the frame buffer below).
const strokeGroup = new THREE.Group();
const strokeScene = new THREE.Scene();
strokeScene.add(strokeGroup);

// Frames: the surface is drawn into `frame.target` and copied to the screen with the strokes on top.
// After an edit only the faces it touched are drawn again over the previous frame (same positions,
// same depths): a frame costs what the edit changed, not the mesh's size, which matters with
// software WebGL (no GPU), where a full frame of a million faces takes seconds.
const frame = { target: null, full: true, faces: new Set(), copy: true };
const patchScene = new THREE.Scene();
const patchMesh = new THREE.Mesh(new THREE.BufferGeometry(), null);
patchMesh.frustumCulled = false;
patchScene.add(patchMesh);
const copyScene = new THREE.Scene();
const copyCamera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
const copyMaterial = new THREE.ShaderMaterial({
  uniforms: { frame: { value: null } },
  vertexShader: 'void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }',
  fragmentShader: 'uniform sampler2D frame; void main() { gl_FragColor = texelFetch(frame, ivec2(gl_FragCoord.xy), 0); }',
  depthTest: false,
  depthWrite: false,
});
{
  const quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), copyMaterial);
  quad.frustumCulled = false;
  copyScene.add(quad);
}

function redrawAll() { frame.full = true; }
function redrawFaces(faces) { for (const f of faces) frame.faces.add(f); }

function showError(text) {
  const box = document.getElementById('error');
  box.textContent = text;
  box.style.display = 'block';
  console.error(text);
}
window.addEventListener('error', (e) => showError(`error: ${e.message}`));
window.addEventListener('unhandledrejection', (e) => showError(`error: ${e.reason && e.reason.message ? e.reason.message : e.reason}`));

async function api(method, path, body) {
  const init = { method };
  if (method === 'POST') {
    init.headers = { 'Content-Type': 'application/json' };
    init.body = JSON.stringify(body || {});
  }
  const response = await fetch(path, init);
  if (!response.ok) {
    const reason = (await response.text()).trim();
    const error = new Error(`${path}: ${response.status} ${reason}`);
    error.status = response.status;
    throw error;
  }
  return response;
}

function setStatus() {
  const s = session;
  const latency = timing.latencies.length ? `, last stroke to frame ${timing.latencies[timing.latencies.length - 1].toFixed(0)} ms` : '';
  document.getElementById('status').textContent =
    `version ${s.shownVersion}${s.settled && s.shownVersion === s.serverVersion ? ', settled' : ', settling\u2026'}${latency}`;
}

// --- versions ----------------------------------------------------------------------------------------

/** Draws `version` (fetches its UVs) unless a newer one is shown. */
async function showVersion(version) {
  if (version <= session.shownVersion) return;
  // Only the faces that changed since the version shown (all of them when the server no longer keeps it).
  const shown = session.shownVersion;
  timing.last.fetchStart = performance.now();
  let response;
  try {
    response = await api('GET', `/api/uv?version=${version}&since=${shown}`);
  } catch (e) {
    if (e.status === 404) return;  // no longer kept: a newer version is on its way
    throw e;
  }
  const delta = response.headers.get('X-Tailor-Delta') === '1';
  const buffer = await response.arrayBuffer();
  if (version <= session.shownVersion || session.shownVersion !== shown) return;
  const fetched = performance.now();
  const changed = delta ? session.surface.applyDelta(buffer) : session.surface.setUvs(new Float32Array(buffer));
  timing.last.fetchMs = fetched - timing.last.fetchStart;
  timing.last.updateMs = performance.now() - fetched;
  timing.last.changed = changed;
  session.shownVersion = version;
  updateInfo(changed);
  redrawFaces(session.surface.lastTouched || []);
  setStatus();
}

/** Draws what changed (see `frame`); false when nothing did. */
function draw() {
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  if (!frame.target || frame.target.width !== w || frame.target.height !== h) {
    if (frame.target) frame.target.dispose();
    frame.target = new THREE.WebGLRenderTarget(w, h, { depthBuffer: true });
    copyMaterial.uniforms.frame.value = frame.target.texture;
    frame.full = true;
  }
  const faces = frame.faces.size;
  if (!frame.full && faces === 0 && !frame.copy) return false;
  renderer.setRenderTarget(frame.target);
  if (frame.full || faces > session.surface.faces / 4) {
    renderer.clear();
    renderer.render(scene, camera);
  } else if (faces > 0) {
    patchMesh.geometry.dispose();
    patchMesh.geometry = session.surface.subsetGeometry([...frame.faces]);
    patchMesh.material = material;
    renderer.autoClear = false;
    renderer.render(patchScene, camera);
    renderer.autoClear = true;
  }
  renderer.setRenderTarget(null);
  renderer.render(copyScene, copyCamera);
  if (state.showStrokes && strokeGroup.children.length) {
    renderer.autoClear = false;
    renderer.render(strokeScene, camera);
    renderer.autoClear = true;
  }
  frame.full = false;
  frame.faces.clear();
  frame.copy = false;
  frames += 1;
  return true;
}

/** Draws a frame now and waits for the GPU to finish it (a one-pixel read). */
function drawNow() {
  const start = performance.now();
  draw();
  const gl = renderer.getContext();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  timing.last.drawMs = performance.now() - start;
}

/** After an edit's answer: draw its version; poll the status until the server settled. */
function edited(result) {
  session.serverVersion = Math.max(session.serverVersion, result.version);
  session.settled = result.settled;
  setStatus();
  if (!result.settled) pollStatus();
  return showVersion(result.version);
}

let polling = false;
async function pollStatus() {
  if (polling) return;
  polling = true;
  try {
    for (;;) {
      await new Promise((r) => setTimeout(r, kStatusPollMs));
      const status = await (await api('GET', '/api/status')).json();
      session.serverVersion = status.version;
      session.settled = status.settled;
      if (status.settled) {
        await showVersion(status.version);
        setStatus();
        if (session.inFlight === 0) break;
      }
    }
  } finally {
    polling = false;
  }
}

// --- edits -------------------------------------------------------------------------------------------

/**
 * Sends the faces painted so far: one request in flight, at most one every kSendEveryMs while the
 * button is down, the faces painted meanwhile going with the next. Every request of one stroke
 * after the first says "join", so the stroke is one undo step.
 */
let pump = null;
function schedulePaint() {
  if (!pump) pump = runPump().finally(() => { pump = null; });
  return pump;
}

async function runPump() {
  while (session.pendingAdd.size || session.pendingRemove.size) {
    const wait = kSendEveryMs - (performance.now() - session.lastSend);
    if (painting && wait > 0) await new Promise((r) => setTimeout(r, wait));
    await sendPainted();
  }
}

/** Sends the faces painted and not yet sent, as one edit. */
async function sendPainted() {
  const body = {};
  if (session.pendingAdd.size) body.add_seam_faces = [...session.pendingAdd];
  if (session.pendingRemove.size) body.remove_seam_faces = [...session.pendingRemove];
  const first = !session.strokeSent;
  if (!first) body.join = true;
  session.strokeSent = true;
  session.pendingAdd.clear();
  session.pendingRemove.clear();
  await send(body);
  if (first) session.firstAnswered = true;
}

/** One edit request (every kind: paint, stroke, options). */
async function send(body) {
  session.inFlight += 1;
  session.lastSend = performance.now();
  try {
    const start = performance.now();
    const result = await (await api('POST', '/api/edit', body)).json();
    timing.last.editMs = performance.now() - start;
    timing.last.serverMs = result.ms;
    await edited(result);
  } catch (e) {
    showError(e.message);
    await refreshState();  // the server refused it: show what it holds
  } finally {
    session.inFlight -= 1;
  }
}

async function undoRedo(which) {
  if (session.inFlight > 0) return;
  session.inFlight += 1;
  try {
    const result = await (await api('POST', `/api/${which}`)).json();
    await edited(result);
    await refreshState();
  } catch (e) {
    if (e.status !== 409) showError(e.message);  // 409: nothing to undo / redo
  } finally {
    session.inFlight -= 1;
  }
}

async function save() {
  const box = document.getElementById('saved');
  box.textContent = 'saving\u2026';
  try {
    const r = await (await api('POST', '/api/save')).json();
    box.textContent = `saved version ${r.version}: ${r.glb}, ${r.seam_faces}, ${r.strokes}\nreplay: ${r.command}`;
    return r;
  } catch (e) {
    box.textContent = '';
    showError(e.message);
    return null;
  }
}

/** The server's seam faces, strokes and options (after undo / redo or a refused edit). */
async function refreshState() {
  const info = await (await api('GET', '/api/state')).json();
  session.info = info;
  const flags = new Uint8Array(session.surface.faces);
  for (const f of info.seam_faces) flags[f] = 1;
  session.surface.setMarked(flags);
  session.surface.setSymmetry(info.options?.symmetry);
  drawStrokes(info.strokes);
  showOptions(info.options, info.patches_only);
  redrawAll();
}

function updateInfo(changed) {
  const c = session.surface.seamCounts();
  document.getElementById('info').textContent =
    `${session.surface.faces.toLocaleString('en')} faces, ${c.patches.toLocaleString('en')} patches, ` +
    `${c.visible.toLocaleString('en')} visible and ${c.invisible.toLocaleString('en')} invisible seam edges; ` +
    `last update changed ${changed.toLocaleString('en')} faces`;
}

// --- picking -----------------------------------------------------------------------------------------

const pickMaterial = new THREE.ShaderMaterial({
  vertexShader: /* glsl */ `
    flat out float vFace;
    void main() {
      vFace = float(gl_VertexID / 3);
      gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
    }`,
  fragmentShader: /* glsl */ `
    flat in float vFace;
    void main() {
      float id = vFace + 1.0;  // 0 is the background
      gl_FragColor = vec4(mod(id, 256.0), mod(floor(id / 256.0), 256.0), floor(id / 65536.0), 0.0) / 255.0;
    }`,
  side: THREE.DoubleSide,
});
let pickTarget = null;
let pickPixels = null;
let pickStale = true;

/** Face ids under the screen, rendered again when the camera moved. */
function updatePick() {
  if (!pickStale && pickPixels) return;
  const w = renderer.getContext().drawingBufferWidth;
  const h = renderer.getContext().drawingBufferHeight;
  if (!pickTarget || pickTarget.width !== w || pickTarget.height !== h) {
    if (pickTarget) pickTarget.dispose();
    pickTarget = new THREE.WebGLRenderTarget(w, h, { depthBuffer: true });
    pickPixels = new Uint8Array(4 * w * h);
  }
  const clear = renderer.getClearColor(new THREE.Color());
  const alpha = renderer.getClearAlpha();
  scene.overrideMaterial = pickMaterial;
  renderer.setRenderTarget(pickTarget);
  renderer.setClearColor(0x000000, 0);
  renderer.clear();
  renderer.render(scene, camera);
  renderer.readRenderTargetPixels(pickTarget, 0, 0, w, h, pickPixels);
  renderer.setRenderTarget(null);
  renderer.setClearColor(clear, alpha);
  scene.overrideMaterial = null;
  pickStale = false;
}

/** Device pixel of a pointer event (origin bottom left, as the pick buffer). */
function devicePixel(event) {
  const rect = renderer.domElement.getBoundingClientRect();
  const ratio = renderer.getContext().drawingBufferWidth / rect.width;
  return { x: (event.clientX - rect.left) * ratio, y: (rect.bottom - event.clientY) * ratio, ratio };
}

function faceAt(x, y) {
  const w = pickTarget.width;
  const h = pickTarget.height;
  const px = Math.round(x), py = Math.round(y);
  if (px < 0 || py < 0 || px >= w || py >= h) return -1;
  const i = 4 * (py * w + px);
  return pickPixels[i] + 256 * pickPixels[i + 1] + 65536 * pickPixels[i + 2] - 1;
}

/** Faces seen within the brush circle around the pointer. */
function facesUnderBrush(event) {
  const { x, y, ratio } = devicePixel(event);
  const r = state.brushPx * ratio;
  const faces = new Set();
  for (let dy = -Math.ceil(r); dy <= r; ++dy) {
    for (let dx = -Math.ceil(r); dx <= r; ++dx) {
      if (dx * dx + dy * dy > r * r) continue;
      const f = faceAt(x + dx, y + dy);
      if (f >= 0) faces.add(f);
    }
  }
  return faces;
}

/** The surface point under the pointer: the picked face's triangle hit by the camera ray. */
function surfacePoint(event) {
  const { x, y } = devicePixel(event);
  const f = faceAt(x, y);
  if (f < 0) return null;
  const rect = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
  const raycaster = new THREE.Raycaster();
  raycaster.setFromCamera(ndc, camera);
  const { index, position } = session.mesh;
  const corner = (k) => new THREE.Vector3().fromArray(position, 3 * index[3 * f + k]);
  const hit = raycaster.ray.intersectTriangle(corner(0), corner(1), corner(2), false, new THREE.Vector3());
  return hit;
}

// --- painting and strokes ----------------------------------------------------------------------------

let painting = false;
let strokePoints = [];
let strokeLine = null;
let lastStrokePixel = null;

function paintAt(event) {
  const faces = facesUnderBrush(event);
  const mark = state.tool === 'brush' ? 1 : 0;
  const fresh = [];
  for (const f of faces) {
    if (session.surface.marked[f] === mark) continue;
    fresh.push(f);
    if (mark) {
      session.pendingAdd.add(f);
      session.pendingRemove.delete(f);
    } else {
      session.pendingRemove.add(f);
      session.pendingAdd.delete(f);
    }
  }
  if (fresh.length) {
    session.surface.markFaces(fresh, mark);
    redrawFaces(fresh);
    schedulePaint();
  }
}

function strokeRadius() {
  const box = session.surface.geometry.boundingBox;
  return (state.reachPercent / 100) * box.getSize(new THREE.Vector3()).length();
}

function addStrokePoint(event) {
  if (lastStrokePixel && Math.hypot(event.clientX - lastStrokePixel[0], event.clientY - lastStrokePixel[1]) < kStrokeStepPx) return;
  const p = surfacePoint(event);
  if (!p) return;
  lastStrokePixel = [event.clientX, event.clientY];
  strokePoints.push(p);
  if (strokeLine) strokeGroup.remove(strokeLine);
  strokeLine = strokeObject(strokePoints, 0xff6a00);
  strokeGroup.add(strokeLine);
  frame.copy = true;
}

function strokeObject(points, color) {
  const geometry = new THREE.BufferGeometry().setFromPoints(points);
  const line = new THREE.Line(geometry, new THREE.LineBasicMaterial({ color, depthTest: false, transparent: true }));
  line.renderOrder = 2;
  return line;
}

function drawStrokes(strokes) {
  for (const child of [...strokeGroup.children]) {
    strokeGroup.remove(child);
    child.geometry.dispose();
  }
  strokeLine = null;
  for (const s of strokes) strokeGroup.add(strokeObject(s.points.map((p) => new THREE.Vector3(...p)), 0x1f5fd6));
  frame.copy = true;
}

function onPointerDown(event) {
  if (!ready || event.button !== 0 || state.tool === 'orbit') return;
  event.preventDefault();
  renderer.domElement.setPointerCapture(event.pointerId);
  updatePick();
  painting = true;
  session.strokeSent = false;
  session.firstAnswered = false;
  if (state.tool === 'stroke') {
    strokePoints = [];
    lastStrokePixel = null;
    addStrokePoint(event);
  } else {
    paintAt(event);
  }
}

function onPointerMove(event) {
  moveBrushRing(event);
  if (!painting) return;
  if (state.tool === 'stroke') addStrokePoint(event);
  else paintAt(event);
}

function onPointerUp(event) {
  if (!painting) return;
  painting = false;
  renderer.domElement.releasePointerCapture(event.pointerId);
  timing.strokeEnd = performance.now();
  if (state.tool === 'stroke') {
    const points = strokePoints.map((p) => [p.x, p.y, p.z]);
    strokePoints = [];
    if (points.length < 2) return;
    send({ strokes: [{ points, radius: strokeRadius() }] }).then(() => refreshState());
    return;
  }
  finishStroke();
}

/** Sends the stroke's last faces at once; the frame showing their version ends the latency measurement. */
async function finishStroke() {
  timing.measuring += 1;
  try {
    // The last faces go at once, beside a request still in flight: a stroke only marks or only
    // unmarks, so the two commute; only the stroke's first request (the one the others join) must
    // be answered before.
    if (pump && session.firstAnswered && (session.pendingAdd.size || session.pendingRemove.size)) {
      await Promise.all([pump, sendPainted()]);
    }
    while (pump || session.pendingAdd.size || session.pendingRemove.size) await schedulePaint();
    if (!session.strokeSent) return;  // the stroke painted nothing new
    drawNow();
    timing.latencies.push(performance.now() - timing.strokeEnd);
    timing.parts.push({ ...timing.last });
    setStatus();
  } finally {
    timing.measuring -= 1;
  }
}

function moveBrushRing(event) {
  const ring = document.getElementById('brush-ring');
  if (state.tool !== 'brush' && state.tool !== 'erase') {
    ring.style.display = 'none';
    return;
  }
  const r = state.brushPx;
  ring.style.display = 'block';
  ring.style.left = `${event.clientX - r}px`;
  ring.style.top = `${event.clientY - r}px`;
  ring.style.width = ring.style.height = `${2 * r}px`;
  ring.style.borderColor = state.tool === 'brush' ? 'rgba(230,120,0,0.95)' : 'rgba(20,20,30,0.8)';
}

// --- the panels --------------------------------------------------------------------------------------

const kOptionInputs = ['axis', 'smooth_passes', 'field_following', 'mode', 'scale', 'max_stretch', 'min_patch_faces',
  'crack_rings', 'shorten_seams', 'close_cracks'];

/**
 * Shows the session's options in the mapping panel (axis auto and field following auto stay shown),
 * those the thesis mode does not read (`patchesOnly`: the server refuses a change of them there, as
 * tailor map does) greyed in that mode.
 */
function showOptions(options, patchesOnly) {
  session.options = options;
  for (const key of kOptionInputs) {
    const input = document.getElementById(`opt-${key}`);
    if (document.activeElement === input) continue;
    const value = options[key];
    if (input.type === 'checkbox') input.checked = !!value;
    else if (key === 'axis' && input.value === 'auto' && ['x', 'y', 'z', 'pca'].includes(value)) continue;
    else if (key === 'field_following' && input.value === 'auto') continue;
    else if (input.tagName === 'SELECT' && ![...input.options].some((o) => o.value === String(value))) {
      const option = document.createElement('option');
      option.value = option.textContent = String(value);
      input.appendChild(option);
      input.value = String(value);
    } else input.value = String(value);
  }
  for (const key of kOptionInputs)
    document.getElementById(`opt-${key}`).disabled = options.mode === 'thesis' && patchesOnly.includes(key);
}

function optionValue(key) {
  const input = document.getElementById(`opt-${key}`);
  if (input.type === 'checkbox') return input.checked;
  if (key === 'axis' || key === 'mode') return input.value;
  if (key === 'field_following') return input.value === 'auto' ? 'auto' : Number(input.value);
  return Number(input.value);
}

function applyState() {
  updateSurfaceMaterial(material, state, textures);
  document.getElementById('legend').style.display = state.view === 'distortion' ? 'block' : 'none';
  document.getElementById('seam-legend').style.display = state.view === 'seams' ? 'block' : 'none';
  redrawAll();
}

function setView(name) {
  if (!kViews.includes(name)) throw new Error(`unknown view '${name}'`);
  state.view = name;
  const radio = document.querySelector(`input[name=view][value=${name}]`);
  if (radio) radio.checked = true;
  applyState();
}

function setTool(tool) {
  state.tool = tool;
  document.querySelector(`input[name=tool][value=${tool}]`).checked = true;
  // Painting tools leave the left button to the tool: the right one turns the view.
  controls.mouseButtons = tool === 'orbit'
    ? { LEFT: THREE.MOUSE.ROTATE, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.PAN }
    : { LEFT: null, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.ROTATE };
  if (tool !== 'brush' && tool !== 'erase') document.getElementById('brush-ring').style.display = 'none';
}

function setScale(value) {
  state.scale = value;
  document.getElementById('scale').value = String(Math.log2(value));
  document.getElementById('scale-value').textContent = value.toFixed(2);
  applyState();
}

function bindPanel() {
  for (const swatch of document.querySelectorAll('#seam-legend .swatch')) {
    const c = kSeamColors[swatch.dataset.seam];
    swatch.style.background = `rgb(${c.map((x) => Math.round(255 * x)).join(',')})`;
  }
  for (const input of document.querySelectorAll('input[name=view]')) input.addEventListener('change', () => setView(input.value));
  for (const input of document.querySelectorAll('input[name=tool]')) input.addEventListener('change', () => setTool(input.value));
  const brush = document.getElementById('brush');
  brush.addEventListener('input', () => {
    state.brushPx = Number(brush.value);
    document.getElementById('brush-value').textContent = `${state.brushPx} px`;
  });
  const reach = document.getElementById('reach');
  reach.addEventListener('input', () => {
    state.reachPercent = Number(reach.value);
    document.getElementById('reach-value').textContent = `${state.reachPercent}% of the mesh`;
  });
  const scale = document.getElementById('scale');
  scale.addEventListener('input', () => setScale(Math.pow(2, Number(scale.value))));
  const toggle = (id, key) => {
    const input = document.getElementById(id);
    input.addEventListener('change', () => { state[key] = input.checked; applyState(); });
  };
  toggle('show-marked', 'showMarked');
  toggle('show-strokes', 'showStrokes');
  toggle('wireframe', 'wireframe');
  document.getElementById('undo').addEventListener('click', () => undoRedo('undo'));
  document.getElementById('redo').addEventListener('click', () => undoRedo('redo'));
  document.getElementById('save').addEventListener('click', () => save());
  for (const key of kOptionInputs) {
    const input = document.getElementById(`opt-${key}`);
    input.addEventListener('change', () => {
      document.getElementById('status').textContent = 'mapping\u2026';
      timing.strokeEnd = performance.now();
      send({ options: { [key]: optionValue(key) } }).then(() => refreshState());
    });
  }
  const canvas = renderer.domElement;
  canvas.addEventListener('pointerdown', onPointerDown);
  canvas.addEventListener('pointermove', onPointerMove);
  canvas.addEventListener('pointerup', onPointerUp);
  canvas.addEventListener('pointerleave', () => { document.getElementById('brush-ring').style.display = 'none'; });
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  window.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLInputElement && (e.target.type === 'number' || e.target.type === 'text')) return;
    if (e.target instanceof HTMLSelectElement) return;
    if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'z') {
      e.preventDefault();
      undoRedo(e.shiftKey ? 'redo' : 'undo');
      return;
    }
    if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'y') {
      e.preventDefault();
      undoRedo('redo');
      return;
    }
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    const n = Number(e.key);
    if (n >= 1 && n <= kViews.length) setView(kViews[n - 1]);
    const tools = { b: 'brush', e: 'erase', s: 'stroke', o: 'orbit' };
    if (tools[e.key]) setTool(tools[e.key]);
    if (e.key === 'm' || e.key === 'w') {
      const id = e.key === 'm' ? 'show-marked' : 'wireframe';
      const input = document.getElementById(id);
      input.checked = !input.checked;
      input.dispatchEvent(new Event('change'));
    }
    if (e.key === '[' || e.key === ']') {
      brush.value = String(Math.max(1, Math.min(100, state.brushPx + (e.key === ']' ? 2 : -2))));
      brush.dispatchEvent(new Event('input'));
    }
  });
  window.addEventListener('resize', () => { view.resize(); pickStale = true; });
}

// --- start -------------------------------------------------------------------------------------------

async function load() {
  const info = await (await api('GET', '/api/state')).json();
  session.info = info;
  document.getElementById('title').textContent = `${info.name} - tailor edit`;
  document.title = `${info.name} - tailor edit`;
  const [meshBuffer, uvBuffer] = await Promise.all([
    api('GET', '/api/mesh').then((r) => r.arrayBuffer()),
    api('GET', `/api/uv?version=${info.version}`).then((r) => r.arrayBuffer()),
  ]);
  session.mesh = parseMesh(meshBuffer);
  const surface = new EditSurface(session.mesh, info.texture_width, info.texture_height, info.options?.symmetry);
  session.surface = surface;
  surface.setUvs(new Float32Array(uvBuffer));
  session.shownVersion = session.serverVersion = info.version;
  session.settled = info.settled;
  // 4x anisotropy: the view is redrawn after every edit, and 16x doubles a frame of software WebGL.
  if (info.texture) textures.map = prepareTexture(renderer, await new THREE.TextureLoader().loadAsync(info.texture), 4);
  textures.blank = new THREE.DataTexture(new Uint8Array([255, 255, 255, 255]), 1, 1);
  textures.blank.needsUpdate = true;
  const mesh = new THREE.Mesh(surface.geometry, material);
  mesh.frustumCulled = false;
  scene.add(mesh);
  view.frame(mesh);
  await refreshState();
  updateInfo(surface.faces);
  setStatus();
  applyState();
  if (!info.settled) pollStatus();
}

function animate() {
  requestAnimationFrame(animate);
  controls.update();
  if (ready) draw();
}

window.tailorEdit = {
  get ready() { return ready; },
  get frames() { return frames; },
  get state() { return { ...state }; },
  get version() { return session.shownVersion; },
  get serverVersion() { return session.serverVersion; },
  get settled() { return session.settled && session.shownVersion === session.serverVersion; },
  /** Nothing waiting to be sent, in flight, or to be drawn. */
  get idle() {
    return session.inFlight === 0 && session.pendingAdd.size === 0 && session.pendingRemove.size === 0 && !pump &&
      !painting && timing.measuring === 0 && session.shownVersion === session.serverVersion;
  },
  get latencies() { return [...timing.latencies]; },
  /** Per measured stroke: the last request's times (ms): editMs (round trip), serverMs, fetchMs, updateMs, drawMs. */
  get latencyParts() { return timing.parts.map((p) => ({ ...p })); },
  get markedCount() { return session.surface ? session.surface.marked.reduce((a, b) => a + b, 0) : 0; },
  get seamCounts() { return session.surface.seamCounts(); },
  /** The corner UVs drawn now (a copy). */
  shownUvs() { return Array.from(session.surface.uv); },
  setView,
  setTool,
  setBrush(px) { const b = document.getElementById('brush'); b.value = String(px); b.dispatchEvent(new Event('input')); },
  pixelStats() { return pixelStats(renderer, scene, camera); },
  /**
   * Pixels that differ between the frame on screen (built by partial redraws after edits) and the
   * same frame drawn in full: 0 when redrawing only the touched faces is exact.
   */
  partialFrameError() {
    const gl = renderer.getContext();
    const read = () => {
      const px = new Uint8Array(4 * gl.drawingBufferWidth * gl.drawingBufferHeight);
      gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, px);
      return px;
    };
    frame.copy = true;
    draw();
    const partial = read();
    redrawAll();
    draw();
    const full = read();
    let differ = 0;
    for (let i = 0; i < full.length; i += 4) {
      if (partial[i] !== full[i] || partial[i + 1] !== full[i + 1] || partial[i + 2] !== full[i + 2]) differ += 1;
    }
    return differ;
  },
  /** Mean time of `n` frames drawn and finished (ms). */
  timeFrames(n, trivial = false) {
    if (trivial) scene.overrideMaterial = pickMaterial;
    const start = performance.now();
    for (let i = 0; i < n; ++i) {
      redrawAll();
      drawNow();
    }
    scene.overrideMaterial = null;
    redrawAll();
    return (performance.now() - start) / n;
  },
  undo() { return undoRedo('undo'); },
  redo() { return undoRedo('redo'); },
  save,
};

bindPanel();
setTool('brush');
animate();
load()
  .then(() => { ready = true; redrawAll(); })
  .catch((e) => showError(`cannot load the session: ${e.message}`));
