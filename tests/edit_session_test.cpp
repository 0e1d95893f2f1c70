// EditSession (tailor/edit_session.h): edits, undo and redo, settle, on a real mesh.
#include "tailor/edit_session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <memory>
#include <span>
#include <thread>
#include <utility>
#include <vector>

#include "support/fixtures.h"
#include "tailor/chunks.h"
#include "tailor/topology.h"

namespace tailor {
namespace {

MapTextureOptions default_options() {
  MapTextureOptions options;
  EXPECT_TRUE(set_map_texture_size(options, 512, 512).is_ok());
  return options;
}

// What `tailor map` gives for these seam flags, strokes and options.
Atlas full_map(const Mesh& mesh, const std::vector<uint8_t>& seam, const std::vector<OrientationStroke>& strokes,
               MapTextureOptions options) {
  options.mapping.seam_faces = seam;
  options.orientation.strokes = strokes;
  TextureMap map;
  const Status s = map_texture(mesh, build_topology(mesh), options, map);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return map.atlas;
}

Atlas current_atlas(const EditSession& session) {
  Atlas atlas;
  std::vector<uint8_t> seam;
  std::vector<OrientationStroke> strokes;
  MapTextureOptions options;
  session.snapshot(atlas, seam, strokes, options);
  return atlas;
}

std::vector<float> uvs_of(const EditSession& session, uint64_t version) {
  std::vector<float> uv;
  EXPECT_TRUE(session.corner_uv_repeats(version, uv)) << "version " << version;
  return uv;
}

// A stroke through the first corners of a run of faces (on the surface), with a radius of a
// twentieth of the mesh's longest side.
OrientationStroke stroke_along(const Mesh& mesh, uint32_t first, uint32_t count) {
  OrientationStroke s;
  for (uint32_t f = first; f < first + count; ++f) {
    const uint32_t v = mesh.indices[3 * f];
    for (int c = 0; c < 3; ++c) s.points.push_back(mesh.positions[3 * v + c]);
  }
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], mesh.positions[3 * v + c]);
      hi[c] = std::max(hi[c], mesh.positions[3 * v + c]);
    }
  s.radius = 0.05f * std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  return s;
}

std::unique_ptr<EditSession> open_session(const Mesh& mesh, const MapTextureOptions& options) {
  std::unique_ptr<EditSession> session;
  const Status s = EditSession::open(mesh, options, session);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return session;
}

TEST(EditSession, OpensWithTheFullMap) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  EXPECT_EQ(session->version(), 0u);
  EXPECT_TRUE(session->settled());
  const Atlas expected = full_map(mesh, {}, {}, default_options());
  const Atlas atlas = current_atlas(*session);
  EXPECT_EQ(atlas.corner_uv, expected.corner_uv);
  EXPECT_EQ(atlas.patch, expected.patch);
  const std::vector<float> uv = uvs_of(*session, 0);
  ASSERT_EQ(uv.size(), expected.corner_uv.size());
  for (size_t i = 0; i < uv.size(); ++i) ASSERT_EQ(uv[i], static_cast<float>(expected.corner_uv[i] * (1.0 / 512)));
  EXPECT_EQ(session->mesh().face_count(), mesh.face_count());
}

TEST(EditSession, EditsThenSettleGiveTheFullMapBitForBit) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  MapTextureOptions options = default_options();
  options.mapping.threads = 2;
  const auto session = open_session(mesh, options);
  ASSERT_TRUE(session);
  EditRequest edit;
  for (uint32_t f = 1000; f < 1200; ++f) edit.add_seam_faces.push_back(f);
  EditResult result;
  ASSERT_TRUE(session->apply(edit, result).is_ok());
  EXPECT_EQ(result.version, 1u);
  EXPECT_GT(result.changed_faces, 0u);
  edit = {};
  edit.remove_seam_faces = {1000, 1001, 1002};
  edit.strokes.push_back(stroke_along(mesh, 3000, 20));
  ASSERT_TRUE(session->apply(edit, result).is_ok());
  EXPECT_EQ(result.version, 2u);
  ASSERT_TRUE(session->settle(result).is_ok());
  EXPECT_TRUE(result.settled);
  EXPECT_TRUE(session->settled());

  std::vector<uint8_t> seam(mesh.face_count(), 0);
  for (uint32_t f = 1003; f < 1200; ++f) seam[f] = 1;
  options.mapping.threads = 1;  // the settled map does not depend on the thread count
  const Atlas expected = full_map(mesh, seam, {stroke_along(mesh, 3000, 20)}, options);
  const Atlas atlas = current_atlas(*session);
  EXPECT_EQ(atlas.corner_uv, expected.corner_uv);
  EXPECT_EQ(atlas.patch, expected.patch);
  EXPECT_EQ(atlas.patch_count, expected.patch_count);

  Atlas snapshot_atlas;
  std::vector<uint8_t> snapshot_seam;
  std::vector<OrientationStroke> snapshot_strokes;
  MapTextureOptions snapshot_options;
  session->snapshot(snapshot_atlas, snapshot_seam, snapshot_strokes, snapshot_options);
  EXPECT_EQ(snapshot_seam, seam);
  ASSERT_EQ(snapshot_strokes.size(), 1u);
  EXPECT_EQ(snapshot_strokes[0].points, stroke_along(mesh, 3000, 20).points);
  EXPECT_TRUE(snapshot_options.mapping.seam_faces.empty());
}

TEST(EditSession, UndoAndRedoRestoreTheUvsBitForBit) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  const std::vector<float> uv0 = uvs_of(*session, 0);
  EditRequest a;
  for (uint32_t f = 200; f < 400; ++f) a.add_seam_faces.push_back(f);
  EditResult result;
  ASSERT_TRUE(session->apply(a, result).is_ok());
  const std::vector<float> uv_a = uvs_of(*session, result.version);
  EXPECT_NE(uv_a, uv0);
  EditRequest b;
  b.strokes.push_back(stroke_along(mesh, 4000, 30));
  ASSERT_TRUE(session->apply(b, result).is_ok());
  const std::vector<float> uv_b = uvs_of(*session, result.version);
  EXPECT_NE(uv_b, uv_a);

  ASSERT_TRUE(session->undo(result).is_ok());
  EXPECT_EQ(result.version, 3u);
  EXPECT_EQ(uvs_of(*session, result.version), uv_a);
  ASSERT_TRUE(session->undo(result).is_ok());
  EXPECT_EQ(uvs_of(*session, result.version), uv0);
  EXPECT_TRUE(result.settled);
  EXPECT_EQ(session->undo(result).code(), ErrorCode::kInvalidArgument);  // nothing left to undo
  ASSERT_TRUE(session->redo(result).is_ok());
  EXPECT_EQ(uvs_of(*session, result.version), uv_a);
  ASSERT_TRUE(session->redo(result).is_ok());
  EXPECT_EQ(uvs_of(*session, result.version), uv_b);
  EXPECT_EQ(session->redo(result).code(), ErrorCode::kInvalidArgument);  // nothing left to redo

  // Undo then a new edit drops the redo branch.
  ASSERT_TRUE(session->undo(result).is_ok());
  EditRequest c;
  c.remove_seam_faces = {200};
  ASSERT_TRUE(session->apply(c, result).is_ok());
  EXPECT_EQ(session->redo(result).code(), ErrorCode::kInvalidArgument);
  // The settled state is the full map of the state after a and c.
  ASSERT_TRUE(session->settle(result).is_ok());
  std::vector<uint8_t> seam(mesh.face_count(), 0);
  for (uint32_t f = 201; f < 400; ++f) seam[f] = 1;
  const Atlas expected = full_map(mesh, seam, {}, default_options());
  EXPECT_EQ(current_atlas(*session).corner_uv, expected.corner_uv);
}

TEST(EditSession, BadEditsChangeNothing) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  const Atlas before = current_atlas(*session);
  const uint32_t faces = static_cast<uint32_t>(mesh.face_count());
  std::vector<EditRequest> bad(7);
  bad[0].add_seam_faces = {1, faces};
  bad[1].remove_seam_faces = {faces + 10};
  bad[2].strokes.push_back({{0.f, 0.f, 0.f}, 1.f});                 // one point
  bad[3].strokes.push_back({{0.f, 0.f, 0.f, 1.f, NAN, 0.f}, 1.f});  // not finite
  bad[4].strokes.push_back({{0.f, 0.f, 0.f, 1.f, 1.f, 0.f}, 0.f});  // radius 0
  bad[5].options = default_options();
  bad[5].options->mapping.scale = 0.f;  // check_map_options refuses
  bad[6].options = default_options();
  bad[6].options->mapping.max_stretch = 100.f;  // map_texture refuses
  for (EditRequest& edit : bad) {
    edit.add_seam_faces.push_back(5);  // a valid part that must not be applied either
    EditResult result;
    EXPECT_EQ(session->apply(edit, result).code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(session->version(), 0u);
    EXPECT_TRUE(session->settled());
  }
  Atlas atlas;
  std::vector<uint8_t> seam;
  std::vector<OrientationStroke> strokes;
  MapTextureOptions options;
  session->snapshot(atlas, seam, strokes, options);
  EXPECT_EQ(atlas.corner_uv, before.corner_uv);
  EXPECT_EQ(seam, std::vector<uint8_t>(mesh.face_count(), 0));
  EXPECT_TRUE(strokes.empty());
  EXPECT_EQ(options.mapping.scale, default_options().mapping.scale);
  EditResult result;
  EXPECT_EQ(session->undo(result).code(), ErrorCode::kInvalidArgument);
  // An edit that changes nothing makes no version.
  EditRequest none;
  none.remove_seam_faces = {3};
  ASSERT_TRUE(session->apply(none, result).is_ok());
  EXPECT_EQ(result.version, 0u);
  EXPECT_EQ(result.changed_faces, 0u);
  EXPECT_TRUE(result.settled);
}

// A stroke of n points along x, far beyond the mesh (its field reaches no face).
OrientationStroke far_stroke(size_t n) {
  OrientationStroke s{std::vector<float>(3 * n, 100.f), 0.01f};
  for (size_t i = 0; i < n; ++i) s.points[3 * i] = 100.f + 0.001f * static_cast<float>(i);
  return s;
}

// Every edit samples all the strokes a session holds: at most 2^20 points, counted over the
// session's strokes and the edit's, and over a file's strokes when it opens.
TEST(EditSession, TheStrokePointsOfASessionAreBounded) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  EditRequest half;
  half.strokes.push_back(far_stroke((size_t{1} << 19) + 1));
  EditResult result;
  ASSERT_TRUE(session->apply(half, result).is_ok());
  const uint64_t version = session->version();
  half.strokes[0] = far_stroke(size_t{1} << 19);
  const Status refused = session->apply(half, result);
  EXPECT_EQ(refused.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(refused.message().find("at most 1048576 stroke points, these are 1048577"), std::string::npos)
      << refused.message();
  EXPECT_EQ(session->version(), version);
  MapTextureOptions options = default_options();
  const std::vector<OrientationStroke> file_strokes = {far_stroke((size_t{1} << 20) + 1)};
  options.orientation.strokes = file_strokes;
  std::unique_ptr<EditSession> too_many;
  EXPECT_EQ(EditSession::open(mesh, options, too_many).code(), ErrorCode::kInvalidArgument);
  EXPECT_FALSE(too_many);
}

// The most a local update may change: faces of the patches holding `edited` faces and of the
// patches bordering those, and (local_update.cpp: 24) within 40 edge rings of the edited faces.
std::vector<uint8_t> patch_region(const Topology& topology, const Atlas& atlas, const std::vector<uint32_t>& edited) {
  std::vector<uint8_t> mark(atlas.patch_count, 0), region(atlas.patch.size(), 0);
  for (const uint32_t f : edited) mark[atlas.patch[f]] = 1;
  for (size_t f = 0; f < atlas.patch.size(); ++f)
    if (mark[atlas.patch[f]] == 1)
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = neighbour_face(topology, static_cast<uint32_t>(3 * f + k));
        if (g != kInvalid && mark[atlas.patch[g]] == 0) mark[atlas.patch[g]] = 2;
      }
  std::vector<uint32_t> ring(atlas.patch.size(), kInvalid), fifo;
  for (const uint32_t f : edited)
    if (ring[f] == kInvalid) ring[f] = 0, fifo.push_back(f);
  for (size_t head = 0; head < fifo.size(); ++head)
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = neighbour_face(topology, 3 * fifo[head] + k);
      if (g != kInvalid && ring[g] == kInvalid) ring[g] = ring[fifo[head]] + 1, fifo.push_back(g);
    }
  for (size_t f = 0; f < atlas.patch.size(); ++f) region[f] = mark[atlas.patch[f]] != 0 && ring[f] <= 40;
  return region;
}

uint32_t faces_changed(const Atlas& a, const Atlas& b) {
  uint32_t n = 0;
  for (size_t f = 0; f < a.patch.size(); ++f) {
    bool same = a.patch[f] == b.patch[f];
    for (int i = 0; i < 6; ++i) same = same && a.corner_uv[6 * f + i] == b.corner_uv[6 * f + i];
    n += same ? 0 : 1;
  }
  return n;
}

// Edges (each once) whose two faces' UVs differ along them, touching one of `faces`.
size_t seam_edges_at(const Mesh& mesh, const Topology& topology, const Atlas& atlas,
                     const std::vector<uint8_t>& faces) {
  size_t n = 0;
  for (size_t e = 0; e < 3 * mesh.face_count(); ++e) {
    const uint32_t o = topology.opposite[e];
    if (o == kInvalid || o < e || !(faces[e / 3] || faces[o / 3])) continue;
    const float* a = &atlas.corner_uv[2 * e];
    const float* a1 = &atlas.corner_uv[2 * (3 * (e / 3) + (e + 1) % 3)];
    const float* b = &atlas.corner_uv[2 * o];
    const float* b1 = &atlas.corner_uv[2 * (3 * (o / 3) + (o + 1) % 3)];
    n += !(a[0] == b1[0] && a[1] == b1[1] && a1[0] == b[0] && a1[1] == b[1]);
  }
  return n;
}

// Every face placed with finite UVs, within the per-face stretch bound, not inverted.
void expect_valid(const Mesh& mesh, const Atlas& atlas, const MapTextureOptions& options) {
  FaceFrames frames;
  ASSERT_TRUE(compute_orientation(mesh, build_topology(mesh), options.orientation, frames).is_ok());
  ASSERT_EQ(atlas.corner_uv.size(), 6 * mesh.face_count());
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    ASSERT_LT(atlas.patch[f], atlas.patch_count);
    for (int i = 0; i < 6; ++i) ASSERT_TRUE(std::isfinite(atlas.corner_uv[6 * f + i])) << "face " << f;
    const float* l = &frames.local[6 * f];
    if (l[2] * l[5] - l[3] * l[4] <= 0.f) continue;  // zero-area face
    const float e = face_stretch_error(std::span<const float, 6>(l, 6), options.mapping.scale,
                                       std::span<const float, 6>(&atlas.corner_uv[6 * f], 6));
    ASSERT_LE(e, options.mapping.max_stretch * 1.001f) << "face " << f;
  }
}

TEST(EditSession, ALocalUpdateKeepsTheFacesBeyondTheEditedPatchesBitForBit) {
  const Mesh mesh = test::load_test_mesh("fertility.off");
  const Topology topology = build_topology(mesh);
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  // A brush of 80 faces, breadth first from a face in the middle of the face order.
  std::vector<uint32_t> brush{static_cast<uint32_t>(mesh.face_count() / 2)};
  std::vector<uint8_t> in_brush(mesh.face_count(), 0);
  in_brush[brush[0]] = 1;
  for (size_t i = 0; i < brush.size() && brush.size() < 80; ++i)
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = neighbour_face(topology, 3 * brush[i] + k);
      if (g != kInvalid && !in_brush[g] && brush.size() < 80) in_brush[g] = 1, brush.push_back(g);
    }
  const Atlas before = current_atlas(*session);
  EditRequest edit;
  edit.add_seam_faces = brush;
  EditResult result;
  ASSERT_TRUE(session->apply(edit, result).is_ok());
  EXPECT_FALSE(result.settled);
  EXPECT_FALSE(session->settled());
  const Atlas after = current_atlas(*session);
  const std::vector<uint8_t> region = patch_region(topology, before, brush);
  size_t outside = 0;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    if (region[f]) continue;
    ++outside;
    ASSERT_EQ(after.patch[f], before.patch[f]) << "face " << f;
    for (int i = 0; i < 6; ++i) ASSERT_EQ(after.corner_uv[6 * f + i], before.corner_uv[6 * f + i]) << "face " << f;
  }
  EXPECT_GT(outside, 0u);
  EXPECT_EQ(result.changed_faces, faces_changed(before, after));
  EXPECT_GT(result.changed_faces, 0u);
  expect_valid(mesh, after, default_options());
  // The seams move onto the marked faces (thesis figure 2.8), already in the fast update.
  const size_t seams_before = seam_edges_at(mesh, topology, before, in_brush);
  const size_t seams_after = seam_edges_at(mesh, topology, after, in_brush);
  std::vector<uint8_t> flags(mesh.face_count(), 0);
  for (const uint32_t f : brush) flags[f] = 1;
  const Atlas settled_atlas = full_map(mesh, flags, {}, default_options());
  const size_t seams_full = seam_edges_at(mesh, topology, settled_atlas, in_brush);
  const std::vector<uint8_t> all(mesh.face_count(), 1);
  std::printf("seam edges in all: %zu before, %zu after the local update, %zu settled\n",
              seam_edges_at(mesh, topology, before, all), seam_edges_at(mesh, topology, after, all),
              seam_edges_at(mesh, topology, settled_atlas, all));
  std::printf(
      "brush of %zu faces: %zu seam edges at it before, %zu after the local update (%zu settled); %u faces "
      "changed\n",
      brush.size(), seams_before, seams_after, seams_full, result.changed_faces);
  EXPECT_GT(seams_after, seams_before);

  // Unmarking them again is local too; settling gives the full map of the state.
  EditRequest undo_edit;
  undo_edit.remove_seam_faces = brush;
  ASSERT_TRUE(session->apply(undo_edit, result).is_ok());
  expect_valid(mesh, current_atlas(*session), default_options());
  ASSERT_TRUE(session->settle(result).is_ok());
  EXPECT_EQ(current_atlas(*session).corner_uv, before.corner_uv);
}

TEST(EditSession, AStrokeUpdatesOnlyThePatchesItReaches) {
  const Mesh mesh = test::load_test_mesh("fertility.off");
  const Topology topology = build_topology(mesh);
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  const Atlas before = current_atlas(*session);
  const OrientationStroke stroke = stroke_along(mesh, static_cast<uint32_t>(mesh.face_count() / 3), 12);
  // The faces whose frame the stroke can change: those it reaches (centroid within the radius).
  FaceFrames plain, stroked;
  MapTextureOptions options = default_options();
  ASSERT_TRUE(compute_orientation(mesh, topology, options.orientation, plain).is_ok());
  options.orientation.strokes = std::span<const OrientationStroke>(&stroke, 1);
  ASSERT_TRUE(compute_orientation(mesh, topology, options.orientation, stroked).is_ok());
  std::vector<uint32_t> reached;
  for (uint32_t f = 0; f < mesh.face_count(); ++f)
    if (plain.orientation[3 * f] != stroked.orientation[3 * f] ||
        plain.orientation[3 * f + 1] != stroked.orientation[3 * f + 1] ||
        plain.orientation[3 * f + 2] != stroked.orientation[3 * f + 2])
      reached.push_back(f);
  ASSERT_GT(reached.size(), 10u);
  EditRequest edit;
  edit.strokes.push_back(stroke);
  EditResult result;
  ASSERT_TRUE(session->apply(edit, result).is_ok());
  const Atlas after = current_atlas(*session);
  const std::vector<uint8_t> region = patch_region(topology, before, reached);
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    if (region[f]) continue;
    ASSERT_EQ(after.patch[f], before.patch[f]) << "face " << f;
    for (int i = 0; i < 6; ++i) ASSERT_EQ(after.corner_uv[6 * f + i], before.corner_uv[6 * f + i]) << "face " << f;
  }
  EXPECT_EQ(result.changed_faces, faces_changed(before, after));
  EXPECT_GT(result.changed_faces, 0u);
  expect_valid(mesh, after, options);
  ASSERT_TRUE(session->settle(result).is_ok());
  EXPECT_EQ(current_atlas(*session).corner_uv, full_map(mesh, {}, {stroke}, default_options()).corner_uv);
}

// Opens `mesh` with `options` on 1 and on 3 threads, applies three edits (50 seam faces from face
// `stride` * i and a stroke from face `stride` * i + 1000) to both and expects the same changes and
// UV bits after each. Returns the two sessions for more checks.
std::pair<std::unique_ptr<EditSession>, std::unique_ptr<EditSession>> expect_edits_same_on_1_and_3_threads(
    const Mesh& mesh, const MapTextureOptions& options, uint32_t stride) {
  MapTextureOptions one = options, three = options;
  one.mapping.threads = one.orientation.threads = 1;
  three.mapping.threads = three.orientation.threads = 3;
  auto a = open_session(mesh, one);
  auto b = open_session(mesh, three);
  EXPECT_TRUE(a && b);
  if (!a || !b) return {};
  for (uint32_t i = 0; i < 3; ++i) {
    EditRequest edit;
    for (uint32_t f = stride * i; f < stride * i + 50; ++f) edit.add_seam_faces.push_back(f);
    edit.strokes.push_back(stroke_along(mesh, stride * i + 1000, 8));
    EditResult ra, rb;
    EXPECT_TRUE(a->apply(edit, ra).is_ok());
    EXPECT_TRUE(b->apply(edit, rb).is_ok());
    EXPECT_EQ(ra.changed_faces, rb.changed_faces);
    EXPECT_EQ(uvs_of(*a, ra.version), uvs_of(*b, rb.version));
  }
  return {std::move(a), std::move(b)};
}

TEST(EditSession, LocalUpdatesAreTheSameForAnyThreadCount) {
  const Mesh mesh = test::load_test_mesh("fertility.off");
  expect_edits_same_on_1_and_3_threads(mesh, default_options(), 2000);
}

// Beyond the 8 kept atlases, undo updates locally (strokes removed, seam flags flipped back):
// settled, the state is the full map of what is left.
TEST(EditSession, UndoingPastTheKeptAtlasesSettlesToTheFullMap) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  EditResult result;
  for (uint32_t i = 0; i < 11; ++i) {
    EditRequest edit;
    for (uint32_t f = 500 * i; f < 500 * i + 30; ++f) edit.add_seam_faces.push_back(f);
    if (i % 2 == 0) edit.strokes.push_back(stroke_along(mesh, 500 * i + 200, 6));
    ASSERT_TRUE(session->apply(edit, result).is_ok());
  }
  for (int i = 0; i < 9; ++i) ASSERT_TRUE(session->undo(result).is_ok());
  EXPECT_FALSE(result.settled);
  ASSERT_TRUE(session->settle(result).is_ok());
  std::vector<uint8_t> seam(mesh.face_count(), 0);
  for (uint32_t f = 0; f < 30; ++f) seam[f] = seam[500 + f] = 1;
  const Atlas expected = full_map(mesh, seam, {stroke_along(mesh, 200, 6)}, default_options());
  EXPECT_EQ(current_atlas(*session).corner_uv, expected.corner_uv);
  EXPECT_EQ(current_atlas(*session).patch, expected.patch);
}

TEST(EditSession, EditsFromSeveralThreadsSettleToTheFullMap) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const auto session = open_session(mesh, default_options());
  ASSERT_TRUE(session);
  std::thread settler([&] {
    for (int i = 0; i < 20; ++i) {
      EditResult r;
      EXPECT_TRUE(session->settle(r).is_ok());
    }
  });
  std::thread reader([&] {
    for (int i = 0; i < 200; ++i) {
      std::vector<float> uv;
      if (session->corner_uv_repeats(session->version(), uv)) {
        EXPECT_EQ(uv.size(), 6 * mesh.face_count());
      }
    }
  });
  for (uint32_t i = 0; i < 6; ++i) {
    EditRequest edit;
    for (uint32_t f = 500 * i; f < 500 * i + 80; ++f) edit.add_seam_faces.push_back(f);
    EditResult r;
    EXPECT_TRUE(session->apply(edit, r).is_ok());
  }
  settler.join();
  reader.join();
  EditResult r;
  ASSERT_TRUE(session->settle(r).is_ok());
  EXPECT_TRUE(r.settled);
  std::vector<uint8_t> seam(mesh.face_count(), 0);
  for (uint32_t i = 0; i < 6; ++i)
    for (uint32_t f = 500 * i; f < 500 * i + 80; ++f) seam[f] = 1;
  EXPECT_EQ(current_atlas(*session).corner_uv, full_map(mesh, seam, {}, default_options()).corner_uv);
}

// === Chunked sessions: the mesh cut into chunks (tailor/chunks.h); an edit touches only its chunks ===

// Options that cut the horse (97k faces) into chunks of a cell 1/3 of its longest side.
MapTextureOptions chunked_options(const Mesh& mesh) {
  MapTextureOptions options = default_options();
  float lo = INFINITY, hi = -INFINITY;
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    for (size_t k = 0; k < 3; ++k) {
      lo = std::min(lo, mesh.positions[3 * v + k]);
      hi = std::max(hi, mesh.positions[3 * v + k]);
    }
  options.chunks.mode = ChunkMode::kOn;
  options.chunks.cell_exponent = static_cast<int>(std::floor(std::log2((double{hi} - lo) / 3)));
  return options;
}

// Each face's chunk under those options.
std::vector<uint32_t> chunk_of_faces(const Mesh& mesh, const MapTextureOptions& options, size_t& chunks) {
  ChunkPlan plan;
  EXPECT_TRUE(plan_chunks(mesh, options.chunks, plan).is_ok());
  std::vector<uint32_t> chunk(mesh.face_count(), 0);
  for (uint32_t c = 0; c < plan.chunk_count(); ++c)
    for (uint32_t i = plan.chunk_start[c]; i < plan.chunk_start[c + 1]; ++i) chunk[plan.faces[i]] = c;
  chunks = plan.chunk_count();
  return chunk;
}

// The chunks holding a face whose centroid lies within a stroke's radius (brute force).
std::vector<uint8_t> chunks_reached(const Mesh& mesh, const std::vector<uint32_t>& chunk, size_t chunks,
                                    const OrientationStroke& stroke) {
  std::vector<uint8_t> reached(chunks, 0);
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    double q[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) q[c] += mesh.positions[3 * size_t{mesh.indices[3 * f + k]} + c] / 3.0;
    for (size_t i = 0; i + 5 < stroke.points.size(); i += 3) {
      double d[3], aq[3], dd = 0, t = 0;
      for (int c = 0; c < 3; ++c) {
        d[c] = double{stroke.points[i + 3 + c]} - stroke.points[i + c];
        aq[c] = q[c] - stroke.points[i + c];
        dd += d[c] * d[c];
        t += aq[c] * d[c];
      }
      t = dd > 0 ? std::clamp(t / dd, 0.0, 1.0) : 0.0;
      double e2 = 0;
      for (int c = 0; c < 3; ++c) e2 += (aq[c] - t * d[c]) * (aq[c] - t * d[c]);
      if (e2 < double{stroke.radius} * stroke.radius * 1.01) reached[chunk[f]] = 1;
    }
  }
  return reached;
}

// The UVs (repeats, 6 per face) of the faces in chunks not flagged are bit-identical in a and b;
// returns how many faces were compared.
size_t expect_same_outside(const std::vector<float>& a, const std::vector<float>& b, const std::vector<uint32_t>& chunk,
                           const std::vector<uint8_t>& touched) {
  size_t compared = 0;
  for (size_t f = 0; f < chunk.size(); ++f) {
    if (touched[chunk[f]]) continue;
    ++compared;
    for (size_t k = 6 * f; k < 6 * f + 6; ++k)
      if (std::bit_cast<uint32_t>(a[k]) != std::bit_cast<uint32_t>(b[k])) {
        ADD_FAILURE() << "face " << f << " of untouched chunk " << chunk[f] << " moved";
        return compared;
      }
  }
  return compared;
}

std::vector<uint8_t> changed_chunks(const std::vector<float>& a, const std::vector<float>& b,
                                    const std::vector<uint32_t>& chunk, size_t chunks) {
  std::vector<uint8_t> changed(chunks, 0);
  for (size_t f = 0; f < chunk.size(); ++f)
    for (size_t k = 6 * f; k < 6 * f + 6; ++k)
      if (std::bit_cast<uint32_t>(a[k]) != std::bit_cast<uint32_t>(b[k])) changed[chunk[f]] = 1;
  return changed;
}

TEST(EditSession, ChunkedEditsChangeOnlyTheTouchedChunksAndSettleToAFreshChunkedMap) {
  const Mesh mesh = test::load_test_mesh("horse.ply");
  const MapTextureOptions options = chunked_options(mesh);
  size_t chunks = 0;
  const std::vector<uint32_t> chunk = chunk_of_faces(mesh, options, chunks);
  ASSERT_GE(chunks, 6u);
  const auto session = open_session(mesh, options);
  ASSERT_TRUE(session);
  {  // version 0 is the chunked map_texture
    const Atlas expected = full_map(mesh, {}, {}, options);
    EXPECT_EQ(current_atlas(*session).corner_uv, expected.corner_uv);
    EXPECT_EQ(current_atlas(*session).patch, expected.patch);
  }
  const std::vector<float> uv0 = uvs_of(*session, 0);

  // Seam faces in one chunk: only that chunk's UVs change.
  const uint32_t brush_chunk = chunk[20000];
  EditRequest seams;
  std::vector<uint8_t> seam(mesh.face_count(), 0);
  for (uint32_t f = 20000; seams.add_seam_faces.size() < 60 && f < mesh.face_count(); ++f)
    if (chunk[f] == brush_chunk) seams.add_seam_faces.push_back(f), seam[f] = 1;
  EditResult result;
  ASSERT_TRUE(session->apply(seams, result).is_ok());
  EXPECT_FALSE(result.settled);
  EXPECT_GT(result.changed_faces, 0u);
  const std::vector<float> uv1 = uvs_of(*session, result.version);
  std::vector<uint8_t> touched(chunks, 0);
  touched[brush_chunk] = 1;
  EXPECT_GT(expect_same_outside(uv0, uv1, chunk, touched), mesh.face_count() / 2);
  EXPECT_TRUE(changed_chunks(uv0, uv1, chunk, chunks)[brush_chunk]);

  // A stroke: only the chunks holding faces it reaches change.
  OrientationStroke stroke = stroke_along(mesh, 60000, 12);
  stroke.radius *= 0.5f;
  const std::vector<uint8_t> reached = chunks_reached(mesh, chunk, chunks, stroke);
  ASSERT_LT(std::count(reached.begin(), reached.end(), 1), static_cast<std::ptrdiff_t>(chunks) - 2);
  EditRequest draw;
  draw.strokes.push_back(stroke);
  ASSERT_TRUE(session->apply(draw, result).is_ok());
  const std::vector<float> uv2 = uvs_of(*session, result.version);
  EXPECT_GT(expect_same_outside(uv1, uv2, chunk, reached), mesh.face_count() / 3);
  const std::vector<uint8_t> moved = changed_chunks(uv1, uv2, chunk, chunks);
  EXPECT_GT(std::count(moved.begin(), moved.end(), 1), 0);

  // Settled: a fresh chunked map of the mesh with those seam faces and that stroke, bit for bit;
  // the chunks no edit touched still have version 0's UVs.
  ASSERT_TRUE(session->settle(result).is_ok());
  EXPECT_TRUE(result.settled);
  const Atlas expected = full_map(mesh, seam, {stroke}, options);
  const Atlas atlas = current_atlas(*session);
  EXPECT_EQ(atlas.corner_uv, expected.corner_uv);
  EXPECT_EQ(atlas.patch, expected.patch);
  EXPECT_EQ(atlas.patch_count, expected.patch_count);
  std::vector<uint8_t> any = reached;
  any[brush_chunk] = 1;
  expect_same_outside(uv0, uvs_of(*session, result.version), chunk, any);

  // Undo the stroke (the kept atlas of version 1), then draw it elsewhere and settle: the kept
  // canonical forms followed the undo.
  ASSERT_TRUE(session->undo(result).is_ok());
  EXPECT_EQ(uvs_of(*session, result.version), uv1);
  const OrientationStroke other = stroke_along(mesh, 20100, 10);
  draw.strokes = {other};
  ASSERT_TRUE(session->apply(draw, result).is_ok());
  ASSERT_TRUE(session->settle(result).is_ok());
  const Atlas expected2 = full_map(mesh, seam, {other}, options);
  EXPECT_EQ(current_atlas(*session).corner_uv, expected2.corner_uv);
  EXPECT_EQ(current_atlas(*session).patch, expected2.patch);
}

TEST(EditSession, ChunkedLocalUpdatesAreTheSameForAnyThreadCount) {
  const Mesh mesh = test::load_test_mesh("horse.ply");
  const auto [a, b] = expect_edits_same_on_1_and_3_threads(mesh, chunked_options(mesh), 30000);
  ASSERT_TRUE(a && b);
  EditResult ra, rb;
  ASSERT_TRUE(a->settle(ra).is_ok());
  ASSERT_TRUE(b->settle(rb).is_ok());
  EXPECT_EQ(uvs_of(*a, ra.version), uvs_of(*b, rb.version));
}

// Field smoothing spreads a stroke within its chunk: the touched chunks are mapped again at
// once (settled), the others keep their bits.
TEST(EditSession, ChunkedEditsWithSmoothingMapTheTouchedChunksAtOnce) {
  const Mesh mesh = test::load_test_mesh("horse.ply");
  MapTextureOptions options = chunked_options(mesh);
  options.orientation.smooth_passes = 2;
  size_t chunks = 0;
  const std::vector<uint32_t> chunk = chunk_of_faces(mesh, options, chunks);
  const auto session = open_session(mesh, options);
  ASSERT_TRUE(session);
  OrientationStroke stroke = stroke_along(mesh, 60000, 12);
  stroke.radius *= 0.5f;
  EditRequest draw;
  draw.strokes.push_back(stroke);
  EditResult result;
  ASSERT_TRUE(session->apply(draw, result).is_ok());
  EXPECT_TRUE(result.settled);
  EXPECT_GT(expect_same_outside(uvs_of(*session, 0), uvs_of(*session, result.version), chunk,
                                chunks_reached(mesh, chunk, chunks, stroke)),
            mesh.face_count() / 3);
  EXPECT_EQ(current_atlas(*session).corner_uv, full_map(mesh, {}, {stroke}, options).corner_uv);
}

}  // namespace
}  // namespace tailor
