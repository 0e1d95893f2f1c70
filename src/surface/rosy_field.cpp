// 4-RoSy orientation and lattice position fields on a vertex hierarchy (see rosy_field.h).
//
// Design after Instant Meshes (Jakob et al. 2015), written from its paper's description: the
// hierarchy here clusters vertices by a voxel grid whose cell doubles per level (and by the
// dominant axis of the normal, so that the two sides of a thin part stay apart), and every
// smoothing step is a Jacobi step (new values from old ones only) or a Gauss-Seidel step by
// coloured blocks (the coarse position levels), so threads do not change the result.
#include "surface/rosy_field.h"

#include <algorithm>
#include <cmath>

#include "util/block_sweep.h"
#include "util/flat_hash.h"
#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

// The smoothing sweeps run many times over each level: worth a thread from fewer vertices than a
// single pass (util/parallel_chunks.h's 100k), and in smaller chunks than its default so that two
// threads share a level of 50k vertices evenly (no sums are taken: any chunking gives the same
// bytes).
constexpr size_t kVerticesPerThread = 20000;
constexpr size_t kSweepChunk = 4096;

struct V3 {
  float x = 0, y = 0, z = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline float length(V3 a) { return std::sqrt(dot(a, a)); }
inline V3 load3(const std::vector<float>& a, size_t i) { return {a[3 * i], a[3 * i + 1], a[3 * i + 2]}; }
inline void store3(std::vector<float>& a, size_t i, V3 v) {
  a[3 * i] = v.x;
  a[3 * i + 1] = v.y;
  a[3 * i + 2] = v.z;
}
//! v projected on the plane of unit normal n, normalised; `fallback` when that degenerates.
inline V3 tangent(V3 v, V3 n, V3 fallback) {
  const V3 t = v - n * dot(v, n);
  const float l = length(t);
  return l > 1e-12f ? t * (1.f / l) : fallback;
}
//! Any unit vector perpendicular to n.
inline V3 any_tangent(V3 n) {
  const V3 a = std::abs(n.x) < 0.9f ? V3{1, 0, 0} : V3{0, 1, 0};
  return tangent(a, n, V3{0, 0, 1});
}
//! R^k q (R = quarter turn about n) that best matches ref, and k.
inline V3 match(V3 ref, V3 n, V3 q, int& k) {
  const V3 p = cross(n, q);
  const float a = dot(ref, q), b = dot(ref, p);
  k = 0;
  float best = a;
  if (b > best) {
    best = b;
    k = 1;
  }
  if (-a > best) {
    best = -a;
    k = 2;
  }
  if (-b > best) k = 3;
  switch (k) {
    case 0: return q;
    case 1: return p;
    case 2: return q * -1.f;
    default: return p * -1.f;
  }
}

struct Level {
  std::vector<uint32_t> start, adj;  // CSR adjacency
  std::vector<float> p, n, q, c;     // 3 per vertex: position, normal, field, feature direction
  std::vector<uint8_t> fixed;        // 1: q is tied to c
  std::vector<float> u;              // 2 per vertex: lattice coordinate
  std::vector<uint32_t> parent;      // vertex of the next coarser level
  size_t size() const { return fixed.size(); }
};

//! Offset (pixels, in v's frame averaged with w's matched frame) of w from v, and the quarter
//! turns k taking w's frame to v's.
inline void edge_offset(const Level& L, size_t v, const Level& M, size_t w, float scale, int& k, float d[2]) {
  const V3 qv = load3(L.q, v), nv = load3(L.n, v), qw = load3(M.q, w), nw = load3(M.n, w);
  const V3 qw_k = match(qv, nw, qw, k);
  const V3 pw_k = cross(nw, qw_k);
  V3 e1 = qv + qw_k, e2 = cross(nv, qv) + pw_k;
  const float l1 = length(e1), l2 = length(e2);
  e1 = l1 > 1e-12f ? e1 * (1.f / l1) : qv;
  e2 = l2 > 1e-12f ? e2 * (1.f / l2) : cross(nv, qv);
  const V3 delta = load3(M.p, w) - load3(L.p, v);
  d[0] = scale * dot(delta, e1);
  d[1] = scale * dot(delta, e2);
}

// std::round and std::floor are library calls on the x86-64 baseline (no SSE4.1), and the position
// smoothing makes two rounds per edge and sweep (a fifth of a 4-fold map's time). round_nearest
// adds and takes away 1.5 * 2^23, which leaves x rounded to the nearest integer (ties to even) for
// |x| < 2^22, without a branch that mispredicts (the lattice coordinates are within a few periods
// of 0; beyond, and for NaN, the library). round_down truncates and corrects.
inline float round_nearest(float x) {
  constexpr float kShift = 12582912.f;  // 1.5 * 2^23: the sum's last bit is the units
  if (!(std::abs(x) < 4194304.f)) return std::round(x);
  return (x + kShift) - kShift;
}
inline float round_down(float x) {
  if (!(std::abs(x) < 4194304.f)) return std::floor(x);
  const float t = static_cast<float>(static_cast<int32_t>(x));
  return x < t ? t - 1.f : t;
}

inline float wrap(float x, float period) {
  const float y = x - period * round_down(x / period);
  return y >= period ? 0.f : y;  // rounding can give exactly period
}

//! U of v (level L) predicted from w (level M): rot_k(U_w) - d_vw.
inline void predict(const Level& L, size_t v, const Level& M, size_t w, float scale, float out[2]) {
  int k;
  float d[2];
  edge_offset(L, v, M, w, scale, k, d);
  float x, y;
  rotate_quarter(k, M.u[2 * w], M.u[2 * w + 1], x, y);
  out[0] = x - d[0];
  out[1] = y - d[1];
}

//! The adjacency of `count` vertices from (p << 32 | q) pairs, each row sorted, without repeats.
//! Bucketed by row first, then each short row sorted: a sort of all pairs took a tenth of the
//! field's time.
void build_csr(size_t count, std::vector<uint64_t>& pairs, Level& L) {
  std::vector<uint32_t> fill(count + 1, 0), row(pairs.size());
  for (const uint64_t pq : pairs) ++fill[(pq >> 32) + 1];
  for (size_t i = 0; i < count; ++i) fill[i + 1] += fill[i];
  const std::vector<uint32_t> bucket(fill.begin(), fill.end());
  for (const uint64_t pq : pairs) row[fill[pq >> 32]++] = static_cast<uint32_t>(pq);
  pairs = {};
  L.start.assign(count + 1, 0);
  L.adj.clear();
  L.adj.reserve(row.size());
  for (size_t v = 0; v < count; ++v) {
    const auto first = row.begin() + bucket[v], last = row.begin() + bucket[v + 1];
    std::sort(first, last);
    L.adj.insert(L.adj.end(), first, std::unique(first, last));
    L.start[v + 1] = static_cast<uint32_t>(L.adj.size());
  }
}

//! Clusters level L into a coarser level by a voxel grid of side `cell` and the normal's axis.
Level coarsen(Level& L, float cell) {
  Level C;
  const size_t n = L.size();
  L.parent.assign(n, 0);
  FlatIdTable cluster(n);
  std::vector<uint64_t> cluster_key;
  std::vector<uint32_t> members;
  for (size_t v = 0; v < n; ++v) {
    const V3 p = load3(L.p, v), nv = load3(L.n, v);
    const auto cell_of = [cell](float x) {
      return static_cast<uint64_t>(static_cast<int64_t>(std::floor(x / cell)) + (1 << 19)) & 0xFFFFF;
    };
    const float ax = std::abs(nv.x), ay = std::abs(nv.y), az = std::abs(nv.z);
    const uint64_t bin = ax >= ay && ax >= az ? (nv.x < 0) : ay >= az ? 2u + (nv.y < 0) : 4u + (nv.z < 0);
    const uint64_t key = (cell_of(p.x) << 43) | (cell_of(p.y) << 23) | (cell_of(p.z) << 3) | bin;
    const uint32_t id = cluster.find_or_insert(hash_mix(key), static_cast<uint32_t>(members.size()),
                                               [&](uint32_t s) { return cluster_key[s] == key; });
    if (id == members.size()) {
      members.push_back(0);
      cluster_key.push_back(key);
    }
    L.parent[v] = id;
    ++members[id];
  }
  const size_t m = members.size();
  C.p.assign(3 * m, 0.f);
  C.n.assign(3 * m, 0.f);
  C.q.assign(3 * m, 0.f);
  C.c.assign(3 * m, 0.f);
  C.fixed.assign(m, 0);
  C.u.assign(2 * m, 0.f);
  for (size_t v = 0; v < n; ++v) {
    const uint32_t P = L.parent[v];
    store3(C.p, P, load3(C.p, P) + load3(L.p, v));
    store3(C.n, P, load3(C.n, P) + load3(L.n, v));
    store3(C.q, P, load3(C.q, P) + load3(L.q, v));
    if (L.fixed[v]) {
      const V3 acc = load3(C.c, P);
      int k;
      store3(C.c, P, C.fixed[P] ? acc + match(acc, load3(L.n, v), load3(L.c, v), k) : load3(L.c, v));
      C.fixed[P] = 1;
    }
  }
  for (size_t P = 0; P < m; ++P) {
    store3(C.p, P, load3(C.p, P) * (1.f / static_cast<float>(members[P])));
    V3 nn = load3(C.n, P);
    const float l = length(nn);
    nn = l > 1e-12f ? nn * (1.f / l) : V3{0, 0, 1};
    store3(C.n, P, nn);
    const V3 fallback = any_tangent(nn);
    store3(C.q, P, tangent(load3(C.q, P), nn, fallback));
    if (C.fixed[P]) store3(C.c, P, tangent(load3(C.c, P), nn, fallback));
  }
  std::vector<uint64_t> pairs;
  for (size_t v = 0; v < n; ++v)
    for (uint32_t i = L.start[v]; i < L.start[v + 1]; ++i) {
      const uint64_t P = L.parent[v], Q = L.parent[L.adj[i]];
      if (P != Q) pairs.push_back((P << 32) | Q);
    }
  build_csr(m, pairs, C);
  return C;
}

void smooth_orientation(Level& L, uint32_t iterations, size_t threads) {
  const size_t n = L.size();
  std::vector<float> next(L.q.size());
  for (uint32_t it = 0; it < iterations; ++it) {
    for_each_chunk(
        n, threads,
        [&](size_t begin, size_t end, size_t) {
          for (size_t v = begin; v < end; ++v) {
            const V3 qv = load3(L.q, v);
            if (L.start[v] == L.start[v + 1]) {
              store3(next, v, L.fixed[v] ? load3(L.c, v) : qv);
              continue;
            }
            V3 acc = qv;
            if (L.fixed[v]) {  // a soft pull towards the feature, as strong as all neighbours together
              int k;
              acc = acc + match(acc, load3(L.n, v), load3(L.c, v), k) * static_cast<float>(L.start[v + 1] - L.start[v]);
            }
            for (uint32_t i = L.start[v]; i < L.start[v + 1]; ++i) {
              const uint32_t w = L.adj[i];
              int k;
              acc = acc + match(acc, load3(L.n, w), load3(L.q, w), k);
            }
            store3(next, v, tangent(acc, load3(L.n, v), qv));
          }
        },
        kSweepChunk);
    L.q.swap(next);
  }
}

//! Jacobi steps (over_relaxation 1) or, with over_relaxation > 1, Gauss-Seidel steps by coloured
//! blocks of vertices (util/block_sweep.h), each vertex moved over_relaxation times the way to its
//! mean; both on `threads` threads, the same bytes for any count.
void smooth_position(Level& L, uint32_t iterations, float scale, float period, float robust, size_t threads,
                     float over_relaxation) {
  const size_t n = L.size();
  // The fields' matching and the offsets are fixed while the positions move: computed once.
  std::vector<int8_t> turns(L.adj.size());
  std::vector<float> offset(2 * L.adj.size()), scale2(L.adj.size());  // scale2: the robust s^2 below
  for_each_chunk(
      n, threads,
      [&](size_t begin, size_t end, size_t) {
        for (size_t v = begin; v < end; ++v)
          for (uint32_t i = L.start[v]; i < L.start[v + 1]; ++i) {
            int k;
            edge_offset(L, v, L, L.adj[i], scale, k, &offset[2 * i]);
            turns[i] = static_cast<int8_t>(k & 3);
            scale2[i] = robust * (offset[2 * i] * offset[2 * i] + offset[2 * i + 1] * offset[2 * i + 1]) + 1e-6f;
          }
      },
      kSweepChunk);
  const float inv_period = 1.f / period;
  const bool in_place = over_relaxation > 1.f;         // Gauss-Seidel: each vertex sees its neighbours' new values
  std::vector<float> next(in_place ? 0 : L.u.size());  // Jacobi's second buffer
  const auto update = [&](size_t v) {
    const float ux = L.u[2 * v], uy = L.u[2 * v + 1];
    float sx = ux, sy = uy, sw = 1.f;
    for (uint32_t i = L.start[v]; i < L.start[v + 1]; ++i) {
      const uint32_t w = L.adj[i];
      const float* t = kQuarterTurn[turns[i]];
      const float a = L.u[2 * w], b = L.u[2 * w + 1];
      float x = t[0] * a + t[1] * b - offset[2 * i];
      float y = t[2] * a + t[3] * b - offset[2 * i + 1];
      x += period * round_nearest((ux - x) * inv_period);
      y += period * round_nearest((uy - y) * inv_period);
      // Robust weight: an edge far off its offset is left to become a cut (a visible seam from a
      // cone) instead of stretching everything around it. 1 / (1 + r^2 / s^2) as one division (the
      // sweep's slowest instruction).
      const float rx = x - ux, ry = y - uy;
      const float wgt = robust > 0.f ? scale2[i] / (scale2[i] + (rx * rx + ry * ry)) : 1.f;
      sx += wgt * x;
      sy += wgt * y;
      sw += wgt;
    }
    const float inv = 1.f / sw;
    if (in_place) {
      L.u[2 * v] = wrap(ux + over_relaxation * (sx * inv - ux), period);
      L.u[2 * v + 1] = wrap(uy + over_relaxation * (sy * inv - uy), period);
    } else {
      next[2 * v] = wrap(sx * inv, period);
      next[2 * v + 1] = wrap(sy * inv, period);
    }
  };
  if (in_place) {  // by coloured blocks of vertices (util/block_sweep.h)
    std::vector<uint64_t> pairs;
    for (size_t v = 0; v < n; ++v)
      for (uint32_t i = L.start[v]; i < L.start[v + 1]; ++i) BlockSweep::couple(v, L.adj[i], pairs);
    const BlockSweep blocks(n, std::move(pairs));
    for (uint32_t it = 0; it < iterations; ++it) blocks.sweep(threads, update);
    return;
  }
  for (uint32_t it = 0; it < iterations; ++it) {
    for_each_chunk(
        n, threads,
        [&](size_t begin, size_t end, size_t) {
          for (size_t v = begin; v < end; ++v) update(v);
        },
        kSweepChunk);
    L.u.swap(next);
  }
}

//! Coarsest level's start: every graph component integrated along a breadth-first tree.
void integrate_position(Level& L, float scale, float period) {
  const size_t n = L.size();
  std::vector<uint8_t> seen(n, 0);
  std::vector<uint32_t> queue;
  for (size_t s = 0; s < n; ++s) {
    if (seen[s]) continue;
    seen[s] = 1;
    L.u[2 * s] = L.u[2 * s + 1] = 0.f;
    queue.assign(1, static_cast<uint32_t>(s));
    for (size_t head = 0; head < queue.size(); ++head) {
      const uint32_t v = queue[head];
      for (uint32_t i = L.start[v]; i < L.start[v + 1]; ++i) {
        const uint32_t w = L.adj[i];
        if (seen[w]) continue;
        seen[w] = 1;
        float pr[2];
        predict(L, w, L, v, scale, pr);
        L.u[2 * w] = wrap(pr[0], period);
        L.u[2 * w + 1] = wrap(pr[1], period);
        queue.push_back(w);
      }
    }
  }
}

}  // namespace

LatticeMap lattice_map(const RosyField& field, uint32_t v, uint32_t w) {
  const bool direct = v < w;
  const uint32_t a = direct ? v : w, b = direct ? w : v;  // map from b's chart to a's
  const V3 qa = load3(field.q, a), qb = load3(field.q, b), nb = load3(field.normal, b);
  LatticeMap m;
  const V3 qb_k = match(qa, nb, qb, m.r);
  const V3 e1s = qa + qb_k, e2s = cross(load3(field.normal, a), qa) + cross(nb, qb_k);
  const float l1 = length(e1s), l2 = length(e2s);
  const V3 e1 = l1 > 1e-12f ? e1s * (1.f / l1) : qa;
  const V3 e2 = l2 > 1e-12f ? e2s * (1.f / l2) : cross(load3(field.normal, a), qa);
  const V3 delta = load3(field.position, b) - load3(field.position, a);
  float x, y;
  rotate_quarter(m.r, field.uv[2 * b], field.uv[2 * b + 1], x, y);
  const float inv = 1.f / field.period;
  m.tx = static_cast<int>(std::lround((field.uv[2 * a] + field.scale * dot(delta, e1) - x) * inv));
  m.ty = static_cast<int>(std::lround((field.uv[2 * a + 1] + field.scale * dot(delta, e2) - y) * inv));
  return direct ? m : inverse(m);
}

void compute_rosy_field(const Mesh& mesh, const Topology& topology, const FaceFrames& frames,
                        const RosyFieldOptions& options, RosyField& field) {
  const size_t nv = mesh.vertex_count(), nf = mesh.face_count();
  const uint32_t* idx = mesh.indices.data();
  std::vector<Level> levels(1);
  levels.reserve(16);  // F stays valid while levels are added
  Level& F = levels[0];
  F.p.resize(3 * nv);
  for (size_t v = 0; v < nv; ++v)
    for (size_t i = 0; i < 3; ++i) F.p[3 * v + i] = (mesh.positions[3 * v + i] - frames.origin[i]) * frames.unit_scale;
  F.n.assign(3 * nv, 0.f);
  F.q.assign(3 * nv, 0.f);
  F.c.assign(3 * nv, 0.f);
  F.fixed.assign(nv, 0);
  F.u.assign(2 * nv, 0.f);
  for (size_t f = 0; f < nf; ++f) {
    const V3 fn = load3(frames.normal, f) * frames.area[f], fo = load3(frames.orientation, f);
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t v = idx[3 * f + k];
      store3(F.n, v, load3(F.n, v) + fn);
      store3(F.q, v, load3(F.q, v) + fo);
    }
  }
  for (size_t v = 0; v < nv; ++v) {
    V3 nn = load3(F.n, v);
    const float l = length(nn);
    nn = l > 1e-20f ? nn * (1.f / l) : V3{0, 0, 1};
    store3(F.n, v, nn);
    store3(F.q, v, tangent(load3(F.q, v), nn, any_tangent(nn)));
  }
  // Features: the field follows sharp edges (their direction, up to quarter turns).
  std::vector<uint8_t> sharp_count(nv, 0);
  const float sharp_cos = std::cos(options.sharp_angle_deg * 3.14159265f / 180.f);
  std::vector<uint64_t> pairs;
  pairs.reserve(6 * nf);
  double edge_length_sum = 0;
  size_t edge_count = 0;
  for (size_t e = 0; e < 3 * nf; ++e) {
    const uint64_t a = idx[e], b = idx[e - e % 3 + (e % 3 + 1) % 3];
    pairs.push_back((a << 32) | b);
    pairs.push_back((b << 32) | a);
    const V3 dir = load3(F.p, b) - load3(F.p, a);
    edge_length_sum += length(dir);
    ++edge_count;
    const uint32_t o = topology.opposite[e];
    if (o == kInvalid || o < e) continue;
    if (dot(load3(frames.normal, e / 3), load3(frames.normal, o / 3)) >= sharp_cos) continue;
    for (const uint64_t v : {a, b}) {
      const V3 nn = load3(F.n, v);
      const V3 t = tangent(dir, nn, V3{0, 0, 0});
      if (length(t) == 0.f) continue;
      int k;
      store3(F.c, v, F.fixed[v] ? load3(F.c, v) + match(load3(F.c, v), nn, t, k) : t);
      F.fixed[v] = 1;
      if (sharp_count[v] < 255) ++sharp_count[v];
    }
  }
  for (size_t v = 0; v < nv; ++v)
    if (F.fixed[v] && sharp_count[v] < 2) F.fixed[v] = 0;  // a lone sharp edge is noise, not a feature line
  for (size_t v = 0; v < nv; ++v)
    if (F.fixed[v]) {
      const V3 t = tangent(load3(F.c, v), load3(F.n, v), V3{0, 0, 0});
      if (length(t) == 0.f) F.fixed[v] = 0;
      store3(F.c, v, t);
    }
  build_csr(nv, pairs, F);
  // Hierarchy: voxel cells doubling per level, until it stops shrinking or is small.
  float cell = 2.f * static_cast<float>(edge_length_sum / static_cast<double>(std::max<size_t>(edge_count, 1)));
  while (levels.size() < 16 && levels.back().size() > 64) {
    Level coarse = coarsen(levels.back(), cell);
    if (coarse.size() > levels.back().size() * 7 / 8) {
      levels.back().parent.clear();
      break;
    }
    levels.push_back(std::move(coarse));
    cell *= 2.f;
  }
  const size_t top = levels.size() - 1;
  // Orientation, coarse to fine.
  for (size_t l = top + 1; l-- > 0;) {
    Level& L = levels[l];
    if (l < top) {
      const Level& P = levels[l + 1];
      for (size_t v = 0; v < L.size(); ++v) {
        const V3 nn = load3(L.n, v);
        store3(L.q, v, tangent(load3(P.q, L.parent[v]), nn, load3(L.q, v)));
      }
    }
    const uint32_t iterations =
        std::min(options.orientation_iterations, options.fine_orientation_iterations << std::min<size_t>(l, 8));
    smooth_orientation(L, l == top ? 4 * options.orientation_iterations : iterations,
                       parallel_threads(L.size(), options.threads, kVerticesPerThread));
  }
  // Positions, coarse to fine.
  for (size_t l = top + 1; l-- > 0;) {
    Level& L = levels[l];
    if (l == top) {
      integrate_position(L, options.scale, options.period);
    } else {
      const Level& P = levels[l + 1];
      for (size_t v = 0; v < L.size(); ++v) {
        float pr[2];
        predict(L, v, P, L.parent[v], options.scale, pr);
        L.u[2 * v] = wrap(pr[0], options.period);
        L.u[2 * v + 1] = wrap(pr[1], options.period);
      }
    }
    // The coarse levels settle the positions at the scale of the lattice (with the tile repeating
    // 1.5 times across a mesh, the coarsest levels hold it): Gauss-Seidel, many steps, cheap there.
    const uint32_t steps = l == 0 ? options.position_iterations : options.coarse_position_iterations;
    smooth_position(L, l == top ? 4 * steps : steps, options.scale, options.period, options.robust,
                    parallel_threads(L.size(), options.threads, kVerticesPerThread),
                    l == 0 ? 1.f : options.coarse_over_relaxation);
  }
  field.position = std::move(F.p);
  field.normal = std::move(F.n);
  field.q = std::move(F.q);
  field.uv = std::move(F.u);
  field.sharp = std::move(F.fixed);
  field.scale = options.scale;
  field.period = options.period;
  field.levels = static_cast<uint32_t>(levels.size());
}

}  // namespace tailor::internal
