// Whether the SSE2 code paths are compiled. x86-64 always has SSE2; the compiler define
// TAILOR_NO_SIMD (set for the map_scalar test tool and by the CMake option TAILOR_TSAN) builds
// the scalar paths instead. Every SIMD path repeats its scalar path's operations lane by lane, so
// both give the same bits; tests/simd_test.sh checks that on real meshes with a scalar build of
// the mapping (meshoptimizer's MESHOPTIMIZER_NO_SIMD idea).
#pragma once

#if defined(__SSE2__) && !defined(TAILOR_NO_SIMD)
#define TAILOR_SSE2 1
#include <emmintrin.h>
#else
#define TAILOR_SSE2 0
#endif
