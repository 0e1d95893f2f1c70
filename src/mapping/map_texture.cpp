// Texture mapping entry point: validates the inputs, orders the components' seeds and dispatches
// to the patches mode (mapping_patches.cpp) or the thesis reference (mapping_thesis.cpp).
//
// This work is based on:
//   V. Singh, A. M. Namboodiri, "Efficient texture mapping by homogeneous patch discovery",
//   ICVGIP 2012 (thesis chapter 2).
#include "tailor/mapping.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "mapping/face_stretch.h"
#include "mapping/mapping_common.h"

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
      target[i] = 0.5 * (static_cast<double>(frames.bbox_min[static_cast<size_t>(i)]) + frames.bbox_max[static_cast<size_t>(i)]);
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

namespace internal {

}  // namespace internal

Status map_texture(const Mesh& mesh, const Topology& topology, const FaceFrames& frames,
                   const MappingOptions& options, Atlas& atlas, MappingStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  // Cleared, not freed: a caller mapping again reuses the memory (no page faults on 37 MB).
  atlas.corner_uv.clear();
  atlas.patch.clear();
  atlas.patch_count = 0;
  const size_t face_count = mesh.face_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  if (topology.opposite.size() != 3 * face_count || topology.face_component.size() != face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "topology does not match the mesh");
  if (frames.face_count() != face_count || frames.local.size() != 6 * face_count ||
      frames.variation.size() != face_count || frames.anchor.size() != 2 * face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "face frames do not match the mesh");
  if (!(options.scale > 0.f) || !std::isfinite(options.scale) || options.scale > 1e7f)
    return Status::error(ErrorCode::kInvalidArgument, "", "scale must be a positive finite number of pixels (<= 1e7)");
  if (!(options.max_stretch >= 0.01f && options.max_stretch <= 4.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "max stretch must be in [0.01, 4]");
  if (!(options.field_following >= 0.f && options.field_following <= 1.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "field following must be in [0, 1]");
  if (!(options.max_seed_rotation_deg >= 0.f && options.max_seed_rotation_deg <= 180.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "max seed rotation must be in [0, 180] degrees");
  if (!(options.threshold_px > 0.f) || !std::isfinite(options.threshold_px) || !(options.threshold_step_px > 0.f) ||
      !std::isfinite(options.threshold_step_px))
    return Status::error(ErrorCode::kInvalidArgument, "", "threshold and its step must be positive pixels");
  if (!(options.hop_age >= 0.f && options.hop_age <= 1.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "hop age must be in [0, 1] radians");
  if (options.crack_rings < 2 || options.crack_rings > 64)
    return Status::error(ErrorCode::kInvalidArgument, "", "crack rings must be in [2, 64]");
  if (options.relax_iterations > 1000)
    return Status::error(ErrorCode::kInvalidArgument, "", "relax iterations must be at most 1000");
  if (!std::isfinite(options.factor_step) || options.factor_step > 1.0)
    return Status::error(ErrorCode::kInvalidArgument, "", "factor step must be finite and at most 1");
  if (!options.seam_faces.empty() && options.seam_faces.size() != face_count)
    return Status::error(ErrorCode::kInvalidArgument, "", "seam face flags must hold one entry per face");
  if (options.use_seed_point && !(std::isfinite(options.seed_point[0]) && std::isfinite(options.seed_point[1]) &&
                                  std::isfinite(options.seed_point[2])))
    return Status::error(ErrorCode::kInvalidArgument, "", "seed point must be finite");

  const bool thesis = options.mode == MappingMode::kThesis;
  double factor_step = options.factor_step;
  // Patches mode: negative = the hop rule (hop_age); with hop_age 0, the global counter at 1e-4.
  if (factor_step < 0 && (thesis || options.hop_age == 0.f)) factor_step = thesis ? 1.0 / static_cast<double>(face_count) : 1e-4;
  // With crack closing the growth reports the first part of the progress, the closing the rest
  // (measured: the closing takes 70-90% of the mapping time).
  const bool close_cracks = !thesis && options.close_cracks;
  constexpr float kGrowthShare = 0.2f;
  MappingOptions growth_options = options;
  if (close_cracks && options.progress)
    growth_options.progress = [&options](float done) { return options.progress(kGrowthShare * done); };
  internal::MappingInput input{mesh, topology, frames, growth_options, factor_step,
                               component_seed_faces(mesh, topology, frames, options)};
  MappingStats local_stats;
  local_stats.components = static_cast<uint32_t>(input.component_seeds.size());
  Status status = thesis ? internal::map_thesis(input, atlas, local_stats)
                         : internal::map_patches(input, atlas, local_stats);
  if (status.is_ok() && close_cracks) {
    ProgressCallback closing_progress;
    if (options.progress)
      closing_progress = [&options](float done) { return options.progress(kGrowthShare + (1.f - kGrowthShare) * done); };
    status = internal::close_cracks(input, closing_progress, atlas, local_stats.cracks_closed);
  }
  if (status.is_ok() && !thesis && options.relax_iterations > 0)
    status = internal::relax_patches(input, atlas, local_stats.relax_moves);
  if (!status.is_ok()) {
    atlas.corner_uv.clear();
    atlas.patch.clear();
    atlas.patch_count = 0;
    return status;
  }
  local_stats.patches = atlas.patch_count;
  local_stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = local_stats;
  return Status::ok();
}

}  // namespace tailor
