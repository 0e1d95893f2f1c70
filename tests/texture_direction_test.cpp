// Texture isotropy: the photos without a direction (gravel, grass, caustics) read isotropic and
// are mapped with rigid unfolding; those with one (bark, ripples, bricks, weaves, tiles) are not.
#include "tailor/texture_direction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tailor/image.h"

namespace tailor {
namespace {

const std::string kData = std::string(TAILOR_TEST_DATA) + "/textures/";

Image load(const std::string& name) {
  Image image;
  EXPECT_TRUE(load_image(kData + name, image)) << name;
  return image;
}

// The same pixels turned by 90 degrees (clockwise).
Image turned(const Image& in) {
  Image out;
  out.width = in.height;
  out.height = in.width;
  out.channels = in.channels;
  out.pixels.resize(in.pixels.size());
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x)
      for (int c = 0; c < in.channels; ++c)
        out.pixels[(static_cast<size_t>(x) * out.width + (in.height - 1 - y)) * in.channels + c] =
            in.pixels[(static_cast<size_t>(y) * in.width + x) * in.channels + c];
  return out;
}

TEST(TextureDirection, StochasticPhotosAreIsotropic) {
  for (const char* name : {"gravel-gray-512.png", "grass-gray-512.png", "water-caustics-300.jpg"}) {
    const Image image = load(name);
    const float isotropy = texture_isotropy(image);
    EXPECT_GE(isotropy, kIsotropicTextureAbove) << name;
    EXPECT_FALSE(texture_has_direction(image)) << name;
    // Turning the photo changes which bins fill, not how evenly.
    EXPECT_NEAR(texture_isotropy(turned(image)), isotropy, 0.05f) << name;
  }
}

TEST(TextureDirection, DirectionalAndRegularPhotosAreNot) {
  for (const char* name : {"brick-gray-512.png", "vistex-bark11-128.png", "vistex-sand05-128.png",
                           "vistex-fabric02-128.png", "vistex-tile04-128.png"}) {
    const Image image = load(name);
    EXPECT_LT(texture_isotropy(image), kIsotropicTextureAbove) << name;
    EXPECT_TRUE(texture_has_direction(image)) << name;
  }
}

TEST(TextureDirection, StripesFlatAndMissingTextures) {
  Image stripes;
  stripes.width = stripes.height = 64;
  stripes.channels = 1;
  stripes.pixels.resize(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      stripes.pixels[static_cast<size_t>(y) * 64 + x] =
          static_cast<uint8_t>(127.5 + 127.5 * std::sin(2.0 * 3.14159265358979 * x / 16.0));
  EXPECT_LT(texture_isotropy(stripes), 0.01f);
  EXPECT_LT(texture_isotropy(turned(stripes)), 0.01f);

  Image flat = stripes;
  flat.pixels.assign(flat.pixels.size(), 90);
  EXPECT_EQ(texture_isotropy(flat), 1.f);
  EXPECT_TRUE(texture_has_direction(Image{}));  // no texture: follow the field (thesis)
}

TEST(TextureDirection, AdaptsTheMappingOnlyForTexturesWithoutDirection) {
  MappingOptions options;
  adapt_mapping_to_texture(load("vistex-bark11-128.png"), options);
  EXPECT_EQ(options.field_following, MappingOptions{}.field_following);
  EXPECT_EQ(options.crack_rings, MappingOptions{}.crack_rings);
  EXPECT_EQ(adapt_mapping_to_texture(Image{}, options), -1.f);
  EXPECT_EQ(options.field_following, MappingOptions{}.field_following);
  adapt_mapping_to_texture(load("gravel-gray-512.png"), options);
  EXPECT_EQ(options.field_following, 0.f);
  EXPECT_EQ(options.crack_rings, kUndirectedCrackRings);
  // Crack rings the user chose stay; the field following still goes to 0.
  MappingOptions chosen;
  chosen.crack_rings = 5;
  adapt_mapping_to_texture(load("gravel-gray-512.png"), chosen, true);
  EXPECT_EQ(chosen.field_following, 0.f);
  EXPECT_EQ(chosen.crack_rings, 5u);
}

}  // namespace
}  // namespace tailor
