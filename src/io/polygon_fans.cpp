// retriangulate_concave_fans: ear clipping of the concave polygons the readers cut into fans.
// Hand-written: the polygons are small (at most kMaxEarClippedCorners corners) and already in the
// mesh's arrays; a polygon library would need them copied out and back, with their attributes.
#include "io/polygon_fans.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace tailor::internal {
namespace {

// The polygon's corner j in the fan that starts at triangle t0: corners 0 and 1 are the first
// triangle's first two, corner j >= 2 the third of triangle t0 + j - 2.
size_t fan_corner(size_t t0, size_t j) { return j < 2 ? 3 * t0 + j : 3 * (t0 + j - 2) + 2; }

struct Point2 {
  double u, v;
};

double turn(const Point2& a, const Point2& b, const Point2& c) {
  return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
}

// Ears of the polygon q[0..n) (counter-clockwise), as corner triples in polygon order, each ear
// (previous, tip, next) cut at the first corner from where the last cut left off whose triangle
// turns left and holds no other remaining corner. False when none is found (a self-crossing
// projection), or after 4 n^2 corner tests (a hostile shape would take n^3): the caller keeps the
// fan.
bool ear_clip(const std::array<Point2, kMaxEarClippedCorners>& q, size_t n,
              std::array<std::array<uint8_t, 3>, kMaxEarClippedCorners>& ears) {
  std::array<uint8_t, kMaxEarClippedCorners> prev{}, next{};
  for (size_t j = 0; j < n; ++j) {
    prev[j] = static_cast<uint8_t>((j + n - 1) % n);
    next[j] = static_cast<uint8_t>((j + 1) % n);
  }
  size_t remaining = n, count = 0, tip = 0, tried = 0, budget = 4 * n * n;
  while (remaining > 3) {
    const size_t a = prev[tip], c = next[tip];
    bool ear = turn(q[a], q[tip], q[c]) > 0;
    for (size_t k = next[c]; ear && k != a; k = next[k]) {
      if (budget-- == 0) return false;
      const Point2& p = q[k];
      if ((p.u == q[a].u && p.v == q[a].v) || (p.u == q[c].u && p.v == q[c].v)) continue;  // a repeated corner
      ear = !(turn(q[a], q[tip], p) >= 0 && turn(q[tip], q[c], p) >= 0 && turn(q[c], q[a], p) >= 0);
    }
    if (ear) {
      ears[count++] = {static_cast<uint8_t>(a), static_cast<uint8_t>(tip), static_cast<uint8_t>(c)};
      next[a] = static_cast<uint8_t>(c);
      prev[c] = static_cast<uint8_t>(a);
      --remaining;
      tip = c;
      tried = 0;
    } else {
      tip = next[tip];
      if (++tried > remaining) return false;
    }
  }
  ears[count++] = {prev[tip], static_cast<uint8_t>(tip), next[tip]};
  return true;
}

}  // namespace

size_t retriangulate_concave_fans(Mesh& mesh, const PolygonFans& fans) {
  size_t cut = 0;
  const size_t faces = std::min(fans.continues.size(), mesh.face_count());
  std::array<uint32_t, kMaxEarClippedCorners> vertex{};
  std::array<Point2, kMaxEarClippedCorners> q{};
  std::array<std::array<uint8_t, 3>, kMaxEarClippedCorners> ears{};
  std::vector<float> saved;  // the polygon's per-corner values, before they move
  for (size_t t0 = 0; t0 < faces;) {
    size_t end = t0 + 1;
    while (end < faces && fans.continues[end]) ++end;
    const size_t n = end - t0 + 2, first = t0;
    t0 = end;
    if (n <= 3 || n > kMaxEarClippedCorners) continue;
    bool in_range = true;
    for (size_t j = 0; j < n; ++j) {
      vertex[j] = mesh.indices[fan_corner(first, j)];
      in_range = in_range && vertex[j] < mesh.vertex_count();
    }
    if (!in_range) continue;  // finalize_mesh names it
    // Newell's normal: the plane the polygon is projected on, dropping its largest axis, the other
    // two ordered so that the polygon turns counter-clockwise.
    double normal[3] = {0, 0, 0};
    for (size_t j = 0; j < n; ++j) {
      const float* p = &mesh.positions[3 * size_t{vertex[j]}];
      const float* r = &mesh.positions[3 * size_t{vertex[(j + 1) % n]}];
      normal[0] += (double{p[1]} - r[1]) * (double{p[2]} + r[2]);
      normal[1] += (double{p[2]} - r[2]) * (double{p[0]} + r[0]);
      normal[2] += (double{p[0]} - r[0]) * (double{p[1]} + r[1]);
    }
    const int drop = std::abs(normal[0]) >= std::abs(normal[1]) && std::abs(normal[0]) >= std::abs(normal[2]) ? 0
                     : std::abs(normal[1]) >= std::abs(normal[2])                                             ? 1
                                                                                                              : 2;
    if (!(normal[drop] != 0.0) || !std::isfinite(normal[drop])) continue;
    int u_axis = (drop + 1) % 3, v_axis = (drop + 2) % 3;
    if (normal[drop] < 0) std::swap(u_axis, v_axis);
    bool convex = true;
    for (size_t j = 0; j < n; ++j) {
      const float* p = &mesh.positions[3 * size_t{vertex[j]}];
      q[j] = {p[u_axis], p[v_axis]};
    }
    for (size_t j = 0; j < n && convex; ++j) convex = turn(q[(j + n - 1) % n], q[j], q[(j + 1) % n]) >= 0;
    if (convex || !ear_clip(q, n, ears)) continue;
    ++cut;
    // Each ear's corners take their vertex and their per-corner values from the polygon's corners.
    auto move_values = [&](std::vector<float>& values, size_t width) {
      if (values.empty()) return;
      saved.resize(n * width);
      for (size_t j = 0; j < n; ++j)
        for (size_t w = 0; w < width; ++w) saved[j * width + w] = values[fan_corner(first, j) * width + w];
      for (size_t m = 0; m + 2 < n; ++m)
        for (size_t k = 0; k < 3; ++k)
          for (size_t w = 0; w < width; ++w) values[(3 * (first + m) + k) * width + w] = saved[ears[m][k] * width + w];
    };
    move_values(mesh.corner_uvs, 2);
    for (CornerAttribute& attribute : mesh.corner_attributes)
      move_values(attribute.values, static_cast<size_t>(attribute.components));
    for (size_t m = 0; m + 2 < n; ++m)
      for (size_t k = 0; k < 3; ++k) mesh.indices[3 * (first + m) + k] = vertex[ears[m][k]];
  }
  return cut;
}

}  // namespace tailor::internal
