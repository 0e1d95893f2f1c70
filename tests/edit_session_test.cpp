// EditSession (tailor/edit_session.h): edits, undo and redo, settle, on a real mesh.
#include "tailor/edit_session.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "support/fixtures.h"
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

// A stroke through a run of the mesh's vertices (on the surface), with a radius of a tenth of it.
OrientationStroke stroke_along(const Mesh& mesh, uint32_t first, uint32_t count) {
  OrientationStroke s;
  for (uint32_t f = first; f < first + count; ++f) {
    const uint32_t v = mesh.indices[3 * f];
    for (int c = 0; c < 3; ++c) s.points.push_back(mesh.positions[3 * v + c]);
  }
  s.radius = 0.1f;
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

}  // namespace
}  // namespace tailor
