// The bounding box of the vertices a mesh's faces use (an unreferenced vertex far away does not
// count), in doubles: the chunked engine's texel density and canonical cube, the stability
// experiment's ball.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "tailor/mesh.h"

namespace tailor::internal {

struct Bounds {
  std::array<double, 3> lo{HUGE_VAL, HUGE_VAL, HUGE_VAL};
  std::array<double, 3> hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  //! The longest side (0 for an empty mesh or a single point; not finite for an empty one).
  double longest() const { return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}); }
};

//! Bounds of the referenced vertices. O(F).
inline Bounds referenced_bounds(const Mesh& mesh) {
  Bounds b;
  for (const uint32_t v : mesh.indices)
    for (size_t k = 0; k < 3; ++k) {
      const double x = mesh.positions[3 * size_t{v} + k];
      b.lo[k] = std::min(b.lo[k], x);
      b.hi[k] = std::max(b.hi[k], x);
    }
  return b;
}

}  // namespace tailor::internal
