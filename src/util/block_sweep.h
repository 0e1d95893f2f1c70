// Gauss-Seidel sweeps that run on threads and give the same bytes on any number of them.
//
// The unknowns [0, n) are cut into blocks of consecutive indices, and the blocks coloured so that
// no two blocks of a colour are coupled. A sweep moves colour after colour, a colour's blocks
// independently (on any threads), each block's unknowns one after the other in index order. So a
// sweep stays close to a plain sequential one (which converges best) and reads memory nearly in
// order; a colouring of single unknowns read it at random and waited on memory (the lattice
// relaxation, mapping/grid_relax.cpp), and converged less far (the coarse position levels,
// surface/rosy_field.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "util/parallel_chunks.h"

namespace tailor::internal {

class BlockSweep {
 public:
  static constexpr size_t kBlock = 256;         //!< unknowns per block
  static constexpr size_t kBlocksPerChunk = 4;  //!< blocks per parallel chunk: enough work for a thread

  //! Adds the coupling of unknowns i and j (both orders) to `pairs`; nothing when they share a block.
  static void couple(size_t i, size_t j, std::vector<uint64_t>& pairs) {
    const uint64_t a = i / kBlock, b = j / kBlock;
    if (a == b) return;
    pairs.push_back(a << 32 | b);
    pairs.push_back(b << 32 | a);
  }

  BlockSweep() = default;

  //! Colours the blocks of n unknowns, greedily in block order, given their couplings (from
  //! couple(); consumed). used[c] == b + 1 marks colour c as taken by a neighbour of block b: the
  //! search for a free colour stops within b's neighbours + 1 steps, so the colouring is
  //! O(pairs log pairs) on any input (a badly ordered one gets many colours, not wrong ones).
  BlockSweep(size_t n, std::vector<uint64_t> pairs) : n_(n) {
    const size_t blocks = (n + kBlock - 1) / kBlock;
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    std::vector<uint32_t> colour(blocks, 0), used(1, 0);
    uint32_t colours = 1;
    for (size_t b = 0, i = 0; b < blocks; ++b) {
      const uint32_t mark = static_cast<uint32_t>(b + 1);
      for (; i < pairs.size() && (pairs[i] >> 32) == b; ++i) {
        const uint32_t w = static_cast<uint32_t>(pairs[i]);
        if (w < b) used[colour[w]] = mark;
      }
      uint32_t c = 0;
      while (c < colours && used[c] == mark) ++c;
      colour[b] = c;
      if (c == colours) {
        ++colours;
        used.push_back(0);
      }
    }
    colour_start_.assign(colours + 1, 0);
    for (size_t b = 0; b < blocks; ++b) ++colour_start_[colour[b] + 1];
    for (uint32_t c = 0; c < colours; ++c) colour_start_[c + 1] += colour_start_[c];
    std::vector<uint32_t> fill(colour_start_.begin(), colour_start_.end() - 1);
    order_.resize(blocks);
    for (size_t b = 0; b < blocks; ++b) order_[fill[colour[b]]++] = static_cast<uint32_t>(b);
  }

  //! One sweep: move(i) for every unknown i, as above. move must only write unknown i's state and
  //! read that of i's block and of the blocks coupled to it.
  template <class Move>
  void sweep(size_t threads, const Move& move) const {
    for (size_t c = 0; c + 1 < colour_start_.size(); ++c) {
      const size_t first = colour_start_[c], count = colour_start_[c + 1] - first;
      for_each_chunk(
          count, threads,
          [&](size_t begin, size_t end, size_t) {
            for (size_t k = first + begin; k < first + end; ++k)
              for (size_t i = size_t{order_[k]} * kBlock, last = std::min(n_, i + kBlock); i < last; ++i) move(i);
          },
          kBlocksPerChunk);
    }
  }

 private:
  size_t n_ = 0;
  std::vector<uint32_t> colour_start_;  // the blocks of colour c: order_[colour_start_[c] .. colour_start_[c + 1])
  std::vector<uint32_t> order_;
};

}  // namespace tailor::internal
