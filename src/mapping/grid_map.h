// Integer-grid mapping for tiles with 4-fold symmetry (MappingOptions::symmetry = 4, issue 14).
//
// A 4-RoSy orientation field and a lattice position field per vertex (surface/rosy_field.h) give
// every vertex a chart: its coordinate U_v modulo the texture period, in its own frame. Between
// neighbouring vertices the charts differ by a lattice map (quarter turns plus whole repeats).
// Each face expresses its three corners in its first corner's chart through those maps; where the
// maps compose to the identity around the face (no singularity) any two such faces sharing an
// edge differ by one lattice map along the whole edge, so the seam between them is invisible
// under a texture that tiles with period T and looks the same turned by 90 degrees. A breadth-
// first walk over those faces chains the lattice maps so that neighbours get identical UVs
// wherever it reaches them first (patches). The coordinates are relaxed first with the maps held
// (grid_relax.h), which puts far more faces within the bound. Faces at singularities, or that come
// out over the lattice bound (lattice_max_stretch), are unfolded afterwards from a placed
// neighbour (a similarity that copies the shared edge, or a rigid copy when that breaks
// max_stretch): the only visible seams are theirs. map_texture then shortens the seams, closes
// cracks and relaxes the angles as in the patches mode, keeping invisible seams as they are.
#pragma once

#include <cstdint>
#include <vector>

#include "mapping/mapping_common.h"

namespace tailor::internal {

//! The per-face bound of a face that keeps its lattice chart: looser than max_stretch, because
//! cutting such a face makes visible seams and stretching it does not. 6x max_stretch (singular
//! values within [1/2.5, 2.5] by default, within the Sander Linf <= 3; map_grid keeps L2
//! within its budget by cutting the most squashed faces). Medians over the 16 shared meshes,
//! visible seams at scale 800 / 8000 (over-relaxation 1.9, L2 budget): 4x: 2.88 / 1.60 %, Linf
//! <= 1.99; 5x: 2.88 / 1.53 %, 2.24; 6x: 2.85 / 1.46 %, 2.49; 7x: 2.84 / 1.44 %, 2.73; 8x: 2.83 /
//! 1.41 %, 2.99 (too near 3). Before the L2 budget, 8x put L2 past 1.02.
inline float lattice_max_stretch(float max_stretch) { return 6.f * max_stretch; }

//! Fills atlas.corner_uv, atlas.patch and patch_count (symmetry 4), and on_seam (#F, where the
//! seam shortening looks: every face). Deterministic for any options.threads. O(V) per field
//! iteration; O(F) per relaxation iteration and for the extraction.
Status map_grid(const MappingInput& input, Atlas& atlas, MappingStats& stats, std::vector<uint8_t>& on_seam);

}  // namespace tailor::internal
