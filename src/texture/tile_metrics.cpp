// Quality metrics of a self-tileable texture (see TileMetrics in tailor/tiling.h).
//
// This work is based on:
//   C. Barnes, E. Shechtman, A. Finkelstein, D. B. Goldman, "PatchMatch: A Randomized Correspondence
//   Algorithm for Structural Image Editing", SIGGRAPH 2009 (approximate nearest patches for the
//   patch-coherence metric: random init, propagation, random search with halving radius).
//
// Patch coherence is evaluated on a fixed grid of tile patches (stride 1 up to 128 x 128, then the
// smallest stride giving <= 16384 patches over the smaller of tile and exemplar, at most 4 x 16384
// over the tile) so that a 512 px image costs ~0.1 s; the generator is
// seeded with a constant, so the value is deterministic. Everything works on the 8-bit samples
// in place (no float copies) and the exact-copy pass streams over the exemplar with a rolling
// hash, so a 4096 px pair costs about 1 s and 100 MB (float planes and a sorted table of every
// exemplar patch took 40 s and 1.1 GB).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "tailor/image_ops.h"
#include "tailor/tiling.h"
#include "texture/tiling_util.h"
#include "util/union_find.h"

namespace tailor {

namespace {

//! The 8-bit samples of an image, read in place (layout of image.h).
struct BytePlane {
  int width = 0, height = 0, channels = 0;
  const uint8_t* data = nullptr;
  const uint8_t* at(int x, int y) const { return data + (static_cast<size_t>(y) * width + x) * channels; }
  size_t size() const { return static_cast<size_t>(width) * height * channels; }
};

BytePlane view(const Image& image) { return {image.width, image.height, image.channels, image.pixels.data()}; }

constexpr int kPatch = 7;
constexpr int kMaxPatches = 16384;
constexpr int kMaxGridGrowth = 4;  // a tile larger than its exemplar: up to this many times the patches
constexpr int kIterations = 6;
constexpr int kSamplesPerRadius = 1;  // random samples per search radius
constexpr int kBins = 64;

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
  return m;
}

double ratio(double value, double median) {
  if (median < 1e-9) return value < 1e-9 ? 1.0 : 1e9;
  return value / median;
}

//! Mean absolute difference across each column boundary (x, x+1 mod W) and row boundary.
void boundary_differences(const BytePlane& p, std::vector<double>& cols, std::vector<double>& rows) {
  const int w = p.width, h = p.height, c = p.channels;
  cols.assign(static_cast<size_t>(w), 0.0);
  rows.assign(static_cast<size_t>(h), 0.0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const uint8_t* a = p.at(x, y);
      const uint8_t* right = p.at((x + 1) % w, y);
      const uint8_t* down = p.at(x, (y + 1) % h);
      int dx = 0, dy = 0;
      for (int k = 0; k < c; ++k) {
        dx += std::abs(a[k] - right[k]);
        dy += std::abs(a[k] - down[k]);
      }
      cols[static_cast<size_t>(x)] += dx;
      rows[static_cast<size_t>(y)] += dy;
    }
  }
  for (double& v : cols) v /= static_cast<double>(h) * c;
  for (double& v : rows) v /= static_cast<double>(w) * c;
}

struct SeamStats {
  double wrap_x = 0.0, wrap_y = 0.0, worst_all = 0.0, worst_interior = 0.0;
};

SeamStats seam_stats(const BytePlane& p) {
  std::vector<double> cols, rows;
  boundary_differences(p, cols, rows);
  const double mc = median_of(std::vector<double>(cols.begin(), cols.end() - 1));
  const double mr = median_of(std::vector<double>(rows.begin(), rows.end() - 1));
  SeamStats s;
  s.wrap_x = ratio(cols.back(), mc);
  s.wrap_y = ratio(rows.back(), mr);
  for (size_t i = 0; i < cols.size(); ++i) {
    const double r = ratio(cols[i], mc);
    s.worst_all = std::max(s.worst_all, r);
    if (i + 1 < cols.size()) s.worst_interior = std::max(s.worst_interior, r);
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    const double r = ratio(rows[i], mr);
    s.worst_all = std::max(s.worst_all, r);
    if (i + 1 < rows.size()) s.worst_interior = std::max(s.worst_interior, r);
  }
  return s;
}

double gradient_energy(const BytePlane& p) {
  const int w = p.width, h = p.height, c = p.channels;
  double sum = 0.0;
  for (int y = 0; y + 1 < h; ++y)
    for (int x = 0; x + 1 < w; ++x) {
      const uint8_t* a = p.at(x, y);
      const uint8_t* right = p.at(x + 1, y);
      const uint8_t* down = p.at(x, y + 1);
      int row = 0;
      for (int k = 0; k < c; ++k) row += std::abs(a[k] - right[k]) + std::abs(a[k] - down[k]);
      sum += row;
    }
  return sum / (static_cast<double>(w - 1) * (h - 1) * c);
}

double histogram_l1(const Image& a, const Image& b) {
  const int c = a.channels;
  double total = 0.0;
  for (int k = 0; k < c; ++k) {
    std::vector<double> ha(kBins, 0.0), hb(kBins, 0.0);
    for (size_t i = static_cast<size_t>(k); i < a.pixels.size(); i += static_cast<size_t>(c))
      ha[a.pixels[i] >> 2] += 1.0;
    for (size_t i = static_cast<size_t>(k); i < b.pixels.size(); i += static_cast<size_t>(c))
      hb[b.pixels[i] >> 2] += 1.0;
    const double na = static_cast<double>(a.pixels.size() / static_cast<size_t>(c));
    const double nb = static_cast<double>(b.pixels.size() / static_cast<size_t>(c));
    for (int i = 0; i < kBins; ++i)
      total += std::abs(ha[static_cast<size_t>(i)] / na - hb[static_cast<size_t>(i)] / nb);
  }
  return total / c;
}

//! Mean over channels of the per-channel variance (8-bit units squared).
double variance(const BytePlane& p) {
  const int c = p.channels;
  const double n = static_cast<double>(p.width) * p.height;
  double total = 0.0;
  for (int k = 0; k < c; ++k) {
    double s = 0.0, s2 = 0.0;
    for (size_t i = static_cast<size_t>(k); i < p.size(); i += static_cast<size_t>(c)) {
      s += p.data[i];
      s2 += static_cast<double>(p.data[i]) * p.data[i];
    }
    total += std::max(0.0, s2 / n - (s / n) * (s / n));
  }
  return total / c;
}

//! PatchMatch nearest-patch distances from a fixed grid of (toroidal) `source` patches to the
//! patches of `target` (non-toroidal): `cost` gets each grid patch's squared distance (summed over
//! its samples).
void nearest_patch_costs(const BytePlane& source, const BytePlane& target, std::vector<float>& cost);

//! The smallest stride whose grid over a w x h image holds at most `limit` patches.
int patch_stride(int w, int h, int limit) {
  int stride = 1;
  while ((((w + stride - 1) / stride) * ((h + stride - 1) / stride)) > limit) ++stride;
  return stride;
}

//! The mean per-sample squared distance of nearest_patch_costs; with `turns`, the nearest over
//! the target and its three quarter turns.
double mean_nearest_patch_distance(const BytePlane& source, const BytePlane& target, bool turns = false) {
  std::vector<float> cost, other;
  nearest_patch_costs(source, target, cost);
  if (turns) {
    std::vector<uint8_t> prev(target.data, target.data + target.size()), next(prev.size());
    BytePlane turned = target;
    for (int k = 1; k < 4; ++k) {
      const BytePlane from{turned.width, turned.height, turned.channels, prev.data()};
      turned.width = from.height;
      turned.height = from.width;
      turned.data = next.data();
      for (int y = 0; y < from.height; ++y)
        for (int x = 0; x < from.width; ++x) {
          const uint8_t* v = from.at(x, y);
          std::copy(v, v + from.channels,
                    next.data() + (static_cast<size_t>(x) * turned.width + from.height - 1 - y) * turned.channels);
        }
      nearest_patch_costs(source, turned, other);
      prev.swap(next);
      turned.data = prev.data();
      for (size_t i = 0; i < cost.size(); ++i) cost[i] = std::min(cost[i], other[i]);
    }
  }
  double total = 0.0;
  for (float v : cost) total += v;
  return total / (static_cast<double>(cost.size()) * kPatch * kPatch * source.channels);
}

void nearest_patch_costs(const BytePlane& source, const BytePlane& target, std::vector<float>& cost) {
  const int c = source.channels;
  const int w = source.width, h = source.height;
  const int pw = w + kPatch - 1, ph = h + kPatch - 1;
  std::vector<uint8_t> padded(static_cast<size_t>(pw) * ph * c);
  for (int y = 0; y < ph; ++y)
    for (int x = 0; x < pw; ++x) {
      const uint8_t* s = source.at(x % w, y % h);
      std::copy(s, s + c, &padded[(static_cast<size_t>(y) * pw + x) * c]);
    }
  const int tx = target.width - kPatch + 1, ty = target.height - kPatch + 1;
  // The stride of the smaller image: at a stride above 1 PatchMatch's propagation between grid
  // neighbours helps less and the estimate of a patch across a cut rises (a 2 x 2 repeat of a
  // 512 px tile read 2x the tile's coherence at stride 8), so a tile larger than its exemplar
  // (symmetry 4: twice the side) is sampled as finely as the exemplar's own baseline, up to
  // kMaxPatches x kMaxGridGrowth patches.
  const int stride =
      std::max(std::min(patch_stride(w, h, kMaxPatches), patch_stride(target.width, target.height, kMaxPatches)),
               patch_stride(w, h, kMaxPatches * kMaxGridGrowth));
  const int gx = (w + stride - 1) / stride, gy = (h + stride - 1) / stride;
  const int ox = std::max(0, w - (kPatch - 1) - (gx - 1) * stride);
  const int oy = std::max(0, h - (kPatch - 1) - (gy - 1) * stride);
  const size_t count = static_cast<size_t>(gx) * gy;

  // Integer sums (exact: at most 49 x 4 x 255^2 < 2^24), returned as float.
  auto distance = [&](int sx, int sy, int u, int v, float bound) {
    int sum = 0;
    for (int j = 0; j < kPatch; ++j) {
      const uint8_t* a = &padded[(static_cast<size_t>(sy + j) * pw + sx) * c];
      const uint8_t* b = target.at(u, v + j);
      for (int i = 0; i < kPatch * c; ++i) {
        const int d = a[i] - b[i];
        sum += d * d;
      }
      if (static_cast<float>(sum) >= bound) return static_cast<float>(sum);
    }
    return static_cast<float>(sum);
  };

  std::vector<int> nu(count), nv(count);
  cost.assign(count, 0.0f);
  internal::SplitMix64 rng(0x5EED5EEDull);
  for (size_t i = 0; i < count; ++i) {
    const int sx = ox + static_cast<int>(i % static_cast<size_t>(gx)) * stride;
    const int sy = oy + static_cast<int>(i / static_cast<size_t>(gx)) * stride;
    nu[i] = static_cast<int>(rng.below(static_cast<uint32_t>(tx)));
    nv[i] = static_cast<int>(rng.below(static_cast<uint32_t>(ty)));
    cost[i] = distance(sx, sy, nu[i], nv[i], std::numeric_limits<float>::max());
  }
  // Patches copied verbatim: the first exemplar position (raster order) holding the same samples.
  // Polynomial hash (mod 2^64) of the 7 x 7 x c samples, row-major; over the exemplar it is rolled
  // along x (row hashes) and then along y, O(1) per position and channel.
  constexpr uint64_t kBase = 0x100000001B3ull;
  const int row_len = kPatch * c;
  uint64_t pow_row = 1;  // kBase^(row_len)
  for (int i = 0; i < row_len; ++i) pow_row *= kBase;
  uint64_t pow_c = 1;  // kBase^c
  for (int i = 0; i < c; ++i) pow_c *= kBase;
  uint64_t pow_block = 1;  // kBase^(row_len * kPatch)
  for (int j = 0; j < kPatch; ++j) pow_block *= pow_row;
  std::vector<std::pair<uint64_t, uint32_t>> wanted(count);
  for (size_t i = 0; i < count; ++i) {
    const int sx = ox + static_cast<int>(i % static_cast<size_t>(gx)) * stride;
    const int sy = oy + static_cast<int>(i / static_cast<size_t>(gx)) * stride;
    uint64_t hv = 0;
    for (int j = 0; j < kPatch; ++j) {
      const uint8_t* row = &padded[(static_cast<size_t>(sy + j) * pw + sx) * c];
      for (int k = 0; k < row_len; ++k) hv = hv * kBase + row[k];
    }
    wanted[i] = {hv, static_cast<uint32_t>(i)};
  }
  std::sort(wanted.begin(), wanted.end());
  // A bit per hash bucket in front of the binary search: most exemplar positions hold no wanted
  // patch, and the search over 16384 entries per position dominated the cost at 4096 px.
  constexpr int kFilterBits = 22;
  std::vector<uint64_t> filter((size_t{1} << kFilterBits) / 64, 0);
  auto bucket = [](uint64_t hv) { return static_cast<size_t>((hv * 0x9E3779B97F4A7C15ull) >> (64 - kFilterBits)); };
  for (const auto& entry : wanted) filter[bucket(entry.first) / 64] |= uint64_t{1} << (bucket(entry.first) % 64);
  // The first entry of `wanted` from k on whose patch is not found yet: found entries point past
  // themselves (paths halved on the way), so that a hash many patches share (a flat image: one
  // hash for all of them) costs a walk over the unfound ones only, not over all at every position.
  std::vector<uint32_t> skip(count + 1);
  for (size_t k = 0; k <= count; ++k) skip[k] = static_cast<uint32_t>(k);
  auto unfound = [&skip](size_t k) { return size_t{internal::find_root(skip.data(), static_cast<uint32_t>(k))}; };
  std::vector<uint64_t> rows(static_cast<size_t>(kPatch + 1) * tx), column(static_cast<size_t>(tx), 0);
  auto row_hashes = [&](int y, uint64_t* out) {
    const uint8_t* r = target.at(0, y);
    uint64_t hv = 0;
    for (int k = 0; k < row_len; ++k) hv = hv * kBase + r[k];
    out[0] = hv;
    for (int x = 1; x < tx; ++x) {
      const uint8_t* gone = r + static_cast<size_t>(x - 1) * c;
      const uint8_t* come = r + static_cast<size_t>(x - 1 + kPatch) * c;
      uint64_t drop = 0, add = 0;
      for (int k = 0; k < c; ++k) {
        drop = drop * kBase + gone[k];
        add = add * kBase + come[k];
      }
      hv = hv * pow_c - drop * pow_row + add;
      out[x] = hv;
    }
  };
  for (int y = 0; y < target.height; ++y) {
    uint64_t* slot = &rows[static_cast<size_t>(y % (kPatch + 1)) * tx];
    row_hashes(y, slot);
    const uint64_t* old = &rows[static_cast<size_t>((y + 1) % (kPatch + 1)) * tx];  // row y - kPatch
    for (int x = 0; x < tx; ++x) {
      column[static_cast<size_t>(x)] =
          column[static_cast<size_t>(x)] * pow_row + slot[x] - (y >= kPatch ? old[x] * pow_block : 0);
    }
    const int v = y - kPatch + 1;  // patches starting on row v are complete
    if (v < 0) continue;
    for (int u = 0; u < tx; ++u) {
      const uint64_t hv = column[static_cast<size_t>(u)];
      if (((filter[bucket(hv) / 64] >> (bucket(hv) % 64)) & 1u) == 0) continue;
      const auto first = std::lower_bound(wanted.begin(), wanted.end(), std::make_pair(hv, uint32_t{0}));
      for (size_t k = unfound(static_cast<size_t>(first - wanted.begin())); k < count && wanted[k].first == hv;
           k = unfound(k + 1)) {
        const size_t i = wanted[k].second;
        const int sx = ox + static_cast<int>(i % static_cast<size_t>(gx)) * stride;
        const int sy = oy + static_cast<int>(i / static_cast<size_t>(gx)) * stride;
        if (distance(sx, sy, u, v, 1.0f) == 0.0f) {
          skip[k] = static_cast<uint32_t>(k + 1);
          nu[i] = u;
          nv[i] = v;
          cost[i] = 0.0f;
        }
      }
    }
  }
  auto try_candidate = [&](size_t i, int sx, int sy, int u, int v) {
    u = std::clamp(u, 0, tx - 1);
    v = std::clamp(v, 0, ty - 1);
    if (u == nu[i] && v == nv[i]) return;
    const float d = distance(sx, sy, u, v, cost[i]);
    if (d < cost[i]) {
      cost[i] = d;
      nu[i] = u;
      nv[i] = v;
    }
  };
  const int max_radius = std::max(target.width, target.height);
  for (int iter = 0; iter < kIterations; ++iter) {
    const bool forward = iter % 2 == 0;
    const int step = forward ? 1 : -1;
    for (size_t n = 0; n < count; ++n) {
      const size_t i = forward ? n : count - 1 - n;
      if (cost[i] == 0.0f) continue;  // already exact
      const int ix = static_cast<int>(i % static_cast<size_t>(gx)), iy = static_cast<int>(i / static_cast<size_t>(gx));
      const int sx = ox + ix * stride, sy = oy + iy * stride;
      // Propagation from the previous neighbours in scan order.
      const int px = ix - step, py = iy - step;
      if (px >= 0 && px < gx) {
        const size_t k = static_cast<size_t>(iy) * gx + px;
        try_candidate(i, sx, sy, nu[k] + step * stride, nv[k]);
      }
      if (py >= 0 && py < gy) {
        const size_t k = static_cast<size_t>(py) * gx + ix;
        try_candidate(i, sx, sy, nu[k], nv[k] + step * stride);
      }
      // Random search around the current best with a halving radius.
      for (int r = max_radius; r >= 1; r /= 2) {
        for (int rep = 0; rep < kSamplesPerRadius; ++rep) {
          const int du = static_cast<int>(rng.below(static_cast<uint32_t>(2 * r + 1))) - r;
          const int dv = static_cast<int>(rng.below(static_cast<uint32_t>(2 * r + 1))) - r;
          try_candidate(i, sx, sy, nu[i] + du, nv[i] + dv);
        }
      }
    }
  }
}

}  // namespace

int quarter_turn_difference(const Image& tile, int* shift_x, int* shift_y) {
  if (!check_image(tile).is_ok() || tile.width != tile.height) return -1;
  const int n = tile.width, c = tile.channels;
  int best = -1, best_sx = 0, best_sy = 0;
  for (int sy : {0, n / 2})
    for (int sx : {0, n / 2}) {
      // rot90(tile)(x, y) = tile(y, n - 1 - x) (the inverse of r in Quilter::set_quarter_turns),
      // against tile((x + sx) % n, (y + sy) % n).
      int worst = 0;
      for (int y = 0; y < n && (best < 0 || worst < best) && worst < 255; ++y)
        for (int x = 0; x < n; ++x) {
          const uint8_t* a = &tile.pixels[(static_cast<size_t>(n - 1 - x) * n + y) * c];
          const uint8_t* b = &tile.pixels[(static_cast<size_t>((y + sy) % n) * n + (x + sx) % n) * c];
          for (int k = 0; k < c; ++k)
            worst = std::max(worst, std::abs(static_cast<int>(a[k]) - static_cast<int>(b[k])));
        }
      if (best < 0 || worst < best) {
        best = worst;
        best_sx = sx;
        best_sy = sy;
      }
    }
  if (shift_x) *shift_x = best_sx;
  if (shift_y) *shift_y = best_sy;
  return best;
}

double orientation_anisotropy(const Image& image) {
  if (!check_image(image).is_ok() || image.width < 3 || image.height < 3) return 0.0;
  const Image grey = image.channels == 1 ? image : to_grey(image);
  const int w = grey.width, h = grey.height;
  auto at = [&](int x, int y) { return static_cast<double>(grey.pixels[static_cast<size_t>(y) * w + x]); };
  double jxx = 0.0, jyy = 0.0, jxy = 0.0;
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      const double gx = at(x + 1, y) - at(x - 1, y), gy = at(x, y + 1) - at(x, y - 1);
      jxx += gx * gx;
      jyy += gy * gy;
      jxy += gx * gy;
    }
  const double trace = jxx + jyy;
  if (trace <= 0.0) return 0.0;
  return std::sqrt((jxx - jyy) * (jxx - jyy) + 4.0 * jxy * jxy) / trace;
}

Status wrap_ratios(const Image& tile, double& x, double& y) {
  x = y = 0.0;
  TAILOR_RETURN_IF_ERROR(check_image(tile));
  if (tile.width < 8 || tile.height < 8)
    return Status::error(ErrorCode::kInvalidImage, "", "image too small to evaluate (at least 8 px a side)");
  const SeamStats s = seam_stats(view(tile));
  x = s.wrap_x;
  y = s.wrap_y;
  return Status::ok();
}

Status tile_metrics(const Image& tile_in, const Image* exemplar_in, TileMetrics& metrics) {
  metrics = TileMetrics{};
  TAILOR_RETURN_IF_ERROR(check_image(tile_in));
  if (tile_in.width < 8 || tile_in.height < 8)
    return Status::error(ErrorCode::kInvalidImage, "", "image too small to evaluate (at least 8 px a side)");
  // Read in place; only differing channel counts need luminance copies.
  Image tile_grey, exemplar_grey;
  const Image* tile_ptr = &tile_in;
  const Image* exemplar_ptr = exemplar_in;
  if (exemplar_in) {
    TAILOR_RETURN_IF_ERROR(check_image(*exemplar_in));
    if (exemplar_in->width < 8 || exemplar_in->height < 8)
      return Status::error(ErrorCode::kInvalidImage, "", "exemplar too small to evaluate (at least 8 px a side)");
    if (exemplar_in->channels != tile_in.channels) {
      tile_grey = to_grey(tile_in);
      exemplar_grey = to_grey(*exemplar_in);
      tile_ptr = &tile_grey;
      exemplar_ptr = &exemplar_grey;
    }
  }
  const Image& tile = *tile_ptr;
  metrics.quarter_turn_difference =
      quarter_turn_difference(tile, &metrics.quarter_turn_shift_x, &metrics.quarter_turn_shift_y);
  const BytePlane tp = view(tile);
  const SeamStats ts = seam_stats(tp);
  metrics.wrap_ratio_x = ts.wrap_x;
  metrics.wrap_ratio_y = ts.wrap_y;
  metrics.worst_seam_ratio = ts.worst_all;
  metrics.gradient_energy = gradient_energy(tp);
  if (!exemplar_in) return Status::ok();

  const Image& exemplar = *exemplar_ptr;
  const BytePlane ep = view(exemplar);
  const SeamStats es = seam_stats(ep);
  metrics.has_exemplar = true;
  metrics.exemplar_worst_seam_ratio = es.worst_interior;
  metrics.exemplar_wrap_ratio_x = es.wrap_x;
  metrics.exemplar_wrap_ratio_y = es.wrap_y;
  metrics.histogram_l1 = histogram_l1(tile, exemplar);
  const double eg = gradient_energy(ep);
  metrics.gradient_ratio = ratio(metrics.gradient_energy, eg);
  const double var = std::max(variance(ep), 1e-6);
  if (ep.width >= kPatch && ep.height >= kPatch) {
    // A quarter-turn tile holds every patch in four orientations: compare with all four.
    const bool turns = metrics.quarter_turn_difference == 0;
    metrics.coherence_with_turns = turns;
    metrics.patch_coherence = mean_nearest_patch_distance(tp, ep, turns) / var;
    metrics.exemplar_patch_coherence = mean_nearest_patch_distance(ep, ep, turns) / var;
  }
  return Status::ok();
}

namespace internal {

double fast_target_misses(const Image& tile, const Image& exemplar) {
  if (!check_image(tile).is_ok() || !check_image(exemplar).is_ok() || tile.channels != exemplar.channels) return 1e9;
  const SeamStats ts = seam_stats(view(tile)), es = seam_stats(view(exemplar));
  double misses = 0.0;
  auto over = [&](double value, double limit) { misses += std::max(0.0, value / limit - 1.0); };
  over(ts.worst_all, std::max(es.worst_interior, 1.5));
  over(std::max(ts.wrap_x, ts.wrap_y), 1.2);
  over(0.8, std::min(ts.wrap_x, ts.wrap_y));
  over(histogram_l1(tile, exemplar), 0.1);
  over(0.95, ratio(gradient_energy(view(tile)), gradient_energy(view(exemplar))));
  return misses;
}

}  // namespace internal

namespace {

//! Every target of meets_tile_targets in one place: `check(ok, label, figure)` is called once per
//! target, with the label meets_tile_targets lists and the same with the measured figure.
template <typename Check>
void each_tile_target(const TileMetrics& m, Check check) {
  auto fixed = [](double v, int digits) {
    char text[32];
    std::snprintf(text, sizeof text, "%.*f", digits, v);
    return std::string(text);
  };
  check(m.wrap_ratio_x >= 0.8 && m.wrap_ratio_x <= 1.2, "wrap ratio x outside [0.8, 1.2]",
        "wrap ratio x " + fixed(m.wrap_ratio_x, 2) + " outside [0.8, 1.2]");
  check(m.wrap_ratio_y >= 0.8 && m.wrap_ratio_y <= 1.2, "wrap ratio y outside [0.8, 1.2]",
        "wrap ratio y " + fixed(m.wrap_ratio_y, 2) + " outside [0.8, 1.2]");
  if (m.has_exemplar) {
    const double seam = std::max(m.exemplar_worst_seam_ratio, 1.5);
    check(m.worst_seam_ratio <= seam, "worst seam above the exemplar's (and 1.5)",
          "worst seam " + fixed(m.worst_seam_ratio, 3) + " above " + fixed(seam, 3) + " (the exemplar's " +
              fixed(m.exemplar_worst_seam_ratio, 3) + ", at least 1.5)");
    check(m.histogram_l1 <= 0.1, "histogram L1 above 0.1", "histogram L1 " + fixed(m.histogram_l1, 3) + " above 0.1");
    check(m.gradient_ratio >= 0.95, "gradient ratio below 0.95",
          "gradient ratio " + fixed(m.gradient_ratio, 3) + " below 0.95");
    // No allowance: the estimator is deterministic (constant seed), and it can only overestimate
    // the tile's figure (patches not copied verbatim are matched approximately).
    check(m.patch_coherence <= m.exemplar_patch_coherence, "patch coherence worse than the exemplar's",
          "patch coherence " + fixed(m.patch_coherence, 4) + " above the exemplar's " +
              fixed(m.exemplar_patch_coherence, 4));
  } else {
    check(m.worst_seam_ratio <= 1.5, "worst seam above 1.5",
          "worst seam " + fixed(m.worst_seam_ratio, 3) + " above 1.5");
  }
}

}  // namespace

bool meets_tile_targets(const TileMetrics& m, std::string* failed) {
  std::string out;
  each_tile_target(m, [&](bool ok, const char* what, const std::string&) {
    if (!ok) out += (out.empty() ? "" : ", ") + std::string(what);
  });
  if (failed) *failed = out;
  return out.empty();
}

std::vector<std::string> missed_tile_targets(const TileMetrics& m) {
  std::vector<std::string> out;
  each_tile_target(m, [&](bool ok, const char*, const std::string& figure) {
    if (!ok) out.push_back(figure);
  });
  return out;
}

}  // namespace tailor
