// The tileset view of tailor's web viewer: a 3D Tiles tileset (`tailor view OUTDIR/tileset.json`,
// e.g. from `python3 -m tailor.tiles`) streamed by 3d-tiles-renderer into the viewer's scene. The
// renderer picks the tiles the camera needs (levels of detail by geometric error) each frame.
// ?errorTarget=N in the page's URL sets its screen-space error target (pixels; 0 loads every leaf).
// Test hook: window.tailorTiles (ready, frames, loaded content URLs, errors, pixelStats()).
import * as THREE from 'three';
import { TilesRenderer } from '/node_modules/3d-tiles-renderer/build/index.three.js';
import { pixelStats as scenePixelStats } from './scene_tools.js';

/** Shows config.tileset in `view` (scene_tools.js createView); resolves when the root tileset is in. */
export function showTileset(config, view, showError) {
  const { renderer, scene, camera, controls } = view;
  const tiles = new TilesRenderer(config.tileset);
  const query = new URLSearchParams(window.location.search);
  if (query.has('errorTarget')) tiles.errorTarget = Number(query.get('errorTarget'));
  tiles.setCamera(camera);
  tiles.setResolutionFromRenderer(camera, renderer);
  // 3D Tiles are Z up (the renderer turns glTF contents Z up); the viewer's camera is Y up.
  tiles.group.rotation.x = -Math.PI / 2;
  scene.add(tiles.group);
  // The viewer writes display values (no output conversion): lit colours straight from the texture.
  scene.add(new THREE.HemisphereLight(0xffffff, 0x707070, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.2);
  sun.position.set(1, 2, 1.5);
  scene.add(sun);

  const loaded = new Set();
  const errors = [];
  let frames = 0;
  let ready = false;
  tiles.addEventListener('load-model', (e) => {
    e.scene.traverse((o) => {
      if (o.isMesh && o.material && o.material.map) {
        o.material.map.colorSpace = THREE.NoColorSpace;
        o.material = new THREE.MeshLambertMaterial({ map: o.material.map });
      }
    });
    loaded.add(e.tile && e.tile.content ? e.tile.content.uri : String(e.url));
  });
  tiles.addEventListener('load-error', (e) => {
    errors.push(String(e.error && e.error.message ? e.error.message : e.error));
    showError(`cannot load a tile: ${errors[errors.length - 1]}`);
  });

  function loop() {
    requestAnimationFrame(loop);
    controls.update();
    camera.updateMatrixWorld();
    tiles.setResolutionFromRenderer(camera, renderer);
    tiles.update();
    renderer.render(scene, camera);
    frames += 1;
  }

  window.tailorTiles = {
    get ready() { return ready; },
    get frames() { return frames; },
    get loaded() { return [...loaded]; },
    get errors() { return [...errors]; },
    get queued() { return tiles.stats ? { ...tiles.stats } : {}; },
    pixelStats() { return scenePixelStats(renderer, scene, camera); },
  };

  return new Promise((resolve) => {
    tiles.addEventListener('load-root-tileset', () => {
      // Frames the root's bounding sphere as the viewer frames a model (a stand-in mesh of its size).
      tiles.group.updateMatrixWorld(true);
      const sphere = new THREE.Sphere();
      tiles.getBoundingSphere(sphere);
      sphere.applyMatrix4(tiles.group.matrixWorld);
      const standIn = new THREE.Mesh(new THREE.SphereGeometry(sphere.radius));
      standIn.position.copy(sphere.center);
      standIn.updateMatrixWorld(true);
      view.frame(standIn);
      ready = true;
      resolve(tiles);
    });
    loop();
  });
}
