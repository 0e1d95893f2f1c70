// Shared helpers of the tiling sources: a seeded generator with a fully specified sequence
// (std::uniform_int_distribution is implementation-defined, so it would break determinism
// across standard libraries), and a float plane with toroidal access.
#pragma once

#include <cstdint>
#include <vector>

#include "tailor/image.h"

namespace tailor::internal {

//! SplitMix64 (Steele, Lea, Flood 2014): tiny, fast, same numbers everywhere.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  //! Uniform in [0, n) for n >= 1 (modulo bias below 2^-32 for the sizes used here).
  uint32_t below(uint32_t n) { return static_cast<uint32_t>((next() >> 16) % n); }

 private:
  uint64_t state_;
};

//! Float copy of an 8-bit image in 8-bit units ([0, 255]), same interleaved layout as image.h.
struct Plane {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> px;

  const float* at(int x, int y) const { return &px[(static_cast<size_t>(y) * width + x) * channels]; }
  float* at(int x, int y) { return &px[(static_cast<size_t>(y) * width + x) * channels]; }
  //! Toroidal access: x and y may be any integers.
  const float* wrap(int x, int y) const { return at(mod(x, width), mod(y, height)); }
  static int mod(int a, int n) {
    const int r = a % n;
    return r < 0 ? r + n : r;
  }
};

inline Plane to_plane(const Image& image) {
  Plane p;
  p.width = image.width;
  p.height = image.height;
  p.channels = image.channels;
  p.px.assign(image.pixels.begin(), image.pixels.end());
  return p;
}

//! The most ordinary boundary (s - 1, s) within `reach` of `centre` (0 < s < diff.size()): the
//! one whose difference diff[s] is closest, in log ratio, to the median of the interior ones (ties
//! to the nearer, then the lower), so that a wrap placed there is as ordinary as any interior
//! boundary. `centre` when diff has fewer than 3 entries. tiling.cpp.
int ordinary_boundary(const std::vector<double>& diff, int centre, int reach);

//! How far `tile` misses the O(N) targets of meets_tile_targets against `exemplar` (same
//! channels): the sum of the relative excesses of the worst seam, the wrap ratios, histogram L1
//! and gradient ratio (0 = all met; patch coherence is not measured). tile_metrics.cpp.
double fast_target_misses(const Image& tile, const Image& exemplar);

}  // namespace tailor::internal
