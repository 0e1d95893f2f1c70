// The chunked engine (tailor/chunks.h, DESIGN.md section 8): the mesh is cut by the chunk rule,
// every chunk is mapped by the whole pipeline (map_texture on the chunk alone) on the next free
// worker thread, and its UVs and patches are written back to the mesh's corners.
//
// Each chunk is mapped in canonical form (chunk_mesh.h), so its UVs are a function of its geometry
// and connectivity alone. Its frame (origin, unit) is its cell's, its texel density is one number
// for the whole mesh (a power of two unless the caller fixed it), so nothing outside the chunk
// reaches in.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "mapping/chunk_mesh.h"
#include "mapping/mapping_common.h"
#include "tailor/chunks.h"
#include "tailor/mapping.h"
#include "tailor/topology.h"
#include "util/huge_pages.h"
#include "util/mesh_bounds.h"

namespace tailor::internal {

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
  total.orientation_seconds += s.orientation_seconds;
  total.growth_seconds += s.growth_seconds;
  total.closing_seconds += s.closing_seconds;
  total.relaxing_seconds += s.relaxing_seconds;
}

MapTextureOptions chunk_map_options(const MapTextureOptions& options, const std::array<double, 3>& origin, double size,
                                    double texels_per_unit) {
  MapTextureOptions o = options;
  o.chunks.mode = ChunkMode::kOff;
  o.measure = false;
  o.stage_progress = nullptr;
  o.mapping.progress = nullptr;
  o.orientation.progress = nullptr;
  o.orientation.fixed_unit_scale = static_cast<float>(1.0 / size);
  for (size_t k = 0; k < 3; ++k) o.orientation.fixed_origin[k] = static_cast<float>(origin[k]);
  o.mapping.scale = static_cast<float>(texels_per_unit * size);
  // Seeds placed by their world position modulo the texture's repeat: where two chunks' patches
  // meet on a plane with one direction (a user axis), their UVs differ by whole repeats and the
  // chunk border does not show under the tiling texture.
  const double period_u = options.mapping.texture_period_px;
  const double period_v = options.mapping.texture_period_v_px > 0.f ? options.mapping.texture_period_v_px : period_u;
  o.orientation.anchor_period = {period_u / o.mapping.scale, period_v / o.mapping.scale};
  o.mapping.seam_faces = {};
  return o;
}

// A chunk is mapped in its cell's frame at texels_per_unit * size pixels per cell side, which the
// mapping takes within its scale's range (MappingLimits). Out of range says what a user can change;
// the cell's exponent is -60..60, so a mesh far from unit scale may need no chunks at all (map_chunks
// says so: a ChunkedMapper or a tile has no other way).
Status check_chunk_scale(double texels_per_unit, double size) {
  const double chunk_scale = texels_per_unit * size;
  if (chunk_scale >= MappingLimits::min_scale && chunk_scale <= MappingLimits::max_scale) return Status::ok();
  char figures[96];
  std::snprintf(figures, sizeof figures, "%.3g pixels per chunk cell of side 2^%d units", chunk_scale,
                std::ilogb(size));
  return Status::error(ErrorCode::kInvalidArgument, "",
                       std::string("the texel density gives ") + figures + ", outside " +
                           limit_text(MappingLimits::min_scale) + " to " + limit_text(MappingLimits::max_scale) +
                           ": give another chunk cell (2^-60 to 2^60) or texel density");
}

Status map_chunk(const MapTextureOptions& options, const std::array<double, 3>& origin, double size,
                 double texels_per_unit, uint32_t threads, ProgressCallback progress, ChunkWorker& w) {
  TAILOR_RETURN_IF_ERROR(check_chunk_scale(texels_per_unit, size));
  const Topology topology = build_topology(w.mesh, {}, threads);
  MapTextureOptions o = chunk_map_options(options, origin, size, texels_per_unit);
  o.mapping.progress = std::move(progress);
  o.mapping.threads = threads;
  o.orientation.threads = threads;
  o.mapping.seam_faces = w.seam_flags;
  return map_texture_in_order(w.mesh, topology, o, w.map);
}

Status map_whole_canonical(const Mesh& mesh, const MapTextureOptions& options, TextureMap& map) {
  const size_t face_count = mesh.face_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  if (!options.mapping.seam_faces.empty() && options.mapping.seam_faces.size() != face_count)
    return Status::error(ErrorCode::kInvalidArgument, "", "seam face flags must hold one entry per face");
  // The Morton keys over a cube that an edit rarely moves: the caller's fixed frame, else a
  // power-of-two cube on the world grid of that size that holds the bounding box (it moves only
  // when the box crosses a power of two), so that an edit leaves the other faces' order as it was.
  std::array<double, 3> origin;
  double side;
  if (options.orientation.fixed_unit_scale > 0.f) {
    side = 1.0 / options.orientation.fixed_unit_scale;
    for (size_t k = 0; k < 3; ++k) origin[k] = options.orientation.fixed_origin[k];
  } else {
    const Bounds box = referenced_bounds(mesh);
    const std::array<double, 3>& lo = box.lo;
    const double extent = box.longest();
    const double grid = extent > 0 && std::isfinite(extent) ? std::exp2(std::ceil(std::log2(extent))) : 1.0;
    for (size_t k = 0; k < 3; ++k) origin[k] = std::isfinite(lo[k]) ? std::floor(lo[k] / grid) * grid : 0.0;
    side = 2 * grid;
  }
  std::vector<uint32_t> all(face_count);
  for (size_t f = 0; f < face_count; ++f) all[f] = static_cast<uint32_t>(f);
  ChunkWorker w;
  build_chunk_mesh(mesh, all, origin, side, options.mapping.seam_faces, w);
  std::vector<uint32_t>().swap(all);
  {
    const Topology topology = build_topology(w.mesh, {}, options.mapping.threads);
    MapTextureOptions o = options;
    o.mapping.seam_faces = w.seam_flags;
    o.measure = false;  // map_texture measures the result on the mesh as given
    TAILOR_RETURN_IF_ERROR(map_texture_in_order(w.mesh, topology, o, w.map));
  }
  // Back to the mesh's faces and corners (write_chunk_atlas), the frames too.
  reserve_huge(map.atlas.corner_uv, 6 * face_count);
  reserve_huge(map.atlas.patch, face_count);
  map.atlas.corner_uv.resize(6 * face_count);
  map.atlas.patch.resize(face_count);
  map.atlas.patch_count = w.map.atlas.patch_count;
  write_chunk_atlas(w, 0, map.atlas.corner_uv.data(), map.atlas.patch.data());
  const FaceFrames& in = w.map.frames;
  FaceFrames& out = map.frames;
  out = FaceFrames{};
  out.normal.resize(3 * face_count);
  out.orientation.resize(3 * face_count);
  out.bitangent.resize(3 * face_count);
  out.area.resize(face_count);
  out.local.resize(6 * face_count);
  out.variation.resize(face_count);
  out.anchor.resize(2 * face_count);
  for (size_t i = 0; i < face_count; ++i) {
    const uint32_t f = w.faces[i].face, r = w.faces[i].rotation;
    std::copy_n(&in.normal[3 * i], 3, &out.normal[3 * size_t{f}]);
    std::copy_n(&in.orientation[3 * i], 3, &out.orientation[3 * size_t{f}]);
    std::copy_n(&in.bitangent[3 * i], 3, &out.bitangent[3 * size_t{f}]);
    out.area[f] = in.area[i];
    out.variation[f] = in.variation[i];
    // The face's corners from its own corner 0 (chunk corner k0); exact when it was not rotated.
    const uint32_t k0 = (3 - r) % 3;
    const float* l = &in.local[6 * i];
    for (uint32_t j = 0; j < 3; ++j) {
      const uint32_t k = (j + 3 - r) % 3;
      out.local[6 * size_t{f} + 2 * j] = r == 0 ? l[2 * k] : l[2 * k] - l[2 * k0];
      out.local[6 * size_t{f} + 2 * j + 1] = r == 0 ? l[2 * k + 1] : l[2 * k + 1] - l[2 * k0 + 1];
    }
    out.anchor[2 * size_t{f}] = r == 0 ? in.anchor[2 * i] : in.anchor[2 * i] + l[2 * k0];
    out.anchor[2 * size_t{f} + 1] = r == 0 ? in.anchor[2 * i + 1] : in.anchor[2 * i + 1] + l[2 * k0 + 1];
  }
  out.axis = in.axis;
  out.axis2 = in.axis2;
  out.origin = in.origin;
  out.bbox_min = in.bbox_min;
  out.bbox_max = in.bbox_max;
  out.unit_scale = in.unit_scale;
  out.degenerate_faces = in.degenerate_faces;
  out.fallback_faces = in.fallback_faces;
  out.skeleton_edges = in.skeleton_edges;
  out.skeleton_closed_holes = in.skeleton_closed_holes;
  out.skeleton_pca_faces = in.skeleton_pca_faces;
  out.skeleton_seconds = in.skeleton_seconds;
  out.seconds = in.seconds;
  map.stats = w.map.stats;
  return Status::ok();
}

double chunk_texels_per_unit(const Mesh& mesh, const MapTextureOptions& options) {
  if (options.orientation.fixed_unit_scale > 0.f)
    return double{options.mapping.scale} * options.orientation.fixed_unit_scale;
  // The longest side of the referenced vertices' bounding box, as the whole-mesh mapping
  // normalises, then the density rounded to a power of two: a local edit that does not change the
  // bounding box by a factor near sqrt(2) leaves it where it is.
  const double longest = referenced_bounds(mesh).longest();
  if (!(longest > 0) || !std::isfinite(longest)) return 0;
  return std::exp2(std::round(std::log2(double{options.mapping.scale} / longest)));
}

Status map_chunks(const Mesh& mesh, const MapTextureOptions& options, TextureMap& map, ChunkPlan* plan_out) {
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
  // A whole mesh may be mapped without chunks, which a ChunkedMapper or a tile cannot: the refusals
  // of a cell (too far, too large, too many pixels; each names the chunk cell) say so here only.
  const auto or_whole = [](Status s) {
    if (s.is_ok() || s.what().find("chunk cell") == std::string::npos) return s;
    return Status::error(s.code(), s.file(), s.what() + ", or map it without chunks (chunks off)", s.where());
  };
  ChunkPlan plan;
  TAILOR_RETURN_IF_ERROR(or_whole(plan_chunks(mesh, options.chunks, plan, options.mapping.threads)));
  const double texels_per_unit = chunk_texels_per_unit(mesh, options);
  TAILOR_RETURN_IF_ERROR(or_whole(check_chunk_scale(texels_per_unit, plan.cell_size)));

  const size_t chunks = plan.chunk_count();
  const size_t cores = std::max<size_t>(std::thread::hardware_concurrency(), 1);
  const size_t threads =
      std::clamp<size_t>(options.mapping.threads ? options.mapping.threads : std::min<size_t>(cores, 64), 1, chunks);
  // With fewer chunks than threads each chunk's own stages get the rest; and a chunk holding a large
  // share of the faces gets that share of the threads (the largest chunk sets the wall time: on a
  // mesh of a few cells, one can hold a fifth of the faces). The result is the same for any count (map_texture's
  // promise); the threads of a large chunk and of the others running beside it may exceed the
  // cores for a while.
  const size_t all_threads = options.mapping.threads ? options.mapping.threads : cores;
  const uint32_t fewer_chunks_threads = static_cast<uint32_t>(std::max<size_t>(1, all_threads / threads));
  auto inner_threads = [&](size_t chunk_faces) {
    const double share =
        static_cast<double>(all_threads) * static_cast<double>(chunk_faces) / static_cast<double>(face_count);
    return std::max(fewer_chunks_threads, static_cast<uint32_t>(std::min<double>(std::round(share), 64.0)));
  };
  // Largest chunks first: the last ones to finish are then the small ones.
  std::vector<uint32_t> order(chunks);
  for (size_t c = 0; c < chunks; ++c) order[c] = static_cast<uint32_t>(c);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return plan.chunk_start[a + 1] - plan.chunk_start[a] > plan.chunk_start[b + 1] - plan.chunk_start[b];
  });

  // Every corner is written by its chunk: on huge pages, the zero-fill before that is nearly free
  // (in 4 KiB pages it was a tenth of the time outside the chunks' own stages).
  reserve_huge(map.atlas.corner_uv, 6 * face_count);
  reserve_huge(map.atlas.patch, face_count);
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
      const std::span<const uint32_t> faces(plan.faces.data() + plan.chunk_start[c],
                                            plan.chunk_start[c + 1] - plan.chunk_start[c]);
      const std::array<double, 3> origin = plan.chunk_origin(c);
      build_chunk_mesh(mesh, faces, origin, plan.chunk_size(c), options.mapping.seam_faces, w);
      const size_t chunk_faces = w.faces.size();
      const Status s = map_chunk(
          options, origin, plan.chunk_size(c), texels_per_unit, inner_threads(chunk_faces),
          [&report, chunk_faces](float done) {
            return report(static_cast<size_t>(done * static_cast<float>(chunk_faces)), 0, false);
          },
          w);
      if (!s) {
        chunk_status[c] = s;
        failed.store(true);
        return;
      }
      write_chunk_atlas(w, 0, map.atlas.corner_uv.data(), map.atlas.patch.data());  // ids offset below
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
  if (plan_out) *plan_out = std::move(plan);
  return Status::ok();
}

}  // namespace tailor::internal
