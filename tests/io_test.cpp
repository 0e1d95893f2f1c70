// Tests for the mesh readers (PLY, OBJ, OFF, STL) and finalize_mesh: exact counts on real meshes
// (numbers from /work/shared/data/meshes/MANIFEST.md), hand-built adversarial files, error
// messages that name the right line / element, and every prefix of small files failing cleanly.
#include "tailor/io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "support/fixtures.h"
#include "util/atomic_file.h"
#include "util/bounded_json.h"

namespace tailor {
namespace {

using test::load_test_mesh;
using test::mesh_path;

Status parse(const std::string& text, MeshFormat format, Mesh& mesh, LoadReport* report = nullptr) {
  return read_mesh(std::span<const char>(text.data(), text.size()), format, "test", mesh, report);
}

// Every index in range, every coordinate finite, side arrays in step: what finalize promises.
void expect_valid(const Mesh& m) {
  ASSERT_FALSE(m.empty());
  for (uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count());
  for (float x : m.positions) ASSERT_TRUE(std::isfinite(x));
  if (!m.corner_uvs.empty()) {
    ASSERT_EQ(m.corner_uvs.size(), 6 * m.face_count());
  }
  if (!m.seam_faces.empty()) {
    ASSERT_EQ(m.seam_faces.size(), m.face_count());
  }
}

size_t referenced_vertices(const Mesh& m) {
  std::vector<uint8_t> used(m.vertex_count(), 0);
  for (uint32_t i : m.indices) used[i] = 1;
  return static_cast<size_t>(std::count(used.begin(), used.end(), 1));
}

// ================================================================================================
// Writers used to build test inputs in memory
// ================================================================================================

template <class T>
void put(std::string& out, T v, bool big_endian) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

std::string binary_ply(const Mesh& m, bool big_endian) {
  std::string s = "ply\nformat ";
  s += big_endian ? "binary_big_endian" : "binary_little_endian";
  s += " 1.0\ncomment written by io_test\nelement vertex " + std::to_string(m.vertex_count()) +
       "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(m.face_count()) +
       "\nproperty list uchar int vertex_indices\nend_header\n";
  for (float x : m.positions) put(s, x, big_endian);
  for (size_t f = 0; f < m.face_count(); ++f) {
    put(s, uint8_t{3}, big_endian);
    for (int k = 0; k < 3; ++k) put(s, static_cast<int32_t>(m.indices[3 * f + k]), big_endian);
  }
  return s;
}

std::string ascii_ply(const Mesh& m) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(m.vertex_count()) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(m.face_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  char buf[128];
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", m.positions[3 * v], m.positions[3 * v + 1],
                  m.positions[3 * v + 2]);
    s += buf;
  }
  for (size_t f = 0; f < m.face_count(); ++f) {
    std::snprintf(buf, sizeof buf, "3 %u %u %u\n", m.indices[3 * f], m.indices[3 * f + 1], m.indices[3 * f + 2]);
    s += buf;
  }
  return s;
}

// OBJ with one vt per corner when the mesh has corner uvs.
std::string obj_text(const Mesh& m) {
  std::string s = "# written by io_test\nmtllib missing.mtl\no part\n";
  char buf[128];
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", m.positions[3 * v], m.positions[3 * v + 1],
                  m.positions[3 * v + 2]);
    s += buf;
  }
  for (size_t c = 0; c < m.corner_uvs.size() / 2; ++c) {
    std::snprintf(buf, sizeof buf, "vt %.9g %.9g\n", m.corner_uvs[2 * c], m.corner_uvs[2 * c + 1]);
    s += buf;
  }
  for (size_t f = 0; f < m.face_count(); ++f) {
    if (m.corner_uvs.empty()) {
      std::snprintf(buf, sizeof buf, "f %u %u %u\n", m.indices[3 * f] + 1, m.indices[3 * f + 1] + 1,
                    m.indices[3 * f + 2] + 1);
    } else {
      std::snprintf(buf, sizeof buf, "f %u/%zu %u/%zu %u/%zu\n", m.indices[3 * f] + 1, 3 * f + 1,
                    m.indices[3 * f + 1] + 1, 3 * f + 2, m.indices[3 * f + 2] + 1, 3 * f + 3);
    }
    s += buf;
  }
  return s;
}

// The first n faces of m with their vertices renumbered in order of first use.
Mesh first_faces(const Mesh& m, size_t n) {
  Mesh out;
  std::vector<uint32_t> map(m.vertex_count(), kInvalid);
  for (size_t c = 0; c < 3 * n; ++c) {
    const uint32_t v = m.indices[c];
    if (map[v] == kInvalid) {
      map[v] = static_cast<uint32_t>(out.vertex_count());
      out.positions.insert(out.positions.end(), {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
    }
    out.indices.push_back(map[v]);
  }
  if (!m.corner_uvs.empty())
    out.corner_uvs.assign(m.corner_uvs.begin(), m.corner_uvs.begin() + static_cast<std::ptrdiff_t>(6 * n));
  return out;
}

// ================================================================================================
// Real meshes: exact counts from MANIFEST.md
// ================================================================================================

struct Expected {
  const char* file;
  size_t faces, vertices, referenced;
  const char* format;
};

TEST(RealMeshes, LoadWithManifestCounts) {
  const Expected cases[] = {
      {"spot.obj", 5856, 2930, 2930, "OBJ"},
      {"fandisk.off", 14454, 7229, 7229, "OFF"},
      {"fertility.off", 9000, 4494, 4494, "OFF"},
      {"blobby-3cc.off", 3417, 1820, 1820, "OFF"},
      {"horse.ply", 96966, 48485, 48485, "PLY binary_little_endian"},
      {"featuretype.stl", 3476, 2010, 2010, "STL binary"},
      {"adis16480.stl", 7436, 3672, 3672, "STL ascii"},
  };
  for (const Expected& e : cases) {
    SCOPED_TRACE(e.file);
    LoadReport r;
    const Mesh m = load_test_mesh(e.file, &r);
    expect_valid(m);
    EXPECT_EQ(m.face_count(), e.faces);
    EXPECT_EQ(m.vertex_count(), e.vertices);
    EXPECT_EQ(referenced_vertices(m), e.referenced);
    EXPECT_EQ(r.format, e.format);
    EXPECT_EQ(r.source_faces, e.faces);
    EXPECT_EQ(r.degenerate_faces, 0u);
    EXPECT_EQ(r.duplicate_faces, 0u);
    EXPECT_EQ(r.polygons_triangulated, 0u);
    EXPECT_EQ(r.unreferenced_vertices, e.vertices - e.referenced);
    EXPECT_EQ(r.file_bytes, std::filesystem::file_size(mesh_path(e.file)));
    EXPECT_GT(r.load_seconds, 0.0);
  }
}

TEST(RealMeshes, SpotHasCornerUvsAndStlCountsWelds) {
  LoadReport r;
  const Mesh spot = load_test_mesh("spot.obj");
  EXPECT_EQ(spot.corner_uvs.size(), 6u * 5856);
  // The first face is "f 739/1 735/2 736/3": its first corner carries the first vt of the file.
  std::string text;
  ASSERT_TRUE(internal::read_file(mesh_path("spot.obj"), text).is_ok());
  const size_t vt = text.find("\nvt ") + 4;
  char* end = nullptr;
  const float u0 = std::strtof(text.c_str() + vt, &end);
  const float v0 = std::strtof(end, nullptr);
  EXPECT_EQ(spot.corner_uvs[0], u0);
  EXPECT_EQ(spot.corner_uvs[1], v0);
  EXPECT_EQ(spot.indices[0], 738u);
  const Mesh stl = load_test_mesh("featuretype.stl", &r);
  EXPECT_EQ(r.welded_vertices, 3u * 3476 - 2010);
  EXPECT_TRUE(stl.corner_uvs.empty());
}

TEST(RealMeshes, HorseFirstVertexMatchesFileBytes) {
  // Reads the first float of the body independently of the reader.
  std::string bytes;
  ASSERT_TRUE(internal::read_file(mesh_path("horse.ply"), bytes).is_ok());
  const size_t body = bytes.find("end_header\n") + 11;
  float x0;
  std::memcpy(&x0, bytes.data() + body, 4);
  const Mesh m = load_test_mesh("horse.ply");
  EXPECT_EQ(m.positions[0], x0);
}

// ================================================================================================
// PLY variants
// ================================================================================================

TEST(Ply, BigEndianMatchesLittleEndian) {
  const Mesh horse = load_test_mesh("horse.ply");
  Mesh le, be;
  LoadReport r;
  ASSERT_TRUE(parse(binary_ply(horse, false), MeshFormat::kPly, le).is_ok());
  ASSERT_TRUE(parse(binary_ply(horse, true), MeshFormat::kPly, be, &r).is_ok());
  EXPECT_EQ(r.format, "PLY binary_big_endian");
  EXPECT_EQ(le.positions, horse.positions);
  EXPECT_EQ(le.indices, horse.indices);
  EXPECT_EQ(be.positions, horse.positions);
  EXPECT_EQ(be.indices, horse.indices);
}

TEST(Ply, AsciiMatchesBinary) {
  const Mesh small = first_faces(load_test_mesh("fandisk.off"), 300);
  Mesh a;
  LoadReport r;
  ASSERT_TRUE(parse(ascii_ply(small), MeshFormat::kPly, a, &r).is_ok());
  EXPECT_EQ(r.format, "PLY ascii");
  EXPECT_EQ(a.positions, small.positions);  // %.9g round-trips floats exactly
  EXPECT_EQ(a.indices, small.indices);
}

TEST(Ply, ShuffledPropertiesExtraElementsAndListTypes) {
  Mesh m;
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/shuffled.ply"), m).is_ok());
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
}

// The shuffled layout again, in binary: vertex (nx float, z float, red uchar, x double,
// junk list uchar float, y float), face (flags uchar, vertex_index list <count_type> <index_type>,
// extra list int short) with a trailing element of ushort-counted lists.
std::string shuffled_binary(bool big, const std::string& count_type, const std::string& index_type) {
  std::string s = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 4\nproperty float nx\nproperty float z\nproperty uchar red\n"
                  "property double x\nproperty list uchar float junk\nproperty float y\n"
                  "element face 2\nproperty uchar flags\nproperty list " +
                  count_type + " " + index_type +
                  " vertex_index\nproperty list int short extra\n"
                  "element trailer 1\nproperty list ushort uchar name\nend_header\n";
  const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int v = 0; v < 4; ++v) {
    put(s, 9.0f, big);
    put(s, 0.0f, big);
    put(s, uint8_t{255}, big);
    put(s, double{xy[v][0]}, big);
    put(s, static_cast<uint8_t>(v), big);
    for (int k = 0; k < v; ++k) put(s, 7.0f, big);
    put(s, xy[v][1], big);
  }
  const uint32_t faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (int f = 0; f < 2; ++f) {
    put(s, uint8_t{1}, big);
    if (count_type == "uchar")
      put(s, uint8_t{3}, big);
    else if (count_type == "ushort")
      put(s, uint16_t{3}, big);
    else
      put(s, int32_t{3}, big);
    for (uint32_t i : faces[f]) {
      if (index_type == "uchar")
        put(s, static_cast<uint8_t>(i), big);
      else if (index_type == "ushort")
        put(s, static_cast<uint16_t>(i), big);
      else
        put(s, i, big);
    }
    put(s, int32_t{2}, big);
    put(s, int16_t{-5}, big);
    put(s, int16_t{6}, big);
  }
  put(s, uint16_t{2}, big);
  s += "ab";
  return s;
}

TEST(Ply, BinaryShuffledLayoutsAllListTypes) {
  for (bool big : {false, true}) {
    for (const char* ct : {"uchar", "ushort", "int"}) {
      for (const char* it : {"uchar", "ushort", "int", "uint"}) {
        SCOPED_TRACE(std::string(big ? "BE " : "LE ") + ct + " " + it);
        Mesh m;
        const Status s = parse(shuffled_binary(big, ct, it), MeshFormat::kPly, m);
        ASSERT_TRUE(s.is_ok()) << s.message();
        EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}));
        EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
      }
    }
  }
}

TEST(Ply, RepeatedPropertyIsReported) {
  // x given twice: the first is the coordinate, the second is named in the report.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float x\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 9\n1 0 0 9\n"
      "0 1 0 9\n3 0 1 2\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(ply, MeshFormat::kPly, m, &r).is_ok());
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  EXPECT_EQ(r.not_read, "PLY vertex property x (x before it is read in its place)");
  // Two names for one value: u and s both name the texture's u; a lone name of half a pair is no uv.
  const std::string alias =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float u\nproperty float v\nproperty float s\nproperty float nx\nproperty float nx\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 9 1 1\n1 0 0 1 0 9 1 1\n"
      "0 1 0 0 1 9 1 1\n3 0 1 2\n";
  LoadReport a;
  ASSERT_TRUE(parse(alias, MeshFormat::kPly, m, &a).is_ok());
  EXPECT_EQ(a.not_read, "PLY vertex property s (u before it is read in its place); PLY vertex property nx");
}

TEST(Ply, AsciiLinesAfterTheDeclaredElementsAreReported) {
  // The header counts one face of two: the second is not read, and the report says where it starts.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n"
      "3 0 1 2\n3 1 3 2\n\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(ply, MeshFormat::kPly, m, &r).is_ok());
  EXPECT_EQ(m.face_count(), 1u);
  EXPECT_EQ(r.not_read, "1 line after the elements the PLY header declares (from line 15)");
}

TEST(Ply, TristripsWithRestartsAlternateWinding) {
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/tristrips.ply"), m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 5, 6}));
  EXPECT_EQ(r.source_faces, 4u);
}

TEST(Ply, FastPathFallsBackForPolygonsMidFile) {
  // Binary faces: triangle, quad, triangle: the triangle fast path must hand over to the generic
  // reader at the quad and fan-triangulate it.
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nelement face 3\nproperty list uchar uint vertex_indices\nend_header\n";
  const float p[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}};
  for (const auto& v : p) {
    for (float x : v) put(s, x, false);
  }
  put(s, uint8_t{3}, false);
  for (uint32_t i : {0u, 1u, 3u}) put(s, i, false);
  put(s, uint8_t{4}, false);
  for (uint32_t i : {1u, 4u, 2u, 3u}) put(s, i, false);
  put(s, uint8_t{3}, false);
  for (uint32_t i : {2u, 4u, 3u}) put(s, i, false);
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(s, MeshFormat::kPly, m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 3, 1, 4, 2, 1, 2, 3, 2, 4, 3}));
  EXPECT_EQ(r.source_faces, 3u);
  EXPECT_EQ(r.polygons_triangulated, 1u);
}

// An L-shaped hexagon (area 3) fanned from its reflex-adjacent first corner overlaps itself (one
// triangle turns back, the fan covers 4): it is cut into ears, each corner keeping its UV; a
// convex polygon keeps its fan.
TEST(Polygons, ConcavePolygonsAreCutIntoEars) {
  const std::string corners = "v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\n";
  for (const auto& [text, format] :
       {std::pair{corners + "vt 2 1\nvt 1 1\nvt 1 2\nvt 0 2\nvt 0 0\nvt 2 0\nf 1/1 2/2 3/3 4/4 5/5 6/6\n",
                  MeshFormat::kObj},
        std::pair{std::string("OFF\n6 1 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n0 0 0\n2 0 0\n6 0 1 2 3 4 5\n"),
                  MeshFormat::kOff},
        std::pair{std::string("ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                              "end_header\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n0 0 0\n2 0 0\n6 0 1 2 3 4 5\n"),
                  MeshFormat::kPly}}) {
    SCOPED_TRACE(text);
    Mesh m;
    LoadReport r;
    ASSERT_TRUE(parse(text, format, m, &r).is_ok());
    ASSERT_EQ(m.face_count(), 4u);
    EXPECT_EQ(r.polygons_triangulated, 1u);
    EXPECT_EQ(r.concave_polygons, 1u);
    double total = 0;
    for (size_t f = 0; f < 4; ++f) {
      const float* a = &m.positions[3 * m.indices[3 * f]];
      const float* b = &m.positions[3 * m.indices[3 * f + 1]];
      const float* c = &m.positions[3 * m.indices[3 * f + 2]];
      const double area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
      EXPECT_GT(area, 0.0) << "face " << f;  // the polygon's winding, no triangle turned back
      total += area;
    }
    EXPECT_DOUBLE_EQ(total, 3.0);
    if (format == MeshFormat::kObj) {
      ASSERT_EQ(m.corner_uvs.size(), 24u);
      for (size_t c = 0; c < 12; ++c) {  // each corner's vt is its vertex's x y
        EXPECT_EQ(m.corner_uvs[2 * c], m.positions[3 * m.indices[c]]);
        EXPECT_EQ(m.corner_uvs[2 * c + 1], m.positions[3 * m.indices[c] + 1]);
      }
    }
  }
  // A convex pentagon keeps its fan from the first corner.
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse("v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n", MeshFormat::kObj, m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
  EXPECT_EQ(r.concave_polygons, 0u);
}

TEST(Ply, TexcoordsAndSeamsFollowDroppedFaces) {
  // Per-face texcoord lists and seam flags; face 2 is degenerate and face 3 duplicates face 0
  // (other winding): both dropped, the uvs and seams of the kept faces stay with them.
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\n"
      "property uchar seam\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
      "3 0 1 2 6 0 0 1 0 1 1 0\n"
      "3 0 2 3 6 0 0 1 1 0 1 1\n"
      "3 0 0 1 6 9 9 9 9 9 9 1\n"
      "3 2 1 0 6 8 8 8 8 8 8 0\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(s, MeshFormat::kPly, m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(m.corner_uvs, (std::vector<float>{0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1}));
  EXPECT_EQ(m.seam_faces, (std::vector<uint8_t>{0, 1}));
  EXPECT_EQ(r.degenerate_faces, 1u);
  EXPECT_EQ(r.duplicate_faces, 1u);
  EXPECT_EQ(r.source_faces, 4u);
}

TEST(Ply, PerVertexTextureCoordinates) {
  for (const char* names : {"s t", "u v", "texture_u texture_v"}) {
    SCOPED_TRACE(names);
    const std::string n(names);
    const std::string u = n.substr(0, n.find(' ')), v = n.substr(n.find(' ') + 1);
    const std::string s = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float " + u +
                          "\nproperty float x\nproperty float y\nproperty float z\nproperty float " + v +
                          "\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          "0.1 0 0 0 0.2\n0.3 1 0 0 0.4\n0.5 0 1 0 0.6\n3 2 0 1\n";
    Mesh m;
    ASSERT_TRUE(parse(s, MeshFormat::kPly, m).is_ok());
    EXPECT_EQ(m.corner_uvs, (std::vector<float>{0.5f, 0.6f, 0.1f, 0.2f, 0.3f, 0.4f}));
  }
}

// ================================================================================================
// OBJ, OFF, STL variants
// ================================================================================================

TEST(Obj, AllCornerFormsNegativeIndicesAndIgnoredStatements) {
  const std::string s =
      "# comment\r\nmtllib nowhere.mtl\r\no thing\r\ng group\r\ns 1\r\nusemtl red\r\n"
      "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0 1.0 0.5 0.5\r\n"
      "vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\nvn 0 0 1\r\n"
      "f 1/1 2/2 3/3\r\n"
      "f -4/-4/-1 -2/-2/-1 \\\r\n -1/-1/-1\r\n"
      "l 1 2\r\np 3\r\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(s, MeshFormat::kObj, m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(m.corner_uvs, (std::vector<float>{0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1}));
  EXPECT_EQ(r.format, "OBJ");

  // v//vn and bare forms have no vt: corner uvs are left empty.
  Mesh n;
  ASSERT_TRUE(parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2/1 4/1 3/1\n",
                    MeshFormat::kObj, n)
                  .is_ok());
  EXPECT_EQ(n.indices, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_TRUE(n.corner_uvs.empty());

  // A UTF-8 byte order mark does not hide the first line (its vertex would be lost, the face shifted).
  Mesh bom;
  ASSERT_TRUE(parse("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj, bom).is_ok());
  EXPECT_EQ(bom.vertex_count(), 3u);
  EXPECT_EQ(bom.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  // Lines ending in CR alone are said, not read as one line ("mesh has no faces").
  Mesh cr;
  EXPECT_NE(parse("v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r", MeshFormat::kObj, cr).message().find("end in CR alone"),
            std::string::npos);
  // A normal index without normals says normals.
  Mesh none;
  const Status no_normals = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", MeshFormat::kObj, none);
  EXPECT_NE(no_normals.message().find("normal index 1 out of range (mesh has 0 normals)"), std::string::npos)
      << no_normals.message();
}

TEST(Obj, PolygonsAreFanTriangulated) {
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/prism_polygons.obj"), m, &r).is_ok());
  EXPECT_EQ(m.vertex_count(), 10u);
  EXPECT_EQ(m.face_count(), 16u);
  EXPECT_EQ(r.source_faces, 7u);
  EXPECT_EQ(r.polygons_triangulated, 7u);
  // The top pentagon 6 7 8 9 10 (1-based) becomes the fan (5,6,7) (5,7,8) (5,8,9).
  EXPECT_EQ(std::vector<uint32_t>(m.indices.begin() + 9, m.indices.begin() + 18),
            (std::vector<uint32_t>{5, 6, 7, 5, 7, 8, 5, 8, 9}));
}

TEST(Off, KeywordVariantsColoursAndComments) {
  const std::string cases[] = {
      "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      "COFF\n# colours per vertex and face\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n"
      "3 0 1 2 255 255 255\n",
      "NOFF 3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
      "CNOFF\n\n3 1\n0 0 0 0 0 1 1 1 1\n1 0 0 0 0 1 1 1 1\n0 1 0 0 0 1 1 1 1\n3 0 1 2 0.5 0.5 0.5\n",
      "STOFF\n3 1 0\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n",
      "nOFF\n3\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      "off\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",             // lower case, as some writers give it
      "OFF\n3\n1\n0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",           // the counts one per line
      "OFF\n3\n1\n# no edges\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",  // and without the edge count
  };
  for (const std::string& c : cases) {
    SCOPED_TRACE(c.substr(0, 6));
    Mesh m;
    const Status s = parse(c, MeshFormat::kOff, m);
    ASSERT_TRUE(s.is_ok()) << s.message();
    EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
  }
  Mesh m;
  EXPECT_EQ(parse("4OFF\n1 1 0\n0 0 0 0\n", MeshFormat::kOff, m).code(), ErrorCode::kUnsupported);
  EXPECT_EQ(parse("OFF BINARY\n", MeshFormat::kOff, m).code(), ErrorCode::kUnsupported);
  // The data run on after the counts, on the keyword's line or the counts' own: named, not "too short".
  for (const char* one_line : {"OFF 3 1 0 0 0 0 1 0 0 0 1 0 3 0 1 2\n", "OFF\n3 1 0 0 0 0 1 0 0 0 1 0 3 0 1 2\n"}) {
    const Status s = parse(one_line, MeshFormat::kOff, m);
    EXPECT_EQ(s.code(), ErrorCode::kUnsupported) << one_line;
    EXPECT_NE(s.message().find("values after the OFF counts on their line ('0'...)"), std::string::npos) << s.message();
  }
}

TEST(Off, ContentAfterTheDeclaredFacesIsReported) {
  // A header that counts one face of two: the second is not read, and the report says so.
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(
      parse("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n# end\n\n", MeshFormat::kOff, m, &r).is_ok());
  EXPECT_EQ(m.face_count(), 1u);
  EXPECT_EQ(r.not_read, "1 line after the 1 face the OFF header declares (from line 8)");
  // Trailing blank lines and comments are nothing unread.
  LoadReport clean;
  ASSERT_TRUE(parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n# written by a tool\n\n", MeshFormat::kOff, m, &clean)
                  .is_ok());
  EXPECT_EQ(clean.not_read, "");
}

TEST(Stl, AsciiPolygonLoopsAndBinaryStartingWithSolid) {
  const std::string ascii =
      "solid square\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n"
      "   vertex 0 1 0\n  endloop\n endfacet\nendsolid square\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(ascii, MeshFormat::kStl, m, &r).is_ok());
  EXPECT_EQ(r.format, "STL ascii");
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(r.welded_vertices, 2u);
  EXPECT_EQ(r.polygons_triangulated, 1u);

  // Keywords in upper case (some CAD exporters), and a corner written as -0: the same point as 0.
  const std::string upper =
      "SOLID square\n FACET NORMAL 0 0 1\n  OUTER LOOP\n   VERTEX 0 0 0\n   VERTEX 1 0 0\n   VERTEX 1 1 0\n"
      "  ENDLOOP\n ENDFACET\n FACET NORMAL 0 0 1\n  OUTER LOOP\n   VERTEX -0 0 0\n   VERTEX 1 1 0\n"
      "   VERTEX 0 1 -0.0\n  ENDLOOP\n ENDFACET\nENDSOLID square\n";
  Mesh u;
  ASSERT_TRUE(parse(upper, MeshFormat::kStl, u, &r).is_ok());
  EXPECT_EQ(r.format, "STL ascii");
  EXPECT_EQ(u.vertex_count(), 4u);
  EXPECT_EQ(u.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  // Text that is not STL at all (an OBJ named .stl): said so, not read as a binary count.
  const std::string obj(100, 'v');
  EXPECT_EQ(parse(obj, MeshFormat::kStl, u).what(), "not an STL file: text without the 'solid' keyword of ascii STL");

  // Binary whose 80-byte header starts with "solid": decided by the size rule.
  std::string bin = "solid but actually binary";
  bin.resize(80, ' ');
  put(bin, uint32_t{2}, false);
  const float tris[2][9] = {{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}};
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) put(bin, 0.0f, false);
    for (float x : t) put(bin, x, false);
    put(bin, uint16_t{0}, false);
  }
  Mesh b;
  ASSERT_TRUE(parse(bin, MeshFormat::kUnknown, b, &r).is_ok());
  EXPECT_EQ(r.format, "STL binary");
  EXPECT_EQ(b.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(r.welded_vertices, 2u);
  // One byte short: binary by content, but truncated.
  bin.pop_back();
  EXPECT_EQ(parse(bin, MeshFormat::kStl, b).code(), ErrorCode::kParse);
}

// ================================================================================================
// Topological oddities load as they are (the topology stage deals with them)
// ================================================================================================

TEST(Adversarial, TopologicalOdditiesLoadUnchanged) {
  LoadReport r;
  Mesh m;
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/bowtie.obj"), m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 3, 4}));
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/fin.off"), m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 1, 0, 3, 0, 1, 4}));
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/flipped.obj"), m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 3, 2}));
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/zero_area.off"), m, &r).is_ok());
  EXPECT_EQ(m.face_count(), 2u);
  EXPECT_EQ(r.zero_area_faces, 1u);
  EXPECT_EQ(r.degenerate_faces, 0u);
}

TEST(Adversarial, RepairsAreCounted) {
  // Face 1 repeats a vertex, face 3 is face 0 reversed, face 4 is face 0 rotated; vertex 4 unused.
  const std::string s =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 5 5\n"
      "f 1 2 3\nf 1 1 2\nf 2 4 3\nf 3 2 1\nf 2 3 1\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(s, MeshFormat::kObj, m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(r.source_faces, 5u);
  EXPECT_EQ(r.degenerate_faces, 1u);
  EXPECT_EQ(r.duplicate_faces, 2u);
  EXPECT_EQ(r.unreferenced_vertices, 1u);
  EXPECT_EQ(m.vertex_count(), 5u);  // unreferenced vertices are kept so ids match the file
}

TEST(Adversarial, ManyDuplicatesInOneFanBucket) {
  // 40 copies of each of 3 fan triangles around vertex 0: the sorted-bucket path (> 16 entries).
  std::string s = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\n";
  for (int copy = 0; copy < 40; ++copy) s += "f 1 2 3\nf 1 3 4\nf 1 4 5\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(s, MeshFormat::kObj, m, &r).is_ok());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
  EXPECT_EQ(r.duplicate_faces, 117u);
}

TEST(Adversarial, HugeFanFallsBackToExactDuplicateSearch) {
  // 300 distinct triangles around vertex 0 (more than the duplicate chain walks), then every
  // third one again with the other winding, then a copy of a duplicate: all later copies dropped.
  std::string s = "v 0 0 0\n";
  for (int k = 0; k <= 300; ++k) s += "v " + std::to_string(k) + " 1 0\n";
  for (int k = 1; k <= 300; ++k) s += "f 1 " + std::to_string(k + 1) + " " + std::to_string(k + 2) + "\n";
  for (int k = 1; k <= 300; k += 3) s += "f 1 " + std::to_string(k + 2) + " " + std::to_string(k + 1) + "\n";
  s += "f 2 3 1\n";
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(parse(s, MeshFormat::kObj, m, &r).is_ok());
  EXPECT_EQ(m.face_count(), 300u);
  EXPECT_EQ(r.duplicate_faces, 101u);
  for (uint32_t k = 0; k < 300; ++k) {
    ASSERT_EQ(m.indices[3 * k + 1], k + 1);
    ASSERT_EQ(m.indices[3 * k + 2], k + 2);
  }
  EXPECT_EQ(r.zero_area_faces, 0u);
}

TEST(Adversarial, LargeMeshRepairsMatchSmallMeshRepairs) {
  // Horse three times over (290,898 faces: large enough for finalize_mesh's second thread), the
  // copies rotated and reversed, plus degenerate faces: repairs must match the plain horse.
  LoadReport plain;
  const Mesh horse = load_test_mesh("horse.ply", &plain);
  Mesh big;
  big.positions = horse.positions;
  big.indices = horse.indices;
  const size_t nf = horse.face_count();
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t* t = &horse.indices[3 * f];
    big.indices.insert(big.indices.end(), {t[1], t[2], t[0]});
  }
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t* t = &horse.indices[3 * f];
    big.indices.insert(big.indices.end(), {t[2], t[1], t[0], t[0], t[0], t[1]});
  }
  LoadReport r;
  ASSERT_TRUE(finalize_mesh("big", big, r).is_ok());
  EXPECT_EQ(big.indices, horse.indices);
  EXPECT_EQ(r.duplicate_faces, 2 * nf);
  EXPECT_EQ(r.degenerate_faces, nf);
  EXPECT_EQ(r.zero_area_faces, plain.zero_area_faces);
  EXPECT_EQ(r.unreferenced_vertices, 0u);
}

TEST(Adversarial, BinaryTetrahedraWithSeamsAndExtraElements) {
  Mesh le, be, stl;
  LoadReport r;
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/tetra_seam_le.ply"), le, &r).is_ok());
  EXPECT_EQ(r.format, "PLY binary_little_endian");
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/tetra_seam_be.ply"), be, &r).is_ok());
  EXPECT_EQ(r.format, "PLY binary_big_endian");
  EXPECT_EQ(le.positions, be.positions);
  EXPECT_EQ(le.indices, (std::vector<uint32_t>{0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2}));
  EXPECT_EQ(be.indices, le.indices);
  EXPECT_EQ(le.seam_faces, (std::vector<uint8_t>{0, 0, 1, 0}));
  EXPECT_EQ(be.seam_faces, le.seam_faces);
  ASSERT_TRUE(load_mesh(mesh_path("adversarial/tetra_binary.stl"), stl, &r).is_ok());
  EXPECT_EQ(r.format, "STL binary");
  // Welded vertices are numbered in order of first use: (0 0 0) (0 1 0) (1 0 0) (0 0 1).
  EXPECT_EQ(stl.positions, (std::vector<float>{0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1}));
  EXPECT_EQ(stl.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 2, 1, 3, 0, 3, 1}));
  EXPECT_EQ(r.welded_vertices, 8u);
}

// ================================================================================================
// Errors: clean Status naming the place
// ================================================================================================

TEST(Errors, NonFiniteCoordinateNamesTheVertex) {
  Mesh m;
  Status s = parse("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj, m);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.where(), "vertex 1");
  EXPECT_TRUE(m.empty());
  s = parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 inf 0\n3 0 1 2\n", MeshFormat::kOff, m);
  EXPECT_EQ(s.where(), "vertex 2");
}

TEST(Errors, IndexOutOfRangeNamesLineOrFace) {
  Mesh m;
  Status s = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\nf 1 2 10\n", MeshFormat::kObj, m);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.what(), "face index 10 out of range (mesh has 3 vertices)");
  EXPECT_EQ(s.where(), "line 6");
  EXPECT_EQ(s.message(), "test: face index 10 out of range (mesh has 3 vertices) (line 6)");
  s = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", MeshFormat::kObj, m);
  EXPECT_EQ(s.where(), "line 4");
  s = parse("v 0 0 0\nf 1 2 3\nv 1 0 0\n", MeshFormat::kObj, m);  // forward reference, never defined
  EXPECT_EQ(s.where(), "line 2");
  s = parse("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 3\n", MeshFormat::kOff, m);
  EXPECT_EQ(s.where(), "line 7");

  const Mesh small = first_faces(load_test_mesh("fandisk.off"), 100);
  Mesh bad = small;
  bad.indices[3 * 57 + 1] = static_cast<uint32_t>(small.vertex_count()) + 5;
  s = parse(binary_ply(bad, false), MeshFormat::kPly, m);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.where(), "face 57");
  s = parse(binary_ply(bad, true), MeshFormat::kPly, m);
  EXPECT_EQ(s.where(), "face 57");
  const std::string ascii = ascii_ply(bad);
  s = parse(ascii, MeshFormat::kPly, m);
  const size_t header_lines = 9;
  EXPECT_EQ(s.where(), "line " + std::to_string(header_lines + small.vertex_count() + 57 + 1));
}

TEST(Errors, FaceWithTwoVertices) {
  Mesh m;
  Status s = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", MeshFormat::kObj, m);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.what(), "face with 2 vertices");
  EXPECT_EQ(s.where(), "line 4");
  s = parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", MeshFormat::kOff, m);
  EXPECT_EQ(s.what(), "face with 2 vertices");
  s = parse(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
      MeshFormat::kPly, m);
  EXPECT_EQ(s.what(), "face with 2 vertices");
  EXPECT_EQ(s.where(), "line 13");
}

// An ascii PLY record is one line: a line with more values than the element's properties is an
// error at that line, not values of the next record (a face "3 0 1 2 3" would give a second,
// shifted face; a vertex line of four numbers would shift every vertex after it).
TEST(Errors, AsciiPlyLineWithMoreValuesThanProperties) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  Mesh m;
  Status s = parse(header + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2 3\n3 1 3 2\n", MeshFormat::kPly, m);
  EXPECT_EQ(s.what(), "more values on the line than PLY element 'face' has properties");
  EXPECT_EQ(s.where(), "line 14");
  s = parse(header + "0 0 0\n1 0 0 7\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n", MeshFormat::kPly, m);
  EXPECT_EQ(s.what(), "more values on the line than PLY element 'vertex' has properties");
  EXPECT_EQ(s.where(), "line 11");
  // A short record whose values run onto the next line: said at the line it started on.
  s = parse(header + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1\n3 1 3 2\n", MeshFormat::kPly, m);
  EXPECT_EQ(s.what(), "a record of PLY element 'face' runs onto the next line (fewer values than its properties)");
  EXPECT_EQ(s.where(), "line 14");
  // Blank space and CR line ends after a record are fine.
  ASSERT_TRUE(parse(header + "0 0 0 \r\n1 0 0\t\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2", MeshFormat::kPly, m).is_ok());
  EXPECT_EQ(m.face_count(), 2u);
}

TEST(Errors, HugeHeaderCountsFailBeforeAllocating) {
  Mesh m;
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\nend_header\n";
  s.resize(200, '\0');
  Status st = parse(s, MeshFormat::kPly, m);
  EXPECT_EQ(st.code(), ErrorCode::kParse);
  EXPECT_NE(st.what().find("4000000000"), std::string::npos) << st.what();
  // Overflowing products and counts beyond 64 bits.
  st = parse(
      "ply\nformat ascii 1.0\nelement vertex 18446744073709551615\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n",
      MeshFormat::kPly, m);
  EXPECT_EQ(st.code(), ErrorCode::kParse);
  st = parse("ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nend_header\n", MeshFormat::kPly, m);
  EXPECT_EQ(st.code(), ErrorCode::kParse);
  // A count of 2^64 or more is a bad element line (from_chars leaves the count at 0 on overflow),
  // in the face element and in an extra element alike.
  const std::string triangle_body = "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string vertices =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  for (const char* faces : {"element face 18446744073709551616\nproperty list uchar int vertex_indices\n",
                            "element face 1\nproperty list uchar int vertex_indices\nelement junk "
                            "18446744073709551619\nproperty float a\n"}) {
    st = parse(vertices + faces + triangle_body, MeshFormat::kPly, m);
    EXPECT_EQ(st.code(), ErrorCode::kParse) << faces;
    EXPECT_NE(st.message().find("bad PLY element line"), std::string::npos) << st.message();
  }
  st = parse("OFF\n4000000000 4000000000 0\n0 0 0\n", MeshFormat::kOff, m);
  EXPECT_EQ(st.code(), ErrorCode::kParse);
  std::string stl(84, ' ');
  const uint32_t n = 0xffffffffu;
  std::memcpy(&stl[80], &n, 4);
  EXPECT_EQ(parse(stl, MeshFormat::kStl, m).code(), ErrorCode::kParse);
  // A list count far larger than the file.
  st = parse(
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n" +
          std::string(36, '\0') + std::string("\xff\xff\xff\x7f", 4),
      MeshFormat::kPly, m);
  EXPECT_EQ(st.code(), ErrorCode::kParse);
  EXPECT_EQ(st.where(), "face 0");
}

TEST(Errors, GarbageEmptyAndUnknown) {
  std::string garbage;
  uint32_t x = 12345;
  for (int i = 0; i < 4096; ++i) {
    x = x * 1664525u + 1013904223u;
    garbage.push_back(static_cast<char>(x >> 24));
  }
  for (MeshFormat f : {MeshFormat::kPly, MeshFormat::kObj, MeshFormat::kOff, MeshFormat::kStl, MeshFormat::kUnknown}) {
    Mesh m;
    const Status s = parse(garbage, f, m);
    EXPECT_FALSE(s.is_ok());
    EXPECT_TRUE(m.empty());
  }
  Mesh m;
  Status s = parse("# nothing here\nv 0 0 0\n", MeshFormat::kObj, m);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.what(), "mesh has no faces");
  s = parse("v 0 0 0\nf 1 1 1\n", MeshFormat::kObj, m);  // every face degenerate: says why none is left
  EXPECT_EQ(s.what(), "mesh has no faces left: all 1 name a vertex twice and were dropped");
  s = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 2 3 1\nf 1 1 2\n", MeshFormat::kObj, m);
  EXPECT_TRUE(s.is_ok()) << s.what();  // one face kept of three
  s = parse("", MeshFormat::kUnknown, m);
  EXPECT_EQ(s.code(), ErrorCode::kUnsupported);
  EXPECT_NE(s.what().find(".ply"), std::string::npos);
}

// Header caps: each limit fails with one line naming it (the parser is one linear pass; before the
// caps, 200,000 element lines took 20 s because each new element was compared with all before it).
TEST(Errors, OversizedPlyHeadersFailWithOneLine) {
  Mesh m;
  std::string many = "ply\nformat ascii 1.0\n";
  for (int i = 0; i < 20000; ++i) many += "element e" + std::to_string(i) + " 0\n";
  many += "end_header\n";
  Status s = parse(many, MeshFormat::kPly, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kLimit);
  EXPECT_NE(s.message().find("more than 4096 elements"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("(line 4099)"), std::string::npos) << s.message();

  std::string props = "ply\nformat ascii 1.0\nelement vertex 0\n";
  for (int i = 0; i < 20000; ++i) props += "property float p" + std::to_string(i) + "\n";
  props += "end_header\n";
  s = parse(props, MeshFormat::kPly, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(s.message().find("more than 16384 properties"), std::string::npos) << s.message();

  std::string longer = "ply\nformat ascii 1.0\n";
  while (longer.size() <= (size_t{1} << 20)) longer += "comment " + std::string(100, 'c') + "\n";
  longer += "end_header\n";
  s = parse(longer, MeshFormat::kPly, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(s.message().find("PLY header longer than 1 MiB"), std::string::npos) << s.message();
  // No newline at all: the same error, not a scan of the whole input.
  s = parse("ply\nformat ascii 1.0\n" + std::string((size_t{1} << 20) + 10, 'x'), MeshFormat::kPly, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(s.message().find("PLY header longer than 1 MiB"), std::string::npos) << s.message();
}

// Error lines quote file content as printable ASCII only, at most 200 characters, and end with
// the position.
TEST(Errors, QuotedInputIsEscapedAndShort) {
  const auto ascii_only = [](const std::string& text) {
    return std::all_of(text.begin(), text.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
  };
  Mesh m;
  Status s = parse("ply\nformat ascii 1.0\nbad\xff\x1b[2Jword\\x\nend_header\n", MeshFormat::kPly, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(ascii_only(s.message())) << s.message();
  EXPECT_NE(s.message().find("'bad\\xff\\x1b[2Jword\\\\x'"), std::string::npos) << s.message();
  EXPECT_TRUE(s.message().ends_with("(line 3)")) << s.message();

  s = parse("ply\nformat ascii 1.0\n" + std::string(1000000, '\xff') + "\nend_header\n", MeshFormat::kPly, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(ascii_only(s.message())) << s.message();
  EXPECT_LT(s.message().size(), 300u) << s.message();
  EXPECT_TRUE(s.message().ends_with("(line 3)")) << s.message();

  // An element name (quoted again in body errors) and the other readers go through the same helper.
  s = parse("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement \x1b" + std::string(5000, 'n') +
                " 1\nproperty float y\nend_header\n1\n",
            MeshFormat::kPly, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(ascii_only(s.message())) << s.message();
  EXPECT_LT(s.message().size(), 300u) << s.message();
  s = parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::kOff, m);
  ASSERT_TRUE(s.is_ok()) << s.message();
  s = parse("\xff\x1b" + std::string(4000, 'O') + "\n3 1 0\n", MeshFormat::kOff, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(ascii_only(s.message())) << s.message();
  EXPECT_LT(s.message().size(), 300u) << s.message();
  s = parse("solid x\n\x1b" + std::string(4000, 'f') + "\nendsolid\n", MeshFormat::kStl, m);
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(ascii_only(s.message())) << s.message();
  EXPECT_LT(s.message().size(), 300u) << s.message();
}

TEST(LoadMesh, SniffsContentAndReportsIoErrors) {
  const std::string dir = ::testing::TempDir();
  const std::string copy = dir + "/io_test_fandisk.dat";
  std::string bytes;
  ASSERT_TRUE(internal::read_file(mesh_path("fandisk.off"), bytes).is_ok());
  ASSERT_TRUE(internal::write_file_atomic(copy, bytes).is_ok());
  Mesh m;
  LoadReport r;
  ASSERT_TRUE(load_mesh(copy, m, &r).is_ok());
  EXPECT_EQ(m.face_count(), 14454u);
  EXPECT_EQ(r.format, "OFF");
  const std::string junk = dir + "/io_test_junk.dat";
  ASSERT_TRUE(internal::write_file_atomic(junk, std::string("hello world\n")).is_ok());
  Status s = load_mesh(junk, m);
  EXPECT_EQ(s.code(), ErrorCode::kUnsupported);
  EXPECT_EQ(s.file(), junk);
  s = load_mesh(dir + "/does-not-exist.ply", m);
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  std::remove(copy.c_str());
  std::remove(junk.c_str());
  EXPECT_EQ(mesh_format_from_path("A.PLY"), MeshFormat::kPly);
  EXPECT_EQ(mesh_format_from_path("b.Obj"), MeshFormat::kObj);
  EXPECT_EQ(mesh_format_from_path("c.glb"), MeshFormat::kGlb);
  EXPECT_EQ(mesh_format_from_path("d.stl.bak"), MeshFormat::kUnknown);
}

TEST(AtomicFiles, ABatchLandsWholeOrNotAtAll) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / "io_test_batch";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string a = (dir / "a.txt").string(), b = (dir / "b.txt").string();
  ASSERT_TRUE(internal::write_file_atomic(a, std::string("old a\n")).is_ok());
  auto content = [](const std::string& path) {
    std::string bytes;
    return internal::read_file(path, bytes).is_ok() ? bytes : std::string("<missing>");
  };
  auto entries = [&dir] {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
  };
  {
    // A command that fails after its first write: nothing lands, the old file stays, no temp left.
    internal::FileBatch batch;
    ASSERT_TRUE(internal::write_file_atomic(a, std::string("new a\n")).is_ok());
    ASSERT_TRUE(internal::write_file_atomic(b, std::string("new b\n")).is_ok());
    EXPECT_EQ(content(a), "old a\n");
    EXPECT_EQ(content(b), "<missing>");
  }
  EXPECT_EQ(content(a), "old a\n");
  EXPECT_EQ(content(b), "<missing>");
  EXPECT_EQ(entries(), 1u);
  {
    internal::FileBatch batch;
    ASSERT_TRUE(internal::write_file_atomic(a, std::string("new a\n")).is_ok());
    ASSERT_TRUE(internal::write_file_atomic(b, std::string("first b\n")).is_ok());
    ASSERT_TRUE(internal::write_file_atomic(b, std::string("new b\n")).is_ok());  // last write wins
    ASSERT_TRUE(batch.commit().is_ok());
  }
  EXPECT_EQ(content(a), "new a\n");
  EXPECT_EQ(content(b), "new b\n");
  EXPECT_EQ(entries(), 2u);
  // Without a batch, writes land at once again.
  ASSERT_TRUE(internal::write_file_atomic(b, std::string("plain\n")).is_ok());
  EXPECT_EQ(content(b), "plain\n");
  fs::remove_all(dir);
}

TEST(Errors, FinalizeRejectsBadArraysAndLimits) {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 7};
  LoadReport r;
  Status s = finalize_mesh("x", m, r);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(s.what(), "face index 7 out of range (mesh has 3 vertices)");
  EXPECT_EQ(s.where(), "face 0");
  m.indices = {0, 1, 2};
  m.corner_uvs = {0, 0};
  EXPECT_EQ(finalize_mesh("x", m, r).code(), ErrorCode::kInvalidMesh);
}

// ================================================================================================
// Every prefix of small files loads or fails with a Status (ASan builds check memory)
// ================================================================================================

void check_all_prefixes(const std::string& full, MeshFormat format) {
  size_t ok = 0;
  for (size_t n = 0; n <= full.size(); ++n) {
    const std::string prefix = full.substr(0, n);
    Mesh m;
    const Status s = parse(prefix, format, m);
    if (s.is_ok()) {
      ++ok;
      expect_valid(m);
    } else {
      ASSERT_TRUE(m.empty()) << "prefix " << n;
      ASSERT_FALSE(s.what().empty());
    }
  }
  Mesh whole;
  EXPECT_TRUE(parse(full, format, whole).is_ok());
  EXPECT_GT(ok, 0u);
}

TEST(Truncation, EveryPrefixOfSmallFilesFailsCleanly) {
  const Mesh fandisk = first_faces(load_test_mesh("fandisk.off"), 100);
  const Mesh spot = first_faces(load_test_mesh("spot.obj"), 100);
  ASSERT_EQ(spot.corner_uvs.size(), 600u);
  {
    SCOPED_TRACE("binary ply");
    check_all_prefixes(binary_ply(fandisk, false), MeshFormat::kPly);
  }
  {
    SCOPED_TRACE("binary ply big endian");
    check_all_prefixes(binary_ply(spot, true), MeshFormat::kPly);
  }
  {
    SCOPED_TRACE("ascii ply");
    check_all_prefixes(ascii_ply(spot), MeshFormat::kPly);
  }
  {
    SCOPED_TRACE("obj");
    check_all_prefixes(obj_text(spot), MeshFormat::kObj);
  }
  std::string off;
  ASSERT_TRUE(internal::read_file(mesh_path("adversarial/fin.off"), off).is_ok());
  check_all_prefixes(off, MeshFormat::kOff);
  std::string strips;
  ASSERT_TRUE(internal::read_file(mesh_path("adversarial/shuffled.ply"), strips).is_ok());
  check_all_prefixes(strips, MeshFormat::kPly);
  check_all_prefixes(shuffled_binary(true, "ushort", "uint"), MeshFormat::kPly);
}

TEST(Truncation, ObjRoundTripKeepsCornerUvs) {
  const Mesh spot = first_faces(load_test_mesh("spot.obj"), 100);
  Mesh m;
  ASSERT_TRUE(parse(obj_text(spot), MeshFormat::kObj, m).is_ok());
  EXPECT_EQ(m.positions, spot.positions);
  EXPECT_EQ(m.indices, spot.indices);
  EXPECT_EQ(m.corner_uvs, spot.corner_uvs);
}

TEST(Strokes, JsonRoundTripsBitForBit) {
  std::vector<OrientationStroke> strokes(2);
  strokes[0].points = {0.1f, -2.5f, 1e-7f, 3.f, 4.f, 5.f};
  strokes[0].radius = 0.1f;
  strokes[1].points = {1.f / 3.f, 2.f / 7.f, -1e20f, 0.f, 0.f, 0.f, 1.f, 1.f, 1.f};
  strokes[1].radius = 123.456f;
  std::vector<OrientationStroke> back;
  const Status s = parse_strokes(strokes_json(strokes), "mem", back);
  ASSERT_TRUE(s.is_ok()) << s.message();
  ASSERT_EQ(back.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].points, strokes[i].points);
    EXPECT_EQ(back[i].radius, strokes[i].radius);
  }
  ASSERT_TRUE(parse_strokes(R"({"strokes": []})", "mem", back).is_ok());
  EXPECT_TRUE(back.empty());
}

// The nesting bound: 256 levels parse, 257 do not, counted outside strings; a long array of
// objects parses (the depth is counted before the parse, in one pass).
TEST(Json, NestingBoundIsExactAndIgnoresStrings) {
  const auto nested = [](int levels) { return std::string(levels, '[') + std::string(levels, ']'); };
  nlohmann::json j;
  EXPECT_EQ(internal::parse_json_bounded(nested(256), j), internal::JsonParse::kOk);
  EXPECT_EQ(internal::parse_json_bounded(nested(257), j), internal::JsonParse::kTooDeep);
  EXPECT_TRUE(j.is_discarded());
  EXPECT_EQ(internal::parse_json_bounded("[\"" + std::string(1000, '[') + "\\\"\"]", j), internal::JsonParse::kOk);
  EXPECT_EQ(j[0].get<std::string>().size(), 1001u);
  EXPECT_EQ(internal::parse_json_bounded("[1,", j), internal::JsonParse::kInvalid);
  std::string objects = "[";
  for (int k = 0; k < 200000; ++k) objects += k ? ",{}" : "{}";
  EXPECT_EQ(internal::parse_json_bounded(objects + "]", j), internal::JsonParse::kOk);
  EXPECT_EQ(j.size(), 200000u);
}

TEST(Strokes, BadJsonNamesWhereAndLeavesNothing) {
  std::vector<OrientationStroke> back;
  auto message = [&](const std::string& text) {
    back.assign(1, OrientationStroke{});
    const Status s = parse_strokes(text, "in.json", back);
    EXPECT_EQ(s.code(), ErrorCode::kParse) << text;
    EXPECT_TRUE(back.empty()) << text;
    return s.message();
  };
  EXPECT_NE(message(R"({"strokes": [)").find("byte"), std::string::npos);
  EXPECT_NE(message(R"([1, 2])").find("top level"), std::string::npos);
  EXPECT_NE(message(R"({"strokes": {}})").find("must be an array"), std::string::npos);
  EXPECT_NE(message(R"({"strokes": [{"points": [[0,0,0]], "radius": 1}]})").find("strokes[0].points"),
            std::string::npos);
  EXPECT_NE(message(R"({"strokes": [{"points": [[0,0,0],[1,1,"a"]], "radius": 1}]})").find("strokes[0].points[1]"),
            std::string::npos);
  EXPECT_NE(message(R"({"strokes": [{"points": [[0,0,0],[1,1,1e300]], "radius": 1}]})").find("points[1]"),
            std::string::npos);
  // A radius that is positive but no float (1e-300 becomes 0): the message gives the least one.
  EXPECT_NE(message(R"({"strokes": [{"points": [[0,0,0],[1,1,1]], "radius": 1e-300}]})").find("at least 1.2e-38"),
            std::string::npos);
  EXPECT_NE(message(R"({"strokes": [{"points": [[0,0,0],[1,1,1]], "radius": -1}]})").find("strokes[0].radius"),
            std::string::npos);
  EXPECT_NE(message(R"({"strokes": [{"points": [[0,0,0],[1,1,1]], "radius": 1, "x": 2}]})").find("unknown key"),
            std::string::npos);
  // A number past a double's range, and a nesting too deep to copy safely: one line each.
  EXPECT_NE(message(R"({"strokes": [{"points": [[0,0,0],[1,1,1e400]], "radius": 1}]})").find("number out of range"),
            std::string::npos);
  EXPECT_NE(message("{\"strokes\": " + std::string(100000, '[') + std::string(100000, ']') + "}")
                .find("nested more than 256 levels deep"),
            std::string::npos);
  EXPECT_EQ(load_strokes(test::temp_path("no_such_strokes.json"), back).code(), ErrorCode::kIo);
}

// === Load progress for OFF and STL (issue 18 point 5) ===========================================

// Loads `file` with a progress callback: every value in [0, 1], never going back, the last one 1;
// returns whether one came from the parse itself (strictly inside (0, 0.8), before the repairs).
bool expect_progress_complete(const std::string& file) {
  std::vector<float> seen;
  Mesh mesh;
  EXPECT_TRUE(load_mesh(file, mesh, nullptr,
                        [&seen](float f) {
                          seen.push_back(f);
                          return true;
                        })
                  .is_ok())
      << file;
  EXPECT_FALSE(mesh.empty()) << file;
  if (seen.empty()) {
    ADD_FAILURE() << file << ": no progress";
    return false;
  }
  bool from_parse = false;
  for (size_t i = 0; i < seen.size(); ++i) {
    EXPECT_TRUE(seen[i] >= 0.f && seen[i] <= 1.f) << file << " " << seen[i];
    if (i > 0) {
      EXPECT_GE(seen[i], seen[i - 1]) << file;
    }
    from_parse = from_parse || (seen[i] > 0.f && seen[i] < 0.8f);
  }
  EXPECT_EQ(seen.back(), 1.f) << file;
  return from_parse;
}

void expect_cancels(const std::string& file, float at) {
  Mesh mesh;
  const Status s = load_mesh(file, mesh, nullptr, [at](float f) { return f < at; });
  EXPECT_EQ(s.code(), ErrorCode::kCancelled) << file << " at " << at;
  EXPECT_TRUE(mesh.empty()) << file;
}

TEST(LoadProgress, OffAndStlReportAndCancel) {
  for (const char* name : {"fandisk.off", "blobby-3cc.off", "featuretype.stl", "adis16480.stl"}) {
    expect_progress_complete(mesh_path(name));
    expect_cancels(mesh_path(name), 0.f);   // in the parse
    expect_cancels(mesh_path(name), 0.9f);  // in the repairs
  }
}

TEST(LoadProgress, LargeOffAndStlReportWhileParsing) {
  // Files over the reporting step (a few MB): the parse itself reports, and cancelling there stops it.
  const std::string dir = test::empty_temp_dir("io_test_load_progress");
  const Mesh horse = load_test_mesh("horse.ply");
  // Binary STL of the horse (4.8 MB): the welding reports.
  std::string stl(80, 'x');
  const uint32_t nf = static_cast<uint32_t>(horse.face_count());
  stl.append(reinterpret_cast<const char*>(&nf), 4);
  for (size_t f = 0; f < nf; ++f) {
    float facet[12] = {};
    for (int k = 0; k < 3; ++k)
      std::memcpy(&facet[3 + 3 * k], &horse.positions[3 * size_t{horse.indices[3 * f + k]}], 12);
    stl.append(reinterpret_cast<const char*>(facet), sizeof(facet));
    stl.append(2, '\0');
  }
  // Ascii STL: adis16480.stl's facets three times over (6.4 MB).
  std::string ascii;
  ASSERT_TRUE(internal::read_file(mesh_path("adis16480.stl"), ascii).is_ok());
  ascii = ascii + "\n" + ascii + "\n" + ascii;  // the file ends without a newline
  // Ascii OFF of the horse, with face colours (over 4 MB).
  std::string off = "OFF\n" + std::to_string(horse.vertex_count()) + " " + std::to_string(nf) + " 0\n";
  char line[96];
  for (size_t v = 0; v < horse.vertex_count(); ++v) {
    std::snprintf(line, sizeof(line), "%.9g %.9g %.9g\n", horse.positions[3 * v], horse.positions[3 * v + 1],
                  horse.positions[3 * v + 2]);
    off += line;
  }
  for (size_t f = 0; f < nf; ++f) {
    std::snprintf(line, sizeof(line), "3 %u %u %u 0.5 0.5 0.5\n", horse.indices[3 * f], horse.indices[3 * f + 1],
                  horse.indices[3 * f + 2]);
    off += line;
  }
  ASSERT_GT(off.size(), size_t{4} << 20);
  const std::vector<std::pair<std::string, std::string>> files = {
      {dir + "/horse.stl", stl}, {dir + "/adis3.stl", ascii}, {dir + "/horse.off", off}};
  for (const auto& [path, bytes] : files) {
    std::ofstream(path, std::ios::binary) << bytes;
    EXPECT_TRUE(expect_progress_complete(path)) << path;
    expect_cancels(path, 0.01f);
  }
  Mesh mesh;
  ASSERT_TRUE(load_mesh(dir + "/horse.stl", mesh).is_ok());
  EXPECT_EQ(mesh.face_count(), horse.face_count());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tailor
