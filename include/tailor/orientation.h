// tailor: per-face frames and the texture orientation field (thesis 2.2, DESIGN.md section 4).
//
// Every face f gets a unit normal n, a unit orientation o lying in the face plane (the direction
// the texture's u axis should follow) and p = n x o, so that (o, p, n) is right-handed and a
// counter-clockwise face maps to a counter-clockwise UV triangle (the texture is not mirrored;
// DESIGN.md writes o x n, which mirrors it). A 3D edge d maps to the texture offset
// scale * (d.o, d.p), in pixels, once the mesh is normalised into the unit cube.
//
// The orientation comes from a global axis projected onto each face: the first principal axis
// of the vertices (PCA, the default) or a user axis; or, with AxisSource::kSkeleton, from the
// direction of the mesh's curve skeleton nearest to each face (src/surface/skeleton.h). Where the projection
// degenerates (the axis is nearly normal to the face) the second principal axis is used instead. Optional smoothing
// averages each face's orientation with its neighbours' (N passes, renormalised in the plane).
//
// All outputs are flat arrays indexed by face. The mapping stage reads only `local` (corner
// positions in the face frame), `variation` and `area`, so the frames are computed once.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "tailor/api.h"
#include "tailor/mesh.h"
#include "tailor/option_doc.h"
#include "tailor/progress.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace tailor {

//! Where the global texture axis comes from.
enum class AxisSource {
  kPca,       //!< first principal axis of the referenced vertices (default, as the thesis)
  kUser,      //!< OrientationOptions::user_axis (CLI: x|y|z|vx,vy,vz)
  kSkeleton,  //!< per face: the nearest curve-skeleton edge (CGAL mean curvature flow; thesis fig. 4.4);
              //!< faces of components without a skeleton, and where it is ~normal to the face, use PCA
};

//! A curve the user drew on the surface (tailor edit, tailor map --strokes FILE): near it the
//! orientation field follows the curve's direction, blended into the axis field with a weight
//! that falls from 1 on the curve to 0 at `radius` (smoothly), so strokes act locally.
//! Per face (its centroid): each stroke within reach gives the tangent at its nearest point (the
//! nearest segment's direction, turning towards the next segment's near a shared point) and the
//! weight w = 1 - smoothstep(distance / radius); several strokes add their tangents times their
//! weights and the largest weight counts. The face's o is turned in its plane towards that
//! direction projected onto the face by w times the angle between them (at w = 1, o is the
//! direction; the sign of the stroke counts: a texture runs the way it was drawn). Blended before
//! smoothing; without smoothing, faces beyond every radius keep their frames bit for bit.
struct OrientationStroke {
  std::vector<float> points;  //!< N by 3 (N >= 2): points along the curve, mesh coordinates
  float radius = 0.f;         //!< reach of the stroke, mesh units (> 0)
};

//! The range of OrientationOptions' passes, read by the orientation and every check of it (as
//! MappingLimits, tailor/mapping.h).
struct OrientationLimits {
  static constexpr uint32_t max_smooth_passes = 1000;
};

struct OrientationOptions {
  AxisSource axis = AxisSource::kPca;              //!< source of the global axis projected on each face
  std::array<float, 3> user_axis{0.f, 1.f, 0.f};   //!< kUser: axis, any non-zero length (normalised inside)
  std::array<float, 3> user_axis2{0.f, 0.f, 0.f};  //!< kUser: fallback axis where user_axis is ~normal
                                                   //!< to a face; zero = pick one perpendicular to user_axis
  uint32_t smooth_passes = 0;                      //!< passes of neighbour averaging of o (0 = off; OrientationLimits)
  float degenerate_cos = 0.995f;                   //!< |axis . n| above this counts as "axis normal to face"
                                                   //!< and the second axis is projected instead (0.5..1)
  // Normalisation into the unit cube. Leave fixed_unit_scale at 0 to derive it from the mesh's
  // bounding box; stability runs pass the full mesh's values so a cut mesh keeps the same frame.
  std::array<float, 3> fixed_origin{0.f, 0.f, 0.f};  //!< with fixed_unit_scale > 0: bbox minimum, mesh units
  float fixed_unit_scale = 0.f;                   //!< > 0: normalised = (x - origin) * this; 0 = 1 / longest bbox side
  std::array<double, 2> anchor_period{0.0, 0.0};  //!< > 0: each face's anchor is its position's projection
                                                  //!< measured from the world origin, modulo these periods
                                                  //!< (normalised units, u and v): seeds of neighbouring
                                                  //!< chunks sit whole repeats apart (the chunked engine)
  uint32_t threads = 0;                           //!< threads for the per-face frames (0 = one per 100k faces, at most
                                                  //!< the cores and 8); the result is identical for any count
  std::span<const OrientationStroke> strokes;     //!< user strokes blended into the field (empty = none)
  ProgressCallback progress;                      //!< optional, at each pass over the faces; false cancels (kCancelled)
};

//! Flags and help of the OrientationOptions a user sets (option_doc.h).
inline constexpr OptionDoc kOrientationOptionDocs[] = {
    {"axis", "--axis",
     "Orientation field: pca, x, y, z, X,Y,Z, or auto (maps with each of pca, x, y, z first and keeps the one "
     "with the least seam: halves the seams of CAD parts, 4 growths more time), or skeleton (each face follows "
     "its nearest curve-skeleton edge, so the texture runs along limbs; CGAL mean curvature flow: 3 s on the "
     "97k-face horse, up to 30 s on scans; holes are closed first, see docs/mapping.md)"},
    {"smooth_passes", "--smooth", "Orientation smoothing passes over face neighbours"},
    {"strokes", "--strokes",
     "JSON file of orientation strokes, {\"strokes\": [{\"points\": [[x,y,z], ...], \"radius\": r}]} in mesh "
     "coordinates (what tailor edit saves): within r of a stroke the field turns to follow it, fully on the curve"},
};

//! Per-face frames. Shapes: #F by 3 arrays are packed xyz per face.
struct FaceFrames {
  std::vector<float> normal;       //!< #F by 3: unit normal (any unit vector for zero-area faces)
  std::vector<float> orientation;  //!< #F by 3: o, unit, in the face plane
  std::vector<float> bitangent;    //!< #F by 3: p = n x o, unit
  std::vector<float> area;         //!< #F: area in normalised units^2 (unit cube)
  std::vector<float> local;        //!< #F by 6: corners k=0..2 as (x, y) = ((P_k - P_0).o, (P_k - P_0).p),
                                   //!< normalised units; corner 0 is (0, 0)
  std::vector<float> variation;    //!< #F: sum over edge neighbours g of angle(o_f, o_g), radians (thesis "age")
  std::vector<float> anchor;       //!< #F by 2: (P_0.o, P_0.p) of normalised corner 0, so that a face placed
                                   //!< on its own sits at a position-derived (file-order independent) UV
  std::array<float, 3> axis{};     //!< the global axis used (unit), in mesh coordinates
  std::array<float, 3> axis2{};    //!< the fallback axis used (unit)
  std::array<float, 3> origin{};   //!< normalisation: normalised = (x - origin) * unit_scale
  std::array<float, 3> bbox_min{}, bbox_max{};  //!< bounding box of the referenced vertices (mesh coordinates)
  float unit_scale = 1.f;                       //!< 1 / longest bbox side (or OrientationOptions::fixed_unit_scale)
  uint32_t degenerate_faces = 0;                //!< zero-area faces given an arbitrary valid frame
  uint32_t fallback_faces = 0;                  //!< faces where the second axis was projected
  // AxisSource::kSkeleton only:
  uint32_t skeleton_edges = 0;         //!< edges of the curve skeleton
  uint32_t skeleton_closed_holes = 0;  //!< holes closed before skeletonizing
  uint32_t skeleton_pca_faces = 0;     //!< faces of components without a skeleton: given the PCA axis
  double skeleton_seconds = 0.0;       //!< wall time of the skeleton and the nearest-edge lookup
  double seconds = 0.0;                //!< wall time of compute_orientation

  size_t face_count() const { return area.size(); }
};

//! Computes normals, areas, the orientation field, corner positions in each face's frame and the
//! per-face variation. Inputs: a finalised mesh and its topology (build_topology(mesh)).
//! Never produces NaN: zero-area faces get an arbitrary orthonormal frame and variation 0 to
//! themselves. Fails with kInvalidArgument on a zero user axis, smooth_passes beyond OrientationLimits or a bad
//! stroke (naming it: points not x, y, z triples, fewer than 2, not finite, radius <= 0), and with
//! kInvalidMesh on an empty mesh or a topology of the wrong size. Cost: O(V + F * (1 + passes)) plus, with
//! strokes, a uniform grid over their segments and one cell's segments per face.
//! Deterministic; safe for any mesh that passed finalize_mesh.
TAILOR_API Status compute_orientation(const Mesh& mesh, const Topology& topology, const OrientationOptions& options,
                                      FaceFrames& frames);

//! Mean angle (radians) between the orientations of edge-adjacent faces (each interior edge once);
//! a measure of field smoothness used by tests and benchmarks. O(F).
TAILOR_API double mean_neighbour_angle(const Topology& topology, const FaceFrames& frames);

}  // namespace tailor
