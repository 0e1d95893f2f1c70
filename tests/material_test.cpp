// tailor map --material (material.h): a PBR material folder made here from real photos, mapped on
// spot; the .glb's material, packing, tangents and validity are read back from the file.
#include "tailor/material.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "support/fixtures.h"
#include "tailor/gltf.h"
#include "tailor/image.h"
#include "tailor/io.h"
#include "tailor/render.h"

namespace tailor {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
const std::string kTextures = std::string(TAILOR_TEST_DATA) + "/textures/";

Image grey_of(const Image& rgb) {
  Image g{rgb.width, rgb.height, 1, {}};
  g.pixels.resize(size_t(rgb.width) * rgb.height);
  for (size_t i = 0; i < g.pixels.size(); ++i) {
    const uint8_t* p = &rgb.pixels[size_t(rgb.channels) * i];
    g.pixels[i] = rgb.channels >= 3 ? uint8_t((299 * p[0] + 587 * p[1] + 114 * p[2] + 500) / 1000) : p[0];
  }
  return g;
}

// A tangent-space normal map (GL convention) from a height map's gradient, wrapping at the borders.
Image normals_of(const Image& height, float strength) {
  Image n{height.width, height.height, 3, {}};
  n.pixels.resize(3 * size_t(height.width) * height.height);
  const int w = height.width, h = height.height;
  auto at = [&](int x, int y) { return height.pixels[size_t((y + h) % h) * w + size_t((x + w) % w)] / 255.f; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float dx = (at(x + 1, y) - at(x - 1, y)) * strength, dy = (at(x, y - 1) - at(x, y + 1)) * strength;
      const float l = std::sqrt(dx * dx + dy * dy + 1);
      const float v[3] = {-dx / l, -dy / l, 1 / l};
      for (int c = 0; c < 3; ++c)
        n.pixels[3 * (size_t(y) * w + x) + c] = uint8_t(std::lround((v[c] * 0.5f + 0.5f) * 255));
    }
  return n;
}

struct Glb {
  Json json;
  std::string bin;
};

Glb read_glb(const std::string& file) {
  const std::string bytes = test::read_all(file);
  Glb g;
  if (bytes.size() < 28) return g;
  uint32_t json_size = 0, bin_size = 0;
  std::memcpy(&json_size, bytes.data() + 12, 4);
  g.json = Json::parse(bytes.substr(20, json_size));
  std::memcpy(&bin_size, bytes.data() + 20 + json_size, 4);
  g.bin = bytes.substr(28 + json_size, bin_size);
  return g;
}

// The image a texture reference points at, decoded through a file.
Image16 texture_image(const Glb& g, const Json& ref, const std::string& scratch) {
  const Json& image = g.json["images"][ref["index"].get<size_t>()];
  const Json& view = g.json["bufferViews"][image["bufferView"].get<size_t>()];
  std::ofstream(scratch, std::ios::binary)
      << g.bin.substr(view["byteOffset"].get<size_t>(), view["byteLength"].get<size_t>());
  Image16 out;
  EXPECT_TRUE(load_image16(scratch, out).is_ok());
  return out;
}

std::vector<float> float_accessor(const Glb& g, size_t index, size_t components) {
  const Json& a = g.json["accessors"][index];
  const Json& view = g.json["bufferViews"][a["bufferView"].get<size_t>()];
  std::vector<float> out(a["count"].get<size_t>() * components);
  std::memcpy(out.data(), g.bin.data() + view["byteOffset"].get<size_t>(), out.size() * 4);
  return out;
}

// flags: "--allow-external" reads images named by URI beside the file.
void expect_valid_gltf(const std::string& file, const std::string& flags = "") {
  std::string out;
  if (test::run_command("command -v node", out) != 0) GTEST_SKIP() << "node not installed";
  const int rc = test::run_command(
      std::string("node ") + TAILOR_SOURCE_DIR + "/tests/tools/validate_gltf.mjs --strict " + flags + " '" + file + "'",
      out);
  EXPECT_EQ(rc, 0) << out;
}

class MaterialTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::empty_temp_dir("material");
    ASSERT_TRUE(load_image(kTextures + "vistex-bark11-128.png", color_).is_ok());
    grey_ = grey_of(color_);
    metal_ = grey_;
    for (uint8_t& v : metal_.pixels) v = v > 128 ? 255 : 0;  // metal where bright
    ASSERT_TRUE(write_png(dir_ + "/bark_Color.png", color_).is_ok());
    ASSERT_TRUE(write_png(dir_ + "/bark_normal-GL.png", normals_of(grey_, 4)).is_ok());
    ASSERT_TRUE(write_png(dir_ + "/bark_roughness.png", grey_).is_ok());
    ASSERT_TRUE(write_png(dir_ + "/bark metalness.png", metal_).is_ok());
    ASSERT_TRUE(write_png(dir_ + "/bark.height.png", grey_).is_ok());
    std::ofstream(dir_ + "/notes.txt") << "not a map\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  int map(const std::string& material, const std::string& out, const std::string& extra, std::string& text) {
    return test::run_command(std::string(TAILOR_BINARY) + " map " + TAILOR_SOURCE_DIR +
                                 "/examples/spot.obj --material '" + material + "' -o '" + out + "' " + extra,
                             text);
  }

  std::string dir_;
  Image color_, grey_, metal_;
};

TEST(MaterialRoles, SuffixesAreRecognised) {
  bool dx = false;
  EXPECT_EQ(material_role_from_name("Bricks_BaseColor.png"), MaterialRole::kColor);
  EXPECT_EQ(material_role_from_name("rock-albedo.jpg"), MaterialRole::kColor);
  EXPECT_EQ(material_role_from_name("rock_diff.png"), MaterialRole::kNone);
  EXPECT_EQ(material_role_from_name("wood_nrm.png"), MaterialRole::kNormal);
  EXPECT_EQ(material_role_from_name("wood_Normal_DX.png", &dx), MaterialRole::kNormal);
  EXPECT_TRUE(dx);
  EXPECT_EQ(material_role_from_name("wood_NormalGL.png", &dx), MaterialRole::kNormal);
  EXPECT_FALSE(dx);
  EXPECT_EQ(material_role_from_name("wood_rough.png"), MaterialRole::kRoughness);
  EXPECT_EQ(material_role_from_name("metal.png"), MaterialRole::kMetallic);
  EXPECT_EQ(material_role_from_name("floor_AO.png"), MaterialRole::kOcclusion);
  EXPECT_EQ(material_role_from_name("floor_disp.png"), MaterialRole::kHeight);
  EXPECT_EQ(material_role_from_name("tornado.png"), MaterialRole::kNone);  // "ao" only as a whole word
  EXPECT_EQ(material_role_from_name("windsor.png"), MaterialRole::kNone);
}

TEST_F(MaterialTest, GlbHasThePackedMaterialAndTangents) {
  const std::string out = dir_ + "/spot.glb";
  std::string text;
  ASSERT_EQ(map(dir_, out, "", text), 0) << text;
  EXPECT_NE(text.find("height map not embedded"), std::string::npos) << text;
  const Glb g = read_glb(out);
  const Json& m = g.json["materials"][0];
  const Json& pbr = m["pbrMetallicRoughness"];
  ASSERT_TRUE(pbr.contains("baseColorTexture") && pbr.contains("metallicRoughnessTexture") &&
              m.contains("normalTexture"))
      << m.dump();
  EXPECT_FALSE(m.contains("occlusionTexture"));  // no AO map given

  // metallicRoughness: G = roughness, B = metallic, same size as the colour map.
  const Image16 orm = texture_image(g, pbr["metallicRoughnessTexture"], dir_ + "/orm.png");
  ASSERT_EQ(orm.width, color_.width);
  ASSERT_EQ(orm.channels, 3);
  size_t metal_pixels = 0;
  for (size_t i = 0; i < grey_.pixels.size(); i += 37) {
    EXPECT_EQ(orm.pixels[3 * i + 1], grey_.pixels[i]) << i;
    EXPECT_EQ(orm.pixels[3 * i + 2], metal_.pixels[i]) << i;
    metal_pixels += metal_.pixels[i] != 0;
  }
  EXPECT_GT(metal_pixels, 0u);
  // The base colour is the file itself.
  const Image16 base = texture_image(g, pbr["baseColorTexture"], dir_ + "/base.png");
  EXPECT_EQ(to_image8(base).pixels, color_.pixels);

  // TANGENT: unit xyz, w = +-1, orthogonal to the normal.
  const Json& attributes = g.json["meshes"][0]["primitives"][0]["attributes"];
  ASSERT_TRUE(attributes.contains("TANGENT"));
  const std::vector<float> t = float_accessor(g, attributes["TANGENT"].get<size_t>(), 4);
  const std::vector<float> n = float_accessor(g, attributes["NORMAL"].get<size_t>(), 3);
  ASSERT_EQ(t.size() / 4, n.size() / 3);
  for (size_t v = 0; v < n.size() / 3; ++v) {
    const float* tv = &t[4 * v];
    const float* nv = &n[3 * v];
    ASSERT_NEAR(std::sqrt(tv[0] * tv[0] + tv[1] * tv[1] + tv[2] * tv[2]), 1.0, 1e-3) << v;
    ASSERT_EQ(std::abs(tv[3]), 1.0f) << v;
    ASSERT_NEAR(tv[0] * nv[0] + tv[1] * nv[1] + tv[2] * nv[2], 0.0, 1e-3) << v;
  }
  // The frame follows the UVs: T along +s and B = w (N x T) along up the image (glTF: -v) on
  // nearly every face (a sign error would flip them all).
  const Json& primitive = g.json["meshes"][0]["primitives"][0];
  const std::vector<float> p = float_accessor(g, attributes["POSITION"].get<size_t>(), 3);
  const std::vector<float> uv = float_accessor(g, attributes["TEXCOORD_0"].get<size_t>(), 2);
  const Json& ia = g.json["accessors"][primitive["indices"].get<size_t>()];
  std::vector<uint32_t> idx(ia["count"].get<size_t>());
  std::memcpy(idx.data(),
              g.bin.data() + g.json["bufferViews"][ia["bufferView"].get<size_t>()]["byteOffset"].get<size_t>(),
              idx.size() * 4);
  size_t agree_t = 0, agree_b = 0, faces = 0;
  for (size_t f = 0; f < idx.size() / 3; ++f) {
    const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) e1[k] = p[3 * b + k] - p[3 * a + k], e2[k] = p[3 * c + k] - p[3 * a + k];
    const double s1 = uv[2 * b] - uv[2 * a], s2 = uv[2 * c] - uv[2 * a];
    const double t1 = -(uv[2 * b + 1] - uv[2 * a + 1]), t2 = -(uv[2 * c + 1] - uv[2 * a + 1]);  // up the image
    const double r = s1 * t2 - s2 * t1;
    if (std::abs(r) < 1e-12) continue;
    double dps[3], dpt[3];
    for (int k = 0; k < 3; ++k) dps[k] = (e1[k] * t2 - e2[k] * t1) / r, dpt[k] = (e2[k] * s1 - e1[k] * s2) / r;
    const float* tv = &t[4 * a];
    const float* nv = &n[3 * a];
    const double bv[3] = {tv[3] * (nv[1] * tv[2] - nv[2] * tv[1]), tv[3] * (nv[2] * tv[0] - nv[0] * tv[2]),
                          tv[3] * (nv[0] * tv[1] - nv[1] * tv[0])};
    agree_t += dps[0] * tv[0] + dps[1] * tv[1] + dps[2] * tv[2] > 0;
    agree_b += dpt[0] * bv[0] + dpt[1] * bv[1] + dpt[2] * bv[2] > 0;
    ++faces;
  }
  EXPECT_GT(agree_t, faces * 95 / 100) << faces;
  EXPECT_GT(agree_b, faces * 95 / 100) << faces;
  expect_valid_gltf(out);
}

// tailor render and tailor map --preview shade with the .glb's normal map (render.h PreviewMaterial):
// the file's maps and tangents are read back, the normal map changes the picture, a flat one does not.
TEST_F(MaterialTest, RenderAndPreviewShadeWithTheNormalMap) {
  const std::string out = dir_ + "/spot.glb", preview = dir_ + "/map_preview.png";
  std::string text;
  ASSERT_EQ(map(dir_, out, "--preview '" + preview + "' --preview-all", text), 0) << text;
  Mesh mesh;
  Image base;
  GltfMaterialMaps maps;
  ASSERT_TRUE(read_glb_with_material(out, mesh, &base, &maps).is_ok());
  EXPECT_EQ(base.pixels, color_.pixels);
  ASSERT_EQ(maps.normal.width, color_.width);
  EXPECT_EQ(maps.normal.pixels, normals_of(grey_, 4).pixels);  // 8-bit in, 8-bit back
  EXPECT_FALSE(maps.metallic_roughness.empty());
  EXPECT_TRUE(maps.occlusion.empty());
  ASSERT_EQ(maps.corner_tangents.size(), 4 * mesh.indices.size());
  for (const CornerAttribute& a : mesh.corner_attributes) EXPECT_NE(a.name, "TANGENT");
  // Without asking for the material, nothing of it is read.
  Mesh plain;
  ASSERT_TRUE(read_glb_file(out, plain, nullptr).is_ok());
  EXPECT_EQ(plain.indices, mesh.indices);

  // The file's tangents are the UVs' frames (as corner_tangents computes them): the same picture.
  RenderOptions o;
  o.width = 320;
  o.height = 240;
  PreviewMaterial from_file, computed;
  from_file.normal = computed.normal = &maps.normal;
  from_file.corner_tangents = maps.corner_tangents;
  Image a, b, none;
  ASSERT_TRUE(render_preview(mesh, mesh.corner_uvs, {}, &base, from_file, o, a).is_ok());
  ASSERT_TRUE(render_preview(mesh, mesh.corner_uvs, {}, &base, computed, o, b).is_ok());
  ASSERT_TRUE(render_preview(mesh, mesh.corner_uvs, {}, &base, o, none).is_ok());
  double diff_ab = 0, diff_none = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    diff_ab += std::abs(int{a.pixels[i]} - int{b.pixels[i]});
    diff_none += std::abs(int{a.pixels[i]} - int{none.pixels[i]});
  }
  EXPECT_LT(diff_ab / double(a.pixels.size()), 0.1);
  EXPECT_GT(diff_none / double(a.pixels.size()), 0.5) << diff_ab / double(a.pixels.size());  // background included

  // The command: the material's picture differs from --no-material's; so does map's preview from a
  // flat normal map's, whose picture equals the colour map's alone within 2 levels.
  const std::string cli = std::string(TAILOR_BINARY);
  ASSERT_EQ(test::run_command(cli + " render '" + out + "' -o '" + dir_ + "/with.png' --size 320x240", text), 0)
      << text;
  ASSERT_EQ(
      test::run_command(cli + " render '" + out + "' --no-material -o '" + dir_ + "/without.png' --size 320x240", text),
      0)
      << text;
  Image with, without;
  ASSERT_TRUE(load_image(dir_ + "/with.png", with).is_ok());
  ASSERT_TRUE(load_image(dir_ + "/without.png", without).is_ok());
  EXPECT_EQ(with.pixels, a.pixels);
  EXPECT_EQ(without.pixels, none.pixels);

  const std::string flat_dir = dir_ + "/flat";
  fs::create_directory(flat_dir);
  ASSERT_TRUE(write_png(flat_dir + "/bark_color.png", color_).is_ok());
  Image flat{color_.width, color_.height, 3, {}};
  for (int i = 0; i < color_.width * color_.height; ++i) flat.pixels.insert(flat.pixels.end(), {128, 128, 255});
  ASSERT_TRUE(write_png(flat_dir + "/bark_normal.png", flat).is_ok());
  const std::string colour_only = dir_ + "/colour_only";
  fs::create_directory(colour_only);
  ASSERT_TRUE(write_png(colour_only + "/bark_color.png", color_).is_ok());
  ASSERT_EQ(map(flat_dir, dir_ + "/flat.glb", "--preview '" + dir_ + "/flat_preview.png'", text), 0) << text;
  ASSERT_EQ(map(colour_only, dir_ + "/colour.glb", "--preview '" + dir_ + "/colour_preview.png'", text), 0) << text;
  Image map_bumps, map_flat, map_colour;
  ASSERT_TRUE(load_image(preview, map_bumps).is_ok());
  ASSERT_TRUE(load_image(dir_ + "/flat_preview.png", map_flat).is_ok());
  ASSERT_TRUE(load_image(dir_ + "/colour_preview.png", map_colour).is_ok());
  int worst = 0;
  double bump_diff = 0;
  for (size_t i = 0; i < map_flat.pixels.size(); ++i) {
    worst = std::max(worst, std::abs(int{map_flat.pixels[i]} - int{map_colour.pixels[i]}));
    bump_diff += std::abs(int{map_bumps.pixels[i]} - int{map_colour.pixels[i]});
  }
  EXPECT_LE(worst, 2);
  EXPECT_GT(bump_diff / double(map_flat.pixels.size()), 0.5) << worst;
}

TEST_F(MaterialTest, CompressedFilesKeepTangentsAndValidate) {
  for (const char* mode : {"quantize", "meshopt", "draco"}) {
    SCOPED_TRACE(mode);
    const std::string out = dir_ + "/spot_" + mode + ".glb";
    std::string text;
    ASSERT_EQ(map(dir_, out, std::string("--quiet --compress ") + mode, text), 0) << text;
    const Glb g = read_glb(out);
    const Json& primitive = g.json["meshes"][0]["primitives"][0];
    const bool draco = primitive.contains("extensions");
    EXPECT_TRUE(primitive["attributes"].contains("TANGENT"));
    if (draco) {
      EXPECT_TRUE(primitive["extensions"]["KHR_draco_mesh_compression"]["attributes"].contains("TANGENT"));
    }
    // The reader decodes them too (tailor render shades with them): unit xyz, w = +-1, per corner.
    Mesh mesh;
    GltfMaterialMaps maps;
    ASSERT_TRUE(read_glb_with_material(out, mesh, nullptr, &maps).is_ok());
    ASSERT_EQ(maps.corner_tangents.size(), 4 * mesh.indices.size());
    EXPECT_FALSE(maps.normal.empty());
    for (size_t c = 0; c < maps.corner_tangents.size(); c += 4) {
      const float* t = &maps.corner_tangents[c];
      ASSERT_NEAR(std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]), 1.0, 1e-2) << c / 4;
      ASSERT_EQ(std::abs(t[3]), 1.0f) << c / 4;
    }
    expect_valid_gltf(out);
  }
}

TEST_F(MaterialTest, JsonAndDirectXConvention) {
  // {"color": ..., "normal": ..., "normal_convention": "dx"}: the embedded green is flipped.
  std::ofstream(dir_ + "/m.json") << R"({"color": "bark_Color.png", "normal": "bark_normal-GL.png",
                                          "occlusion": "bark_roughness.png", "normal_convention": "dx"})";
  MaterialMaps gl, dx;
  ASSERT_TRUE(load_material(dir_, gl).is_ok());
  ASSERT_TRUE(load_material(dir_ + "/m.json", dx).is_ok());
  EXPECT_EQ(gl.color, dir_ + "/bark_Color.png");
  EXPECT_EQ(dx.width, 128);
  std::ofstream(dir_ + "/gl.png", std::ios::binary) << gl.textures.normal_png;
  std::ofstream(dir_ + "/dx.png", std::ios::binary) << dx.textures.normal_png;
  Image a, b;
  ASSERT_TRUE(load_image(dir_ + "/gl.png", a).is_ok());
  ASSERT_TRUE(load_image(dir_ + "/dx.png", b).is_ok());
  for (size_t i = 0; i < a.pixels.size(); i += 3) {
    ASSERT_EQ(a.pixels[i], b.pixels[i]);
    ASSERT_EQ(a.pixels[i + 1], 255 - b.pixels[i + 1]);
  }
  // Occlusion alone: its own packed image, read from R, no metallicRoughness texture.
  EXPECT_TRUE(dx.textures.orm_occlusion);
  EXPECT_FALSE(dx.textures.orm_roughness_metallic);
}

TEST_F(MaterialTest, SixteenBitMapsStaySixteenBit) {
  // A 16-bit roughness map (the grey widened with distinct low bits): the packed image is 16-bit
  // and its G channel is the map itself; the 8-bit metallic map is widened (255 -> 65535).
  Image16 rough = to_image16(grey_);
  rough.bits = 16;
  for (size_t i = 0; i < rough.pixels.size(); ++i) rough.pixels[i] = uint16_t(rough.pixels[i] * 257 + i % 200);
  ASSERT_TRUE(write_png16(dir_ + "/bark_roughness.png", rough).is_ok());
  MaterialMaps m;
  ASSERT_TRUE(load_material(dir_, m).is_ok());
  std::ofstream(dir_ + "/orm16.png", std::ios::binary) << m.textures.orm_png;
  Image16 orm;
  ASSERT_TRUE(load_image16(dir_ + "/orm16.png", orm).is_ok());
  ASSERT_EQ(orm.bits, 16);
  for (size_t i = 0; i < rough.pixels.size(); i += 17) {
    ASSERT_EQ(orm.pixels[3 * i + 1], rough.pixels[i]) << i;
    ASSERT_EQ(orm.pixels[3 * i + 2], metal_.pixels[i] * 257) << i;
  }
}

// Files that share one material (the tiles of python3 -m tailor.tiles) name its images by URI
// instead of each embedding a copy: the same material, tangents and geometry, no image in the BIN
// chunk, the colour map's file not read; a URI for a map the export lacks, or a non-.glb, fails.
TEST_F(MaterialTest, ImagesNamedByUriAreNotEmbedded) {
  MaterialMaps maps;
  ASSERT_TRUE(load_material(dir_, maps).is_ok());
  Mesh mesh;
  ASSERT_TRUE(load_mesh(std::string(TAILOR_SOURCE_DIR) + "/examples/spot.obj", mesh).is_ok());
  Atlas atlas;  // planar UVs (x, y), one patch
  for (uint32_t c : mesh.indices) {
    atlas.corner_uv.push_back(mesh.positions[3 * c] * 300.f);
    atlas.corner_uv.push_back(mesh.positions[3 * c + 1] * 300.f);
  }
  atlas.patch.assign(mesh.face_count(), 0);
  atlas.patch_count = 1;
  ExportOptions embedded;
  embedded.texture_path = maps.color;
  embedded.texture_width = maps.width;
  embedded.texture_height = maps.height;
  embedded.material = maps.textures;
  ExportOptions named = embedded;
  named.texture_path = dir_ + "/not_read.png";  // absent: a colour map named by URI is not read
  named.image_uris = {"../color.png", "../normal.png", "../orm.png"};
  fs::copy_file(maps.color, dir_ + "/color.png");
  std::ofstream(dir_ + "/normal.png", std::ios::binary) << maps.textures.normal_png;
  std::ofstream(dir_ + "/orm.png", std::ios::binary) << maps.textures.orm_png;
  fs::create_directory(dir_ + "/tiles");
  for (const MeshCompression compression : {MeshCompression::kNone, MeshCompression::kMeshopt}) {
    SCOPED_TRACE(static_cast<int>(compression));
    embedded.compression = named.compression = compression;
    const std::string a = dir_ + "/embedded.glb", b = dir_ + "/tiles/named.glb";
    ASSERT_TRUE(export_mesh(a, mesh, atlas, embedded).is_ok());
    ASSERT_TRUE(export_mesh(b, mesh, atlas, named).is_ok());
    const Glb ga = read_glb(a), gb = read_glb(b);
    ASSERT_EQ(gb.json["images"].size(), 3u);
    for (const Json& image : gb.json["images"]) EXPECT_FALSE(image.contains("bufferView")) << image.dump();
    const Json& m = gb.json["materials"][0];
    auto uri = [&](const Json& ref) {
      return gb.json["images"][gb.json["textures"][ref["index"].get<size_t>()]["source"].get<size_t>()]["uri"];
    };
    EXPECT_EQ(uri(m["pbrMetallicRoughness"]["baseColorTexture"]), "../color.png");
    EXPECT_EQ(uri(m["normalTexture"]), "../normal.png");
    EXPECT_EQ(uri(m["pbrMetallicRoughness"]["metallicRoughnessTexture"]), "../orm.png");
    EXPECT_EQ(m, ga.json["materials"][0]);
    EXPECT_EQ(gb.json["meshes"], ga.json["meshes"]);
    auto padded = [](size_t bytes) { return (bytes + 3) / 4 * 4; };
    EXPECT_EQ(ga.bin.size() - gb.bin.size(), padded(fs::file_size(maps.color)) +
                                                 padded(maps.textures.normal_png.size()) +
                                                 padded(maps.textures.orm_png.size()));
    EXPECT_EQ(ga.bin.compare(0, gb.bin.size(), gb.bin), 0);  // the geometry's bytes, the images after them
    expect_valid_gltf(b, "--allow-external");
    // Maps named by URI need no bytes: the same file without them (TANGENT still from the normal map).
    ExportOptions unread = named;
    unread.material.normal_png.clear();
    unread.material.orm_png.clear();
    const std::string c = dir_ + "/tiles/unread.glb";
    ASSERT_TRUE(export_mesh(c, mesh, atlas, unread).is_ok());
    EXPECT_EQ(test::read_all(c), test::read_all(b));
  }
  // A URI for a colour map without a texture, for an ORM map without a role, or for a format
  // without images: an error, no file.
  for (const auto& [path, uris, texture] :
       {std::tuple{dir_ + "/x.glb", ImageUris{"../color.png", "", ""}, std::string()},
        std::tuple{dir_ + "/x.glb", ImageUris{"", "", "../orm.png"}, maps.color},
        std::tuple{dir_ + "/x.obj", ImageUris{"../color.png", "", ""}, maps.color}}) {
    ExportOptions bad = embedded;
    bad.compression = MeshCompression::kNone;
    bad.material = MaterialTextures{};
    bad.texture_path = texture;
    bad.image_uris = uris;
    const Status s = export_mesh(path, mesh, atlas, bad);
    EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument) << s.message();
    EXPECT_FALSE(fs::exists(path));
  }
}

TEST_F(MaterialTest, BadMaterialsFailWithOneLineAndNoOutput) {
  const std::string out = dir_ + "/bad.glb";
  auto expect_error = [&](const std::string& material, const std::string& what, int code = 2) {
    std::string err, text;
    const int rc = test::run_command(std::string(TAILOR_BINARY) + " map " + TAILOR_SOURCE_DIR +
                                         "/examples/spot.obj --material '" + material + "' -o '" + out + "'",
                                     text, &err);
    EXPECT_EQ(rc, code) << err;  // 2: the material as given is wrong; 1: a file is unreadable
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_NE(err.find(what), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out));
  };
  // Maps of different sizes.
  Image big;
  ASSERT_TRUE(load_image(kTextures + "brick-gray-512.png", big).is_ok());
  ASSERT_TRUE(write_png(dir_ + "/bark_ao.png", big).is_ok());
  expect_error(dir_, "share one size");
  fs::remove(dir_ + "/bark_ao.png");
  // Two files for one role.
  ASSERT_TRUE(write_png(dir_ + "/bark_albedo.png", color_).is_ok());
  expect_error(dir_, "two files claim the color map");
  // A folder with no recognised map.
  const std::string empty = dir_ + "/plain";
  fs::create_directory(empty);
  ASSERT_TRUE(write_png(empty + "/photo.png", color_).is_ok());
  expect_error(empty, "no map recognised");
  // An unreadable map.
  std::ofstream(empty + "/x_normal.png") << "not a png";
  expect_error(empty, "x_normal.png", 1);
  // A material JSON nested too deep to copy or print safely (its "symmetry" quoted in an error).
  const std::string deep = dir_ + "/deep.json";
  std::ofstream(deep) << "{\"color\": \"a.png\", \"symmetry\": " << std::string(100000, '[') << std::string(100000, ']')
                      << "}";
  expect_error(deep, "JSON nested more than 256 levels deep");
}

}  // namespace
}  // namespace tailor
