// tailor: stability of the mapping under removal of part of the mesh (thesis 2.6, DESIGN.md 5).
//
// Maps the whole mesh, removes the faces whose centroids lie in a ball holding ~remove_fraction
// of the faces (centred on the face farthest from the seed face; if it still holds the seed, both
// runs start at the surviving face nearest to the seed instead), maps
// what is left with the same seed point, the same global axis and the same unit-cube
// normalisation (as a streaming client that keeps them would), and compares the UVs of the
// surviving corners.
#pragma once

#include <cstdint>

#include "tailor/api.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/option_doc.h"
#include "tailor/orientation.h"
#include "tailor/status.h"

namespace tailor {

struct StabilityOptions {
  float remove_fraction = 0.1f;  //!< share of faces removed, (0, 0.9]
};

//! Flags and help of the StabilityOptions (option_doc.h).
inline constexpr OptionDoc kStabilityOptionDocs[] = {
    {"remove_fraction", "--remove-fraction", "With --stability: share of the faces removed"},
};

struct StabilityReport {
  size_t faces = 0;                 //!< faces of the full mesh
  size_t removed_faces = 0;         //!< faces removed (inside the ball)
  size_t compared_corners = 0;      //!< corners of surviving faces
  double mean_difference_px = 0;    //!< mean |uv_full - uv_cut| over surviving corners, pixels
  double max_difference_px = 0;     //!< largest such difference, pixels
  double median_difference_px = 0;  //!< median of the differences, pixels (robust to the few regions that a
                                    //!< changed growth order re-places whole)
  double identical_ratio = 0;       //!< share of surviving corners with bit-identical UVs
  double within_1px_ratio = 0;      //!< share of surviving corners that moved less than 1 px
  uint32_t patches_full = 0;        //!< patches of the full mapping
  uint32_t patches_cut = 0;         //!< patches of the cut mapping
  double seconds = 0;               //!< wall time
};

//! Runs the experiment above, both mappings by map_texture with `options` (its axis and, when
//! given, seed point resolved on the full mesh; options.mapping.progress and options.measure are
//! ignored: no metrics are computed). Fails like map_texture (its Status is returned), or with
//! kInvalidArgument when remove_fraction is out of range, or kInvalidMesh when the mesh has fewer
//! than 10 faces. Cost: two orientation + mapping runs, O(F log F). Deterministic.
TAILOR_API Status measure_stability(const Mesh& mesh, const MapTextureOptions& options, StabilityReport& report,
                                    const StabilityOptions& stability = {});

}  // namespace tailor
