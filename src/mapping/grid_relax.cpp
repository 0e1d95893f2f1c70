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
// Vertices are coloured so that no two of a colour share a face; a colour's moves are
// independent, so they run on any number of threads with the same result.
//
// This work is based on:
//   L. Liu, L. Zhang, Y. Xu, C. Gotsman, S. J. Gortler, "A local/global approach to mesh
//   parameterization", SGP 2008.
#include "mapping/grid_relax.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

// Successive over-relaxation of the global step (an exact block Gauss-Seidel step of a positive
// semi-definite quadratic for the rotations and weights of the sweep: it converges below 2). The
// figures follow how far the relaxation gets in its sweeps; medians over the 16 shared meshes,
// visible seams at scale 800 / 8000: 1.6: 3.27 / 1.80 %, 1.8: 3.09 / 1.68 %, 1.85: 2.98 / 1.63 %,
// 1.9: 2.88 / 1.60 %, 1.95: 2.75 / 1.61 % (Sander L2 up to 1.026 without grid_map's L2 budget),
// the horse in 1.1x / 1.5x the time of 1.6. 1.9 keeps a margin from 2 for the changing rotations.
constexpr float kOverRelaxation = 1.9f;
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
// follow the relaxation's convergence (docs/mapping.md section 7, tenth session).
constexpr float kSettledShare = 0.01f;
// ... or less than this many pixels (a twentieth of a texel), whichever is larger: finer moves do
// not show in the texture, and on meshes whose faces are a pixel or less wide (horse_x16 at scale
// 800: 0.65 px) the share alone took 1.4x the time for 0.885 -> 0.822 % visible seams.
constexpr float kSettledPx = 0.05f;

// The quarter turns of rosy_field.h's rotate_quarter as matrices (x' = a x + b y, y' = c x + d y):
// the same values without a branch per corner (the turns are as good as random).
struct Turn {
  float a, b, c, d;
};
constexpr Turn kTurn[4] = {{1.f, 0.f, 0.f, 1.f}, {0.f, 1.f, -1.f, 0.f}, {-1.f, 0.f, 0.f, -1.f}, {0.f, -1.f, 1.f, 0.f}};

//! apply(m, period, in, out) of rosy_field.h.
inline void map_point(const LatticeMap& m, float period, const float* in, float* out) {
  const Turn& t = kTurn[m.r & 3];
  out[0] = t.a * in[0] + t.b * in[1] + period * static_cast<float>(m.tx);
  out[1] = t.c * in[0] + t.d * in[1] + period * static_cast<float>(m.ty);
}

//! The inverse map: the turn transposed after the shift taken off.
inline void unmap_point(const LatticeMap& m, float period, const float* in, float* out) {
  const Turn& t = kTurn[m.r & 3];
  const float x = in[0] - period * static_cast<float>(m.tx), y = in[1] - period * static_cast<float>(m.ty);
  out[0] = t.a * x + t.c * y;
  out[1] = t.b * x + t.d * y;
}

}  // namespace

void relax_lattice_coordinates(const GridRelaxInput& in, std::vector<float>& uv) {
  const size_t nf = in.mesh.face_count(), nv = in.mesh.vertex_count();
  const uint32_t* idx = in.mesh.indices.data();
  const float period = in.period;
  if (in.iterations == 0 || nf == 0) return;

  // Per face: the barycentric gradients (pixels^-1) and the area (pixels^2); 0 = not relaxed.
  std::vector<float> grad(6 * nf, 0.f), area(nf, 0.f);
  for_each_chunk(nf, in.threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      if (!in.flat[f]) continue;
      const float* l = &in.frames.local[6 * f];
      float x[6];
      for (int i = 0; i < 6; ++i) x[i] = in.scale * l[i];
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

  // Vertex -> corners of its relaxed faces (CSR).
  std::vector<uint32_t> start(nv + 1, 0), corners;
  for (size_t f = 0; f < nf; ++f)
    if (area[f] > 0.f)
      for (int k = 0; k < 3; ++k) ++start[idx[3 * f + k] + 1];
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  corners.resize(start[nv]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t f = 0; f < nf; ++f)
      if (area[f] > 0.f)
        for (uint32_t k = 0; k < 3; ++k) corners[fill[idx[3 * f + k]]++] = static_cast<uint32_t>(3 * f + k);
  }

  // Per vertex the move below which it has settled (pixels).
  std::vector<float> settled(nv, 0.f);
  for_each_chunk(nv, in.threads, [&](size_t begin, size_t end, size_t) {
    for (size_t v = begin; v < end; ++v) {
      float side = 0.f;
      for (uint32_t c = start[v]; c < start[v + 1]; ++c) side += std::sqrt(area[corners[c] / 3]);
      const uint32_t n = start[v + 1] - start[v];
      settled[v] = std::max(kSettledPx, n > 0 ? kSettledShare * side / static_cast<float>(n) : 0.f);
    }
  });

  // Greedy colouring in vertex order; vertices grouped by colour. used[c] == v + 1 marks colour c
  // as taken by a neighbour of v: the search for a free colour stops within v's corners + 1 steps,
  // so the colouring is O(corners) on any mesh (a colour count of its own per vertex would not be).
  std::vector<uint32_t> colour(nv, 0), used(1, 0);
  uint32_t colours = 1;
  for (size_t v = 0; v < nv; ++v) {
    const uint32_t mark = static_cast<uint32_t>(v + 1);
    for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
      const uint32_t f = corners[i] / 3;
      for (int k = 0; k < 3; ++k) {
        const uint32_t w = idx[3 * f + k];
        if (w < v) used[colour[w]] = mark;
      }
    }
    uint32_t c = 0;
    while (c < colours && used[c] == mark) ++c;
    colour[v] = c;
    if (c == colours) {
      ++colours;
      used.push_back(0);
    }
  }
  std::vector<uint32_t> colour_start(colours + 1, 0), order(nv);
  for (size_t v = 0; v < nv; ++v) ++colour_start[colour[v] + 1];
  for (uint32_t c = 0; c < colours; ++c) colour_start[c + 1] += colour_start[c];
  {
    std::vector<uint32_t> fill(colour_start.begin(), colour_start.end() - 1);
    for (size_t v = 0; v < nv; ++v) order[fill[colour[v]]++] = static_cast<uint32_t>(v);
  }

  std::vector<float> rotation(2 * nf, 0.f);  // per face (cos, sin) of R
  std::vector<float> robust(nf, 1.f);        // per face: the robust weight of its energy
  const auto corner_pos = [&](size_t f, int k, float* out) {
    map_point(in.corner_map[3 * f + k], period, &uv[2 * idx[3 * f + k]], out);
  };
  // Activity: a vertex is moved again only while a vertex of one of its faces moved by more than
  // its settled share in the last sweep (at first every vertex, or those input.moving names); a
  // face is fitted again only then too (at first every face: the rotations start from nothing).
  const bool warm = in.moving && in.moving->size() == nv;
  std::vector<uint8_t> own_moved;
  if (!warm) own_moved.assign(nv, 1);
  std::vector<uint8_t>& moved = warm ? *in.moving : own_moved;
  std::vector<uint8_t> face_active(nf, 1), vertex_active(nv, 1);
  for (uint32_t it = 0; it < in.iterations; ++it) {
    if (it > 0 || warm) {
      for_each_chunk(nf, in.threads, [&](size_t begin, size_t end, size_t) {
        for (size_t f = begin; f < end; ++f)
          face_active[f] = it == 0 || (moved[idx[3 * f]] | moved[idx[3 * f + 1]] | moved[idx[3 * f + 2]]);
      });
      for_each_chunk(nv, in.threads, [&](size_t begin, size_t end, size_t) {
        for (size_t v = begin; v < end; ++v) {
          uint8_t active = 0;
          for (uint32_t c = start[v]; c < start[v + 1] && !active; ++c) {
            const uint32_t* t = &idx[corners[c] - corners[c] % 3];
            active = moved[t[0]] | moved[t[1]] | moved[t[2]];
          }
          vertex_active[v] = active;
        }
      });
    }
    // Local step: the rotation nearest to each face's Jacobian.
    for_each_chunk(nf, in.threads, [&](size_t begin, size_t end, size_t) {
      for (size_t f = begin; f < end; ++f) {
        if (!(area[f] > 0.f) || !face_active[f]) continue;
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
        rotation[2 * f] = n > 0.f ? c / n : 1.f;
        rotation[2 * f + 1] = n > 0.f ? s / n : 0.f;
        const float rc = rotation[2 * f], rs = rotation[2 * f + 1];
        const float e =
            (j00 - rc) * (j00 - rc) + (j01 + rs) * (j01 + rs) + (j10 - rs) * (j10 - rs) + (j11 - rc) * (j11 - rc);
        robust[f] = 1.f / (1.f + e / (kRobustScale * kRobustScale));
      }
    });
    // Global step, colour by colour.
    for (uint32_t col = 0; col < colours; ++col) {
      const size_t first = colour_start[col], count = colour_start[col + 1] - first;
      for_each_chunk(count, in.threads, [&](size_t begin, size_t end, size_t) {
        for (size_t i = first + begin; i < first + end; ++i) {
          const uint32_t v = order[i];
          moved[v] = 0;
          if (!vertex_active[v]) continue;
          double sx = 0.0, sy = 0.0, sw = 0.0;
          for (uint32_t c = start[v]; c < start[v + 1]; ++c) {
            const uint32_t f = corners[c] / 3;
            const int k = static_cast<int>(corners[c] % 3);
            const float* g = &grad[6 * f];
            const float gkx = g[2 * k], gky = g[2 * k + 1];
            const float gg = gkx * gkx + gky * gky;
            if (!(gg > 0.f)) continue;
            const float rc = rotation[2 * f], rs = rotation[2 * f + 1];
            float tx = rc * gkx - rs * gky, ty = rs * gkx + rc * gky;  // R g_k
            for (int j = 0; j < 3; ++j) {
              if (j == k) continue;
              float p[2];
              corner_pos(f, j, p);
              const float d = g[2 * j] * gkx + g[2 * j + 1] * gky;
              tx -= p[0] * d;
              ty -= p[1] * d;
            }
            float target[2] = {tx / gg, ty / gg}, back[2];
            unmap_point(in.corner_map[3 * f + k], period, target, back);
            const double w = static_cast<double>(area[f]) * gg * robust[f];
            sx += w * back[0];
            sy += w * back[1];
            sw += w;
          }
          if (!(sw > 0.0)) continue;
          const float mx = static_cast<float>(sx / sw), my = static_cast<float>(sy / sw);
          const float dx = kOverRelaxation * (mx - uv[2 * v]), dy = kOverRelaxation * (my - uv[2 * v + 1]);
          uv[2 * v] += dx;
          uv[2 * v + 1] += dy;
          moved[v] = std::abs(dx) + std::abs(dy) > settled[v];
        }
      });
    }
  }
  if (in.moving && !warm) *in.moving = std::move(own_moved);
}

}  // namespace tailor::internal
