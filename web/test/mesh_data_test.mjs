// Unit test of web/mesh_data.js in node (no browser): patches, seams, seam classes and stretch on
// meshes small enough to check by hand; given the tailor binary, also the seam figures of a real
// .glb (tailor map of tests/data/meshes/horse.ply) against `tailor eval --json`.
// Usage: node web/test/mesh_data_test.mjs [TAILOR_BINARY] (exit 0 = pass).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import {
  edgesAndPatches, faceStretch, buildSurface, seamClasses, seamRatios, weldByPosition,
  kSeamNone, kSeamInvisible, kSeamVisible, kSeamBorder,
} from '../mesh_data.js';

// Two triangles sharing the edge 0-2 of a unit square: one patch, four border edges.
{
  const index = new Uint32Array([0, 1, 2, 0, 2, 3]);
  const { seam, patch, count } = edgesAndPatches(index);
  assert.equal(count, 1);
  assert.deepEqual(Array.from(patch), [0, 0]);
  // Face 0: edges 0->1 (border), 1->2 (border), 2->0 (shared); face 1: 0->2 (shared), 2->3, 3->0.
  assert.deepEqual(Array.from(seam), [1, 1, 0, 0, 1, 1]);
}

// The same square split along its diagonal (vertex 2 duplicated as 4, 0 as 5, as a glTF writer
// does on a UV seam): two patches, every edge a seam.
{
  const index = new Uint32Array([0, 1, 2, 5, 4, 3]);
  const { seam, patch, count } = edgesAndPatches(index);
  assert.equal(count, 2);
  assert.deepEqual(Array.from(patch), [0, 1]);
  assert.ok(Array.from(seam).every((s) => s === 1));
}

// Stretch: both faces have 3D area 1/2; UV areas 1/2 and 1, so the mesh-wide ratio is
// R = 1.5 / 1 and the per-face values are log2(1 / 1.5) and log2(2 / 1.5).
{
  const position = new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 2, 1, 0]);
  const uv = new Float32Array([0, 0, 1, 0, 0, 1, 0, 0, 2, 0, 0, 1]);
  const index = new Uint32Array([0, 1, 2, 3, 4, 5]);
  const stretch = faceStretch(index, position, uv);
  assert.ok(Math.abs(stretch[0] - Math.log2(1 / 1.5)) < 1e-6);
  assert.ok(Math.abs(stretch[1] - Math.log2(2 / 1.5)) < 1e-6);
}

// buildSurface: unindexed output, per-corner barycentrics, face values repeated on its corners.
{
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]), 3));
  g.setAttribute('uv', new THREE.BufferAttribute(new Float32Array([0, 0, 1, 0, 1, 1, 0, 1]), 2));
  g.setIndex([0, 1, 2, 0, 2, 3]);
  const s = buildSurface(g);
  assert.equal(s.faces, 2);
  assert.equal(s.patches, 1);
  assert.equal(s.seamEdges, 4);
  assert.equal(s.geometry.getAttribute('position').count, 6);
  assert.deepEqual(Array.from(s.geometry.getAttribute('bary').array.slice(0, 9)), [255, 0, 0, 0, 255, 0, 0, 0, 255]);
  // Face 0's shared edge is 2->0, opposite corner 1: only component 1 of its seam flags is clear.
  assert.deepEqual(Array.from(s.geometry.getAttribute('seam').array.slice(0, 3)), [255, 0, 255]);
  assert.deepEqual(Array.from(s.geometry.getAttribute('stretch').array), [0, 0, 0, 0, 0, 0]);
}

// Welding by position: copies share the first vertex's id; -0 and +0 differ (float bits, as in C++).
{
  const position = new Float32Array([0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, -0, 0, 0]);
  assert.deepEqual(Array.from(weldByPosition(position)), [0, 1, 0, 1, 4]);
}

// Seam classes. The unit square in two triangles cut along the diagonal, as tailor's .glb writer
// splits vertices on (position, uv): face 0 = (0, 1, 2), face 1 = (4, 5, 3) with 4 a copy of 0
// and 5 a copy of 2. UVs are 1/4 repeat per unit; face 1's corners are shifted by `shift`
// (`shift5` for vertex 5 when given). Directed edges: face 0: 0->1, 1->2, 2->0 (diagonal); face 1:
// 4->5 (diagonal), 5->3, 3->4. The four outer edges are mesh borders, never seams.
function square(shift, shift5 = shift) {
  const p = [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0], [1, 1]];
  const position = new Float32Array(p.flatMap(([x, y]) => [x, y, 0]));
  const uv = new Float32Array(p.flatMap(([x, y], v) => {
    const s = v === 5 ? shift5 : v >= 3 ? shift : [0, 0];
    return [x / 4 + s[0], y / 4 + s[1]];
  }));
  return { index: new Uint32Array([0, 1, 2, 4, 5, 3]), position, uv };
}
const diagonalClass = (shift, shift5, width = 512, height = 512) => {
  const { index, position, uv } = square(shift, shift5);
  const s = seamClasses(index, position, uv, width, height);
  assert.equal(s.seamClass[2], s.seamClass[3], 'both sides of the diagonal alike');
  for (const e of [0, 1, 4, 5]) assert.equal(s.seamClass[e], kSeamBorder, 'outer edges are borders');
  return s;
};
{
  // Same UVs on both sides (split vertices, nothing cut): no seam.
  const s = diagonalClass([0, 0]);
  assert.equal(s.seamClass[2], kSeamNone);
  assert.equal(s.seamEdges, 0);
  assert.ok(Math.abs(s.totalLength - (4 + Math.SQRT2)) < 1e-12);
  assert.deepEqual(seamRatios(s), { visibleSeamRatio: 0, seamInvisibleRatio: 1 });
}
{
  // Shifted by whole repeats: the texture continues across the cut, an invisible seam.
  for (const shift of [[1, 0], [0, -2], [-3, 5]]) {
    const s = diagonalClass(shift);
    assert.equal(s.seamClass[2], kSeamInvisible, `shift ${shift}`);
    assert.equal(s.seamEdges, 1);
    assert.ok(Math.abs(s.seamLength - Math.SQRT2) < 1e-12 && s.invisibleLength === s.seamLength && s.visibleLength === 0);
    assert.deepEqual(seamRatios(s), { visibleSeamRatio: 0, seamInvisibleRatio: 1 });
  }
}
{
  // Shifted by 0.3 repeats (153.6 px): visible; the visible share of all edge length is the diagonal's.
  const s = diagonalClass([0.3, 0]);
  assert.equal(s.seamClass[2], kSeamVisible);
  const r = seamRatios(s);
  assert.ok(Math.abs(r.visibleSeamRatio - Math.SQRT2 / (4 + Math.SQRT2)) < 1e-12);
  assert.equal(r.seamInvisibleRatio, 0);
}
{
  // The pixel threshold: 0.001 repeat = 0.512 px is invisible; (0.0015, 0.0015) = 1.09 px apart
  // (each component 0.77 px) is visible; 0.003 repeat is 0.77 px on a 256 px texture, 1.54 on 512.
  assert.equal(diagonalClass([0.001, 0]).seamClass[2], kSeamInvisible);
  assert.equal(diagonalClass([0.0015, 0.0015]).seamClass[2], kSeamVisible);
  assert.equal(diagonalClass([0.003, 0], undefined, 256, 512).seamClass[2], kSeamInvisible);
  assert.equal(diagonalClass([0.003, 0]).seamClass[2], kSeamVisible);
  assert.equal(diagonalClass([0, 0.003], undefined, 512, 256).seamClass[2], kSeamInvisible);
  // Whole repeats, but not the same at both ends: one offset fits both ends only to 512 px.
  assert.equal(diagonalClass([1, 0], [0, 0]).seamClass[2], kSeamVisible);
}
{
  // Symmetry 4 (a 4-fold map under a tile a quarter turn leaves unchanged): face 1's UVs turned a
  // quarter turn and shifted by whole repeats is an invisible seam then, a visible one without; a
  // turn plus a fraction of a repeat stays visible.
  const turned = (k, fraction) => {
    const { index, position, uv } = square([0, 0]);
    // Face 1 (vertices 3, 4, 5): (x, y) -> (y, -x) + k, which a quarter turn counter-clockwise,
    // (x, y) -> (-y, x), takes back to face 0's UVs plus whole repeats.
    for (const v of [3, 4, 5]) {
      const x = uv[2 * v], y = uv[2 * v + 1];
      uv[2 * v] = y + k[0] + fraction;
      uv[2 * v + 1] = -x + k[1];
    }
    return (symmetry) => seamClasses(index, position, uv, 512, 512, symmetry).seamClass[2];
  };
  for (const k of [[0, 0], [1, -2], [-3, 4]]) {
    assert.equal(turned(k, 0)(1), kSeamVisible, `turn + ${k}, symmetry 1`);
    assert.equal(turned(k, 0)(4), kSeamInvisible, `turn + ${k}, symmetry 4`);
    assert.equal(turned(k, 0.3)(4), kSeamVisible, `turn + ${k} + 0.3, symmetry 4`);
  }
  // A shift alone stays invisible with symmetry 4.
  const { index, position, uv } = square([2, -1]);
  assert.equal(seamClasses(index, position, uv, 512, 512, 4).seamClass[2], kSeamInvisible);
}
{
  // A third face on the diagonal (non-manifold) or a flipped face 1 (inconsistent orientation):
  // unpaired, so borders, as in tailor's topology.
  const { index, position, uv } = square([0.3, 0]);
  const position3 = new Float32Array([...position, 0.5, 0.5, 1]);
  const uv3 = new Float32Array([...uv, 0.7, 0.1]);
  const s3 = seamClasses(new Uint32Array([...index, 0, 2, 6]), position3, uv3, 512, 512);
  assert.deepEqual(Array.from(s3.seamClass), Array(9).fill(kSeamBorder));
  assert.equal(s3.seamEdges, 0);
  const flipped = seamClasses(new Uint32Array([0, 1, 2, 5, 4, 3]), position, uv, 512, 512);
  assert.deepEqual(Array.from(flipped.seamClass), Array(6).fill(kSeamBorder));
  assert.equal(flipped.seamEdges, 0);
  // Border uses each count in the edge length (as eval's distinct edges): 4 + 2 diagonals.
  assert.ok(Math.abs(flipped.totalLength - (4 + 2 * Math.SQRT2)) < 1e-12);
  // No UVs: no seams, borders still marked.
  assert.deepEqual(Array.from(seamClasses(index, position, null).seamClass), [3, 3, 0, 0, 3, 3]);
}
{
  // buildSurface: the seam classes per corner, component m = the edge opposite corner m (face 0's
  // diagonal 2->0 is opposite corner 1); the sums come back without the per-edge array.
  const { index, position, uv } = square([0.3, 0]);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(position, 3));
  g.setAttribute('uv', new THREE.BufferAttribute(uv, 2));
  g.setIndex(new THREE.BufferAttribute(index, 1));
  const s = buildSurface(g, { textureWidth: 512, textureHeight: 512 });
  const classes = Array.from(s.geometry.getAttribute('seamClass').array);
  assert.deepEqual(classes.slice(0, 3), [kSeamBorder, kSeamVisible, kSeamBorder]);
  assert.deepEqual(classes.slice(9, 12), [kSeamBorder, kSeamBorder, kSeamVisible]);  // face 1: 4->5 opposite corner 2
  assert.equal(s.seams.seamEdges, 1);
  assert.equal(s.seams.seamClass, undefined);
}

// A real .glb: `tailor map` of the horse, its seam figures against `tailor eval --json`.
const tailor = process.argv[2];
if (tailor) {
  const repo = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'tailor-mesh-data-'));
  try {
    const glb = path.join(dir, 'horse.glb');
    execFileSync(tailor, ['map', path.join(repo, 'tests/data/meshes/horse.ply'), '-o', glb, '-q'], { stdio: 'inherit' });
    const evaluation = JSON.parse(execFileSync(tailor, ['eval', glb, '--json', '-q'], { encoding: 'utf8' }));
    const bytes = fs.readFileSync(glb);
    const gltf = await new GLTFLoader().parseAsync(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), '');
    const meshes = [];
    gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
    assert.equal(meshes.length, 1);
    // No texture in the file (tailor map without --texture): eval's default size, as the viewer's.
    assert.equal(evaluation.texture_size_from, 'default');
    const start = performance.now();
    const s = buildSurface(meshes[0].geometry, { textureWidth: evaluation.texture_width, textureHeight: evaluation.texture_height });
    const seconds = (performance.now() - start) / 1000;
    const r = seamRatios(s.seams);
    console.log(`horse.glb: ${s.faces} faces in ${seconds.toFixed(2)} s; seam edges ${s.seams.seamEdges} (eval ${evaluation.seam_edges}), ` +
      `visible_seam_ratio ${r.visibleSeamRatio} (eval ${evaluation.visible_seam_ratio}), ` +
      `seam_invisible_ratio ${r.seamInvisibleRatio} (eval ${evaluation.seam_invisible_ratio})`);
    assert.equal(s.faces, evaluation.faces);
    assert.equal(s.seams.seamEdges, evaluation.seam_edges);
    assert.ok(Math.abs(r.visibleSeamRatio - evaluation.visible_seam_ratio) < 1e-6, 'visible_seam_ratio differs from eval');
    assert.ok(Math.abs(r.seamInvisibleRatio - evaluation.seam_invisible_ratio) < 1e-6, 'seam_invisible_ratio differs from eval');
    // Both classes present, or the comparison would not test much.
    assert.ok(r.visibleSeamRatio > 0 && r.seamInvisibleRatio > 0 && r.seamInvisibleRatio < 1);

    // Random grids cut along random edges (holes for borders, corners shifted by whole or partial
    // repeats, by sub-pixel amounts and along the diagonal), written as OBJ: eval's figures exactly.
    let seed = 11;
    const random = (n) => {
      seed = (Math.imul(seed, 1103515245) + 12345) >>> 0;
      return (seed >>> 8) % n;
    };
    const shifts = [[0, 0], [1, 0], [0, -2], [0.3, 0], [0.001, 0], [0.0015, 0.0015], [0.5, 0.5], [-1, 1]];
    for (let trial = 0; trial < 10; ++trial) {
      const n = 6;
      const points = [];
      for (let y = 0; y < n; ++y) for (let x = 0; x < n; ++x) points.push([x + 0.1 * random(3), y, 0.05 * random(4)]);
      const faces = [];
      for (let y = 0; y < n - 1; ++y) {
        for (let x = 0; x < n - 1; ++x) {
          const a = y * n + x;
          if (random(6) !== 0) faces.push([a, a + 1, a + n + 1], [a, a + n + 1, a + n]);
        }
      }
      const index = new Uint32Array(3 * faces.length);
      const position = new Float32Array(9 * faces.length);
      const uv = new Float32Array(6 * faces.length);
      let obj = points.map((p) => `v ${p.join(' ')}\n`).join('');
      const faceTurn = faces.map(() => (random(3) === 0 ? random(4) : 0));
      faces.forEach((face, f) => {
        const faceShift = shifts[random(shifts.length)];
        face.forEach((v, k) => {
          const c = 3 * f + k;
          const shift = random(5) === 0 ? shifts[random(shifts.length)] : faceShift;
          index[c] = c;
          position.set(points[v], 3 * c);
          // Odd trials turn some faces' UVs by quarter turns (tailor map --symmetry 4's seams).
          const turns = trial % 2 ? faceTurn[f] : 0;
          let [x, y] = [points[v][0] / 10, points[v][1] / 10];
          for (let r = 0; r < turns; ++r) [x, y] = [y, -x];
          uv[2 * c] = x + shift[0];
          uv[2 * c + 1] = y + shift[1];
          obj += `vt ${uv[2 * c]} ${uv[2 * c + 1]}\n`;
        });
      });
      obj += faces.map((face, f) => `f ${face.map((v, k) => `${v + 1}/${3 * f + k + 1}`).join(' ')}\n`).join('');
      const file = path.join(dir, 'grid.obj');
      fs.writeFileSync(file, obj);
      // With symmetry 4 too (UVs turned by quarter turns on some faces below).
      for (const symmetry of trial % 2 ? [1, 4] : [1]) {
        const grid = JSON.parse(
          execFileSync(tailor, ['eval', file, '--json', '-q', '--symmetry', `${symmetry}`], { encoding: 'utf8' }));
        const g = seamClasses(index, position, uv, grid.texture_width, grid.texture_height, symmetry);
        const gr = seamRatios(g);
        const what = `grid ${trial}, symmetry ${symmetry}`;
        assert.equal(g.seamEdges, grid.seam_edges, `${what}: seam edges`);
        assert.ok(Math.abs(gr.visibleSeamRatio - grid.visible_seam_ratio) < 1e-9, `${what}: visible_seam_ratio`);
        assert.ok(Math.abs(gr.seamInvisibleRatio - grid.seam_invisible_ratio) < 1e-9, `${what}: seam_invisible_ratio`);
      }
    }
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}

console.log('PASS: mesh_data');
