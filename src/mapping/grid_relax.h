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
#include "util/block_sweep.h"

namespace tailor::internal {

//! The relaxation of one mesh at one scale: built once (the faces' gradients and areas, each
//! vertex's corners, the blocks and their colours), run for each round of lattice maps. It keeps a
//! pointer to the mesh's indices: the mesh must outlive it.
class LatticeRelaxation {
 public:
  //! threads: for the parallel loops (the same result for any count).
  LatticeRelaxation(const Mesh& mesh, const FaceFrames& frames, float scale, float period, size_t threads);

  //! Moves uv (#V*2, field.uv: per vertex its lattice coordinate in its own chart, pixels) by
  //! `iterations` local/global ARAP iterations over the faces `flat` names (#F: 1 where the
  //! lattice maps close around the face), each corner seen through corner_map (#F*3: corner k's
  //! chart -> corner 0's chart). Gauss-Seidel by blocks of vertices in index order, the blocks by
  //! colour (no two blocks of a colour share a face), so the result is the same for any thread
  //! count. O(F) per iteration at most; vertices that have settled (and their neighbours) are
  //! skipped. moving (#V, in and out; may be null or empty): 1 where a vertex is still moving (it
  //! and its neighbours start active; set it for the vertices of faces whose maps changed); on
  //! return, the vertices that moved in the last sweep. Null or empty: every vertex starts active.
  void run(const std::vector<LatticeMap>& corner_map, const std::vector<uint8_t>& flat, uint32_t iterations,
           std::vector<uint8_t>* moving, std::vector<float>& uv) const;

 private:
  const uint32_t* idx_;
  size_t face_count_, vertex_count_;
  float period_;
  size_t threads_;
  std::vector<float> grad_;            // #F*6: barycentric gradients (pixels^-1); 0 for a degenerate face
  std::vector<uint32_t> sweep_order_;  // #V: the vertices in the order of the sweeps
  std::vector<uint32_t> start_;        // #V+1, in sweep order: CSR of each vertex's corners of non-degenerate faces
  std::vector<uint32_t> corners_;      // corner indices 3f + k
  std::vector<float> area_;            // #F: area (pixels^2); 0 for a degenerate face
  std::vector<float> settled_;         // #V, in sweep order: the move below which a vertex has settled (pixels)
  BlockSweep blocks_;                  // the Gauss-Seidel sweep's blocks of vertices (sweep order)
};

}  // namespace tailor::internal
