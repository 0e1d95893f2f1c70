// Mesh loading front end: format detection, dispatch to the per-format parsers, and the
// validation / repair pass shared by all of them (finalize_mesh). See include/tailor/io.h.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "internal/atomic_file.h"
#include "internal/huge_pages.h"
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

// The two larger vertex ids of face f's sorted triple, as (mid << 32) | max, and the smallest.
inline uint64_t sorted_pair(const uint32_t* idx, size_t f, uint32_t& lo) {
  uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  lo = a;
  return uint64_t{b} << 32 | c;
}

template <class T>
std::vector<T> huge_vector(size_t n, T value) {
  std::vector<T> v;
  internal::reserve_huge(v, n);
  v.assign(n, value);
  return v;
}

// Per smallest vertex: the last kept face with that smallest vertex, and a 32-bit signature
// (one bit per face, chosen by a hash of its other two vertices). A face whose bit is not yet set
// cannot be a duplicate, so the chain is walked for ~1 face in 10 on real meshes instead of all.
struct Chain {
  uint32_t head;
  uint32_t signature;
};

constexpr uint8_t kKeep = 1;

// Meshes with at least this many faces check geometry on a second thread (thread start-up costs
// ~50 us, the geometry pass ~4 ns per face).
constexpr size_t kThreadedFaces = 200000;

// Longest duplicate chain walked per face before switching to the bucket sort; real meshes have
// a handful of faces per smallest vertex, only fans of thousands of faces exceed it.
constexpr size_t kMaxChain = 64;

// Exact duplicate marking by a counting sort on the smallest vertex and a sort of each bucket by
// (pair, face). Clears kKeep on every face whose sorted triple equals an earlier kept face's and
// returns the number marked. O(F + V + sum k log k) for buckets of size k.
size_t mark_duplicates_by_buckets(const std::vector<uint32_t>& indices, std::vector<uint8_t>& flags) {
  const size_t nf = flags.size();
  uint32_t nv = 0;
  for (uint32_t i : indices) nv = std::max(nv, i + 1);
  auto lowest = [&](size_t f) {
    return std::min(indices[3 * f], std::min(indices[3 * f + 1], indices[3 * f + 2]));
  };
  // Faces the chains already dropped stay dropped (their twin is kept); the others compete here.
  std::vector<uint32_t> start(size_t{nv} + 1, 0);
  for (size_t f = 0; f < nf; ++f) {
    if (flags[f] & kKeep) ++start[lowest(f) + 1];
  }
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<std::pair<uint64_t, uint32_t>> entries(start[nv]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t f = 0; f < nf; ++f) {
      uint32_t lo = 0;
      const uint64_t key = sorted_pair(indices.data(), f, lo);
      if (flags[f] & kKeep) entries[fill[lo]++] = {key, static_cast<uint32_t>(f)};
    }
  }
  size_t marked = 0;
  for (size_t v = 0; v < nv; ++v) {
    const auto b = entries.begin() + start[v], e = entries.begin() + start[v + 1];
    if (e - b < 2) continue;
    std::sort(b, e);
    for (auto it = b + 1; it != e; ++it) {
      if (it->first == (it - 1)->first) {
        flags[it->second] &= static_cast<uint8_t>(~kKeep);
        ++marked;
      }
    }
  }
  return marked;
}

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
  // Branch-free scan of the exponent bits (vectorizes); the slow search runs only on failure.
  {
    uint32_t all_ones = 0;
    const size_t np = mesh.positions.size();
    const float* p = mesh.positions.data();
    for (size_t i = 0; i < np; ++i) {
      uint32_t bits;
      std::memcpy(&bits, p + i, 4);
      all_ones |= static_cast<uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
    }
    if (all_ones) {
      for (size_t i = 0; i < np; ++i) {
        if (!std::isfinite(p[i])) {
          return Status::error(ErrorCode::kInvalidMesh, name, "non-finite vertex coordinate",
                               "vertex " + std::to_string(i / 3));
        }
      }
    }
  }
  for (size_t i = 0; i < mesh.corner_uvs.size(); ++i) {
    if (!std::isfinite(mesh.corner_uvs[i])) {
      return Status::error(ErrorCode::kInvalidMesh, name, "non-finite texture coordinate",
                           "face " + std::to_string(i / 6));
    }
  }

  // === Index range ===============================================================================
  // Checked first and branch-free (vectorizes), so that the passes below may read positions.
  const uint32_t* idx = mesh.indices.data();
  {
    uint32_t max_index = 0;
    for (size_t c = 0; c < 3 * nf; ++c) max_index = std::max(max_index, idx[c]);
    if (max_index >= nv) {
      for (size_t c = 0; c < 3 * nf; ++c) {
        if (idx[c] >= nv) {
          return Status::error(ErrorCode::kInvalidMesh, name,
                               "face index " + std::to_string(idx[c]) + " out of range (mesh has " +
                                   std::to_string(nv) + " vertices)",
                               "face " + std::to_string(c / 3));
        }
      }
    }
  }

  // === Two independent passes over the faces, run side by side ==================================
  // Geometry (zero-area flags, referenced vertices) and connectivity (degenerate and duplicate
  // faces) read the same indices but write disjoint arrays, so they run on two threads when
  // the mesh is large; the results do not depend on it.
  std::vector<uint8_t> zero = huge_vector<uint8_t>(nf, 0);
  std::vector<uint8_t> used = huge_vector<uint8_t>(nv, 0);
  auto geometry = [&] {
    // Zero area: the cross product in double from float inputs is exact for all but extreme
    // exponent ranges, so "zero" means exactly collinear. Degenerate faces are skipped (dropped).
    const float* pos = mesh.positions.data();
    for (size_t f = 0; f < nf; ++f) {
      const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
      if ((a == b) | (b == c) | (a == c)) continue;
      used[a] = used[b] = used[c] = 1;  // a duplicate uses the same vertices as its kept twin
      const double ux = double{pos[3 * b]} - pos[3 * a], uy = double{pos[3 * b + 1]} - pos[3 * a + 1],
                   uz = double{pos[3 * b + 2]} - pos[3 * a + 2];
      const double vx = double{pos[3 * c]} - pos[3 * a], vy = double{pos[3 * c + 1]} - pos[3 * a + 1],
                   vz = double{pos[3 * c + 2]} - pos[3 * a + 2];
      const double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
      zero[f] = (cx == 0.0 && cy == 0.0 && cz == 0.0) ? 1 : 0;
    }
  };
  // Everything is allocated before the thread starts: nothing below may throw while it runs.
  std::vector<uint8_t> flags = huge_vector<uint8_t>(nf, 0);  // kKeep
  std::vector<Chain> chains = huge_vector<Chain>(nv, Chain{kInvalid, 0});
  std::vector<uint32_t> next = huge_vector<uint32_t>(nf, kInvalid);
  std::thread worker;
  if (nf >= kThreadedFaces) {
    try {
      worker = std::thread(geometry);
    } catch (...) {  // no thread available: run it inline below
    }
  }

  // Duplicates (same vertex set, any order; the first is kept) are found through a chain per
  // smallest vertex: chains[v].head is the last kept face whose smallest vertex is v, next[f] the
  // one before it, and chains[v].signature filters out most walks. Meshes store faces with vertex
  // locality, so this stays in cache where a hash of 1.5M triples costs a cache miss per face.
  // A chain longer than kMaxChain (a huge fan, i.e. adversarial input) switches to the exact
  // bucket sort in mark_duplicates_by_buckets, so the worst case is O(F log F), never quadratic.
  // Both give the same result.
  size_t degenerate = 0, duplicates = 0;
  bool chain_overflow = false;
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
    if ((a == b) | (b == c) | (a == c)) {
      ++degenerate;
      continue;
    }
    uint32_t lo = 0, unused = 0;
    const uint64_t key = sorted_pair(idx, f, lo);
    flags[f] = kKeep;
    if (chain_overflow) continue;
    Chain& chain = chains[lo];
    const uint32_t bit = 1u << ((key * 0x9e3779b97f4a7c15ULL) >> 59);
    if (chain.signature & bit) {  // possibly a duplicate: walk the chain (exact)
      size_t steps = 0;
      uint32_t g = chain.head;
      while (g != kInvalid && sorted_pair(idx, g, unused) != key && ++steps <= kMaxChain) g = next[g];
      if (steps > kMaxChain) {
        chain_overflow = true;
        continue;
      }
      if (g != kInvalid) {
        flags[f] = 0;
        ++duplicates;
        continue;
      }
    }
    next[f] = chain.head;
    chain.head = static_cast<uint32_t>(f);
    chain.signature |= bit;
  }
  if (worker.joinable()) worker.join();
  else geometry();
  std::vector<Chain>().swap(chains);
  std::vector<uint32_t>().swap(next);
  if (chain_overflow) duplicates += mark_duplicates_by_buckets(mesh.indices, flags);

  // === Compact, keeping corner_uvs and seam_faces in step ======================================
  size_t zero_area = 0;
  if (degenerate + duplicates > 0) {
    size_t out = 0;
    const bool uvs = !mesh.corner_uvs.empty(), seams = !mesh.seam_faces.empty();
    for (size_t f = 0; f < nf; ++f) {
      if (!(flags[f] & kKeep)) continue;
      zero_area += zero[f];
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
  } else {
    for (size_t f = 0; f < nf; ++f) zero_area += zero[f];
  }
  report.degenerate_faces += degenerate;
  report.duplicate_faces += duplicates;
  report.zero_area_faces += zero_area;
  if (mesh.indices.empty()) return Status::error(ErrorCode::kInvalidMesh, name, "mesh has no faces");
  size_t unreferenced = 0;
  for (size_t v = 0; v < nv; ++v) unreferenced += used[v] == 0;
  report.unreferenced_vertices += unreferenced;
  return Status::ok();
}

}  // namespace tailor
