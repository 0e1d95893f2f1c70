// Export (.glb / .obj / .ply), vertex splitting, the glb reader and `tailor eval`.
#include "tailor/export.h"

#include <gtest/gtest.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <sys/resource.h>

#include <bit>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <string_view>
#include <tuple>

#include "support/fixtures.h"
#include "tailor/gltf.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/metrics.h"
#include "tailor/orientation.h"
#include "tailor/topology.h"
#include "util/atomic_file.h"

namespace tailor {
namespace {

namespace fs = std::filesystem;
using test::read_all;
using test::run_command;

const std::string kTexture = std::string(TAILOR_TEST_DATA) + "/textures/vistex-tile04-128.png";
const std::string kSpot = std::string(TAILOR_TEST_DATA) + "/meshes/spot.obj";
constexpr float kPixelsPerUnit = 64;

// Unit cube, 8 vertices, 12 triangles counter-clockwise from outside; each side is its own patch
// with an identity map (64 px per unit) offset by 100 px per patch along u.
void make_cube(Mesh& mesh, Atlas& atlas) {
  mesh = Mesh{};
  atlas = Atlas{};
  for (int v = 0; v < 8; ++v) {
    mesh.positions.push_back(static_cast<float>(v & 1));
    mesh.positions.push_back(static_cast<float>((v >> 1) & 1));
    mesh.positions.push_back(static_cast<float>((v >> 2) & 1));
  }
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  const float quad_uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (uint32_t q = 0; q < 6; ++q) {
    const int tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (const auto& tri : tris) {
      for (int k : tri) {
        mesh.indices.push_back(quads[q][k]);
        atlas.corner_uv.push_back(kPixelsPerUnit * quad_uv[k][0] + 100.0f * static_cast<float>(q));
        atlas.corner_uv.push_back(kPixelsPerUnit * quad_uv[k][1]);
      }
      atlas.patch.push_back(q);
    }
  }
  atlas.patch_count = 6;
}

class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::empty_temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    make_cube(cube_, cube_atlas_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // Names of the files in the test folder that contain ".tmp-" (left-over temporaries).
  size_t temporaries() const {
    size_t n = 0;
    for (const auto& entry : fs::recursive_directory_iterator(dir_))
      if (entry.path().filename().string().find(".tmp-") != std::string::npos) ++n;
    return n;
  }
  fs::path dir_;
  Mesh cube_;
  Atlas cube_atlas_;
};

bool have_node() {
  std::string out;
  return run_command("command -v node", out) == 0;
}

// Runs the Khronos validator; expects no error and no warning.
void expect_valid_gltf(const std::string& file) {
  if (!have_node()) GTEST_SKIP() << "node not installed: glTF validation skipped";
  std::string out;
  const int rc = run_command(
      std::string("node ") + TAILOR_SOURCE_DIR + "/tests/tools/validate_gltf.mjs --strict '" + file + "'", out);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("errors 0 warnings 0"), std::string::npos) << out;
}

// The JSON chunk of a glb file.
nlohmann::json glb_json(const std::string& bytes) {
  uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);
  return nlohmann::json::parse(bytes.substr(20, length));
}

// Re-packs a glb from a JSON document and the original file's BIN chunk.
std::string rebuild_glb(const nlohmann::json& json, const std::string& original) {
  uint32_t json_length = 0;
  std::memcpy(&json_length, original.data() + 12, 4);
  const std::string bin_chunk = original.substr(20 + json_length);
  std::string text = json.dump();
  while (text.size() % 4) text += ' ';
  std::string out(20, '\0');
  const uint32_t header[5] = {0x46546C67, 2, static_cast<uint32_t>(20 + text.size() + bin_chunk.size()),
                              static_cast<uint32_t>(text.size()), 0x4E4F534A};
  std::memcpy(out.data(), header, 20);
  return out + text + bin_chunk;
}

UvMetrics metrics_px(const Mesh& mesh, std::span<const float> uv_px, float size) {
  UvMetrics m;
  const Status s = compute_uv_metrics(mesh, build_topology(mesh), uv_px, {}, MetricsOptions{size, size}, m);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return m;
}

std::vector<float> repeats_to_px(const std::vector<float>& repeats, float size) {
  std::vector<float> px(repeats.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = repeats[i] * size;
  return px;
}

TEST_F(ExportTest, SplitsVerticesOnUvAndWeldsThemBack) {
  SplitMesh split;
  split_vertices(cube_, cube_atlas_.corner_uv, split);
  // Each side has its own 4 UVs: 6 * 4 split vertices, numbered in order of first corner.
  EXPECT_EQ(split.xref.size(), 24u);
  EXPECT_EQ(split.positions.size(), 72u);
  ASSERT_EQ(split.indices.size(), cube_.indices.size());
  EXPECT_EQ(split.indices[0], 0u);
  EXPECT_EQ(split.indices[1], 1u);
  EXPECT_EQ(split.indices[2], 2u);
  EXPECT_EQ(split.indices[3], 0u);  // second triangle of the first side reuses corner 0
  for (size_t c = 0; c < cube_.indices.size(); ++c) {
    const uint32_t s = split.indices[c];
    EXPECT_EQ(split.xref[s], cube_.indices[c]);
    EXPECT_EQ(split.uvs[2 * s], cube_atlas_.corner_uv[2 * c]);
    EXPECT_EQ(split.uvs[2 * s + 1], cube_atlas_.corner_uv[2 * c + 1]);
    EXPECT_EQ(std::memcmp(&split.positions[3 * s], &cube_.positions[3 * size_t{cube_.indices[c]}], 12), 0);
  }
  // -0 and +0 are one UV.
  Atlas signed_zero = cube_atlas_;
  signed_zero.corner_uv[1] = -0.0f;  // corner 0 has v = +0 elsewhere (corner 3)
  split_vertices(cube_, signed_zero.corner_uv, split);
  EXPECT_EQ(split.xref.size(), 24u);

  Mesh welded;
  welded.positions = split.positions;
  welded.indices = split.indices;
  EXPECT_EQ(weld_identical_positions(welded), 16u);
  EXPECT_EQ(welded.vertex_count(), 8u);
  for (size_t c = 0; c < cube_.indices.size(); ++c)
    EXPECT_EQ(std::memcmp(&welded.positions[3 * size_t{welded.indices[c]}],
                          &cube_.positions[3 * size_t{cube_.indices[c]}], 12),
              0);
}

// The split of a reference implementation: a std::map over (vertex, u bits, v bits), -0 as +0.
void reference_split(const Mesh& mesh, const std::vector<float>& corner_uv, SplitMesh& out) {
  out = SplitMesh{};
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> ids;
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const float u = corner_uv[2 * c] + 0.0f, w = corner_uv[2 * c + 1] + 0.0f;
    const auto key = std::make_tuple(mesh.indices[c], std::bit_cast<uint32_t>(u), std::bit_cast<uint32_t>(w));
    auto [it, added] = ids.emplace(key, static_cast<uint32_t>(out.xref.size()));
    if (added) {
      out.xref.push_back(mesh.indices[c]);
      out.uvs.push_back(u);
      out.uvs.push_back(w);
      for (int i = 0; i < 3; ++i) out.positions.push_back(mesh.positions[3 * size_t{mesh.indices[c]} + i]);
    }
    out.indices.push_back(it->second);
  }
}

void expect_same_split(const SplitMesh& a, const SplitMesh& b) {
  EXPECT_EQ(a.xref, b.xref);
  EXPECT_EQ(a.indices, b.indices);
  ASSERT_EQ(a.uvs.size(), b.uvs.size());
  EXPECT_EQ(std::memcmp(a.uvs.data(), b.uvs.data(), 4 * a.uvs.size()), 0);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), 4 * a.positions.size()), 0);
}

// A closed fan of n faces around vertex 0, rim vertex k at angle k; each face gives the centre its
// own UV (n UVs at one vertex), the rim vertices keep one UV each.
void make_fan(size_t n, Mesh& mesh, std::vector<float>& corner_uv) {
  mesh = Mesh{};
  corner_uv.clear();
  mesh.positions = {0, 0, 1};
  for (size_t k = 0; k < n; ++k) {
    const double a = 2 * 3.14159265358979 * static_cast<double>(k) / static_cast<double>(n);
    mesh.positions.insert(mesh.positions.end(), {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0});
  }
  for (size_t k = 0; k < n; ++k) {
    const auto a = static_cast<uint32_t>(1 + k), b = static_cast<uint32_t>(1 + (k + 1) % n);
    mesh.indices.insert(mesh.indices.end(), {0, a, b});
    corner_uv.insert(corner_uv.end(),
                     {0, static_cast<float>(k + 1), static_cast<float>(a), 0, static_cast<float>(b), 0});
  }
}

TEST_F(ExportTest, SplitMatchesReferenceOnSeamsAndHugeFans) {
  // Seam vertices with 1 to 4 UVs each, on a real mesh: UVs drawn from a few values per vertex.
  Mesh mesh;
  ASSERT_TRUE(load_mesh(kSpot, mesh).is_ok());
  std::mt19937 rng(7);
  std::vector<float> uv(2 * mesh.indices.size());
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const uint32_t pick = rng() % 4;
    uv[2 * c] = pick == 3 ? -0.0f : static_cast<float>(mesh.indices[c] % 5 + pick);  // -0 and +0 meet
    uv[2 * c + 1] = pick == 3 ? 0.0f : 0.25f * static_cast<float>(pick);
  }
  SplitMesh got, want;
  split_vertices(mesh, uv, got);
  reference_split(mesh, uv, want);
  EXPECT_GT(want.xref.size(), 2 * mesh.vertex_count());  // many vertices with several UVs
  expect_same_split(got, want);

  // A fan with 300 UVs at its centre: the chain walks exceed their budget and the split falls
  // back to its hash table; the result is the same.
  std::vector<float> fan_uv;
  make_fan(300, mesh, fan_uv);
  split_vertices(mesh, fan_uv, got);
  reference_split(mesh, fan_uv, want);
  EXPECT_EQ(got.xref.size(), 600u);  // 300 centre copies + 300 rim vertices
  expect_same_split(got, want);
  // And through export_mesh (scaled on the fly): the .ply holds the 600 split vertices.
  Atlas atlas;
  atlas.corner_uv = fan_uv;
  atlas.patch.assign(mesh.face_count(), 0);
  ExportOptions options;
  options.texture_width = options.texture_height = 1;
  ASSERT_TRUE(export_mesh(path("fan.ply"), mesh, atlas, options).is_ok());
  EXPECT_NE(read_all(path("fan.ply")).find("element vertex 600\n"), std::string::npos);
}

TEST_F(ExportTest, NonFiniteUvIsReportedAtItsCorner) {
  Atlas atlas = cube_atlas_;
  atlas.corner_uv[2 * 7 + 1] = std::numeric_limits<float>::infinity();
  atlas.corner_uv[2 * 9] = std::numeric_limits<float>::quiet_NaN();
  for (const char* name : {"cube.glb", "cube.obj", "cube.ply"}) {
    const Status s = export_mesh(path(name), cube_, atlas, ExportOptions{});
    EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument) << name;
    EXPECT_EQ(s.what(), "UV is not finite");
    EXPECT_EQ(s.where(), "corner 7");
    EXPECT_FALSE(fs::exists(path(name)));
  }
}

// A file size limit (RLIMIT_FSIZE) makes writes fail part-way: the streamed writers must then leave
// the previous file as it was and no temporary file.
TEST_F(ExportTest, WriteFailuresPartWayLeaveNoPartialFile) {
  Mesh mesh;
  ASSERT_TRUE(load_mesh(kSpot, mesh).is_ok());  // 5856 faces: every output is well over 64 KiB
  Atlas atlas;
  atlas.corner_uv = mesh.corner_uvs;
  atlas.patch.assign(mesh.face_count(), 0);
  ExportOptions options;
  options.texture_path = kTexture;
  const std::string names[] = {"m.glb", "m.obj", "m.ply", "raw.bin"};
  for (const std::string& name : names) std::ofstream(path(name)) << "old\n";

  struct rlimit old_limit;
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  void (*old_handler)(int) = std::signal(SIGXFSZ, SIG_IGN);  // fail with EFBIG, do not kill
  struct rlimit limit = old_limit;
  limit.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  Status statuses[4];
  for (int i = 0; i < 3; ++i) statuses[i] = export_mesh(path(names[i]), mesh, atlas, options);
  const std::string big(48 * 1024, 'x');
  const std::span<const char> pieces[2] = {big, big};
  statuses[3] = internal::write_file_atomic(path(names[3]), pieces);
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &old_limit), 0);
  std::signal(SIGXFSZ, old_handler);

  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(statuses[i].code(), ErrorCode::kIo) << names[i];
    EXPECT_NE(statuses[i].what().find("cannot write file"), std::string::npos) << statuses[i].message();
    EXPECT_EQ(read_all(path(names[i])), "old\n") << names[i];
  }
  EXPECT_EQ(temporaries(), 0u);

  // Without the limit the gather write lands, pieces in order.
  const std::span<const char> small[3] = {std::string_view("ab"), std::string_view(""), std::string_view("cde")};
  ASSERT_TRUE(internal::write_file_atomic(path(names[3]), small).is_ok());
  EXPECT_EQ(read_all(path(names[3])), "abcde");
  // A writer dropped before its commit (an early return) leaves nothing either.
  {
    internal::AtomicFileWriter file(path("dropped.bin"));
    ASSERT_TRUE(file.open().is_ok());
    ASSERT_TRUE(file.write(big).is_ok());
  }
  EXPECT_FALSE(fs::exists(path("dropped.bin")));
  EXPECT_EQ(temporaries(), 0u);
}

TEST_F(ExportTest, GlbRoundTripsAndValidates) {
  ExportOptions options;
  options.texture_path = kTexture;
  options.texture_width = options.texture_height = 128;
  const std::string out = path("cube.glb");
  ASSERT_TRUE(export_mesh(out, cube_, cube_atlas_, options).is_ok());
  EXPECT_EQ(temporaries(), 0u);

  Mesh back;
  Image texture;
  LoadReport report;
  const Status s = read_glb_file(out, back, &texture, &report);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(back.face_count(), 12u);
  EXPECT_EQ(back.vertex_count(), 8u);  // 24 split vertices welded back
  EXPECT_EQ(report.welded_vertices, 16u);
  ASSERT_EQ(back.corner_uvs.size(), cube_atlas_.corner_uv.size());
  for (size_t c = 0; c < 36; ++c) {
    EXPECT_EQ(back.corner_uvs[2 * c], cube_atlas_.corner_uv[2 * c] / 128.0f);
    EXPECT_EQ(back.corner_uvs[2 * c + 1], cube_atlas_.corner_uv[2 * c + 1] / 128.0f);
    EXPECT_EQ(
        std::memcmp(&back.positions[3 * size_t{back.indices[c]}], &cube_.positions[3 * size_t{cube_.indices[c]}], 12),
        0);
  }
  // The embedded texture decodes to the file's pixels.
  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load(kTexture.c_str(), &w, &h, &n, 0);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(texture.width, w);
  EXPECT_EQ(texture.height, h);
  EXPECT_EQ(texture.channels, n);
  EXPECT_EQ(texture.pixels.size(), size_t(w) * size_t(h) * size_t(n));
  EXPECT_EQ(std::memcmp(texture.pixels.data(), pixels, texture.pixels.size()), 0);
  stbi_image_free(pixels);

  // Same metrics before and after (the seams come back through welding).
  const UvMetrics before = metrics_px(cube_, cube_atlas_.corner_uv, 128);
  const UvMetrics after = metrics_px(back, repeats_to_px(back.corner_uvs, 128), 128);
  EXPECT_EQ(before.patches, 6u);
  EXPECT_EQ(before.seam_edges, 12u);
  EXPECT_EQ(after.patches, before.patches);
  EXPECT_EQ(after.seam_edges, before.seam_edges);
  EXPECT_EQ(after.flipped, 0u);
  EXPECT_NEAR(after.l2_stretch, 1.0, 1e-5);
  EXPECT_NEAR(after.seam_gap_px, before.seam_gap_px, 1e-3);

  // Structure: REPEAT sampler, mipmapped filtering, PNG embedded byte for byte, POSITION min/max.
  const std::string bytes = read_all(out);
  const nlohmann::json j = glb_json(bytes);
  EXPECT_EQ(j["samplers"][0]["wrapS"], 10497);
  EXPECT_EQ(j["samplers"][0]["wrapT"], 10497);
  EXPECT_EQ(j["samplers"][0]["minFilter"], 9987);
  EXPECT_EQ(j["images"][0]["mimeType"], "image/png");
  const std::string png = read_all(kTexture);
  const size_t view = j["images"][0]["bufferView"];
  const size_t offset = j["bufferViews"][view]["byteOffset"];
  uint32_t json_length = 0;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  EXPECT_EQ(bytes.substr(20 + json_length + 8 + offset, png.size()), png);
  const size_t position = j["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
  EXPECT_EQ(j["accessors"][position]["min"], nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_EQ(j["accessors"][position]["max"], nlohmann::json({1.0, 1.0, 1.0}));
  EXPECT_EQ(j["accessors"][j["meshes"][0]["primitives"][0]["indices"].get<size_t>()]["componentType"], 5125);

  expect_valid_gltf(out);
}

TEST_F(ExportTest, GlbEmbedsJpegAndWorksWithoutTexture) {
  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load(kTexture.c_str(), &w, &h, &n, 0);
  ASSERT_NE(pixels, nullptr);
  const std::string jpeg = path("texture.jpg");
  ASSERT_NE(stbi_write_jpg(jpeg.c_str(), w, h, n, pixels, 90), 0);
  const std::string wide = path("wide.jpg");  // its upper half: w x h / 2
  ASSERT_NE(stbi_write_jpg(wide.c_str(), w, h / 2, n, pixels, 90), 0);
  stbi_image_free(pixels);

  ExportOptions options;
  options.texture_path = jpeg;
  ASSERT_TRUE(export_mesh(path("jpeg.glb"), cube_, cube_atlas_, options).is_ok());
  EXPECT_EQ(glb_json(read_all(path("jpeg.glb")))["images"][0]["mimeType"], "image/jpeg");
  Mesh back;
  Image texture;
  ASSERT_TRUE(read_glb_file(path("jpeg.glb"), back, &texture).is_ok());
  EXPECT_EQ(texture.width, w);
  expect_valid_gltf(path("jpeg.glb"));
  // The same photo stored wide with an EXIF quarter turn (a phone's portrait shot): the .glb holds
  // its upright pixels as PNG, h / 2 wide and w high, since glTF viewers show the stored rows.
  {
    std::ofstream f(path("turned.jpg"), std::ios::binary);
    f << test::with_exif_orientation(read_all(wide), 6);
  }
  options.texture_path = path("turned.jpg");
  ASSERT_TRUE(export_mesh(path("turned.glb"), cube_, cube_atlas_, options).is_ok());
  EXPECT_EQ(glb_json(read_all(path("turned.glb")))["images"][0]["mimeType"], "image/png");
  ASSERT_TRUE(read_glb_file(path("turned.glb"), back, &texture).is_ok());
  EXPECT_EQ(texture.width, h / 2);
  EXPECT_EQ(texture.height, w);
  expect_valid_gltf(path("turned.glb"));

  options = ExportOptions{};
  options.normals = false;
  ASSERT_TRUE(export_mesh(path("plain.glb"), cube_, cube_atlas_, options).is_ok());
  const nlohmann::json j = glb_json(read_all(path("plain.glb")));
  EXPECT_FALSE(j.contains("images"));
  EXPECT_FALSE(j["meshes"][0]["primitives"][0]["attributes"].contains("NORMAL"));
  ASSERT_TRUE(read_glb_file(path("plain.glb"), back, &texture).is_ok());
  EXPECT_TRUE(texture.empty());
  EXPECT_EQ(back.face_count(), 12u);
  expect_valid_gltf(path("plain.glb"));
}

TEST_F(ExportTest, ObjRoundTripsWithMaterial) {
  ExportOptions options;
  options.texture_path = kTexture;
  options.texture_width = options.texture_height = 128;
  fs::create_directories(dir_ / "sub");
  const std::string out = path("sub/cube.obj");
  ASSERT_TRUE(export_mesh(out, cube_, cube_atlas_, options).is_ok());
  const std::string mtl = read_all(path("sub/cube.mtl"));
  // The texture is copied beside the .mtl and named by its bare file name: the folder moves whole.
  EXPECT_NE(mtl.find("map_Kd vistex-tile04-128.png\n"), std::string::npos) << mtl;
  EXPECT_EQ(read_all(path("sub/vistex-tile04-128.png")), read_all(kTexture));
  EXPECT_NE(read_all(out).find("mtllib cube.mtl\n"), std::string::npos);

  Mesh back;
  const Status s = load_mesh(out, back);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(back.face_count(), 12u);
  EXPECT_EQ(back.vertex_count(), 8u);  // shared v, one vt per split vertex
  EXPECT_EQ(back.indices, cube_.indices);
  ASSERT_EQ(back.corner_uvs.size(), cube_atlas_.corner_uv.size());
  for (size_t i = 0; i < back.corner_uvs.size(); ++i)
    EXPECT_FLOAT_EQ(back.corner_uvs[i], cube_atlas_.corner_uv[i] / 128.0f) << i;
  EXPECT_EQ(temporaries(), 0u);
}

// The copy of the texture beside an .obj/.ply never replaces a different file of its name (another
// output may name it): it takes the next free name; the same bytes are named again, not copied.
TEST_F(ExportTest, TextureCopyBesideTheOutputNeverReplacesAnotherFile) {
  ExportOptions options;
  options.texture_path = kTexture;
  options.texture_width = options.texture_height = 128;
  fs::create_directories(dir_ / "out");
  {
    std::ofstream other(path("out/vistex-tile04-128.png"), std::ios::binary);
    other << "another picture";
  }
  ASSERT_TRUE(export_mesh(path("out/a.obj"), cube_, cube_atlas_, options).is_ok());
  EXPECT_NE(read_all(path("out/a.mtl")).find("map_Kd vistex-tile04-128-2.png\n"), std::string::npos);
  EXPECT_EQ(read_all(path("out/vistex-tile04-128.png")), "another picture");
  EXPECT_EQ(read_all(path("out/vistex-tile04-128-2.png")), read_all(kTexture));
  // Again, and as a .ply: the copy already there is named, nothing more is written.
  ASSERT_TRUE(export_mesh(path("out/b.obj"), cube_, cube_atlas_, options).is_ok());
  EXPECT_NE(read_all(path("out/b.mtl")).find("map_Kd vistex-tile04-128-2.png\n"), std::string::npos);
  ASSERT_TRUE(export_mesh(path("out/c.ply"), cube_, cube_atlas_, options).is_ok());
  EXPECT_NE(read_all(path("out/c.ply")).find("comment TextureFile vistex-tile04-128-2.png\n"), std::string::npos);
  EXPECT_FALSE(fs::exists(path("out/vistex-tile04-128-3.png")));
  // A texture that already lies beside the output is named as it is, whatever its name.
  fs::copy_file(kTexture, path("out/my tile.png"));
  options.texture_path = path("out/my tile.png");
  ASSERT_TRUE(export_mesh(path("out/d.obj"), cube_, cube_atlas_, options).is_ok());
  // ...but a name with a space is one map_Kd readers split: the copy is named my_tile.png.
  EXPECT_NE(read_all(path("out/d.mtl")).find("map_Kd my_tile.png\n"), std::string::npos);
  fs::copy_file(kTexture, path("out/plain.png"));
  options.texture_path = path("out/plain.png");
  ASSERT_TRUE(export_mesh(path("out/e.obj"), cube_, cube_atlas_, options).is_ok());
  EXPECT_NE(read_all(path("out/e.mtl")).find("map_Kd plain.png\n"), std::string::npos);
  EXPECT_FALSE(fs::exists(path("out/plain-2.png")));
  // A name another output of the run takes (a preview or stats file, not written yet) is skipped
  // as a file already there is: the copy written now would be replaced by it afterwards.
  fs::create_directories(dir_ / "fresh");
  options.texture_path = kTexture;
  options.other_outputs = {path("fresh/vistex-tile04-128.png"), path("elsewhere/vistex-tile04-128-2.png")};
  ASSERT_TRUE(export_mesh(path("fresh/f.obj"), cube_, cube_atlas_, options).is_ok());
  EXPECT_NE(read_all(path("fresh/f.mtl")).find("map_Kd vistex-tile04-128-2.png\n"), std::string::npos);
  ASSERT_TRUE(export_mesh(path("fresh/g.ply"), cube_, cube_atlas_, options).is_ok());
  EXPECT_NE(read_all(path("fresh/g.ply")).find("comment TextureFile vistex-tile04-128-2.png\n"), std::string::npos);
  EXPECT_FALSE(fs::exists(path("fresh/vistex-tile04-128.png")));
  // The same folder spelt another way (relative against absolute, with a "." in it) is the same.
  fs::create_directories(dir_ / "mixed");
  const fs::path relative = fs::relative(dir_ / "mixed", fs::current_path());
  options.other_outputs = {(dir_ / "mixed" / "." / "vistex-tile04-128.png").string()};
  ASSERT_TRUE(export_mesh((relative / "h.obj").string(), cube_, cube_atlas_, options).is_ok());
  EXPECT_NE(read_all(path("mixed/h.mtl")).find("map_Kd vistex-tile04-128-2.png\n"), std::string::npos);
  EXPECT_EQ(temporaries(), 0u);
}

TEST_F(ExportTest, PlyRoundTripsWithSplitVertices) {
  ExportOptions options;
  options.texture_width = options.texture_height = 256;
  const std::string out = path("cube.ply");
  ASSERT_TRUE(export_mesh(out, cube_, cube_atlas_, options).is_ok());
  EXPECT_EQ(read_all(out).rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  Mesh back;
  const Status s = load_mesh(out, back);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(back.face_count(), 12u);
  EXPECT_EQ(back.vertex_count(), 24u);
  ASSERT_EQ(back.corner_uvs.size(), cube_atlas_.corner_uv.size());
  for (size_t i = 0; i < back.corner_uvs.size(); ++i)
    EXPECT_FLOAT_EQ(back.corner_uvs[i], cube_atlas_.corner_uv[i] / 256.0f) << i;
  EXPECT_EQ(weld_identical_positions(back), 16u);
  EXPECT_EQ(metrics_px(back, repeats_to_px(back.corner_uvs, 256), 256).seam_edges, 12u);
}

// A real UV-mapped mesh (spot.obj's own atlas) through all three formats.
TEST_F(ExportTest, RealMeshRoundTripsThroughAllFormats) {
  Mesh spot;
  const Status loaded = load_mesh(kSpot, spot);
  ASSERT_TRUE(loaded.is_ok()) << loaded.message();
  ASSERT_EQ(spot.face_count(), 5856u);
  ASSERT_FALSE(spot.corner_uvs.empty());
  const float size = 128;
  Atlas atlas;
  atlas.corner_uv = repeats_to_px(spot.corner_uvs, size);
  std::vector<uint32_t> patch;
  atlas.patch_count = derive_patches(spot, build_topology(spot), atlas.corner_uv, patch);
  atlas.patch = patch;
  const UvMetrics original = metrics_px(spot, atlas.corner_uv, size);

  ExportOptions options;
  options.texture_path = kTexture;
  options.texture_width = options.texture_height = 128;
  for (const char* name : {"spot.glb", "spot.obj", "spot.ply"}) {
    SCOPED_TRACE(name);
    const std::string out = path(name);
    ASSERT_TRUE(export_mesh(out, spot, atlas, options).is_ok());
    Mesh back;
    const Status s = std::string(name).ends_with(".glb") ? read_glb_file(out, back, nullptr) : load_mesh(out, back);
    ASSERT_TRUE(s.is_ok()) << s.message();
    if (std::string(name).ends_with(".ply")) weld_identical_positions(back);
    EXPECT_EQ(back.face_count(), spot.face_count());
    EXPECT_EQ(back.vertex_count(), spot.vertex_count());
    ASSERT_EQ(back.corner_uvs.size(), spot.corner_uvs.size());
    double max_error = 0;
    for (size_t i = 0; i < spot.corner_uvs.size(); ++i)
      max_error = std::max(max_error, double(std::abs(back.corner_uvs[i] - spot.corner_uvs[i])));
    EXPECT_EQ(max_error, 0.0);  // pixels / 128 and back are exact; every format stores floats exactly
    const UvMetrics m = metrics_px(back, repeats_to_px(back.corner_uvs, size), size);
    EXPECT_EQ(m.patches, original.patches);
    EXPECT_EQ(m.seam_edges, original.seam_edges);
    EXPECT_EQ(m.flipped, original.flipped);
    EXPECT_NEAR(m.stretch, original.stretch, 1e-4);
  }
  expect_valid_gltf(path("spot.glb"));
}

// The mapping's own output (fandisk, default options) exports to a valid glb whose texture is
// upright and unmirrored: every face keeps a positive signed UV area (t up) after the round trip.
TEST_F(ExportTest, MappedMeshExportsUpright) {
  Mesh mesh;
  ASSERT_TRUE(load_mesh(std::string(TAILOR_TEST_DATA) + "/meshes/fandisk.off", mesh).is_ok());
  const Topology topology = build_topology(mesh);
  TextureMap map;
  const Status mapped = map_texture(mesh, topology, MapTextureOptions{}, map);
  ASSERT_TRUE(mapped.is_ok()) << mapped.message();
  const Atlas& atlas = map.atlas;
  const UvMetrics& before = map.metrics;

  ExportOptions options;
  options.texture_path = kTexture;
  options.texture_width = options.texture_height = 128;
  ASSERT_TRUE(export_mesh(path("fandisk.glb"), mesh, atlas, options).is_ok());
  Mesh back;
  ASSERT_TRUE(read_glb_file(path("fandisk.glb"), back, nullptr).is_ok());
  ASSERT_EQ(back.face_count(), mesh.face_count());
  size_t positive = 0;
  for (size_t f = 0; f < back.face_count(); ++f) {
    const float* t = &back.corner_uvs[6 * f];
    if ((t[2] - t[0]) * (t[5] - t[1]) - (t[4] - t[0]) * (t[3] - t[1]) > 0) ++positive;
  }
  EXPECT_EQ(positive + before.flipped, mesh.face_count());
  const UvMetrics after = metrics_px(back, repeats_to_px(back.corner_uvs, 128), 128);
  EXPECT_EQ(after.seam_edges, before.seam_edges);
  EXPECT_EQ(after.flipped, before.flipped);
  EXPECT_NEAR(after.stretch, before.stretch, 1e-6);
  expect_valid_gltf(path("fandisk.glb"));
}

// A map's figures are those of the file it is written to: the UVs the writers store are the bits
// uv_repeats_from_px gives (a 300 px texture, where pixels / 300 and back is not exact), and
// compute_stored_uv_metrics of the map equals it of the file read back, .glb, .obj and .ply alike.
// The .obj's .mtl and the .ply's comments give the texture's size and file and a 4-fold map's
// record (load_mesh); without the .mtl, none.
TEST_F(ExportTest, StoredMetricsOfAMapAreThoseOfItsFile) {
  Mesh spot;
  ASSERT_TRUE(load_mesh(kSpot, spot).is_ok());
  const std::string texture = std::string(TAILOR_TEST_DATA) + "/textures/water-caustics-300.jpg";
  const float size = 300;
  Atlas atlas;
  atlas.corner_uv = repeats_to_px(spot.corner_uvs, size * 1.37f);  // pixels that are no round repeats
  std::vector<uint32_t> patch;
  atlas.patch_count = derive_patches(spot, build_topology(spot), atlas.corner_uv, patch);
  atlas.patch = patch;
  std::vector<float> stored;
  uv_repeats_from_px(atlas.corner_uv, size, size, stored);
  MetricsOptions metrics_options{size, size};
  metrics_options.symmetry = 4;
  UvMetrics of_map;
  ASSERT_TRUE(compute_stored_uv_metrics(spot, nullptr, stored, metrics_options, of_map).is_ok());
  size_t inexact = 0;  // pixels -> repeats -> pixels changes some bits here: the reason to measure `stored`
  for (size_t i = 0; i < stored.size(); ++i) inexact += stored[i] * size != atlas.corner_uv[i];
  EXPECT_GT(inexact, 0u);

  ExportOptions options;
  options.texture_path = texture;
  options.texture_width = options.texture_height = 300;
  options.symmetry = 4;
  for (const char* name : {"spot.glb", "spot.obj", "spot.ply"}) {
    SCOPED_TRACE(name);
    const std::string out = path(name);
    ASSERT_TRUE(export_mesh(out, spot, atlas, options).is_ok());
    Mesh back;
    LoadReport report;
    const bool glb = std::string(name).ends_with(".glb");
    const Status s = glb ? read_glb_file(out, back, nullptr, &report) : load_mesh(out, back, &report);
    ASSERT_TRUE(s.is_ok()) << s.message();
    EXPECT_EQ(report.texture_width, 300);
    EXPECT_EQ(report.texture_height, 300);
    EXPECT_EQ(report.texture_symmetry, 4u);
    EXPECT_EQ(report.texture_file, !glb);
    if (!glb) {
      EXPECT_EQ(fs::path(report.texture_path).filename(), fs::path(texture).filename());
    }
    UvMetrics of_file;
    if (!glb) {  // the .obj and .ply keep the corner order: the stored UVs bit for bit
      ASSERT_EQ(back.corner_uvs.size(), stored.size());
      EXPECT_EQ(std::memcmp(back.corner_uvs.data(), stored.data(), 4 * stored.size()), 0);
    }
    ASSERT_TRUE(compute_stored_uv_metrics(back, nullptr, back.corner_uvs, metrics_options, of_file).is_ok());
    EXPECT_EQ(of_file.patches, of_map.patches);
    EXPECT_EQ(of_file.seam_edges, of_map.seam_edges);
    EXPECT_EQ(of_file.flipped, of_map.flipped);
    EXPECT_EQ(of_file.seam_length_ratio, of_map.seam_length_ratio);
    EXPECT_EQ(of_file.seam_gap_px, of_map.seam_gap_px);
    EXPECT_EQ(of_file.seam_invisible_ratio, of_map.seam_invisible_ratio);
    EXPECT_EQ(of_file.visible_seam_ratio, of_map.visible_seam_ratio);
    EXPECT_EQ(of_file.visible_dangling_ends, of_map.visible_dangling_ends);
    EXPECT_EQ(of_file.visible_branch_points, of_map.visible_branch_points);
  }
  // Without its .mtl the .obj still loads, with no texture size and no record.
  fs::remove(path("spot.mtl"));
  Mesh back;
  LoadReport report;
  ASSERT_TRUE(load_mesh(path("spot.obj"), back, &report).is_ok());
  EXPECT_EQ(report.texture_width, 0);
  EXPECT_EQ(report.texture_symmetry, 1u);
}

TEST_F(ExportTest, OutputIsDeterministic) {
  ExportOptions options;
  options.texture_path = kTexture;
  fs::create_directories(dir_ / "a");
  fs::create_directories(dir_ / "b");
  for (const char* name : {"a/m.glb", "b/m.glb", "a/m.obj", "b/m.obj", "a/m.ply", "b/m.ply"})
    ASSERT_TRUE(export_mesh(path(name), cube_, cube_atlas_, options).is_ok());
  for (const char* name : {"m.glb", "m.obj", "m.mtl", "m.ply"})
    EXPECT_EQ(read_all(path(std::string("a/") + name)), read_all(path(std::string("b/") + name))) << name;
}

TEST_F(ExportTest, FailuresLeaveNoPartialFile) {
  ExportOptions options;
  // Unsupported extension: usage error, nothing written.
  EXPECT_EQ(export_mesh(path("cube.fbx"), cube_, cube_atlas_, options).code(), ErrorCode::kInvalidArgument);
  EXPECT_FALSE(fs::exists(path("cube.fbx")));
  // Missing directory.
  EXPECT_EQ(export_mesh(path("missing/cube.glb"), cube_, cube_atlas_, options).code(), ErrorCode::kIo);
  EXPECT_FALSE(fs::exists(path("missing")));

  // A good file, then failing exports over it: it stays byte-identical.
  const std::string out = path("cube.glb");
  ASSERT_TRUE(export_mesh(out, cube_, cube_atlas_, options).is_ok());
  const std::string good = read_all(out);
  ExportOptions bad_texture;
  bad_texture.texture_path = path("no-such-texture.png");
  EXPECT_EQ(export_mesh(out, cube_, cube_atlas_, bad_texture).code(), ErrorCode::kIo);
  bad_texture.texture_path = kSpot;  // exists, but not an image
  EXPECT_EQ(export_mesh(out, cube_, cube_atlas_, bad_texture).code(), ErrorCode::kInvalidImage);
  Atlas short_atlas = cube_atlas_;
  short_atlas.corner_uv.pop_back();
  EXPECT_EQ(export_mesh(out, cube_, short_atlas, options).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(read_all(out), good);

  // The target is a directory: the rename fails and the temporary file is removed.
  fs::create_directories(dir_ / "taken.glb");
  EXPECT_EQ(export_mesh(path("taken.glb"), cube_, cube_atlas_, options).code(), ErrorCode::kIo);
  EXPECT_TRUE(fs::is_directory(dir_ / "taken.glb"));
  EXPECT_EQ(temporaries(), 0u);
}

TEST_F(ExportTest, GlbReaderRejectsDamagedFiles) {
  const std::string out = path("cube.glb");
  ExportOptions options;
  options.texture_path = kTexture;
  ASSERT_TRUE(export_mesh(out, cube_, cube_atlas_, options).is_ok());
  const std::string good = read_all(out);
  Mesh mesh;
  Image texture;
  // Every truncation fails cleanly (the file's length field no longer matches).
  for (size_t length = 0; length < good.size(); length += (length < 2048 ? 1 : 97)) {
    const Status s = read_glb_memory(std::span<const char>(good.data(), length), "cut.glb", mesh, &texture);
    EXPECT_FALSE(s.is_ok()) << length;
    EXPECT_TRUE(mesh.empty());
  }
  // Random byte damage never crashes (the result may or may not be ok).
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 300; ++trial) {
    std::string damaged = good;
    for (int k = 0; k < 4; ++k) damaged[rng() % damaged.size()] = static_cast<char>(rng());
    (void)read_glb_memory(damaged, "damaged.glb", mesh, &texture);
  }
  // Accessors that lie about their size, and out-of-range indices.
  nlohmann::json j = glb_json(good);
  const size_t position = j["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
  nlohmann::json lie = j;
  lie["accessors"][position]["count"] = 1u << 30;
  EXPECT_EQ(read_glb_memory(rebuild_glb(lie, good), "lie.glb", mesh, nullptr).code(), ErrorCode::kParse);
  lie = j;
  lie["bufferViews"][0]["byteOffset"] = 1u << 31;
  EXPECT_EQ(read_glb_memory(rebuild_glb(lie, good), "lie.glb", mesh, nullptr).code(), ErrorCode::kParse);
  lie = j;
  lie["images"][0]["bufferView"] = 99;  // texture unreachable: the mesh still loads, no texture
  EXPECT_TRUE(read_glb_memory(rebuild_glb(lie, good), "lie.glb", mesh, &texture).is_ok());
  EXPECT_TRUE(texture.empty());
  lie = j;
  for (const auto& item : j["meshes"][0]["primitives"][0]["attributes"].items())
    lie["accessors"][item.value().get<size_t>()]["count"] = 3;  // fewer vertices than the indices use
  lie["accessors"][position].erase("min");
  lie["accessors"][position].erase("max");
  EXPECT_EQ(read_glb_memory(rebuild_glb(lie, good), "lie.glb", mesh, nullptr).code(), ErrorCode::kInvalidMesh);
  lie = j;
  lie["buffers"][0]["uri"] = "/etc/passwd";
  EXPECT_EQ(read_glb_memory(rebuild_glb(lie, good), "lie.glb", mesh, nullptr).code(), ErrorCode::kUnsupported);
  EXPECT_EQ(read_glb_memory(std::string("not a glb at all, just text......"), "t.glb", mesh, nullptr).code(),
            ErrorCode::kParse);
  // The load_mesh route (no texture) reads the same mesh.
  ASSERT_TRUE(load_mesh(out, mesh).is_ok());
  EXPECT_EQ(mesh.face_count(), 12u);
  EXPECT_EQ(mesh.vertex_count(), 8u);
}

TEST_F(ExportTest, EvalCommandReportsMetrics) {
  ExportOptions options;
  options.texture_path = kTexture;
  options.texture_width = options.texture_height = 128;
  ASSERT_TRUE(export_mesh(path("cube.glb"), cube_, cube_atlas_, options).is_ok());
  ASSERT_TRUE(export_mesh(path("cube.obj"), cube_, cube_atlas_, options).is_ok());
  std::string out;
  ASSERT_EQ(run_command(std::string(TAILOR_BINARY) + " eval --json " + path("cube.glb"), out), 0) << out;
  nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["faces"], 12);
  EXPECT_EQ(j["patches"], 6);
  EXPECT_EQ(j["seam_edges"], 12);
  EXPECT_EQ(j["flipped"], 0);
  EXPECT_EQ(j["texture_width"], 128);  // from the embedded image
  EXPECT_NEAR(j["l2_stretch"].get<double>(), 1.0, 1e-5);
  EXPECT_NEAR(j["stretch"].get<double>(), 0.0, 1e-5);
  // Patch q is offset by 100 q px: across the seams gaps are k*100 px modulo 128, never 0 here.
  EXPECT_GT(j["seam_gap_px"].get<double>(), 1.0);

  // OBJ: UVs in repeats times the size of the texture its .mtl names, or --texture-size.
  ASSERT_EQ(run_command(std::string(TAILOR_BINARY) + " eval --json " + path("cube.obj"), out), 0) << out;
  nlohmann::json k = nlohmann::json::parse(out);
  EXPECT_EQ(k["patches"], 6);
  EXPECT_EQ(k["texture_width"], 128);
  EXPECT_EQ(k["texture_size_from"], "texture file");
  EXPECT_EQ(k["seam_gap_px"].get<double>(), j["seam_gap_px"].get<double>());
  ASSERT_EQ(run_command(std::string(TAILOR_BINARY) + " eval --texture-size 512 " + path("cube.obj"), out), 0) << out;
  EXPECT_NE(out.find("12 faces, 6 patches"), std::string::npos) << out;
  EXPECT_NE(out.find("512x512 px, option"), std::string::npos) << out;

  // PLY (split vertices): eval welds them, so the 12 seams come back.
  ASSERT_TRUE(export_mesh(path("cube.ply"), cube_, cube_atlas_, options).is_ok());
  ASSERT_EQ(run_command(std::string(TAILOR_BINARY) + " eval --json --texture-size 128 " + path("cube.ply"), out), 0)
      << out;
  k = nlohmann::json::parse(out);
  EXPECT_EQ(k["seam_edges"], 12);
  EXPECT_EQ(k["welded_vertices"], 16);

  // No UVs: a clear one-line error, exit 1. Bad option: exit 2.
  std::ofstream(path("tri.off")) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(run_command(std::string(TAILOR_BINARY) + " eval " + path("tri.off"), out), 1);
  EXPECT_NE(out.find("no texture coordinates"), std::string::npos) << out;
  EXPECT_EQ(run_command(std::string(TAILOR_BINARY) + " eval --texture-size 0 " + path("cube.obj"), out), 2) << out;
}

}  // namespace
}  // namespace tailor
