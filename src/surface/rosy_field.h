// A 4-RoSy orientation field and a lattice position field per vertex (issue 14: integer-grid
// maps), after Instant Meshes (Jakob, Tarini, Panozzo, Sorkine-Hornung 2015): both fields are
// smoothed by local Jacobi iterations on a multi-resolution hierarchy of the vertex graph, coarse
// to fine, so the result does not depend on the thread count.
//
// Per vertex v: a unit normal n_v, a unit tangent q_v (the field's u direction; the field is
// defined up to quarter turns about n_v) and a lattice coordinate U_v in pixels, in the frame
// (q_v, n_v x q_v), modulo the lattice period T (the texture size): U_v is where v lies in the
// repeating texture. Between the charts of two neighbouring vertices there is a lattice map
// (quarter turns plus whole repeats; lattice_map below), found by matching the two fields.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/topology.h"

namespace tailor::internal {

struct RosyFieldOptions {
  float scale = 800.f;           //!< pixels per normalised unit
  float period = 512.f;          //!< lattice period in pixels (the square texture's size)
  float sharp_angle_deg = 30.f;  //!< edges whose faces' normals differ by more are features the field follows
  //! Jacobi iterations of the orientation per level: fine_orientation_iterations on the mesh's own
  //! vertices, twice as many on each coarser level up to orientation_iterations (the coarsest
  //! gets 4x that). Each level starts from the coarser one's field and only smooths at its own
  //! scale: 40 on every level (before) and 10 / 20 / 40 give the same 4-fold maps (median visible
  //! seams over the 16 shared meshes 2.82 / 1.47 % and 2.85 / 1.45 % at scale 800 / 8000) for a
  //! fifth less mapping time; 5 / 10 / 40: 2.83 / 1.54 %.
  uint32_t orientation_iterations = 40;
  uint32_t fine_orientation_iterations = 10;
  //! Jacobi iterations of the positions on the mesh's own vertices (the finest level). The lattice
  //! relaxation that follows (mapping/grid_relax.h) does the fine work: 25, 10 and 5 give the same
  //! 4-fold maps (median visible seams over the 16 shared meshes 2.85 / 1.44, 2.84 / 1.47 and 2.85
  //! / 1.45 % at scale 800 / 8000); 10 keeps a margin.
  uint32_t position_iterations = 10;
  //! Gauss-Seidel iterations on each coarser level (the coarsest gets 4x), over-relaxed. The
  //! positions were Jacobi-smoothed 100 times on every level before: the coarse levels had not
  //! settled, and their error came back as strips of cut faces. Measured with the integer-grid map
  //! (median visible seams over the 16 shared meshes, scale 800 / 8000): 100 Jacobi everywhere 4.48
  //! / 2.05 %; coarse levels 300 Jacobi 3.72 / 1.90 %; 300 Gauss-Seidel over-relaxed 1.6: 3.35 / 1.96
  //! % (1000: 3.13 / 1.85 % for 1.7x the time); then the finest level's 100 -> 25: 3.32 / 1.87 %, and
  //! the whole map 0.92x the time on the horse. Over-relaxation 1.8 / 1.9: 3.19 / 1.85 %, 3.07 / 1.82 %
  //! (1.8 kept: the optimum for a Laplacian on a grid 10-100 vertices across, the coarse levels' size,
  //! is 1.7-1.94, and nearer 2 diverges sooner); 600 steps 3.10 / 1.87 % for 1.4x the time; the
  //! robust scale 0.02 / 0.1 instead of 0.04: 3.64 / 1.95 %, 3.03 / 2.08 %. With the cone pairs
  //! cancelled (grid_cones.h), 300 -> 150 steps: 3.16 / 1.73 -> 3.22 / 1.77 % for 20 % less mapping
  //! time (the whole 4-fold map within 3x the default mode's on the horse).
  uint32_t coarse_position_iterations = 150;
  float coarse_over_relaxation = 1.8f;
  float robust = 0.04f;  //!< position smoothing weighs an edge by 1 / (1 + |r|^2 / (robust |d|^2)), r its
                         //!< residual, d its offset: edges far off are left as cuts (0 = least squares)
  uint32_t threads = 0;  //!< 0 = one per 20k vertices of a level, at most the cores and 8; same result for any count
};

//! The fields on the mesh's vertices; all arrays per vertex, normalised mesh units.
struct RosyField {
  std::vector<float> position;  //!< #V by 3: normalised position
  std::vector<float> normal;    //!< #V by 3: unit vertex normal (area weighted)
  std::vector<float> q;         //!< #V by 3: unit tangent, the field's u axis (mod quarter turns)
  std::vector<float> uv;        //!< #V by 2: lattice coordinate in [0, period)^2, pixels
  std::vector<uint8_t> sharp;   //!< #V: 1 where the field is tied to a feature edge
  float scale = 800.f;
  float period = 512.f;
  uint32_t levels = 0;  //!< levels of the hierarchy used
};

//! Computes both fields. Preconditions as map_texture. Cost: O(V) per iteration, a geometric sum
//! over levels; O(V + F) memory.
void compute_rosy_field(const Mesh& mesh, const Topology& topology, const FaceFrames& frames,
                        const RosyFieldOptions& options, RosyField& field);

//! A lattice map x -> rot_r(x) + period * t, with rot_1(a, b) = (b, -a) (a quarter turn) and t
//! integer. Compositions and inverses are exact on the integers.
struct LatticeMap {
  int r = 0;
  int tx = 0, ty = 0;
  bool operator==(const LatticeMap&) const = default;
};

// (x, y) = (a, b) turned by r quarter turns clockwise (r taken modulo 4); ints (lattice
// translations) and floats (positions) alike.
template <typename T>
inline void rotate_quarter(int r, T a, T b, T& x, T& y) {
  switch (r & 3) {
    case 0:
      x = a;
      y = b;
      break;
    case 1:
      x = b;
      y = -a;
      break;
    case 2:
      x = -a;
      y = -b;
      break;
    default:
      x = -b;
      y = a;
      break;
  }
}
//! rotate_quarter(r, a, b) as a product, (m[0] a + m[1] b, m[2] a + m[3] b) for
//! m = kQuarterTurn[r & 3]: the same values without a branch (a field's turns between neighbours
//! are as good as random, and a switch on them mispredicts in the sweeps).
inline constexpr float kQuarterTurn[4][4] = {
    {1.f, 0.f, 0.f, 1.f}, {0.f, 1.f, -1.f, 0.f}, {-1.f, 0.f, 0.f, -1.f}, {0.f, -1.f, 1.f, 0.f}};
//! (a o b)(x) = a(b(x)).
inline LatticeMap compose(const LatticeMap& a, const LatticeMap& b) {
  LatticeMap c;
  c.r = (a.r + b.r) & 3;
  int x, y;
  rotate_quarter(a.r, b.tx, b.ty, x, y);
  c.tx = x + a.tx;
  c.ty = y + a.ty;
  return c;
}
inline LatticeMap inverse(const LatticeMap& a) {
  LatticeMap c;
  c.r = (4 - a.r) & 3;
  int x, y;
  rotate_quarter(c.r, a.tx, a.ty, x, y);
  c.tx = -x;
  c.ty = -y;
  return c;
}
inline void apply(const LatticeMap& m, float period, const float* in, float* out) {
  float x, y;
  rotate_quarter(m.r, in[0], in[1], x, y);
  out[0] = x + period * static_cast<float>(m.tx);
  out[1] = y + period * static_cast<float>(m.ty);
}

//! The lattice map from vertex w's chart to vertex v's chart (v, w neighbours), computed in the
//! canonical direction (lower id first) and inverted otherwise, so that lattice_map(v, w) is
//! exactly inverse(lattice_map(w, v)).
LatticeMap lattice_map(const RosyField& field, uint32_t v, uint32_t w);

}  // namespace tailor::internal
