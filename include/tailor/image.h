// tailor: images.
//
// Layout, stated exactly (as stb_image does): pixels are stored row by row, top row first; within
// a row left to right; within a pixel `channels` interleaved samples (1 grey, 2 grey+alpha,
// 3 RGB, 4 RGBA). Sample (x, y, c) is at index (y * width + x) * channels + c.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tailor/api.h"
#include "tailor/option_doc.h"
#include "tailor/status.h"

namespace tailor {

//! 8-bit image, layout above.
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<uint8_t> pixels;  //!< width * height * channels samples
  bool empty() const { return pixels.empty(); }
};

//! Float image, same layout, samples in [0, 1] for images converted from 8 bits.
struct ImageF {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;
  bool empty() const { return pixels.empty(); }
};

//! 8- or 16-bit image (the two depths of PNG), same layout; samples lie in [0, 2^bits - 1] and are
//! stored in 16 bits whatever the depth. Map sets (tiling.h) use it so that 16-bit height maps keep
//! their precision.
struct Image16 {
  int width = 0;
  int height = 0;
  int channels = 0;
  int bits = 8;                  //!< 8 or 16
  std::vector<uint16_t> pixels;  //!< width * height * channels samples
  bool empty() const { return pixels.empty(); }
};

//! Largest width or height accepted by the readers (absurd sizes are rejected before decoding).
inline constexpr int kMaxImageSide = 16384;

//! Checks that an Image is consistent: 1 <= width, height <= kMaxImageSide, 1 <= channels <= 4
//! and pixels.size() == width * height * channels. Fails with kInvalidImage saying which.
TAILOR_API Status check_image(const Image& image);

//! Limits on the images a reader accepts, checked from the header before anything is decoded.
struct ImageLoadOptions {
  uint64_t max_pixels = uint64_t{64} << 20;  //!< largest width x height (64 Mpx: 8192 x 8192)
  bool exif_orientation = true;              //!< a JPEG turned upright as its EXIF orientation says, as photo viewers
                                             //!< show it; false: its stored rows, as glTF viewers show a texture
};

//! Flags and help of the ImageLoadOptions a user sets (option_doc.h).
inline constexpr OptionDoc kImageLoadOptionDocs[] = {
    {"max_pixels", "--max-image-pixels",
     "Largest input image accepted, in pixels (width x height), checked from its header before decoding; "
     "each side is also limited to 16384 px"},
};

//! Reads PNG (8 or 16 bit; 16-bit is reduced to 8: see load_image16), JPEG, TGA, BMP or binary PPM/PGM with 1-4
//! channels. Untrusted input: before decoding, the header's size is checked against kMaxImageSide
//! and options.max_pixels, and for uncompressed formats (TGA, BMP, PPM/PGM) against the file's
//! length (a 30-byte file claiming 4000 x 4000 px is refused as truncated without allocating).
//! Fails with kIo (open, read, not a regular file), kInvalidImage (too large, truncated, corrupt).
TAILOR_API Status load_image(const std::string& path, Image& image, const ImageLoadOptions& options = {});

//! Writes a PNG atomically (temporary file, then rename).
TAILOR_API Status write_png(const std::string& path, const Image& image);

//! Like load_image, but a 16-bit PNG keeps its 16 bits (bits = 16); every other image is read
//! as 8 bits (bits = 8, samples widened to 16-bit storage). Same checks and errors.
TAILOR_API Status load_image16(const std::string& path, Image16& image, const ImageLoadOptions& options = {});

//! Writes an 8- or 16-bit PNG (by image.bits) atomically. Fails with kInvalidImage for an
//! inconsistent image (sizes as check_image, bits not 8 or 16, a sample above 2^bits - 1).
TAILOR_API Status write_png16(const std::string& path, const Image16& image);

//! The PNG file's bytes of an 8- or 16-bit image (as write_png16 writes, in memory): for embedding.
TAILOR_API Status encode_png16(const Image16& image, std::string& encoded);

//! The PNG file's bytes of an 8-bit image (as write_png writes, in memory).
TAILOR_API Status encode_png(const Image& image, std::string& encoded);

//! The 8-bit image of an Image16: 16-bit samples scaled by 255 / 65535 and rounded.
TAILOR_API Image to_image8(const Image16& image);

//! The Image16 (bits = 8) of an 8-bit image.
TAILOR_API Image16 to_image16(const Image& image);

}  // namespace tailor
