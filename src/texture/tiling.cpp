// Self-tileable textures: quadrant swap, then image quilting of the '+' seam (thesis chapter 3).
//
// This work is based on:
//   A. A. Efros, W. T. Freeman, "Image Quilting for Texture Synthesis and Transfer", SIGGRAPH 2001
//     (block choice by overlap SSD with a tolerance, minimum-error boundary cut by dynamic programming).
//   The thesis, chapter 3: swap quadrants, repair H1+H2, V1+V2 and the centre C with a weight map
//     that keeps the outer border; variants from different weight maps (3.2); period fitting (3.1).
//
// The SSD of a masked template against every exemplar position is computed with FFTs
// (SSD = sum M T^2 - 2 sum_c corr(M T_c, E_c) + corr(M, sum_c E_c^2); colour in luminance); the
// exemplar's spectra are computed once, so each block costs one or two forward real DFTs of the
// template and one inverse. Among the blocks within the SSD tolerance, up to kCandidatePool are
// ranked by the 7 x 7 patches their cuts would create (distance to the exemplar patches their
// pixels came from), the quantity the patch-coherence metric charges (Barnes et al. 2009 for the
// metric; the per-source candidate patches are PatchMatch's "coherent" candidates, Ashikhmin 2001).
// Small tolerance sets are topped up with the next best blocks by SSD (on stochastic exemplars
// the 10 % set often holds one or two smooth blocks, the same for every seed). Where the
// exemplar's own strongest edge decides the worst seam, the arms' blocks are also ranked by the
// straight-boundary profile they leave (Quilter::profile_deficit), and a few whole attempts are
// compared by O(N) checks (make_tile_variants).
#include "tailor/tiling.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>

#include "texture/tiling_util.h"
#include "tailor/image_ops.h"

namespace tailor {

using internal::Plane;
using internal::SplitMix64;

namespace {

constexpr int kMinTileSide = 32;
constexpr int kChainPercent = 100;      // arm blocks are this many percent as long as wide (150, 200: faster, worse seams)
constexpr int kArmDivisor = 2;          // the '+' is repaired with blocks and overlaps this many times smaller
constexpr int kCandidatePool = 32;      // near-best (SSD) blocks compared by the patch cost of their cuts
constexpr double kCostTolerance = 0.01; // blocks whose patch cost is within this of the best are ties
constexpr double kSmoothPenalty = 2.0;  // cost * (mean gradient / block gradient)^this for smooth blocks
constexpr double kRetryPenalty = 1.0;   // the same for the second try of the other exemplars
constexpr double kSeamFloor = 1.5;      // worst-seam target: max(exemplar's interior worst, this)
constexpr double kStrongEdge = 2.0;     // exemplars whose interior worst seam ratio exceeds this get kSmoothPenalty
constexpr double kSeamHeadroom = 0.998; // an attempt meets the worst-seam target with this much room (a tie is a miss)
constexpr size_t kScanKeep = 8;         // the SSD scan keeps at least this many lowest positions (see select_candidates)
constexpr int kMinCandidates = 8;       // a tolerance set smaller than this is topped up with the next best (SSD) blocks
constexpr int kProfileCandidates = 16;  // the same where the straight-boundary profile is checked
constexpr double kProfilePower = 8.0;   // cost * (1 + relative profile deficit)^this
constexpr double kStrongLine = 2.0;     // lines whose difference exceeds this x the median may not get stronger
constexpr int kAttemptPixels = 320 * 320;  // best of (this / pixels) attempts, at most kMaxAttempts
constexpr int kMaxAttempts = 4;

//! SSD of a masked B x B template against every B x B block of the exemplar, by FFT.
class SsdSearch {
 public:
  void init(const Plane& exemplar) {
    ex_ = &exemplar;
    // Colour exemplars are searched in luminance (one correlation instead of three); the near-best
    // candidates are then ranked in full colour by their cut patches (Quilter::patch_cost).
    search_channels_ = exemplar.channels >= 3 ? 1 : exemplar.channels;
    const int dft_w = cv::getOptimalDFTSize(exemplar.width);
    const int dft_h = cv::getOptimalDFTSize(exemplar.height);
    // Circular correlation is exact for the valid positions p <= size - block: p + q < size <= dft size.
    cv::Mat plane(dft_h, dft_w, CV_32F, cv::Scalar(0));
    cv::Mat square(dft_h, dft_w, CV_32F, cv::Scalar(0));
    spectra_.assign(static_cast<size_t>(search_channels_), cv::Mat());
    for (int c = 0; c < search_channels_; ++c) {
      for (int y = 0; y < exemplar.height; ++y) {
        float* row = plane.ptr<float>(y);
        float* sq = square.ptr<float>(y);
        for (int x = 0; x < exemplar.width; ++x) {
          const float v = sample(exemplar.at(x, y), c);
          row[x] = v;
          sq[x] += v * v;
        }
      }
      cv::dft(plane, spectra_[c], 0, exemplar.height);
    }
    cv::dft(square, square_spectrum_, 0, exemplar.height);
    padded_ = cv::Mat(dft_h, dft_w, CV_32F, cv::Scalar(0));
    accumulated_ = cv::Mat(dft_h, dft_w, CV_32F, cv::Scalar(0));
  }

  //! Search sample c of a pixel: the channel itself, or the luminance (Rec. 601) of a colour pixel.
  float sample(const float* p, int c) const {
    if (search_channels_ == ex_->channels) return p[c];
    return 0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2];
  }

  int positions_x(int bw) const { return ex_->width - bw + 1; }
  int positions_y(int bh) const { return ex_->height - bh + 1; }

  //! templ: bw*bh*channels samples, mask: bw*bh weights (0 or 1), row-major.
  //! ssd: positions_x(bw) * positions_y(bh) values.
  void search(int bw, int bh, const std::vector<float>& templ, const std::vector<float>& mask,
              std::vector<float>& ssd) {
    const int channels = ex_->channels;
    if (bw != last_bw_ || bh != last_bh_) {  // the template area changed: clear what it left
      padded_.setTo(0);
      last_bw_ = bw;
      last_bh_ = bh;
    }
    // The mask term depends on the mask only, and chains repeat a few mask shapes: cache it.
    const cv::Mat* mask_term = nullptr;
    for (const MaskEntry& e : mask_cache_)
      if (e.bw == bw && e.bh == bh && e.mask == mask) mask_term = &e.product;
    if (mask_term == nullptr) {
      for (int y = 0; y < bh; ++y) {
        float* row = padded_.ptr<float>(y);
        for (int x = 0; x < bw; ++x) row[x] = mask[static_cast<size_t>(y) * bw + x];
      }
      cv::dft(padded_, spectrum_, 0, bh);
      MaskEntry& slot = mask_cache_.size() < kMaskCacheSize ? mask_cache_.emplace_back() : mask_cache_[next_slot_];
      if (mask_cache_.size() == kMaskCacheSize) next_slot_ = (next_slot_ + 1) % kMaskCacheSize;
      slot.bw = bw;
      slot.bh = bh;
      slot.mask = mask;
      cv::mulSpectrums(square_spectrum_, spectrum_, slot.product, 0, true);
      mask_term = &slot.product;
    }
    mask_term->copyTo(accumulated_);
    double constant = 0.0;
    for (int c = 0; c < search_channels_; ++c) {
      for (int y = 0; y < bh; ++y) {
        float* row = padded_.ptr<float>(y);
        for (int x = 0; x < bw; ++x) {
          const size_t i = static_cast<size_t>(y) * bw + x;
          const float t = sample(&templ[i * channels], c);
          row[x] = mask[i] * t;
          constant += static_cast<double>(mask[i]) * t * t;
        }
      }
      cv::dft(padded_, spectrum_, 0, bh);
      cv::mulSpectrums(spectra_[c], spectrum_, product_, 0, true);
      cv::scaleAdd(product_, -2.0, accumulated_, accumulated_);
    }
    const int nx = positions_x(bw);
    const int ny = positions_y(bh);
    cv::dft(accumulated_, result_, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE, ny);
    ssd.resize(static_cast<size_t>(nx) * ny);
    for (int y = 0; y < ny; ++y) {
      const float* row = result_.ptr<float>(y);
      for (int x = 0; x < nx; ++x)
        ssd[static_cast<size_t>(y) * nx + x] = std::max(0.0f, static_cast<float>(constant + row[x]));
    }
  }

 private:
  struct MaskEntry {
    int bw = 0, bh = 0;
    std::vector<float> mask;
    cv::Mat product;  // square_spectrum_ times the conjugate spectrum of the mask
  };
  static constexpr size_t kMaskCacheSize = 4;

  const Plane* ex_ = nullptr;
  int search_channels_ = 0;
  int last_bw_ = 0, last_bh_ = 0;
  std::vector<MaskEntry> mask_cache_;
  size_t next_slot_ = 0;
  std::vector<cv::Mat> spectra_;
  cv::Mat square_spectrum_, padded_, spectrum_, product_, accumulated_, result_;
};

//! A rectangle of exemplar positions that must not be chosen (variants: "not what was there").
struct Exclusion {
  bool active = false;
  int x = 0, y = 0, radius = 0;
  bool contains(int px, int py) const { return active && std::abs(px - x) < radius && std::abs(py - y) < radius; }
};

//! Minimum-error path through a strip of `length` x `width` errors (err[i * width + j], i along the
//! strip): one j per i, |j(i) - j(i-1)| <= 1. Dynamic programming, ties to the smaller j.
void min_error_path(const std::vector<float>& err, int length, int width, std::vector<float>& cost,
                    std::vector<int>& path) {
  cost.assign(err.begin(), err.begin() + static_cast<size_t>(length) * width);
  for (int i = 1; i < length; ++i) {
    for (int j = 0; j < width; ++j) {
      float best = cost[static_cast<size_t>(i - 1) * width + j];
      if (j > 0) best = std::min(best, cost[static_cast<size_t>(i - 1) * width + j - 1]);
      if (j + 1 < width) best = std::min(best, cost[static_cast<size_t>(i - 1) * width + j + 1]);
      cost[static_cast<size_t>(i) * width + j] += best;
    }
  }
  path.assign(static_cast<size_t>(length), 0);
  int j = 0;
  for (int k = 1; k < width; ++k)
    if (cost[static_cast<size_t>(length - 1) * width + k] < cost[static_cast<size_t>(length - 1) * width + j]) j = k;
  path[static_cast<size_t>(length - 1)] = j;
  for (int i = length - 2; i >= 0; --i) {
    int next = j;
    for (int k = std::max(0, j - 1); k <= std::min(width - 1, j + 1); ++k)
      if (cost[static_cast<size_t>(i) * width + k] < cost[static_cast<size_t>(i) * width + next]) next = k;
    j = next;
    path[static_cast<size_t>(i)] = j;
  }
}

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
  void place(int bx, int by, int bw, int bh, const Exclusion& exclusion) {
    bw_ = bw;
    bh_ = bh;
    const int channels = canvas_.channels;
    const size_t area = static_cast<size_t>(bw) * bh;
    templ_.resize(area * channels);
    mask_.assign(area, 0.0f);
    bool any_known = false;
    for (int y = 0; y < bh; ++y) {
      for (int x = 0; x < bw; ++x) {
        const size_t i = static_cast<size_t>(y) * bw + x;
        const int cx = Plane::mod(bx + x, canvas_.width);
        const int cy = Plane::mod(by + y, canvas_.height);
        const float* p = canvas_.at(cx, cy);
        std::copy(p, p + channels, &templ_[i * channels]);
        if (known_[static_cast<size_t>(cy) * canvas_.width + cx]) {
          mask_[i] = 1.0f;
          any_known = true;
        }
      }
    }

    // Choose the exemplar block among those within the tolerance of the best SSD.
    const int nx = search_.positions_x(bw);
    const int ny = search_.positions_y(bh);
    int chosen = 0;
    if (!any_known) {
      chosen = static_cast<int>(rng_.below(static_cast<uint32_t>(nx * ny)));
    } else {
      search_.search(bw, bh, templ_, mask_, ssd_);
      float energy = 0.0f;
      for (size_t i = 0; i < templ_.size(); ++i) energy += mask_[i / channels] * templ_[i] * templ_[i];
      select_candidates(nx, ny, energy, exclusion);
      if (pool_ <= 1 || source_ == nullptr) {
        chosen = candidates_[rng_.below(static_cast<uint32_t>(candidates_.size()))];
      } else {
        // Draw up to `pool` candidates at random (seeded); keep the one whose cut patches are
        // closest to exemplar patches (what the tile's patch coherence measures). SSD alone
        // treats every overlap pixel alike, while a 7 x 7 patch across a cut is cheap only if
        // both sides agree near the cut.
        // When the whole set fits in the pool, one random candidate is left out so that the seed
        // still matters.
        const size_t n = candidates_.size();
        const size_t k = std::min(n > 2 && n <= static_cast<size_t>(pool_) ? n - 1 : n, static_cast<size_t>(pool_));
        for (size_t i = 0; i < k; ++i) {
          const size_t j = i + rng_.below(static_cast<uint32_t>(candidates_.size() - i));
          std::swap(candidates_[i], candidates_[j]);
        }
        costs_.resize(k);
        double best_cost = std::numeric_limits<double>::max();
        for (size_t i = 0; i < k; ++i) {
          const int cx = candidates_[i] % nx, cy = candidates_[i] / nx;
          compute_error(cx, cy);
          take_new_.assign(area, 1);
          for (int side = 0; side < 4; ++side) cut_side(side);
          // Optional: penalise blocks smoother than the exemplar on average (smooth blocks match
          // more easily, and a strip of them lowers the tile's median boundary difference).
          double smooth_factor = 1.0, profile_factor = 1.0;
          if (gradient_penalty_ > 0.0) {
            const double g = block_gradient(cx, cy);
            if (g < mean_gradient()) smooth_factor = std::pow(mean_gradient() / std::max(g, 1e-6), gradient_penalty_);
          }
          if (profile_axes_ != 0) profile_factor = std::pow(1.0 + profile_deficit(bx, by, cx, cy), kProfilePower);
          // A candidate whose partial cost already exceeds the ties' bound can be neither.
          const double cost = patch_cost(bx, by, cx, cy, smooth_factor, profile_factor, best_cost * (1.0 + kCostTolerance));
          costs_[i] = cost;
          best_cost = std::min(best_cost, cost);
        }
        // Near ties (within kCostTolerance) are broken at random.
        size_t ties = 0;
        for (size_t i = 0; i < k; ++i)
          if (costs_[i] <= best_cost * (1.0 + kCostTolerance)) {
            candidates_[ties] = candidates_[i];
            costs_[ties++] = costs_[i];
          }
        const size_t pick = rng_.below(static_cast<uint32_t>(ties));
        chosen = candidates_[pick];
        cut_cost_ += costs_[pick];
      }
    }
    const int px = chosen % nx;
    const int py = chosen / nx;

    // Boundary cuts on every side whose overlap strip holds known pixels.
    compute_error(px, py);
    take_new_.assign(area, 1);
    for (int side = 0; side < 4; ++side) cut_side(side);

    for (int y = 0; y < bh; ++y) {
      for (int x = 0; x < bw; ++x) {
        const size_t i = static_cast<size_t>(y) * bw + x;
        const int cx = Plane::mod(bx + x, canvas_.width);
        const int cy = Plane::mod(by + y, canvas_.height);
        const size_t ci = static_cast<size_t>(cy) * canvas_.width + cx;
        if (locked_[ci]) continue;
        if (take_new_[i] || mask_[i] == 0.0f) {
          const float* e = ex_.at(px + x, py + y);
          std::copy(e, e + channels, canvas_.at(cx, cy));
          if (source_) (*source_)[ci] = (py + y) * ex_.width + px + x;
        }
        known_[ci] = 1;
      }
    }
    ++placed_;
  }

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
  void set_profile(const Plane* original, int axes, int skip_first = 0, int skip_count = 0) {
    original_ = original;
    profile_axes_ = axes;
    skip_first_ = skip_first;
    skip_count_ = skip_count;
    if (original == nullptr || !strong_rows_.empty()) return;
    for (int a = 1; a <= 2; ++a) {
      const bool rows = a == 1;
      const int n = rows ? original->height : original->width;
      std::vector<double> diff(static_cast<size_t>(n), 0.0);
      for (int y = 0; y < original->height; ++y)
        for (int x = 0; x < original->width; ++x) {
          const float* p = original->at(x, y);
          const float* q = rows ? original->wrap(x, y + 1) : original->wrap(x + 1, y);
          for (int c = 0; c < original->channels; ++c) diff[static_cast<size_t>(rows ? y : x)] += std::abs(p[c] - q[c]);
        }
      std::vector<double> sorted = diff;
      std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
      const double median = sorted[static_cast<size_t>(n / 2)];
      std::vector<uint8_t>& strong = rows ? strong_rows_ : strong_cols_;
      strong.assign(static_cast<size_t>(n), 0);
      for (int i = 0; i < n; ++i) strong[static_cast<size_t>(i)] = diff[static_cast<size_t>(i)] > kStrongLine * median ? 1 : 0;
    }
  }

 private:
  //! candidates_ = the positions within the SSD tolerance of the best (raster order), excluded
  //! ones left out (unless all are excluded); fewer than min_candidates_ -> the min_candidates_
  //! lowest (SSD, position) pairs instead, lowest first (ties to the lower position, so nothing
  //! depends on a sort order). Without exclusion one pass usually suffices: the kScanKeep lowest
  //! pairs give the best SSD, and hold the whole tolerance set when their last one is above it.
  void select_candidates(int nx, int ny, float energy, const Exclusion& exclusion) {
    const size_t top = static_cast<size_t>(min_candidates_);
    candidates_.clear();
    ranked_.clear();
    // The small absolute term absorbs FFT round-off (relative ~1e-6 of the template energy).
    auto threshold_of = [&](float best) { return best * static_cast<float>(1.0 + tolerance_) + 1e-5f * energy + 1e-3f; };
    auto keep_lowest = [&](const std::pair<float, int>& entry, size_t m) {
      if (ranked_.size() == m) {
        if (!(entry < ranked_.back())) return;
        ranked_.pop_back();
      }
      ranked_.insert(std::upper_bound(ranked_.begin(), ranked_.end(), entry), entry);
    };
    if (!exclusion.active) {
      const size_t m = std::max(top, kScanKeep);
      float kept_worst = std::numeric_limits<float>::max();
      for (size_t i = 0; i < ssd_.size(); ++i) {
        if (ssd_[i] > kept_worst) continue;
        keep_lowest({ssd_[i], static_cast<int>(i)}, m);
        if (ranked_.size() == m) kept_worst = ranked_.back().first;
      }
      const float threshold = threshold_of(ranked_.front().first);
      if (ranked_.size() < m || ranked_.back().first > threshold) {
        for (const auto& entry : ranked_)
          if (entry.first <= threshold) candidates_.push_back(entry.second);
        std::sort(candidates_.begin(), candidates_.end());  // raster order, as a full scan gives
      } else {
        for (size_t i = 0; i < ssd_.size(); ++i)
          if (ssd_[i] <= threshold) candidates_.push_back(static_cast<int>(i));
      }
      ranked_.resize(std::min(ranked_.size(), top));
    } else {
      float best = std::numeric_limits<float>::max();
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
          if (!exclusion.contains(x, y)) best = std::min(best, ssd_[static_cast<size_t>(y) * nx + x]);
      const bool use_exclusion = best < std::numeric_limits<float>::max();
      if (!use_exclusion)
        for (float v : ssd_) best = std::min(best, v);
      const float threshold = threshold_of(best);
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          if (use_exclusion && exclusion.contains(x, y)) continue;
          const std::pair<float, int> entry{ssd_[static_cast<size_t>(y) * nx + x], y * nx + x};
          if (entry.first <= threshold) candidates_.push_back(entry.second);
          if (top > 0) keep_lowest(entry, top);
        }
    }
    if (candidates_.size() < top) {
      candidates_.clear();
      for (const auto& entry : ranked_) candidates_.push_back(entry.second);
    }
  }

  //! error_ = per-pixel squared difference between the template and the exemplar block at (px, py).
  void compute_error(int px, int py) {
    const int channels = canvas_.channels;
    error_.assign(static_cast<size_t>(bw_) * bh_, 0.0f);
    for (int y = 0; y < bh_; ++y) {
      for (int x = 0; x < bw_; ++x) {
        const size_t i = static_cast<size_t>(y) * bw_ + x;
        if (mask_[i] == 0.0f) continue;
        const float* e = ex_.at(px + x, py + y);
        float sum = 0.0f;
        for (int c = 0; c < channels; ++c) {
          const float d = templ_[i * channels + c] - e[c];
          sum += d * d;
        }
        error_[i] = sum;
      }
    }
  }

  //! Mean |dx| + |dy| of the exemplar block at (px, py).
  double block_gradient(int px, int py) const {
    const int channels = canvas_.channels;
    double sum = 0.0;
    for (int y = 0; y + 1 < bh_; ++y)
      for (int x = 0; x + 1 < bw_; ++x) {
        const float* a = ex_.at(px + x, py + y);
        const float* r = ex_.at(px + x + 1, py + y);
        const float* d = ex_.at(px + x, py + y + 1);
        for (int c = 0; c < channels; ++c) sum += std::abs(a[c] - r[c]) + std::abs(a[c] - d[c]);
      }
    return sum / (static_cast<double>(bw_ - 1) * (bh_ - 1) * channels);
  }
  //! Mean |dx| + |dy| of the whole exemplar (computed once).
  double mean_gradient() {
    if (mean_gradient_ < 0.0) {
      const int channels = canvas_.channels;
      double sum = 0.0;
      for (int y = 0; y + 1 < ex_.height; ++y)
        for (int x = 0; x + 1 < ex_.width; ++x) {
          const float* a = ex_.at(x, y);
          const float* r = ex_.at(x + 1, y);
          const float* d = ex_.at(x, y + 1);
          for (int c = 0; c < channels; ++c) sum += std::abs(a[c] - r[c]) + std::abs(a[c] - d[c]);
        }
      mean_gradient_ = sum / (static_cast<double>(ex_.width - 1) * (ex_.height - 1) * channels);
    }
    return mean_gradient_;
  }

  //! Relative shortfall of the straight-boundary differences (sum over the block's width of
  //! |a - b| across each row boundary it spans, or over its height across each column boundary)
  //! after the cut block at exemplar (px, py) is placed, against the same sums in the original
  //! canvas: sum of max(0, original - new) over ordinary lines plus max(0, new - original) over
  //! strong lines (> kStrongLine x the median), over the sum of the originals. The worst-seam
  //! metric divides each line's difference by the median one: an arm that smooths the lines it
  //! crosses lowers that median and lifts the exemplar's own strongest edge above its ratio in
  //! the exemplar, and one that strengthens a strong line lifts that line.
  double profile_deficit(int bx, int by, int px, int py) const {
    const int channels = canvas_.channels;
    auto value = [&](int x, int y) -> const float* {
      const int cx = Plane::mod(bx + x, canvas_.width);
      const int cy = Plane::mod(by + y, canvas_.height);
      const size_t i = static_cast<size_t>(y) * bw_ + x;
      if (!locked_[static_cast<size_t>(cy) * canvas_.width + cx] && (take_new_[i] || mask_[i] == 0.0f))
        return ex_.at(px + x, py + y);
      return canvas_.at(cx, cy);
    };
    double deficit = 0.0, total = 0.0;
    for (int axis = 1; axis <= 2; ++axis) {
      if ((profile_axes_ & axis) == 0) continue;
      const bool rows = axis == 1;
      const std::vector<uint8_t>& strong = rows ? strong_rows_ : strong_cols_;
      const int lines = rows ? bh_ - 1 : bw_ - 1, along = rows ? bw_ : bh_;
      for (int o = 0; o < lines; ++o) {
        const int size = rows ? canvas_.height : canvas_.width;
        const int line = Plane::mod((rows ? by : bx) + o, size);
        if (Plane::mod(line - skip_first_, size) < skip_count_) continue;
        double now = 0.0, before = 0.0;
        for (int k = 0; k < along; ++k) {
          const int x0 = rows ? k : o, y0 = rows ? o : k;
          const int x1 = rows ? k : o + 1, y1 = rows ? o + 1 : k;
          const float* a = value(x0, y0);
          const float* b = value(x1, y1);
          const float* oa = original_->wrap(bx + x0, by + y0);
          const float* ob = original_->wrap(bx + x1, by + y1);
          for (int c = 0; c < channels; ++c) {
            now += std::abs(a[c] - b[c]);
            before += std::abs(oa[c] - ob[c]);
          }
        }
        deficit += strong[static_cast<size_t>(line)] ? std::max(0.0, now - before) : std::max(0.0, before - now);
        total += before;
      }
    }
    return total > 0.0 ? deficit / total : 0.0;
  }

  //! Sum over the 7 x 7 canvas patches that would hold pixels of the block at exemplar (px, py)
  //! (cut by take_new_) and pixels of another source, of the squared distance to the nearest of
  //! the exemplar patches their corner and centre pixels came from: an upper bound of what the
  //! patch coherence metric charges them. Patches still holding unknown pixels are skipped.
  //! The result is multiplied by factor_a then factor_b; once that exceeds `bound` the sum stops
  //! and the result is +infinity (the caller only needs costs up to its bound).
  double patch_cost(int bx, int by, int px, int py, double factor_a, double factor_b, double bound) {
    constexpr int kP = 7, kR = kP - 1;
    const int channels = canvas_.channels;
    const int rw = bw_ + 2 * kR, rh = bh_ + 2 * kR;
    region_val_.resize(static_cast<size_t>(rw) * rh * channels);
    region_src_.resize(static_cast<size_t>(rw) * rh);
    region_known_.resize(static_cast<size_t>(rw) * rh);
    for (int j = 0; j < rh; ++j) {
      for (int i = 0; i < rw; ++i) {
        const size_t r = static_cast<size_t>(j) * rw + i;
        const int x = i - kR, y = j - kR;
        const int cx = Plane::mod(bx + x, canvas_.width);
        const int cy = Plane::mod(by + y, canvas_.height);
        const size_t ci = static_cast<size_t>(cy) * canvas_.width + cx;
        const bool in_block = x >= 0 && y >= 0 && x < bw_ && y < bh_;
        const size_t bi = in_block ? static_cast<size_t>(y) * bw_ + x : 0;
        if (in_block && !locked_[ci] && (take_new_[bi] || mask_[bi] == 0.0f)) {
          const float* e = ex_.at(px + x, py + y);
          std::copy(e, e + channels, &region_val_[r * channels]);
          region_src_[r] = (py + y) * ex_.width + px + x;
          region_known_[r] = 1;
        } else {
          const float* e = canvas_.at(cx, cy);
          std::copy(e, e + channels, &region_val_[r * channels]);
          region_src_[r] = (*source_)[ci];
          region_known_[r] = known_[ci] && (*source_)[ci] >= 0 ? 1 : 0;
        }
      }
    }
    double total = 0.0;
    const int ew = ex_.width, eh = ex_.height;
    // Summed-area tables of: unknown pixels, and pixel pairs (right, down) that are not one
    // translated copy of the exemplar. A window with none of the latter is an exemplar patch
    // (cost 0, what the first probe would find), so only windows across a cut are measured.
    const int sw = rw + 1;
    sat_unknown_.assign(static_cast<size_t>(sw) * (rh + 1), 0);
    sat_right_.assign(static_cast<size_t>(sw) * (rh + 1), 0);
    sat_down_.assign(static_cast<size_t>(sw) * (rh + 1), 0);
    for (int j = 0; j < rh; ++j) {
      int row_unknown = 0, row_right = 0, row_down = 0;
      for (int i = 0; i < rw; ++i) {
        const size_t r = static_cast<size_t>(j) * rw + i;
        const bool known = region_known_[r] != 0;
        row_unknown += known ? 0 : 1;
        if (i + 1 < rw) row_right += known && region_known_[r + 1] && region_src_[r + 1] == region_src_[r] + 1 ? 0 : 1;
        if (j + 1 < rh) row_down += known && region_known_[r + static_cast<size_t>(rw)] &&
                                            region_src_[r + static_cast<size_t>(rw)] == region_src_[r] + ew
                                        ? 0
                                        : 1;
        const size_t k = static_cast<size_t>(j + 1) * sw + i + 1;
        sat_unknown_[k] = sat_unknown_[k - static_cast<size_t>(sw)] + row_unknown;
        sat_right_[k] = sat_right_[k - static_cast<size_t>(sw)] + row_right;
        sat_down_[k] = sat_down_[k - static_cast<size_t>(sw)] + row_down;
      }
    }
    auto box = [&](const std::vector<int>& sat, int x0, int y0, int x1, int y1) {  // sum over [x0, x1) x [y0, y1)
      return sat[static_cast<size_t>(y1) * sw + x1] - sat[static_cast<size_t>(y0) * sw + x1] -
             sat[static_cast<size_t>(y1) * sw + x0] + sat[static_cast<size_t>(y0) * sw + x0];
    };
    for (int j = 0; j + kR < rh; ++j) {
      for (int i = 0; i + kR < rw; ++i) {
        if (box(sat_unknown_, i, j, i + kP, j + kP) != 0) continue;  // still holds unknown pixels
        if (box(sat_right_, i, j, i + kR, j + kP) == 0 && box(sat_down_, i, j, i + kP, j + kR) == 0) continue;
        static constexpr int kProbe[5][2] = {{0, 0}, {kR, 0}, {0, kR}, {kR, kR}, {kR / 2, kR / 2}};
        int32_t tried[5];
        int n_tried = 0;
        float best = std::numeric_limits<float>::max();
        for (const auto& probe : kProbe) {
          const int32_t s = region_src_[static_cast<size_t>(j + probe[1]) * rw + i + probe[0]];
          const int ox = std::clamp(s % ew - probe[0], 0, ew - kP);
          const int oy = std::clamp(s / ew - probe[1], 0, eh - kP);
          const int32_t origin = oy * ew + ox;
          if (std::find(tried, tried + n_tried, origin) != tried + n_tried) continue;
          tried[n_tried++] = origin;
          float sum = 0.0f;
          for (int b = 0; b < kP && sum < best; ++b) {
            const float* t = &region_val_[(static_cast<size_t>(j + b) * rw + i) * channels];
            const float* e = ex_.at(ox, oy + b);
            for (int a = 0; a < kP * channels; ++a) {
              const float d = t[a] - e[a];
              sum += d * d;
            }
          }
          best = std::min(best, sum);
          if (best == 0.0f) break;
        }
        total += best;
        if (total * factor_a * factor_b > bound) return std::numeric_limits<double>::infinity();
      }
    }
    return total * factor_a * factor_b;
  }

  // side: 0 left, 1 right, 2 top, 3 bottom. Pixels beyond the cut (towards the side) keep the old value.
  void cut_side(int side) {
    const int length = side < 2 ? bh_ : bw_;
    const int ov = std::min(ov_, side < 2 ? bw_ : bh_);
    bool active = false;
    strip_.assign(static_cast<size_t>(length) * ov, 0.0f);
    for (int i = 0; i < length; ++i) {
      for (int j = 0; j < ov; ++j) {
        int x = 0, y = 0;
        strip_coords(side, i, j, x, y);
        const size_t k = static_cast<size_t>(y) * bw_ + x;
        if (mask_[k] != 0.0f) active = true;
        strip_[static_cast<size_t>(i) * ov + j] = error_[k];
      }
    }
    if (!active) return;
    min_error_path(strip_, length, ov, cost_, path_);
    for (int i = 0; i < length; ++i) {
      for (int j = 0; j < path_[static_cast<size_t>(i)]; ++j) {
        int x = 0, y = 0;
        strip_coords(side, i, j, x, y);
        take_new_[static_cast<size_t>(y) * bw_ + x] = 0;
      }
    }
  }

  // Strip coordinates (i along the side, j = depth from the block's edge) -> block (x, y).
  void strip_coords(int side, int i, int j, int& x, int& y) const {
    switch (side) {
      case 0:
        x = j;
        y = i;
        break;
      case 1:
        x = bw_ - 1 - j;
        y = i;
        break;
      case 2:
        x = i;
        y = j;
        break;
      default:
        x = i;
        y = bh_ - 1 - j;
        break;
    }
  }

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
};

//! Start positions of `count` blocks of side b evenly covering [start, start + length).
std::vector<int> chain_positions(int start, int length, int b, int overlap) {
  if (length <= b) return {start};
  const int steps = (length - b + (b - overlap) - 1) / (b - overlap);  // ceil((length - b) / (b - overlap))
  std::vector<int> out;
  for (int i = 0; i <= steps; ++i)
    out.push_back(start + static_cast<int>((static_cast<int64_t>(i) * (length - b) + steps / 2) / steps));
  return out;
}

struct Setup {
  Plane exemplar;  // possibly period-fitted
  int block = 0;
  int overlap = 0;
  int shift_x = 0;  // toroidal shift: tile(x, y) = exemplar((x + shift_x) % W, (y + shift_y) % H)
  int shift_y = 0;
  int fold_x = 0;  // px added by fit_period extension: its fold seam lies fold_x px before the wrap
  int fold_y = 0;
};

void choose_shift(const Plane& ex, int& shift_x, int& shift_y);

//! Crops or extends to period_fitted_size() without resampling (the texels keep their size):
//! a pixel beyond the input is copied from a whole number of (rounded) periods before it.
Image fit_to_period(const Image& input, const PeriodEstimate& period) {
  int w = input.width, h = input.height;
  period_fitted_size(period, input.width, input.height, w, h);
  const int px = std::max(1, static_cast<int>(std::lround(period.period_x)));
  const int py = std::max(1, static_cast<int>(std::lround(period.period_y)));
  auto fold = [](int v, int size, int p) {
    while (v >= size) v -= p;
    return v;
  };
  Image out;
  out.width = w;
  out.height = h;
  out.channels = input.channels;
  out.pixels.resize(static_cast<size_t>(w) * h * input.channels);
  for (int y = 0; y < h; ++y) {
    const int sy = fold(y, input.height, py);
    for (int x = 0; x < w; ++x) {
      const int sx = fold(x, input.width, px);
      const uint8_t* s = &input.pixels[(static_cast<size_t>(sy) * input.width + sx) * input.channels];
      std::copy(s, s + input.channels, &out.pixels[(static_cast<size_t>(y) * w + x) * input.channels]);
    }
  }
  return out;
}

Status prepare(const Image& input, const TileOptions& options, Setup& setup, TileReport& report) {
  TAILOR_RETURN_IF_ERROR(check_image(input));
  if (options.block < 8 || options.block > 256)
    return Status::error(ErrorCode::kInvalidArgument, "", "block size must be in [8, 256] px",
                         "got " + std::to_string(options.block));
  if (options.overlap != 0 && (options.overlap < 1 || options.overlap > options.block / 2 - 1))
    return Status::error(ErrorCode::kInvalidArgument, "", "overlap must be in [1, block/2 - 1] px",
                         "got " + std::to_string(options.overlap) + " for block " + std::to_string(options.block));
  if (!(options.tolerance >= 0.0 && options.tolerance <= 1.0))
    return Status::error(ErrorCode::kInvalidArgument, "", "tolerance must be in [0, 1]");
  if (input.width < kMinTileSide || input.height < kMinTileSide)
    return Status::error(ErrorCode::kInvalidImage, "",
                         "image too small to make tileable (at least " + std::to_string(kMinTileSide) + " px a side)",
                         std::to_string(input.width) + "x" + std::to_string(input.height));
  Image work = input;
  if (options.fit_period) {
    report.period = estimate_period(input);
    int w = input.width, h = input.height;
    period_fitted_size(report.period, input.width, input.height, w, h);
    if (w != input.width || h != input.height) work = fit_to_period(input, report.period);
  }
  report.width = work.width;
  report.height = work.height;
  int block = options.block;
  const int max_block = std::min(work.width, work.height) / 4;
  if (block > max_block) {
    report.warnings.push_back("block shrunk from " + std::to_string(block) + " to " + std::to_string(max_block) +
                              " px for a " + std::to_string(work.width) + "x" + std::to_string(work.height) + " image");
    block = max_block;
  }
  int overlap = options.overlap == 0 ? std::max(1, block / 4) : options.overlap;
  if (overlap > block / 2 - 1) {
    const int shrunk = std::max(1, block / 4);
    report.warnings.push_back("overlap shrunk from " + std::to_string(overlap) + " to " + std::to_string(shrunk) +
                              " px");
    overlap = shrunk;
  }
  setup.exemplar = internal::to_plane(work);
  setup.fold_x = std::clamp(work.width - input.width, 0, work.width / 4);
  setup.fold_y = std::clamp(work.height - input.height, 0, work.height / 4);
  setup.block = block;
  setup.overlap = overlap;
  choose_shift(setup.exemplar, setup.shift_x, setup.shift_y);
  report.shift_x = setup.shift_x;
  report.shift_y = setup.shift_y;
  report.block = block;
  report.overlap = overlap;
  report.border = overlap;
  return Status::ok();
}

Image plane_to_image(const Plane& p) {
  Image out;
  out.width = p.width;
  out.height = p.height;
  out.channels = p.channels;
  out.pixels.resize(p.px.size());
  // Every sample is a copy of an 8-bit exemplar sample, so the rounding is exact.
  for (size_t i = 0; i < p.px.size(); ++i)
    out.pixels[i] = static_cast<uint8_t>(std::lround(std::clamp(p.px[i], 0.0f, 255.0f)));
  return out;
}

uint64_t mix_seed(uint64_t seed, uint64_t stream) {
  SplitMix64 g(seed ^ (0xD1B54A32D192ED03ull * (stream + 1)));
  return g.next();
}

//! Where the input's column boundary (s-1, s) should become the tile's wrap: near the middle
//! (within 1/8 of the size), on the boundary whose mean absolute difference is closest (in log
//! ratio) to the median one, so that the new wrap is as ordinary as any interior boundary.
void choose_shift(const Plane& ex, int& shift_x, int& shift_y) {
  const int w = ex.width, h = ex.height, c = ex.channels;
  std::vector<double> cols(static_cast<size_t>(w), 0.0), rows(static_cast<size_t>(h), 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* a = ex.at(x, y);
      for (int k = 0; k < c; ++k) {
        if (x > 0) cols[static_cast<size_t>(x)] += std::abs(a[k] - ex.at(x - 1, y)[k]);
        if (y > 0) rows[static_cast<size_t>(y)] += std::abs(a[k] - ex.at(x, y - 1)[k]);
      }
    }
  auto pick = [](const std::vector<double>& diff, int size) {
    std::vector<double> interior(diff.begin() + 1, diff.end());
    std::nth_element(interior.begin(), interior.begin() + static_cast<std::ptrdiff_t>(interior.size() / 2),
                     interior.end());
    const double median = std::max(interior[interior.size() / 2], 1e-9);
    int best = size / 2;
    double best_score = std::numeric_limits<double>::max();
    const int reach = std::max(1, size / 8);
    for (int d = 0; d <= reach; ++d) {
      for (int s : {size / 2 - d, size / 2 + d}) {
        if (s < 1 || s >= size) continue;
        const double score = std::abs(std::log(std::max(diff[static_cast<size_t>(s)], 1e-9) / median));
        if (score < best_score - 1e-12) {
          best_score = score;
          best = s;
        }
      }
    }
    return best;
  };
  shift_x = pick(cols, w);
  shift_y = pick(rows, h);
}

//! Largest (mean absolute difference across a column or row boundary) / (median one), the wrap
//! boundaries included or not: the worst-seam figure of tile_metrics(). O(N).
double worst_seam_ratio(const Plane& p, bool include_wrap) {
  const int w = p.width, h = p.height, c = p.channels;
  std::vector<double> cols(static_cast<size_t>(w), 0.0), rows(static_cast<size_t>(h), 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* a = p.at(x, y);
      const float* right = p.at((x + 1) % w, y);
      const float* down = p.at(x, (y + 1) % h);
      for (int k = 0; k < c; ++k) {
        cols[static_cast<size_t>(x)] += std::abs(a[k] - right[k]);
        rows[static_cast<size_t>(y)] += std::abs(a[k] - down[k]);
      }
    }
  double worst = 0.0;
  for (const std::vector<double>* diff : {&cols, &rows}) {
    std::vector<double> interior(diff->begin(), diff->end() - 1);
    std::nth_element(interior.begin(), interior.begin() + static_cast<std::ptrdiff_t>(interior.size() / 2),
                     interior.end());
    const double median = std::max(interior[interior.size() / 2], 1e-9);
    const size_t n = include_wrap ? diff->size() : diff->size() - 1;
    for (size_t i = 0; i < n; ++i) worst = std::max(worst, (*diff)[i] / median);
  }
  return worst;
}

//! How one attempt at the base tile chooses its blocks.
struct CrossPlan {
  uint64_t stream = 0;            // random stream (mix_seed(seed, stream))
  double gradient_penalty = 0.0;  // smooth-block penalty exponent (0 = off)
  int min_candidates = 0;         // see Quilter::set_min_candidates; kProfileCandidates for an arm with a profile check
  int vertical_profile = 0;       // profile axes checked by the vertical arm's blocks (Quilter::set_profile)
  int horizontal_profile = 0;     // the same for the horizontal arm's blocks
};

//! Base tile: shift, then quilt the vertical arm, the horizontal arm and the centre.
//! cut_cost: Quilter::cut_cost() of the result.
Status quilt_cross(const Setup& setup, const TileOptions& options, const CrossPlan& plan, SsdSearch& search,
                   Plane& canvas, int& placed, double& cut_cost) {
  const Plane& ex = setup.exemplar;
  const int w = ex.width, h = ex.height;
  // The '+' is repaired with half-size blocks (and overlaps): a narrower strip holds fewer 7 x 7
  // patches that straddle a cut (patch coherence 0.92-1.03x the exemplar's toroidal one on the
  // stochastic exemplars, against 1.10-1.38x with full-size blocks).
  const int b = std::max(8, setup.block / kArmDivisor);
  const int ov = std::clamp(setup.overlap / kArmDivisor, 1, b / 2 - 1);
  const int sx = setup.shift_x, sy = setup.shift_y;
  canvas = ex;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* s = ex.at((x + sx) % w, (y + sy) % h);
      std::copy(s, s + ex.channels, canvas.at(x, y));
    }
  const int cx = w - sx, cy = h - sy;
  // The seams lie between columns cx-1, cx and rows cy-1, cy; the zones around them are unknown.
  // A period-fitted extension adds a fold seam fold px before each: the zone covers both.
  const int margin = b - 2 * ov;
  const int zone_x = margin + setup.fold_x, zone_y = margin + setup.fold_y;
  const int zx = cx - setup.fold_x - margin / 2, zy = cy - setup.fold_y - margin / 2;
  const int arm_x = zone_x + 2 * ov, arm_y = zone_y + 2 * ov;  // block extent across each arm
  std::vector<uint8_t> known(static_cast<size_t>(w) * h, 1), locked(static_cast<size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if ((x >= zx && x < zx + zone_x) || (y >= zy && y < zy + zone_y)) known[static_cast<size_t>(y) * w + x] = 0;

  // Exemplar pixel each canvas pixel was copied from (index y * W + x), -1 where unknown.
  std::vector<int32_t> source(static_cast<size_t>(w) * h, -1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (known[static_cast<size_t>(y) * w + x]) source[static_cast<size_t>(y) * w + x] = ((y + sy) % h) * w + (x + sx) % w;
  const Plane original = canvas;
  SplitMix64 rng(mix_seed(options.seed, plan.stream));
  Quilter quilter(ex, search, canvas, known, locked, ov, options.tolerance, rng, &source, kCandidatePool,
                  plan.gradient_penalty);
  quilter.set_min_candidates(plan.min_candidates);
  // Arms are quilted with blocks `chain` px long: fewer chain cuts than square blocks.
  const int chain = std::min(b * kChainPercent / 100, std::min(w, h) / 2);
  const std::vector<int> vertical = chain_positions(zy + zone_y, h - zone_y, chain, ov);
  const std::vector<int> horizontal = chain_positions(zx + zone_x, w - zone_x, chain, ov);
  const double total = static_cast<double>(vertical.size() + horizontal.size() + 1);
  double done = 0.0;
  auto tick = [&]() -> bool {
    done += 1.0;
    return !options.progress || options.progress(done / total);
  };
  const Exclusion none;
  // V1 + V2: one chain through the top/bottom border (toroidal), from below the centre to above it.
  quilter.set_profile(&original, plan.vertical_profile, zy - ov, zone_y + 2 * ov);
  quilter.set_min_candidates(plan.vertical_profile != 0 ? kProfileCandidates : plan.min_candidates);
  for (int y : vertical) {
    quilter.place(zx - ov, y, arm_x, chain, none);
    if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  }
  // H1 + H2: likewise through the left/right border.
  quilter.set_profile(&original, plan.horizontal_profile, zx - ov, zone_x + 2 * ov);
  quilter.set_min_candidates(plan.horizontal_profile != 0 ? kProfileCandidates : plan.min_candidates);
  for (int x : horizontal) {
    quilter.place(x, zy - ov, chain, arm_y, none);
    if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  }
  // C: the centre, constrained on all four sides.
  quilter.set_profile(&original, 0);
  quilter.set_min_candidates(plan.min_candidates);
  quilter.place(zx - ov, zy - ov, arm_x, arm_y, none);
  tick();
  placed += quilter.placed();
  cut_cost = quilter.cut_cost();
  return Status::ok();
}

}  // namespace

Image swap_quadrants(const Image& image) {
  if (!check_image(image).is_ok()) return Image{};
  Image out = image;
  const int w = image.width, h = image.height, c = image.channels;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t* s = &image.pixels[(static_cast<size_t>((y + h / 2) % h) * w + (x + w / 2) % w) * c];
      std::copy(s, s + c, &out.pixels[(static_cast<size_t>(y) * w + x) * c]);
    }
  return out;
}

Status make_tileable(const Image& exemplar, const TileOptions& options, Image& tile, TileReport* report) {
  std::vector<Image> tiles;
  TAILOR_RETURN_IF_ERROR(make_tile_variants(exemplar, options, 1, tiles, report));
  tile = std::move(tiles[0]);
  return Status::ok();
}

Status make_tile_variants(const Image& exemplar, const TileOptions& options, int count, std::vector<Image>& tiles,
                          TileReport* report) {
  tiles.clear();
  if (count < 1 || count > 64)
    return Status::error(ErrorCode::kInvalidArgument, "", "variant count must be in [1, 64]",
                         "got " + std::to_string(count));
  TileReport local;
  TileReport& rep = report ? *report : local;
  rep = TileReport{};
  try {
    Setup setup;
    TAILOR_RETURN_IF_ERROR(prepare(exemplar, options, setup, rep));
    const Plane& ex = setup.exemplar;
    const int w = ex.width, h = ex.height, b = setup.block, ov = setup.overlap;
    SsdSearch search;
    search.init(ex);

    // Progress: the base tile counts as one share, each variant as one more.
    TileOptions base_options = options;
    if (options.progress) base_options.progress = [&](double f) { return options.progress(f / count); };
    // Blocks chosen for their cut patches can be smoother than the exemplar on average. When the
    // exemplar's own strongest edge decides the worst seam (ornamental tiles, water, brick:
    // interior worst > kStrongEdge x median), that edge is kept verbatim and the target is a tie
    // with its ratio in the exemplar: arms that smooth the lines they cross lower the median line
    // difference and lift the edge's ratio above it (water: median row difference -3 %, edge
    // 3.83 against 3.69). There, smooth blocks are penalised, tolerance sets are topped up to
    // kProfileCandidates blocks, and each arm's blocks are ranked with the profile check of the
    // lines they cross (Quilter::profile_deficit): first with both arms checked, then (when the
    // worst seam still misses) with the horizontal arm only. Elsewhere the 1.5 floor leaves room;
    // small exemplars get a few attempts with derived random streams (best of them by cut cost,
    // the proxy of patch coherence), and a smooth-block penalty is a last try when the worst seam
    // misses its target. Each check of the worst seam is O(N); the better result is kept.
    // The reference is the input as given (with fit_period, `ex` also holds the fold seam).
    const double exemplar_worst = worst_seam_ratio(internal::to_plane(exemplar), false);
    const double target = std::max(exemplar_worst, kSeamFloor);
    std::vector<CrossPlan> plans;
    if (exemplar_worst > kStrongEdge) {
      plans.push_back({0, kSmoothPenalty, 0, 1, 2});
      plans.push_back({0, kSmoothPenalty, 0, 0, 2});
    } else {
      const int attempts = std::clamp(kAttemptPixels / std::max(1, w * h), 1, kMaxAttempts);
      for (int a = 0; a < attempts; ++a) plans.push_back({a == 0 ? 0u : 1000u + static_cast<unsigned>(a), 0.0, kMinCandidates, 0, 0});
      plans.push_back({0, kRetryPenalty, kMinCandidates, 0, 0});
    }
    Plane base;
    int base_blocks = 0;
    double base_worst = 0.0, base_cost = 0.0;
    bool base_meets = false;
    const size_t retry_plan = exemplar_worst > kStrongEdge ? 1 : plans.size() - 1;
    for (size_t i = 0; i < plans.size(); ++i) {
      // Later plans of strong-edge exemplars, and the smooth-penalty retry, run only if needed.
      if (i >= retry_plan && base_meets) break;
      TileOptions plan_options = base_options;
      // Later attempts report the base share as done, and can still be cancelled.
      if (i > 0 && base_options.progress) plan_options.progress = [&](double) { return base_options.progress(1.0); };
      Plane canvas;
      int blocks = 0;
      double cost = 0.0;
      TAILOR_RETURN_IF_ERROR(quilt_cross(setup, plan_options, plans[i], search, canvas, blocks, cost));
      const double worst = worst_seam_ratio(canvas, true);
      const bool meets = worst <= target * kSeamHeadroom;
      // Meeting the seam target first, then the lower cut cost (or, both missing, the lower worst seam).
      const bool better = i == 0 || (meets && !base_meets) ||
                          (meets == base_meets && (meets ? cost < base_cost : worst < base_worst));
      if (better) {
        base = std::move(canvas);
        base_blocks = blocks;
        base_worst = worst;
        base_cost = cost;
        base_meets = meets;
      }
    }
    rep.blocks += base_blocks;
    tiles.push_back(plane_to_image(base));

    // Variants: re-quilt everything inside a ring of `border` px, in a raster order that changes
    // with the variant; the ring and the cut band (overlap px) inside it are known context.
    const int border = rep.border;
    std::vector<uint8_t> locked(static_cast<size_t>(w) * h, 0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (x < border || y < border || x >= w - border || y >= h - border) locked[static_cast<size_t>(y) * w + x] = 1;
    // 2 x 2 large blocks: few cuts, so each variant keeps the exemplar's statistics (small blocks
    // over the whole interior drift its histogram and gradients, a known weakness of quilting).
    const int vbw = std::max(b, (w - 2 * border + ov + 1) / 2);
    const int vbh = std::max(b, (h - 2 * border + ov + 1) / 2);
    const std::vector<int> xs = chain_positions(border, w - 2 * border, vbw, ov);
    const std::vector<int> ys = chain_positions(border, h - 2 * border, vbh, ov);
    for (int k = 1; k < count; ++k) {
      Plane canvas = base;
      std::vector<uint8_t> known(static_cast<size_t>(w) * h, 0);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          if (x < border + ov || y < border + ov || x >= w - border - ov || y >= h - border - ov)
            known[static_cast<size_t>(y) * w + x] = 1;
      SplitMix64 rng(mix_seed(options.seed, static_cast<uint64_t>(k)));
      Quilter quilter(ex, search, canvas, known, locked, ov, options.tolerance, rng);
      const bool flip_x = ((k - 1) & 1) != 0, flip_y = ((k - 1) & 2) != 0;
      const size_t per_variant = xs.size() * ys.size();
      size_t done = 0;
      for (size_t j = 0; j < ys.size(); ++j) {
        const int y = ys[flip_y ? ys.size() - 1 - j : j];
        for (size_t i = 0; i < xs.size(); ++i) {
          const int x = xs[flip_x ? xs.size() - 1 - i : i];
          // Do not simply re-copy what the base tile has there (its source in the exemplar).
          Exclusion exclusion;
          exclusion.active = true;
          exclusion.x = (x + setup.shift_x) % w;
          exclusion.y = (y + setup.shift_y) % h;
          exclusion.radius = std::min(vbw, vbh) / 2;
          quilter.place(x, y, vbw, vbh, exclusion);
          ++done;
          if (options.progress &&
              !options.progress((k + static_cast<double>(done) / static_cast<double>(per_variant)) / count))
            return Status::error(ErrorCode::kCancelled, "", "cancelled");
        }
      }
      rep.blocks += quilter.placed();
      tiles.push_back(plane_to_image(canvas));
    }
  } catch (const std::exception& e) {
    tiles.clear();
    return Status::error(ErrorCode::kInvalidImage, "", std::string("tiling failed: ") + e.what());
  }
  return Status::ok();
}

}  // namespace tailor
