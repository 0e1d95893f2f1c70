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
// It is kept only if every face it touched is within the bound, else undone: every face stays
// within max_stretch, no face inverts, and each kept zip removes at least one seam edge.
//
// This work is based on:
//   L. Liu, L. Zhang, Y. Xu, C. Gotsman, S. J. Gortler, "A local/global approach to mesh
//   parameterization", SGP 2008 (ARAP local/global iterations; uniform weights here).
#include <algorithm>
#include <cmath>
#include <vector>

#include "internal/face_stretch.h"
#include "internal/mapping_common.h"

namespace tailor::internal {
namespace {

constexpr int kNext[3] = {1, 2, 0};
constexpr int kPrev[3] = {2, 0, 1};
// Tuned on the shared meshes (bunny, horse, spot, chinese-dragon; docs/mapping.md section 2):
// A gap wider than its crack edge is more than a region of 16 rings absorbs within the bound
// (< 1 % of those zips passed): left without trying.
constexpr float kMaxGapRatio = 1.f;
// Rings of the first region per unit of gap / edge length (at least kMinRings); a zip that fails
// is tried once more with twice the rings (at most options.crack_rings) unless its distortion was
// beyond kEscalateAbove times the bound (then a larger region rarely helped: 4 % of tries).
constexpr float kRingsPerGap = 8.f;
constexpr int kMinRings = 2;
constexpr float kEscalateAbove = 1.5f;
// Local/global iterations per relaxation, stopped early once no UV moves by kSettledPx, or given
// up when the distortion after kAbortAt iterations is still beyond kEscalateAbove times the bound
// (measured on the horse: 1 % of those relaxations ended within it; saves 20 % of the time).
constexpr int kIterations = 12;
constexpr float kSettledPx = 0.05f;
constexpr int kAbortAt = 5;
// Reweighting: a face's weight is multiplied by 1 + (distortion / bound)^2 after each iteration.
// Without it the distortion peaks at the zipped vertex (uniform ARAP) and 40 % fewer zips pass.
// A zipped face must also keep its area within 1/(1 + kAreaBound)..1 + kAreaBound of the
// surface's: the cone a zip flattens is mostly area change, and unbounded it raised the thesis
// stretch (the area ratio's variation) past 0.08 on spot.
constexpr float kAreaBound = 0.2f;


class CrackCloser {
 public:
  CrackCloser(const MappingInput& in, Atlas& atlas, const ProgressCallback& progress)
      : in_(in), atlas_(atlas), progress_(progress) {}

  Status run(uint64_t& zipped) {
    zipped = 0;
    const size_t face_count = in_.mesh.face_count();
    opposite_ = in_.topology.opposite.data();
    indices_ = in_.mesh.indices.data();
    local_ = in_.frames.local.data();
    uv_ = atlas_.corner_uv.data();
    scale_ = in_.options.scale;
    bound_ = in_.options.max_stretch;
    max_rings_ = static_cast<int>(std::max<uint32_t>(in_.options.crack_rings, kMinRings));
    seam_flags_ = in_.options.seam_faces.empty() ? nullptr : in_.options.seam_faces.data();
    build_wedges();
    build_vertex_corners();
    face_stamp_.assign(face_count, 0);
    wedge_stamp_.assign(3 * face_count, 0);
    wedge_local_.assign(3 * face_count, 0);

    // Crack edges, each once (its half-edge in the face of lower id), in edge order; a zip queues
    // the crack edges around the vertices it merged (they may end there now), first in first out.
    std::vector<uint32_t> queue;
    std::vector<uint8_t> queued(3 * face_count, 0);
    for (uint32_t e = 0; e < 3 * face_count; ++e) {
      if (e < opposite_[e] && is_crack(e)) {
        queue.push_back(e);
        queued[e] = 1;
      }
    }
    for (size_t head = 0; head < queue.size(); ++head) {
      if (head % kProgressInterval == 0 && progress_ && !progress_(static_cast<float>(head) / static_cast<float>(queue.size())))
        return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
      const uint32_t e = queue[head];
      queued[e] = 0;
      if (!is_crack(e)) continue;
      const int merged = zip(e);
      if (merged == 0) continue;
      zipped += static_cast<uint64_t>(merged);
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
            queue.push_back(canonical);
          }
        }
      }
    }
    return Status::ok();
  }

 private:
  // === UV vertices ("wedges") ===================================================================
  // Corners around one mesh vertex that hold the same UV through a chain of faces form a wedge;
  // wedge_[c] is the id of corner c's wedge (one of its corners). Found by union-find across every
  // edge whose two faces agree on the shared corner.
  void build_wedges() {
    const uint32_t corners = static_cast<uint32_t>(3 * in_.mesh.face_count());
    wedge_.resize(corners);
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
    wedge_size_.assign(corners, 0);
    for (uint32_t c = 0; c < corners; ++c) {
      wedge_[c] = find(c);
      ++wedge_size_[wedge_[c]];
    }
  }

  void build_vertex_corners() {
    const size_t vertex_count = in_.mesh.vertex_count();
    const uint32_t corners = static_cast<uint32_t>(3 * in_.mesh.face_count());
    vertex_start_.assign(vertex_count + 1, 0);
    for (uint32_t c = 0; c < corners; ++c) ++vertex_start_[indices_[c] + 1];
    for (size_t v = 0; v < vertex_count; ++v) vertex_start_[v + 1] += vertex_start_[v];
    vertex_corners_.resize(corners);
    std::vector<uint32_t> fill(vertex_start_.begin(), vertex_start_.end() - 1);
    for (uint32_t c = 0; c < corners; ++c) vertex_corners_[fill[indices_[c]]++] = c;
  }

  bool same_uv(uint32_t a, uint32_t b) const {
    return uv_[2 * a] == uv_[2 * b] && uv_[2 * a + 1] == uv_[2 * b + 1];
  }

  // The corners of half-edge e = 3f + k at its start A and end B, and the neighbour's at A and B.
  struct EdgeCorners {
    uint32_t fa, fb, ga, gb;
  };
  EdgeCorners edge_corners(uint32_t e) const {
    const uint32_t o = opposite_[e], f = e / 3, g = o / 3;
    return {e, 3 * f + static_cast<uint32_t>(kNext[e - 3 * f]), 3 * g + static_cast<uint32_t>(kNext[o - 3 * g]), o};
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

  // === Zips ======================================================================================
  // Zips crack edge e: merges the two sides' wedges at its open end when the other end is shared
  // (a crack's tip), or at both ends when neither is (a crack without a tip, e.g. a cut from a
  // patch's border to its border), and relaxes around them. Returns the merged vertices' count
  // (0: nothing changed; merges_ then lists the merges).
  int zip(uint32_t e) {
    const EdgeCorners c = edge_corners(e);
    const float edge = std::hypot(uv_[2 * c.fa] - uv_[2 * c.fb], uv_[2 * c.fa + 1] - uv_[2 * c.fb + 1]);
    merges_.clear();
    changed_.clear();
    float gap_ratio = 0.f;
    for (const auto& [fc, gc] : {std::pair{c.fa, c.ga}, std::pair{c.fb, c.gb}}) {
      const uint32_t keep = wedge_[fc], drop = wedge_[gc];
      if (keep == drop) continue;
      const float gap = std::hypot(uv_[2 * keep] - uv_[2 * drop], uv_[2 * keep + 1] - uv_[2 * drop + 1]);
      if (!(gap <= kMaxGapRatio * edge)) {
        undo_merges();
        return 0;
      }
      gap_ratio = std::max(gap_ratio, gap / edge);
      if (!merge(indices_[fc], keep, drop)) {
        undo_merges();
        return 0;
      }
    }
    if (merges_.empty()) return 0;
    const uint32_t patch = atlas_.patch[e / 3];
    const int first = std::clamp(static_cast<int>(std::ceil(kRingsPerGap * gap_ratio)), kMinRings, max_rings_);
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
    const Merge m{vertex, keep, drop, {0.5f * (uv_[2 * keep] + uv_[2 * drop]), 0.5f * (uv_[2 * keep + 1] + uv_[2 * drop + 1])}};
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
    if (++stamp_ == 0) {  // wrapped: forget every mark
      std::fill(face_stamp_.begin(), face_stamp_.end(), 0);
      std::fill(wedge_stamp_.begin(), wedge_stamp_.end(), 0);
      stamp_ = 1;
    }
    last_max_ = 0.f;
    // --- Region: faces of the patch within `rings` edge-steps of the merged vertices' fans ---
    region_.clear();
    for (const Merge& m : merges_) {
      const uint32_t v = m.vertex;
      for (uint32_t i = vertex_start_[v]; i < vertex_start_[v + 1]; ++i) {
        const uint32_t f = vertex_corners_[i] / 3;
        if (atlas_.patch[f] == patch && face_stamp_[f] != stamp_) {
          face_stamp_[f] = stamp_;
          region_.push_back(f);
        }
      }
    }
    for (size_t begin = 0, ring = 0; ring < static_cast<size_t>(rings); ++ring) {
      const size_t end = region_.size();
      for (size_t i = begin; i < end; ++i) {
        const uint32_t f = region_[i];
        for (int k = 0; k < 3; ++k) {
          const uint32_t o = opposite_[3 * f + static_cast<uint32_t>(k)];
          if (o == kInvalid) continue;
          const uint32_t g = o / 3;
          if (face_stamp_[g] == stamp_ || atlas_.patch[g] != patch) continue;
          face_stamp_[g] = stamp_;
          region_.push_back(g);
        }
      }
      begin = end;
    }
    // --- Wedges of the region; free = every corner of the wedge lies in the region ---
    wedges_.clear();
    for (const uint32_t f : region_) {
      for (uint32_t c = 3 * f; c < 3 * f + 3; ++c) {
        const uint32_t w = wedge_[c];
        if (wedge_stamp_[w] != stamp_) {
          wedge_stamp_[w] = stamp_;
          wedge_local_[w] = static_cast<uint32_t>(wedges_.size());
          float u = uv_[2 * w], v = uv_[2 * w + 1];
          for (const Merge& m : merges_) {
            if (m.keep != w) continue;
            u = m.mid[0];
            v = m.mid[1];
          }
          wedges_.push_back(Wedge{w, 0, u, v});
        }
        ++wedges_[wedge_local_[w]].corners_in_region;
      }
    }
    // Faces with a free corner move; a zero-area face among them is left alone (its rotation is
    // meaningless and its image may not invert).
    moving_.clear();
    for (const uint32_t f : region_) {
      bool moves = false;
      for (uint32_t c = 3 * f; c < 3 * f + 3; ++c) moves = moves || is_free(wedge_[c]);
      if (!moves) continue;
      if (is_zero_area_frame(local_ + 6 * f)) return false;
      moving_.push_back(f);
    }
    // --- Per moving face: its wedges (local ids) and edge vectors in pixels ---
    const size_t moving = moving_.size();
    face_wedge_.resize(3 * moving);
    face_edge_.resize(6 * moving);
    rotation_.resize(2 * moving);
    frame_.resize(moving);
    weight_.assign(moving, 1.f);
    for (size_t i = 0; i < moving; ++i) {
      frame_[i] = stretch_frame(local_ + 6 * moving_[i], scale_);
      const uint32_t f = moving_[i];
      const float* l = local_ + 6 * f;
      for (int k = 0; k < 3; ++k) {
        face_wedge_[3 * i + static_cast<size_t>(k)] = wedge_local_[wedge_[3 * f + static_cast<uint32_t>(k)]];
        // Edge k: corner k -> corner k+1.
        face_edge_[6 * i + 2 * static_cast<size_t>(k)] = (l[2 * kNext[k]] - l[2 * k]) * scale_;
        face_edge_[6 * i + 2 * static_cast<size_t>(k) + 1] = (l[2 * kNext[k] + 1] - l[2 * k + 1]) * scale_;
      }
    }
    // Corners of each free wedge in the moving faces (CSR over local wedge ids), each with what
    // its prediction needs: the face, the other two corners' wedges, and the sum of the frame
    // vectors from them to it (the rotation is linear, so one vector serves both predictions).
    wedge_start_.assign(wedges_.size() + 1, 0);
    for (size_t i = 0; i < 3 * moving; ++i)
      if (is_free(wedges_[face_wedge_[i]])) ++wedge_start_[face_wedge_[i] + 1];
    for (size_t w = 0; w < wedges_.size(); ++w) wedge_start_[w + 1] += wedge_start_[w];
    terms_.resize(wedge_start_.back());
    fill_.assign(wedge_start_.begin(), wedge_start_.end() - 1);
    for (uint32_t i = 0; i < moving; ++i) {
      const float* e = &face_edge_[6 * i];
      for (int k = 0; k < 3; ++k) {
        const uint32_t w = face_wedge_[3 * i + static_cast<uint32_t>(k)];
        if (!is_free(wedges_[w])) continue;
        // From the next corner: minus edge k; from the previous: edge k-1.
        terms_[fill_[w]++] = Term{i, face_wedge_[3 * i + static_cast<uint32_t>(kNext[k])],
                                  face_wedge_[3 * i + static_cast<uint32_t>(kPrev[k])], e[2 * kPrev[k]] - e[2 * k],
                                  e[2 * kPrev[k] + 1] - e[2 * k + 1]};
      }
    }

    // --- Local/global iterations: per face the rotation nearest to its Jacobian (and, from the
    // second on, its weight raised by its distortion: iteratively reweighted, so the distortion
    // is spread instead of peaking at the zipped vertex), then Gauss-Seidel over the free wedges,
    // each moved to the weighted mean of the positions its faces' other corners predict ---
    for (int iteration = 0; iteration < kIterations; ++iteration) {
      last_max_ = 0.f;
      for (uint32_t i = 0; i < moving; ++i) fit_rotation(i, iteration > 0);
      float moved = 0.f;
      for (size_t w = 0; w < wedges_.size(); ++w) {
        const uint32_t begin = wedge_start_[w], end = wedge_start_[w + 1];
        if (begin == end) continue;
        float su = 0.f, sv = 0.f, sw = 0.f;
        for (uint32_t j = begin; j < end; ++j) {
          const Term& t = terms_[j];
          const float wt = weight_[t.face], rc = rotation_[2 * t.face], rs = rotation_[2 * t.face + 1];  // rotation premultiplied by wt
          const Wedge& a = wedges_[t.a];
          const Wedge& b = wedges_[t.b];
          sw += wt;
          su += wt * (a.u + b.u) + rc * t.x - rs * t.y;
          sv += wt * (a.v + b.v) + rs * t.x + rc * t.y;
        }
        const float inv = 0.5f / sw;
        Wedge& target = wedges_[w];
        const float u = su * inv, v = sv * inv;
        moved = std::max(moved, std::abs(u - target.u) + std::abs(v - target.v));
        target.u = u;
        target.v = v;
      }
      if (moved < kSettledPx) break;
      if (iteration == kAbortAt && last_max_ > kEscalateAbove) break;
    }
    // --- Check, then keep or restore ---
    saved_.resize(6 * moving_.size());
    for (size_t i = 0; i < moving_.size(); ++i) std::copy(uv_ + 6 * moving_[i], uv_ + 6 * moving_[i] + 6, &saved_[6 * i]);
    bool within = true;
    for (size_t i = 0; i < moving_.size() && within; ++i) {
      const uint32_t f = moving_[i];
      float* uv = uv_ + 6 * f;
      for (int k = 0; k < 3; ++k) {
        const Wedge& w = wedges_[wedge_local_[wedge_[3 * f + static_cast<uint32_t>(k)]]];
        uv[2 * k] = w.u;
        uv[2 * k + 1] = w.v;
      }
      const float area_ratio = ((uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[4] - uv[0]) * (uv[3] - uv[1])) * frame_[i].inv;
      within = stretch_error(frame_[i], uv) <= bound_ && area_ratio <= 1.f + kAreaBound &&
               area_ratio * (1.f + kAreaBound) >= 1.f;
    }
    if (within) return true;
    for (size_t i = 0; i < moving_.size(); ++i) std::copy(&saved_[6 * i], &saved_[6 * i] + 6, uv_ + 6 * moving_[i]);
    return false;
  }

  struct Wedge {
    uint32_t id;                 // wedge id (a corner)
    uint32_t corners_in_region;  // of its corners, those in region faces
    float u, v;                  // current UV
  };
  bool is_free(const Wedge& w) const { return w.corners_in_region == wedge_size_[w.id]; }
  bool is_free(uint32_t wedge) const { return is_free(wedges_[wedge_local_[wedge]]); }

  // Moving face i: the rotation nearest to its Jacobian J (frame -> current UVs), stored
  // premultiplied by its weight; with reweight, first the weight times 1 + beta (d / bound)^2,
  // d its distortion max(sigma_max - 1, 1/sigma_min - 1) (capped). Closed form for 2x2: with
  // J = [a b; c d], the rotation turns by atan2(c - b, a + d) and sigma = |q| +- |r|, q and r its
  // conformal and anti-conformal parts (face_stretch.h). The adjugate of Q is used: 1/det(Q) > 0
  // scales J without turning it.
  void fit_rotation(uint32_t i, bool reweight) {
    const float* e = &face_edge_[6 * i];
    const Wedge& w0 = wedges_[face_wedge_[3 * i]];
    const Wedge& w1 = wedges_[face_wedge_[3 * i + 1]];
    const Wedge& w2 = wedges_[face_wedge_[3 * i + 2]];
    const float q1x = e[0], q1y = e[1], q2x = -e[4], q2y = -e[5];  // corner 1 and 2 minus corner 0
    const float u1x = w1.u - w0.u, u1y = w1.v - w0.v, u2x = w2.u - w0.u, u2y = w2.v - w0.v;
    const float a = u1x * q2y - u2x * q1y, b = u2x * q1x - u1x * q2x;
    const float c = u1y * q2y - u2y * q1y, d = u2y * q1x - u1y * q2x;
    const float x = a + d, y = c - b;
    const float n = std::sqrt(x * x + y * y);
    if (reweight) {
      constexpr float kCap = 10.f;  // inverted or collapsed: weigh as 10x the bound
      const float half_inv = 0.5f * frame_[i].inv;
      const float fx = a - d, fy = c + b;
      const float qn = n * half_inv, rn = std::sqrt(fx * fx + fy * fy) * half_inv;
      const float sigma_min = qn - rn;
      const float distortion = sigma_min > 1e-6f ? std::min(std::max(qn + rn - 1.f, 1.f / sigma_min - 1.f), kCap) : kCap;
      const float ratio = distortion / bound_;
      last_max_ = std::max(last_max_, ratio);
      weight_[i] *= 1.f + ratio * ratio;
    }
    const float wt = weight_[i];
    rotation_[2 * i] = n > 0.f ? wt * x / n : wt;
    rotation_[2 * i + 1] = n > 0.f ? wt * y / n : 0.f;
  }

  struct Term {
    uint32_t face, a, b;  // moving face, its other two corners' wedges (local ids)
    float x, y;           // frame vector a -> corner plus b -> corner, pixels
  };

  const MappingInput& in_;
  Atlas& atlas_;
  const ProgressCallback& progress_;  // share of the queue done (it grows as zips queue more)
  const uint32_t* opposite_ = nullptr;
  const uint32_t* indices_ = nullptr;
  const float* local_ = nullptr;
  float* uv_ = nullptr;
  const uint8_t* seam_flags_ = nullptr;
  float scale_ = 1.f, bound_ = 0.f;
  int max_rings_ = kMinRings;
  float last_max_ = 0.f;
  std::vector<uint32_t> wedge_;       // per corner: its wedge id
  std::vector<uint32_t> wedge_size_;  // per wedge id: corners
  std::vector<uint32_t> vertex_start_, vertex_corners_;  // corners around each vertex (CSR)
  // Scratch of one relaxation, reused (no allocation per zip once warm).
  uint32_t stamp_ = 0;
  std::vector<uint32_t> face_stamp_, wedge_stamp_, wedge_local_;
  std::vector<uint32_t> region_, moving_;  // faces within the rings; those with a free corner
  std::vector<Change> changed_;
  std::vector<Merge> merges_;
  std::vector<Wedge> wedges_;
  std::vector<float> rotation_, saved_;
  std::vector<uint32_t> face_wedge_, wedge_start_, fill_;
  std::vector<Term> terms_;
  std::vector<float> face_edge_, weight_;
  std::vector<StretchFrame> frame_;
};

}  // namespace

Status close_cracks(const MappingInput& input, const ProgressCallback& progress, Atlas& atlas, uint64_t& zipped) {
  CrackCloser closer(input, atlas, progress);
  return closer.run(zipped);
}

}  // namespace tailor::internal
