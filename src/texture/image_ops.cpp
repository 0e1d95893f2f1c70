// Conversions and resampling of images (see tailor/image_ops.h).
#include "tailor/image_ops.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace tailor {

ImageF to_float(const Image& image) {
  ImageF out;
  out.width = image.width;
  out.height = image.height;
  out.channels = image.channels;
  out.pixels.resize(image.pixels.size());
  for (size_t i = 0; i < image.pixels.size(); ++i) out.pixels[i] = static_cast<float>(image.pixels[i]) / 255.0f;
  return out;
}

Image to_image(const ImageF& image) {
  Image out;
  out.width = image.width;
  out.height = image.height;
  out.channels = image.channels;
  out.pixels.resize(image.pixels.size());
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const float v = std::clamp(image.pixels[i], 0.0f, 1.0f) * 255.0f;
    out.pixels[i] = static_cast<uint8_t>(std::lround(v));
  }
  return out;
}

Image to_grey(const Image& image) {
  Image out;
  out.width = image.width;
  out.height = image.height;
  out.channels = 1;
  const size_t n = static_cast<size_t>(image.width) * image.height;
  out.pixels.resize(n);
  const int c = image.channels;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = &image.pixels[i * c];
    if (c >= 3) {
      const double y = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
      out.pixels[i] = static_cast<uint8_t>(std::lround(std::min(255.0, y)));
    } else {
      out.pixels[i] = p[0];
    }
  }
  return out;
}

Status resize_image(const Image& image, int width, int height, Image& resized) {
  TAILOR_RETURN_IF_ERROR(check_image(image));
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "resize target outside [1, " + std::to_string(kMaxImageSide) + "]");
  try {
    const cv::Mat src(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
    resized = Image{};
    resized.width = width;
    resized.height = height;
    resized.channels = image.channels;
    resized.pixels.resize(static_cast<size_t>(width) * height * image.channels);
    cv::Mat dst(height, width, CV_8UC(image.channels), resized.pixels.data());
    const bool shrink = width < image.width && height < image.height;
    cv::resize(src, dst, dst.size(), 0, 0, shrink ? cv::INTER_AREA : cv::INTER_CUBIC);
    if (dst.data != resized.pixels.data())  // OpenCV reallocated: copy back (not expected)
      std::copy(dst.datastart, dst.dataend, resized.pixels.begin());
  } catch (const std::exception& e) {
    return Status::error(ErrorCode::kInvalidImage, "", std::string("resize failed: ") + e.what());
  }
  return Status::ok();
}

}  // namespace tailor
