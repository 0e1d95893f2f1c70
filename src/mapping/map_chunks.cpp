// The chunked engine (tailor/chunks.h, DESIGN.md section 8): the mesh is cut by the chunk rule,
// every chunk is mapped by the whole pipeline (map_texture on the chunk alone) on the next free
// worker thread, and its UVs and patches are written back to the mesh's corners.
//
// Why each chunk is rebuilt in a canonical form: the mapping's every tie (front keys, seed
// distances, sums over vertices) is broken by ids, so the same surface in another file order
// would map differently. A chunk's faces are sorted by the Morton key of their centroid (then by
// their corners' coordinates), each face starts at its lexicographically smallest corner, and the
// vertices are numbered by first use: the chunk's mesh, and so its UVs, are a function of its
// geometry and connectivity alone. Its frame (origin, unit) is its cell's, its texel density is
// one number for the whole mesh (a power of two unless the caller fixed it), so nothing outside
// the chunk reaches in.
#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <thread>
#include <vector>

#include "mapping/mapping_common.h"
#include "tailor/chunks.h"
#include "tailor/mapping.h"
#include "tailor/topology.h"

namespace tailor::internal {
namespace {

// Spreads the low 21 bits of x to every third bit (Morton interleave).
inline uint64_t spread3(uint64_t x) {
  x &= 0x1FFFFF;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// Lexicographic order of two points (x, then y, then z).
inline bool point_less(const float* a, const float* b) {
  if (a[0] != b[0]) return a[0] < b[0];
  if (a[1] != b[1]) return a[1] < b[1];
  return a[2] < b[2];
}

// One face of a chunk in canonical form: its sort key, its global id, the corner it starts at.
struct ChunkFace {
  uint64_t morton;
  uint32_t face;
  uint32_t rotation;
};

// Global vertex id -> chunk vertex id, for one chunk at a time (open addressing, cleared by
// stamping: no per-chunk reallocation once it has grown to the largest chunk).
class VertexTable {
 public:
  void reset(size_t expected) {
    size_t want = 64;
    while (want < 2 * expected) want *= 2;
    if (want > keys_.size()) {
      keys_.assign(want, 0);
      values_.assign(want, 0);
      stamps_.assign(want, 0);
      stamp_ = 0;
    }
    if (++stamp_ == 0) {  // wrapped: clear the stamps once
      std::fill(stamps_.begin(), stamps_.end(), 0u);
      stamp_ = 1;
    }
  }
  // The chunk id of global vertex v, `next` (then incremented) when v is new.
  uint32_t find_or_add(uint32_t v, uint32_t& next, bool& added) {
    const size_t mask = keys_.size() - 1;
    size_t i = (uint64_t{v} * 0x9E3779B97F4A7C15ull >> 20) & mask;
    while (stamps_[i] == stamp_) {
      if (keys_[i] == v) {
        added = false;
        return values_[i];
      }
      i = (i + 1) & mask;
    }
    stamps_[i] = stamp_;
    keys_[i] = v;
    values_[i] = next;
    added = true;
    return next++;
  }

 private:
  std::vector<uint32_t> keys_, values_, stamps_;
  uint32_t stamp_ = 0;
};

// What one worker reuses from chunk to chunk.
struct ChunkWorker {
  std::vector<ChunkFace> faces;
  VertexTable vertices;
  Mesh mesh;
  std::vector<uint8_t> seam_flags;
  TextureMap map;
};

// Builds the canonical mesh of chunk `c` into w.mesh (and w.faces: chunk face i is global face
// w.faces[i].face starting at its corner w.faces[i].rotation).
void build_chunk_mesh(const Mesh& mesh, const ChunkPlan& plan, size_t c, std::span<const uint8_t> seam_faces,
                      ChunkWorker& w) {
  const float* pos = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();
  const uint32_t begin = plan.chunk_start[c], end = plan.chunk_start[c + 1];
  const double inverse = 1.0 / plan.cell_size;
  const std::array<int32_t, 3>& cell = plan.cells[c];
  w.faces.resize(end - begin);
  for (uint32_t i = begin; i < end; ++i) {
    const uint32_t f = plan.faces[i];
    const float* p[3] = {pos + 3 * size_t{idx[3 * f]}, pos + 3 * size_t{idx[3 * f + 1]},
                         pos + 3 * size_t{idx[3 * f + 2]}};
    uint32_t r = 0;
    if (point_less(p[1], p[r])) r = 1;
    if (point_less(p[2], p[r])) r = 2;
    uint64_t morton = 0;
    for (int k = 0; k < 3; ++k) {
      double a = p[0][k], b = p[1][k], d = p[2][k];  // summed smallest first, as the chunk rule does
      if (a > b) std::swap(a, b);
      if (b > d) std::swap(b, d);
      if (a > b) std::swap(a, b);
      const double t = ((a + b) + d) / 3.0 * inverse - cell[static_cast<size_t>(k)];
      const double q = std::clamp(std::floor(t * double{1 << 21}), 0.0, double{(1 << 21) - 1});
      morton |= spread3(static_cast<uint64_t>(q)) << k;
    }
    w.faces[i - begin] = ChunkFace{morton, f, r};
  }
  auto corner = [&](const ChunkFace& face, uint32_t k) {
    return pos + 3 * size_t{idx[3 * size_t{face.face} + (face.rotation + k) % 3]};
  };
  std::sort(w.faces.begin(), w.faces.end(), [&](const ChunkFace& a, const ChunkFace& b) {
    if (a.morton != b.morton) return a.morton < b.morton;
    for (uint32_t k = 0; k < 3; ++k) {
      const float *pa = corner(a, k), *pb = corner(b, k);
      if (point_less(pa, pb)) return true;
      if (point_less(pb, pa)) return false;
    }
    return a.face < b.face;  // the same triangle twice: indistinguishable anyway
  });
  const size_t n = w.faces.size();
  w.vertices.reset(3 * n);
  w.mesh.indices.resize(3 * n);
  w.mesh.positions.clear();
  w.mesh.positions.reserve(3 * n);
  const bool seams = !seam_faces.empty();
  w.seam_flags.resize(seams ? n : 0);
  uint32_t next = 0;
  for (size_t i = 0; i < n; ++i) {
    const ChunkFace& face = w.faces[i];
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t v = idx[3 * size_t{face.face} + (face.rotation + k) % 3];
      bool added = false;
      w.mesh.indices[3 * i + k] = w.vertices.find_or_add(v, next, added);
      if (added) w.mesh.positions.insert(w.mesh.positions.end(), pos + 3 * size_t{v}, pos + 3 * size_t{v} + 3);
    }
    if (seams) w.seam_flags[i] = seam_faces[face.face];
  }
}

void add_stats(const MappingStats& s, MappingStats& total) {
  total.patches += s.patches;
  total.patches_before_absorb += s.patches_before_absorb;
  total.components += s.components;
  total.deferrals += s.deferrals;
  total.threshold_raises += s.threshold_raises;
  total.final_threshold_px = std::max(total.final_threshold_px, s.final_threshold_px);
  total.max_error_px = std::max(total.max_error_px, s.max_error_px);
  total.max_stretch_accepted = std::max(total.max_stretch_accepted, s.max_stretch_accepted);
  total.faces_three_textured += s.faces_three_textured;
  total.faces_unfolded += s.faces_unfolded;
  total.faces_rigid += s.faces_rigid;
  total.faces_cut += s.faces_cut;
  total.faces_reseamed += s.faces_reseamed;
  total.cracks_closed += s.cracks_closed;
  total.relax_moves += s.relax_moves;
  total.faces_seam += s.faces_seam;
  total.inverted_accepted += s.inverted_accepted;
}

}  // namespace

double chunk_texels_per_unit(const Mesh& mesh, const MapTextureOptions& options) {
  if (options.orientation.fixed_unit_scale > 0.f)
    return double{options.mapping.scale} * options.orientation.fixed_unit_scale;
  // The longest side of the referenced vertices' bounding box, as the whole-mesh mapping
  // normalises, then the density rounded to a power of two: a local edit that does not change the
  // bounding box by a factor near sqrt(2) leaves it where it is.
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (const uint32_t v : mesh.indices)
    for (size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * size_t{v} + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * size_t{v} + k]);
    }
  const double longest = std::max({double{hi[0]} - lo[0], double{hi[1]} - lo[1], double{hi[2]} - lo[2]});
  if (!(longest > 0) || !std::isfinite(longest)) return 0;
  return std::exp2(std::round(std::log2(double{options.mapping.scale} / longest)));
}

Status map_chunks(const Mesh& mesh, const MapTextureOptions& options, TextureMap& map) {
  const auto start = std::chrono::steady_clock::now();
  map.frames = FaceFrames{};
  map.atlas.corner_uv.clear();
  map.atlas.patch.clear();
  map.atlas.patch_count = 0;
  map.stats = MappingStats{};
  map.metrics = UvMetrics{};
  const size_t face_count = mesh.face_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  if (!options.mapping.seam_faces.empty() && options.mapping.seam_faces.size() != face_count)
    return Status::error(ErrorCode::kInvalidArgument, "", "seam face flags must hold one entry per face");
  if (options.orientation.axis == AxisSource::kSkeleton)
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "the skeleton axis needs the whole mesh: map it without chunks (chunks off)");
  ChunkPlan plan;
  TAILOR_RETURN_IF_ERROR(plan_chunks(mesh, options.chunks, plan));
  const double texels_per_unit = chunk_texels_per_unit(mesh, options);
  const double chunk_scale = texels_per_unit * plan.cell_size;
  if (!(chunk_scale >= 1e-3 && chunk_scale <= 1e7))
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "the texel density gives " + std::to_string(chunk_scale) +
                             " pixels per chunk cell, outside 0.001 to 1e7: give another chunk cell or scale");

  const size_t chunks = plan.chunk_count();
  const size_t cores = std::max<size_t>(std::thread::hardware_concurrency(), 1);
  const size_t threads =
      std::clamp<size_t>(options.mapping.threads ? options.mapping.threads : std::min<size_t>(cores, 64), 1, chunks);
  // With fewer chunks than threads each chunk's own stages get the rest (the result is the same
  // for any count: map_texture's promise).
  const uint32_t inner_threads =
      static_cast<uint32_t>(std::max<size_t>(1, (options.mapping.threads ? options.mapping.threads : cores) / threads));
  // Largest chunks first: the last ones to finish are then the small ones.
  std::vector<uint32_t> order(chunks);
  for (size_t c = 0; c < chunks; ++c) order[c] = static_cast<uint32_t>(c);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return plan.chunk_start[a + 1] - plan.chunk_start[a] > plan.chunk_start[b + 1] - plan.chunk_start[b];
  });

  map.atlas.corner_uv.resize(6 * face_count);
  map.atlas.patch.resize(face_count);
  std::vector<uint32_t> chunk_patches(chunks, 0);
  std::vector<MappingStats> chunk_stats(chunks);
  std::vector<Status> chunk_status(chunks, Status::ok());
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};     // stop taking chunks: a chunk failed or the caller cancelled
  std::atomic<bool> cancelled{false};  // the caller cancelled
  std::mutex report_mutex;             // progress callbacks are called by one worker at a time
  size_t faces_done = 0;               // faces of the chunks mapped so far (under report_mutex)
  float reported = 0.f;                // the largest share reported (reports never go back)
  const StageProgressCallback& stage = options.stage_progress;
  const ProgressCallback& progress = options.mapping.progress;
  // Reports the share of faces mapped, `partial` of them in a chunk still being mapped; false
  // (and everything stops) when the caller cancels. A worker that finds another one reporting
  // goes on without waiting, unless `last` (its chunk's end, which must be counted).
  auto report = [&](size_t partial, size_t finished, bool last) {
    if (failed.load(std::memory_order_relaxed)) return false;
    if (!stage && !progress && !finished) return true;
    std::unique_lock<std::mutex> lock(report_mutex, std::defer_lock);
    if (last)
      lock.lock();
    else if (!lock.try_lock())
      return true;
    faces_done += finished;
    reported = std::max(reported, static_cast<float>(faces_done + partial) / static_cast<float>(face_count));
    if ((stage && !stage("mapping", reported)) || (progress && !progress(reported))) {
      cancelled.store(true);
      failed.store(true);
      return false;
    }
    return true;
  };

  auto work = [&] {
    ChunkWorker w;
    for (size_t i; !failed.load(std::memory_order_relaxed) && (i = next.fetch_add(1)) < chunks;) {
      const uint32_t c = order[i];
      build_chunk_mesh(mesh, plan, c, options.mapping.seam_faces, w);
      const Topology topology = build_topology(w.mesh);
      MapTextureOptions o = options;
      o.chunks.mode = ChunkMode::kOff;
      o.measure = false;
      o.stage_progress = nullptr;
      const size_t chunk_faces = w.faces.size();
      o.mapping.progress = [&report, chunk_faces](float done) {
        return report(static_cast<size_t>(done * static_cast<float>(chunk_faces)), 0, false);
      };
      o.orientation.progress = nullptr;
      o.mapping.threads = inner_threads;
      o.orientation.threads = inner_threads;
      o.orientation.fixed_unit_scale = static_cast<float>(1.0 / plan.cell_size);
      for (size_t k = 0; k < 3; ++k)
        o.orientation.fixed_origin[k] = static_cast<float>(plan.cells[c][k] * plan.cell_size);
      o.mapping.scale = static_cast<float>(chunk_scale);
      o.mapping.seam_faces = w.seam_flags;
      Status s = map_texture(w.mesh, topology, o, w.map);
      if (!s) {
        chunk_status[c] = s;
        failed.store(true);
        return;
      }
      // Back to the mesh's corners: chunk corner k of face i is global corner (rotation + k) % 3.
      float* uv = map.atlas.corner_uv.data();
      for (size_t f = 0; f < w.faces.size(); ++f) {
        const ChunkFace& face = w.faces[f];
        for (uint32_t k = 0; k < 3; ++k) {
          const size_t global = 3 * size_t{face.face} + (face.rotation + k) % 3;
          uv[2 * global] = w.map.atlas.corner_uv[6 * f + 2 * k];
          uv[2 * global + 1] = w.map.atlas.corner_uv[6 * f + 2 * k + 1];
        }
        map.atlas.patch[face.face] = w.map.atlas.patch[f];
      }
      chunk_patches[c] = w.map.atlas.patch_count;
      chunk_stats[c] = w.map.stats;
      if (!report(0, chunk_faces, true)) return;
    }
  };
  {
    std::vector<std::thread> workers;
    try {
      for (size_t t = 1; t < threads; ++t) workers.emplace_back(work);
    } catch (...) {  // no thread to be had: the calling thread does the rest
    }
    work();
    for (std::thread& t : workers) t.join();
  }
  // A chunk's own error first (the first in cell order), else the caller's cancelling (which the
  // chunks still running saw as theirs).
  Status failure = Status::ok();
  for (size_t c = 0; c < chunks && failure.is_ok(); ++c)
    if (!chunk_status[c] && chunk_status[c].code() != ErrorCode::kCancelled) failure = chunk_status[c];
  if (failure.is_ok() && (cancelled.load() || failed.load()))
    failure = Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
  if (!failure.is_ok()) {
    map.atlas.corner_uv.clear();
    map.atlas.patch.clear();
    return failure;
  }
  // Patch ids: each chunk's after those of the chunks before it (in cell order).
  std::vector<uint32_t> first_patch(chunks + 1, 0);
  for (size_t c = 0; c < chunks; ++c) first_patch[c + 1] = first_patch[c] + chunk_patches[c];
  for (size_t c = 0; c < chunks; ++c)
    for (uint32_t i = plan.chunk_start[c]; i < plan.chunk_start[c + 1]; ++i)
      map.atlas.patch[plan.faces[i]] += first_patch[c];
  map.atlas.patch_count = first_patch[chunks];
  for (const MappingStats& s : chunk_stats) add_stats(s, map.stats);
  map.stats.patches = map.atlas.patch_count;
  map.stats.chunks = static_cast<uint32_t>(chunks);
  map.stats.chunk_cell_size = plan.cell_size;
  map.stats.texels_per_unit = texels_per_unit;
  map.stats.locality_radius = plan.locality_radius();
  map.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::ok();
}

}  // namespace tailor::internal
