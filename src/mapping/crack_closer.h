// One zip of the crack closing (close_cracks.cpp schedules them), and the state the zips share.
//
// A zip merges the two UVs a vertex has on the two sides of a crack edge that ends at a shared
// vertex (the tip), then relaxes the free UVs of the faces within a few rings of it by local-global
// ARAP iterations (per face the nearest rotation of its Jacobian, per UV vertex the mean of the
// positions its faces predict); the UVs on the ring's edge stay fixed, so nothing outside changes.
// It is kept only if every face it touched is within the bounds (max_stretch, and an area ratio
// near 1), else undone: every face stays within max_stretch, no face inverts, and each kept zip
// removes at least one seam edge. The relaxation's local and global steps are the kernels of
// arap_kernels.h.
//
// Cost: the horse (97k faces) runs ~7,500 relaxations of ~70 moving faces and ~10 iterations each.
// The local step (fit_rotations) takes four faces per instruction and the global step (sweep) u
// and v side by side (SSE2), each bit-identical to its scalar twin; per relaxation the buffers
// only grow, and what a face needs in every relaxation (its zero-area test) is computed once.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mapping/arap_kernels.h"
#include "mapping/face_stretch.h"
#include "mapping/mapping_common.h"
#include "util/huge_pages.h"

namespace tailor::internal {

// Tuned on the shared meshes (bunny, horse, spot, chinese-dragon; docs/mapping.md section 2):
// A gap wider than its crack edge is more than a region of 16 rings absorbs within the bound
// (< 1 % of those zips passed): left without trying.
inline constexpr float kMaxGapRatio = 1.f;
// The first region has crack_rings / 2 rings per unit of gap / edge length (at least kMinRings; 8
// by default); a zip that fails is tried once more with twice the rings (at most crack_rings)
// unless its distortion was beyond kEscalateAbove times the bound (then a larger region rarely
// helped: 4 % of tries). So crack_rings scales the effort: bunny 16 -> 32 rings, 4.0 -> 3.5 %
// seams for 2.2x the closing's time (docs/mapping.md).
inline constexpr int kMinRings = 2;
inline constexpr float kEscalateAbove = 1.5f;
// Local/global iterations per relaxation, stopped early once no UV moves by kSettledPx, or given
// up when the distortion after kAbortAt iterations is still beyond kEscalateAbove times the bound
// (measured on the horse: 1 % of those relaxations ended within it; saves 20 % of the time).
inline constexpr int kIterations = 12;
inline constexpr float kSettledPx = 0.05f;
inline constexpr int kAbortAt = 5;
// Reweighting: a face's weight is multiplied by 1 + x^2 after each iteration, x the larger of
// distortion / bound and area change / area bound (fit_rotations). Without it the distortion peaks
// at the zipped vertex (uniform ARAP) and 40 % fewer zips pass; without the area term 60 % of the
// failed relaxations failed on the area bound.
// A zipped face must also keep its area within 1/(1 + kAreaBound)..1 + kAreaBound of the
// surface's: the cone a zip flattens is mostly area change, and unbounded it raised the thesis
// stretch (the area ratio's variation) past 0.08 on spot. It widens in proportion to max_stretch
// above the default 0.25 (at max_stretch 4 a fixed 0.2 let 0 zips through on spot).
inline constexpr float kAreaBound = 0.2f;
// A zip at a vertex with more corners than this would relax its whole fan, once per crack edge
// there (O(valence^2): a fan of 40k faces took 48 s, one of 1e6 would never end); such vertices
// keep their cracks. Scans have valences of 4-12.
inline constexpr uint32_t kMaxZipValence = 64;

// Sets a per-face, per-corner or per-vertex array to n copies of value, on huge pages (these are
// fresh and large: in 4 KiB pages, faulting them in was 40% of the mapping's page faults).
template <typename T>
void fresh(std::vector<T>& v, size_t n, T value) {
  reserve_huge(v, n);
  v.assign(n, value);
}

// What the workers share. Each worker processes one band of seed distance at a time and reads or
// writes these only for the faces, corners and wedges of vertices near its band (see kZoneSteps
// and close_cracks): bands processed at the same time are further apart than that, so they never
// touch the same element.
struct CrackShared {
  std::vector<uint32_t> wedge;                         // per corner: its wedge id
  std::vector<uint32_t> wedge_size;                    // per wedge id: corners
  std::vector<uint32_t> vertex_start, vertex_corners;  // corners around each vertex (CSR)
  std::vector<uint8_t> zero_area;  // per face: is_zero_area_frame (a moving face is in ~6 relaxations)
  std::vector<uint32_t> face_stamp, wedge_stamp, wedge_local;  // per face / wedge id: relaxation marks
  std::vector<uint8_t> queued;                                 // per half-edge: waiting in a band's queue or an outbox
  std::vector<uint32_t> face_distance;    // per face: edge steps from its component's seed face (order)
  std::vector<uint32_t> vertex_distance;  // per vertex: edges from the nearest seed face's corners (bands)
  std::atomic<uint32_t> stamp{0};         // the last relaxation mark handed out (unique across workers)
  std::atomic<uint64_t> popped{0};        // queue entries taken, all workers
  std::atomic<bool> cancelled{false};
  const uint8_t* locked = nullptr;  // per face, or nullptr: faces no zip may move (a local update's kept faces)
};

// A crack closer per worker: zips crack edges one at a time (crack_closer.cpp), and works through
// the queue of one band of them (close_band; the seed distances that order the queues and band
// them are in close_cracks.cpp with the scheduling).
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
  void build_shared(size_t threads);

  // Crack edges are processed nearest to the component's seed first (queue key: the distance of
  // the edge's nearer face in edge steps, then the edge id). Why this order: zips overlap along a
  // crack and between neighbouring cracks, so each depends on those before it; with the seed's
  // neighbourhood first, removing part of the mesh (far from the seed, as in the stability test)
  // changes only zips processed after it (and zips beside the band boundaries that move where the
  // removal lengthens the seed distances: see close_cracks), as the growth's hop rule does for the
  // placements. (The vertex distance, coarser, leaves more ties to the edge ids, which a removal
  // renumbers: it cut the bit-identical share of the stability test from 88.8% to 72.5% on the
  // bunny.)
  uint64_t key(uint32_t e) const;

  // The band of crack edge e: the distance of its nearer vertex over the band width.
  uint32_t band_of(uint32_t e, uint32_t band_steps) const;

  // A seam edge inside one patch, not next to a user seam face (those seams were asked for).
  bool is_crack(uint32_t e) const {
    const uint32_t o = opposite_[e];
    if (o == kInvalid) return false;
    const uint32_t f = e / 3, g = o / 3;
    if (atlas_.patch[f] != atlas_.patch[g]) return false;
    if (seam_flags_ && (seam_flags_[f] || seam_flags_[g])) return false;
    if (shared_.locked && (shared_.locked[f] || shared_.locked[g])) return false;
    const EdgeCorners c = edge_corners(e);
    return wedge_[c.fa] != wedge_[c.ga] || wedge_[c.fb] != wedge_[c.gb];
  }

  // Zips the crack edges of one band (a min-heap of keys) until none is left; a zip queues the
  // crack edges around the vertices it merged (they may end there now): into `heap` when they
  // are of this band, else into `outbox` (their keys). `report`: this worker reports progress
  // (every 256 pops, the share of `initial` popped by all workers) and may cancel.
  void close_band(std::vector<uint64_t>& heap, uint32_t band, uint32_t band_steps, std::vector<uint64_t>& outbox,
                  const ProgressCallback* report, size_t initial);

  uint64_t zipped() const { return zipped_; }

 private:
  // Per face, its distance in edge steps from its component's seed face (breadth first).
  std::vector<uint32_t> face_seed_distances() const;

  // Per vertex, its distance in edges from the nearest corner of a seed face (in_.component_seeds;
  // vertices no seed reaches start their own search at 0), breadth first.
  std::vector<uint32_t> vertex_seed_distances() const;

  // === UV vertices ("wedges") ===================================================================
  // Corners around one mesh vertex that hold the same UV through a chain of faces form a wedge;
  // wedge_[c] is the id of corner c's wedge (one of its corners). Found by union-find across every
  // edge whose two faces agree on the shared corner.
  void build_wedges();
  void build_vertex_corners();

  // Corner c's UV (size_t arithmetic: 2c wraps in 32 bits beyond 2^31 corners).
  const float* uv_of(uint32_t corner) const { return uv_ + 2 * size_t{corner}; }

  bool same_uv(uint32_t a, uint32_t b) const { return uv_of(a)[0] == uv_of(b)[0] && uv_of(a)[1] == uv_of(b)[1]; }

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
  int zip(uint32_t e);

  // Joins wedge `drop` into `keep` at `vertex` (recorded in merges_ and changed_ for undo_merges).
  // Returns false if either reaches into another patch (its UV is pinned there) or holds a corner
  // of a user seam face (a zip there could close a seam the user asked for): no zip.
  bool merge(uint32_t vertex, uint32_t keep, uint32_t drop);

  // Splits the merges of the current zip again.
  void undo_merges();

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
  bool relax(uint32_t patch, int rings);
  float max_ratio() const;

  // region_: the faces of the patch within `rings` edge-steps of the merged vertices' fans, ring by
  // ring (marked in face_stamp_).
  void collect_region(uint32_t patch, int rings);

  // The wedges of the region in order of first appearance (local ids; free: every corner of the
  // wedge lies in the region) with their start UVs, then the moving faces (those with a free
  // corner) with their corners, frames and the fit's inputs. Returns false if a moving face has
  // zero area (its rotation is meaningless and its image may not invert): no relaxation.
  bool collect_moving();

  // The corners of each free wedge in the moving faces (CSR over the free wedges in local id
  // order, each wedge's in face order), each with what its prediction needs: the face's record,
  // the other two corners' UVs, and the sum of the frame vectors from them to it (the rotation is
  // linear, so one vector serves both predictions).
  void build_terms();

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

}  // namespace tailor::internal
