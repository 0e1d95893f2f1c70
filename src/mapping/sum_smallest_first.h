// The sum of three coordinates, smallest first: what the chunk rule and a chunk's Morton keys add
// a face's corners by, so that the corners' order cannot change a rounding.
#pragma once

#include <algorithm>

namespace tailor::internal {

//! (smallest + middle) + largest, ordered by min and max without branches (branches on the
//! coordinates mispredict about half the time). std::min and std::max drop a NaN in their second
//! argument: the last term, 0 for finite values and NaN otherwise, keeps a NaN in the sum. The
//! sign of a zero sum may depend on the order; callers offset it (kChunkGridOffset, an origin).
inline double sum_smallest_first(double a, double b, double c) {
  const double low2 = std::min(a, b), high2 = std::max(a, b);
  const double low = std::min(low2, c), high = std::max(high2, c), middle = std::max(low2, std::min(high2, c));
  return (low + middle) + high + (a + b + c) * 0.0;
}

}  // namespace tailor::internal
