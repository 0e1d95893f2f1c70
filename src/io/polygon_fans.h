// Polygons of more than three corners: the readers cut each into a fan from its first corner as
// they parse (positions may come later in the file, a PLY's faces before its vertices), and record
// which triangles continue a polygon; once the whole mesh is read, a concave polygon's fan, whose
// triangles overlap, is cut again into ears (retriangulate_concave_fans).
#pragma once

#include <cstddef>
#include <vector>

#include "tailor/mesh.h"

namespace tailor::internal {

//! Which triangles continue the polygon of the triangle before them. Empty while the mesh has
//! only triangles: a mesh without polygons pays nothing.
struct PolygonFans {
  std::vector<bool> continues;  //!< #F once add() was called (shorter: the rest are triangles)

  //! The fan of a polygon of `corners` > 3 corners starts at triangle `first`.
  void add(size_t first, size_t corners) {
    continues.resize(first, false);
    continues.push_back(false);
    continues.resize(first + corners - 2, true);
  }
};

//! Polygons with at most this many corners are cut into ears when concave; a larger one keeps its
//! fan (ear clipping is quadratic in the corners, and such polygons are rare outside hostile files).
constexpr size_t kMaxEarClippedCorners = 64;

//! Cuts each concave polygon of `fans` (at most kMaxEarClippedCorners corners, planar enough that
//! its projection along its Newell normal is simple) into ears instead of its fan: the same number
//! of triangles in the same places, the same winding, each corner's attributes (corner_uvs,
//! corner_attributes) moved with it. Convex polygons keep their fans, so their output is as before.
//! Returns how many polygons were cut again. O(corners) for convex polygons.
size_t retriangulate_concave_fans(Mesh& mesh, const PolygonFans& fans);

}  // namespace tailor::internal
