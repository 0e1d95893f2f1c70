// Crack closing, the last step of the patches mode: cracks (seams inside one patch) are zipped
// shut vertex by vertex from their tips, each zip relaxing the UVs of the faces around it.
//
// Why: the growth places every face isometrically (zero distortion) and so spends the whole
// curvature of the surface at the front: where two arms of the front meet with a gap wider than
// one face can absorb, it cuts, and the gap grows along the cut as the front goes on. The
// distortion budget (max_stretch) is left unused almost everywhere (Sander L2 ~1.004). Spreading
// the gap over the faces around a crack's tip, as-rigidly-as-possible, closes most of each crack
// within the same per-face bound.
//
// A zip merges the two UVs a vertex has on the two sides of a crack edge that ends at a shared
// vertex (the tip), then relaxes the free UVs of the faces within a few rings of it by local-global
// ARAP iterations (per face the nearest rotation of its Jacobian, per UV vertex the mean of the
// positions its faces predict); the UVs on the ring's edge stay fixed, so nothing outside changes.
// It is kept only if every face it touched is within the bounds (max_stretch, and an area ratio
// near 1), else undone: every face stays within max_stretch, no face inverts, and each kept zip
// removes at least one seam edge. Zips go nearest to the component's seed first, band by band of
// seed distance, so removing part of a mesh changes only zips near or after the first one it
// touches (stability, as the hop rule); bands far enough apart not to share a vertex are zipped on
// several threads, with the same result for any thread count (close_cracks at the end).
//
// Cost: the horse (97k faces) runs ~7,500 relaxations of ~70 moving faces and ~10 iterations each.
// The local step (fit_rotations) takes four faces per instruction and the global step (sweep) u
// and v side by side (SSE2), each bit-identical to its scalar twin; per relaxation the buffers
// only grow, and what a face needs in every relaxation (its zero-area test) is computed once.
//
// This work is based on:
//   L. Liu, L. Zhang, Y. Xu, C. Gotsman, S. J. Gortler, "A local/global approach to mesh
//   parameterization", SGP 2008 (ARAP local/global iterations; uniform weights here).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "util/simd.h"

#include "mapping/face_stretch.h"
#include "util/huge_pages.h"
#include "mapping/mapping_common.h"
#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

constexpr int kNext[3] = {1, 2, 0};
constexpr int kPrev[3] = {2, 0, 1};
// Tuned on the shared meshes (bunny, horse, spot, chinese-dragon; docs/mapping.md section 2):
// A gap wider than its crack edge is more than a region of 16 rings absorbs within the bound
// (< 1 % of those zips passed): left without trying.
constexpr float kMaxGapRatio = 1.f;
// The first region has crack_rings / 2 rings per unit of gap / edge length (at least kMinRings; 8
// by default); a zip that fails is tried once more with twice the rings (at most crack_rings)
// unless its distortion was beyond kEscalateAbove times the bound (then a larger region rarely
// helped: 4 % of tries). So crack_rings scales the effort: bunny 16 -> 32 rings, 4.0 -> 3.5 %
// seams for 2.2x the closing's time (docs/mapping.md).
constexpr int kMinRings = 2;
constexpr float kEscalateAbove = 1.5f;
// Local/global iterations per relaxation, stopped early once no UV moves by kSettledPx, or given
// up when the distortion after kAbortAt iterations is still beyond kEscalateAbove times the bound
// (measured on the horse: 1 % of those relaxations ended within it; saves 20 % of the time).
constexpr int kIterations = 12;
constexpr float kSettledPx = 0.05f;
constexpr int kAbortAt = 5;
// Successive over-relaxation of the Gauss-Seidel sweep: each free UV moves 1.2x of the way to its
// weighted mean. Within the same iterations more zips settle within the bound: mean seam length
// over the 16 shared meshes 6.43 -> 6.34% (13 lower, 2 higher; bunny 4.04 -> 3.90%, spot 6.72 ->
// 6.30%) for the same instructions; 1.3-1.4 gained little more, 1.6 raised the seams again.
constexpr float kOverRelaxation = 1.2f;
// Reweighting: a face's weight is multiplied by 1 + (distortion / bound)^2 after each iteration.
// Without it the distortion peaks at the zipped vertex (uniform ARAP) and 40 % fewer zips pass.
// A zipped face must also keep its area within 1/(1 + kAreaBound)..1 + kAreaBound of the
// surface's: the cone a zip flattens is mostly area change, and unbounded it raised the thesis
// stretch (the area ratio's variation) past 0.08 on spot. It widens in proportion to max_stretch
// above the default 0.25 (at max_stretch 4 a fixed 0.2 let 0 zips through on spot).
constexpr float kAreaBound = 0.2f;
// A zip at a vertex with more corners than this would relax its whole fan, once per crack edge
// there (O(valence^2): a fan of 40k faces took 48 s, one of 1e6 would never end); such vertices
// keep their cracks. Scans have valences of 4-12.
constexpr uint32_t kMaxZipValence = 64;
// Faces per closing worker: below this, starting threads costs more than it saves.
constexpr size_t kFacesPerClosingThread = 10000;

// === Local step ===================================================================================
// Per moving face, what the Gauss-Seidel step reads of it (kRecord floats, see fit_rotations).
constexpr uint32_t kRecord = 8;

// Moving face i's part of fit_rotations, one face at a time (the SIMD loop's scalar twin: the same
// operations in the same order). u1x..u2y: its UVs' corners 1 and 2 minus corner 0.
template <bool kReweight>
void fit_face(size_t i, size_t count, float bound, float u1x, float u1y, float u2x, float u2y, const float* frame,
              float* weight, float* ratio, float* record) {
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
    const float distortion = sigma_min > 1e-6f ? std::min(std::max(qn + rn - 1.f, 1.f / sigma_min - 1.f), kCap) : kCap;
    ratio[i] = distortion / bound;
    weight[i] *= 1.f + ratio[i] * ratio[i];
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

// With GCC on x86-64 the fit and the sweep are also compiled for AVX, and that version is taken at
// load time where the CPU has it: the same SSE operations in three-operand (VEX) form, 8 % fewer
// instructions in the closing on the horse (AVX enables no FMA: the results are the same). Clang
// 14 cannot multiversion a template.
#if TAILOR_SSE2 && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define TAILOR_AVX_CLONES __attribute__((target_clones("avx", "default")))
#else
#define TAILOR_AVX_CLONES
#endif

#if TAILOR_SSE2
inline __m128 load_pair(const float* p) {  // p[0] p[1] 0 0
  return _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
}
inline __m128 blend(__m128 mask, __m128 yes, __m128 no) {
  return _mm_or_ps(_mm_and_ps(mask, yes), _mm_andnot_ps(mask, no));
}
#endif

// The local step for the `count` moving faces: per face the rotation nearest to its Jacobian J
// (frame -> current UVs), premultiplied by its weight; with kReweight, first the weight times
// 1 + (d / bound)^2, d its distortion max(sigma_max - 1, 1/sigma_min - 1) (capped), and d / bound to
// ratio. Closed form for 2x2: with J = [a b; c d], the rotation turns by atan2(c - b, a + d) and
// sigma = |q| +- |r|, q and r its conformal and anti-conformal parts (face_stretch.h). The adjugate
// of Q is used: 1/det(Q) > 0 scales J without turning it.
// corner_pos: per face its 3 corners' offsets in pos (UV pairs); frame: 5 blocks of `count` floats,
// q1x, q1y, q2x, q2y (the frame's corners 1 and 2 minus corner 0, pixels) and half the inverse of
// their determinant; weight, ratio: per face; record: per face kRecord floats, the rotation's columns
// (c, s) and (-s, c), then the weight twice.
template <bool kReweight>
TAILOR_AVX_CLONES void fit_rotations(size_t count, float bound, const uint32_t* corner_pos, const float* pos,
                                     const float* frame, float* weight, float* ratio, float* record) {
  size_t i = 0;
#if TAILOR_SSE2
  // Four faces at a time: the scalar operations lane by lane (IEEE operations round each lane as
  // the scalar ones do, nothing is reordered, and a lane whose division the scalar code skips gets
  // a harmless divisor and is not selected), so the results have the same bits; a third of the
  // instructions of fit_face (the fit is a quarter of the closing's instructions).
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f), cap = _mm_set1_ps(10.f);
  for (; i + 4 <= count; i += 4) {
    __m128 u1x, u1y, u2x, u2y;
    {
      __m128 e[4];  // per face u1x u1y u2x u2y
      for (size_t k = 0; k < 4; ++k) {
        const uint32_t* c = corner_pos + 3 * (i + k);
        const __m128 p0 = load_pair(pos + c[0]);
        const __m128 p12 = _mm_loadh_pi(load_pair(pos + c[1]), reinterpret_cast<const __m64*>(pos + c[2]));
        e[k] = _mm_sub_ps(p12, _mm_movelh_ps(p0, p0));
      }
      _MM_TRANSPOSE4_PS(e[0], e[1], e[2], e[3]);
      u1x = e[0], u1y = e[1], u2x = e[2], u2y = e[3];
    }
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
      const __m128 r = _mm_div_ps(blend(valid, _mm_min_ps(cap, worst), cap), _mm_set1_ps(bound));
      _mm_storeu_ps(ratio + i, r);
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
    fit_face<kReweight>(i, count, bound, p1[0] - p0[0], p1[1] - p0[1], p2[0] - p0[0], p2[1] - p0[1], frame, weight,
                        ratio, record);
  }
}

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

// Sets a per-face, per-corner or per-vertex array to n copies of value, on huge pages (these are
// fresh and large: in 4 KiB pages, faulting them in was 40% of the mapping's page faults).
template <typename T>
void fresh(std::vector<T>& v, size_t n, T value) {
  reserve_huge(v, n);
  v.assign(n, value);
}

// Grows a scratch buffer to at least n elements (never shrinks: no refill when a smaller region
// comes before a larger one) and returns its data.
template <typename T>
T* scratch(std::vector<T>& v, size_t n) {
  if (v.size() < n) v.resize(n);
  return v.data();
}

// What the workers share. Each worker processes one band of seed distance at a time and reads or
// writes these only for the faces, corners and wedges of vertices near its band (see kZoneSteps
// and close_cracks): bands processed at the same time are further apart than that, so they never
// touch the same element.
struct CrackShared {
  std::vector<uint32_t> wedge;       // per corner: its wedge id
  std::vector<uint32_t> wedge_size;  // per wedge id: corners
  std::vector<uint32_t> vertex_start, vertex_corners;  // corners around each vertex (CSR)
  std::vector<uint8_t> zero_area;    // per face: is_zero_area_frame (a moving face is in ~6 relaxations)
  std::vector<uint32_t> face_stamp, wedge_stamp, wedge_local;  // per face / wedge id: relaxation marks
  std::vector<uint8_t> queued;       // per half-edge: waiting in a band's queue or an outbox
  std::vector<uint32_t> face_distance;    // per face: edge steps from its component's seed face (order)
  std::vector<uint32_t> vertex_distance;  // per vertex: edges from the nearest seed face's corners (bands)
  std::atomic<uint32_t> stamp{0};    // the last relaxation mark handed out (unique across workers)
  std::atomic<uint64_t> popped{0};   // queue entries taken, all workers
  std::atomic<bool> cancelled{false};
};

// A zip at a crack edge reads and writes only what belongs to vertices within crack_rings + 1
// edges of the edge's own: the merged vertices' fans (1 edge), one more edge per ring, the faces
// across the last ring (their corners' wedges and UVs), and the crack edges around the merged
// vertices. A band is crack_rings + kZoneSteps wide, so bands three apart stay 2 edges clear.
constexpr uint32_t kZoneSteps = 3;
constexpr uint32_t kBandPhases = 3;

class CrackCloser {
 public:
  CrackCloser(const MappingInput& in, Atlas& atlas, CrackShared& shared)
      : in_(in),
        atlas_(atlas),
        shared_(shared),
        wedge_(shared.wedge),
        wedge_size_(shared.wedge_size),
        vertex_start_(shared.vertex_start),
        vertex_corners_(shared.vertex_corners),
        zero_area_(shared.zero_area),
        face_stamp_(shared.face_stamp),
        wedge_stamp_(shared.wedge_stamp),
        wedge_local_(shared.wedge_local) {
    opposite_ = in_.topology.opposite.data();
    indices_ = in_.mesh.indices.data();
    local_ = in_.frames.local.data();
    uv_ = atlas_.corner_uv.data();
    scale_ = in_.options.scale;
    bound_ = in_.options.max_stretch;
    max_rings_ = static_cast<int>(std::max<uint32_t>(in_.options.crack_rings, kMinRings));
    area_bound_ = kAreaBound * std::max(1.f, bound_ / 0.25f);
    seam_flags_ = in_.options.seam_faces.empty() ? nullptr : in_.options.seam_faces.data();
  }

  // Fills the shared state (once, before any worker runs). With threads, the vertex distances
  // (a breadth-first search that reads only the mesh and the vertex fans) are found on a second
  // thread meanwhile.
  void build_shared(size_t threads) {
    const size_t face_count = in_.mesh.face_count();
    build_vertex_corners();
    run_beside(
        threads > 1, [this] { shared_.vertex_distance = vertex_seed_distances(); },
        [&] {
          build_wedges();
          fresh(zero_area_, face_count, uint8_t{0});
          for (size_t f = 0; f < face_count; ++f) zero_area_[f] = is_zero_area_frame(local_ + 6 * f);
          fresh(face_stamp_, face_count, 0u);
          fresh(wedge_stamp_, 3 * face_count, 0u);
          fresh(wedge_local_, 3 * face_count, 0u);
          fresh(shared_.queued, 3 * face_count, uint8_t{0});
          shared_.face_distance = face_seed_distances();
        });
  }

  // Crack edges are processed nearest to the component's seed first (queue key: the distance of
  // the edge's nearer face in edge steps, then the edge id). Why this order: zips overlap along a
  // crack and between neighbouring cracks, so each depends on those before it; with the seed's
  // neighbourhood first, removing part of the mesh (far from the seed, as in the stability test)
  // changes only zips processed after it (and zips beside the band boundaries that move where the
  // removal lengthens the seed distances: see close_cracks), as the growth's hop rule does for the
  // placements. (The vertex distance, coarser, leaves more ties to the edge ids, which a removal
  // renumbers: it cut the bit-identical share of the stability test from 88.8% to 72.5% on the
  // bunny.)
  uint64_t key(uint32_t e) const {
    const uint32_t d = std::min(shared_.face_distance[e / 3], shared_.face_distance[opposite_[e] / 3]);
    return (uint64_t{d} << 32) | e;
  }

  // The band of crack edge e: the distance of its nearer vertex over the band width.
  uint32_t band_of(uint32_t e, uint32_t band_steps) const {
    const EdgeCorners c = edge_corners(e);
    return std::min(shared_.vertex_distance[indices_[c.fa]], shared_.vertex_distance[indices_[c.fb]]) / band_steps;
  }

  // A seam edge inside one patch, not next to a user seam face (those seams were asked for).
  bool is_crack(uint32_t e) const {
    const uint32_t o = opposite_[e];
    if (o == kInvalid) return false;
    const uint32_t f = e / 3, g = o / 3;
    if (atlas_.patch[f] != atlas_.patch[g]) return false;
    if (seam_flags_ && (seam_flags_[f] || seam_flags_[g])) return false;
    const EdgeCorners c = edge_corners(e);
    return wedge_[c.fa] != wedge_[c.ga] || wedge_[c.fb] != wedge_[c.gb];
  }

  // Zips the crack edges of one band (a min-heap of keys) until none is left; a zip queues the
  // crack edges around the vertices it merged (they may end there now): into `heap` when they
  // are of this band, else into `outbox` (their keys). `report`: this worker reports progress
  // (every 256 pops, the share of `initial` popped by all workers) and may cancel.
  void close_band(std::vector<uint64_t>& heap, uint32_t band, uint32_t band_steps, std::vector<uint64_t>& outbox,
                  const ProgressCallback* report, size_t initial) {
    std::make_heap(heap.begin(), heap.end(), std::greater<>());
    uint8_t* const queued = shared_.queued.data();
    while (!heap.empty()) {
      if (shared_.cancelled.load(std::memory_order_relaxed)) return;
      const uint64_t popped = shared_.popped.fetch_add(1, std::memory_order_relaxed);
      // Every 256 pops (kProgressInterval counts placements; a pop here costs up to two
      // relaxations): the closing is most of the mapping's time, so it reports and can be cancelled.
      if (report && ++own_pops_ % 256 == 0 &&
          !(*report)(std::min(1.f, static_cast<float>(popped) / static_cast<float>(initial + 1)))) {
        shared_.cancelled.store(true, std::memory_order_relaxed);
        return;
      }
      std::pop_heap(heap.begin(), heap.end(), std::greater<>());
      const uint32_t e = static_cast<uint32_t>(heap.back());
      heap.pop_back();
      queued[e] = 0;
      if (!is_crack(e)) continue;
      const int merged = zip(e);
      if (merged == 0) continue;
      zipped_ += static_cast<uint64_t>(merged);
      for (int m = 0; m < merged; ++m) {
        const uint32_t v = merges_[static_cast<size_t>(m)].vertex;
        for (uint32_t i = vertex_start_[v]; i < vertex_start_[v + 1]; ++i) {
          const uint32_t c = vertex_corners_[i], f = c / 3, k = c - 3 * f;
          for (const uint32_t h : {c, 3 * f + static_cast<uint32_t>(kPrev[k])}) {  // f's two edges at v
            const uint32_t o = opposite_[h];
            if (o == kInvalid) continue;
            const uint32_t canonical = std::min(h, o);
            if (queued[canonical] || !is_crack(canonical)) continue;
            queued[canonical] = 1;
            const uint64_t k2 = key(canonical);
            const uint32_t b = band_of(canonical, band_steps);
            if (b == band) {
              heap.push_back(k2);
              std::push_heap(heap.begin(), heap.end(), std::greater<>());
            } else {
              outbox.push_back(k2);
            }
          }
        }
      }
    }
  }

  uint64_t zipped() const { return zipped_; }

 private:
  // Per face, its distance in edge steps from its component's seed face (breadth first).
  std::vector<uint32_t> face_seed_distances() const {
    const size_t face_count = in_.mesh.face_count();
    std::vector<uint32_t> distance, fifo;
    fresh(distance, face_count, kInvalid);
    reserve_huge(fifo, face_count);
    for (const uint32_t seed : in_.component_seeds) {
      distance[seed] = 0;
      fifo.push_back(seed);
    }
    for (size_t head = 0; head < fifo.size(); ++head) {
      const uint32_t f = fifo[head];
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t o = opposite_[3 * size_t{f} + k];
        if (o == kInvalid || distance[o / 3] != kInvalid) continue;
        distance[o / 3] = distance[f] + 1;
        fifo.push_back(o / 3);
      }
    }
    return distance;
  }

  // Per vertex, its distance in edges from the nearest corner of a seed face (in_.component_seeds;
  // vertices no seed reaches start their own search at 0), breadth first.
  std::vector<uint32_t> vertex_seed_distances() const {
    const size_t vertex_count = in_.mesh.vertex_count();
    std::vector<uint32_t> distance, fifo;
    fresh(distance, vertex_count, kInvalid);
    reserve_huge(fifo, vertex_count);
    auto reach = [&](uint32_t v, uint32_t d) {
      if (distance[v] != kInvalid) return;
      distance[v] = d;
      fifo.push_back(v);
    };
    auto search = [&](size_t head) {
      for (; head < fifo.size(); ++head) {
        const uint32_t v = fifo[head], d = distance[v] + 1;
        for (uint32_t i = vertex_start_[v]; i < vertex_start_[v + 1]; ++i) {
          const uint32_t c = vertex_corners_[i], f = c / 3, k = c - 3 * f;
          reach(indices_[3 * size_t{f} + static_cast<uint32_t>(kNext[k])], d);
          reach(indices_[3 * size_t{f} + static_cast<uint32_t>(kPrev[k])], d);
        }
      }
    };
    for (const uint32_t seed : in_.component_seeds)
      for (size_t k = 0; k < 3; ++k) reach(indices_[3 * size_t{seed} + k], 0);
    search(0);
    for (uint32_t v = 0; v < vertex_count; ++v) {
      if (distance[v] != kInvalid) continue;
      const size_t head = fifo.size();
      reach(v, 0);
      search(head);
    }
    return distance;
  }

  // === UV vertices ("wedges") ===================================================================
  // Corners around one mesh vertex that hold the same UV through a chain of faces form a wedge;
  // wedge_[c] is the id of corner c's wedge (one of its corners). Found by union-find across every
  // edge whose two faces agree on the shared corner.
  void build_wedges() {
    const uint32_t corners = static_cast<uint32_t>(3 * in_.mesh.face_count());
    fresh(wedge_, corners, 0u);
    for (uint32_t c = 0; c < corners; ++c) wedge_[c] = c;
    auto find = [this](uint32_t c) {
      while (wedge_[c] != c) c = wedge_[c] = wedge_[wedge_[c]];
      return c;
    };
    for (uint32_t e = 0; e < corners; ++e) {
      const uint32_t o = opposite_[e];
      if (o == kInvalid || o < e) continue;
      const uint32_t f = e / 3, g = o / 3;
      // Across patches too: a patch seeded from its neighbour continues its UVs across the seed
      // edge, and such a wedge (never wholly inside one patch's region) then stays where it is.
      // f's edge runs A -> B, g's B -> A.
      const uint32_t fa = e, fb = 3 * f + static_cast<uint32_t>(kNext[e - 3 * f]);
      const uint32_t gb = o, ga = 3 * g + static_cast<uint32_t>(kNext[o - 3 * g]);
      for (const auto& [x, y] : {std::pair{fa, ga}, std::pair{fb, gb}}) {
        if (!same_uv(x, y)) continue;
        const uint32_t rx = find(x), ry = find(y);
        if (rx != ry) wedge_[std::max(rx, ry)] = std::min(rx, ry);
      }
    }
    fresh(wedge_size_, corners, 0u);
    for (uint32_t c = 0; c < corners; ++c) {
      wedge_[c] = find(c);
      ++wedge_size_[wedge_[c]];
    }
  }

  void build_vertex_corners() {
    const size_t vertex_count = in_.mesh.vertex_count();
    const uint32_t corners = static_cast<uint32_t>(3 * in_.mesh.face_count());
    fresh(vertex_start_, vertex_count + 1, 0u);
    for (uint32_t c = 0; c < corners; ++c) ++vertex_start_[indices_[c] + 1];
    for (size_t v = 0; v < vertex_count; ++v) vertex_start_[v + 1] += vertex_start_[v];
    fresh(vertex_corners_, corners, 0u);
    std::vector<uint32_t> fill(vertex_start_.begin(), vertex_start_.end() - 1);
    for (uint32_t c = 0; c < corners; ++c) vertex_corners_[fill[indices_[c]]++] = c;
  }

  // Corner c's UV (size_t arithmetic: 2c wraps in 32 bits beyond 2^31 corners).
  const float* uv_of(uint32_t corner) const { return uv_ + 2 * size_t{corner}; }

  bool same_uv(uint32_t a, uint32_t b) const {
    return uv_of(a)[0] == uv_of(b)[0] && uv_of(a)[1] == uv_of(b)[1];
  }

  // The corners of half-edge e = 3f + k at its start A and end B, and the neighbour's at A and B.
  struct EdgeCorners {
    uint32_t fa, fb, ga, gb;
  };
  EdgeCorners edge_corners(uint32_t e) const {
    const uint32_t o = opposite_[e], f = e / 3, g = o / 3;
    return {e, 3 * f + static_cast<uint32_t>(kNext[e - 3 * f]), 3 * g + static_cast<uint32_t>(kNext[o - 3 * g]), o};
  }

  // === Zips ======================================================================================
  // Zips crack edge e: merges the two sides' wedges at its open end when the other end is shared
  // (a crack's tip), or at both ends when neither is (a crack without a tip, e.g. a cut from a
  // patch's border to its border), and relaxes around them. Returns the merged vertices' count
  // (0: nothing changed; merges_ then lists the merges).
  int zip(uint32_t e) {
    const EdgeCorners c = edge_corners(e);
    const float edge = std::hypot(uv_of(c.fa)[0] - uv_of(c.fb)[0], uv_of(c.fa)[1] - uv_of(c.fb)[1]);
    merges_.clear();
    changed_.clear();
    float gap_ratio = 0.f;
    for (const auto& [fc, gc] : {std::pair{c.fa, c.ga}, std::pair{c.fb, c.gb}}) {
      const uint32_t keep = wedge_[fc], drop = wedge_[gc];
      if (keep == drop) continue;
      const uint32_t v = indices_[fc];
      if (vertex_start_[v + 1] - vertex_start_[v] > kMaxZipValence) {
        undo_merges();
        return 0;
      }
      const float gap = std::hypot(uv_of(keep)[0] - uv_of(drop)[0], uv_of(keep)[1] - uv_of(drop)[1]);
      if (!(gap <= kMaxGapRatio * edge)) {
        undo_merges();
        return 0;
      }
      gap_ratio = std::max(gap_ratio, gap / edge);
      if (!merge(v, keep, drop)) {
        undo_merges();
        return 0;
      }
    }
    if (merges_.empty()) return 0;
    const uint32_t patch = atlas_.patch[e / 3];
    const float rings_per_gap = 0.5f * static_cast<float>(max_rings_);
    const int first = std::clamp(static_cast<int>(std::ceil(rings_per_gap * gap_ratio)), kMinRings, max_rings_);
    if (relax(patch, first)) return static_cast<int>(merges_.size());
    const int second = std::min(max_rings_, 2 * first);
    if (second > first && last_max_ <= kEscalateAbove && relax(patch, second)) return static_cast<int>(merges_.size());
    undo_merges();
    return 0;
  }

  // Joins wedge `drop` into `keep` at `vertex` (recorded in merges_ and changed_ for undo_merges).
  // Returns false if either reaches into another patch (its UV is pinned there) or holds a corner
  // of a user seam face (a zip there could close a seam the user asked for): no zip.
  bool merge(uint32_t vertex, uint32_t keep, uint32_t drop) {
    const Merge m{vertex, keep, drop, {0.5f * (uv_of(keep)[0] + uv_of(drop)[0]), 0.5f * (uv_of(keep)[1] + uv_of(drop)[1])}};
    const uint32_t patch = atlas_.patch[keep / 3];
    bool inside = true;
    for (uint32_t j = vertex_start_[vertex]; j < vertex_start_[vertex + 1]; ++j) {
      const uint32_t corner = vertex_corners_[j];
      const uint32_t w = wedge_[corner];
      if (w != keep && w != drop) continue;
      inside = inside && atlas_.patch[corner / 3] == patch && !(seam_flags_ && seam_flags_[corner / 3]);
      if (w != drop) continue;
      wedge_[corner] = keep;
      changed_.push_back(Change{corner, drop});
    }
    wedge_size_[keep] += wedge_size_[drop];
    merges_.push_back(m);
    return inside;
  }

  // Splits the merges of the current zip again.
  void undo_merges() {
    for (size_t i = changed_.size(); i-- > 0;) wedge_[changed_[i].corner] = changed_[i].wedge;
    for (size_t i = merges_.size(); i-- > 0;) wedge_size_[merges_[i].keep] -= wedge_size_[merges_[i].drop];
    changed_.clear();
    merges_.clear();
  }

  struct Change {
    uint32_t corner, wedge;  // the corner's wedge before the merge
  };
  struct Merge {
    uint32_t vertex = 0, keep = 0, drop = 0;
    float mid[2] = {0.f, 0.f};  // start UV of the merged wedge: the mean of the two
  };

  // Relaxes the faces of `patch` within `rings` rings around the merged vertices of merges_ (whose
  // corners still hold two UVs; started at the mean). Keeps the result and returns true if every
  // moved face is within the bounds; else restores every UV it changed. last_max_: the largest
  // distortion / bound of the last iteration.
  bool relax(uint32_t patch, int rings) {
    // A mark no other relaxation used, on any worker (close_cracks resets them before a wrap).
    stamp_ = shared_.stamp.fetch_add(1, std::memory_order_relaxed) + 1;
    last_max_ = 0.f;
    collect_region(patch, rings);
    if (!collect_moving()) {
      last_max_ = std::numeric_limits<float>::infinity();  // a larger region holds the same face: no retry
      return false;
    }
    build_terms();
    const size_t moving = moving_.size(), free_count = free_wedge_.size();
    const uint32_t* const corner_pos = corner_pos_.data();
    const uint32_t* const free_wedge = free_wedge_.data();
    const uint32_t* const term_end = term_end_.data();
    const Term* const terms = terms_.data();
    const float* const fit_frame = fit_frame_.data();
    float* const pos = pos_.data();
    float* const weight = weight_.data();
    float* const ratio = ratio_.data();
    float* const record = record_.data();

    // --- Local/global iterations: per face the rotation nearest to its Jacobian (and, from the
    // second on, its weight raised by its distortion: iteratively reweighted, so the distortion
    // is spread instead of peaking at the zipped vertex), then Gauss-Seidel over the free wedges,
    // each moved to the weighted mean of the positions its faces' other corners predict ---
    int iteration = 0;
    for (; iteration < kIterations; ++iteration) {
      if (iteration == 0)
        fit_rotations<false>(moving, bound_, corner_pos, pos, fit_frame, weight, ratio, record);
      else
        fit_rotations<true>(moving, bound_, corner_pos, pos, fit_frame, weight, ratio, record);
      const float moved = sweep(free_count, free_wedge, term_end, terms, record, pos);
      if (moved < kSettledPx) break;
      if (iteration == kAbortAt && max_ratio() > kEscalateAbove) break;
    }
    // The ratios are the last iteration's (none when that was the first: no reweighting there).
    if (std::min(iteration, kIterations - 1) > 0) last_max_ = max_ratio();

    // --- Check, then keep or restore (the faces written so far: the check stops at the first
    // face out of the bounds) ---
    float* const saved = scratch(saved_, 6 * moving);
    size_t written = 0;
    bool within = true;
    for (; written < moving && within; ++written) {
      float* uv = uv_ + 6 * size_t{moving_[written]};
      std::copy(uv, uv + 6, saved + 6 * written);
      for (size_t k = 0; k < 3; ++k) {
        const float* p = pos + corner_pos[3 * written + k];
        uv[2 * k] = p[0];
        uv[2 * k + 1] = p[1];
      }
      const StretchFrame& frame = frame_[written];
      const float area_ratio = ((uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[4] - uv[0]) * (uv[3] - uv[1])) * frame.inv;
      within = stretch_error(frame, uv) <= bound_ && area_ratio <= 1.f + area_bound_ &&
               area_ratio * (1.f + area_bound_) >= 1.f;
    }
    if (within) return true;
    for (size_t i = 0; i < written; ++i) std::copy(saved + 6 * i, saved + 6 * i + 6, uv_ + 6 * size_t{moving_[i]});
    return false;
  }

  float max_ratio() const {
    float m = 0.f;
    for (size_t i = 0; i < moving_.size(); ++i) m = std::max(m, ratio_[i]);
    return m;
  }

  // region_: the faces of the patch within `rings` edge-steps of the merged vertices' fans, ring by
  // ring (marked in face_stamp_).
  void collect_region(uint32_t patch, int rings) {
    const uint32_t* const face_patch = atlas_.patch.data();
    uint32_t* const face_stamp = face_stamp_.data();
    const uint32_t stamp = stamp_;
    region_.clear();
    for (const Merge& m : merges_) {
      for (uint32_t i = vertex_start_[m.vertex]; i < vertex_start_[m.vertex + 1]; ++i) {
        const uint32_t f = vertex_corners_[i] / 3;
        if (face_patch[f] == patch && face_stamp[f] != stamp) {
          face_stamp[f] = stamp;
          region_.push_back(f);
        }
      }
    }
    for (size_t begin = 0, ring = 0; ring < static_cast<size_t>(rings); ++ring) {
      const size_t end = region_.size();
      const auto add = [&](uint32_t o) {
        if (o == kInvalid) return;
        const uint32_t g = o / 3;
        if (face_stamp[g] == stamp || face_patch[g] != patch) return;
        face_stamp[g] = stamp;
        region_.push_back(g);
      };
      for (size_t i = begin; i < end; ++i) {
        const uint32_t* o = opposite_ + 3 * size_t{region_[i]};
        add(o[0]);
        add(o[1]);
        add(o[2]);
      }
      begin = end;
    }
  }

  // The wedges of the region in order of first appearance (local ids; free: every corner of the
  // wedge lies in the region) with their start UVs, then the moving faces (those with a free
  // corner) with their corners, frames and the fit's inputs. Returns false if a moving face has
  // zero area (its rotation is meaningless and its image may not invert): no relaxation.
  bool collect_moving() {
    const uint32_t* const wedge = wedge_.data();
    uint32_t* const wedge_stamp = wedge_stamp_.data();
    uint32_t* const wedge_local = wedge_local_.data();
    const uint32_t stamp = stamp_;
    local_wedge_.clear();
    local_count_.clear();
    const auto count = [&](uint32_t w) {
      if (wedge_stamp[w] == stamp) {
        ++local_count_[wedge_local[w]];
        return;
      }
      wedge_stamp[w] = stamp;
      wedge_local[w] = static_cast<uint32_t>(local_wedge_.size());
      local_wedge_.push_back(w);
      local_count_.push_back(1);
    };
    for (const uint32_t f : region_) {
      count(wedge[3 * f]);
      count(wedge[3 * f + 1]);
      count(wedge[3 * f + 2]);
    }
    // Start UVs: the atlas's, a merged wedge's the mean of its two; free_index: the free wedges'
    // order (kInvalid: fixed); term_end: each free wedge's first term (build_terms moves it to its
    // end). A free wedge has a term per corner: each of its faces is in the region and moving.
    const size_t wedge_count = local_wedge_.size();
    float* const pos = scratch(pos_, 2 * wedge_count);
    uint32_t* const free_index = scratch(free_index_, wedge_count);
    uint32_t* const term_end = scratch(term_end_, wedge_count);
    free_wedge_.clear();
    term_count_ = 0;
    for (size_t l = 0; l < wedge_count; ++l) {
      const uint32_t w = local_wedge_[l];
      pos[2 * l] = uv_[2 * size_t{w}];
      pos[2 * l + 1] = uv_[2 * size_t{w} + 1];
      free_index[l] = kInvalid;
      if (local_count_[l] != wedge_size_[w]) continue;
      free_index[l] = static_cast<uint32_t>(free_wedge_.size());
      term_end[free_wedge_.size()] = term_count_;
      term_count_ += local_count_[l];
      free_wedge_.push_back(static_cast<uint32_t>(2 * l));
    }
    for (const Merge& m : merges_) {
      if (wedge_stamp[m.keep] != stamp) continue;
      pos[2 * size_t{wedge_local[m.keep]}] = m.mid[0];
      pos[2 * size_t{wedge_local[m.keep]} + 1] = m.mid[1];
    }
    moving_.clear();
    uint32_t* const corner_pos = scratch(corner_pos_, 3 * region_.size());
    for (const uint32_t f : region_) {
      const uint32_t l0 = wedge_local[wedge[3 * f]], l1 = wedge_local[wedge[3 * f + 1]],
                     l2 = wedge_local[wedge[3 * f + 2]];
      if ((free_index[l0] & free_index[l1] & free_index[l2]) == kInvalid) continue;  // no free corner
      if (zero_area_[f]) return false;
      uint32_t* c = corner_pos + 3 * moving_.size();
      c[0] = 2 * l0;
      c[1] = 2 * l1;
      c[2] = 2 * l2;
      moving_.push_back(f);
    }
    // Per moving face: its frame, the fit's inputs (see fit_rotations) and its edge vectors in
    // pixels (edge k: corner k -> corner k+1; the terms' frame vectors are their differences).
    const size_t moving = moving_.size();
    StretchFrame* const frame = scratch(frame_, moving);
    float* const fit_frame = scratch(fit_frame_, 5 * moving);
    float* const edge = scratch(face_edge_, 6 * moving);
    std::fill_n(scratch(weight_, moving), moving, 1.f);
    scratch(ratio_, moving);
    scratch(record_, kRecord * moving);
    for (size_t i = 0; i < moving; ++i) {
      const float* l = local_ + 6 * size_t{moving_[i]};
      float* e = edge + 6 * i;
      for (int k = 0; k < 3; ++k) {
        e[2 * k] = (l[2 * kNext[k]] - l[2 * k]) * scale_;
        e[2 * k + 1] = (l[2 * kNext[k] + 1] - l[2 * k + 1]) * scale_;
      }
      frame[i] = stretch_frame(l, scale_);
      fit_frame[i] = e[0];
      fit_frame[moving + i] = e[1];
      fit_frame[2 * moving + i] = -e[4];
      fit_frame[3 * moving + i] = -e[5];
      fit_frame[4 * moving + i] = 0.5f * frame[i].inv;
    }
    return true;
  }

  // The corners of each free wedge in the moving faces (CSR over the free wedges in local id
  // order, each wedge's in face order), each with what its prediction needs: the face's record,
  // the other two corners' UVs, and the sum of the frame vectors from them to it (the rotation is
  // linear, so one vector serves both predictions).
  void build_terms() {
    const size_t moving = moving_.size();
    const uint32_t* const corner_pos = corner_pos_.data();
    const uint32_t* const free_index = free_index_.data();
    uint32_t* const end = term_end_.data();
    Term* const terms = scratch(terms_, term_count_);
    for (uint32_t i = 0; i < moving; ++i) {
      const float* e = &face_edge_[6 * size_t{i}];
      const uint32_t* c = corner_pos + 3 * size_t{i};
      for (int k = 0; k < 3; ++k) {
        const uint32_t index = free_index[c[k] / 2];
        if (index == kInvalid) continue;
        // From the next corner: minus edge k; from the previous: edge k-1.
        const float x = e[2 * kPrev[k]] - e[2 * k], y = e[2 * kPrev[k] + 1] - e[2 * k + 1];
        terms[end[index]++] = Term{c[kNext[k]], c[kPrev[k]], kRecord * i, 0, {x, x, y, y}};
      }
    }
  }

  const MappingInput& in_;
  Atlas& atlas_;
  CrackShared& shared_;
  const uint32_t* opposite_ = nullptr;
  const uint32_t* indices_ = nullptr;
  const float* local_ = nullptr;
  float* uv_ = nullptr;
  const uint8_t* seam_flags_ = nullptr;
  float scale_ = 1.f, bound_ = 0.f;
  int max_rings_ = kMinRings;
  float area_bound_ = kAreaBound;  // kAreaBound, widened in proportion above the default max_stretch
  float last_max_ = 0.f;
  uint64_t zipped_ = 0, own_pops_ = 0;
  // The shared arrays (see CrackShared), by their names here.
  std::vector<uint32_t>& wedge_;
  std::vector<uint32_t>& wedge_size_;
  std::vector<uint32_t>& vertex_start_;
  std::vector<uint32_t>& vertex_corners_;
  std::vector<uint8_t>& zero_area_;
  std::vector<uint32_t>& face_stamp_;
  std::vector<uint32_t>& wedge_stamp_;
  std::vector<uint32_t>& wedge_local_;
  // Scratch of one relaxation, reused (no allocation per zip once warm; the per-face and
  // per-wedge buffers only grow, see scratch()).
  uint32_t stamp_ = 0;
  std::vector<uint32_t> region_, moving_;  // faces within the rings; those with a free corner
  std::vector<Change> changed_;
  std::vector<Merge> merges_;
  // Per local wedge: its wedge id, its corners in the region, its UV (pos_, 2 floats) and its index
  // among the free ones (kInvalid: fixed); per free wedge: its offset in pos_ and the end of its
  // terms (CSR, term_count_ in all).
  std::vector<uint32_t> local_wedge_, local_count_, free_index_, free_wedge_, term_end_;
  uint32_t term_count_ = 0;
  std::vector<float> pos_;
  std::vector<Term> terms_;
  // Per moving face: its corners' offsets in pos_ (3), frame, the fit's inputs (5 blocks, see
  // fit_rotations), edges (6), weight, last distortion / bound, record (kRecord) and UVs before the
  // check (6).
  std::vector<uint32_t> corner_pos_;
  std::vector<StretchFrame> frame_;
  std::vector<float> fit_frame_, face_edge_, weight_, ratio_, record_, saved_;
};

}  // namespace

// Threads: the crack edges are cut into bands of seed distance crack_rings + kZoneSteps wide. A
// zip reaches only vertices within crack_rings + 1 edges of its own (kZoneSteps), so bands three
// apart never touch the same vertex, face, corner or wedge: the bands 0, 3, 6... are zipped at
// once (each in key order, largest first, each by the next free worker), then 1, 4, 7... and
// 2, 5, 8..., and again while zips queue edges into bands already done. The result depends on the
// bands only, not on which worker zipped which band nor on how many workers there were.
// Stability: where removing part of a mesh lengthens the seed distances (behind the hole), the
// band boundaries move with them and the zips beside a boundary change order. That, not the
// phase order, cost the stability test's bit-identical share 9 points on fertility and the bunny
// (measured before the sweeps were over-relaxed; bands in seed order without phases lost the
// same; bands 2x / 4x wider lost 5 / 2 on the bunny, with less parallelism). Cubes fixed in space
// (coloured modulo 3) kept the bunny's share but, run colour by colour, lost 55 points on spot;
// and any Lipschitz bound in space comes from the longest edge, an outlier on scans (the bunny
// would be one band). docs/mapping.md, section 2.
Status close_cracks(const MappingInput& input, const ProgressCallback& progress, Atlas& atlas, uint64_t& zipped) {
  zipped = 0;
  const size_t face_count = input.mesh.face_count();
  CrackShared shared;
  const size_t threads = parallel_threads(face_count, input.options.threads, kFacesPerClosingThread);
  std::vector<std::unique_ptr<CrackCloser>> workers;  // one allocation per worker, not per element
  for (size_t t = 0; t < threads; ++t) workers.push_back(std::make_unique<CrackCloser>(input, atlas, shared));
  CrackCloser& first = *workers[0];
  first.build_shared(threads);

  const uint32_t band_steps = std::max<uint32_t>(input.options.crack_rings, kMinRings) + kZoneSteps;
  const uint32_t* opposite = input.topology.opposite.data();
  std::vector<std::vector<uint64_t>> heaps;  // per band: keys (the edge in the low 32 bits)
  auto add_to_band = [&](uint64_t key) {
    const uint32_t band = first.band_of(static_cast<uint32_t>(key), band_steps);
    if (band >= heaps.size()) heaps.resize(band + 1);
    heaps[band].push_back(key);
  };
  size_t initial = 0;
  for (uint32_t e = 0; e < 3 * face_count; ++e) {
    if (!(e < opposite[e] && first.is_crack(e))) continue;  // each crack edge once
    add_to_band(first.key(e));
    shared.queued[e] = 1;
    ++initial;
  }
  std::vector<std::vector<uint64_t>> outboxes(threads);
  for (bool any = true; any;) {
    any = false;
    for (uint32_t parity = 0; parity < kBandPhases; ++parity) {
      std::vector<uint32_t> bands;
      for (uint32_t b = parity; b < heaps.size(); b += kBandPhases)
        if (!heaps[b].empty()) bands.push_back(b);
      if (bands.empty()) continue;
      any = true;
      // Relaxation marks are 32-bit: reset between phases once half are used (a phase would need
      // 2^31 relaxations, ~10^10 faces, to wrap).
      if (shared.stamp.load() > (uint32_t{1} << 31)) {
        std::fill(shared.face_stamp.begin(), shared.face_stamp.end(), 0);
        std::fill(shared.wedge_stamp.begin(), shared.wedge_stamp.end(), 0);
        shared.stamp.store(0);
      }
      // Largest first, each to the next free worker: the phase ends with its largest band.
      std::stable_sort(bands.begin(), bands.end(),
                       [&](uint32_t a, uint32_t b) { return heaps[a].size() > heaps[b].size(); });
      const size_t used = std::min(threads, bands.size());
      std::atomic<size_t> next_band{0}, helpers_done{0};
      std::exception_ptr failure;  // the first exception of a helper (out of memory), rethrown here
      std::mutex failure_mutex;
      auto work = [&](size_t w) {
        try {
          for (size_t i; (i = next_band.fetch_add(1)) < bands.size();)
            workers[w]->close_band(heaps[bands[i]], bands[i], band_steps, outboxes[w],
                                   w == 0 && progress ? &progress : nullptr, initial);
        } catch (...) {
          if (w == 0) throw;
          const std::lock_guard<std::mutex> lock(failure_mutex);
          if (!failure) failure = std::current_exception();
          shared.cancelled.store(true);
        }
        if (w != 0) helpers_done.fetch_add(1);
      };
      std::vector<std::thread> helpers;
      try {
        helpers.reserve(used - 1);
        for (size_t w = 1; w < used; ++w) helpers.emplace_back(work, w);
      } catch (...) {  // no thread to be had: fewer workers, same result
      }
      try {
        work(0);
      } catch (...) {
        shared.cancelled.store(true);
        for (std::thread& h : helpers) h.join();
        throw;
      }
      // The calling thread, out of bands, keeps reporting (and may cancel) until the others finish.
      while (helpers_done.load() < helpers.size()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        if (progress && !shared.cancelled.load() &&
            !progress(std::min(1.f, static_cast<float>(shared.popped.load()) / static_cast<float>(initial + 1))))
          shared.cancelled.store(true);
      }
      for (std::thread& h : helpers) h.join();
      if (failure) std::rethrow_exception(failure);
      if (shared.cancelled.load()) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
      // Edges queued into other bands: a heap's pops depend only on its set of (unique) keys.
      for (std::vector<uint64_t>& outbox : outboxes) {
        for (const uint64_t key : outbox) add_to_band(key);
        outbox.clear();
      }
    }
  }
  for (const auto& worker : workers) zipped += worker->zipped();
  if (progress && !progress(1.f)) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
  return Status::ok();
}

}  // namespace tailor::internal
