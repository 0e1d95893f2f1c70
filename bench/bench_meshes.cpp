// Shared benchmark meshes (see bench_meshes.h).
#include "bench_meshes.h"

#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "tailor/io.h"
#include "util/atomic_file.h"
#include "util/flat_hash.h"

namespace {

using tailor::Mesh;
using tailor::Status;
namespace internal = tailor::internal;

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "bench: %s\n", what.c_str());
  std::exit(1);
}

// One 1-to-4 midpoint subdivision: each edge gets one new vertex (shared by its two faces), each
// triangle (a b c) becomes (a ab ca) (ab b bc) (ca bc c) (ab bc ca), keeping the winding.
Mesh subdivide(const Mesh& in) {
  Mesh out;
  out.positions = in.positions;
  const size_t nf = in.face_count();
  std::vector<std::array<uint32_t, 2>> edges;  // key of each midpoint vertex, by id - #V
  edges.reserve(3 * nf / 2 + 16);
  internal::FlatIdTable table(3 * nf);
  const uint32_t base = static_cast<uint32_t>(in.vertex_count());
  auto midpoint = [&](uint32_t a, uint32_t b) {
    const std::array<uint32_t, 2> key{std::min(a, b), std::max(a, b)};
    const uint32_t next = base + static_cast<uint32_t>(edges.size());
    const uint32_t id = table.find_or_insert(internal::hash_mix(uint64_t{key[0]} << 32 | key[1]), next,
                                             [&](uint32_t stored) { return edges[stored - base] == key; });
    if (id == next) {
      edges.push_back(key);
      for (int k = 0; k < 3; ++k) out.positions.push_back(0.5f * (in.positions[3 * a + k] + in.positions[3 * b + k]));
    }
    return id;
  };
  out.indices.reserve(4 * in.indices.size());
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t a = in.indices[3 * f], b = in.indices[3 * f + 1], c = in.indices[3 * f + 2];
    const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    out.indices.insert(out.indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
  }
  return out;
}

std::string binary_ply(const Mesh& m) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(m.vertex_count()) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(m.face_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  const size_t header = s.size();
  s.resize(header + 4 * m.positions.size() + 13 * m.face_count());
  char* p = s.data() + header;
  std::memcpy(p, m.positions.data(), 4 * m.positions.size());
  p += 4 * m.positions.size();
  for (size_t f = 0; f < m.face_count(); ++f, p += 13) {
    p[0] = 3;
    std::memcpy(p + 1, &m.indices[3 * f], 12);
  }
  return s;
}

std::string obj_text(const Mesh& m) {
  std::string s;
  char buf[96];
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const int n = std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", m.positions[3 * v], m.positions[3 * v + 1],
                                m.positions[3 * v + 2]);
    s.append(buf, static_cast<size_t>(n));
  }
  for (size_t f = 0; f < m.face_count(); ++f) {
    const int n = std::snprintf(buf, sizeof buf, "f %u %u %u\n", m.indices[3 * f] + 1, m.indices[3 * f + 1] + 1,
                                m.indices[3 * f + 2] + 1);
    s.append(buf, static_cast<size_t>(n));
  }
  return s;
}

// A per-process directory for the written files, removed when the process exits.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    path = std::filesystem::temp_directory_path() / ("tailor-bench-" + std::to_string(static_cast<long>(getpid())));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

std::string write_once(const std::string& file, std::string (*encode)(const Mesh&)) {
  static TempDir dir;
  const std::string path = (dir.path / file).string();
  const Status s = internal::write_file_atomic(path, encode(subdivided_horse()));
  if (!s.is_ok()) die(s.message());
  return path;
}

}  // namespace

const tailor::Mesh& subdivided_horse() {
  static const Mesh mesh = [] {
    Mesh horse;
    const std::string path = std::string(TAILOR_SOURCE_DIR) + "/tests/data/meshes/horse.ply";
    const Status s = tailor::load_mesh(path, horse);
    if (!s.is_ok()) die(s.message());
    return subdivide(subdivide(horse));
  }();
  return mesh;
}

const std::string& subdivided_horse_ply_path() {
  static const std::string path = write_once("horse-x16.ply", binary_ply);
  return path;
}

const std::string& subdivided_horse_obj_path() {
  static const std::string path = write_once("horse-x16.obj", obj_text);
  return path;
}

tailor::Status write_subdivided_horse_ply(const std::string& path) {
  return internal::write_file_atomic(path, binary_ply(subdivided_horse()));
}

tailor::Status write_subdivided_ply(const std::string& path, const std::string& input, int levels) {
  Mesh mesh;
  TAILOR_RETURN_IF_ERROR(tailor::load_mesh(input, mesh));
  for (int i = 0; i < levels; ++i) {
    if (mesh.face_count() > (size_t{1} << 30) / 4)
      return Status::error(tailor::ErrorCode::kInvalidArgument, input, "more than 2^30 faces after subdividing");
    mesh = subdivide(mesh);
  }
  return internal::write_file_atomic(path, binary_ply(mesh));
}
