// Reading images (PNG, JPEG, TGA, BMP through stb_image) and writing PNG atomically
// (stb_image_write to memory, then internal::write_file_atomic).
//
// Untrusted input: the header is inspected with stbi_info_from_memory and the size checked
// against kMaxImageSide before anything is decoded, so a 100-byte file claiming 100000 x 100000
// pixels is refused without allocating.
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <climits>
#include <cstring>
#include <string>

#include "internal/atomic_file.h"
#include "tailor/image.h"
#include "tailor/image_ops.h"

namespace tailor {

namespace {

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

}  // namespace

Status load_image(const std::string& path, Image& image) {
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
    const char* reason = stbi_failure_reason();
    return Status::error(ErrorCode::kInvalidImage, path,
                         "not a readable PNG, JPEG, TGA or BMP image",
                         std::string("header: ") + (reason ? reason : "unknown format"));
  }
  if (width <= 0 || height <= 0)
    return Status::error(ErrorCode::kInvalidImage, path, "image has no pixels", "header says " + size_text(width, height));
  if (width > kMaxImageSide || height > kMaxImageSide)
    return Status::error(ErrorCode::kInvalidImage, path,
                         "image too large (the limit is " + std::to_string(kMaxImageSide) + " px a side)",
                         "header says " + size_text(width, height));
  if (channels < 1 || channels > 4)
    return Status::error(ErrorCode::kUnsupported, path, "unsupported channel count " + std::to_string(channels));

  // 16-bit PNGs are reduced to 8 bits by stbi_load_from_memory itself.
  int w = 0, h = 0, c = 0;
  stbi_uc* pixels = stbi_load_from_memory(data, length, &w, &h, &c, 0);
  if (pixels == nullptr) {
    const char* reason = stbi_failure_reason();
    return Status::error(ErrorCode::kInvalidImage, path, "truncated or corrupt image data",
                         std::string("decoder: ") + (reason ? reason : "unknown error"));
  }
  if (w != width || h != height || c != channels) {
    stbi_image_free(pixels);
    return Status::error(ErrorCode::kInvalidImage, path, "image header and data disagree on the size");
  }
  image.width = w;
  image.height = h;
  image.channels = c;
  image.pixels.assign(pixels, pixels + static_cast<size_t>(w) * h * c);
  stbi_image_free(pixels);
  return Status::ok();
}

Status write_png(const std::string& path, const Image& image) {
  TAILOR_RETURN_IF_ERROR(check_image(image).with_file(path));
  std::string encoded;
  encoded.reserve(image.pixels.size() / 2 + 1024);
  auto append = [](void* context, void* bytes, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(bytes), static_cast<size_t>(size));
  };
  const int ok = stbi_write_png_to_func(append, &encoded, image.width, image.height, image.channels,
                                        image.pixels.data(), image.width * image.channels);
  if (ok == 0 || encoded.empty()) return Status::error(ErrorCode::kIo, path, "PNG encoding failed");
  return internal::write_file_atomic(path, std::span<const char>(encoded.data(), encoded.size()));
}

}  // namespace tailor
