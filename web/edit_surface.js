// The editing page's mesh (edit.js): the session's mesh in input face order (GET /api/mesh) drawn
// unindexed, three corners per face, with the per-face values of the viewer's shader
// (surface_material.js): UVs, patch colours, seam flags and classes, stretch, and the marked seam
// faces. A new version's corner UVs (GET /api/uv) are applied incrementally: only faces whose UVs
// changed, and their edge neighbours, are rewritten and uploaded, so an edit that re-maps a few
// thousand faces of a million costs a few thousand faces of work here, plus one union-find pass for
// the patches (faces joined across edges whose two sides have the same UVs, as derive_patches in
// metrics.h; a patch's colour follows its lowest face, so untouched patches keep their colours).
import * as THREE from 'three';
import { edgeRings, patchColor, seamGap, kSeamNone, kSeamInvisible, kSeamVisible, kSeamBorder } from './mesh_data.js';

const next = (e) => (e % 3 === 2 ? e - 2 : e + 1);

/** Union-find root with path halving. */
function findRoot(parent, x) {
  while (parent[x] !== x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

/**
 * Parses GET /api/mesh: uint32 vertex count V, uint32 face count F, float32 positions (3V), uint32
 * indices (3F), little-endian.
 */
export function parseMesh(buffer) {
  const head = new Uint32Array(buffer, 0, 2);
  const vertices = head[0];
  const faces = head[1];
  if (buffer.byteLength !== 8 + 12 * vertices + 12 * faces) throw new Error('/api/mesh: unexpected size');
  return {
    vertices,
    faces,
    position: new Float32Array(buffer, 8, 3 * vertices),
    index: new Uint32Array(buffer, 8 + 12 * vertices, 3 * faces),
  };
}

export class EditSurface {
  /**
   * mesh: parseMesh()'s result; textureWidth, textureHeight: pixels per repeat (seam gaps);
   * symmetry: 4 for a 4-fold map (quarter-turn seams invisible, seamGap), else 1.
   */
  constructor(mesh, textureWidth, textureHeight, symmetry = 1) {
    const { position, index, faces, vertices } = mesh;
    this.faces = faces;
    this.index = index;
    this.position = position;
    this.width = textureWidth;
    this.height = textureHeight;
    this.symmetry = 1;  // setSymmetry(symmetry) below, once this.uv exists (null: nothing to classify yet)
    // Edge pairs: the other use of an undirected edge used exactly twice, in opposite directions.
    const ring = edgeRings(index, null, vertices);
    const pair = new Int32Array(3 * faces).fill(-1);
    for (let e = 0; e < 3 * faces; ++e) {
      const o = ring[e];
      if (o !== e && ring[o] === e && index[e] === index[next(o)] && index[e] !== index[next(e)]) pair[e] = o;
    }
    this.pair = pair;
    this.length = new Float32Array(3 * faces);
    this.area3d = new Float64Array(faces);
    let sum3d = 0;
    for (let f = 0; f < faces; ++f) {
      const p = [0, 1, 2].map((k) => 3 * index[3 * f + k]);
      for (let k = 0; k < 3; ++k) {
        const a = p[k], b = p[(k + 1) % 3];
        const dx = position[b] - position[a], dy = position[b + 1] - position[a + 1], dz = position[b + 2] - position[a + 2];
        this.length[3 * f + k] = Math.sqrt(dx * dx + dy * dy + dz * dz);
      }
      const e1 = [0, 1, 2].map((c) => position[p[1] + c] - position[p[0] + c]);
      const e2 = [0, 1, 2].map((c) => position[p[2] + c] - position[p[0] + c]);
      const cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
      this.area3d[f] = 0.5 * Math.sqrt(cx * cx + cy * cy + cz * cz);
      sum3d += this.area3d[f];
    }
    this.sum3d = sum3d;
    this.areaUv = new Float64Array(faces);
    this.sumUv = 0;
    this.uv = null;                                // Float32Array(6F), corner UVs in repeats
    this.setSymmetry(symmetry);
    this.same = new Uint8Array(3 * faces);         // per edge: paired and the same UVs on both sides
    this.seamClass = new Uint8Array(3 * faces);    // per edge: kSeam*
    this.root = new Int32Array(faces).fill(-1);    // per face: lowest face of its patch
    this.marked = new Uint8Array(faces);
    this.patches = 0;

    // The geometry: three corners per face.
    const n = 3 * faces;
    const indexed = new THREE.BufferGeometry();
    indexed.setAttribute('position', new THREE.BufferAttribute(position, 3));
    indexed.setIndex(new THREE.BufferAttribute(index, 1));
    indexed.computeVertexNormals();
    const normal = indexed.getAttribute('normal').array;
    const outPos = new Float32Array(3 * n);
    const outNor = new Float32Array(3 * n);
    const outBary = new Uint8Array(3 * n);
    for (let c = 0; c < n; ++c) {
      const v = index[c];
      for (let k = 0; k < 3; ++k) {
        outPos[3 * c + k] = position[3 * v + k];
        outNor[3 * c + k] = normal[3 * v + k];
      }
      outBary[3 * c + (c % 3)] = 255;
    }
    const geometry = new THREE.BufferGeometry();
    const dynamic = (attribute) => attribute.setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute('position', new THREE.BufferAttribute(outPos, 3));
    geometry.setAttribute('normal', new THREE.BufferAttribute(outNor, 3));
    geometry.setAttribute('bary', new THREE.BufferAttribute(outBary, 3, true));
    geometry.setAttribute('uv', dynamic(new THREE.BufferAttribute(new Float32Array(2 * n), 2)));
    geometry.setAttribute('seam', dynamic(new THREE.BufferAttribute(new Uint8Array(3 * n), 3, true)));
    geometry.setAttribute('seamClass', dynamic(new THREE.BufferAttribute(new Uint8Array(3 * n), 3)));
    geometry.setAttribute('patchColor', dynamic(new THREE.BufferAttribute(new Uint8Array(3 * n), 3, true)));
    geometry.setAttribute('stretch', dynamic(new THREE.BufferAttribute(new Float32Array(n), 1)));
    geometry.setAttribute('marked', dynamic(new THREE.BufferAttribute(new Float32Array(n), 1)));
    geometry.computeBoundingSphere();
    geometry.computeBoundingBox();
    indexed.dispose();
    this.geometry = geometry;
    this.palette = new Map();  // patch root -> [r, g, b] bytes
  }

  /** Whether the two sides of paired edge e (face f, corner k -> k+1) and o carry the same UVs. */
  sameUv(bits, e, o) {
    // e runs a -> b, o runs b -> a: uv(e's a) = uv(o's end), uv(e's b) = uv(o's start).
    const ea = 2 * e, eb = 2 * next(e), oa = 2 * next(o), ob = 2 * o;
    return bits[ea] === bits[oa] && bits[ea + 1] === bits[oa + 1] && bits[eb] === bits[ob] && bits[eb + 1] === bits[ob + 1];
  }

  /** The seam class of edge e against its pair o, as seamClasses() in mesh_data.js. */
  edgeClass(e, o) {
    if (o < 0) return kSeamBorder;
    const uv = this.uv, w = this.width, h = this.height;
    const fa = 2 * e, fb = 2 * next(e), ga = 2 * next(o), gb = 2 * o;
    const px = (i, s) => Math.fround(uv[i] * s);
    const fau = px(fa, w), fav = px(fa + 1, h), fbu = px(fb, w), fbv = px(fb + 1, h);
    const gau = px(ga, w), gav = px(ga + 1, h), gbu = px(gb, w), gbv = px(gb + 1, h);
    if (fau === gau && fav === gav && fbu === gbu && fbv === gbv) return kSeamNone;
    return seamGap(fau, fav, fbu, fbv, gau, gav, gbu, gbv, w, h, this.symmetry) < 1 ? kSeamInvisible : kSeamVisible;
  }

  /**
   * Applies corner UVs (Float32Array, 6 per face, repeats). Returns the number of faces whose UVs
   * changed; the geometry's attributes are rewritten and marked for upload where they changed.
   */
  setUvs(uv) {
    const faces = this.faces;
    if (uv.length !== 6 * faces) throw new Error(`expected ${6 * faces} UV values, got ${uv.length}`);
    const bits = new Uint32Array(uv.buffer, uv.byteOffset, uv.length);
    const changed = [];
    if (this.uv === null) {
      for (let f = 0; f < faces; ++f) changed.push(f);
    } else {
      const old = new Uint32Array(this.uv.buffer, this.uv.byteOffset, this.uv.length);
      for (let f = 0; f < faces; ++f) {
        const i = 6 * f;
        if (old[i] !== bits[i] || old[i + 1] !== bits[i + 1] || old[i + 2] !== bits[i + 2] || old[i + 3] !== bits[i + 3] ||
            old[i + 4] !== bits[i + 4] || old[i + 5] !== bits[i + 5]) changed.push(f);
      }
    }
    this.uv = uv;
    return this.update(changed);
  }

  /**
   * Applies the answer of GET /api/uv?version=N&since=M (the version shown): uint32 count K, K face
   * ids, 6K floats. Returns the number of faces whose UVs changed.
   */
  applyDelta(buffer) {
    const count = new Uint32Array(buffer, 0, 1)[0];
    if (buffer.byteLength !== 4 + 28 * count) throw new Error('/api/uv: unexpected size of a delta');
    const ids = new Uint32Array(buffer, 4, count);
    const values = new Float32Array(buffer, 4 + 4 * count, 6 * count);
    const changed = [];
    for (let i = 0; i < count; ++i) {
      const f = ids[i];
      if (f >= this.faces) throw new Error('/api/uv: face id out of range');
      for (let k = 0; k < 6; ++k) this.uv[6 * f + k] = values[6 * i + k];
      changed.push(f);
    }
    return this.update(changed);
  }

  /** Sets the map's symmetry (4: quarter-turn seams invisible) and classifies every seam again. */
  setSymmetry(symmetry) {
    const s = symmetry === 4 && this.width === this.height ? 4 : 1;
    if (s === this.symmetry) return;
    this.symmetry = s;
    if (this.uv === null) return;
    const changed = [];
    for (let f = 0; f < this.faces; ++f) changed.push(f);
    this.update(changed);
  }

  /** Rewrites what depends on the UVs of the `changed` faces (this.uv holds the new ones). */
  update(changed) {
    const faces = this.faces;
    const first = this.root[0] < 0;
    if (changed.length === 0) return 0;
    const uv = this.uv;
    const bits = new Uint32Array(uv.buffer, uv.byteOffset, uv.length);
    const touched = new Uint8Array(faces);  // faces whose attributes are rewritten
    const pair = this.pair;
    for (const f of changed) {
      touched[f] = 1;
      for (let k = 0; k < 3; ++k) {
        const e = 3 * f + k;
        const o = pair[e];
        const same = o >= 0 && this.sameUv(bits, e, o) ? 1 : 0;
        const cls = this.edgeClass(e, o);
        this.same[e] = same;
        this.seamClass[e] = cls;
        if (o >= 0) {
          this.same[o] = same;
          this.seamClass[o] = cls;
          touched[(o / 3) | 0] = 1;
        }
      }
      // UV area for the stretch (the viewer's faceStretch, relative to the mesh-wide ratio).
      const u1 = uv[6 * f + 2] - uv[6 * f], v1 = uv[6 * f + 3] - uv[6 * f + 1];
      const u2 = uv[6 * f + 4] - uv[6 * f], v2 = uv[6 * f + 5] - uv[6 * f + 1];
      const a = 0.5 * Math.abs(u1 * v2 - u2 * v1);
      this.sumUv += a - this.areaUv[f];
      this.areaUv[f] = a;
    }
    // Patches: one union-find pass over the edges whose sides agree; the root is the lowest face.
    const parent = new Int32Array(faces);
    for (let f = 0; f < faces; ++f) parent[f] = f;
    const same = this.same;
    for (let e = 0; e < 3 * faces; ++e) {
      if (!same[e]) continue;
      const o = pair[e];
      if (o < e) continue;
      const r1 = findRoot(parent, (e / 3) | 0);
      const r2 = findRoot(parent, (o / 3) | 0);
      if (r1 !== r2) {
        if (r1 < r2) parent[r2] = r1;
        else parent[r1] = r2;
      }
    }
    let patches = 0;
    for (let f = 0; f < faces; ++f) {
      const r = findRoot(parent, f);
      if (r === f) patches += 1;
      if (r !== this.root[f]) {
        this.root[f] = r;
        touched[f] = 1;
      }
    }
    this.patches = patches;
    this.writeFaces(touched, first || changed.length === faces);
    return changed.length;
  }

  /** Colour bytes of the patch whose lowest face is `root` (cached). */
  colorOf(root) {
    let c = this.palette.get(root);
    if (!c) {
      const color = patchColor(root);
      c = [Math.round(color.r * 255), Math.round(color.g * 255), Math.round(color.b * 255)];
      this.palette.set(root, c);
    }
    return c;
  }

  /** Rewrites the attributes of the touched faces and marks their ranges for upload. */
  writeFaces(touched, all) {
    const g = this.geometry;
    const uvOut = g.getAttribute('uv');
    const seamOut = g.getAttribute('seam');
    const classOut = g.getAttribute('seamClass');
    const patchOut = g.getAttribute('patchColor');
    const stretchOut = g.getAttribute('stretch');
    const global = this.sumUv > 0 && this.sum3d > 0 ? this.sumUv / this.sum3d : 1;
    const ranges = [];
    const list = [];
    for (let f = 0; f < this.faces; ++f) {
      if (!touched[f]) continue;
      list.push(f);
      const last = ranges[ranges.length - 1];
      if (last && f - last[1] < 256) last[1] = f + 1;
      else ranges.push([f, f + 1]);
      const color = this.colorOf(this.root[f]);
      const area3d = this.area3d[f];
      const ratio = area3d > 0 ? this.areaUv[f] / area3d : -1;
      const stretch = ratio < 0 ? 0 : ratio > 0 ? Math.log2(ratio / global) : -16;
      for (let k = 0; k < 3; ++k) {
        const corner = 3 * f + k;
        uvOut.array[2 * corner] = this.uv[2 * corner];
        uvOut.array[2 * corner + 1] = this.uv[2 * corner + 1];
        // Component m flags the edge opposite corner m, i.e. edge (m+1) -> (m+2).
        for (let m = 0; m < 3; ++m) {
          const e = 3 * f + ((m + 1) % 3);
          seamOut.array[3 * corner + m] = this.same[e] ? 0 : 255;
          classOut.array[3 * corner + m] = this.seamClass[e];
        }
        for (let c = 0; c < 3; ++c) patchOut.array[3 * corner + c] = color[c];
        stretchOut.array[corner] = stretch;
      }
    }
    this.lastTouched = list;
    for (const attribute of [uvOut, seamOut, classOut, patchOut, stretchOut]) {
      attribute.clearUpdateRanges();
      if (!all && ranges.length <= 256) {
        for (const [a, b] of ranges) attribute.addUpdateRange(3 * a * attribute.itemSize, 3 * (b - a) * attribute.itemSize);
      }
      attribute.needsUpdate = true;
    }
  }

  /**
   * A geometry of only `faces`, with their attributes as the full one holds them: the page redraws
   * just these over the previous frame after an edit (same positions, so the same depths).
   */
  subsetGeometry(faces) {
    const g = new THREE.BufferGeometry();
    for (const [name, attribute] of Object.entries(this.geometry.attributes)) {
      const size = 3 * attribute.itemSize;  // values per face
      const out = new attribute.array.constructor(faces.length * size);
      for (let i = 0; i < faces.length; ++i) out.set(attribute.array.subarray(faces[i] * size, (faces[i] + 1) * size), i * size);
      g.setAttribute(name, new THREE.BufferAttribute(out, attribute.itemSize, attribute.normalized));
    }
    return g;
  }

  /** Sets the marked seam faces (Uint8Array or array of ids with `ids`). */
  setMarked(flags) {
    const out = this.geometry.getAttribute('marked');
    for (let f = 0; f < this.faces; ++f) {
      this.marked[f] = flags[f] ? 1 : 0;
      out.array[3 * f] = out.array[3 * f + 1] = out.array[3 * f + 2] = this.marked[f];
    }
    out.clearUpdateRanges();
    out.needsUpdate = true;
  }

  /** Marks (value 1) or unmarks (0) the given faces locally, for instant feedback while painting. */
  markFaces(faces, value) {
    const out = this.geometry.getAttribute('marked');
    for (const f of faces) {
      this.marked[f] = value;
      out.array[3 * f] = out.array[3 * f + 1] = out.array[3 * f + 2] = value;
      out.addUpdateRange(3 * f, 3);
    }
    out.needsUpdate = true;
  }

  /** Seam statistics of the current UVs: patches, seam edges (pairs), visible and invisible ones. */
  seamCounts() {
    let seams = 0, visible = 0, invisible = 0;
    for (let e = 0; e < this.seamClass.length; ++e) {
      const o = this.pair[e];
      if (o < e) continue;
      if (this.seamClass[e] === kSeamVisible) { seams += 1; visible += 1; }
      if (this.seamClass[e] === kSeamInvisible) { seams += 1; invisible += 1; }
    }
    return { patches: this.patches, seams, visible, invisible };
  }
}
