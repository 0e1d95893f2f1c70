// Whether a triangle has exactly zero area: the mesh repairs count such faces, the stability
// experiment refuses a mesh made only of them.
#pragma once

#include <cstdint>

namespace tailor::internal {

//! True when triangle (a, b, c) of `pos` (xyz floats per vertex) has exactly zero area. The cross
//! product in double from float inputs is exact for all but extreme exponent ranges, so "zero"
//! means exactly collinear.
inline bool is_zero_area(const float* pos, uint32_t a, uint32_t b, uint32_t c) {
  const double ux = double{pos[3 * size_t{b}]} - pos[3 * size_t{a}],
               uy = double{pos[3 * size_t{b} + 1]} - pos[3 * size_t{a} + 1],
               uz = double{pos[3 * size_t{b} + 2]} - pos[3 * size_t{a} + 2];
  const double vx = double{pos[3 * size_t{c}]} - pos[3 * size_t{a}],
               vy = double{pos[3 * size_t{c} + 1]} - pos[3 * size_t{a} + 1],
               vz = double{pos[3 * size_t{c} + 2]} - pos[3 * size_t{a} + 2];
  const double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
  return cx == 0.0 && cy == 0.0 && cz == 0.0;
}

}  // namespace tailor::internal
