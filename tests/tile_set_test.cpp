// Material sets tiled with one cut (make_tileable_set, `tailor tile --set`), 16-bit maps, and the
// coarse-to-fine path of images above kPlanMaxSide.
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
#include "tailor/tiling.h"

namespace tailor {
namespace {

const std::string kData = std::string(TAILOR_TEST_DATA) + "/textures/";

Image load(const std::string& name) {
  Image im;
  const Status s = load_image(kData + name, im);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return im;
}

TileMap map_of(const Image& im, bool normal = false) {
  TileMap m;
  m.image = to_image16(im);
  m.normal = normal;
  return m;
}

//! A tangent-space normal map of the height `h` (grey): n = (-s dh/dx, -s dh/dy, 1) / |.|, times
//! `length` (1: unit normals), encoded in 8 bits.
Image normals_of(const Image& h, double s, double length) {
  Image n;
  n.width = h.width;
  n.height = h.height;
  n.channels = 3;
  n.pixels.resize(static_cast<size_t>(h.width) * h.height * 3);
  auto at = [&](int x, int y) {
    return static_cast<double>(
        h.pixels[static_cast<size_t>((y + h.height) % h.height) * h.width + (x + h.width) % h.width]);
  };
  for (int y = 0; y < h.height; ++y)
    for (int x = 0; x < h.width; ++x) {
      double v[3] = {-s * (at(x + 1, y) - at(x - 1, y)) / 2.0, -s * (at(x, y + 1) - at(x, y - 1)) / 2.0, 1.0};
      const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int k = 0; k < 3; ++k)
        n.pixels[(static_cast<size_t>(y) * h.width + x) * 3 + k] =
            static_cast<uint8_t>(std::lround(std::clamp((v[k] / len * length + 1.0) * 127.5, 0.0, 255.0)));
    }
  return n;
}

//! Fraction of pixels where grey(colour) and the height map differ by at most 2 levels.
double registered_fraction(const Image16& colour, const Image16& height) {
  const Image grey = to_grey(to_image8(colour));
  const Image h = to_image8(height);
  size_t close = 0;
  for (size_t i = 0; i < grey.pixels.size(); ++i)
    if (std::abs(static_cast<int>(grey.pixels[i]) - static_cast<int>(h.pixels[i])) <= 2) ++close;
  return static_cast<double>(close) / static_cast<double>(grey.pixels.size());
}

TEST(TileSet, ColourAndItsGreyHeightShareOneCut) {
  for (const char* name : {"vistex-bark11-128.png", "water-caustics-300.jpg"}) {
    const Image a = load(name);
    const Image h = to_grey(a);
    std::vector<std::vector<Image16>> tiles;
    ASSERT_TRUE(make_tileable_set({map_of(a), map_of(h)}, TileOptions{}, 1, tiles).is_ok());
    ASSERT_EQ(tiles.size(), 1u);
    ASSERT_EQ(tiles[0].size(), 2u);
    EXPECT_EQ(tiles[0][0].channels, 3);
    EXPECT_EQ(tiles[0][1].channels, 1);
    EXPECT_GE(registered_fraction(tiles[0][0], tiles[0][1]), 0.99) << name;
    // Each map tiled alone is cut differently: the check above can fail.
    Image alone;
    TileOptions other;
    other.seed = 2;
    ASSERT_TRUE(make_tileable(h, other, alone).is_ok());
    EXPECT_LT(registered_fraction(tiles[0][0], to_image16(alone)), 0.99) << name;
    // The shared cut still makes a seamless tile of the colour map.
    TileMetrics m;
    ASSERT_TRUE(tile_metrics(to_image8(tiles[0][0]), &a, m).is_ok());
    EXPECT_GE(m.wrap_ratio_x, 0.8);
    EXPECT_LE(m.wrap_ratio_x, 1.2);
    EXPECT_GE(m.wrap_ratio_y, 0.8);
    EXPECT_LE(m.wrap_ratio_y, 1.2);
  }
}

TEST(TileSet, VariantsAndPeriodFittingKeepTheMapsRegistered) {
  const Image a = load("vistex-tile04-128.png");
  const Image h = to_grey(a);
  TileOptions options;
  options.fit_period = true;
  std::vector<std::vector<Image16>> tiles;
  TileReport report;
  ASSERT_TRUE(make_tileable_set({map_of(a), map_of(h)}, options, 3, tiles, &report).is_ok());
  ASSERT_EQ(tiles.size(), 3u);
  for (const std::vector<Image16>& set : tiles) {
    EXPECT_EQ(set[0].width, report.width);
    EXPECT_EQ(set[1].height, report.height);
    EXPECT_GE(registered_fraction(set[0], set[1]), 0.99);
  }
  EXPECT_NE(tiles[1][0].pixels, tiles[0][0].pixels);
  // Every variant of every map shares the outer ring of report.border px with the first one.
  ASSERT_GE(report.border, 1);
  for (size_t k = 1; k < tiles.size(); ++k)
    for (size_t m = 0; m < 2; ++m) {
      const Image16& first = tiles[0][m];
      const Image16& other = tiles[k][m];
      size_t differing = 0;
      for (int y = 0; y < first.height; ++y)
        for (int x = 0; x < first.width; ++x) {
          if (x >= report.border && y >= report.border && x < first.width - report.border &&
              y < first.height - report.border)
            continue;
          const size_t i = (static_cast<size_t>(y) * first.width + x) * first.channels;
          if (!std::equal(&first.pixels[i], &first.pixels[i] + first.channels, &other.pixels[i])) ++differing;
        }
      EXPECT_EQ(differing, 0u) << "variant " << k << " map " << m;
    }
}

TEST(TileSet, OutputNormalsAreUnitLength) {
  const Image a = load("vistex-sand05-128.png");
  const Image h = to_grey(a);
  // Input normals of length 0.8: only renormalisation makes them unit.
  for (double length : {1.0, 0.8}) {
    std::vector<std::vector<Image16>> tiles;
    ASSERT_TRUE(
        make_tileable_set({map_of(a), map_of(normals_of(h, 0.05, length), true)}, TileOptions{}, 1, tiles).is_ok());
    const Image16& n = tiles[0][1];
    ASSERT_EQ(n.channels, 3);
    double worst = 0.0;
    for (size_t i = 0; i < n.pixels.size(); i += 3) {
      double len2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double v = n.pixels[i + k] / 127.5 - 1.0;
        len2 += v * v;
      }
      worst = std::max(worst, std::abs(std::sqrt(len2) - 1.0));
    }
    EXPECT_LE(worst, 0.01) << "input length " << length;
  }
}

// Up to the size planned whole, a map tiled alone, as a set or at 16 bits gets exactly the cut
// make_tileable gives its 8-bit copy: no second cut, no blending across it (a 0/255 mask keeps
// its two values).
TEST(TileSet, SetsAndSixteenBitMapsGetTheSameCutAsMakeTileable) {
  for (const char* name : {"gravel-gray-512.png", "vistex-bark11-128.png", "brick-gray-512.png"}) {
    const Image a = load(name);
    Image direct;
    ASSERT_TRUE(make_tileable(a, TileOptions{}, direct).is_ok());
    TileMap m;
    m.image = to_image16(a);
    std::vector<std::vector<Image16>> tiles;
    ASSERT_TRUE(make_tileable_set({m}, TileOptions{}, 1, tiles).is_ok());
    EXPECT_EQ(tiles[0][0].pixels, to_image16(direct).pixels) << name;
    for (uint16_t& v : m.image.pixels) v = static_cast<uint16_t>(v * 257);
    m.image.bits = 16;
    ASSERT_TRUE(make_tileable_set({m}, TileOptions{}, 1, tiles).is_ok());
    std::vector<uint16_t> deep = to_image16(direct).pixels;
    for (uint16_t& v : deep) v = static_cast<uint16_t>(v * 257);
    EXPECT_EQ(tiles[0][0].pixels, deep) << name;
  }
  Image mask = to_grey(load("vistex-sand05-128.png"));
  for (uint8_t& v : mask.pixels) v = v < 128 ? 0 : 255;
  std::vector<std::vector<Image16>> tiles;
  ASSERT_TRUE(
      make_tileable_set({map_of(load("vistex-sand05-128.png")), map_of(mask)}, TileOptions{}, 1, tiles).is_ok());
  EXPECT_TRUE(
      std::all_of(tiles[0][1].pixels.begin(), tiles[0][1].pixels.end(), [](uint16_t v) { return v == 0 || v == 255; }));
}

// A strip too thin to tile is refused naming its own size, not its planned copy's; a strip that
// is reduced keeps its aspect (1000 x 40 planned at 800 x 32, not squashed to 512 x 32).
TEST(TileSet, StripsAreNamedAndPlannedAtTheirOwnAspect) {
  const Image gravel = load("gravel-gray-512.png");
  const auto strip = [&](int w, int h) {
    Image s{w, h, 1, std::vector<uint8_t>(static_cast<size_t>(w) * h)};
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        s.pixels[static_cast<size_t>(y) * w + x] = gravel.pixels[(static_cast<size_t>(y % 512) * 512 + x % 512) * 1];
    return s;
  };
  Image tile;
  const Status thin = make_tileable(strip(4000, 16), TileOptions{}, tile);
  ASSERT_FALSE(thin.is_ok());
  EXPECT_NE(thin.message().find("image too small to make tileable (at least 32 px a side) (4000x16)"),
            std::string::npos)
      << thin.message();
  TileReport report;
  TileOptions plain;
  plain.auto_period = false;  // the strip repeats the 512 px photo: a period fit would resize it
  ASSERT_TRUE(make_tileable(strip(1000, 40), plain, tile, &report).is_ok());
  EXPECT_EQ(tile.width, 1000);
  EXPECT_EQ(tile.height, 40);
  EXPECT_TRUE(std::any_of(report.warnings.begin(), report.warnings.end(), [](const std::string& w) {
    return w.find("planned on a 800x32 px copy") == 0;
  })) << (report.warnings.empty() ? std::string() : report.warnings[0]);
}

TEST(TileSet, SixteenBitMapsStaySixteenBit) {
  const Image a = load("gravel-gray-512.png");
  TileMap m;
  m.image = to_image16(a);
  m.image.bits = 16;
  // Low bytes that 8 bits would lose.
  for (size_t i = 0; i < m.image.pixels.size(); ++i)
    m.image.pixels[i] = static_cast<uint16_t>(a.pixels[i] * 256 + (i * 37) % 251);
  std::vector<std::vector<Image16>> tiles;
  ASSERT_TRUE(make_tileable_set({m}, TileOptions{}, 1, tiles).is_ok());
  const Image16& t = tiles[0][0];
  EXPECT_EQ(t.bits, 16);
  EXPECT_TRUE(std::any_of(t.pixels.begin(), t.pixels.end(), [](uint16_t v) { return v % 256 != 0; }));

  // Through files and the CLI: a 16-bit PNG gives a 16-bit PNG, samples read back exactly.
  const std::string dir = test::temp_dir();
  ASSERT_TRUE(write_png16(dir + "/h16.png", m.image).is_ok());
  Image16 back;
  ASSERT_TRUE(load_image16(dir + "/h16.png", back).is_ok());
  EXPECT_EQ(back.bits, 16);
  EXPECT_EQ(back.pixels, m.image.pixels);
  std::string out;  // --allow-misses below: these checks are about bits and names, not the targets
  ASSERT_EQ(test::run_command(
                std::string(TAILOR_BINARY) + " tile " + dir + "/h16.png -o " + dir + "/t16.png -q --allow-misses", out),
            0)
      << out;
  Image16 tiled;
  ASSERT_TRUE(load_image16(dir + "/t16.png", tiled).is_ok());
  EXPECT_EQ(tiled.bits, 16);
  EXPECT_EQ(tiled.width, 512);
  // The quarter-turn tile of a 16-bit PNG: 16-bit, twice
  // the side, exactly unchanged by a quarter turn, the low bytes kept.
  ASSERT_EQ(test::run_command(std::string(TAILOR_BINARY) + " tile " + dir + "/h16.png -o " + dir +
                                  "/q16.png --symmetry 4 -q --allow-misses",
                              out),
            0)
      << out;
  Image16 quarter;
  ASSERT_TRUE(load_image16(dir + "/q16.png", quarter).is_ok());
  EXPECT_EQ(quarter.bits, 16);
  ASSERT_EQ(quarter.width, 1024);
  const int n = quarter.width;
  bool turned_equal = true;
  for (int y = 0; y < n && turned_equal; ++y)
    for (int x = 0; x < n; ++x)  // rot90(tile)(x, y) = tile(y, n - 1 - x)
      turned_equal &=
          quarter.pixels[static_cast<size_t>(y) * n + x] == quarter.pixels[static_cast<size_t>(n - 1 - x) * n + y];
  EXPECT_TRUE(turned_equal);
  EXPECT_TRUE(std::any_of(quarter.pixels.begin(), quarter.pixels.end(), [](uint16_t v) { return v % 256 != 0; }));
  // An 8-bit PNG stays 8-bit.
  Image16 eight;
  ASSERT_TRUE(load_image16(kData + "gravel-gray-512.png", eight).is_ok());
  EXPECT_EQ(eight.bits, 8);
}

// A quarter-turn tile of a set turns its normal map with its content: a height map and the
// normal map computed from it (+x right, +y up, as glTF), tiled together with symmetry 4 (at
// 512 px, quilted directly, and at 800 px, through a 512 px plan read at full size), give a
// normal map that agrees with the normals of the tiled height map (away from the cuts, where the
// blocks cross-fade), and both tiles are exactly unchanged by a quarter turn (the normals turned
// with it). Without turning the normals they would point 90 degrees off in three quarters. A
// DirectX normal map (+y down the image) turns the other way round.
TEST(TileSet, QuarterTurnSetsTurnTheirNormalMaps) {
  for (const std::pair<int, bool>& run : {std::pair{512, false}, std::pair{800, false}, std::pair{512, true}}) {
    const int side = run.first;
    const bool dx = run.second;  // not structured bindings: clang 14 cannot capture those in lambdas
    Image grey;
    ASSERT_TRUE(resize_image(load("gravel-gray-512.png"), side, side, grey).is_ok());
    // Height: the photo smoothed (a 5 x 5 box twice), so its normals vary slowly.
    std::vector<double> h(static_cast<size_t>(side) * side);
    for (size_t i = 0; i < h.size(); ++i) h[i] = grey.pixels[i];
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<double> next(h.size());
      for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
          double sum = 0.0;
          for (int oy = -2; oy <= 2; ++oy)
            for (int ox = -2; ox <= 2; ++ox)
              sum += h[static_cast<size_t>(std::clamp(y + oy, 0, side - 1)) * side + std::clamp(x + ox, 0, side - 1)];
          next[static_cast<size_t>(y) * side + x] = sum / 25.0;
        }
      h.swap(next);
    }
    // Normal of a height field z = h(x, y_down) / 16: (-h_x, h_y_down, 1) with +y up (-h_y_down
    // with +y down); 16-bit.
    auto normal_of = [dx](double hx, double hy, uint16_t* o) {
      double nx = -hx / 16.0, ny = (dx ? -hy : hy) / 16.0, nz = 1.0;
      const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
      nx /= len, ny /= len, nz /= len;
      o[0] = static_cast<uint16_t>(std::lround((nx + 1.0) * 32767.5));
      o[1] = static_cast<uint16_t>(std::lround((ny + 1.0) * 32767.5));
      o[2] = static_cast<uint16_t>(std::lround((nz + 1.0) * 32767.5));
    };
    TileMap height, normal;
    height.image.width = height.image.height = normal.image.width = normal.image.height = side;
    height.image.channels = 1;
    height.image.bits = normal.image.bits = 16;
    normal.image.channels = 3;
    normal.normal = true;
    normal.directx = dx;
    height.image.pixels.resize(h.size());
    normal.image.pixels.resize(3 * h.size());
    auto hat = [&](int x, int y) {
      return h[static_cast<size_t>(std::clamp(y, 0, side - 1)) * side + std::clamp(x, 0, side - 1)];
    };
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) {
        height.image.pixels[static_cast<size_t>(y) * side + x] = static_cast<uint16_t>(std::lround(256.0 * hat(x, y)));
        normal_of(0.5 * (hat(x + 1, y) - hat(x - 1, y)), 0.5 * (hat(x, y + 1) - hat(x, y - 1)),
                  &normal.image.pixels[3 * (static_cast<size_t>(y) * side + x)]);
      }
    TileOptions options;
    options.symmetry = 4;
    std::vector<std::vector<Image16>> tiles;
    ASSERT_TRUE(make_tileable_set({height, normal}, options, 1, tiles).is_ok());
    const Image16 &th = tiles[0][0], &tn = tiles[0][1];
    const int n = th.width;
    ASSERT_EQ(n, 2 * side);
    ASSERT_EQ(tn.width, n);
    // Exactly 4-fold: the height unchanged, the normal turned: tile(x, y) seen from its quarter
    // turn's place (n - 1 - y, x) holds the vector turned once, (nx, ny) -> (ny, -nx) (+y down:
    // (-ny, nx)).
    size_t height_off = 0, normal_off = 0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const size_t p = static_cast<size_t>(y) * n + x, q = static_cast<size_t>(x) * n + (n - 1 - y);
        height_off += th.pixels[p] != th.pixels[q];
        const double nx = tn.pixels[3 * p] / 32767.5 - 1.0, ny = tn.pixels[3 * p + 1] / 32767.5 - 1.0;
        const double mx = tn.pixels[3 * q] / 32767.5 - 1.0, my = tn.pixels[3 * q + 1] / 32767.5 - 1.0;
        const double f = dx ? -1.0 : 1.0;
        normal_off += std::abs(mx - f * ny) > 1e-3 || std::abs(my + f * nx) > 1e-3;
      }
    EXPECT_EQ(height_off, 0u) << side;
    EXPECT_EQ(normal_off, 0u) << side;
    // The tiled normals against the tiled height's, where the 3 x 3 neighbourhood is smooth.
    std::vector<double> angle;
    for (int y = 1; y + 1 < n; y += 3)
      for (int x = 1; x + 1 < n; x += 3) {
        auto at = [&](int u, int v) { return th.pixels[static_cast<size_t>(v) * n + u] / 256.0; };
        uint16_t expected[3];
        normal_of(0.5 * (at(x + 1, y) - at(x - 1, y)), 0.5 * (at(x, y + 1) - at(x, y - 1)), expected);
        const uint16_t* got = &tn.pixels[3 * (static_cast<size_t>(y) * n + x)];
        double dot = 0.0;
        for (int k = 0; k < 3; ++k) dot += (got[k] / 32767.5 - 1.0) * (expected[k] / 32767.5 - 1.0);
        angle.push_back(std::acos(std::clamp(dot, -1.0, 1.0)) * 180.0 / std::acos(-1.0));
      }
    std::sort(angle.begin(), angle.end());
    const double median = angle[angle.size() / 2], p90 = angle[angle.size() * 9 / 10];
    std::printf("%d px set%s, symmetry 4: normals against the tiled height's: median %.2f, 90th percentile %.2f deg\n",
                side, dx ? " (DirectX normals)" : "", median, p90);
    EXPECT_LT(median, 1.0) << side;
    EXPECT_LT(p90, 5.0) << side;
  }
}

// The output name of a set's map, shared by `tailor tile --set` and tailor.tile_set.
TEST(TileSet, OutputFileNames) {
  EXPECT_EQ(tile_set_file_name("maps/bark_color.jpg"), "bark_color.png");
  EXPECT_EQ(tile_set_file_name("/a/b/x.y.png"), "x.y.png");
  EXPECT_EQ(tile_set_file_name("noext"), "noext.png");
  EXPECT_EQ(tile_set_file_name(".hidden"), ".hidden.png");
}

TEST(TileSet, AlphaIsKept) {
  const Image rgb = load("vistex-fabric02-128.png");
  Image rgba;
  rgba.width = rgb.width;
  rgba.height = rgb.height;
  rgba.channels = 4;
  for (size_t i = 0; i < rgb.pixels.size(); i += 3) {
    rgba.pixels.insert(rgba.pixels.end(), rgb.pixels.begin() + static_cast<std::ptrdiff_t>(i),
                       rgb.pixels.begin() + static_cast<std::ptrdiff_t>(i + 3));
    rgba.pixels.push_back(static_cast<uint8_t>(255 - rgb.pixels[i + 1]));  // alpha follows the texture
  }
  std::vector<std::vector<Image16>> tiles;
  ASSERT_TRUE(make_tileable_set({map_of(rgba)}, TileOptions{}, 1, tiles).is_ok());
  const Image16& t = tiles[0][0];
  ASSERT_EQ(t.channels, 4);
  size_t close = 0;
  for (size_t i = 0; i < t.pixels.size(); i += 4)
    if (std::abs(static_cast<int>(t.pixels[i + 3]) - (255 - static_cast<int>(t.pixels[i + 1]))) <= 2) ++close;
  EXPECT_GE(static_cast<double>(close) / static_cast<double>(t.pixels.size() / 4), 0.99);
}

TEST(TileSet, MapsOfDifferentSizesAreAClearError) {
  std::vector<std::vector<Image16>> tiles;
  const Status s =
      make_tileable_set({map_of(load("vistex-bark11-128.png")), map_of(load("gravel-gray-512.png"))}, {}, 1, tiles);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidImage);
  EXPECT_NE(s.message().find("same size"), std::string::npos) << s.message();
  EXPECT_TRUE(tiles.empty());
  EXPECT_FALSE(make_tileable_set({}, {}, 1, tiles).is_ok());
  TileMap grey_normal = map_of(load("gravel-gray-512.png"), true);
  EXPECT_FALSE(make_tileable_set({grey_normal}, {}, 1, tiles).is_ok());

  // The CLI: one error line, exit 1, no output folder.
  const std::string dir = test::temp_dir() + "/mixed";
  std::filesystem::remove_all(dir);
  std::string out, err;
  const int code = test::run_command(std::string(TAILOR_BINARY) + " tile --set " + kData + "vistex-bark11-128.png " +
                                         kData + "gravel-gray-512.png -o " + dir,
                                     out, &err);
  EXPECT_EQ(code, 1);
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("same size"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir));
}

TEST(TileSetCli, SetAndMaterialWriteTheInputNamesIntoTheFolder) {
  const std::string dir = test::empty_temp_dir("set");
  const Image a = load("vistex-bark11-128.png");
  ASSERT_TRUE(write_png(dir + "/bark_color.png", a).is_ok());
  ASSERT_TRUE(write_png(dir + "/bark_height.png", to_grey(a)).is_ok());
  ASSERT_TRUE(write_png(dir + "/bark_normal.png", normals_of(to_grey(a), 0.05, 1.0)).is_ok());
  std::string out, err;
  ASSERT_EQ(test::run_command(std::string(TAILOR_BINARY) + " tile --set " + dir + "/bark_color.png " + dir +
                                  "/bark_height.png " + dir + "/bark_normal.png --normal-map " + dir +
                                  "/bark_normal.png -o " + dir + "/out --variants 2 --quiet --allow-misses",
                              out, &err),
            0)
      << err;
  for (const char* f : {"bark_color_0.png", "bark_color_1.png", "bark_height_1.png", "bark_normal_0.png"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/out/" + f)) << f;
  std::ifstream jf(dir + "/out/material.json");
  const nlohmann::json j = nlohmann::json::parse(jf, nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  EXPECT_EQ(j["maps"][2]["normal"], true);
  EXPECT_EQ(j["normal_convention"], "gl");

  // The JSON alternative, files relative to it.
  {
    std::ofstream m(dir + "/bark.json");
    m << R"({"maps": [{"file": "bark_color.png"}, {"file": "bark_normal.png", "type": "normal"}],
             "normal_convention": "dx"})";
  }
  ASSERT_EQ(test::run_command(std::string(TAILOR_BINARY) + " tile --material " + dir + "/bark.json -o " + dir +
                                  "/out2 --quiet --allow-misses",
                              out, &err),
            0)
      << err;
  Image16 c, n;
  ASSERT_TRUE(load_image16(dir + "/out2/bark_color.png", c).is_ok());
  ASSERT_TRUE(load_image16(dir + "/out2/bark_normal.png", n).is_ok());
  EXPECT_EQ(c.width, 128);
  std::ifstream jf2(dir + "/out2/material.json");
  const nlohmann::json j2 = nlohmann::json::parse(jf2, nullptr, false);
  EXPECT_EQ(j2["normal_convention"], "dx");
  EXPECT_EQ(j2["maps"][1]["normal"], true);
  // A "normal" that is not true or false is refused: read as false, the normal map was tiled as colour.
  {
    std::ofstream m(dir + "/bad.json");
    m << R"({"maps": [{"file": "bark_color.png"}, {"file": "bark_normal.png", "normal": "yes"}]})";
  }
  EXPECT_EQ(test::run_command(std::string(TAILOR_BINARY) + " tile --material " + dir + "/bad.json -o " + dir +
                                  "/out3 --quiet --allow-misses",
                              out, &err),
            2);
  EXPECT_NE(err.find("\"normal\" must be true or false (maps[1])"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out3"));
  // A key tile does not know is named (a typo would be ignored without a word); the material.json
  // tile writes, given back to it, has none.
  {
    std::ofstream m(dir + "/typo.json");
    m << R"({"maps": [{"file": "bark_color.png"}, {"file": "bark_normal.png", "nomal": true}], "colour": 1})";
  }
  ASSERT_EQ(test::run_command(std::string(TAILOR_BINARY) + " tile --material " + dir + "/typo.json -o " + dir +
                                  "/out4 --allow-misses",
                              out, &err),
            0)
      << err;
  EXPECT_NE(err.find("typo.json: unknown key 'colour' ignored (known: maps, "), std::string::npos) << err;
  EXPECT_NE(err.find("typo.json: maps[1]: unknown key 'nomal' ignored (known: file, normal, "), std::string::npos)
      << err;
  ASSERT_EQ(test::run_command(std::string(TAILOR_BINARY) + " tile --material " + dir + "/out2/material.json -o " + dir +
                                  "/out5 --allow-misses",
                              out, &err),
            0)
      << err;
  EXPECT_EQ(err.find("unknown key"), std::string::npos) << err;
  // A material JSON written as `name` and tiled into `folder`: the command's exit status.
  const auto tile_material = [&](const std::string& name, const std::string& json, const std::string& folder) {
    std::ofstream(dir + "/" + name) << json;
    return test::run_command(std::string(TAILOR_BINARY) + " tile --material " + dir + "/" + name + " -o " + dir + "/" +
                                 folder + " --quiet --allow-misses",
                             out, &err);
  };
  const auto material_of = [&](const std::string& folder) {
    std::ifstream in(dir + "/" + folder + "/material.json");
    return nlohmann::json::parse(in, nullptr, false);
  };
  // "role" names a normal map as `tailor map --material` reads it (any case, role words).
  ASSERT_EQ(
      tile_material("role.json",
                    R"({"maps": [{"file": "bark_color.png"}, {"file": "bark_normal.png", "role": "Normal"}]})", "out6"),
      0)
      << err;
  EXPECT_EQ(material_of("out6")["maps"][1]["normal"], true);
  // A DirectX role is kept for `tailor map --material`, which reads its green the other way.
  ASSERT_EQ(tile_material("role_dx.json",
                          R"({"maps": [{"file": "bark_color.png"}, {"file": "bark_normal.png", "role": "normal_dx"}]})",
                          "out8"),
            0)
      << err;
  const nlohmann::json j8 = material_of("out8");
  EXPECT_EQ(j8["maps"][1]["role"], "normal_dx");
  EXPECT_FALSE(j8["maps"][0].contains("role"));
  EXPECT_EQ(
      tile_material("convention.json", R"({"maps": [{"file": "bark_color.png"}], "normal_convention": 5})", "out7"), 2);
  EXPECT_NE(err.find("normal_convention must be \"gl\" or \"dx\""), std::string::npos) << err;
  std::filesystem::remove_all(dir);
}

//! A running-bond brick wall: bricks bw x bh px (rows offset by bw / 2), `mortar` px joints of
//! grey 150, brick tones 90-150, noise +-40, 3 x 3 box blur; fixed generator (deterministic).
Image brick_wall(int width, int height, int bw, int bh, int mortar) {
  uint64_t state = 5;
  auto next = [&state](int n) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>((state >> 33) % static_cast<uint64_t>(n));
  };
  std::vector<int> tone(static_cast<size_t>((height / bh + 1) * (width / bw + 2)));
  for (int& t : tone) t = 90 + next(61);
  std::vector<int> raw(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int course = y / bh, shifted = x + (bw / 2) * (course % 2);
      const bool joint = y % bh < mortar || shifted % bw < mortar;
      const int base = joint ? 150 : tone[static_cast<size_t>(course * (width / bw + 2) + shifted / bw)];
      raw[static_cast<size_t>(y) * width + x] = base + next(81) - 40;
    }
  Image im;
  im.width = width;
  im.height = height;
  im.channels = 1;
  im.pixels.resize(raw.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      int sum = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          sum += raw[static_cast<size_t>(std::clamp(y + dy, 0, height - 1)) * width + std::clamp(x + dx, 0, width - 1)];
      im.pixels[static_cast<size_t>(y) * width + x] = static_cast<uint8_t>(std::clamp((sum + 4) / 9, 0, 255));
    }
  return im;
}

TEST(TileRegular, BrickBondsFollowTheirPeriodAndMeetTheStraightSeamTarget) {
  // 40 x 20 px bricks (period 40 x 40 with the offset rows) in 230 x 190 px: not whole periods.
  const Image wall = brick_wall(230, 190, 40, 20, 3);
  const PeriodEstimate p = estimate_period(wall);
  ASSERT_TRUE(p.found_x && p.found_y);
  EXPECT_GE(std::min(p.confidence_x, p.confidence_y), kStrongPeriod);
  Image tile;
  TileReport report;
  ASSERT_TRUE(make_tileable(wall, TileOptions{}, tile, &report).is_ok());
  // By default the size follows the period: whole periods, so courses and joints continue across the wrap.
  EXPECT_TRUE(report.period_fitted);
  EXPECT_EQ(tile.width % 40, 0);
  EXPECT_EQ(tile.height % 40, 0);
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(tile, &wall, m).is_ok());
  std::string failed;
  EXPECT_TRUE(meets_tile_targets(m, &failed)) << failed;
  EXPECT_LE(m.worst_seam_ratio, std::max(m.exemplar_worst_seam_ratio, 1.5));
  // --no-auto-period keeps the size.
  TileOptions keep;
  keep.auto_period = false;
  Image plain;
  TileReport plain_report;
  ASSERT_TRUE(make_tileable(wall, keep, plain, &plain_report).is_ok());
  EXPECT_FALSE(plain_report.period_fitted);
  EXPECT_EQ(plain.width, 230);
  // Noise has no strong period: the size is kept.
  Image gravel_tile;
  TileReport gravel_report;
  ASSERT_TRUE(make_tileable(load("vistex-sand05-128.png"), TileOptions{}, gravel_tile, &gravel_report).is_ok());
  EXPECT_FALSE(gravel_report.period_fitted);
  EXPECT_EQ(gravel_tile.width, 128);
}

TEST(TileRegular, BondsAndTilesKeepTheirStrongestLineAtMostTheExemplars) {
  // Regular patterns with a detected period: the shared stretcher-bond photo, a photo of
  // ornamental wall tiles (VisTex Tile.0004, a square grid of joints) and a Flemish bond (header and
  // stretcher alternating in each course, synthetic; tests/data/textures/README.md). The repair
  // follows the joints: no straight line of the tile is stronger than 1.03 x the exemplar's strongest.
  for (const char* name : {"brick-gray-512.png", "vistex-tile04-128.png", "flemish-bond-256.png"}) {
    SCOPED_TRACE(name);
    const Image wall = load(name);
    const PeriodEstimate p = estimate_period(wall);
    EXPECT_TRUE(p.found_x || p.found_y);
    Image tile;
    ASSERT_TRUE(make_tileable(wall, TileOptions{}, tile).is_ok());
    TileMetrics m;
    ASSERT_TRUE(tile_metrics(tile, &wall, m).is_ok());
    std::string failed;
    EXPECT_TRUE(meets_tile_targets(m, &failed)) << failed;
    EXPECT_GT(m.exemplar_worst_seam_ratio, 1.5);  // a joint, not noise, is the exemplar's strongest line
    EXPECT_LE(m.worst_seam_ratio, 1.03 * m.exemplar_worst_seam_ratio);
  }
}

//! A photo enlarged 3 x by pixel repetition (each value in a 3 x 3 cell) plus fine noise: every
//! third column (row) boundary is strong, the others weak (JPEG blocks do the same every 8 px).
Image blocky_photo(int cells) {
  Image im;
  im.width = im.height = 3 * cells;
  im.channels = 1;
  im.pixels.resize(static_cast<size_t>(im.width) * im.height);
  uint64_t state = 12345;
  auto next = [&state]() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>((state >> 33) % 1000);
  };
  std::vector<int> cell(static_cast<size_t>(cells) * cells);
  for (int& v : cell) v = 60 + next() % 130;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      im.pixels[static_cast<size_t>(y) * im.width + x] =
          static_cast<uint8_t>(cell[static_cast<size_t>(y / 3) * cells + x / 3] + next() % 7);
  return im;
}

TEST(TileLarge, TheWrapIsChosenAtFullSize) {
  // 1536 px, planned at 512: a boundary of the plan stands for three of the photo, and the one it
  // scales to (3 s) is always a strong one here. The wrap is chosen among the three at full size,
  // so it joins its sides like an ordinary (weak) boundary; the scaled one would be a strong one.
  const Image photo = blocky_photo(512);
  Image tile;
  TileReport report;
  ASSERT_TRUE(make_tileable(photo, TileOptions{}, tile, &report).is_ok());
  ASSERT_EQ(tile.width, 1536);
  EXPECT_NE(report.shift_x % 3, 0);
  EXPECT_NE(report.shift_y % 3, 0);
  double wx = 0, wy = 0;
  ASSERT_TRUE(wrap_ratios(tile, wx, wy).is_ok());
  EXPECT_GE(wx, 0.8);
  EXPECT_LE(wx, 1.2);
  EXPECT_GE(wy, 0.8);
  EXPECT_LE(wy, 1.2);
}

TEST(TileLarge, CoarseToFineAboveThePlanSizeMeetsTheSeamTargets) {
  // 768 px (above kPlanMaxSide): planned at 512 px, replayed at full size.
  const Image small = load("water-caustics-300.jpg");
  Image big;
  ASSERT_TRUE(resize_image(small, 768, 768, big).is_ok());
  Image tile, again;
  TileReport report;
  ASSERT_TRUE(make_tileable(big, TileOptions{}, tile, &report).is_ok());
  EXPECT_EQ(tile.width, 768);
  EXPECT_GT(report.block, TileOptions{}.block);  // the block scaled with the image
  TileMetrics m;
  ASSERT_TRUE(tile_metrics(tile, &big, m).is_ok());
  std::string failed;
  EXPECT_TRUE(meets_tile_targets(m, &failed)) << failed;
  ASSERT_TRUE(make_tileable(big, TileOptions{}, again).is_ok());
  EXPECT_EQ(tile.pixels, again.pixels);
  // Variants replayed at full size share the outer ring bit-exactly and differ inside.
  std::vector<Image> variants;
  TileReport vr;
  ASSERT_TRUE(make_tile_variants(big, TileOptions{}, 2, variants, &vr).is_ok());
  ASSERT_EQ(variants.size(), 2u);
  EXPECT_EQ(variants[0].pixels, tile.pixels);
  size_t ring_differs = 0, inside_differs = 0;
  for (int y = 0; y < 768; ++y)
    for (int x = 0; x < 768; ++x) {
      const size_t i = (static_cast<size_t>(y) * 768 + x) * 3;
      const bool same = std::equal(&variants[0].pixels[i], &variants[0].pixels[i] + 3, &variants[1].pixels[i]);
      const bool ring = x < vr.border || y < vr.border || x >= 768 - vr.border || y >= 768 - vr.border;
      if (!same) ++(ring ? ring_differs : inside_differs);
    }
  EXPECT_EQ(ring_differs, 0u);
  EXPECT_GT(inside_differs, 768u * 768u / 4);
}

}  // namespace
}  // namespace tailor
