// Isotropy of a texture from the angular spread of its gradient energy (texture_direction.h).
#include "tailor/texture_direction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace tailor {
namespace {

constexpr int kMinSide = 16;  // a reduced image smaller than this says nothing: skipped
constexpr double kPi = 3.14159265358979323846;

// Luminance (Rec. 601, as image_ops' to_grey; alpha ignored) of pixel i.
float luminance(const Image& image, size_t i) {
  const uint8_t* p = &image.pixels[i * static_cast<size_t>(image.channels)];
  return image.channels >= 3 ? 0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2] : static_cast<float>(p[0]);
}

// Luminance averaged over factor x factor blocks (the remainder rows/columns are dropped).
std::vector<float> box_reduce(const Image& image, int factor, int& width, int& height) {
  width = image.width / factor;
  height = image.height / factor;
  std::vector<float> out(static_cast<size_t>(width) * height, 0.f);
  const float norm = 1.f / static_cast<float>(factor * factor);
  for (int y = 0; y < height * factor; ++y)
    for (int x = 0; x < width * factor; ++x)
      out[static_cast<size_t>(y / factor) * width + x / factor] +=
          norm * luminance(image, static_cast<size_t>(y) * image.width + x);
  return out;
}

// 1 minus the strongest of the angular harmonics of order 2, 4 and 6 of the gradient energy
// (one dominant direction, two axes as in bricks and weaves, three as in hexagonal tiles), each
// normalised by the total energy: 1 for energy spread evenly over the directions, 0 for stripes.
// Central differences with wrap-around (textures meant to tile have no border).
// progress (may be empty) gets [from, to) as the rows go, every 64 rows.
float isotropy_at(const std::vector<float>& g, int width, int height, const ProgressCallback& progress = {},
                  float from = 0.f, float to = 1.f) {
  double total = 0.0;
  std::array<double, 3> re{}, im{};
  for (int y = 0; y < height; ++y) {
    if (progress && y % 64 == 0)
      (void)progress(from + (to - from) * static_cast<float>(y) / static_cast<float>(height));
    const float* up = &g[static_cast<size_t>((y + height - 1) % height) * width];
    const float* row = &g[static_cast<size_t>(y) * width];
    const float* down = &g[static_cast<size_t>((y + 1) % height) * width];
    for (int x = 0; x < width; ++x) {
      const double gx = row[(x + 1) % width] - row[(x + width - 1) % width];
      const double gy = down[x] - up[x];
      const double m = gx * gx + gy * gy;
      if (m == 0.0) continue;
      const double angle = std::atan2(gy, gx);
      total += m;
      for (int k = 0; k < 3; ++k) {
        re[k] += m * std::cos(2.0 * (k + 1) * angle);
        im[k] += m * std::sin(2.0 * (k + 1) * angle);
      }
    }
  }
  if (total <= 0.0) return 1.f;
  double strongest = 0.0;
  for (int k = 0; k < 3; ++k) strongest = std::max(strongest, std::hypot(re[k], im[k]) / total);
  return static_cast<float>(1.0 - strongest);
}

}  // namespace

float texture_isotropy(const Image& texture) { return texture_isotropy(texture, {}); }

float texture_isotropy(const Image& texture, const ProgressCallback& progress) {
  if (!check_image(texture)) return 1.f;
  float isotropy = 1.f;
  bool measured = false;
  for (int factor : {2, 4}) {
    int width = 0, height = 0;
    if (texture.width / factor < kMinSide || texture.height / factor < kMinSide) continue;
    const std::vector<float> reduced = box_reduce(texture, factor, width, height);
    // The half-size pass has four times the pixels of the quarter-size one.
    isotropy = std::min(isotropy, factor == 2 ? isotropy_at(reduced, width, height, progress, 0.f, 0.8f)
                                              : isotropy_at(reduced, width, height, progress, 0.8f, 1.f));
    measured = true;
  }
  if (!measured && texture.width >= 3 && texture.height >= 3) {  // a tiny texture: its own pixels
    int width = 0, height = 0;
    isotropy = isotropy_at(box_reduce(texture, 1, width, height), width, height);
  }
  return isotropy;
}

bool texture_has_direction(const Image& texture) {
  return texture.empty() || texture_isotropy(texture) < kIsotropicTextureAbove;
}

float adapt_mapping_to_texture(const Image& texture, MappingOptions& options, bool keep_crack_rings,
                               const ProgressCallback& progress) {
  if (texture.empty()) return -1.f;
  const float isotropy = texture_isotropy(texture, progress);
  if (progress) (void)progress(1.f);
  if (isotropy >= kIsotropicTextureAbove) {
    options.field_following = 0.f;
    if (!keep_crack_rings) options.crack_rings = kUndirectedCrackRings;
  }
  return isotropy;
}

}  // namespace tailor
