// An order statistic by counting: values whose bits order as unsigned integers (non-negative
// floats and doubles) are counted by their top 16 bits, a row of counts per thread; the bin that
// holds the rank-th smallest is found from the rows' sum, and only that bin's values need a closer
// look. The chunk rule's median edge and the metrics' median angle select this way.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tailor::internal {

inline constexpr size_t kSelectBins = size_t{1} << 16;

//! Adds `rows` rows of kSelectBins counts into the first.
inline void sum_bin_rows(std::vector<uint32_t>& counts, size_t rows) {
  for (size_t t = 1; t < rows; ++t)
    for (size_t b = 0; b < kSelectBins; ++b) counts[b] += counts[t * kSelectBins + b];
}

//! The bin (of the first row) holding the rank-th smallest (from 0) counted value; rank becomes its
//! rank within the bin. The last bin if the counts fall short of rank.
inline uint32_t select_bin(const std::vector<uint32_t>& counts, uint64_t& rank) {
  uint32_t bin = 0;
  for (; bin + 1 < kSelectBins && rank >= counts[bin]; ++bin) rank -= counts[bin];
  return bin;
}

}  // namespace tailor::internal
