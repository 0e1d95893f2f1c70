// Faces wound against their neighbours: found through the edges they share running the same way,
// and turned so that each piece of surface runs one way (include/tailor/topology.h).
#include "surface/face_winding.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace tailor {
namespace internal {

std::vector<std::pair<size_t, size_t>> same_way_edge_pairs(const Mesh& mesh, const Topology& topology) {
  std::vector<std::pair<size_t, size_t>> pairs;
  if (topology.inconsistent_edges == 0) return pairs;
  std::vector<std::pair<uint64_t, size_t>> loose;  // (lower vertex << 32 | upper vertex, edge)
  for (size_t e = 0; e < topology.opposite.size(); ++e) {
    if (topology.opposite[e] != kInvalid) continue;
    const uint64_t a = mesh.indices[e], b = mesh.indices[3 * (e / 3) + (e % 3 + 1) % 3];
    loose.emplace_back(std::min(a, b) << 32 | std::max(a, b), e);
  }
  std::sort(loose.begin(), loose.end());
  for (size_t i = 0; i < loose.size();) {
    size_t end = i + 1;
    while (end < loose.size() && loose[end].first == loose[i].first) ++end;
    const size_t e = loose[i].second;
    if (end - i == 2 && mesh.indices[e] == mesh.indices[loose[i + 1].second])
      pairs.emplace_back(e, loose[i + 1].second);
    i = end;
  }
  return pairs;
}

}  // namespace internal

namespace {

// Union-find over the topology's components with the parity of each to its parent: 1 when the
// two are wound against each other. A component is its own root at first, parity 0.
struct WindingClasses {
  std::vector<uint32_t> parent;
  std::vector<uint8_t> parity;

  explicit WindingClasses(uint32_t count) : parent(count), parity(count, 0) {
    for (uint32_t c = 0; c < count; ++c) parent[c] = c;
  }
  // The root of c and c's parity to it, halving the path on the way.
  std::pair<uint32_t, uint8_t> find(uint32_t c) {
    uint8_t to_root = 0;
    while (parent[c] != c) {
      const uint32_t p = parent[c];
      if (parent[p] != p) {  // skip p: c's parity to p's parent is the sum of the two links
        parity[c] ^= parity[p];
        parent[c] = parent[p];
      }
      to_root ^= parity[c];
      c = parent[c];
    }
    return {c, to_root};
  }
  // Joins a and b with the given parity; nothing when they are joined already (with the other
  // parity: a band whose two sides meet turned, a Moebius strip, whose edge stays unpaired).
  void join(uint32_t a, uint32_t b, uint8_t wanted) {
    const auto [ra, pa] = find(a);
    const auto [rb, pb] = find(b);
    if (ra == rb) return;
    const uint32_t lo = std::min(ra, rb), hi = std::max(ra, rb);
    parent[hi] = lo;
    parity[hi] = pa ^ pb ^ wanted;
  }
};

void turn_face(Mesh& mesh, size_t f) {
  std::swap(mesh.indices[3 * f + 1], mesh.indices[3 * f + 2]);
  if (!mesh.corner_uvs.empty())
    for (size_t k = 0; k < 2; ++k)
      std::swap(mesh.corner_uvs[2 * (3 * f + 1) + k], mesh.corner_uvs[2 * (3 * f + 2) + k]);
  for (CornerAttribute& attribute : mesh.corner_attributes) {
    const size_t n = static_cast<size_t>(attribute.components);
    for (size_t k = 0; k < n; ++k)
      std::swap(attribute.values[n * (3 * f + 1) + k], attribute.values[n * (3 * f + 2) + k]);
  }
}

double face_area(const Mesh& mesh, size_t f) {
  const float* p[3];
  for (size_t k = 0; k < 3; ++k) p[k] = &mesh.positions[3 * size_t{mesh.indices[3 * f + k]}];
  double u[3], v[3];
  for (size_t k = 0; k < 3; ++k) {
    u[k] = double{p[1][k]} - p[0][k];
    v[k] = double{p[2][k]} - p[0][k];
  }
  const double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
  return std::sqrt(x * x + y * y + z * z);
}

// A face by its corners' positions, sorted (x, then y, then z): the same whatever the order of the
// faces, the vertices or the corners.
using FaceKey = std::array<float, 9>;
FaceKey face_key(const Mesh& mesh, size_t f) {
  std::array<std::array<float, 3>, 3> corners;
  for (size_t k = 0; k < 3; ++k)
    for (size_t d = 0; d < 3; ++d) corners[k][d] = mesh.positions[3 * size_t{mesh.indices[3 * f + k]} + d];
  std::sort(corners.begin(), corners.end());
  FaceKey key;
  for (size_t k = 0; k < 3; ++k)
    for (size_t d = 0; d < 3; ++d) key[3 * k + d] = corners[k][d];
  return key;
}

// What decides which side of a group turns: its area, summed exactly (each face's area in units of
// 2^-32 of the largest face's, added as integers, so that no order of the faces rounds differently;
// under 2^32 faces of up to 2^32 units cannot overflow 64 bits), and its least face key for a tie.
struct Side {
  uint64_t area = 0;
  FaceKey least{};
  bool any = false;
  void add(uint64_t a, const FaceKey& key) {
    area += a;
    if (!any || key < least) least = key;
    any = true;
  }
};

}  // namespace

size_t orient_faces_coherently(Mesh& mesh, const Topology& topology) {
  if (topology.opposite.size() != mesh.indices.size() || topology.face_component.size() != mesh.face_count()) return 0;
  const auto pairs = internal::same_way_edge_pairs(mesh, topology);
  if (pairs.empty()) return 0;
  // The topology's components run one way each (joined through edges that run both ways); an
  // edge two of them share running the same way says one of the two is turned.
  const uint32_t components = topology.edge_components;
  WindingClasses classes(components);
  for (const auto& [e, g] : pairs) classes.join(topology.face_component[e / 3], topology.face_component[g / 3], 1);
  // In each group of joined components, the side of the lesser area turns; on a tie, the side
  // whose least face key is the greater. Neither depends on the order of the faces in the file.
  const size_t faces = mesh.face_count();
  double largest = 0.0;
  for (size_t f = 0; f < faces; ++f) largest = std::max(largest, face_area(mesh, f));
  const double unit = largest > 0.0 ? std::ldexp(1.0, 32) / largest : 0.0;
  // Each component's group (numbered in order of the groups' lowest components) and side.
  std::vector<uint32_t> group(components), group_of_root(components, kInvalid);
  std::vector<uint8_t> side(components);
  uint32_t groups = 0;
  for (uint32_t c = 0; c < components; ++c) {
    const auto [root, parity] = classes.find(c);
    if (group_of_root[root] == kInvalid) group_of_root[root] = groups++;
    group[c] = group_of_root[root];
    side[c] = parity;
  }
  std::vector<uint32_t>().swap(group_of_root);
  std::vector<Side> sides(2 * size_t{groups});  // per group: parity 0, parity 1
  for (size_t f = 0; f < faces; ++f) {
    const uint32_t c = topology.face_component[f];
    sides[2 * size_t{group[c]} + side[c]].add(static_cast<uint64_t>(std::llround(face_area(mesh, f) * unit)),
                                              face_key(mesh, f));
  }
  std::vector<uint8_t> turns(components, 0);
  for (uint32_t c = 0; c < components; ++c) {
    const Side& s0 = sides[2 * size_t{group[c]}];
    const Side& s1 = sides[2 * size_t{group[c]} + 1];
    if (!s1.any) continue;  // a component no same-way edge joins: nothing to turn
    const bool turn_0 = s0.area != s1.area ? s0.area < s1.area : s1.least < s0.least;
    turns[c] = side[c] == (turn_0 ? 0 : 1);
  }
  size_t turned = 0;
  for (size_t f = 0; f < mesh.face_count(); ++f)
    if (turns[topology.face_component[f]]) {
      turn_face(mesh, f);
      ++turned;
    }
  return turned;
}

}  // namespace tailor
