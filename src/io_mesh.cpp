// Mesh loading front end: format detection, dispatch to the per-format parsers, and the
// validation / repair pass shared by all of them (finalize_mesh). See include/tailor/io.h.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>
#include <string_view>

#include "internal/atomic_file.h"
#include "internal/readers.h"
#include "tailor/io.h"

namespace tailor {
namespace {

constexpr const char* kSupported = "supported: .ply .obj .off .stl .glb";

bool ends_with_ci(const std::string& s, std::string_view suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i) {
    char c = s[s.size() - suffix.size() + i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != suffix[i]) return false;
  }
  return true;
}

// True when the first word of the data is an OFF keyword: [ST][C][N][4][n]OFF.
bool starts_with_off_keyword(std::string_view s) {
  size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r' || s[i] == '\n')) ++i;
  size_t j = i;
  while (j < s.size() && j - i < 16 && s[j] > ' ') ++j;
  const std::string_view w = s.substr(i, j - i);
  return w.size() >= 3 && w.substr(w.size() - 3) == "OFF" && w.size() <= 9;
}

MeshFormat sniff_format(std::span<const char> data) {
  const std::string_view s(data.data(), data.size());
  if (s.size() >= 4 && s.substr(0, 3) == "ply" && (s[3] == '\n' || s[3] == '\r')) return MeshFormat::kPly;
  if (s.size() >= 4 && s.substr(0, 4) == "glTF") return MeshFormat::kGlb;
  if (s.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, s.data() + 80, 4);
    if (84 + 50 * uint64_t{n} == s.size()) return MeshFormat::kStl;
  }
  if (starts_with_off_keyword(s)) return MeshFormat::kOff;
  size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r' || s[i] == '\n')) ++i;
  if (s.substr(i, 5) == "solid") return MeshFormat::kStl;
  return MeshFormat::kUnknown;
}

// Duplicate detection entry: a non-degenerate face keyed by its sorted vertex triple; faces are
// bucketed by the smallest vertex (counting sort), so only mid/max and the face id are stored.
struct FaceKey {
  uint32_t mid;
  uint32_t max;
  uint32_t face;
};

// Buckets with more entries than this are sorted; smaller ones are compared pairwise.
constexpr size_t kPairwiseBucket = 16;

}  // namespace

MeshFormat mesh_format_from_path(const std::string& path) {
  if (ends_with_ci(path, ".ply")) return MeshFormat::kPly;
  if (ends_with_ci(path, ".obj")) return MeshFormat::kObj;
  if (ends_with_ci(path, ".off")) return MeshFormat::kOff;
  if (ends_with_ci(path, ".stl")) return MeshFormat::kStl;
  if (ends_with_ci(path, ".glb")) return MeshFormat::kGlb;
  return MeshFormat::kUnknown;
}

Status read_mesh(std::span<const char> data, MeshFormat format, const std::string& name, Mesh& mesh,
                 LoadReport* report) {
  mesh = Mesh{};
  LoadReport local;
  LoadReport& r = report ? *report : local;
  r = LoadReport{};
  r.file_bytes = data.size();
  if (format == MeshFormat::kUnknown) format = sniff_format(data);
  Status s;
  // The parsers never throw by design; only an allocation of a (checked, but large) size can.
  try {
    switch (format) {
      case MeshFormat::kPly: s = internal::read_ply(data, name, mesh, r); break;
      case MeshFormat::kObj: s = internal::read_obj(data, name, mesh, r); break;
      case MeshFormat::kOff: s = internal::read_off(data, name, mesh, r); break;
      case MeshFormat::kStl: s = internal::read_stl(data, name, mesh, r); break;
      case MeshFormat::kGlb: s = internal::read_glb(data, name, mesh, r); break;
      case MeshFormat::kUnknown:
        s = Status::error(ErrorCode::kUnsupported, name, std::string("unknown mesh format (") + kSupported + ")");
        break;
    }
    if (s.is_ok()) s = finalize_mesh(name, mesh, r);
  } catch (const std::bad_alloc&) {
    s = Status::error(ErrorCode::kLimit, name, "not enough memory to load the mesh");
  } catch (...) {
    s = Status::error(ErrorCode::kParse, name, "unexpected failure while parsing");
  }
  if (!s.is_ok()) {
    mesh = Mesh{};
    return s.with_file(name);
  }
  return s;
}

Status load_mesh(const std::string& path, Mesh& mesh, LoadReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  mesh = Mesh{};
  std::string bytes;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, bytes));
  MeshFormat format = mesh_format_from_path(path);
  if (format == MeshFormat::kUnknown) {
    format = sniff_format(bytes);
    if (format == MeshFormat::kUnknown) {
      return Status::error(ErrorCode::kUnsupported, path,
                           std::string("unknown mesh file extension and content (") + kSupported + ")");
    }
  }
  LoadReport local;
  LoadReport& r = report ? *report : local;
  const Status s = read_mesh(bytes, format, path, mesh, &r);
  r.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

Status finalize_mesh(const std::string& name, Mesh& mesh, LoadReport& report) {
  // === Shape and limits =========================================================================
  if (mesh.positions.size() % 3 != 0 || mesh.indices.size() % 3 != 0) {
    return Status::error(ErrorCode::kInvalidMesh, name, "position or index array not a multiple of 3");
  }
  const size_t nv = mesh.vertex_count();
  const size_t nf = mesh.face_count();
  if (nv > kMaxVertices) {
    return Status::error(ErrorCode::kLimit, name, "too many vertices (" + std::to_string(nv) + ")");
  }
  if (nf > kMaxFaces) {
    return Status::error(ErrorCode::kLimit, name, "too many faces (" + std::to_string(nf) + ")");
  }
  if (!mesh.corner_uvs.empty() && mesh.corner_uvs.size() != nf * 6) {
    return Status::error(ErrorCode::kInvalidMesh, name, "corner texture coordinates do not match the faces");
  }
  if (!mesh.seam_faces.empty() && mesh.seam_faces.size() != nf) {
    return Status::error(ErrorCode::kInvalidMesh, name, "seam flags do not match the faces");
  }
  if (nf == 0) return Status::error(ErrorCode::kInvalidMesh, name, "mesh has no faces");

  // === Finite coordinates ========================================================================
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    if (!std::isfinite(mesh.positions[i])) {
      return Status::error(ErrorCode::kInvalidMesh, name, "non-finite vertex coordinate",
                           "vertex " + std::to_string(i / 3));
    }
  }
  for (size_t i = 0; i < mesh.corner_uvs.size(); ++i) {
    if (!std::isfinite(mesh.corner_uvs[i])) {
      return Status::error(ErrorCode::kInvalidMesh, name, "non-finite texture coordinate",
                           "face " + std::to_string(i / 6));
    }
  }

  // === Index range, degenerate faces, buckets by smallest vertex ================================
  const uint32_t* idx = mesh.indices.data();
  std::vector<uint8_t> keep(nf, 1);
  std::vector<uint32_t> bucket_start(nv + 1, 0);
  size_t degenerate = 0;
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
    if (a >= nv || b >= nv || c >= nv) {
      const uint32_t bad = a >= nv ? a : (b >= nv ? b : c);
      return Status::error(ErrorCode::kInvalidMesh, name,
                           "face index " + std::to_string(bad) + " out of range (mesh has " + std::to_string(nv) +
                               " vertices)",
                           "face " + std::to_string(f));
    }
    if (a == b || b == c || a == c) {
      keep[f] = 0;
      ++degenerate;
      continue;
    }
    ++bucket_start[std::min(a, std::min(b, c)) + 1];
  }
  for (size_t v = 0; v < nv; ++v) bucket_start[v + 1] += bucket_start[v];

  // === Exact duplicates (same vertex set, any order): keep the first, drop the later ones =======
  // Counting sort by smallest vertex instead of a hash of the triple: meshes store faces with
  // vertex locality, so the buckets are filled almost sequentially (a hashed table of 1.5M keys
  // costs a cache miss per face), and an adversarial fan degrades to one O(k log k) sort, not to
  // quadratic probing.
  std::vector<FaceKey> keys(nf - degenerate);
  {
    std::vector<uint32_t> fill(bucket_start.begin(), bucket_start.end() - 1);
    for (size_t f = 0; f < nf; ++f) {
      if (!keep[f]) continue;
      std::array<uint32_t, 3> t{idx[3 * f], idx[3 * f + 1], idx[3 * f + 2]};
      if (t[0] > t[1]) std::swap(t[0], t[1]);
      if (t[1] > t[2]) std::swap(t[1], t[2]);
      if (t[0] > t[1]) std::swap(t[0], t[1]);
      keys[fill[t[0]]++] = FaceKey{t[1], t[2], static_cast<uint32_t>(f)};
    }
  }
  size_t duplicates = 0;
  std::vector<FaceKey> scratch;
  for (size_t v = 0; v < nv; ++v) {
    const size_t b = bucket_start[v], e = bucket_start[v + 1];
    const size_t k = e - b;
    if (k < 2) continue;
    if (k <= kPairwiseBucket) {
      // Entries are in increasing face order, so an entry equal to an earlier one is the later face.
      for (size_t i = b + 1; i < e; ++i) {
        for (size_t j = b; j < i; ++j) {
          if (keys[i].mid == keys[j].mid && keys[i].max == keys[j].max) {
            keep[keys[i].face] = 0;
            ++duplicates;
            break;
          }
        }
      }
    } else {
      scratch.assign(keys.begin() + static_cast<std::ptrdiff_t>(b), keys.begin() + static_cast<std::ptrdiff_t>(e));
      std::sort(scratch.begin(), scratch.end(), [](const FaceKey& x, const FaceKey& y) {
        if (x.mid != y.mid) return x.mid < y.mid;
        if (x.max != y.max) return x.max < y.max;
        return x.face < y.face;
      });
      for (size_t i = 1; i < k; ++i) {
        if (scratch[i].mid == scratch[i - 1].mid && scratch[i].max == scratch[i - 1].max) {
          keep[scratch[i].face] = 0;
          ++duplicates;
        }
      }
    }
  }
  std::vector<FaceKey>().swap(keys);
  std::vector<uint32_t>().swap(bucket_start);

  // === Compact, keeping corner_uvs and seam_faces in step ======================================
  if (degenerate + duplicates > 0) {
    size_t out = 0;
    const bool uvs = !mesh.corner_uvs.empty(), seams = !mesh.seam_faces.empty();
    for (size_t f = 0; f < nf; ++f) {
      if (!keep[f]) continue;
      if (out != f) {
        std::memmove(&mesh.indices[3 * out], &mesh.indices[3 * f], 3 * sizeof(uint32_t));
        if (uvs) std::memmove(&mesh.corner_uvs[6 * out], &mesh.corner_uvs[6 * f], 6 * sizeof(float));
        if (seams) mesh.seam_faces[out] = mesh.seam_faces[f];
      }
      ++out;
    }
    mesh.indices.resize(3 * out);
    if (uvs) mesh.corner_uvs.resize(6 * out);
    if (seams) mesh.seam_faces.resize(out);
  }
  report.degenerate_faces += degenerate;
  report.duplicate_faces += duplicates;
  if (mesh.indices.empty()) return Status::error(ErrorCode::kInvalidMesh, name, "mesh has no faces");

  // === Zero-area faces (kept) and unreferenced vertices (kept) =================================
  // The cross product is taken in double from float inputs: differences and products are then
  // exact for all but extreme exponent ranges, so "zero" means exactly collinear.
  const float* pos = mesh.positions.data();
  std::vector<uint8_t> used(nv, 0);
  size_t zero_area = 0;
  const size_t kept = mesh.face_count();
  idx = mesh.indices.data();
  for (size_t f = 0; f < kept; ++f) {
    const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
    used[a] = used[b] = used[c] = 1;
    const double ux = double{pos[3 * b]} - pos[3 * a], uy = double{pos[3 * b + 1]} - pos[3 * a + 1],
                 uz = double{pos[3 * b + 2]} - pos[3 * a + 2];
    const double vx = double{pos[3 * c]} - pos[3 * a], vy = double{pos[3 * c + 1]} - pos[3 * a + 1],
                 vz = double{pos[3 * c + 2]} - pos[3 * a + 2];
    const double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
    if (cx == 0.0 && cy == 0.0 && cz == 0.0) ++zero_area;
  }
  size_t unreferenced = 0;
  for (size_t v = 0; v < nv; ++v) unreferenced += used[v] == 0;
  report.zero_area_faces += zero_area;
  report.unreferenced_vertices += unreferenced;
  return Status::ok();
}

}  // namespace tailor
