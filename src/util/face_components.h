// Connected components of n elements (faces) joined through pairs, on threads, numbered in the order
// of their lowest element: the same labels for any thread count. The topology's components and the
// metrics' patches are both this.
//
// A union-find whose root is always the lowest element of its set (the higher root goes under the
// lower), so the sets and their roots do not depend on the order of the links. Each slice of
// elements joins the pairs inside it on its own thread (only its own entries are touched), then the
// pairs across slices are joined on the threads at once with atomic parents (a root linked by
// compare-and-swap, retried when another thread linked it first; paths halved on the way, any
// ancestor being a lower element of the same set). The labels follow slice by slice with the
// parents only read: each element's root (in element order, a parent in the same slice already
// knows its root), the roots numbered from the count of roots in the slices before, then each
// element's label from its root's.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "util/huge_pages.h"
#include "util/parallel_chunks.h"
#include "util/union_find.h"

namespace tailor::internal {

//! Labels the components: `joined(x, wanted, visit)` calls visit(y) for every element y joined to x
//! for which wanted(y) holds (both x's and y's calls must name each other; y == x is ignored); it
//! asks wanted(y) first, so a costly test of the pair is skipped for the pairs the pass does not
//! want. label[x] gets the component of x, numbered from 0 in the order of their lowest elements;
//! returns the number of components. n fits 32 bits; `slices` threads at most (at least 1).
template <class Joined>
uint32_t label_components(size_t n, size_t slices, const Joined& joined, uint32_t* label) {
  slices = std::clamp<size_t>(slices, 1, std::max<size_t>(n, 1));
  HugeArray<uint32_t> parent_array = huge_uninitialized<uint32_t>(n);
  uint32_t* const parent = parent_array.get();
  // Slice s is [n s / slices, n (s + 1) / slices), as for_each_part cuts it.
  for_each_part(n, slices, [&](size_t, size_t begin, size_t end) {
    const auto lo = static_cast<uint32_t>(begin), hi = static_cast<uint32_t>(end);
    for (uint32_t x = lo; x < hi; ++x) parent[x] = x;
    for (uint32_t x = lo; x < hi; ++x)
      joined(
          x, [x, hi](uint32_t y) { return y > x && y < hi; },  // each pair inside the slice once
          [&](uint32_t y) {
            const uint32_t a = find_root(parent, x), b = find_root(parent, y);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
          });
  });
  const auto atomic_root = [parent](uint32_t x) {
    for (;;) {
      std::atomic_ref<uint32_t> at(parent[x]);
      const uint32_t p = at.load(std::memory_order_acquire);
      if (p == x) return x;
      const uint32_t grand = std::atomic_ref<uint32_t>(parent[p]).load(std::memory_order_acquire);
      if (grand != p) at.store(grand, std::memory_order_release);
      x = grand;
    }
  };
  // The pairs across slices, each from its lower slice's side (the last slice has none to give).
  for_each_part(n, slices, [&](size_t s, size_t begin, size_t end) {
    if (s + 1 == slices) return;
    const auto hi = static_cast<uint32_t>(end);
    for (auto x = static_cast<uint32_t>(begin); x < hi; ++x)
      joined(
          x, [hi](uint32_t y) { return y >= hi; },
          [&](uint32_t y) {
            for (uint32_t a = x, b = y;;) {
              a = atomic_root(a);
              b = atomic_root(b);
              if (a == b) return;
              if (a < b) std::swap(a, b);  // a, the higher root, goes under b
              uint32_t expected = a;
              if (std::atomic_ref<uint32_t>(parent[a]).compare_exchange_strong(expected, b, std::memory_order_acq_rel))
                return;
            }
          });
  });
  std::vector<uint32_t> roots_before(slices + 1, 0);
  for_each_part(n, slices, [&](size_t s, size_t begin, size_t end) {
    const auto lo = static_cast<uint32_t>(begin), hi = static_cast<uint32_t>(end);
    uint32_t roots = 0;
    for (uint32_t x = lo; x < hi; ++x) {
      uint32_t p = parent[x];
      if (p == x) {
        ++roots;
      } else if (p >= lo) {
        p = label[p];
      } else {
        while (parent[p] != p) p = parent[p];
      }
      label[x] = p;  // its root, for now
    }
    roots_before[s + 1] = roots;
  });
  for (size_t s = 0; s < slices; ++s) roots_before[s + 1] += roots_before[s];
  for_each_part(n, slices, [&](size_t s, size_t begin, size_t end) {
    uint32_t next = roots_before[s];
    for (auto x = static_cast<uint32_t>(begin); x < end; ++x)
      if (label[x] == x) parent[x] = next++;  // the root's number, in its parent's place
  });
  for_each_part(n, slices, [&](size_t, size_t begin, size_t end) {
    for (size_t x = begin; x < end; ++x) label[x] = parent[label[x]];
  });
  return roots_before[slices];
}

}  // namespace tailor::internal
