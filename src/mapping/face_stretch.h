// The per-face stretch bound of the patches mode, split so that a face tried against several
// candidate UV triangles computes its own part once (face_stretch_error in mapping.cpp is the
// two halves together; the arithmetic is the same, so results are bit-identical).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "util/simd.h"

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
#if TAILOR_SSE2
  // The same operations as the scalar code below, four lanes at a time (IEEE operations round
  // each lane as the scalar ones do, and nothing is reordered, so the result has the same bits;
  // checked on 2e7 random triangles). The growth runs this ~1.5 times per face: 3% of its
  // instructions saved (callgrind, horse).
  const __m128 first = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(uv)));  // uv0 uv1 0 0
  const __m128 u = _mm_sub_ps(_mm_loadu_ps(uv + 2), _mm_movelh_ps(first, first));                // u1x u1y u2x u2y
  const __m128 q = _mm_setr_ps(s.q1x, s.q1y, s.q2x, s.q2y);
  // (a, b, c, d) = ((u1x, u2x, u1y, u2y) * (q2y, q1x, q2y, q1x) - (u2x, u1x, u2y, u1y) * (q1y, q2x, q1y, q2x)) * inv
  const __m128 p1 =
      _mm_mul_ps(_mm_shuffle_ps(u, u, _MM_SHUFFLE(3, 1, 2, 0)), _mm_shuffle_ps(q, q, _MM_SHUFFLE(0, 3, 0, 3)));
  const __m128 p2 =
      _mm_mul_ps(_mm_shuffle_ps(u, u, _MM_SHUFFLE(1, 3, 0, 2)), _mm_shuffle_ps(q, q, _MM_SHUFFLE(2, 1, 2, 1)));
  const __m128 abcd = _mm_mul_ps(_mm_sub_ps(p1, p2), _mm_set1_ps(s.inv));
  // (a + d, a - d, c - b, c + b) halved = (e, f, h, g); x - y is x + (-y) exactly.
  const __m128 sign = _mm_setr_ps(0.f, -0.f, -0.f, 0.f);
  const __m128 sums = _mm_add_ps(_mm_shuffle_ps(abcd, abcd, _MM_SHUFFLE(2, 2, 0, 0)),
                                 _mm_xor_ps(_mm_shuffle_ps(abcd, abcd, _MM_SHUFFLE(1, 1, 3, 3)), sign));
  const __m128 efhg = _mm_mul_ps(_mm_set1_ps(0.5f), sums);
  const __m128 squares = _mm_mul_ps(efhg, efhg);
  const __m128 norms = _mm_sqrt_ps(_mm_add_ps(squares, _mm_movehl_ps(squares, squares)));  // qn rn . .
  const float qn = _mm_cvtss_f32(norms), rn = _mm_cvtss_f32(_mm_shuffle_ps(norms, norms, 1));
  const float a = _mm_cvtss_f32(abcd), b = _mm_cvtss_f32(_mm_shuffle_ps(abcd, abcd, 1));
  const float c = _mm_cvtss_f32(_mm_shuffle_ps(abcd, abcd, 2)), d = _mm_cvtss_f32(_mm_shuffle_ps(abcd, abcd, 3));
  const float sigma_max = qn + rn, sigma_min = qn - rn;
  if (!(sigma_min > 1e-6f) || !(a * d - b * c > 0.f)) return kInf;
  return std::max(sigma_max - 1.f, 1.f / sigma_min - 1.f);
#else
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
#endif
}

}  // namespace tailor::internal
