// Orientation strokes (OrientationOptions::strokes): the direction and weight a set of user
// strokes gives a point, for compute_orientation to blend into the axis field.
//
// A stroke is a polyline with a radius. At a point q, each stroke within reach contributes the
// tangent at its nearest point (the nearest segment's direction, blended with the adjacent
// segment's towards a shared vertex so that it turns smoothly along the curve) with the weight
// 1 - smoothstep(distance / radius): 1 on the curve, 0 at the radius and beyond. Several strokes
// combine: the direction is the weighted sum of their tangents, the weight the largest one.
//
// The segments are binned once in a uniform grid (each in every cell its bounding box, grown by
// its stroke's radius, overlaps), so a lookup reads one cell: O(segments in that cell), no
// allocation, safe to call from several threads.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "tailor/orientation.h"
#include "tailor/status.h"

namespace tailor::internal {

//! kInvalidArgument naming the stroke (0-based) and what is wrong: points not a multiple of 3,
//! fewer than 2 points, a non-finite coordinate, a radius not finite or <= 0.
Status check_strokes(std::span<const OrientationStroke> strokes);

class StrokeField {
 public:
  //! Precondition: check_strokes(strokes) passed.
  explicit StrokeField(std::span<const OrientationStroke> strokes);

  bool empty() const { return segments_.empty(); }

  //! Weight in [0, 1] at q (mesh coordinates) and, when it is > 0, the unit direction there in
  //! `direction`. 0 when no stroke reaches q (or their tangents cancel). Deterministic.
  double sample(const double q[3], double direction[3]) const;

 private:
  struct Segment {
    double a[3];          // start point
    double d[3];          // end - start
    double inv_len2;      // 1 / |d|^2
    double tangent[3];    // unit d
    double radius;        // of its stroke
    uint32_t stroke;      // stroke index
    uint32_t prev, next;  // adjacent segments of the same stroke (kInvalid at the ends)
  };
  std::vector<Segment> segments_;
  double origin_[3] = {0, 0, 0};
  double cell_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<uint32_t> start_, items_;  // CSR: segment ids per cell, stroke-major order
};

}  // namespace tailor::internal
