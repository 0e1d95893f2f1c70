// tailor: choosing the orientation field's axis by the seams it leads to (CLI `--axis auto`).
//
// The thesis projects the first principal axis onto every face. On CAD parts, whose faces are
// mostly aligned with the coordinate axes while the principal axis runs diagonally, that field
// jumps between faces and the growth cuts there: a coordinate axis halves their seams
// (adis16480 13.4% -> 4.0% of edge length). On scans the four candidates are within a point or two.
#pragma once

#include <array>
#include <cstdint>

#include "tailor/api.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace tailor {

//! The axes choose_orientation_axis tries, in this order (ties go to the earlier one).
enum class AxisCandidate : uint8_t { kPca, kX, kY, kZ };
inline constexpr int kAxisCandidates = 4;

//! Short name of a candidate: "pca", "x", "y", "z".
TAILOR_API const char* axis_candidate_name(AxisCandidate candidate);

//! `base` with its axis set to `candidate` (kPca, or kUser with a unit coordinate axis).
TAILOR_API OrientationOptions orientation_for(AxisCandidate candidate, const OrientationOptions& base);

struct AxisChoice {
  AxisCandidate best = AxisCandidate::kPca;          //!< the candidate with the least seam length
  std::array<double, kAxisCandidates> seam_ratio{};  //!< per candidate: seam length / edge length of the growth
};

//! Maps the mesh once per candidate axis (orientation_for(candidate, options.orientation)) with
//! map_texture in patches mode minus the crack closing (the growth and seam shortening, which rank
//! the axes as the full mapping does on CAD parts, at a fifth of its cost; in thesis mode every
//! candidate would score 0) and picks the axis leaving the least seam length.
//! options.mapping.progress, if set, gets the share of candidates done; false cancels
//! (kCancelled). Fails as map_texture does. Cost: four orientations, growths and metrics,
//! O(F log front). Deterministic.
TAILOR_API Status choose_orientation_axis(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                                          AxisChoice& choice);

}  // namespace tailor
