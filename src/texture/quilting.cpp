// Image quilting (quilting.h): block choice among the candidates, their ranking by the patches
// their cuts create, and the minimum-error boundary cut.
#include "texture/quilting.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <utility>
#include <vector>

#include "texture/cut_refine.h"

namespace tailor::internal {
namespace {

constexpr double kCostTolerance = 0.01;  // blocks whose patch cost is within this of the best are ties
constexpr size_t kScanKeep = 8;        // the SSD scan keeps at least this many lowest positions (see select_candidates)
constexpr double kProfilePower = 8.0;  // cost * (1 + relative profile deficit)^this
constexpr double kStrongLine = 2.0;    // lines whose difference exceeds this x the median may not get stronger

}  // namespace

void Quilter::place(int bx, int by, int bw, int bh, const Exclusion& exclusion) {
  bw_ = bw;
  bh_ = bh;
  const int channels = canvas_.channels;
  const size_t area = static_cast<size_t>(bw) * bh;
  templ_.resize(area * channels);
  mask_.assign(area, 0.0f);
  bool any_known = false;
  for (int y = 0; y < bh; ++y) {
    for (int x = 0; x < bw; ++x) {
      const size_t i = static_cast<size_t>(y) * bw + x;
      const int cx = Plane::mod(bx + x, canvas_.width);
      const int cy = Plane::mod(by + y, canvas_.height);
      const float* p = canvas_.at(cx, cy);
      std::copy(p, p + channels, &templ_[i * channels]);
      if (known_[static_cast<size_t>(cy) * canvas_.width + cx]) {
        mask_[i] = 1.0f;
        any_known = true;
      }
    }
  }

  // Choose the exemplar block among those within the tolerance of the best SSD.
  const int nx = search_.positions_x(bw);
  const int ny = search_.positions_y(bh);
  const int searched_turns = turn_search_ ? 4 : 1;  // candidate i: turn i / (nx ny), position i % (nx ny)
  const int per_turn = nx * ny;
  int chosen = 0;
  turn_ = 0;
  if (!any_known) {
    chosen = static_cast<int>(rng_.below(static_cast<uint32_t>(per_turn * searched_turns)));
  } else if (turn_search_) {
    // The exemplar's four quarter turns are searched as one candidate set: a seam between two
    // turned copies is repaired from blocks that match both without a turn in the middle.
    ssd_.resize(static_cast<size_t>(per_turn) * 4);
    for (int k = 0; k < 4; ++k) {
      (*turn_search_)[static_cast<size_t>(k)].search(bw, bh, templ_, mask_, turn_ssd_);
      std::copy(turn_ssd_.begin(), turn_ssd_.end(), ssd_.begin() + static_cast<std::ptrdiff_t>(k) * per_turn);
    }
  } else {
    search_.search(bw, bh, templ_, mask_, ssd_);
  }
  if (any_known) {
    float energy = 0.0f;
    for (size_t i = 0; i < templ_.size(); ++i) energy += mask_[i / channels] * templ_[i] * templ_[i];
    select_candidates(nx, ny, energy, exclusion);
    if (pool_ <= 1 || source_ == nullptr) {
      chosen = candidates_[rng_.below(static_cast<uint32_t>(candidates_.size()))];
    } else {
      // Draw up to `pool` candidates at random (seeded); keep the one whose cut patches are
      // closest to exemplar patches (what the tile's patch coherence measures). SSD alone
      // treats every overlap pixel alike, while a 7 x 7 patch across a cut is cheap only if
      // both sides agree near the cut.
      // When the whole set fits in the pool, one random candidate is left out so that the seed
      // still matters.
      const size_t n = candidates_.size();
      const size_t k = std::min(n > 2 && n <= static_cast<size_t>(pool_) ? n - 1 : n, static_cast<size_t>(pool_));
      for (size_t i = 0; i < k; ++i) {
        const size_t j = i + rng_.below(static_cast<uint32_t>(candidates_.size() - i));
        std::swap(candidates_[i], candidates_[j]);
      }
      costs_.resize(k);
      double best_cost = std::numeric_limits<double>::max();
      for (size_t i = 0; i < k; ++i) {
        turn_ = candidates_[i] / per_turn;
        const int cx = candidates_[i] % per_turn % nx, cy = candidates_[i] % per_turn / nx;
        compute_error(cx, cy);
        take_new_.assign(area, 1);
        for (int side = 0; side < 4; ++side) cut_side(side);
        // Optional: penalise blocks smoother than the exemplar on average (smooth blocks match
        // more easily, and a strip of them lowers the tile's median boundary difference).
        double smooth_factor = 1.0, profile_factor = 1.0;
        if (gradient_penalty_ > 0.0) {
          const double g = block_gradient(cx, cy);
          if (g < mean_gradient()) smooth_factor = std::pow(mean_gradient() / std::max(g, 1e-6), gradient_penalty_);
        }
        if (profile_axes_ != 0) profile_factor = std::pow(1.0 + profile_deficit(bx, by, cx, cy), kProfilePower);
        // A candidate whose partial cost already exceeds the ties' bound can be neither.
        const double cost =
            patch_cost(bx, by, cx, cy, smooth_factor, profile_factor, best_cost * (1.0 + kCostTolerance));
        costs_[i] = cost;
        best_cost = std::min(best_cost, cost);
      }
      // Near ties (within kCostTolerance) are broken at random.
      size_t ties = 0;
      for (size_t i = 0; i < k; ++i)
        if (costs_[i] <= best_cost * (1.0 + kCostTolerance)) {
          candidates_[ties] = candidates_[i];
          costs_[ties++] = costs_[i];
        }
      const size_t pick = rng_.below(static_cast<uint32_t>(ties));
      chosen = candidates_[pick];
      cut_cost_ += costs_[pick];
    }
  }
  turn_ = chosen / per_turn;
  const int px = chosen % per_turn % nx;
  const int py = chosen % per_turn / nx;
  if (record_) record_->push_back({bx, by, bw, bh, px, py});

  // Boundary cuts on every side whose overlap strip holds known pixels.
  compute_error(px, py);
  take_new_.assign(area, 1);
  for (int side = 0; side < 4; ++side) cut_side(side);

  for (int y = 0; y < bh; ++y) {
    for (int x = 0; x < bw; ++x) {
      const size_t i = static_cast<size_t>(y) * bw + x;
      const int cx = Plane::mod(bx + x, canvas_.width);
      const int cy = Plane::mod(by + y, canvas_.height);
      const size_t ci = static_cast<size_t>(cy) * canvas_.width + cx;
      if (locked_[ci]) continue;
      if (take_new_[i] || mask_[i] == 0.0f) {
        const float* e = block_plane().at(px + x, py + y);
        std::copy(e, e + channels, canvas_.at(cx, cy));
        if (source_) (*source_)[ci] = turn_offset() + (py + y) * ex_.width + px + x;
        if (turns_) {
          // The three images under r(x, y) = (N - 1 - y, x); the source turns with them:
          // turns[k + 1](S - 1 - sy, sx) = turns[k](sx, sy) for the S x S exemplar.
          const int n = canvas_.width, s = ex_.width;
          const int32_t plane = s * s;
          int rx = cx, ry = cy;
          int32_t src = turn_offset() + (py + y) * ex_.width + px + x;
          for (int turn = 1; turn < 4; ++turn) {
            const int nx2 = n - 1 - ry;
            ry = rx;
            rx = nx2;
            const int32_t k = src / plane, sx = src % plane % s, sy = src % plane / s;
            src = ((k + 1) % 4) * plane + sx * s + (s - 1 - sy);
            const size_t ri = static_cast<size_t>(ry) * n + rx;
            std::copy(e, e + channels, canvas_.at(rx, ry));
            if (source_) (*source_)[ri] = src;
            known_[ri] = 1;
          }
        }
      }
      known_[ci] = 1;
    }
  }
  ++placed_;
}

void Quilter::set_profile(const Plane* original, int axes, int skip_first, int skip_count) {
  original_ = original;
  profile_axes_ = axes;
  skip_first_ = skip_first;
  skip_count_ = skip_count;
  if (original == nullptr || !strong_rows_.empty()) return;
  for (int a = 1; a <= 2; ++a) {
    const bool rows = a == 1;
    const int n = rows ? original->height : original->width;
    std::vector<double> diff(static_cast<size_t>(n), 0.0);
    for (int y = 0; y < original->height; ++y)
      for (int x = 0; x < original->width; ++x) {
        const float* p = original->at(x, y);
        const float* q = rows ? original->wrap(x, y + 1) : original->wrap(x + 1, y);
        for (int c = 0; c < original->channels; ++c) diff[static_cast<size_t>(rows ? y : x)] += std::abs(p[c] - q[c]);
      }
    std::vector<double> sorted = diff;
    std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
    const double median = sorted[static_cast<size_t>(n / 2)];
    std::vector<uint8_t>& strong = rows ? strong_rows_ : strong_cols_;
    strong.assign(static_cast<size_t>(n), 0);
    for (int i = 0; i < n; ++i)
      strong[static_cast<size_t>(i)] = diff[static_cast<size_t>(i)] > kStrongLine * median ? 1 : 0;
  }
}

void Quilter::select_candidates(int nx, int ny, float energy, const Exclusion& exclusion) {
  const size_t top = static_cast<size_t>(min_candidates_);
  candidates_.clear();
  ranked_.clear();
  // The small absolute term absorbs FFT round-off (relative ~1e-6 of the template energy).
  auto threshold_of = [&](float best) { return best * static_cast<float>(1.0 + tolerance_) + 1e-5f * energy + 1e-3f; };
  auto keep_lowest = [&](const std::pair<float, int>& entry, size_t m) {
    if (ranked_.size() == m) {
      if (!(entry < ranked_.back())) return;
      ranked_.pop_back();
    }
    ranked_.insert(std::upper_bound(ranked_.begin(), ranked_.end(), entry), entry);
  };
  if (!exclusion.active) {
    const size_t m = std::max(top, kScanKeep);
    float kept_worst = std::numeric_limits<float>::max();
    for (size_t i = 0; i < ssd_.size(); ++i) {
      if (ssd_[i] > kept_worst) continue;
      keep_lowest({ssd_[i], static_cast<int>(i)}, m);
      if (ranked_.size() == m) kept_worst = ranked_.back().first;
    }
    const float threshold = threshold_of(ranked_.front().first);
    if (ranked_.size() < m || ranked_.back().first > threshold) {
      for (const auto& entry : ranked_)
        if (entry.first <= threshold) candidates_.push_back(entry.second);
      std::sort(candidates_.begin(), candidates_.end());  // raster order, as a full scan gives
    } else {
      for (size_t i = 0; i < ssd_.size(); ++i)
        if (ssd_[i] <= threshold) candidates_.push_back(static_cast<int>(i));
    }
    ranked_.resize(std::min(ranked_.size(), top));
  } else {
    // The exclusion names upright exemplar positions (variants; no turned search there).
    const int per_turn = nx * ny, count = static_cast<int>(ssd_.size());
    auto excluded = [&](int i) { return i < per_turn && exclusion.contains(i % nx, i / nx); };
    float best = std::numeric_limits<float>::max();
    for (int i = 0; i < count; ++i)
      if (!excluded(i)) best = std::min(best, ssd_[static_cast<size_t>(i)]);
    const bool use_exclusion = best < std::numeric_limits<float>::max();
    if (!use_exclusion)
      for (float v : ssd_) best = std::min(best, v);
    const float threshold = threshold_of(best);
    for (int i = 0; i < count; ++i) {
      if (use_exclusion && excluded(i)) continue;
      const std::pair<float, int> entry{ssd_[static_cast<size_t>(i)], i};
      if (entry.first <= threshold) candidates_.push_back(entry.second);
      if (top > 0) keep_lowest(entry, top);
    }
  }
  if (candidates_.size() < top) {
    candidates_.clear();
    for (const auto& entry : ranked_) candidates_.push_back(entry.second);
  }
}

void Quilter::compute_error(int px, int py) {
  const int channels = canvas_.channels;
  error_.assign(static_cast<size_t>(bw_) * bh_, 0.0f);
  for (int y = 0; y < bh_; ++y) {
    for (int x = 0; x < bw_; ++x) {
      const size_t i = static_cast<size_t>(y) * bw_ + x;
      if (mask_[i] == 0.0f) continue;
      const float* e = block_plane().at(px + x, py + y);
      float sum = 0.0f;
      for (int c = 0; c < channels; ++c) {
        const float d = templ_[i * channels + c] - e[c];
        sum += d * d;
      }
      error_[i] = sum;
    }
  }
}

double Quilter::block_gradient(int px, int py) const {
  const int channels = canvas_.channels;
  double sum = 0.0;
  const Plane& plane = block_plane();
  for (int y = 0; y + 1 < bh_; ++y)
    for (int x = 0; x + 1 < bw_; ++x) {
      const float* a = plane.at(px + x, py + y);
      const float* r = plane.at(px + x + 1, py + y);
      const float* d = plane.at(px + x, py + y + 1);
      for (int c = 0; c < channels; ++c) sum += std::abs(a[c] - r[c]) + std::abs(a[c] - d[c]);
    }
  return sum / (static_cast<double>(bw_ - 1) * (bh_ - 1) * channels);
}

double Quilter::mean_gradient() {
  if (mean_gradient_ < 0.0) {
    const int channels = canvas_.channels;
    double sum = 0.0;
    for (int y = 0; y + 1 < ex_.height; ++y)
      for (int x = 0; x + 1 < ex_.width; ++x) {
        const float* a = ex_.at(x, y);
        const float* r = ex_.at(x + 1, y);
        const float* d = ex_.at(x, y + 1);
        for (int c = 0; c < channels; ++c) sum += std::abs(a[c] - r[c]) + std::abs(a[c] - d[c]);
      }
    mean_gradient_ = sum / (static_cast<double>(ex_.width - 1) * (ex_.height - 1) * channels);
  }
  return mean_gradient_;
}

double Quilter::profile_deficit(int bx, int by, int px, int py) const {
  const int channels = canvas_.channels;
  auto value = [&](int x, int y) -> const float* {
    const int cx = Plane::mod(bx + x, canvas_.width);
    const int cy = Plane::mod(by + y, canvas_.height);
    const size_t i = static_cast<size_t>(y) * bw_ + x;
    if (!locked_[static_cast<size_t>(cy) * canvas_.width + cx] && (take_new_[i] || mask_[i] == 0.0f))
      return block_plane().at(px + x, py + y);
    return canvas_.at(cx, cy);
  };
  double deficit = 0.0, total = 0.0;
  for (int axis = 1; axis <= 2; ++axis) {
    if ((profile_axes_ & axis) == 0) continue;
    const bool rows = axis == 1;
    const std::vector<uint8_t>& strong = rows ? strong_rows_ : strong_cols_;
    const int lines = rows ? bh_ - 1 : bw_ - 1, along = rows ? bw_ : bh_;
    for (int o = 0; o < lines; ++o) {
      const int size = rows ? canvas_.height : canvas_.width;
      const int line = Plane::mod((rows ? by : bx) + o, size);
      if (Plane::mod(line - skip_first_, size) < skip_count_) continue;
      double now = 0.0, before = 0.0;
      for (int k = 0; k < along; ++k) {
        const int x0 = rows ? k : o, y0 = rows ? o : k;
        const int x1 = rows ? k : o + 1, y1 = rows ? o + 1 : k;
        const float* a = value(x0, y0);
        const float* b = value(x1, y1);
        const float* oa = original_->wrap(bx + x0, by + y0);
        const float* ob = original_->wrap(bx + x1, by + y1);
        for (int c = 0; c < channels; ++c) {
          now += std::abs(a[c] - b[c]);
          before += std::abs(oa[c] - ob[c]);
        }
      }
      deficit += strong[static_cast<size_t>(line)] ? std::max(0.0, now - before) : std::max(0.0, before - now);
      total += before;
    }
  }
  return total > 0.0 ? deficit / total : 0.0;
}

double Quilter::patch_cost(int bx, int by, int px, int py, double factor_a, double factor_b, double bound) {
  constexpr int kP = 7, kR = kP - 1;
  const int channels = canvas_.channels;
  const int rw = bw_ + 2 * kR, rh = bh_ + 2 * kR;
  region_val_.resize(static_cast<size_t>(rw) * rh * channels);
  region_src_.resize(static_cast<size_t>(rw) * rh);
  region_known_.resize(static_cast<size_t>(rw) * rh);
  for (int j = 0; j < rh; ++j) {
    for (int i = 0; i < rw; ++i) {
      const size_t r = static_cast<size_t>(j) * rw + i;
      const int x = i - kR, y = j - kR;
      const int cx = Plane::mod(bx + x, canvas_.width);
      const int cy = Plane::mod(by + y, canvas_.height);
      const size_t ci = static_cast<size_t>(cy) * canvas_.width + cx;
      const bool in_block = x >= 0 && y >= 0 && x < bw_ && y < bh_;
      const size_t bi = in_block ? static_cast<size_t>(y) * bw_ + x : 0;
      if (in_block && !locked_[ci] && (take_new_[bi] || mask_[bi] == 0.0f)) {
        const float* e = block_plane().at(px + x, py + y);
        std::copy(e, e + channels, &region_val_[r * channels]);
        region_src_[r] = turn_offset() + (py + y) * ex_.width + px + x;
        region_known_[r] = 1;
      } else {
        const float* e = canvas_.at(cx, cy);
        std::copy(e, e + channels, &region_val_[r * channels]);
        region_src_[r] = (*source_)[ci];
        region_known_[r] = known_[ci] && (*source_)[ci] >= 0 ? 1 : 0;
      }
    }
  }
  double total = 0.0;
  const int ew = ex_.width, eh = ex_.height;
  // Summed-area tables of: unknown pixels, and pixel pairs (right, down) that are not one
  // translated copy of the exemplar. A window with none of the latter is an exemplar patch
  // (cost 0, what the first probe would find), so only windows across a cut are measured.
  const int sw = rw + 1;
  sat_unknown_.assign(static_cast<size_t>(sw) * (rh + 1), 0);
  sat_right_.assign(static_cast<size_t>(sw) * (rh + 1), 0);
  sat_down_.assign(static_cast<size_t>(sw) * (rh + 1), 0);
  for (int j = 0; j < rh; ++j) {
    int row_unknown = 0, row_right = 0, row_down = 0;
    for (int i = 0; i < rw; ++i) {
      const size_t r = static_cast<size_t>(j) * rw + i;
      const bool known = region_known_[r] != 0;
      row_unknown += known ? 0 : 1;
      if (i + 1 < rw) row_right += known && region_known_[r + 1] && region_src_[r + 1] == region_src_[r] + 1 ? 0 : 1;
      if (j + 1 < rh)
        row_down += known && region_known_[r + static_cast<size_t>(rw)] &&
                            region_src_[r + static_cast<size_t>(rw)] == region_src_[r] + ew
                        ? 0
                        : 1;
      const size_t k = static_cast<size_t>(j + 1) * sw + i + 1;
      sat_unknown_[k] = sat_unknown_[k - static_cast<size_t>(sw)] + row_unknown;
      sat_right_[k] = sat_right_[k - static_cast<size_t>(sw)] + row_right;
      sat_down_[k] = sat_down_[k - static_cast<size_t>(sw)] + row_down;
    }
  }
  auto box = [&](const std::vector<int>& sat, int x0, int y0, int x1, int y1) {  // sum over [x0, x1) x [y0, y1)
    return sat[static_cast<size_t>(y1) * sw + x1] - sat[static_cast<size_t>(y0) * sw + x1] -
           sat[static_cast<size_t>(y1) * sw + x0] + sat[static_cast<size_t>(y0) * sw + x0];
  };
  for (int j = 0; j + kR < rh; ++j) {
    for (int i = 0; i + kR < rw; ++i) {
      if (box(sat_unknown_, i, j, i + kP, j + kP) != 0) continue;  // still holds unknown pixels
      if (box(sat_right_, i, j, i + kR, j + kP) == 0 && box(sat_down_, i, j, i + kP, j + kR) == 0) continue;
      static constexpr int kProbe[5][2] = {{0, 0}, {kR, 0}, {0, kR}, {kR, kR}, {kR / 2, kR / 2}};
      int32_t tried[5];
      int n_tried = 0;
      float best = std::numeric_limits<float>::max();
      for (const auto& probe : kProbe) {
        int32_t s = region_src_[static_cast<size_t>(j + probe[1]) * rw + i + probe[0]];
        // Quarter-turn mode: the source names a pixel of one of the exemplar's turns.
        const int32_t turn = turns_ ? s / (ew * eh) : 0;
        if (turns_) s %= ew * eh;
        const Plane& plane = turns_ ? (*turns_)[static_cast<size_t>(turn)] : ex_;
        const int ox = std::clamp(s % ew - probe[0], 0, ew - kP);
        const int oy = std::clamp(s / ew - probe[1], 0, eh - kP);
        const int32_t origin = turn * ew * eh + oy * ew + ox;
        if (std::find(tried, tried + n_tried, origin) != tried + n_tried) continue;
        tried[n_tried++] = origin;
        float sum = 0.0f;
        for (int b = 0; b < kP && sum < best; ++b) {
          const float* t = &region_val_[(static_cast<size_t>(j + b) * rw + i) * channels];
          const float* e = plane.at(ox, oy + b);
          for (int a = 0; a < kP * channels; ++a) {
            const float d = t[a] - e[a];
            sum += d * d;
          }
        }
        best = std::min(best, sum);
        if (best == 0.0f) break;
      }
      total += best;
      if (total * factor_a * factor_b > bound) return std::numeric_limits<double>::infinity();
    }
  }
  return total * factor_a * factor_b;
}

void Quilter::cut_side(int side) {
  const int length = side < 2 ? bh_ : bw_;
  const int ov = std::min(ov_, side < 2 ? bw_ : bh_);
  bool active = false;
  strip_.assign(static_cast<size_t>(length) * ov, 0.0f);
  for (int i = 0; i < length; ++i) {
    for (int j = 0; j < ov; ++j) {
      int x = 0, y = 0;
      strip_coords(side, i, j, x, y);
      const size_t k = static_cast<size_t>(y) * bw_ + x;
      if (mask_[k] != 0.0f) active = true;
      strip_[static_cast<size_t>(i) * ov + j] = error_[k];
    }
  }
  if (!active) return;
  min_error_path(strip_, length, ov, cost_, path_);
  for (int i = 0; i < length; ++i) {
    for (int j = 0; j < path_[static_cast<size_t>(i)]; ++j) {
      int x = 0, y = 0;
      strip_coords(side, i, j, x, y);
      take_new_[static_cast<size_t>(y) * bw_ + x] = 0;
    }
  }
}

void Quilter::strip_coords(int side, int i, int j, int& x, int& y) const {
  switch (side) {
    case 0:
      x = j;
      y = i;
      break;
    case 1:
      x = bw_ - 1 - j;
      y = i;
      break;
    case 2:
      x = i;
      y = j;
      break;
    default:
      x = i;
      y = bh_ - 1 - j;
      break;
  }
}

}  // namespace tailor::internal
