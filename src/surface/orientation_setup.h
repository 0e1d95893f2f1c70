// What compute_orientation fixes for the whole mesh, kept so that the frames of a few faces can be
// computed again later (EditSession's local update, after strokes are added or removed) with the
// same bits compute_orientation would give them.
#pragma once

#include <span>
#include <vector>

#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace tailor::internal {

struct OrientationSetup {
  double axis[3] = {1, 0, 0};    //!< the global axis, as computed (double)
  double axis2[3] = {0, 1, 0};   //!< the fallback axis
  double origin[3] = {0, 0, 0};  //!< normalisation: (x - origin) * unit_scale
  double unit_scale = 1;
  std::vector<float> face_axis;  //!< AxisSource::kSkeleton: #F by 3 skeleton directions; else empty
};

//! compute_orientation, also filling `setup` when it is not null.
Status compute_orientation_setup(const Mesh& mesh, const Topology& topology, const OrientationOptions& options,
                                 FaceFrames& frames, OrientationSetup* setup);

//! Computes again the frames (normal, orientation, bitangent, area, local, anchor) of `faces` with
//! options.strokes, then the variation of those faces and their edge neighbours: afterwards
//! `frames` is bit for bit what compute_orientation gives with these options, provided it was
//! before for the other faces' strokes and options.smooth_passes is 0 (with smoothing a stroke
//! reaches further than its radius). The counters (degenerate_faces...) are not updated.
//! Precondition: check_strokes(options.strokes) passed; `setup` from the same mesh and options
//! but the strokes. O(faces + segments near them).
void refresh_face_frames(const Mesh& mesh, const Topology& topology, const OrientationOptions& options,
                         const OrientationSetup& setup, std::span<const uint32_t> faces, FaceFrames& frames);

}  // namespace tailor::internal
