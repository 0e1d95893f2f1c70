// The mapping front of the patches mode: faces keyed by the 64-bit front key of mapping_common.h
// (class | rank | age | face id), popped smallest first.
//
// Same order as one heap over the whole key (keys are unique, so any correct priority queue pops
// the same sequence), but cheaper for this workload:
//  - one 4-ary min-heap per (class, rank) bucket, 12 in all, keyed by the low 60 bits (age, face
//    id); the bucket to pop is the lowest set bit of a mask. Faces with three or two placed
//    neighbours (most pops) sit in small heaps, and the pile of deferred faces no longer deepens
//    the heap of waiting ones;
//  - lazy deletion instead of an index per face: changing a face's key pushes a new entry and
//    leaves the old one, which is skipped when it surfaces. The caller keeps, per face, the bucket
//    of its live entry (a byte next to the rest of the face's state): every change of a waiting
//    face's key changes its class or lowers its rank, so (face, bucket) identifies the live entry.
//    This removes the per-face position writes on every sift step (random stores, cache misses);
//  - pops move the hole down to a leaf along the smaller children and sift the last entry up from
//    there (Floyd's bottom-up variant): the last entry belongs near the bottom, so this halves the
//    comparisons and the child choice is branch-free.
// Storage: the heaps only; they grow by doubling to at most the number of pushes (about 1.6 per
// face). Not thread-safe.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

namespace tailor::internal {

class FrontBuckets {
 public:
  //! Drops every entry (keeps the memory).
  void clear() {
    for (uint32_t m = mask_; m != 0; m &= m - 1) heaps_[std::countr_zero(m)].clear();
    mask_ = 0;
  }

  bool has_entries() const { return mask_ != 0; }
  static uint32_t face_of(uint64_t key) { return static_cast<uint32_t>(key); }
  static uint32_t bucket_of(uint64_t key) { return static_cast<uint32_t>(key >> 60); }

  //! Face of the smallest entry (live or not), kNone when empty: the likely next pop, to prefetch.
  uint32_t peek_face() const {
    if (mask_ == 0) return kNone;
    return face_of(heaps_[std::countr_zero(mask_)].front());
  }
  static constexpr uint32_t kNone = ~uint32_t{0};

  //! Adds an entry. `key`'s low 32 bits must be the face id, its top 4 bits (class, rank) at most 11.
  //! The caller records which entry of the face is live (see pop).
  void push(uint64_t key) {
    const uint32_t b = bucket_of(key);
    push(heaps_[b], key & kLowMask);
    mask_ |= 1u << b;
  }

  //! Removes the smallest entries until one for which live(key) is true, and returns it in `key`;
  //! false when none is left. live() tells whether the entry is still the face's current one.
  template <class Live>
  bool pop(Live live, uint64_t& key) {
    while (mask_ != 0) {
      const uint32_t b = static_cast<uint32_t>(std::countr_zero(mask_));
      std::vector<uint64_t>& heap = heaps_[b];
      key = (uint64_t{b} << 60) | pop_min(heap);
      if (heap.empty()) mask_ &= ~(1u << b);
      if (live(key)) return true;
    }
    return false;
  }

 private:
  static constexpr uint64_t kLowMask = (uint64_t{1} << 60) - 1;

  // Moves the hole at i up until key fits there, and puts key in it.
  static void sift_up(uint64_t* h, size_t i, uint64_t key) {
    while (i > 0) {
      const size_t parent = (i - 1) / 4;
      if (h[parent] <= key) break;
      h[i] = h[parent];
      i = parent;
    }
    h[i] = key;
  }

  static void push(std::vector<uint64_t>& heap, uint64_t key) {
    const size_t i = heap.size();
    heap.push_back(key);
    sift_up(heap.data(), i, key);
  }

  static uint64_t pop_min(std::vector<uint64_t>& heap) {
    uint64_t* h = heap.data();
    const uint64_t result = h[0];
    const uint64_t last = heap.back();
    heap.pop_back();
    const size_t n = heap.size();
    if (n == 0) return result;
    // Hole from the root down to a leaf, always along the smallest child.
    size_t i = 0;
    for (;;) {
      const size_t first = 4 * i + 1;
      if (first + 4 <= n) {
        const size_t a = h[first + 1] < h[first] ? first + 1 : first;
        const size_t b = h[first + 3] < h[first + 2] ? first + 3 : first + 2;
        const size_t c = h[b] < h[a] ? b : a;
        h[i] = h[c];
        i = c;
      } else {
        if (first >= n) break;
        size_t c = first;
        for (size_t j = first + 1; j < n; ++j) c = h[j] < h[c] ? j : c;
        h[i] = h[c];
        i = c;
        break;
      }
    }
    // Then the former last entry up from that leaf.
    sift_up(h, i, last);
    return result;
  }

  std::vector<uint64_t> heaps_[12];
  uint32_t mask_ = 0;
};

}  // namespace tailor::internal
