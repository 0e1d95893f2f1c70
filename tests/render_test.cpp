// Tests of the headless preview renderer (render.h): picture size, non-blank content, views that
// differ from each other, texture orientation, determinism and input validation.
#include "tailor/render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "support/fixtures.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/io.h"
#include "tailor/tiling.h"

namespace tailor {
namespace {

using test::box;
using test::load_test_mesh;

const std::string kData = std::string(TAILOR_TEST_DATA) + "/";

struct Fixture {
  Mesh mesh;
  Image texture;
};

const Fixture& spot() {
  static const Fixture f = [] {
    Fixture x;
    x.mesh = load_test_mesh("spot.obj");
    EXPECT_TRUE(load_image(kData + "textures/vistex-tile04-128.png", x.texture).is_ok());
    return x;
  }();
  return f;
}

RenderOptions small(PreviewView view) {
  RenderOptions o;
  o.width = 320;
  o.height = 240;
  o.view = view;
  return o;
}

Image render_ok(const Mesh& mesh, const Image* texture, const RenderOptions& options,
                std::span<const uint32_t> patch = {}) {
  Image out;
  const Status s = render_preview(mesh, mesh.corner_uvs, patch, texture, options, out);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return out;
}

double luminance_variance(const Image& img) {
  double sum = 0, sum2 = 0;
  const size_t n = static_cast<size_t>(img.width) * static_cast<size_t>(img.height);
  for (size_t i = 0; i < n; ++i) {
    const double l = 0.299 * img.pixels[3 * i] + 0.587 * img.pixels[3 * i + 1] + 0.114 * img.pixels[3 * i + 2];
    sum += l;
    sum2 += l * l;
  }
  const double mean = sum / static_cast<double>(n);
  return sum2 / static_cast<double>(n) - mean * mean;
}

//! Share of pixels that differ from the background colour (the top-left pixel).
double covered_share(const Image& img) {
  size_t covered = 0;
  const size_t n = static_cast<size_t>(img.width) * static_cast<size_t>(img.height);
  for (size_t i = 0; i < n; ++i) {
    for (size_t c = 0; c < 3; ++c) {
      if (std::abs(int{img.pixels[3 * i + c]} - int{img.pixels[c]}) > 4) {
        ++covered;
        break;
      }
    }
  }
  return static_cast<double>(covered) / static_cast<double>(n);
}

double mean_abs_difference(const Image& a, const Image& b) {
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) sum += std::abs(int{a.pixels[i]} - int{b.pixels[i]});
  return sum / static_cast<double>(a.pixels.size());
}

const uint8_t* pixel(const Image& img, int x, int y) {
  return &img.pixels[(static_cast<size_t>(y) * static_cast<size_t>(img.width) + static_cast<size_t>(x)) * 3];
}

TEST(RenderPreview, EveryViewHasTheRequestedSizeAndIsNotBlank) {
  const Fixture& f = spot();
  ASSERT_FALSE(f.mesh.corner_uvs.empty());
  for (const PreviewView view : {PreviewView::kTexture, PreviewView::kPatches, PreviewView::kDistortion,
                                 PreviewView::kChecker, PreviewView::kSeams}) {
    SCOPED_TRACE(preview_view_name(view));
    const Image img = render_ok(f.mesh, &f.texture, small(view));
    EXPECT_EQ(img.width, 320);
    EXPECT_EQ(img.height, 240);
    EXPECT_EQ(img.channels, 3);
    ASSERT_EQ(img.pixels.size(), 320u * 240u * 3u);
    EXPECT_GT(luminance_variance(img), 100.0);
    // Spot framed by its bounding sphere covers a good part of the picture, not all of it.
    EXPECT_GT(covered_share(img), 0.10);
    EXPECT_LT(covered_share(img), 0.80);
  }
}

TEST(RenderPreview, PatchCheckerAndDistortionViewsDifferFromTheTextureView) {
  const Fixture& f = spot();
  const Image texture = render_ok(f.mesh, &f.texture, small(PreviewView::kTexture));
  for (const PreviewView view : {PreviewView::kPatches, PreviewView::kDistortion, PreviewView::kChecker}) {
    SCOPED_TRACE(preview_view_name(view));
    const Image other = render_ok(f.mesh, &f.texture, small(view));
    // Over the whole picture (background included) the views differ by several grey levels.
    EXPECT_GT(mean_abs_difference(texture, other), 5.0);
  }
}

TEST(RenderPreview, SameInputGivesIdenticalPictures) {
  const Fixture& f = spot();
  const Image a = render_ok(f.mesh, &f.texture, small(PreviewView::kTexture));
  const Image b = render_ok(f.mesh, &f.texture, small(PreviewView::kTexture));
  EXPECT_EQ(a.pixels, b.pixels);
}

TEST(RenderPreview, SizeOptionIsHonoured) {
  const Fixture& f = spot();
  RenderOptions o = small(PreviewView::kChecker);
  o.width = 200;
  o.height = 300;
  o.supersample = 1;
  const Image img = render_ok(f.mesh, nullptr, o);
  EXPECT_EQ(img.width, 200);
  EXPECT_EQ(img.height, 300);
}

TEST(RenderPreview, DistortionViewDrawsItsColourBarLegend) {
  const Fixture& f = spot();
  const Image img = render_ok(f.mesh, nullptr, small(PreviewView::kDistortion));
  // The legend runs along the bottom band, below the mesh: its ends are saturated blue and red.
  bool blue = false, red = false;
  for (int y = img.height * 85 / 100; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = pixel(img, x, y);
      blue = blue || (p[2] > 150 && p[0] < 90);
      red = red || (p[0] > 150 && p[2] < 60);
    }
  }
  EXPECT_TRUE(blue);
  EXPECT_TRUE(red);
}

//! A unit square in the xy plane facing +z, UVs = xy (texture repeats, v up).
Mesh unit_square() {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  m.indices = {0, 1, 2, 0, 2, 3};
  for (const uint32_t v : m.indices) {
    m.corner_uvs.push_back(m.positions[3 * v]);
    m.corner_uvs.push_back(m.positions[3 * v + 1]);
  }
  return m;
}

TEST(RenderPreview, TextureTopRowAppearsAtTheTopForVUp) {
  // Image top half red, bottom half blue (image rows run top first).
  Image tex;
  tex.width = tex.height = 8;
  tex.channels = 3;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      const bool top = y < 4;
      tex.pixels.insert(tex.pixels.end(), {uint8_t(top ? 255 : 0), 0, uint8_t(top ? 0 : 255)});
    }
  }
  const Mesh square = unit_square();
  RenderOptions o = small(PreviewView::kTexture);
  o.yaw_degrees = 0.0f;  // camera on +z, looking at the square's front
  o.pitch_degrees = 0.0f;
  const Image img = render_ok(square, &tex, o);
  const uint8_t* upper = pixel(img, img.width / 2, img.height * 35 / 100);
  const uint8_t* lower = pixel(img, img.width / 2, img.height * 65 / 100);
  EXPECT_GT(upper[0], 150);
  EXPECT_LT(upper[2], 60);
  EXPECT_GT(lower[2], 150);
  EXPECT_LT(lower[0], 60);
}

TEST(RenderPreview, ExplicitPatchIdsColourFacesApart) {
  const Mesh square = unit_square();
  RenderOptions o = small(PreviewView::kPatches);
  o.yaw_degrees = 0.0f;
  o.pitch_degrees = 0.0f;
  const std::vector<uint32_t> one = {0, 0};
  const std::vector<uint32_t> two = {0, 1};
  const Image same = render_ok(square, nullptr, o, one);
  const Image apart = render_ok(square, nullptr, o, two);
  // Face 0 is the lower-right triangle, face 1 the upper-left one: sample inside each.
  const uint8_t* a0 = pixel(same, same.width * 58 / 100, same.height * 60 / 100);
  const uint8_t* a1 = pixel(same, same.width * 42 / 100, same.height * 40 / 100);
  const uint8_t* b0 = pixel(apart, apart.width * 58 / 100, apart.height * 60 / 100);
  const uint8_t* b1 = pixel(apart, apart.width * 42 / 100, apart.height * 40 / 100);
  int same_diff = 0, apart_diff = 0;
  for (int c = 0; c < 3; ++c) {
    same_diff += std::abs(int{a0[c]} - int{a1[c]});
    apart_diff += std::abs(int{b0[c]} - int{b1[c]});
  }
  EXPECT_LT(same_diff, 10);
  EXPECT_GT(apart_diff, 60);
}

TEST(RenderPreview, MissingTextureFallsBackToANeutralChecker) {
  const Fixture& f = spot();
  const Image img = render_ok(f.mesh, nullptr, small(PreviewView::kTexture));
  EXPECT_GT(luminance_variance(img), 100.0);
  // Grey checker under white light: every pixel is (nearly) grey.
  for (size_t i = 0; i < img.pixels.size(); i += 3) {
    ASSERT_LE(std::abs(int{img.pixels[i]} - int{img.pixels[i + 1]}), 8);
    ASSERT_LE(std::abs(int{img.pixels[i + 1]} - int{img.pixels[i + 2]}), 8);
  }
}

TEST(RenderPreview, PatchesViewWorksWithoutUvs) {
  Mesh m = unit_square();
  m.corner_uvs.clear();
  Image out;
  EXPECT_TRUE(render_preview(m, {}, {}, nullptr, small(PreviewView::kPatches), out).is_ok());
  EXPECT_EQ(out.width, 320);
}

TEST(RenderPreview, RejectsBadInput) {
  const Mesh square = unit_square();
  Image out;
  // UV array of the wrong size.
  std::vector<float> short_uv(4, 0.0f);
  Status s = render_preview(square, short_uv, {}, nullptr, small(PreviewView::kTexture), out);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(out.empty());
  // Views that need UVs without UVs.
  s = render_preview(square, {}, {}, nullptr, small(PreviewView::kChecker), out);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  // Patch ids of the wrong size.
  const std::vector<uint32_t> patch(5, 0);
  s = render_preview(square, square.corner_uvs, patch, nullptr, small(PreviewView::kPatches), out);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  // Sizes out of range.
  RenderOptions o = small(PreviewView::kTexture);
  o.width = 0;
  EXPECT_EQ(render_preview(square, square.corner_uvs, {}, nullptr, o, out).code(), ErrorCode::kInvalidArgument);
  o = small(PreviewView::kTexture);
  o.height = 100000;
  EXPECT_EQ(render_preview(square, square.corner_uvs, {}, nullptr, o, out).code(), ErrorCode::kInvalidArgument);
  o = small(PreviewView::kTexture);
  o.pitch_degrees = NAN;
  EXPECT_EQ(render_preview(square, square.corner_uvs, {}, nullptr, o, out).code(), ErrorCode::kInvalidArgument);
  // Empty mesh, index out of range.
  EXPECT_EQ(render_preview(Mesh{}, {}, {}, nullptr, small(PreviewView::kPatches), out).code(), ErrorCode::kInvalidMesh);
  Mesh broken = square;
  broken.indices[4] = 99;
  EXPECT_EQ(render_preview(broken, broken.corner_uvs, {}, nullptr, small(PreviewView::kTexture), out).code(),
            ErrorCode::kInvalidMesh);
  // Inconsistent texture image.
  Image bad_texture;
  bad_texture.width = bad_texture.height = 4;
  bad_texture.channels = 3;
  bad_texture.pixels.resize(5);
  EXPECT_EQ(render_preview(square, square.corner_uvs, {}, &bad_texture, small(PreviewView::kTexture), out).code(),
            ErrorCode::kInvalidImage);
}

// Width and height of the box around the pixels that differ from the background.
std::pair<int, int> covered_extent(const Image& img) {
  int x0 = img.width, y0 = img.height, x1 = -1, y1 = -1;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = pixel(img, x, y);
      if (std::abs(int{p[0]} - int{img.pixels[0]}) + std::abs(int{p[1]} - int{img.pixels[1]}) +
              std::abs(int{p[2]} - int{img.pixels[2]}) <=
          12)
        continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  return {x1 - x0 + 1, y1 - y0 + 1};
}

TEST(RenderPreview, UpAxisStandsAZUpPillarUpright) {
  const Mesh pillar = box(0.2f, 0.2f, 2.f);  // tall along z, as scans often are
  RenderOptions o = small(PreviewView::kPatches);
  o.yaw_degrees = 0.f;
  o.pitch_degrees = 0.f;
  o.up = UpAxis::kPosZ;
  const auto [w_up, h_up] = covered_extent(render_ok(pillar, nullptr, o));
  EXPECT_GT(h_up, 3 * w_up) << w_up << "x" << h_up;
  o.up = UpAxis::kPosY;  // seen end-on from +z: a small square
  const auto [w_y, h_y] = covered_extent(render_ok(pillar, nullptr, o));
  EXPECT_LT(h_y, 2 * w_y) << w_y << "x" << h_y;
  o.up = UpAxis::kNegZ;  // upside down, still upright
  const auto [w_down, h_down] = covered_extent(render_ok(pillar, nullptr, o));
  EXPECT_GT(h_down, 3 * w_down) << w_down << "x" << h_down;
  UpAxis parsed = UpAxis::kPosY;
  EXPECT_TRUE(up_axis_from_name("z", parsed));
  EXPECT_EQ(parsed, UpAxis::kPosZ);
  EXPECT_TRUE(up_axis_from_name("-x", parsed));
  EXPECT_EQ(parsed, UpAxis::kNegX);
  EXPECT_TRUE(up_axis_from_name("+y", parsed));
  EXPECT_EQ(parsed, UpAxis::kPosY);
  EXPECT_FALSE(up_axis_from_name("w", parsed));
  EXPECT_FALSE(up_axis_from_name("", parsed));
}

// Planar UVs from the mesh's x and y: `repeats` texture repeats across its bounding box; faces whose
// centroid lies right of the box's middle get their UVs turned by `quarter_turns` x 90 degrees about
// the UV origin and `shift` (repeats) added, which cuts the mesh there.
std::vector<float> planar_uvs(const Mesh& mesh, float repeats, float shift_u, float shift_v, int quarter_turns = 0) {
  float lo[2] = {1e30f, 1e30f}, hi[2] = {-1e30f, -1e30f};
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    for (size_t k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * v + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * v + k]);
    }
  const float size = std::max(hi[0] - lo[0], hi[1] - lo[1]), middle = 0.5f * (lo[0] + hi[0]);
  std::vector<float> uv(2 * mesh.indices.size());
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    float cx = 0;
    for (size_t k = 0; k < 3; ++k) cx += mesh.positions[3 * size_t{mesh.indices[3 * f + k]}] / 3;
    for (size_t k = 0; k < 3; ++k) {
      const float* p = &mesh.positions[3 * size_t{mesh.indices[3 * f + k]}];
      float u = (p[0] - lo[0]) / size * repeats, v = (p[1] - lo[1]) / size * repeats;
      if (cx > middle) {
        for (int t = 0; t < quarter_turns; ++t) u = -std::exchange(v, u);  // (u, v) -> (-v, u)
        u += shift_u;
        v += shift_v;
      }
      uv[6 * f + 2 * k] = u;
      uv[6 * f + 2 * k + 1] = v;
    }
  }
  return uv;
}

Image render_uv(const Mesh& mesh, std::span<const float> uv, const Image* texture, const RenderOptions& options) {
  Image out;
  const Status s = render_preview(mesh, uv, {}, texture, options, out);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return out;
}

// Pixels of one colour (within 40 per channel).
std::vector<uint8_t> pixels_near(const Image& img, const std::array<int, 3>& rgb) {
  std::vector<uint8_t> mask(static_cast<size_t>(img.width) * static_cast<size_t>(img.height), 0);
  for (size_t i = 0; i < mask.size(); ++i) {
    bool near = true;
    for (size_t c = 0; c < 3; ++c) near = near && std::abs(int{img.pixels[3 * i + c]} - rgb[c]) <= 40;
    mask[i] = near ? 1 : 0;
  }
  return mask;
}

size_t count(const std::vector<uint8_t>& mask) { return static_cast<size_t>(std::count(mask.begin(), mask.end(), 1)); }

// Mean luminance gradient (central differences) over the masked pixels.
double mean_gradient(const Image& img, const std::vector<uint8_t>& mask) {
  const auto lum = [&](int x, int y) {
    const uint8_t* p =
        &img.pixels[3 * (static_cast<size_t>(y) * static_cast<size_t>(img.width) + static_cast<size_t>(x))];
    return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
  };
  double sum = 0;
  size_t n = 0;
  for (int y = 1; y + 1 < img.height; ++y)
    for (int x = 1; x + 1 < img.width; ++x) {
      if (!mask[static_cast<size_t>(y) * static_cast<size_t>(img.width) + static_cast<size_t>(x)]) continue;
      sum += std::abs(lum(x + 1, y) - lum(x - 1, y)) + std::abs(lum(x, y + 1) - lum(x, y - 1));
      ++n;
    }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

// Issue 14's proof in pixels, on a shared mesh with the gravel tile: spot cut in two with the
// right half's UVs shifted by whole repeats (an invisible seam, green in the seams view) renders
// exactly as the uncut mesh; shifted by a fraction of a repeat (a visible seam, red) the texture
// jumps across the cut: the luminance gradient along the seam's pixels rises well above the
// uncut rendering's there.
TEST(RenderPreview, InvisibleSeamsDoNotJumpInPixelsAndVisibleOnesDo) {
  const Mesh mesh = load_test_mesh("spot.obj");
  Image gravel;
  ASSERT_TRUE(load_image(kData + "textures/gravel-gray-512.png", gravel).is_ok());
  // 0.4 repeats across the mesh: each texel covers a few pixels, so neighbouring pixels of a
  // continuous texture are alike and a cut shows.
  const std::vector<float> uncut = planar_uvs(mesh, 0.4f, 0, 0);
  const std::vector<float> whole = planar_uvs(mesh, 0.4f, 1, -2);
  const std::vector<float> fraction = planar_uvs(mesh, 0.4f, 0.37f, 0.21f);
  RenderOptions seams = small(PreviewView::kSeams);
  seams.width = 640;
  seams.height = 480;
  const auto green = [](const Image& img) { return pixels_near(img, {20, 170, 60}); };
  const auto red = [](const Image& img) { return pixels_near(img, {225, 30, 30}); };
  const Image seams_whole = render_uv(mesh, whole, &gravel, seams);
  const Image seams_fraction = render_uv(mesh, fraction, &gravel, seams);
  EXPECT_GT(count(green(seams_whole)), 100u);
  EXPECT_EQ(count(red(seams_whole)), 0u);
  const std::vector<uint8_t> cut = red(seams_fraction);
  EXPECT_GT(count(cut), 100u);
  EXPECT_EQ(count(green(seams_fraction)), 0u);

  RenderOptions texture = seams;
  texture.view = PreviewView::kTexture;
  const Image a = render_uv(mesh, uncut, &gravel, texture);
  const Image b = render_uv(mesh, whole, &gravel, texture);
  const Image c = render_uv(mesh, fraction, &gravel, texture);
  EXPECT_LT(mean_abs_difference(a, b), 0.05);  // the invisible cut renders as no cut at all
  EXPECT_GT(mean_abs_difference(a, c), 1.0);   // the shifted half shows other texels
  const double along_uncut = mean_gradient(a, cut), along_whole = mean_gradient(b, cut);
  const double along_fraction = mean_gradient(c, cut);
  EXPECT_NEAR(along_whole, along_uncut, 0.05 * along_uncut + 0.1);
  EXPECT_GT(along_fraction, 1.5 * along_uncut) << along_fraction << " vs " << along_uncut;
}

// The same for symmetry 4 (issue 14, point 4): spot's right half turned by a quarter turn plus
// whole repeats. Under the gravel tile made 4-fold by make_tileable (unchanged by a quarter turn
// about its corner) it renders as the uncut mesh and the seams view (seam_symmetry 4) draws the
// cut green; under the plain gravel tile the same cut is red and the texture jumps across it.
TEST(RenderPreview, QuarterTurnSeamsDoNotJumpUnderAFourFoldTile) {
  const Mesh mesh = load_test_mesh("spot.obj");
  Image gravel, plain, four_fold;
  ASSERT_TRUE(load_image(kData + "textures/gravel-gray-512.png", gravel).is_ok());
  TileOptions tiling;
  ASSERT_TRUE(make_tileable(gravel, tiling, plain).is_ok());
  tiling.symmetry = 4;
  ASSERT_TRUE(make_tileable(gravel, tiling, four_fold).is_ok());
  const std::vector<float> uncut = planar_uvs(mesh, 0.4f, 0, 0);
  const std::vector<float> turned = planar_uvs(mesh, 0.4f, 2, -1, 1);
  RenderOptions seams = small(PreviewView::kSeams);
  seams.width = 640;
  seams.height = 480;
  const auto green = [](const Image& img) { return pixels_near(img, {20, 170, 60}); };
  const auto red = [](const Image& img) { return pixels_near(img, {225, 30, 30}); };
  const Image seams_plain = render_uv(mesh, turned, &four_fold, seams);  // seam_symmetry 1: a turn is visible
  seams.seam_symmetry = 4;
  const Image seams_four_fold = render_uv(mesh, turned, &four_fold, seams);
  const std::vector<uint8_t> cut = red(seams_plain);
  EXPECT_GT(count(cut), 100u);
  EXPECT_EQ(count(green(seams_plain)), 0u);
  EXPECT_GT(count(green(seams_four_fold)), 100u);
  EXPECT_EQ(count(red(seams_four_fold)), 0u);

  RenderOptions texture = seams;
  texture.view = PreviewView::kTexture;
  const Image a = render_uv(mesh, uncut, &four_fold, texture);
  const Image b = render_uv(mesh, turned, &four_fold, texture);
  EXPECT_LT(mean_abs_difference(a, b), 0.05);  // the quarter-turn cut renders as no cut at all
  const double along_uncut = mean_gradient(a, cut), along_turned = mean_gradient(b, cut);
  EXPECT_NEAR(along_turned, along_uncut, 0.05 * along_uncut + 0.1);
  const Image c = render_uv(mesh, uncut, &plain, texture);
  const Image d = render_uv(mesh, turned, &plain, texture);
  EXPECT_GT(mean_abs_difference(c, d), 1.0);  // the plain tile turned shows other texels
  const double along_plain = mean_gradient(c, cut), along_plain_turned = mean_gradient(d, cut);
  // Measured 1.47x (the whole-repeat test's fractional shift: over 1.5x); the 4-fold tile within 5 %.
  EXPECT_GT(along_plain_turned, 1.3 * along_plain) << along_plain_turned << " vs " << along_plain;
}

// === Material: normal and occlusion maps (PreviewMaterial) ======================================

//! A w x h RGB image of one colour.
Image constant_image(int w, int h, std::array<uint8_t, 3> rgb) {
  Image img{w, h, 3, {}};
  for (int i = 0; i < w * h; ++i) img.pixels.insert(img.pixels.end(), rgb.begin(), rgb.end());
  return img;
}

//! A tangent-space normal map (GL convention: +Y up the image) from the grey levels of `image`
//! taken as heights, wrapping at the borders.
Image bump_normals(const Image& image, float strength) {
  const int w = image.width, h = image.height, ch = image.channels;
  auto height = [&](int x, int y) {
    return image.pixels[(size_t((y + h) % h) * size_t(w) + size_t((x + w) % w)) * size_t(ch)] / 255.0f;
  };
  Image n{w, h, 3, {}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float dx = (height(x + 1, y) - height(x - 1, y)) * strength;
      const float dy = (height(x, y - 1) - height(x, y + 1)) * strength;  // rows run down, +Y up
      const float l = std::sqrt(dx * dx + dy * dy + 1.0f);
      for (const float c : {-dx / l, -dy / l, 1.0f / l})
        n.pixels.push_back(static_cast<uint8_t>(std::lround((c * 0.5f + 0.5f) * 255.0f)));
    }
  return n;
}

Image render_material(const Mesh& mesh, const Image* texture, const PreviewMaterial& material,
                      const RenderOptions& options) {
  Image out;
  const Status s = render_preview(mesh, mesh.corner_uvs, {}, texture, material, options, out);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return out;
}

TEST(RenderMaterial, NormalMapTurnsTheLightByTheTangentFrame) {
  // A white square facing the camera (+z), u along +x and v along +y; one constant normal map per
  // case. The light comes from the upper left (eye space (-0.35, 0.55, 0.76)), so a normal tilted
  // left or up must brighten and one tilted right or down darken, by exactly the diffuse term:
  // level = 255 * (0.36 + 0.72 * max(0, n . l)), n the map's decoded normal in (t, b, n) = (x, y, z).
  const Mesh square = unit_square();
  const Image white = constant_image(4, 4, {255, 255, 255});
  RenderOptions o = small(PreviewView::kTexture);
  o.yaw_degrees = 0.0f;
  o.pitch_degrees = 0.0f;
  const double light[3] = {-0.35, 0.55, 0.76};
  const double light_length = std::sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
  std::vector<int> levels;
  for (const std::array<float, 2> tilt :
       {std::array<float, 2>{0, 0}, {-0.45f, 0}, {0.45f, 0}, {0, 0.45f}, {0, -0.45f}}) {
    const float z = std::sqrt(1.0f - tilt[0] * tilt[0] - tilt[1] * tilt[1]);
    std::array<uint8_t, 3> rgb{};
    double n[3];
    for (int c = 0; c < 3; ++c) {
      rgb[c] = static_cast<uint8_t>(std::lround(((c < 2 ? tilt[c] : z) * 0.5 + 0.5) * 255.0));
      n[c] = rgb[c] / 255.0 * 2.0 - 1.0;  // what the shader decodes
    }
    const Image map = constant_image(4, 4, rgb);
    PreviewMaterial material;
    material.normal = &map;
    const Image img = render_material(square, &white, material, o);
    const double nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double diffuse = std::max(0.0, (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / (nl * light_length));
    const double expected = 255.0 * std::min(1.0, 0.36 + 0.72 * diffuse);
    const uint8_t* centre = pixel(img, img.width / 2, img.height / 2);
    EXPECT_NEAR(centre[0], expected, 2.0) << "tilt " << tilt[0] << "," << tilt[1];
    levels.push_back(centre[0]);
  }
  EXPECT_GT(levels[1], levels[0] + 10);  // left: towards the light
  EXPECT_LT(levels[2], levels[0] - 10);  // right: away
  EXPECT_GT(levels[3], levels[0] + 10);  // up: towards
  EXPECT_LT(levels[4], levels[0] - 10);  // down: away
}

TEST(RenderMaterial, BumpyNormalMapChangesLitPixelsAndAFlatOneDoesNot) {
  const Fixture& f = spot();
  const RenderOptions o = small(PreviewView::kTexture);
  const Image none = render_material(f.mesh, &f.texture, PreviewMaterial{}, o);
  const Image bumps = bump_normals(f.texture, 6.0f);
  const Image flat = constant_image(f.texture.width, f.texture.height, {128, 128, 255});
  PreviewMaterial bumpy, flat_material;
  bumpy.normal = &bumps;
  flat_material.normal = &flat;
  const Image with_bumps = render_material(f.mesh, &f.texture, bumpy, o);
  const Image with_flat = render_material(f.mesh, &f.texture, flat_material, o);
  // The plain overload is the same picture as no material.
  EXPECT_EQ(render_ok(f.mesh, &f.texture, o).pixels, none.pixels);
  // Lit surface pixels (not background, bright enough to be lit): the bumps move them, the flat map not.
  size_t lit = 0, moved = 0;
  int flat_worst = 0;
  double bump_sum = 0;
  for (size_t i = 0; i < none.pixels.size(); i += 3) {
    const uint8_t* p = &none.pixels[i];
    const bool background = p[0] == 236 && p[1] == 238 && p[2] == 242;
    for (size_t c = 0; c < 3; ++c)
      flat_worst = std::max(flat_worst, std::abs(int{with_flat.pixels[i + c]} - int{none.pixels[i + c]}));
    if (background || p[0] + p[1] + p[2] < 3 * 60) continue;
    ++lit;
    const int d = std::abs(int{with_bumps.pixels[i]} - int{p[0]});
    bump_sum += d;
    moved += d > 2;
  }
  ASSERT_GT(lit, size_t{5000});
  EXPECT_LE(flat_worst, 2);
  EXPECT_GT(static_cast<double>(moved) / static_cast<double>(lit), 0.3) << moved << " of " << lit;
  EXPECT_GT(bump_sum / static_cast<double>(lit), 4.0);
}

TEST(RenderMaterial, OcclusionDarkensAndFileTangentsAreUsed) {
  const Fixture& f = spot();
  const RenderOptions o = small(PreviewView::kTexture);
  const Image none = render_material(f.mesh, &f.texture, PreviewMaterial{}, o);
  const Image half = constant_image(8, 8, {128, 128, 128});
  PreviewMaterial occluded;
  occluded.occlusion = &half;
  const Image dark = render_material(f.mesh, &f.texture, occluded, o);
  EXPECT_LT(mean_abs_difference(dark, none), 40.0);
  EXPECT_GT(mean_abs_difference(dark, none), 1.0);
  double sum_none = 0, sum_dark = 0;
  for (size_t i = 0; i < none.pixels.size(); ++i) sum_none += none.pixels[i], sum_dark += dark.pixels[i];
  EXPECT_LT(sum_dark, sum_none);

  // Tangents given per corner are the frame: the UVs' own frames give the computed picture, the
  // same frames turned a quarter (t -> b) another.
  const Image bumps = bump_normals(f.texture, 6.0f);
  std::vector<float> tangents;
  ASSERT_TRUE(corner_tangents(f.mesh, f.mesh.corner_uvs, tangents).is_ok());
  ASSERT_EQ(tangents.size(), 4 * f.mesh.indices.size());
  PreviewMaterial computed, given;
  computed.normal = given.normal = &bumps;
  given.corner_tangents = tangents;
  const Image a = render_material(f.mesh, &f.texture, computed, o);
  const Image b = render_material(f.mesh, &f.texture, given, o);
  EXPECT_LT(mean_abs_difference(a, b), 0.05);
  std::vector<float> flipped = tangents;
  for (size_t c = 0; c < flipped.size(); c += 4) flipped[c + 3] = -flipped[c + 3];  // the bitangent reversed
  given.corner_tangents = flipped;
  EXPECT_GT(mean_abs_difference(render_material(f.mesh, &f.texture, given, o), a), 1.0);

  // Bad material input is refused.
  Image out;
  given.corner_tangents = std::span<const float>(tangents).first(8);
  EXPECT_EQ(render_preview(f.mesh, f.mesh.corner_uvs, {}, &f.texture, given, o, out).code(),
            ErrorCode::kInvalidArgument);
  Image grey1{4, 4, 1, std::vector<uint8_t>(16, 128)};
  PreviewMaterial not_rgb;
  not_rgb.normal = &grey1;
  EXPECT_EQ(render_preview(f.mesh, f.mesh.corner_uvs, {}, &f.texture, not_rgb, o, out).code(),
            ErrorCode::kInvalidImage);
  EXPECT_TRUE(out.empty());
}

TEST(RenderPreview, ViewNamesRoundTrip) {
  for (const PreviewView view : {PreviewView::kTexture, PreviewView::kPatches, PreviewView::kDistortion,
                                 PreviewView::kChecker, PreviewView::kSeams}) {
    PreviewView parsed = PreviewView::kTexture;
    ASSERT_TRUE(preview_view_from_name(preview_view_name(view), parsed));
    EXPECT_EQ(parsed, view);
  }
  PreviewView parsed = PreviewView::kChecker;
  EXPECT_FALSE(preview_view_from_name("normals", parsed));
  EXPECT_FALSE(preview_view_from_name("", parsed));
  EXPECT_EQ(parsed, PreviewView::kChecker);
}

}  // namespace
}  // namespace tailor
