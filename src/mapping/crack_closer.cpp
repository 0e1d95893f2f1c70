// One zip of the crack closing (crack_closer.h): merge the two UVs of a crack vertex, relax the
// region around it with the ARAP kernels (arap_kernels.h), keep it only within the bounds.
#include "mapping/crack_closer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "mapping/arap_kernels.h"
#include "mapping/face_stretch.h"
#include "util/union_find.h"

namespace tailor::internal {
namespace {

// Grows a scratch buffer to at least n elements (never shrinks: no refill when a smaller region
// comes before a larger one) and returns its data.
template <typename T>
T* scratch(std::vector<T>& v, size_t n) {
  if (v.size() < n) v.resize(n);
  return v.data();
}

}  // namespace

// === UV vertices ("wedges") =====================================================================
void CrackCloser::build_wedges() {
  const uint32_t corners = static_cast<uint32_t>(3 * in_.mesh.face_count());
  fresh(wedge_, corners, 0u);
  for (uint32_t c = 0; c < corners; ++c) wedge_[c] = c;
  auto find = [this](uint32_t c) { return find_root(wedge_.data(), c); };
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

void CrackCloser::build_vertex_corners() {
  const size_t vertex_count = in_.mesh.vertex_count();
  const uint32_t corners = static_cast<uint32_t>(3 * in_.mesh.face_count());
  fresh(vertex_start_, vertex_count + 1, 0u);
  for (uint32_t c = 0; c < corners; ++c) ++vertex_start_[indices_[c] + 1];
  for (size_t v = 0; v < vertex_count; ++v) vertex_start_[v + 1] += vertex_start_[v];
  fresh(vertex_corners_, corners, 0u);
  std::vector<uint32_t> fill(vertex_start_.begin(), vertex_start_.end() - 1);
  for (uint32_t c = 0; c < corners; ++c) vertex_corners_[fill[indices_[c]]++] = c;
}

// === Zips ========================================================================================
int CrackCloser::zip(uint32_t e) {
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

bool CrackCloser::merge(uint32_t vertex, uint32_t keep, uint32_t drop) {
  const Merge m{
      vertex, keep, drop, {0.5f * (uv_of(keep)[0] + uv_of(drop)[0]), 0.5f * (uv_of(keep)[1] + uv_of(drop)[1])}};
  const uint32_t patch = atlas_.patch[keep / 3];
  bool inside = true;
  for (uint32_t j = vertex_start_[vertex]; j < vertex_start_[vertex + 1]; ++j) {
    const uint32_t corner = vertex_corners_[j];
    const uint32_t w = wedge_[corner];
    if (w != keep && w != drop) continue;
    inside = inside && atlas_.patch[corner / 3] == patch && !(seam_flags_ && seam_flags_[corner / 3]) &&
             !(shared_.locked && shared_.locked[corner / 3]);
    if (w != drop) continue;
    wedge_[corner] = keep;
    changed_.push_back(Change{corner, drop});
  }
  wedge_size_[keep] += wedge_size_[drop];
  merges_.push_back(m);
  return inside;
}

void CrackCloser::undo_merges() {
  for (size_t i = changed_.size(); i-- > 0;) wedge_[changed_[i].corner] = changed_[i].wedge;
  for (size_t i = merges_.size(); i-- > 0;) wedge_size_[merges_[i].keep] -= wedge_size_[merges_[i].drop];
  changed_.clear();
  merges_.clear();
}

bool CrackCloser::relax(uint32_t patch, int rings) {
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
      fit_rotations<false>(moving, bound_, area_bound_, corner_pos, pos, fit_frame, weight, ratio, record);
    else
      fit_rotations<true>(moving, bound_, area_bound_, corner_pos, pos, fit_frame, weight, ratio, record);
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

float CrackCloser::max_ratio() const {
  float m = 0.f;
  for (size_t i = 0; i < moving_.size(); ++i) m = std::max(m, ratio_[i]);
  return m;
}

void CrackCloser::collect_region(uint32_t patch, int rings) {
  const uint32_t* const face_patch = atlas_.patch.data();
  uint32_t* const face_stamp = face_stamp_.data();
  const uint32_t stamp = stamp_;
  // Locked faces are left out like other patches' faces: their wedges then stay fixed.
  const uint8_t* const locked = shared_.locked;
  region_.clear();
  for (const Merge& m : merges_) {
    for (uint32_t i = vertex_start_[m.vertex]; i < vertex_start_[m.vertex + 1]; ++i) {
      const uint32_t f = vertex_corners_[i] / 3;
      if (face_patch[f] == patch && face_stamp[f] != stamp && !(locked && locked[f])) {
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
      if (face_stamp[g] == stamp || face_patch[g] != patch || (locked && locked[g])) return;
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

bool CrackCloser::collect_moving() {
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

void CrackCloser::build_terms() {
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

}  // namespace tailor::internal
