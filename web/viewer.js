// tailor's web viewer: loads the .glb served by `tailor view` (see /config.json), shows it with
// orbit controls and a panel (view, texture scale and rotation, wireframe, tile variants). The
// seams view draws the seams `tailor eval` calls visible in red, the invisible ones in green.
// Frames are drawn only when something changed, so a 1 M face mesh costs nothing while idle.
// A small test hook (window.tailorViewer) lets the browser test switch views and read pixels.
// A tileset.json (`tailor view OUTDIR/tileset.json`) is shown by tileset_view.js instead.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { buildSurface, seamRatios, kDefaultTextureSize } from './mesh_data.js';
import { createSurfaceMaterial, updateSurfaceMaterial, kMaxVariants, kViews, kSeamColors } from './surface_material.js';
import { createView, prepareTexture as prepareSceneTexture, pixelStats as scenePixelStats } from './scene_tools.js';

const state = {
  view: 'texture',
  scale: 1,
  rotationDeg: 0,
  wireframe: false,
  seams: true,
  useVariants: true,
  normalMapping: true,  // the file's normal map (`tailor map --material`), when it has one
  seed: 1,
  checkerSquares: 8,
  distortionRange: 2,
};
const textures = { map: null, normalMap: null, occlusionMap: null, variants: [], blank: null };
const stats = {
  faces: 0, patches: 0, seamEdges: 0, loadSeconds: 0, analysisSeconds: 0,
  // Seam lengths of the welded mesh (mesh_data.js seamClasses) and eval's ratios from them.
  seams: { totalLength: 0, seamLength: 0, invisibleLength: 0, visibleLength: 0, seamEdges: 0, invisibleEdges: 0 },
  visibleSeamRatio: 0, seamInvisibleRatio: 1,
};
let frames = 0;
let dirty = true;
let ready = false;
let tilesetMode = false;  // a 3D Tiles tileset (tileset_view.js) instead of one .glb

const container = document.getElementById('view');
const view = createView(container, () => { dirty = true; });
const { renderer, scene, camera, controls } = view;
const material = createSurfaceMaterial();

function showError(text) {
  const box = document.getElementById('error');
  box.textContent = text;
  box.style.display = 'block';
  console.error(text);
}

window.addEventListener('error', (e) => showError(`error: ${e.message}`));
window.addEventListener('unhandledrejection', (e) => showError(`error: ${e.reason && e.reason.message ? e.reason.message : e.reason}`));

function prepareTexture(texture) {
  return prepareSceneTexture(renderer, texture);
}

function loadTexture(url) {
  return new THREE.TextureLoader().loadAsync(url).then(prepareTexture);
}

function applyState() {
  updateSurfaceMaterial(material, state, textures);
  document.getElementById('legend').style.display = state.view === 'distortion' ? 'block' : 'none';
  document.getElementById('seam-legend').style.display = state.view === 'seams' ? 'block' : 'none';
  dirty = true;
}

async function load() {
  const start = performance.now();
  const config = await (await fetch('/config.json')).json();
  document.getElementById('title').textContent = config.name || 'tailor viewer';
  document.title = `${config.name} - tailor viewer`;
  if (config.tileset) {
    // A 3D Tiles tileset: streamed by 3d-tiles-renderer (tileset_view.js), which draws every frame.
    tilesetMode = true;
    document.getElementById('panel').style.display = 'none';
    const { showTileset } = await import('./tileset_view.js');
    await showTileset(config, view, showError);
    return;
  }
  // `tailor map --compress meshopt|draco` files: the decoders are three.js's own (WebAssembly; Draco's
  // in a worker), served from node_modules like the rest of three.js.
  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);
  loader.setDRACOLoader(new DRACOLoader());  // its decoder: libs/draco/gltf/ beside the loader
  const gltf = await loader.loadAsync(config.model);

  const meshes = [];
  gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
  if (meshes.length === 0) throw new Error(`${config.name}: no triangle mesh in the file`);
  let hasUv = false;
  for (const mesh of meshes) {
    if (!textures.map && mesh.material && mesh.material.map) textures.map = prepareTexture(mesh.material.map);
    // `tailor map --material`: the file's normal map, with the TANGENT that buildSurface keeps.
    if (!textures.normalMap && mesh.material && mesh.material.normalMap && mesh.geometry.getAttribute('tangent')) {
      textures.normalMap = prepareTexture(mesh.material.normalMap);
    }
    // Its occlusion map (three.js's aoMap) darkens the ambient light, as `tailor render` does.
    if (!textures.occlusionMap && mesh.material && mesh.material.aoMap) {
      textures.occlusionMap = prepareTexture(mesh.material.aoMap);
    }
    // UVs are in repeats of the embedded texture: its size turns them into pixels for the seam
    // gaps, as `tailor eval` does (512 without one).
    const image = (mesh.material && mesh.material.map ? mesh.material.map : textures.map)?.image;
    const textureWidth = image && image.width > 0 ? image.width : kDefaultTextureSize;
    const textureHeight = image && image.height > 0 ? image.height : kDefaultTextureSize;
    const analysisStart = performance.now();
    // A 4-fold map (`tailor map --symmetry 4`) says so in its material's extras (three.js's userData):
    // quarter-turn seams are invisible under its tile, as `tailor eval` counts them.
    const symmetry = mesh.material?.userData?.tailor?.symmetry === 4 && textureWidth === textureHeight ? 4 : 1;
    const surface = buildSurface(mesh.geometry, { textureWidth, textureHeight, symmetry });
    stats.analysisSeconds += (performance.now() - analysisStart) / 1000;
    mesh.geometry.dispose();
    mesh.geometry = surface.geometry;
    mesh.material = material;
    stats.faces += surface.faces;
    stats.patches += surface.patches;
    stats.seamEdges += surface.seamEdges;
    for (const key of Object.keys(stats.seams)) stats.seams[key] += surface.seams[key];
    hasUv = hasUv || surface.hasUv;
  }
  // UVs are texture pixels / the embedded texture's size: a replacement texture of another size
  // starts at the scale that keeps the same texel density on the surface.
  const embeddedWidth = textures.map && textures.map.image ? textures.map.image.width : 0;
  if (config.texture) textures.map = await loadTexture(config.texture);
  if (config.variants) {
    textures.variants = await Promise.all(config.variants.files.slice(0, kMaxVariants).map(loadTexture));
    state.seed = config.variants.seed >>> 0;
    document.getElementById('variant-controls').style.display = 'block';
    document.getElementById('variant-count').textContent = `(${textures.variants.length})`;
    document.getElementById('seed').value = String(state.seed);
  }
  const shown = textures.variants.length > 0 ? textures.variants[0] : textures.map;
  if (embeddedWidth > 0 && shown && shown.image && shown.image.width > 0 && shown.image.width !== embeddedWidth) {
    setScale(embeddedWidth / shown.image.width);
  }
  textures.blank = new THREE.DataTexture(new Uint8Array([255, 255, 255, 255]), 1, 1);
  textures.blank.needsUpdate = true;
  if (!hasUv) console.warn(`${config.name}: no texture coordinates; only the patches view is meaningful`);

  scene.add(gltf.scene);
  view.frame(gltf.scene);
  stats.loadSeconds = (performance.now() - start) / 1000;
  Object.assign(stats, seamRatios(stats.seams));
  const percent = (x) => `${(100 * x).toFixed(2)}%`;
  document.getElementById('info').textContent =
    `${stats.faces.toLocaleString('en')} faces, ${stats.patches.toLocaleString('en')} patches, ` +
    (hasUv ? `visible seams ${percent(stats.visibleSeamRatio)} of edge length, ` +
      `${percent(stats.seamInvisibleRatio)} of seam length invisible; ` : '') +
    `loaded in ${stats.loadSeconds.toFixed(2)} s (patches, seams, stretch: ${stats.analysisSeconds.toFixed(2)} s)`;
  applyState();
}

function bindPanel() {
  for (const swatch of document.querySelectorAll('#seam-legend .swatch')) {
    const c = kSeamColors[swatch.dataset.seam];
    swatch.style.background = `rgb(${c.map((x) => Math.round(255 * x)).join(',')})`;
  }
  for (const input of document.querySelectorAll('input[name=view]')) {
    input.addEventListener('change', () => setView(input.value));
  }
  const scale = document.getElementById('scale');
  scale.addEventListener('input', () => setScale(Math.pow(2, Number(scale.value))));
  const rotation = document.getElementById('rotation');
  rotation.addEventListener('input', () => {
    state.rotationDeg = Number(rotation.value);
    document.getElementById('rotation-value').textContent = `${state.rotationDeg}\u00b0`;
    applyState();
  });
  const wireframe = document.getElementById('wireframe');
  wireframe.addEventListener('change', () => { state.wireframe = wireframe.checked; applyState(); });
  const variants = document.getElementById('variants');
  variants.addEventListener('change', () => { state.useVariants = variants.checked; applyState(); });
  const seed = document.getElementById('seed');
  seed.addEventListener('input', () => { state.seed = Number(seed.value) >>> 0; applyState(); });
  window.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLInputElement && e.target.type === 'number') return;
    const n = Number(e.key);
    if (n >= 1 && n <= kViews.length) setView(kViews[n - 1]);
    if (e.key === 'w') { wireframe.checked = !wireframe.checked; state.wireframe = wireframe.checked; applyState(); }
  });
  window.addEventListener('resize', view.resize);
}

/** Texture repeats per UV unit (the slider is logarithmic, 1/8 .. 8). */
function setScale(value) {
  state.scale = value;
  document.getElementById('scale').value = String(Math.log2(value));
  document.getElementById('scale-value').textContent = value.toFixed(2);
  applyState();
}

function setView(view) {
  if (!kViews.includes(view)) throw new Error(`unknown view '${view}'`);
  state.view = view;
  const radio = document.querySelector(`input[name=view][value=${view}]`);
  if (radio) radio.checked = true;
  applyState();
}

function animate() {
  requestAnimationFrame(animate);
  controls.update();
  if (!dirty || !ready) return;
  dirty = false;
  renderer.render(scene, camera);
  frames += 1;
}

function pixelStats() {
  return scenePixelStats(renderer, scene, camera);
}

window.tailorViewer = {
  get ready() { return ready; },
  get frames() { return frames; },
  get stats() { return { ...stats, seams: { ...stats.seams } }; },
  get state() { return { ...state }; },
  setView,
  pixelStats,
  get hasNormalMap() { return !!textures.normalMap; },
  /** Turns the file's normal map on or off (the test compares both pictures). */
  setNormalMapping(on) { state.normalMapping = on; applyState(); },
};

bindPanel();
animate();
load()
  .then(() => { ready = !tilesetMode; dirty = true; })
  .catch((e) => showError(`cannot load the model: ${e.message}`));
