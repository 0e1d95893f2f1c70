// Tiling at any size and of map sets (tiling.h): small single images are quilted directly
// (tiling.cpp); large ones, 16-bit ones and sets get a plan on a reduced 8-bit guide, replayed at
// full size (cut_refine.h) into one source map that every map is composed through.
#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "tailor/image_ops.h"
#include "tailor/tiling.h"
#include "texture/cut_refine.h"

namespace tailor {

using internal::BlendKind;
using internal::CutRefiner;
using internal::TilePlan;

namespace {

// The smallest side of a plan's reduced copy: the least a tile is made of (tiling.cpp).
constexpr int kPlanMinSide = 32;

//! Crops or extends (never resamples) to fw x fh: a pixel beyond the input is copied from a whole
//! number of periods (px, py) before it (tiling.cpp's fit_to_period at full size).
template <typename T>
std::vector<T> fit_samples(const T* in, int w, int h, int c, int fw, int fh, int px, int py) {
  std::vector<T> out(static_cast<size_t>(fw) * fh * c);
  for (int y = 0; y < fh; ++y) {
    int sy = y;
    while (sy >= h) sy -= std::max(1, py);
    for (int x = 0; x < fw; ++x) {
      int sx = x;
      while (sx >= w) sx -= std::max(1, px);
      const T* s = &in[(static_cast<size_t>(sy) * w + sx) * c];
      std::copy(s, s + c, &out[(static_cast<size_t>(y) * fw + x) * c]);
    }
  }
  return out;
}

//! Full-size plan replay: the source map of every session, the fitted size and period in px.
struct Replayed {
  std::vector<std::vector<int32_t>> sources;
  std::vector<uint8_t> ring;  // the variants' shared outer ring (full size)
  int width = 0, height = 0;  // output size (period-fitted or the input's)
  int period_x = 1, period_y = 1;
  double scale = 1.0;
  int feather = 1;         // px each side of a cut blended: scale / 2, at least 1
  int period_message = 0;  // auto_period: 0 none, 1 fitted, 2 kept
};

//! The reduction of a w x h map for its plan: the larger side to kPlanSide when above `above`,
//! unless that takes the smaller side below kPlanMinSide (a strip keeps its aspect: 1000 x 40 is
//! planned at 800 x 32, not squashed to 512 x 32, and 4000 x 16 at its own size, which the
//! quilting refuses naming that size). 1: planned at its own size.
double plan_scale(int w, int h, int above) {
  const int side = std::max(w, h);
  if (side <= above) return 1.0;
  const double scale = std::min(static_cast<double>(side) / kPlanSide, std::min(w, h) / double{kPlanMinSide});
  return std::max(1.0, scale);
}

//! `image` resized by 1 / scale (scale from plan_scale, > 1): its plan copy.
Status plan_copy(const Image& image, double scale, Image& copy) {
  const int w = std::max(kPlanMinSide, static_cast<int>(std::lround(image.width / scale)));
  const int h = std::max(kPlanMinSide, static_cast<int>(std::lround(image.height / scale)));
  return resize_image(image, w, h, copy);
}

//! auto_period: whether `image` has a strong period (kStrongPeriod) on an axis that changes its
//! fitted size; estimated on a copy of at most kPlanSide px (periods scaled back).
bool strong_period(const Image& image, PeriodEstimate& period) {
  Image small;
  const double scale = plan_scale(image.width, image.height, kPlanSide);
  if (scale > 1.0 && !plan_copy(image, scale, small).is_ok()) return false;
  period = estimate_period(scale > 1.0 ? small : image);
  period.found_x = period.found_x && period.confidence_x >= kStrongPeriod;
  period.found_y = period.found_y && period.confidence_y >= kStrongPeriod;
  if (!period.found_x && !period.found_y) return false;
  period.period_x *= static_cast<double>(image.width) / (scale > 1.0 ? small.width : image.width);
  period.period_y *= static_cast<double>(image.height) / (scale > 1.0 ? small.height : image.height);
  int w = image.width, h = image.height;
  period_fitted_size(period, image.width, image.height, w, h);
  return w != image.width || h != image.height;
}

//! How far `tile` misses the targets against `reference`: the sum of relative excesses of every
//! target of meets_tile_targets; patch coherence (about 0.1 s at 512 px, seconds at 4096) only up
//! to kPlanMaxSide, where it is the tightest target (coarse-to-fine tiles have it 10-30 x below
//! the exemplar's).
double target_misses(const Image& tile, const Image& reference) {
  double misses = internal::fast_target_misses(tile, reference);
  if (std::max(reference.width, reference.height) <= kPlanMaxSide) {
    TileMetrics m;
    if (!tile_metrics(tile, &reference, m).is_ok()) return 1e9;
    misses += std::max(0.0, m.patch_coherence / std::max(m.exemplar_patch_coherence, 1e-12) - 1.0);
  }
  return misses;
}

//! The two auto_period messages (the choice was made, or not).
std::string period_message(bool fitted, const TileReport& rep) {
  if (!fitted) return "strong period found, but the period-fitted tile missed more targets: size kept";
  return "strong period (" + std::to_string(std::lround(rep.period.period_x)) + " x " +
         std::to_string(std::lround(rep.period.period_y)) + " px): fitted to " + std::to_string(rep.width) + "x" +
         std::to_string(rep.height) + " (--no-auto-period keeps the size)";
}

//! Plans on `guide` reduced to kPlanSide (when larger than kPlanMaxSide) and replays at full size.
//! `guide` is replaced by its period-fitted copy when fit_period changed the size.
Status plan_and_replay(Image& guide, bool all_channels, const TileOptions& options, int count, TileReport& rep,
                       Replayed& out) {
  TAILOR_RETURN_IF_ERROR(check_image(guide));
  const int w = guide.width, h = guide.height;
  out.scale = plan_scale(w, h, kPlanMaxSide);
  Image reduced;
  if (out.scale > 1.0)
    TAILOR_RETURN_IF_ERROR(plan_copy(guide, out.scale, reduced));
  else
    reduced = guide;
  std::vector<Image> plan_tiles;
  TilePlan plan;
  TAILOR_RETURN_IF_ERROR(internal::plan_tile_variants(reduced, options, count, all_channels, plan_tiles, &rep, &plan));
  rep.period_fitted = options.fit_period;
  // auto_period, decided on the plans (the reduced tiles), so only one is replayed at full size.
  PeriodEstimate period;
  if (options.auto_period && !options.fit_period && options.symmetry == 1 && strong_period(reduced, period)) {
    TileOptions fit = options;
    fit.fit_period = true;
    std::vector<Image> fit_tiles;
    TilePlan fit_plan;
    TileReport fit_rep;
    TAILOR_RETURN_IF_ERROR(
        internal::plan_tile_variants(reduced, fit, count, all_channels, fit_tiles, &fit_rep, &fit_plan));
    const bool fitted = target_misses(fit_tiles[0], reduced) <= target_misses(plan_tiles[0], reduced);
    if (fitted) {
      plan = std::move(fit_plan);
      rep = std::move(fit_rep);
      rep.period_fitted = true;
    } else {
      rep.period = period;
    }
    out.period_message = fitted ? 1 : 2;
  }
  // The plan's exemplar may be period-fitted: the full-size guide is fitted the same way, with
  // the period scaled.
  const int rw = reduced.width, rh = reduced.height;
  auto up = [](int v, int full, int small) { return static_cast<int>((2 * int64_t{v} * full + small) / (2 * small)); };
  out.width = plan.width == rw ? w : up(plan.width, w, rw);
  out.height = plan.height == rh ? h : up(plan.height, h, rh);
  out.period_x = std::max(1, static_cast<int>(std::lround(rep.period.period_x * w / rw)));
  out.period_y = std::max(1, static_cast<int>(std::lround(rep.period.period_y * h / rh)));
  if (out.width != w || out.height != h) {
    if (out.width > kMaxImageSide || out.height > kMaxImageSide)
      return Status::error(ErrorCode::kInvalidImage, "", "period-fitted size above the image size limit");
    guide.pixels =
        fit_samples(guide.pixels.data(), w, h, guide.channels, out.width, out.height, out.period_x, out.period_y);
    guide.width = out.width;
    guide.height = out.height;
  }
  const internal::Guide view{guide.pixels.data(), guide.width, guide.height, guide.channels};
  CutRefiner refiner(view, plan.width, plan.height);
  const int radius = out.scale > 1.0 ? static_cast<int>(std::ceil(out.scale / 2.0)) + 1 : 0;
  // Upsampled-looking content is smooth at full size: a hard cut between two sources that agree
  // only to within a reduced pixel shows as a straight step (bark resampled to 4096 px: worst seam
  // 1.96 with 1 px, 1.65 with 2, 1.54 with 4 against the photo's 1.56; gradient ratio 1.007).
  // At full size the plan is the tile: its wrap and cuts are replayed as they are, unblended, so a
  // map set or a 16-bit map gets the cut make_tileable gives its 8-bit guide.
  out.feather = out.scale > 1.0 ? std::max(1, static_cast<int>(std::lround(out.scale / 2.0))) : 0;
  if (out.scale > 1.0) refiner.choose_wrap(plan.shift_x, plan.shift_y);
  out.sources.clear();
  for (size_t s = 0; s < plan.sessions.size(); ++s) {
    refiner.replay(plan, s, s == 0 ? nullptr : &out.sources[0], radius);
    out.sources.push_back(refiner.source());
  }
  out.ring.assign(static_cast<size_t>(guide.width) * guide.height, 0);
  const int bx = refiner.map_x(rep.border), by = refiner.map_y(rep.border);
  for (int y = 0; y < guide.height; ++y)
    for (int x = 0; x < guide.width; ++x)
      if (x < bx || y < by || x >= guide.width - bx || y >= guide.height - by)
        out.ring[static_cast<size_t>(y) * guide.width + x] = 1;
  rep.width = guide.width;
  rep.height = guide.height;
  rep.block = refiner.map_x(rep.block);
  rep.overlap = refiner.map_x(rep.overlap);
  rep.border = bx;
  rep.shift_x = refiner.shift_x();
  rep.shift_y = refiner.shift_y();
  if (out.period_message != 0) rep.warnings.push_back(period_message(out.period_message == 1, rep));
  if (out.scale > 1.0)
    rep.warnings.push_back("planned on a " + std::to_string(rw) + "x" + std::to_string(rh) +
                           " px copy and refined at full size (block " + std::to_string(rep.block) + " px)");
  return Status::ok();
}

//! Composes every session of one map; variants get the base tile's outer ring (the feather may
//! blend ring pixels with the interior, which differs between variants).
template <typename T>
void compose_sessions(const T* in, int channels, int max_value, BlendKind kind, const Replayed& r, int feather,
                      std::vector<std::vector<T>>& outs) {
  outs.resize(r.sources.size());
  for (size_t s = 0; s < r.sources.size(); ++s) {
    internal::compose(in, r.width, r.height, channels, max_value, kind, r.sources[s], feather, outs[s]);
    if (s == 0) continue;
    for (size_t i = 0; i < r.ring.size(); ++i)
      if (r.ring[i]) std::copy(&outs[0][i * channels], &outs[0][(i + 1) * channels], &outs[s][i * channels]);
  }
}

}  // namespace

Status make_tileable(const Image& exemplar, const TileOptions& options, Image& tile, TileReport* report) {
  std::vector<Image> tiles;
  TAILOR_RETURN_IF_ERROR(make_tile_variants(exemplar, options, 1, tiles, report));
  tile = std::move(tiles[0]);
  return Status::ok();
}

namespace {

//! make_tile_variants without auto_period.
Status tile_variants_once(const Image& exemplar, const TileOptions& options, int count, std::vector<Image>& tiles,
                          TileReport* report) {
  tiles.clear();
  if (options.symmetry == 4 || std::max(exemplar.width, exemplar.height) <= kPlanMaxSide ||
      !check_image(exemplar).is_ok())
    return internal::plan_tile_variants(exemplar, options, count, false, tiles, report, nullptr);
  TileReport local;
  TileReport& rep = report ? *report : local;
  try {
    Image guide = exemplar;  // the map itself (fitted in place when fit_period changes the size)
    Replayed r;
    TAILOR_RETURN_IF_ERROR(plan_and_replay(guide, false, options, count, rep, r));
    std::vector<std::vector<uint8_t>> outs;
    compose_sessions(guide.pixels.data(), guide.channels, 255, BlendKind::kScalar, r, r.feather, outs);
    for (std::vector<uint8_t>& o : outs) {
      Image t;
      t.width = r.width;
      t.height = r.height;
      t.channels = guide.channels;
      t.pixels = std::move(o);
      tiles.push_back(std::move(t));
    }
  } catch (const std::exception& e) {
    tiles.clear();
    return Status::error(ErrorCode::kInvalidImage, "", std::string("tiling failed: ") + e.what());
  }
  return Status::ok();
}

//! make_tileable_set without auto_period.
Status tile_set_once(const std::vector<TileMap>& maps, const TileOptions& options, int count,
                     std::vector<std::vector<Image16>>& tiles, TileReport* report) {
  tiles.clear();
  if (maps.empty()) return Status::error(ErrorCode::kInvalidArgument, "", "a map set needs at least one map");
  for (size_t m = 0; m < maps.size(); ++m) {
    const Image16& a = maps[m].image;
    if ((a.bits != 8 && a.bits != 16) || a.channels < 1 || a.channels > 4 || a.width < 1 || a.height < 1 ||
        a.width > kMaxImageSide || a.height > kMaxImageSide ||
        a.pixels.size() != static_cast<size_t>(a.width) * a.height * a.channels)
      return Status::error(ErrorCode::kInvalidImage, "", "map " + std::to_string(m + 1) + " is not a valid image");
    if (maps[m].normal && a.channels < 3)
      return Status::error(ErrorCode::kInvalidArgument, "",
                           "map " + std::to_string(m + 1) + " is marked as a normal map but has " +
                               std::to_string(a.channels) + " channel(s), not 3 or 4");
    if (a.width != maps[0].image.width || a.height != maps[0].image.height)
      return Status::error(ErrorCode::kInvalidImage, "", "every map of a set must have the same size",
                           "map " + std::to_string(m + 1) + " is " + std::to_string(a.width) + "x" +
                               std::to_string(a.height) + ", map 1 is " + std::to_string(maps[0].image.width) + "x" +
                               std::to_string(maps[0].image.height));
  }
  TileReport local;
  TileReport& rep = report ? *report : local;
  try {
    // The guide: one 8-bit channel per map (luminance of colour maps), maps k, k + 4... averaged
    // into channel k % 4; a single map is its own guide (searched like make_tileable's).
    const int w = maps[0].image.width, h = maps[0].image.height;
    Image guide;
    bool all_channels = true;
    if (maps.size() == 1) {
      guide = to_image8(maps[0].image);
      all_channels = false;
    } else {
      const int gc = static_cast<int>(std::min<size_t>(4, maps.size()));
      guide.width = w;
      guide.height = h;
      guide.channels = gc;
      guide.pixels.assign(static_cast<size_t>(w) * h * gc, 0);
      std::vector<double> sum(static_cast<size_t>(gc));
      std::vector<int> shares(static_cast<size_t>(gc), 0);
      for (size_t m = 0; m < maps.size(); ++m) ++shares[m % static_cast<size_t>(gc)];
      for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i) {
        std::fill(sum.begin(), sum.end(), 0.0);
        for (size_t m = 0; m < maps.size(); ++m) {
          const Image16& a = maps[m].image;
          const uint16_t* p = &a.pixels[i * a.channels];
          const double unit = a.bits == 16 ? 255.0 / 65535.0 : 1.0;
          const double v = a.channels >= 3 ? 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2] : p[0];
          sum[m % static_cast<size_t>(gc)] += v * unit;
        }
        for (int k = 0; k < gc; ++k)
          guide.pixels[i * gc + k] = static_cast<uint8_t>(
              std::lround(std::clamp(sum[static_cast<size_t>(k)] / shares[static_cast<size_t>(k)], 0.0, 255.0)));
      }
    }
    if (options.symmetry == 4) {
      // One quarter-turn tile quilted on the guide, every map read through it at full size (normal
      // maps turned with their content).
      std::vector<Image> guide_tiles;
      internal::QuarterTurnPlan plan;
      TAILOR_RETURN_IF_ERROR(
          internal::plan_tile_variants(guide, options, count, all_channels, guide_tiles, &rep, nullptr, &plan));
      tiles.assign(1, std::vector<Image16>(maps.size()));
      for (size_t m = 0; m < maps.size(); ++m) {
        const Image16& a = maps[m].image;
        Image16& t = tiles[0][m];
        t.width = t.height = plan.tile_side;
        t.channels = a.channels;
        t.bits = a.bits;
        internal::read_quarter_turn(a.pixels.data(), a.width, a.channels, a.bits == 16 ? 65535.0 : 255.0,
                                    maps[m].normal, maps[m].directx, plan, t.pixels);
      }
      return Status::ok();
    }
    Replayed r;
    TAILOR_RETURN_IF_ERROR(plan_and_replay(guide, all_channels, options, count, rep, r));
    tiles.assign(r.sources.size(), std::vector<Image16>(maps.size()));
    for (size_t m = 0; m < maps.size(); ++m) {
      const Image16& a = maps[m].image;
      const std::vector<uint16_t> fitted =
          r.width != w || r.height != h
              ? fit_samples(a.pixels.data(), w, h, a.channels, r.width, r.height, r.period_x, r.period_y)
              : std::vector<uint16_t>{};
      std::vector<std::vector<uint16_t>> outs;
      compose_sessions(fitted.empty() ? a.pixels.data() : fitted.data(), a.channels, a.bits == 16 ? 65535 : 255,
                       maps[m].normal ? BlendKind::kNormal : BlendKind::kScalar, r, r.feather, outs);
      for (size_t s = 0; s < outs.size(); ++s) {
        Image16& t = tiles[s][m];
        t.width = r.width;
        t.height = r.height;
        t.channels = a.channels;
        t.bits = a.bits;
        t.pixels = std::move(outs[s]);
      }
    }
  } catch (const std::exception& e) {
    tiles.clear();
    return Status::error(ErrorCode::kInvalidImage, "", std::string("tiling failed: ") + e.what());
  }
  return Status::ok();
}

//! Runs `once` plain and, for a strongly periodic exemplar, period-fitted; keeps the fitted result
//! unless it misses the targets by more than the plain one (target_misses of the first tile
//! against `reference`).
template <typename Result, typename Once, typename First>
Status with_auto_period(const Image& reference, const TileOptions& options, Result& result, TileReport* report,
                        Once once, First first) {
  TileReport local;
  TileReport& rep = report ? *report : local;
  PeriodEstimate period;
  if (options.fit_period || !options.auto_period || options.symmetry != 1 || !check_image(reference).is_ok() ||
      reference.width < 32 || reference.height < 32 || !strong_period(reference, period)) {
    TAILOR_RETURN_IF_ERROR(once(options, result, rep));
    rep.period_fitted = options.fit_period;
    return Status::ok();
  }
  TileOptions fit = options;
  fit.fit_period = true;
  Result fitted;
  TileReport fitted_report;
  TAILOR_RETURN_IF_ERROR(once(options, result, rep));
  TAILOR_RETURN_IF_ERROR(once(fit, fitted, fitted_report));
  const double plain_misses = target_misses(first(result), reference);
  const double fitted_misses = target_misses(first(fitted), reference);
  const bool keep_fitted = fitted_misses <= plain_misses;
  if (keep_fitted) {
    result = std::move(fitted);
    rep = std::move(fitted_report);
    rep.period_fitted = true;
  } else {
    rep.period = period;
  }
  rep.warnings.push_back(period_message(keep_fitted, rep));
  return Status::ok();
}

}  // namespace

Status make_tile_variants(const Image& exemplar, const TileOptions& options, int count, std::vector<Image>& tiles,
                          TileReport* report) {
  // Above kPlanMaxSide, auto_period is decided between the plans (plan_and_replay).
  if (std::max(exemplar.width, exemplar.height) > kPlanMaxSide && options.symmetry == 1)
    return tile_variants_once(exemplar, options, count, tiles, report);
  return with_auto_period(
      exemplar, options, tiles, report,
      [&](const TileOptions& o, std::vector<Image>& out, TileReport& rep) {
        return tile_variants_once(exemplar, o, count, out, &rep);
      },
      [](const std::vector<Image>& out) -> const Image& { return out[0]; });
}

std::string tile_set_file_name(const std::string& input_path) {
  const size_t slash = input_path.find_last_of('/');
  std::string name = slash == std::string::npos ? input_path : input_path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  if (dot != std::string::npos && dot > 0) name = name.substr(0, dot);
  return name + ".png";
}

Status make_tileable_set(const std::vector<TileMap>& maps, const TileOptions& options, int count,
                         std::vector<std::vector<Image16>>& tiles, TileReport* report) {
  // auto_period is decided between the plans on the guide (plan_and_replay).
  return tile_set_once(maps, options, count, tiles, report);
}

}  // namespace tailor
