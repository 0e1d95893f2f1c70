// Per-face directions from a curve skeleton: the nearest skeleton edge's direction (skeleton.h).
//
// Skeleton edges are directed away from a root per skeleton tree, so that the direction does not
// flip sign from one edge to the next along a limb (a flip would turn the texture by 180 degrees
// there and cut a seam). The root is the leaf lowest along the PCA axis: one end of the body, so
// the trunk runs one way from end to end and every limb points away from the trunk.
//
// The nearest edge of a face's centroid is found in a uniform grid of edge bounding boxes,
// searched ring by ring outwards until no closer edge can remain: O(1) cells per face for the
// skeleton's few hundred edges, instead of all edges per face.
#include <algorithm>
#include <cmath>
#include <queue>

#include "surface/skeleton.h"
#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

struct P3 {
  double x = 0, y = 0, z = 0;
};
inline P3 sub(P3 a, P3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline double dot(P3 a, P3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Squared distance from q to the segment [a, b].
double segment_distance2(P3 q, P3 a, P3 b) {
  const P3 ab = sub(b, a), aq = sub(q, a);
  const double len2 = dot(ab, ab);
  double t = len2 > 0 ? dot(aq, ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const P3 d = {aq.x - t * ab.x, aq.y - t * ab.y, aq.z - t * ab.z};
  return dot(d, d);
}

// Unit direction of every edge, directed away from the root of its skeleton tree; (0,0,0) for an
// edge of zero length.
std::vector<P3> directed_edges(const CurveSkeleton& s, const std::array<double, 3>& axis) {
  const size_t n = s.points.size() / 3, m = s.edge_count();
  auto point = [&](size_t v) { return P3{s.points[3 * v], s.points[3 * v + 1], s.points[3 * v + 2]}; };
  // Adjacency (CSR, edge order): neighbour vertex and edge id.
  std::vector<uint32_t> start(n + 1, 0), next_vertex(2 * m), next_edge(2 * m);
  for (size_t e = 0; e < m; ++e) ++start[s.edges[2 * e] + 1], ++start[s.edges[2 * e + 1] + 1];
  for (size_t v = 0; v < n; ++v) start[v + 1] += start[v];
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t e = 0; e < m; ++e) {
      const uint32_t a = s.edges[2 * e], b = s.edges[2 * e + 1];
      next_vertex[fill[a]] = b, next_edge[fill[a]++] = e;
      next_vertex[fill[b]] = a, next_edge[fill[b]++] = e;
    }
  }
  const P3 along{axis[0], axis[1], axis[2]};
  // Breadth-first from each tree's root; `rank` is the order of discovery.
  std::vector<uint32_t> rank(n, kInvalid), queue;
  queue.reserve(n);
  std::vector<uint8_t> in_tree(n, 0);
  uint32_t discovered = 0;
  for (size_t seed = 0; seed < n; ++seed) {
    if (rank[seed] != kInvalid) continue;
    // The vertices of seed's tree, to choose the root among them.
    std::vector<uint32_t> tree{static_cast<uint32_t>(seed)};
    in_tree[seed] = 1;
    for (size_t i = 0; i < tree.size(); ++i)
      for (uint32_t j = start[tree[i]]; j < start[tree[i] + 1]; ++j)
        if (!in_tree[next_vertex[j]]) in_tree[next_vertex[j]] = 1, tree.push_back(next_vertex[j]);
    uint32_t root = kInvalid;
    bool root_is_leaf = false;
    for (uint32_t v : tree) {
      const bool leaf = start[v + 1] - start[v] == 1;
      const double key = dot(point(v), along);
      if (root == kInvalid || (leaf && !root_is_leaf) ||
          (leaf == root_is_leaf && (key < dot(point(root), along) || (key == dot(point(root), along) && v < root)))) {
        root = v;
        root_is_leaf = leaf;
      }
    }
    queue.clear();
    queue.push_back(root);
    rank[root] = discovered++;
    for (size_t i = 0; i < queue.size(); ++i)
      for (uint32_t j = start[queue[i]]; j < start[queue[i] + 1]; ++j)
        if (rank[next_vertex[j]] == kInvalid) rank[next_vertex[j]] = discovered++, queue.push_back(next_vertex[j]);
  }
  std::vector<P3> direction(m);
  for (size_t e = 0; e < m; ++e) {
    uint32_t a = s.edges[2 * e], b = s.edges[2 * e + 1];
    if (rank[b] < rank[a]) std::swap(a, b);
    const P3 d = sub(point(b), point(a));
    const double len = std::sqrt(dot(d, d));
    if (len > 0 && std::isfinite(len)) direction[e] = {d.x / len, d.y / len, d.z / len};
  }
  return direction;
}

// Uniform grid over the skeleton edges' bounding boxes (CSR of edge ids per cell).
struct EdgeGrid {
  P3 origin;
  double cell = 1;
  int dims[3] = {1, 1, 1};
  std::vector<uint32_t> start, items;

  size_t index(int x, int y, int z) const { return (size_t(z) * dims[1] + y) * dims[0] + x; }
  int coordinate(double v, double o, int d) const {
    return std::clamp(static_cast<int>(std::floor((v - o) / cell)), 0, d - 1);
  }
};

EdgeGrid build_grid(const CurveSkeleton& s, const std::vector<P3>& direction) {
  EdgeGrid g;
  const size_t m = s.edge_count();
  P3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < s.points.size() / 3; ++v) {
    lo = {std::min(lo.x, s.points[3 * v]), std::min(lo.y, s.points[3 * v + 1]), std::min(lo.z, s.points[3 * v + 2])};
    hi = {std::max(hi.x, s.points[3 * v]), std::max(hi.y, s.points[3 * v + 1]), std::max(hi.z, s.points[3 * v + 2])};
  }
  const double extent[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
  const double longest = std::max({extent[0], extent[1], extent[2], 1e-30});
  // About 4 cells per edge along the skeleton's longest side, at most 64^3 cells in all.
  const double per_side = std::clamp(4.0 * std::cbrt(static_cast<double>(m)), 1.0, 64.0);
  g.origin = lo;
  g.cell = longest / per_side;
  for (int k = 0; k < 3; ++k) g.dims[k] = std::clamp(static_cast<int>(std::ceil(extent[k] / g.cell)), 1, 64);
  const size_t cells = size_t(g.dims[0]) * g.dims[1] * g.dims[2];
  g.start.assign(cells + 1, 0);
  auto for_cells = [&](size_t e, auto&& visit) {
    const double* a = &s.points[3 * size_t{s.edges[2 * e]}];
    const double* b = &s.points[3 * size_t{s.edges[2 * e + 1]}];
    int from[3], to[3];
    const double o[3] = {g.origin.x, g.origin.y, g.origin.z};
    for (int k = 0; k < 3; ++k) {
      from[k] = g.coordinate(std::min(a[k], b[k]), o[k], g.dims[k]);
      to[k] = g.coordinate(std::max(a[k], b[k]), o[k], g.dims[k]);
    }
    for (int z = from[2]; z <= to[2]; ++z)
      for (int y = from[1]; y <= to[1]; ++y)
        for (int x = from[0]; x <= to[0]; ++x) visit(g.index(x, y, z));
  };
  for (size_t e = 0; e < m; ++e)
    if (direction[e].x != 0 || direction[e].y != 0 || direction[e].z != 0)
      for_cells(e, [&](size_t c) { ++g.start[c + 1]; });
  for (size_t c = 0; c < cells; ++c) g.start[c + 1] += g.start[c];
  g.items.resize(g.start[cells]);
  std::vector<uint32_t> fill(g.start.begin(), g.start.end() - 1);
  for (size_t e = 0; e < m; ++e)
    if (direction[e].x != 0 || direction[e].y != 0 || direction[e].z != 0)
      for_cells(e, [&](size_t c) { g.items[fill[c]++] = static_cast<uint32_t>(e); });
  return g;
}

// The nearest edge of component `component` to q (ties: lower id), or kInvalid.
uint32_t nearest_edge(const EdgeGrid& g, const CurveSkeleton& s, uint32_t component, P3 q) {
  const int c[3] = {g.coordinate(q.x, g.origin.x, g.dims[0]), g.coordinate(q.y, g.origin.y, g.dims[1]),
                    g.coordinate(q.z, g.origin.z, g.dims[2])};
  const int max_ring = std::max({g.dims[0], g.dims[1], g.dims[2]});
  uint32_t best = kInvalid;
  double best_d2 = INFINITY;
  auto point = [&](uint32_t v) { return P3{s.points[3 * v], s.points[3 * v + 1], s.points[3 * v + 2]}; };
  for (int r = 0; r <= max_ring; ++r) {
    // Every cell at Chebyshev distance exactly r from c.
    for (int z = c[2] - r; z <= c[2] + r; ++z) {
      if (z < 0 || z >= g.dims[2]) continue;
      for (int y = c[1] - r; y <= c[1] + r; ++y) {
        if (y < 0 || y >= g.dims[1]) continue;
        const bool face_zy = std::abs(z - c[2]) == r || std::abs(y - c[1]) == r;
        for (int x = c[0] - r; x <= c[0] + r; x += (face_zy || r == 0) ? 1 : 2 * r) {
          if (x < 0 || x >= g.dims[0]) continue;
          const size_t cell = g.index(x, y, z);
          for (uint32_t i = g.start[cell]; i < g.start[cell + 1]; ++i) {
            const uint32_t e = g.items[i];
            if (s.edge_component[e] != component) continue;
            const double d2 = segment_distance2(q, point(s.edges[2 * e]), point(s.edges[2 * e + 1]));
            if (d2 < best_d2 || (d2 == best_d2 && e < best)) best_d2 = d2, best = e;
          }
        }
      }
    }
    // Cells beyond ring r are at least r cells away from q (also when q lies outside the grid).
    const double reach = r * g.cell;
    if (best != kInvalid && best_d2 < reach * reach) break;
  }
  return best;
}

}  // namespace

void skeleton_face_directions(const Mesh& mesh, const Topology& topology, const CurveSkeleton& skeleton,
                              const std::array<double, 3>& axis, size_t threads, std::vector<float>& directions) {
  const size_t face_count = mesh.face_count();
  directions.assign(3 * face_count, 0.f);
  if (skeleton.edge_count() == 0) return;
  const std::vector<P3> direction = directed_edges(skeleton, axis);
  const EdgeGrid grid = build_grid(skeleton, direction);
  for_each_chunk(face_count, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      const uint32_t component = topology.face_component[f];
      if (component >= skeleton.component_done.size() || !skeleton.component_done[component]) continue;
      P3 q;
      for (int k = 0; k < 3; ++k) {
        const float* p = &mesh.positions[3 * size_t{mesh.indices[3 * f + k]}];
        q = {q.x + p[0], q.y + p[1], q.z + p[2]};
      }
      q = {q.x / 3, q.y / 3, q.z / 3};
      const uint32_t e = nearest_edge(grid, skeleton, component, q);
      if (e == kInvalid) continue;
      directions[3 * f] = static_cast<float>(direction[e].x);
      directions[3 * f + 1] = static_cast<float>(direction[e].y);
      directions[3 * f + 2] = static_cast<float>(direction[e].z);
    }
  });
}

}  // namespace tailor::internal
