// Union-find over 32-bit ids kept in a flat array of parent links (a root is its own parent).
#pragma once

#include <cstdint>

namespace tailor::internal {

//! The root of x, halving the path on the way (each visited link then skips one).
inline uint32_t find_root(uint32_t* parent, uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace tailor::internal
