// The ARAP kernels of the crack closing: one local/global iteration over the moving faces of a
// relaxation (crack_closer.cpp builds their inputs around a zip and runs the iterations). The local
// step (fit_rotations) fits per face the rotation nearest to its Jacobian, four faces per
// instruction; the global step (sweep) moves each free UV to the weighted mean of the positions
// its faces predict, u and v side by side (SSE2). Each is bit-identical to its scalar twin
// (util/simd.h; tests/simd_test.sh), and with GCC on x86-64 each is also compiled for AVX.
//
// This work is based on:
//   L. Liu, L. Zhang, Y. Xu, C. Gotsman, S. J. Gortler, "A local/global approach to mesh
//   parameterization", SGP 2008 (ARAP local/global iterations; uniform weights here).
#pragma once

#include <cstddef>
#include <cstdint>

namespace tailor::internal {

// Successive over-relaxation of the Gauss-Seidel sweep: each free UV moves 1.2x of the way to its
// weighted mean. Within the same iterations more zips settle within the bound: mean seam length
// over the 16 shared meshes 6.43 -> 6.34% (13 lower, 2 higher; bunny 4.04 -> 3.90%, spot 6.72 ->
// 6.30%) for the same instructions; 1.3-1.4 gained little more, 1.6 raised the seams again.
inline constexpr float kOverRelaxation = 1.2f;

// === Local step ===================================================================================
// Per moving face, what the Gauss-Seidel step reads of it (kRecord floats, see fit_rotations).
inline constexpr uint32_t kRecord = 8;

// The local step for the `count` moving faces: per face the rotation nearest to its Jacobian J
// (frame -> current UVs), premultiplied by its weight; with kReweight, first d / bound to ratio, d
// its distortion max(sigma_max - 1, 1/sigma_min - 1) (capped), and the weight times 1 + x^2, x the
// larger of d / bound and the area change max(A - 1, 1/A - 1) / area_bound (A = sigma_max
// sigma_min): the zip's check bounds both, and weighing only d left the area bound to fail most of
// the relaxations that failed. Closed form for 2x2: with J = [a b; c d], the rotation turns by atan2(c - b, a + d) and
// sigma = |q| +- |r|, q and r its conformal and anti-conformal parts (face_stretch.h). The adjugate
// of Q is used: 1/det(Q) > 0 scales J without turning it.
// corner_pos: per face its 3 corners' offsets in pos (UV pairs); frame: 5 blocks of `count` floats,
// q1x, q1y, q2x, q2y (the frame's corners 1 and 2 minus corner 0, pixels) and half the inverse of
// their determinant; weight, ratio: per face; record: per face kRecord floats, the rotation's columns
// (c, s) and (-s, c), then the weight twice.
template <bool kReweight>
void fit_rotations(size_t count, float bound, float area_bound, const uint32_t* corner_pos, const float* pos,
                   const float* frame, float* weight, float* ratio, float* record);

// === Global step ==================================================================================
// A free wedge's corner in a moving face: what its prediction needs.
struct alignas(16) Term {
  uint32_t a, b;    // offsets in pos of the face's other two corners' UVs
  uint32_t record;  // offset of the face's record
  uint32_t unused;
  float xy[4];  // x x y y: the frame vector a -> corner plus b -> corner, pixels (twice: the sums
                // of u and v read them as pairs)
};

// One Gauss-Seidel sweep: each free wedge (in order) moved towards the weighted mean of the
// positions its faces' other corners predict, from the records of fit_rotations (over-relaxed by
// kOverRelaxation). free_wedge: the free wedges' offsets in pos; term_end: the end of each one's
// terms. Returns the largest move (|du| + |dv|, pixels).
float sweep(size_t free_count, const uint32_t* free_wedge, const uint32_t* term_end, const Term* terms,
            const float* record, float* pos);

}  // namespace tailor::internal
