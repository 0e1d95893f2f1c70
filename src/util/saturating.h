// Sizes from untrusted headers (counts of vertices, faces, list lengths): arithmetic that saturates
// at UINT64_MAX instead of wrapping, so a size check against the file's bytes cannot be fooled.
#pragma once

#include <cstdint>

namespace tailor::internal {

inline uint64_t mul_sat(uint64_t a, uint64_t b) { return (a != 0 && b > UINT64_MAX / a) ? UINT64_MAX : a * b; }
inline uint64_t add_sat(uint64_t a, uint64_t b) { return b > UINT64_MAX - a ? UINT64_MAX : a + b; }

}  // namespace tailor::internal
