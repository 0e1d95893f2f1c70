// Reading images (PNG, JPEG, TGA, BMP through stb_image) and writing PNG atomically
// (a PNG encoder over zlib, 8 and 16 bit, then internal::write_file_atomic).
//
// Untrusted input: the header is inspected with stbi_info_from_memory and the size checked
// against kMaxImageSide, ImageLoadOptions::max_pixels and (uncompressed formats) the file's
// length before anything is decoded, so a 30-byte file claiming 16000 x 16000 pixels is refused
// without allocating.
#include <stb/stb_image.h>
#include <zlib.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

#include "io/exif_orientation.h"
#include "io/readers.h"
#include "tailor/image.h"
#include "util/atomic_file.h"

namespace tailor {

Status check_image(const Image& image) {
  if (image.width < 1 || image.height < 1) return Status::error(ErrorCode::kInvalidImage, "", "image has no pixels");
  if (image.width > kMaxImageSide || image.height > kMaxImageSide)
    return Status::error(ErrorCode::kInvalidImage, "",
                         "image too large (the limit is " + std::to_string(kMaxImageSide) + " px a side)");
  if (image.channels < 1 || image.channels > 4)
    return Status::error(ErrorCode::kInvalidImage, "", "image must have 1 to 4 channels");
  const size_t expected = static_cast<size_t>(image.width) * image.height * image.channels;
  if (image.pixels.size() != expected)
    return Status::error(ErrorCode::kInvalidImage, "", "pixel buffer size does not match width x height x channels");
  return Status::ok();
}

namespace {

std::string size_text(long width, long height) { return std::to_string(width) + "x" + std::to_string(height); }

uint32_t be16(const unsigned char* p) { return (uint32_t{p[0]} << 8) | p[1]; }
uint32_t be32(const unsigned char* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

//! The size a PNG, JPEG or BMP header claims, read directly: stb_image refuses (with a vague
//! "unknown image type") headers whose size would overflow its own limits, and the user should
//! rather hear "too large". Returns false when the header is not recognised.
bool claimed_size(std::span<const unsigned char> bytes, long& width, long& height) {
  const unsigned char* p = bytes.data();
  const size_t n = bytes.size();
  if (n >= 24 && std::memcmp(p, "\x89PNG\r\n\x1a\n", 8) == 0 && std::memcmp(p + 12, "IHDR", 4) == 0) {
    width = be32(p + 16);
    height = be32(p + 20);
    return true;
  }
  if (n >= 4 && p[0] == 0xFF && p[1] == 0xD8) {  // JPEG: walk the markers up to a start-of-frame
    size_t i = 2;
    while (i + 9 < n && p[i] == 0xFF) {
      const unsigned marker = p[i + 1];
      if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
        height = be16(p + i + 5);
        width = be16(p + i + 7);
        return true;
      }
      i += 2 + be16(p + i + 2);
    }
    return false;
  }
  if (n >= 26 && p[0] == 'B' && p[1] == 'M') {
    auto le32 = [&](size_t o) {
      return static_cast<int32_t>(uint32_t{p[o]} | (uint32_t{p[o + 1]} << 8) | (uint32_t{p[o + 2]} << 16) |
                                  (uint32_t{p[o + 3]} << 24));
    };
    width = std::labs(le32(18));
    height = std::labs(le32(22));
    return true;
  }
  return false;
}

uint32_t le16(const unsigned char* p) { return uint32_t{p[0]} | (uint32_t{p[1]} << 8); }
uint32_t le32(const unsigned char* p) { return le16(p) | (le16(p + 2) << 16); }

//! The fewest bytes a file of this format needs for width x height pixels, from its header; 0
//! when unknown (compressed formats: PNG, JPEG, GIF, PSD, HDR...).
uint64_t min_file_bytes(std::span<const unsigned char> b, uint64_t width, uint64_t height) {
  const uint64_t pixels = width * height;
  const size_t n = b.size();
  const unsigned char* p = b.data();
  if (n >= 2 && p[0] == 'P' && (p[1] == '5' || p[1] == '6'))  // binary PGM / PPM, >= 1 byte a sample
    return pixels * (p[1] == '5' ? 1 : 3);
  if (n >= 2 && p[0] == 'B' && p[1] == 'M') {
    if (n < 34) return 0;
    const uint32_t bits = le16(p + 28), compression = le32(p + 30);
    if (compression != 0 && compression != 3) return 0;  // RLE4/RLE8 and others
    const uint64_t row = (width * bits + 31) / 32 * 4;
    return row * height;
  }
  const bool magic = (n >= 8 && std::memcmp(p, "\x89PNG", 4) == 0) || (n >= 2 && p[0] == 0xFF && p[1] == 0xD8) ||
                     (n >= 4 && std::memcmp(p, "GIF8", 4) == 0) || (n >= 4 && std::memcmp(p, "8BPS", 4) == 0) ||
                     (n >= 2 && p[0] == '#' && p[1] == '?') ||
                     (n >= 4 && p[0] == 0x53 && p[1] == 0x80 && p[2] == 0xF6 && p[3] == 0x34);
  if (magic || n < 18) return 0;
  // TGA (stb_image tries it last, it has no magic number): image type at byte 2, bits per pixel
  // at 16; with a colour map each pixel is an index of (bits + 7) / 8 bytes.
  const unsigned type = p[2];
  const uint64_t bytes_per_pixel = (p[16] + 7u) / 8u;
  if (type == 1 || type == 2 || type == 3) return 18 + pixels * std::max<uint64_t>(bytes_per_pixel, 1);
  if (type == 9 || type == 10 || type == 11) return 18 + (pixels + 127) / 128 * 2;  // RLE: <= 128 px a packet
  return 0;
}

}  // namespace

namespace internal {

bool image_header_size(std::span<const unsigned char> bytes, long& width, long& height, bool exif_orientation) {
  width = height = 0;
  if (!claimed_size(bytes, width, height)) {
    int w = 0, h = 0, channels = 0;
    if (bytes.size() > size_t{INT_MAX} ||
        stbi_info_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &channels) == 0)
      return false;
    width = w;
    height = h;
  }
  if (exif_orientation && jpeg_exif_orientation(bytes) >= 5) std::swap(width, height);  // shown turned a quarter
  return width > 0 && height > 0;
}

Status check_image_header(std::span<const unsigned char> bytes, long width, long height,
                          const ImageLoadOptions& options, const std::string& name) {
  if (width <= 0 || height <= 0)
    return Status::error(ErrorCode::kInvalidImage, name, "image has no pixels",
                         "header says " + size_text(width, height));
  if (width > kMaxImageSide || height > kMaxImageSide)
    return Status::error(ErrorCode::kInvalidImage, name,
                         "image too large (the limit is " + std::to_string(kMaxImageSide) + " px a side)",
                         "header says " + size_text(width, height));
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  if (pixels > options.max_pixels)
    return Status::error(ErrorCode::kInvalidImage, name,
                         "image too large: " + size_text(width, height) + " is " + std::to_string(pixels) +
                             " px, the limit is " + std::to_string(options.max_pixels) +
                             " px (raise it with --max-image-pixels)");
  const uint64_t needed = min_file_bytes(bytes, static_cast<uint64_t>(width), static_cast<uint64_t>(height));
  if (needed > bytes.size())
    return Status::error(ErrorCode::kInvalidImage, name,
                         "truncated image: the header claims " + size_text(width, height) +
                             " px, which needs at least " + std::to_string(needed) + " bytes, but the file has " +
                             std::to_string(bytes.size()));
  return Status::ok();
}

}  // namespace internal

namespace {

//! load_image, and with `deep` (load_image16) a 16-bit PNG decoded at 16 bits into it instead.
Status load_pixels(const std::string& path, Image& image, Image16* deep, const ImageLoadOptions& options) {
  image = Image{};
  std::string bytes;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, bytes));
  if (bytes.empty()) return Status::error(ErrorCode::kInvalidImage, path, "empty file, not an image");
  if (bytes.size() > static_cast<size_t>(INT_MAX))
    return Status::error(ErrorCode::kInvalidImage, path, "file too large to be an image (over 2 GiB)");
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int length = static_cast<int>(bytes.size());

  int width = 0, height = 0, channels = 0;
  if (stbi_info_from_memory(data, length, &width, &height, &channels) == 0) {
    long claimed_w = 0, claimed_h = 0;
    if (claimed_size({data, bytes.size()}, claimed_w, claimed_h) &&
        (claimed_w > kMaxImageSide || claimed_h > kMaxImageSide))
      return Status::error(ErrorCode::kInvalidImage, path,
                           "image too large (the limit is " + std::to_string(kMaxImageSide) + " px a side)",
                           "header says " + size_text(claimed_w, claimed_h));
    const char* reason = stbi_failure_reason();
    return Status::error(ErrorCode::kInvalidImage, path, "not a readable PNG, JPEG, TGA or BMP image",
                         std::string("header: ") + (reason ? reason : "unknown format"));
  }
  // A top-down BMP (rows stored first to last) says so with a negative height, which stb_image's
  // info passes on as it is (its loader reads the rows in either order).
  if (height < 0 && height != INT_MIN && bytes.size() >= 2 && bytes[0] == 'B' && bytes[1] == 'M') height = -height;
  // stb reads Radiance .hdr files too, clipping their light values to 8 bits without a word: a
  // tile of one would be a white picture.
  if (stbi_is_hdr_from_memory(data, length))
    return Status::error(ErrorCode::kUnsupported, path,
                         "high dynamic range (Radiance .hdr) images are not read: tone-map it to a PNG first");
  TAILOR_RETURN_IF_ERROR(internal::check_image_header({data, bytes.size()}, width, height, options, path));
  if (channels < 1 || channels > 4)
    return Status::error(ErrorCode::kUnsupported, path, "unsupported channel count " + std::to_string(channels));

  int w = 0, h = 0, c = 0;
  // A grey or RGB PNG with a tRNS chunk (one colour transparent) decodes with an alpha channel its
  // header does not count: the sizes must agree, the channels may be one more.
  const auto disagrees = [&] {
    return w != width || h != height || !(c == channels || ((channels == 1 || channels == 3) && c == channels + 1));
  };
  if (deep && stbi_is_16_bit_from_memory(data, length)) {
    stbi_us* samples = stbi_load_16_from_memory(data, length, &w, &h, &c, 0);
    if (samples == nullptr) {
      const char* reason = stbi_failure_reason();
      return Status::error(ErrorCode::kInvalidImage, path, "truncated or corrupt image data",
                           std::string("decoder: ") + (reason ? reason : "unknown error"));
    }
    if (disagrees()) {
      stbi_image_free(samples);
      return Status::error(ErrorCode::kInvalidImage, path, "image header and data disagree on the size");
    }
    deep->width = w;
    deep->height = h;
    deep->channels = c;
    deep->bits = 16;
    deep->pixels.assign(samples, samples + static_cast<size_t>(w) * h * c);
    stbi_image_free(samples);
    return Status::ok();
  }
  // 16-bit PNGs are reduced to 8 bits by stbi_load_from_memory itself.
  if (deep) deep->bits = 8;
  stbi_uc* pixels = stbi_load_from_memory(data, length, &w, &h, &c, 0);
  if (pixels == nullptr) {
    const char* reason = stbi_failure_reason();
    return Status::error(ErrorCode::kInvalidImage, path, "truncated or corrupt image data",
                         std::string("decoder: ") + (reason ? reason : "unknown error"));
  }
  if (disagrees()) {
    stbi_image_free(pixels);
    return Status::error(ErrorCode::kInvalidImage, path, "image header and data disagree on the size");
  }
  image.width = w;
  image.height = h;
  image.channels = c;
  image.pixels.assign(pixels, pixels + static_cast<size_t>(w) * h * c);
  stbi_image_free(pixels);
  // A camera's JPEG shown upright, as viewers show it (stb decodes the stored rows).
  if (options.exif_orientation)
    internal::apply_exif_orientation(internal::jpeg_exif_orientation({data, bytes.size()}), image);
  return Status::ok();
}

}  // namespace

Status load_image(const std::string& path, Image& image, const ImageLoadOptions& options) {
  return load_pixels(path, image, nullptr, options);
}

Status load_image16(const std::string& path, Image16& image, const ImageLoadOptions& options) {
  image = Image16{};
  Image flat;
  TAILOR_RETURN_IF_ERROR(load_pixels(path, flat, &image, options));
  if (image.bits == 8) image = to_image16(flat);
  return Status::ok();
}

Image to_image8(const Image16& image) {
  Image out;
  out.width = image.width;
  out.height = image.height;
  out.channels = image.channels;
  out.pixels.resize(image.pixels.size());
  for (size_t i = 0; i < image.pixels.size(); ++i)
    out.pixels[i] = image.bits == 16 ? static_cast<uint8_t>((uint32_t{image.pixels[i]} * 255u + 32767u) / 65535u)
                                     : static_cast<uint8_t>(std::min<uint16_t>(image.pixels[i], 255));
  return out;
}

Image16 to_image16(const Image& image) {
  Image16 out;
  out.width = image.width;
  out.height = image.height;
  out.channels = image.channels;
  out.bits = 8;
  out.pixels.assign(image.pixels.begin(), image.pixels.end());
  return out;
}

namespace {

void append_chunk(std::string& out, const char type[4], const std::string& data) {
  const uint32_t n = static_cast<uint32_t>(data.size());
  const unsigned char len[4] = {static_cast<unsigned char>(n >> 24), static_cast<unsigned char>(n >> 16),
                                static_cast<unsigned char>(n >> 8), static_cast<unsigned char>(n)};
  out.append(reinterpret_cast<const char*>(len), 4);
  const size_t start = out.size();
  out.append(type, 4);
  out += data;
  const uLong crc =
      crc32(0L, reinterpret_cast<const Bytef*>(out.data() + start), static_cast<uInt>(out.size() - start));
  const unsigned char tail[4] = {static_cast<unsigned char>(crc >> 24), static_cast<unsigned char>(crc >> 16),
                                 static_cast<unsigned char>(crc >> 8), static_cast<unsigned char>(crc)};
  out.append(reinterpret_cast<const char*>(tail), 4);
}

//! PNG of `bits` (8 or 16) bits from big-endian rows `raw(y)` of width * channels * bits / 8 bytes:
//! per row the filter (None, Sub, Up, Average, Paeth) with the least sum of |filtered byte| (the
//! usual heuristic), deflated by zlib at level 3 (4096 x 4096 RGB in about a second; stb's
//! encoder took 3.6 s).
template <typename RowFn>
Status encode_png(const std::string& path, int width, int height, int channels, int bits, RowFn raw,
                  std::string& encoded) {
  const size_t stride = static_cast<size_t>(width) * channels * (bits / 8);
  const size_t bpp = static_cast<size_t>(channels) * (bits / 8);
  z_stream z{};
  if (deflateInit(&z, 3) != Z_OK) return Status::error(ErrorCode::kIo, path, "PNG encoding failed (zlib)");
  std::string idat;
  std::vector<unsigned char> prev(stride, 0), cur(stride), best(stride + 1), trial(stride + 1);
  std::vector<unsigned char> out(1 << 16);
  bool failed = false;
  auto feed = [&](const unsigned char* data, size_t n, int flush) {
    z.next_in = const_cast<Bytef*>(data);
    z.avail_in = static_cast<uInt>(n);
    do {
      z.next_out = out.data();
      z.avail_out = static_cast<uInt>(out.size());
      if (deflate(&z, flush) == Z_STREAM_ERROR) failed = true;
      idat.append(reinterpret_cast<const char*>(out.data()), out.size() - z.avail_out);
    } while (z.avail_out == 0 && !failed);
  };
  for (int y = 0; y < height; ++y) {
    raw(y, cur.data());
    long best_sum = -1;
    for (unsigned char f = 0; f < 5; ++f) {
      trial[0] = f;
      long sum = 0;
      for (size_t i = 0; i < stride; ++i) {
        const int a = i >= bpp ? cur[i - bpp] : 0, b = prev[i], c = i >= bpp ? prev[i - bpp] : 0;
        int pred = 0;
        if (f == 1) pred = a;
        if (f == 2) pred = b;
        if (f == 3) pred = (a + b) / 2;
        if (f == 4) {
          const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          pred = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
        }
        const unsigned char v = static_cast<unsigned char>(cur[i] - pred);
        trial[i + 1] = v;
        sum += v < 128 ? v : 256 - v;
      }
      if (best_sum < 0 || sum < best_sum) {
        best_sum = sum;
        best.swap(trial);
      }
    }
    feed(best.data(), best.size(), Z_NO_FLUSH);
    prev.swap(cur);
  }
  feed(nullptr, 0, Z_FINISH);
  deflateEnd(&z);
  if (failed) return Status::error(ErrorCode::kIo, path, "PNG encoding failed (zlib)");
  static const int kColorType[5] = {0, 0, 4, 2, 6};  // grey, grey+alpha, RGB, RGBA
  std::string ihdr(13, '\0');
  for (int k = 0; k < 4; ++k) {
    ihdr[static_cast<size_t>(k)] = static_cast<char>(static_cast<uint32_t>(width) >> (24 - 8 * k));
    ihdr[static_cast<size_t>(4 + k)] = static_cast<char>(static_cast<uint32_t>(height) >> (24 - 8 * k));
  }
  ihdr[8] = static_cast<char>(bits);
  ihdr[9] = static_cast<char>(kColorType[channels]);
  encoded.assign("\x89PNG\r\n\x1a\n", 8);
  append_chunk(encoded, "IHDR", ihdr);
  append_chunk(encoded, "IDAT", idat);
  append_chunk(encoded, "IEND", "");
  return Status::ok();
}

}  // namespace

Status write_png16(const std::string& path, const Image16& image) {
  std::string encoded;
  TAILOR_RETURN_IF_ERROR(encode_png16(image, encoded).with_file(path));
  return internal::write_file_atomic(path, std::span<const char>(encoded.data(), encoded.size()));
}

Status encode_png16(const Image16& image, std::string& encoded) {
  const std::string path;
  if (image.bits != 8 && image.bits != 16)
    return Status::error(ErrorCode::kInvalidImage, path, "bit depth must be 8 or 16",
                         "got " + std::to_string(image.bits));
  if (image.width < 1 || image.height < 1 || image.width > kMaxImageSide || image.height > kMaxImageSide ||
      image.channels < 1 || image.channels > 4 ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels)
    return Status::error(ErrorCode::kInvalidImage, path, "inconsistent image (size, channels or sample count)");
  const int limit = (1 << image.bits) - 1;
  for (uint16_t v : image.pixels)
    if (v > limit) return Status::error(ErrorCode::kInvalidImage, path, "8-bit image with a sample above 255");
  const size_t row = static_cast<size_t>(image.width) * image.channels;
  return encode_png(
      path, image.width, image.height, image.channels, image.bits,
      [&](int y, unsigned char* out) {
        const uint16_t* s = &image.pixels[row * y];
        if (image.bits == 8) {
          for (size_t i = 0; i < row; ++i) out[i] = static_cast<unsigned char>(s[i]);
        } else {
          for (size_t i = 0; i < row; ++i) {
            out[2 * i] = static_cast<unsigned char>(s[i] >> 8);
            out[2 * i + 1] = static_cast<unsigned char>(s[i] & 0xFF);
          }
        }
      },
      encoded);
}

Status encode_png(const Image& image, std::string& encoded) {
  TAILOR_RETURN_IF_ERROR(check_image(image));
  const size_t row = static_cast<size_t>(image.width) * image.channels;
  return encode_png(
      std::string(), image.width, image.height, image.channels, 8,
      [&](int y, unsigned char* out) { std::copy_n(&image.pixels[row * y], row, out); }, encoded);
}

Status write_png(const std::string& path, const Image& image) {
  std::string encoded;
  TAILOR_RETURN_IF_ERROR(encode_png(image, encoded).with_file(path));
  return internal::write_file_atomic(path, std::span<const char>(encoded.data(), encoded.size()));
}

}  // namespace tailor
