// Seam shortening, the last step of the patches mode: faces on a seam are re-placed from their
// neighbours when that makes the seams shorter and keeps the face within the stretch bound.
//
// Why: the growth cuts a face off wherever the front reaches it with disagreeing neighbours, so
// the cut lines it leaves are jagged: teeth (faces with two seam edges) and notches alternate along
// them. Once every face is placed, a tooth can often take the UVs its two neighbours on the other
// side give it; the seam then runs along its third edge instead of the two others. This is a local
// descent on total seam length: each move strictly shortens it, so the pass ends. With symmetry 4
// (after the integer-grid map) the length counted is the visible seams' only: a seam whose sides
// differ by a lattice map (quarter turns plus whole repeats) costs nothing, so invisible seams stay
// (median invisible share over the shared meshes 6.6 -> 11.7 % at scale 800, 47.6 -> 51.0 % at
// 8000; visible length within 0.02 points).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "mapping/face_stretch.h"
#include "mapping/mapping_common.h"
#include "tailor/metrics.h"

namespace tailor::internal {
namespace {

// Passes over the changed faces' neighbourhoods; each strictly shortens the seams, the cap only
// bounds the time on adversarial input (measured: 3-5 passes settle the shared meshes).
constexpr int kMaxPasses = 16;

class SeamShortener {
 public:
  SeamShortener(const MappingInput& in, Atlas& atlas) : in_(in), atlas_(atlas) {}

  //! seam_mark: per face, 1 on every face with a seam edge (others may be 1 too); cleared.
  uint64_t run(std::vector<uint8_t>& seam_mark, std::span<const uint8_t> locked) {
    locked_ = locked.empty() ? nullptr : locked.data();
    opposite_ = in_.topology.opposite.data();
    uv_ = atlas_.corner_uv.data();
    bound_ = in_.options.max_stretch;
    scale_ = in_.options.scale;
    lattice_ = lattice_of(in_.options);
    lattice_aware_ = in_.options.symmetry == 4;
    seam_flags_ = in_.options.seam_faces.empty() ? nullptr : in_.options.seam_faces.data();
    // A move must not shrink its patch under the absorption's minimum (a patch may still vanish
    // when its last face leaves): the shortening never makes tiny or single-face patches.
    min_keep_ = std::max<uint32_t>(in_.options.min_patch_faces, 2);
    patch_size_.assign(atlas_.patch_count, 0);
    for (const uint32_t p : atlas_.patch) ++patch_size_[p];
    const uint64_t moves = move_faces(seam_mark);
    if (!locked_) compact_patches();
    return moves;
  }

 private:
  // === Face moves ================================================================================
  uint64_t move_faces(std::vector<uint8_t>& queued) {
    std::vector<uint32_t> current, next;
    for (uint32_t f = 0; f < queued.size(); ++f)
      if (queued[f]) current.push_back(f);
    uint64_t moved = 0;
    for (int pass = 0; pass < kMaxPasses && !current.empty(); ++pass) {
      next.clear();
      for (const uint32_t f : current) {
        queued[f] = 0;
        // User seam faces keep the seams the user asked for.
        if (seam_flags_ && seam_flags_[f]) continue;
        if (locked_ && locked_[f]) continue;
        if (!improve(f)) continue;
        ++moved;
        for (int k = 0; k < 3; ++k) {
          const uint32_t o = opposite_[3 * f + k];
          if (o == kInvalid || queued[o / 3]) continue;
          queued[o / 3] = 1;
          next.push_back(o / 3);
        }
      }
      std::sort(next.begin(), next.end());  // face order: the result does not depend on visit order
      current.swap(next);
    }
    for (const uint32_t f : current) queued[f] = 0;  // left by the pass cap
    return moved;
  }

  float edge_length(uint32_t f, int k) const {
    const float* p = in_.mesh.positions.data();
    const uint32_t a = in_.mesh.indices[3 * f + k], b = in_.mesh.indices[3 * f + kNext[k]];
    const float dx = p[3 * b] - p[3 * a], dy = p[3 * b + 1] - p[3 * a + 1], dz = p[3 * b + 2] - p[3 * a + 2];
    return std::sqrt(dx * dx + dy * dy + dz * dz);
  }

  // Re-places f if some placement copied from its neighbours shortens the seams around it and is
  // within the bound. Candidates: two corners from the neighbour across edge k, the third from the
  // neighbour across another edge, or from f's own triangle carried along by the similarity that
  // takes its edge k onto the neighbour's.
  bool improve(uint32_t f) {
    float* own = uv_ + 6 * f;
    // The neighbours' UVs of f's edges (f's edge k runs corner k -> k+1, the neighbour's the
    // other way), read once: every candidate is compared against them.
    const float* ends[3][2] = {};
    for (int k = 0; k < 3; ++k) {
      const uint32_t o = opposite_[3 * f + k];
      if (o == kInvalid) continue;
      const float* g = uv_ + 6 * (o / 3);
      const int kk = static_cast<int>(o % 3);
      ends[k][0] = g + 2 * kNext[kk];
      ends[k][1] = g + 2 * kk;
    }
    auto seam_at = [&](const float* uv, int k) {
      if (!ends[k][0]) return false;
      const int k1 = kNext[k];
      const bool cut = uv[2 * k] != ends[k][0][0] || uv[2 * k + 1] != ends[k][0][1] || uv[2 * k1] != ends[k][1][0] ||
                       uv[2 * k1 + 1] != ends[k][1][1];
      // With symmetry 4 a seam on the lattice costs nothing: only visible seams are shortened. Not
      // with symmetry 1: there the invisible seams are mostly cracks under a pixel wide, and
      // shortening them too gives fewer visible seams and dangling ends (measured: 3.91 against 3.95 %
      // visible, 136 against 142 ends, medians over the shared meshes, gravel tile).
      return cut && !(lattice_aware_ && seam_gap_px(uv + 2 * k, uv + 2 * k1, ends[k][0], ends[k][1], lattice_) <
                                            lattice_.invisible_gap_px);
    };
    const bool seam[3] = {seam_at(own, 0), seam_at(own, 1), seam_at(own, 2)};
    const int seams = seam[0] + seam[1] + seam[2];
    if (seams == 0) return false;
    const float length[3] = {edge_length(f, 0), edge_length(f, 1), edge_length(f, 2)};
    // With one seam edge f agrees with its two other neighbours, which fix all three of its
    // corners: a move breaks at least one of those edges, so it can only pay when the seam edge is
    // the longer (the seam slides onto a shorter edge). Most faces on a seam are of this kind.
    if (seams == 1) {
      const int k = seam[0] ? 0 : seam[1] ? 1 : 2;
      if (!(length[k] > std::min(length[kNext[k]], length[kPrev[k]]))) return false;
    }
    auto seam_cost = [&](const float* uv) {
      return (seam_at(uv, 0) ? length[0] : 0.f) + (seam_at(uv, 1) ? length[1] : 0.f) +
             (seam_at(uv, 2) ? length[2] : 0.f);
    };
    const float before = seam_cost(own);
    const float* local = in_.frames.local.data() + 6 * f;
    const StretchFrame frame = stretch_frame(local, scale_);
    const bool degenerate = is_zero_area_frame(local);
    // A gain must be a whole edge (not rounding): a tenth of the shortest edge of f.
    const float min_gain = 0.1f * std::min({length[0], length[1], length[2]});

    float best[6];
    float best_gain = 0.f, best_stretch = 0.f;
    int best_edge = -1;
    // Which neighbours' patches f may join: its own always; another only if f's patch keeps at
    // least the absorption minimum and stays in one piece without f. Asked only for the edges
    // whose candidates are built (with one seam edge, that one).
    const uint32_t from = atlas_.patch[f];
    int may_leave = -1;  // -1 unknown, 0 no, 1 yes
    auto may_join = [&](int k) {
      if (atlas_.patch[opposite_[3 * f + k] / 3] == from) return true;
      if (may_leave < 0) may_leave = can_leave(f) ? 1 : 0;
      return may_leave == 1;
    };
    // Edges towards user seam faces keep their state: the seams asked for stay where they are.
    bool fixed[3] = {false, false, false};
    if (seam_flags_) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t o = opposite_[3 * f + k];
        fixed[k] = o != kInvalid && seam_flags_[o / 3];
      }
    }
    // Every candidate copies edge k from across it, so that edge is never a seam (UVs are finite):
    // only the two others are compared. Their cost is summed in the order of seam_cost (adding the
    // zero of edge k changes no bit), so gains are the same floats.
    auto consider = [&](const float* candidate, int k) {
      const int lo = k == 0 ? 1 : 0, hi = k == 2 ? 1 : 2;
      const bool seam_lo = seam_at(candidate, lo), seam_hi = seam_at(candidate, hi);
      if (seam_flags_ &&
          ((fixed[k] && seam[k]) || (fixed[lo] && seam_lo != seam[lo]) || (fixed[hi] && seam_hi != seam[hi])))
        return;
      const float gain = before - ((seam_lo ? length[lo] : 0.f) + (seam_hi ? length[hi] : 0.f));
      if (!(gain > min_gain) || gain < best_gain) return;
      const float s = degenerate ? 0.f : stretch_error(frame, candidate);
      if (!(s <= bound_)) return;
      if (gain == best_gain && best_edge >= 0 && s >= best_stretch) return;
      best_gain = gain;
      best_stretch = s;
      best_edge = k;
      std::copy(candidate, candidate + 6, best);
    };
    float candidate[6];
    for (int k = 0; k < 3; ++k) {
      if (!ends[k][0]) continue;
      // With one seam edge, only copying that edge from across it can close it: copying an edge
      // f already shares keeps the seam and at best moves one corner onto it.
      if (seams == 1 && !seam[k]) continue;
      if (!may_join(k)) continue;  // every candidate below would join that neighbour's patch
      const int ka = k, kb = kNext[k], kc = kPrev[k];
      candidate[2 * ka] = ends[k][0][0];
      candidate[2 * ka + 1] = ends[k][0][1];
      candidate[2 * kb] = ends[k][1][0];
      candidate[2 * kb + 1] = ends[k][1][1];
      // Third corner from another neighbour: edge k+1 ends at kc, edge k+2 starts at it.
      if (ends[kNext[k]][1]) {
        candidate[2 * kc] = ends[kNext[k]][1][0];
        candidate[2 * kc + 1] = ends[kNext[k]][1][1];
        consider(candidate, k);
      }
      // The same corner from the neighbour on the other side is skipped when bit-identical (always
      // so around a face with one seam edge): the same candidate cannot change the best.
      if (const float* c = ends[kPrev[k]][0];
          c && !(ends[kNext[k]][1] && std::memcmp(c, ends[kNext[k]][1], 2 * sizeof(float)) == 0)) {
        candidate[2 * kc] = c[0];
        candidate[2 * kc + 1] = c[1];
        consider(candidate, k);
      }
      // Third corner carried by the similarity own AB -> new AB (z -> a' + (z - a) w / v in
      // complex numbers, v = own B - A, w = new B - A).
      const float vx = own[2 * kb] - own[2 * ka], vy = own[2 * kb + 1] - own[2 * ka + 1];
      const float wx = candidate[2 * kb] - candidate[2 * ka], wy = candidate[2 * kb + 1] - candidate[2 * ka + 1];
      const float vv = vx * vx + vy * vy;
      if (vv > 0.f) {
        const float zx = own[2 * kc] - own[2 * ka], zy = own[2 * kc + 1] - own[2 * ka + 1];
        // (z * conj(v) * w) / |v|^2
        const float tx = zx * vx + zy * vy, ty = zy * vx - zx * vy;
        candidate[2 * kc] = candidate[2 * ka] + (tx * wx - ty * wy) / vv;
        candidate[2 * kc + 1] = candidate[2 * ka + 1] + (tx * wy + ty * wx) / vv;
        if (std::isfinite(candidate[2 * kc]) && std::isfinite(candidate[2 * kc + 1])) consider(candidate, k);
      }
    }
    if (best_edge < 0) return false;
    const uint32_t to = atlas_.patch[opposite_[3 * f + best_edge] / 3];
    if (from != to) {
      --patch_size_[from];
      ++patch_size_[to];
    }
    std::copy(best, best + 6, own);
    atlas_.patch[f] = to;
    return true;
  }

  // Whether f may leave its patch: the patch keeps at least min_keep_ faces (or vanishes with its
  // last one) and stays in one piece. A patch is edge-connected, so it can only fall apart when
  // f links two of its faces; f has at most two neighbours in the patch here (it joins another
  // patch through the third edge), and those two share f's corner between their edges: the patch
  // stays whole if the fan of faces around that corner joins them without f. This misses only
  // links through longer detours (then the move is refused, never wrongly allowed).
  bool can_leave(uint32_t f) const {
    const uint32_t from = atlas_.patch[f];
    if (patch_size_[from] != 1 && patch_size_[from] - 1 < min_keep_) return false;
    int inside[2];
    int count = 0;
    for (int k = 0; k < 3; ++k) {
      const uint32_t o = opposite_[3 * f + k];
      if (o != kInvalid && atlas_.patch[o / 3] == from) {
        if (count == 2) return false;
        inside[count++] = k;
      }
    }
    if (count < 2) return true;
    // Edges inside[0] and inside[1] share one corner of f: the end of one is the start of the other.
    const int ka = inside[0], kb = inside[1];
    const int corner = kNext[ka] == kb ? kb : ka;
    const uint32_t v = in_.mesh.indices[3 * f + corner];
    const uint32_t na = opposite_[3 * f + ka] / 3, nb = opposite_[3 * f + kb] / 3;
    if (na == nb) return true;
    // Walk the fan around v from na, away from f, through faces of the patch, until nb.
    uint32_t e = opposite_[3 * f + ka];
    for (int steps = 0; steps < 64 && e != kInvalid; ++steps) {
      const uint32_t g = e / 3;
      if (g == nb) return true;
      if (g == f || atlas_.patch[g] != from) return false;
      // g's two edges at v: edge j (v -> next) and edge j-1 (prev -> v); leave by the one not
      // entered through.
      int j = 0;
      while (j < 3 && in_.mesh.indices[3 * g + static_cast<uint32_t>(j)] != v) ++j;
      if (j == 3) return false;
      const int entered = static_cast<int>(e % 3);
      const int leave = entered == j ? kPrev[j] : j;
      e = opposite_[3 * g + static_cast<uint32_t>(leave)];
    }
    return false;
  }

  // Patches that lost all their faces are dropped; the others keep their order.
  void compact_patches() {
    std::vector<uint32_t> remap(atlas_.patch_count);
    uint32_t next = 0;
    for (size_t p = 0; p < remap.size(); ++p) remap[p] = patch_size_[p] > 0 ? next++ : kInvalid;
    if (next == atlas_.patch_count) return;
    for (uint32_t& p : atlas_.patch) p = remap[p];
    atlas_.patch_count = next;
  }

  const MappingInput& in_;
  Atlas& atlas_;
  const uint32_t* opposite_ = nullptr;
  float* uv_ = nullptr;
  const uint8_t* seam_flags_ = nullptr;  // user seam faces, or nullptr
  const uint8_t* locked_ = nullptr;      // faces that never move, or nullptr
  float bound_ = 0.f, scale_ = 1.f;
  bool lattice_aware_ = false;  // symmetry 4: seams on the lattice are free
  MetricsOptions lattice_;      // the texture's periods and symmetry, for seam_gap_px
  uint32_t min_keep_ = 2;
  std::vector<uint32_t> patch_size_;  // faces per patch, kept up to date by the moves
};

}  // namespace

uint64_t shorten_seams(const MappingInput& input, std::vector<uint8_t>& seam_mark, Atlas& atlas,
                       std::span<const uint8_t> locked) {
  SeamShortener shortener(input, atlas);
  return shortener.run(seam_mark, locked);
}

}  // namespace tailor::internal
