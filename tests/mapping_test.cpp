// Texture mapping by patch discovery (tailor/mapping.h) and its stability (tailor/stability.h).
#include "tailor/mapping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "mapping/grid_cones.h"
#include "mapping/grid_map.h"
#include "mapping/mapping_common.h"
#include "support/fixtures.h"
#include "surface/rosy_field.h"
#include "tailor/axis_choice.h"
#include "tailor/io.h"
#include "tailor/metrics.h"
#include "tailor/orientation.h"
#include "tailor/stability.h"
#include "tailor/topology.h"

namespace tailor {
namespace {

using test::Diagonal;
using test::grid;
using test::load_test_mesh;

struct Mapped {
  Mesh mesh;
  Topology topology;
  FaceFrames frames;
  Atlas atlas;
  MappingStats stats;
};

// map_texture with these mapping options (default orientation, no metrics) on m.mesh and m.topology.
Status map_into(Mapped& m, const MappingOptions& options) {
  MapTextureOptions all;
  all.mapping = options;
  all.measure = false;
  TextureMap map;
  const Status s = map_texture(m.mesh, m.topology, all, map);
  m.frames = std::move(map.frames);
  m.atlas = std::move(map.atlas);
  m.stats = map.stats;
  return s;
}

void map_mesh(Mapped& m, const MappingOptions& options = {}) {
  m.topology = build_topology(m.mesh);
  const Status s = map_into(m, options);
  ASSERT_TRUE(s.is_ok()) << s.message();
}

// An open cylinder of radius 1 around y: m segments around, h rings of height 0.1.
Mesh cylinder(int m, int h) {
  Mesh mesh;
  const double pi = std::acos(-1.0);
  for (int j = 0; j <= h; ++j)
    for (int i = 0; i < m; ++i)
      mesh.positions.insert(mesh.positions.end(),
                            {float(std::cos(2 * pi * i / m)), 0.1f * float(j), float(std::sin(2 * pi * i / m))});
  auto id = [m](int i, int j) { return static_cast<uint32_t>(j * m + (i % m)); };
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < m; ++i) {
      mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  return mesh;
}

UvMetrics metrics_of(const Mapped& m) {
  UvMetrics metrics;
  const Status s = compute_uv_metrics(m.mesh, m.topology, m.atlas.corner_uv, m.atlas.patch, {}, metrics);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return metrics;
}

bool is_degenerate(const FaceFrames& frames, size_t f) {
  const float* l = &frames.local[6 * f];
  const float twice_area = l[2] * l[5] - l[3] * l[4];
  float longest = 0;
  for (int k = 1; k < 3; ++k) longest = std::max(longest, l[2 * k] * l[2 * k] + l[2 * k + 1] * l[2 * k + 1]);
  longest = std::max(longest, (l[4] - l[2]) * (l[4] - l[2]) + (l[5] - l[3]) * (l[5] - l[3]));
  return !(twice_area > 1e-6f * longest);
}

// Every patch is one edge-connected region (flood fill within each patch id).
void expect_connected_patches(const Mapped& m, const std::string& name) {
  const size_t face_count = m.mesh.face_count();
  std::vector<uint8_t> seen(face_count, 0);
  std::vector<uint32_t> regions(m.atlas.patch_count, 0), stack;
  for (size_t start = 0; start < face_count; ++start) {
    if (seen[start]) continue;
    const uint32_t p = m.atlas.patch[start];
    ++regions[p];
    seen[start] = 1;
    stack.assign(1, static_cast<uint32_t>(start));
    while (!stack.empty()) {
      const uint32_t f = stack.back();
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const uint32_t o = m.topology.opposite[3 * f + k];
        if (o == kInvalid || seen[o / 3] || m.atlas.patch[o / 3] != p) continue;
        seen[o / 3] = 1;
        stack.push_back(o / 3);
      }
    }
  }
  for (uint32_t p = 0; p < m.atlas.patch_count; ++p) EXPECT_EQ(regions[p], 1u) << name << " patch " << p;
}

// The invariants every patches-mode atlas must hold.
void expect_valid_patches_atlas(const Mapped& m, const MappingOptions& options, const std::string& name) {
  const size_t face_count = m.mesh.face_count();
  ASSERT_EQ(m.atlas.corner_uv.size(), 6 * face_count) << name;
  ASSERT_EQ(m.atlas.patch.size(), face_count) << name;
  std::vector<uint32_t> patch_faces(m.atlas.patch_count, 0);
  size_t checked = 0;
  for (size_t f = 0; f < face_count; ++f) {
    ASSERT_LT(m.atlas.patch[f], m.atlas.patch_count) << name << " face " << f;
    ++patch_faces[m.atlas.patch[f]];
    const float* uv = &m.atlas.corner_uv[6 * f];
    for (int i = 0; i < 6; ++i) ASSERT_TRUE(std::isfinite(uv[i])) << name << " face " << f;
    if (is_degenerate(m.frames, f)) continue;
    const float error = face_stretch_error(std::span<const float, 6>(&m.frames.local[6 * f], 6), options.scale,
                                           std::span<const float, 6>(uv, 6));
    // Rigid placements may differ from the bound's own rounding by a few ulps.
    ASSERT_LE(error, options.max_stretch + 1e-3f) << name << " face " << f;
    ++checked;
  }
  EXPECT_GT(checked, face_count * 9 / 10) << name;
  for (uint32_t p = 0; p < m.atlas.patch_count; ++p) EXPECT_GT(patch_faces[p], 0u) << name << " patch " << p;
  expect_connected_patches(m, name);
  const UvMetrics metrics = metrics_of(m);
  EXPECT_EQ(metrics.flipped, 0u) << name;
  EXPECT_EQ(metrics.zero_uv_area_faces, 0u) << name;
  EXPECT_EQ(metrics.single_face_patches, 0u) << name;
  EXPECT_LT(metrics.l2_stretch, 1.02) << name;
  EXPECT_LT(metrics.linf_stretch, 1.0 + options.max_stretch + 0.01) << name;
  EXPECT_EQ(m.stats.patches, m.atlas.patch_count) << name;
}

TEST(Mapping, EveryTestMeshMapsCompletelyWithinTheBound) {
  const std::filesystem::path dir = std::filesystem::path(TAILOR_TEST_DATA) / "meshes";
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl"))
      names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  ASSERT_GE(names.size(), 4u);
  const MappingOptions options;
  for (const std::string& name : names) {
    Mapped m;
    m.mesh = load_test_mesh(name);
    map_mesh(m, options);
    expect_valid_patches_atlas(m, options, name);
  }
}

TEST(Mapping, PureUnfoldingAndLooserBoundsStayValid) {
  Mapped follow, unfold;
  follow.mesh = load_test_mesh("fertility.off");
  unfold.mesh = follow.mesh;
  map_mesh(follow);
  MappingOptions options;
  options.field_following = 0.f;
  map_mesh(unfold, options);
  expect_valid_patches_atlas(unfold, options, "fertility.off unfolded");
  // Without the field's shear the faces keep their shape better (median angle distortion).
  EXPECT_LT(metrics_of(unfold).distortion_deg, metrics_of(follow).distortion_deg);
  Mapped loose;
  loose.mesh = follow.mesh;
  options = {};
  options.max_stretch = 0.5f;
  map_mesh(loose, options);
  expect_valid_patches_atlas(loose, options, "fertility.off max_stretch 0.5");
  EXPECT_GT(loose.stats.max_stretch_accepted, 0.25f);
  options.field_following = 2.f;
  EXPECT_EQ(map_into(loose, options).code(), ErrorCode::kInvalidArgument);
}

// Maps mesh `name` into `on` with default options and into `off` with `step` switched off; returns
// the latter options.
MappingOptions map_with_and_without(const char* name, bool MappingOptions::*step, Mapped& on, Mapped& off,
                                    MappingOptions options = {}) {
  on.mesh = load_test_mesh(name);
  off.mesh = on.mesh;
  map_mesh(on, options);
  options.*step = false;
  map_mesh(off, options);
  return options;
}

TEST(Mapping, SeamShorteningShortensSeamsWithinTheBound) {
  for (const char* name : {"horse.ply", "spot.obj"}) {
    Mapped shortened, kept;
    // The shortening's own effect on the growth's seams (the crack closing after it zips most of
    // what is left either way).
    MappingOptions growth;
    growth.close_cracks = false;
    growth.relax_iterations = 0;
    const MappingOptions options = map_with_and_without(name, &MappingOptions::shorten_seams, shortened, kept, growth);
    EXPECT_GT(shortened.stats.faces_reseamed, 0u) << name;
    EXPECT_EQ(kept.stats.faces_reseamed, 0u) << name;
    expect_valid_patches_atlas(shortened, options, std::string(name) + " shortened");
    const UvMetrics with = metrics_of(shortened), without = metrics_of(kept);
    // At least 5% less seam length than the growth left.
    EXPECT_LT(with.seam_length_ratio, 0.95 * without.seam_length_ratio) << name;
    EXPECT_LT(with.seam_edges, without.seam_edges) << name;
    EXPECT_LE(with.patches, without.patches) << name;
  }
  // Without absorption, patches are small and many: moving a face out of one must never cut it in
  // two (it did on the horse before the fan check: 3 patches split).
  Mapped small;
  small.mesh = load_test_mesh("horse.ply");
  MappingOptions keep_all;
  keep_all.min_patch_faces = 0;
  map_mesh(small, keep_all);
  EXPECT_GT(small.stats.faces_reseamed, 0u);
  expect_connected_patches(small, "horse.ply, min_patch_faces 0");
}

// Whether the two faces of half-edge e disagree on the UV of a shared corner.
bool is_seam_edge(const Mapped& m, uint32_t e) {
  const uint32_t o = m.topology.opposite[e];
  if (o == kInvalid) return false;
  const uint32_t f = e / 3, g = o / 3, k = e % 3, kk = o % 3;
  const float* a = &m.atlas.corner_uv[6 * f];
  const float* b = &m.atlas.corner_uv[6 * g];
  // f's edge runs corner k -> k+1, g's the other way.
  const uint32_t k1 = (k + 1) % 3, kk1 = (kk + 1) % 3;
  return a[2 * k] != b[2 * kk1] || a[2 * k + 1] != b[2 * kk1 + 1] || a[2 * k1] != b[2 * kk] ||
         a[2 * k1 + 1] != b[2 * kk + 1];
}

TEST(Mapping, CrackClosingZipsCracksWithinTheBound) {
  for (const char* name : {"horse.ply", "spot.obj"}) {
    Mapped closed, open;
    MappingOptions no_relaxation;  // the faces a zip moved, alone (the relaxation moves nearly all)
    no_relaxation.relax_iterations = 0;
    const MappingOptions options =
        map_with_and_without(name, &MappingOptions::close_cracks, closed, open, no_relaxation);
    EXPECT_GT(closed.stats.cracks_closed, 100u) << name;
    EXPECT_EQ(open.stats.cracks_closed, 0u) << name;
    expect_valid_patches_atlas(closed, options, std::string(name) + " cracks closed");
    // Zips only join UVs: faces keep their patches, and no seamless edge becomes a seam.
    EXPECT_EQ(closed.atlas.patch, open.atlas.patch) << name;
    size_t opened = 0, zipped = 0;
    for (uint32_t e = 0; e < closed.topology.opposite.size(); ++e) {
      const bool was = is_seam_edge(open, e), is = is_seam_edge(closed, e);
      opened += !was && is;
      zipped += was && !is;
    }
    EXPECT_EQ(opened, 0u) << name;
    EXPECT_GT(zipped, 0u) << name;
    // Every face a zip moved keeps its area within 1/1.2..1.2 of the surface's.
    size_t moved = 0;
    for (size_t f = 0; f < closed.mesh.face_count(); ++f) {
      const float* uv = &closed.atlas.corner_uv[6 * f];
      if (std::equal(uv, uv + 6, &open.atlas.corner_uv[6 * f]) || is_degenerate(closed.frames, f)) continue;
      ++moved;
      const float* l = &closed.frames.local[6 * f];
      const double uv_area = (uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[4] - uv[0]) * (uv[3] - uv[1]);
      const double frame_area = (l[2] * l[5] - l[3] * l[4]) * double(options.scale) * options.scale;
      EXPECT_LE(uv_area / frame_area, 1.2 + 1e-3) << name << " face " << f;
      EXPECT_GE(uv_area / frame_area, 1 / 1.2 - 1e-3) << name << " face " << f;
    }
    EXPECT_GT(moved, 0u) << name;
    // Measured: horse 7.0% -> 4.3%, spot 11.4% -> 6.4% of edge length; assert at least 25% less,
    // with the thesis stretch (the area ratio's variation) still under the 0.08.
    const UvMetrics with = metrics_of(closed), without = metrics_of(open);
    EXPECT_LT(with.seam_length_ratio, 0.75 * without.seam_length_ratio) << name;
    EXPECT_LT(with.stretch, 0.08) << name;
  }
}

TEST(Mapping, FlatGridIsOnePatchWithoutSeamOrDistortion) {
  Mapped m;
  m.mesh = grid(30, 30, Diagonal::kRising);
  map_mesh(m);
  const UvMetrics metrics = metrics_of(m);
  EXPECT_EQ(m.atlas.patch_count, 1u);
  EXPECT_EQ(metrics.seam_edges, 0u);
  EXPECT_NEAR(metrics.l2_stretch, 1.0, 1e-4);
  EXPECT_NEAR(metrics.linf_stretch, 1.0, 1e-3);
  EXPECT_LT(m.stats.max_stretch_accepted, 1e-3f);
  // About half the faces close a gap with all three corners known (thesis fig. 2.4).
  EXPECT_GT(m.stats.faces_three_textured, m.mesh.face_count() * 4 / 10);
}

TEST(Mapping, CylinderIsCutAlongOneLine) {
  Mapped m;
  m.mesh = cylinder(60, 40);  // 4800 faces, 40 rings of 60 faces each
  map_mesh(m);
  const UvMetrics metrics = metrics_of(m);
  EXPECT_EQ(m.atlas.patch_count, 1u);
  EXPECT_EQ(metrics.flipped, 0u);
  // One cut from bottom to top: about one seam edge per ring (a few more where it steps sideways).
  EXPECT_GE(metrics.seam_edges, 40u);
  EXPECT_LE(metrics.seam_edges, 100u);
}

TEST(Mapping, IsDeterministic) {
  Mapped a, b;
  a.mesh = load_test_mesh("fertility.off");
  b.mesh = a.mesh;
  map_mesh(a);
  map_mesh(b);
  EXPECT_EQ(a.atlas.corner_uv, b.atlas.corner_uv);
  EXPECT_EQ(a.atlas.patch, b.atlas.patch);
  MappingOptions thesis;
  thesis.mode = MappingMode::kThesis;
  map_mesh(a, thesis);
  map_mesh(b, thesis);
  EXPECT_EQ(a.atlas.corner_uv, b.atlas.corner_uv);
}

// The topology serves only the metrics: mapped without it (measure off, an empty topology), whole or
// in chunks, then measured, a map equals map_texture's with its metrics; measuring needs it.
TEST(Mapping, MeasuredAfterTheMappingWithoutATopologyIsTheSameMap) {
  const Mesh mesh = load_test_mesh("fertility.off");
  const Topology topology = build_topology(mesh);
  for (const ChunkMode mode : {ChunkMode::kOff, ChunkMode::kOn}) {
    MapTextureOptions options;
    options.chunks.mode = mode;
    TextureMap direct, later;
    ASSERT_TRUE(map_texture(mesh, topology, options, direct).is_ok());
    MapTextureOptions unmeasured = options;
    unmeasured.measure = false;
    ASSERT_TRUE(map_texture(mesh, Topology{}, unmeasured, later).is_ok());
    EXPECT_EQ(later.metrics.faces, 0u);
    EXPECT_FALSE(measure_texture_map(mesh, Topology{}, options, later).is_ok());
    ASSERT_TRUE(measure_texture_map(mesh, topology, options, later).is_ok());
    EXPECT_EQ(later.atlas.corner_uv, direct.atlas.corner_uv);
    EXPECT_EQ(later.metrics.visible_seam_ratio, direct.metrics.visible_seam_ratio);
    EXPECT_EQ(later.metrics.l2_stretch, direct.metrics.l2_stretch);
    EXPECT_EQ(later.metrics.flipped, direct.metrics.flipped);
    EXPECT_GT(later.metrics.faces, 0u);
  }
  // With metrics asked for, a missing topology is an error, not a crash.
  TextureMap map;
  EXPECT_EQ(map_texture(mesh, Topology{}, MapTextureOptions{}, map).code(), ErrorCode::kInvalidMesh);
}

// The crack closing zips bands of seed distance on several threads: the horse has a dozen bands,
// and the atlas must not depend on how many workers shared them.
TEST(Mapping, CrackClosingIsTheSameOnAnyThreadCount) {
  Mapped one, many;
  one.mesh = load_test_mesh("horse.ply");
  many.mesh = one.mesh;
  MappingOptions options;
  options.threads = 1;
  map_mesh(one, options);
  EXPECT_GT(one.stats.cracks_closed, 1000u);
  for (const uint32_t threads : {2u, 5u}) {
    options.threads = threads;
    map_mesh(many, options);
    EXPECT_EQ(one.atlas.corner_uv, many.atlas.corner_uv) << threads << " threads";
    EXPECT_EQ(one.atlas.patch, many.atlas.patch) << threads << " threads";
    EXPECT_EQ(one.stats.cracks_closed, many.stats.cracks_closed);
  }
}

// The relaxation (relax_iterations, the last step) lowers the angle distortion, keeps every face it
// moves within the bound and the patches and seam edges as they were, leaves both sides of every
// seam that is less than a pixel wide where they were (invisible seams stay invisible), and gives
// the same atlas on any number of threads.
TEST(Mapping, RelaxationLowersAngleDistortion) {
  Mapped before, one, four;
  before.mesh = load_test_mesh("horse.ply");
  one.mesh = before.mesh;
  four.mesh = before.mesh;
  MappingOptions options;
  options.relax_iterations = 0;
  map_mesh(before, options);
  EXPECT_EQ(before.stats.relax_moves, 0u);
  options = {};
  options.threads = 1;
  map_mesh(one, options);
  options.threads = 4;
  map_mesh(four, options);
  EXPECT_EQ(one.atlas.corner_uv, four.atlas.corner_uv);
  EXPECT_EQ(one.stats.relax_moves, four.stats.relax_moves);
  EXPECT_GT(one.stats.relax_moves, 100000u);
  expect_valid_patches_atlas(one, options, "horse relaxed");
  EXPECT_EQ(one.atlas.patch, before.atlas.patch);
  const size_t face_count = one.mesh.face_count();
  size_t moved = 0;
  for (size_t f = 0; f < face_count; ++f) {
    const float* uv = &one.atlas.corner_uv[6 * f];
    if (std::equal(uv, uv + 6, &before.atlas.corner_uv[6 * f])) continue;
    ++moved;
    ASSERT_FALSE(is_degenerate(one.frames, f)) << "face " << f;
    EXPECT_LE(face_stretch_error(std::span<const float, 6>(&one.frames.local[6 * f], 6), options.scale,
                                 std::span<const float, 6>(uv, 6)),
              options.max_stretch)
        << "face " << f;
  }
  EXPECT_GT(moved, face_count / 2);
  size_t seams = 0, narrow = 0;
  for (uint32_t e = 0; e < one.topology.opposite.size(); ++e) {
    const bool seam = is_seam_edge(before, e);
    EXPECT_EQ(is_seam_edge(one, e), seam) << "edge " << e;
    if (!seam || one.topology.opposite[e] < e) continue;
    ++seams;
    const uint32_t o = one.topology.opposite[e];
    const uint32_t corners[4] = {e, 3 * (e / 3) + (e % 3 + 1) % 3, o, 3 * (o / 3) + (o % 3 + 1) % 3};
    const float* uv = before.atlas.corner_uv.data();
    const auto gap = [uv](uint32_t a, uint32_t b) {
      return std::hypot(uv[2 * a] - uv[2 * b], uv[2 * a + 1] - uv[2 * b + 1]);
    };
    if (!(gap(corners[0], corners[3]) < 1.f && gap(corners[1], corners[2]) < 1.f)) continue;
    ++narrow;
    for (const uint32_t c : corners) {
      EXPECT_EQ(one.atlas.corner_uv[2 * c], uv[2 * c]) << "edge " << e;
      EXPECT_EQ(one.atlas.corner_uv[2 * c + 1], uv[2 * c + 1]) << "edge " << e;
    }
  }
  EXPECT_GT(seams, 1000u);
  EXPECT_GT(narrow, 10u);
  // Measured: 6.52 -> 1.73 degrees (median over faces of the sum of |UV angle - 3D angle|), Sander
  // L2 1.0045 -> 1.0028, thesis stretch 0.064 -> 0.056.
  const UvMetrics unrelaxed = metrics_of(before), relaxed = metrics_of(one);
  EXPECT_LT(relaxed.distortion_deg, 0.5 * unrelaxed.distortion_deg);
  EXPECT_LT(relaxed.distortion_deg, 3.0);
  EXPECT_EQ(relaxed.flipped, 0u);
  EXPECT_EQ(relaxed.seam_edges, unrelaxed.seam_edges);
  EXPECT_LT(relaxed.l2_stretch, unrelaxed.l2_stretch);
  EXPECT_LT(relaxed.stretch, unrelaxed.stretch);
}

// The relaxation holds every seam that is invisible on the texture's lattice, with the lattice's
// width and height apart (texture_period_px, texture_period_v_px): spot mapped without it, its
// half x > 0 shifted by three repeats of a 8 x 4 px texture in v (12 px, which a square 8 px
// lattice would see 4 px off), then relaxed: the cut's corners stay where they are, the rest moves.
TEST(Mapping, RelaxationHoldsSeamsOnANonSquareLattice) {
  Mapped m;
  m.mesh = load_test_mesh("spot.obj");
  MappingOptions options;
  options.relax_iterations = 0;
  map_mesh(m, options);
  // The cut's edges that were seamless: their sides then differ by the shift alone.
  std::vector<uint8_t> was_seamless(m.topology.opposite.size());
  for (uint32_t e = 0; e < was_seamless.size(); ++e) was_seamless[e] = !is_seam_edge(m, e);
  const size_t face_count = m.mesh.face_count();
  std::vector<uint8_t> right(face_count, 0);
  for (size_t f = 0; f < face_count; ++f) {
    float x = 0.f;
    for (int k = 0; k < 3; ++k) x += m.mesh.positions[3 * m.mesh.indices[3 * f + k]];
    if (x <= 0.f) continue;
    right[f] = 1;
    for (int k = 0; k < 3; ++k) m.atlas.corner_uv[6 * f + 2 * k + 1] += 12.f;
  }
  const std::vector<float> shifted = m.atlas.corner_uv;
  options.relax_iterations = 10;
  options.texture_period_px = 8.f;
  options.texture_period_v_px = 4.f;
  const internal::MappingInput input{m.mesh, m.topology, m.frames, options, 0.0, {}};
  uint64_t moves = 0;
  ASSERT_TRUE(internal::relax_patches(input, m.atlas, moves).is_ok());
  EXPECT_GT(moves, face_count);
  size_t cut = 0;
  for (uint32_t e = 0; e < m.topology.opposite.size(); ++e) {
    const uint32_t o = m.topology.opposite[e];
    if (o == kInvalid || right[e / 3] == right[o / 3] || !was_seamless[e]) continue;
    ++cut;
    for (const uint32_t c : {e, 3 * (e / 3) + (e % 3 + 1) % 3}) {
      EXPECT_EQ(m.atlas.corner_uv[2 * c], shifted[2 * c]) << "edge " << e;
      EXPECT_EQ(m.atlas.corner_uv[2 * c + 1], shifted[2 * c + 1]) << "edge " << e;
    }
  }
  EXPECT_GT(cut, 100u);
}

TEST(Mapping, SeedPointChoosesTheFirstPatch) {
  Mapped m;
  m.mesh = load_test_mesh("spot.obj");
  // Centroid of face 1000: the nearest face to it is face 1000 itself.
  double c[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i) c[i] += m.mesh.positions[3 * m.mesh.indices[3 * 1000 + k] + i] / 3.0;
  MappingOptions options;
  options.min_patch_faces = 0;   // keep the seed's own patch even if small
  options.relax_iterations = 0;  // which would move the seed's corners
  options.use_seed_point = true;
  options.seed_point = {float(c[0]), float(c[1]), float(c[2])};
  map_mesh(m, options);
  EXPECT_EQ(m.atlas.patch[1000], 0u);
  // The seed sits at the UV its own position gives (origin independent of the file order).
  const float expected_u = (m.frames.anchor[2 * 1000] + m.frames.local[6 * 1000]) * options.scale;
  EXPECT_FLOAT_EQ(m.atlas.corner_uv[6 * 1000], expected_u);
}

TEST(Mapping, ThesisModeReproducesItsCounters) {
  Mapped m;
  m.mesh = load_test_mesh("spot.obj");
  MappingOptions options;
  options.mode = MappingMode::kThesis;
  map_mesh(m, options);
  const size_t face_count = m.mesh.face_count();
  // Thesis fig. 2.4: about half the faces are textured with all three vertices already known.
  EXPECT_GT(m.stats.faces_three_textured, face_count * 35 / 100);
  EXPECT_LT(m.stats.faces_three_textured, face_count * 65 / 100);
  EXPECT_EQ(m.stats.faces_three_textured + m.stats.faces_unfolded, face_count);
  EXPECT_GT(m.stats.deferrals, 0u);
  EXPECT_LE(m.stats.max_error_px, m.stats.final_threshold_px);
  EXPECT_EQ(m.atlas.patch_count, 1u);
  // One UV per vertex: every corner of a vertex carries the same UV, so there is no seam at all.
  std::vector<float> first(2 * m.mesh.vertex_count(), std::numeric_limits<float>::quiet_NaN());
  for (size_t c = 0; c < 3 * face_count; ++c) {
    const uint32_t v = m.mesh.indices[c];
    if (std::isnan(first[2 * v])) {
      first[2 * v] = m.atlas.corner_uv[2 * c];
      first[2 * v + 1] = m.atlas.corner_uv[2 * c + 1];
    }
    ASSERT_EQ(first[2 * v], m.atlas.corner_uv[2 * c]);
  }
  const UvMetrics metrics = metrics_of(m);
  EXPECT_EQ(metrics.seam_edges, 0u);
  // What the thesis leaves behind: inverted faces (accepted with three textured vertices).
  EXPECT_GT(m.stats.inverted_accepted, 0u);
  EXPECT_GT(metrics.flipped, 0u);

  // With a threshold the front cannot meet, it is raised in 10 px steps until everything is placed.
  options.threshold_px = 1.f;
  map_mesh(m, options);
  EXPECT_GE(m.stats.threshold_raises, 1u);
  EXPECT_FLOAT_EQ(m.stats.final_threshold_px, 1.f + 10.f * static_cast<float>(m.stats.threshold_raises));
  EXPECT_LE(m.stats.max_error_px, m.stats.final_threshold_px);
  EXPECT_GT(m.stats.max_error_px, m.stats.final_threshold_px - 10.f);
}

TEST(Mapping, ThesisModeInvertsFacesOnADenseMeshWherePatchesModeDoesNot) {
  // The measurement on horse (97k faces): 4,708 inverted faces, Sander L2 30.6.
  Mapped thesis, patches;
  thesis.mesh = load_test_mesh("horse.ply");
  patches.mesh = thesis.mesh;
  MappingOptions options;
  options.mode = MappingMode::kThesis;
  map_mesh(thesis, options);
  map_mesh(patches);
  const UvMetrics t = metrics_of(thesis);
  const UvMetrics p = metrics_of(patches);
  EXPECT_GT(thesis.stats.inverted_accepted, 3000u);  // measured 4,729
  EXPECT_GT(t.flipped, 3000u);
  EXPECT_GT(t.l2_stretch, 10.0);  // measured 26.7
  EXPECT_EQ(p.flipped, 0u);
  EXPECT_LT(p.l2_stretch, 1.01);
}

// Seam edges touching the marked faces.
size_t seam_edges_on(const Mapped& m, const std::vector<uint8_t>& marked) {
  size_t count = 0;
  for (size_t e = 0; e < m.topology.opposite.size(); ++e) {
    const uint32_t o = m.topology.opposite[e];
    if (o == kInvalid || o < e) continue;
    const size_t f = e / 3, g = o / 3;
    if (!marked[f] && !marked[g]) continue;
    const float* a0 = &m.atlas.corner_uv[2 * e];
    const float* a1 = &m.atlas.corner_uv[2 * (3 * f + (e + 1) % 3)];
    const float* b0 = &m.atlas.corner_uv[2 * (3 * g + (o + 1) % 3)];  // the opposite edge runs back
    const float* b1 = &m.atlas.corner_uv[2 * o];
    if (a0[0] != b0[0] || a0[1] != b0[1] || a1[0] != b1[0] || a1[1] != b1[1]) ++count;
  }
  return count;
}

TEST(Mapping, SeamFacesAttractTheSeams) {
  Mapped plain, constrained;
  plain.mesh = load_test_mesh("spot.obj");
  constrained.mesh = plain.mesh;
  map_mesh(plain);
  // Mark a band of faces: centroids with x in the middle 10% of the bounding box.
  float lo = INFINITY, hi = -INFINITY;
  for (size_t v = 0; v < plain.mesh.vertex_count(); ++v) {
    lo = std::min(lo, plain.mesh.positions[3 * v]);
    hi = std::max(hi, plain.mesh.positions[3 * v]);
  }
  std::vector<uint8_t> marked(plain.mesh.face_count(), 0);
  size_t marked_count = 0;
  for (size_t f = 0; f < plain.mesh.face_count(); ++f) {
    float x = 0;
    for (int k = 0; k < 3; ++k) x += plain.mesh.positions[3 * plain.mesh.indices[3 * f + k]] / 3.f;
    const float t = (x - lo) / (hi - lo);
    marked[f] = t > 0.45f && t < 0.55f;
    marked_count += marked[f];
  }
  ASSERT_GT(marked_count, 100u);
  MappingOptions options;
  options.seam_faces = marked;
  map_mesh(constrained, options);
  expect_valid_patches_atlas(constrained, options, "spot.obj with seam faces");
  EXPECT_EQ(constrained.stats.faces_seam, marked_count);
  const size_t before = seam_edges_on(plain, marked);
  const size_t after = seam_edges_on(constrained, marked);
  RecordProperty("seam_edges_on_band_before", static_cast<int>(before));
  RecordProperty("seam_edges_on_band_after", static_cast<int>(after));
  EXPECT_GT(after, before + before / 4) << "before " << before << " after " << after;
  // The seam shortening leaves the edges around marked faces as the growth put them.
  Mapped unshortened;
  unshortened.mesh = plain.mesh;
  options.shorten_seams = false;
  map_mesh(unshortened, options);
  EXPECT_GE(after, seam_edges_on(unshortened, marked));
  // So does the crack closing.
  Mapped unzipped;
  unzipped.mesh = plain.mesh;
  options.shorten_seams = true;
  options.close_cracks = false;
  map_mesh(unzipped, options);
  EXPECT_GE(after, seam_edges_on(unzipped, marked));
}

TEST(Mapping, FaceStretchErrorMeasuresSingularValues) {
  const float local[6] = {0.f, 0.f, 1.f, 0.f, 0.f, 1.f};
  const float same[6] = {5.f, 5.f, 15.f, 5.f, 5.f, 15.f};  // scale 10, translated
  EXPECT_NEAR(face_stretch_error(local, 10.f, same), 0.f, 1e-6);
  const float stretched[6] = {0.f, 0.f, 12.f, 0.f, 0.f, 10.f};  // 20% longer along u
  EXPECT_NEAR(face_stretch_error(local, 10.f, stretched), 0.2f, 1e-5);
  const float shrunk[6] = {0.f, 0.f, 8.f, 0.f, 0.f, 10.f};  // sigma_min 0.8 -> 1/0.8 - 1
  EXPECT_NEAR(face_stretch_error(local, 10.f, shrunk), 0.25f, 1e-5);
  const float rotated[6] = {0.f, 0.f, 0.f, 10.f, -10.f, 0.f};  // 90 degrees: no stretch
  EXPECT_NEAR(face_stretch_error(local, 10.f, rotated), 0.f, 1e-5);
  const float mirrored[6] = {0.f, 0.f, 10.f, 0.f, 0.f, -10.f};
  EXPECT_TRUE(std::isinf(face_stretch_error(local, 10.f, mirrored)));
  const float flat[6] = {0.f, 0.f, 10.f, 0.f, 20.f, 0.f};
  EXPECT_TRUE(std::isinf(face_stretch_error(local, 10.f, flat)));
}

TEST(Mapping, ProgressCanCancel) {
  Mapped m;
  m.mesh = load_test_mesh("horse.ply");  // more faces than one progress interval
  m.topology = build_topology(m.mesh);
  MappingOptions options;
  int calls = 0;
  options.progress = [&calls](float done) {
    EXPECT_GE(done, 0.f);
    EXPECT_LE(done, 1.f);
    ++calls;
    return false;
  };
  const Status s = map_into(m, options);
  EXPECT_EQ(s.code(), ErrorCode::kCancelled);
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(m.atlas.corner_uv.empty());
  // The crack closing (most of the time) reports the last 80% and can be cancelled too: progress
  // rises through it, and stopping half-way leaves the atlas empty.
  std::vector<float> seen;
  options.progress = [&seen](float done) {
    seen.push_back(done);
    return true;
  };
  ASSERT_TRUE(map_into(m, options).is_ok());
  ASSERT_GT(seen.size(), 10u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GT(seen.back(), 0.9f);
  EXPECT_GT(std::count_if(seen.begin(), seen.end(), [](float d) { return d > 0.2f; }), 5);
  options.progress = [](float done) { return done < 0.6f; };
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kCancelled);
  EXPECT_TRUE(m.atlas.corner_uv.empty());
  EXPECT_TRUE(m.atlas.patch.empty());
}

// Meshes made to break the mapping (the adversarial test files, a random triangle soup, needles,
// a non-manifold fan, sheets at 1e-12 and 1e12 units) map in every mode with every face placed
// and every UV finite, or fail with a message (symmetry 4 refuses faces far below a pixel).
TEST(Mapping, AdversarialMeshesGetFiniteUvsInEveryMode) {
  std::vector<std::pair<std::string, Mesh>> meshes;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(TAILOR_TEST_DATA) + "/meshes/adversarial")) {
    Mesh mesh;
    if (load_mesh(entry.path().string(), mesh).is_ok()) meshes.emplace_back(entry.path().filename().string(), mesh);
  }
  std::sort(meshes.begin(), meshes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  uint64_t state = 12345;  // a fixed linear congruential stream: the same meshes on every platform
  auto uniform = [&state](float lo, float hi) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * static_cast<float>(state >> 40) / static_cast<float>(1ull << 24);
  };
  auto add = [&meshes](const std::string& name, Mesh mesh) {
    LoadReport report;
    if (finalize_mesh(name, mesh, report).is_ok()) meshes.emplace_back(name, std::move(mesh));
  };
  Mesh soup;
  for (int i = 0; i < 3 * 60; ++i) soup.positions.push_back(uniform(-1.0f, 1.0f));
  for (int f = 0; f < 150; ++f)
    for (int k = 0; k < 3; ++k) soup.indices.push_back(static_cast<uint32_t>(uniform(0.0f, 59.99f)));
  add("soup", soup);
  Mesh fan;
  fan.positions = {0, 0, 0};
  const int spokes = 40;
  for (int i = 0; i < spokes; ++i)
    fan.positions.insert(fan.positions.end(), {std::cos(0.157f * static_cast<float>(i)),
                                               std::sin(0.157f * static_cast<float>(i)), uniform(-1.0f, 1.0f)});
  for (uint32_t i = 0; i < spokes; ++i) {
    fan.indices.insert(fan.indices.end(), {0, 1 + i, 1 + (i + 1) % spokes});
    if (i % 3 == 0) fan.indices.insert(fan.indices.end(), {0, 1 + i, 1 + (i + 2) % spokes});  // a second sheet
  }
  add("fan", fan);
  for (const float scale : {1e-12f, 1e12f}) {
    Mesh sheet = grid(12, 9, Diagonal::kRising);
    for (size_t i = 0; i < sheet.positions.size(); ++i)
      sheet.positions[i] = (i % 3 == 2 ? uniform(0.0f, 3.0f) : sheet.positions[i]) * scale;
    add("sheet x" + std::to_string(scale), sheet);
  }
  Mesh needles = grid(20, 4, Diagonal::kFalling);
  for (size_t i = 0; i < needles.positions.size(); i += 3) needles.positions[i] *= 1e4f;
  add("needles", needles);
  ASSERT_GE(meshes.size(), 10u);

  for (const auto& [name, mesh] : meshes) {
    const Topology topology = build_topology(mesh);
    for (int mode = 0; mode < 4; ++mode) {
      SCOPED_TRACE(name + " mode " + std::to_string(mode));
      MapTextureOptions options;
      ASSERT_TRUE(set_map_texture_size(options, 512, 512).is_ok());
      if (mode == 1) options.mapping.symmetry = 4;
      if (mode == 2) options.mapping.mode = MappingMode::kThesis;
      if (mode == 3) options.mapping.field_following = 0.0f;
      TextureMap map;
      const Status s = map_texture(mesh, topology, options, map);
      if (!s.is_ok()) {
        EXPECT_EQ(mode, 1) << s.message();
        EXPECT_FALSE(s.what().empty());
        continue;
      }
      ASSERT_EQ(map.atlas.corner_uv.size(), 6 * mesh.face_count());
      ASSERT_EQ(map.atlas.patch.size(), mesh.face_count());
      EXPECT_TRUE(std::all_of(map.atlas.corner_uv.begin(), map.atlas.corner_uv.end(),
                              [](float v) { return std::isfinite(v); }));
      EXPECT_TRUE(std::all_of(map.atlas.patch.begin(), map.atlas.patch.end(),
                              [&](uint32_t p) { return p < map.atlas.patch_count; }));
    }
  }
}

TEST(Mapping, RejectsBadOptionsAndMismatchedInputs) {
  Mapped m;
  m.mesh = grid(3, 3, Diagonal::kRising);
  map_mesh(m);
  MappingOptions options;
  options.scale = 0.f;
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options = {};
  options.scale = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options = {};
  options.max_stretch = 0.f;
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options = {};
  options.hop_age = -0.5f;
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options.hop_age = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options = {};
  options.crack_rings = 1;
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options.crack_rings = 65;
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options = {};
  options.relax_iterations = 1001;
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  options = {};
  const std::vector<uint8_t> wrong_size(3, 1);
  options.seam_faces = wrong_size;
  EXPECT_EQ(map_into(m, options).code(), ErrorCode::kInvalidArgument);
  TextureMap map;
  EXPECT_EQ(map_texture(m.mesh, Topology{}, {}, map).code(), ErrorCode::kInvalidMesh);
}

TEST(Mapping, SeveralComponentsEachGetTheirPatches) {
  Mapped m;
  m.mesh = load_test_mesh("blobby-3cc.off");
  map_mesh(m);
  EXPECT_EQ(m.stats.components, m.topology.edge_components);
  EXPECT_GE(m.atlas.patch_count, m.stats.components);
}

// Symmetry 4 (issue 14, experimental): an integer-grid map. Seams between faces away from the
// field's singularities are quarter turns plus whole repeats, so under a 4-fold symmetric tile
// more seam length is invisible than the growth's (its patches' sides differ by arbitrary
// rotations), and with the lattice coordinates relaxed (grid_relax.h) less of it is visible too.
// Every face stays within the lattice bound, none is flipped, and the result is the same bytes
// for any thread count.
TEST(Mapping, SymmetryFourGivesInvisibleSeams) {
  MetricsOptions quarter_turns;
  quarter_turns.symmetry = 4;
  auto metrics4 = [&](const Mapped& m) {
    UvMetrics metrics;
    const Status s = compute_uv_metrics(m.mesh, m.topology, m.atlas.corner_uv, m.atlas.patch, quarter_turns, metrics);
    EXPECT_TRUE(s.is_ok()) << s.message();
    return metrics;
  };
  Mapped growth, grid1, grid4;
  growth.mesh = grid1.mesh = grid4.mesh = load_test_mesh("fandisk.off");
  MappingOptions options;
  options.scale = 8000.f;  // ten times the default: the texture repeats ~15 times across the part
  map_mesh(growth, options);
  options.symmetry = 4;
  options.threads = 1;
  map_mesh(grid1, options);
  options.threads = 4;
  map_mesh(grid4, options);
  EXPECT_EQ(grid1.atlas.corner_uv, grid4.atlas.corner_uv);
  EXPECT_EQ(grid1.atlas.patch, grid4.atlas.patch);
  EXPECT_GT(grid1.stats.faces_reseamed, 0u);  // the seam shortening and relaxation follow the grid map
  EXPECT_GT(grid1.stats.relax_moves, 0u);
  const UvMetrics before = metrics4(growth), after = metrics4(grid1);
  EXPECT_EQ(after.flipped, 0u);
  // Measured: invisible share 0.0% -> 66%, visible seams 3.2% -> 1.4% of edge length (before the
  // relaxation of the lattice coordinates: 31% and 5.4%).
  EXPECT_GT(after.seam_invisible_ratio, 0.5);
  EXPECT_LT(after.visible_seam_ratio, 0.6 * before.visible_seam_ratio);
  EXPECT_LT(after.l2_stretch, 1.02);
  EXPECT_LT(after.linf_stretch, 3.0);
  for (size_t f = 0; f < grid1.mesh.face_count(); ++f) {
    if (is_degenerate(grid1.frames, f)) continue;
    const float err = face_stretch_error(std::span<const float, 6>(&grid1.frames.local[6 * f], 6), options.scale,
                                         std::span<const float, 6>(&grid1.atlas.corner_uv[6 * f], 6));
    ASSERT_LE(err, internal::lattice_max_stretch(options.max_stretch) + 1e-3f) << "face " << f;
  }
  std::printf(
      "fandisk at scale 8000: invisible share growth %.3f, symmetry 4 %.3f (seams %.4f -> %.4f, visible "
      "%.4f -> %.4f)\n",
      before.seam_invisible_ratio, after.seam_invisible_ratio, before.seam_length_ratio, after.seam_length_ratio,
      before.visible_seam_ratio, after.visible_seam_ratio);
  MappingOptions bad;
  bad.symmetry = 3;
  EXPECT_EQ(map_into(grid1, bad).code(), ErrorCode::kInvalidArgument);
  bad.symmetry = 4;
  bad.mode = MappingMode::kThesis;
  EXPECT_EQ(map_into(grid1, bad).code(), ErrorCode::kInvalidArgument);
  bad.mode = MappingMode::kPatches;
  bad.texture_period_px = 0.f;
  EXPECT_EQ(map_into(grid1, bad).code(), ErrorCode::kInvalidArgument);
  // Faces a few millionths of the texture wide (scale 0.01: fandisk within 0.01 px) are refused,
  // not mapped with flipped faces (the lattice coordinates are floats modulo the period).
  bad.texture_period_px = 512.f;
  bad.scale = 0.01f;
  const Status tiny = map_into(grid1, bad);
  EXPECT_EQ(tiny.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(tiny.message().find("symmetry 4 needs faces at least"), std::string::npos) << tiny.message();
  bad.scale = 10.f;  // faces ~0.1 px: mapped, none flipped
  ASSERT_TRUE(map_into(grid1, bad).is_ok());
  EXPECT_EQ(metrics4(grid1).flipped, 0u);
}

// The local mixed-integer step of symmetry 4 (grid_cones.h) only moves singularities: the turns
// around all faces add up as before, paired half-edges keep inverse maps, cone pairs and
// dislocations merge away and no cone is made.
TEST(GridCones, MovesKeepTheTurnsAndMergeDislocations) {
  Mapped m;
  m.mesh = load_test_mesh("fandisk.off");
  m.topology = build_topology(m.mesh);
  ASSERT_TRUE(compute_orientation(m.mesh, m.topology, {}, m.frames).is_ok());
  internal::RosyFieldOptions field_options;
  field_options.scale = 8000.f;
  internal::RosyField field;
  internal::compute_rosy_field(m.mesh, m.topology, m.frames, field_options, field);
  const size_t nf = m.mesh.face_count();
  const uint32_t* idx = m.mesh.indices.data();
  std::vector<internal::LatticeMap> edge_map(3 * nf);
  for (size_t e = 0; e < 3 * nf; ++e)
    edge_map[e] = internal::lattice_map(field, idx[e], idx[e - e % 3 + (e % 3 + 1) % 3]);
  struct Count {
    size_t cones = 0, dislocations = 0;
    int turns = 0;
  };
  const auto count = [&] {
    Count c;
    for (size_t f = 0; f < nf; ++f) {
      const internal::LatticeMap h =
          internal::compose(edge_map[3 * f], internal::compose(edge_map[3 * f + 1], edge_map[3 * f + 2]));
      c.turns += h.r;
      if (h.r != 0)
        ++c.cones;
      else if (!(h == internal::LatticeMap{}))
        ++c.dislocations;
    }
    for (size_t e = 0; e < 3 * nf; ++e) {
      const uint32_t o = m.topology.opposite[e];
      if (o != kInvalid) {
        EXPECT_EQ(edge_map[o], internal::inverse(edge_map[e])) << "half-edge " << e;
      }
    }
    return c;
  };
  const Count before = count();
  const uint32_t paired = internal::cancel_cone_pairs(m.mesh, m.topology, edge_map);
  const Count unpaired = count();
  EXPECT_EQ(unpaired.turns % 4, before.turns % 4);
  EXPECT_EQ(unpaired.cones + 2 * paired, before.cones);  // a pair closes, or leaves a shift without a turn
  const uint32_t merged = internal::merge_dislocations(m.mesh, m.topology, edge_map);
  const internal::ConeMoves moves = internal::move_cones(m.mesh, m.topology, field.uv, field.period, edge_map);
  const Count after = count();
  std::printf(
      "fandisk at scale 8000: cones %zu -> %zu (%u pairs cancelled), dislocations %zu -> %zu (%u merged), %u "
      "cones moved\n",
      before.cones, after.cones, paired, before.dislocations, after.dislocations, merged, moves.moved);
  EXPECT_EQ(after.turns % 4, before.turns % 4);
  EXPECT_LE(after.cones, before.cones);
  EXPECT_GT(merged, 0u);
  EXPECT_LT(after.dislocations, before.dislocations);
  EXPECT_EQ(moves.cones, after.cones);
  EXPECT_GT(moves.moved, 0u);
}

TEST(AxisChoice, ACoordinateAxisCutsTheCadPartsSeams) {
  Mapped m;
  m.mesh = load_test_mesh("adis16480.stl");  // an axis-aligned CAD part; its principal axis runs diagonally
  m.topology = build_topology(m.mesh);
  AxisChoice choice;
  ASSERT_TRUE(choose_orientation_axis(m.mesh, m.topology, {}, choice).is_ok());
  // Measured: pca 7.7%, x 4.4%, y 4.1%, z 6.7% of edge length.
  EXPECT_NE(choice.best, AxisCandidate::kPca);
  const double best = choice.seam_ratio[static_cast<size_t>(choice.best)];
  for (const double ratio : choice.seam_ratio) EXPECT_LE(best, ratio);
  EXPECT_LT(best, 0.6 * choice.seam_ratio[0]);
  EXPECT_STREQ(axis_candidate_name(choice.best), "y");
  // The chosen options map to the same seams as the trial (growth only) reported.
  const OrientationOptions chosen = orientation_for(choice.best, {});
  EXPECT_EQ(chosen.axis, AxisSource::kUser);
  EXPECT_EQ(chosen.user_axis, (std::array<float, 3>{0.f, 1.f, 0.f}));
  MapTextureOptions growth;
  growth.orientation = chosen;
  growth.mapping.close_cracks = false;
  TextureMap map;
  ASSERT_TRUE(map_texture(m.mesh, m.topology, growth, map).is_ok());
  EXPECT_DOUBLE_EQ(map.metrics.seam_length_ratio, best);
  EXPECT_EQ(orientation_for(AxisCandidate::kPca, chosen).axis, AxisSource::kPca);
  // Cancelling through the progress callback.
  MapTextureOptions cancel;
  cancel.mapping.progress = [](float done) { return done < 0.5f; };
  EXPECT_EQ(choose_orientation_axis(m.mesh, m.topology, cancel, choice).code(), ErrorCode::kCancelled);
}

// The absorption re-places the faces held on more sides first: taken breadth first in face order,
// the faces of a CAD part's sliver fans joined their neighbours along the long edges (adis16480:
// 20.9 % visible seams, 5.4 % so).
TEST(Mapping, AbsorbedSliverFansKeepTheSeamsShort) {
  const Mesh mesh = load_test_mesh("adis16480.stl");
  const Topology topology = build_topology(mesh);
  TextureMap map;
  ASSERT_TRUE(map_texture(mesh, topology, MapTextureOptions{}, map).is_ok());  // field following
  EXPECT_EQ(map.metrics.flipped, 0u);
  EXPECT_LT(map.metrics.visible_seam_ratio, 0.08);
}

// A surface without area is refused, as a map's metrics refuse it (every vertex at one point).
TEST(Stability, ASurfaceWithoutAreaIsRefused) {
  Mesh flat = load_test_mesh("fandisk.off");
  for (size_t i = 0; i < flat.positions.size(); ++i) flat.positions[i] = static_cast<float>(i % 3);
  StabilityReport report;
  const Status s = measure_stability(flat, {}, report);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.message(), "every face has zero 3D area");
}

TEST(Stability, RemovingTenPercentKeepsMostOfTheMapping) {
  const Mesh mesh = load_test_mesh("fandisk.off");
  // The thesis's experiment: both runs keep the full mesh's axis, normalisation and seed.
  StabilityOptions pinned;
  pinned.pin_frame = true;
  StabilityReport report;
  const Status s = measure_stability(mesh, {}, report, pinned);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(report.faces, mesh.face_count());
  EXPECT_NEAR(static_cast<double>(report.removed_faces), 0.1 * static_cast<double>(mesh.face_count()), 1.0);
  EXPECT_EQ(report.compared_corners, 3 * (report.faces - report.removed_faces));
  EXPECT_TRUE(std::isfinite(report.mean_difference_px));
  EXPECT_GE(report.max_difference_px, report.mean_difference_px);
  EXPECT_GE(report.within_1px_ratio, report.identical_ratio);
  // The growth order is local (hop rule), so almost everything is reproduced bit for bit
  // (measured: 99.1%; 84% with the thesis's global counter). Crack closing relaxes regions that
  // overlap along a crack, so zips processed after one near the removed part change in the last
  // bits (measured: 97.7% bit-identical, 99.0% within 1 px, mean 0.04 px; 92.2% when the zips
  // went in edge order instead of nearest to the seed first). The final relaxation spreads any
  // change over the rings its iterations reach: 77.3% bit-identical, 98.8% within 1 px, 0.07 px.
  EXPECT_GT(report.identical_ratio, 0.7);
  EXPECT_GT(report.within_1px_ratio, 0.97);
  EXPECT_LT(report.mean_difference_px, 1.0);
  // On the horse the hop rule keeps 99% of the corners bit-identical and the mean change under
  // 1 px (measured 0.5 px); the global counter re-places whole regions (83%, 3.5 px). Compared
  // without crack closing, which would blur the difference (see above).
  const Mesh horse = load_test_mesh("horse.ply");
  StabilityReport hops, counter, closed;
  MapTextureOptions growth_only;
  growth_only.mapping.close_cracks = false;
  growth_only.mapping.relax_iterations = 0;
  ASSERT_TRUE(measure_stability(horse, growth_only, hops, pinned).is_ok());
  MapTextureOptions global_counter = growth_only;
  global_counter.mapping.hop_age = 0.f;
  ASSERT_TRUE(measure_stability(horse, global_counter, counter, pinned).is_ok());
  EXPECT_GT(hops.identical_ratio, 0.97);
  EXPECT_LT(hops.mean_difference_px, 1.0);
  // With crack closing and relaxation (default): measured 90.8% bit-identical, 99.3% within 1 px,
  // 0.51 px (without the relaxation 95.7%, 99.2%, 0.51 px; 91.1% with zips in edge order).
  ASSERT_TRUE(measure_stability(horse, {}, closed, pinned).is_ok());
  EXPECT_GT(closed.identical_ratio, 0.85);
  EXPECT_GT(closed.within_1px_ratio, 0.98);
  EXPECT_LT(closed.mean_difference_px, 1.0);
  EXPECT_LT(counter.identical_ratio, 0.9);
  EXPECT_GT(counter.mean_difference_px, 2.0 * hops.mean_difference_px);
  StabilityOptions bad;
  bad.remove_fraction = 0.f;
  EXPECT_EQ(measure_stability(mesh, {}, report, bad).code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace tailor
