// The block search of the quilting: the SSD of a masked template against every exemplar position,
// computed with FFTs (SSD = sum M T^2 - 2 sum_c corr(M T_c, E_c) + corr(M, sum_c E_c^2); colour in
// luminance). The exemplar's spectra are computed once, so each block costs one or two forward real
// DFTs of the template and one inverse.
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "texture/tiling_util.h"

namespace tailor::internal {

//! SSD of a masked B x B template against every B x B block of the exemplar, by FFT.
class SsdSearch {
 public:
  //! all_channels: search every channel (a map set's guide) instead of a colour image's luminance.
  void init(const Plane& exemplar, bool all_channels = false);

  //! Search sample c of a pixel: the channel itself, or the luminance (Rec. 601) of a colour pixel.
  float sample(const float* p, int c) const {
    if (search_channels_ == ex_->channels) return p[c];
    return 0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2];
  }

  int positions_x(int bw) const { return ex_->width - bw + 1; }
  int positions_y(int bh) const { return ex_->height - bh + 1; }

  //! templ: bw*bh*channels samples, mask: bw*bh weights (0 or 1), row-major.
  //! ssd: positions_x(bw) * positions_y(bh) values.
  void search(int bw, int bh, const std::vector<float>& templ, const std::vector<float>& mask, std::vector<float>& ssd);

 private:
  struct MaskEntry {
    int bw = 0, bh = 0;
    std::vector<float> mask;
    cv::Mat product;  // square_spectrum_ times the conjugate spectrum of the mask
  };
  static constexpr size_t kMaskCacheSize = 4;

  const Plane* ex_ = nullptr;
  int search_channels_ = 0;
  int last_bw_ = 0, last_bh_ = 0;
  std::vector<MaskEntry> mask_cache_;
  size_t next_slot_ = 0;
  std::vector<cv::Mat> spectra_;
  cv::Mat square_spectrum_, padded_, spectrum_, product_, accumulated_, result_;
};

}  // namespace tailor::internal
