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
  std::vector<uint64_t> sorted(corner_count);
  {
    std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (size_t f = 0; f < corner_count; f += 3) {
      const uint32_t v[3] = {indices[f], indices[f + 1], indices[f + 2]};
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t a = v[k], b = v[k == 2 ? 0 : k + 1];
        sorted[cursor[std::min(a, b)]++] = (uint64_t{std::max(a, b)} << 33) | (uint64_t{a < b} << 32) |
                                           static_cast<uint32_t>(f + k);
      }
    }
  }

  // === Match the uses of each undirected edge (same lower and higher vertex) ===
  // Sorting a vertex's entries puts the uses of one edge next to each other, ordered by edge id,
  // so the pairing does not depend on anything but the mesh. Lists are short (~6 on average):
  // insertion sort, with std::sort for the rare high-valence vertex.
  for (size_t v = 0; v < vertex_count; ++v) {
    uint64_t* list = sorted.data() + offsets[v];
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

  // === Components through paired edges (flat stack, faces numbered by lowest face) ===
  const size_t face_count = mesh.face_count();
  // Visited flags are kept as bits: 8x smaller than face_component, so the random reads of the
  // flood fill stay in cache.
  t.face_component.assign(face_count, kInvalid);
  std::vector<uint64_t> visited((face_count + 63) / 64, 0);
  auto test_and_set = [&visited](uint32_t f) {
    uint64_t& word = visited[f >> 6];
    const uint64_t bit = uint64_t{1} << (f & 63);
    const bool was = (word & bit) != 0;
    word |= bit;
    return was;
  };
  std::vector<uint32_t> stack;
  for (size_t seed = 0; seed < face_count; ++seed) {
    if (test_and_set(static_cast<uint32_t>(seed))) continue;
    const uint32_t id = t.edge_components++;
    stack.push_back(static_cast<uint32_t>(seed));
    while (!stack.empty()) {
      const uint32_t f = stack.back();
      stack.pop_back();
      t.face_component[f] = id;
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t g = neighbour_face(t, 3 * f + k);
        if (g != kInvalid && !test_and_set(g)) stack.push_back(g);
      }
    }
  }

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
      const uint32_t a = find_root(parent, label);
      const uint32_t b = find_root(parent, component);
      if (a != b) {
        parent[std::max(a, b)] = std::min(a, b);
        ++merges;
      }
    }
  }
  t.vertex_components = t.edge_components - merges;

  t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

}  // namespace tailor
