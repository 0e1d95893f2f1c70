// Relaxation of the lattice coordinates of an integer-grid map (symmetry 4, issue 14).
//
// The position field (surface/rosy_field.h) gives every vertex a lattice coordinate U_v in its own
// chart, and every pair of neighbouring charts a lattice map (quarter turns plus whole repeats).
// Those maps decide which seams are invisible; the coordinates only decide the distortion. The
// field's coordinates are a smoothed guess: a quarter of the faces or more come out over the
// per-face stretch bound and would have to be cut. This step moves the coordinates, with every
// lattice map held, to lower the as-rigid-as-possible energy of the faces the maps close around:
// seams stay on the lattice by construction, the faces get within the bound.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "surface/rosy_field.h"
#include "tailor/mesh.h"
#include "tailor/orientation.h"

namespace tailor::internal {

struct GridRelaxInput {
  const Mesh& mesh;
  const FaceFrames& frames;
  const std::vector<LatticeMap>& corner_map;  //!< #F*3: corner k's chart -> corner 0's chart
  const std::vector<uint8_t>& flat;           //!< #F: 1 where the maps close around the face
  float scale = 800.f;                        //!< pixels per normalised unit
  float period = 512.f;                       //!< lattice period, pixels
  uint32_t iterations = 30;
  size_t threads = 1;
  //! #V, in and out: 1 where a vertex is still moving (it and its neighbours start active; set it
  //! for the vertices of faces whose maps changed); on return, the vertices that moved in the last
  //! sweep. Null or empty: every vertex starts active.
  std::vector<uint8_t>* moving = nullptr;
};

//! Moves uv (#V*2, field.uv: per vertex its lattice coordinate in its own chart, pixels) by local/
//! global ARAP iterations over the flat faces, Gauss-Seidel by vertex colour (no two vertices of a
//! colour share a face), so the result is the same for any thread count. O(F) per iteration at
//! most; vertices that have settled (and their neighbours) are skipped; with input.moving only those
//! still moving and their neighbours start.
void relax_lattice_coordinates(const GridRelaxInput& input, std::vector<float>& uv);

}  // namespace tailor::internal
