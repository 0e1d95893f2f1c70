// Orientation field and face frames (tailor/orientation.h).
#include "tailor/orientation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "support/fixtures.h"
#include "surface/orientation_setup.h"
#include "tailor/io.h"
#include "tailor/topology.h"

namespace tailor {
namespace {

using test::box_sides;
using test::load_test_mesh;

double dot3(const float* a, const float* b) {
  return static_cast<double>(a[0]) * b[0] + static_cast<double>(a[1]) * b[1] + static_cast<double>(a[2]) * b[2];
}

FaceFrames frames_of(const Mesh& mesh, const OrientationOptions& options = {}) {
  FaceFrames frames;
  const Status s = compute_orientation(mesh, build_topology(mesh), options, frames);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return frames;
}

TEST(Orientation, PcaAxisOfElongatedBoxIsItsLongSide) {
  const FaceFrames frames = frames_of(box_sides(10.f, 1.f, 2.f, 4));
  EXPECT_GT(std::abs(frames.axis[0]), 0.999f);
  EXPECT_GT(std::abs(frames.axis2[2]), 0.999f);  // second longest side
  EXPECT_FLOAT_EQ(frames.unit_scale, 0.1f);      // 1 / longest side
  EXPECT_FLOAT_EQ(frames.origin[0], 0.f);
}

TEST(Orientation, FramesAreOrthonormalInTheFacePlaneAndRightHanded) {
  const Mesh mesh = load_test_mesh("spot.obj");
  const FaceFrames frames = frames_of(mesh);
  ASSERT_EQ(frames.face_count(), mesh.face_count());
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const float* n = &frames.normal[3 * f];
    const float* o = &frames.orientation[3 * f];
    const float* p = &frames.bitangent[3 * f];
    ASSERT_NEAR(dot3(n, n), 1.0, 1e-5);
    ASSERT_NEAR(dot3(o, o), 1.0, 1e-5);
    ASSERT_NEAR(dot3(o, n), 0.0, 1e-5);
    // p = n x o
    ASSERT_NEAR(p[0], n[1] * o[2] - n[2] * o[1], 1e-5);
    ASSERT_NEAR(p[1], n[2] * o[0] - n[0] * o[2], 1e-5);
    ASSERT_NEAR(p[2], n[0] * o[1] - n[1] * o[0], 1e-5);
  }
}

TEST(Orientation, LocalCoordinatesKeepEdgeLengthsAndCounterClockwiseOrder) {
  const Mesh mesh = load_test_mesh("fandisk.off");
  const FaceFrames frames = frames_of(mesh);
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const float* l = &frames.local[6 * f];
    for (int k = 1; k < 3; ++k) {
      const float* a = &mesh.positions[3 * mesh.indices[3 * f]];
      const float* b = &mesh.positions[3 * mesh.indices[3 * f + k]];
      const double d3 =
          std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2])) *
          frames.unit_scale;
      ASSERT_NEAR(std::hypot(l[2 * k], l[2 * k + 1]), d3, 1e-5 + 1e-4 * d3);
    }
    const double twice_area = static_cast<double>(l[2]) * l[5] - static_cast<double>(l[3]) * l[4];
    ASSERT_GT(twice_area, 0.0) << "face " << f;
    ASSERT_NEAR(0.5 * twice_area, frames.area[f], 1e-4 * frames.area[f] + 1e-12);
  }
}

TEST(Orientation, UserAxisIsProjectedAndFallsBackWhereNormal) {
  OrientationOptions options;
  options.axis = AxisSource::kUser;
  options.user_axis = {0.f, 2.f, 0.f};  // any length
  const Mesh mesh = box_sides(1.f, 1.f, 1.f, 2);
  const FaceFrames frames = frames_of(mesh, options);
  EXPECT_FLOAT_EQ(frames.axis[1], 1.f);
  uint32_t fallback = 0;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const float* n = &frames.normal[3 * f];
    const float* o = &frames.orientation[3 * f];
    if (std::abs(n[1]) > 0.9f) {
      ++fallback;  // top and bottom: y is their normal, the fallback axis is used
      EXPECT_NEAR(o[1], 0.f, 1e-6);
    } else {
      EXPECT_NEAR(o[1], 1.f, 1e-6);  // sides: o is +y itself
    }
  }
  EXPECT_EQ(fallback, frames.fallback_faces);
  EXPECT_EQ(fallback, 16u);
}

TEST(Orientation, ZeroAreaFacesGetAFiniteFrame) {
  Mesh mesh;
  mesh.positions = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0};  // vertices 0,1,2 collinear
  mesh.indices = {0, 1, 2, 0, 1, 3};
  const FaceFrames frames = frames_of(mesh);
  EXPECT_EQ(frames.degenerate_faces, 1u);
  for (float x : frames.normal) EXPECT_TRUE(std::isfinite(x));
  for (float x : frames.orientation) EXPECT_TRUE(std::isfinite(x));
  for (float x : frames.local) EXPECT_TRUE(std::isfinite(x));
  for (float x : frames.variation) EXPECT_TRUE(std::isfinite(x));
  EXPECT_NEAR(dot3(&frames.orientation[0], &frames.orientation[0]), 1.0, 1e-6);
}

TEST(Orientation, SmoothingReducesTheMeanNeighbourAngle) {
  const Mesh mesh = load_test_mesh("fertility.off");
  const Topology topology = build_topology(mesh);
  FaceFrames raw, smooth;
  ASSERT_TRUE(compute_orientation(mesh, topology, {}, raw).is_ok());
  OrientationOptions options;
  options.smooth_passes = 5;
  ASSERT_TRUE(compute_orientation(mesh, topology, options, smooth).is_ok());
  const double before = mean_neighbour_angle(topology, raw);
  const double after = mean_neighbour_angle(topology, smooth);
  EXPECT_GT(before, 0.0);
  // Part of the angle is the surface's own curvature (o lives in different planes), so smoothing
  // cannot remove it all; measured on fertility: 0.145 rad -> 0.127 after 5 passes.
  EXPECT_LT(after, 0.95 * before);
  FaceFrames smoother;
  options.smooth_passes = 20;
  ASSERT_TRUE(compute_orientation(mesh, topology, options, smoother).is_ok());
  EXPECT_LT(mean_neighbour_angle(topology, smoother), after);
  // Still unit and in the face plane after smoothing.
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    ASSERT_NEAR(dot3(&smooth.orientation[3 * f], &smooth.orientation[3 * f]), 1.0, 1e-5);
    ASSERT_NEAR(dot3(&smooth.orientation[3 * f], &smooth.normal[3 * f]), 0.0, 1e-5);
  }
}

TEST(Orientation, VariationSumsNeighbourAngles) {
  // Each side of the box is a separate flat sheet: one orientation per sheet, so every face's
  // variation is ~0 (acos near 1 amplifies float rounding to ~1e-4 rad).
  OrientationOptions options;
  options.axis = AxisSource::kUser;
  options.user_axis = {1.f, 2.f, 3.f};
  const FaceFrames frames = frames_of(box_sides(1.f, 1.f, 1.f, 3), options);
  for (float v : frames.variation) EXPECT_LT(v, 3e-3f);
  // Two faces folded by 90 degrees along their shared edge, axis across the fold: o turns by
  // 90 degrees, so each face's variation is pi/2.
  Mesh fold;
  fold.positions = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
  fold.indices = {0, 2, 1, 0, 1, 3};  // z = 0 (normal +z) and x = 0 (normal +x), sharing edge 0-1
  options.user_axis = {1.f, 0.f, 1.f};
  const FaceFrames folded = frames_of(fold, options);
  EXPECT_NEAR(folded.variation[0], std::acos(-1.0) / 2, 1e-5);
  EXPECT_NEAR(folded.variation[1], std::acos(-1.0) / 2, 1e-5);
}

TEST(Orientation, ThreadCountDoesNotChangeTheFrames) {
  const Mesh mesh = load_test_mesh("horse.ply");
  const Topology topology = build_topology(mesh);
  FaceFrames one, three;
  OrientationOptions options;
  options.threads = 1;
  ASSERT_TRUE(compute_orientation(mesh, topology, options, one).is_ok());
  options.threads = 3;  // uneven ranges on purpose
  ASSERT_TRUE(compute_orientation(mesh, topology, options, three).is_ok());
  EXPECT_EQ(one.normal, three.normal);
  EXPECT_EQ(one.orientation, three.orientation);
  EXPECT_EQ(one.bitangent, three.bitangent);
  EXPECT_EQ(one.area, three.area);
  EXPECT_EQ(one.local, three.local);
  EXPECT_EQ(one.anchor, three.anchor);
  EXPECT_EQ(one.variation, three.variation);
  EXPECT_EQ(one.fallback_faces, three.fallback_faces);
  EXPECT_EQ(one.degenerate_faces, three.degenerate_faces);
}

TEST(Orientation, RejectsBadOptionsAndMismatchedTopology) {
  const Mesh mesh = box_sides(1.f, 1.f, 1.f, 1);
  const Topology topology = build_topology(mesh);
  FaceFrames frames;
  OrientationOptions options;
  options.axis = AxisSource::kUser;
  options.user_axis = {0.f, 0.f, 0.f};
  EXPECT_EQ(compute_orientation(mesh, topology, options, frames).code(), ErrorCode::kInvalidArgument);
  options = {};
  options.smooth_passes = 5000;
  EXPECT_EQ(compute_orientation(mesh, topology, options, frames).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(compute_orientation(mesh, Topology{}, {}, frames).code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(compute_orientation(Mesh{}, Topology{}, {}, frames).code(), ErrorCode::kInvalidMesh);
}

// Distance from q to the segment [a, b], in double.
double segment_distance(const double q[3], const float* a, const float* b) {
  double d[3], aq[3], len2 = 0, t = 0;
  for (int c = 0; c < 3; ++c) {
    d[c] = static_cast<double>(b[c]) - a[c];
    aq[c] = q[c] - a[c];
    len2 += d[c] * d[c];
    t += aq[c] * d[c];
  }
  t = std::clamp(t / len2, 0.0, 1.0);
  double e2 = 0;
  for (int c = 0; c < 3; ++c) e2 += (aq[c] - t * d[c]) * (aq[c] - t * d[c]);
  return std::sqrt(e2);
}

// A stroke between two surface points of the cow: faces on it follow its direction, faces beyond
// its radius keep the axis field bit for bit.
TEST(Orientation, StrokeTurnsTheFieldNearItAndLeavesTheRestAlone) {
  const Mesh mesh = load_test_mesh("spot.obj");
  const FaceFrames plain = frames_of(mesh);
  const float* a = &mesh.positions[0];
  float longest = 0;
  for (int c = 0; c < 3; ++c) longest = std::max(longest, plain.bbox_max[c] - plain.bbox_min[c]);
  // The other end: the vertex whose distance from vertex 0 is nearest to a tenth of the mesh,
  // roughly across the field's axis (a stroke along the axis would change little).
  size_t other = 1;
  double best = INFINITY;
  for (size_t v = 1; v < mesh.vertex_count(); ++v) {
    const float* p = &mesh.positions[3 * v];
    const double d[3] = {double(p[0]) - a[0], double(p[1]) - a[1], double(p[2]) - a[2]};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double along = std::abs(d[0] * plain.axis[0] + d[1] * plain.axis[1] + d[2] * plain.axis[2]) / len;
    const double cost = std::abs(len - 0.1 * longest) / longest + along;
    if (cost < best) best = cost, other = v;
  }
  const float* b = &mesh.positions[3 * other];
  OrientationStroke stroke;
  stroke.points = {a[0], a[1], a[2], b[0], b[1], b[2]};
  stroke.radius = 0.25f * longest;
  OrientationOptions options;
  options.strokes = std::span<const OrientationStroke>(&stroke, 1);
  const FaceFrames stroked = frames_of(mesh, options);

  double t[3], t_len = 0;
  for (int c = 0; c < 3; ++c) t[c] = double(b[c]) - a[c], t_len += t[c] * t[c];
  for (double& x : t) x /= std::sqrt(t_len);
  size_t on = 0, beyond = 0, changed = 0;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    double q[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) q[c] += mesh.positions[3 * size_t{mesh.indices[3 * f + k]} + c];
    for (double& x : q) x /= 3;
    const double distance = segment_distance(q, a, b);
    const float* o = &stroked.orientation[3 * f];
    if (distance >= stroke.radius) {
      ++beyond;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(o[c], plain.orientation[3 * f + c]) << "face " << f;
      for (int c = 0; c < 6; ++c) ASSERT_EQ(stroked.local[6 * f + c], plain.local[6 * f + c]) << "face " << f;
      continue;
    }
    changed += o[0] != plain.orientation[3 * f] || o[1] != plain.orientation[3 * f + 1];
    if (distance > 0.02 * longest) continue;
    // The stroke's direction projected onto the face.
    const float* n = &stroked.normal[3 * f];
    const double tn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
    if (std::abs(tn) > 0.9) continue;  // the stroke runs into the face: no direction in its plane
    double p[3], p_len = 0;
    for (int c = 0; c < 3; ++c) p[c] = t[c] - tn * n[c], p_len += p[c] * p[c];
    const double cosine = (p[0] * o[0] + p[1] * o[1] + p[2] * o[2]) / std::sqrt(p_len);
    EXPECT_GT(cosine, std::cos(4.0 * M_PI / 180.0)) << "face " << f << " at " << distance;
    ++on;
  }
  EXPECT_GE(on, 5u);
  EXPECT_GT(beyond, mesh.face_count() / 2);
  EXPECT_GT(changed, on);
}

TEST(Orientation, StrokesAreTheSameForAnyThreadCount) {
  const Mesh mesh = load_test_mesh("spot.obj");
  std::vector<OrientationStroke> strokes(2);
  for (size_t i = 0; i < 2; ++i) {
    for (size_t v = 0; v < 40; ++v)
      for (int c = 0; c < 3; ++c) strokes[i].points.push_back(mesh.positions[3 * (v * 37 + i * 11) + c]);
    strokes[i].radius = 0.2f;
  }
  OrientationOptions options;
  options.strokes = strokes;
  options.threads = 1;
  const FaceFrames one = frames_of(mesh, options);
  options.threads = 3;
  const FaceFrames three = frames_of(mesh, options);
  EXPECT_EQ(one.orientation, three.orientation);
  EXPECT_EQ(one.local, three.local);
  EXPECT_NE(one.orientation, frames_of(mesh).orientation);
}

TEST(Orientation, RejectsBadStrokes) {
  const Mesh mesh = load_test_mesh("spot.obj");
  const Topology topology = build_topology(mesh);
  FaceFrames frames;
  auto code_of = [&](OrientationStroke stroke) {
    OrientationOptions options;
    options.strokes = std::span<const OrientationStroke>(&stroke, 1);
    const Status s = compute_orientation(mesh, topology, options, frames);
    EXPECT_NE(s.message().find("stroke 0"), std::string::npos) << s.message();
    return s.code();
  };
  EXPECT_EQ(code_of({{0.f, 0.f, 0.f}, 1.f}), ErrorCode::kInvalidArgument);                      // one point
  EXPECT_EQ(code_of({{0.f, 0.f, 0.f, 1.f, 0.f}, 1.f}), ErrorCode::kInvalidArgument);            // not triples
  EXPECT_EQ(code_of({{0.f, 0.f, 0.f, 1.f, NAN, 0.f}, 1.f}), ErrorCode::kInvalidArgument);       // not finite
  EXPECT_EQ(code_of({{0.f, 0.f, 0.f, 1.f, 0.f, 0.f}, 0.f}), ErrorCode::kInvalidArgument);       // radius 0
  EXPECT_EQ(code_of({{0.f, 0.f, 0.f, 1.f, 0.f, 0.f}, INFINITY}), ErrorCode::kInvalidArgument);  // radius inf
}

// EditSession's local update recomputes only the faces a stroke reaches: the frames must then be
// bit for bit those of compute_orientation with the stroke.
TEST(Orientation, RefreshingTheFacesAStrokeReachesGivesTheFullResult) {
  const Mesh mesh = load_test_mesh("fertility.off");
  const Topology topology = build_topology(mesh);
  OrientationOptions options;
  FaceFrames frames;
  internal::OrientationSetup setup;
  ASSERT_TRUE(internal::compute_orientation_setup(mesh, topology, options, frames, &setup).is_ok());
  OrientationStroke stroke;
  for (size_t f = 100; f < 1000; f += 60)
    for (int c = 0; c < 3; ++c) stroke.points.push_back(mesh.positions[3 * size_t{mesh.indices[3 * f]} + c]);
  stroke.radius = 0.03f * (frames.bbox_max[0] - frames.bbox_min[0]);
  options.strokes = std::span<const OrientationStroke>(&stroke, 1);
  const FaceFrames expected = frames_of(mesh, options);
  std::vector<uint32_t> changed;
  for (uint32_t f = 0; f < mesh.face_count(); ++f)
    if (expected.orientation[3 * f] != frames.orientation[3 * f] ||
        expected.orientation[3 * f + 1] != frames.orientation[3 * f + 1] ||
        expected.orientation[3 * f + 2] != frames.orientation[3 * f + 2])
      changed.push_back(f);
  ASSERT_GT(changed.size(), 20u);
  ASSERT_LT(changed.size(), mesh.face_count() * 3 / 4);
  internal::refresh_face_frames(mesh, topology, options, setup, changed, frames);
  EXPECT_EQ(frames.normal, expected.normal);
  EXPECT_EQ(frames.orientation, expected.orientation);
  EXPECT_EQ(frames.bitangent, expected.bitangent);
  EXPECT_EQ(frames.area, expected.area);
  EXPECT_EQ(frames.local, expected.local);
  EXPECT_EQ(frames.anchor, expected.anchor);
  EXPECT_EQ(frames.variation, expected.variation);
}

TEST(Orientation, IsDeterministic) {
  const Mesh mesh = load_test_mesh("blobby-3cc.off");
  const FaceFrames a = frames_of(mesh);
  const FaceFrames b = frames_of(mesh);
  EXPECT_EQ(a.orientation, b.orientation);
  EXPECT_EQ(a.local, b.local);
  EXPECT_EQ(a.variation, b.variation);
}

}  // namespace
}  // namespace tailor
