// Texture mapping entry point: map_texture runs the pipeline, one stage per module, in order:
// the orientation field (surface/orientation.cpp), the growth (grow_patches.cpp, or the thesis
// reference in thesis_mode.cpp), seam shortening (shorten_seams.cpp), crack closing
// (close_cracks.cpp), relaxation (relax_patches.cpp), the metrics (metrics/uv_metrics.cpp); with
// symmetry 4 the integer-grid map (grid_map.cpp) takes the place of the growth. Here: the
// checks of the options and the components' seed order.
//
// This work is based on:
//   V. Singh, A. M. Namboodiri, "Efficient texture mapping by homogeneous patch discovery",
//   ICVGIP 2012 (thesis chapter 2).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "mapping/chunk_mesh.h"
#include "mapping/face_stretch.h"
#include "mapping/grid_map.h"
#include "mapping/mapping_common.h"
#include "metrics/stored_metrics.h"
#include "tailor/mapping.h"

namespace tailor {

float face_stretch_error(std::span<const float, 6> local, float scale, std::span<const float, 6> uv) {
  return internal::stretch_error(internal::stretch_frame(local.data(), scale), uv.data());
}

std::vector<uint32_t> component_seed_faces(const Mesh& mesh, const Topology& topology, const FaceFrames& frames,
                                           const MappingOptions& options) {
  const size_t face_count = mesh.face_count();
  const float* pos = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();
  double target[3];
  if (options.use_seed_point) {
    for (int i = 0; i < 3; ++i) target[i] = options.seed_point[i];
  } else {
    // Centre of the bounding box of the referenced vertices (found by the orientation; float
    // min/max are exact, so doubles are only needed for the centre).
    for (int i = 0; i < 3; ++i)
      target[i] = 0.5 * (static_cast<double>(frames.bbox_min[static_cast<size_t>(i)]) +
                         frames.bbox_max[static_cast<size_t>(i)]);
  }
  const uint32_t components = topology.edge_components;
  std::vector<double> best_distance(components, INFINITY);
  std::vector<uint32_t> best_face(components, kInvalid);
  // Distances of three times the centroid to three times the target: the same order without a
  // division per face.
  for (int i = 0; i < 3; ++i) target[i] *= 3.0;
  for (size_t f = 0; f < face_count; ++f) {
    double d2 = 0;
    const float* a = pos + 3 * idx[3 * f];
    const float* b = pos + 3 * idx[3 * f + 1];
    const float* c = pos + 3 * idx[3 * f + 2];
    for (int i = 0; i < 3; ++i) {
      const double d = static_cast<double>(a[i]) + b[i] + c[i] - target[i];
      d2 += d * d;
    }
    const uint32_t comp = topology.face_component[f];
    if (d2 < best_distance[comp]) {  // strict: the lowest face id wins ties
      best_distance[comp] = d2;
      best_face[comp] = static_cast<uint32_t>(f);
    }
  }
  std::vector<uint32_t> order;
  order.reserve(components);
  for (uint32_t c = 0; c < components; ++c)
    if (best_face[c] != kInvalid) order.push_back(c);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    if (best_distance[a] != best_distance[b]) return best_distance[a] < best_distance[b];
    return best_face[a] < best_face[b];
  });
  std::vector<uint32_t> seeds(order.size());
  for (size_t i = 0; i < order.size(); ++i) seeds[i] = best_face[order[i]];
  return seeds;
}

namespace {

// Checks what steps 2-4 are given (the frames come from step 1), before any of them runs.
Status check_mapping_inputs(const Mesh& mesh, const Topology& topology, const FaceFrames& frames,
                            const MappingOptions& options) {
  const size_t face_count = mesh.face_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  if (topology.opposite.size() != 3 * face_count || topology.face_component.size() != face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "topology does not match the mesh");
  if (frames.face_count() != face_count || frames.local.size() != 6 * face_count ||
      frames.variation.size() != face_count || frames.anchor.size() != 2 * face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "face frames do not match the mesh");
  if (!options.seam_faces.empty() && options.seam_faces.size() != face_count)
    return Status::error(ErrorCode::kInvalidArgument, "", "seam face flags must hold one entry per face");
  return internal::check_mapping_values(options);
}

// Cleared, not freed: a caller mapping again reuses the memory (no page faults on 37 MB).
void clear_atlas(Atlas& atlas) {
  atlas.corner_uv.clear();
  atlas.patch.clear();
  atlas.patch_count = 0;
}

}  // namespace

namespace internal {

Status check_mapping_values(const MappingOptions& options) {
  using L = MappingLimits;
  if (!(options.scale >= L::min_scale && options.scale <= L::max_scale))
    return Status::error(
        ErrorCode::kInvalidArgument, "",
        "scale must be in [" + limit_text(L::min_scale) + ", " + limit_text(L::max_scale) + "] pixels");
  if (!(options.max_stretch >= L::min_max_stretch && options.max_stretch <= L::max_max_stretch))
    return Status::error(
        ErrorCode::kInvalidArgument, "",
        "max stretch must be in [" + limit_text(L::min_max_stretch) + ", " + limit_text(L::max_max_stretch) + "]");
  if (!(options.field_following >= 0.f && options.field_following <= 1.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "field following must be in [0, 1]");
  if (!(options.max_seed_rotation_deg >= 0.f && options.max_seed_rotation_deg <= 180.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "max seed rotation must be in [0, 180] degrees");
  if (!(options.threshold_px > 0.f) || !std::isfinite(options.threshold_px) || !(options.threshold_step_px > 0.f) ||
      !std::isfinite(options.threshold_step_px))
    return Status::error(ErrorCode::kInvalidArgument, "", "threshold and its step must be positive pixels");
  if (!(options.hop_age >= 0.f && options.hop_age <= L::max_hop_age))
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "hop age must be in [0, " + limit_text(L::max_hop_age) + "] radians");
  if (options.crack_rings < L::min_crack_rings || options.crack_rings > L::max_crack_rings)
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "crack rings must be in [" + std::to_string(L::min_crack_rings) + ", " +
                             std::to_string(L::max_crack_rings) + "]");
  if (options.relax_iterations > L::max_relax_iterations)
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "relax iterations must be at most " + std::to_string(L::max_relax_iterations));
  if (!std::isfinite(options.factor_step) || options.factor_step > 1.0)
    return Status::error(ErrorCode::kInvalidArgument, "", "factor step must be finite and at most 1");
  if (options.use_seed_point && !(std::isfinite(options.seed_point[0]) && std::isfinite(options.seed_point[1]) &&
                                  std::isfinite(options.seed_point[2])))
    return Status::error(ErrorCode::kInvalidArgument, "", "seed point must be finite");
  if (options.symmetry != 1 && options.symmetry != 4)
    return Status::error(ErrorCode::kInvalidArgument, "", "symmetry must be 1 or 4");
  if (options.symmetry == 4 && (options.mode != MappingMode::kPatches || !(options.texture_period_px >= 1.f) ||
                                !std::isfinite(options.texture_period_px)))
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "symmetry 4 needs the patches mode and a texture period >= 1 px");
  return Status::ok();
}

double factor_step_for(const MappingOptions& options, size_t face_count) {
  const bool thesis = options.mode == MappingMode::kThesis;
  // Patches mode: negative = the hop rule (hop_age); with hop_age 0, the global counter at 1e-4.
  if (options.factor_step < 0 && (thesis || options.hop_age == 0.f))
    return thesis ? 1.0 / static_cast<double>(face_count) : 1e-4;
  return options.factor_step;
}

}  // namespace internal

const char* mapping_mode_name(MappingMode mode) { return mode == MappingMode::kThesis ? "thesis" : "patches"; }

bool mapping_mode_from_name(std::string_view name, MappingMode& mode) {
  if (name == "patches")
    mode = MappingMode::kPatches;
  else if (name == "thesis")
    mode = MappingMode::kThesis;
  else
    return false;
  return true;
}

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The progress of one named stage of options.stage_progress (empty when that is unset).
ProgressCallback stage_progress(const StageProgressCallback& stage, const char* name) {
  return stage ? ProgressCallback([&stage, name](float done) { return stage(name, done); }) : ProgressCallback();
}

// Calls both (either may be empty); cancelled when either asks.
ProgressCallback both_progress(ProgressCallback a, ProgressCallback b) {
  if (!a || !b) return a ? a : b;
  return ProgressCallback([a, b](float done) { return a(done) && b(done); });
}

}  // namespace

Status map_texture(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options, TextureMap& map) {
  clear_atlas(map.atlas);
  map.stats = MappingStats{};
  map.metrics = UvMetrics{};
  // === 0. Chunks: a large mesh is cut by the world-space chunk rule and every chunk runs steps
  //        1-4 on its own, in parallel (mapping/map_chunks.cpp, tailor/chunks.h); a smaller mesh
  //        runs them on the whole mesh rebuilt in canonical order, so that the file's order of
  //        faces, vertices and corners does not change a bit. The topology serves the metrics. ===
  TAILOR_RETURN_IF_ERROR(check_chunk_options(options.chunks));
  if (options.measure && topology.opposite.size() != 3 * mesh.face_count())
    return Status::error(ErrorCode::kInvalidMesh, "", "topology does not match the mesh");
  // The skeleton axis needs the whole mesh: auto maps it whole, `on` refuses it (map_chunks).
  const bool whole_only = options.chunks.mode == ChunkMode::kAuto && options.orientation.axis == AxisSource::kSkeleton;
  const bool chunked = uses_chunks(options.chunks, mesh.face_count()) && !whole_only;
  TAILOR_RETURN_IF_ERROR(chunked ? internal::map_chunks(mesh, options, map)
                                 : internal::map_whole_canonical(mesh, options, map));
  // === 5. Metrics of the result, on the mesh as given (metrics/uv_metrics.cpp) ===
  return options.measure ? measure_texture_map(mesh, topology, options, map) : Status::ok();
}

// The metrics of the result, measured as a file holds the map (`tailor eval` of it reports the same
// figures): the UVs in texture repeats as the writers store them, patches as the UVs join faces.
Status measure_texture_map(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                           TextureMap& map) {
  if (topology.opposite.size() != 3 * mesh.face_count())
    return Status::error(ErrorCode::kInvalidMesh, "", "topology does not match the mesh");
  if (map.atlas.corner_uv.size() != 6 * mesh.face_count())
    return Status::error(ErrorCode::kInvalidMesh, "", "the atlas does not match the mesh");
  const StageProgressCallback& stage = options.stage_progress;
  if (stage && !stage("metrics", 0.f)) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
  // For a power-of-two texture the stored repeats scale back to the atlas's own pixels: it is
  // measured as it is (a copy of the UVs is 24 bytes per face at the mapping's peak).
  const float width = options.metrics.texture_width_px, height = options.metrics.texture_height_px;
  if (internal::stored_round_trip_exact(map.atlas.corner_uv, width, height)) {
    TAILOR_RETURN_IF_ERROR(internal::compute_stored_uv_metrics_px(mesh, &topology, map.atlas.corner_uv, options.metrics,
                                                                  map.metrics, nullptr));
  } else {
    std::vector<float> stored;
    uv_repeats_from_px(map.atlas.corner_uv, width, height, stored);
    TAILOR_RETURN_IF_ERROR(compute_stored_uv_metrics(mesh, &topology, std::move(stored), options.metrics, map.metrics));
  }
  if (stage && !stage("metrics", 1.f)) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
  return Status::ok();
}

Status internal::map_texture_in_order(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                                      TextureMap& map) {
  clear_atlas(map.atlas);
  map.stats = MappingStats{};
  map.metrics = UvMetrics{};
  // === 1. Orientation field: per-face frames, the field and its variation (surface/orientation.cpp) ===
  const auto start = std::chrono::steady_clock::now();
  if (options.stage_progress) {
    OrientationOptions orientation = options.orientation;
    orientation.progress = both_progress(orientation.progress, stage_progress(options.stage_progress, "orientation"));
    TAILOR_RETURN_IF_ERROR(compute_orientation(mesh, topology, orientation, map.frames));
  } else {
    TAILOR_RETURN_IF_ERROR(compute_orientation(mesh, topology, options.orientation, map.frames));
  }
  const double orientation_seconds = seconds_since(start);
  TAILOR_RETURN_IF_ERROR(internal::map_texture_frames(mesh, topology, options, map));
  map.stats.orientation_seconds = orientation_seconds;
  return Status::ok();
}

Status internal::map_texture_frames(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                                    TextureMap& map) {
  clear_atlas(map.atlas);
  map.stats = MappingStats{};
  map.metrics = UvMetrics{};
  const MappingOptions& mapping = options.mapping;
  // Each stage's own progress (options.stage_progress), beside the growth and closing's shares of
  // mapping.progress.
  const StageProgressCallback& stage = options.stage_progress;
  auto stage_callback = [&stage](const char* name) { return stage_progress(stage, name); };
  const auto both = both_progress;
  const auto start = std::chrono::steady_clock::now();
  TAILOR_RETURN_IF_ERROR(check_mapping_inputs(mesh, topology, map.frames, mapping));
  const bool thesis = mapping.mode == MappingMode::kThesis;
  const bool grid = mapping.symmetry == 4;                    // the integer-grid map replaces the growth (step 2)
  const bool close_cracks = !thesis && mapping.close_cracks;  // steps 3-5 follow the patches mode's growth or grid
  // With crack closing the growth reports the first part of the progress, the closing the rest
  // (measured: the closing takes 70-90% of the mapping time; the grid map's fields take most of it).
  const float growth_share = grid ? 0.8f : 0.2f;
  MappingOptions growth_options = mapping;
  if (close_cracks && mapping.progress)
    growth_options.progress = [&mapping, growth_share](float done) { return mapping.progress(growth_share * done); };
  ProgressCallback closing_progress;
  if (close_cracks && mapping.progress)
    closing_progress = [&mapping, growth_share](float done) {
      return mapping.progress(growth_share + (1.f - growth_share) * done);
    };
  growth_options.progress = both(growth_options.progress, stage_callback("mapping"));
  closing_progress = both(closing_progress, stage_callback("closing"));
  const internal::MappingInput input{mesh,
                                     topology,
                                     map.frames,
                                     growth_options,
                                     internal::factor_step_for(mapping, mesh.face_count()),
                                     component_seed_faces(mesh, topology, map.frames, mapping)};
  MappingStats& stats = map.stats;
  stats.components = static_cast<uint32_t>(input.component_seeds.size());

  // === 2. Growth: the patch-discovery front (mapping/grow_patches.cpp), or the thesis's (thesis_mode.cpp);
  //        with symmetry 4 the integer-grid map instead (mapping/grid_map.cpp) ===
  std::vector<uint8_t> on_seam;  // per face: placed on a seam by the growth (where step 3 looks)
  auto stage_start = start;
  Status status = grid     ? internal::map_grid(input, map.atlas, stats, on_seam)
                  : thesis ? internal::map_thesis(input, map.atlas, stats)
                           : internal::grow_patches(input, map.atlas, stats, on_seam);
  // === 3. Seam shortening (mapping/shorten_seams.cpp) ===
  if (status.is_ok() && !thesis && mapping.shorten_seams)
    stats.faces_reseamed = internal::shorten_seams(input, on_seam, map.atlas);
  if (status.is_ok() && stage && !stage("mapping", 1.f))  // the growth reports only every few thousand faces
    status = Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
  stats.growth_seconds = seconds_since(stage_start);
  // === 4. Crack closing (mapping/close_cracks.cpp) ===
  stage_start = std::chrono::steady_clock::now();
  if (status.is_ok() && close_cracks)
    status = internal::close_cracks(input, closing_progress, map.atlas, stats.cracks_closed);
  stats.closing_seconds = seconds_since(stage_start);
  // === 5. Relaxation of the angle distortion (mapping/relax_patches.cpp) ===
  stage_start = std::chrono::steady_clock::now();
  if (status.is_ok() && !thesis && mapping.relax_iterations > 0)
    status = internal::relax_patches(input, map.atlas, stats.relax_moves, stage_callback("relaxing"));
  stats.relaxing_seconds = seconds_since(stage_start);
  if (!status.is_ok()) {
    clear_atlas(map.atlas);
    map.stats = MappingStats{};
    return status;
  }
  stats.patches = map.atlas.patch_count;
  stats.seconds = seconds_since(start);

  // === 6. Metrics of the result (metrics/uv_metrics.cpp) ===
  return options.measure ? measure_texture_map(mesh, topology, options, map) : Status::ok();
}

}  // namespace tailor
