// tailor: quality metrics of a UV map (thesis ch. 4; Sander et al. 2001), as printed by
// `tailor eval` and by `tailor map --stats`. Exact definitions and how to read them: docs/metrics.md.
//
// Notation: for face f, a_f is its UV area (absolute, px^2), A_f its 3D area, and
// R = sum_f a_f / sum_f A_f the global scale (px^2 per unit^2). Faces with zero 3D area
// (degenerate) are skipped by every per-face metric, so no metric is ever NaN or inf; they are
// still counted in `faces` and their edges still count in the seam statistics.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "tailor/api.h"
#include "tailor/mesh.h"
#include "tailor/option_doc.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace tailor {

struct MetricsOptions {
  float texture_width_px = 512;   //!< texture period along u in pixels (> 0); the seam gap is measured modulo it
  float texture_height_px = 512;  //!< texture period along v in pixels (> 0)
  uint32_t symmetry = 1;          //!< 1, or 4 for a tile that looks the same turned by 90 degrees (up to a
                                  //!< shift; needs a square texture): a seam whose sides differ by a quarter
                                  //!< turn and a whole number of repeats is then invisible too
  float invisible_gap_px = 1.f;   //!< a seam edge whose lattice gap is below this is invisible (> 0)
  float sharp_angle_deg = 30.f;   //!< an edge is sharp when its faces' normals differ by more than this
  uint32_t threads = 0;           //!< threads (0 = one per 100k faces, at most the cores and 8); the
                                  //!< figures are identical for any count
};

//! Flags and help of the MetricsOptions a user sets (option_doc.h): `tailor eval` shows these.
inline constexpr OptionDoc kMetricsOptionDocs[] = {
    {"symmetry", "--symmetry",
     "1, or 4 for a square tile that looks the same turned by 90 degrees: seams whose sides differ by a quarter "
     "turn plus whole repeats count as invisible too (needs a square texture)"},
};

struct UvMetrics {
  size_t faces = 0;                //!< faces in the mesh (degenerate included)
  uint32_t patches = 0;            //!< distinct patch ids (given, or derived from UV connectivity)
  size_t single_face_patches = 0;  //!< patches holding exactly one face
  size_t degenerate_faces = 0;     //!< faces with no 3D area floats resolve, skipped by the per-face metrics
  double stretch = 0;  //!< thesis ch.4: coefficient of variation of r_f = a_f / A_f (population std / mean); 0 ideal
  double stretch_area_weighted = 0;  //!< same, mean and variance weighted by A_f; 0 ideal
  double distortion_deg = 0;         //!< median over faces of sum_k |angle_uv_k - angle_3d_k|, degrees; 0 ideal
  double l2_stretch = 0;             //!< Sander et al. 2001 L2 stretch times sqrt(R); 1 ideal, >= 1
  double linf_stretch = 0;           //!< Sander et al. 2001 max singular value over faces times sqrt(R); 1 ideal
  size_t flipped = 0;                //!< faces whose signed UV area has the opposite sign to the majority of their
                                     //!< patch (zero-area UV faces count as flipped; degenerate 3D faces are skipped)
  size_t zero_uv_area_faces = 0;     //!< non-degenerate faces with zero UV area (included in `flipped`,
                                     //!< excluded from l2/linf where their stretch is infinite)
  size_t seam_edges =
      0;  //!< edges of two faces (paired, or running the same way) whose faces disagree on the UV of a shared vertex
  double seam_length_ratio = 0;        //!< 3D length of seam edges / 3D length of all distinct edges
  double seam_gap_px = 0;              //!< 3D-length-weighted mean over seam edges of their lattice gap (px; see
                                       //!< seam_gap_px() below)
  double seam_invisible_ratio = 0;     //!< share of seam length whose lattice gap is < invisible_gap_px: the
                                       //!< texture continues across it (1 when there is no seam)
  double visible_seam_ratio = 0;       //!< 3D length of visible seam edges / 3D length of all distinct edges
  double visible_off_sharp_ratio = 0;  //!< the same for visible seam edges that are not sharp (dihedral angle
                                       //!< <= sharp_angle_deg): visible seams the geometry does not hide
  size_t visible_dangling_ends = 0;    //!< interior vertices with exactly 1 visible seam edge (a cut that stops)
  size_t visible_branch_points = 0;    //!< interior vertices with 3 or more visible seam edges
  double uv_scale = 0;                 //!< R: sum of UV areas / sum of 3D areas (px^2 per unit^2)
  double seconds = 0;                  //!< wall time of compute_uv_metrics
};

//! Computes all metrics of a per-corner UV map.
//! mesh: a finalized mesh (indices < #V). topology: build_topology(mesh).
//! corner_uv: #F*3 by 2, u, v in pixels (finite). patch: #F patch ids (each < #F), or empty to derive
//! them with derive_patches.
//! Fails with kInvalidArgument when the array sizes do not match, a patch id is >= #F or the texture
//! size is not positive (caller errors), and with kInvalidMesh when a UV is not finite, every face
//! has zero 3D area or every non-degenerate face has zero UV area (bad data: no scale).
//! Cost: O(F) time and memory (sort-free passes, on threads for large meshes, the median too: a
//! count of the values' top bits, then a selection within one bin). Deterministic, whatever the
//! thread count.
TAILOR_API Status compute_uv_metrics(const Mesh& mesh, const Topology& topology, std::span<const float> corner_uv,
                                     std::span<const uint32_t> patch, const MetricsOptions& options,
                                     UvMetrics& metrics);

//! Pixel UVs -> texture repeats as files store them (OBJ vt, PLY s/t, glTF TEXCOORD_0): each u times
//! 1.0 / width and v times 1.0 / height in double, cast to float, -0 written as +0: the same bits
//! export_mesh writes. uv_px: #F*3 by 2 (any count of pairs); uv_repeats gets as many. O(F).
TAILOR_API void uv_repeats_from_px(std::span<const float> uv_px, double width, double height,
                                   std::vector<float>& uv_repeats);

//! What compute_stored_uv_metrics measured the surface as.
struct StoredSurface {
  size_t welded_vertices = 0;    //!< vertices joined to others at bit-identical positions
  size_t boundary_edges = 0;     //!< of the (joined) surface: edges used by one face
  size_t nonmanifold_edges = 0;  //!< of the (joined) surface: edges used by three or more faces
};

//! The metrics of a UV map as a file holds it: what `tailor eval` reports for a file, and what
//! `tailor map` (map_texture) reports for the map it writes, so the two agree bit for bit.
//! - corner_uv: #F*3 by 2, in texture repeats as stored (uv_repeats_from_px of a map's pixels),
//!   taken by value and turned into pixels in place (u * options.texture_width_px, a float product,
//!   as a reader scales a file's repeats): move a vector in to save the copy.
//! - vertices at bit-identical positions count as one (weld_identical_positions, on a copy): readers
//!   of split files (.glb, .ply) join them, so a seam is an edge between two faces again;
//! - patches are derived from the UVs (derive_patches): a file holds no patch ids.
//! topology: build_topology(mesh), or null to build it here (it is built for the joined copy anyway).
//! surface (optional) gets the joined vertices and the edge counts of the surface measured.
//! Fails as compute_uv_metrics does. Cost: O(F) time; O(V) for the check of identical positions,
//! plus O(F) (a topology, a copy of the indices) when some are found or no topology is given.
TAILOR_API Status compute_stored_uv_metrics(const Mesh& mesh, const Topology* topology, std::vector<float> corner_uv,
                                            const MetricsOptions& options, UvMetrics& metrics,
                                            StoredSurface* surface = nullptr);

//! Lattice gap of a seam edge, in pixels: with the edge's ends a and b seen from its two faces f
//! and g (uv_fa, uv_fb, uv_ga, uv_gb: 2 floats each, pixels), d_a = uv_f(a) - uv_g(a) and
//! d_b = uv_f(b) - uv_g(b); k = the texture period (width, height) times round((d_a + d_b) / 2 /
//! period) per component; gap = max(|d_a - k|, |d_b - k|). Under a texture repeating with that period
//! the texture continues across the edge when the gap is below a pixel. With options.symmetry 4 the
//! smallest gap over g's UVs turned by 0, 90, 180 and 270 degrees. O(1).
TAILOR_API double seam_gap_px(const float* uv_fa, const float* uv_fb, const float* uv_ga, const float* uv_gb,
                              const MetricsOptions& options);

//! Seam class of every edge e (#F*3, both sides of a pair alike): 0 no seam (boundary, or the two
//! sides have identical UVs), 1 invisible seam (lattice gap < options.invisible_gap_px), 2 visible.
//! For the seam views. Preconditions as compute_uv_metrics. Cost O(F).
TAILOR_API void classify_seam_edges(const Mesh& mesh, const Topology& topology, std::span<const float> corner_uv,
                                    const MetricsOptions& options, std::vector<uint8_t>& seam_class);

//! Patches = connected components of faces joined across paired edges whose two sides have
//! bit-identical UVs at both endpoints. Fills patch (#F ids, numbered in order of lowest face) and
//! returns the count. Precondition: corner_uv has #F*3*2 floats. Cost: O(F), union-find, on
//! `threads` threads (0: one per 100k faces, at most the cores and 8; the same patches for any count).
TAILOR_API uint32_t derive_patches(const Mesh& mesh, const Topology& topology, std::span<const float> corner_uv,
                                   std::vector<uint32_t>& patch, uint32_t threads = 0);

//! Per-face area ratio (a_f / A_f) / R for heat maps: 1 = ideal, > 1 magnified, < 1 shrunk.
//! Faces with zero 3D area get 1 (neutral); when R is 0 every face gets 0. ratio gets #F values.
//! Precondition: corner_uv has #F*3*2 floats. Cost: O(F).
TAILOR_API void face_area_stretch(const Mesh& mesh, std::span<const float> corner_uv, std::vector<float>& ratio);

}  // namespace tailor
