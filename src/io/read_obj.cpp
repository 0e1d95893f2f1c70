// Wavefront OBJ reader: `v`, `vt` and `f` statements (v, v/vt, v//vn, v/vt/vn corners, negative
// indices relative to the current counts), polygons fan-triangulated (concave ones cut again: polygon_fans.h), `\r\n`
// line ends, `#` comments, backslash line continuation. Vertex colours (`v x y z r g b [a]`) and normals (`vn`, when
// every corner names one) are kept as COLOR_0 and NORMAL corner attributes. `o`, `g`, `s`, `usemtl`, `l`, `p` and any
// other statement are ignored; the first `mtllib`'s file name is handed back (load_mesh reads that .mtl's texture size,
// read_mesh.cpp).
//
// Hand-written instead of tinyobjloader (which Debian ships): tinyobjloader reports bad indices as
// warnings without line numbers (or silently clamps them), stores per-shape index structs that we
// would copy again, and its float parser is slower than fast_float. This reader is a single pass
// over the bytes with exact float parsing (fast_float) and line-accurate errors.
#include <algorithm>
#include <cstring>
#include <string_view>
#include <vector>

#include "io/readers.h"
#include "util/text_scan.h"

namespace tailor::internal {
namespace {

// A positive index that refers past the elements defined so far (legal if defined later);
// checked once the whole file is read.
struct ForwardRef {
  uint64_t index;  // 0-based
  size_t line;
};

std::string out_of_range_text(const char* what, int64_t index, size_t count) {
  const std::string kind = what[0] == 'f' ? " vertices)" : what[0] == 'n' ? " normals)" : " texture coordinates)";
  return std::string(what) + " index " + std::to_string(index) + " out of range (mesh has " + std::to_string(count) +
         kind;
}

// Resolves a 1-based or negative OBJ index against the current count; returns false when it
// cannot be valid (0, or negative past the start).
bool resolve(int64_t raw, size_t count, uint64_t& out) {
  if (raw > 0) {
    out = static_cast<uint64_t>(raw - 1);
    return out < kMaxVertices;
  }
  if (raw < 0 && static_cast<uint64_t>(-(raw + 1)) < count) {
    out = count - static_cast<uint64_t>(-(raw + 1)) - 1;
    return true;
  }
  return false;
}

}  // namespace

Status read_obj(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress, std::string* material_library, PolygonFans* fans) {
  if (material_library) material_library->clear();
  report.format = "OBJ";
  // A UTF-8 byte order mark (editors on Windows write one) is not part of the first line.
  if (data.size() >= 3 && static_cast<unsigned char>(data[0]) == 0xEF && static_cast<unsigned char>(data[1]) == 0xBB &&
      static_cast<unsigned char>(data[2]) == 0xBF)
    data = data.subspan(3);
  // Lines that end in CR alone (classic Mac OS) would read as one line: said, not misread.
  if (std::memchr(data.data(), '\n', data.size()) == nullptr && std::memchr(data.data(), '\r', data.size()) != nullptr)
    return Status::error(ErrorCode::kParse, name, "its lines end in CR alone (classic Mac OS): convert them to LF");
  TextScanner s(data.data(), data.data() + data.size());
  s.set_hash_comments(true);
  s.set_line_continuation(true);

  std::vector<float> texcoords;     // #VT by 2
  std::vector<uint32_t> corner_vt;  // per triangle corner: vt index or kInvalid
  std::vector<ForwardRef> forward_v, forward_vt;
  std::vector<uint32_t> poly, poly_vt;
  size_t corners_without_vt = 0;  // once nonzero, corner_vt is dropped and no longer filled
  size_t faces_lacking_vt = 0;    // source faces with a corner without vt
  // Kept attributes: vertex colours (`v x y z r g b [a]`, when every vertex has them) and normals
  // (`vn`, referenced by every face corner as v/vt/vn or v//vn).
  std::vector<float> colours, normals;  // #V by 4 (alpha 1 when not given), #VN by 3
  size_t vertices_without_colour = 0;
  std::vector<uint32_t> corner_vn, poly_vn;
  std::vector<ForwardRef> forward_vn;
  size_t corners_without_vn = 0;

  while (!s.at_end()) {
    if (progress && !progress->at(data.size() - s.remaining())) return progress->cancelled(name);
    const std::string_view w = s.word();
    if (w.empty()) {
      s.next_line();
      continue;
    }
    if (w == "v") {
      float x, y, z;
      if (!s.read_float(x) || !s.read_float(y) || !s.read_float(z)) {
        return Status::error(ErrorCode::kParse, name, "bad vertex line (expected 3 numbers)", s.where());
      }
      mesh.positions.insert(mesh.positions.end(), {x, y, z});
      float rgba[4] = {0.f, 0.f, 0.f, 1.f};
      int extra = 0;
      while (extra < 4 && !s.at_line_end() && s.read_float(rgba[extra])) ++extra;
      if ((extra == 3 || extra == 4) && s.at_line_end())
        colours.insert(colours.end(), rgba, rgba + 4);
      else
        ++vertices_without_colour;
    } else if (w == "vn") {
      float n[3];
      if (!s.read_float(n[0]) || !s.read_float(n[1]) || !s.read_float(n[2]))
        return Status::error(ErrorCode::kParse, name, "bad normal line (expected 3 numbers)", s.where());
      normals.insert(normals.end(), n, n + 3);
    } else if (w == "vt") {
      float u, v = 0.0f;
      if (!s.read_float(u)) return Status::error(ErrorCode::kParse, name, "bad texture coordinate line", s.where());
      if (!s.at_line_end() && !s.read_float(v)) {
        return Status::error(ErrorCode::kParse, name, "bad texture coordinate line", s.where());
      }
      texcoords.insert(texcoords.end(), {u, v});
    } else if (w == "f") {
      poly.clear();
      poly_vt.clear();
      poly_vn.clear();
      const size_t nv = mesh.positions.size() / 3, nt = texcoords.size() / 2, nn = normals.size() / 3;
      while (!s.at_line_end()) {
        int64_t raw = 0;
        uint64_t vi = 0, ti = kInvalid, ni = kInvalid;
        if (!s.read_int(raw, false)) return Status::error(ErrorCode::kParse, name, "bad face corner", s.where());
        if (!resolve(raw, nv, vi)) {
          return Status::error(ErrorCode::kInvalidMesh, name, out_of_range_text("face", raw, nv), s.where());
        }
        if (vi >= nv) forward_v.push_back({vi, s.line()});
        if (s.consume('/')) {
          if (s.at_token_end()) return Status::error(ErrorCode::kParse, name, "bad face corner", s.where());
          if (*s.pos() != '/') {
            if (!s.read_int(raw, false)) return Status::error(ErrorCode::kParse, name, "bad face corner", s.where());
            if (!resolve(raw, nt, ti)) {
              return Status::error(ErrorCode::kInvalidMesh, name, out_of_range_text("texture", raw, nt), s.where());
            }
            if (ti >= nt) forward_vt.push_back({ti, s.line()});
          }
          if (s.consume('/')) {
            int64_t normal = 0;
            if (!s.read_int(normal, false)) return Status::error(ErrorCode::kParse, name, "bad face corner", s.where());
            if (!resolve(normal, nn, ni))
              return Status::error(ErrorCode::kInvalidMesh, name, out_of_range_text("normal", normal, nn), s.where());
            if (ni >= nn) forward_vn.push_back({ni, s.line()});
          }
        }
        if (!s.at_token_end()) return Status::error(ErrorCode::kParse, name, "bad face corner", s.where());
        poly.push_back(static_cast<uint32_t>(vi));
        poly_vt.push_back(static_cast<uint32_t>(ti));
        poly_vn.push_back(static_cast<uint32_t>(ni));
      }
      const size_t n = poly.size();
      if (n < 3) {
        return Status::error(ErrorCode::kInvalidMesh, name, "face with " + std::to_string(n) + " vertices", s.where());
      }
      ++report.source_faces;
      if (n > 3) ++report.polygons_triangulated;
      if (n > 3 && fans) fans->add(mesh.face_count(), n);
      for (size_t k = 1; k + 1 < n; ++k) mesh.indices.insert(mesh.indices.end(), {poly[0], poly[k], poly[k + 1]});
      const bool lacks_vt = std::find(poly_vt.begin(), poly_vt.end(), kInvalid) != poly_vt.end();
      faces_lacking_vt += lacks_vt;
      if (corners_without_vt == 0) {
        for (uint32_t t : poly_vt) corners_without_vt += t == kInvalid;
        if (corners_without_vt == 0) {
          for (size_t k = 1; k + 1 < n; ++k)
            corner_vt.insert(corner_vt.end(), {poly_vt[0], poly_vt[k], poly_vt[k + 1]});
        } else {
          std::vector<uint32_t>().swap(corner_vt);  // no uvs after all: stop recording them
        }
      }
      if (corners_without_vn == 0) {
        for (uint32_t t : poly_vn) corners_without_vn += t == kInvalid;
        if (corners_without_vn == 0) {
          for (size_t k = 1; k + 1 < n; ++k)
            corner_vn.insert(corner_vn.end(), {poly_vn[0], poly_vn[k], poly_vn[k + 1]});
        } else {
          std::vector<uint32_t>().swap(corner_vn);
        }
      }
      if (mesh.indices.size() / 3 > kMaxFaces)
        return Status::error(ErrorCode::kLimit, name, "too many faces", s.where());
    } else if (w == "mtllib" && material_library && material_library->empty()) {
      s.skip_blanks();  // the file name: the rest of the line (names may hold blanks)
      const char* b = s.pos();
      const char* e = b;
      while (e < s.end() && *e != '\n' && *e != '#') ++e;
      while (e > b && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r')) --e;
      material_library->assign(b, static_cast<size_t>(e - b));
    }
    // Every other statement (vn, o, g, s, usemtl, l, p, unknown ones) is skipped.
    s.next_line();
  }

  // Positive indices may refer to elements defined further down; check them now.
  const size_t nv = mesh.positions.size() / 3, nt = texcoords.size() / 2;
  for (const ForwardRef& r : forward_v) {
    if (r.index >= nv) {
      return Status::error(ErrorCode::kInvalidMesh, name,
                           out_of_range_text("face", static_cast<int64_t>(r.index + 1), nv),
                           "line " + std::to_string(r.line));
    }
  }
  for (const ForwardRef& r : forward_vt) {
    if (r.index >= nt) {
      return Status::error(ErrorCode::kInvalidMesh, name,
                           out_of_range_text("texture", static_cast<int64_t>(r.index + 1), nt),
                           "line " + std::to_string(r.line));
    }
  }
  for (const ForwardRef& r : forward_vn) {
    if (r.index >= normals.size() / 3) {
      return Status::error(ErrorCode::kInvalidMesh, name,
                           out_of_range_text("normal", static_cast<int64_t>(r.index + 1), normals.size() / 3),
                           "line " + std::to_string(r.line));
    }
  }
  if (!mesh.indices.empty() && corners_without_vn == 0 && corner_vn.size() == mesh.indices.size()) {
    CornerAttribute& a = mesh.corner_attributes.emplace_back(CornerAttribute{"NORMAL", 3, {}});
    a.values.resize(3 * corner_vn.size());
    for (size_t c = 0; c < corner_vn.size(); ++c) std::memcpy(&a.values[3 * c], &normals[3 * corner_vn[c]], 12);
  }
  if (!mesh.indices.empty() && vertices_without_colour == 0 && 3 * colours.size() == 4 * mesh.positions.size()) {
    CornerAttribute& a = mesh.corner_attributes.emplace_back(CornerAttribute{"COLOR_0", 4, {}});
    a.values.resize(4 * mesh.indices.size());
    for (size_t c = 0; c < mesh.indices.size(); ++c)
      std::memcpy(&a.values[4 * c], &colours[4 * size_t{mesh.indices[c]}], 16);
  }
  // Corner uvs only when every corner has one: a partial set cannot be used as a mapping.
  if (faces_lacking_vt < report.source_faces) report.faces_without_uv = faces_lacking_vt;
  if (!mesh.indices.empty() && corners_without_vt == 0) {
    mesh.corner_uvs.resize(2 * corner_vt.size());
    for (size_t c = 0; c < corner_vt.size(); ++c) {
      mesh.corner_uvs[2 * c] = texcoords[2 * corner_vt[c]];
      mesh.corner_uvs[2 * c + 1] = texcoords[2 * corner_vt[c] + 1];
    }
  }
  return Status::ok();
}

}  // namespace tailor::internal
