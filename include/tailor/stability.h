// tailor: stability of the mapping under removal of part of the mesh (thesis 2.6, DESIGN.md 5).
//
// Two experiments, each a fresh mapping with the same options and nothing carried over (what a
// streaming client that maps each piece as it loads gets):
//  - order: the mesh written with its faces, vertices and corners in another order is mapped
//    again; the share of corners with bit-identical UVs (the chunked engine: 1.0);
//  - edit: the faces whose centroids lie in a ball holding ~remove_fraction of the faces (centred
//    on the face farthest from the centre of the bounding box) are removed, what is left is mapped
//    again, and the UVs of the surviving corners are compared, overall and beyond the locality
//    radius the mapping reports (MappingStats::locality_radius; chunked mapping only).
// With pin_frame the edit experiment is the thesis's (Table 2.1) instead: both runs keep the full
// mesh's axis, unit-cube normalisation and seed point, as a client that stored them would.
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
  bool pin_frame = false;        //!< edit experiment with the full mesh's axis, normalisation and seed (and
                                 //!< no order experiment); false: both runs fresh
};

//! Flags and help of the StabilityOptions (option_doc.h).
inline constexpr OptionDoc kStabilityOptionDocs[] = {
    {"remove_fraction", "--remove-fraction", "With --stability: share of the faces removed"},
};

struct StabilityReport {
  size_t faces = 0;                   //!< faces of the full mesh
  size_t removed_faces = 0;           //!< faces removed (inside the ball)
  size_t compared_corners = 0;        //!< corners of surviving faces
  double mean_difference_px = 0;      //!< mean |uv_full - uv_cut| over surviving corners, pixels
  double max_difference_px = 0;       //!< largest such difference, pixels
  double median_difference_px = 0;    //!< median of the differences, pixels (robust to the few regions that a
                                      //!< changed growth order re-places whole)
  double identical_ratio = 0;         //!< share of surviving corners with bit-identical UVs
  double within_1px_ratio = 0;        //!< share of surviving corners that moved less than 1 px
  uint32_t patches_full = 0;          //!< patches of the full mapping
  uint32_t patches_cut = 0;           //!< patches of the cut mapping
  double order_identical_ratio = -1;  //!< share of corners bit-identical after reordering (-1: not measured)
  double locality_radius = 0;         //!< the full mapping's MappingStats::locality_radius (0: mapped whole)
  size_t corners_beyond_radius = 0;   //!< surviving corners farther than locality_radius from every removed face
  double identical_beyond_radius_ratio = -1;  //!< share of those bit-identical (-1: none, or mapped whole)
  double seconds = 0;                         //!< wall time
};

//! Runs the experiments above, every mapping by map_texture with `options`
//! (options.mapping.progress and options.measure are ignored: no metrics are computed). Fails like map_texture (its
//! Status is returned), or with kInvalidArgument when remove_fraction is out of range, or kInvalidMesh when the mesh
//! has fewer than 10 faces. Cost: three mappings (two with pin_frame), O(F log F). Deterministic.
TAILOR_API Status measure_stability(const Mesh& mesh, const MapTextureOptions& options, StabilityReport& report,
                                    const StabilityOptions& stability = {});

}  // namespace tailor
