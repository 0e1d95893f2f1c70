// Metrics on hand-computed cases (docs/metrics.md has the definitions).
#include "tailor/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "support/fixtures.h"
#include "tailor/export.h"
#include "tailor/io.h"
#include "tailor/topology.h"

namespace tailor {
namespace {

using test::Diagonal;
using test::grid;

// Corner UVs (px) from a function of the vertex position.
template <typename F>
std::vector<float> corner_uvs(const Mesh& mesh, F&& uv_of) {
  std::vector<float> uv(2 * mesh.indices.size());
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const float* p = &mesh.positions[3 * size_t{mesh.indices[c]}];
    const auto [u, v] = uv_of(p[0], p[1]);
    uv[2 * c] = u;
    uv[2 * c + 1] = v;
  }
  return uv;
}

UvMetrics metrics_of(const Mesh& mesh, const std::vector<float>& uv, const std::vector<uint32_t>& patch = {},
                     MetricsOptions options = {}) {
  UvMetrics m;
  const Topology topology = build_topology(mesh);
  const Status s = compute_uv_metrics(mesh, topology, uv, patch, options, m);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return m;
}

TEST(Metrics, IdentityMapIsIdeal) {
  const Mesh mesh = grid(3, 2, Diagonal::kFalling);
  const auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{x, y}; });
  const UvMetrics m = metrics_of(mesh, uv);
  EXPECT_EQ(m.faces, 12u);
  EXPECT_EQ(m.patches, 1u);
  EXPECT_EQ(m.single_face_patches, 0u);
  EXPECT_NEAR(m.stretch, 0.0, 1e-12);
  EXPECT_NEAR(m.stretch_area_weighted, 0.0, 1e-12);
  EXPECT_NEAR(m.l2_stretch, 1.0, 1e-12);
  EXPECT_NEAR(m.linf_stretch, 1.0, 1e-12);
  EXPECT_NEAR(m.distortion_deg, 0.0, 1e-9);
  EXPECT_NEAR(m.uv_scale, 1.0, 1e-12);
  EXPECT_EQ(m.flipped, 0u);
  EXPECT_EQ(m.seam_edges, 0u);
  EXPECT_EQ(m.seam_length_ratio, 0.0);
  EXPECT_EQ(m.seam_invisible_ratio, 1.0);
}

TEST(Metrics, UniformScaleIsIdeal) {
  const Mesh mesh = grid(3, 2, Diagonal::kFalling);
  // 800 px per unit, as the thesis's scale, and an offset: only R changes.
  const auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{800 * x + 13, 800 * y - 7}; });
  const UvMetrics m = metrics_of(mesh, uv);
  EXPECT_NEAR(m.stretch, 0.0, 1e-9);
  EXPECT_NEAR(m.l2_stretch, 1.0, 1e-9);
  EXPECT_NEAR(m.linf_stretch, 1.0, 1e-9);
  EXPECT_NEAR(m.distortion_deg, 0.0, 1e-6);
  EXPECT_NEAR(m.uv_scale, 640000.0, 1e-3);
  EXPECT_EQ(m.flipped, 0u);
}

// Shear uv = s * (x + y, y), s = 100. The 2D map M = [[1, 1], [0, 1]] has det 1 (R = s^2, every
// r_f equal: stretch 0). M^T M = [[1, 1], [1, 2]], eigenvalues (3 +- sqrt 5) / 2, so the singular
// values of M are phi = 1.618... and 1/phi; those of the inverse map uv -> 3D (times s) are the
// same pair, G = phi, g = 1/phi. L2 = sqrt((G^2 + g^2) / 2) = sqrt(3 / 2), Linf = phi.
// Angles: lower triangle (0,0) (1,0) (0,1) has 90, 45, 45 degrees; its image (0,0) (1,0) (1,1)
// has 45, 90, 45: distortion |45-90| + |90-45| + 0 = 90. Upper triangle (1,0) (1,1) (0,1):
// 45, 90, 45 -> image (1,0) (2,1) (1,1): 45, 45, 90: also 90. Median 90.
TEST(Metrics, ShearHasKnownStretchAndAngles) {
  const Mesh mesh = grid(2, 2, Diagonal::kFalling);
  const auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{100 * (x + y), 100 * y}; });
  const UvMetrics m = metrics_of(mesh, uv);
  const double phi = (1 + std::sqrt(5.0)) / 2;
  EXPECT_NEAR(m.stretch, 0.0, 1e-9);
  EXPECT_NEAR(m.stretch_area_weighted, 0.0, 1e-9);
  EXPECT_NEAR(m.l2_stretch, std::sqrt(1.5), 1e-9);
  EXPECT_NEAR(m.linf_stretch, phi, 1e-9);
  EXPECT_NEAR(m.distortion_deg, 90.0, 1e-6);
  EXPECT_EQ(m.flipped, 0u);
}

// Two unit right triangles with separate UVs: T0 at 10 px per unit (r = 100), T1 at 20 px per unit
// (r = 400). Mean r 250, population std 150: stretch 0.6 (equal areas, so the weighted form too).
// R = (50 + 200) / 1 = 250. Sander: T0 (a+c)/2 = 1/100, T1 1/400; L2 = sqrt(0.00625) * sqrt(250)
// = 1.25; Linf = (1/10) * sqrt(250) = 1.5811.
// A UV triangle with two corners on one point has the angles atan2(0, 0) = 0 (not a sum of pi):
// distortion = the 3D angles' sum, 180 degrees; the untouched face has 0: median 90.
TEST(Metrics, CollapsedUvEdgeCountsEveryAngle) {
  const Mesh mesh = grid(1, 1, Diagonal::kFalling);
  auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{8 * x, 8 * y}; });
  uv[2] = uv[0];  // lower face: corner 1 onto corner 0
  uv[3] = uv[1];
  const UvMetrics m = metrics_of(mesh, uv);
  EXPECT_NEAR(m.distortion_deg, 90.0, 1e-9);
}

// The passes run on chunks of 32k elements summed in order: any thread count, the same bits.
TEST(Metrics, ThreadCountDoesNotChangeAnyFigure) {
  const Mesh mesh = grid(180, 120, Diagonal::kFalling);  // 43,200 faces, 129,600 corners: several chunks
  auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{7 * x + 0.01f * y * y, 6.5f * y + std::sin(x)}; });
  for (size_t f = 0; f < mesh.face_count(); ++f)  // a cut at x = 90: seams, two patches
    if (mesh.positions[3 * size_t{mesh.indices[3 * f]}] >= 90.f)
      for (size_t k = 0; k < 3; ++k) uv[2 * (3 * f + k)] += 1000.f;
  MetricsOptions one, three;
  one.threads = 1;
  three.threads = 3;
  const UvMetrics a = metrics_of(mesh, uv, {}, one), b = metrics_of(mesh, uv, {}, three);
  EXPECT_GT(a.seam_edges, 0u);
  EXPECT_EQ(a.patches, 2u);
  for (const auto& [x, y] : {std::pair{a.stretch, b.stretch},
                             {a.stretch_area_weighted, b.stretch_area_weighted},
                             {a.distortion_deg, b.distortion_deg},
                             {a.l2_stretch, b.l2_stretch},
                             {a.linf_stretch, b.linf_stretch},
                             {a.seam_length_ratio, b.seam_length_ratio},
                             {a.seam_gap_px, b.seam_gap_px},
                             {a.seam_invisible_ratio, b.seam_invisible_ratio},
                             {a.uv_scale, b.uv_scale}})
    EXPECT_EQ(x, y);
  EXPECT_EQ(a.flipped, b.flipped);
  EXPECT_EQ(a.seam_edges, b.seam_edges);
}

// From 131,072 faces (and vertices) on, the median, the patches derived from the UVs and the test
// for identical positions run on threads: the same figures as on one.
TEST(Metrics, LargeMeshesGiveTheSameFiguresOnAnyThreadCount) {
  const Mesh mesh = grid(520, 260, Diagonal::kFalling);  // 270,400 faces, 135,981 vertices
  // A jitter per vertex: every face's angles differ, so a median off by one rank would show.
  const auto jitter = [](float x, float y, float seed) {
    const float h = std::sin(x * 12.9898f + y * 78.233f + seed) * 43758.547f;
    return 0.3f * (h - std::floor(h));
  };
  auto uv = corner_uvs(mesh, [&](float x, float y) {
    return std::pair{7 * x + 0.01f * y * y + jitter(x, y, 0.f), 6.5f * y + std::sin(x) + jitter(x, y, 1.f)};
  });
  for (size_t f = 0; f < mesh.face_count(); ++f)  // a cut at x = 260: seams, two patches
    if (mesh.positions[3 * size_t{mesh.indices[3 * f]}] >= 260.f)
      for (size_t k = 0; k < 3; ++k) uv[2 * (3 * f + k)] += 1000.f;
  const Topology topology = build_topology(mesh);
  std::vector<uint32_t> one_patches;
  ASSERT_EQ(derive_patches(mesh, topology, uv, one_patches, 1), 2u);
  SplitMesh split;  // the seam's vertices twice: identical positions to join
  split_vertices(mesh, uv, split);
  Mesh split_mesh;
  split_mesh.positions = split.positions;
  split_mesh.indices = split.indices;
  std::vector<float> repeats(uv.size());  // as a file stores them: a power of two scales exactly
  for (size_t i = 0; i < uv.size(); ++i) repeats[i] = uv[i] / 1024.f;
  const auto stored_metrics = [&](const MetricsOptions& options, UvMetrics& m, StoredSurface& surface) {
    return compute_stored_uv_metrics(split_mesh, nullptr, repeats, options, m, &surface).is_ok();
  };
  MetricsOptions one{1024.f, 1024.f};
  one.threads = 1;
  const UvMetrics a = metrics_of(mesh, uv, {}, one);
  UvMetrics a_stored;
  StoredSurface a_surface;
  ASSERT_TRUE(stored_metrics(one, a_stored, a_surface));
  EXPECT_GT(a_surface.welded_vertices, 0u);
  EXPECT_GT(a.distortion_deg, 0.0);
  for (const uint32_t threads : {2u, 3u, 8u}) {
    std::vector<uint32_t> patches;
    EXPECT_EQ(derive_patches(mesh, topology, uv, patches, threads), 2u);
    EXPECT_EQ(patches, one_patches) << threads << " threads";
    MetricsOptions options{1024.f, 1024.f};
    options.threads = threads;
    const UvMetrics b = metrics_of(mesh, uv, {}, options);
    EXPECT_EQ(a.distortion_deg, b.distortion_deg) << threads << " threads";
    EXPECT_EQ(a.stretch, b.stretch);
    EXPECT_EQ(a.patches, b.patches);
    EXPECT_EQ(a.seam_edges, b.seam_edges);
    UvMetrics b_stored;
    StoredSurface b_surface;
    ASSERT_TRUE(stored_metrics(options, b_stored, b_surface));
    EXPECT_EQ(b_surface.welded_vertices, a_surface.welded_vertices) << threads << " threads";
    EXPECT_EQ(b_stored.seam_edges, a_stored.seam_edges);
    EXPECT_EQ(b_stored.patches, a_stored.patches);
    EXPECT_EQ(b_stored.distortion_deg, a_stored.distortion_deg);
  }
}

TEST(Metrics, UnequalScalesGiveKnownStretch) {
  Mesh mesh;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  mesh.indices = {0, 1, 2, 1, 3, 2};
  const std::vector<float> uv = {0,   0, 10,  0,  0,  10,   // T0
                                 100, 0, 100, 20, 80, 20};  // T1: 20 px per unit, shifted
  const UvMetrics m = metrics_of(mesh, uv);
  EXPECT_NEAR(m.stretch, 0.6, 1e-9);
  EXPECT_NEAR(m.stretch_area_weighted, 0.6, 1e-9);
  EXPECT_NEAR(m.uv_scale, 250.0, 1e-9);
  EXPECT_NEAR(m.l2_stretch, 1.25, 1e-9);
  EXPECT_NEAR(m.linf_stretch, std::sqrt(250.0) / 10, 1e-9);
  EXPECT_EQ(m.patches, 2u);
  EXPECT_EQ(m.single_face_patches, 2u);

  std::vector<float> ratio;
  face_area_stretch(mesh, uv, ratio);
  ASSERT_EQ(ratio.size(), 2u);
  EXPECT_NEAR(ratio[0], 0.4f, 1e-6f);
  EXPECT_NEAR(ratio[1], 1.6f, 1e-6f);
}

TEST(Metrics, CountsFlippedFaceAgainstPatchMajority) {
  // 2x2 cells; moving the UV of corner vertex (2,2), used only by the last upper triangle
  // (2,1) (2,2) (1,2), to (0.5, 0.5) inverts that triangle: signed area 0.5 * ((0.5-2)(2-1) -
  // (1-2)(0.5-1)) = -1. UVs stay shared, so it is still one patch.
  const Mesh mesh = grid(2, 2, Diagonal::kFalling);
  auto uv = corner_uvs(mesh, [](float x, float y) {
    return (x == 2 && y == 2) ? std::pair{0.5f, 0.5f} : std::pair{x, y};
  });
  UvMetrics m = metrics_of(mesh, uv);
  EXPECT_EQ(m.patches, 1u);
  EXPECT_EQ(m.flipped, 1u);
  EXPECT_EQ(m.zero_uv_area_faces, 0u);
  EXPECT_EQ(m.seam_edges, 0u);

  // With one explicit patch, a face whose UVs are collinear counts as flipped too.
  const std::vector<uint32_t> one_patch(mesh.face_count(), 0);
  uv = corner_uvs(mesh, [](float x, float y) { return std::pair{x, y}; });
  uv[0] = uv[2] = uv[4] = 0;  // face 0: u = 0 at all three corners
  m = metrics_of(mesh, uv, one_patch);
  EXPECT_EQ(m.flipped, 1u);
  EXPECT_EQ(m.zero_uv_area_faces, 1u);
  EXPECT_TRUE(std::isfinite(m.l2_stretch));
  EXPECT_TRUE(std::isfinite(m.linf_stretch));

  // A mirrored patch is not flipped: the majority of its own faces sets the orientation.
  uv = corner_uvs(mesh, [](float x, float y) { return std::pair{-x, y}; });
  m = metrics_of(mesh, uv);
  EXPECT_EQ(m.flipped, 0u);
}

// Two triangles sharing the diagonal (1,0)-(0,1); T1's UVs are T0's shifted by (du, dv) px.
// The diagonal is the only seam: ratio sqrt(2) / (4 + sqrt(2)).
UvMetrics seam_case(float du, float dv, MetricsOptions options = {}) {
  Mesh mesh;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  mesh.indices = {0, 1, 2, 1, 3, 2};
  const float s = 100;
  const std::vector<float> uv = {0, 0, s, 0, 0, s, s + du, dv, s + du, s + dv, du, s + dv};
  return metrics_of(mesh, uv, {}, options);
}

TEST(Metrics, SeamGapIsTheToroidalDistance) {
  UvMetrics m = seam_case(30, 40);
  EXPECT_EQ(m.seam_edges, 1u);
  EXPECT_EQ(m.patches, 2u);
  EXPECT_NEAR(m.seam_length_ratio, std::sqrt(2.0) / (4 + std::sqrt(2.0)), 1e-9);
  EXPECT_NEAR(m.seam_gap_px, 50.0, 1e-9);
  EXPECT_EQ(m.seam_invisible_ratio, 0.0);

  // 300 px along u on a 512 px texture is 212 px the other way round.
  m = seam_case(300, 0);
  EXPECT_NEAR(m.seam_gap_px, 212.0, 1e-9);

  // A whole number of periods: still a seam (UVs differ) but the texture matches across it.
  m = seam_case(512, -1024);
  EXPECT_EQ(m.seam_edges, 1u);
  EXPECT_NEAR(m.seam_gap_px, 0.0, 1e-9);
  EXPECT_EQ(m.seam_invisible_ratio, 1.0);

  // Period from the options: 256 x 128 texture, shift (256, 128.5) -> gap 0.5 px, invisible.
  m = seam_case(256, 128.5f, MetricsOptions{256, 128});
  EXPECT_NEAR(m.seam_gap_px, 0.5, 1e-6);
  EXPECT_EQ(m.seam_invisible_ratio, 1.0);
}

// A face wound against its neighbours: the topology leaves its three interior edges unpaired, yet
// the surface goes on across them. With the same UVs on both sides they are no seam; with its own
// UVs, half a repeat off, they are visible seams, counted once each in the total edge length.
TEST(Metrics, FacesWoundAgainstTheirNeighboursStillHaveSeams) {
  Mesh mesh = grid(3, 3, Diagonal::kFalling);
  const size_t flipped = 8;  // the middle cell's first triangle: all three edges interior
  std::swap(mesh.indices[3 * flipped + 1], mesh.indices[3 * flipped + 2]);
  const Topology topology = build_topology(mesh);
  ASSERT_EQ(topology.inconsistent_edges, 3u);
  auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{100 * x, 100 * y}; });
  UvMetrics m = metrics_of(mesh, uv);
  EXPECT_EQ(m.seam_edges, 0u);
  EXPECT_EQ(m.visible_seam_ratio, 0.0);
  const UvMetrics continuous = m;
  for (size_t c = 3 * flipped; c < 3 * flipped + 3; ++c) uv[2 * c] += 256;  // half a 512 px repeat
  m = metrics_of(mesh, uv);
  EXPECT_EQ(m.seam_edges, 3u);
  EXPECT_NEAR(m.seam_gap_px, 256.0, 1e-9);
  EXPECT_GT(m.visible_seam_ratio, 0.0);
  EXPECT_EQ(m.visible_seam_ratio, m.seam_length_ratio);
  // The edge lengths sum as if the face were wound as its neighbours: 2 + sqrt(2) of seams over
  // 24 unit edges and 9 diagonals.
  EXPECT_NEAR(m.seam_length_ratio, (2 + std::sqrt(2.0)) / (24 + 9 * std::sqrt(2.0)), 1e-9);
  EXPECT_EQ(continuous.seam_length_ratio, 0.0);
}

// The lattice gap takes one whole-repeat offset for both ends of an edge, and the larger end.
TEST(Metrics, SeamGapUsesOneLatticeOffsetForBothEnds) {
  const MetricsOptions options;  // 512 x 512 px
  const float fa[2] = {0, 0}, fb[2] = {10, 0};
  // g's side shifted by (512, 0) at a and (512.6, 0) at b: k = (512, 0), gap 0.6 px: invisible.
  const float ga[2] = {-512, 0}, gb[2] = {10 - 512.6f, 0};
  EXPECT_NEAR(seam_gap_px(fa, fb, ga, gb, options), 0.6, 1e-4);
  // Offsets (300, 0) and (-212, 0) are each 212 px from the lattice, but no single offset fits
  // both ends: k = round(44 / 512) = 0, gap max(300, 212) = 300.
  const float ga2[2] = {-300, 0}, gb2[2] = {10 + 212, 0};
  EXPECT_NEAR(seam_gap_px(fa, fb, ga2, gb2, options), 300.0, 1e-4);
}

// g's side turned by a quarter turn and shifted by whole repeats: a seam under any texture, but
// invisible under a 4-fold symmetric one.
TEST(Metrics, QuarterTurnIsInvisibleOnlyWithFourfoldSymmetry) {
  Mesh mesh;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  mesh.indices = {0, 1, 2, 1, 3, 2};
  const float s = 100;
  // Face 0 identity; face 1 rotated by +90 degrees ((u, v) -> (-v, u)) then shifted by (1024, 512).
  const auto turned = [&](float x, float y) { return std::pair{-y * s + 1024, x * s + 512}; };
  std::vector<float> uv = {0, 0, s, 0, 0, s};
  for (const auto& [x, y] : {std::pair{1.f, 0.f}, std::pair{1.f, 1.f}, std::pair{0.f, 1.f}}) {
    const auto [u, v] = turned(x, y);
    uv.push_back(u);
    uv.push_back(v);
  }
  UvMetrics m = metrics_of(mesh, uv);
  EXPECT_EQ(m.seam_edges, 1u);
  EXPECT_EQ(m.seam_invisible_ratio, 0.0);
  EXPECT_GT(m.visible_seam_ratio, 0.0);
  MetricsOptions four;
  four.symmetry = 4;
  m = metrics_of(mesh, uv, {}, four);
  EXPECT_EQ(m.seam_edges, 1u);
  EXPECT_EQ(m.seam_invisible_ratio, 1.0);
  EXPECT_EQ(m.visible_seam_ratio, 0.0);

  four.texture_height_px = 256;  // quarter turns need a square texture
  UvMetrics unused;
  EXPECT_EQ(compute_uv_metrics(mesh, build_topology(mesh), uv, {}, four, unused).code(), ErrorCode::kInvalidArgument);
}

// A cut from the border into a 4x4 grid along y = 2, stopping at the interior vertex (2, 2), then
// a second cut down from (1, 2) to the border: the first cut's tip is a dangling end, (1, 2) a
// branch point; vertices on the border are not counted. All cut edges are visible (30 px gap).
TEST(Metrics, CountsDanglingEndsAndBranchPointsOfVisibleSeams) {
  const Mesh mesh = grid(4, 4, Diagonal::kFalling);
  std::vector<float> uv = corner_uvs(mesh, [](float x, float y) { return std::pair{100 * x, 100 * y}; });
  const auto move_corners = [&](auto&& face_selected, auto&& vertex_selected, float du, float dv) {
    for (size_t c = 0; c < mesh.indices.size(); ++c) {
      const size_t f = c / 3;
      float cx = 0, cy = 0;
      for (int k = 0; k < 3; ++k) {
        cx += mesh.positions[3 * size_t{mesh.indices[3 * f + k]}] / 3;
        cy += mesh.positions[3 * size_t{mesh.indices[3 * f + k]} + 1] / 3;
      }
      const float* p = &mesh.positions[3 * size_t{mesh.indices[c]}];
      if (face_selected(cx, cy) && vertex_selected(p[0], p[1])) {
        uv[2 * c] += du;
        uv[2 * c + 1] += dv;
      }
    }
  };
  // Horizontal cut: faces above y = 2 move their corners on y = 2 with x < 2 up by 30 px.
  move_corners([](float, float cy) { return cy > 2; }, [](float x, float y) { return y == 2 && x < 2; }, 0, 30);
  UvMetrics m = metrics_of(mesh, uv);
  EXPECT_EQ(m.visible_dangling_ends, 1u);  // (2, 2); (0, 2) is on the border
  EXPECT_EQ(m.visible_branch_points, 0u);
  EXPECT_NEAR(m.visible_seam_ratio, m.seam_length_ratio, 1e-12);
  EXPECT_EQ(m.visible_off_sharp_ratio, m.visible_seam_ratio);  // flat: no sharp edge

  // Vertical cut below (1, 2): faces left of x = 1 (and below y = 2) move their corners on x = 1
  // with y < 2 left by 30 px. (1, 2) now has three visible seam edges.
  move_corners([](float cx, float cy) { return cx < 1 && cy < 2; }, [](float x, float y) { return x == 1 && y < 2; },
               -30, 0);
  m = metrics_of(mesh, uv);
  EXPECT_EQ(m.visible_dangling_ends, 1u);
  EXPECT_EQ(m.visible_branch_points, 1u);
}

// Visible seams on a sharp edge (a fold of 90 degrees) are not counted as off sharp edges.
TEST(Metrics, VisibleSeamsOnSharpEdgesAreNotOffSharp) {
  Mesh mesh;  // two triangles folded by 90 degrees along the edge (0,0,0)-(0,1,0)
  mesh.positions = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
  mesh.indices = {0, 2, 1, 0, 1, 3};
  const std::vector<float> uv = {0, 0, 100, 0, 0, 100, 40, 0, 40, 100, -60, 0};
  MetricsOptions options;
  UvMetrics m = metrics_of(mesh, uv, {}, options);
  EXPECT_EQ(m.seam_edges, 1u);
  EXPECT_GT(m.visible_seam_ratio, 0.0);
  EXPECT_EQ(m.visible_off_sharp_ratio, 0.0);
  options.sharp_angle_deg = 95;  // now the fold is not sharp
  m = metrics_of(mesh, uv, {}, options);
  EXPECT_EQ(m.visible_off_sharp_ratio, m.visible_seam_ratio);
}

TEST(Metrics, DerivesPatchesOfAMeshCutInTwo) {
  // 4x2 cells; the right half (x > 2, and x = 2 for faces of the right half) is shifted by 1000 px.
  const Mesh mesh = grid(4, 2, Diagonal::kFalling);
  std::vector<float> uv(2 * mesh.indices.size());
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    float cx = 0;
    for (int k = 0; k < 3; ++k) cx += mesh.positions[3 * size_t{mesh.indices[3 * f + k]}];
    const float shift = cx / 3 > 2 ? 1000.0f : 0.0f;
    for (int k = 0; k < 3; ++k) {
      const float* p = &mesh.positions[3 * size_t{mesh.indices[3 * f + k]}];
      uv[2 * (3 * f + k)] = 10 * p[0] + shift;
      uv[2 * (3 * f + k) + 1] = 10 * p[1];
    }
  }
  const Topology topology = build_topology(mesh);
  std::vector<uint32_t> patch;
  EXPECT_EQ(derive_patches(mesh, topology, uv, patch), 2u);
  ASSERT_EQ(patch.size(), mesh.face_count());
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const float cx =
        (mesh.positions[3 * size_t{mesh.indices[3 * f]}] + mesh.positions[3 * size_t{mesh.indices[3 * f + 1]}] +
         mesh.positions[3 * size_t{mesh.indices[3 * f + 2]}]) /
        3;
    EXPECT_EQ(patch[f], cx > 2 ? 1u : 0u) << "face " << f;  // numbered in order of lowest face
  }
  const UvMetrics m = metrics_of(mesh, uv);
  EXPECT_EQ(m.patches, 2u);
  EXPECT_EQ(m.seam_edges, 2u);  // the cut x = 2 crosses two cells
  // 1000 px = 1000 - 2*512 = -24 px on the torus.
  EXPECT_NEAR(m.seam_gap_px, 24.0, 1e-6);
}

// compute_stored_uv_metrics measures UVs in repeats as a file holds them: on spot's own atlas the
// figures of compute_uv_metrics in pixels with derived patches; on spot split along its UV seams
// (vertices at identical positions, as a .glb or .ply stores it) the same figures again, the split
// vertices joined, where compute_uv_metrics of the split mesh sees boundaries and no seam.
TEST(Metrics, StoredMetricsJoinIdenticalPositionsAndDerivePatches) {
  Mesh spot;
  ASSERT_TRUE(load_mesh(std::string(TAILOR_TEST_DATA) + "/meshes/spot.obj", spot).is_ok());
  const float size = 256;  // a power of two: repeats times the size are exact pixels
  std::vector<float> px(spot.corner_uvs.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = spot.corner_uvs[i] * size;
  const MetricsOptions options{size, size};
  const UvMetrics reference = metrics_of(spot, px, {}, options);
  ASSERT_GT(reference.seam_edges, 0u);
  ASSERT_GT(reference.patches, 1u);

  UvMetrics stored;
  StoredSurface surface;
  const Topology topology = build_topology(spot);
  ASSERT_TRUE(compute_stored_uv_metrics(spot, &topology, spot.corner_uvs, options, stored, &surface).is_ok());
  EXPECT_EQ(surface.welded_vertices, 0u);
  EXPECT_EQ(surface.boundary_edges, topology.boundary_edges);
  EXPECT_EQ(stored.patches, reference.patches);
  EXPECT_EQ(stored.seam_edges, reference.seam_edges);
  EXPECT_EQ(stored.seam_gap_px, reference.seam_gap_px);
  EXPECT_EQ(stored.visible_dangling_ends, reference.visible_dangling_ends);
  EXPECT_EQ(stored.stretch, reference.stretch);

  SplitMesh split;
  split_vertices(spot, spot.corner_uvs, split);
  Mesh split_mesh;
  split_mesh.positions = split.positions;
  split_mesh.indices = split.indices;
  ASSERT_GT(split_mesh.vertex_count(), spot.vertex_count());
  EXPECT_EQ(metrics_of(split_mesh, px, {}, options).seam_edges, 0u);  // every seam became a boundary
  UvMetrics joined;
  ASSERT_TRUE(compute_stored_uv_metrics(split_mesh, nullptr, spot.corner_uvs, options, joined, &surface).is_ok());
  EXPECT_EQ(surface.welded_vertices, split_mesh.vertex_count() - spot.vertex_count());
  EXPECT_EQ(surface.boundary_edges, topology.boundary_edges);
  EXPECT_EQ(joined.patches, reference.patches);
  EXPECT_EQ(joined.seam_edges, reference.seam_edges);
  EXPECT_EQ(joined.seam_length_ratio, reference.seam_length_ratio);
  EXPECT_EQ(joined.seam_invisible_ratio, reference.seam_invisible_ratio);
  EXPECT_EQ(joined.visible_dangling_ends, reference.visible_dangling_ends);
  EXPECT_EQ(joined.visible_branch_points, reference.visible_branch_points);
}

// A double-sided sheet (a leaf, a cloth): the grid and its reversed copy on vertices of their own at
// the same positions. Joined by position its inner edges have four faces; its own vertex ids still
// pair each side, and the two sides meet along the rim: one patch without seams (144 single-face
// patches when the four-face edges are left unpaired).
TEST(Metrics, StoredMetricsKeepBothSidesOfADoubleSidedSheet) {
  const Mesh side = grid(6, 6, Diagonal::kRising);
  Mesh sheet = side;
  const uint32_t offset = static_cast<uint32_t>(side.vertex_count());
  sheet.positions.insert(sheet.positions.end(), side.positions.begin(), side.positions.end());
  for (size_t f = 0; f < side.face_count(); ++f)
    for (const int k : {0, 2, 1}) sheet.indices.push_back(side.indices[3 * f + static_cast<size_t>(k)] + offset);
  const std::vector<float> repeats = corner_uvs(sheet, [](float x, float y) { return std::pair{x / 8, y / 8}; });
  UvMetrics m;
  StoredSurface surface;
  ASSERT_TRUE(compute_stored_uv_metrics(sheet, nullptr, repeats, MetricsOptions{}, m, &surface).is_ok());
  EXPECT_EQ(surface.welded_vertices, side.vertex_count());
  EXPECT_GT(surface.nonmanifold_edges, 0u);  // true of the joined surface
  EXPECT_EQ(m.patches, 1u);
  EXPECT_EQ(m.single_face_patches, 0u);
  EXPECT_EQ(m.seam_edges, 0u);
  EXPECT_EQ(m.visible_seam_ratio, 0.0);
}

TEST(Metrics, DegenerateFacesAreSkippedWithoutNaN) {
  Mesh mesh = grid(2, 1, Diagonal::kFalling);
  // A zero-area face on three collinear vertices (0,0) (1,0) (2,0).
  mesh.indices.insert(mesh.indices.end(), {0, 1, 2});
  auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{5 * x, 5 * y}; });
  const UvMetrics m = metrics_of(mesh, uv);
  EXPECT_EQ(m.faces, 5u);
  EXPECT_EQ(m.degenerate_faces, 1u);
  EXPECT_EQ(m.flipped, 0u);
  for (double v : {m.stretch, m.stretch_area_weighted, m.distortion_deg, m.l2_stretch, m.linf_stretch,
                   m.seam_length_ratio, m.seam_gap_px, m.seam_invisible_ratio})
    EXPECT_TRUE(std::isfinite(v));
  EXPECT_NEAR(m.stretch, 0.0, 1e-9);
  EXPECT_NEAR(m.l2_stretch, 1.0, 1e-9);

  std::vector<float> ratio;
  face_area_stretch(mesh, uv, ratio);
  ASSERT_EQ(ratio.size(), 5u);
  EXPECT_FLOAT_EQ(ratio[4], 1.0f);  // neutral
  EXPECT_NEAR(ratio[0], 1.0f, 1e-6f);
}

// A sliver whose height (2^-21) is below what floats resolve at its coordinates (2^-22 x 3): its
// orientation is its corners' rounding, so reversed UVs do not make it flipped, nor its area ratio
// the stretch. The same sliver moved near the origin, where floats resolve it, is measured.
TEST(Metrics, SliversBelowFloatResolutionAreDegenerate) {
  Mesh mesh = grid(2, 1, Diagonal::kFalling);  // 4 faces over [0,2] x [0,1]
  const uint32_t base = static_cast<uint32_t>(mesh.vertex_count());
  mesh.positions.insert(mesh.positions.end(), {2.f, 3.f, 0.f, 3.f, 3.f, 0.f, 2.5f, 3.f + 0x1p-21f, 0.f});
  mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
  auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{50 * x, 50 * y}; });
  uv[2 * 14 + 1] -= 20;  // the sliver's apex below its base in UV: wide, and reversed
  const std::vector<uint32_t> one_patch(5, 0);
  UvMetrics m = metrics_of(mesh, uv, one_patch);
  EXPECT_EQ(m.degenerate_faces, 1u);
  EXPECT_EQ(m.flipped, 0u);
  EXPECT_NEAR(m.stretch, 0.0, 1e-6);
  EXPECT_NEAR(m.linf_stretch, 1.0, 1e-6);
  for (size_t v = base; v < mesh.vertex_count(); ++v) {  // to x in [0.25, 1.25], y = 0.25: exact moves
    mesh.positions[3 * v] -= 1.75f;
    mesh.positions[3 * v + 1] -= 2.75f;
  }
  ASSERT_EQ(mesh.positions[3 * (base + 2) + 1], 0.25f + 0x1p-21f);
  m = metrics_of(mesh, uv, one_patch);
  EXPECT_EQ(m.degenerate_faces, 0u);
  EXPECT_EQ(m.flipped, 1u);
}

TEST(Metrics, RejectsBadInput) {
  const Mesh mesh = grid(1, 1, Diagonal::kFalling);
  const Topology topology = build_topology(mesh);
  auto uv = corner_uvs(mesh, [](float x, float y) { return std::pair{x, y}; });
  UvMetrics m;
  EXPECT_EQ(compute_uv_metrics(mesh, topology, std::span<const float>(uv).first(4), {}, {}, m).code(),
            ErrorCode::kInvalidArgument);
  const std::vector<uint32_t> short_patch = {0};
  EXPECT_EQ(compute_uv_metrics(mesh, topology, uv, short_patch, {}, m).code(), ErrorCode::kInvalidArgument);
  const std::vector<uint32_t> bad_patch = {0, 7};
  EXPECT_EQ(compute_uv_metrics(mesh, topology, uv, bad_patch, {}, m).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(compute_uv_metrics(mesh, topology, uv, {}, MetricsOptions{0, 512}, m).code(), ErrorCode::kInvalidArgument);
  auto nan_uv = uv;
  nan_uv[3] = std::nanf("");
  // Bad data rather than a bad call: the CLI reports these as bad input (exit 1).
  EXPECT_EQ(compute_uv_metrics(mesh, topology, nan_uv, {}, {}, m).code(), ErrorCode::kInvalidMesh);
  const std::vector<float> collapsed(uv.size(), 3.0f);
  EXPECT_EQ(compute_uv_metrics(mesh, topology, collapsed, {}, {}, m).code(), ErrorCode::kInvalidMesh);
}

// A file's UV that is finite but overflows when scaled to pixels (vt 1e38 at 512 px) is named as
// such, at its corner, not as a UV that is not finite.
TEST(Metrics, StoredUvTooLargeForPixelsIsNamed) {
  const Mesh mesh = grid(1, 1, Diagonal::kFalling);
  auto repeats = corner_uvs(mesh, [](float x, float y) { return std::pair{x, y}; });
  repeats[2 * 4] = 1e38f;
  UvMetrics m;
  const Status s = compute_stored_uv_metrics(mesh, nullptr, repeats, MetricsOptions{}, m);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.what(), "UV is too large to scale to the texture's pixels");
  EXPECT_EQ(s.where(), "corner 4");
  repeats[2 * 4] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(compute_stored_uv_metrics(mesh, nullptr, repeats, MetricsOptions{}, m).what(), "UV is not finite");
}

}  // namespace
}  // namespace tailor
