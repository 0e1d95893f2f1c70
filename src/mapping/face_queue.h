// Indexed 4-ary min-heap of faces keyed by a 64-bit integer (the mapping front). Four children
// per node halve the depth of a binary heap; the children share one cache line.
//
// Each face is in the heap at most once; its key can be changed in place (decrease or increase),
// so there is no lazy-deletion garbage: the heap never holds more entries than faces waiting.
// The key carries the face id in its low 32 bits, so keys are unique and ties are broken by face
// id (deterministic). Storage: one uint64 per entry plus one uint32 position per face, both
// allocated once by reset().
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "tailor/mesh.h"

namespace tailor::internal {

class FaceQueue {
 public:
  //! Empties the queue and sizes it for faces 0..face_count-1 (allocates only when it grows).
  void reset(size_t face_count) {
    heap_.clear();
    heap_.reserve(face_count);
    position_.assign(face_count, kInvalid);
  }

  bool empty() const { return heap_.empty(); }
  size_t size() const { return heap_.size(); }
  bool contains(uint32_t face) const { return position_[face] != kInvalid; }
  uint64_t top() const { return heap_.front(); }
  static uint32_t face_of(uint64_t key) { return static_cast<uint32_t>(key); }

  //! Inserts the face or changes its key. `key`'s low 32 bits must be the face id.
  void set(uint64_t key) {
    const uint32_t face = face_of(key);
    uint32_t i = position_[face];
    if (i == kInvalid) {
      i = static_cast<uint32_t>(heap_.size());
      heap_.push_back(key);
      sift_up(i);
    } else if (key < heap_[i]) {
      heap_[i] = key;
      sift_up(i);
    } else {
      heap_[i] = key;
      sift_down(i);
    }
  }

  //! Removes and returns the smallest key. Precondition: not empty.
  uint64_t pop() {
    const uint64_t result = heap_.front();
    position_[face_of(result)] = kInvalid;
    const uint64_t last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_[0] = last;
      position_[face_of(last)] = 0;
      sift_down(0);
    }
    return result;
  }

  //! Replaces every key k by fn(k) (face id bits must be kept) and restores the heap in O(n).
  template <class Fn>
  void transform_keys(Fn fn) {
    for (uint64_t& k : heap_) k = fn(k);
    for (size_t i = heap_.size() / 4 + 1; i-- > 0;)
      if (i < heap_.size()) sift_down(static_cast<uint32_t>(i));
    for (size_t i = 0; i < heap_.size(); ++i) position_[face_of(heap_[i])] = static_cast<uint32_t>(i);
  }

 private:
  void sift_up(uint32_t i) {
    const uint64_t key = heap_[i];
    while (i > 0) {
      const uint32_t parent = (i - 1) / 4;
      if (heap_[parent] <= key) break;
      heap_[i] = heap_[parent];
      position_[face_of(heap_[i])] = i;
      i = parent;
    }
    heap_[i] = key;
    position_[face_of(key)] = i;
  }

  void sift_down(uint32_t i) {
    const uint64_t key = heap_[i];
    const uint32_t n = static_cast<uint32_t>(heap_.size());
    for (;;) {
      const uint32_t first = 4 * i + 1;
      if (first >= n) break;
      uint32_t child = first;
      const uint32_t last = std::min(first + 4, n);
      for (uint32_t c = first + 1; c < last; ++c)
        if (heap_[c] < heap_[child]) child = c;
      if (key <= heap_[child]) break;
      heap_[i] = heap_[child];
      position_[face_of(heap_[i])] = i;
      i = child;
    }
    heap_[i] = key;
    position_[face_of(key)] = i;
  }

  std::vector<uint64_t> heap_;
  std::vector<uint32_t> position_;
};

}  // namespace tailor::internal
