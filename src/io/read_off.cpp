// OFF reader (Geomview Object File Format): OFF, COFF, NOFF, CNOFF, STOFF, ... keywords, counts on
// the keyword line, the next or one per line, `#` comments, one vertex per line (extra values such as normals,
// colours or texture coordinates ignored), polygon faces fan-triangulated (concave ones cut again: polygon_fans.h),
// optional colour values after the face indices ignored. 4D (4OFF, nOFF with n != 3) and binary OFF are rejected.
#include <string_view>
#include <vector>

#include "io/readers.h"
#include "util/huge_pages.h"
#include "util/saturating.h"
#include "util/text_scan.h"

namespace tailor::internal {
namespace {

// Smallest ascii encodings: "0 0 0\n" for a vertex, "3 0 0 0\n" for a face.
constexpr uint64_t kMinVertexBytes = 6;
constexpr uint64_t kMinFaceBytes = 8;

}  // namespace

Status read_off(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress, PolygonFans* fans) {
  TextScanner s(data.data(), data.data() + data.size());
  s.set_hash_comments(true);
  s.skip_space();

  // === Keyword: [ST][C][N][4][n]OFF, optional (some writers start with the counts) ============
  const TextScanner start = s;
  const std::string_view kw = s.word();
  bool dimension_follows = false;
  if ((kw.size() >= 3 && kw.substr(kw.size() - 3) == "OFF") || kw == "off") {  // some writers use lower case
    std::string_view prefix = kw.substr(0, kw.size() - 3);
    if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
    if (!prefix.empty() && prefix[0] == 'C') prefix.remove_prefix(1);
    if (!prefix.empty() && prefix[0] == 'N') prefix.remove_prefix(1);
    if (!prefix.empty() && prefix[0] == '4') {
      return Status::error(ErrorCode::kUnsupported, name, "4D OFF files are not supported", s.where());
    }
    if (!prefix.empty() && prefix[0] == 'n') {
      prefix.remove_prefix(1);
      dimension_follows = true;
    }
    if (!prefix.empty())
      return Status::error(ErrorCode::kParse, name, "unknown OFF keyword " + quote_input(kw), s.where());
    report.format = kw == "OFF" || kw == "off" ? "OFF" : "OFF (" + std::string(kw) + ")";
    if (s.peek() == 'B') {
      return Status::error(ErrorCode::kUnsupported, name, "binary OFF files are not supported", s.where());
    }
  } else {
    s = start;
    report.format = "OFF (no keyword)";
  }
  s.skip_space();
  if (dimension_follows) {
    uint64_t dim = 0;
    if (!s.read_uint(dim)) return Status::error(ErrorCode::kParse, name, "bad OFF dimension", s.where());
    if (dim != 3)
      return Status::error(ErrorCode::kUnsupported, name, "OFF dimension " + std::to_string(dim) + " is not 3",
                           s.where());
    s.skip_space();
  }

  // === Counts ===================================================================================
  uint64_t nv = 0, nf = 0, ne = 0;
  if (!s.read_uint(nv))
    return Status::error(ErrorCode::kParse, name, "bad OFF header (expected vertex count)", s.where());
  s.skip_space();
  if (!s.read_uint(nf))
    return Status::error(ErrorCode::kParse, name, "bad OFF header (expected face count)", s.where());
  if (!s.at_line_end()) {
    if (!s.read_uint(ne))
      return Status::error(ErrorCode::kParse, name, "bad OFF header (expected edge count)", s.where());
  } else {
    // Counts one per line ("3\n1\n0", as some writers put them): a line of one whole number after
    // the face count is the edge count, never a vertex (which has three coordinates).
    TextScanner ahead = s;
    ahead.next_line();
    ahead.skip_space();
    if (uint64_t edges = 0; ahead.read_uint(edges) && ahead.at_line_end()) {
      ne = edges;
      s = ahead;
    }
  }
  // Vertices and faces are read a line each (the rest of a line ignored: colours, normals), so a
  // file that runs its data on after the counts would be misread from its first vertex on.
  if (!s.at_line_end())
    return Status::error(ErrorCode::kUnsupported, name,
                         "values after the OFF counts on their line (" + quote_input(s.word()) +
                             "...): this reader takes each vertex and each face on a line of its own",
                         s.where());
  s.next_line();
  // Checked before any allocation: the counts must fit in the bytes that are left.
  const uint64_t need = mul_sat(nv, kMinVertexBytes) + mul_sat(nf, kMinFaceBytes);
  if (need > s.remaining() + 2) {
    return Status::error(ErrorCode::kParse, name,
                         "OFF header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                             " faces, more than the file can hold (" + std::to_string(s.remaining()) + " bytes left)",
                         "line " + std::to_string(s.line() - 1));
  }
  if (nv > kMaxVertices)
    return Status::error(ErrorCode::kLimit, name, "too many vertices (" + std::to_string(nv) + ")");
  if (nf > kMaxFaces) return Status::error(ErrorCode::kLimit, name, "too many faces (" + std::to_string(nf) + ")");

  // === Vertices: x y z, then anything up to the end of the line =================================
  reserve_huge(mesh.positions, static_cast<size_t>(3 * nv));
  mesh.positions.resize(static_cast<size_t>(3 * nv));
  for (size_t i = 0; i < nv; ++i) {
    if (progress && !progress->at(data.size() - s.remaining())) return progress->cancelled(name);
    s.skip_space();
    if (s.at_end())
      return Status::error(ErrorCode::kParse, name, "unexpected end of file in vertex " + std::to_string(i), s.where());
    if (!s.read_float(mesh.positions[3 * i]) || !s.read_float(mesh.positions[3 * i + 1]) ||
        !s.read_float(mesh.positions[3 * i + 2])) {
      return Status::error(ErrorCode::kParse, name, "bad vertex " + std::to_string(i) + " (expected 3 numbers)",
                           s.where());
    }
    s.next_line();
  }

  // === Faces: n i0 .. i(n-1), then optional colour values =======================================
  reserve_huge(mesh.indices, static_cast<size_t>(3 * nf));
  std::vector<uint32_t> poly;
  for (size_t f = 0; f < nf; ++f) {
    if (progress && !progress->at(data.size() - s.remaining())) return progress->cancelled(name);
    s.skip_space();
    if (s.at_end())
      return Status::error(ErrorCode::kParse, name, "unexpected end of file in face " + std::to_string(f), s.where());
    uint64_t n = 0;
    if (!s.read_uint(n))
      return Status::error(ErrorCode::kParse, name, "bad face " + std::to_string(f) + " (expected a vertex count)",
                           s.where());
    if (n < 3)
      return Status::error(ErrorCode::kInvalidMesh, name, "face with " + std::to_string(n) + " vertices", s.where());
    if (mul_sat(n, 2) > s.remaining() + 1) {
      return Status::error(ErrorCode::kParse, name,
                           "face of " + std::to_string(n) + " vertices runs past the end of the file", s.where());
    }
    poly.resize(static_cast<size_t>(n));
    for (size_t k = 0; k < n; ++k) {
      uint64_t v = 0;
      if (!s.read_uint(v)) {
        return Status::error(ErrorCode::kParse, name,
                             "bad face " + std::to_string(f) + " (expected " + std::to_string(n) + " vertex indices)",
                             s.where());
      }
      if (v >= nv) {
        return Status::error(
            ErrorCode::kInvalidMesh, name,
            "face index " + std::to_string(v) + " out of range (mesh has " + std::to_string(nv) + " vertices)",
            s.where());
      }
      poly[k] = static_cast<uint32_t>(v);
    }
    ++report.source_faces;
    if (n > 3) ++report.polygons_triangulated;
    if (n > 3 && fans) fans->add(mesh.face_count(), n);
    for (size_t k = 1; k + 1 < n; ++k) mesh.indices.insert(mesh.indices.end(), {poly[0], poly[k], poly[k + 1]});
    if (mesh.indices.size() / 3 > kMaxFaces) return Status::error(ErrorCode::kLimit, name, "too many faces", s.where());
    s.next_line();
  }
  // What follows the faces the header declares is not read: a header that counts too few faces
  // would lose the rest without a word.
  if (const std::string rest =
          lines_after(s, 0, std::to_string(nf) + (nf == 1 ? " face" : " faces") + " the OFF header declares");
      !rest.empty())
    add_not_read(report, rest);
  return Status::ok();
}

}  // namespace tailor::internal
