// The block search by FFT (block_search.h).
#include "texture/block_search.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <vector>

namespace tailor::internal {

void SsdSearch::init(const Plane& exemplar, bool all_channels) {
  ex_ = &exemplar;
  // Colour exemplars are searched in luminance (one correlation instead of three); the near-best
  // candidates are then ranked in full colour by their cut patches (Quilter::patch_cost).
  search_channels_ = exemplar.channels >= 3 && !all_channels ? 1 : exemplar.channels;
  const int dft_w = cv::getOptimalDFTSize(exemplar.width);
  const int dft_h = cv::getOptimalDFTSize(exemplar.height);
  // Circular correlation is exact for the valid positions p <= size - block: p + q < size <= dft size.
  cv::Mat plane(dft_h, dft_w, CV_32F, cv::Scalar(0));
  cv::Mat square(dft_h, dft_w, CV_32F, cv::Scalar(0));
  spectra_.assign(static_cast<size_t>(search_channels_), cv::Mat());
  for (int c = 0; c < search_channels_; ++c) {
    for (int y = 0; y < exemplar.height; ++y) {
      float* row = plane.ptr<float>(y);
      float* sq = square.ptr<float>(y);
      for (int x = 0; x < exemplar.width; ++x) {
        const float v = sample(exemplar.at(x, y), c);
        row[x] = v;
        sq[x] += v * v;
      }
    }
    cv::dft(plane, spectra_[c], 0, exemplar.height);
  }
  cv::dft(square, square_spectrum_, 0, exemplar.height);
  padded_ = cv::Mat(dft_h, dft_w, CV_32F, cv::Scalar(0));
  accumulated_ = cv::Mat(dft_h, dft_w, CV_32F, cv::Scalar(0));
}

void SsdSearch::search(int bw, int bh, const std::vector<float>& templ, const std::vector<float>& mask,
                       std::vector<float>& ssd) {
  const int channels = ex_->channels;
  if (bw != last_bw_ || bh != last_bh_) {  // the template area changed: clear what it left
    padded_.setTo(0);
    last_bw_ = bw;
    last_bh_ = bh;
  }
  // The mask term depends on the mask only, and chains repeat a few mask shapes: cache it.
  const cv::Mat* mask_term = nullptr;
  for (const MaskEntry& e : mask_cache_)
    if (e.bw == bw && e.bh == bh && e.mask == mask) mask_term = &e.product;
  if (mask_term == nullptr) {
    for (int y = 0; y < bh; ++y) {
      float* row = padded_.ptr<float>(y);
      for (int x = 0; x < bw; ++x) row[x] = mask[static_cast<size_t>(y) * bw + x];
    }
    cv::dft(padded_, spectrum_, 0, bh);
    MaskEntry& slot = mask_cache_.size() < kMaskCacheSize ? mask_cache_.emplace_back() : mask_cache_[next_slot_];
    if (mask_cache_.size() == kMaskCacheSize) next_slot_ = (next_slot_ + 1) % kMaskCacheSize;
    slot.bw = bw;
    slot.bh = bh;
    slot.mask = mask;
    cv::mulSpectrums(square_spectrum_, spectrum_, slot.product, 0, true);
    mask_term = &slot.product;
  }
  mask_term->copyTo(accumulated_);
  double constant = 0.0;
  for (int c = 0; c < search_channels_; ++c) {
    for (int y = 0; y < bh; ++y) {
      float* row = padded_.ptr<float>(y);
      for (int x = 0; x < bw; ++x) {
        const size_t i = static_cast<size_t>(y) * bw + x;
        const float t = sample(&templ[i * channels], c);
        row[x] = mask[i] * t;
        constant += static_cast<double>(mask[i]) * t * t;
      }
    }
    cv::dft(padded_, spectrum_, 0, bh);
    cv::mulSpectrums(spectra_[c], spectrum_, product_, 0, true);
    cv::scaleAdd(product_, -2.0, accumulated_, accumulated_);
  }
  const int nx = positions_x(bw);
  const int ny = positions_y(bh);
  cv::dft(accumulated_, result_, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE, ny);
  ssd.resize(static_cast<size_t>(nx) * ny);
  for (int y = 0; y < ny; ++y) {
    const float* row = result_.ptr<float>(y);
    for (int x = 0; x < nx; ++x)
      ssd[static_cast<size_t>(y) * nx + x] = std::max(0.0f, static_cast<float>(constant + row[x]));
  }
}

}  // namespace tailor::internal
