// Whether the SSE2 code paths are compiled. x86-64 always has SSE2; the compiler define
// TAILOR_NO_SIMD (set for the map_scalar test tool and by the CMake option TAILOR_TSAN) builds
// the scalar paths instead. Every SIMD path repeats its scalar path's operations lane by lane, so
// both give the same bits; tests/simd_test.sh checks that on real meshes with a scalar build of
// the mapping (meshoptimizer's MESHOPTIMIZER_NO_SIMD idea).
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__SSE2__) && !defined(TAILOR_NO_SIMD)
#define TAILOR_SSE2 1
#include <emmintrin.h>
#else
#define TAILOR_SSE2 0
#endif

#if TAILOR_SSE2
namespace tailor::internal {
// p[0] p[1] 0 0.
inline __m128 load_pair(const float* p) {
  return _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
}
// The edges P1 - P0 and P2 - P0 of four faces in UV (pos: 2 floats per UV vertex; corner_pos: the
// three UV vertices of each face, 3 per face), one face per lane: u1x, u1y, u2x, u2y.
inline void load_edges4(const float* pos, const uint32_t* corner_pos, __m128& u1x, __m128& u1y, __m128& u2x,
                        __m128& u2y) {
  __m128 e[4];  // per face u1x u1y u2x u2y
  for (size_t k = 0; k < 4; ++k) {
    const uint32_t* c = corner_pos + 3 * k;
    const __m128 p0 = load_pair(pos + c[0]);
    const __m128 p12 = _mm_loadh_pi(load_pair(pos + c[1]), reinterpret_cast<const __m64*>(pos + c[2]));
    e[k] = _mm_sub_ps(p12, _mm_movelh_ps(p0, p0));
  }
  _MM_TRANSPOSE4_PS(e[0], e[1], e[2], e[3]);
  u1x = e[0], u1y = e[1], u2x = e[2], u2y = e[3];
}
// Per lane: yes where mask is set, else no.
inline __m128 blend(__m128 mask, __m128 yes, __m128 no) {
  return _mm_or_ps(_mm_and_ps(mask, yes), _mm_andnot_ps(mask, no));
}
}  // namespace tailor::internal
#endif

// With GCC on x86-64 the ARAP kernels (the crack closing's, arap_kernels.cpp, and the
// relaxation's, relax_patches.cpp) are also compiled for AVX, and that version is taken at load
// time where the CPU has it: the same SSE operations in three-operand (VEX) form (AVX enables no
// FMA: the results are the same). Clang 14 cannot multiversion a template.
#if TAILOR_SSE2 && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define TAILOR_AVX_CLONES __attribute__((target_clones("avx", "default")))
#else
#define TAILOR_AVX_CLONES
#endif
