// Texel period estimation by autocorrelation (thesis 3.1, "Dynamic size texture").
//
// The luminance, minus its mean, is zero-padded to at least twice its size so that the FFT gives
// the linear (not circular) autocorrelation; each lag is divided by its number of overlapping
// pixel pairs (unbiased estimate) and by the lag-0 value, giving a correlation coefficient in
// [-1, 1]. Along each axis the profile r(d) = R(d, 0) (resp. R(0, d)) is searched for peaks in
// [3, 2 size / 3] (at least a third of the pixels overlap): the fundamental is the first peak
// reaching 80 % of the highest one (so harmonics 2p, 3p are not taken for the period), refined to sub-pixel by a
// parabola and then by the highest harmonic k p still in range (dividing its position by k divides the error by k).
#include <algorithm>
#include <cmath>
#include <exception>
#include <opencv2/core.hpp>

#include "tailor/image_ops.h"
#include "tailor/tiling.h"

namespace tailor {

namespace {

constexpr int kMinLag = 3;
constexpr double kHarmonicShare = 0.8;      // fundamental: first peak >= this share of the highest
constexpr double kMinCorrelation = 0.15;    // a period needs a peak at least this correlated...
constexpr double kMinConfidence = 0.2;      // ...and this far above the dip before it
constexpr double kMaxLagShare = 2.0 / 3.0;  // lags up to this share of the size (>= 1/3 overlap)

//! Sub-pixel position of a peak at d from its two neighbours (parabola through three points).
double parabola_peak(const std::vector<double>& r, int d) {
  if (d <= 0 || d + 1 >= static_cast<int>(r.size())) return d;
  const double a = r[static_cast<size_t>(d - 1)], b = r[static_cast<size_t>(d)], c = r[static_cast<size_t>(d + 1)];
  const double denom = a - 2.0 * b + c;
  if (std::abs(denom) < 1e-12) return d;
  return d + std::clamp(0.5 * (a - c) / denom, -0.5, 0.5);
}

void find_period(const std::vector<double>& r, double& period, double& confidence, bool& found) {
  period = 0.0;
  confidence = 0.0;
  found = false;
  const int last = static_cast<int>(r.size()) - 2;  // a peak needs a right neighbour
  std::vector<int> peaks;
  for (int d = kMinLag; d <= last; ++d)
    if (r[static_cast<size_t>(d)] >= r[static_cast<size_t>(d - 1)] &&
        r[static_cast<size_t>(d)] > r[static_cast<size_t>(d + 1)])
      peaks.push_back(d);
  if (peaks.empty()) return;
  double highest = -1.0;
  for (int d : peaks) highest = std::max(highest, r[static_cast<size_t>(d)]);
  if (highest <= 0.0) return;
  int fundamental = peaks.front();
  for (int d : peaks)
    if (r[static_cast<size_t>(d)] >= kHarmonicShare * highest) {
      fundamental = d;
      break;
    }
  double dip = 1.0;
  for (int d = 1; d < fundamental; ++d) dip = std::min(dip, r[static_cast<size_t>(d)]);
  const double value = r[static_cast<size_t>(fundamental)];
  confidence = std::clamp(std::min(value, value - dip), 0.0, 1.0);
  double p = parabola_peak(r, fundamental);
  // Refine with the highest harmonic in range that is still a clear peak.
  for (int k = static_cast<int>((last - 1) / p); k >= 2; --k) {
    const int centre = static_cast<int>(std::lround(k * p));
    int best = -1;
    for (int d = std::max(kMinLag, centre - 2); d <= std::min(last, centre + 2); ++d)
      if (r[static_cast<size_t>(d)] >= r[static_cast<size_t>(d - 1)] &&
          r[static_cast<size_t>(d)] > r[static_cast<size_t>(d + 1)] &&
          (best < 0 || r[static_cast<size_t>(d)] > r[static_cast<size_t>(best)]))
        best = d;
    if (best >= 0 && r[static_cast<size_t>(best)] >= 0.5 * value) {
      p = parabola_peak(r, best) / k;
      break;
    }
  }
  period = p;
  found = value >= kMinCorrelation && confidence >= kMinConfidence;
  if (!found) period = 0.0;
}

}  // namespace

PeriodEstimate estimate_period(const Image& image) {
  PeriodEstimate out;
  if (!check_image(image).is_ok() || image.width < 2 * kMinLag + 2 || image.height < 2 * kMinLag + 2) return out;
  try {
    const Image grey = to_grey(image);
    const int w = grey.width, h = grey.height;
    double mean = 0.0;
    for (uint8_t v : grey.pixels) mean += v;
    mean /= static_cast<double>(grey.pixels.size());
    const int pw = cv::getOptimalDFTSize(2 * w), ph = cv::getOptimalDFTSize(2 * h);
    cv::Mat padded(ph, pw, CV_32F, cv::Scalar(0));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        padded.at<float>(y, x) = static_cast<float>(grey.pixels[static_cast<size_t>(y) * w + x] - mean);
    cv::Mat spectrum, power, autocorr;
    cv::dft(padded, spectrum, 0, h);
    cv::mulSpectrums(spectrum, spectrum, power, 0, true);
    cv::dft(power, autocorr, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
    const double zero = autocorr.at<float>(0, 0) / (static_cast<double>(w) * h);
    if (!(zero > 1e-9)) return out;  // flat image: no structure at all
    const int max_x = static_cast<int>(w * kMaxLagShare), max_y = static_cast<int>(h * kMaxLagShare);
    std::vector<double> rx(static_cast<size_t>(max_x + 1)), ry(static_cast<size_t>(max_y + 1));
    for (int d = 0; d <= max_x; ++d)
      rx[static_cast<size_t>(d)] = autocorr.at<float>(0, d) / (static_cast<double>(w - d) * h) / zero;
    for (int d = 0; d <= max_y; ++d)
      ry[static_cast<size_t>(d)] = autocorr.at<float>(d, 0) / (static_cast<double>(h - d) * w) / zero;
    find_period(rx, out.period_x, out.confidence_x, out.found_x);
    find_period(ry, out.period_y, out.confidence_y, out.found_y);
  } catch (const std::exception&) {
    return PeriodEstimate{};
  }
  return out;
}

void period_fitted_size(const PeriodEstimate& period, int width, int height, int& fitted_width, int& fitted_height) {
  auto fit = [](bool found, double p, int size) {
    if (!found || !(p > 0.0)) return size;
    const double n = std::max(1.0, std::floor(size / p + 0.55));
    const long fitted = std::lround(n * p);
    return static_cast<int>(std::clamp<long>(fitted, 32, kMaxImageSide));
  };
  fitted_width = fit(period.found_x, period.period_x, width);
  fitted_height = fit(period.found_y, period.period_y, height);
}

}  // namespace tailor
