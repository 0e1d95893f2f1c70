// Self-tileable textures: quadrant swap, then image quilting of the '+' seam (thesis chapter 3).
//
// This work is based on:
//   A. A. Efros, W. T. Freeman, "Image Quilting for Texture Synthesis and Transfer", SIGGRAPH 2001
//     (block choice by overlap SSD with a tolerance, minimum-error boundary cut by dynamic programming).
//   The thesis, chapter 3: swap quadrants, repair H1+H2, V1+V2 and the centre C with a weight map
//     that keeps the outer border; variants from different weight maps (3.2); period fitting (3.1).
//
// The quilting itself is quilting.h (block choice, ranking, boundary cut) over the block search of
// block_search.h (SSD by FFT). Here: the strategy. Where the exemplar's own strongest edge decides
// the worst seam, the arms' blocks are also ranked by the straight-boundary profile they leave
// (Quilter::profile_deficit), and a few whole attempts are compared by O(N) checks
// (make_tile_variants).
#include "tailor/tiling.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <exception>
#include <limits>

#include "tailor/image_ops.h"
#include "texture/cut_refine.h"
#include "texture/quilting.h"
#include "texture/tiling_util.h"

namespace tailor {

using internal::Exclusion;
using internal::Plane;
using internal::Quilter;
using internal::SessionRecord;
using internal::SplitMix64;
using internal::SsdSearch;
using internal::TilePlan;

namespace {

constexpr int kMinTileSide = 32;
constexpr int kChainPercent = 100;  // arm blocks are this many percent as long as wide (150, 200: faster, worse seams)
constexpr int kArmDivisor = 2;      // the '+' is repaired with blocks and overlaps this many times smaller
constexpr int kCandidatePool = 32;  // near-best (SSD) blocks compared by the patch cost of their cuts
constexpr double kSmoothPenalty = 2.0;   // cost * (mean gradient / block gradient)^this for smooth blocks
constexpr double kRetryPenalty = 1.0;    // the same for the second try of the other exemplars
constexpr double kSeamFloor = 1.5;       // worst-seam target: max(exemplar's interior worst, this)
constexpr double kStrongEdge = 2.0;      // exemplars whose interior worst seam ratio exceeds this get kSmoothPenalty
constexpr double kSeamHeadroom = 0.998;  // an attempt meets the worst-seam target with this much room (a tie is a miss)
constexpr int kMinCandidates = 8;  // a tolerance set smaller than this is topped up with the next best (SSD) blocks
constexpr int kProfileCandidates = 16;     // the same where the straight-boundary profile is checked
constexpr int kAttemptPixels = 320 * 320;  // best of (this / pixels) attempts, at most kMaxAttempts
constexpr int kMaxAttempts = 4;
constexpr double kDirectional = 0.5;               // symmetry 4 warns above this orientation_anisotropy()
constexpr double kWrapLow = 0.8, kWrapHigh = 1.2;  // the wrap-ratio target (meets_tile_targets)
constexpr unsigned kQuarterTurnRedraws = 4;        // symmetry 4: draws after the retry while a target misses
// Symmetry 4 makes a tile twice the exemplar's side up to this side, the exemplar's own side beyond
// it, and draws blocks from the exemplar's four turns up to kMaxTurnedSearchSide (each turn is
// one more FFT search per block: at 1024 px 3.5 s -> 12.7 s). Exemplars above kPlanMaxSide are
// quilted on a kPlanSide px copy and read at full size from its source map
// (tile_from_reduced_sources), so the turned search always runs.
constexpr int kMaxDoubledSide = 2048;
constexpr int kMaxTurnedSearchSide = 512;

//! Square image cut out of `in`.
Image crop(const Image& in, int x0, int y0, int w, int h) {
  Image out;
  out.width = w;
  out.height = h;
  out.channels = in.channels;
  out.pixels.resize(static_cast<size_t>(w) * h * in.channels);
  for (int y = 0; y < h; ++y) {
    const uint8_t* s = &in.pixels[(static_cast<size_t>(y0 + y) * in.width + x0) * in.channels];
    std::copy(s, s + static_cast<size_t>(w) * in.channels, &out.pixels[static_cast<size_t>(y) * w * in.channels]);
  }
  return out;
}

//! The plane turned once the way of Quilter::set_quarter_turns: out(S - 1 - y, x) = in(x, y).
Plane turn_plane(const Plane& in) {
  Plane out = in;
  out.width = in.height;
  out.height = in.width;
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      const float* v = in.at(x, y);
      std::copy(v, v + in.channels, out.at(in.height - 1 - y, x));
    }
  return out;
}

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
  int symmetry = 1;  // 4: quarter-turn tile (exemplar cropped to its centred square, even side)
  int quadrant = 0;  // symmetry 4: side M of the exemplar square each quadrant holds (tile side 2M)
  int crop_x = 0;    // symmetry 4: where the exemplar square starts in the input
  int crop_y = 0;
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
  if (options.symmetry != 1 && options.symmetry != 4)
    return Status::error(ErrorCode::kInvalidArgument, "", "symmetry must be 1 or 4",
                         "got " + std::to_string(options.symmetry));
  if (options.symmetry == 4 && options.fit_period)
    return Status::error(ErrorCode::kInvalidArgument, "", "--symmetry 4 cannot be combined with --fit-period",
                         "a quarter-turn tile is square; a period fitted along x and y would not survive the turn");
  if (options.same_size && options.symmetry != 4)
    return Status::error(ErrorCode::kInvalidArgument, "", "--same-size needs --symmetry 4");
  Image work = input;
  report.symmetry = options.symmetry;
  setup.symmetry = options.symmetry;
  if (options.symmetry == 4) {
    // Square of even side: the quarter turn about the centre maps the pixel grid onto itself.
    report.anisotropy = orientation_anisotropy(input);
    if (report.anisotropy > kDirectional)
      report.warnings.push_back("directional texture (orientation anisotropy " +
                                std::to_string(report.anisotropy).substr(0, 4) +
                                " > 0.5): a quarter-turn tile shows it turned by 90 degrees in three of its quadrants");
    const int side = std::min(input.width, input.height) & ~3;
    if (side != input.width || side != input.height) {
      report.warnings.push_back("cropped to the centred " + std::to_string(side) + "x" + std::to_string(side) +
                                " square for --symmetry 4");
      setup.crop_x = (input.width - side) / 2;
      setup.crop_y = (input.height - side) / 2;
      work = crop(input, setup.crop_x, setup.crop_y, side, side);
    }
  }
  if (options.fit_period) {
    report.period = estimate_period(input);
    int w = input.width, h = input.height;
    period_fitted_size(report.period, input.width, input.height, w, h);
    if (w != input.width || h != input.height) work = fit_to_period(input, report.period);
  }
  report.width = work.width;
  report.height = work.height;
  if (options.symmetry == 4) {
    // Each quadrant holds the whole exemplar (tile side 2N): the tile then has a plain tile's seam
    // length per pixel and the exemplar's histogram; with quadrants of N/2 (same_size), twice the
    // seam length per pixel and a quarter of the photo (docs/tiling.md).
    const bool doubled = !options.same_size && 2 * work.width <= kMaxDoubledSide;
    if (!options.same_size && !doubled)
      report.warnings.push_back("tile kept at " + std::to_string(work.width) + " px: twice the side would exceed " +
                                std::to_string(kMaxDoubledSide) + " px (as with --same-size)");
    setup.quadrant = doubled ? work.width : work.width / 2;
    report.width = report.height = 2 * setup.quadrant;
  }
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
  if (setup.symmetry == 1) choose_shift(setup.exemplar, setup.shift_x, setup.shift_y);
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
  shift_x = internal::ordinary_boundary(cols, w / 2, std::max(1, w / 8));
  shift_y = internal::ordinary_boundary(rows, h / 2, std::max(1, h / 8));
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

//! Where a quarter-turn tile's wrap goes (symmetry 4): the 4-fold centre must stay on the tile's
//! corner or centre (a map that turns the texture by quarter turns across a seam turns it about a
//! lattice point, docs/mapping.md "Symmetry 4"; about any other point its seams would jump by half a
//! repeat), so the wrap runs through one of the pinwheel's two '+' lines: shift 0 or N/2, whichever
//! joins its two sides more like the tile's median column boundary. Returns the shift and, in
//! `wrap`, that line's difference over the median (the wrap ratio; rows are the turned columns).
int quarter_turn_wrap(const Plane& pinwheel, double& wrap) {
  const int n = pinwheel.width;
  std::vector<double> boundary(static_cast<size_t>(n), 0.0);  // summed |difference| across x-1 | x
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const float* left = pinwheel.at((x + n - 1) % n, y);
      const float* right = pinwheel.at(x, y);
      for (int k = 0; k < pinwheel.channels; ++k) boundary[static_cast<size_t>(x)] += std::abs(left[k] - right[k]);
    }
  // The wrap line's difference over the median of the other lines, as tile_metrics measures it.
  const auto ratio = [&](int x) {
    std::vector<double> others = boundary;
    others.erase(others.begin() + x);
    std::nth_element(others.begin(), others.begin() + static_cast<std::ptrdiff_t>(others.size() / 2), others.end());
    return std::max(boundary[static_cast<size_t>(x)], 1e-9) / std::max(others[others.size() / 2], 1e-9);
  };
  const double at_zero = ratio(0), at_half = ratio(n / 2);
  const int q = std::abs(std::log(at_half)) < std::abs(std::log(at_zero)) ? n / 2 : 0;
  wrap = q == 0 ? at_zero : at_half;
  return q;
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
                   Plane& canvas, int& placed, double& cut_cost, SessionRecord* record) {
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
      if (known[static_cast<size_t>(y) * w + x])
        source[static_cast<size_t>(y) * w + x] = ((y + sy) % h) * w + (x + sx) % w;
  const Plane original = canvas;
  SplitMix64 rng(mix_seed(options.seed, plan.stream));
  Quilter quilter(ex, search, canvas, known, locked, ov, options.tolerance, rng, &source, kCandidatePool,
                  plan.gradient_penalty);
  quilter.set_min_candidates(plan.min_candidates);
  if (record) {
    record->known = known;
    record->locked = locked;
    record->overlap = ov;
    quilter.set_record(&record->placements);
  }
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

//! Quarter-turn tile (symmetry 4) of side N = 2M from the square S x S exemplar, M = setup.quadrant
//! (S, or S / 2 with same_size): the canvas starts as a pinwheel of an M x M exemplar square Q (Q in
//! the top-left quadrant, its images under r(x, y) = (N - 1 - y, x) in the others), so it is
//! unchanged by r and has seams on the lines x, y = M (the centre '+') and x, y = 0 (the wrap '+').
//! Zones of `margin` px around them are unknown and quilted with the arm blocks of quilt_cross,
//! drawn from the exemplar's four turns and each written into its four places
//! (Quilter::set_quarter_turns). Up to the turn, there are two seams: segment A (x = M, y in
//! [0, M): between the 2-fold point (M, 0) and the centre) and segment B (x = 0, y in [0, M):
//! between the corner and the 2-fold point (0, M)); the centre and the corner, where a block
//! would overlap its own images, get one quarter block each (its images are the other three
//! quarters). The result is made exact by rebuilding it from its top-left quadrant.
Status quilt_pinwheel(const Setup& setup, const TileOptions& options, const CrossPlan& plan, SsdSearch& search,
                      const std::vector<Plane>& turns, std::vector<SsdSearch>& turn_search, Plane& canvas, int& placed,
                      double& cut_cost, std::vector<int32_t>& source_out) {
  const Plane& ex = setup.exemplar;
  const int es = ex.width, c = ex.channels;
  const int m = setup.quadrant, n = 2 * m;
  const int b = std::max(8, setup.block / kArmDivisor);
  const int ov = std::clamp(setup.overlap / kArmDivisor, 1, b / 2 - 1);
  const int margin = b - 2 * ov;    // unknown zone across each line
  const int half = margin / 2;      // the zone is [line - half, line - half + margin)
  const int arm = margin + 2 * ov;  // block extent across a line
  // A chain block must not reach its own quarter-turn image near a 4-fold point: the chains stop
  // `reach` px before it and a quarter block of side `quarter` (>= reach + ov) fills the rest.
  const int reach = half + 2 * ov;
  const int quarter = std::max(b, reach + ov);
  if (quarter > m / 2) return Status::error(ErrorCode::kInvalidArgument, "", "block too large for --symmetry 4");
  canvas.width = canvas.height = n;
  canvas.channels = c;
  canvas.px.assign(static_cast<size_t>(n) * n * c, 0.0f);
  std::vector<int32_t> source(static_cast<size_t>(n) * n, -1);
  std::vector<uint8_t> known(static_cast<size_t>(n) * n, 1), locked(static_cast<size_t>(n) * n, 0);
  // Q = exemplar [qx, qx + m) x [qy, qy + m): the whole exemplar, or (m < es) of 3 x 3 places the
  // one whose 64-bin histogram (all channels) is nearest the exemplar's (a non-stationary photo:
  // its centre alone can be lighter or darker than the whole).
  auto histogram = [&](int x0, int y0, int size) {
    std::vector<double> h(static_cast<size_t>(64 * c), 0.0);
    for (int y = y0; y < y0 + size; ++y)
      for (int x = x0; x < x0 + size; ++x)
        for (int k = 0; k < c; ++k)
          h[static_cast<size_t>(k * 64 + std::clamp(static_cast<int>(ex.at(x, y)[k]), 0, 255) / 4)] +=
              1.0 / (static_cast<double>(size) * size);
    return h;
  };
  const std::vector<double> whole = histogram(0, 0, es);
  int qx = (es - m) / 2, qy = (es - m) / 2;
  double best_l1 = std::numeric_limits<double>::max();
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) {
      const int x0 = i * (es - m) / 2, y0 = j * (es - m) / 2;
      const std::vector<double> h = histogram(x0, y0, m);
      double l1 = 0.0;
      for (size_t k = 0; k < h.size(); ++k) l1 += std::abs(h[k] - whole[k]);
      if (l1 < best_l1 - 1e-12) {
        best_l1 = l1;
        qx = x0;
        qy = y0;
      }
    }
  for (int y = 0; y < m; ++y)
    for (int x = 0; x < m; ++x) {
      int rx = x, ry = y;
      int32_t src = (qy + y) * es + qx + x;
      const float* e = ex.at(qx + x, qy + y);
      for (int turn = 0; turn < 4; ++turn) {
        std::copy(e, e + c, canvas.at(rx, ry));
        source[static_cast<size_t>(ry) * n + rx] = src;
        const int nx2 = n - 1 - ry;
        ry = rx;
        rx = nx2;
        src = internal::next_turn_source(src, es);
      }
    }
  auto in_zone = [&](int v) { return Plane::mod(v - (m - half), n) < margin || Plane::mod(v + half, n) < margin; };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      if (in_zone(x) || in_zone(y)) {
        known[static_cast<size_t>(y) * n + x] = 0;
        source[static_cast<size_t>(y) * n + x] = -1;
      }
  SplitMix64 rng(mix_seed(options.seed, plan.stream));
  Quilter quilter(ex, search, canvas, known, locked, ov, options.tolerance, rng, &source, kCandidatePool,
                  plan.gradient_penalty);
  quilter.set_quarter_turns(&turns, turn_search.empty() ? nullptr : &turn_search);
  quilter.set_min_candidates(plan.min_candidates);
  // The 2-fold point (M, 0) gets a block of 2 quarter x 2 quarter, so chain A starts below it.
  const int a0 = quarter - ov;
  const std::vector<int> chain_a = chain_positions(a0, m - reach + ov - a0, b, ov);
  const std::vector<int> chain_b = chain_positions(reach - ov, m - half + ov - (reach - ov), b, ov);
  const double total = static_cast<double>(chain_a.size() + chain_b.size() + 3);
  double done = 0.0;
  auto tick = [&]() -> bool {
    done += 1.0;
    return !options.progress || options.progress(done / total);
  };
  const Exclusion none;
  // A: down segment x = M from the 2-fold point (M, 0) (its half-turn image fills y < 0) to the centre.
  for (int y : chain_a) {
    quilter.place(m - half - ov, y, arm, std::min(b, m - reach + ov - y), none);
    if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  }
  // B: down segment x = 0 from the corner to the centre line (filled by A's images by now).
  for (int y : chain_b) {
    quilter.place(-half - ov, y, arm, std::min(b, m - half + ov - y), none);
    if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  }
  // The rotation centres, where a block would overlap its own images: a block that writes only
  // one wedge between diagonals (the rest of it is locked; its images fill the other wedges), so
  // that the unrepaired seams between the images run along diagonals, spread over many columns
  // and rows, not along the wrap or centre lines that the seam metrics measure. (dx2, dy2): twice
  // the pixel centre's offset from the rotation centre.
  auto place_wedge = [&](int cx, int cy, int bx, int by, int bw, int bh, auto inside) {
    for (int y = by; y < by + bh; ++y)
      for (int x = bx; x < bx + bw; ++x)
        if (!inside(2 * (x - cx) + 1, 2 * (y - cy) + 1))
          locked[static_cast<size_t>(Plane::mod(y, n)) * n + Plane::mod(x, n)] = 1;
    quilter.place(bx, by, bw, bh, none);
    std::fill(locked.begin(), locked.end(), uint8_t{0});
  };
  // 4-fold: the upper wedge (dx in [dy, -dy)); its quarter turns are the right, lower, left ones.
  auto upper_wedge = [](int dx2, int dy2) { return dy2 < 0 && dx2 >= dy2 && dx2 < -dy2; };
  // 2-fold: the half below the anti-diagonal through the point (its half turn is the other half).
  auto lower_half = [](int dx2, int dy2) { return dx2 + dy2 < 0 || (dx2 + dy2 == 0 && dx2 < 0); };
  place_wedge(m, 0, m - quarter, -quarter, 2 * quarter, 2 * quarter, lower_half);
  if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  place_wedge(m, m, m - quarter, m - quarter, 2 * quarter, quarter, upper_wedge);
  if (!tick()) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  place_wedge(0, 0, -quarter, -quarter, 2 * quarter, quarter, upper_wedge);
  tick();
  // Exact: every quadrant from the top-left one.
  for (int y = 0; y < m; ++y)
    for (int x = 0; x < m; ++x) {
      const float* e = canvas.at(x, y);
      int rx = x, ry = y;
      for (int turn = 1; turn < 4; ++turn) {
        const int nx2 = n - 1 - ry;
        ry = rx;
        rx = nx2;
        std::copy(e, e + c, canvas.at(rx, ry));
      }
    }
  placed += quilter.placed();
  cut_cost = quilter.cut_cost();
  source_out = std::move(source);
  return Status::ok();
}

//! The pinwheel read at full size from the 8-bit square exemplar through `plan` (its geometry and
//! a quilted tile's sources), as a float plane (judged per attempt).
Plane tile_from_reduced_sources(const Image& full, const internal::QuarterTurnPlan& plan) {
  const int big_n = plan.tile_side;
  std::vector<uint8_t> samples;
  internal::read_quarter_turn(full.pixels.data(), full.width, full.channels, 255.0, false, false, plan, samples);
  Plane out;
  out.width = out.height = big_n;
  out.channels = full.channels;
  out.px.assign(samples.begin(), samples.end());
  return out;
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

namespace internal {

int ordinary_boundary(const std::vector<double>& diff, int centre, int reach) {
  const int size = static_cast<int>(diff.size());
  if (size < 3) return centre;
  std::vector<double> interior(diff.begin() + 1, diff.end());
  std::nth_element(interior.begin(), interior.begin() + static_cast<std::ptrdiff_t>(interior.size() / 2),
                   interior.end());
  const double median = std::max(interior[interior.size() / 2], 1e-9);
  int best = centre;
  double best_score = std::numeric_limits<double>::max();
  for (int d = 0; d <= reach; ++d)
    for (int s : {centre - d, centre + d}) {
      if (s < 1 || s >= size) continue;
      const double score = std::abs(std::log(std::max(diff[static_cast<size_t>(s)], 1e-9) / median));
      if (score < best_score - 1e-12) {
        best_score = score;
        best = s;
      }
    }
  return best;
}

Status plan_tile_variants(const Image& exemplar, const TileOptions& options, int count, bool all_channels,
                          std::vector<Image>& tiles, TileReport* report, TilePlan* tile_plan,
                          QuarterTurnPlan* quarter_plan) {
  tiles.clear();
  if (count < 1 || count > 64)
    return Status::error(ErrorCode::kInvalidArgument, "", "variant count must be in [1, 64]",
                         "got " + std::to_string(count));
  if (options.symmetry == 4 && count > 1)
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "--symmetry 4 makes one tile: --variants cannot be used with it",
                         "variants re-quilt the interior freely, which would break the quarter-turn symmetry");
  TileReport local;
  TileReport& rep = report ? *report : local;
  rep = TileReport{};
  try {
    Setup setup;
    TAILOR_RETURN_IF_ERROR(prepare(exemplar, options, setup, rep));
    // Symmetry 4 above kPlanMaxSide: quilted on a kPlanSide px copy, then read at full size from
    // that tile's source map (tile_from_reduced_sources). Quilting at full size searched the whole
    // photo for every block: a 2048 px photo took 14-30 s, a 4096 px one over 10 minutes.
    Image full;  // 8 bits: a float copy of an 8192 px photo is 0.8 GB
    // Symmetry 4: how the quilted tile's sources map onto the (full-size) exemplar square; `full`
    // is that square already, the input's crop is added for quarter_plan.
    QuarterTurnPlan geometry;
    geometry.full_side = setup.exemplar.width;
    geometry.tile_side = 2 * setup.quadrant;
    const int crop_x = setup.crop_x, crop_y = setup.crop_y;
    const bool planned = setup.symmetry == 4 && setup.exemplar.width > kPlanMaxSide;
    if (planned) {
      full = plane_to_image(setup.exemplar);
      Image reduced;
      TAILOR_RETURN_IF_ERROR(resize_image(full, kPlanSide, kPlanSide, reduced));
      TileOptions reduced_options = options;
      reduced_options.same_size = setup.quadrant != full.width;  // quadrants of the full tile's kind
      TileReport plan_report;
      TAILOR_RETURN_IF_ERROR(prepare(reduced, reduced_options, setup, plan_report));
      rep.block = setup.block;
      rep.overlap = setup.overlap;
      rep.border = setup.overlap;
    }
    const Plane& ex = setup.exemplar;
    const int w = ex.width, h = ex.height, b = setup.block, ov = setup.overlap;
    geometry.n = 2 * setup.quadrant;  // the quilted tile, on the reduced copy when planned
    geometry.s = ex.width;
    SsdSearch search;
    search.init(ex, all_channels);
    if (tile_plan) {
      *tile_plan = TilePlan{};
      tile_plan->width = w;
      tile_plan->height = h;
      tile_plan->shift_x = setup.shift_x;
      tile_plan->shift_y = setup.shift_y;
      tile_plan->sessions.resize(static_cast<size_t>(count));
    }

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
    std::vector<Plane> turns;
    std::vector<SsdSearch> turn_search;
    if (setup.symmetry == 4) {
      turns.push_back(ex);
      for (int k = 1; k < 4; ++k) turns.push_back(turn_plane(turns.back()));
      if (ex.width <= kMaxTurnedSearchSide) {
        turn_search.resize(4);
        for (int k = 0; k < 4; ++k)
          turn_search[static_cast<size_t>(k)].init(turns[static_cast<size_t>(k)], all_channels);
      }
    }
    if (exemplar_worst > kStrongEdge && setup.symmetry == 1) {
      plans.push_back({0, kSmoothPenalty, 0, 1, 2});
      plans.push_back({0, kSmoothPenalty, 0, 0, 2});
    } else {
      const int attempts = std::clamp(kAttemptPixels / std::max(1, w * h), 1, kMaxAttempts);
      for (int a = 0; a < attempts; ++a)
        plans.push_back({a == 0 ? 0u : 1000u + static_cast<unsigned>(a), 0.0, kMinCandidates, 0, 0});
      plans.push_back({0, kRetryPenalty, kMinCandidates, 0, 0});
    }
    const size_t retry_plan = exemplar_worst > kStrongEdge && setup.symmetry == 1 ? 1 : plans.size() - 1;
    // A quarter-turn wrap that is too sharp is not helped by the smooth-block penalty: other draws.
    if (setup.symmetry == 4)
      for (unsigned k = 1; k <= kQuarterTurnRedraws; ++k) plans.push_back({2000u + k, 0.0, kMinCandidates, 0, 0});
    Plane base;
    std::vector<int32_t> base_source;  // symmetry 4: the chosen tile's source map (QuarterTurnPlan)
    int base_blocks = 0;
    double base_worst = 0.0, base_cost = 0.0;
    bool base_meets = false;
    for (size_t i = 0; i < plans.size(); ++i) {
      // Later plans of strong-edge exemplars, and the smooth-penalty retry, run only if needed.
      if (i >= retry_plan && base_meets) break;
      TileOptions plan_options = base_options;
      // Later attempts report the base share as done, and can still be cancelled.
      if (i > 0 && base_options.progress) plan_options.progress = [&](double) { return base_options.progress(1.0); };
      Plane canvas;
      int blocks = 0;
      double cost = 0.0;
      SessionRecord record;
      std::vector<int32_t> source;
      if (setup.symmetry == 4) {
        TAILOR_RETURN_IF_ERROR(
            quilt_pinwheel(setup, plan_options, plans[i], search, turns, turn_search, canvas, blocks, cost, source));
        // A planned tile is judged as it will be written, at full size (its wrap and worst seam
        // differ from the reduced tile's: water at 1024 px met its wrap on no reduced attempt).
        if (planned) {
          geometry.source.swap(source);
          canvas = tile_from_reduced_sources(full, geometry);
          geometry.source.swap(source);
        }
      } else
        TAILOR_RETURN_IF_ERROR(
            quilt_cross(setup, plan_options, plans[i], search, canvas, blocks, cost, tile_plan ? &record : nullptr));
      double worst = worst_seam_ratio(canvas, true);
      bool meets = worst <= target * kSeamHeadroom;
      if (setup.symmetry == 4) {
        // The wrap runs through a repaired line, which smooth blocks can leave too smooth (the
        // smooth-block penalty of the retry helps) or too sharp: its ratio is a target too, and
        // `worst` becomes how far both miss (the smaller, the better).
        double wrap = 1.0;
        quarter_turn_wrap(canvas, wrap);
        meets = meets && wrap >= kWrapLow && wrap <= kWrapHigh;
        worst = std::max(0.0, worst / (target * kSeamHeadroom) - 1.0) + std::max(0.0, kWrapLow / wrap - 1.0) +
                std::max(0.0, wrap / kWrapHigh - 1.0);
      }
      // Meeting the seam target first, then the lower cut cost (or, both missing, the lower worst seam).
      const bool better =
          i == 0 || (meets && !base_meets) || (meets == base_meets && (meets ? cost < base_cost : worst < base_worst));
      if (better) {
        if (!planned) base = std::move(canvas);  // a planned tile is read again from its sources below
        base_source = std::move(source);
        base_blocks = blocks;
        base_worst = worst;
        base_cost = cost;
        base_meets = meets;
        if (tile_plan) tile_plan->sessions[0] = std::move(record);
      }
    }
    rep.blocks += base_blocks;
    // One full-size tile alive at a time: the planned attempts' tiles were only judged.
    geometry.source = std::move(base_source);
    if (planned) base = tile_from_reduced_sources(full, geometry);
    if (setup.symmetry == 4) {
      // The wrap through one of the '+' lines (quarter_turn_wrap; an earlier N/4 shift ran it
      // through quadrant interiors but put the 4-fold centre off the lattice). rot90(tile) == tile.
      double wrap = 1.0;
      const int q = quarter_turn_wrap(base, wrap);
      // tile(x, y) = pinwheel((x + q) % N, (y + q) % N), in place: rows, then within each row.
      const int tw = base.width;
      const size_t row = static_cast<size_t>(tw) * base.channels;
      std::rotate(base.px.begin(), base.px.begin() + static_cast<std::ptrdiff_t>(q * row), base.px.end());
      for (int y = 0; y < tw; ++y) {
        const auto start = base.px.begin() + static_cast<std::ptrdiff_t>(y * row);
        std::rotate(start, start + static_cast<std::ptrdiff_t>(q) * base.channels,
                    start + static_cast<std::ptrdiff_t>(row));
      }
      rep.shift_x = rep.shift_y = q;
      if (quarter_plan) {
        geometry.roll = q;
        geometry.crop_x = crop_x;
        geometry.crop_y = crop_y;
        *quarter_plan = std::move(geometry);
      }
    }
    tiles.push_back(plane_to_image(base));
    if (setup.symmetry == 4) {
      rep.border = 0;
      rep.quarter_turn_difference = quarter_turn_difference(tiles[0]);
      return Status::ok();
    }

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
      if (tile_plan) {
        SessionRecord& record = tile_plan->sessions[static_cast<size_t>(k)];
        record.known = known;
        record.locked = locked;
        record.overlap = ov;
        quilter.set_record(&record.placements);
      }
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

}  // namespace internal

}  // namespace tailor
