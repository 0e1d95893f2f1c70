// Orientation strokes: validation, the segment grid and the per-point lookup (stroke_field.h).
#include "surface/stroke_field.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace tailor::internal {
namespace {

// Grid bounds: at most this many cells per axis, and about this many (segment, cell) entries in
// all; the cell grows until both hold (a long segment with a large radius covers many cells).
constexpr int kMaxCellsPerAxis = 128;
constexpr double kMaxItems = 4e6;

double smoothstep(double x) { return x * x * (3.0 - 2.0 * x); }

}  // namespace

Status check_strokes(std::span<const OrientationStroke> strokes) {
  for (size_t i = 0; i < strokes.size(); ++i) {
    const OrientationStroke& s = strokes[i];
    const std::string where = "orientation stroke " + std::to_string(i);
    if (s.points.size() % 3 != 0)
      return Status::error(ErrorCode::kInvalidArgument, "", where + ": points must be x, y, z triples");
    if (s.points.size() < 6) return Status::error(ErrorCode::kInvalidArgument, "", where + ": fewer than 2 points");
    for (size_t k = 0; k < s.points.size(); ++k)
      if (!std::isfinite(s.points[k]))
        return Status::error(ErrorCode::kInvalidArgument, "",
                             where + ": point " + std::to_string(k / 3) + " is not finite");
    if (!(s.radius > 0.f) || !std::isfinite(s.radius))
      return Status::error(ErrorCode::kInvalidArgument, "", where + ": radius must be finite and > 0");
  }
  return Status::ok();
}

StrokeField::StrokeField(std::span<const OrientationStroke> strokes) {
  // Segments of non-zero length, linked to their neighbours along the stroke.
  for (size_t i = 0; i < strokes.size(); ++i) {
    const std::vector<float>& p = strokes[i].points;
    uint32_t previous = kInvalid;
    for (size_t k = 0; k + 1 < p.size() / 3; ++k) {
      Segment s{};
      double len2 = 0;
      for (int c = 0; c < 3; ++c) {
        s.a[c] = p[3 * k + c];
        s.d[c] = static_cast<double>(p[3 * k + 3 + c]) - p[3 * k + c];
        len2 += s.d[c] * s.d[c];
      }
      if (!(len2 > 0)) continue;
      const double len = std::sqrt(len2);
      for (int c = 0; c < 3; ++c) s.tangent[c] = s.d[c] / len;
      s.inv_len2 = 1.0 / len2;
      s.radius = strokes[i].radius;
      s.stroke = static_cast<uint32_t>(i);
      s.prev = previous;
      s.next = kInvalid;
      const uint32_t id = static_cast<uint32_t>(segments_.size());
      if (previous != kInvalid) segments_[previous].next = id;
      previous = id;
      segments_.push_back(s);
    }
  }
  if (segments_.empty()) return;

  // Bounds of the segments grown by their radii; the cell starts at the largest radius.
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  double max_radius = 0;
  for (const Segment& s : segments_) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], std::min(s.a[c], s.a[c] + s.d[c]) - s.radius);
      hi[c] = std::max(hi[c], std::max(s.a[c], s.a[c] + s.d[c]) + s.radius);
    }
    max_radius = std::max(max_radius, s.radius);
  }
  const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  cell_ = std::max(max_radius, longest / kMaxCellsPerAxis);
  auto cell_range = [&](const Segment& s, int from[3], int to[3]) {
    for (int c = 0; c < 3; ++c) {
      const double a = std::min(s.a[c], s.a[c] + s.d[c]) - s.radius, b = std::max(s.a[c], s.a[c] + s.d[c]) + s.radius;
      from[c] = std::clamp(static_cast<int>(std::floor((a - lo[c]) / cell_)), 0, dims_[c] - 1);
      to[c] = std::clamp(static_cast<int>(std::floor((b - lo[c]) / cell_)), 0, dims_[c] - 1);
    }
  };
  for (;;) {
    for (int c = 0; c < 3; ++c)
      dims_[c] = std::clamp(static_cast<int>(std::ceil((hi[c] - lo[c]) / cell_)), 1, kMaxCellsPerAxis);
    double items = 0;
    for (const Segment& s : segments_) {
      int from[3], to[3];
      cell_range(s, from, to);
      items += double(to[0] - from[0] + 1) * (to[1] - from[1] + 1) * (to[2] - from[2] + 1);
    }
    if (items <= kMaxItems) break;
    cell_ *= 2;
  }
  for (int c = 0; c < 3; ++c) origin_[c] = lo[c];

  const size_t cells = size_t(dims_[0]) * dims_[1] * dims_[2];
  start_.assign(cells + 1, 0);
  auto for_cells = [&](const Segment& s, auto&& visit) {
    int from[3], to[3];
    cell_range(s, from, to);
    for (int z = from[2]; z <= to[2]; ++z)
      for (int y = from[1]; y <= to[1]; ++y)
        for (int x = from[0]; x <= to[0]; ++x) visit((size_t(z) * dims_[1] + y) * dims_[0] + x);
  };
  for (const Segment& s : segments_) for_cells(s, [&](size_t c) { ++start_[c + 1]; });
  for (size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  items_.resize(start_[cells]);
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  // Segments in id order, so each cell lists them stroke by stroke (sample relies on it).
  for (uint32_t id = 0; id < segments_.size(); ++id)
    for_cells(segments_[id], [&](size_t c) { items_[fill[c]++] = id; });
}

double StrokeField::sample(const double q[3], double direction[3]) const {
  if (segments_.empty()) return 0.0;
  int cell[3];
  for (int c = 0; c < 3; ++c) {
    const double x = std::floor((q[c] - origin_[c]) / cell_);
    if (!(x >= 0 && x < dims_[c])) return 0.0;  // outside every stroke's reach (or NaN)
    cell[c] = static_cast<int>(x);
  }
  const size_t index = (size_t(cell[2]) * dims_[1] + cell[1]) * dims_[0] + cell[0];
  double sum[3] = {0, 0, 0}, weight = 0;
  // The nearest segment of the stroke being scanned: its entries are consecutive in the cell.
  uint32_t best = kInvalid;
  double best_d2 = INFINITY, best_t = 0;
  auto finish_stroke = [&] {
    if (best == kInvalid) return;
    const Segment& s = segments_[best];
    const double r = s.radius;
    if (best_d2 < r * r) {
      const double w = 1.0 - smoothstep(std::sqrt(best_d2) / r);
      // Tangent at the nearest point, turning towards the adjacent segment's near a shared vertex.
      double t[3] = {s.tangent[0], s.tangent[1], s.tangent[2]};
      const uint32_t other = best_t < 0.5 ? s.prev : s.next;
      if (other != kInvalid) {
        const double share = best_t < 0.5 ? 0.5 - best_t : best_t - 0.5;
        for (int c = 0; c < 3; ++c) t[c] = (1.0 - share) * t[c] + share * segments_[other].tangent[c];
        const double len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        if (len > 1e-12)
          for (double& x : t) x /= len;
      }
      for (int c = 0; c < 3; ++c) sum[c] += w * t[c];
      weight = std::max(weight, w);
    }
    best = kInvalid;
    best_d2 = INFINITY;
  };
  for (uint32_t i = start_[index]; i < start_[index + 1]; ++i) {
    const uint32_t id = items_[i];
    const Segment& s = segments_[id];
    if (best != kInvalid && segments_[best].stroke != s.stroke) finish_stroke();
    const double aq[3] = {q[0] - s.a[0], q[1] - s.a[1], q[2] - s.a[2]};
    const double t = std::clamp((aq[0] * s.d[0] + aq[1] * s.d[1] + aq[2] * s.d[2]) * s.inv_len2, 0.0, 1.0);
    const double e[3] = {aq[0] - t * s.d[0], aq[1] - t * s.d[1], aq[2] - t * s.d[2]};
    const double d2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    if (d2 < best_d2) best_d2 = d2, best = id, best_t = t;  // strict: the lower id wins ties
  }
  finish_stroke();
  const double len = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
  if (!(weight > 0) || !(len > 1e-12)) return 0.0;
  for (int c = 0; c < 3; ++c) direction[c] = sum[c] / len;
  return weight;
}

}  // namespace tailor::internal
