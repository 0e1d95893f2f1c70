// Colours and legend text of the preview pictures (preview_scene.cpp): distinct patch colours,
// the diverging heat map of the distortion view, and a tiny bitmap font stamped into the final
// RGB image for the legend labels (text drawn on the CPU keeps the GL part free of font code).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>

#include "tailor/image.h"

namespace tailor::internal {

using Rgb = std::array<uint8_t, 3>;

inline uint8_t to_byte(float v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

//! A distinct, deterministic colour per patch id: hues stepped by the golden ratio so that
//! neighbouring ids (often neighbouring patches) differ strongly; saturation and value vary a
//! little so that ids with close hues still differ.
inline Rgb patch_color(uint32_t id) {
  constexpr double kGolden = 0.6180339887498949;
  const double hue = std::fmod(0.11 + kGolden * static_cast<double>(id), 1.0) * 6.0;
  const float sat = 0.45f + 0.25f * static_cast<float>((id * 7u) % 3u) / 2.0f;
  const float val = 0.95f - 0.15f * static_cast<float>((id * 5u) % 2u);
  const int sector = static_cast<int>(hue) % 6;
  const float frac = static_cast<float>(hue - std::floor(hue));
  const float p = val * (1.0f - sat);
  const float q = val * (1.0f - sat * frac);
  const float t = val * (1.0f - sat * (1.0f - frac));
  float r = val, g = t, b = p;
  switch (sector) {
    case 0:
      r = val;
      g = t;
      b = p;
      break;
    case 1:
      r = q;
      g = val;
      b = p;
      break;
    case 2:
      r = p;
      g = val;
      b = t;
      break;
    case 3:
      r = p;
      g = q;
      b = val;
      break;
    case 4:
      r = t;
      g = p;
      b = val;
      break;
    default:
      r = val;
      g = p;
      b = q;
      break;
  }
  return {to_byte(r), to_byte(g), to_byte(b)};
}

//! Diverging blue-white-red map (Moreland's "cool to warm" end points) for t in [-1, 1]:
//! -1 = shrunk in UV (blue), 0 = ideal (near white), +1 = enlarged in UV (red).
inline Rgb heat_color(float t) {
  constexpr std::array<float, 3> kCold = {0.230f, 0.299f, 0.754f};
  constexpr std::array<float, 3> kMid = {0.865f, 0.865f, 0.865f};
  constexpr std::array<float, 3> kWarm = {0.706f, 0.016f, 0.150f};
  t = std::clamp(t, -1.0f, 1.0f);
  const auto& end = t < 0.0f ? kCold : kWarm;
  const float w = std::fabs(t);
  Rgb c{};
  for (int k = 0; k < 3; ++k) c[k] = to_byte(kMid[k] + (end[k] - kMid[k]) * w);
  return c;
}

// === A 5x7 bitmap font for the legend labels ======================================================

//! Rows top to bottom, bit 4 = leftmost column. Only the characters the legend needs.
inline const std::array<uint8_t, 7>* glyph(char ch) {
  static constexpr std::array<std::array<uint8_t, 7>, 13> kGlyphs = {{
      {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E},  // 0
      {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},  // 1
      {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F},  // 2
      {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},  // 3
      {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02},  // 4
      {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},  // 5
      {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E},  // 6
      {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},  // 7
      {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E},  // 8
      {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},  // 9
      {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C},  // .
      {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11},  // x
      {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},  // space
  }};
  if (ch >= '0' && ch <= '9') return &kGlyphs[static_cast<size_t>(ch - '0')];
  if (ch == '.') return &kGlyphs[10];
  if (ch == 'x') return &kGlyphs[11];
  if (ch == ' ') return &kGlyphs[12];
  return nullptr;
}

//! Width in pixels of `text` drawn at `scale` image pixels per font pixel (6 columns per glyph).
inline int text_width(std::string_view text, int scale) {
  return text.empty() ? 0 : (static_cast<int>(text.size()) * 6 - 1) * scale;
}

//! Stamps `text` into an RGB image with its top-left corner at (x, y); clipped to the image.
inline void draw_text(Image& image, std::string_view text, int x, int y, int scale, Rgb color) {
  for (const char ch : text) {
    const auto* rows = glyph(ch);
    if (rows != nullptr) {
      for (int r = 0; r < 7; ++r) {
        for (int c = 0; c < 5; ++c) {
          if (((*rows)[static_cast<size_t>(r)] >> (4 - c) & 1) == 0) continue;
          for (int dy = 0; dy < scale; ++dy) {
            for (int dx = 0; dx < scale; ++dx) {
              const int px = x + c * scale + dx;
              const int py = y + r * scale + dy;
              if (px < 0 || py < 0 || px >= image.width || py >= image.height) continue;
              const size_t at =
                  (static_cast<size_t>(py) * static_cast<size_t>(image.width) + static_cast<size_t>(px)) * 3;
              image.pixels[at] = color[0];
              image.pixels[at + 1] = color[1];
              image.pixels[at + 2] = color[2];
            }
          }
        }
      }
    }
    x += 6 * scale;
  }
}

}  // namespace tailor::internal
