// Unit test of web/mesh_data.js in node (no browser): patches, seams and stretch on meshes small
// enough to check by hand. Usage: node web/test/mesh_data_test.mjs (exit 0 = pass).
import assert from 'node:assert/strict';
import * as THREE from 'three';
import { edgesAndPatches, faceStretch, buildSurface } from '../mesh_data.js';

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

console.log('PASS: mesh_data');
