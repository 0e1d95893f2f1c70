// Relaxation, the last step of the patches mode: a few local/global ARAP iterations over the UV
// vertices, to lower the angle distortion that the growth and the crack closing leave.
//
// Why: the growth places each face in its own frame and takes the third corner from its placed
// neighbours where they know it, so the faces that close a gap are sheared; the crack closing
// spends the distortion budget within a few rings of each zip. Both leave every face's angles a few
// degrees off (median over the shared meshes 6.5 degrees, the sum over a face's corners) where a
// map of the same patches with the same seams can do with far less.
//
// What moves: the UV vertices ("wedges": the corners of one vertex joined by faces that agree on
// their UV, across patches too, so a seamless edge stays seamless) except the two sides of an
// invisible seam (a seam edge whose sides are less than kInvisibleGapPx apart at both ends, or
// whose lattice gap at the texture period is: both
// ends' wedges stay where they are, so the seam stays invisible) and the corners of zero-area faces.
// The two sides of a visible seam move independently: the seam stays a seam, its gap changes.
// Patches, seam edges and invisible seams are exactly as before.
//
// One iteration: the local step gives each face the rotation nearest to its Jacobian (face frame,
// pixels -> UV) and a weight 1 / max(|J - R|, kIrlsFloor) (iteratively reweighted towards the sum
// of |J - R| instead of its square: the distortion concentrates on fewer faces, the median goes
// down); the global step moves each free wedge towards the weighted mean of the positions its
// faces predict from their other two corners with that rotation (cotangent weights divided by the
// face's area: every face's |J - R|^2 counts alike), over-relaxed by kPatchOverRelaxation, unless a
// face around it would leave max_stretch or invert (checked with stretch_error; skipped where the
// face's slack, the distance of its singular values from the bound at the local step less what
// its corners moved since, covers the move: a singular value moves by at most the move times
// 1 / the face's height over that corner). The free wedges are coloured so that no two of a colour
// share a face: the moves of one colour are independent of each other, so a colour is swept by any
// number of threads with the same result, and the colours go in a fixed order (Gauss-Seidel by
// colour).
//
// The texture direction: the rotations are not pulled towards the patch's direction (the
// orientation field's, with field_following 1). The relaxation keeps it as it is: the median angle
// between a face's field direction in UV and its patch's mean direction goes 2.7 -> 2.4 degrees on
// the horse (5.0 -> 4.5 on the armadillo); a pull (the rotation of J + 0.1 R_patch) took it to 2.3
// for a median distortion of 2.4 instead of 1.85 degrees over the shared meshes.
//
// Cost: O(F) setup (wedges, colouring, per-face fields and per-corner terms; sequential), then
// O(F) per iteration, parallel over faces (local step) and over the wedges of each colour (global
// step); no global solve. The local step reads the faces' fields in blocks (SoA: four faces per
// SSE2 instruction) and writes each free corner's prediction (m wn, m wp, m R d) into its term;
// the global step reads a wedge's terms in a row and its neighbours' positions, u and v side by
// side, and checks the slack of the wedge's faces at once (their least slack against the move
// times their largest inverse height) before it checks them one by one. Each SIMD loop has its
// scalar twin (same bits: tests/simd_test.sh), and GCC also compiles both steps for AVX. On the
// horse, one thread (`valgrind --tool=callgrind --toggle-collect='tailor::internal::relax_patches*'
// build/tailor map horse.ply -o h.glb --threads 1`): ~2,800 instructions per face, ~850 of them
// setup, then ~190 per face and iteration (local step ~57, global step ~120, stretch checks ~12).
// Memory: ~57 bytes per corner while it runs.
//
// This work is based on:
//   L. Liu, L. Zhang, Y. Xu, C. Gotsman, S. J. Gortler, "A local/global approach to mesh
//   parameterization", SGP 2008.
#include <algorithm>
#include <atomic>
#include <barrier>
#include <cmath>
#include <limits>
#include <system_error>
#include <thread>
#include <vector>

#include "mapping/face_stretch.h"
#include "mapping/mapping_common.h"
#include "tailor/metrics.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"
#include "util/simd.h"
#include "util/union_find.h"

namespace tailor::internal {
namespace {

// Tuned on the 16 shared meshes (docs/mapping.md, section 2, relaxation); 10 iterations by default:
// Successive over-relaxation of the global step: 1.6 / 1.8 / 1.9 gave a median distortion of
// 1.97 / 1.83 / 1.88 degrees after 10 iterations (1.0: about twice the iterations for the same).
constexpr float kPatchOverRelaxation = 1.8f;
// Reweighting floor (|J - R|, dimensionless): 0.005 / 0.01 / 0.02 gave 1.94 / 1.83 / 2.09 degrees;
// without reweighting (plain ARAP) 2.86, with the CAD parts' distortion up from 0.2-0.45 to 1-1.6.
constexpr float kIrlsFloor = 0.01f;
// Seam sides nearer than this at both ends of an edge are an invisible seam (the metrics' default
// invisible gap): they stay put.
constexpr float kInvisibleGapPx = 1.f;
// The iterations stop early once no wedge moves by this much (|du| + |dv|).
constexpr float kPatchSettledPx = 0.01f;
// The slack that lets a move skip its check is kept kSlackMargin + kRoundingPerCondition times the
// face's condition (|q1|^2 + |q2|^2) / det(q) inside the bound: the float singular values of the
// local step and of stretch_error are each within ~1e-7 times the condition of the exact ones, so
// a skipped check would have passed (a sliver of condition 1e4 is always checked).
constexpr float kSlackMargin = 1e-4f;
constexpr float kRoundingPerCondition = 1e-6f;
// Work items per claim of a thread, and faces per thread worth starting.
constexpr size_t kFacesPerChunk = 4096;
constexpr size_t kWedgesPerChunk = 1024;
constexpr size_t kFacesPerRelaxThread = 20000;

// Per corner of a free wedge: its prediction (rewritten by every local step) and what the global
// step and the check read of it. The terms of a wedge are contiguous, and the wedges of a colour
// too, so a sweep streams through them; the local step writes each face's three.
struct alignas(16) Term {
  // The face's weight m times the cotangent weights of the predictions from the next and the
  // previous corner, and m R (wn (x_k - x_next) + wp (x_k - x_prev)), R its rotation, x its frame
  // corners (pixels): the prediction is mwn p_next + mwp p_prev + (tx, ty), of weight mwn + mwp.
  float mwn, mwp, tx, ty;
  uint32_t next, prev;  // offsets in pos of the face's corners k + 1 and k + 2
  uint32_t face;        // the face's active index
  float inv_height;     // 1 / the face's height over corner k, 1/pixels
};

// Per active face, blocks of the face count (SoA: the local step reads four faces at a time): its
// frame edges q1, q2 (pixels) and the inverse of their determinant, the cotangent weights of its
// edges opposite corners 0, 1, 2 (over its area), the margin kept off its slack.
enum FaceField : size_t { kQ1x, kQ1y, kQ2x, kQ2y, kInv, kW0, kW1, kW2, kMargin, kFaceFields };

class Relaxer {
 public:
  Relaxer(const MappingInput& in, Atlas& atlas)
      : in_(in),
        uv_(atlas.corner_uv.data()),
        scale_(in.options.scale),
        bound_(in.options.max_stretch),
        high_(1.f + bound_),
        low_(1.f / (1.f + bound_)) {
    lattice_ = lattice_of(in.options);  // quarter turns too with symmetry 4
  }

  // Wedges, the free ones' colours and terms, per active face its frame and weights.
  void build() {
    const size_t face_count = in_.mesh.face_count();
    const uint32_t corners = static_cast<uint32_t>(3 * face_count);
    const uint32_t* const opposite = in_.topology.opposite.data();
    const float* const local = in_.frames.local.data();
    // Wedges: union-find over every paired edge whose two faces agree on the shared corner's UV;
    // a root is its wedge's lowest corner. id: per corner kInvalid when pinned (both sides at both
    // ends of an invisible seam, and the corners of zero-area faces), else (below) its free
    // wedge's provisional id; a wedge with a pinned corner is pinned.
    constexpr uint32_t kFree = 0;
    HugeArray<uint32_t> root = huge_uninitialized<uint32_t>(corners);
    std::vector<uint32_t> id;
    reserve_huge(id, corners);
    id.assign(corners, kFree);
    for (uint32_t c = 0; c < corners; ++c) root[c] = c;
    const auto find = [&root](uint32_t c) { return find_root(root.get(), c); };
    for (uint32_t e = 0; e < corners; ++e) {
      const uint32_t o = opposite[e];
      if (o == kInvalid || o < e) continue;
      const Sides s = sides(e, o);
      bool seamless = true;
      for (const auto& [x, y] : {std::pair{s.fa, s.ga}, std::pair{s.fb, s.gb}}) {
        if (!same_uv(x, y)) {
          seamless = false;
          continue;
        }
        const uint32_t rx = find(x), ry = find(y);
        if (rx != ry) root[std::max(rx, ry)] = std::min(rx, ry);
      }
      if (seamless) continue;
      const bool narrow = gap(s.fa, s.ga) < kInvisibleGapPx && gap(s.fb, s.gb) < kInvisibleGapPx;
      if (!narrow && !(seam_gap_px(&uv_[2 * size_t{s.fa}], &uv_[2 * size_t{s.fb}], &uv_[2 * size_t{s.ga}],
                                   &uv_[2 * size_t{s.gb}], lattice_) < kInvisibleGapPx))
        continue;
      for (const uint32_t c : {s.fa, s.fb, s.ga, s.gb}) id[c] = kInvalid;
    }
    for (size_t f = 0; f < face_count; ++f)
      if (is_zero_area_frame(local + 6 * f))
        for (size_t k = 0; k < 3; ++k) id[3 * f + k] = kInvalid;
    for (uint32_t c = 0; c < corners; ++c) {
      root[c] = find(c);
      if (id[c] == kInvalid) id[root[c]] = kInvalid;
    }
    // Provisional ids in root order (a wedge's root comes before its other corners), and the
    // corners of each free wedge (CSR, in corner order).
    uint32_t free_count = 0, pinned = 0;
    std::vector<uint32_t> start(1, 0), members;
    for (uint32_t c = 0; c < corners; ++c) {
      uint32_t w = kInvalid;
      if (root[c] != c) {
        w = id[root[c]];
      } else if (id[c] == kFree) {
        w = free_count++;
        start.push_back(0);
      } else {
        ++pinned;
      }
      id[c] = w;
      if (w != kInvalid) ++start[w + 1];
    }
    for (size_t w = 0; w < free_count; ++w) start[w + 1] += start[w];
    reserve_huge(members, start[free_count]);
    members.resize(start[free_count]);
    {
      std::vector<uint32_t> fill(start.begin(), start.end() - 1);
      for (uint32_t c = 0; c < corners; ++c)
        if (id[c] != kInvalid) members[fill[id[c]]++] = c;
    }
    // Colours, greedily in provisional id order: the lowest that no free wedge sharing a face has.
    std::vector<uint32_t> colour(free_count, kInvalid), taken;  // taken: per colour, the last wedge it was taken for
    uint32_t colours = 0;
    for (uint32_t w = 0; w < free_count; ++w) {
      for (uint32_t m = start[w]; m < start[w + 1]; ++m) {
        const uint32_t f = members[m] / 3;
        for (uint32_t k = 0; k < 3; ++k) {
          const uint32_t other = id[3 * f + k];
          if (other != kInvalid && other != w && colour[other] != kInvalid) taken[colour[other]] = w;
        }
      }
      uint32_t c = 0;
      while (c < colours && taken[c] == w) ++c;
      if (c == colours) {
        ++colours;
        taken.push_back(kInvalid);
      }
      colour[w] = c;
    }
    members = {};
    // Final wedge ids: the free ones by colour, then provisional id; then the pinned ones.
    colour_start_.assign(size_t{colours} + 1, 0);
    for (uint32_t w = 0; w < free_count; ++w) ++colour_start_[colour[w] + 1];
    for (size_t c = 0; c < colours; ++c) colour_start_[c + 1] += colour_start_[c];
    std::vector<uint32_t> final_id(free_count);
    {
      std::vector<uint32_t> fill(colour_start_.begin(), colour_start_.end() - 1);
      for (uint32_t w = 0; w < free_count; ++w) final_id[w] = fill[colour[w]]++;
    }
    free_count_ = free_count;
    // Final ids (a wedge's root comes before its other corners) and positions.
    uint32_t wedges = free_count;
    pos_.resize(2 * (size_t{free_count} + pinned));
    for (uint32_t c = 0; c < corners; ++c) {
      if (id[c] != kInvalid) {
        id[c] = final_id[id[c]];
      } else if (root[c] == c) {
        id[c] = wedges++;
      } else {
        id[c] = id[root[c]];
        continue;
      }
      pos_[2 * size_t{id[c]}] = uv_[2 * size_t{c}];
      pos_[2 * size_t{id[c]} + 1] = uv_[2 * size_t{c} + 1];
    }
    const std::vector<uint32_t> corner_wedge = std::move(id);
    root.reset();
    // The active faces (with a free corner), their frames and the terms. Each corner of an active
    // face on a pinned wedge gets a term of its own after the free wedges' (a sink: the local step
    // writes every corner's term, nothing reads these).
    term_start_.assign(size_t{free_count} + 1, 0);
    size_t sinks = 0;
    for (uint32_t f = 0; f < face_count; ++f) {
      const uint32_t* const w = &corner_wedge[3 * size_t{f}];
      const size_t free_corners = (w[0] < free_count) + (w[1] < free_count) + (w[2] < free_count);
      if (free_corners == 0) continue;
      active_.push_back(f);
      sinks += 3 - free_corners;
      for (uint32_t k = 0; k < 3; ++k)
        if (w[k] < free_count) ++term_start_[w[k] + 1];
    }
    const size_t n = active_.size();
    for (size_t w = 0; w < free_count; ++w) term_start_[w + 1] += term_start_[w];
    terms_ = huge_uninitialized<Term>(term_start_[free_count] + sinks);
    uint32_t sink = term_start_[free_count];
    face_ = huge_uninitialized<float>(kFaceFields * n);
    corner_pos_ = huge_uninitialized<uint32_t>(3 * n);
    slot_ = huge_uninitialized<uint32_t>(3 * n);
    slack_ = huge_uninitialized<float>(n);
    std::vector<uint32_t> fill(term_start_.begin(), term_start_.end() - 1);
    float* const field = face_.get();
    for (size_t i = 0; i < n; ++i) {  // in face order: the frames are read in order, each wedge's terms in corner order
      const uint32_t f = active_[i];
      const StretchFrame q = stretch_frame(local + 6 * size_t{f}, scale_);
      // The frame's corners are 0, q1, q2 (pixels); per corner j the dot product of its edges,
      // times 2 / det^2: the cotangent of its angle over the face's area.
      const float per_area = 2.f * q.inv * q.inv;
      const float e12x = q.q2x - q.q1x, e12y = q.q2y - q.q1y;
      const float w[3] = {per_area * (q.q1x * q.q2x + q.q1y * q.q2y), per_area * -(e12x * q.q1x + e12y * q.q1y),
                          per_area * (e12x * q.q2x + e12y * q.q2y)};
      // 1 / the height over corner k: the opposite edge's length over twice the area.
      const float inv_height[3] = {std::sqrt(e12x * e12x + e12y * e12y) * q.inv,
                                   std::sqrt(q.q2x * q.q2x + q.q2y * q.q2y) * q.inv,
                                   std::sqrt(q.q1x * q.q1x + q.q1y * q.q1y) * q.inv};
      const float condition = (q.q1x * q.q1x + q.q1y * q.q1y + q.q2x * q.q2x + q.q2y * q.q2y) * q.inv;
      const float values[kFaceFields] = {
          q.q1x, q.q1y, q.q2x, q.q2y, q.inv, w[0], w[1], w[2], kSlackMargin + kRoundingPerCondition * condition};
      for (size_t j = 0; j < kFaceFields; ++j) field[j * n + i] = values[j];
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t wedge = corner_wedge[3 * f + k];
        corner_pos_[3 * i + k] = 2 * wedge;
        if (wedge >= free_count) {
          slot_[3 * i + k] = sink++;
          continue;
        }
        const uint32_t slot = slot_[3 * i + k] = fill[wedge]++;
        terms_[slot] = Term{0.f,
                            0.f,
                            0.f,
                            0.f,
                            2 * corner_wedge[3 * f + static_cast<uint32_t>(kNext[k])],
                            2 * corner_wedge[3 * f + static_cast<uint32_t>(kPrev[k])],
                            static_cast<uint32_t>(i),
                            inv_height[k]};
      }
    }
  }

  // threads iterations at most, on `threads` threads (each phase's work is claimed in fixed
  // chunks, and a barrier separates the phases: the result does not depend on the count).
  // Returns the moves taken.
  uint64_t run(uint32_t iterations, size_t threads, const ProgressCallback& progress) {
    const uint32_t phases = static_cast<uint32_t>(colour_start_.size());  // the local step, then each colour
    std::atomic<size_t> next_chunk{0};
    uint32_t phase = 0, iteration = 0;
    bool done = iterations == 0 || free_count_ == 0;
    std::vector<float> largest(threads, 0.f);  // per thread: its largest move in this iteration
    std::vector<uint64_t> moves(threads, 0);
    // Run by the last thread to arrive at the end of a phase, before any goes on.
    const auto phase_done = [&]() noexcept {
      next_chunk.store(0, std::memory_order_relaxed);
      if (++phase < phases) return;
      phase = 0;
      const float moved = *std::max_element(largest.begin(), largest.end());
      std::fill(largest.begin(), largest.end(), 0.f);
      done = ++iteration == iterations || moved < kPatchSettledPx;
      if (!done && progress) {  // on one thread at a time (the barrier's completion)
        bool go = true;
        try {
          go = progress(static_cast<float>(iteration) / static_cast<float>(iterations));
        } catch (...) {
          go = false;
        }
        cancelled_ = !go;
        done = !go;
      }
    };
    std::barrier sync(static_cast<std::ptrdiff_t>(threads), phase_done);
    const auto work = [&](size_t t) {
      while (!done) {
        const bool local_step = phase == 0;
        const size_t first = local_step ? 0 : colour_start_[phase - 1];
        const size_t count = local_step ? active_.size() : colour_start_[phase] - first;
        const size_t chunk = local_step ? kFacesPerChunk : kWedgesPerChunk;
        for (size_t i; (i = next_chunk.fetch_add(1, std::memory_order_relaxed) * chunk) < count;) {
          const size_t end = std::min(count, i + chunk);
          if (local_step)
            fit(i, end);
          else
            largest[t] = std::max(largest[t], sweep(first + i, first + end, moves[t]));
        }
        sync.arrive_and_wait();
      }
    };
    std::vector<std::thread> helpers;
    helpers.reserve(threads - 1);
    for (size_t t = 1; t < threads; ++t) {
      try {
        helpers.emplace_back(work, t);
      } catch (const std::system_error&) {
        // No thread to be had: the barrier stops waiting for it (same result, fewer threads).
        for (size_t missing = t; missing < threads; ++missing) sync.arrive_and_drop();
        break;
      }
    }
    work(0);
    for (std::thread& h : helpers) h.join();
    uint64_t total = 0;
    for (const uint64_t m : moves) total += m;
    return total;
  }

  bool cancelled() const { return cancelled_; }

  // Writes the free wedges' positions to their corners (only active faces have free corners).
  void store() const {
    const uint32_t free_end = 2 * free_count_;
    for (size_t i = 0; i < active_.size(); ++i)
      for (size_t k = 0; k < 3; ++k) {
        const uint32_t p = corner_pos_[3 * i + k];
        if (p >= free_end) continue;
        const size_t c = 3 * size_t{active_[i]} + k;
        uv_[2 * c] = pos_[p];
        uv_[2 * c + 1] = pos_[p + 1];
      }
  }

 private:
  bool cancelled_ = false;  // the progress callback said stop
  // The corners at both ends of paired edge e (face f) and o (face g): e runs A -> B, o B -> A.
  struct Sides {
    uint32_t fa, fb, ga, gb;
  };
  static Sides sides(uint32_t e, uint32_t o) {
    const uint32_t f = e / 3, g = o / 3;
    return {e, 3 * f + static_cast<uint32_t>(kNext[e - 3 * f]), 3 * g + static_cast<uint32_t>(kNext[o - 3 * g]), o};
  }
  bool same_uv(uint32_t a, uint32_t b) const {
    return uv_[2 * size_t{a}] == uv_[2 * size_t{b}] && uv_[2 * size_t{a} + 1] == uv_[2 * size_t{b} + 1];
  }
  float gap(uint32_t a, uint32_t b) const {
    return std::hypot(uv_[2 * size_t{a}] - uv_[2 * size_t{b}], uv_[2 * size_t{a} + 1] - uv_[2 * size_t{b} + 1]);
  }

  // Local step for active faces [first, last): per face its slack, how far its singular values
  // may move before one leaves [1/(1+bound), 1+bound], and its corners' terms: its weight m and
  // the rotation R nearest to its Jacobian J. With J = [a b; c d] (times the frame's inverse
  // determinant), R turns by atan2(c - b, a + d) and the singular values are |q| +- |r|, q and r
  // its conformal and anti-conformal parts (face_stretch.h); m = 1 / max(|J - R|, kIrlsFloor)
  // with |J - R| measured as sqrt((|q| - 1)^2 + |r|^2) (the Frobenius norm over sqrt 2). Four
  // faces at a time with SSE2, the scalar operations lane by lane (same bits as fit_face).
  TAILOR_AVX_CLONES void fit(size_t first, size_t last) {
    size_t i = first;
#if TAILOR_SSE2
    const size_t n = active_.size();
    const float* const field = face_.get();
    const float* const pos = pos_.data();
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f), half = _mm_set1_ps(0.5f);
    const __m128 high = _mm_set1_ps(high_), low = _mm_set1_ps(low_), floor = _mm_set1_ps(kIrlsFloor);
    // Locals, not members: a vector store may alias anything, the members would be read again.
    const uint32_t* const corner_pos = corner_pos_.get();
    const uint32_t* const slot = slot_.get();
    Term* const terms = terms_.get();
    float* const slack_out = slack_.get();
    const __m128 sign = _mm_set1_ps(-0.f), minus_inf = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    for (; i + 4 <= last; i += 4) {
      __m128 u1x, u1y, u2x, u2y;
      load_edges4(pos, corner_pos + 3 * i, u1x, u1y, u2x, u2y);
      const __m128 q1x = _mm_loadu_ps(field + kQ1x * n + i), q1y = _mm_loadu_ps(field + kQ1y * n + i);
      const __m128 q2x = _mm_loadu_ps(field + kQ2x * n + i), q2y = _mm_loadu_ps(field + kQ2y * n + i);
      const __m128 a = _mm_sub_ps(_mm_mul_ps(u1x, q2y), _mm_mul_ps(u2x, q1y));
      const __m128 b = _mm_sub_ps(_mm_mul_ps(u2x, q1x), _mm_mul_ps(u1x, q2x));
      const __m128 c = _mm_sub_ps(_mm_mul_ps(u1y, q2y), _mm_mul_ps(u2y, q1y));
      const __m128 d = _mm_sub_ps(_mm_mul_ps(u2y, q1x), _mm_mul_ps(u1y, q2x));
      const __m128 h = _mm_mul_ps(half, _mm_loadu_ps(field + kInv * n + i));
      const __m128 x = _mm_mul_ps(_mm_add_ps(a, d), h), y = _mm_mul_ps(_mm_sub_ps(c, b), h);
      const __m128 fx = _mm_sub_ps(a, d), fy = _mm_add_ps(c, b);
      const __m128 qn = _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)));
      const __m128 rn = _mm_mul_ps(_mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(fx, fx), _mm_mul_ps(fy, fy))), h);
      // std::min(p, q) is _mm_min_ps(q, p) and std::max(p, q) is _mm_max_ps(q, p): the same
      // operand on ties and NaN.
      const __m128 slack =
          _mm_sub_ps(_mm_min_ps(_mm_sub_ps(_mm_sub_ps(qn, rn), low), _mm_sub_ps(high, _mm_add_ps(qn, rn))),
                     _mm_loadu_ps(field + kMargin * n + i));
      _mm_storeu_ps(slack_out + i, _mm_max_ps(slack, minus_inf));
      const __m128 qm = _mm_sub_ps(qn, one);
      const __m128 residual = _mm_max_ps(floor, _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(qm, qm), _mm_mul_ps(rn, rn))));
      const __m128 turned = _mm_cmpgt_ps(qn, zero);
      const __m128 inv = _mm_div_ps(one, blend(turned, _mm_mul_ps(qn, residual), residual));
      const __m128 mc = blend(turned, _mm_mul_ps(x, inv), inv), ms = blend(turned, _mm_mul_ps(y, inv), zero);
      const __m128 m = blend(turned, _mm_mul_ps(qn, inv), inv);
      const __m128 w0 = _mm_loadu_ps(field + kW0 * n + i), w1 = _mm_loadu_ps(field + kW1 * n + i);
      const __m128 w2 = _mm_loadu_ps(field + kW2 * n + i);
      const __m128 ex = _mm_sub_ps(q1x, q2x), ey = _mm_sub_ps(q1y, q2y);
      const __m128 nq1x = _mm_xor_ps(q1x, sign), nq1y = _mm_xor_ps(q1y, sign);
      const __m128 nq2x = _mm_xor_ps(q2x, sign), nq2y = _mm_xor_ps(q2y, sign);
      const __m128 nex = _mm_xor_ps(ex, sign), ney = _mm_xor_ps(ey, sign);
      // Per corner k: wn, wp and d = wn (x_k - x_next) + wp (x_k - x_prev).
      const __m128 corner[3][4] = {{w2, w1, _mm_add_ps(_mm_mul_ps(w2, nq1x), _mm_mul_ps(w1, nq2x)),
                                    _mm_add_ps(_mm_mul_ps(w2, nq1y), _mm_mul_ps(w1, nq2y))},
                                   {w0, w2, _mm_add_ps(_mm_mul_ps(w0, ex), _mm_mul_ps(w2, q1x)),
                                    _mm_add_ps(_mm_mul_ps(w0, ey), _mm_mul_ps(w2, q1y))},
                                   {w1, w0, _mm_add_ps(_mm_mul_ps(w1, q2x), _mm_mul_ps(w0, nex)),
                                    _mm_add_ps(_mm_mul_ps(w1, q2y), _mm_mul_ps(w0, ney))}};
      for (size_t k = 0; k < 3; ++k) {
        const __m128 dx = corner[k][2], dy = corner[k][3];
        __m128 r0 = _mm_mul_ps(m, corner[k][0]), r1 = _mm_mul_ps(m, corner[k][1]);
        __m128 r2 = _mm_sub_ps(_mm_mul_ps(mc, dx), _mm_mul_ps(ms, dy));
        __m128 r3 = _mm_add_ps(_mm_mul_ps(ms, dx), _mm_mul_ps(mc, dy));
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        const __m128 record[4] = {r0, r1, r2, r3};
        for (size_t j = 0; j < 4; ++j) _mm_store_ps(&terms[slot[3 * (i + j) + k]].mwn, record[j]);
      }
    }
#endif
    for (; i < last; ++i) fit_face(i);
  }

  // fit for active face i alone (the scalar path, and the SIMD loop's scalar twin).
  void fit_face(size_t i) {
    const size_t n = active_.size();
    const float* const field = face_.get();
    const float* const p0 = &pos_[corner_pos_[3 * i]];
    const float* const p1 = &pos_[corner_pos_[3 * i + 1]];
    const float* const p2 = &pos_[corner_pos_[3 * i + 2]];
    const float u1x = p1[0] - p0[0], u1y = p1[1] - p0[1];
    const float u2x = p2[0] - p0[0], u2y = p2[1] - p0[1];
    const float q1x = field[kQ1x * n + i], q1y = field[kQ1y * n + i];
    const float q2x = field[kQ2x * n + i], q2y = field[kQ2y * n + i];
    const float a = u1x * q2y - u2x * q1y, b = u2x * q1x - u1x * q2x;
    const float c = u1y * q2y - u2y * q1y, d = u2y * q1x - u1y * q2x;
    const float h = 0.5f * field[kInv * n + i];
    const float x = (a + d) * h, y = (c - b) * h;
    const float fx = a - d, fy = c + b;
    const float qn = std::sqrt(x * x + y * y), rn = std::sqrt(fx * fx + fy * fy) * h;
    // Never NaN (-inf instead: every move of the face is checked), so that a wedge's least slack
    // (move) is that of one of its faces.
    const float slack = std::min(high_ - (qn + rn), (qn - rn) - low_) - field[kMargin * n + i];
    slack_[i] = std::max(-std::numeric_limits<float>::infinity(), slack);
    const float qm = qn - 1.f;
    const float residual = std::max(std::sqrt(qm * qm + rn * rn), kIrlsFloor);
    float mc, ms, m;  // m R: its columns (mc, ms) and (-ms, mc)
    if (qn > 0.f) {
      const float inv = 1.f / (qn * residual);
      mc = x * inv;
      ms = y * inv;
      m = qn * inv;
    } else {
      mc = m = 1.f / residual;
      ms = 0.f;
    }
    const float w0 = field[kW0 * n + i], w1 = field[kW1 * n + i], w2 = field[kW2 * n + i];
    const float ex = q1x - q2x, ey = q1y - q2y;
    const float corner[3][4] = {{w2, w1, w2 * -q1x + w1 * -q2x, w2 * -q1y + w1 * -q2y},
                                {w0, w2, w0 * ex + w2 * q1x, w0 * ey + w2 * q1y},
                                {w1, w0, w1 * q2x + w0 * -ex, w1 * q2y + w0 * -ey}};
    for (size_t k = 0; k < 3; ++k) {
      const float dx = corner[k][2], dy = corner[k][3];
      Term& t = terms_[slot_[3 * i + k]];
      t.mwn = m * corner[k][0];
      t.mwp = m * corner[k][1];
      t.tx = mc * dx - ms * dy;
      t.ty = ms * dx + mc * dy;
    }
  }

  // Global step for free wedges [first, last) of one colour: returns the largest move, adds the
  // moves taken to `moves`.
  TAILOR_AVX_CLONES float sweep(size_t first, size_t last, uint64_t& moves) {
    float largest = 0.f;
    uint64_t taken = 0;
    for (size_t w = first; w < last; ++w) {
      const float m = move(w);
      taken += m > 0.f;
      largest = std::max(largest, m);
    }
    moves += taken;
    return largest;
  }

  // Global step for free wedge w: returns how far it moved (|du| + |dv|; 0: it did not).
  float move(size_t w) {
    const Term* const begin = &terms_[term_start_[w]];
    const Term* const end = &terms_[term_start_[w + 1]];
    const float* const pos = pos_.data();
    float* const at = &pos_[2 * w];
    const float u0 = at[0], v0 = at[1];
    // The sums of mwn p_next, mwp p_prev, the weights and (tx, ty) apart, then added; the least
    // slack and the largest inverse height of the faces around.
    const float* const slack = slack_.get();
    float u, v, lowest = std::numeric_limits<float>::infinity(), widest = 0.f;
#if TAILOR_SSE2
    // u and v side by side, the scalar operations lane by lane (same bits): pairs holds the sums
    // of mwn p_next and mwp p_prev, records those of mwn, mwp, tx, ty.
    __m128 pairs = _mm_setzero_ps(), records = _mm_setzero_ps();
    for (const Term* t = begin; t != end; ++t) {
      lowest = std::min(lowest, slack[t->face]);
      widest = std::max(widest, t->inv_height);
      const __m128 r = _mm_load_ps(&t->mwn);
      const __m128 p = _mm_movelh_ps(load_pair(pos + t->next), load_pair(pos + t->prev));
      pairs = _mm_add_ps(pairs, _mm_mul_ps(_mm_unpacklo_ps(r, r), p));
      records = _mm_add_ps(records, r);
    }
    const __m128 sum = _mm_add_ps(_mm_add_ps(pairs, _mm_movehl_ps(pairs, pairs)), _mm_movehl_ps(records, records));
    const __m128 weight = _mm_add_ss(records, _mm_shuffle_ps(records, records, 1));
    const __m128 p0 = load_pair(at);
    const __m128 target = _mm_div_ps(sum, _mm_shuffle_ps(weight, weight, 0));
    const __m128 moved = _mm_add_ps(p0, _mm_mul_ps(_mm_set1_ps(kPatchOverRelaxation), _mm_sub_ps(target, p0)));
    u = _mm_cvtss_f32(moved);
    v = _mm_cvtss_f32(_mm_shuffle_ps(moved, moved, 1));
#else
    float nu = 0.f, nv = 0.f, pu = 0.f, pv = 0.f, wn = 0.f, wp = 0.f, tu = 0.f, tv = 0.f;
    for (const Term* t = begin; t != end; ++t) {
      lowest = std::min(lowest, slack[t->face]);
      widest = std::max(widest, t->inv_height);
      const float* a = pos + t->next;
      const float* b = pos + t->prev;
      nu += t->mwn * a[0];
      nv += t->mwn * a[1];
      pu += t->mwp * b[0];
      pv += t->mwp * b[1];
      wn += t->mwn;
      wp += t->mwp;
      tu += t->tx;
      tv += t->ty;
    }
    const float sw = wn + wp;
    u = u0 + kPatchOverRelaxation * (((nu + pu) + tu) / sw - u0);
    v = v0 + kPatchOverRelaxation * (((nv + pv) + tv) / sw - v0);
#endif
    if ((u == u0 && v == v0) || !fits(w, begin, end, u, v, u0, v0, lowest, widest)) return 0.f;
    at[0] = u;
    at[1] = v;
    return std::abs(u - u0) + std::abs(v - v0);
  }

  // Whether every face around a free wedge (its terms) stays within the bound with the wedge moved
  // from (u0, v0) to (u, v); if so, takes the move off their slack. lowest, widest: the least slack
  // and the largest inverse height of those faces (when the move times widest is within lowest,
  // it is within each face's slack: a float product does not decrease with a factor).
  bool fits(size_t w, const Term* begin, const Term* end, float u, float v, float u0, float v0, float lowest,
            float widest) {
    float* const slack = slack_.get();
    const float distance = std::sqrt((u - u0) * (u - u0) + (v - v0) * (v - v0));
    if (!(distance * widest <= lowest))
      for (const Term* t = begin; t != end; ++t)  // within the bound by the slack, else checked
        if (!(distance * t->inv_height <= slack[t->face]) && !within_bound(*t, w, u, v)) return false;
    for (const Term* t = begin; t != end; ++t) slack[t->face] -= distance * t->inv_height;
    return true;
  }

  // Whether term t's face stays within the bound with its corner on free wedge w moved to (u, v)
  // (stretch_error).
  [[gnu::noinline]] bool within_bound(const Term& t, size_t w, float u, float v) const {
    const float* const pos = pos_.data();
    const uint32_t i = t.face;
    uint32_t k = 0;
    while (corner_pos_[3 * size_t{i} + k] != 2 * w) ++k;
    const uint32_t n = static_cast<uint32_t>(kNext[k]), p = static_cast<uint32_t>(kPrev[k]);
    float uv[6];
    uv[2 * k] = u;
    uv[2 * k + 1] = v;
    uv[2 * n] = pos[t.next];
    uv[2 * n + 1] = pos[t.next + 1];
    uv[2 * p] = pos[t.prev];
    uv[2 * p + 1] = pos[t.prev + 1];
    const size_t count = active_.size();
    const float* const field = face_.get();
    StretchFrame frame;
    frame.q1x = field[kQ1x * count + i];
    frame.q1y = field[kQ1y * count + i];
    frame.q2x = field[kQ2x * count + i];
    frame.q2y = field[kQ2y * count + i];
    frame.inv = field[kInv * count + i];
    frame.valid = frame.inv > 0.f;  // stretch_frame leaves inv 0 when not valid
    return stretch_error(frame, uv) <= bound_;
  }

  const MappingInput& in_;
  float* const uv_;
  MetricsOptions lattice_;  // the texture period, for the lattice gap of seams (metrics.h)
  const float scale_, bound_;
  const float high_, low_;  // the singular values' bounds
  uint32_t free_count_ = 0;
  // Per wedge its UV (free wedges 0..free_count_ - 1 by colour, then the pinned ones); per colour
  // its first free wedge; per free wedge its first term.
  std::vector<uint32_t> colour_start_, term_start_;
  std::vector<float> pos_;
  HugeArray<Term> terms_;
  // The active faces (with a free corner); per active face its fields (kFaceFields blocks), per
  // corner its wedge's offset in pos_ and its term (a sink for a pinned wedge), its slack.
  std::vector<uint32_t> active_;
  HugeArray<float> face_;
  HugeArray<uint32_t> corner_pos_, slot_;
  HugeArray<float> slack_;
};

}  // namespace

Status relax_patches(const MappingInput& input, Atlas& atlas, uint64_t& moves, const ProgressCallback& progress) {
  moves = 0;
  if (input.options.relax_iterations == 0) return Status::ok();
  const Status cancelled = Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
  if (progress && !progress(0.f)) return cancelled;
  Relaxer relaxer(input, atlas);
  relaxer.build();
  moves = relaxer.run(input.options.relax_iterations,
                      parallel_threads(input.mesh.face_count(), input.options.threads, kFacesPerRelaxThread), progress);
  if (relaxer.cancelled()) return cancelled;
  relaxer.store();
  if (progress && !progress(1.f)) return cancelled;
  return Status::ok();
}

}  // namespace tailor::internal
