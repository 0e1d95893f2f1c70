// Image I/O: every supported format reads back what was written, 16-bit PNGs are reduced to
// 8 bits, and broken or hostile files give a clear error instead of a crash or a huge allocation.
#include "tailor/image.h"

#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "io/readers.h"
#include "support/fixtures.h"
#include "tailor/image_ops.h"
#include "util/atomic_file.h"

// Compiled into libstb.so (C linkage) but declared only in stb_image_write's implementation part.
extern "C" unsigned char* stbi_zlib_compress(unsigned char* data, int data_len, int* out_len, int quality);

namespace tailor {
namespace {

const std::string kData = std::string(TAILOR_TEST_DATA) + "/textures/";

using test::temp_path;

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

uint32_t crc32(const std::string& bytes) {
  uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char ch : bytes) {
    crc ^= ch;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::string be32(uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

std::string chunk(const std::string& type, const std::string& data) {
  return be32(static_cast<uint32_t>(data.size())) + type + data + be32(crc32(type + data));
}

//! A PNG with the given header fields and raw (unfiltered) scanline bytes; `extra`: chunks between
//! the header and the data.
std::string make_png(uint32_t width, uint32_t height, int depth, int color_type, const std::string& raw,
                     const std::string& extra = "") {
  std::string ihdr = be32(width) + be32(height);
  ihdr += static_cast<char>(depth);
  ihdr += static_cast<char>(color_type);
  ihdr += std::string(3, '\0');
  int zlen = 0;
  std::string copy = raw;
  unsigned char* z =
      stbi_zlib_compress(reinterpret_cast<unsigned char*>(copy.data()), static_cast<int>(copy.size()), &zlen, 8);
  std::string idat(reinterpret_cast<char*>(z), static_cast<size_t>(zlen));
  std::free(z);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + extra + chunk("IDAT", idat) + chunk("IEND", "");
}

TEST(ImageIo, ReadsGreyPng) {
  Image im;
  ASSERT_TRUE(load_image(kData + "brick-gray-512.png", im).is_ok());
  EXPECT_EQ(im.width, 512);
  EXPECT_EQ(im.height, 512);
  EXPECT_EQ(im.channels, 1);
  EXPECT_EQ(im.pixels.size(), 512u * 512u);
}

TEST(ImageIo, ReadsRgbPngAndProgressiveJpeg) {
  Image png, jpg;
  ASSERT_TRUE(load_image(kData + "vistex-bark11-128.png", png).is_ok());
  EXPECT_EQ(png.channels, 3);
  EXPECT_EQ(png.width, 128);
  ASSERT_TRUE(load_image(kData + "water-caustics-300.jpg", jpg).is_ok());
  EXPECT_EQ(jpg.width, 300);  // EXIF says 535x534: the decoder must not trust it
  EXPECT_EQ(jpg.height, 300);
  EXPECT_EQ(jpg.channels, 3);
}

// A camera's JPEG: stored rows plus an EXIF Orientation tag. A 32 x 16 picture dark in its top-left
// quadrant only, tagged 1..8 (both TIFF byte orders), reads as viewers show it: the dark quadrant
// where EXIF puts it, width and height swapped for 5..8.
TEST(ImageIo, JpegExifOrientationIsApplied) {
  constexpr int kW = 32, kH = 16;
  std::vector<uint8_t> pixels(kW * kH, 230);
  for (int y = 0; y < kH / 2; ++y)
    for (int x = 0; x < kW / 2; ++x) pixels[static_cast<size_t>(y) * kW + x] = 20;
  const std::string plain = temp_path("upright.jpg");
  ASSERT_NE(stbi_write_jpg(plain.c_str(), kW, kH, 1, pixels.data(), 100), 0);
  std::ifstream in(plain, std::ios::binary);
  const std::string jpeg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Where the dark quadrant shows, per orientation: 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left.
  const int corner[9] = {0, 0, 1, 2, 3, 0, 1, 2, 3};
  for (const bool little : {true, false})
    for (int orientation = 1; orientation <= 8; ++orientation) {
      const std::string path = temp_path("turned" + std::to_string(orientation) + ".jpg");
      const std::string tagged = test::with_exif_orientation(jpeg, orientation, little);
      write_bytes(path, tagged);
      long header_w = 0, header_h = 0;  // the size a glTF's texture is measured by, without decoding
      ASSERT_TRUE(internal::image_header_size({reinterpret_cast<const unsigned char*>(tagged.data()), tagged.size()},
                                              header_w, header_h, true));
      EXPECT_EQ(header_w, orientation >= 5 ? kH : kW);
      ASSERT_TRUE(internal::image_header_size({reinterpret_cast<const unsigned char*>(tagged.data()), tagged.size()},
                                              header_w, header_h, false));
      EXPECT_EQ(header_w, kW);  // a glTF's texture: its stored rows
      Image stored;
      ImageLoadOptions as_stored;
      as_stored.exif_orientation = false;
      ASSERT_TRUE(load_image(path, stored, as_stored).is_ok());
      EXPECT_EQ(stored.width, kW);
      Image im;
      ASSERT_TRUE(load_image(path, im).is_ok());
      const bool swapped = orientation >= 5;
      ASSERT_EQ(im.width, swapped ? kH : kW) << orientation;
      ASSERT_EQ(im.height, swapped ? kW : kH) << orientation;
      const int qw = im.width / 2, qh = im.height / 2;
      for (int q = 0; q < 4; ++q) {
        const int cx = (q == 1 || q == 2) ? qw + qw / 2 : qw / 2, cy = q >= 2 ? qh + qh / 2 : qh / 2;
        const uint8_t v = im.pixels[(static_cast<size_t>(cy) * im.width + cx) * static_cast<size_t>(im.channels)];
        EXPECT_EQ(v < 128, q == corner[orientation]) << "orientation " << orientation << ", quadrant " << q;
      }
    }
}

TEST(ImageIo, PngRoundTripIsExactForOneToFourChannels) {
  for (int c = 1; c <= 4; ++c) {
    Image im;
    im.width = 37;
    im.height = 21;
    im.channels = c;
    im.pixels.resize(static_cast<size_t>(37 * 21 * c));
    for (size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = static_cast<uint8_t>((i * 7919u) & 0xFF);
    const std::string path = temp_path("round_" + std::to_string(c) + ".png");
    ASSERT_TRUE(write_png(path, im).is_ok());
    Image back;
    ASSERT_TRUE(load_image(path, back).is_ok());
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 21);
    EXPECT_EQ(back.channels, c);
    EXPECT_EQ(back.pixels, im.pixels);
  }
}

TEST(ImageIo, ReadsTgaAndBmp) {
  Image im;
  ASSERT_TRUE(load_image(kData + "vistex-tile04-128.png", im).is_ok());
  const std::string tga = temp_path("tile.tga"), bmp = temp_path("tile.bmp");
  ASSERT_NE(stbi_write_tga(tga.c_str(), im.width, im.height, im.channels, im.pixels.data()), 0);
  ASSERT_NE(stbi_write_bmp(bmp.c_str(), im.width, im.height, im.channels, im.pixels.data()), 0);
  for (const std::string& path : {tga, bmp}) {
    Image back;
    ASSERT_TRUE(load_image(path, back).is_ok()) << path;
    EXPECT_EQ(back.width, 128);
    EXPECT_EQ(back.channels, 3);
    EXPECT_EQ(back.pixels, im.pixels) << path;
  }
}

TEST(ImageIo, ReadsTopDownBmp) {
  // A negative height says the rows are stored top first: the same picture as the bottom-up file
  // stbi_write_bmp writes, with its rows reversed (128 px of 3 bytes: 384 bytes a row, no padding).
  Image im;
  ASSERT_TRUE(load_image(kData + "vistex-tile04-128.png", im).is_ok());
  const std::string bottom_up = temp_path("bottom_up.bmp"), top_down = temp_path("top_down.bmp");
  ASSERT_NE(stbi_write_bmp(bottom_up.c_str(), im.width, im.height, im.channels, im.pixels.data()), 0);
  std::ifstream in(bottom_up, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GE(bytes.size(), 54u);
  const size_t offset = static_cast<uint8_t>(bytes[10]) | static_cast<size_t>(static_cast<uint8_t>(bytes[11])) << 8;
  const size_t row = 128 * 3;
  ASSERT_EQ(bytes.size(), offset + 128 * row);
  std::string flipped = bytes;
  for (size_t y = 0; y < 128; ++y) flipped.replace(offset + y * row, row, bytes, offset + (127 - y) * row, row);
  const int32_t height = -128;
  std::memcpy(&flipped[22], &height, 4);  // little-endian, as BMP stores it
  write_bytes(top_down, flipped);
  Image back;
  const Status s = load_image(top_down, back);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(back.width, 128);
  EXPECT_EQ(back.height, 128);
  EXPECT_EQ(back.pixels, im.pixels);
}

TEST(ImageIo, ReadsGreyAndRgbPngsWithATransparentColour) {
  // A tRNS chunk makes one colour transparent: the decoder adds the alpha channel the header does
  // not count (such files were refused as "header and data disagree").
  const std::string rgb_raw = std::string("\0", 1) + std::string("\x10\x20\x30\x40\x50\x60", 6);
  const std::string rgb = temp_path("transparent_rgb.png");
  write_bytes(rgb, make_png(2, 1, 8, 2, rgb_raw, chunk("tRNS", std::string("\0\x10\0\x20\0\x30", 6))));
  Image im;
  Status s = load_image(rgb, im);
  ASSERT_TRUE(s.is_ok()) << s.message();
  ASSERT_EQ(im.channels, 4);
  EXPECT_EQ(im.pixels, (std::vector<uint8_t>{0x10, 0x20, 0x30, 0, 0x40, 0x50, 0x60, 255}));
  const std::string grey = temp_path("transparent_grey.png");
  write_bytes(grey, make_png(2, 1, 8, 0, std::string("\0\x07\x09", 3), chunk("tRNS", std::string("\0\x07", 2))));
  s = load_image(grey, im);
  ASSERT_TRUE(s.is_ok()) << s.message();
  ASSERT_EQ(im.channels, 2);
  EXPECT_EQ(im.pixels, (std::vector<uint8_t>{7, 0, 9, 255}));
}

TEST(ImageIo, Reads16BitPngAsEightBit) {
  // 4 x 2 grey, 16-bit big-endian samples; each row starts with filter byte 0.
  const std::array<uint16_t, 8> samples = {0, 257, 0x8080, 0xFFFF, 0x1234, 0xABCD, 0x00FF, 0xFF00};
  std::string raw;
  for (int y = 0; y < 2; ++y) {
    raw += '\0';
    for (int x = 0; x < 4; ++x) {
      const uint16_t v = samples[static_cast<size_t>(y * 4 + x)];
      raw += static_cast<char>(v >> 8);
      raw += static_cast<char>(v & 0xFF);
    }
  }
  const std::string path = temp_path("sixteen.png");
  write_bytes(path, make_png(4, 2, 16, 0, raw));
  Image im;
  const Status s = load_image(path, im);
  ASSERT_TRUE(s.is_ok()) << s.message();
  ASSERT_EQ(im.channels, 1);
  ASSERT_EQ(im.pixels.size(), 8u);
  EXPECT_EQ(im.pixels[0], 0);
  EXPECT_EQ(im.pixels[1], 1);
  EXPECT_EQ(im.pixels[2], 0x80);
  EXPECT_EQ(im.pixels[3], 0xFF);
  EXPECT_EQ(im.pixels[5], 0xAB);
}

TEST(ImageIo, TruncatedPngIsAClearError) {
  std::string bytes;
  ASSERT_TRUE(internal::read_file(kData + "vistex-sand05-128.png", bytes).is_ok());
  const std::string path = temp_path("truncated.png");
  write_bytes(path, bytes.substr(0, bytes.size() / 2));
  Image im;
  const Status s = load_image(path, im);
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidImage);
  EXPECT_EQ(s.file(), path);
  EXPECT_NE(s.what().find("truncated or corrupt"), std::string::npos) << s.message();
  EXPECT_TRUE(im.empty());
}

TEST(ImageIo, TextFileNamedPngIsAClearError) {
  const std::string path = temp_path("notes.png");
  write_bytes(path, "this is not an image, just some text\n");
  Image im;
  const Status s = load_image(path, im);
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidImage);
  EXPECT_NE(s.message().find("not a readable PNG, JPEG, TGA or BMP"), std::string::npos) << s.message();
}

// A Radiance .hdr (2 x 1 pixels, flat RGBE scanlines): stb would clip its light to 8 bits.
TEST(ImageIo, HighDynamicRangeImageIsRefusedNotClipped) {
  const std::string path = temp_path("light.hdr");
  std::string bytes = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
  for (int k = 0; k < 2; ++k) bytes += std::string("\x80\x80\x80\x84", 4);  // 8.0 in each channel
  write_bytes(path, bytes);
  Image im;
  const Status s = load_image(path, im);
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kUnsupported);
  EXPECT_NE(s.message().find("high dynamic range (Radiance .hdr) images are not read"), std::string::npos)
      << s.message();
  Image16 deep;
  EXPECT_FALSE(load_image16(path, deep).is_ok());
}

TEST(ImageIo, AbsurdHeaderSizeIsRejectedBeforeDecoding) {
  // A valid-looking 100000 x 100000 RGB header with a few bytes of data: decoding would need 30 GB.
  const std::string path = temp_path("huge.png");
  write_bytes(path, make_png(100000, 100000, 8, 2, std::string(64, '\0')));
  Image im;
  const Status s = load_image(path, im);
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidImage);
  EXPECT_NE(s.what().find("too large"), std::string::npos) << s.message();
  EXPECT_NE(s.where().find("100000x100000"), std::string::npos) << s.message();
  // 20000 x 20000 grey passes stb_image's own limits: our kMaxImageSide check must catch it.
  const std::string path2 = temp_path("big.png");
  write_bytes(path2, make_png(20000, 20000, 8, 0, std::string(64, '\0')));
  const Status s2 = load_image(path2, im);
  EXPECT_EQ(s2.code(), ErrorCode::kInvalidImage);
  EXPECT_NE(s2.message().find("too large"), std::string::npos) << s2.message();
  EXPECT_NE(s2.message().find("20000x20000"), std::string::npos) << s2.message();
}

TEST(ImageIo, ClaimedSizeIsCheckedAgainstThePixelLimitAndTheFileLength) {
  // Uncompressed TGA: 18-byte header claiming 16000 x 16000 RGB, then 12 bytes.
  std::string tga(18, '\0');
  tga[2] = 2;
  tga[12] = tga[14] = static_cast<char>(0x80);
  tga[13] = tga[15] = 0x3e;
  tga[16] = 24;
  tga += std::string(12, '\0');
  const std::string path = temp_path("claims16000.tga");
  write_bytes(path, tga);
  Image im;
  Status s = load_image(path, im);  // default limit: 64 Mpx
  EXPECT_EQ(s.code(), ErrorCode::kInvalidImage);
  EXPECT_NE(s.what().find("image too large: 16000x16000 is 256000000 px"), std::string::npos) << s.message();
  ImageLoadOptions raised;
  raised.max_pixels = 300000000;
  s = load_image(path, im, raised);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidImage);
  EXPECT_NE(s.what().find("truncated image"), std::string::npos) << s.message();
  EXPECT_NE(s.what().find("768000018 bytes"), std::string::npos) << s.message();
  // Binary PPM: the same with the header in text.
  const std::string ppm = temp_path("claims4000.ppm");
  write_bytes(ppm, "P6\n4000 4000\n255\n" + std::string(12, '\0'));
  s = load_image(ppm, im);
  EXPECT_NE(s.what().find("truncated image: the header claims 4000x4000 px"), std::string::npos) << s.message();
  EXPECT_TRUE(im.empty());
  // A real image passes at its exact pixel count and is refused one pixel below.
  ImageLoadOptions exact;
  exact.max_pixels = 128 * 128;
  EXPECT_TRUE(load_image(kData + "vistex-tile04-128.png", im, exact).is_ok());
  exact.max_pixels -= 1;
  EXPECT_EQ(load_image(kData + "vistex-tile04-128.png", im, exact).code(), ErrorCode::kInvalidImage);
}

TEST(ImageIo, MissingAndEmptyFiles) {
  Image im;
  EXPECT_EQ(load_image(temp_path("does_not_exist.png"), im).code(), ErrorCode::kIo);
  const std::string empty = temp_path("empty.png");
  write_bytes(empty, "");
  EXPECT_EQ(load_image(empty, im).code(), ErrorCode::kInvalidImage);
}

TEST(ImageIo, WritePngFailsCleanlyAndLeavesNoFile) {
  Image im;
  im.width = 4;
  im.height = 4;
  im.channels = 3;
  im.pixels.assign(48, 7);
  const Status s = write_png("/nonexistent_dir_for_tailor/x.png", im);
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  Image bad = im;
  bad.pixels.resize(10);  // inconsistent buffer
  const std::string path = temp_path("bad.png");
  EXPECT_EQ(write_png(path, bad).code(), ErrorCode::kInvalidImage);
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(ImageOps, FloatRoundTripIsExactAndLayoutKept) {
  Image im;
  ASSERT_TRUE(load_image(kData + "vistex-fabric02-128.png", im).is_ok());
  const ImageF f = to_float(im);
  EXPECT_EQ(f.width, im.width);
  EXPECT_EQ(f.channels, 3);
  // Sample (x, y, c) at (y * width + x) * channels + c, scaled to [0, 1].
  const size_t i = (static_cast<size_t>(5) * 128 + 9) * 3 + 2;
  EXPECT_FLOAT_EQ(f.pixels[i], im.pixels[i] / 255.0f);
  EXPECT_EQ(to_image(f).pixels, im.pixels);
}

TEST(ImageOps, GreyAndResize) {
  Image im;
  ASSERT_TRUE(load_image(kData + "vistex-tile04-128.png", im).is_ok());
  const Image grey = to_grey(im);
  EXPECT_EQ(grey.channels, 1);
  EXPECT_EQ(grey.pixels.size(), 128u * 128u);
  Image big;
  ASSERT_TRUE(resize_image(im, 150, 140, big).is_ok());
  EXPECT_EQ(big.width, 150);
  EXPECT_EQ(big.height, 140);
  EXPECT_EQ(big.pixels.size(), 150u * 140u * 3u);
  EXPECT_EQ(resize_image(im, 0, 10, big).code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace tailor
