// Curve skeleton of a mesh (thesis figures 4.4 and 4.6) and the per-face directions it gives.
//
// compute_curve_skeleton (skeleton.cpp, the only file that includes CGAL) runs CGAL's
// mean-curvature-flow skeletonization on each edge component of the mesh, after closing the
// component's holes (a fan around each hole's centroid, rings of fewer vertices first around a
// long one, and the same around a vertex of very many neighbours: the flow's cost grows with the
// square of a vertex's valence); skeleton_face_directions
// (skeleton_field.cpp) gives each face the direction of its nearest skeleton edge.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "tailor/mesh.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace tailor::internal {

struct CurveSkeleton {
  std::vector<double> points;            //!< 3 per skeleton vertex, mesh coordinates
  std::vector<uint32_t> edges;           //!< 2 per skeleton edge (vertex ids)
  std::vector<uint32_t> edge_component;  //!< per edge: the mesh edge component it was built from
  std::vector<uint8_t> component_done;   //!< per mesh edge component: 1 if it has a skeleton
  uint32_t closed_holes = 0;             //!< holes closed before skeletonizing
  uint32_t skipped_components = 0;       //!< components left without a skeleton (see skeleton.cpp)
  uint32_t flow_max_valence = 0;         //!< the most neighbours of a vertex of the meshes handed to the flow
  double seconds = 0.0;                  //!< wall time

  size_t edge_count() const { return edges.size() / 2; }
};

//! The curve skeleton of every edge component of the mesh (topology.face_component). A component
//! with fewer than 4 faces, one that is not a manifold surface once its holes are closed, or one
//! where the flow fails is skipped (component_done 0, counted). Deterministic (sequential).
Status compute_curve_skeleton(const Mesh& mesh, const Topology& topology, CurveSkeleton& skeleton);

//! Per face: the unit direction of the nearest skeleton edge of the face's own component (to the
//! face centroid; ties to the lower edge id), with edges directed away from one end of each
//! skeleton tree (the leaf lowest along `axis`) so that the direction runs on along a limb.
//! Faces of components without a skeleton get (0, 0, 0). A uniform grid finds the nearest edge.
//! Identical for any thread count.
void skeleton_face_directions(const Mesh& mesh, const Topology& topology, const CurveSkeleton& skeleton,
                              const std::array<double, 3>& axis, size_t threads, std::vector<float>& directions);

}  // namespace tailor::internal
