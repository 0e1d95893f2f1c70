// Mesh loading front end: format detection, dispatch to the per-format parsers, and the
// validation / repair pass shared by all of them (finalize_mesh). See include/tailor/io.h.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <new>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "io/readers.h"
#include "tailor/image.h"
#include "tailor/io.h"
#include "util/atomic_file.h"
#include "util/file_view.h"
#include "util/huge_pages.h"
#include "util/zero_area.h"

namespace tailor {
namespace {

constexpr const char* kSupported = "supported: .ply .obj .off .stl .glb .gltf";

// Whether `s` at `at` reads `lower` (lower case) in any case (ASCII).
bool reads_ci(std::string_view s, size_t at, std::string_view lower) {
  if (at > s.size() || s.size() - at < lower.size()) return false;
  for (size_t i = 0; i < lower.size(); ++i) {
    char c = s[at + i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != lower[i]) return false;
  }
  return true;
}

bool ends_with_ci(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && reads_ci(s, s.size() - suffix.size(), suffix);
}

// True when the first word of the data is an OFF keyword: [ST][C][N][4][n]OFF.
bool starts_with_off_keyword(std::string_view s) {
  size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r' || s[i] == '\n')) ++i;
  size_t j = i;
  while (j < s.size() && j - i < 16 && s[j] > ' ') ++j;
  const std::string_view w = s.substr(i, j - i);
  return (w.size() >= 3 && w.substr(w.size() - 3) == "OFF" && w.size() <= 9) || w == "off";
}

MeshFormat sniff_format(std::span<const char> data) {
  const std::string_view s(data.data(), data.size());
  if (s.size() >= 4 && s.substr(0, 3) == "ply" && (s[3] == '\n' || s[3] == '\r')) return MeshFormat::kPly;
  if (s.size() >= 4 && s.substr(0, 4) == "glTF") return MeshFormat::kGlb;
  if (s.size() >= 1 && s[0] == '{') return MeshFormat::kGltf;  // JSON: only glTF among ours
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

using internal::is_zero_area;

// Per smallest vertex: 1 + the last kept face with that smallest vertex (0: none, so that an
// all-zero array from calloc is a set of empty chains), and a 32-bit signature (one bit per face,
// chosen by a hash of its other two vertices). A face whose bit is not yet set cannot be a
// duplicate, so the chain is walked for ~1 face in 10 on real meshes instead of all.
struct Chain {
  uint32_t head;
  uint32_t signature;
};

constexpr uint8_t kKeep = 1;

// Meshes with at least this many faces use a second thread (thread start-up costs ~50 us, the
// geometry pass ~4-8 ns per face).
constexpr size_t kThreadedFaces = 200000;

// Faces per chunk of the shared geometry pass (~0.5 ms of work: few atomic operations, and a
// thread that finishes early waits at most one chunk for the other).
constexpr size_t kGeometryChunk = 65536;

// The geometry pass over the chunks this thread takes from next_chunk (kGeometryChunk faces
// each): marks the vertices of non-degenerate faces in `used` and returns how many of those faces
// have zero area. Faces with an index >= nv are skipped (reported by the caller). Plain pointer
// parameters: the byte stores to `used` would otherwise force reloads of captured variables.
size_t zero_area_in_chunks(const uint32_t* idx, const float* pos, size_t nf, uint32_t nv, size_t chunks,
                           std::atomic<size_t>& next_chunk, uint8_t* used) {
  size_t zeros = 0;
  for (size_t k = next_chunk.fetch_add(1, std::memory_order_relaxed); k < chunks;
       k = next_chunk.fetch_add(1, std::memory_order_relaxed)) {
    const size_t end = std::min(nf, (k + 1) * kGeometryChunk);
    for (size_t f = k * kGeometryChunk; f < end; ++f) {
      const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
      if ((a == b) | (b == c) | (a == c) | (std::max(a, std::max(b, c)) >= nv)) continue;
      used[a] = used[b] = used[c] = 1;  // a duplicate uses the same vertices as its kept twin
      zeros += is_zero_area(pos, a, b, c);
    }
  }
  return zeros;
}

// Longest duplicate chain walked per face before switching to the bucket sort; real meshes have
// a handful of faces per smallest vertex, only fans of thousands of faces exceed it.
constexpr size_t kMaxChain = 64;

// Exact duplicate marking by a counting sort on the smallest vertex and a sort of each bucket by
// (pair, face). Clears kKeep on every face whose sorted triple equals an earlier kept face's and
// returns the number marked. O(F + V + sum k log k) for buckets of size k.
size_t mark_duplicates_by_buckets(const std::vector<uint32_t>& indices, uint8_t* flags) {
  const size_t nf = indices.size() / 3;
  uint32_t nv = 0;
  for (uint32_t i : indices) nv = std::max(nv, i + 1);
  auto lowest = [&](size_t f) { return std::min(indices[3 * f], std::min(indices[3 * f + 1], indices[3 * f + 2])); };
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
  if (ends_with_ci(path, ".gltf")) return MeshFormat::kGltf;
  return MeshFormat::kUnknown;
}

namespace {

// Up to max_bytes of a file's start; false when it cannot be opened or is not a regular file (a
// FIFO named as a material or a texture would block the read: internal::open_input refuses it).
bool read_file_start(const std::filesystem::path& path, size_t max_bytes, std::string& out) {
  return internal::read_file_head(path.string(), max_bytes, out).is_ok();
}

// The texture a mesh file names (an image next to it): report.texture_width/height from the
// image's header (never decoded), texture_file and texture_path. A missing or unreadable image
// leaves them as they are: the mesh itself loaded, and its texture is optional.
void read_texture_header(const std::filesystem::path& image, LoadReport& report) {
  report.texture_named = image.string();
  std::string head;
  long width = 0, height = 0;
  for (const size_t max_bytes : {size_t{64} << 10, size_t{16} << 20}) {  // a JPEG's frame header may lie far in
    if (!read_file_start(image, max_bytes, head)) return;
    if (internal::image_header_size({reinterpret_cast<const unsigned char*>(head.data()), head.size()}, width, height,
                                    true))
      break;
    if (head.size() < max_bytes) return;
  }
  // Beyond the sides any command reads (kMaxImageSide) the image is as unreadable as a missing one.
  if (width <= 0 || height <= 0 || width > kMaxImageSide || height > kMaxImageSide) return;
  report.texture_width = static_cast<int>(width);
  report.texture_height = static_cast<int>(height);
  report.texture_file = true;
  report.texture_path = image.string();
}

// An .obj's texture, as its .mtl names it (the first map_Kd: the file name after any options, a
// file next to the .mtl), read by read_texture_header; a `# tailor symmetry 4` line (tailor map
// --symmetry 4) into report.texture_symmetry. A missing .mtl leaves them as they are.
void read_obj_material(const std::filesystem::path& folder, const std::string& library, LoadReport& report) {
  std::string mtl;
  std::filesystem::path mtl_path = folder / library;
  if (!read_file_start(mtl_path, size_t{1} << 20, mtl)) {
    // `mtllib a.mtl b.mtl`: several names; the first.
    const size_t blank = library.find_first_of(" \t");
    if (blank == std::string::npos) return;
    mtl_path = folder / library.substr(0, blank);
    if (!read_file_start(mtl_path, size_t{1} << 20, mtl)) return;
  }
  std::string texture;
  uint32_t symmetry = 1;
  std::string_view rest = mtl;
  while (!rest.empty()) {
    const size_t end = rest.find('\n');
    const std::string_view line = internal::trimmed(rest.substr(0, end));
    rest = end == std::string_view::npos ? std::string_view{} : rest.substr(end + 1);
    if (line == "# tailor symmetry 4") symmetry = 4;
    // The keyword in any case: some writers put map_kd.
    if (!texture.empty() || !(reads_ci(line, 0, "map_kd ") || reads_ci(line, 0, "map_kd\t"))) continue;
    const std::string_view name = internal::trimmed(line.substr(7));
    // The name, unless options (-s 1 1 1, -clamp on, ...) come first: then its last word.
    const size_t last_blank = name.find_last_of(" \t");
    texture =
        std::string(name.front() == '-' && last_blank != std::string_view::npos ? name.substr(last_blank + 1) : name);
  }
  report.texture_symmetry = symmetry;
  if (!texture.empty()) read_texture_header(mtl_path.parent_path() / texture, report);
}

// read_mesh with the folder where a .gltf's buffer files are (empty: none is opened).
Status read_mesh_in(std::span<const char> data, MeshFormat format, const std::string& name, const std::string& base_dir,
                    Mesh& mesh, LoadReport* report, const ProgressCallback* callback = nullptr) {
  mesh = Mesh{};
  LoadReport local;
  LoadReport& r = report ? *report : local;
  r = LoadReport{};
  r.file_bytes = data.size();
  if (format == MeshFormat::kUnknown) format = sniff_format(data);
  Status s;
  internal::ReadProgress progress(callback, data.size());
  std::string material_library;  // OBJ: its mtllib (the texture's size is read from it)
  std::string texture_name;      // PLY: its TextureFile comment (the same)
  internal::PolygonFans fans;    // PLY, OBJ, OFF: the polygons cut into fans
  // The parsers never throw by design; only an allocation of a (checked, but large) size can.
  try {
    switch (format) {
      case MeshFormat::kPly: s = internal::read_ply(data, name, mesh, r, &progress, &texture_name, &fans); break;
      case MeshFormat::kObj: s = internal::read_obj(data, name, mesh, r, &progress, &material_library, &fans); break;
      case MeshFormat::kOff: s = internal::read_off(data, name, mesh, r, &progress, &fans); break;
      case MeshFormat::kStl: s = internal::read_stl(data, name, mesh, r, &progress); break;
      case MeshFormat::kGlb:
      case MeshFormat::kGltf: s = internal::read_gltf(data, name, base_dir, mesh, r, &progress); break;
      case MeshFormat::kUnknown:
        s = Status::error(ErrorCode::kUnsupported, name, std::string("unknown mesh format (") + kSupported + ")");
        break;
    }
    if (s.is_ok() && !progress.repairs(0.f)) s = progress.cancelled(name);
    if (s.is_ok()) r.concave_polygons = internal::retriangulate_concave_fans(mesh, fans);
    if (s.is_ok()) s = finalize_mesh(name, mesh, r);
    if (s.is_ok() && !base_dir.empty() && !material_library.empty()) read_obj_material(base_dir, material_library, r);
    if (s.is_ok() && !base_dir.empty() && !texture_name.empty())
      read_texture_header(std::filesystem::path(base_dir) / texture_name, r);
    if (s.is_ok() && !progress.repairs(1.f)) s = progress.cancelled(name);
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

}  // namespace

Status read_mesh(std::span<const char> data, MeshFormat format, const std::string& name, Mesh& mesh,
                 LoadReport* report) {
  return read_mesh_in(data, format, name, "", mesh, report);
}

Status load_mesh(const std::string& path, Mesh& mesh, LoadReport* report) { return load_mesh(path, mesh, report, {}); }

Status load_mesh(const std::string& path, Mesh& mesh, LoadReport* report, const ProgressCallback& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  mesh = Mesh{};
  // Mapped, not copied: a read into a fresh buffer cost a quarter of loading a large binary PLY.
  internal::FileView file;
  TAILOR_RETURN_IF_ERROR(internal::view_file(path, file));
  const std::span<const char> bytes = file.bytes();
  MeshFormat format = mesh_format_from_path(path);
  // By content when the name says nothing; and a PLY or binary glTF header is unmistakable: such a
  // file is read as what it holds, whatever its name (a .ply saved as .obj read as an OBJ without faces).
  const MeshFormat held = sniff_format(bytes);
  if (format == MeshFormat::kUnknown || held == MeshFormat::kPly || held == MeshFormat::kGlb) format = held;
  if (format == MeshFormat::kUnknown)
    return Status::error(ErrorCode::kUnsupported, path,
                         std::string("unknown mesh file extension and content (") + kSupported + ")");
  LoadReport local;
  LoadReport& r = report ? *report : local;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  const Status s = read_mesh_in(bytes, format, path, folder.empty() ? "." : folder.string(), mesh, &r, &progress);
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
  if (!mesh.face_parts.empty() && mesh.face_parts.size() != nf) {
    return Status::error(ErrorCode::kInvalidMesh, name, "face parts do not match the faces");
  }
  for (const CornerAttribute& a : mesh.corner_attributes)
    if (a.components < 1 || a.components > 4 || a.values.size() != nf * 3 * size_t(a.components))
      return Status::error(ErrorCode::kInvalidMesh, name, "corner attribute " + a.name + " does not match the faces");
  if (nf == 0) return Status::error(ErrorCode::kInvalidMesh, name, "mesh has no faces");

  // === Three passes over the faces, on two threads ==============================================
  // The worker checks the coordinates, then starts on the geometry (zero-area faces, referenced
  // vertices); this thread checks index ranges, finds degenerate and duplicate faces, then helps
  // with the geometry. They read the same arrays and write disjoint ones; every result is a count,
  // a per-face flag or a union of marks, so nothing depends on the thread timing. A face with an
  // out-of-range index is skipped by both and reported after the join (the range check is folded
  // into the face loops instead of a pass of its own).
  const uint32_t* idx = mesh.indices.data();
  const float* pos = mesh.positions.data();
  const uint32_t nv32 = static_cast<uint32_t>(nv);  // nv <= kMaxVertices < 2^32
  // Everything is allocated before the thread starts: nothing below may throw while it runs.
  // Each thread marks referenced vertices in its own array (no shared writes); they are merged after.
  internal::HugeArray<uint8_t> used_main = internal::huge_zeroed<uint8_t>(nv);
  internal::HugeArray<uint8_t> used_worker = internal::huge_zeroed<uint8_t>(nv);
  internal::HugeArray<uint8_t> flags = internal::huge_uninitialized<uint8_t>(nf);  // kKeep or 0
  internal::HugeArray<Chain> chains = internal::huge_zeroed<Chain>(nv);
  internal::HugeArray<uint32_t> next = internal::huge_uninitialized<uint32_t>(nf);
  // The geometry pass is shared out in chunks: the worker starts on it at once, this thread joins
  // in when its duplicate pass is done. Which thread takes a chunk varies from run to run; the
  // results (a sum and the union of the marks) do not.
  std::atomic<size_t> next_chunk{0};
  const size_t chunks = (nf + kGeometryChunk - 1) / kGeometryChunk;
  auto geometry = [idx, pos, nf, nv32, chunks, &next_chunk](uint8_t* used) {
    return zero_area_in_chunks(idx, pos, nf, nv32, chunks, next_chunk, used);
  };
  bool non_finite = false;
  size_t zero_area = 0;
  auto worker_job = [&, np = mesh.positions.size(), used = used_worker.get()] {
    // Finite coordinates: a branch-free scan of the exponent bits (vectorizes).
    uint32_t all_ones = 0;
    for (size_t i = 0; i < np; ++i) {
      uint32_t bits;
      std::memcpy(&bits, pos + i, 4);
      all_ones |= static_cast<uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
    }
    non_finite = all_ones != 0;
    zero_area = geometry(used);
  };
  std::thread worker;
  if (nf >= kThreadedFaces) {
    try {
      worker = std::thread(worker_job);
    } catch (...) {  // no thread available: run it inline below
    }
  }

  // Duplicates (same vertex set, any order; the first is kept) are found through a chain per
  // smallest vertex: chains[v].head is 1 + the last kept face whose smallest vertex is v (0: none),
  // next[f] the same for the one before it, and chains[v].signature filters out most walks.
  // Meshes store faces with vertex locality, so this stays in cache where a hash of 1.5M triples
  // costs a cache miss per face. A chain longer than kMaxChain (a huge fan, i.e. adversarial
  // input) switches to the exact bucket sort in mark_duplicates_by_buckets, so the worst case is
  // O(F log F), never quadratic. Both give the same result.
  // Raw pointers in locals: the byte stores to keep[] could otherwise alias the array owners,
  // whose addresses the worker lambda holds, and force a reload of each per face.
  uint8_t* const keep = flags.get();
  Chain* const chain_of = chains.get();
  uint32_t* const before = next.get();
  size_t degenerate = 0, duplicates = 0;
  bool chain_overflow = false;
  uint32_t max_index = 0;
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
    uint32_t lo = 0, unused = 0;
    const uint64_t key = sorted_pair(idx, f, lo);
    const uint32_t hi = static_cast<uint32_t>(key);
    max_index = std::max(max_index, hi);
    if ((a == b) | (b == c) | (a == c) | (hi >= nv32)) {
      degenerate += hi < nv32;
      keep[f] = 0;
      continue;
    }
    keep[f] = kKeep;
    if (chain_overflow) continue;
    Chain& chain = chain_of[lo];
    const uint32_t bit = 1u << ((key * 0x9e3779b97f4a7c15ULL) >> 59);
    if (chain.signature & bit) {  // possibly a duplicate: walk the chain (exact)
      size_t steps = 0;
      uint32_t g = chain.head;
      while (g != 0 && sorted_pair(idx, g - 1, unused) != key && ++steps <= kMaxChain) g = before[g - 1];
      if (steps > kMaxChain) {
        chain_overflow = true;
        continue;
      }
      if (g != 0) {
        keep[f] = 0;
        ++duplicates;
        continue;
      }
    }
    before[f] = chain.head;
    chain.head = static_cast<uint32_t>(f + 1);
    chain.signature |= bit;
  }
  chains.reset();
  next.reset();
  const size_t main_zeros = geometry(used_main.get());
  if (worker.joinable())
    worker.join();
  else
    worker_job();
  zero_area += main_zeros;
  size_t unreferenced = 0;
  for (size_t v = 0; v < nv; ++v) unreferenced += (used_main[v] | used_worker[v]) == 0;

  // === Errors, in a fixed order whatever the thread timing ======================================
  // The slow searches below run only on failure, to name the first offending element.
  if (non_finite) {
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      if (!std::isfinite(pos[i])) {
        // A text file's 1e39 reads as infinity: say so, it is no NaN.
        return Status::error(ErrorCode::kInvalidMesh, name,
                             "vertex coordinate not finite or beyond the range of 32-bit floats (3.4e38)",
                             "vertex " + std::to_string(i / 3));
      }
    }
  }
  for (const CornerAttribute& a : mesh.corner_attributes)
    for (size_t i = 0; i < a.values.size(); ++i)
      if (!std::isfinite(a.values[i]))
        return Status::error(ErrorCode::kInvalidMesh, name, "non-finite " + a.name,
                             "face " + std::to_string(i / (3 * size_t(a.components))));
  for (size_t i = 0; i < mesh.corner_uvs.size(); ++i) {
    if (!std::isfinite(mesh.corner_uvs[i])) {
      return Status::error(ErrorCode::kInvalidMesh, name, "non-finite texture coordinate",
                           "face " + std::to_string(i / 6));
    }
  }
  if (max_index >= nv) {
    for (size_t c = 0; c < 3 * nf; ++c) {
      if (idx[c] >= nv) {
        return Status::error(
            ErrorCode::kInvalidMesh, name,
            "face index " + std::to_string(idx[c]) + " out of range (mesh has " + std::to_string(nv) + " vertices)",
            "face " + std::to_string(c / 3));
      }
    }
  }
  if (chain_overflow) duplicates += mark_duplicates_by_buckets(mesh.indices, flags.get());

  // === Compact, keeping corner_uvs and seam_faces in step ======================================
  if (degenerate + duplicates > 0) {
    size_t out = 0;
    const bool uvs = !mesh.corner_uvs.empty(), seams = !mesh.seam_faces.empty(), parts = !mesh.face_parts.empty();
    for (size_t f = 0; f < nf; ++f) {
      if (!(flags[f] & kKeep)) {
        const uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
        // The geometry pass counted every non-degenerate face; a dropped duplicate is not kept.
        if ((a != b) & (b != c) & (a != c)) zero_area -= is_zero_area(pos, a, b, c);
        continue;
      }
      if (out != f) {
        std::memmove(&mesh.indices[3 * out], &mesh.indices[3 * f], 3 * sizeof(uint32_t));
        if (uvs) std::memmove(&mesh.corner_uvs[6 * out], &mesh.corner_uvs[6 * f], 6 * sizeof(float));
        if (seams) mesh.seam_faces[out] = mesh.seam_faces[f];
        if (parts) mesh.face_parts[out] = mesh.face_parts[f];
        for (CornerAttribute& a : mesh.corner_attributes) {
          const size_t k = 3 * size_t(a.components);
          std::memmove(&a.values[k * out], &a.values[k * f], k * sizeof(float));
        }
      }
      ++out;
    }
    mesh.indices.resize(3 * out);
    if (uvs) mesh.corner_uvs.resize(6 * out);
    if (seams) mesh.seam_faces.resize(out);
    if (parts) mesh.face_parts.resize(out);
    for (CornerAttribute& a : mesh.corner_attributes) a.values.resize(3 * size_t(a.components) * out);
  }
  report.degenerate_faces += degenerate;
  report.duplicate_faces += duplicates;
  report.zero_area_faces += zero_area;
  if (mesh.indices.empty())  // every face named a vertex twice (a duplicate always keeps one copy)
    return Status::error(
        ErrorCode::kInvalidMesh, name,
        "mesh has no faces left: all " + std::to_string(degenerate) + " name a vertex twice and were dropped");
  report.unreferenced_vertices += unreferenced;
  return Status::ok();
}

}  // namespace tailor
