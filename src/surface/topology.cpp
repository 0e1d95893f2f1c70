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
#include <type_traits>
#include <utility>
#include <vector>

#include "util/face_components.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"
#include "util/union_find.h"

namespace tailor {
namespace {

// A vertex with more edge uses than this is sorted with std::sort instead of insertion sort
// (a fan of a million faces around one vertex must not take 10^12 steps).
constexpr size_t kLinearMatchLimit = 32;

// Edge counts of one slice of lower vertices (summed into Topology after the matching).
struct EdgeCounts {
  size_t edges = 0, boundary = 0, nonmanifold = 0, inconsistent = 0;
};

// Faces per thread of the edge passes: below this, starting a thread costs more than it saves.
constexpr size_t kFacesPerThread = 250000;
// Components up to which each slice of the vertex-component pass keeps a union-find of them all
// (4 bytes each per slice); a mesh of more (a soup of loose faces) is labelled on one thread.
constexpr uint32_t kSlicedComponentLimit = uint32_t{1} << 16;

// Decides the fate of one undirected edge, given its uses sorted by (direction, edge id).
void match_group(const uint64_t* uses, size_t count, uint32_t* opposite, EdgeCounts& counts) {
  if (count == 1) {
    ++counts.boundary;
  } else if (count == 2) {
    const uint32_t e0 = static_cast<uint32_t>(uses[0]);
    const uint32_t e1 = static_cast<uint32_t>(uses[1]);
    if (((uses[0] ^ uses[1]) >> 32) & 1) {
      opposite[e0] = e1;
      opposite[e1] = e0;
    } else {
      ++counts.inconsistent;  // both faces run the edge the same way: left unpaired
    }
  } else {
    ++counts.nonmanifold;  // three or more faces: all uses left unpaired
  }
  ++counts.edges;
}

}  // namespace

Topology build_topology(const Mesh& mesh) { return build_topology(mesh, {}, 0); }

Topology build_topology(const Mesh& mesh, const ProgressCallback& progress) {
  return build_topology(mesh, progress, 0);
}

Topology build_topology(const Mesh& mesh, const ProgressCallback& progress, uint32_t threads) {
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

  // The edge passes on several threads, each owning a range of lower vertices: it reads every
  // face but counts, places and matches only the edges whose lower vertex is its own, so no two
  // threads write the same entry and the result does not depend on the count (a vertex's list is
  // sorted before matching). Reading all faces per thread is sequential and cheap next to the
  // scattered writes it divides.
  const size_t slices = std::min(internal::parallel_threads(corner_count / 3, threads, kFacesPerThread),
                                 std::max<size_t>(vertex_count, 1));
  const auto slice_begin = [&](size_t s) { return static_cast<uint32_t>(vertex_count * s / slices); };
  const auto each_slice = [&](auto body) {
    internal::for_each_chunk(
        slices, slices, [&](size_t s, size_t, size_t) { body(slice_begin(s), slice_begin(s + 1), s); }, 1);
  };

  // === Group edge uses by their lower vertex (counting sort) ===
  // Each entry is (higher vertex << 33) | (runs lower -> higher) << 32 | edge id, so grouping and
  // the direction check need no further index lookups (vertex ids < 2^31, see kMaxVertices).
  std::vector<uint32_t> offsets(vertex_count + 1, 0);
  // `sliced` (std::true_type with several slices) compiles the range test in; one slice runs without.
  const auto ours = [](auto sliced, uint32_t low, uint32_t lo, uint32_t hi) {
    if constexpr (decltype(sliced)::value) return low >= lo && low < hi;
    return true;
  };
  const auto count_uses = [&](auto sliced, uint32_t lo, uint32_t hi) {
    const auto count = [&](uint32_t low) {
      if (ours(sliced, low, lo, hi)) ++offsets[low + 1];
    };
    for (size_t f = 0; f < corner_count; f += 3) {
      const uint32_t a = indices[f], b = indices[f + 1], c = indices[f + 2];
      count(std::min(a, b));
      count(std::min(b, c));
      count(std::min(c, a));
    }
  };
  each_slice([&](uint32_t lo, uint32_t hi, size_t) {
    slices == 1 ? count_uses(std::false_type{}, lo, hi) : count_uses(std::true_type{}, lo, hi);
  });
  for (size_t v = 0; v < vertex_count; ++v) offsets[v + 1] += offsets[v];
  internal::HugeArray<uint64_t> sorted = internal::huge_uninitialized<uint64_t>(corner_count);
  {
    std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    const auto place_uses = [&](auto sliced, uint32_t lo, uint32_t hi) {
      for (size_t f = 0; f < corner_count; f += 3) {
        const uint32_t v[3] = {indices[f], indices[f + 1], indices[f + 2]};
        for (uint32_t k = 0; k < 3; ++k) {
          const uint32_t a = v[k], b = v[k == 2 ? 0 : k + 1], low = std::min(a, b);
          if (!ours(sliced, low, lo, hi)) continue;
          sorted[cursor[low]++] =
              (uint64_t{std::max(a, b)} << 33) | (uint64_t{a < b} << 32) | static_cast<uint32_t>(f + k);
        }
      }
    };
    each_slice([&](uint32_t lo, uint32_t hi, size_t) {
      slices == 1 ? place_uses(std::false_type{}, lo, hi) : place_uses(std::true_type{}, lo, hi);
    });
  }

  reached(0.3f);
  // === Match the uses of each undirected edge (same lower and higher vertex) ===
  // Sorting a vertex's entries puts the uses of one edge next to each other, ordered by edge id,
  // so the pairing does not depend on anything but the mesh. Lists are short (~6 on average):
  // insertion sort, with std::sort for the rare high-valence vertex. Each slice counts its edges
  // apart; the counts are summed after.
  std::vector<EdgeCounts> counts(slices);
  each_slice([&](uint32_t lo, uint32_t hi, size_t s) {
    for (size_t v = lo; v < hi; ++v) {
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
        match_group(list + i, end - i, t.opposite.data(), counts[s]);
        i = end;
      }
    }
  });
  for (const EdgeCounts& c : counts) {
    t.edges += c.edges;
    t.boundary_edges += c.boundary;
    t.nonmanifold_edges += c.nonmanifold;
    t.inconsistent_edges += c.inconsistent;
  }

  reached(0.6f);
  // === Components through paired edges ===
  // Union-find in face order rather than a flood fill: neighbouring faces are mostly near each
  // other in file order, so the pass reads opposite[] sequentially and the parents with good
  // locality; components numbered by their lowest face, the same for any count
  // (util/face_components.h).
  const size_t face_count = mesh.face_count();
  internal::reserve_huge(t.face_component, face_count);
  t.face_component.resize(face_count);
  uint32_t* const component = t.face_component.data();
  t.edge_components = internal::label_components(
      face_count, slices,
      [&t](uint32_t f, const auto& wanted, const auto& visit) {
        for (uint32_t k = 0; k < 3; ++k) {
          const uint32_t g = neighbour_face(t, 3 * f + k);
          if (g != kInvalid && wanted(g)) visit(g);
        }
      },
      component);

  reached(0.85f);
  // === Components of faces sharing a vertex ===
  // Edge components touching at a vertex (bow-ties, fins) are merged with a union-find over the
  // few edge components, labelling each vertex with the first component seen: one pass over the
  // corners instead of a union-find over all vertices. With one edge component there is nothing
  // to merge. Each slice of vertices labels its own and joins the components that meet there in a
  // union-find of its own (up to kSlicedComponentLimit components; beyond, one slice), then the
  // slices' sets are joined into the first's: the number of sets does not depend on the order.
  t.vertex_components = t.edge_components;
  if (t.edge_components > 1) {
    const size_t label_slices = t.edge_components <= kSlicedComponentLimit ? slices : 1;
    std::vector<std::vector<uint32_t>> parent(label_slices, std::vector<uint32_t>(t.edge_components));
    std::vector<uint32_t> vertex_label(vertex_count, kInvalid);
    internal::for_each_part(vertex_count, label_slices, [&](size_t s, size_t lo, size_t hi) {
      uint32_t* const own = parent[s].data();
      for (uint32_t c = 0; c < t.edge_components; ++c) own[c] = c;
      for (size_t c = 0; c < corner_count; ++c) {
        const uint32_t v = indices[c];
        if (v < lo || v >= hi) continue;
        const uint32_t here = component[c / 3];
        uint32_t& label = vertex_label[v];
        if (label == kInvalid) {
          label = here;
        } else if (label != here) {
          const uint32_t a = internal::find_root(own, label), b = internal::find_root(own, here);
          if (a != b) own[std::max(a, b)] = std::min(a, b);
        }
      }
    });
    uint32_t* const joined = parent[0].data();
    for (size_t s = 1; s < label_slices; ++s)
      for (uint32_t c = 0; c < t.edge_components; ++c) {
        const uint32_t a = internal::find_root(joined, c),
                       b = internal::find_root(joined, internal::find_root(parent[s].data(), c));
        if (a != b) joined[std::max(a, b)] = std::min(a, b);
      }
    t.vertex_components = 0;
    for (uint32_t c = 0; c < t.edge_components; ++c) t.vertex_components += internal::find_root(joined, c) == c;
  }

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
        const uint32_t a = internal::find_root(parent.data(), around[g].second);
        const uint32_t b = internal::find_root(parent.data(), around[g + 1].second);
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
