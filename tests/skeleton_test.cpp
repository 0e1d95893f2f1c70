// Skeleton orientation (AxisSource::kSkeleton, src/surface/skeleton.h): the texture axis follows
// the curve skeleton (thesis figures 4.4 and 4.6).
#include "surface/skeleton.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "support/fixtures.h"
#include "tailor/orientation.h"
#include "tailor/topology.h"

namespace tailor {
namespace {

using test::load_test_mesh;

constexpr double kPi = 3.14159265358979323846;

// A tube of radius r around a half circle of radius R in the xy plane (angle 0..pi), with a fan
// cap at each end unless `open`. Ring i, vertex j; faces outward. The centre line's tangent at
// angle t is (-sin t, cos t, 0): a bent limb, which no single axis follows.
Mesh bent_tube(bool open, int rings = 60, int around = 16, double R = 3.0, double r = 0.5) {
  Mesh m;
  auto add = [&](double x, double y, double z) {
    m.positions.insert(m.positions.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)});
  };
  for (int i = 0; i <= rings; ++i) {
    const double t = kPi * i / rings;
    for (int j = 0; j < around; ++j) {
      const double phi = 2 * kPi * j / around;
      const double radial = R + r * std::cos(phi);
      add(radial * std::cos(t), radial * std::sin(t), r * std::sin(phi));
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>(i * around + (j % around)); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < around; ++j)
      m.indices.insert(m.indices.end(),
                       {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
  if (!open) {
    const uint32_t start = static_cast<uint32_t>(m.vertex_count()), end = start + 1;
    add(R, 0, 0);
    add(-R, 0, 0);
    for (int j = 0; j < around; ++j) {
      m.indices.insert(m.indices.end(), {start, id(0, j), id(0, j + 1)});
      m.indices.insert(m.indices.end(), {end, id(rings, j + 1), id(rings, j)});
    }
  }
  return m;
}

FaceFrames frames_of(const Mesh& mesh, AxisSource axis, uint32_t threads = 0) {
  OrientationOptions options;
  options.axis = axis;
  options.threads = threads;
  FaceFrames frames;
  const Status s = compute_orientation(mesh, build_topology(mesh), options, frames);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return frames;
}

// Per tube face (caps and the first/last 20 degrees left out): o . tangent at the face's angle.
std::vector<double> tube_alignment(const Mesh& mesh, const FaceFrames& frames) {
  std::vector<double> dots;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) c[a] += mesh.positions[3 * size_t{mesh.indices[3 * f + k]} + a] / 3.0;
    const double t = std::atan2(c[1], c[0]);
    if (t < kPi / 9 || t > kPi - kPi / 9) continue;
    const float* of = &frames.orientation[3 * f];
    dots.push_back(-std::sin(t) * of[0] + std::cos(t) * of[1]);
  }
  return dots;
}

size_t aligned(const std::vector<double>& dots, double cos_limit) {
  return static_cast<size_t>(
      std::count_if(dots.begin(), dots.end(), [&](double d) { return std::abs(d) > cos_limit; }));
}

TEST(Skeleton, BentTubeFollowsItsCentreLineWherePcaCannot) {
  const Mesh tube = bent_tube(false);
  const FaceFrames skeleton = frames_of(tube, AxisSource::kSkeleton);
  EXPECT_GT(skeleton.skeleton_edges, 3u);
  EXPECT_EQ(skeleton.skeleton_closed_holes, 0u);
  EXPECT_EQ(skeleton.skeleton_pca_faces, 0u);
  const std::vector<double> along = tube_alignment(tube, skeleton);
  ASSERT_GT(along.size(), 1000u);
  // Within 15 degrees of the local tangent nearly everywhere, and one sign all along the tube
  // (a sign flip would turn the texture by 180 degrees and cut a seam).
  EXPECT_GT(aligned(along, std::cos(kPi / 12)), along.size() * 95 / 100);
  const size_t positive =
      static_cast<size_t>(std::count_if(along.begin(), along.end(), [](double d) { return d > 0; }));
  EXPECT_TRUE(positive == 0 || positive == along.size()) << positive << " of " << along.size();
  // The PCA field is one axis for the whole half circle: most of the tube is far from the tangent.
  const std::vector<double> pca = tube_alignment(tube, frames_of(tube, AxisSource::kPca));
  EXPECT_LT(aligned(pca, std::cos(kPi / 12)), pca.size() / 2);
}

TEST(Skeleton, OpenTubeIsClosedFirstAndTinyComponentsKeepPca) {
  Mesh tube = bent_tube(true);
  // A lone triangle beside the tube: too small to skeletonize, it keeps the PCA field.
  const uint32_t base = static_cast<uint32_t>(tube.vertex_count());
  tube.positions.insert(tube.positions.end(), {10.f, 0.f, 0.f, 11.f, 0.f, 0.f, 10.f, 1.f, 0.f});
  tube.indices.insert(tube.indices.end(), {base, base + 1, base + 2});
  const FaceFrames frames = frames_of(tube, AxisSource::kSkeleton);
  EXPECT_EQ(frames.skeleton_closed_holes, 2u);
  EXPECT_EQ(frames.skeleton_pca_faces, 1u);
  const std::vector<double> along = tube_alignment(tube, frames);
  EXPECT_GT(aligned(along, std::cos(kPi / 12)), along.size() * 95 / 100);
  for (float v : frames.orientation) ASSERT_TRUE(std::isfinite(v));
}

// The flow's linear solve fills in a dense block among a vertex's neighbours, so a vertex of n
// neighbours costs n^2 memory: a fan cap of 129 faces, or an open end of 129 edges closed with one,
// is replaced by rings of fewer vertices before the flow (129 -> 65 -> 33, odd counts twice), and
// the skeleton still runs along the tube.
TEST(Skeleton, LongHolesAndVerticesOfManyNeighboursAreClosedWithRings) {
  for (const bool open : {true, false}) {
    const Mesh tube = bent_tube(open, 120, 129);
    internal::CurveSkeleton skeleton;
    ASSERT_TRUE(internal::compute_curve_skeleton(tube, build_topology(tube), skeleton).is_ok());
    EXPECT_EQ(skeleton.component_done, std::vector<uint8_t>{1}) << "open " << open;
    EXPECT_EQ(skeleton.closed_holes, open ? 2u : 0u);
    EXPECT_GT(skeleton.flow_max_valence, 6u);
    EXPECT_LE(skeleton.flow_max_valence, 64u) << "open " << open;
    const std::vector<double> along = tube_alignment(tube, frames_of(tube, AxisSource::kSkeleton));
    ASSERT_GT(along.size(), 1000u);
    EXPECT_GT(aligned(along, std::cos(kPi / 12)), along.size() * 95 / 100) << "open " << open;
  }
}

// A wavy sheet whose vertices are snapped to a coarse grid: many faces with collinear or
// coincident corners, on which CGAL's inside test (the flow's medial centering) finds no ray that
// misses every edge. The flow contracts without the centering and every face gets a finite frame.
TEST(Skeleton, DegenerateFacesDoNotStopTheFlow) {
  Mesh sheet;
  const int n = 20;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = static_cast<float>(i) / n, y = static_cast<float>(j) / n;
      sheet.positions.insert(sheet.positions.end(), {std::round(7.f * x), std::round(7.f * y),
                                                     std::round(1.43f * std::sin(5.f * x) * std::cos(4.f * y))});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = static_cast<uint32_t>(j * (n + 1) + i);
      sheet.indices.insert(sheet.indices.end(), {a, a + 1, a + n + 2, a, a + n + 2, a + n + 1});
    }
  const FaceFrames frames = frames_of(sheet, AxisSource::kSkeleton);
  ASSERT_EQ(frames.orientation.size(), 3 * sheet.face_count());
  for (float v : frames.orientation) ASSERT_TRUE(std::isfinite(v));
}

TEST(Skeleton, HorseLegsRunUpAndDownAndThreadsDoNotMatter) {
  // The shared horse stands on z, its body along y: its legs (the lowest quarter of its height)
  // should get an orientation close to vertical, which the PCA axis (the body) is not.
  const Mesh horse = load_test_mesh("horse.ply");
  const FaceFrames one = frames_of(horse, AxisSource::kSkeleton, 1);
  const FaceFrames pca = frames_of(horse, AxisSource::kPca);
  float lo = INFINITY, hi = -INFINITY;
  for (size_t v = 0; v < horse.vertex_count(); ++v)
    lo = std::min(lo, horse.positions[3 * v + 2]), hi = std::max(hi, horse.positions[3 * v + 2]);
  size_t legs = 0, skeleton_vertical = 0, pca_vertical = 0;
  for (size_t f = 0; f < horse.face_count(); ++f) {
    float z = 0;
    for (int k = 0; k < 3; ++k) z += horse.positions[3 * size_t{horse.indices[3 * f + k]} + 2] / 3.f;
    if (z > lo + 0.25f * (hi - lo)) continue;
    ++legs;
    // Vertical as far as the face allows: up projected onto the face plane.
    const float* n = &one.normal[3 * f];
    double up[3] = {-n[2] * n[0], -n[2] * n[1], 1.0 - n[2] * n[2]};
    const double len = std::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    if (len < 0.5) continue;  // a face looking up or down (hooves): no vertical to follow
    auto cosine = [&](const float* o) { return std::abs(o[0] * up[0] + o[1] * up[1] + o[2] * up[2]) / len; };
    skeleton_vertical += cosine(&one.orientation[3 * f]) > std::cos(kPi / 9);
    pca_vertical += cosine(&pca.orientation[3 * f]) > std::cos(kPi / 9);
  }
  ASSERT_GT(legs, 5000u);
  EXPECT_GT(skeleton_vertical, legs * 7 / 10) << skeleton_vertical << " of " << legs;
  EXPECT_LT(pca_vertical, legs / 4) << pca_vertical << " of " << legs;
  EXPECT_EQ(one.skeleton_pca_faces, 0u);

  const FaceFrames three = frames_of(horse, AxisSource::kSkeleton, 3);
  EXPECT_EQ(one.orientation, three.orientation);
  EXPECT_EQ(one.variation, three.variation);
  EXPECT_EQ(one.skeleton_edges, three.skeleton_edges);
}

TEST(Skeleton, SeveralOpenComponentsEachGetASkeleton) {
  // blobby-3cc: three open components (219 boundary edges).
  const Mesh blobby = load_test_mesh("blobby-3cc.off");
  const Topology topology = build_topology(blobby);
  internal::CurveSkeleton skeleton;
  ASSERT_TRUE(internal::compute_curve_skeleton(blobby, topology, skeleton).is_ok());
  EXPECT_GT(skeleton.closed_holes, 0u);
  EXPECT_EQ(skeleton.skipped_components, 0u);
  for (uint8_t done : skeleton.component_done) EXPECT_EQ(done, 1);
  for (double p : skeleton.points) ASSERT_TRUE(std::isfinite(p));
}

TEST(Skeleton, CliAxisSkeletonGivesTheSameFileForAnyThreadCount) {
  const std::string mesh = test::mesh_path("spot.obj");
  std::string out;
  for (const char* threads : {"1", "2"}) {
    const std::string glb = test::temp_path(std::string("spot_skeleton_") + threads + ".glb");
    ASSERT_EQ(test::run_command(std::string(TAILOR_BINARY) + " map " + mesh + " -q --axis skeleton --threads " +
                                    threads + " -o " + glb + " --stats " + glb + ".json",
                                out),
              0)
        << out;
  }
  EXPECT_EQ(test::read_all(test::temp_path("spot_skeleton_1.glb")),
            test::read_all(test::temp_path("spot_skeleton_2.glb")));
  EXPECT_NE(test::read_all(test::temp_path("spot_skeleton_1.glb.json")).find("\"axis\": \"skeleton\""),
            std::string::npos);
  // A misspelt axis names the values it accepts.
  EXPECT_NE(test::run_command(
                std::string(TAILOR_BINARY) + " map " + mesh + " --axis skeletn -o " + test::temp_path("bad.glb"), out),
            0);
  EXPECT_NE(out.find("--axis must be auto, pca, skeleton, x, y, z"), std::string::npos) << out;
}

}  // namespace
}  // namespace tailor
