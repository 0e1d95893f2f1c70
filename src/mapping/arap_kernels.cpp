// The ARAP kernels of the crack closing (arap_kernels.h): the local step (fit_rotations) and the
// global step (sweep), each with its SSE2 path and the scalar twin that gives the same bits.
#include "mapping/arap_kernels.h"

#include <algorithm>
#include <cmath>

#include "util/simd.h"

namespace tailor::internal {
namespace {

// Moving face i's part of fit_rotations, one face at a time (the SIMD loop's scalar twin: the same
// operations in the same order). u1x..u2y: its UVs' corners 1 and 2 minus corner 0.
template <bool kReweight>
void fit_face(size_t i, size_t count, float bound, float area_bound, float u1x, float u1y, float u2x, float u2y,
              const float* frame, float* weight, float* ratio, float* record) {
  constexpr float kCap = 10.f;  // inverted or collapsed: weigh as 10x the bound
  const float q1x = frame[i], q1y = frame[count + i], q2x = frame[2 * count + i], q2y = frame[3 * count + i];
  const float a = u1x * q2y - u2x * q1y, b = u2x * q1x - u1x * q2x;
  const float c = u1y * q2y - u2y * q1y, d = u2y * q1x - u1y * q2x;
  const float x = a + d, y = c - b;
  const float n = std::sqrt(x * x + y * y);
  if constexpr (kReweight) {
    const float half_inv = frame[4 * count + i];
    const float fx = a - d, fy = c + b;
    const float qn = n * half_inv, rn = std::sqrt(fx * fx + fy * fy) * half_inv;
    const float sigma_min = qn - rn;
    const bool valid = sigma_min > 1e-6f;
    const float distortion = valid ? std::min(std::max(qn + rn - 1.f, 1.f / sigma_min - 1.f), kCap) : kCap;
    const float area = (qn + rn) * sigma_min;
    const float area_change = valid ? std::min(std::max(area - 1.f, 1.f / area - 1.f), kCap) : 0.f;
    ratio[i] = distortion / bound;
    const float rw = std::max(ratio[i], area_change / area_bound);
    weight[i] *= 1.f + rw * rw;
  }
  const float wt = weight[i];
  const float rc = n > 0.f ? wt * x / n : wt, rs = n > 0.f ? wt * y / n : 0.f;
  float* r = record + kRecord * i;
  r[0] = rc;
  r[1] = rs;
  r[2] = -rs;
  r[3] = rc;
  r[4] = r[5] = wt;
}

}  // namespace

// With GCC on x86-64 the fit and the sweep are also compiled for AVX (TAILOR_AVX_CLONES,
// util/simd.h): 8 % fewer instructions in the closing on the horse.
template <bool kReweight>
TAILOR_AVX_CLONES void fit_rotations(size_t count, float bound, float area_bound, const uint32_t* corner_pos,
                                     const float* pos, const float* frame, float* weight, float* ratio, float* record) {
  size_t i = 0;
#if TAILOR_SSE2
  // Four faces at a time: the scalar operations lane by lane (IEEE operations round each lane as
  // the scalar ones do, nothing is reordered, and a lane whose division the scalar code skips gets
  // a harmless divisor and is not selected), so the results have the same bits; a third of the
  // instructions of fit_face (the fit is a quarter of the closing's instructions).
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f), cap = _mm_set1_ps(10.f);
  for (; i + 4 <= count; i += 4) {
    __m128 u1x, u1y, u2x, u2y;
    load_edges4(pos, corner_pos + 3 * i, u1x, u1y, u2x, u2y);
    const __m128 q1x = _mm_loadu_ps(frame + i), q1y = _mm_loadu_ps(frame + count + i);
    const __m128 q2x = _mm_loadu_ps(frame + 2 * count + i), q2y = _mm_loadu_ps(frame + 3 * count + i);
    const __m128 a = _mm_sub_ps(_mm_mul_ps(u1x, q2y), _mm_mul_ps(u2x, q1y));
    const __m128 b = _mm_sub_ps(_mm_mul_ps(u2x, q1x), _mm_mul_ps(u1x, q2x));
    const __m128 c = _mm_sub_ps(_mm_mul_ps(u1y, q2y), _mm_mul_ps(u2y, q1y));
    const __m128 d = _mm_sub_ps(_mm_mul_ps(u2y, q1x), _mm_mul_ps(u1y, q2x));
    const __m128 x = _mm_add_ps(a, d), y = _mm_sub_ps(c, b);
    const __m128 n = _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)));
    __m128 wt = _mm_loadu_ps(weight + i);
    if constexpr (kReweight) {
      const __m128 half_inv = _mm_loadu_ps(frame + 4 * count + i);
      const __m128 fx = _mm_sub_ps(a, d), fy = _mm_add_ps(c, b);
      const __m128 qn = _mm_mul_ps(n, half_inv);
      const __m128 rn = _mm_mul_ps(_mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(fx, fx), _mm_mul_ps(fy, fy))), half_inv);
      const __m128 sigma_min = _mm_sub_ps(qn, rn);
      const __m128 valid = _mm_cmpgt_ps(sigma_min, _mm_set1_ps(1e-6f));
      const __m128 inverse = _mm_div_ps(one, blend(valid, sigma_min, one));
      // std::max(p, q) is _mm_max_ps(q, p) and std::min(p, q) is _mm_min_ps(q, p): the same
      // operand on ties and NaN.
      const __m128 worst = _mm_max_ps(_mm_sub_ps(inverse, one), _mm_sub_ps(_mm_add_ps(qn, rn), one));
      const __m128 area = _mm_mul_ps(_mm_add_ps(qn, rn), sigma_min);
      const __m128 area_inverse = _mm_div_ps(one, blend(valid, area, one));
      const __m128 area_worst = _mm_max_ps(_mm_sub_ps(area_inverse, one), _mm_sub_ps(area, one));
      const __m128 r_area = _mm_div_ps(blend(valid, _mm_min_ps(cap, area_worst), zero), _mm_set1_ps(area_bound));
      const __m128 r_stretch = _mm_div_ps(blend(valid, _mm_min_ps(cap, worst), cap), _mm_set1_ps(bound));
      _mm_storeu_ps(ratio + i, r_stretch);
      const __m128 r = _mm_max_ps(r_area, r_stretch);
      wt = _mm_mul_ps(wt, _mm_add_ps(one, _mm_mul_ps(r, r)));
      _mm_storeu_ps(weight + i, wt);
    }
    const __m128 turned = _mm_cmpgt_ps(n, zero);
    const __m128 norm = blend(turned, n, one);
    const __m128 rc = blend(turned, _mm_div_ps(_mm_mul_ps(wt, x), norm), wt);
    const __m128 rs = blend(turned, _mm_div_ps(_mm_mul_ps(wt, y), norm), zero);
    const __m128 minus_rs = _mm_xor_ps(rs, _mm_set1_ps(-0.f));
    // Records: c s -s c | w w, two faces from each half of the lanes.
    const __m128 cs_lo = _mm_unpacklo_ps(rc, rs), cs_hi = _mm_unpackhi_ps(rc, rs);
    const __m128 sc_lo = _mm_unpacklo_ps(minus_rs, rc), sc_hi = _mm_unpackhi_ps(minus_rs, rc);
    const __m128 w_lo = _mm_unpacklo_ps(wt, wt), w_hi = _mm_unpackhi_ps(wt, wt);
    float* out = record + kRecord * i;
    _mm_storeu_ps(out, _mm_movelh_ps(cs_lo, sc_lo));
    _mm_storel_pi(reinterpret_cast<__m64*>(out + 4), w_lo);
    _mm_storeu_ps(out + kRecord, _mm_movehl_ps(sc_lo, cs_lo));
    _mm_storeh_pi(reinterpret_cast<__m64*>(out + kRecord + 4), w_lo);
    _mm_storeu_ps(out + 2 * kRecord, _mm_movelh_ps(cs_hi, sc_hi));
    _mm_storel_pi(reinterpret_cast<__m64*>(out + 2 * kRecord + 4), w_hi);
    _mm_storeu_ps(out + 3 * kRecord, _mm_movehl_ps(sc_hi, cs_hi));
    _mm_storeh_pi(reinterpret_cast<__m64*>(out + 3 * kRecord + 4), w_hi);
  }
#endif
  for (; i < count; ++i) {
    const float* p0 = pos + corner_pos[3 * i];
    const float* p1 = pos + corner_pos[3 * i + 1];
    const float* p2 = pos + corner_pos[3 * i + 2];
    fit_face<kReweight>(i, count, bound, area_bound, p1[0] - p0[0], p1[1] - p0[1], p2[0] - p0[0], p2[1] - p0[1], frame,
                        weight, ratio, record);
  }
}

template void fit_rotations<false>(size_t, float, float, const uint32_t*, const float*, const float*, float*, float*,
                                   float*);
template void fit_rotations<true>(size_t, float, float, const uint32_t*, const float*, const float*, float*, float*,
                                  float*);

TAILOR_AVX_CLONES float sweep(size_t free_count, const uint32_t* free_wedge, const uint32_t* term_end,
                              const Term* terms, const float* record, float* pos) {
  float moved = 0.f;
  const Term* t = terms;
  for (size_t k = 0; k < free_count; ++k) {
    float su = 0.f, sv = 0.f, sw = 0.f;
#if TAILOR_SSE2
    // u and v side by side, the scalar operations lane by lane (same bits, as in fit_rotations):
    // (w (a + b) + (c x, s x)) + (-s y, c y); x - y is x + (-y) exactly.
    __m128 sum = _mm_setzero_ps(), weights = _mm_setzero_ps();
    for (const Term* const end = terms + term_end[k]; t != end; ++t) {
      const float* r = record + t->record;
      const __m128 w = load_pair(r + 4);
      const __m128 rotated = _mm_mul_ps(_mm_loadu_ps(r), _mm_load_ps(t->xy));
      const __m128 p = _mm_add_ps(_mm_mul_ps(w, _mm_add_ps(load_pair(pos + t->a), load_pair(pos + t->b))), rotated);
      sum = _mm_add_ps(sum, _mm_add_ps(p, _mm_movehl_ps(rotated, rotated)));
      weights = _mm_add_ss(weights, w);
    }
    su = _mm_cvtss_f32(sum);
    sv = _mm_cvtss_f32(_mm_shuffle_ps(sum, sum, 1));
    sw = _mm_cvtss_f32(weights);
#else
    for (const Term* const end = terms + term_end[k]; t != end; ++t) {
      // r: the rotation's columns (c, s) and (-s, c) premultiplied by the weight, then the weight
      // twice; x - y is x + (-y) exactly, so su gets "+ c x - s y" and sv "+ s x + c y".
      const float* r = record + t->record;
      const float* a = pos + t->a;
      const float* b = pos + t->b;
      sw += r[4];
      su += r[4] * (a[0] + b[0]) + r[0] * t->xy[0] + r[2] * t->xy[2];
      sv += r[5] * (a[1] + b[1]) + r[1] * t->xy[1] + r[3] * t->xy[3];
    }
#endif
    const float inv = 0.5f / sw;
    float* target = pos + free_wedge[k];
    const float u = target[0] + kOverRelaxation * (su * inv - target[0]);
    const float v = target[1] + kOverRelaxation * (sv * inv - target[1]);
    moved = std::max(moved, std::abs(u - target[0]) + std::abs(v - target[1]));
    target[0] = u;
    target[1] = v;
  }
  return moved;
}

}  // namespace tailor::internal
