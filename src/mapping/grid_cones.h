// Cone placement of an integer-grid map (symmetry 4, issue 14).
//
// Around a face where the lattice maps between its corners' charts compose to a quarter turn (a
// cone of the cross field), the maps fix one point: the cone's position in the lattice, a lattice
// point or a cell centre. The field puts the cone in some face; when the relaxed coordinates show
// that fixed point in a neighbouring face instead, every face around has to stretch to close the
// turn there, and the stretched ones are cut (measured: three quarters of the visible seam edges
// at ten times the default scale lie within four faces of a cone). Moving the cone into the face
// that holds its fixed point is a change of one lattice map: across the shared edge, the map is
// composed with the face's turn, so the face closes and its neighbour takes the turn.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "surface/rosy_field.h"
#include "tailor/mesh.h"
#include "tailor/topology.h"

namespace tailor::internal {

struct ConeMoves {
  uint32_t cones = 0;  //!< faces whose maps compose to a turn
  uint32_t moved = 0;  //!< cones moved at least once
  uint32_t steps = 0;  //!< edges crossed in all
};

//! edge_map: per half-edge e = 3f + k the lattice map from the chart of its end vertex (corner k+1)
//! to its start's (corner k); a paired half-edge holds the inverse of its opposite's (lattice_map
//! gives that). Each cone walks (in face order, at most a few faces) towards the face that holds its
//! fixed point in the coordinates uv (#V*2, per vertex in its own chart), never into another
//! singular face or across the boundary. Deterministic, sequential; O(cones).
ConeMoves move_cones(const Mesh& mesh, const Topology& topology, const std::vector<float>& uv, float period,
                     std::vector<LatticeMap>& edge_map);

//! Cones next to a cone of the opposite turn (noise in the field: a pair within a few faces) hand
//! their turn to it, and both close (or leave a dislocation, merged next). Returns the pairs.
//! Deterministic, sequential; O(cones x faces within reach).
uint32_t cancel_cone_pairs(const Mesh& mesh, const Topology& topology, std::vector<LatticeMap>& edge_map);

//! Faces whose maps compose to a whole-repeat shift (a dislocation, no turn) hand the shift along
//! the shortest path of faces to the nearest other singular face within a few faces: two
//! opposite dislocations cancel, one that meets a cone moves the cone's fixed point. Returns the
//! dislocations merged. Deterministic, sequential; O(dislocations x faces within reach).
uint32_t merge_dislocations(const Mesh& mesh, const Topology& topology, std::vector<LatticeMap>& edge_map);

//! Per face the maps of its corners into corner 0's chart (corner_map, #F*3) and whether they
//! compose to the identity around the face (flat, #F), from the half-edge maps.
void maps_from_edges(size_t face_count, size_t threads, const std::vector<LatticeMap>& edge_map,
                     std::vector<LatticeMap>& corner_map, std::vector<uint8_t>& flat);

}  // namespace tailor::internal
