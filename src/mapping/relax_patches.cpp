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
// Cost: O(F) setup (wedges, colouring, per-corner terms; sequential), then O(F) per iteration,
// parallel over faces (local step) and over the wedges of each colour (global step); no global
// solve. Memory: ~50 bytes per corner (horse_x16: 170 MB more at the peak).
//
// This work is based on:
//   L. Liu, L. Zhang, Y. Xu, C. Gotsman, S. J. Gortler, "A local/global approach to mesh
//   parameterization", SGP 2008.
#include <algorithm>
#include <atomic>
#include <barrier>
#include <cmath>
#include <system_error>
#include <thread>
#include <vector>

#include "mapping/face_stretch.h"
#include "mapping/mapping_common.h"
#include "tailor/metrics.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"

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

// Per corner of a free wedge: what its prediction and its check need. The terms of a wedge are
// contiguous, and the wedges of a colour too, so a sweep streams through them.
struct Term {
  uint32_t corner;      // corner id (3 f + k)
  uint32_t next, prev;  // the wedges of the face's corners k + 1 and k + 2
  float wn, wp;         // the weights of the predictions from the next and the previous corner
  float dx, dy;         // wn (x_k - x_next) + wp (x_k - x_prev), face frame, pixels
  float inv_height;     // 1 / the face's height over corner k, 1/pixels
};

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

  // Wedges, the free ones' colours and terms, per face its frame.
  void build() {
    const size_t face_count = in_.mesh.face_count();
    const uint32_t corners = static_cast<uint32_t>(3 * face_count);
    const uint32_t* const opposite = in_.topology.opposite.data();
    const float* const local = in_.frames.local.data();
    // Wedges: union-find over every paired edge whose two faces agree on the shared corner's UV;
    // a root is its wedge's lowest corner.
    std::vector<uint32_t> root;
    reserve_huge(root, corners);
    root.resize(corners);
    for (uint32_t c = 0; c < corners; ++c) root[c] = c;
    const auto find = [&root](uint32_t c) {
      while (root[c] != c) c = root[c] = root[root[c]];
      return c;
    };
    for (uint32_t e = 0; e < corners; ++e) {
      const uint32_t o = opposite[e];
      if (o == kInvalid || o < e) continue;
      const Sides s = sides(e, o);
      for (const auto& [x, y] : {std::pair{s.fa, s.ga}, std::pair{s.fb, s.gb}}) {
        if (!same_uv(x, y)) continue;
        const uint32_t rx = find(x), ry = find(y);
        if (rx != ry) root[std::max(rx, ry)] = std::min(rx, ry);
      }
    }
    for (uint32_t c = 0; c < corners; ++c) root[c] = find(c);
    // id: per root, kInvalid when pinned, else (below) its free wedge's provisional id. Pinned: both
    // sides at both ends of an invisible seam, and the corners of zero-area faces.
    constexpr uint32_t kFree = 0;
    std::vector<uint32_t> id;
    reserve_huge(id, corners);
    id.assign(corners, kFree);
    for (uint32_t e = 0; e < corners; ++e) {
      const uint32_t o = opposite[e];
      if (o == kInvalid || o < e) continue;
      const Sides s = sides(e, o);
      if (root[s.fa] == root[s.ga] && root[s.fb] == root[s.gb]) continue;  // seamless
      const bool narrow = gap(s.fa, s.ga) < kInvisibleGapPx && gap(s.fb, s.gb) < kInvisibleGapPx;
      if (!narrow && !(seam_gap_px(&uv_[2 * size_t{s.fa}], &uv_[2 * size_t{s.fb}], &uv_[2 * size_t{s.ga}],
                                   &uv_[2 * size_t{s.gb}], lattice_) < kInvisibleGapPx))
        continue;
      for (const uint32_t c : {s.fa, s.fb, s.ga, s.gb}) id[root[c]] = kInvalid;
    }
    for (size_t f = 0; f < face_count; ++f)
      if (is_zero_area_frame(local + 6 * f))
        for (size_t k = 0; k < 3; ++k) id[root[3 * f + k]] = kInvalid;
    uint32_t free_count = 0;
    for (uint32_t c = 0; c < corners; ++c)
      if (root[c] == c && id[c] == kFree) id[c] = free_count++;
    for (uint32_t c = 0; c < corners; ++c) id[c] = root[c] == c ? id[c] : id[root[c]];
    // The corners of each free wedge (CSR, in corner order).
    std::vector<uint32_t> start(size_t{free_count} + 1, 0), members;
    for (uint32_t c = 0; c < corners; ++c)
      if (id[c] != kInvalid) ++start[id[c] + 1];
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
    uint32_t wedges = free_count;
    for (uint32_t c = 0; c < corners; ++c) {  // a wedge's root comes before its other corners
      if (id[c] != kInvalid)
        id[c] = final_id[id[c]];
      else
        id[c] = root[c] == c ? wedges++ : id[root[c]];
    }
    corner_wedge_.swap(id);
    root = {};
    // Positions, faces with a free corner, their frames and the terms.
    pos_.resize(2 * size_t{wedges});
    for (uint32_t c = 0; c < corners; ++c) {
      pos_[2 * size_t{corner_wedge_[c]}] = uv_[2 * size_t{c}];
      pos_[2 * size_t{corner_wedge_[c]} + 1] = uv_[2 * size_t{c} + 1];
    }
    for (uint32_t f = 0; f < face_count; ++f)
      if (corner_wedge_[3 * f] < free_count || corner_wedge_[3 * f + 1] < free_count ||
          corner_wedge_[3 * f + 2] < free_count)
        active_.push_back(f);
    frame_.resize(face_count);
    record_.resize(3 * face_count);
    slack_.resize(face_count);
    margin_.resize(face_count);
    for (const uint32_t f : active_) {
      const StretchFrame& q = frame_[f] = stretch_frame(local + 6 * size_t{f}, scale_);
      const float condition = (q.q1x * q.q1x + q.q1y * q.q1y + q.q2x * q.q2x + q.q2y * q.q2y) * q.inv;
      margin_[f] = kSlackMargin + kRoundingPerCondition * condition;
    }
    term_start_.assign(size_t{free_count} + 1, 0);
    for (uint32_t c = 0; c < corners; ++c)
      if (corner_wedge_[c] < free_count) ++term_start_[corner_wedge_[c] + 1];
    for (size_t w = 0; w < free_count; ++w) term_start_[w + 1] += term_start_[w];
    reserve_huge(terms_, term_start_[free_count]);
    terms_.resize(term_start_[free_count]);
    std::vector<uint32_t> fill(term_start_.begin(), term_start_.end() - 1);
    for (uint32_t c = 0; c < corners; ++c)  // in corner order: the frames are read in order
      if (corner_wedge_[c] < free_count) terms_[fill[corner_wedge_[c]]++] = term(c, local + 6 * size_t{c / 3});
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
          if (local_step) {
            for (; i < end; ++i) fit(active_[i]);
          } else {
            for (; i < end; ++i) {
              const float m = move(static_cast<uint32_t>(first + i));
              moves[t] += m > 0.f;
              largest[t] = std::max(largest[t], m);
            }
          }
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

  // Writes the free wedges' positions to their corners.
  void store() const {
    const size_t corners = corner_wedge_.size();
    for (size_t c = 0; c < corners; ++c) {
      const uint32_t w = corner_wedge_[c];
      if (w >= free_count_) continue;
      uv_[2 * c] = pos_[2 * size_t{w}];
      uv_[2 * c + 1] = pos_[2 * size_t{w} + 1];
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

  // The term of corner c (of a free wedge) of the face whose frame corners are l (6 floats).
  Term term(uint32_t c, const float* l) const {
    const uint32_t f = c / 3;
    const int k = static_cast<int>(c - 3 * f), n = kNext[k], p = kPrev[k];
    const float inv_twice = 1.f / ((l[2] - l[0]) * (l[5] - l[1]) - (l[4] - l[0]) * (l[3] - l[1]));
    // Cotangent weights (the edge k-next is opposite corner prev, k-prev opposite next: cot = the
    // dot product of the edges at that corner over twice the area) over the area in pixels.
    const auto dot = [&](int j) {
      const int a = kNext[j], b = kPrev[j];
      const float ax = l[2 * a] - l[2 * j], ay = l[2 * a + 1] - l[2 * j + 1];
      const float bx = l[2 * b] - l[2 * j], by = l[2 * b + 1] - l[2 * j + 1];
      return ax * bx + ay * by;
    };
    const float per_area = 2.f * inv_twice * inv_twice / (scale_ * scale_);
    const float wn = per_area * dot(p), wp = per_area * dot(n);
    const float dx = (wn * (l[2 * k] - l[2 * n]) + wp * (l[2 * k] - l[2 * p])) * scale_;
    const float dy = (wn * (l[2 * k + 1] - l[2 * n + 1]) + wp * (l[2 * k + 1] - l[2 * p + 1])) * scale_;
    const float ox = l[2 * p] - l[2 * n], oy = l[2 * p + 1] - l[2 * n + 1];
    const float inv_height = std::sqrt(ox * ox + oy * oy) * inv_twice / scale_;
    return Term{c,
                corner_wedge_[3 * f + static_cast<uint32_t>(n)],
                corner_wedge_[3 * f + static_cast<uint32_t>(p)],
                wn,
                wp,
                dx,
                dy,
                inv_height};
  }

  // Local step for face f: record_ gets its weight m and m times the rotation nearest to its
  // Jacobian J (columns (c, s) and (-s, c)); slack_ how far its singular values may move before one
  // leaves [1/(1+bound), 1+bound]. With J = [a b; c d] (times the frame's inverse determinant), the
  // rotation turns by atan2(c - b, a + d) and the singular values are |q| +- |r|, q and r its
  // conformal and anti-conformal parts (face_stretch.h); |J - R| is measured as
  // sqrt((|q| - 1)^2 + |r|^2) (the Frobenius norm over sqrt 2).
  void fit(uint32_t f) {
    const StretchFrame& s = frame_[f];
    const float* p0 = &pos_[2 * size_t{corner_wedge_[3 * size_t{f}]}];
    const float* p1 = &pos_[2 * size_t{corner_wedge_[3 * size_t{f} + 1]}];
    const float* p2 = &pos_[2 * size_t{corner_wedge_[3 * size_t{f} + 2]}];
    const float u1x = p1[0] - p0[0], u1y = p1[1] - p0[1];
    const float u2x = p2[0] - p0[0], u2y = p2[1] - p0[1];
    const float a = u1x * s.q2y - u2x * s.q1y, b = u2x * s.q1x - u1x * s.q2x;
    const float c = u1y * s.q2y - u2y * s.q1y, d = u2y * s.q1x - u1y * s.q2x;
    const float h = 0.5f * s.inv;
    const float x = (a + d) * h, y = (c - b) * h;
    const float qn = std::sqrt(x * x + y * y), rn = std::sqrt((a - d) * (a - d) + (c + b) * (c + b)) * h;
    slack_[f] = std::min(high_ - (qn + rn), (qn - rn) - low_) - margin_[f];
    const float residual = std::max(std::sqrt((qn - 1.f) * (qn - 1.f) + rn * rn), kIrlsFloor);
    float* r = &record_[3 * size_t{f}];
    if (qn > 0.f) {
      const float inv = 1.f / (qn * residual);  // m / qn
      r[0] = x * inv;
      r[1] = y * inv;
      r[2] = qn * inv;
    } else {
      r[0] = r[2] = 1.f / residual;
      r[1] = 0.f;
    }
  }

  // Global step for free wedge w: returns how far it moved (|du| + |dv|; 0: it did not).
  float move(uint32_t w) {
    const Term* const begin = terms_.data() + term_start_[w];
    const Term* const end = terms_.data() + term_start_[w + 1];
    const float* const pos = pos_.data();
    float su = 0.f, sv = 0.f, sw = 0.f;
    for (const Term* t = begin; t != end; ++t) {
      const float* a = pos + 2 * size_t{t->next};
      const float* b = pos + 2 * size_t{t->prev};
      const float* r = &record_[3 * size_t{t->corner / 3}];
      su += r[2] * (t->wn * a[0] + t->wp * b[0]) + (r[0] * t->dx - r[1] * t->dy);
      sv += r[2] * (t->wn * a[1] + t->wp * b[1]) + (r[1] * t->dx + r[0] * t->dy);
      sw += r[2] * (t->wn + t->wp);
    }
    float* const at = &pos_[2 * size_t{w}];
    const float u0 = at[0], v0 = at[1];
    const float u = u0 + kPatchOverRelaxation * (su / sw - u0), v = v0 + kPatchOverRelaxation * (sv / sw - v0);
    if ((u == u0 && v == v0) || !fits(begin, end, u, v, u0, v0)) return 0.f;
    at[0] = u;
    at[1] = v;
    return std::abs(u - u0) + std::abs(v - v0);
  }

  // Whether every face around a free wedge (its terms) stays within the bound with the wedge moved
  // from (u0, v0) to (u, v); if so, takes the move off their slack.
  bool fits(const Term* begin, const Term* end, float u, float v, float u0, float v0) {
    const float* const pos = pos_.data();
    const float distance = std::sqrt((u - u0) * (u - u0) + (v - v0) * (v - v0));
    for (const Term* t = begin; t != end; ++t) {
      const uint32_t f = t->corner / 3;
      if (distance * t->inv_height <= slack_[f]) continue;  // within the bound by the slack
      const uint32_t k = t->corner - 3 * f;
      const uint32_t n = static_cast<uint32_t>(kNext[k]), p = static_cast<uint32_t>(kPrev[k]);
      float uv[6];
      uv[2 * k] = u;
      uv[2 * k + 1] = v;
      uv[2 * n] = pos[2 * size_t{t->next}];
      uv[2 * n + 1] = pos[2 * size_t{t->next} + 1];
      uv[2 * p] = pos[2 * size_t{t->prev}];
      uv[2 * p + 1] = pos[2 * size_t{t->prev} + 1];
      if (!(stretch_error(frame_[f], uv) <= bound_)) return false;
    }
    for (const Term* t = begin; t != end; ++t) slack_[t->corner / 3] -= distance * t->inv_height;
    return true;
  }

  const MappingInput& in_;
  float* const uv_;
  MetricsOptions lattice_;  // the texture period, for the lattice gap of seams (metrics.h)
  const float scale_, bound_;
  const float high_, low_;  // the singular values' bounds
  uint32_t free_count_ = 0;
  // Per corner: its wedge (free wedges 0..free_count_ - 1 by colour, then the pinned ones); per
  // wedge its UV; per colour its first free wedge; per free wedge its first term.
  std::vector<uint32_t> corner_wedge_, colour_start_, term_start_;
  std::vector<float> pos_;
  std::vector<Term> terms_;
  // The faces with a free corner; per face its frame, record (3 floats, see fit), slack and the
  // margin kept off its slack.
  std::vector<uint32_t> active_;
  std::vector<StretchFrame> frame_;
  std::vector<float> record_, slack_, margin_;
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
