// EXIF orientation of JPEG files (src/io/exif_orientation.h). stb_image decodes the stored rows
// and ignores the tag; the few fields read here are all that showing the picture upright needs.
#include "io/exif_orientation.h"

#include <cstring>
#include <utility>
#include <vector>

namespace tailor::internal {

int jpeg_exif_orientation(std::span<const unsigned char> bytes) {
  const unsigned char* p = bytes.data();
  const size_t n = bytes.size();
  if (n < 4 || p[0] != 0xFF || p[1] != 0xD8) return 1;
  size_t i = 2;
  while (i + 4 <= n && p[i] == 0xFF) {
    const unsigned marker = p[i + 1];
    if (marker == 0xDA || marker == 0xD9) break;  // start of scan, end of image: no EXIF before
    const size_t length = (size_t{p[i + 2]} << 8) | p[i + 3];
    if (length < 2 || i + 2 + length > n) break;
    const unsigned char* s = p + i + 4;
    const size_t size = length - 2;
    if (marker == 0xE1 && size >= 14 && std::memcmp(s, "Exif\0\0", 6) == 0) {
      const unsigned char* tiff = s + 6;
      const size_t tiff_size = size - 6;
      const bool little = tiff[0] == 'I' && tiff[1] == 'I';
      if (!little && !(tiff[0] == 'M' && tiff[1] == 'M')) return 1;
      const auto u16 = [&](size_t o) -> uint32_t {
        return little ? (uint32_t{tiff[o]} | (uint32_t{tiff[o + 1]} << 8)) : ((uint32_t{tiff[o]} << 8) | tiff[o + 1]);
      };
      const auto u32 = [&](size_t o) -> uint32_t {
        return little ? (u16(o) | (u16(o + 2) << 16)) : ((u16(o) << 16) | u16(o + 2));
      };
      const size_t ifd = u32(4);
      if (ifd + 2 > tiff_size) return 1;
      const size_t entries = u16(ifd);
      for (size_t k = 0; k < entries; ++k) {
        const size_t e = ifd + 2 + 12 * k;
        if (e + 12 > tiff_size) return 1;
        if (u16(e) == 0x0112 && u16(e + 2) == 3) {  // Orientation, SHORT: the value in the entry
          const uint32_t v = u16(e + 8);
          return v >= 1 && v <= 8 ? static_cast<int>(v) : 1;
        }
      }
      return 1;
    }
    i += 2 + length;
  }
  return 1;
}

void apply_exif_orientation(int orientation, Image& image) {
  if (orientation < 2 || orientation > 8) return;
  const int w = image.width, h = image.height, c = image.channels;
  const bool swap = orientation >= 5;
  const int ow = swap ? h : w, oh = swap ? w : h;
  std::vector<uint8_t> out(image.pixels.size());
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      // The stored pixel shown at (x, y).
      int sx = x, sy = y;
      switch (orientation) {
        case 2: sx = w - 1 - x; break;
        case 3: sx = w - 1 - x, sy = h - 1 - y; break;
        case 4: sy = h - 1 - y; break;
        case 5: sx = y, sy = x; break;
        case 6: sx = y, sy = h - 1 - x; break;
        case 7: sx = w - 1 - y, sy = h - 1 - x; break;
        default: sx = w - 1 - y, sy = x; break;  // 8
      }
      std::memcpy(&out[(static_cast<size_t>(y) * ow + x) * c], &image.pixels[(static_cast<size_t>(sy) * w + sx) * c],
                  static_cast<size_t>(c));
    }
  image.pixels = std::move(out);
  image.width = ow;
  image.height = oh;
}

}  // namespace tailor::internal
