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
//    This removes the per-face position writes on every sift step (random stores, cache misses).
//    The caller reports each superseded entry (supersede()); a heap more than a quarter stale is
//    purged of them and rebuilt in one linear pass when it is next popped (a third of all pops
//    were of stale entries, each a full sift down. Callgrind, whole mapping of the subdivided
//    horse: purging at a quarter saves 2.4% of the instructions against purging at a half, which
//    seldom triggers; an eighth saved less);
//  - pops move the hole down to a leaf along the smaller children and sift the last entry up from
//    there (Floyd's bottom-up variant): the last entry belongs near the bottom, so this halves the
//    comparisons and the child choice is branch-free.
// Storage: the heaps only, plain arrays (std::vector's bookkeeping in push and pop cost 2% of the
// mapping's instructions); they grow by doubling to at most the number of pushes (about 1.6 per
// face).
// Not thread-safe.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <memory>

namespace tailor::internal {

class FrontBuckets {
 public:
  //! Drops every entry (keeps the memory).
  void clear() {
    for (Heap& heap : heaps_) heap.size = 0;
    mask_ = 0;
    for (uint32_t& s : stale_) s = 0;
  }

  bool has_entries() const { return mask_ != 0; }
  static uint32_t face_of(uint64_t key) { return static_cast<uint32_t>(key); }
  static uint32_t bucket_of(uint64_t key) { return static_cast<uint32_t>(key >> 60); }

  //! Face of the smallest entry (live or not), kNone when empty: the likely next pop, to prefetch.
  uint32_t peek_face() const {
    if (mask_ == 0) return kNone;
    return face_of(heaps_[std::countr_zero(mask_)].data[0]);
  }
  static constexpr uint32_t kNone = ~uint32_t{0};

  //! Adds an entry. `key`'s low 32 bits must be the face id, its top 4 bits (class, rank) at most 11.
  //! The caller records which entry of the face is live (see pop).
  void push(uint64_t key) {
    const uint32_t b = bucket_of(key);
    Heap& heap = heaps_[b];
    if (heap.size == heap.capacity) grow(heap);
    sift_up(heap.data.get(), heap.size++, key & kLowMask);
    mask_ |= 1u << b;
  }

  //! Records that a live entry in `bucket` (the one the caller kept for a face) was superseded by
  //! a newer entry of the same face: it is stale from now on.
  void supersede(uint32_t bucket) { ++stale_[bucket]; }

  //! Removes the smallest entries until one for which live(key) is true, and returns it in `key`;
  //! false when none is left. live() tells whether the entry is still the face's current one; it
  //! must not change what it answers for other entries (it may be asked about every entry).
  template <class Live>
  bool pop(Live live, uint64_t& key) {
    while (mask_ != 0) {
      const uint32_t b = static_cast<uint32_t>(std::countr_zero(mask_));
      Heap& heap = heaps_[b];
      if (stale_[b] >= kPurgeMin && 4 * size_t{stale_[b]} > heap.size) {
        purge(b, live);
        if (heap.size == 0) {
          mask_ &= ~(1u << b);
          continue;
        }
      }
      key = (uint64_t{b} << 60) | pop_min(heap);
      if (heap.size == 0) mask_ &= ~(1u << b);
      if (live(key)) return true;
      --stale_[b];
    }
    return false;
  }

 private:
  struct Heap {
    std::unique_ptr<uint64_t[]> data;
    size_t size = 0, capacity = 0;
  };

  static constexpr uint64_t kLowMask = (uint64_t{1} << 60) - 1;
  // Stale entries a heap must hold before it is purged: small heaps are cheap to pop anyway.
  // (Their share that triggers a purge is in pop().)
  static constexpr uint32_t kPurgeMin = 64;

  static void grow(Heap& heap) {
    const size_t capacity = heap.capacity < 64 ? 64 : 2 * heap.capacity;
    std::unique_ptr<uint64_t[]> data(new uint64_t[capacity]);
    if (heap.size > 0) std::memcpy(data.get(), heap.data.get(), heap.size * sizeof(uint64_t));
    heap.data = std::move(data);
    heap.capacity = capacity;
  }

  // Drops the stale entries of bucket b's heap (possibly all) and restores the heap order
  // bottom-up (Floyd). The pop sequence is unchanged: keys are unique, so it depends only on the
  // set of live entries.
  template <class Live>
  void purge(uint32_t b, Live live) {
    Heap& heap = heaps_[b];
    uint64_t* h = heap.data.get();
    size_t n = 0;
    for (size_t i = 0; i < heap.size; ++i)
      if (live((uint64_t{b} << 60) | h[i])) h[n++] = h[i];
    heap.size = n;
    stale_[b] = 0;
    for (size_t i = n / 4 + 1; i-- > 0;) sift_down(h, n, i);
  }

  // Moves the entry at i down until its children are not smaller (top-down, for the rebuild).
  static void sift_down(uint64_t* h, size_t n, size_t i) {
    const uint64_t key = h[i];
    for (;;) {
      const size_t first = 4 * i + 1;
      if (first >= n) break;
      size_t c = first;
      const size_t end = first + 4 < n ? first + 4 : n;
      for (size_t j = first + 1; j < end; ++j) c = h[j] < h[c] ? j : c;
      if (h[c] >= key) break;
      h[i] = h[c];
      i = c;
    }
    h[i] = key;
  }

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

  // Removes and returns the smallest entry of a non-empty heap.
  static uint64_t pop_min(Heap& heap) {
    uint64_t* h = heap.data.get();
    const uint64_t result = h[0];
    const size_t n = --heap.size;
    if (n == 0) return result;
    const uint64_t last = h[n];
    // Hole from the root down to a leaf, always along the smallest child.
    size_t i = 0;
    for (;;) {
      const size_t first = 4 * i + 1;
      if (first + 4 <= n) {
        // Smallest of the four children, carrying the keys along (no reload by index).
        const uint64_t* child = h + first;
        const uint64_t k0 = child[0], k1 = child[1], k2 = child[2], k3 = child[3];
        const size_t a = k1 < k0 ? 1 : 0, b = k3 < k2 ? 3 : 2;
        const uint64_t ka = k1 < k0 ? k1 : k0, kb = k3 < k2 ? k3 : k2;
        h[i] = kb < ka ? kb : ka;
        i = first + (kb < ka ? b : a);
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

  Heap heaps_[12];
  uint32_t stale_[12] = {};  // superseded entries still in each heap
  uint32_t mask_ = 0;
};

}  // namespace tailor::internal
