// Mapping mode "patches": per-corner UVs grown by unfolding, every face within a bound relative to
// its size, a new patch when the front is exhausted (see tailor/mapping.h and docs/mapping.md).
//
// This work is based on:
//   V. Singh, A. M. Namboodiri, "Efficient texture mapping by homogeneous patch discovery",
//   ICVGIP 2012 (thesis chapter 2): the front order and the two-prediction unfolding;
//   P. V. Sander, J. Snyder, S. J. Gortler, H. Hoppe, "Texture mapping progressive meshes",
//   SIGGRAPH 2001: the singular values of the face Jacobian as the per-face bound.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <span>

#include "mapping/face_stretch.h"
#include "mapping/front_buckets.h"
#include "mapping/mapping_common.h"
#include "util/huge_pages.h"
#include "util/simd.h"

namespace tailor::internal {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr uint32_t kAnyPatch = kInvalid;

// Everything the growth reads or writes about one face, in one cache line: the popped face's
// geometry and connectivity, and the state its neighbours' placements update. Reading these from
// nine separate arrays (topology, frames, atlas, scratch) cost a cache line per array per face
// touched; the records halve the L1 misses of try_place (cachegrind, bunny). The neighbours are
// kept as face ids and edge indices (Topology::opposite split once): every use needs one or the
// other, and the division by 3 took a few instructions at each of them.
struct alignas(64) FaceRecord {
  uint32_t neighbour[3];  // face across edge k (Topology::opposite / 3), kInvalid on a boundary
  uint32_t vertex[3];     // Mesh::indices
  float local[6];         // FaceFrames::local
  float variation;        // FaceFrames::variation
  uint32_t patch;         // kInvalid until placed
  uint8_t placed;         // placed edge neighbours (0..3)
  uint8_t front;          // 1 + bucket of the face's live front entry, 0 = not on the front
  uint8_t seam;           // user seam face
  uint8_t degenerate;     // no meaningful Jacobian (is_zero_area_frame)
  uint8_t across;         // bits 2k, 2k+1: the neighbour's index of the edge it shares with edge k
};
static_assert(sizeof(FaceRecord) == 64);

// Per vertex: the patch whose UV the hint holds, and that UV.
struct VertexHint {
  uint32_t patch;
  float u, v;  // contiguous: read as one UV
};

#if TAILOR_SSE2
// Two floats (a UV or a frame corner) into the low lanes.
inline __m128 load_uv(const float* p) { return _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))); }
#endif

struct Rotation {
  float c = 1.f, s = 0.f;
  float angle() const { return std::atan2(s, c); }
};

class PatchMapper {
 public:
  PatchMapper(const MappingInput& in, Atlas& atlas, MappingStats& stats, std::vector<uint8_t>& seam_mark)
      : in_(in), stats_(stats), atlas_(atlas), seam_mark_(seam_mark) {}

  Status run() {
    const Mesh& mesh = in_.mesh;
    const size_t face_count = mesh.face_count();
    prepare();

    // Fresh multi-megabyte arrays: on huge pages (see huge_pages.h).
    reserve_huge(atlas_.corner_uv, 6 * face_count);
    atlas_.corner_uv.assign(6 * face_count, 0.f);
    uv_ = atlas_.corner_uv.data();
    fill_records();
    reserve_huge(hint_, mesh.vertex_count());
    hint_.assign(mesh.vertex_count(), VertexHint{kInvalid, 0.f, 0.f});
    // Not initialised: a face's entry is written when it is placed, and only placed faces' are read.
    if (hop_age_ > 0.f) hops_.reset(new uint32_t[face_count]);

    // === Grow: one component at a time, patches one after another ===
    FaceRecord* rec = rec_.get();
    for (const uint32_t seed : in_.component_seeds) {
      if (rec[seed].patch != kInvalid) continue;
      current_ = start_patch(seed);
      TAILOR_RETURN_IF_ERROR(grow(false));
    }
    if (cancelled_) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
    stats_.patches_before_absorb = static_cast<uint32_t>(patch_size_.size());
    absorb_small_patches();
    renumber_patches();
    return Status::ok();
  }

  // Grows the faces flagged in `region` again, every other face keeping its UVs and patch (see
  // regrow_patches in mapping_common.h).
  Status run_region(std::span<const uint8_t> region) {
    const Mesh& mesh = in_.mesh;
    const size_t face_count = mesh.face_count();
    prepare();
    uv_ = atlas_.corner_uv.data();
    fill_records();
    hint_.assign(mesh.vertex_count(), VertexHint{kInvalid, 0.f, 0.f});
    if (hop_age_ > 0.f) hops_.reset(new uint32_t[face_count]);
    // The kept faces are placed as they are, in their patches (ids kept); the first UV each patch
    // gives a vertex is its hint, as in the growth.
    FaceRecord* rec = rec_.get();
    kept_patches_ = atlas_.patch_count;
    patch_size_.assign(kept_patches_, 0);
    patch_rotation_.assign(kept_patches_, Rotation{});
    patch_seed_.assign(kept_patches_, kInvalid);
    for (uint32_t f = 0; f < face_count; ++f) {
      if (region[f]) continue;
      const uint32_t p = atlas_.patch[f];
      rec[f].patch = p;
      ++patch_size_[p];
      if (patch_seed_[p] == kInvalid) patch_seed_[p] = f;
      if (hop_age_ > 0.f) hops_[f] = 0;
      for (int k = 0; k < 3; ++k) {
        VertexHint& hint = hint_[rec[f].vertex[k]];
        if (hint.patch == kInvalid) hint = VertexHint{p, uv_[6 * f + 2 * k], uv_[6 * f + 2 * k + 1]};
      }
    }
    // The region's faces next to kept ones join the front; a kept patch bordering the region gets
    // the rotation its face there shows (the growth's patch rotation is not kept).
    std::vector<uint8_t> rotation_known(kept_patches_, 0);
    for (uint32_t f = 0; f < face_count; ++f) {
      if (!region[f]) continue;
      FaceRecord& r = rec[f];
      for (const uint32_t g : r.neighbour) {
        if (g == kInvalid || region[g]) continue;
        ++r.placed;
        const uint32_t p = rec[g].patch;
        if (rotation_known[p]) continue;
        rotation_known[p] = 1;
        const float theta = edge_rotation(g, 0, uv_ + 6 * g, uv_ + 6 * g + 2);
        patch_rotation_[p] = Rotation{std::cos(theta), std::sin(theta)};
      }
      if (r.placed > 0) push_front(front_key(r.seam ? kSeam : kWaiting, r.placed, r.variation + hop_age_, f));
    }
    current_ = kAnyPatch;
    TAILOR_RETURN_IF_ERROR(grow(true));
    // Pieces of the region that touch no kept face (a whole component): from their seed, as the growth.
    for (const uint32_t seed : in_.component_seeds) {
      if (!region[seed] || rec[seed].patch != kInvalid) continue;
      current_ = start_patch(seed);
      TAILOR_RETURN_IF_ERROR(grow(true));
    }
    for (uint32_t f = 0; f < face_count; ++f) {
      if (!region[f] || rec[f].patch != kInvalid) continue;
      current_ = start_patch(f);
      TAILOR_RETURN_IF_ERROR(grow(true));
    }
    stats_.patches_before_absorb = static_cast<uint32_t>(patch_size_.size());
    absorb_small_patches();
    renumber_region_patches(region);
    return Status::ok();
  }

 private:
  // Options and per-run settings shared by run and run_region.
  void prepare() {
    anchor_ = in_.frames.anchor.data();
    scale_ = in_.options.scale;
    bound_ = in_.options.max_stretch;
    max_seed_rotation_ = in_.options.max_seed_rotation_deg * kPi / 180.f;
    factor_step_ = in_.factor_step;
    relax_ = 1.f - in_.options.field_following;
    hop_age_ = in_.factor_step < 0 ? in_.options.hop_age : 0.f;
    queue_.clear();
    patch_rotation_.reserve(256);
    patch_size_.reserve(256);
    patch_seed_.reserve(256);
  }

  // Pops the front until it is empty. `any_patch` (the region's growth): a waiting face joins
  // whichever neighbouring patch fits without a cut, not only the current one.
  Status grow(bool any_patch) {
    FaceRecord* rec = rec_.get();
    // A front entry is live while it is the face's latest (see front_buckets.h); the popped one's
    // face leaves the front (its front byte is cleared below, not here: the queue may ask about
    // every entry when it purges).
    auto live = [rec](uint64_t key) {
      return rec[FrontBuckets::face_of(key)].front == FrontBuckets::bucket_of(key) + 1;
    };
    {
      for (uint64_t key; queue_.pop(live, key);) {
        if (cancelled_) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
        const uint32_t f = FrontBuckets::face_of(key);
        rec[f].front = 0;
        // The next pop is most likely the current top (new entries come from f's neighbours,
        // which accept() touches anyway): start loading its record now.
        if (const uint32_t next = queue_.peek_face(); next != FrontBuckets::kNone) __builtin_prefetch(rec + next);
        const uint64_t cls = front_class(key);
        if (cls == kWaiting) {
          // First pass: only placements that leave no cut; the others wait, so the front flows
          // around them and cuts are made only where it is otherwise stuck (measured: 10-35%
          // less seam length than cutting at once, e.g. bunny 9.4% -> 8.2% of edge length).
          if (!try_place(f, any_patch ? kAnyPatch : current_, false)) {
            ++stats_.deferrals;
            push_front(with_class(key, kDeferred));
          }
        } else if (cls == kDeferred) {
          // Only deferred (and seam) faces wait: the front of the current patch is exhausted.
          // Join it (or, for a face deferred by an earlier patch, the neighbouring patch) with a
          // cut if that fits the bound, else start a new patch there.
          if ((any_patch || !try_place(f, current_, true)) && !try_place(f, kAnyPatch, true)) current_ = start_patch(f);
        } else if (!try_place(f, kAnyPatch)) {
          join_rigidly(f);  // a user seam face: joins a neighbouring patch, the cut runs along it
        }
        // The top's record was requested above; request what try_place will read through it.
        if (const uint32_t next = queue_.peek_face(); next != FrontBuckets::kNone) {
          for (const uint32_t g : rec[next].neighbour) {
            if (g == kInvalid) continue;
            __builtin_prefetch(rec + g);
            __builtin_prefetch(uv_ + 6 * g);
          }
        }
      }
    }
    if (cancelled_) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
    return Status::ok();
  }

  // Copies the inputs into one record per face (sequential passes; the growth then reads one
  // cache line per face instead of one per array).
  void fill_records() {
    const size_t face_count = in_.mesh.face_count();
    // Uninitialised (every field is written below): no extra pass over 64 bytes per face; on huge
    // pages (100 MB on 1.5 M faces: in 4 KiB pages, faulting it in was a third of the mapping's
    // page faults).
    rec_ = huge_uninitialized<FaceRecord>(face_count);
    const uint32_t* opposite = in_.topology.opposite.data();
    const uint32_t* indices = in_.mesh.indices.data();
    const float* local = in_.frames.local.data();
    const float* variation = in_.frames.variation.data();
    const uint8_t* seam = in_.options.seam_faces.empty() ? nullptr : in_.options.seam_faces.data();
    uint64_t seam_count = 0;
    for (size_t f = 0; f < face_count; ++f) {
      FaceRecord& r = rec_[f];
      uint32_t across = 0;
      for (int k = 0; k < 3; ++k) {
        const uint32_t o = opposite[3 * f + k];
        const uint32_t g = o / 3;  // kInvalid = 3 * (kInvalid / 3): its remainder adds nothing
        r.neighbour[k] = o == kInvalid ? kInvalid : g;
        across |= (o - 3 * g) << (2 * k);
      }
      r.across = static_cast<uint8_t>(across);
      std::memcpy(r.vertex, indices + 3 * f, sizeof r.vertex);
      const float* l = local + 6 * f;
      std::memcpy(r.local, l, sizeof r.local);
      r.variation = variation[f];
      r.patch = kInvalid;
      r.placed = 0;
      r.front = 0;
      r.seam = seam && seam[f] ? 1 : 0;
      seam_count += r.seam;
      r.degenerate = is_zero_area_frame(l);
    }
    stats_.faces_seam += seam_count;
  }

  void push_front(uint64_t key) {
    FaceRecord& r = rec_[FrontBuckets::face_of(key)];
    if (r.front != 0) queue_.supersede(r.front - 1u);
    r.front = static_cast<uint8_t>(FrontBuckets::bucket_of(key) + 1);
    queue_.push(key);
  }

  // === Geometry helpers ==========================================================================
  // UVs of the two ends of face f's edge k, as the placed neighbour across it has them.
  void neighbour_edge_uv(uint32_t f, int k, const float*& ua, const float*& ub) const {
    const FaceRecord& r = rec_[f];
    const uint32_t g = r.neighbour[k], kk = (r.across >> (2 * k)) & 3u;
    ua = uv_ + 6 * g + 2 * kNext[kk];  // the neighbour's edge runs B -> A
    ub = uv_ + 6 * g + 2 * kk;
  }

  // Frame vector from corner i to corner j of face f, in pixels, rotated by r.
  void frame_vector(uint32_t f, int i, int j, Rotation r, float& x, float& y) const {
    const float* l = rec_[f].local;
    const float dx = (l[2 * j] - l[2 * i]) * scale_, dy = (l[2 * j + 1] - l[2 * i + 1]) * scale_;
    x = r.c * dx - r.s * dy;
    y = r.s * dx + r.c * dy;
  }

  // Thesis eq. 2.3-2.4: A, B copied, C the mean of its predictions from A and from B. With
  // field_following < 1 the face's frame is first turned by that share of the angle between its
  // edge AB and the UV edge AB, so the texture direction follows the unfolding instead of the field.
  float unfold(uint32_t f, int k, const float* ua, const float* ub, Rotation r, float* out) const {
    const int ka = k, kb = kNext[k], kc = kPrev[k];
    if (relax_ > 0.f) {
      float vx, vy;
      frame_vector(f, ka, kb, r, vx, vy);
      const float wx = ub[0] - ua[0], wy = ub[1] - ua[1];
      const float theta = relax_ * std::atan2(vx * wy - vy * wx, vx * wx + vy * wy);
      const float c = std::cos(theta), sn = std::sin(theta);
      r = Rotation{r.c * c - r.s * sn, r.s * c + r.c * sn};
    }
#if TAILOR_SSE2
    // Both predictions at once, lane by lane the operations of the scalar code below (same bits,
    // checked on 2e7 random cases; x - y is x + (-y) and a sum does not depend on operand order).
    const float* l = rec_[f].local;
    const __m128 c = load_uv(l + 2 * kc);
    const __m128 ab = _mm_movelh_ps(load_uv(l + 2 * ka), load_uv(l + 2 * kb));
    const __m128 d = _mm_mul_ps(_mm_sub_ps(_mm_movelh_ps(c, c), ab), _mm_set1_ps(scale_));  // C - A, C - B, pixels
    const __m128 swapped = _mm_shuffle_ps(d, d, _MM_SHUFFLE(2, 3, 0, 1));
    const __m128 negate_x = _mm_setr_ps(-0.f, 0.f, -0.f, 0.f);
    const __m128 turned =
        _mm_add_ps(_mm_mul_ps(_mm_set1_ps(r.c), d), _mm_xor_ps(_mm_mul_ps(_mm_set1_ps(r.s), swapped), negate_x));
    const __m128 p = _mm_add_ps(_mm_movelh_ps(load_uv(ua), load_uv(ub)), turned);  // pax pay pbx pby
    const __m128 pb = _mm_movehl_ps(p, p);
    const __m128 mid = _mm_mul_ps(_mm_set1_ps(0.5f), _mm_add_ps(p, pb));
    const __m128 gap = _mm_sub_ps(p, pb);
    const __m128 gap2 = _mm_mul_ps(gap, gap);
    const float err = _mm_cvtss_f32(_mm_sqrt_ss(_mm_add_ss(gap2, _mm_shuffle_ps(gap2, gap2, 1))));
    out[2 * ka] = ua[0];
    out[2 * ka + 1] = ua[1];
    out[2 * kb] = ub[0];
    out[2 * kb + 1] = ub[1];
    out[2 * kc] = _mm_cvtss_f32(mid);
    out[2 * kc + 1] = _mm_cvtss_f32(_mm_shuffle_ps(mid, mid, 1));
    return err;
#else
    float ax, ay, bx, by;
    frame_vector(f, ka, kc, r, ax, ay);
    frame_vector(f, kb, kc, r, bx, by);
    const float pax = ua[0] + ax, pay = ua[1] + ay;
    const float pbx = ub[0] + bx, pby = ub[1] + by;
    out[2 * ka] = ua[0];
    out[2 * ka + 1] = ua[1];
    out[2 * kb] = ub[0];
    out[2 * kb + 1] = ub[1];
    out[2 * kc] = 0.5f * (pax + pbx);
    out[2 * kc + 1] = 0.5f * (pay + pby);
    return std::sqrt((pax - pbx) * (pax - pbx) + (pay - pby) * (pay - pby));
#endif
  }

  // Whether two UVs (2 floats each) have the same bits.
  static bool same_uv(const float* a, const float* b) { return std::memcmp(a, b, 2 * sizeof(float)) == 0; }

  bool is_degenerate(uint32_t f) const { return rec_[f].degenerate != 0; }

  float stretch(uint32_t f, const float* uv) const { return stretch_error(stretch_frame(rec_[f].local, scale_), uv); }

  // Rigid placement of face f: corner `at` goes to uv0, the rest follow the frame rotated by r.
  void place_rigid(uint32_t f, int at, const float* uv0, Rotation r, float* out) const {
    for (int k = 0; k < 3; ++k) {
      float x, y;
      frame_vector(f, at, k, r, x, y);
      out[2 * k] = uv0[0] + x;
      out[2 * k + 1] = uv0[1] + y;
    }
  }

  // Angle that rotates face f's own frame edge k onto the UV edge its neighbour gives.
  float edge_rotation(uint32_t f, int k, const float* ua, const float* ub) const {
    float vx, vy;
    frame_vector(f, k, kNext[k], Rotation{}, vx, vy);
    const float wx = ub[0] - ua[0], wy = ub[1] - ua[1];
    return std::atan2(vx * wy - vy * wx, vx * wx + vy * wy);
  }

  static float wrap_angle(float a) {
    while (a > kPi) a -= 2 * kPi;
    while (a < -kPi) a += 2 * kPi;
    return a;
  }

  // === Placement ===============================================================================
  // Tries to join face f to patch `target` (kAnyPatch: the neighbouring patch with the most shared
  // edges). The face is unfolded across one edge from a placed neighbour (its two corners copied,
  // so that edge is seamless); its third corner reuses, in this order of preference, the UV a
  // second placed neighbour gives it (seamless with that one too; with every neighbour when they
  // all agree), the UV the patch already gave its vertex through a face around it (the thesis's
  // "three textured vertices"), or a fresh UV, the mean of its two predictions (thesis eq. 2.3).
  // Reusing UVs first keeps a cut, once made, from spreading along the front. Within a tier the
  // least stretched triangle wins; the first tier with one within the bound is accepted. Without
  // allow_cuts, placements that disagree with a placed neighbour of the patch are not considered.
  bool try_place(uint32_t f, uint32_t target, bool allow_cuts = true) {
    const FaceRecord& self = rec_[f];
    if (target == kAnyPatch) {
      uint32_t patches[3];
      int n = 0;
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = self.neighbour[k];
        if (g != kInvalid && rec_[g].patch != kInvalid) patches[n++] = rec_[g].patch;
      }
      if (n == 0) return false;
      int best_votes = 0;
      for (int i = 0; i < n; ++i) {
        int votes = 0;
        for (int j = 0; j < n; ++j) votes += patches[j] == patches[i];
        if (votes > best_votes || (votes == best_votes && patches[i] < target)) {
          best_votes = votes;
          target = patches[i];
        }
      }
    }
    // Corner UVs offered by the placed neighbours of the target patch, per edge (set for the
    // edges listed in `edges` only: nothing else is read).
    const float* ends[3][2];
    int edges[3];
    int count = 0;
    bool other_patch = false;  // a placed neighbour in another patch: a seam edge for sure
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = self.neighbour[k];
      if (g == kInvalid) continue;
      const uint32_t q = rec_[g].patch;
      if (q != target) {
        other_patch = other_patch || q != kInvalid;
        continue;
      }
      neighbour_edge_uv(f, k, ends[k][0], ends[k][1]);
      edges[count++] = k;
    }
    if (count == 0) return false;
    const bool degenerate = is_degenerate(f);
    const StretchFrame frame = stretch_frame(self.local, scale_);
    float candidate[6], best[6] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
    float best_stretch = std::numeric_limits<float>::infinity(), best_error = 0.f;
    bool best_cuts = false;
    // Whether the candidate disagrees with any placed neighbour of the patch on a shared corner;
    // `copied` is the edge the candidate copied from its neighbour (equal by construction: UVs
    // are always finite).
    auto cuts_any = [&](int copied) {
      for (int i = 0; i < count; ++i) {
        const int e = edges[i], e1 = kNext[e];
        if (e == copied) continue;
        if (candidate[2 * e] != ends[e][0][0] || candidate[2 * e + 1] != ends[e][0][1] ||
            candidate[2 * e1] != ends[e][1][0] || candidate[2 * e1 + 1] != ends[e][1][1])
          return true;
      }
      return false;
    };
    // Callers skip the stretch of candidates that cut when cuts are not allowed (never kept).
    auto consider = [&](float s, float err, bool cuts) {
      if (s < best_stretch) {
        best_stretch = s;
        best_error = err;
        best_cuts = cuts;
        std::copy(candidate, candidate + 6, best);
      }
    };
    auto accept_best = [&](bool three_known) {
      if (!(degenerate || best_stretch <= bound_)) return false;
      if (best_cuts) ++stats_.faces_cut;
      accept(f, target, best, best_error, degenerate ? 0.f : best_stretch, three_known, best_cuts || other_patch);
      return true;
    };

    // Tiers 1 and 2 often rebuild a triangle already tried in this call: two neighbours that agree
    // on their shared corner give the same candidate from either edge, and the patch's UV of a
    // vertex is mostly the one a neighbour gives it. A repeat cannot change the outcome (its
    // stretch equals the first one's, which best_stretch is already at or below, and it cuts
    // exactly when the first one did, so the early accept cannot fire on it either): the repeats
    // found cheaply below are skipped (horse: 41% of the candidates of tiers 1 and 2 were repeats).
    // UVs are compared bit for bit, so one differing only in the sign of a zero is still tried.

    // --- Tier 1: third corner from a second placed neighbour ----------------------------------
    // Candidate: edge k copied, corner kc from edge m (one of the other edges touching it: k+1,
    // which ends there, or k+2, which starts there). Returns whether it is accepted at once.
    auto try_pair = [&](int k, int m, bool cuts) {
      const int ka = k, kb = kNext[k], kc = kPrev[k];
      const float* c = (m == kb) ? ends[m][1] : ends[m][0];
      candidate[2 * ka] = ends[k][0][0];
      candidate[2 * ka + 1] = ends[k][0][1];
      candidate[2 * kb] = ends[k][1][0];
      candidate[2 * kb + 1] = ends[k][1][1];
      candidate[2 * kc] = c[0];
      candidate[2 * kc + 1] = c[1];
      consider(degenerate ? 0.f : stretch_error(frame, candidate), 0.f, cuts);
      return !cuts && best_stretch <= bound_ && !best_cuts;
    };
    // Every corner touched by two of the edges has two sources: the neighbour across the edge
    // starting there (ends[c][0]) and the one across the edge ending there (ends[c - 1][1]).
    // Every candidate takes the other corners from their only source, so it cuts exactly when
    // two sources disagree (the same for all candidates), and two candidates coincide when they
    // differ only at corners whose sources agree bit for bit.
    if (count == 2) {
      // One corner has two sources, the one the edges share (the end of one, the start of the
      // other); the second candidate is the first when they agree there.
      const int k = edges[0], m = edges[1];
      const float* from_k = m == kNext[k] ? ends[k][1] : ends[k][0];
      const float* from_m = m == kNext[k] ? ends[m][0] : ends[m][1];
      const bool cuts = from_k[0] != from_m[0] || from_k[1] != from_m[1];
      if (allow_cuts || !cuts) {
        if (try_pair(k, m, cuts)) return accept_best(true);
        if (!same_uv(from_k, from_m) && try_pair(m, k, cuts)) return accept_best(true);
      }
    } else if (count == 3) {
      // The candidates' picks (bit c set: corner c from the edge ending there), reduced to the
      // corners whose sources disagree, are each tried once.
      uint32_t agree = 0, seen = 0;
      bool cuts = false;
      for (int c = 0; c < 3; ++c) {
        const float* a = ends[c][0];
        const float* b = ends[kPrev[c]][1];
        agree |= same_uv(a, b) ? 1u << c : 0u;
        cuts = cuts || a[0] != b[0] || a[1] != b[1];
      }
      if (allow_cuts || !cuts) {
        for (int k = 0; k < 3; ++k) {
          for (const int m : {std::min(kNext[k], kPrev[k]), std::max(kNext[k], kPrev[k])}) {  // edge order
            const uint32_t pick = ((1u << kNext[k]) | (m == kNext[k] ? 1u << kPrev[k] : 0u)) & ~agree;
            if (seen >> pick & 1u) continue;
            seen |= 1u << pick;
            if (try_pair(k, m, cuts)) return accept_best(true);
          }
        }
      }
    }
    if (count >= 2) {
      if (accept_best(true)) return true;
    }

    // --- Tier 2: third corner from the patch's UV of its vertex --------------------------------
    for (int i = 0; i < count; ++i) {
      const int k = edges[i], kc = kPrev[k];
      const VertexHint& hint = hint_[self.vertex[kc]];
      if (hint.patch != target) continue;
      // Tier 1 tried edge k with corner kc from each other edge (or a candidate identical to it):
      // a hint with the same bits as one of those corners repeats it.
      if (count >= 2) {
        bool tried = false;
        for (int j = 0; j < count; ++j) {
          const int m = edges[j];
          if (m != k) tried = tried || same_uv(&hint.u, m == kNext[k] ? ends[m][1] : ends[m][0]);
        }
        if (tried) continue;
      }
      const int ka = k, kb = kNext[k];
      candidate[2 * ka] = ends[k][0][0];
      candidate[2 * ka + 1] = ends[k][0][1];
      candidate[2 * kb] = ends[k][1][0];
      candidate[2 * kb + 1] = ends[k][1][1];
      candidate[2 * kc] = hint.u;
      candidate[2 * kc + 1] = hint.v;
      const bool cuts = count > 1 && cuts_any(k);
      if (allow_cuts || !cuts) consider(degenerate ? 0.f : stretch_error(frame, candidate), 0.f, cuts);
    }
    if (accept_best(true)) return true;

    // --- Tier 3: a fresh third corner ----------------------------------------------------------
    if (count > 1 && !allow_cuts) return false;  // a fresh corner cuts from all but one neighbour
    const Rotation r = patch_rotation_[target];
    for (int i = 0; i < count; ++i) {
      const int k = edges[i];
      const float err = unfold(f, k, ends[k][0], ends[k][1], r, candidate);
      consider(degenerate ? err : stretch_error(frame, candidate), err, count > 1);
    }
    return accept_best(false);
  }

  // Chooses the placed neighbour edge of f whose UV edge is closest in direction to f's frame
  // rotated by `reference` (per patch when reference_per_patch). Returns -1 when none.
  int best_rigid_edge(uint32_t f, bool reference_per_patch, float& rotation) const {
    int best = -1;
    float best_delta = std::numeric_limits<float>::infinity();
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = rec_[f].neighbour[k];
      if (g == kInvalid || rec_[g].patch == kInvalid) continue;
      const float* ua;
      const float* ub;
      neighbour_edge_uv(f, k, ua, ub);
      const float theta = edge_rotation(f, k, ua, ub);
      const float reference = reference_per_patch ? patch_rotation_[rec_[g].patch].angle() : 0.f;
      const float delta = std::abs(wrap_angle(theta - reference));
      if (delta < best_delta) {
        best_delta = delta;
        best = k;
        rotation = theta;
      }
    }
    return best;
  }

  // Starts a new patch at face f: unfolded from its best placed neighbour so the texture goes on
  // across that edge (rotated by at most max_seed_rotation), or at a position-derived UV when it
  // has none (the first face of a component).
  uint32_t start_patch(uint32_t f) {
    const uint32_t id = static_cast<uint32_t>(patch_size_.size());
    float theta = 0.f;
    const int k = best_rigid_edge(f, false, theta);
    Rotation r;
    float uv[6];
    if (k < 0) {
      const float anchor[2] = {anchor_[2 * f] * scale_, anchor_[2 * f + 1] * scale_};
      place_rigid(f, 0, anchor, r, uv);
    } else {
      const float* ua;
      const float* ub;
      neighbour_edge_uv(f, k, ua, ub);
      if (std::abs(theta) <= max_seed_rotation_) {
        r = Rotation{std::cos(theta), std::sin(theta)};
        place_aligned(f, k, ua, ub, r, uv);
      } else {
        place_rigid(f, k, ua, r, uv);  // follows the field; continuous at vertex A only
      }
    }
    patch_rotation_.push_back(r);
    patch_size_.push_back(0);
    patch_seed_.push_back(f);
    ++stats_.faces_rigid;
    accept(f, id, uv, 0.f, 0.f, false, true);
    --stats_.faces_unfolded;  // counted as rigid above
    return id;
  }

  // Places face f rigidly against the neighbour edge closest to its patch's rotation, seamless on
  // that edge; used for seam faces and absorbed faces that no unfolding fits.
  void join_rigidly(uint32_t f) {
    float theta = 0.f;
    const int k = best_rigid_edge(f, true, theta);
    if (k < 0) {
      current_ = start_patch(f);
      return;
    }
    const float* ua;
    const float* ub;
    neighbour_edge_uv(f, k, ua, ub);
    float uv[6];
    place_aligned(f, k, ua, ub, Rotation{std::cos(theta), std::sin(theta)}, uv);
    ++stats_.faces_rigid;
    accept(f, rec_[rec_[f].neighbour[k]].patch, uv, 0.f, 0.f, false, true);
    --stats_.faces_unfolded;
  }

  // Face f turned by r (which aligns its edge k with the neighbour's UV edge): the edge's two
  // corners are copied, so that edge is seamless; the stretch is only the neighbour's edge length
  // mismatch. Falls back to a rigid copy from corner k when even that exceeds the bound.
  void place_aligned(uint32_t f, int k, const float* ua, const float* ub, Rotation r, float* uv) {
    const float err = unfold(f, k, ua, ub, r, uv);
    const float s = is_degenerate(f) ? 0.f : stretch(f, uv);
    if (s <= bound_) {
      stats_.max_error_px = std::max(stats_.max_error_px, err);
      stats_.max_stretch_accepted = std::max(stats_.max_stretch_accepted, s);
    } else {
      place_rigid(f, k, ua, r, uv);
    }
  }

  // on_seam: f may disagree with a placed neighbour (a cut, another patch, a rigid placement).
  void accept(uint32_t f, uint32_t p, const float* uv, float error_px, float stretch_error, bool three_known,
              bool on_seam) {
    std::memcpy(uv_ + 6 * f, uv, 6 * sizeof(float));  // a constant size: no library call
    FaceRecord& self = rec_[f];
    self.patch = p;
    for (int k = 0; k < 3; ++k) {
      VertexHint& hint = hint_[self.vertex[k]];
      if (hint.patch == p) continue;  // the first UV a patch gives a vertex stays its hint
      hint = VertexHint{p, uv[2 * k], uv[2 * k + 1]};
    }
    ++patch_size_[p];
    if (three_known)
      ++stats_.faces_three_textured;
    else
      ++stats_.faces_unfolded;
    stats_.max_error_px = std::max(stats_.max_error_px, error_px);
    stats_.max_stretch_accepted = std::max(stats_.max_stretch_accepted, stretch_error);
    // One pass over the neighbours: the placed ones are marked (on a seam) and give the hops, the
    // others are pushed below, in edge order.
    // Where seams lie: the seam shortening afterwards starts from these faces and their neighbours
    // (placed neighbours only: one placed later that disagrees with f is marked when it is placed).
    if (on_seam) seam_mark_[f] = 1;
    const bool hop = hop_age_ > 0.f && !absorbing_;  // the absorption pass keeps its own queue
    uint32_t unplaced[3];
    int unplaced_count = 0;
    uint32_t fewest = kInvalid, fewest_any = kInvalid;
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = self.neighbour[k];
      if (g == kInvalid) continue;
      const uint32_t q = rec_[g].patch;
      if (q == kInvalid) {
        unplaced[unplaced_count++] = g;
        continue;
      }
      if (on_seam) seam_mark_[g] = 1;
      if (hop) {
        fewest_any = std::min(fewest_any, hops_[g]);
        if (q == p) fewest = std::min(fewest, hops_[g]);
      }
    }
    if (absorbing_) return;
    // Age offset of the neighbours pushed now. Default: grows with the length of f's path from its
    // component's seed in faces (hops: one more than its fewest among placed neighbours of its
    // patch; a patch's first face continues from its placed neighbours in other patches), so the
    // order in which two faces are reached depends only on the faces between them and the seed,
    // not on how many faces elsewhere were placed first; and the deferred face that seeds the
    // next patch is the one nearest the seed among equals. With the thesis's global counter,
    // removing a part of the mesh shifted every later key and reordered the growth everywhere
    // (stability, removing 10%: bit-identical corners 14-97% -> 83-99.9%, docs/mapping.md).
    float age_offset;
    if (hop) {
      if (fewest == kInvalid) fewest = fewest_any;  // a new patch's seed
      const uint32_t hops = fewest == kInvalid ? 0 : fewest + 1;
      hops_[f] = hops;
      age_offset = hop_age_ * static_cast<float>(hops + 1);
    } else {
      age_offset = static_cast<float>(factor_);
    }
    for (int i = 0; i < unplaced_count; ++i) {
      const uint32_t h = unplaced[i];
      FaceRecord& r = rec_[h];
      const uint32_t placed = ++r.placed;
      const uint64_t cls = r.seam ? kSeam : kWaiting;
      const uint64_t key = front_key(cls, placed, r.variation + age_offset, h);
      if (r.front != 0) queue_.supersede(r.front - 1u);
      r.front = static_cast<uint8_t>(FrontBuckets::bucket_of(key) + 1);
      queue_.push(key);
    }
    factor_ += factor_step_;
    if (++placed_count_ % kProgressInterval == 0 && in_.options.progress) {
      const float done = static_cast<float>(placed_count_) / static_cast<float>(in_.mesh.face_count());
      if (!in_.options.progress(std::min(done, 1.f))) cancelled_ = true;
    }
  }

  // === Absorption of small patches ==============================================================
  // Faces of patches below min_patch_faces (except the largest patch of each component) are
  // re-placed from their neighbours in kept patches, from the kept border inwards.
  void absorb_small_patches() {
    const uint32_t min_faces = in_.options.min_patch_faces;
    const size_t patch_count = patch_size_.size();
    if (min_faces <= 1 || patch_count <= 1) return;
    const std::vector<uint32_t>& component = in_.topology.face_component;
    FaceRecord* rec = rec_.get();
    std::vector<uint32_t> largest(in_.topology.edge_components, kInvalid);
    for (uint32_t p = 0; p < patch_count; ++p) {
      if (patch_seed_[p] == kInvalid) continue;  // a region's former patch, now empty
      uint32_t& l = largest[component[patch_seed_[p]]];
      if (l == kInvalid || patch_size_[p] > patch_size_[l]) l = p;
    }
    std::vector<uint8_t> kept(patch_count, 0);
    bool any_small = false;
    for (uint32_t p = 0; p < patch_count; ++p) {
      // The patches of faces outside a regrown region are never touched.
      kept[p] = p < kept_patches_ || patch_size_[p] >= min_faces || largest[component[patch_seed_[p]]] == p;
      any_small = any_small || !kept[p];
    }
    if (!any_small) return;
    // Every face is placed after the growth: the unplaced ones are those removed here, in face
    // order, so the border is found among them instead of in a second pass over all faces.
    const size_t face_count = in_.mesh.face_count();
    std::vector<uint32_t> removed;
    for (size_t f = 0; f < face_count; ++f) {
      if (!kept[rec[f].patch]) {
        --patch_size_[rec[f].patch];
        rec[f].patch = kInvalid;
        removed.push_back(static_cast<uint32_t>(f));
      }
    }
    absorbing_ = true;
    // Faces with more placed neighbours first (three, then two, then one; first come first within
    // each), as the growth's rank: a face held on more sides is placed with fewer cuts. Plain
    // breadth first, in face order, runs cuts along the long edges of sliver fans (adis16480 with
    // field following: 20.9 % visible seams against 5.4 %; the other shared meshes within 0.3
    // points).
    auto placed_neighbours = [&](uint32_t f) {
      int n = 0;
      for (const uint32_t g : rec[f].neighbour) n += g != kInvalid && rec[g].patch != kInvalid;
      return n;
    };
    std::vector<uint32_t> level[3];
    size_t head[3] = {0, 0, 0};
    for (const uint32_t f : removed)
      if (const int n = placed_neighbours(f); n > 0) level[n - 1].push_back(f);
    for (;;) {
      int l = 2;
      while (l >= 0 && head[l] == level[l].size()) --l;
      if (l < 0) break;
      const uint32_t f = level[l][head[l]++];
      if (rec[f].patch != kInvalid) continue;
      if (!try_place(f, kAnyPatch)) join_rigidly(f);
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = rec[f].neighbour[k];
        if (g != kInvalid && rec[g].patch == kInvalid) level[placed_neighbours(g) - 1].push_back(g);
      }
    }
    absorbing_ = false;
  }

  // Dense patch ids in order of creation, dropping the emptied ones, into the atlas.
  void renumber_patches() {
    std::vector<uint32_t> remap(patch_size_.size(), kInvalid);
    uint32_t next = 0;
    for (size_t p = 0; p < patch_size_.size(); ++p)
      if (patch_size_[p] > 0) remap[p] = next++;
    const size_t face_count = in_.mesh.face_count();
    reserve_huge(atlas_.patch, face_count);
    atlas_.patch.resize(face_count);
    for (size_t f = 0; f < face_count; ++f) atlas_.patch[f] = remap[rec_[f].patch];
    atlas_.patch_count = next;
  }

  // Region growth: the kept faces' patches keep their ids; the new ones take the ids the region's
  // former patches left free (lowest first), then ids after the kept ones.
  void renumber_region_patches(std::span<const uint8_t> region) {
    std::vector<uint32_t> remap(patch_size_.size(), kInvalid);
    uint32_t count = 0, free = 0, after = kept_patches_;
    for (uint32_t p = 0; p < kept_patches_; ++p)
      if (patch_size_[p] > 0) remap[p] = p, count = p + 1;
    for (uint32_t p = kept_patches_; p < patch_size_.size(); ++p) {
      if (patch_size_[p] == 0) continue;
      while (free < kept_patches_ && patch_size_[free] > 0) ++free;
      remap[p] = free < kept_patches_ ? free++ : after++;
      count = std::max(count, remap[p] + 1);
    }
    const size_t face_count = in_.mesh.face_count();
    for (size_t f = 0; f < face_count; ++f)
      if (region[f]) atlas_.patch[f] = remap[rec_[f].patch];
    atlas_.patch_count = count;
  }

  const MappingInput& in_;
  MappingStats& stats_;
  Atlas& atlas_;
  const float* anchor_ = nullptr;
  float scale_ = 1.f, bound_ = 0.f, max_seed_rotation_ = 0.f;
  float relax_ = 0.f;                        // 1 - field_following: share of the edge mismatch taken as rotation
  double factor_step_ = 0.0, factor_ = 0.0;  // the thesis's global age counter (when hop_age_ is 0)
  float hop_age_ = 0.f;                      // age per hop from the component's seed; 0 = the global counter
  std::unique_ptr<uint32_t[]> hops_;         // per face: hops from its component's seed (hop_age_ > 0)
  float* uv_ = nullptr;
  HugeArray<FaceRecord> rec_;     // per face
  std::vector<VertexHint> hint_;  // per vertex: the UV its patch first gave it
  std::vector<Rotation> patch_rotation_;
  std::vector<uint32_t> patch_size_;
  std::vector<uint32_t> patch_seed_;
  FrontBuckets queue_;
  std::vector<uint8_t>& seam_mark_;  // per face: 1 = placed on a seam (for shorten_seams)
  uint32_t current_ = 0;
  uint64_t placed_count_ = 0;
  bool cancelled_ = false;
  bool absorbing_ = false;
  uint32_t kept_patches_ = 0;  // run_region: patch ids below this are the kept faces' (never absorbed)
};

}  // namespace

Status grow_patches(const MappingInput& input, Atlas& atlas, MappingStats& stats, std::vector<uint8_t>& on_seam) {
  on_seam.assign(input.mesh.face_count(), 0);
  PatchMapper mapper(input, atlas, stats, on_seam);
  return mapper.run();
}

Status regrow_patches(const MappingInput& input, std::span<const uint8_t> region, Atlas& atlas, MappingStats& stats,
                      std::vector<uint8_t>& on_seam) {
  on_seam.assign(input.mesh.face_count(), 0);
  PatchMapper mapper(input, atlas, stats, on_seam);
  TAILOR_RETURN_IF_ERROR(mapper.run_region(region));
  // Only the region's faces are where the seam shortening may look (a kept face never moves).
  for (size_t f = 0; f < on_seam.size(); ++f) on_seam[f] &= region[f];
  return Status::ok();
}

}  // namespace tailor::internal
