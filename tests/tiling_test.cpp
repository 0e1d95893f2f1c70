// Self-tileable textures (thesis chapter 3): quality targets on real exemplars, bit-exact borders,
// determinism, variants, period detection, and the `tailor tile` / `tailor eval-tile` commands.
#include "tailor/tiling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/fixtures.h"
#include "tailor/image.h"
#include "tailor/image_ops.h"

namespace tailor {
namespace {

const std::string kData = std::string(TAILOR_TEST_DATA) + "/textures/";

using test::temp_dir;

Image load(const std::string& name) {
  Image im;
  const Status s = load_image(kData + name, im);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return im;
}

const uint8_t* px(const Image& im, int x, int y) {
  return &im.pixels[(static_cast<size_t>(y) * im.width + x) * im.channels];
}

bool same_pixel(const Image& a, int ax, int ay, const Image& b, int bx, int by) {
  return std::equal(px(a, ax, ay), px(a, ax, ay) + a.channels, px(b, bx, by));
}

// Vertical stripes: `period` px, half black half white, starting black at x = 0.
Image stripes(int width, int height, int period) {
  Image im;
  im.width = width;
  im.height = height;
  im.channels = 1;
  im.pixels.resize(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) im.pixels[static_cast<size_t>(y) * width + x] = (x % period) < period / 2 ? 0 : 255;
  return im;
}

// Checkerboard of `cell` px squares (period 2 * cell in both directions), RGB.
Image checkers(int width, int height, int cell) {
  Image im;
  im.width = width;
  im.height = height;
  im.channels = 3;
  im.pixels.resize(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const bool on = ((x / cell) + (y / cell)) % 2 == 0;
      uint8_t* p = &im.pixels[(static_cast<size_t>(y) * width + x) * 3];
      p[0] = on ? 200 : 30;
      p[1] = on ? 60 : 180;
      p[2] = on ? 90 : 20;
    }
  return im;
}

// ------------------------------------------------------------------------------------------------
// Quality targets (issue 4) on each exemplar copied into tests/data/textures.

// Every issue 4 target, no allowance: wrap ratios in [0.8, 1.2], worst straight seam <= max(the
// exemplar's own interior worst, 1.5), histogram L1 <= 0.1, gradient ratio >= 0.95, patch
// coherence <= the exemplar's own read toroidally.
// The wrap, seam, histogram and gradient targets; patch coherence at most coherence_allowance
// times the exemplar's.
void expect_target_figures(const TileMetrics& m, double coherence_allowance) {
  EXPECT_GE(m.wrap_ratio_x, 0.8);
  EXPECT_LE(m.wrap_ratio_x, 1.2);
  EXPECT_GE(m.wrap_ratio_y, 0.8);
  EXPECT_LE(m.wrap_ratio_y, 1.2);
  EXPECT_LE(m.worst_seam_ratio, std::max(m.exemplar_worst_seam_ratio, 1.5));
  EXPECT_LE(m.histogram_l1, 0.1);
  EXPECT_GE(m.gradient_ratio, 0.95);
  EXPECT_LE(m.patch_coherence, coherence_allowance * m.exemplar_patch_coherence);
}

void expect_targets(const Image& ex, const Image& tile, const std::string& what, const TileReport& report) {
  SCOPED_TRACE(what);
  // The exemplar's size, or (auto_period on a strongly periodic exemplar) its period-fitted size.
  if (report.period_fitted) {
    int w = 0, h = 0;
    period_fitted_size(report.period, ex.width, ex.height, w, h);
    EXPECT_EQ(tile.width, w);
    EXPECT_EQ(tile.height, h);
  } else {
    EXPECT_EQ(tile.width, ex.width);
    EXPECT_EQ(tile.height, ex.height);
  }
  EXPECT_EQ(tile.channels, ex.channels);
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(tile, &ex, m).is_ok());
  // The exemplar itself is not tileable (MANIFEST.md: wrap ratios 1.5 to 10.8).
  EXPECT_GT(std::max(m.exemplar_wrap_ratio_x, m.exemplar_wrap_ratio_y), 1.4);
  expect_target_figures(m, 1.0);
  std::string failed;
  EXPECT_TRUE(meets_tile_targets(m, &failed)) << failed;
}

class TileTargets : public ::testing::TestWithParam<const char*> {};

TEST_P(TileTargets, MeetsQualityTargets) {
  const Image ex = load(GetParam());
  Image tile;
  TileReport report;
  ASSERT_TRUE(make_tileable(ex, TileOptions{}, tile, &report).is_ok());
  expect_targets(ex, tile, GetParam(), report);
}

// The hardest exemplars: water and the ornamental tiles, whose own strongest edge decides the
// worst seam (the tile must not lift its ratio at all), and bark, with the thinnest margins
// against the 1.5 floor and the coherence target. Seed 1 is the default, checked above.
TEST(TileTargets, MeetsQualityTargetsForOtherSeedsOnTheHardestExemplars) {
  for (const char* file : {"water-caustics-300.jpg", "vistex-tile04-128.png", "vistex-bark11-128.png"}) {
    const Image ex = load(file);
    for (uint64_t seed = 2; seed <= 5; ++seed) {
      TileOptions o;
      o.seed = seed;
      Image tile;
      TileReport report;
      ASSERT_TRUE(make_tileable(ex, o, tile, &report).is_ok());
      expect_targets(ex, tile, std::string(file) + " seed " + std::to_string(seed), report);
    }
  }
}

const char* const kExemplars[] = {
    "brick-gray-512.png",    "grass-gray-512.png",    "gravel-gray-512.png",   "vistex-fabric02-128.png",
    "vistex-tile04-128.png", "vistex-sand05-128.png", "vistex-bark11-128.png", "water-caustics-300.jpg",
};

INSTANTIATE_TEST_SUITE_P(Exemplars, TileTargets, ::testing::ValuesIn(kExemplars),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                           std::string name = param.param;
                           name = name.substr(0, name.find('.'));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

// ------------------------------------------------------------------------------------------------

TEST(Tiling, PixelsOutsideTheRepairedStripsAreBitExactShiftedCopies) {
  const Image ex = load("brick-gray-512.png");
  Image tile;
  TileReport r;
  ASSERT_TRUE(make_tileable(ex, TileOptions{}, tile, &r).is_ok());
  EXPECT_EQ(r.block, 32);
  EXPECT_EQ(r.overlap, 8);
  EXPECT_NEAR(r.shift_x, 256, 64);
  EXPECT_NEAR(r.shift_y, 256, 64);
  const int w = ex.width, h = ex.height;
  const int cx = w - r.shift_x, cy = h - r.shift_y;
  // The strips span block / 2 px around the old seams (the '+' is repaired with half-size blocks:
  // a zone of block / 2 - overlap plus the cut bands); block / 2 on each side is a safe bound.
  auto in_strip = [&](int v, int centre, int size) {
    const int d = std::abs(((v - centre) % size + size + size / 2) % size - size / 2);
    return d <= r.block / 2;
  };
  size_t outside_changed = 0, inside_changed = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool same = same_pixel(tile, x, y, ex, (x + r.shift_x) % w, (y + r.shift_y) % h);
      if (in_strip(x, cx, w) || in_strip(y, cy, h)) {
        inside_changed += same ? 0 : 1;
      } else {
        outside_changed += same ? 0 : 1;
      }
    }
  EXPECT_EQ(outside_changed, 0u);
  EXPECT_GT(inside_changed, 5000u);  // the '+' was really repaired
}

TEST(Tiling, SameSeedGivesBitIdenticalOutputOtherSeedsDiffer) {
  const Image ex = load("vistex-sand05-128.png");
  TileOptions o;
  o.seed = 42;
  Image a, b, c;
  ASSERT_TRUE(make_tileable(ex, o, a).is_ok());
  ASSERT_TRUE(make_tileable(ex, o, b).is_ok());
  EXPECT_EQ(a.pixels, b.pixels);
  o.seed = 43;
  ASSERT_TRUE(make_tileable(ex, o, c).is_ok());
  EXPECT_NE(a.pixels, c.pixels);
}

TEST(Tiling, VariantsShareTheirBorderBitExactlyAndDifferInside) {
  const Image ex = load("vistex-bark11-128.png");
  std::vector<Image> tiles;
  TileReport r;
  ASSERT_TRUE(make_tile_variants(ex, TileOptions{}, 4, tiles, &r).is_ok());
  ASSERT_EQ(tiles.size(), 4u);
  ASSERT_GE(r.border, 1);
  Image base;
  ASSERT_TRUE(make_tileable(ex, TileOptions{}, base).is_ok());
  EXPECT_EQ(tiles[0].pixels, base.pixels);  // variant 0 is the plain tile
  const int w = ex.width, h = ex.height;
  for (size_t k = 1; k < tiles.size(); ++k) {
    size_t border_diff = 0, interior_diff = 0, interior = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool on_border = x < r.border || y < r.border || x >= w - r.border || y >= h - r.border;
        const bool same = same_pixel(tiles[k], x, y, tiles[0], x, y);
        if (on_border) {
          border_diff += same ? 0 : 1;
        } else {
          ++interior;
          interior_diff += same ? 0 : 1;
        }
      }
    EXPECT_EQ(border_diff, 0u) << "variant " << k;
    EXPECT_GT(interior_diff, interior / 2) << "variant " << k;
    // Each variant is tileable with itself and, sharing the border, with the others.
    TileMetrics m;
    ASSERT_TRUE(tile_metrics(tiles[k], &ex, m).is_ok());
    EXPECT_GE(m.wrap_ratio_x, 0.8);
    EXPECT_LE(m.wrap_ratio_x, 1.2);
    EXPECT_GE(m.wrap_ratio_y, 0.8);
    EXPECT_LE(m.wrap_ratio_y, 1.2);
    // Re-quilting almost the whole 128 px interior drifts the histogram more than the plain tile
    // (measured 0.10 to 0.21 on bark): the 0.1 target is for the plain tile.
    EXPECT_LE(m.histogram_l1, 0.25);
    EXPECT_GE(m.gradient_ratio, 0.9);
  }
  EXPECT_NE(tiles[1].pixels, tiles[2].pixels);
}

TEST(Tiling, SmallAndNonSquareImagesWork) {
  const Image ex = load("vistex-tile04-128.png");
  Image small;
  ASSERT_TRUE(resize_image(ex, 64, 64, small).is_ok());
  Image tile;
  TileReport r;
  TileOptions keep_size;  // the ornamental tiles are strongly periodic: without this, fitted to their period
  keep_size.auto_period = false;
  ASSERT_TRUE(make_tileable(small, keep_size, tile, &r).is_ok());
  EXPECT_EQ(r.block, 16);  // adapted to a quarter of the side, with a warning
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("block shrunk"), std::string::npos);
  EXPECT_EQ(tile.width, 64);

  // Non-square crop, grey.
  const Image brick = load("brick-gray-512.png");
  Image crop;
  crop.width = 200;
  crop.height = 96;
  crop.channels = 1;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 200; ++x) crop.pixels.push_back(*px(brick, x + 40, y + 300));
  ASSERT_TRUE(make_tileable(crop, keep_size, tile, &r).is_ok());
  EXPECT_EQ(tile.width, 200);
  EXPECT_EQ(tile.height, 96);
  EXPECT_EQ(r.block, 24);
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(tile, &crop, m).is_ok());
  EXPECT_LT(m.wrap_ratio_x, 1.5);
  EXPECT_LT(m.wrap_ratio_y, 1.5);
}

// Regression: above ~900 px the coherence grid's stride exceeds 6, and its last patch used to stop
// short of the wrap, so an image's own toroidal coherence read 0 whatever its wrap seam.
TEST(Tiling, ToroidalCoherenceSeesTheWrapSeamOfLargeImages) {
  Image ramp;
  ramp.width = 1000;
  ramp.height = 1000;
  ramp.channels = 1;
  ramp.pixels.resize(static_cast<size_t>(ramp.width) * ramp.height);
  for (int y = 0; y < ramp.height; ++y)
    for (int x = 0; x < ramp.width; ++x)
      ramp.pixels[static_cast<size_t>(y) * ramp.width + x] = static_cast<uint8_t>((x * 255) / (ramp.width - 1));
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(ramp, &ramp, m).is_ok());
  EXPECT_GT(m.exemplar_wrap_ratio_x, 10.0);     // a hard seam: 255 -> 0
  EXPECT_GT(m.exemplar_patch_coherence, 1e-3);  // was exactly 0
  EXPECT_DOUBLE_EQ(m.patch_coherence, m.exemplar_patch_coherence);
}

// A flat map (a constant roughness or metallic value in a material set): every patch is a copy of
// every other and has one hash, which the exact search for copied patches must not walk again at
// every position. The tile is the image itself, every patch found exactly.
TEST(Tiling, FlatImagesTileAsThemselves) {
  Image flat;
  flat.width = 300;
  flat.height = 200;
  flat.channels = 3;
  flat.pixels.assign(static_cast<size_t>(flat.width) * flat.height * flat.channels, 128);
  Image tile;
  TileReport r;
  ASSERT_TRUE(make_tileable(flat, TileOptions{}, tile, &r).is_ok());
  EXPECT_EQ(tile.pixels, flat.pixels);
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(tile, &flat, m).is_ok());
  EXPECT_EQ(m.patch_coherence, 0.0);
  EXPECT_EQ(m.histogram_l1, 0.0);
}

TEST(Tiling, BadInputsAndOptionsAreErrors) {
  Image tiny = stripes(20, 20, 4);
  Image out;
  EXPECT_EQ(make_tileable(tiny, TileOptions{}, out).code(), ErrorCode::kInvalidImage);
  Image broken = stripes(64, 64, 8);
  broken.pixels.resize(100);
  EXPECT_EQ(make_tileable(broken, TileOptions{}, out).code(), ErrorCode::kInvalidImage);
  const Image ok = stripes(64, 64, 8);
  TileOptions o;
  o.block = 300;
  EXPECT_EQ(make_tileable(ok, o, out).code(), ErrorCode::kInvalidArgument);
  o.block = 32;
  o.overlap = 16;
  EXPECT_EQ(make_tileable(ok, o, out).code(), ErrorCode::kInvalidArgument);
  std::vector<Image> tiles;
  EXPECT_EQ(make_tile_variants(ok, TileOptions{}, 0, tiles).code(), ErrorCode::kInvalidArgument);
  o = TileOptions{};
  o.progress = [](double f) { return f < 0.5; };
  EXPECT_EQ(make_tileable(load("vistex-sand05-128.png"), o, out).code(), ErrorCode::kCancelled);
}

// ------------------------------------------------------------------------------------------------
// Period detection (thesis 3.1).

TEST(Period, StripesOfTenPixelsInFiftyFiveGiveSixtyPixels) {
  const Image im = stripes(55, 55, 10);
  const PeriodEstimate p = estimate_period(im);
  ASSERT_TRUE(p.found_x);
  EXPECT_NEAR(p.period_x, 10.0, 0.1);
  EXPECT_GT(p.confidence_x, 0.5);
  EXPECT_FALSE(p.found_y);  // constant along y: nothing repeats
  int w = 0, h = 0;
  period_fitted_size(p, 55, 55, w, h);
  EXPECT_EQ(w, 60);
  EXPECT_EQ(h, 55);

  // End to end: the tile is 60 px wide and the stripes run in phase across the wrap.
  TileOptions o;
  o.fit_period = true;
  Image tile;
  TileReport r;
  ASSERT_TRUE(make_tileable(im, o, tile, &r).is_ok());
  EXPECT_EQ(tile.width, 60);
  EXPECT_EQ(tile.height, 55);
  EXPECT_NEAR(r.period.period_x, 10.0, 0.1);
  size_t off_phase = 0;
  for (int y = 0; y < tile.height; ++y)
    for (int x = 0; x < tile.width; ++x) off_phase += *px(tile, x, y) != *px(tile, (x + 10) % 60, y) ? 1 : 0;
  EXPECT_EQ(off_phase, 0u);
}

TEST(Period, CheckersOfKnownPeriod) {
  const Image im = checkers(100, 90, 8);  // period 16 both ways
  const PeriodEstimate p = estimate_period(im);
  ASSERT_TRUE(p.found_x);
  ASSERT_TRUE(p.found_y);
  EXPECT_NEAR(p.period_x, 16.0, 0.2);
  EXPECT_NEAR(p.period_y, 16.0, 0.2);
  int w = 0, h = 0;
  period_fitted_size(p, 100, 90, w, h);
  EXPECT_EQ(w, 96);  // 6.25 periods -> 6
  EXPECT_EQ(h, 96);  // 5.625 periods -> 6
}

TEST(Period, PhotosOfRegularPatternsAndNoise) {
  // Brick: vertical stretcher courses ~37.5 px apart along x; no clean period along y.
  const PeriodEstimate brick = estimate_period(load("brick-gray-512.png"));
  EXPECT_TRUE(brick.found_x);
  EXPECT_NEAR(brick.period_x, 37.5, 2.0);
  EXPECT_FALSE(brick.found_y);
  // Ornamental tiles: the motif repeats every ~66 px both ways.
  const PeriodEstimate tiles = estimate_period(load("vistex-tile04-128.png"));
  EXPECT_TRUE(tiles.found_x);
  EXPECT_TRUE(tiles.found_y);
  EXPECT_NEAR(tiles.period_x, 67.0, 2.0);
  EXPECT_NEAR(tiles.period_y, 66.0, 2.0);
  // Stochastic textures: no period, the size is kept.
  for (const char* name : {"water-caustics-300.jpg", "vistex-bark11-128.png"}) {
    const PeriodEstimate p = estimate_period(load(name));
    EXPECT_FALSE(p.found_x) << name;
    EXPECT_FALSE(p.found_y) << name;
  }
}

// ------------------------------------------------------------------------------------------------
// The command line, as a user runs it.

// ------------------------------------------------------------------------------------------------
// --symmetry 4 (issue 14): a tile also unchanged by a quarter turn.

TileOptions quarter_turn_options() {
  TileOptions o;
  o.symmetry = 4;
  return o;
}

// rot90(tile)(x, y) = tile(y, N - 1 - x) equals tile(x, y), sample for sample: the 4-fold centre is
// on the tile's centre (or corner), a lattice point of the map (docs/mapping.md, "Symmetry 4").
// The tile is twice the exemplar's (square) side, or its side with same_size.
TEST(QuarterTurn, InvarianceIsExactOnEveryExemplar) {
  for (const char* file : kExemplars)
    for (const bool same_size : {false, true}) {
      SCOPED_TRACE(std::string(file) + (same_size ? " same_size" : ""));
      const Image ex = load(file);
      Image tile;
      TileReport report;
      TileOptions options = quarter_turn_options();
      options.same_size = same_size;
      ASSERT_TRUE(make_tileable(ex, options, tile, &report).is_ok());
      const int n = tile.width;
      ASSERT_EQ(tile.height, n);
      EXPECT_EQ(n, std::min(ex.width, ex.height) / 4 * 4 * (same_size ? 1 : 2));
      EXPECT_EQ(report.width, n);
      EXPECT_EQ(tile.channels, ex.channels);
      size_t differing = 0;
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          if (!same_pixel(tile, y, n - 1 - x, tile, x, y)) ++differing;
      EXPECT_EQ(differing, 0u);
      int sx = -1, sy = -1;
      EXPECT_EQ(quarter_turn_difference(tile, &sx, &sy), 0);
      EXPECT_EQ(sx, 0);
      EXPECT_EQ(sy, 0);
      EXPECT_EQ(report.quarter_turn_difference, 0);
      EXPECT_EQ(report.symmetry, 4);
    }
  // A plain tile is not quarter-turn symmetric, and a non-square image has no figure.
  const Image sand = load("vistex-sand05-128.png");
  Image plain;
  ASSERT_TRUE(make_tileable(sand, TileOptions{}, plain).is_ok());
  EXPECT_GT(quarter_turn_difference(plain), 50);
  EXPECT_EQ(quarter_turn_difference(stripes(64, 40, 8)), -1);
}

// Four of the five targets hold on the stochastic shared photos, all five on fabric and water;
// patch coherence (measured, like the exemplar's baseline, against the exemplar's four quarter
// turns) is 1.1-1.4 x the exemplar's on the others: the known shortfall (docs/tiling.md), bounded
// here so that it cannot get worse unnoticed. With same_size (quadrants of a quarter of the photo,
// twice the seam length per pixel) it is 2.2-2.5 x.
TEST(QuarterTurn, TargetsOnStochasticPhotos) {
  for (const char* file :
       {"gravel-gray-512.png", "vistex-sand05-128.png", "vistex-fabric02-128.png", "water-caustics-300.jpg"}) {
    SCOPED_TRACE(file);
    const Image ex = load(file);
    Image tile;
    ASSERT_TRUE(make_tileable(ex, quarter_turn_options(), tile).is_ok());
    TileMetrics m;
    ASSERT_TRUE(tile_metrics(tile, &ex, m).is_ok());
    EXPECT_EQ(m.quarter_turn_difference, 0);
    EXPECT_TRUE(m.coherence_with_turns);
    const bool all_met =
        std::string(file) == "vistex-fabric02-128.png" || std::string(file) == "water-caustics-300.jpg";
    expect_target_figures(m, all_met ? 1.0 : 1.3);
    EXPECT_EQ(meets_tile_targets(m), all_met);
  }
  const Image sand = load("vistex-sand05-128.png");
  TileOptions same = quarter_turn_options();
  same.same_size = true;
  Image tile;
  ASSERT_TRUE(make_tileable(sand, same, tile).is_ok());
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(tile, &sand, m).is_ok());
  EXPECT_GT(m.patch_coherence, 1.5 * m.exemplar_patch_coherence);  // why it is not the default
  EXPECT_LE(m.patch_coherence, 2.6 * m.exemplar_patch_coherence);
}

// A tile twice the exemplar's size is sampled at the exemplar's patch stride (at a stride above
// 1 PatchMatch finds the cut patches' matches less well): a 2 x 2 repeat of a tile reads the tile's
// own coherence, where it read about twice it when the stride followed the tile's size.
TEST(TileMetricsTest, CoherenceDoesNotDependOnTheTilesSize) {
  const Image ex = load("gravel-gray-512.png");
  Image tile;
  ASSERT_TRUE(make_tileable(ex, TileOptions{}, tile).is_ok());
  Image twice;
  twice.width = 2 * tile.width;
  twice.height = 2 * tile.height;
  twice.channels = tile.channels;
  twice.pixels.resize(static_cast<size_t>(twice.width) * twice.height * twice.channels);
  for (int y = 0; y < twice.height; ++y)
    for (int x = 0; x < twice.width; ++x)
      for (int c = 0; c < tile.channels; ++c)
        twice.pixels[(static_cast<size_t>(y) * twice.width + x) * tile.channels + c] =
            tile.pixels[(static_cast<size_t>(y % tile.height) * tile.width + x % tile.width) * tile.channels + c];
  TileMetrics one, two;
  ASSERT_TRUE(tile_metrics(tile, &ex, one).is_ok());
  ASSERT_TRUE(tile_metrics(twice, &ex, two).is_ok());
  EXPECT_NEAR(two.patch_coherence, one.patch_coherence, 0.1 * one.patch_coherence);
  EXPECT_DOUBLE_EQ(two.exemplar_patch_coherence, one.exemplar_patch_coherence);
}

TEST(QuarterTurn, DeterministicAndDirectionalTexturesWarn) {
  const Image gravel = load("gravel-gray-512.png");
  Image a, b;
  TileReport report;
  ASSERT_TRUE(make_tileable(gravel, quarter_turn_options(), a, &report).is_ok());
  ASSERT_TRUE(make_tileable(gravel, quarter_turn_options(), b).is_ok());
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_TRUE(report.warnings.empty());
  EXPECT_LT(report.anisotropy, 0.1);
  TileOptions other = quarter_turn_options();
  other.seed = 2;
  ASSERT_TRUE(make_tileable(gravel, other, b).is_ok());
  EXPECT_NE(a.pixels, b.pixels);

  ASSERT_TRUE(make_tileable(load("brick-gray-512.png"), quarter_turn_options(), a, &report).is_ok());
  EXPECT_GT(report.anisotropy, 0.5);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings[0].find("directional"), std::string::npos) << report.warnings[0];
  EXPECT_GT(orientation_anisotropy(stripes(64, 64, 8)), 0.99);
  EXPECT_LT(orientation_anisotropy(checkers(64, 64, 8)), 0.01);

  // Non-square exemplar: cropped (with a warning) to its centred square, side a multiple of 4.
  ASSERT_TRUE(make_tileable(stripes(150, 90, 10), quarter_turn_options(), a, &report).is_ok());
  EXPECT_EQ(a.width, 176);
  EXPECT_EQ(a.height, 176);
  EXPECT_EQ(quarter_turn_difference(a), 0);
}

// Photos over 1024 px keep their side (a tile twice as wide would be over 2048 px: its quilting
// runs at full size), with a warning that says so.
TEST(QuarterTurn, LargePhotosKeepTheirSide) {
  Image large;
  ASSERT_TRUE(resize_image(load("vistex-sand05-128.png"), 1032, 1032, large).is_ok());
  Image tile;
  TileReport report;
  TileOptions options = quarter_turn_options();
  options.block = 128;  // fewer full-size FFT searches: a short test
  ASSERT_TRUE(make_tileable(large, options, tile, &report).is_ok());
  EXPECT_EQ(tile.width, 1032);
  EXPECT_EQ(report.width, 1032);
  EXPECT_EQ(quarter_turn_difference(tile), 0);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings.back().find("tile kept at 1032 px"), std::string::npos) << report.warnings.back();
}

// Photos above kPlanMaxSide are quilted on a kPlanSide px copy and read at full size from its
// source map: the tile keeps the photo's own pixel-level detail (here gravel upsampled to 1024 px
// with per-pixel noise on top, which the reduced tile scaled up would lose: gradient ratio 0.55,
// worst seam 1.90, coherence 11x the exemplar's), is exactly unchanged by a quarter turn, and
// meets the tiling targets.
TEST(QuarterTurn, LargePhotosArePlannedOnAReducedCopyAtFullDetail) {
  Image large;
  ASSERT_TRUE(resize_image(load("gravel-gray-512.png"), 1024, 1024, large).is_ok());
  uint32_t state = 12345u;
  for (uint8_t& v : large.pixels) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<uint8_t>(std::clamp(static_cast<int>(v) + static_cast<int>(state >> 27) - 16, 0, 255));
  }
  Image tile;
  TileReport report;
  ASSERT_TRUE(make_tileable(large, quarter_turn_options(), tile, &report).is_ok());
  EXPECT_EQ(tile.width, 2048);
  EXPECT_EQ(quarter_turn_difference(tile), 0);
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(tile, &large, m).is_ok());
  std::string failed;
  EXPECT_TRUE(meets_tile_targets(m, &failed)) << failed;
  EXPECT_GT(m.gradient_ratio, 0.95);
  std::printf(
      "1024 px noisy gravel, 4-fold: wrap %.2f, worst seam %.2f, hist %.3f, gradient %.3f, coherence %.4f "
      "(exemplar %.4f)\n",
      m.wrap_ratio_x, m.worst_seam_ratio, m.histogram_l1, m.gradient_ratio, m.patch_coherence,
      m.exemplar_patch_coherence);
}

TEST(QuarterTurn, VariantsFitPeriodAndOtherOrdersAreErrors) {
  const Image sand = load("vistex-sand05-128.png");
  std::vector<Image> tiles;
  EXPECT_EQ(make_tile_variants(sand, quarter_turn_options(), 2, tiles).code(), ErrorCode::kInvalidArgument);
  TileOptions o = quarter_turn_options();
  o.fit_period = true;
  Image tile;
  EXPECT_EQ(make_tileable(sand, o, tile).code(), ErrorCode::kInvalidArgument);
  o = TileOptions{};
  o.symmetry = 3;
  EXPECT_EQ(make_tileable(sand, o, tile).code(), ErrorCode::kInvalidArgument);
  o = TileOptions{};
  o.same_size = true;  // only with symmetry 4
  EXPECT_EQ(make_tileable(sand, o, tile).code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(make_tile_variants(sand, quarter_turn_options(), 1, tiles).is_ok());
}

struct CliRun {
  int code = 0;
  std::string out;
  std::string err;
};

CliRun run_cli(const std::string& args) {
  CliRun r;
  r.code = test::run_command(std::string(TAILOR_BINARY) + " " + args, r.out, &r.err);
  return r;
}

int j_width(const std::string& json) {
  std::ifstream jf(json);
  const nlohmann::json j = nlohmann::json::parse(jf, nullptr, false);
  return j.is_discarded() ? -1 : j["width"].get<int>();
}

TEST(TileCli, TilesPrintsOneSummaryLineAndEvalTileAgrees) {
  const std::string dir = temp_dir();
  const std::string out = dir + "/fabric_tile.png", json = dir + "/fabric.json";
  const CliRun r = run_cli("tile " + kData + "vistex-fabric02-128.png -o " + out + " --seed 7 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find("wrap"), std::string::npos);
  EXPECT_NE(r.out.find("coherence"), std::string::npos);
  EXPECT_NE(r.out.find(" s\n"), std::string::npos);
  Image tile;
  ASSERT_TRUE(load_image(out, tile).is_ok());
  EXPECT_EQ(tile.width, j_width(json));  // 125: the weave's period (auto_period)
  std::ifstream jf(json);
  const nlohmann::json j = nlohmann::json::parse(jf, nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  EXPECT_EQ(j["seed"], 7);
  EXPECT_TRUE(j["tiles"][0]["wrap_ratio_x"].is_number());

  const CliRun e = run_cli("eval-tile " + out + " " + kData + "vistex-fabric02-128.png --json");
  ASSERT_EQ(e.code, 0) << e.err;
  const nlohmann::json m = nlohmann::json::parse(e.out, nullptr, false);
  ASSERT_FALSE(m.is_discarded()) << e.out;
  EXPECT_DOUBLE_EQ(m["wrap_ratio_x"].get<double>(), j["tiles"][0]["wrap_ratio_x"].get<double>());
  EXPECT_DOUBLE_EQ(m["patch_coherence"].get<double>(), j["tiles"][0]["patch_coherence"].get<double>());

  // Same seed twice: bit-identical files.
  const std::string again = dir + "/fabric_again.png";
  ASSERT_EQ(run_cli("tile " + kData + "vistex-fabric02-128.png -o " + again + " --seed 7 --quiet").code, 0);
  Image tile2;
  ASSERT_TRUE(load_image(again, tile2).is_ok());
  EXPECT_EQ(tile.pixels, tile2.pixels);
}

TEST(TileCli, VariantsWriteNumberedFilesAndAJson) {
  const std::string dir = temp_dir();
  // Variants re-quilt the interior with large blocks: their coherence may miss (accepted here).
  const CliRun r =
      run_cli("tile " + kData + "vistex-sand05-128.png -o " + dir + "/sand.png --variants 3 --quiet --allow-misses");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::filesystem::exists(dir + "/sand_" + std::to_string(k) + ".png"));
  std::ifstream jf(dir + "/sand.json");
  const nlohmann::json j = nlohmann::json::parse(jf, nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  EXPECT_EQ(j["count"], 3);
  EXPECT_EQ(j["width"], 128);
  ASSERT_EQ(j["files"].size(), 3u);
  EXPECT_EQ(j["files"][2], "sand_2.png");
  EXPECT_GE(j["border_px"].get<int>(), 1);
}

TEST(TileCli, SymmetryFourReportsTheQuarterTurnAndRefusesVariants) {
  const std::string dir = temp_dir();
  const std::string out = dir + "/sand_q.png", json = dir + "/sand_q.json";
  const CliRun r =
      run_cli("tile " + kData + "vistex-sand05-128.png -o " + out + " --symmetry 4 --allow-misses --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("quarter-turn symmetric (exact)"), std::string::npos) << r.out;
  std::ifstream jf(json);
  const nlohmann::json j = nlohmann::json::parse(jf, nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  EXPECT_EQ(j["symmetry"], 4);
  EXPECT_EQ(j["width"], 256);  // twice the input's side
  Image written;
  ASSERT_TRUE(load_image(out, written).is_ok());
  EXPECT_EQ(written.width, 256);
  EXPECT_EQ(j["quarter_turn_difference"], 0);
  EXPECT_EQ(j["quarter_turn_exact"], true);
  EXPECT_EQ(j["tiles"][0]["quarter_turn_symmetric"], true);
  const CliRun e = run_cli("eval-tile " + out + " " + kData + "vistex-sand05-128.png");
  ASSERT_EQ(e.code, 0) << e.err;
  EXPECT_NE(e.out.find("quarter turn            max difference 0 after the best shift (0, 0)"), std::string::npos)
      << e.out;
  const CliRun plain = run_cli("eval-tile " + kData + "vistex-sand05-128.png --json");
  const nlohmann::json m = nlohmann::json::parse(plain.out, nullptr, false);
  ASSERT_FALSE(m.is_discarded()) << plain.out;
  EXPECT_GT(m["quarter_turn_difference"].get<int>(), 0);
  EXPECT_EQ(m["quarter_turn_symmetric"], false);

  const CliRun same = run_cli("tile " + kData + "vistex-sand05-128.png -o " + dir +
                              "/same.png --symmetry 4 --same-size -q --allow-misses");
  ASSERT_EQ(same.code, 0) << same.err;
  ASSERT_TRUE(load_image(dir + "/same.png", written).is_ok());
  EXPECT_EQ(written.width, 128);
  EXPECT_EQ(quarter_turn_difference(written), 0);

  for (const std::string& bad : {std::string("--variants 2"), std::string("--fit-period"), std::string("--symmetry 2"),
                                 std::string("--same-size")}) {
    const std::string args = bad == "--symmetry 2" || bad == "--same-size" ? bad : "--symmetry 4 " + bad;
    const CliRun u = run_cli("tile " + kData + "vistex-sand05-128.png -o " + dir + "/u.png " + args);
    EXPECT_EQ(u.code, 2) << args << ": " << u.err;
    EXPECT_EQ(std::count(u.err.begin(), u.err.end(), '\n'), 1) << u.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/u.png"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/u_0.png"));
}

TEST(TileCli, AMissedTargetIsAnErrorPerTargetUnlessAllowed) {
  // The quarter-turn tile of the photo's side misses its patch coherence (each quadrant is a
  // quarter of the photo): one error line with the figure, exit 3, the tile written anyway.
  const std::string dir = temp_dir();
  const std::string in = kData + "vistex-sand05-128.png", out = dir + "/q.png";
  const std::string args = "tile " + in + " -o " + out + " --symmetry 4 --same-size";
  CliRun r = run_cli(args);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_EQ(r.err.rfind("tailor: error: " + out +
                            ": misses a target, written anyway (--allow-misses accepts it): "
                            "patch coherence 0.",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.out.find("targets NOT met"), std::string::npos) << r.out;  // the summary line says so too
  Image written;
  ASSERT_TRUE(load_image(out, written).is_ok());
  std::filesystem::remove(out);
  // --quiet silences the summary, not the verdict (the metrics are measured for it).
  r = run_cli(args + " -q");
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  // Accepted: a warning per target, exit 0; with --quiet nothing at all.
  r = run_cli(args + " --allow-misses");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.rfind("tailor: warning: " + out + ": misses a target: patch coherence 0.", 0), 0u) << r.err;
  r = run_cli(args + " --allow-misses -q");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  // The same figures as eval-tile's verdict; a tile meeting every target says nothing on stderr.
  const CliRun e = run_cli("eval-tile " + out + " " + in);
  EXPECT_NE(e.out.find("patch coherence"), std::string::npos);
  r = run_cli("tile " + in + " -o " + dir + "/plain.png -q");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  // Every missed target is listed with its figure and limit.
  TileMetrics m;
  m.has_exemplar = true;
  m.wrap_ratio_x = 1.61;
  m.wrap_ratio_y = 1.0;
  m.worst_seam_ratio = 6.75;
  m.exemplar_worst_seam_ratio = 6.52;
  m.histogram_l1 = 0.2;
  m.gradient_ratio = 0.9;
  m.patch_coherence = 0.02;
  m.exemplar_patch_coherence = 0.01;
  const std::vector<std::string> missed = missed_tile_targets(m);
  ASSERT_EQ(missed.size(), 5u);
  EXPECT_EQ(missed[0], "wrap ratio x 1.61 outside [0.8, 1.2]");
  EXPECT_EQ(missed[1], "worst seam 6.750 above 6.520 (the exemplar's 6.520, at least 1.5)");
  EXPECT_EQ(missed[2], "histogram L1 0.200 above 0.1");
  EXPECT_EQ(missed[3], "gradient ratio 0.900 below 0.95");
  EXPECT_EQ(missed[4], "patch coherence 0.0200 above the exemplar's 0.0100");
  std::string failed;
  EXPECT_FALSE(meets_tile_targets(m, &failed));
  EXPECT_EQ(failed.rfind("wrap ratio x outside [0.8, 1.2], worst seam above", 0), 0u) << failed;
}

TEST(TileCli, BadInputGivesOneErrorLineAndExitCode) {
  const std::string dir = temp_dir();
  const std::string text = dir + "/notes.png";
  std::ofstream(text) << "not an image\n";
  CliRun r = run_cli("tile " + text + " -o " + dir + "/x.png");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err.rfind("tailor: error: " + text + ": ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.png"));
  r = run_cli("tile " + kData + "vistex-sand05-128.png -o " + dir + "/x.jpg");
  EXPECT_EQ(r.code, 2) << r.err;
  r = run_cli("tile " + kData + "vistex-sand05-128.png -o " + dir + "/x.png --block 4");
  EXPECT_EQ(r.code, 2) << r.err;
  r = run_cli("eval-tile " + dir + "/missing.png");
  EXPECT_EQ(r.code, 1);
}

}  // namespace
}  // namespace tailor
