// Face adjacency through opposite edges, connected components, edge counts.
//
// Edges are grouped by their lower vertex with a counting sort (CSR), then matched within each
// vertex's short list. This is O(F) with sequential passes and no hashing: on scanned meshes,
// whose vertex order is spatially coherent, it stays in cache far better than a hash of 3F keys.
// (Same idea as meshoptimizer's buildTriangleAdjacency.)
#include "tailor/topology.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <utility>
#include <vector>

#include "util/huge_pages.h"

namespace tailor {
namespace {

// A vertex with more edge uses than this is sorted with std::sort instead of insertion sort
// (a fan of a million faces around one vertex must not take 10^12 steps).
constexpr size_t kLinearMatchLimit = 32;

// Decides the fate of one undirected edge, given its uses sorted by (direction, edge id).
void match_group(const uint64_t* uses, size_t count, Topology& t) {
  if (count == 1) {
    ++t.boundary_edges;
  } else if (count == 2) {
    const uint32_t e0 = static_cast<uint32_t>(uses[0]);
    const uint32_t e1 = static_cast<uint32_t>(uses[1]);
    if (((uses[0] ^ uses[1]) >> 32) & 1) {
      t.opposite[e0] = e1;
      t.opposite[e1] = e0;
    } else {
      ++t.inconsistent_edges;  // both faces run the edge the same way: left unpaired
    }
  } else {
    ++t.nonmanifold_edges;  // three or more faces: all uses left unpaired
  }
  ++t.edges;
}

uint32_t find_root(uint32_t* parent, uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];  // path halving
    x = parent[x];
  }
  return x;
}

}  // namespace

Topology build_topology(const Mesh& mesh) { return build_topology(mesh, {}); }

Topology build_topology(const Mesh& mesh, const ProgressCallback& progress) {
  auto reached = [&progress](float done) {
    if (progress) (void)progress(done);
  };
  const auto start = std::chrono::steady_clock::now();
  Topology t;
  const size_t corner_count = mesh.indices.size();
  const size_t vertex_count = mesh.vertex_count();
  const uint32_t* indices = mesh.indices.data();
  // Every array here is fresh and large; faulting it in 4 KiB pages cost ~15 % of this stage on
  // 1.5 M faces, so big ones ask for huge pages, and scratch that is fully written skips zeroing.
  internal::reserve_huge(t.opposite, corner_count);
  t.opposite.assign(corner_count, kInvalid);

  // === Group edge uses by their lower vertex (counting sort) ===
  // Each entry is (higher vertex << 33) | (runs lower -> higher) << 32 | edge id, so grouping and
  // the direction check need no further index lookups (vertex ids < 2^31, see kMaxVertices).
  std::vector<uint32_t> offsets(vertex_count + 1, 0);
  for (size_t f = 0; f < corner_count; f += 3) {
    const uint32_t a = indices[f], b = indices[f + 1], c = indices[f + 2];
    ++offsets[std::min(a, b) + 1];
    ++offsets[std::min(b, c) + 1];
    ++offsets[std::min(c, a) + 1];
  }
  for (size_t v = 0; v < vertex_count; ++v) offsets[v + 1] += offsets[v];
  internal::HugeArray<uint64_t> sorted = internal::huge_uninitialized<uint64_t>(corner_count);
  {
    std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (size_t f = 0; f < corner_count; f += 3) {
      const uint32_t v[3] = {indices[f], indices[f + 1], indices[f + 2]};
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t a = v[k], b = v[k == 2 ? 0 : k + 1];
        sorted[cursor[std::min(a, b)]++] =
            (uint64_t{std::max(a, b)} << 33) | (uint64_t{a < b} << 32) | static_cast<uint32_t>(f + k);
      }
    }
  }

  reached(0.3f);
  // === Match the uses of each undirected edge (same lower and higher vertex) ===
  // Sorting a vertex's entries puts the uses of one edge next to each other, ordered by edge id,
  // so the pairing does not depend on anything but the mesh. Lists are short (~6 on average):
  // insertion sort, with std::sort for the rare high-valence vertex.
  for (size_t v = 0; v < vertex_count; ++v) {
    uint64_t* list = sorted.get() + offsets[v];
    const size_t n = offsets[v + 1] - offsets[v];
    if (n <= kLinearMatchLimit) {
      for (size_t i = 1; i < n; ++i) {
        const uint64_t x = list[i];
        size_t j = i;
        for (; j > 0 && list[j - 1] > x; --j) list[j] = list[j - 1];
        list[j] = x;
      }
    } else {
      std::sort(list, list + n);
    }
    for (size_t i = 0; i < n;) {
      size_t end = i + 1;
      while (end < n && (list[end] >> 33) == (list[i] >> 33)) ++end;
      match_group(list + i, end - i, t);
      i = end;
    }
  }

  reached(0.6f);
  // === Components through paired edges ===
  // Union-find in face order rather than a flood fill: neighbouring faces are mostly near each
  // other in file order, so this pass reads opposite[] sequentially and parent[] with good
  // locality. Roots are always the lowest face of their set, so numbering roots in face order
  // numbers components by their lowest face.
  const size_t face_count = mesh.face_count();
  internal::HugeArray<uint32_t> face_parent = internal::huge_uninitialized<uint32_t>(face_count);
  for (size_t f = 0; f < face_count; ++f) face_parent[f] = static_cast<uint32_t>(f);
  for (size_t f = 0; f < face_count; ++f) {
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t g = neighbour_face(t, static_cast<uint32_t>(3 * f + k));
      if (g == kInvalid || g < f) continue;  // each pair once
      const uint32_t a = find_root(face_parent.get(), static_cast<uint32_t>(f));
      const uint32_t b = find_root(face_parent.get(), g);
      if (a != b) face_parent[std::max(a, b)] = std::min(a, b);
    }
  }
  internal::reserve_huge(t.face_component, face_count);
  t.face_component.resize(face_count);
  for (size_t f = 0; f < face_count; ++f) {
    const uint32_t root = find_root(face_parent.get(), static_cast<uint32_t>(f));
    t.face_component[f] = root == f ? t.edge_components++ : t.face_component[root];
  }

  reached(0.85f);
  // === Components of faces sharing a vertex ===
  // Edge components touching at a vertex (bow-ties, fins) are merged with a union-find over the
  // few edge components, labelling each vertex with the first component seen: one pass over the
  // corners instead of a union-find over all vertices.
  std::vector<uint32_t> parent(t.edge_components);
  for (uint32_t c = 0; c < t.edge_components; ++c) parent[c] = c;
  std::vector<uint32_t> vertex_label(vertex_count, kInvalid);
  uint32_t merges = 0;
  for (size_t c = 0; c < corner_count; ++c) {
    const uint32_t component = t.face_component[c / 3];
    uint32_t& label = vertex_label[indices[c]];
    if (label == kInvalid) {
      label = component;
    } else if (label != component) {
      const uint32_t a = find_root(parent.data(), label);
      const uint32_t b = find_root(parent.data(), component);
      if (a != b) {
        parent[std::max(a, b)] = std::min(a, b);
        ++merges;
      }
    }
  }
  t.vertex_components = t.edge_components - merges;

  t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  reached(1.f);
  return t;
}

size_t count_nonmanifold_vertices(const Mesh& mesh) {
  const size_t nv = mesh.vertex_count();
  const std::vector<uint32_t>& idx = mesh.indices;
  // The corners of each vertex (CSR, by a counting sort).
  std::vector<uint32_t> first(nv + 1, 0);
  for (const uint32_t v : idx) ++first[v + 1];
  for (size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
  std::vector<uint32_t> corners(idx.size());
  {
    std::vector<uint32_t> cursor(first.begin(), first.end() - 1);
    for (uint32_t c = 0; c < idx.size(); ++c) corners[cursor[idx[c]]++] = c;
  }
  size_t count = 0;
  std::vector<std::pair<uint32_t, uint32_t>> around;  // (the other end of an edge at v, the face's slot)
  std::vector<uint32_t> parent;
  for (size_t v = 0; v < nv; ++v) {
    const uint32_t begin = first[v], degree = first[v + 1] - begin;
    if (degree <= 1) continue;
    around.clear();
    for (uint32_t i = 0; i < degree; ++i) {
      const uint32_t c = corners[begin + i], f = c / 3, k = c % 3;
      around.emplace_back(idx[3 * f + (k + 1) % 3], i);
      around.emplace_back(idx[3 * f + (k + 2) % 3], i);
    }
    std::sort(around.begin(), around.end());
    parent.resize(degree);
    std::iota(parent.begin(), parent.end(), 0u);
    uint32_t fans = degree;
    bool fin = false;
    for (size_t g = 0; g < around.size();) {
      size_t end = g + 1;
      while (end < around.size() && around[end].first == around[g].first) ++end;
      if (end - g >= 3) {
        fin = true;  // an edge with three or more faces
        break;
      }
      if (end - g == 2) {
        const uint32_t a = find_root(parent.data(), around[g].second);
        const uint32_t b = find_root(parent.data(), around[g + 1].second);
        if (a != b) {
          parent[a] = b;
          --fans;
        }
      }
      g = end;
    }
    if (fin || fans > 1) ++count;
  }
  return count;
}

}  // namespace tailor
