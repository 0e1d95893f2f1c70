// Cone placement of an integer-grid map (grid_cones.h).
#include "mapping/grid_cones.h"

#include <algorithm>
#include <cmath>

#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

// Faces a cone may walk. Measured at ten times the default scale, before any move, the fixed point
// lay a median 0.7 edge lengths from the cone face's centre (90th percentile 1.4-2.8).
constexpr uint32_t kMaxSteps = 4;
// How far a dislocation looks for a cone or another dislocation to merge with, in faces.
constexpr uint32_t kMaxDislocationHops = 12;
// How far a cone looks for a cone of the opposite turn to cancel with, in faces. Median visible
// seams over the shared meshes at scale 800 / 8000: none 3.19 / 1.85 %, 3: 3.17 / 1.76 %, 6: 3.16 /
// 1.73 %, 12: 3.18 / 1.74 % with Sander L2 up to 1.025 (cancelling far pairs strains the faces
// between them), 24: 3.44 / 2.00 %.
constexpr uint32_t kMaxConePairHops = 6;

//! The map around face f from corner k's chart back to it.
LatticeMap holonomy(const std::vector<LatticeMap>& edge_map, size_t f, uint32_t k) {
  return compose(edge_map[3 * f + k], compose(edge_map[3 * f + (k + 1) % 3], edge_map[3 * f + (k + 2) % 3]));
}

//! The fixed point p of x -> rot_r(x) + period t (r != 0): (I - rot_r) p = period t.
void fixed_point(const LatticeMap& m, float period, float p[2]) {
  float c0[2], c1[2];  // columns of rot_r
  rotate_quarter(m.r, 1.f, 0.f, c0[0], c0[1]);
  rotate_quarter(m.r, 0.f, 1.f, c1[0], c1[1]);
  const float a = 1.f - c0[0], b = -c1[0], c = -c0[1], d = 1.f - c1[1];
  const float det = a * d - b * c;  // 2 for a quarter turn, 4 for a half turn
  const float tx = period * static_cast<float>(m.tx), ty = period * static_cast<float>(m.ty);
  p[0] = (d * tx - b * ty) / det;
  p[1] = (a * ty - c * tx) / det;
}

// Breadth-first search state, reused from one start face to the next.
struct Search {
  std::vector<uint32_t> stamp, from, queue;  // per face: last search that reached it, the half-edge it came by
  uint32_t count = 0;
  explicit Search(size_t faces) : stamp(faces, 0), from(faces, kInvalid) {}
};

//! Hands face start's holonomy along the shortest path of flat faces to the nearest face within
//! max_hops for which accepts(face, its holonomy) holds (singular faces that do not accept block
//! the way): across each edge of the path the map is composed with the holonomy, so the face
//! behind closes and the next takes it. Returns whether a face was found.
template <class Accept>
bool hand_over(const Topology& topology, size_t start, uint32_t max_hops, Accept accepts, Search& s,
               std::vector<LatticeMap>& edge_map) {
  ++s.count;
  s.stamp[start] = s.count;
  s.queue.assign(1, static_cast<uint32_t>(start));
  size_t head = 0, ring_end = 1;
  uint32_t target = kInvalid, hops = 0;
  while (head < s.queue.size() && target == kInvalid) {
    const uint32_t f = s.queue[head++];
    for (uint32_t k = 0; k < 3 && target == kInvalid; ++k) {
      const uint32_t o = topology.opposite[3 * f + k];
      if (o == kInvalid || s.stamp[o / 3] == s.count) continue;
      s.stamp[o / 3] = s.count;
      s.from[o / 3] = 3 * f + k;
      const LatticeMap h = holonomy(edge_map, o / 3, 0);
      if (accepts(o / 3, h))
        target = o / 3;
      else if (h == LatticeMap{})
        s.queue.push_back(o / 3);
    }
    if (head == ring_end) {
      ring_end = s.queue.size();
      if (++hops >= max_hops) break;
    }
  }
  if (target == kInvalid) return false;
  // The path back from the target, then the holonomy handed face to face along it.
  const size_t path_start = s.queue.size();
  for (uint32_t f = target; f != start; f = s.from[f] / 3) s.queue.push_back(s.from[f]);
  for (size_t i = s.queue.size(); i-- > path_start;) {
    const uint32_t e = s.queue[i], f = e / 3, k = e % 3, o = topology.opposite[e];
    edge_map[e] = compose(inverse(holonomy(edge_map, f, k)), edge_map[e]);
    edge_map[o] = inverse(edge_map[e]);
  }
  return true;
}

}  // namespace

uint32_t cancel_cone_pairs(const Mesh& mesh, const Topology& topology, std::vector<LatticeMap>& edge_map) {
  const size_t nf = mesh.face_count();
  Search search(nf);
  uint32_t cancelled = 0;
  for (size_t start = 0; start < nf; ++start) {
    const int r = holonomy(edge_map, start, 0).r;
    if (r == 0) continue;
    const auto opposite_turn = [r](uint32_t, const LatticeMap& h) { return h.r != 0 && ((h.r + r) & 3) == 0; };
    if (hand_over(topology, start, kMaxConePairHops, opposite_turn, search, edge_map)) ++cancelled;
  }
  return cancelled;
}

uint32_t merge_dislocations(const Mesh& mesh, const Topology& topology, std::vector<LatticeMap>& edge_map) {
  const size_t nf = mesh.face_count();
  Search search(nf);
  uint32_t merged = 0;
  const auto singular = [](uint32_t, const LatticeMap& h) { return !(h == LatticeMap{}); };
  for (size_t start = 0; start < nf; ++start) {
    const LatticeMap h = holonomy(edge_map, start, 0);
    if (h.r != 0 || h == LatticeMap{}) continue;
    if (hand_over(topology, start, kMaxDislocationHops, singular, search, edge_map)) ++merged;
  }
  return merged;
}

void maps_from_edges(size_t face_count, size_t threads, const std::vector<LatticeMap>& edge_map,
                     std::vector<LatticeMap>& corner_map, std::vector<uint8_t>& flat) {
  for_each_chunk(face_count, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      const LatticeMap to_c = compose(edge_map[3 * f], edge_map[3 * f + 1]);
      corner_map[3 * f] = LatticeMap{};
      corner_map[3 * f + 1] = edge_map[3 * f];
      corner_map[3 * f + 2] = to_c;
      flat[f] = compose(to_c, edge_map[3 * f + 2]) == LatticeMap{};
    }
  });
}

ConeMoves move_cones(const Mesh& mesh, const Topology& topology, const std::vector<float>& uv, float period,
                     std::vector<LatticeMap>& edge_map) {
  const size_t nf = mesh.face_count();
  const uint32_t* idx = mesh.indices.data();
  ConeMoves moves;
  std::vector<uint8_t> arrived(nf, 0);  // a cone moved here (not walked again)
  for (size_t start = 0; start < nf; ++start) {
    if (arrived[start] || holonomy(edge_map, start, 0).r == 0) continue;
    ++moves.cones;
    size_t s = start, previous = nf;
    for (uint32_t step = 0; step < kMaxSteps; ++step) {
      // s's corners in corner 0's chart, along the maps of edges 0 and 1, and the cone's fixed point.
      float p[6], fix[2];
      apply(LatticeMap{}, period, &uv[2 * idx[3 * s]], p);
      apply(edge_map[3 * s], period, &uv[2 * idx[3 * s + 1]], p + 2);
      apply(compose(edge_map[3 * s], edge_map[3 * s + 1]), period, &uv[2 * idx[3 * s + 2]], p + 4);
      fixed_point(holonomy(edge_map, s, 0), period, fix);
      const float area = (p[2] - p[0]) * (p[5] - p[1]) - (p[3] - p[1]) * (p[4] - p[0]);
      if (!(std::abs(area) > 0.f)) break;
      // Barycentric coordinate of corner k + 2, negative where fix lies beyond edge k.
      uint32_t beyond = 3;
      float lowest = 0.f;
      for (uint32_t k = 0; k < 3; ++k) {
        const float* a = p + 2 * k;
        const float* b = p + 2 * ((k + 1) % 3);
        const float lambda = ((b[0] - a[0]) * (fix[1] - a[1]) - (b[1] - a[1]) * (fix[0] - a[0])) / area;
        if (lambda < lowest) {
          lowest = lambda;
          beyond = k;
        }
      }
      if (beyond == 3) break;  // the fixed point is in s
      const uint32_t e = static_cast<uint32_t>(3 * s + beyond), o = topology.opposite[e];
      if (o == kInvalid || o / 3 == previous) break;
      const size_t g = o / 3;
      if (!(holonomy(edge_map, g, 0) == LatticeMap{})) break;
      // Across e, compose the map with s's turn: s closes, g takes the turn.
      edge_map[e] = compose(inverse(holonomy(edge_map, s, beyond)), edge_map[e]);
      edge_map[o] = inverse(edge_map[e]);
      if (step == 0) ++moves.moved;
      ++moves.steps;
      previous = s;
      s = g;
    }
    arrived[s] = 1;
  }
  return moves;
}

}  // namespace tailor::internal
