// Orientation axis by trial (tailor/axis_choice.h): one growth per candidate axis, ranked by the
// seam length compute_uv_metrics measures.
#include "tailor/axis_choice.h"

#include "tailor/atlas.h"
#include "tailor/metrics.h"

namespace tailor {

const char* axis_candidate_name(AxisCandidate candidate) {
  switch (candidate) {
    case AxisCandidate::kPca: return "pca";
    case AxisCandidate::kX: return "x";
    case AxisCandidate::kY: return "y";
    case AxisCandidate::kZ: return "z";
  }
  return "pca";
}

OrientationOptions orientation_for(AxisCandidate candidate, const OrientationOptions& base) {
  OrientationOptions options = base;
  if (candidate == AxisCandidate::kPca) {
    options.axis = AxisSource::kPca;
    return options;
  }
  options.axis = AxisSource::kUser;
  options.user_axis = {0.f, 0.f, 0.f};
  options.user_axis[static_cast<size_t>(candidate) - 1] = 1.f;
  options.user_axis2 = {0.f, 0.f, 0.f};  // derived from the axis
  return options;
}

Status choose_orientation_axis(const Mesh& mesh, const Topology& topology, const OrientationOptions& base,
                               const MappingOptions& mapping, AxisChoice& choice) {
  choice = AxisChoice{};
  MappingOptions growth = mapping;
  growth.mode = MappingMode::kPatches;  // the thesis mode has one UV per vertex: no seams to rank by
  growth.close_cracks = false;
  growth.relax_iterations = 0;  // moves no seam
  growth.progress = nullptr;
  FaceFrames frames;
  Atlas atlas;
  UvMetrics metrics;
  for (int i = 0; i < kAxisCandidates; ++i) {
    if (mapping.progress && !mapping.progress(static_cast<float>(i) / kAxisCandidates))
      return Status::error(ErrorCode::kCancelled, "", "axis choice cancelled");
    const AxisCandidate candidate = static_cast<AxisCandidate>(i);
    TAILOR_RETURN_IF_ERROR(compute_orientation(mesh, topology, orientation_for(candidate, base), frames));
    TAILOR_RETURN_IF_ERROR(map_texture(mesh, topology, frames, growth, atlas));
    TAILOR_RETURN_IF_ERROR(compute_uv_metrics(mesh, topology, atlas.corner_uv, atlas.patch, {}, metrics));
    choice.seam_ratio[static_cast<size_t>(i)] = metrics.seam_length_ratio;
    if (metrics.seam_length_ratio < choice.seam_ratio[static_cast<size_t>(choice.best)]) choice.best = candidate;
  }
  if (mapping.progress && !mapping.progress(1.f)) return Status::error(ErrorCode::kCancelled, "", "axis choice cancelled");
  return Status::ok();
}

}  // namespace tailor
