// tailor: small operations on the images of image.h (conversions, resizing).
//
// All functions take the layout documented in image.h: row-major, top row first, `channels`
// interleaved samples per pixel, sample (x, y, c) at index (y * width + x) * channels + c.
// None of them prints, throws or keeps state; all are safe on untrusted Image structs once
// check_image() (image.h) accepted them.
#pragma once

#include "tailor/api.h"
#include "tailor/image.h"

namespace tailor {

//! 8-bit -> float: every sample divided by 255 (so samples lie in [0, 1]). Same layout. Cost O(n).
TAILOR_API ImageF to_float(const Image& image);

//! float -> 8-bit: samples clamped to [0, 1], times 255, rounded to nearest. to_image(to_float(a))
//! reproduces `a` bit-exactly. Same layout. Cost O(n).
TAILOR_API Image to_image(const ImageF& image);

//! Luminance (Rec. 601 weights 0.299, 0.587, 0.114) of RGB(A) images, the grey channel of grey(+alpha)
//! images; alpha is dropped. Returns a 1-channel image of the same size.
TAILOR_API Image to_grey(const Image& image);

//! Resamples to width x height (area averaging when shrinking, bicubic when enlarging, OpenCV).
//! Fails with kInvalidArgument for a size outside [1, kMaxImageSide], kInvalidImage for a bad input.
TAILOR_API Status resize_image(const Image& image, int width, int height, Image& resized);

}  // namespace tailor
