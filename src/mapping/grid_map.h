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
// wherever it reaches them first (patches). Faces at singularities, or that come out over the
// per-face bound (max_stretch), are unfolded afterwards from a placed neighbour (a similarity
// that copies the shared edge, or a rigid copy when that breaks the bound): the only visible
// seams are theirs.
#pragma once

#include "mapping/mapping_common.h"

namespace tailor::internal {

//! Fills atlas.corner_uv, atlas.patch and patch_count (symmetry 4). Deterministic for any
//! options.threads. O(V) per field iteration; O(F) extraction.
Status map_grid(const MappingInput& input, Atlas& atlas, MappingStats& stats);

}  // namespace tailor::internal
