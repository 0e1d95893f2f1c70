// Image quilting of blocks into a toroidal canvas, each block chosen among the exemplar's blocks
// near the best SSD over the known pixels (block_search.h) and cut into the canvas along the
// minimum-error boundary.
//
// This work is based on:
//   A. A. Efros, W. T. Freeman, "Image Quilting for Texture Synthesis and Transfer", SIGGRAPH 2001
//     (block choice by overlap SSD with a tolerance, minimum-error boundary cut by dynamic programming).
//
// Among the blocks within the SSD tolerance, up to `pool` (kCandidatePool in tiling.cpp) are
// ranked by the 7 x 7 patches their cuts would create (distance to the exemplar patches their
// pixels came from), the quantity the patch-coherence metric charges (Barnes et al. 2009 for the
// metric; the per-source candidate patches are PatchMatch's "coherent" candidates, Ashikhmin 2001).
// Small tolerance sets are topped up with the next best blocks by SSD (on stochastic exemplars
// the 10 % set often holds one or two smooth blocks, the same for every seed). Where the
// exemplar's own strongest edge decides the worst seam, the arms' blocks are also ranked by the
// straight-boundary profile they leave (Quilter::profile_deficit).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <utility>
#include <vector>

#include "texture/block_search.h"
#include "texture/tiling_util.h"

namespace tailor::internal {

//! A rectangle of exemplar positions that must not be chosen (variants: "not what was there").
struct Exclusion {
  bool active = false;
  int x = 0, y = 0, radius = 0;
  bool contains(int px, int py) const { return active && std::abs(px - x) < radius && std::abs(py - y) < radius; }
};

//! One block as placed: canvas rectangle (bx, by, bw, bh; bx, by modulo the canvas size) and the
//! exemplar block (px, py) chosen for it. The list of a run is its plan (cut_refine.h replays it
//! at full size).
struct Placement {
  int bx = 0, by = 0, bw = 0, bh = 0, px = 0, py = 0;
};

//! Image quilting on a toroidal canvas: known[] marks pixels that hold valid texture (fixed or
//! already synthesised), locked[] those that must never change (the weight map's zeros).
class Quilter {
 public:
  Quilter(const Plane& exemplar, SsdSearch& search, Plane& canvas, std::vector<uint8_t>& known,
          const std::vector<uint8_t>& locked, int overlap, double tolerance, SplitMix64& rng,
          std::vector<int32_t>* source = nullptr, int pool = 1, double gradient_penalty = 0.0)
      : ex_(exemplar),
        search_(search),
        canvas_(canvas),
        known_(known),
        locked_(locked),
        ov_(overlap),
        tolerance_(tolerance),
        rng_(rng),
        source_(source),
        pool_(pool),
        gradient_penalty_(gradient_penalty) {}

  //! Places one bw x bh block with its top-left corner at canvas (bx, by) (modulo the canvas size).
  void place(int bx, int by, int bw, int bh, const Exclusion& exclusion);

  int placed() const { return placed_; }

  //! Sum of the ranking costs of the blocks chosen so far (patch cost of their cuts, penalties
  //! included): lower means cuts that the patch-coherence metric charges less.
  double cut_cost() const { return cut_cost_; }

  //! Tolerance sets smaller than `count` are topped up with the next best blocks by SSD, so that
  //! the ranking has a choice (on stochastic exemplars the 10 % set often holds one or two
  //! smooth blocks: SSD over the overlap favours them, Efros & Freeman's regression to the mean).
  void set_min_candidates(int count) { min_candidates_ = count; }

  //! Straight-boundary profile check (see profile_deficit): `original` is the canvas before any
  //! repair; axes: 1 = row boundaries, 2 = column boundaries, 0 = off. Lines skip_first to
  //! skip_first + skip_count - 1 (modulo the size) are not checked: the other arm's zone, whose
  //! original content is the old seam and whose pixels are, or will be, replaced anyway.
  void set_profile(const Plane* original, int axes, int skip_first = 0, int skip_count = 0);

  //! Quarter-turn mode (TileOptions::symmetry 4): the canvas is square (N x N) and kept unchanged
  //! by r(x, y) = (N - 1 - y, x): every pixel a block writes is also written at its three images
  //! under r. turns[k] is the (square) exemplar turned k times the same way (turns[0] = the
  //! exemplar); a source index is then k * (exemplar pixels) + the pixel's index in turns[k], so
  //! the patch cost sees rotated copies as copies. The caller keeps blocks from overlapping their
  //! own images.
  //! With `searches` (one SsdSearch per turn, initialised on turns[k]), blocks are drawn from all
  //! four turns, not only from the upright exemplar.
  void set_quarter_turns(const std::vector<Plane>* turns, std::vector<SsdSearch>* searches = nullptr) {
    turns_ = turns;
    turn_search_ = searches;
  }

  //! Appends every placement to `record` (may be null).
  void set_record(std::vector<Placement>* record) { record_ = record; }

 private:
  //! candidates_ = the positions within the SSD tolerance of the best (raster order), excluded
  //! ones left out (unless all are excluded); fewer than min_candidates_ -> the min_candidates_
  //! lowest (SSD, position) pairs instead, lowest first (ties to the lower position, so nothing
  //! depends on a sort order). Without exclusion one pass usually suffices: the kScanKeep lowest
  //! pairs give the best SSD, and hold the whole tolerance set when their last one is above it.
  void select_candidates(int nx, int ny, float energy, const Exclusion& exclusion);

  //! error_ = per-pixel squared difference between the template and the exemplar block at (px, py).
  void compute_error(int px, int py);

  //! Mean |dx| + |dy| of the exemplar block at (px, py).
  double block_gradient(int px, int py) const;
  //! Mean |dx| + |dy| of the whole exemplar (computed once).
  double mean_gradient();

  //! Relative shortfall of the straight-boundary differences (sum over the block's width of
  //! |a - b| across each row boundary it spans, or over its height across each column boundary)
  //! after the cut block at exemplar (px, py) is placed, against the same sums in the original
  //! canvas: sum of max(0, original - new) over ordinary lines plus max(0, new - original) over
  //! strong lines (> kStrongLine x the median), over the sum of the originals. The worst-seam
  //! metric divides each line's difference by the median one: an arm that smooths the lines it
  //! crosses lowers that median and lifts the exemplar's own strongest edge above its ratio in
  //! the exemplar, and one that strengthens a strong line lifts that line.
  double profile_deficit(int bx, int by, int px, int py) const;

  //! Sum over the 7 x 7 canvas patches that would hold pixels of the block at exemplar (px, py)
  //! (cut by take_new_) and pixels of another source, of the squared distance to the nearest of
  //! the exemplar patches their corner and centre pixels came from: an upper bound of what the
  //! patch coherence metric charges them. Patches still holding unknown pixels are skipped.
  //! The result is multiplied by factor_a then factor_b; once that exceeds `bound` the sum stops
  //! and the result is +infinity (the caller only needs costs up to its bound).
  double patch_cost(int bx, int by, int px, int py, double factor_a, double factor_b, double bound);

  // side: 0 left, 1 right, 2 top, 3 bottom. Pixels beyond the cut (towards the side) keep the old value.
  void cut_side(int side);

  // Strip coordinates (i along the side, j = depth from the block's edge) -> block (x, y).
  void strip_coords(int side, int i, int j, int& x, int& y) const;

  const Plane& ex_;
  SsdSearch& search_;
  Plane& canvas_;
  std::vector<uint8_t>& known_;
  const std::vector<uint8_t>& locked_;
  int ov_;
  int bw_ = 0, bh_ = 0;
  double tolerance_;
  SplitMix64& rng_;
  int placed_ = 0;
  std::vector<float> templ_, mask_, ssd_, error_, strip_, cost_;
  std::vector<int> candidates_, path_;
  std::vector<uint8_t> take_new_;
  std::vector<int32_t>* source_;
  std::vector<double> costs_;
  int pool_;
  double gradient_penalty_;
  double mean_gradient_ = -1.0;
  std::vector<float> region_val_;
  std::vector<int32_t> region_src_;
  std::vector<uint8_t> region_known_;
  std::vector<int> sat_unknown_, sat_right_, sat_down_;
  int min_candidates_ = 0;
  std::vector<std::pair<float, int>> ranked_;
  double cut_cost_ = 0.0;
  const Plane* original_ = nullptr;
  int profile_axes_ = 0;
  int skip_first_ = 0, skip_count_ = 0;
  std::vector<uint8_t> strong_rows_, strong_cols_;
  const std::vector<Plane>* turns_ = nullptr;
  std::vector<SsdSearch>* turn_search_ = nullptr;
  std::vector<float> turn_ssd_;
  int turn_ = 0;  // quarter turn of the block being tried or placed (0 without a turned search)
  //! The exemplar turn the current block is read from, and its offset in source indices.
  const Plane& block_plane() const { return turn_search_ ? (*turns_)[static_cast<size_t>(turn_)] : ex_; }
  int32_t turn_offset() const { return turn_ * ex_.width * ex_.height; }
  std::vector<Placement>* record_ = nullptr;
};

}  // namespace tailor::internal
