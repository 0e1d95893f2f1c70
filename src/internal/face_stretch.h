// The per-face stretch bound of the patches mode, split so that a face tried against several
// candidate UV triangles computes its own part once (face_stretch_error in mapping.cpp is the
// two halves together; the arithmetic is the same, so results are bit-identical).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace tailor::internal {

//! Whether a face (its 3 corners in its frame, 6 floats) has no meaningful Jacobian: its doubled
//! area is below 1e-6 of its squared longest edge. Such faces are placed without the stretch check
//! (their UV is the degenerate image of a degenerate face); the growth and the seam shortening
//! must agree on which they are.
inline bool is_zero_area_frame(const float* l) {
  constexpr float kZeroAreaRatio = 1e-6f;
  const float twice_area = l[2] * l[5] - l[3] * l[4];
  const float e0 = l[2] * l[2] + l[3] * l[3], e2 = l[4] * l[4] + l[5] * l[5];
  const float e1 = (l[4] - l[2]) * (l[4] - l[2]) + (l[5] - l[3]) * (l[5] - l[3]);
  return !(twice_area > kZeroAreaRatio * std::max({e0, e1, e2}));
}

//! The face's edges in its frame, in pixels, and the inverse of their determinant.
struct StretchFrame {
  float q1x = 0.f, q1y = 0.f, q2x = 0.f, q2y = 0.f, inv = 0.f;
  bool valid = false;  //!< false when the face's own triangle has no positive area
};

//! local: the face's 3 corners in its frame (6 floats, normalised units); scale: pixels per unit.
inline StretchFrame stretch_frame(const float* local, float scale) {
  StretchFrame s;
  s.q1x = (local[2] - local[0]) * scale;
  s.q1y = (local[3] - local[1]) * scale;
  s.q2x = (local[4] - local[0]) * scale;
  s.q2y = (local[5] - local[1]) * scale;
  const float det_q = s.q1x * s.q2y - s.q2x * s.q1y;
  s.valid = det_q > 0.f;
  if (s.valid) s.inv = 1.f / det_q;
  return s;
}

//! max(sigma_max - 1, 1/sigma_min - 1) of the Jacobian face -> UV triangle `uv` (6 floats,
//! pixels), or +inf when inverted, degenerate, or the frame is not valid. O(1).
inline float stretch_error(const StretchFrame& s, const float* uv) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  if (!s.valid) return kInf;
  // J = U * Q^-1 with U the UV edges.
  const float u1x = uv[2] - uv[0], u1y = uv[3] - uv[1];
  const float u2x = uv[4] - uv[0], u2y = uv[5] - uv[1];
  const float a = (u1x * s.q2y - u2x * s.q1y) * s.inv;
  const float b = (u2x * s.q1x - u1x * s.q2x) * s.inv;
  const float c = (u1y * s.q2y - u2y * s.q1y) * s.inv;
  const float d = (u2y * s.q1x - u1y * s.q2x) * s.inv;
  // Closed-form singular values of a 2x2 matrix: sigma = |q| +- |r| with q, r its conformal and
  // anti-conformal parts; sigma_min is signed (negative when J reverses orientation).
  const float e = 0.5f * (a + d), h = 0.5f * (c - b);
  const float f = 0.5f * (a - d), g = 0.5f * (c + b);
  const float qn = std::sqrt(e * e + h * h), rn = std::sqrt(f * f + g * g);
  const float sigma_max = qn + rn, sigma_min = qn - rn;
  if (!(sigma_min > 1e-6f) || !(a * d - b * c > 0.f)) return kInf;
  return std::max(sigma_max - 1.f, 1.f / sigma_min - 1.f);
}

}  // namespace tailor::internal
