// Face adjacency through opposite edges, connected components, edge counts.
//
// Edges are grouped by their lower vertex with a counting sort (CSR), then matched within each
// vertex's short list. This is O(F) with sequential passes and no hashing: on scanned meshes,
// whose vertex order is spatially coherent, it stays in cache far better than a hash of 3F keys.
// (Same idea as meshoptimizer's buildTriangleAdjacency.)
#include "tailor/topology.h"

#include <algorithm>
#include <chrono>

namespace tailor {
namespace {

// A vertex with more edge uses than this is matched by sorting its list instead of the quadratic
// scan (a fan of a million faces around one vertex must not take 10^12 steps).
constexpr size_t kLinearMatchLimit = 32;

inline uint32_t edge_from(const uint32_t* indices, uint32_t e) { return indices[e]; }
inline uint32_t edge_to(const uint32_t* indices, uint32_t e) { return indices[e - e % 3 + (e % 3 + 1) % 3]; }

// Decides the fate of one undirected edge, given all edge ids that use it (2 to many).
void match_group(const uint32_t* indices, const uint32_t* group, size_t count, Topology& t) {
  if (count == 1) {
    ++t.boundary_edges;
  } else if (count == 2) {
    const uint32_t e0 = group[0];
    const uint32_t e1 = group[1];
    if (edge_from(indices, e0) == edge_to(indices, e1)) {
      t.opposite[e0] = e1;
      t.opposite[e1] = e0;
    } else {
      ++t.inconsistent_edges;  // both faces run a -> b: left unpaired
    }
  } else {
    ++t.nonmanifold_edges;  // three or more faces: all uses left unpaired
  }
  ++t.edges;
}

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];  // path halving
    x = parent[x];
  }
  return x;
}

}  // namespace

Topology build_topology(const Mesh& mesh) {
  const auto start = std::chrono::steady_clock::now();
  Topology t;
  const size_t corner_count = mesh.indices.size();
  const size_t vertex_count = mesh.vertex_count();
  const uint32_t* indices = mesh.indices.data();
  t.opposite.assign(corner_count, kInvalid);

  // === Group edge ids by their lower vertex (counting sort) ===
  std::vector<uint32_t> offsets(vertex_count + 1, 0);
  for (size_t e = 0; e < corner_count; ++e) {
    const uint32_t e32 = static_cast<uint32_t>(e);
    ++offsets[std::min(edge_from(indices, e32), edge_to(indices, e32)) + 1];
  }
  for (size_t v = 0; v < vertex_count; ++v) offsets[v + 1] += offsets[v];
  std::vector<uint32_t> sorted(corner_count);
  {
    std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (size_t e = 0; e < corner_count; ++e) {
      const uint32_t e32 = static_cast<uint32_t>(e);
      sorted[cursor[std::min(edge_from(indices, e32), edge_to(indices, e32))]++] = e32;
    }
  }

  // === Match the uses of each undirected edge (same lower and higher vertex) ===
  std::vector<uint32_t> group;  // scratch: uses of one undirected edge
  std::vector<uint64_t> keyed;  // scratch for long lists: (higher vertex << 32) | edge id
  for (size_t v = 0; v < vertex_count; ++v) {
    uint32_t* list = sorted.data() + offsets[v];
    const size_t n = offsets[v + 1] - offsets[v];
    if (n == 0) continue;
    auto higher = [&](uint32_t e) { return std::max(edge_from(indices, e), edge_to(indices, e)); };
    if (n <= kLinearMatchLimit) {
      // Selection-style grouping in place: move each edge's partners next to it.
      for (size_t i = 0; i < n;) {
        const uint32_t h = higher(list[i]);
        size_t end = i + 1;
        for (size_t j = i + 1; j < n; ++j) {
          if (higher(list[j]) == h) std::swap(list[j], list[end++]);
        }
        // Keep ids ascending inside a group so pairing does not depend on scan order.
        std::sort(list + i, list + end);
        match_group(indices, list + i, end - i, t);
        i = end;
      }
    } else {
      keyed.clear();
      for (size_t i = 0; i < n; ++i) keyed.push_back((uint64_t{higher(list[i])} << 32) | list[i]);
      std::sort(keyed.begin(), keyed.end());
      for (size_t i = 0; i < n;) {
        size_t end = i + 1;
        while (end < n && (keyed[end] >> 32) == (keyed[i] >> 32)) ++end;
        group.clear();
        for (size_t j = i; j < end; ++j) group.push_back(static_cast<uint32_t>(keyed[j]));
        match_group(indices, group.data(), group.size(), t);
        i = end;
      }
    }
  }

  // === Components through paired edges (flat stack, faces numbered by lowest face) ===
  const size_t face_count = mesh.face_count();
  t.face_component.assign(face_count, kInvalid);
  std::vector<uint32_t> stack;
  for (size_t seed = 0; seed < face_count; ++seed) {
    if (t.face_component[seed] != kInvalid) continue;
    const uint32_t id = t.edge_components++;
    t.face_component[seed] = id;
    stack.push_back(static_cast<uint32_t>(seed));
    while (!stack.empty()) {
      const uint32_t f = stack.back();
      stack.pop_back();
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t g = neighbour_face(t, 3 * f + k);
        if (g != kInvalid && t.face_component[g] == kInvalid) {
          t.face_component[g] = id;
          stack.push_back(g);
        }
      }
    }
  }

  // === Components of faces sharing a vertex (union-find over vertices) ===
  std::vector<uint32_t> parent(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) parent[v] = static_cast<uint32_t>(v);
  for (size_t f = 0; f < face_count; ++f) {
    const uint32_t a = find_root(parent, indices[3 * f]);
    for (uint32_t k = 1; k < 3; ++k) {
      const uint32_t b = find_root(parent, indices[3 * f + k]);
      if (a != b) parent[b] = a;
    }
  }
  std::vector<uint8_t> referenced(vertex_count, 0);
  for (size_t c = 0; c < corner_count; ++c) referenced[indices[c]] = 1;
  for (size_t v = 0; v < vertex_count; ++v) {
    if (referenced[v] && find_root(parent, static_cast<uint32_t>(v)) == v) ++t.vertex_components;
  }

  t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

}  // namespace tailor
