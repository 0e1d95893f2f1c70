// The glTF reader on scenes: node hierarchies and transforms, strips and fans, sparse and
// quantized accessors, .gltf with data: URIs and .bin files, required extensions; and on files
// made by glTF-Transform's CLI (quantize, meshopt, draco, instance, merge) from the test meshes,
// whose world positions must match the source within the quantization's tolerance.
#include "tailor/gltf.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "support/fixtures.h"
#include "tailor/export.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/topology.h"

namespace tailor {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using test::run_command;

//! An atlas of one patch whose corner k gets the UV (k % period) * step_px in u and v alike: any
//! UVs will do where a test checks what the export keeps or reports, not the mapping.
Atlas patterned_atlas(size_t faces, size_t period, float step_px) {
  Atlas atlas;
  atlas.corner_uv.resize(6 * faces);
  for (size_t k = 0; k < atlas.corner_uv.size(); ++k) atlas.corner_uv[k] = static_cast<float>(k % period) * step_px;
  atlas.patch.assign(faces, 0);
  return atlas;
}

// A glTF document built in memory: accessors over one binary buffer.
struct Builder {
  Json json = {{"asset", {{"version", "2.0"}}}, {"accessors", Json::array()}, {"bufferViews", Json::array()}};
  std::string bin;

  template <class T>
  size_t accessor(const std::vector<T>& values, int component_type, const char* type, size_t count,
                  bool normalized = false) {
    while (bin.size() % 4) bin.push_back('\0');
    json["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", values.size() * sizeof(T)}});
    bin.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    Json a = {{"bufferView", json["bufferViews"].size() - 1},
              {"componentType", component_type},
              {"type", type},
              {"count", count}};
    if (normalized) a["normalized"] = true;
    json["accessors"].push_back(a);
    return json["accessors"].size() - 1;
  }
  size_t positions(const std::vector<float>& p) { return accessor(p, 5126, "VEC3", p.size() / 3); }
  size_t indices(const std::vector<uint32_t>& i) { return accessor(i, 5125, "SCALAR", i.size()); }

  std::string glb() {
    while (bin.size() % 4) bin.push_back('\0');
    Json j = json;
    j["buffers"] = {{{"byteLength", bin.size()}}};
    std::string text = j.dump();
    while (text.size() % 4) text += ' ';
    std::string out(20, '\0');
    const uint32_t header[5] = {0x46546C67, 2, static_cast<uint32_t>(28 + text.size() + bin.size()),
                                static_cast<uint32_t>(text.size()), 0x4E4F534A};
    std::memcpy(out.data(), header, 20);
    out += text;
    const uint32_t bin_header[2] = {static_cast<uint32_t>(bin.size()), 0x004E4942};
    out.append(reinterpret_cast<const char*>(bin_header), 8);
    return out + bin;
  }
  // .gltf text whose buffer is `uri` (the caller writes bin there) or, when empty, a data: URI.
  std::string gltf(const std::string& uri = {}) const {
    Json j = json;
    j["buffers"] = {
        {{"byteLength", bin.size()}, {"uri", uri.empty() ? "data:application/octet-stream;base64," + base64() : uri}}};
    return j.dump();
  }
  std::string base64() const {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bin.size(); i += 3) {
      const uint32_t b0 = static_cast<unsigned char>(bin[i]);
      const uint32_t b1 = i + 1 < bin.size() ? static_cast<unsigned char>(bin[i + 1]) : 0;
      const uint32_t b2 = i + 2 < bin.size() ? static_cast<unsigned char>(bin[i + 2]) : 0;
      const uint32_t v = b0 << 16 | b1 << 8 | b2;
      out += k[v >> 18 & 63];
      out += k[v >> 12 & 63];
      out += i + 1 < bin.size() ? k[v >> 6 & 63] : '=';
      out += i + 2 < bin.size() ? k[v & 63] : '=';
    }
    return out;
  }
};

const std::vector<float> kTrianglePositions = {0, 0, 0, 1, 0, 0, 0, 1, 0};

Status read(const std::string& bytes, Mesh& mesh, LoadReport* report = nullptr) {
  return read_mesh(bytes, bytes.starts_with("glTF") ? MeshFormat::kGlb : MeshFormat::kGltf, "test", mesh, report);
}

// Builder with one triangle mesh (mesh 0) and the scene/nodes given.
Builder one_triangle(const Json& nodes, const Json& scenes) {
  Builder b;
  const size_t p = b.positions(kTrianglePositions);
  b.json["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", p}}}}}}}};
  b.json["nodes"] = nodes;
  b.json["scenes"] = scenes;
  return b;
}

double signed_area_z(const Mesh& m, size_t f) {
  const float* a = &m.positions[3 * m.indices[3 * f]];
  const float* b = &m.positions[3 * m.indices[3 * f + 1]];
  const float* c = &m.positions[3 * m.indices[3 * f + 2]];
  return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

TEST(GltfScene, NodeTransformsAreAppliedParentsFirst) {
  // Node 0 (translated by (10, 0, 0), scaled by 2) has child node 1 (rotated 90 degrees about z)
  // and both use mesh 0; node 2 mirrors it in x. Scene 1's node 3 is not in the default scene.
  const double s = std::sqrt(0.5);
  const Json nodes = {{{"mesh", 0}, {"translation", {10, 0, 0}}, {"scale", {2, 2, 2}}, {"children", {1}}},
                      {{"mesh", 0}, {"rotation", {0, 0, s, s}}},
                      {{"mesh", 0}, {"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}},
                      {{"mesh", 0}, {"translation", {100, 100, 100}}}};
  Builder b = one_triangle(nodes, {{{"nodes", {0, 2}}}, {{"nodes", {3}}}});
  b.json["scene"] = 0;
  Mesh mesh;
  LoadReport report;
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_EQ(report.mesh_instances, 3u);
  ASSERT_EQ(mesh.face_count(), 3u);
  // Instance 0: 2p + (10,0,0). Instance 1: rotated then the parent's: (x,y) -> (-y,x) * 2 + (10,0,0).
  // Instance 2: x mirrored, z + 5, winding flipped so that it stays counter-clockwise from +z.
  const std::vector<std::array<float, 9>> expected = {std::array<float, 9>{10, 0, 0, 12, 0, 0, 10, 2, 0},
                                                      std::array<float, 9>{10, 0, 0, 10, 2, 0, 8, 0, 0},
                                                      std::array<float, 9>{0, 0, 5, 0, 1, 5, -1, 0, 5}};
  for (size_t f = 0; f < 3; ++f) {
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(mesh.positions[3 * mesh.indices[3 * f + size_t(k)] + size_t(i)], expected[f][size_t(3 * k + i)],
                    1e-5)
            << "face " << f << " corner " << k;
    EXPECT_GT(signed_area_z(mesh, f), 0) << f;
  }
  // The other scene, when it is the default.
  b.json["scene"] = 1;
  ASSERT_TRUE(read(b.glb(), mesh).is_ok());
  ASSERT_EQ(mesh.face_count(), 1u);
  EXPECT_FLOAT_EQ(mesh.positions[0], 100.f);
}

TEST(GltfScene, TangentsAreTurnedByTheNodesAndFlippedByMirrors) {
  // TANGENT (1, 0, 0, +1) on every vertex; node 0 turns the mesh 90 degrees about z and scales it,
  // node 1 mirrors x. read_glb_with_material gives per-corner world tangents: (0, 1, 0, +1) and
  // (-1, 0, 0, -1) (a mirror reverses the bitangent: w flips); read_glb_file keeps none of it.
  const double s = std::sqrt(0.5);
  const Json nodes = {{{"mesh", 0}, {"rotation", {0, 0, s, s}}, {"scale", {3, 3, 3}}},
                      {{"mesh", 0}, {"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}}};
  Builder b = one_triangle(nodes, {{{"nodes", {0, 1}}}});
  const size_t t = b.accessor(std::vector<float>{1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, 5126, "VEC4", 3);
  b.json["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = t;
  const std::string dir = test::empty_temp_dir("gltf_tangents");
  const std::string path = dir + "/tangents.glb";
  std::ofstream(path, std::ios::binary) << b.glb();
  Mesh mesh;
  GltfMaterialMaps maps;
  ASSERT_TRUE(read_glb_with_material(path, mesh, nullptr, &maps).is_ok());
  ASSERT_EQ(mesh.face_count(), 2u);
  ASSERT_EQ(maps.corner_tangents.size(), 4 * 6u);
  EXPECT_TRUE(maps.normal.empty());
  EXPECT_TRUE(mesh.corner_attributes.empty());
  const float expected[2][4] = {{0, 1, 0, 1}, {-1, 0, 0, -1}};
  for (size_t c = 0; c < 6; ++c)
    for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(maps.corner_tangents[4 * c + i], expected[c / 3][i], 1e-6) << c;
  LoadReport report;
  ASSERT_TRUE(read_glb_file(path, mesh, nullptr, &report).is_ok());
  EXPECT_TRUE(mesh.corner_attributes.empty());
  EXPECT_NE(report.not_kept.find("TANGENT"), std::string::npos) << report.not_kept;
  fs::remove_all(dir);
}

TEST(GltfScene, BadHierarchiesFailWithOneLine) {
  Mesh mesh;
  Builder cycle = one_triangle({{{"mesh", 0}, {"children", {1}}}, {{"children", {0}}}}, {{{"nodes", {0}}}});
  Status s = read(cycle.glb(), mesh);
  EXPECT_EQ(s.code(), ErrorCode::kParse);
  EXPECT_NE(s.message().find("node 0"), std::string::npos) << s.message();
  Builder bad = one_triangle({{{"mesh", 7}}}, {{{"nodes", {0}}}});
  EXPECT_EQ(read(bad.glb(), mesh).code(), ErrorCode::kParse);
  Builder nan_scale = one_triangle({{{"mesh", 0}, {"scale", {1, "x", 1}}}}, {{{"nodes", {0}}}});
  EXPECT_EQ(read(nan_scale.glb(), mesh).code(), ErrorCode::kParse);
  EXPECT_TRUE(mesh.empty());
}

TEST(GltfScene, NodesFlattenedToALineOrAPointAreSkippedByName) {
  // A zero scale (how scenes hide a node) or an all-zero matrix: no face of it has an area. Such a
  // node keeps its name in the scene; a flattening scale of rank 2 keeps the faces across it.
  Mesh mesh;
  LoadReport report;
  Builder hidden =
      one_triangle({{{"name", "hidden"}, {"mesh", 0}, {"scale", {0, 0, 0}}}, {{"mesh", 0}, {"translation", {5, 0, 0}}}},
                   {{{"nodes", {0, 1}}}});
  ASSERT_TRUE(read(hidden.glb(), mesh, &report).is_ok());
  EXPECT_EQ(mesh.face_count(), 1u);
  EXPECT_FLOAT_EQ(mesh.positions[0], 5.f);
  EXPECT_EQ(report.mesh_instances, 2u);
  ASSERT_EQ(mesh.scene.instances.size(), 2u);
  EXPECT_EQ(mesh.scene.instances[0].node_name, "hidden");
  EXPECT_TRUE(
      report.not_kept.starts_with("1 mesh instance under a transform that flattens it to a line or a point (node 0), "))
      << report.not_kept;
  Builder all_zero = one_triangle({{{"mesh", 0}, {"matrix", std::vector<double>(16, 0.0)}}}, {{{"nodes", {0}}}});
  const Status s = read(all_zero.glb(), mesh);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_NE(s.message().find("no face with an area in the scene: 1 mesh instance under a transform that flattens it "
                             "to a line or a point (node 0)"),
            std::string::npos)
      << s.message();
  // The triangle lies in z = 0: flattening z keeps it whole.
  Builder flat = one_triangle({{{"mesh", 0}, {"scale", {2, 1, 0}}}}, {{{"nodes", {0}}}});
  ASSERT_TRUE(read(flat.glb(), mesh, &report).is_ok());
  EXPECT_EQ(mesh.face_count(), 1u);
  EXPECT_EQ(report.not_kept.find("flattens"), std::string::npos) << report.not_kept;
}

// A node's extras nested 100,000 levels deep (a 200 KB file) is refused in one line: copying or
// printing such a value recurses once per level and would overflow the stack. 200 levels load.
TEST(GltfScene, JsonNestedTooDeepIsOneLineNotACrash) {
  const Builder b = one_triangle({{{"mesh", 0}, {"extras", "X"}}}, {{{"nodes", {0}}}});
  const auto nested = [&b](size_t levels) {
    std::string text = b.gltf();
    const size_t at = text.find("\"X\"");
    return text.replace(at, 3, std::string(levels, '[') + std::string(levels, ']'));
  };
  Mesh mesh;
  const Status deep = read(nested(100000), mesh);
  EXPECT_EQ(deep.code(), ErrorCode::kParse);
  EXPECT_NE(deep.message().find("JSON nested more than 256 levels deep"), std::string::npos) << deep.message();
  EXPECT_TRUE(mesh.empty());
  EXPECT_TRUE(read(nested(200), mesh).is_ok());
  EXPECT_EQ(mesh.face_count(), 1u);
}

// Invalid JSON is named with the offset where it stops being JSON (in the file: a .glb's JSON chunk
// starts at byte 20); valid JSON that is no object says so.
TEST(GltfScene, InvalidJsonNamesTheByteWhereItBreaks) {
  Builder b = one_triangle({{{"mesh", 0}}}, {{{"nodes", {0}}}});
  std::string text = b.gltf();
  const size_t at = text.find("\"nodes\"");
  Mesh mesh;
  const Status broken = read(text.substr(0, at) + "," + text.substr(at), mesh);
  EXPECT_EQ(broken.code(), ErrorCode::kParse);
  EXPECT_EQ(broken.message(), "test: not a glTF file (not valid JSON) (byte " + std::to_string(at) + ")");
  EXPECT_EQ(read(text.substr(0, 10), mesh).message(), "test: not a glTF file (not valid JSON) (byte 10)");
  // A whole token where none may stand: its last byte.
  EXPECT_EQ(read(R"({"asset" "b"})", mesh).message(), "test: not a glTF file (not valid JSON) (byte 11)");
  EXPECT_EQ(read("{\"asset\": {}, \"x\": 12 34}", mesh).message(), "test: not a glTF file (not valid JSON) (byte 23)");
  EXPECT_EQ(read("[1, 2]", mesh).message(), "test: not a glTF file (not a JSON object)");
  std::string glb = b.glb();
  const size_t in_chunk = glb.find("\"nodes\"");
  ASSERT_NE(in_chunk, std::string::npos);
  glb[in_chunk] = '#';
  EXPECT_EQ(read(glb, mesh).message(), "test: JSON chunk is not valid JSON (byte " + std::to_string(in_chunk) + ")");
  EXPECT_TRUE(mesh.empty());
}

// Every instance keeps its node's and mesh's name and extras: a 100 KB mesh name under 3,000 nodes
// (300 MB of copies from a 200 KB file) is refused by the decode budget; under 10 nodes it loads.
TEST(GltfScene, NamesCopiedPerInstanceCountAgainstTheBudget) {
  const auto scene_of = [](size_t nodes) {
    Json list = Json::array(), roots = Json::array();
    for (size_t i = 0; i < nodes; ++i) {
      list.push_back({{"mesh", 0}});
      roots.push_back(i);
    }
    Builder b = one_triangle(list, {{{"nodes", roots}}});
    b.json["meshes"][0]["name"] = std::string(100000, 'n');
    return b;
  };
  Mesh mesh;
  const Status many = read(scene_of(3000).glb(), mesh);
  EXPECT_EQ(many.code(), ErrorCode::kLimit) << many.message();
  EXPECT_TRUE(mesh.empty());
  LoadReport report;
  ASSERT_TRUE(read(scene_of(10).glb(), mesh, &report).is_ok());
  EXPECT_EQ(report.mesh_instances, 10u);
}

// A rotation that is not a unit quaternion is read as its direction (viewers do; glTF requires
// unit length): [0, 0, 5, 5] turns the triangle a quarter about z and does not scale it by 50.
// One without a direction is a parse error.
TEST(GltfScene, RotationsAreUnitQuaternions) {
  Mesh mesh;
  Builder turned = one_triangle({{{"mesh", 0}, {"rotation", {0, 0, 5, 5}}}}, {{{"nodes", {0}}}});
  ASSERT_TRUE(read(turned.glb(), mesh).is_ok());
  const std::vector<float> expected = {0, 0, 0, 0, 1, 0, -1, 0, 0};  // (1,0,0) -> (0,1,0), (0,1,0) -> (-1,0,0)
  ASSERT_EQ(mesh.positions.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(mesh.positions[i], expected[i], 1e-6) << i;
  Builder none = one_triangle({{{"mesh", 0}, {"rotation", {0, 0, 0, 0}}}}, {{{"nodes", {0}}}});
  EXPECT_EQ(read(none.glb(), mesh).code(), ErrorCode::kParse);
}

TEST(GltfScene, StripsAndFansBecomeTriangles) {
  // A 4 x 1 strip of quads as a triangle strip (10 vertices, 8 triangles) and a fan of 6
  // triangles around the origin; every face must come out, counter-clockwise from +z.
  Builder b;
  // Strip order (x0, y1) (x0, y0) (x1, y1) (x1, y0)...: counter-clockwise first triangle.
  std::vector<float> strip;
  for (int i = 0; i <= 4; ++i) strip.insert(strip.end(), {float(i), 1, 0, float(i), 0, 0});
  std::vector<float> fan = {0, 0, 1};
  for (int i = 0; i <= 6; ++i) fan.insert(fan.end(), {std::cos(float(i) * 0.5f), std::sin(float(i) * 0.5f), 1});
  std::vector<uint32_t> strip_indices(10);
  for (uint32_t i = 0; i < 10; ++i) strip_indices[i] = i;
  const size_t sp2 = b.positions(strip), fp2 = b.positions(fan), si2 = b.indices(strip_indices);
  b.json["meshes"] = {{{"primitives",
                        {{{"attributes", {{"POSITION", sp2}}}, {"indices", si2}, {"mode", 5}},
                         {{"attributes", {{"POSITION", fp2}}}, {"mode", 6}},
                         {{"attributes", {{"POSITION", fp2}}}, {"mode", 0}},
                         {{"attributes", {{"POSITION", fp2}}}, {"mode", 3}}}}}};
  Mesh mesh;
  LoadReport report;
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_EQ(mesh.face_count(), 8u + 6u);
  EXPECT_EQ(report.source_faces, 8u + 6u);
  EXPECT_EQ(report.skipped_primitives, 2u);
  for (size_t f = 0; f < mesh.face_count(); ++f) EXPECT_GT(signed_area_z(mesh, f), 0) << f;
  // Only points and lines: one clear error.
  b.json["meshes"][0]["primitives"] = {{{"attributes", {{"POSITION", fp2}}}, {"mode", 1}}};
  const Status s = read(b.glb(), mesh);
  EXPECT_EQ(s.code(), ErrorCode::kUnsupported);
  EXPECT_NE(s.message().find("1 point and line primitives"), std::string::npos) << s.message();
}

TEST(GltfScene, SparseAndQuantizedAccessors) {
  // Quantized positions (normalized int16, dequantized by the node's scale) with a sparse
  // substitution moving vertex 2 (KHR_mesh_quantization and the spec's sparse accessors).
  Builder b;
  const std::vector<int16_t> q = {0, 0, 0, 32767, 0, 0, 0, 32767, 0, 0, 0, 0};
  const size_t p = b.accessor(q, 5122, "VEC3", 3, /*normalized=*/true);
  const std::vector<uint32_t> sparse_index = {2};
  const std::vector<int16_t> sparse_value = {0, 16384, 0, 0};  // padded to 4 bytes
  b.accessor(sparse_index, 5125, "SCALAR", 1);
  b.accessor(sparse_value, 5122, "VEC3", 1);
  b.json["accessors"][p]["sparse"] = {
      {"count", 1}, {"indices", {{"bufferView", 1}, {"componentType", 5125}}}, {"values", {{"bufferView", 2}}}};
  b.json["accessors"].erase(2);
  b.json["accessors"].erase(1);
  b.json["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", p}}}}}}}};
  b.json["nodes"] = {{{"mesh", 0}, {"scale", {4, 4, 4}}}};
  b.json["scenes"] = {{{"nodes", {0}}}};
  b.json["extensionsUsed"] = {"KHR_mesh_quantization"};
  b.json["extensionsRequired"] = {"KHR_mesh_quantization"};
  Mesh mesh;
  ASSERT_TRUE(read(b.glb(), mesh).is_ok());
  ASSERT_EQ(mesh.vertex_count(), 3u);
  EXPECT_NEAR(mesh.positions[3], 4.f, 1e-5);
  EXPECT_NEAR(mesh.positions[7], 4.f * 16384.f / 32767.f, 1e-5);
  // A sparse index out of range.
  b.json["accessors"][p]["sparse"]["count"] = 1;
  const std::vector<uint32_t> far = {3};
  b.accessor(far, 5125, "SCALAR", 1);
  b.json["accessors"][p]["sparse"]["indices"]["bufferView"] = b.json["bufferViews"].size() - 1;
  EXPECT_EQ(read(b.glb(), mesh).code(), ErrorCode::kParse);
}

TEST(GltfScene, UnsupportedRequiredExtensionIsNamed) {
  Builder b = one_triangle({{{"mesh", 0}}}, {{{"nodes", {0}}}});
  b.json["extensionsUsed"] = {"KHR_texture_basisu", "KHR_mesh_quantization"};
  b.json["extensionsRequired"] = {"KHR_mesh_quantization", "KHR_texture_basisu"};
  Mesh mesh;
  const Status s = read(b.glb(), mesh);
  EXPECT_EQ(s.code(), ErrorCode::kUnsupported);
  EXPECT_NE(s.message().find("KHR_texture_basisu"), std::string::npos) << s.message();
  b.json["extensionsRequired"] = {"KHR_mesh_quantization"};  // used but not required: fine
  EXPECT_TRUE(read(b.glb(), mesh).is_ok());
}

TEST(GltfScene, GltfWithDataUriAndBinFile) {
  Builder b = one_triangle({{{"mesh", 0}, {"translation", {0, 0, 3}}}}, {{{"nodes", {0}}}});
  Mesh mesh;
  ASSERT_TRUE(read(b.gltf(), mesh).is_ok());  // data: URI, from memory
  EXPECT_FLOAT_EQ(mesh.positions[2], 3.f);
  // Beside a file: load_mesh finds "my scene.bin" through its percent-encoded URI.
  const std::string dir = test::empty_temp_dir("gltf_uri");
  std::ofstream(dir + "/my scene.bin", std::ios::binary) << b.bin;
  std::ofstream(dir + "/scene.gltf") << b.gltf("my%20scene.bin");
  LoadReport report;
  ASSERT_TRUE(load_mesh(dir + "/scene.gltf", mesh, &report).is_ok());
  EXPECT_EQ(report.format, "glTF");
  EXPECT_FLOAT_EQ(mesh.positions[2], 3.f);
  Image texture;
  EXPECT_TRUE(read_glb_file(dir + "/scene.gltf", mesh, &texture).is_ok());
  // From memory no file is opened; URIs that leave the folder are refused.
  EXPECT_EQ(read(b.gltf("my%20scene.bin"), mesh).code(), ErrorCode::kUnsupported);
  for (const char* uri : {"../x.bin", "/etc/passwd", "file:///etc/passwd", "http://example.com/a.bin", "a/../../b"}) {
    std::ofstream(dir + "/bad.gltf") << b.gltf(uri);
    const Status s = load_mesh(dir + "/bad.gltf", mesh);
    EXPECT_EQ(s.code(), ErrorCode::kUnsupported) << uri << ": " << s.message();
  }
  // A .bin shorter than byteLength.
  std::ofstream(dir + "/short.bin", std::ios::binary) << b.bin.substr(0, 10);
  std::ofstream(dir + "/short.gltf") << b.gltf("short.bin");
  EXPECT_EQ(load_mesh(dir + "/short.gltf", mesh).code(), ErrorCode::kParse);
  fs::remove_all(dir);
}

TEST(GltfScene, OneBufferFileNamedManyTimesIsReadOnceAndCharged) {
  // 600 buffers name one 64 KiB .bin (as "big.bin", "./big.bin" and a hard link): read once, it
  // widens the budget once (64 x its size), so an 80 MB TEXCOORD_1 of zeros is over the budget.
  // Read per entry, the budget grew by 64 x 600 x 64 KiB and the accessor was allocated.
  Builder b = one_triangle({{{"mesh", 0}}}, {{{"nodes", {0}}}});
  b.json["accessors"].push_back({{"componentType", 5126}, {"type", "VEC2"}, {"count", 10'000'000}});
  b.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = b.json["accessors"].size() - 1;
  b.bin.resize(64 << 10, '\0');
  const std::string dir = test::empty_temp_dir("gltf_many_buffers");
  std::ofstream(dir + "/big.bin", std::ios::binary) << b.bin;
  fs::create_hard_link(dir + "/big.bin", dir + "/alias.bin");
  Json j = Json::parse(b.gltf("big.bin"));
  for (int k = 1; k < 600; ++k)
    j["buffers"].push_back({{"byteLength", 100 + k},
                            {"uri", k % 3 == 0   ? "big.bin"
                                    : k % 3 == 1 ? "./big.bin"
                                                 : "alias.bin"}});
  std::ofstream(dir + "/many.gltf") << j.dump();
  Mesh mesh;
  const Status s = load_mesh(dir + "/many.gltf", mesh);
  EXPECT_EQ(s.code(), ErrorCode::kLimit) << s.message();
  EXPECT_NE(s.message().find("more decoded data than its size allows"), std::string::npos) << s.message();
  // Without the bomb the same buffers load, each entry reading its own length of the shared bytes.
  j["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_1");
  std::ofstream(dir + "/many.gltf") << j.dump();
  EXPECT_TRUE(load_mesh(dir + "/many.gltf", mesh).is_ok());
  EXPECT_EQ(mesh.face_count(), 1u);
  fs::remove_all(dir);
}

// The first bytes of a PNG claiming width x height (IHDR only: enough for its header).
std::string png_header(uint32_t width, uint32_t height) {
  std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16);
  for (const uint32_t v : {width, height})
    for (int shift = 24; shift >= 0; shift -= 8) png.push_back(static_cast<char>(v >> shift & 0xff));
  return png + std::string("\x08\x02\0\0\0\0\0\0\0", 9);
}

TEST(GltfScene, TextureSizeIsReadFromItsHeaderWhereverItIs) {
  // One textured triangle; the image in a buffer view, a data: URI or a file next to the .gltf.
  Builder b = one_triangle({{{"mesh", 0}}}, {{{"nodes", {0}}}});
  b.json["meshes"][0]["primitives"][0]["material"] = 0;
  b.json["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.json["textures"] = {{{"source", 0}}};
  const auto size_of = [](const std::string& path, LoadReport& report) {
    Mesh mesh;
    const Status s = read_glb_file(path, mesh, nullptr, &report);
    EXPECT_TRUE(s.is_ok()) << s.message();
    return std::to_string(report.texture_width) + "x" + std::to_string(report.texture_height);
  };
  const std::string dir = test::empty_temp_dir("gltf_texture_size");
  LoadReport report;
  // Embedded: a header no decoder takes (100000 x 70000 RGB is 21 GB), read all the same.
  {
    Builder e = b;
    const std::string png = png_header(100000, 70000);
    e.json["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", e.bin.size()}, {"byteLength", png.size()}});
    e.bin += png;
    e.json["images"] = {{{"bufferView", e.json["bufferViews"].size() - 1}, {"mimeType", "image/png"}}};
    std::ofstream(dir + "/embedded.glb", std::ios::binary) << e.glb();
    EXPECT_EQ(size_of(dir + "/embedded.glb", report), "100000x70000");
    EXPECT_FALSE(report.texture_file);
  }
  // A data: URI.
  {
    Builder d = b;
    Builder bytes;
    bytes.bin = png_header(16000, 15000);
    d.json["images"] = {{{"uri", "data:image/png;base64," + bytes.base64()}}};
    std::ofstream(dir + "/data.gltf") << d.gltf();
    EXPECT_EQ(size_of(dir + "/data.gltf", report), "16000x15000");
    EXPECT_FALSE(report.texture_file);
  }
  // A file next to the .gltf: a PNG, and a JPEG whose frame header lies beyond 128 KiB of APP1
  // segments (more than the first read of 64 KiB).
  std::ofstream(dir + "/tex.png", std::ios::binary) << png_header(40000, 30000);
  std::string jpeg("\xff\xd8", 2);
  for (int k = 0; k < 2; ++k) jpeg += std::string("\xff\xe1\xff\xff", 4) + std::string(0xffff - 2, 'x');
  jpeg += std::string("\xff\xc0\x00\x11\x08\x75\x30\x9c\x40\x03", 10) + std::string(15, '\0');
  std::ofstream(dir + "/tex.jpg", std::ios::binary) << jpeg;
  for (const auto& [uri, size] : std::vector<std::pair<std::string, std::string>>{
           {"tex.png", "40000x30000"}, {"tex.jpg", "40000x30000"}, {"missing.png", "0x0"}, {"../tex.png", "0x0"}}) {
    Builder f = b;
    f.json["images"] = {{{"uri", uri}}};
    std::ofstream(dir + "/file.gltf") << f.gltf();
    EXPECT_EQ(size_of(dir + "/file.gltf", report), size) << uri;
    EXPECT_EQ(report.texture_file, size != "0x0") << uri;
    // The file's path, which tailor render loads and draws.
    EXPECT_EQ(report.texture_path, size != "0x0" ? (fs::path(dir) / uri).string() : "") << uri;
  }
  fs::remove_all(dir);
}

// One textured triangle (TEXCOORD_0, material 0 with a base colour texture of image 0); the caller
// gives the image.
Builder textured_triangle() {
  Builder b = one_triangle({{{"mesh", 0}}}, {{{"nodes", {0}}}});
  const size_t uv = b.accessor(std::vector<float>{0, 0, 1, 0, 0, 1}, 5126, "VEC2", 3);
  b.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
  b.json["meshes"][0]["primitives"][0]["material"] = 0;
  b.json["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.json["textures"] = {{{"source", 0}}};
  return b;
}

// `bytes` as image 0 in a buffer view of `b`'s buffer.
void embed_image(Builder& b, const std::string& bytes) {
  while (b.bin.size() % 4) b.bin.push_back('\0');
  b.json["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", b.bin.size()}, {"byteLength", bytes.size()}});
  b.bin += bytes;
  b.json["images"] = {{{"bufferView", b.json["bufferViews"].size() - 1}, {"mimeType", "image/png"}}};
}

std::string data_uri(const std::string& bytes, const char* type) {
  Builder holder;
  holder.bin = bytes;
  return std::string("data:") + type + ";base64," + holder.base64();
}

TEST(GltfScene, BaseColourImagesDecodeEmbeddedOrFromDataUris) {
  const std::string png = test::read_all(std::string(TAILOR_SOURCE_DIR) + "/tests/data/textures/vistex-tile04-128.png");
  const std::string dir = test::empty_temp_dir("gltf_image_uri");
  const auto decoded = [](const std::string& file, LoadReport& report) {
    Mesh mesh;
    Image texture;
    const Status s = read_glb_file(file, mesh, &texture, &report);
    EXPECT_TRUE(s.is_ok()) << file << ": " << s.message();
    return std::to_string(texture.width) + "x" + std::to_string(texture.height);
  };
  LoadReport report;
  // A data: URI image in a .glb and in a .gltf.
  Builder b = textured_triangle();
  b.json["images"] = {{{"uri", data_uri(png, "image/png")}}};
  std::ofstream(dir + "/uri.glb", std::ios::binary) << b.glb();
  std::ofstream(dir + "/uri.gltf") << b.gltf();
  EXPECT_EQ(decoded(dir + "/uri.glb", report), "128x128");
  EXPECT_EQ(decoded(dir + "/uri.gltf", report), "128x128");
  // A buffer view of a .gltf's data: URI buffer (the document's own bytes, gone after parsing).
  Builder v = textured_triangle();
  embed_image(v, png);
  std::ofstream(dir + "/view.gltf") << v.gltf();
  EXPECT_EQ(decoded(dir + "/view.gltf", report), "128x128");
  EXPECT_EQ(report.texture_problem, "");
  fs::remove_all(dir);
}

TEST(GltfScene, BaseColourImageThatDoesNotDecodeLeavesTheMeshReadAndSaysWhy) {
  const std::string png = test::read_all(std::string(TAILOR_SOURCE_DIR) + "/tests/data/textures/vistex-tile04-128.png");
  std::string corrupt = png;  // a good header, broken pixel data
  for (size_t i = 64; i < corrupt.size(); ++i) corrupt[i] = static_cast<char>(i * 7);
  const std::string dir = test::empty_temp_dir("gltf_bad_image");
  const auto write_triangle_with = [](const std::string& image, const std::string& path) {
    Builder b = textured_triangle();
    embed_image(b, image);
    std::ofstream(path, std::ios::binary) << b.glb();
  };
  for (const std::string& bytes : {std::string("not an image at all"), corrupt}) {
    write_triangle_with(bytes, dir + "/bad.glb");
    Mesh mesh;
    Image texture;
    LoadReport report;
    const Status s = read_glb_file(dir + "/bad.glb", mesh, &texture, &report);
    ASSERT_TRUE(s.is_ok()) << s.message();
    EXPECT_EQ(mesh.face_count(), 1u);
    EXPECT_EQ(mesh.corner_uvs.size(), 6u);
    EXPECT_TRUE(texture.empty());
    EXPECT_EQ(report.texture_problem, "embedded texture cannot be decoded");
    EXPECT_EQ(report.texture_named, "image 0");
  }
  // An image over the pixel limit is still refused: the limit is the caller's, with a flag to raise it.
  write_triangle_with(png, dir + "/big.glb");
  Mesh mesh;
  Image texture;
  ImageLoadOptions small;
  small.max_pixels = 100;
  EXPECT_EQ(read_glb_file(dir + "/big.glb", mesh, &texture, nullptr, small).code(), ErrorCode::kInvalidImage);
  fs::remove_all(dir);
}

TEST(GltfScene, TextureTransformOnTheBaseColourIsReported) {
  Builder b = textured_triangle();
  Mesh mesh;
  LoadReport report;
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_FALSE(report.texture_transform);
  b.json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
      {"KHR_texture_transform", {{"scale", {4, 1}}}}};
  b.json["extensionsUsed"] = {"KHR_texture_transform"};
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_TRUE(report.texture_transform);
}

TEST(GltfScene, APrimitiveWithoutTheUvsOthersHaveIsNamed) {
  // Mesh 0 "rock": primitive 0 with TEXCOORD_0, primitive 1 (a second triangle) without.
  Builder b = textured_triangle();
  const size_t p = b.positions({2, 0, 0, 3, 0, 0, 2, 1, 0});
  b.json["meshes"][0]["name"] = "rock";
  b.json["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", p}}}});
  Mesh mesh;
  LoadReport report;
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_TRUE(mesh.corner_uvs.empty()) << "all or nothing";
  EXPECT_EQ(report.faces_without_uv, 1u);
  EXPECT_EQ(report.primitive_without_uv, "mesh 0 'rock' primitive 1");
  // None with UVs: nothing to name.
  b.json["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_0");
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_EQ(report.faces_without_uv, 0u);
  EXPECT_EQ(report.primitive_without_uv, "");
}

// === Files made by glTF-Transform =================================================================

std::string gltf_transform() {
  const std::string cli = std::string(TAILOR_SOURCE_DIR) + "/web/node_modules/.bin/gltf-transform";
  std::string out;
  if (run_command("command -v node", out) != 0 || !fs::exists(cli)) return {};
  return cli;
}

void expect_valid_gltf(const std::string& file) {
  std::string out;
  const int rc = run_command(
      std::string("node ") + TAILOR_SOURCE_DIR + "/tests/tools/validate_gltf.mjs --strict '" + file + "'", out);
  EXPECT_EQ(rc, 0) << out;
}

// Every vertex of `a` lies within `tolerance` of a vertex of `b` and vice versa (a sweep over x).
void expect_same_points(const Mesh& a, const Mesh& b, float tolerance, const std::string& what) {
  auto covered = [tolerance](const Mesh& from, const Mesh& to) {
    std::vector<std::array<float, 3>> sorted(to.vertex_count());
    for (size_t v = 0; v < sorted.size(); ++v)
      sorted[v] = {to.positions[3 * v], to.positions[3 * v + 1], to.positions[3 * v + 2]};
    std::sort(sorted.begin(), sorted.end());
    size_t missing = 0;
    for (size_t v = 0; v < from.vertex_count(); ++v) {
      const float* p = &from.positions[3 * v];
      auto it = std::lower_bound(sorted.begin(), sorted.end(), std::array<float, 3>{p[0] - tolerance, -1e30f, -1e30f});
      bool found = false;
      for (; it != sorted.end() && (*it)[0] <= p[0] + tolerance && !found; ++it)
        found = std::abs((*it)[1] - p[1]) <= tolerance && std::abs((*it)[2] - p[2]) <= tolerance;
      missing += !found;
    }
    return missing;
  };
  EXPECT_EQ(covered(a, b), 0u) << what;
  EXPECT_EQ(covered(b, a), 0u) << what;
}

float extent(const Mesh& m) {
  float lo = 1e30f, hi = -1e30f;
  for (float x : m.positions) lo = std::min(lo, x), hi = std::max(hi, x);
  return hi - lo;
}

// The committed files (tests/data/meshes/gltf, made once by glTF-Transform): the source's
// geometry within the quantization's tolerance; every cut of them fails cleanly, random damage
// never crashes.
TEST(GltfFiles, CommittedCompressedFilesMatchTheirSource) {
  const Mesh source = test::load_test_mesh("blobby-3cc.off");
  const float tolerance = extent(source) / 8192.f;
  for (const char* name : {"blobby_quantize.glb", "blobby_meshopt.glb", "blobby_draco.glb"}) {
    SCOPED_TRACE(name);
    LoadReport report;
    Mesh mesh = test::load_test_mesh(std::string("gltf/") + name, &report);
    EXPECT_EQ(mesh.face_count(), source.face_count()) << report.format;
    expect_same_points(mesh, source, tolerance, name);
    const std::string bytes = test::read_all(test::mesh_path(std::string("gltf/") + name));
    for (size_t length = 0; length < bytes.size(); length += 1 + length / 16) {
      const Status s = read_glb_memory(std::span<const char>(bytes.data(), length), name, mesh, nullptr);
      EXPECT_FALSE(s.is_ok()) << length;
    }
    std::mt19937 rng(7);
    for (int trial = 0; trial < 200; ++trial) {
      std::string damaged = bytes;
      for (int k = 0; k < 4; ++k) damaged[rng() % damaged.size()] = static_cast<char>(rng());
      (void)read_glb_memory(damaged, name, mesh, nullptr);
    }
  }
}

// The JSON chunk of a .glb file.
Json glb_json_of(const std::string& file) {
  const std::string glb = test::read_all(file);
  uint32_t json_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  return Json::parse(glb.substr(20, json_length));
}

// Writes the .glb `file` again to `out` with its JSON chunk replaced by `j` (the BIN chunk kept).
void write_glb_with_json(const std::string& file, const Json& j, const std::string& out) {
  const std::string glb = test::read_all(file);
  uint32_t json_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  std::string text = j.dump();
  while (text.size() % 4) text += ' ';
  const std::string bin_chunk = glb.substr(20 + json_length);
  std::string header_bytes(20, '\0');
  const uint32_t header[5] = {0x46546C67, 2, static_cast<uint32_t>(20 + text.size() + bin_chunk.size()),
                              static_cast<uint32_t>(text.size()), 0x4E4F534A};
  std::memcpy(header_bytes.data(), header, 20);
  std::ofstream(out, std::ios::binary) << header_bytes + text + bin_chunk;
}

TEST(GltfScene, TailorsOwnHierarchyIsNotReportedAsLost) {
  // Two instances of a triangle, one moved: their transforms are lost (flattened) on a mapping.
  Builder b = one_triangle({{{"mesh", 0}}, {{"mesh", 0}, {"translation", {3, 0, 0}}}}, {{{"nodes", {0, 1}}}});
  Mesh mesh;
  LoadReport report;
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_NE(report.not_kept.find("node transforms"), std::string::npos) << report.not_kept;
  // tailor's output of it (a root node and one plain child per instance; the root turned by --up z
  // and scaled by the quantization) read again: the layout tailor writes again, nothing lost.
  const std::string dir = test::empty_temp_dir("gltf_own_layout");
  const Atlas atlas = patterned_atlas(mesh.face_count(), 3, 16.f);
  for (const MeshCompression method : {MeshCompression::kNone, MeshCompression::kQuantize, MeshCompression::kMeshopt}) {
    for (const SceneUp up : {SceneUp::kY, SceneUp::kZ}) {
      SCOPED_TRACE(std::string(mesh_compression_name(method)) + (up == SceneUp::kZ ? " up z" : ""));
      ExportOptions options;
      options.compression = method;
      options.up = up;
      ASSERT_TRUE(export_mesh(dir + "/out.glb", mesh, atlas, options).is_ok());
      Mesh back;
      LoadReport again;
      ASSERT_TRUE(load_mesh(dir + "/out.glb", back, &again).is_ok());
      EXPECT_EQ(again.not_kept.find("node transforms"), std::string::npos) << again.not_kept;
      // The same file with a transform on a child is not tailor's layout.
      Json j = glb_json_of(dir + "/out.glb");
      j["nodes"][1]["translation"] = {0, 1, 0};
      write_glb_with_json(dir + "/out.glb", j, dir + "/moved.glb");
      ASSERT_TRUE(load_mesh(dir + "/moved.glb", back, &again).is_ok());
      EXPECT_NE(again.not_kept.find("node transforms"), std::string::npos) << again.not_kept;
    }
  }
  fs::remove_all(dir);
}

class GltfTransformTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cli_ = gltf_transform();
    if (cli_.empty()) GTEST_SKIP() << "node or @gltf-transform/cli (make deps) missing: skipped";
    dir_ = test::empty_temp_dir("gltf_transform");
    source_ = test::load_test_mesh("spot.obj");
    ASSERT_FALSE(source_.empty());
    // The source as a plain .glb (positions, normals, UVs), written by tailor's exporter.
    Atlas atlas;
    atlas.corner_uv.resize(6 * source_.face_count());
    for (size_t c = 0; c < 3 * source_.face_count(); ++c) {
      atlas.corner_uv[2 * c] = source_.positions[3 * source_.indices[c]] * 512;
      atlas.corner_uv[2 * c + 1] = source_.positions[3 * source_.indices[c] + 1] * 512;
    }
    atlas.patch.assign(source_.face_count(), 0);
    atlas.patch_count = 1;
    ASSERT_TRUE(export_mesh(path("source.glb"), source_, atlas, ExportOptions{}).is_ok());
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  // Runs `gltf-transform ARGS` in the scratch folder.
  void transform(const std::string& args) {
    std::string out;
    ASSERT_EQ(run_command("cd '" + dir_ + "' && '" + cli_ + "' " + args, out), 0) << args << "\n" << out;
  }
  std::string cli_, dir_;
  Mesh source_;
};

TEST_F(GltfTransformTest, CompressedFilesReadBackInWorldSpace) {
  transform("quantize source.glb quantize.glb");
  transform("meshopt source.glb meshopt.glb");
  transform("draco source.glb draco.glb");
  transform("copy source.glb separate.gltf");
  const float size = extent(source_);
  for (const char* name : {"quantize.glb", "meshopt.glb", "draco.glb", "separate.gltf"}) {
    SCOPED_TRACE(name);
    if (std::string(name).ends_with(".glb")) expect_valid_gltf(path(name));  // the validator opens no .bin
    Mesh mesh;
    LoadReport report;
    const Status s = load_mesh(path(name), mesh, &report);
    ASSERT_TRUE(s.is_ok()) << s.message();
    EXPECT_EQ(mesh.face_count(), source_.face_count()) << report.format;
    // 14-bit quantization (glTF-Transform's default for positions): within 2^-13 of the extent.
    const float tolerance = std::string(name) == "separate.gltf" ? 0.f : size / 8192.f;
    expect_same_points(mesh, source_, tolerance, name);
  }
}

TEST_F(GltfTransformTest, MergedAndInstancedScenes) {
  // Two files merged into one scene; then a scene whose mesh is used by two nodes, and
  // glTF-Transform's `instance` turning them into EXT_mesh_gpu_instancing: same world geometry.
  transform("copy source.glb a.glb");
  transform("merge source.glb a.glb merged.glb --merge-scenes");
  Mesh merged;
  ASSERT_TRUE(load_mesh(path("merged.glb"), merged).is_ok());
  LoadReport report;
  ASSERT_TRUE(load_mesh(path("merged.glb"), merged, &report).is_ok());
  EXPECT_EQ(report.mesh_instances, 2u);
  EXPECT_EQ(report.source_faces, 2 * source_.face_count());

  // Two nodes over the source's mesh: one where it is, one moved by (3, 0, 0).
  Json j = glb_json_of(path("source.glb"));
  j["nodes"] = {{{"mesh", 0}}, {{"mesh", 0}, {"translation", {3, 0, 0}}}};
  j["scenes"] = {{{"nodes", {0, 1}}}};
  write_glb_with_json(path("source.glb"), j, path("two.glb"));
  transform("instance two.glb instanced.glb --min 2");
  Mesh two, instanced;
  ASSERT_TRUE(load_mesh(path("two.glb"), two).is_ok());
  const Status s = load_mesh(path("instanced.glb"), instanced, &report);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_NE(test::read_all(path("instanced.glb")).find("EXT_mesh_gpu_instancing"), std::string::npos);
  EXPECT_EQ(report.mesh_instances, 2u);
  EXPECT_EQ(two.face_count(), 2 * source_.face_count());
  EXPECT_EQ(instanced.face_count(), two.face_count());
  expect_same_points(instanced, two, 1e-5f, "instanced");
  float max_x = -1e30f;
  for (size_t v = 0; v < two.vertex_count(); ++v) max_x = std::max(max_x, two.positions[3 * v]);
  float source_max_x = -1e30f;
  for (size_t v = 0; v < source_.vertex_count(); ++v) source_max_x = std::max(source_max_x, source_.positions[3 * v]);
  EXPECT_NEAR(max_x, source_max_x + 3, 1e-5);
}

// === Compressed output (ExportOptions::compression) ==============================================

// Every corner of `back` sits within pos_tol of a vertex of `source` that has a corner with a UV
// within uv_tol (UVs in repeats, OBJ convention: what the readers return).
void expect_same_corners(const Mesh& back, const Mesh& source, float pos_tol, float uv_tol, const std::string& what) {
  std::vector<std::pair<std::array<float, 3>, uint32_t>> sorted(source.vertex_count());
  for (size_t v = 0; v < sorted.size(); ++v)
    sorted[v] = {{source.positions[3 * v], source.positions[3 * v + 1], source.positions[3 * v + 2]}, uint32_t(v)};
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::vector<std::array<float, 2>>> uvs(source.vertex_count());
  for (size_t c = 0; c < source.indices.size(); ++c)
    uvs[source.indices[c]].push_back({source.corner_uvs[2 * c], source.corner_uvs[2 * c + 1]});
  size_t bad = 0;
  for (size_t c = 0; c < back.indices.size(); ++c) {
    const float* p = &back.positions[3 * back.indices[c]];
    const float u = back.corner_uvs[2 * c], v = back.corner_uvs[2 * c + 1];
    bool found = false;
    auto it = std::lower_bound(sorted.begin(), sorted.end(),
                               std::make_pair(std::array<float, 3>{p[0] - pos_tol, -1e30f, -1e30f}, 0u));
    for (; it != sorted.end() && it->first[0] <= p[0] + pos_tol && !found; ++it) {
      if (std::abs(it->first[1] - p[1]) > pos_tol || std::abs(it->first[2] - p[2]) > pos_tol) continue;
      for (const auto& uv : uvs[it->second])
        // glTF's v is flipped by a whole repeat (t = -v): compare modulo 1.
        found = found || (std::abs(uv[0] - u) <= uv_tol && std::abs(std::remainder(uv[1] - v, 1.0f)) <= uv_tol);
    }
    bad += !found;
  }
  EXPECT_EQ(bad, 0u) << what << ": corners without a matching source corner";
}

TEST(GltfCompressed, EveryMethodReadsBackValidAndSmaller) {
  const Mesh source = test::load_test_mesh("spot.obj");
  ASSERT_FALSE(source.corner_uvs.empty());
  Atlas atlas;  // the file's own UVs, in pixels of a 512 px texture
  atlas.corner_uv.resize(source.corner_uvs.size());
  for (size_t i = 0; i < atlas.corner_uv.size(); ++i) atlas.corner_uv[i] = source.corner_uvs[i] * 512;
  atlas.patch.assign(source.face_count(), 0);
  const std::string dir = test::empty_temp_dir("gltf_compressed");
  const float tolerance = extent(source) / 16384.f;  // 16-bit positions
  size_t plain_size = 0;
  const bool node = !gltf_transform().empty();
  for (MeshCompression method :
       {MeshCompression::kNone, MeshCompression::kQuantize, MeshCompression::kMeshopt, MeshCompression::kDraco}) {
    const std::string name = mesh_compression_name(method);
    SCOPED_TRACE(name);
    ExportOptions options;
    options.compression = method;
    const std::string file = dir + "/" + name + ".glb";
    ASSERT_TRUE(export_mesh(file, source, atlas, options).is_ok());
    Mesh back;
    LoadReport report;
    const Status s = read_glb_file(file, back, nullptr, &report);
    ASSERT_TRUE(s.is_ok()) << s.message();
    EXPECT_EQ(back.face_count(), source.face_count());
    expect_same_corners(back, source, method == MeshCompression::kNone ? 0.f : tolerance,
                        method == MeshCompression::kNone ? 0.f : 2e-4f, name);
    const size_t size = fs::file_size(file);
    if (method == MeshCompression::kNone) plain_size = size;
    // At most 30% here (5,856 faces; the fixed costs weigh more than on the 1M-face meshes that
    // docs/performance.md measures, where meshopt is under a quarter).
    if (method == MeshCompression::kMeshopt || method == MeshCompression::kDraco) {
      EXPECT_LE(10 * size, 3 * plain_size) << size << " bytes, uncompressed " << plain_size;
    }
    if (node) expect_valid_gltf(file);
    // The same file twice: deterministic.
    ASSERT_TRUE(export_mesh(dir + "/again.glb", source, atlas, options).is_ok());
    EXPECT_EQ(test::read_all(file), test::read_all(dir + "/again.glb"));
  }
  ExportOptions options;
  options.compression = MeshCompression::kDraco;
  EXPECT_EQ(export_mesh(dir + "/x.obj", source, atlas, options).code(), ErrorCode::kInvalidArgument);
  EXPECT_FALSE(fs::exists(dir + "/x.obj"));
  fs::remove_all(dir);
}

// === Kept attributes ==============================================================================

const CornerAttribute* attribute(const Mesh& mesh, const std::string& name) {
  for (const CornerAttribute& a : mesh.corner_attributes)
    if (a.name == name) return &a;
  return nullptr;
}

TEST(GltfKept, NormalsColoursAndOtherUvSetsSurviveAMapping) {
  // A flat-shaded unit box (hard edges: 4 vertices per side with the side's normal), COLOR_0 =
  // position, TEXCOORD_0 = (x + y, z), named, with a material.
  Builder b;
  std::vector<float> positions, normals, colours, uvs;
  std::vector<uint32_t> indices;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const uint32_t base = static_cast<uint32_t>(positions.size() / 3);
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int corner = 0; corner < 4; ++corner) {
        float p[3];
        p[axis] = float(side);
        p[u] = float(corner == 1 || corner == 2);
        p[v] = float(corner >= 2);
        float n[3] = {0, 0, 0};
        n[axis] = side ? 1.f : -1.f;
        positions.insert(positions.end(), p, p + 3);
        normals.insert(normals.end(), n, n + 3);
        colours.insert(colours.end(), {p[0], p[1], p[2]});
        uvs.insert(uvs.end(), {p[0] + p[1], p[2]});
      }
      // Counter-clockwise seen from outside: (0 1 2) (0 2 3) for the + side, reversed for the -.
      if (side)
        indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      else
        indices.insert(indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    }
  const size_t p = b.positions(positions), n = b.accessor(normals, 5126, "VEC3", normals.size() / 3);
  const size_t c = b.accessor(colours, 5126, "VEC3", colours.size() / 3);
  const size_t t = b.accessor(uvs, 5126, "VEC2", uvs.size() / 2), i = b.indices(indices);
  Json primitive = {{"indices", i}, {"material", 0}};
  primitive["attributes"] = {{"POSITION", p}, {"NORMAL", n}, {"COLOR_0", c}, {"TEXCOORD_0", t}};
  Json box_mesh = {{"name", "box"}};
  box_mesh["primitives"] = Json::array({primitive});
  b.json["meshes"] = Json::array({box_mesh});
  b.json["materials"] = {{{"name", "red"}}};
  b.json["nodes"] = {{{"mesh", 0}, {"name", "box"}}};
  b.json["scenes"] = {{{"nodes", {0}}}};
  Mesh mesh;
  LoadReport report;
  ASSERT_TRUE(read(b.glb(), mesh, &report).is_ok());
  EXPECT_EQ(mesh.vertex_count(), 8u);  // welded: the hard edges live in the corner normals
  {  // A base colour texture that names a set the primitive lacks: its TEXCOORD_0, as without texCoord.
    Builder named = b;
    named.json["materials"][0]["pbrMetallicRoughness"] = {{"baseColorTexture", {{"texCoord", 1}}}};
    Mesh other;
    ASSERT_TRUE(read(named.glb(), other).is_ok());
    EXPECT_EQ(other.corner_uvs, mesh.corner_uvs);
    EXPECT_FALSE(mesh.corner_uvs.empty());
  }
  EXPECT_EQ(report.not_kept, "") << "names and materials are kept";
  ASSERT_EQ(mesh.scene.instances.size(), 1u);
  EXPECT_EQ(mesh.scene.instances[0].node_name, "box");
  ASSERT_NE(attribute(mesh, "NORMAL"), nullptr);

  // Map into TEXCOORD_1 (any UVs will do): the file's normals, colours and TEXCOORD_0 come back.
  const Atlas atlas = patterned_atlas(mesh.face_count(), 7, 64.f);
  const std::string dir = test::empty_temp_dir("gltf_kept");
  for (MeshCompression method : {MeshCompression::kNone, MeshCompression::kMeshopt, MeshCompression::kDraco}) {
    SCOPED_TRACE(mesh_compression_name(method));
    ExportOptions options;
    options.uv_set = 1;
    options.compression = method;
    const std::string file = dir + "/kept.glb";
    ASSERT_TRUE(export_mesh(file, mesh, atlas, options).is_ok());
    if (!gltf_transform().empty()) expect_valid_gltf(file);
    Mesh back;
    ASSERT_TRUE(load_mesh(file, back).is_ok());
    const CornerAttribute *normal = attribute(back, "NORMAL"), *colour = attribute(back, "COLOR_0"),
                          *uv0 = attribute(back, "TEXCOORD_0"), *uv1 = attribute(back, "TEXCOORD_1");
    ASSERT_TRUE(normal && colour && uv0 && uv1);
    ASSERT_EQ(back.face_count(), 12u);
    const float tolerance = method == MeshCompression::kNone ? 0.f : 0.01f;
    for (size_t f = 0; f < back.face_count(); ++f) {
      const float* a = &back.positions[3 * back.indices[3 * f]];
      const float* bb = &back.positions[3 * back.indices[3 * f + 1]];
      const float* cc = &back.positions[3 * back.indices[3 * f + 2]];
      const float e1[3] = {bb[0] - a[0], bb[1] - a[1], bb[2] - a[2]},
                  e2[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
      float face[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const float length = std::sqrt(face[0] * face[0] + face[1] * face[1] + face[2] * face[2]);
      for (int k = 0; k < 3; ++k) {
        const size_t corner = 3 * f + size_t(k);
        const float* q = &back.positions[3 * back.indices[corner]];
        for (int d = 0; d < 3; ++d) {
          EXPECT_NEAR(normal->values[3 * corner + size_t(d)], face[d] / length, tolerance) << "corner " << corner;
          EXPECT_NEAR(colour->values[4 * corner + size_t(d)], q[d], tolerance + 1e-6f) << "corner " << corner;
        }
        EXPECT_NEAR(uv0->values[2 * corner], q[0] + q[1], tolerance + 1e-6f);
        EXPECT_NEAR(uv0->values[2 * corner + 1], q[2], tolerance + 1e-6f);
      }
    }
  }
  // Under a texture the material reads TEXCOORD_1, and so does the reader: the mesh's UVs are the
  // mapped ones (what eval measures and render draws), not TEXCOORD_0.
  {
    ExportOptions options;
    options.uv_set = 1;
    options.texture_path = std::string(TAILOR_SOURCE_DIR) + "/tests/data/textures/vistex-sand05-128.png";
    const std::string file = dir + "/textured.glb";
    ASSERT_TRUE(export_mesh(file, mesh, atlas, options).is_ok());
    Mesh back;
    ASSERT_TRUE(load_mesh(file, back).is_ok());
    const CornerAttribute* uv1 = attribute(back, "TEXCOORD_1");
    ASSERT_TRUE(uv1 != nullptr);
    ASSERT_EQ(back.corner_uvs.size(), uv1->values.size());
    for (size_t k = 0; k < back.corner_uvs.size(); k += 2) {
      EXPECT_EQ(back.corner_uvs[k], uv1->values[k]);
      EXPECT_EQ(back.corner_uvs[k + 1], -uv1->values[k + 1]);  // v up in Mesh, down in glTF
    }
  }
  // Without a TEXCOORD_0 to keep, TEXCOORD_1 alone would be a gap glTF does not allow: refused.
  {
    Mesh bare = mesh;
    std::erase_if(bare.corner_attributes, [](const CornerAttribute& a) { return a.name == "TEXCOORD_0"; });
    ExportOptions options;
    options.uv_set = 1;
    const Status s = export_mesh(dir + "/gap.glb", bare, atlas, options);
    EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(s.message().find("no TEXCOORD_0 to keep below it"), std::string::npos) << s.message();
    EXPECT_FALSE(fs::exists(dir + "/gap.glb"));
  }
  fs::remove_all(dir);
}

TEST(GltfKept, PlyNormalsAndColoursReachTheGlb) {
  // A tetrahedron whose vertices carry (not unit) normals and uchar colours.
  const std::string dir = test::empty_temp_dir("gltf_ply_kept");
  std::ofstream(dir + "/t.ply") << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                   "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
                                   "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                                   "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
                                   "0 0 0 -2 -2 -2 255 0 0\n1 0 0 2 0 0 0 255 0\n0 1 0 0 2 0 0 0 255\n"
                                   "0 0 1 0 0 2 51 102 153\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  Mesh mesh;
  ASSERT_TRUE(load_mesh(dir + "/t.ply", mesh).is_ok());
  ASSERT_NE(attribute(mesh, "NORMAL"), nullptr);
  ASSERT_NE(attribute(mesh, "COLOR_0"), nullptr);
  Atlas atlas;
  atlas.corner_uv.assign(6 * mesh.face_count(), 0.f);
  atlas.patch.assign(mesh.face_count(), 0);
  ASSERT_TRUE(export_mesh(dir + "/t.glb", mesh, atlas, ExportOptions{}).is_ok());
  if (!gltf_transform().empty()) expect_valid_gltf(dir + "/t.glb");
  Mesh back;
  ASSERT_TRUE(load_mesh(dir + "/t.glb", back).is_ok());
  const CornerAttribute *normal = attribute(back, "NORMAL"), *colour = attribute(back, "COLOR_0");
  ASSERT_TRUE(normal && colour);
  const float s = 1.f / std::sqrt(3.f);
  for (size_t c = 0; c < back.indices.size(); ++c) {
    const float* p = &back.positions[3 * back.indices[c]];
    const int v = p[0] == 1 ? 1 : p[1] == 1 ? 2 : p[2] == 1 ? 3 : 0;  // which input vertex
    const float expected_normal[4][3] = {{-s, -s, -s}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const float expected_colour[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2f, 0.4f, 0.6f}};
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(normal->values[3 * c + size_t(k)], expected_normal[v][k], 1e-6) << c;
      EXPECT_NEAR(colour->values[4 * c + size_t(k)], expected_colour[v][k], 1e-6) << c;
    }
    EXPECT_EQ(colour->values[4 * c + 3], 1.f);
  }
  fs::remove_all(dir);
}

TEST(GltfKept, ObjColoursAndNormalsReachTheGlb) {
  const std::string dir = test::empty_temp_dir("gltf_obj_kept");
  std::ofstream(dir + "/c.obj") << "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 1 1 0 0.5 0.5 0.5\n"
                                   "vn 0 0 2\nvn 0 0.6 0.8\nf 1//1 2//1 3//1\nf 2//2 4//2 3//2\n";
  Mesh mesh;
  ASSERT_TRUE(load_mesh(dir + "/c.obj", mesh).is_ok());
  Atlas atlas;
  atlas.corner_uv.assign(6 * mesh.face_count(), 0.f);
  atlas.patch.assign(mesh.face_count(), 0);
  ASSERT_TRUE(export_mesh(dir + "/c.glb", mesh, atlas, ExportOptions{}).is_ok());
  Mesh back;
  ASSERT_TRUE(load_mesh(dir + "/c.glb", back).is_ok());
  const CornerAttribute *normal = attribute(back, "NORMAL"), *colour = attribute(back, "COLOR_0");
  ASSERT_TRUE(normal && colour);
  ASSERT_EQ(back.face_count(), 2u);
  for (size_t c = 0; c < back.indices.size(); ++c) {
    const float* p = &back.positions[3 * back.indices[c]];
    const bool second = c >= 3;  // faces keep their order in a plain .glb
    EXPECT_NEAR(normal->values[3 * c + 1], second ? 0.6f : 0.f, 1e-6) << c;
    EXPECT_NEAR(normal->values[3 * c + 2], second ? 0.8f : 1.f, 1e-6) << c;
    const float expected_red = p[0] == 0 && p[1] == 0 ? 1.f : p[0] == 1 && p[1] == 1 ? 0.5f : 0.f;
    EXPECT_NEAR(colour->values[4 * c], expected_red, 1e-6) << c;
  }
  fs::remove_all(dir);
}

// An OBJ's `v x y z r g b a` (some writers add alpha) keeps its colours with their alpha, and an
// .mtl's keyword in lower case (`map_kd`) still names the texture.
TEST(GltfKept, ObjAlphaColoursAndLowerCaseMapKd) {
  const std::string dir = test::empty_temp_dir("gltf_obj_alpha");
  std::ofstream(dir + "/c.obj") << "mtllib c.mtl\nv 0 0 0 1 0 0 0.25\nv 1 0 0 0 1 0 0.5\nv 0 1 0 0 0 1 1\nf 1 2 3\n";
  std::ofstream(dir + "/c.mtl") << "newmtl m\nmap_kd t.png\n";
  fs::copy_file(std::string(TAILOR_SOURCE_DIR) + "/tests/data/textures/vistex-sand05-128.png", dir + "/t.png");
  Mesh mesh;
  LoadReport report;
  ASSERT_TRUE(load_mesh(dir + "/c.obj", mesh, &report).is_ok());
  const CornerAttribute* colour = attribute(mesh, "COLOR_0");
  ASSERT_TRUE(colour != nullptr);
  ASSERT_EQ(colour->values.size(), 12u);
  EXPECT_EQ(colour->values[3], 0.25f);
  EXPECT_EQ(colour->values[4], 0.f);
  EXPECT_EQ(colour->values[5], 1.f);
  EXPECT_EQ(colour->values[7], 0.5f);
  EXPECT_EQ(colour->values[11], 1.f);
  EXPECT_EQ(report.texture_width, 128);
  EXPECT_EQ(report.texture_named, dir + "/t.png");
  fs::remove_all(dir);
}

// The names, extras and materials of a scene made by glTF-Transform reach the output: two
// instances of one mesh (named nodes with extras), two materials (factors, doubleSided, alphaMode,
// emissive, extras), the scene's and the asset's extras; plain, meshopt and Draco inputs, every
// compression on output; each output valid, read back with the same faces per material.
TEST_F(GltfTransformTest, NamesExtrasAndMaterialsSurviveAMapping) {
  Json j = glb_json_of(path("source.glb"));
  // The source's one primitive cut in two (its first half of the faces, its second), each with
  // its own material: the indices accessor split by byte offset.
  Json& primitive = j["meshes"][0]["primitives"][0];
  const size_t indices = primitive["indices"], count = j["accessors"][indices]["count"];
  const size_t half = count / 6 * 3;
  Json second_indices = j["accessors"][indices];
  j["accessors"][indices]["count"] = half;
  second_indices["count"] = count - half;
  second_indices["byteOffset"] = 4 * half;
  j["accessors"].push_back(second_indices);
  Json second = primitive;
  second["indices"] = j["accessors"].size() - 1;
  second["material"] = 1;
  primitive["material"] = 0;
  j["meshes"][0]["primitives"].push_back(second);
  j["meshes"][0]["name"] = "cow";
  j["meshes"][0]["extras"] = {{"scan", 7}};
  j["materials"] = {{{"name", "hide"},
                     {"doubleSided", true},
                     {"emissiveFactor", {0.1, 0.2, 0.3}},
                     {"extras", {{"grade", "A"}}},
                     {"pbrMetallicRoughness", {{"metallicFactor", 0.25}, {"roughnessFactor", 0.75}}}},
                    {{"name", "horn"},
                     {"alphaMode", "MASK"},
                     {"alphaCutoff", 0.4},
                     {"pbrMetallicRoughness", {{"baseColorFactor", {1, 0.5, 0.25, 1}}, {"metallicFactor", 1.0}}}}};
  j["nodes"] = {{{"mesh", 0}, {"name", "left"}, {"extras", {{"id", 1}}}},
                {{"mesh", 0}, {"name", "right"}, {"translation", {3, 0, 0}}, {"extras", {{"id", 2}}}}};
  j["scenes"] = {{{"nodes", {0, 1}}, {"name", "barn"}, {"extras", {{"season", "spring"}}}}};
  j["asset"]["extras"] = {{"author", "test"}};
  j["asset"]["copyright"] = "CC0";
  write_glb_with_json(path("source.glb"), j, path("scene.glb"));
  transform("meshopt scene.glb scene_meshopt.glb");
  transform("draco scene.glb scene_draco.glb");

  for (const char* input : {"scene.glb", "scene_meshopt.glb", "scene_draco.glb"}) {
    Mesh mesh;
    LoadReport report;
    const Status loaded = load_mesh(path(input), mesh, &report);
    ASSERT_TRUE(loaded.is_ok()) << input << ": " << loaded.message();
    EXPECT_EQ(report.not_kept.find("names"), std::string::npos) << report.not_kept;
    EXPECT_EQ(report.not_kept.find("materials,"), std::string::npos) << report.not_kept;
    ASSERT_EQ(mesh.scene.parts.size(), 4u) << input;  // 2 instances x 2 materials
    Atlas atlas = patterned_atlas(mesh.face_count(), 11, 32.f);
    for (MeshCompression method :
         {MeshCompression::kNone, MeshCompression::kQuantize, MeshCompression::kMeshopt, MeshCompression::kDraco}) {
      SCOPED_TRACE(std::string(input) + " -> " + mesh_compression_name(method));
      ExportOptions options;
      options.compression = method;
      const std::string file = path("out.glb");
      ASSERT_TRUE(export_mesh(file, mesh, atlas, options).is_ok());
      expect_valid_gltf(file);
      const Json o = glb_json_of(file);
      // The root "tailor" and one node per instance, named, with its extras, over one mesh each.
      ASSERT_EQ(o["nodes"].size(), 3u);
      EXPECT_EQ(o["nodes"][0]["children"], Json({1, 2}));
      EXPECT_EQ(o["nodes"][1]["name"], "left");
      EXPECT_EQ(o["nodes"][2]["name"], "right");
      EXPECT_EQ(o["nodes"][1]["extras"]["id"], 1);
      EXPECT_EQ(o["nodes"][2]["extras"]["id"], 2);
      for (const Json& m : o["meshes"]) {
        EXPECT_EQ(m["name"], "cow");
        EXPECT_EQ(m["extras"]["scan"], 7);
        ASSERT_EQ(m["primitives"].size(), 2u);
      }
      EXPECT_EQ(o["scenes"][0]["name"], "barn");
      EXPECT_EQ(o["scenes"][0]["extras"]["season"], "spring");
      EXPECT_EQ(o["asset"]["extras"]["author"], "test");
      EXPECT_EQ(o["asset"]["copyright"], "CC0");
      // Materials: the input's properties and tailor's texture coordinates' material.
      ASSERT_EQ(o["materials"].size(), 2u);
      const Json& hide = o["materials"][o["meshes"][0]["primitives"][0]["material"].get<size_t>()];
      const Json& horn = o["materials"][o["meshes"][0]["primitives"][1]["material"].get<size_t>()];
      EXPECT_EQ(hide["name"], "hide");
      EXPECT_EQ(hide["doubleSided"], true);
      EXPECT_EQ(hide["extras"]["grade"], "A");
      EXPECT_NEAR(hide["emissiveFactor"][2].get<double>(), 0.3, 1e-6);
      EXPECT_NEAR(hide["pbrMetallicRoughness"]["metallicFactor"].get<double>(), 0.25, 1e-6);
      EXPECT_NEAR(hide["pbrMetallicRoughness"]["roughnessFactor"].get<double>(), 0.75, 1e-6);
      EXPECT_EQ(horn["name"], "horn");
      EXPECT_EQ(horn["alphaMode"], "MASK");
      EXPECT_NEAR(horn["pbrMetallicRoughness"]["baseColorFactor"][1].get<double>(), 0.5, 1e-6);
      // Read back: the same faces, in world space, the same parts and names.
      Mesh back;
      ASSERT_TRUE(load_mesh(file, back).is_ok());
      EXPECT_EQ(back.face_count(), mesh.face_count());
      const float tolerance = method == MeshCompression::kNone ? 0.f : extent(mesh) / 4000.f;
      expect_same_points(back, mesh, tolerance, "world positions");
      ASSERT_EQ(back.scene.parts.size(), 4u);
      EXPECT_EQ(back.scene.instances[1].node_name, "right");
      for (uint32_t part = 0; part < 4; ++part)
        EXPECT_EQ(std::count(back.face_parts.begin(), back.face_parts.end(), part),
                  std::count(mesh.face_parts.begin(), mesh.face_parts.end(), part));
    }
    // A bad UV is named by its corner in the caller's numbering, though export sorts the faces
    // by part (here the parts' order reversed, so the sort moves every face).
    Mesh reversed = mesh;
    for (uint32_t& part : reversed.face_parts) part = 3 - part;
    const size_t corner = 3 * (mesh.face_count() / 8) + 1;
    atlas.corner_uv[2 * corner] = std::nanf("");
    const Status bad = export_mesh(path("bad.glb"), reversed, atlas, ExportOptions{});
    EXPECT_EQ(bad.where(), "corner " + std::to_string(corner)) << bad.message();
    EXPECT_FALSE(fs::exists(path("bad.glb")));
  }
}

// Per-vertex colours of a PLY (uchar red green blue alpha) and an OBJ (v x y z r g b) are written
// back to .ply and .obj outputs and read back the same.
TEST(GltfKept, PlyAndObjColoursRoundTrip) {
  const std::string dir = test::empty_temp_dir("colour_round_trip");
  std::ofstream(dir + "/t.ply") << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                   "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                                   "property uchar alpha\nelement face 4\nproperty list uchar int vertex_indices\n"
                                   "end_header\n0 0 0 255 0 0 255\n1 0 0 0 255 0 128\n0 1 0 0 0 255 0\n"
                                   "0 0 1 51 102 153 7\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  std::ofstream(dir + "/t.obj") << "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 0 0 1 0.2 0.4 0.6\n"
                                   "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  for (const char* input : {"t.ply", "t.obj"}) {
    Mesh mesh;
    ASSERT_TRUE(load_mesh(dir + "/" + input, mesh).is_ok()) << input;
    const CornerAttribute* colour = attribute(mesh, "COLOR_0");
    ASSERT_NE(colour, nullptr) << input;
    const Atlas atlas = patterned_atlas(mesh.face_count(), 5, 100.f);
    for (const char* output : {"out.ply", "out.obj", "out.glb"}) {
      SCOPED_TRACE(std::string(input) + " -> " + output);
      ASSERT_TRUE(export_mesh(dir + "/" + output, mesh, atlas, ExportOptions{}).is_ok());
      Mesh back;
      ASSERT_TRUE(load_mesh(dir + "/" + output, back).is_ok());
      const CornerAttribute* back_colour = attribute(back, "COLOR_0");
      ASSERT_NE(back_colour, nullptr);
      ASSERT_EQ(back.face_count(), mesh.face_count());
      // Faces keep their order; compare the colour of each corner (OBJ keeps no alpha).
      const bool alpha = std::string(output) != "out.obj";
      for (size_t c = 0; c < mesh.indices.size(); ++c)
        for (size_t k = 0; k < (alpha ? 4u : 3u); ++k)
          EXPECT_NEAR(back_colour->values[4 * c + k], colour->values[4 * c + k], 1e-6) << "corner " << c;
    }
  }
  fs::remove_all(dir);
}

// === World units and up axis (tailor map) ===========================================================

// Median over the faces' edges of texture pixels per scene unit (UVs in repeats of `texture_px`).
double median_texels_per_unit(const Mesh& mesh, double texture_px) {
  std::vector<double> ratios;
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const size_t d = c % 3 == 2 ? c - 2 : c + 1;
    const float* a = &mesh.positions[3 * mesh.indices[c]];
    const float* b = &mesh.positions[3 * mesh.indices[d]];
    const double length = std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    const double uv = std::hypot(mesh.corner_uvs[2 * c] - mesh.corner_uvs[2 * d],
                                 mesh.corner_uvs[2 * c + 1] - mesh.corner_uvs[2 * d + 1]);
    if (length > 0) ratios.push_back(uv * texture_px / length);
  }
  std::nth_element(ratios.begin(), ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
  return ratios[ratios.size() / 2];
}

TEST(GltfWorld, TexelDensityIsPerSceneUnitForEveryMesh) {
  // spot.obj and a copy twice its size: with --tile-size both get the same pixels per unit (the
  // default --scale would give each the same pixels per own size, so the copy half the density).
  const Mesh spot = test::load_test_mesh("spot.obj");
  const std::string dir = test::empty_temp_dir("gltf_world");
  std::ofstream big(dir + "/big.obj");
  for (size_t v = 0; v < spot.vertex_count(); ++v)
    big << "v " << 2 * spot.positions[3 * v] << ' ' << 2 * spot.positions[3 * v + 1] << ' '
        << 2 * spot.positions[3 * v + 2] << '\n';
  for (size_t f = 0; f < spot.face_count(); ++f)
    big << "f " << spot.indices[3 * f] + 1 << ' ' << spot.indices[3 * f + 1] + 1 << ' ' << spot.indices[3 * f + 2] + 1
        << '\n';
  big.close();
  std::string out;
  double density[2] = {0, 0};
  int i = 0;
  for (const std::string& input : {test::mesh_path("spot.obj"), dir + "/big.obj"}) {
    const std::string glb = dir + "/" + std::to_string(i) + ".glb";
    ASSERT_EQ(run_command(std::string(TAILOR_BINARY) + " map '" + input + "' -o '" + glb +
                              "' --tile-size 0.25 --no-crack-closing --stats '" + glb + ".json' -q",
                          out),
              0)
        << out;
    Mesh mesh;
    ASSERT_TRUE(load_mesh(glb, mesh).is_ok());
    density[i] = median_texels_per_unit(mesh, 512);
    const Json stats = Json::parse(test::read_all(glb + ".json"));
    EXPECT_EQ(stats["options"]["unit"], "scene");
    EXPECT_NEAR(stats["options"]["texels_per_unit"].get<double>(), 512 / 0.25, 1e-6);
    ++i;
  }
  EXPECT_NEAR(density[0], 2048, 2048 * 0.05);  // 512 px every 0.25 units, up to the mapping's stretch
  EXPECT_NEAR(density[1], density[0], density[0] * 0.02);
  // --up z: the .glb's node turns the scene Y-up; read back, (x, y, z) became (x, z, -y).
  ASSERT_EQ(run_command(std::string(TAILOR_BINARY) + " map '" + test::mesh_path("spot.obj") + "' -o '" + dir +
                            "/up.glb' --up z --compress quantize -q",
                        out),
            0)
      << out;
  Mesh up;
  ASSERT_TRUE(load_mesh(dir + "/up.glb", up).is_ok());
  Mesh turned = spot;
  for (size_t v = 0; v < turned.vertex_count(); ++v) {
    const float y = turned.positions[3 * v + 1], z = turned.positions[3 * v + 2];
    turned.positions[3 * v + 1] = z;
    turned.positions[3 * v + 2] = -y;
  }
  expect_same_points(up, turned, extent(spot) / 16384.f, "--up z");
  if (!gltf_transform().empty()) expect_valid_gltf(dir + "/up.glb");
  fs::remove_all(dir);
}

// === Progress (issue 18 point 5) ================================================================

// What a progress callback saw: every value in [0, 1], never going back, the last one 1.
struct Seen {
  std::vector<float> values;
  bool keep_going = true;
  ProgressCallback callback() {
    return [this](float f) {
      values.push_back(f);
      return keep_going;
    };
  }
  void expect_complete(const std::string& what) const {
    ASSERT_FALSE(values.empty()) << what;
    for (size_t i = 0; i < values.size(); ++i) {
      EXPECT_TRUE(values[i] >= 0.f && values[i] <= 1.f) << what << " " << values[i];
      if (i > 0) {
        EXPECT_GE(values[i], values[i - 1]) << what;
      }
    }
    EXPECT_EQ(values.back(), 1.f) << what;
  }
};

TEST(Progress, LoadingReportsAndCancels) {
  // The same mesh as PLY (generic ascii loop), OBJ, .glb (plain and Draco).
  const std::string dir = test::empty_temp_dir("progress_load");
  const Mesh source = test::load_test_mesh("horse.ply");
  const Atlas atlas = patterned_atlas(source.face_count(), 13, 16.f);
  ASSERT_TRUE(export_mesh(dir + "/h.obj", source, atlas, ExportOptions{}).is_ok());
  ASSERT_TRUE(export_mesh(dir + "/h.glb", source, atlas, ExportOptions{}).is_ok());
  ExportOptions draco;
  draco.compression = MeshCompression::kDraco;
  ASSERT_TRUE(export_mesh(dir + "/h_draco.glb", source, atlas, draco).is_ok());
  for (const std::string& file : {test::mesh_path("horse.ply"), dir + "/h.obj", dir + "/h.glb", dir + "/h_draco.glb"}) {
    Seen seen;
    Mesh mesh;
    ASSERT_TRUE(load_mesh(file, mesh, nullptr, seen.callback()).is_ok()) << file;
    EXPECT_EQ(mesh.face_count(), source.face_count()) << file;
    seen.expect_complete(file);
    Seen stop;
    stop.keep_going = false;
    const Status s = load_mesh(file, mesh, nullptr, stop.callback());
    EXPECT_EQ(s.code(), ErrorCode::kCancelled) << file;
    EXPECT_TRUE(mesh.empty()) << file;
  }
  fs::remove_all(dir);
}

TEST(Progress, ExportReportsAndCancelsWritingNothing) {
  const std::string dir = test::empty_temp_dir("progress_export");
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const Atlas atlas = patterned_atlas(mesh.face_count(), 9, 40.f);
  for (MeshCompression method :
       {MeshCompression::kNone, MeshCompression::kQuantize, MeshCompression::kMeshopt, MeshCompression::kDraco}) {
    SCOPED_TRACE(mesh_compression_name(method));
    Seen seen;
    ExportOptions options;
    options.compression = method;
    options.progress = seen.callback();
    ASSERT_TRUE(export_mesh(dir + "/p.glb", mesh, atlas, options).is_ok());
    seen.expect_complete("export");
    Seen stop;
    stop.keep_going = false;
    options.progress = stop.callback();
    EXPECT_EQ(export_mesh(dir + "/q.glb", mesh, atlas, options).code(), ErrorCode::kCancelled);
    EXPECT_FALSE(fs::exists(dir + "/q.glb"));
  }
  for (const char* name : {"p.obj", "p.ply"}) {
    Seen seen;
    ExportOptions options;
    options.progress = seen.callback();
    ASSERT_TRUE(export_mesh(dir + "/" + name, mesh, atlas, options).is_ok());
    seen.expect_complete(name);
    Seen stop;
    stop.keep_going = false;
    options.progress = stop.callback();
    EXPECT_EQ(export_mesh(dir + "/q" + std::string(name + 1), mesh, atlas, options).code(), ErrorCode::kCancelled);
  }
  // p.glb, p.obj, p.ply; no temporaries, nothing of the cancelled exports.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 3);
  fs::remove_all(dir);
}

TEST(Progress, MappingReportsEachStage) {
  const Mesh mesh = test::load_test_mesh("spot.obj");
  const Topology topology = build_topology(mesh);
  MapTextureOptions options;
  std::vector<std::pair<std::string, float>> seen;
  options.stage_progress = [&seen](std::string_view stage, float done) {
    seen.emplace_back(std::string(stage), done);
    return true;
  };
  TextureMap map;
  ASSERT_TRUE(map_texture(mesh, topology, options, map).is_ok());
  // The stages in order, each ending at 1.
  std::vector<std::string> order;
  for (const auto& [stage, done] : seen)
    if (order.empty() || order.back() != stage) order.push_back(stage);
  EXPECT_EQ(order, (std::vector<std::string>{"orientation", "mapping", "closing", "relaxing", "metrics"}));
  for (const std::string& stage : order) {
    float last = -1.f;
    for (const auto& [s, done] : seen)
      if (s == stage) last = done;
    EXPECT_EQ(last, 1.f) << stage;
  }
  // Cancelling in any stage fails with kCancelled and leaves the atlas empty.
  for (const char* cancel_in : {"orientation", "mapping", "closing", "relaxing"}) {
    options.stage_progress = [cancel_in](std::string_view stage, float) { return stage != cancel_in; };
    EXPECT_EQ(map_texture(mesh, topology, options, map).code(), ErrorCode::kCancelled) << cancel_in;
    EXPECT_TRUE(map.atlas.corner_uv.empty()) << cancel_in;
  }
}

}  // namespace
}  // namespace tailor
