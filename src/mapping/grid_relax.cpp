// Relaxation of the lattice coordinates of an integer-grid map (grid_relax.h).
//
// Unknowns: per vertex its coordinate U_v in its own chart. A flat face sees its corners through
// the lattice maps into its first corner's chart, P_k = M_k(U_k), and has the energy
// A |J - R|^2, J = sum_k P_k g_k^T its Jacobian (g_k the gradient of corner k's barycentric
// coordinate in the face's frame, pixels), R the rotation nearest to J (local step). The global
// step puts each vertex where its faces' energies are least with the other corners held (the
// exact Gauss-Seidel update: P_k |g_k|^2 = R g_k - sum_{j != k} P_j (g_j . g_k), weighted by
// A |g_k|^2), each face's answer taken back into the vertex's chart through the inverse map.
// Faces weigh robustly (kRobustScale below), so a mismatch the maps force stays in a few faces.
// The vertices move in blocks of consecutive vertices (in the order the faces name them), one
// after the other within a block; the blocks are coloured so that no two of a colour share a face,
// so a colour's blocks move independently, on any number of threads with the same result.
//
// This work is based on:
//   L. Liu, L. Zhang, Y. Xu, C. Gotsman, S. J. Gortler, "A local/global approach to mesh
//   parameterization", SGP 2008.
#include "mapping/grid_relax.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "util/block_sweep.h"
#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

// Successive over-relaxation of the global step (an exact block Gauss-Seidel step of a positive
// semi-definite quadratic for the rotations and weights of the sweep: it converges below 2). The
// figures follow how far the relaxation gets in its sweeps; medians over the 16 shared meshes,
// visible seams at scale 800 / 8000: 1.6: 3.27 / 1.80 %, 1.8: 3.09 / 1.68 %, 1.85: 2.98 / 1.63 %,
// 1.9: 2.88 / 1.60 %, 1.95: 2.75 / 1.61 % (Sander L2 up to 1.026 without grid_map's L2 budget),
// the horse in 1.1x / 1.5x the time of 1.6. 1.9 keeps a margin from 2 for the changing rotations.
constexpr float kLatticeOverRelaxation = 1.9f;
// Robust weights: a face's energy counts 1 / (1 + |J - R|^2 / kRobustScale^2). Where the lattice
// maps cannot be met isometrically (a strip where the position field's whole-repeat jumps disagree
// with the surface by a fraction of a repeat), least squares would spread the mismatch over every
// face around and flip many; the robust weights leave it in the few faces of the strip, which are
// cut afterwards. Measured over the 16 shared meshes (median visible seam length at scale 800 /
// 8000, before the seam shortening): 0.2: 6.9 / 4.9 %, 0.3: 6.3 / 3.7 %, 0.5: 5.9 / 2.7 %,
// 1.0: 5.7 / 2.2 % but Sander L2 up to 1.05 (the bound is 1.02); plain least squares
// flipped a third of the bunny's faces.
constexpr float kRobustScale = 0.5f;

// A vertex that moved less than this share of its faces' mean side (|du| + |dv|) in a sweep has
// settled: it and its neighbours are left alone until one of them moves again. Relative to the
// faces, so the work and the strain left do not depend on the scale: a fixed 0.05 px alone left
// every vertex of the horse active at scale 8000 (faces ten times wider in pixels than at 800).
// Measured against 0.05 px alone (medians over the 16 shared meshes, visible seams at 800 / 8000):
// 3.22 / 1.77 -> 3.27 / 1.80 % of edge length, the horse in 0.98x / 0.59x the time. Looser settles
// are faster and worse (1.5 %: 3.32 / 1.82 %, 2 %: 3.36 / 1.90 %), tighter ones with more sweeps
// better and slower (0.2 % and 60 sweeps a round: 2.89 / 1.62 % for 2.6x the time): the figures
// follow the relaxation's convergence (docs/mapping.md section 7).
constexpr float kSettledShare = 0.01f;
// ... or less than this many pixels (a twentieth of a texel), whichever is larger: finer moves do
// not show in the texture, and on meshes whose faces are a pixel or less wide (horse_x16 at scale
// 800: 0.65 px) the share alone took 1.4x the time for 0.885 -> 0.822 % visible seams.
constexpr float kLatticeSettledPx = 0.05f;

//! apply(m, period, in, out) of rosy_field.h, the turn as a product (kQuarterTurn).
inline void map_point(const LatticeMap& m, float period, const float* in, float* out) {
  const float* t = kQuarterTurn[m.r & 3];
  out[0] = t[0] * in[0] + t[1] * in[1] + period * static_cast<float>(m.tx);
  out[1] = t[2] * in[0] + t[3] * in[1] + period * static_cast<float>(m.ty);
}

//! The inverse map: the turn transposed after the shift taken off.
inline void unmap_point(const LatticeMap& m, float period, const float* in, float* out) {
  const float* t = kQuarterTurn[m.r & 3];
  const float x = in[0] - period * static_cast<float>(m.tx), y = in[1] - period * static_cast<float>(m.ty);
  out[0] = t[0] * x + t[2] * y;
  out[1] = t[1] * x + t[3] * y;
}

}  // namespace

LatticeRelaxation::LatticeRelaxation(const Mesh& mesh, const FaceFrames& frames, float scale, float period,
                                     size_t threads)
    : idx_(mesh.indices.data()),
      face_count_(mesh.face_count()),
      vertex_count_(mesh.vertex_count()),
      period_(period),
      threads_(threads) {
  const size_t nf = face_count_, nv = vertex_count_;
  const uint32_t* idx = idx_;
  // Per face: the barycentric gradients (pixels^-1) and the area (pixels^2); 0 = degenerate.
  std::vector<float>& grad = grad_;
  std::vector<float>& area = area_;
  area.assign(nf, 0.f);
  grad.assign(6 * nf, 0.f);
  for_each_chunk(nf, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      const float* l = &frames.local[6 * f];
      float x[6];
      for (int i = 0; i < 6; ++i) x[i] = scale * l[i];
      const float twice = (x[2] - x[0]) * (x[5] - x[1]) - (x[3] - x[1]) * (x[4] - x[0]);
      if (!(twice > 1e-12f)) continue;
      for (int k = 0; k < 3; ++k) {
        const int a = (k + 1) % 3, b = (k + 2) % 3;  // g_k = perp(x_b - x_a) / 2A, perp(x, y) = (-y, x)
        grad[6 * f + 2 * k] = -(x[2 * b + 1] - x[2 * a + 1]) / twice;
        grad[6 * f + 2 * k + 1] = (x[2 * b] - x[2 * a]) / twice;
      }
      area[f] = 0.5f * twice;
    }
  });

  // The sweep's order of the vertices: as the faces first name them, so that consecutive vertices
  // in it have their faces near each other in the face arrays (the vertex indices of a file need
  // not follow its faces: on the horse, the sweep in index order waited on memory for its faces'
  // maps). Vertices no face names come last. Below, per-vertex arrays but uv and `moving` are in
  // this order.
  std::vector<uint32_t>& sweep = sweep_order_;
  std::vector<uint32_t> rank(nv, kInvalid);
  sweep.reserve(nv);
  for (size_t c = 0; c < 3 * nf; ++c)
    if (rank[idx[c]] == kInvalid) {
      rank[idx[c]] = static_cast<uint32_t>(sweep.size());
      sweep.push_back(idx[c]);
    }
  for (size_t v = 0; v < nv; ++v)
    if (rank[v] == kInvalid) {
      rank[v] = static_cast<uint32_t>(sweep.size());
      sweep.push_back(static_cast<uint32_t>(v));
    }

  // Vertex (in sweep order) -> corners of its non-degenerate faces (CSR).
  std::vector<uint32_t>&start = start_, &corners = corners_;
  start.assign(nv + 1, 0);
  for (size_t f = 0; f < nf; ++f)
    if (area[f] > 0.f)
      for (int k = 0; k < 3; ++k) ++start[rank[idx[3 * f + k]] + 1];
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  corners.resize(start[nv]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t f = 0; f < nf; ++f)
      if (area[f] > 0.f)
        for (uint32_t k = 0; k < 3; ++k) corners[fill[rank[idx[3 * f + k]]]++] = static_cast<uint32_t>(3 * f + k);
  }

  // Per vertex (in sweep order) the move below which it has settled (pixels).
  std::vector<float>& settled = settled_;
  settled.assign(nv, 0.f);
  for_each_chunk(nv, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t p = begin; p < end; ++p) {
      float side = 0.f;
      for (uint32_t c = start[p]; c < start[p + 1]; ++c) side += std::sqrt(area[corners[c] / 3]);
      const uint32_t n = start[p + 1] - start[p];
      settled[p] = std::max(kLatticeSettledPx, n > 0 ? kSettledShare * side / static_cast<float>(n) : 0.f);
    }
  });

  // The Gauss-Seidel sweep by coloured blocks of vertices in sweep order (util/block_sweep.h).
  std::vector<uint64_t> touching;
  for (size_t f = 0; f < nf; ++f) {
    if (!(area[f] > 0.f)) continue;
    for (int k = 0; k < 3; ++k) BlockSweep::couple(rank[idx[3 * f + k]], rank[idx[3 * f + (k + 1) % 3]], touching);
  }
  blocks_ = BlockSweep(nv, std::move(touching));
}

void LatticeRelaxation::run(const std::vector<LatticeMap>& corner_map, const std::vector<uint8_t>& flat,
                            uint32_t iterations, std::vector<uint8_t>* moving, std::vector<float>& uv) const {
  const size_t nf = face_count_, nv = vertex_count_;
  if (iterations == 0 || nf == 0) return;
  const uint32_t* idx = idx_;
  const float period = period_;
  const std::vector<float>&grad = grad_, &area = area_, &settled = settled_;
  const std::vector<uint32_t>&start = start_, &corners = corners_, &sweep = sweep_order_;
  std::vector<float> rotation(2 * nf, 0.f);  // per face (cos, sin) of R
  std::vector<float> robust(nf, 0.f);        // per face: the robust weight of its energy; 0 = not relaxed
  const auto corner_pos = [&](size_t f, int k, float* out) {
    map_point(corner_map[3 * f + k], period, &uv[2 * idx[3 * f + k]], out);
  };
  // Activity: a vertex is moved again only while a vertex of one of its faces moved by more than
  // its settled share in the last sweep (at first every vertex, or those input.moving names); a
  // face is fitted again only then too (at first every face: the rotations start from nothing).
  const bool warm = moving && moving->size() == nv;
  std::vector<uint8_t> own_moved;
  if (!warm) own_moved.assign(nv, 1);
  std::vector<uint8_t>& moved = warm ? *moving : own_moved;
  std::vector<uint8_t> face_active(nf, 1), vertex_active(nv, 1);
  // The vertex's exact Gauss-Seidel update, over-relaxed.
  const auto move = [&](size_t p) {
    const uint32_t v = sweep[p];
    moved[v] = 0;
    if (!vertex_active[p]) return;
    double sx = 0.0, sy = 0.0, sw = 0.0;
    for (uint32_t c = start[p]; c < start[p + 1]; ++c) {
      const uint32_t f = corners[c] / 3, k = corners[c] % 3;
      const float* g = &grad[6 * f];
      const float gx = g[2 * k], gy = g[2 * k + 1], inv_gg = 1.f / (gx * gx + gy * gy);
      const uint32_t j1 = (k + 1) % 3, j2 = (k + 2) % 3;
      // g_k / |g_k|^2, (g_j . g_k) / |g_k|^2 for the next and previous corner j, the weight A |g_k|^2
      // (kept per corner they cost 60 bytes a face, 15 % of horse_x16's peak, for no time measured).
      const float t[5] = {gx * inv_gg, gy * inv_gg, (g[2 * j1] * gx + g[2 * j1 + 1] * gy) * inv_gg,
                          (g[2 * j2] * gx + g[2 * j2 + 1] * gy) * inv_gg, area[f] / inv_gg};
      const float rc = rotation[2 * f], rs = rotation[2 * f + 1];
      float p1[2], p2[2];
      corner_pos(f, static_cast<int>((k + 1) % 3), p1);
      corner_pos(f, static_cast<int>((k + 2) % 3), p2);
      // P_k = R g_k / |g_k|^2 - sum_{j != k} P_j (g_j . g_k) / |g_k|^2
      float target[2] = {rc * t[0] - rs * t[1] - t[2] * p1[0] - t[3] * p2[0],
                         rs * t[0] + rc * t[1] - t[2] * p1[1] - t[3] * p2[1]};
      float back[2];
      unmap_point(corner_map[corners[c]], period, target, back);
      const double w = static_cast<double>(t[4] * robust[f]);
      sx += w * back[0];
      sy += w * back[1];
      sw += w;
    }
    if (!(sw > 0.0)) return;
    const float mx = static_cast<float>(sx / sw), my = static_cast<float>(sy / sw);
    const float dx = kLatticeOverRelaxation * (mx - uv[2 * v]), dy = kLatticeOverRelaxation * (my - uv[2 * v + 1]);
    uv[2 * v] += dx;
    uv[2 * v + 1] += dy;
    moved[v] = std::abs(dx) + std::abs(dy) > settled[p];
  };
  for (uint32_t it = 0; it < iterations; ++it) {
    if (it > 0 || warm) {
      for_each_chunk(nf, threads_, [&](size_t begin, size_t end, size_t) {
        for (size_t f = begin; f < end; ++f)
          face_active[f] = it == 0 || (moved[idx[3 * f]] | moved[idx[3 * f + 1]] | moved[idx[3 * f + 2]]);
      });
      for_each_chunk(nv, threads_, [&](size_t begin, size_t end, size_t) {
        for (size_t p = begin; p < end; ++p) {
          uint8_t active = 0;
          for (uint32_t c = start[p]; c < start[p + 1] && !active; ++c) {
            const uint32_t* t = &idx[corners[c] - corners[c] % 3];
            active = moved[t[0]] | moved[t[1]] | moved[t[2]];
          }
          vertex_active[p] = active;
        }
      });
    }
    // Local step: the rotation nearest to each face's Jacobian.
    for_each_chunk(nf, threads_, [&](size_t begin, size_t end, size_t) {
      for (size_t f = begin; f < end; ++f) {
        if (!face_active[f]) continue;
        if (!flat[f]) {  // no chart to relax (a singularity): its corners take no part
          robust[f] = 0.f;
          continue;
        }
        float j00 = 0.f, j01 = 0.f, j10 = 0.f, j11 = 0.f;
        for (int k = 0; k < 3; ++k) {
          float p[2];
          corner_pos(f, k, p);
          const float gx = grad[6 * f + 2 * k], gy = grad[6 * f + 2 * k + 1];
          j00 += p[0] * gx;
          j01 += p[0] * gy;
          j10 += p[1] * gx;
          j11 += p[1] * gy;
        }
        const float c = j00 + j11, s = j10 - j01, n = std::sqrt(c * c + s * s);
        const float inv_n = n > 0.f ? 1.f / n : 0.f;
        const float rc = n > 0.f ? c * inv_n : 1.f, rs = s * inv_n;
        rotation[2 * f] = rc;
        rotation[2 * f + 1] = rs;
        const float e =
            (j00 - rc) * (j00 - rc) + (j01 + rs) * (j01 + rs) + (j10 - rs) * (j10 - rs) + (j11 - rc) * (j11 - rc);
        constexpr float kRobust2 = kRobustScale * kRobustScale;
        robust[f] = kRobust2 / (kRobust2 + e);  // 1 / (1 + e / scale^2) in one division
      }
    });
    // Global step, block by block.
    blocks_.sweep(threads_, move);
  }
  if (moving && !warm) *moving = std::move(own_moved);
}

}  // namespace tailor::internal
