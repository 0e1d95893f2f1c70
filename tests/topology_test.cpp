// Topology: opposite edges, components and edge counts on real meshes (exact counts from
// shared/data/meshes/MANIFEST.md) and on hand-built adversarial cases.
#include "tailor/topology.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "support/fixtures.h"
#include "tailor/io.h"

namespace tailor {
namespace {

Mesh make_mesh(std::vector<float> positions, std::vector<uint32_t> indices) {
  Mesh m;
  m.positions = std::move(positions);
  m.indices = std::move(indices);
  return m;
}

// Every paired edge must point back, join the same two vertices in opposite directions, and
// belong to another face.
void expect_consistent(const Mesh& mesh, const Topology& t) {
  ASSERT_EQ(t.opposite.size(), mesh.indices.size());
  for (uint32_t e = 0; e < t.opposite.size(); ++e) {
    const uint32_t o = t.opposite[e];
    if (o == kInvalid) continue;
    ASSERT_LT(o, t.opposite.size());
    EXPECT_EQ(t.opposite[o], e);
    EXPECT_NE(o / 3, e / 3);
    const uint32_t a = mesh.indices[e], b = mesh.indices[e - e % 3 + (e % 3 + 1) % 3];
    const uint32_t c = mesh.indices[o], d = mesh.indices[o - o % 3 + (o % 3 + 1) % 3];
    EXPECT_EQ(a, d);
    EXPECT_EQ(b, c);
  }
}

// The topology on several threads is the one-thread topology (every array and count).
void expect_same_on_threads(const Mesh& mesh, const Topology& one) {
  for (const uint32_t threads : {2u, 3u, 7u}) {
    const Topology t = build_topology(mesh, {}, threads);
    EXPECT_EQ(t.opposite, one.opposite) << threads << " threads";
    EXPECT_EQ(t.face_component, one.face_component) << threads << " threads";
    EXPECT_EQ(t.edge_components, one.edge_components);
    EXPECT_EQ(t.vertex_components, one.vertex_components);
    EXPECT_EQ(t.edges, one.edges);
    EXPECT_EQ(t.boundary_edges, one.boundary_edges);
    EXPECT_EQ(t.nonmanifold_edges, one.nonmanifold_edges);
    EXPECT_EQ(t.inconsistent_edges, one.inconsistent_edges);
  }
}

struct Expected {
  const char* file;
  size_t faces;
  uint32_t components;
  size_t boundary_edges;
  long euler;  // referenced vertices - edges + faces
};

void PrintTo(const Expected& x, std::ostream* os) { *os << x.file; }

class RealMeshTopology : public ::testing::TestWithParam<Expected> {};

TEST_P(RealMeshTopology, MatchesManifest) {
  const Expected& x = GetParam();
  Mesh mesh;
  LoadReport report;
  const Status s = load_mesh(std::string(TAILOR_TEST_DATA) + "/meshes/" + x.file, mesh, &report);
  ASSERT_TRUE(s.is_ok()) << s.message();
  const Topology t = build_topology(mesh, {}, 1);
  expect_consistent(mesh, t);
  expect_same_on_threads(mesh, t);
  EXPECT_EQ(mesh.face_count(), x.faces);
  EXPECT_EQ(t.vertex_components, x.components);
  EXPECT_EQ(t.boundary_edges, x.boundary_edges);
  EXPECT_EQ(t.nonmanifold_edges, 0u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  const long referenced = static_cast<long>(mesh.vertex_count() - report.unreferenced_vertices);
  EXPECT_EQ(referenced - static_cast<long>(t.edges) + static_cast<long>(mesh.face_count()), x.euler);
  // Every paired edge is one undirected edge seen twice; boundaries once.
  size_t paired = 0;
  for (uint32_t o : t.opposite) paired += o != kInvalid;
  EXPECT_EQ(paired / 2 + t.boundary_edges, t.edges);
}

INSTANTIATE_TEST_SUITE_P(Manifest, RealMeshTopology,
                         ::testing::Values(Expected{"spot.obj", 5856, 1, 0, 2}, Expected{"fandisk.off", 14454, 1, 0, 2},
                                           Expected{"fertility.off", 9000, 1, 0, -6},
                                           Expected{"blobby-3cc.off", 3417, 3, 219, 2},
                                           Expected{"featuretype.stl", 3476, 1, 576, -16},
                                           Expected{"horse.ply", 96966, 1, 0, 2}),
                         [](const auto& param_info) {
                           std::string name = param_info.param.file;
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

TEST(Topology, TwoTrianglesShareOneEdge) {
  // 0-1-2 and 2-1-3 share edge 1-2 (edge 1 of face 0 runs 1->2, edge 0 of face 1 runs 2->1).
  const Mesh m = make_mesh({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {0, 1, 2, 2, 1, 3});
  const Topology t = build_topology(m);
  EXPECT_EQ(t.opposite[1], 3u);
  EXPECT_EQ(t.opposite[3], 1u);
  EXPECT_EQ(neighbour_face(t, 1), 1u);
  EXPECT_EQ(t.edges, 5u);
  EXPECT_EQ(t.boundary_edges, 4u);
  EXPECT_EQ(t.edge_components, 1u);
  EXPECT_EQ(count_nonmanifold_vertices(m), 0u);
}

TEST(Topology, BowTieVertexJoinsByVertexOnly) {
  // Two triangles touching at vertex 2 only.
  const Mesh m = make_mesh({0, 0, 0, 1, 0, 0, 0.5f, 1, 0, 0, 2, 0, 1, 2, 0}, {0, 1, 2, 2, 3, 4});
  const Topology t = build_topology(m);
  expect_same_on_threads(m, t);
  EXPECT_EQ(t.vertex_components, 1u);
  EXPECT_EQ(t.edge_components, 2u);
  EXPECT_EQ(t.boundary_edges, 6u);
  for (uint32_t o : t.opposite) EXPECT_EQ(o, kInvalid);
  EXPECT_EQ(count_nonmanifold_vertices(m), 1u);  // vertex 2: two fans
}

// Meshes with their faces shuffled: most neighbour pairs then cross the slices of the components'
// union-find, whose links the threads make at once.
TEST(Topology, ShuffledFacesGiveTheSameComponentsOnAnyThreadCount) {
  for (const auto& [file, components] : {std::pair{"horse.ply", 1u}, std::pair{"blobby-3cc.off", 3u}}) {
    Mesh mesh;
    ASSERT_TRUE(load_mesh(std::string(TAILOR_TEST_DATA) + "/meshes/" + file, mesh).is_ok());
    std::vector<uint32_t> order(mesh.face_count());
    std::iota(order.begin(), order.end(), 0u);
    std::mt19937 random(7);
    for (size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[random() % (i + 1)]);
    std::vector<uint32_t> shuffled(mesh.indices.size());
    for (size_t f = 0; f < order.size(); ++f) std::copy_n(&mesh.indices[3 * size_t{order[f]}], 3, &shuffled[3 * f]);
    mesh.indices = std::move(shuffled);
    const Topology t = build_topology(mesh, {}, 1);
    EXPECT_EQ(t.vertex_components, components) << file;
    EXPECT_EQ(t.face_component[0], 0u);
    expect_same_on_threads(mesh, t);
  }
}

// Chains of triangles that touch the next one at a vertex only: every face is its own edge
// component and each chain one vertex component. Below and above the count of components up to
// which the vertex pass runs on several slices, and with the chains' faces in reverse order (then
// other component ids meet first in each slice of vertices).
TEST(Topology, BowTieChainsJoinAcrossVertexSlices) {
  for (const uint32_t chain : {1000u, 70000u}) {
    for (const bool reversed : {false, true}) {
      std::vector<float> positions;
      std::vector<uint32_t> indices;
      for (uint32_t c = 0; c < 2; ++c) {  // two chains
        const uint32_t first = static_cast<uint32_t>(positions.size() / 3);
        for (uint32_t v = 0; v <= 2 * chain; ++v)
          positions.insert(positions.end(), {static_cast<float>(v), static_cast<float>(v % 2 + 3 * c), 0.f});
        for (uint32_t k = 0; k < chain; ++k)
          indices.insert(indices.end(), {first + 2 * k, first + 2 * k + 1, first + 2 * k + 2});
      }
      if (reversed)
        for (size_t f = 0, n = indices.size() / 3; f < n / 2; ++f)
          std::swap_ranges(indices.begin() + 3 * f, indices.begin() + 3 * f + 3, indices.end() - 3 * (f + 1));
      const Mesh m = make_mesh(positions, indices);
      const Topology t = build_topology(m, {}, 1);
      EXPECT_EQ(t.edge_components, 2 * chain);
      EXPECT_EQ(t.vertex_components, 2u) << chain << (reversed ? " reversed" : "");
      for (uint32_t f = 0; f < 2 * chain; ++f) ASSERT_EQ(t.face_component[f], f);
      expect_same_on_threads(m, t);
    }
  }
}

TEST(Topology, FinEdgeWithThreeFacesIsCutAndCounted) {
  // Faces 0,1,2 all use edge 0-1.
  const Mesh m = make_mesh({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1}, {0, 1, 2, 1, 0, 3, 0, 1, 4});
  const Topology t = build_topology(m);
  expect_same_on_threads(m, t);
  EXPECT_EQ(t.nonmanifold_edges, 1u);
  EXPECT_EQ(t.opposite[0], kInvalid);
  EXPECT_EQ(t.opposite[3], kInvalid);
  EXPECT_EQ(t.opposite[6], kInvalid);
  EXPECT_EQ(t.edge_components, 3u);
  EXPECT_EQ(t.vertex_components, 1u);
  EXPECT_EQ(count_nonmanifold_vertices(m), 2u);  // the fin edge's two ends
}

TEST(Topology, FlippedFaceIsInconsistentNotPaired) {
  // Both faces run 1 -> 2.
  const Mesh m = make_mesh({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {0, 1, 2, 1, 2, 3});
  const Topology t = build_topology(m);
  expect_same_on_threads(m, t);
  EXPECT_EQ(t.inconsistent_edges, 1u);
  for (uint32_t o : t.opposite) EXPECT_EQ(o, kInvalid);
  EXPECT_EQ(t.edge_components, 2u);
  EXPECT_EQ(count_nonmanifold_vertices(m), 0u);  // badly oriented, but a manifold
}

TEST(Topology, NonManifoldVertices) {
  // Two closed fans (cones) of 6 faces joined at their apex 0: one vertex, every edge shared by two.
  std::vector<float> p = {0, 0, 0};
  std::vector<uint32_t> idx;
  for (uint32_t cone = 0; cone < 2; ++cone) {
    const uint32_t base = 1 + 6 * cone;
    for (uint32_t i = 0; i < 6; ++i) {
      const float a = 1.0471976f * static_cast<float>(i);
      p.insert(p.end(), {std::cos(a), std::sin(a), cone == 0 ? 1.f : -1.f});
      idx.insert(idx.end(), {0, base + i, base + (i + 1) % 6});
    }
  }
  Mesh m = make_mesh(p, idx);
  EXPECT_EQ(build_topology(m).nonmanifold_edges, 0u);
  EXPECT_EQ(count_nonmanifold_vertices(m), 1u);
  // One closed cone and an open fan of two faces around the same apex: still two fans.
  m.indices.resize(6 * 3 + 2 * 3);
  EXPECT_EQ(count_nonmanifold_vertices(m), 1u);
  // The first cone alone is a single closed fan; a vertex of no face is not counted.
  m.indices.resize(6 * 3);
  EXPECT_EQ(count_nonmanifold_vertices(m), 0u);
}

TEST(Topology, HighValenceFanUsesSortedMatching) {
  // A closed fan (cone without base) of 200 triangles around vertex 0: every spoke is shared.
  constexpr uint32_t kSpokes = 200;
  std::vector<float> p = {0, 0, 1};
  std::vector<uint32_t> idx;
  for (uint32_t i = 0; i < kSpokes; ++i) {
    const float a = 6.2831853f * static_cast<float>(i) / kSpokes;
    p.insert(p.end(), {std::cos(a), std::sin(a), 0});
    idx.insert(idx.end(), {0, 1 + i, 1 + (i + 1) % kSpokes});
  }
  const Mesh m = make_mesh(p, idx);
  const Topology t = build_topology(m);
  expect_consistent(m, t);
  EXPECT_EQ(t.edges, 2u * kSpokes);
  EXPECT_EQ(t.boundary_edges, kSpokes);
  EXPECT_EQ(t.edge_components, 1u);
  for (uint32_t f = 0; f < kSpokes; ++f) {
    EXPECT_NE(t.opposite[3 * f], kInvalid);
    EXPECT_NE(t.opposite[3 * f + 2], kInvalid);
    EXPECT_EQ(t.opposite[3 * f + 1], kInvalid);
  }
}

// The faces of a real mesh turned against their neighbours (every 97th, with their UVs) are turned
// back: the mesh comes out bit-identical, every shared edge paired.
TEST(OrientFaces, TurnsBackAMinorityOfTurnedFaces) {
  Mesh clean;
  ASSERT_TRUE(load_mesh(std::string(TAILOR_TEST_DATA) + "/meshes/spot.obj", clean).is_ok());
  ASSERT_FALSE(clean.corner_uvs.empty());
  Mesh mesh = clean;
  size_t turned = 0;
  for (size_t f = 0; f < mesh.face_count(); f += 97, ++turned) {
    std::swap(mesh.indices[3 * f + 1], mesh.indices[3 * f + 2]);
    for (size_t k = 0; k < 2; ++k) std::swap(mesh.corner_uvs[6 * f + 2 + k], mesh.corner_uvs[6 * f + 4 + k]);
  }
  const Topology before = build_topology(mesh);
  EXPECT_GT(before.inconsistent_edges, 0u);
  EXPECT_EQ(orient_faces_coherently(mesh, before), turned);
  EXPECT_EQ(mesh.indices, clean.indices);
  EXPECT_EQ(mesh.corner_uvs, clean.corner_uvs);
  const Topology after = build_topology(mesh);
  EXPECT_EQ(after.inconsistent_edges, 0u);
  EXPECT_EQ(after.edge_components, 1u);
  EXPECT_EQ(orient_faces_coherently(mesh, after), 0u);  // nothing left to turn
}

// Every second face turned, and a flat grid with its left half turned (the same area each way,
// exactly): the same faces turn whatever the order of the faces, so the surface runs one way, the
// same way.
TEST(OrientFaces, TheSameFacesTurnInAnyFaceOrder) {
  Mesh fandisk;
  ASSERT_TRUE(load_mesh(std::string(TAILOR_TEST_DATA) + "/meshes/fandisk.off", fandisk).is_ok());
  for (size_t f = 1; f < fandisk.face_count(); f += 2)
    std::swap(fandisk.indices[3 * f + 1], fandisk.indices[3 * f + 2]);
  Mesh grid = test::grid(8, 4, test::Diagonal::kRising);
  for (size_t f = 0; f < grid.face_count(); ++f)
    if (grid.positions[3 * grid.indices[3 * f]] + grid.positions[3 * grid.indices[3 * f + 1]] +
            grid.positions[3 * grid.indices[3 * f + 2]] <
        12.f)  // the cells left of x = 4
      std::swap(grid.indices[3 * f + 1], grid.indices[3 * f + 2]);
  for (Mesh* mesh : {&fandisk, &grid}) {
    const size_t nf = mesh->face_count();
    Mesh reversed = *mesh;  // the same faces in the opposite order
    for (size_t f = 0; f < nf; ++f)
      for (size_t k = 0; k < 3; ++k) reversed.indices[3 * f + k] = mesh->indices[3 * (nf - 1 - f) + k];
    const size_t turned = orient_faces_coherently(*mesh, build_topology(*mesh));
    EXPECT_GT(turned, 0u);
    EXPECT_LT(turned, nf);
    EXPECT_EQ(orient_faces_coherently(reversed, build_topology(reversed)), turned);
    for (size_t f = 0; f < nf; ++f)
      for (size_t k = 0; k < 3; ++k)
        ASSERT_EQ(reversed.indices[3 * f + k], mesh->indices[3 * (nf - 1 - f) + k]) << "face " << f;
    const Topology t = build_topology(*mesh);
    EXPECT_EQ(t.inconsistent_edges, 0u);
    EXPECT_EQ(t.edge_components, 1u);
  }
}

// A Moebius strip cannot run one way: one edge stays unpaired, and nothing else is harmed.
TEST(OrientFaces, MoebiusStripKeepsOneEdgeUnpaired) {
  constexpr uint32_t kSegments = 12;
  std::vector<float> p;
  std::vector<uint32_t> idx;
  for (uint32_t i = 0; i < kSegments; ++i) {
    const float a = 6.2831853f * static_cast<float>(i) / kSegments, half = a / 2;
    for (const float s : {-0.3f, 0.3f}) {
      const float r = 1 + s * std::cos(half);
      p.insert(p.end(), {r * std::cos(a), r * std::sin(a), s * std::sin(half)});
    }
  }
  for (uint32_t i = 0; i < kSegments; ++i) {
    const uint32_t a = 2 * i, b = 2 * i + 1;
    // The last segment joins the first one's sides swapped: the half twist.
    const uint32_t c = i + 1 < kSegments ? 2 * i + 2 : 1, d = i + 1 < kSegments ? 2 * i + 3 : 0;
    idx.insert(idx.end(), {a, c, b, b, c, d});
  }
  Mesh mesh = make_mesh(p, idx);
  const Topology t = build_topology(mesh);
  ASSERT_GT(t.inconsistent_edges, 0u);
  orient_faces_coherently(mesh, t);
  const Topology after = build_topology(mesh);
  EXPECT_EQ(after.inconsistent_edges, 1u);
  EXPECT_EQ(after.boundary_edges, t.boundary_edges);
}

}  // namespace
}  // namespace tailor
