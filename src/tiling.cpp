// Self-tileable textures: quadrant swap, then image quilting of the '+' seam (thesis chapter 3).
//
// This work is based on:
//   A. A. Efros, W. T. Freeman, "Image Quilting for Texture Synthesis and Transfer", SIGGRAPH 2001
//     (block choice by overlap SSD with a tolerance, minimum-error boundary cut by dynamic programming).
//   The thesis, chapter 3: swap quadrants, repair H1+H2, V1+V2 and the centre C with a weight map
//     that keeps the outer border; variants from different weight maps (3.2); period fitting (3.1).
//
// The SSD of a masked template against every exemplar position is computed with FFTs
// (SSD = sum M T^2 - 2 sum_c corr(M T_c, E_c) + corr(M, sum_c E_c^2)); the exemplar's spectra are
// computed once, so each block costs channels + 1 forward real DFTs of the template and one inverse.
#include "tailor/tiling.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>

#include "internal/tiling_util.h"
#include "tailor/image_ops.h"

namespace tailor {

using internal::Plane;
using internal::SplitMix64;

namespace {

constexpr int kMinTileSide = 32;

//! SSD of a masked B x B template against every B x B block of the exemplar, by FFT.
class SsdSearch {
 public:
  void init(const Plane& exemplar, int block) {
    ex_ = &exemplar;
    block_ = block;
    const int dft_w = cv::getOptimalDFTSize(exemplar.width);
    const int dft_h = cv::getOptimalDFTSize(exemplar.height);
    // Circular correlation is exact for the valid positions p <= size - block: p + q < size <= dft size.
    cv::Mat plane(dft_h, dft_w, CV_32F, cv::Scalar(0));
    cv::Mat square(dft_h, dft_w, CV_32F, cv::Scalar(0));
    spectra_.assign(static_cast<size_t>(exemplar.channels), cv::Mat());
    for (int c = 0; c < exemplar.channels; ++c) {
      for (int y = 0; y < exemplar.height; ++y) {
        float* row = plane.ptr<float>(y);
        float* sq = square.ptr<float>(y);
        for (int x = 0; x < exemplar.width; ++x) {
          const float v = exemplar.at(x, y)[c];
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

  int positions_x() const { return ex_->width - block_ + 1; }
  int positions_y() const { return ex_->height - block_ + 1; }

  //! templ: B*B*channels samples, mask: B*B weights (0 or 1). ssd: positions_x * positions_y values.
  void search(const std::vector<float>& templ, const std::vector<float>& mask, std::vector<float>& ssd) {
    const int b = block_;
    const int channels = ex_->channels;
    double constant = 0.0;
    accumulated_.setTo(0);
    for (int c = -1; c < channels; ++c) {
      // c = -1: the mask itself, correlated with the summed squares of the exemplar.
      for (int y = 0; y < b; ++y) {
        float* row = padded_.ptr<float>(y);
        for (int x = 0; x < b; ++x) {
          const size_t i = static_cast<size_t>(y) * b + x;
          if (c < 0) {
            row[x] = mask[i];
          } else {
            const float t = templ[i * channels + c];
            row[x] = mask[i] * t;
            constant += static_cast<double>(mask[i]) * t * t;
          }
        }
      }
      cv::dft(padded_, spectrum_, 0, b);
      cv::mulSpectrums(c < 0 ? square_spectrum_ : spectra_[c], spectrum_, product_, 0, true);
      cv::scaleAdd(product_, c < 0 ? 1.0 : -2.0, accumulated_, accumulated_);
    }
    const int nx = positions_x();
    const int ny = positions_y();
    cv::dft(accumulated_, result_, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE, ny);
    ssd.resize(static_cast<size_t>(nx) * ny);
    for (int y = 0; y < ny; ++y) {
      const float* row = result_.ptr<float>(y);
      for (int x = 0; x < nx; ++x)
        ssd[static_cast<size_t>(y) * nx + x] = std::max(0.0f, static_cast<float>(constant + row[x]));
    }
  }

 private:
  const Plane* ex_ = nullptr;
  int block_ = 0;
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
void min_error_path(const std::vector<float>& err, int length, int width, std::vector<float>& cost, std::vector<int>& path) {
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
          const std::vector<uint8_t>& locked, int block, int overlap, double tolerance, SplitMix64& rng)
      : ex_(exemplar), search_(search), canvas_(canvas), known_(known), locked_(locked), b_(block), ov_(overlap),
        tolerance_(tolerance), rng_(rng) {}

  //! Places one block with its top-left corner at canvas (bx, by) (taken modulo the canvas size).
  void place(int bx, int by, const Exclusion& exclusion) {
    const int b = b_;
    const int channels = canvas_.channels;
    const size_t bb = static_cast<size_t>(b) * b;
    templ_.resize(bb * channels);
    mask_.assign(bb, 0.0f);
    bool any_known = false;
    for (int y = 0; y < b; ++y) {
      for (int x = 0; x < b; ++x) {
        const size_t i = static_cast<size_t>(y) * b + x;
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

    // Choose the exemplar block.
    const int nx = search_.positions_x();
    const int ny = search_.positions_y();
    int chosen = 0;
    if (!any_known) {
      chosen = static_cast<int>(rng_.below(static_cast<uint32_t>(nx * ny)));
    } else {
      search_.search(templ_, mask_, ssd_);
      float best = std::numeric_limits<float>::max();
      float energy = 0.0f;
      for (size_t i = 0; i < templ_.size(); ++i) energy += mask_[i / channels] * templ_[i] * templ_[i];
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
          if (!exclusion.contains(x, y)) best = std::min(best, ssd_[static_cast<size_t>(y) * nx + x]);
      const bool use_exclusion = best < std::numeric_limits<float>::max();
      if (!use_exclusion)
        for (float v : ssd_) best = std::min(best, v);
      // The small absolute term absorbs FFT round-off (relative ~1e-6 of the template energy).
      const float threshold = best * static_cast<float>(1.0 + tolerance_) + 1e-5f * energy + 1e-3f;
      candidates_.clear();
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
          if (ssd_[static_cast<size_t>(y) * nx + x] <= threshold && !(use_exclusion && exclusion.contains(x, y)))
            candidates_.push_back(y * nx + x);
      chosen = candidates_[rng_.below(static_cast<uint32_t>(candidates_.size()))];
    }
    const int px = chosen % nx;
    const int py = chosen / nx;

    // Boundary cuts on every side whose overlap strip holds known pixels.
    error_.assign(bb, 0.0f);
    for (int y = 0; y < b; ++y) {
      for (int x = 0; x < b; ++x) {
        const size_t i = static_cast<size_t>(y) * b + x;
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
    take_new_.assign(bb, 1);
    cut_side(0);
    cut_side(1);
    cut_side(2);
    cut_side(3);

    for (int y = 0; y < b; ++y) {
      for (int x = 0; x < b; ++x) {
        const size_t i = static_cast<size_t>(y) * b + x;
        const int cx = Plane::mod(bx + x, canvas_.width);
        const int cy = Plane::mod(by + y, canvas_.height);
        const size_t ci = static_cast<size_t>(cy) * canvas_.width + cx;
        if (locked_[ci]) continue;
        if (take_new_[i] || mask_[i] == 0.0f) {
          const float* e = ex_.at(px + x, py + y);
          std::copy(e, e + channels, canvas_.at(cx, cy));
        }
        known_[ci] = 1;
      }
    }
    ++placed_;
  }

  int placed() const { return placed_; }

 private:
  // side: 0 left, 1 right, 2 top, 3 bottom. Pixels beyond the cut (towards the side) keep the old value.
  void cut_side(int side) {
    const int b = b_;
    const int ov = ov_;
    bool active = false;
    strip_.assign(static_cast<size_t>(b) * ov, 0.0f);
    for (int i = 0; i < b; ++i) {
      for (int j = 0; j < ov; ++j) {
        int x = 0, y = 0;
        strip_coords(side, i, j, x, y);
        const size_t k = static_cast<size_t>(y) * b + x;
        if (mask_[k] != 0.0f) active = true;
        strip_[static_cast<size_t>(i) * ov + j] = error_[k];
      }
    }
    if (!active) return;
    min_error_path(strip_, b, ov, cost_, path_);
    for (int i = 0; i < b; ++i) {
      for (int j = 0; j < path_[static_cast<size_t>(i)]; ++j) {
        int x = 0, y = 0;
        strip_coords(side, i, j, x, y);
        take_new_[static_cast<size_t>(y) * b + x] = 0;
      }
    }
  }

  // Strip coordinates (i along the side, j = depth from the block's edge) -> block (x, y).
  void strip_coords(int side, int i, int j, int& x, int& y) const {
    switch (side) {
      case 0: x = j; y = i; break;
      case 1: x = b_ - 1 - j; y = i; break;
      case 2: x = i; y = j; break;
      default: x = i; y = b_ - 1 - j; break;
    }
  }

  const Plane& ex_;
  SsdSearch& search_;
  Plane& canvas_;
  std::vector<uint8_t>& known_;
  const std::vector<uint8_t>& locked_;
  int b_, ov_;
  double tolerance_;
  SplitMix64& rng_;
  int placed_ = 0;
  std::vector<float> templ_, mask_, ssd_, error_, strip_, cost_;
  std::vector<int> candidates_, path_;
  std::vector<uint8_t> take_new_;
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
};

Status prepare(const Image& input, const TileOptions& options, Setup& setup, TileReport& report) {
  TAILOR_RETURN_IF_ERROR(check_image(input));
  if (options.block < 8 || options.block > 256)
    return Status::error(ErrorCode::kInvalidArgument, "", "block size must be in [8, 256] px", "got " + std::to_string(options.block));
  if (options.overlap != 0 && (options.overlap < 1 || options.overlap > options.block / 2 - 1))
    return Status::error(ErrorCode::kInvalidArgument, "", "overlap must be in [1, block/2 - 1] px",
                         "got " + std::to_string(options.overlap) + " for block " + std::to_string(options.block));
  if (!(options.tolerance >= 0.0 && options.tolerance <= 1.0))
    return Status::error(ErrorCode::kInvalidArgument, "", "tolerance must be in [0, 1]");
  if (input.width < kMinTileSide || input.height < kMinTileSide)
    return Status::error(ErrorCode::kInvalidImage, "", "image too small to make tileable (at least " +
                         std::to_string(kMinTileSide) + " px a side)",
                         std::to_string(input.width) + "x" + std::to_string(input.height));
  Image work = input;
  if (options.fit_period) {
    report.period = estimate_period(input);
    int w = input.width, h = input.height;
    period_fitted_size(report.period, input.width, input.height, w, h);
    if (w != input.width || h != input.height) {
      TAILOR_RETURN_IF_ERROR(resize_image(input, w, h, work));
    }
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
    report.warnings.push_back("overlap shrunk from " + std::to_string(overlap) + " to " + std::to_string(shrunk) + " px");
    overlap = shrunk;
  }
  setup.exemplar = internal::to_plane(work);
  setup.block = block;
  setup.overlap = overlap;
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
  for (size_t i = 0; i < p.px.size(); ++i) out.pixels[i] = static_cast<uint8_t>(std::lround(std::clamp(p.px[i], 0.0f, 255.0f)));
  return out;
}

uint64_t mix_seed(uint64_t seed, uint64_t stream) {
  SplitMix64 g(seed ^ (0xD1B54A32D192ED03ull * (stream + 1)));
  return g.next();
}

//! Base tile: swap, then quilt the vertical arm, the horizontal arm and the centre.
Status quilt_cross(const Setup& setup, const TileOptions& options, SsdSearch& search, Plane& canvas, int& placed) {
  const Plane& ex = setup.exemplar;
  const int w = ex.width, h = ex.height, b = setup.block, ov = setup.overlap;
  canvas = ex;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* s = ex.at((x + w / 2) % w, (y + h / 2) % h);
      std::copy(s, s + ex.channels, canvas.at(x, y));
    }
  // The seams lie between columns cx-1, cx and rows cy-1, cy; the zones around them are unknown.
  const int cx = w - w / 2, cy = h - h / 2;
  const int zone = b - 2 * ov;
  const int zx = cx - zone / 2, zy = cy - zone / 2;
  std::vector<uint8_t> known(static_cast<size_t>(w) * h, 1), locked(static_cast<size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if ((x >= zx && x < zx + zone) || (y >= zy && y < zy + zone)) known[static_cast<size_t>(y) * w + x] = 0;

  SplitMix64 rng(mix_seed(options.seed, 0));
  Quilter quilter(ex, search, canvas, known, locked, b, ov, options.tolerance, rng);
  const std::vector<int> vertical = chain_positions(zy + zone, h - zone, b, ov);
  const std::vector<int> horizontal = chain_positions(zx + zone, w - zone, b, ov);
  const double total = static_cast<double>(vertical.size() + horizontal.size() + 1);
  double done = 0.0;
  auto tick = [&]() -> bool { done += 1.0; return !options.progress || options.progress(done / total); };
  const Exclusion none;
  // V1 + V2: one chain through the top/bottom border (toroidal), from below the centre to above it.
  for (int y : vertical) {
    quilter.place(zx - ov, y, none);
    if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  }
  // H1 + H2: likewise through the left/right border.
  for (int x : horizontal) {
    quilter.place(x, zy - ov, none);
    if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  }
  // C: the centre, constrained on all four sides.
  quilter.place(zx - ov, zy - ov, none);
  tick();
  placed += quilter.placed();
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
    return Status::error(ErrorCode::kInvalidArgument, "", "variant count must be in [1, 64]", "got " + std::to_string(count));
  TileReport local;
  TileReport& rep = report ? *report : local;
  rep = TileReport{};
  try {
    Setup setup;
    TAILOR_RETURN_IF_ERROR(prepare(exemplar, options, setup, rep));
    const Plane& ex = setup.exemplar;
    const int w = ex.width, h = ex.height, b = setup.block, ov = setup.overlap;
    SsdSearch search;
    search.init(ex, b);

    // Progress: the base tile counts as one share, each variant as one more.
    TileOptions base_options = options;
    if (options.progress)
      base_options.progress = [&](double f) { return options.progress(f / count); };
    Plane base;
    TAILOR_RETURN_IF_ERROR(quilt_cross(setup, base_options, search, base, rep.blocks));
    tiles.push_back(plane_to_image(base));

    // Variants: re-quilt everything inside a ring of `border` px, in a raster order that changes
    // with the variant; the ring and the cut band (overlap px) inside it are known context.
    const int border = rep.border;
    std::vector<uint8_t> locked(static_cast<size_t>(w) * h, 0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (x < border || y < border || x >= w - border || y >= h - border) locked[static_cast<size_t>(y) * w + x] = 1;
    const std::vector<int> xs = chain_positions(border, w - 2 * border, b, ov);
    const std::vector<int> ys = chain_positions(border, h - 2 * border, b, ov);
    for (int k = 1; k < count; ++k) {
      Plane canvas = base;
      std::vector<uint8_t> known(static_cast<size_t>(w) * h, 0);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          if (x < border + ov || y < border + ov || x >= w - border - ov || y >= h - border - ov)
            known[static_cast<size_t>(y) * w + x] = 1;
      SplitMix64 rng(mix_seed(options.seed, static_cast<uint64_t>(k)));
      Quilter quilter(ex, search, canvas, known, locked, b, ov, options.tolerance, rng);
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
          exclusion.x = (x + w / 2) % w;
          exclusion.y = (y + h / 2) % h;
          exclusion.radius = b / 2;
          quilter.place(x, y, exclusion);
          ++done;
          if (options.progress && !options.progress((k + static_cast<double>(done) / static_cast<double>(per_variant)) / count))
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
