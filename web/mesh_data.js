// Per-face data of the viewer, computed once when a mesh is loaded (never per frame):
//   patches  - connected components of faces joined across shared edges. glTF files written by
//              tailor split vertices on (position, uv), so two faces share an edge of the split
//              mesh exactly when their UVs agree along it: the components are the UV patches
//              (the definition of `derive_patches` in metrics.h).
//   seams    - edges used by exactly one face of the split mesh: patch borders, cuts and mesh borders.
//   seam classes - the edges of the mesh welded by position, classified as `tailor eval` does
//              (seam_gap_px in include/tailor/metrics.h): no seam, invisible seam (the texture
//              continues across it: the two sides differ by whole repeats, to within a pixel),
//              visible seam, or border (one face, more than two, or two running it the same way);
//              with the length sums behind eval's visible_seam_ratio and seam_invisible_ratio.
//   stretch  - log2 of (UV area / 3D area) divided by the mesh-wide ratio sum(a) / sum(A), the
//              per-face area stretch of `tailor eval` (0 = ideal, +1 = twice the texture area).
// The result is an unindexed BufferGeometry (three corners per face, each with the face's
// values), so the shader can colour faces flat and draw edges from barycentric coordinates.
// Everything runs over typed arrays (edges grouped by a counting sort, vertices welded by a flat
// hash): about half a second per million faces in node.
import * as THREE from 'three';

/** Union-find root with path halving over an Int32Array of parents. */
function findRoot(parent, x) {
  while (parent[x] !== x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

// Lists longer than this (a vertex with a huge fan of faces) are matched by sorting, not by pairs.
const kLinearMatchLimit = 32;

/**
 * The uses of each undirected edge, linked in rings: ring[e] = the next directed edge (e = 3f + k,
 * corner k -> k+1) with the same two vertices, ring[e] === e for an edge used once. Vertices are
 * index values, or weld[index value] when weld is given (ids < vertexCount). The uses are grouped by
 * their lower vertex (a counting sort, as build_topology in C++: sequential passes that keep a
 * scan's vertex order in cache, where a hash of 3F keys scatters), then matched by higher vertex.
 */
export function edgeRings(index, weld, vertexCount) {
  const edges = index.length;
  const vertexOf = (e) => (weld ? weld[index[e]] : index[e]);
  const offset = new Uint32Array(vertexCount + 1);
  for (let e = 0; e < edges; ++e) {
    const u = vertexOf(e);
    const w = vertexOf(e % 3 === 2 ? e - 2 : e + 1);
    offset[(u < w ? u : w) + 1] += 1;
  }
  for (let v = 0; v < vertexCount; ++v) offset[v + 1] += offset[v];
  const listEdge = new Uint32Array(edges);
  const listHigh = new Int32Array(edges);  // -1 once linked
  {
    const cursor = offset.slice(0, vertexCount);
    for (let e = 0; e < edges; ++e) {
      const u = vertexOf(e);
      const w = vertexOf(e % 3 === 2 ? e - 2 : e + 1);
      const at = cursor[u < w ? u : w]++;
      listEdge[at] = e;
      listHigh[at] = u < w ? w : u;
    }
  }
  const ring = new Int32Array(edges);
  for (let v = 0; v < vertexCount; ++v) {
    const begin = offset[v];
    const end = offset[v + 1];
    if (end - begin > kLinearMatchLimit) {
      const order = new Uint32Array(end - begin);
      for (let k = 0; k < order.length; ++k) order[k] = begin + k;
      order.sort((x, y) => listHigh[x] - listHigh[y] || x - y);
      for (let k = 0; k < order.length;) {
        let m = k + 1;
        while (m < order.length && listHigh[order[m]] === listHigh[order[k]]) ++m;
        for (let r = k; r < m; ++r) ring[listEdge[order[r]]] = listEdge[order[r + 1 < m ? r + 1 : k]];
        k = m;
      }
      continue;
    }
    for (let i = begin; i < end; ++i) {
      const high = listHigh[i];
      if (high < 0) continue;
      let last = i;
      for (let j = i + 1; j < end; ++j) {
        if (listHigh[j] !== high) continue;
        listHigh[j] = -1;
        ring[listEdge[last]] = listEdge[j];
        last = j;
      }
      ring[listEdge[last]] = listEdge[i];
    }
  }
  return ring;
}

/**
 * Edge pairing of the split mesh. For each directed edge e = 3f + k (corner k -> k+1): seam[e] = 1
 * when no other face uses the same two vertex indices (a patch or mesh border), and patch ids:
 * faces joined across every shared edge (union-find), dense, in order of first face.
 */
export function edgesAndPatches(index) {
  const edges = index.length;
  const faces = edges / 3;
  let vertexCount = 0;
  for (let e = 0; e < edges; ++e) if (index[e] >= vertexCount) vertexCount = index[e] + 1;
  const ring = edgeRings(index, null, vertexCount);
  const parent = new Int32Array(faces);
  for (let f = 0; f < faces; ++f) parent[f] = f;
  const seam = new Uint8Array(edges);
  for (let e = 0; e < edges; ++e) {
    const o = ring[e];
    if (o === e) {
      seam[e] = 1;
      continue;
    }
    if (o < e) continue;  // each link once (a ring of two is linked both ways)
    const r1 = findRoot(parent, (e / 3) | 0);
    const r2 = findRoot(parent, (o / 3) | 0);
    if (r1 !== r2) parent[Math.max(r1, r2)] = Math.min(r1, r2);
  }
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

/** Edge classes of seamClasses(): no seam, invisible seam, visible seam, border (unpaired edge). */
export const kSeamNone = 0;
export const kSeamInvisible = 1;
export const kSeamVisible = 2;
export const kSeamBorder = 3;

/** Texture size `tailor eval` assumes when the file embeds no image. */
export const kDefaultTextureSize = 512;

/**
 * Welds vertices by exact position (the bits of the three floats, as weld_identical_positions in
 * C++: -0 and +0 differ): weld[v] = the first vertex with v's position. Flat hash, O(V).
 */
export function weldByPosition(position) {
  const count = position.length / 3;
  const bits = new Uint32Array(position.buffer, position.byteOffset, 3 * count);
  let size = 16;
  while (size < 2 * count) size *= 2;
  const mask = size - 1;
  const table = new Int32Array(size).fill(-1);
  const weld = new Uint32Array(count);
  for (let v = 0; v < count; ++v) {
    const x = bits[3 * v], y = bits[3 * v + 1], z = bits[3 * v + 2];
    let h = Math.imul(x, 0x9e3779b1) ^ Math.imul(y ^ (x >>> 16), 0x85ebca6b) ^ Math.imul(z ^ (y >>> 13), 0xc2b2ae35);
    h ^= h >>> 15;
    h = Math.imul(h, 0x2c1b3c6d);
    let slot = (h ^ (h >>> 12)) & mask;
    let id = -1;
    for (let w = table[slot]; w >= 0; w = table[slot]) {
      if (bits[3 * w] === x && bits[3 * w + 1] === y && bits[3 * w + 2] === z) {
        id = w;
        break;
      }
      slot = (slot + 1) & mask;
    }
    if (id < 0) {
      table[slot] = v;
      id = v;
    }
    weld[v] = id;
  }
  return weld;
}

/** std::round: halves away from zero (Math.round rounds -0.5 up), so u and -u give mirrored gaps. */
function roundHalfAway(x) {
  return x < 0 ? -Math.round(-x) : Math.round(x);
}

/**
 * The lattice gap (pixels) of a seam edge a -> b between faces f and g, as seam_gap_px in
 * uv_metrics.cpp: with d = uv_f - uv_g at each end and k the whole repeats nearest to their mean,
 * max over the ends of |d - k|; with symmetry 4 the least over g's UVs turned by 0, 90, 180 and
 * 270 degrees (a square tile that a quarter turn leaves unchanged). UVs in pixels, w x h the
 * texture.
 */
export function seamGap(fau, fav, fbu, fbv, gau, gav, gbu, gbv, w, h, symmetry = 1) {
  let best = Infinity;
  for (let rot = 0; rot < (symmetry === 4 ? 4 : 1); ++rot) {
    // g's side turned `rot` quarter turns counter-clockwise: (x, y) -> (-y, x).
    let au = gau, av = gav, bu = gbu, bv = gbv;
    for (let r = 0; r < rot; ++r) {
      [au, av] = [-av, au];
      [bu, bv] = [-bv, bu];
    }
    const dau = fau - au, dav = fav - av, dbu = fbu - bu, dbv = fbv - bv;
    const ku = w * roundHalfAway((0.5 * (dau + dbu)) / w);
    const kv = h * roundHalfAway((0.5 * (dav + dbv)) / h);
    const gap = Math.sqrt(Math.max((dau - ku) ** 2 + (dav - kv) ** 2, (dbu - ku) ** 2 + (dbv - kv) ** 2));
    best = Math.min(best, gap);
  }
  return best;
}

/**
 * Seam classes of the mesh welded by position, as `tailor eval` computes them (uv_metrics.cpp).
 * index: corners (3 per face) into the split mesh; position: 3 floats per vertex; uv: 2 floats per
 * vertex in texture repeats, or null; width, height: the texture size in pixels; symmetry: 1, or 4
 * for a 4-fold map (seamGap).
 * An undirected edge of the welded mesh used by exactly two faces running it in opposite directions
 * is paired; every other use is a border. A paired edge is a seam when its faces disagree on the UV
 * of an end; its lattice gap (pixels) is max over the ends a, b of |d - k|, with d = uv_f - uv_g
 * and k = the whole repeats nearest to (d_a + d_b) / 2; below 1 px the seam is invisible.
 * Returns { seamClass: Uint8Array(3F) per directed edge e = 3f + k (corner k -> k+1), both sides
 * of a pair alike; totalLength: 3D length of the distinct edges (a pair once, each border use
 * once); seamLength, invisibleLength, visibleLength; seamEdges, invisibleEdges: counts }.
 * Typed arrays only: O(F).
 */
export function seamClasses(index, position, uv, width = kDefaultTextureSize, height = kDefaultTextureSize, symmetry = 1) {
  const edges = index.length;
  const weld = weldByPosition(position);
  // UVs in pixels rounded to float, as eval's corner_uv (identical UVs stay identical).
  let uvPx = null;
  if (uv) {
    uvPx = new Float32Array(uv.length);
    for (let v = 0; v < uv.length; v += 2) {
      uvPx[v] = uv[v] * width;
      uvPx[v + 1] = uv[v + 1] * height;
    }
  }
  // A pair candidate: e's undirected edge has exactly two uses (a ring of two).
  const ring = edgeRings(index, weld, weld.length);

  const seamClass = new Uint8Array(edges);
  let totalLength = 0, seamLength = 0, invisibleLength = 0, visibleLength = 0;
  let seamEdges = 0, invisibleEdges = 0;
  for (let e = 0; e < edges; ++e) {
    const next = ring[e];
    let o = next !== e && ring[next] === e ? next : -1;
    const eNext = e % 3 === 2 ? e - 2 : e + 1;
    if (o >= 0) {
      // Paired only when the two faces run the edge in opposite directions (consistent
      // orientation); an edge whose ends weld into one vertex has no direction (never paired).
      const oNext = o % 3 === 2 ? o - 2 : o + 1;
      const start = weld[index[e]];
      if (start !== weld[index[oNext]] || start === weld[index[eNext]]) o = -1;
      else if (o < e) continue;  // the pair was handled at its lower edge
    }
    const pa = 3 * index[e], pb = 3 * index[eNext];
    const dx = position[pb] - position[pa], dy = position[pb + 1] - position[pa + 1], dz = position[pb + 2] - position[pa + 2];
    const length = Math.sqrt(dx * dx + dy * dy + dz * dz);
    totalLength += length;
    if (o < 0) {
      seamClass[e] = kSeamBorder;
      continue;
    }
    if (!uvPx) continue;
    // e runs a -> b in face f, o runs b -> a in face g.
    const fa = 2 * index[e], fb = 2 * index[eNext];
    const ga = 2 * index[o % 3 === 2 ? o - 2 : o + 1], gb = 2 * index[o];
    if (uvPx[fa] === uvPx[ga] && uvPx[fa + 1] === uvPx[ga + 1] && uvPx[fb] === uvPx[gb] && uvPx[fb + 1] === uvPx[gb + 1]) continue;
    const gap = seamGap(uvPx[fa], uvPx[fa + 1], uvPx[fb], uvPx[fb + 1], uvPx[ga], uvPx[ga + 1], uvPx[gb], uvPx[gb + 1],
      width, height, symmetry);
    seamEdges += 1;
    seamLength += length;
    if (gap < 1) {
      seamClass[e] = seamClass[o] = kSeamInvisible;
      invisibleLength += length;
      invisibleEdges += 1;
    } else {
      seamClass[e] = seamClass[o] = kSeamVisible;
      visibleLength += length;
    }
  }
  return { seamClass, totalLength, seamLength, invisibleLength, visibleLength, seamEdges, invisibleEdges };
}

/**
 * eval's two seam figures from summed seamClasses() results: visibleSeamRatio = visible seam
 * length / length of all edges; seamInvisibleRatio = invisible share of seam length (1 with no
 * seam; the share of seam edges when every seam edge has zero length).
 */
export function seamRatios(s) {
  const visibleSeamRatio = s.totalLength > 0 ? s.visibleLength / s.totalLength : 0;
  let seamInvisibleRatio = 1;
  if (s.seamEdges > 0) {
    seamInvisibleRatio = s.seamLength > 0 ? s.invisibleLength / s.seamLength : s.invisibleEdges / s.seamEdges;
  }
  return { visibleSeamRatio, seamInvisibleRatio };
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
 * normal, uv and tangent; textureWidth, textureHeight: the embedded texture's size in pixels (eval's default
 * 512 without one), for the seam classes, and symmetry (4: a 4-fold map, seamGap). Returns { geometry, faces, patches, seamEdges, hasUv,
 * seams } with seams = seamClasses()'s sums (no per-edge array).
 */
export function buildSurface(source, { textureWidth = kDefaultTextureSize, textureHeight = kDefaultTextureSize, symmetry = 1 } = {}) {
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
  // The file's tangents (`tailor map --material` with a normal map): the shader's normal mapping.
  const tangent = floatArray(source.getAttribute('tangent'));

  const faces = index.length / 3;
  const { seam, patch, count } = edgesAndPatches(index);
  const stretch = faceStretch(index, position, uv);
  const { seamClass, ...seams } = seamClasses(index, position, uv, textureWidth, textureHeight, symmetry);

  const n = 3 * faces;
  const outPos = new Float32Array(3 * n);
  const outNor = new Float32Array(3 * n);
  const outUv = new Float32Array(2 * n);
  const outTangent = tangent ? new Float32Array(4 * n) : null;
  const outBary = new Uint8Array(3 * n);
  const outSeam = new Uint8Array(3 * n);
  const outSeamClass = new Uint8Array(3 * n);
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
      if (outTangent) for (let c = 0; c < 4; ++c) outTangent[4 * corner + c] = tangent[4 * v + c];
      if (uv) {
        outUv[2 * corner] = uv[2 * v];
        outUv[2 * corner + 1] = uv[2 * v + 1];
      }
      outBary[3 * corner + k] = 255;
      // Component m of `seam` flags the edge opposite corner m, i.e. edge (m+1) -> (m+2).
      for (let m = 0; m < 3; ++m) outSeam[3 * corner + m] = seam[3 * f + ((m + 1) % 3)] * 255;
      // The same layout for the seam classes of the welded mesh (0..3, not normalized).
      for (let m = 0; m < 3; ++m) outSeamClass[3 * corner + m] = seamClass[3 * f + ((m + 1) % 3)];
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
  if (outTangent) geometry.setAttribute('fileTangent', new THREE.BufferAttribute(outTangent, 4));
  geometry.setAttribute('bary', new THREE.BufferAttribute(outBary, 3, true));
  geometry.setAttribute('seam', new THREE.BufferAttribute(outSeam, 3, true));
  geometry.setAttribute('seamClass', new THREE.BufferAttribute(outSeamClass, 3));
  geometry.setAttribute('patchColor', new THREE.BufferAttribute(outPatch, 3, true));
  geometry.setAttribute('stretch', new THREE.BufferAttribute(outStretch, 1));
  geometry.computeBoundingSphere();
  geometry.computeBoundingBox();
  return { geometry, faces, patches: count, seamEdges: seamCount, hasUv: !!uv, seams };
}
