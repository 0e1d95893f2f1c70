// Full-size replay of a reduced quilting plan, and the composition of every map through its
// source map (cut_refine.h).
#include "texture/cut_refine.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <type_traits>
#include <vector>

#include "texture/tiling_util.h"

namespace tailor::internal {

void min_error_path(const std::vector<float>& err, int length, int width, std::vector<float>& cost,
                    std::vector<int>& path) {
  cost.assign(err.begin(), err.begin() + static_cast<size_t>(length) * width);
  for (int i = 1; i < length; ++i) {
    for (int j = 0; j < width; ++j) {
      float best = cost[static_cast<size_t>(i - 1) * width + j];
      if (j > 0) best = std::min(best, cost[static_cast<size_t>(i - 1) * width + j - 1]);
      if (j + 1 < width) best = std::min(best, cost[static_cast<size_t>(i - 1) * width + j + 1]);
      cost[static_cast<size_t>(i) * width + j] += best;
    }
  }
  path.assign(static_cast<size_t>(length), 0);
  int j = 0;
  for (int k = 1; k < width; ++k)
    if (cost[static_cast<size_t>(length - 1) * width + k] < cost[static_cast<size_t>(length - 1) * width + j]) j = k;
  path[static_cast<size_t>(length - 1)] = j;
  for (int i = length - 2; i >= 0; --i) {
    int next = j;
    for (int k = std::max(0, j - 1); k <= std::min(width - 1, j + 1); ++k)
      if (cost[static_cast<size_t>(i) * width + k] < cost[static_cast<size_t>(i) * width + next]) next = k;
    j = next;
    path[static_cast<size_t>(i)] = j;
  }
}

CutRefiner::CutRefiner(const Guide& guide, int plan_width, int plan_height)
    : guide_(guide), plan_w_(plan_width), plan_h_(plan_height) {
  cell_x_.assign(static_cast<size_t>(guide.width), 0);
  cell_y_.assign(static_cast<size_t>(guide.height), 0);
  for (int v = 0; v < plan_w_; ++v)
    for (int x = map_x(v); x < map_x(v + 1); ++x) cell_x_[static_cast<size_t>(x)] = v;
  for (int v = 0; v < plan_h_; ++v)
    for (int y = map_y(v); y < map_y(v + 1); ++y) cell_y_[static_cast<size_t>(y)] = v;
}

void CutRefiner::upsample(const std::vector<uint8_t>& reduced, std::vector<uint8_t>& full) const {
  const int w = guide_.width, h = guide_.height;
  full.resize(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = &reduced[static_cast<size_t>(cell_y_[static_cast<size_t>(y)]) * plan_w_];
    for (int x = 0; x < w; ++x) full[static_cast<size_t>(y) * w + x] = row[cell_x_[static_cast<size_t>(x)]];
  }
}

void CutRefiner::choose_wrap(int plan_shift_x, int plan_shift_y) {
  const int w = guide_.width, h = guide_.height, c = guide_.channels;
  std::vector<double> cols(static_cast<size_t>(w), 0.0), rows(static_cast<size_t>(h), 0.0);
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = &guide_.px[static_cast<size_t>(y) * w * c];
    const uint8_t* up = y > 0 ? row - static_cast<size_t>(w) * c : nullptr;
    int64_t across = 0;
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) {
        const int v = row[x * c + k];
        if (x > 0) cols[static_cast<size_t>(x)] += std::abs(v - row[(x - 1) * c + k]);
        if (up) across += std::abs(v - up[x * c + k]);
      }
    rows[static_cast<size_t>(y)] = static_cast<double>(across);
  }
  // The most ordinary boundary within half a plan pixel of the planned one.
  shift_x_ = ordinary_boundary(cols, Plane::mod(map_x(plan_shift_x), w), std::max(0, (w / plan_w_) / 2));
  shift_y_ = ordinary_boundary(rows, Plane::mod(map_y(plan_shift_y), h), std::max(0, (h / plan_h_) / 2));
}

void CutRefiner::replay(const TilePlan& plan, size_t s, const std::vector<int32_t>* base, int radius) {
  const int w = guide_.width, h = guide_.height;
  const SessionRecord& session = plan.sessions[s];
  if (base) {
    source_ = *base;
  } else {
    const int sx = shift_x_ >= 0 ? shift_x_ : Plane::mod(map_x(plan.shift_x), w);
    const int sy = shift_y_ >= 0 ? shift_y_ : Plane::mod(map_y(plan.shift_y), h);
    source_.resize(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        source_[static_cast<size_t>(y) * w + x] = static_cast<int32_t>(((y + sy) % h) * w + (x + sx) % w);
  }
  upsample(session.known, known_);
  upsample(session.locked, locked_);
  for (const Placement& p : session.placements) place(p, session.overlap, radius);
}

void CutRefiner::place(const Placement& p, int overlap, int radius) {
  const int w = guide_.width, h = guide_.height, c = guide_.channels;
  const uint8_t* g = guide_.px;
  const int bx = map_x(p.bx), by = map_y(p.by);
  const int bw = std::min(w, map_x(p.bx + p.bw) - bx), bh = std::min(h, map_y(p.by + p.bh) - by);
  const int px0 = std::clamp(map_x(p.px), 0, w - bw), py0 = std::clamp(map_y(p.py), 0, h - bh);
  const size_t area = static_cast<size_t>(bw) * bh;
  // The block's known canvas pixels, by the exemplar pixel they show (-1: unknown).
  templ_.resize(area);
  for (int y = 0; y < bh; ++y) {
    const int cy = Plane::mod(by + y, h);
    for (int x = 0; x < bw; ++x) {
      const size_t ci = static_cast<size_t>(cy) * w + Plane::mod(bx + x, w);
      templ_[static_cast<size_t>(y) * bw + x] = known_[ci] ? source_[ci] : -1;
    }
  }
  // Refinement: the source within `radius` px of the scaled one with the lowest SSD over the
  // known pixels (ties to the first in raster order, so the result does not depend on anything
  // but the input).
  auto ssd = [&](int qx, int qy, double bound) {
    double sum = 0.0;
    for (int y = 0; y < bh; ++y) {
      const int32_t* t = &templ_[static_cast<size_t>(y) * bw];
      const uint8_t* e = &g[(static_cast<size_t>(qy + y) * w + qx) * c];
      int64_t row = 0;
      for (int x = 0; x < bw; ++x) {
        if (t[x] < 0) continue;
        const uint8_t* a = &g[static_cast<size_t>(t[x]) * c];
        for (int k = 0; k < c; ++k) {
          const int d = static_cast<int>(a[k]) - static_cast<int>(e[x * c + k]);
          row += d * d;
        }
      }
      sum += static_cast<double>(row);
      if (sum > bound) break;
    }
    return sum;
  };
  int px = px0, py = py0;
  if (radius > 0) {
    double best = ssd(px0, py0, std::numeric_limits<double>::max());
    for (int qy = std::max(0, py0 - radius); qy <= std::min(h - bh, py0 + radius); ++qy)
      for (int qx = std::max(0, px0 - radius); qx <= std::min(w - bw, px0 + radius); ++qx) {
        if (qx == px0 && qy == py0) continue;
        const double v = ssd(qx, qy, best);
        if (v < best) {
          best = v;
          px = qx;
          py = qy;
        }
      }
  }
  error_.assign(area, 0.0f);
  for (int y = 0; y < bh; ++y)
    for (int x = 0; x < bw; ++x) {
      const int32_t t = templ_[static_cast<size_t>(y) * bw + x];
      if (t < 0) continue;
      const uint8_t* a = &g[static_cast<size_t>(t) * c];
      const uint8_t* e = &g[(static_cast<size_t>(py + y) * w + px + x) * c];
      int sum = 0;
      for (int k = 0; k < c; ++k) sum += (a[k] - e[k]) * (a[k] - e[k]);
      error_[static_cast<size_t>(y) * bw + x] = static_cast<float>(sum);
    }
  // Minimum-error boundary cut on every side whose overlap strip holds known pixels.
  take_new_.assign(area, 1);
  for (int side = 0; side < 4; ++side) {
    const int length = side < 2 ? bh : bw;
    const int depth = std::min(std::max(1, side < 2 ? map_x(overlap) : map_y(overlap)), side < 2 ? bw : bh);
    auto coords = [&](int i, int j, int& x, int& y) {
      x = side == 0 ? j : side == 1 ? bw - 1 - j : i;
      y = side < 2 ? i : side == 2 ? j : bh - 1 - j;
    };
    bool active = false;
    strip_.assign(static_cast<size_t>(length) * depth, 0.0f);
    for (int i = 0; i < length; ++i)
      for (int j = 0; j < depth; ++j) {
        int x = 0, y = 0;
        coords(i, j, x, y);
        const size_t k = static_cast<size_t>(y) * bw + x;
        if (templ_[k] >= 0) active = true;
        strip_[static_cast<size_t>(i) * depth + j] = error_[k];
      }
    if (!active) continue;
    min_error_path(strip_, length, depth, cost_, path_);
    for (int i = 0; i < length; ++i)
      for (int j = 0; j < path_[static_cast<size_t>(i)]; ++j) {
        int x = 0, y = 0;
        coords(i, j, x, y);
        take_new_[static_cast<size_t>(y) * bw + x] = 0;
      }
  }
  for (int y = 0; y < bh; ++y) {
    const int cy = Plane::mod(by + y, h);
    for (int x = 0; x < bw; ++x) {
      const size_t i = static_cast<size_t>(y) * bw + x;
      const size_t ci = static_cast<size_t>(cy) * w + Plane::mod(bx + x, w);
      if (locked_[ci]) continue;
      if (take_new_[i] || templ_[i] < 0) {
        source_[ci] = static_cast<int32_t>((py + y) * w + px + x);
        known_[ci] = 1;
      }
    }
  }
}

namespace {
// (x, y, z) scaled to unit length; a null vector becomes (0, 0, 1), the flat normal.
void unit_or_up(double& x, double& y, double& z) {
  const double len = std::sqrt(x * x + y * y + z * z);
  if (len < 1e-9) {
    x = y = 0.0;
    z = 1.0;
  } else {
    x /= len;
    y /= len;
    z /= len;
  }
}
}  // namespace

template <typename T>
void compose(const T* in, int width, int height, int channels, int max_value, BlendKind kind,
             const std::vector<int32_t>& source, int feather, std::vector<T>& out) {
  const int w = width, h = height, c = channels;
  out.resize(static_cast<size_t>(w) * h * c);
  const bool normal = kind == BlendKind::kNormal && c >= 3;
  const double half = max_value / 2.0;
  // Writes the vector (x, y, z) in [-1, 1] renormalised (a null vector becomes (0, 0, 1)).
  auto put_normal = [&](double nx, double ny, double nz, T* o) {
    unit_or_up(nx, ny, nz);
    o[0] = static_cast<T>(std::lround(std::clamp((nx + 1.0) * half, 0.0, static_cast<double>(max_value))));
    o[1] = static_cast<T>(std::lround(std::clamp((ny + 1.0) * half, 0.0, static_cast<double>(max_value))));
    o[2] = static_cast<T>(std::lround(std::clamp((nz + 1.0) * half, 0.0, static_cast<double>(max_value))));
  };
  auto offset = [&](int x, int y) {  // source - pixel, toroidal
    const int32_t s = source[static_cast<size_t>(y) * w + x];
    return std::pair<int, int>{Plane::mod(s % w - x, w), Plane::mod(s / w - y, h)};
  };
  // near[p]: within `feather` px (a (2 feather + 1)^2 window) of a pixel whose offset differs
  // from its right or lower neighbour's. Elsewhere the window holds one offset only (a window
  // marked near may also hold one: the mean of equal values is the value).
  std::vector<uint8_t> near(static_cast<size_t>(w) * h, 0);
  if (feather > 0) {
    std::vector<int32_t> ox(static_cast<size_t>(w) * 2), oy(static_cast<size_t>(w) * 2);
    auto fill_row = [&](int y, int slot) {
      for (int x = 0; x < w; ++x) {
        const int32_t s = source[static_cast<size_t>(y) * w + x];
        ox[static_cast<size_t>(slot) * w + x] = Plane::mod(s % w - x, w);
        oy[static_cast<size_t>(slot) * w + x] = Plane::mod(s / w - y, h);
      }
    };
    std::vector<uint8_t> cut(static_cast<size_t>(w) * h, 0);
    fill_row(0, 0);
    for (int y = 0; y < h; ++y) {
      const int cur = y & 1, next = cur ^ 1;
      if (y + 1 < h)
        fill_row(y + 1, next);
      else
        fill_row(0, next);
      const int32_t* cx = &ox[static_cast<size_t>(cur) * w];
      const int32_t* cy = &oy[static_cast<size_t>(cur) * w];
      const int32_t* nx = &ox[static_cast<size_t>(next) * w];
      const int32_t* ny = &oy[static_cast<size_t>(next) * w];
      for (int x = 0; x < w; ++x) {
        const int r = x + 1 < w ? x + 1 : 0;
        cut[static_cast<size_t>(y) * w + x] = cx[r] != cx[x] || cy[r] != cy[x] || nx[x] != cx[x] || ny[x] != cy[x];
      }
    }
    // Separable dilation by the window: rows, then columns (toroidal).
    std::vector<uint8_t> rows(static_cast<size_t>(w) * h, 0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (cut[static_cast<size_t>(y) * w + x])
          for (int d = -feather; d <= feather; ++d) rows[static_cast<size_t>(y) * w + Plane::mod(x + d, w)] = 1;
    for (int y = 0; y < h; ++y)
      for (int d = -feather; d <= feather; ++d) {
        const uint8_t* r = &rows[static_cast<size_t>(Plane::mod(y + d, h)) * w];
        uint8_t* o = &near[static_cast<size_t>(y) * w];
        for (int x = 0; x < w; ++x) o[x] |= r[x];
      }
  }
  std::vector<double> acc(static_cast<size_t>(c));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      T* o = &out[i * c];
      if (!near[i]) {
        const T* s = &in[static_cast<size_t>(source[i]) * c];
        if (normal) {
          put_normal(s[0] / half - 1.0, s[1] / half - 1.0, s[2] / half - 1.0, o);
          for (int k = 3; k < c; ++k) o[k] = s[k];
        } else {
          std::copy(s, s + c, o);
        }
        continue;
      }
      // The window's mean of in(p + offset q) over its pixels q.
      std::fill(acc.begin(), acc.end(), 0.0);
      int n = 0;
      for (int dy = -feather; dy <= feather; ++dy)
        for (int dx = -feather; dx <= feather; ++dx) {
          const auto off = offset(Plane::mod(x + dx, w), Plane::mod(y + dy, h));
          const T* s = &in[(static_cast<size_t>((y + off.second) % h) * w + (x + off.first) % w) * c];
          for (int k = 0; k < c; ++k) acc[static_cast<size_t>(k)] += normal && k < 3 ? s[k] / half - 1.0 : s[k];
          ++n;
        }
      if (normal) {
        put_normal(acc[0], acc[1], acc[2], o);
        for (int k = 3; k < c; ++k) o[k] = static_cast<T>(std::lround(acc[static_cast<size_t>(k)] / n));
      } else {
        for (int k = 0; k < c; ++k) o[k] = static_cast<T>(std::lround(acc[static_cast<size_t>(k)] / n));
      }
    }
}

template <typename T>
void read_quarter_turn(const T* in, int width, int channels, double max_value, bool normal, bool y_down,
                       const QuarterTurnPlan& plan, std::vector<T>& out) {
  const int S = plan.full_side, c = channels, n = plan.n, s = plan.s, big_n = plan.tile_side, m = big_n / 2;
  const int half_n = n / 2;
  const bool vectors = normal && c >= 3;
  const double k = static_cast<double>(S) / s;
  const int32_t plane = s * s;
  // The quilted map made exactly 4-fold from its top-left quadrant (the authority, as for pixels).
  std::vector<int32_t> map(static_cast<size_t>(n) * n, -1);
  for (int y = 0; y < half_n; ++y)
    for (int x = 0; x < half_n; ++x) {
      int32_t src = plan.source[static_cast<size_t>(y) * n + x];
      if (src < 0) src = y * s + x;  // a pixel no block wrote (none is expected): its own place, upright
      int rx = x, ry = y;
      for (int turn = 0; turn < 4; ++turn) {
        map[static_cast<size_t>(ry) * n + rx] = src;
        const int nx = n - 1 - ry;
        ry = rx;
        rx = nx;
        src = next_turn_source(src, s);
      }
    }
  // The map's sample that quilted pixel (cx, cy) (unwrapped) puts at full-size (x, y), and the
  // quarter turns of its content.
  auto sample = [&](int cx, int cy, int x, int y, int& turns) {
    const int32_t src = map[static_cast<size_t>(Plane::mod(cy, n)) * n + Plane::mod(cx, n)];
    const int t = src / plane, sx = src % plane % s, sy = src % plane / s;
    int u = std::clamp(x + static_cast<int>(std::lround((sx - cx) * k)), 0, S - 1);
    int v = std::clamp(y + static_cast<int>(std::lround((sy - cy) * k)), 0, S - 1);
    // (u, v) in the t-th turn; undoing one turn maps (u, v) back to (v, S - 1 - u).
    for (int turn = 0; turn < t; ++turn) {
      const int a = v, b = S - 1 - u;
      u = a;
      v = b;
    }
    turns = t;
    return in + (static_cast<size_t>(plan.crop_y + v) * width + plan.crop_x + u) * c;
  };
  const double half = max_value / 2.0;
  const double flip = y_down ? -1.0 : 1.0;
  auto turn_vector = [flip](double& x, double& y, int turns) {  // r: (x, y) -> (y, -x) with +y up
    for (int i = 0; i < turns; ++i) {
      const double a = flip * y, b = -flip * x;
      x = a;
      y = b;
    }
  };
  std::vector<float> pinwheel(static_cast<size_t>(big_n) * big_n * c);
  std::vector<double> value(static_cast<size_t>(c));
  for (int y = 0; y < m; ++y) {
    const double yc = (y + 0.5) / k - 0.5;
    const int y0 = static_cast<int>(std::floor(yc));
    const double fy = yc - y0;
    for (int x = 0; x < m; ++x) {
      const double xc = (x + 0.5) / k - 0.5;
      const int x0 = static_cast<int>(std::floor(xc));
      const double fx = xc - x0;
      int turns[4];
      const T* p[4] = {sample(x0, y0, x, y, turns[0]), sample(x0 + 1, y0, x, y, turns[1]),
                       sample(x0, y0 + 1, x, y, turns[2]), sample(x0 + 1, y0 + 1, x, y, turns[3])};
      const double weight[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
      const bool one = p[0] == p[1] && p[0] == p[2] && p[0] == p[3];
      std::fill(value.begin(), value.end(), 0.0);
      for (int q = 0; q < (one ? 1 : 4); ++q) {
        const double w = one ? 1.0 : weight[q];
        for (int ch = 0; ch < c; ++ch) value[static_cast<size_t>(ch)] += w * static_cast<double>(p[q][ch]);
        if (vectors) {  // the vector part again, turned with its block's content
          double nx = p[q][0] / half - 1.0, ny = p[q][1] / half - 1.0;
          turn_vector(nx, ny, turns[q]);
          value[0] += w * ((nx + 1.0) * half - static_cast<double>(p[q][0]));
          value[1] += w * ((ny + 1.0) * half - static_cast<double>(p[q][1]));
        }
      }
      int tx = x, ty = y;
      for (int turn = 0; turn < 4; ++turn) {
        float* o = &pinwheel[(static_cast<size_t>(ty) * big_n + tx) * c];
        for (int ch = 0; ch < c; ++ch) o[ch] = static_cast<float>(value[static_cast<size_t>(ch)]);
        if (vectors) {  // renormalised, and turned with the quadrant
          double nx = value[0] / half - 1.0, ny = value[1] / half - 1.0, nz = value[2] / half - 1.0;
          turn_vector(nx, ny, turn);
          unit_or_up(nx, ny, nz);
          o[0] = static_cast<float>((nx + 1.0) * half);
          o[1] = static_cast<float>((ny + 1.0) * half);
          o[2] = static_cast<float>((nz + 1.0) * half);
        }
        const int nx = big_n - 1 - ty;
        ty = tx;
        tx = nx;
      }
    }
  }
  // The wrap's roll; samples rounded into T (floats as they are).
  out.resize(pinwheel.size());
  for (int y = 0; y < big_n; ++y)
    for (int x = 0; x < big_n; ++x) {
      const float* v = &pinwheel[(static_cast<size_t>((y + plan.roll) % big_n) * big_n + (x + plan.roll) % big_n) * c];
      T* o = &out[(static_cast<size_t>(y) * big_n + x) * c];
      for (int ch = 0; ch < c; ++ch) {
        if constexpr (std::is_floating_point_v<T>)
          o[ch] = static_cast<T>(v[ch]);
        else
          o[ch] = static_cast<T>(std::lround(std::clamp(static_cast<double>(v[ch]), 0.0, max_value)));
      }
    }
}

template void read_quarter_turn<float>(const float*, int, int, double, bool, bool, const QuarterTurnPlan&,
                                       std::vector<float>&);
template void read_quarter_turn<uint8_t>(const uint8_t*, int, int, double, bool, bool, const QuarterTurnPlan&,
                                         std::vector<uint8_t>&);
template void read_quarter_turn<uint16_t>(const uint16_t*, int, int, double, bool, bool, const QuarterTurnPlan&,
                                          std::vector<uint16_t>&);

template void compose<uint8_t>(const uint8_t*, int, int, int, int, BlendKind, const std::vector<int32_t>&, int,
                               std::vector<uint8_t>&);
template void compose<uint16_t>(const uint16_t*, int, int, int, int, BlendKind, const std::vector<int32_t>&, int,
                                std::vector<uint16_t>&);

}  // namespace tailor::internal
