// Orientation axis by trial (tailor/axis_choice.h): one map_texture per candidate axis (growth and
// seam shortening), ranked by the seam length its metrics measure.
#include "tailor/axis_choice.h"

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

Status choose_orientation_axis(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                               AxisChoice& choice) {
  choice = AxisChoice{};
  const ProgressCallback& progress = options.mapping.progress;
  MapTextureOptions trial = options;
  trial.mapping.mode = MappingMode::kPatches;  // the thesis mode has one UV per vertex: no seams to rank by
  trial.mapping.close_cracks = false;
  trial.mapping.relax_iterations = 0;  // moves no seam
  trial.mapping.progress = nullptr;
  trial.measure = true;
  TextureMap map;
  for (int i = 0; i < kAxisCandidates; ++i) {
    if (progress && !progress(static_cast<float>(i) / kAxisCandidates))
      return Status::error(ErrorCode::kCancelled, "", "axis choice cancelled");
    const AxisCandidate candidate = static_cast<AxisCandidate>(i);
    trial.orientation = orientation_for(candidate, options.orientation);
    TAILOR_RETURN_IF_ERROR(map_texture(mesh, topology, trial, map));
    choice.seam_ratio[static_cast<size_t>(i)] = map.metrics.seam_length_ratio;
    if (map.metrics.seam_length_ratio < choice.seam_ratio[static_cast<size_t>(choice.best)]) choice.best = candidate;
  }
  if (progress && !progress(1.f)) return Status::error(ErrorCode::kCancelled, "", "axis choice cancelled");
  return Status::ok();
}

}  // namespace tailor
