// STL reader, ascii and binary. STL stores three positions per facet and no shared vertices, so
// corners with identical positions are welded into one vertex (a flat open-addressing hash keyed
// on the 12 position bytes, -0.0 read as 0.0).
//
// Binary or ascii is decided by size, not by the "solid" prefix: many binary files start their
// 80-byte header with "solid". A file is binary when 84 + 50 * n == size (n = the count at byte
// 80); otherwise ascii if it starts with "solid"; otherwise binary with a size check.
#include <cstring>
#include <string_view>
#include <vector>

#include "io/readers.h"
#include "util/flat_hash.h"
#include "util/text_scan.h"

namespace tailor::internal {
namespace {

constexpr size_t kBinaryHeader = 84;
constexpr size_t kBinaryFacet = 50;  // normal, 3 positions (12 floats), 2 attribute bytes

// Welds corner positions (#corners by 3) into mesh.positions / mesh.indices, in order of first use.
// progress (binary files, whose copy is instant and whose welding is the work): told the bytes of
// the facets welded, every 64k corners.
Status weld(const std::vector<float>& corners, const std::string& name, Mesh& mesh, LoadReport& report,
            ReadProgress* progress) {
  const size_t nc = corners.size() / 3;
  FlatIdTable table(nc);
  mesh.indices.resize(nc);
  mesh.positions.reserve(corners.size());
  for (size_t c = 0; c < nc; ++c) {
    if (progress && c % 65536 == 0 && !progress->at(kBinaryHeader + c / 3 * kBinaryFacet)) {
      return progress->cancelled(name);
    }
    // + 0.0f turns -0 into +0: the same point, which exporters write either way.
    const float p[3] = {corners[3 * c] + 0.0f, corners[3 * c + 1] + 0.0f, corners[3 * c + 2] + 0.0f};
    uint32_t bits[3];
    std::memcpy(bits, p, 12);
    const uint64_t h = hash_mix((uint64_t{bits[0]} << 32 | bits[1]) ^ hash_mix(bits[2]));
    const uint32_t next = static_cast<uint32_t>(mesh.positions.size() / 3);
    const uint32_t id = table.find_or_insert(
        h, next, [&](uint32_t stored) { return std::memcmp(&mesh.positions[3 * size_t{stored}], bits, 12) == 0; });
    if (id == next) mesh.positions.insert(mesh.positions.end(), {p[0], p[1], p[2]});
    mesh.indices[c] = id;
  }
  report.welded_vertices = nc - mesh.positions.size() / 3;
  return Status::ok();
}

// ASCII STL keywords in any case: some CAD exporters write SOLID, FACET, VERTEX.
bool is_keyword(std::string_view w, std::string_view keyword) {
  if (w.size() != keyword.size()) return false;
  for (size_t i = 0; i < w.size(); ++i)
    if ((w[i] >= 'A' && w[i] <= 'Z' ? w[i] - 'A' + 'a' : w[i]) != keyword[i]) return false;
  return true;
}

bool starts_with_solid(std::string_view s) {
  size_t i = 0;
  while (i < s.size() && (is_blank(s[i]) || s[i] == '\n')) ++i;
  return is_keyword(s.substr(i, 5), "solid");
}

Status read_binary(std::span<const char> data, const std::string& name, std::vector<float>& corners,
                   LoadReport& report) {
  report.format = "STL binary";
  uint32_t n = 0;
  std::memcpy(&n, data.data() + 80, 4);
  const uint64_t need = kBinaryHeader + kBinaryFacet * uint64_t{n};
  if (need > data.size()) {
    // Text is not a binary STL whose count is off: say what it lacks to be ascii STL.
    if (std::memchr(data.data(), '\0', data.size()) == nullptr)
      return Status::error(ErrorCode::kParse, name, "not an STL file: text without the 'solid' keyword of ascii STL");
    return Status::error(ErrorCode::kParse, name,
                         "binary STL header declares " + std::to_string(n) + " triangles (" + std::to_string(need) +
                             " bytes) but the file has " + std::to_string(data.size()) + " bytes");
  }
  if (n > kMaxFaces) return Status::error(ErrorCode::kLimit, name, "too many faces (" + std::to_string(n) + ")");
  corners.resize(size_t{9} * n);
  const char* p = data.data() + kBinaryHeader;
  for (size_t f = 0; f < n; ++f, p += kBinaryFacet) std::memcpy(&corners[9 * f], p + 12, 36);
  report.source_faces = n;
  // A header that counts too few triangles would lose the rest without a word.
  if (data.size() > need)
    add_not_read(report, std::to_string(data.size() - need) + " bytes after the " + std::to_string(n) +
                             (n == 1 ? " triangle" : " triangles") + " the binary STL header declares");
  return Status::ok();
}

Status read_ascii(std::span<const char> data, const std::string& name, std::vector<float>& corners, LoadReport& report,
                  ReadProgress* progress) {
  report.format = "STL ascii";
  TextScanner s(data.data(), data.data() + data.size());
  std::vector<float> loop;
  auto expect = [&](std::string_view word) -> Status {
    s.skip_space();
    const std::string_view w = s.word();
    if (!is_keyword(w, word)) {
      return Status::error(ErrorCode::kParse, name,
                           "expected '" + std::string(word) + "' in ascii STL, found " + quote_input(w, 32), s.where());
    }
    return Status::ok();
  };
  auto bad_number = [&]() { return Status::error(ErrorCode::kParse, name, "bad number in ascii STL", s.where()); };
  for (;;) {
    if (progress && !progress->at(data.size() - s.remaining())) return progress->cancelled(name);
    s.skip_space();
    if (s.at_end()) break;
    const std::string_view w = s.word();
    if (is_keyword(w, "solid") || is_keyword(w, "endsolid")) {
      s.next_line();  // the solid's name, if any
      continue;
    }
    if (!is_keyword(w, "facet")) {
      return Status::error(ErrorCode::kParse, name, "expected 'facet' in ascii STL, found " + quote_input(w, 32),
                           s.where());
    }
    TAILOR_RETURN_IF_ERROR(expect("normal"));
    float ignored;
    for (int k = 0; k < 3; ++k) {
      if (!s.read_float(ignored)) return bad_number();
    }
    TAILOR_RETURN_IF_ERROR(expect("outer"));
    TAILOR_RETURN_IF_ERROR(expect("loop"));
    loop.clear();
    for (;;) {
      s.skip_space();
      const std::string_view v = s.word();
      if (is_keyword(v, "endloop")) break;
      if (!is_keyword(v, "vertex")) {
        return Status::error(ErrorCode::kParse, name, "expected 'vertex' or 'endloop' in ascii STL", s.where());
      }
      float x, y, z;
      s.skip_space();
      if (!s.read_float(x) || !s.read_float(y) || !s.read_float(z)) return bad_number();
      loop.insert(loop.end(), {x, y, z});
    }
    const size_t n = loop.size() / 3;
    if (n < 3)
      return Status::error(ErrorCode::kInvalidMesh, name, "facet with " + std::to_string(n) + " vertices", s.where());
    TAILOR_RETURN_IF_ERROR(expect("endfacet"));
    ++report.source_faces;
    if (n > 3) ++report.polygons_triangulated;
    for (size_t k = 1; k + 1 < n; ++k) {  // fan triangulation of a polygonal loop
      corners.insert(corners.end(), loop.begin(), loop.begin() + 3);
      corners.insert(corners.end(), loop.begin() + static_cast<std::ptrdiff_t>(3 * k),
                     loop.begin() + static_cast<std::ptrdiff_t>(3 * k + 6));
    }
    if (corners.size() / 9 > kMaxFaces) return Status::error(ErrorCode::kLimit, name, "too many faces", s.where());
  }
  return Status::ok();
}

}  // namespace

Status read_stl(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress) {
  const std::string_view text(data.data(), data.size());
  bool binary = false;
  if (data.size() >= kBinaryHeader) {
    uint32_t n = 0;
    std::memcpy(&n, data.data() + 80, 4);
    // ASCII STL never holds a NUL byte; binary facets nearly always do (zero coordinates,
    // attribute bytes), which catches truncated binary files whose header says "solid".
    binary = kBinaryHeader + kBinaryFacet * uint64_t{n} == data.size() || !starts_with_solid(text) ||
             std::memchr(data.data(), '\0', data.size()) != nullptr;
  }
  if (!binary && !starts_with_solid(text)) {
    return Status::error(ErrorCode::kParse, name, "not an STL file (too short for binary, no 'solid' keyword)");
  }
  std::vector<float> corners;
  if (binary)
    TAILOR_RETURN_IF_ERROR(read_binary(data, name, corners, report));
  else
    TAILOR_RETURN_IF_ERROR(read_ascii(data, name, corners, report, progress));
  return weld(corners, name, mesh, report, binary ? progress : nullptr);
}

}  // namespace tailor::internal
