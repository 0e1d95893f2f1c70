// Pieces of the three.js scene shared by the viewer (viewer.js) and the editing page (edit.js): the
// renderer with its orbit camera, texture set-up, the 3/4 framing of `tailor render`, and the pixel
// statistics the browser tests compare pictures with.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { kSeamColors } from './surface_material.js';

/**
 * A renderer in `container` with a perspective camera and orbit controls whose depth range follows
 * the model. onChange() is called whenever the camera moved (draw a frame then).
 * Returns { renderer, scene, camera, controls, frame(object), resize() }.
 */
export function createView(container, onChange, { antialias = true } = {}) {
  const renderer = new THREE.WebGLRenderer({ antialias });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
  renderer.setSize(container.clientWidth, container.clientHeight);
  // The shader writes display values itself (as the CPU preview does): no output conversion.
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  renderer.setClearColor(new THREE.Color(236 / 255, 238 / 255, 242 / 255), 1);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(35, container.clientWidth / container.clientHeight, 0.01, 100);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.enableDamping = true;
  let sceneRadius = 1;
  controls.addEventListener('change', () => {
    // Keep the depth range tight around the model wherever the camera goes (zooming in past the
    // initial near plane would cut the model open).
    const d = camera.position.distanceTo(controls.target);
    camera.near = Math.max(d - 1.5 * sceneRadius, sceneRadius * 1e-3);
    camera.far = d + 1.5 * sceneRadius;
    camera.updateProjectionMatrix();
    onChange();
  });
  /** Places the camera at a 3/4 view from above, like `tailor render`, fitting the bounding sphere. */
  function frame(object) {
    const box = new THREE.Box3().setFromObject(object);
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const radius = sphere.radius > 0 ? sphere.radius : 1;
    sceneRadius = radius;
    const fovy = THREE.MathUtils.degToRad(camera.fov);
    const half = Math.min(fovy / 2, Math.atan(Math.tan(fovy / 2) * camera.aspect));
    const distance = (radius / Math.sin(half)) * 1.02;
    const yaw = THREE.MathUtils.degToRad(35);
    const pitch = THREE.MathUtils.degToRad(25);
    const dir = new THREE.Vector3(Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw));
    camera.position.copy(sphere.center).addScaledVector(dir, distance);
    camera.near = Math.max(distance - radius * 1.5, distance * 1e-3);
    camera.far = distance + radius * 1.5;
    camera.updateProjectionMatrix();
    controls.target.copy(sphere.center);
    controls.maxDistance = distance * 10;
    controls.update();
  }
  function resize() {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
    onChange();
  }
  return { renderer, scene, camera, controls, frame, resize };
}

/**
 * Textures are sampled as raw data (no colour-space decoding) and repeat, with mipmaps and up to
 * `maxAnisotropy` anisotropic filtering (the device's limit by default).
 */
export function prepareTexture(renderer, texture, maxAnisotropy = Infinity) {
  texture.colorSpace = THREE.NoColorSpace;
  texture.wrapS = THREE.RepeatWrapping;
  texture.wrapT = THREE.RepeatWrapping;
  texture.minFilter = THREE.LinearMipmapLinearFilter;
  texture.magFilter = THREE.LinearFilter;
  texture.anisotropy = Math.min(maxAnisotropy, renderer.capabilities.getMaxAnisotropy());
  texture.generateMipmaps = true;
  // glTF's uv has v pointing down the image, like three's textures with flipY off.
  texture.flipY = false;
  texture.needsUpdate = true;
  return texture;
}

/**
 * Renders now and returns the luminance mean and variance of the canvas, a 100x75 RGB thumbnail
 * (box means, 22500 values) to compare pictures, and the number of pixels close to the seams
 * view's red and green line colours (seamPixels.visible, seamPixels.invisible).
 */
export function pixelStats(renderer, scene, camera) {
  renderer.render(scene, camera);
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const tw = 100;
  const th = 75;
  const thumb = new Float64Array(tw * th * 3);
  const counts = new Float64Array(tw * th);
  let sum = 0;
  let sum2 = 0;
  const near = (i, c) => Math.abs(px[i] - 255 * c[0]) < 40 && Math.abs(px[i + 1] - 255 * c[1]) < 40 && Math.abs(px[i + 2] - 255 * c[2]) < 40;
  const seamPixels = { visible: 0, invisible: 0 };
  for (let y = 0; y < h; ++y) {
    const ty = Math.min(th - 1, Math.floor((th * y) / h));
    for (let x = 0; x < w; ++x) {
      const i = 4 * (y * w + x);
      const l = 0.299 * px[i] + 0.587 * px[i + 1] + 0.114 * px[i + 2];
      sum += l;
      sum2 += l * l;
      if (near(i, kSeamColors.visible)) seamPixels.visible += 1;
      else if (near(i, kSeamColors.invisible)) seamPixels.invisible += 1;
      const cell = ty * tw + Math.min(tw - 1, Math.floor((tw * x) / w));
      for (let c = 0; c < 3; ++c) thumb[3 * cell + c] += px[i + c];
      counts[cell] += 1;
    }
  }
  const n = w * h;
  const mean = sum / n;
  const grid = Array.from(thumb, (v, k) => v / counts[Math.floor(k / 3)]);
  return { width: w, height: h, mean, variance: sum2 / n - mean * mean, grid, seamPixels };
}
