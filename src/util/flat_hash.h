// A flat open-addressing hash table of uint32 ids whose keys live in the caller's own arrays.
//
// Used to weld STL vertices (key = the 12 bytes of a position) without a node per element: the
// table is one std::vector<uint32_t> of power-of-two size at most half full, probed linearly.
// The caller supplies the hash of the key and an `equal(stored_id)` predicate comparing the key
// being inserted with the key of an id already in the table.
//
// Deterministic: the ids returned depend only on the insertion sequence, never on addresses.
// Cost: O(1) expected per call with a well-mixed hash; memory 4 bytes * 2..4 * max_ids.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tailor::internal {

//! splitmix64 finalizer: spreads every input bit over the whole word (Steele et al. 2014).
inline uint64_t hash_mix(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

class FlatIdTable {
 public:
  static constexpr uint32_t kEmpty = 0xffffffffu;

  //! Room for `max_ids` distinct ids at a load factor of at most 0.5.
  explicit FlatIdTable(size_t max_ids) {
    size_t size = 16;
    while (size < 2 * max_ids) size *= 2;
    slots_.assign(size, kEmpty);
    mask_ = size - 1;
  }

  //! Returns the stored id whose key equals the new key, or stores `id` and returns it.
  //! Precondition: at most `max_ids` distinct ids are ever inserted; id != kEmpty.
  template <class Equal>
  uint32_t find_or_insert(uint64_t hash, uint32_t id, Equal&& equal) {
    size_t i = static_cast<size_t>(hash) & mask_;
    for (;;) {
      const uint32_t s = slots_[i];
      if (s == kEmpty) {
        slots_[i] = id;
        return id;
      }
      if (equal(s)) return s;
      i = (i + 1) & mask_;
    }
  }

 private:
  std::vector<uint32_t> slots_;
  size_t mask_ = 0;
};

}  // namespace tailor::internal
