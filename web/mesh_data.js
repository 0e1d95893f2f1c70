// Per-face data of the viewer, computed once when a mesh is loaded (never per frame):
//   patches  - connected components of faces joined across shared edges. glTF files written by
//              tailor split vertices on (position, uv), so two faces share an edge of the split
//              mesh exactly when their UVs agree along it: the components are the UV patches
//              (the definition of `derive_patches` in metrics.h).
//   seams    - edges used by exactly one face of the split mesh: patch borders, cuts and mesh borders.
//   stretch  - log2 of (UV area / 3D area) divided by the mesh-wide ratio sum(a) / sum(A), the
//              per-face area stretch of `tailor eval` (0 = ideal, +1 = twice the texture area).
// The result is an unindexed BufferGeometry (three corners per face, each with the face's
// values), so the shader can colour faces flat and draw edges from barycentric coordinates.
// Everything runs over typed arrays with flat hash tables: about a second per million faces.
import * as THREE from 'three';

/** Union-find root with path halving over an Int32Array of parents. */
function findRoot(parent, x) {
  while (parent[x] !== x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

/**
 * Edge pairing of the split mesh. For each directed edge e = 3f + k (corner k -> k+1): seam[e] = 1
 * when no other face uses the same two vertex indices (a patch or mesh border), and patch ids:
 * faces joined across every shared edge (union-find), dense, in order of first face.
 */
export function edgesAndPatches(index) {
  const edges = index.length;
  const faces = edges / 3;
  let size = 16;
  while (size < 2 * edges) size *= 2;
  const mask = size - 1;
  const keyA = new Uint32Array(size);
  const keyB = new Uint32Array(size);
  const firstFace = new Int32Array(size).fill(-1);
  const uses = new Uint32Array(size);
  const slotOf = new Uint32Array(edges);
  const parent = new Int32Array(faces);
  for (let f = 0; f < faces; ++f) parent[f] = f;
  for (let e = 0; e < edges; ++e) {
    const f = (e / 3) | 0;
    const u = index[e];
    const w = index[3 * f + ((e % 3) + 1) % 3];
    const a = Math.min(u, w);
    const b = Math.max(u, w);
    let slot = (Math.imul(a, 0x9e3779b1) ^ Math.imul(b, 0x85ebca6b)) >>> 0;
    slot = (slot ^ (slot >>> 15)) & mask;
    while (firstFace[slot] >= 0 && (keyA[slot] !== a || keyB[slot] !== b)) slot = (slot + 1) & mask;
    if (firstFace[slot] < 0) {
      firstFace[slot] = f;
      keyA[slot] = a;
      keyB[slot] = b;
    } else {
      const r1 = findRoot(parent, firstFace[slot]);
      const r2 = findRoot(parent, f);
      if (r1 !== r2) parent[Math.max(r1, r2)] = Math.min(r1, r2);
    }
    uses[slot] += 1;
    slotOf[e] = slot;
  }
  const seam = new Uint8Array(edges);
  for (let e = 0; e < edges; ++e) seam[e] = uses[slotOf[e]] === 1 ? 1 : 0;
  const label = new Int32Array(faces).fill(-1);
  const patch = new Uint32Array(faces);
  let count = 0;
  for (let f = 0; f < faces; ++f) {
    const root = findRoot(parent, f);
    if (label[root] < 0) label[root] = count++;
    patch[f] = label[root];
  }
  return { seam, patch, count };
}

/** log2((a_f / A_f) / R) per face; 0 for faces with no 3D area, -16 for collapsed UV faces. */
export function faceStretch(index, position, uv) {
  const faces = index.length / 3;
  const ratio = new Float64Array(faces);
  let sumUv = 0;
  let sum3d = 0;
  for (let f = 0; f < faces; ++f) {
    const a = index[3 * f], b = index[3 * f + 1], c = index[3 * f + 2];
    const e1x = position[3 * b] - position[3 * a], e1y = position[3 * b + 1] - position[3 * a + 1], e1z = position[3 * b + 2] - position[3 * a + 2];
    const e2x = position[3 * c] - position[3 * a], e2y = position[3 * c + 1] - position[3 * a + 1], e2z = position[3 * c + 2] - position[3 * a + 2];
    const cx = e1y * e2z - e1z * e2y, cy = e1z * e2x - e1x * e2z, cz = e1x * e2y - e1y * e2x;
    const area3d = 0.5 * Math.sqrt(cx * cx + cy * cy + cz * cz);
    let areaUv = 0;
    if (uv) {
      const u1 = uv[2 * b] - uv[2 * a], v1 = uv[2 * b + 1] - uv[2 * a + 1];
      const u2 = uv[2 * c] - uv[2 * a], v2 = uv[2 * c + 1] - uv[2 * a + 1];
      areaUv = 0.5 * Math.abs(u1 * v2 - u2 * v1);
    }
    sumUv += areaUv;
    sum3d += area3d;
    ratio[f] = area3d > 0 ? areaUv / area3d : -1;
  }
  const global = sumUv > 0 && sum3d > 0 ? sumUv / sum3d : 1;
  const stretch = new Float32Array(faces);
  for (let f = 0; f < faces; ++f) {
    if (ratio[f] < 0) stretch[f] = 0;
    else stretch[f] = ratio[f] > 0 ? Math.log2(ratio[f] / global) : -16;
  }
  return stretch;
}

/** Distinct colour per patch id (golden-ratio hue steps, as the CPU preview does). */
export function patchColor(id) {
  const golden = 0.6180339887498949;
  const hue = (((0.11 + golden * id) % 1) + 1) % 1;
  const sat = 0.45 + (0.25 * ((id * 7) % 3)) / 2;
  const val = 0.95 - 0.15 * ((id * 5) % 2);
  const c = new THREE.Color();
  // HSV -> HSL for THREE.Color.setHSL.
  const l = val * (1 - sat / 2);
  const s = l === 0 || l === 1 ? 0 : (val - l) / Math.min(l, 1 - l);
  c.setHSL(hue, s, l, THREE.NoColorSpace);
  return c;
}

/** A plain Float32Array of an attribute (copied when interleaved, normalized or not float). */
function floatArray(attribute) {
  if (!attribute) return null;
  if (!attribute.isInterleavedBufferAttribute && !attribute.normalized && attribute.array instanceof Float32Array &&
      attribute.array.length === attribute.count * attribute.itemSize) {
    return attribute.array;
  }
  const out = new Float32Array(attribute.count * attribute.itemSize);
  for (let i = 0; i < attribute.count; ++i) {
    for (let c = 0; c < attribute.itemSize; ++c) out[i * attribute.itemSize + c] = attribute.getComponent(i, c);
  }
  return out;
}

/**
 * Builds the viewer geometry from an (indexed or not) BufferGeometry with position, optional
 * normal and uv. Returns { geometry, faces, patches, seamEdges, hasUv }.
 */
export function buildSurface(source) {
  const position = floatArray(source.getAttribute('position'));
  const vertexCount = source.getAttribute('position').count;
  let index = source.index ? source.index.array : null;
  if (!index) {
    index = new Uint32Array(vertexCount);
    for (let i = 0; i < vertexCount; ++i) index[i] = i;
  }
  if (!source.getAttribute('normal')) source.computeVertexNormals();
  const normal = floatArray(source.getAttribute('normal'));
  const uv = floatArray(source.getAttribute('uv'));

  const faces = index.length / 3;
  const { seam, patch, count } = edgesAndPatches(index);
  const stretch = faceStretch(index, position, uv);

  const n = 3 * faces;
  const outPos = new Float32Array(3 * n);
  const outNor = new Float32Array(3 * n);
  const outUv = new Float32Array(2 * n);
  const outBary = new Uint8Array(3 * n);
  const outSeam = new Uint8Array(3 * n);
  const outPatch = new Uint8Array(3 * n);
  const outStretch = new Float32Array(n);
  const palette = new Uint8Array(3 * count);
  for (let p = 0; p < count; ++p) {
    const c = patchColor(p);
    palette[3 * p] = Math.round(c.r * 255);
    palette[3 * p + 1] = Math.round(c.g * 255);
    palette[3 * p + 2] = Math.round(c.b * 255);
  }
  let seamCount = 0;
  for (let f = 0; f < faces; ++f) {
    const color = 3 * patch[f];
    for (let k = 0; k < 3; ++k) {
      const corner = 3 * f + k;
      const v = index[corner];
      outPos[3 * corner] = position[3 * v];
      outPos[3 * corner + 1] = position[3 * v + 1];
      outPos[3 * corner + 2] = position[3 * v + 2];
      outNor[3 * corner] = normal[3 * v];
      outNor[3 * corner + 1] = normal[3 * v + 1];
      outNor[3 * corner + 2] = normal[3 * v + 2];
      if (uv) {
        outUv[2 * corner] = uv[2 * v];
        outUv[2 * corner + 1] = uv[2 * v + 1];
      }
      outBary[3 * corner + k] = 255;
      // Component m of `seam` flags the edge opposite corner m, i.e. edge (m+1) -> (m+2).
      for (let m = 0; m < 3; ++m) outSeam[3 * corner + m] = seam[3 * f + ((m + 1) % 3)] * 255;
      outPatch[3 * corner] = palette[color];
      outPatch[3 * corner + 1] = palette[color + 1];
      outPatch[3 * corner + 2] = palette[color + 2];
      outStretch[corner] = stretch[f];
    }
    seamCount += seam[3 * f] + seam[3 * f + 1] + seam[3 * f + 2];
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(outPos, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(outNor, 3));
  geometry.setAttribute('uv', new THREE.BufferAttribute(outUv, 2));
  geometry.setAttribute('bary', new THREE.BufferAttribute(outBary, 3, true));
  geometry.setAttribute('seam', new THREE.BufferAttribute(outSeam, 3, true));
  geometry.setAttribute('patchColor', new THREE.BufferAttribute(outPatch, 3, true));
  geometry.setAttribute('stretch', new THREE.BufferAttribute(outStretch, 1));
  geometry.computeBoundingSphere();
  geometry.computeBoundingBox();
  return { geometry, faces, patches: count, seamEdges: seamCount, hasUv: !!uv };
}
