// tailor: texture mapping by homogeneous patch discovery (thesis chapter 2, DESIGN.md section 4).
//
// map_texture runs the whole pipeline, one stage per module: 1. the orientation field
// (orientation.h), 2. the growth described below, 3. seam shortening, 4. crack closing (both in
// patches mode), 5. the metrics of the result (metrics.h).
//
// A greedy front grows over the mesh face by face. Faces waiting on the front are keyed by
// (number of placed edge neighbours, most first; then age = variation + hop_age times the face's
// path length from its component's seed, least first), so the texture spreads through regions where the orientation
// field is homogeneous and stops at faces where it varies (geometric edges, field singularities): those become seams.
// A face is placed by unfolding it across an edge from a placed neighbour's corner UVs: the two
// shared corners are copied and the third comes from a second placed neighbour, from the UV the
// patch already gave that vertex, or is the mean of the two predictions a + scale*frame(C - A)
// and b + scale*frame(C - B) (thesis eq. 2.3-2.4), whichever fits first.
//
// Two modes:
//  - kPatches (default): UVs per corner. Every placement (also faces whose three corners are
//    known from neighbours) is checked against a per-face bound on the singular values of the
//    Jacobian of the map from the face (at `scale` pixels per unit) to UV: both must lie in
//    [1/(1+max_stretch), 1+max_stretch], and the UV triangle must keep the face's orientation, so
//    no inverted or zero-area UV face is ever accepted (zero-area 3D faces excepted: their UV is
//    the degenerate image of the face). Faces that fail are deferred; when only deferred faces
//    remain, a new patch starts from the best of them, unfolded rigidly from an already placed
//    neighbour so the texture continues across that edge (seam gap 0 there). Patches smaller
//    than min_patch_faces are absorbed into a neighbour afterwards; last, faces on seams are re-placed
//    from their neighbours where that shortens the seams and stays within the bound.
//  - kThesis: the thesis as written, kept as the reference: one UV per vertex, an absolute error
//    threshold in pixels, faces with three textured vertices accepted as they are, the threshold
//    raised by threshold_step_px whenever every waiting face exceeds it. It leaves inverted faces
//    on dense meshes; MappingStats reports what it did.
//
// Seam constraints (thesis 2.5): faces flagged in seam_faces are processed after every other face
// of their component, so the seams move onto them.
// Determinism: the result depends only on the mesh, topology, frames and options (ties are broken
// by face id); no randomness, single-threaded.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "tailor/api.h"
#include "tailor/atlas.h"
#include "tailor/chunks.h"
#include "tailor/mesh.h"
#include "tailor/metrics.h"
#include "tailor/option_doc.h"
#include "tailor/orientation.h"
#include "tailor/progress.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace tailor {

enum class MappingMode {
  kPatches,  //!< per-corner UVs, bounded per-face distortion, new patch when the front is exhausted
  kThesis,   //!< per-vertex UVs, absolute threshold raised by 10 px when stuck (reference)
};

// ProgressCallback (tailor/progress.h): called now and then with progress in [0, 1]; return false
// to cancel (map_texture then returns kCancelled and leaves the atlas empty).

//! The ranges of MappingOptions' numbers, one table for every check of them: map_texture's own,
//! check_map_options (the CLI's and the Python module's words), the CLI's help, `tailor edit`'s
//! API and python3 -m tailor.tiles (tailor.MAP_LIMITS).
struct MappingLimits {
  static constexpr float min_scale = 1e-3f, max_scale = 1e7f;  //!< pixels per unit
  static constexpr float min_max_stretch = 0.01f, max_max_stretch = 4.f;
  static constexpr float max_hop_age = 1.f;  //!< radians, from 0
  static constexpr uint32_t min_crack_rings = 2, max_crack_rings = 64;
  static constexpr uint32_t max_relax_iterations = 1000;
};

//! A limit as messages and docs write it: 0.001, 4, 1e7 (printf's %g, its exponent without "+0").
TAILOR_API std::string limit_text(double value);

//! The range of `flag`, one of the options MappingLimits or OrientationLimits bound, as help texts
//! write it ("0.01 to 4", "2 to 64 rings"); "" for any other flag.
TAILOR_API std::string option_range_text(std::string_view flag);

//! `doc`'s help as the CLI and the Python module show it: the table's text, and for an option
//! MappingLimits or OrientationLimits bounds, its range from there (" (0.01 to 4)").
TAILOR_API std::string help_with_range(const OptionDoc& doc);

//! Fails with kInvalidArgument, check_map_options' message ("--max-stretch must be between 0.01
//! and 4, got 5"), when `value` is outside the range of `flag`, one of the options
//! MappingLimits or OrientationLimits bound (NaN is outside); fails too for a flag it has no range of.
TAILOR_API Status check_option_range(std::string_view flag, double value);

struct MappingOptions {
  MappingMode mode = MappingMode::kPatches;  //!< algorithm (CLI --mode patches|thesis)
  float scale = 800.f;          //!< texture pixels per unit of the mesh normalised into the unit cube (MappingLimits)
  bool use_seed_point = false;  //!< true: first face = the face whose centroid is nearest to seed_point
  std::array<float, 3> seed_point{0.f, 0.f, 0.f};  //!< mesh coordinates (not normalised); default rule when
                                                   //!< unused: the face nearest to the centre of the bounding box
  double factor_step = -1.0;  //!< age added per placed face, a global counter (radians); < 0 = mode default:
                              //!< 1/#F in kThesis (as the thesis), the hop rule below in kPatches (1e-4
                              //!< per face when hop_age is 0); >= 0 in kPatches: this counter, no hops
  float hop_age = 0.02f;      //!< kPatches: age added per face of path from the component's seed (radians,
                              //!< 0..1; 0 = use the global counter). Local, so removing part of a mesh
                              //!< leaves the growth order elsewhere unchanged (stability); larger values
                              //!< grow rounder patches (more seam), smaller follow the field's variation
  // kPatches ------------------------------------------------------------------------------------
  float max_stretch = 0.25f;           //!< per-face bound: singular values of the face->UV Jacobian (in units of
                                       //!< `scale`) must lie in [1/(1+x), 1+x] (MappingLimits). 0.25 keeps every face
                                       //!< within 25% of its length in any direction (so Sander Linf <= ~1.25)
                                       //!< and the thesis stretch under 0.08 on the shared meshes; larger values
                                       //!< give fewer seams and more distortion (docs/mapping.md)
  float max_seed_rotation_deg = 45.f;  //!< a new patch is rotated (at most this much) so that it continues its
                                       //!< neighbour's texture across the seed edge; beyond, it follows the field
                                       //!< and only the seed edge's first vertex matches (0..180)
  float field_following = 1.f;         //!< 1: every face's texture direction follows the orientation field (thesis);
                                       //!< 0: pure unfolding, the direction is set by the patch seed and drifts with
                                       //!< the surface (fewer seams, less distortion, see docs/mapping.md); 0..1
  bool shorten_seams = true;           //!< after the growth, re-place faces on seams from their neighbours where
                                       //!< that shortens the seams within the bound (jagged cuts lose their teeth:
                                       //!< 6-11% less seam length on the shared meshes, docs/mapping.md)
  bool close_cracks = true;            //!< last, zip cracks (seams inside one patch) shut from their tips, spreading
                                       //!< each gap over the faces around it within max_stretch (ARAP relaxation):
                                       //!< 23-57% less seam length on scans, mapping 3-10x slower (docs/mapping.md)
  uint32_t crack_rings = 16;  //!< effort of the crack closing (MappingLimits): the largest region a zip relaxes, in
                              //!< rings of faces around it (a first try takes crack_rings / 2 rings per unit
                              //!< of gap / edge length); more closes wider gaps and takes longer
  uint32_t relax_iterations = 10;  //!< last, local/global ARAP iterations over the UV vertices (0 = off, at most
                                   //!< 1000): median angle distortion 6.7 -> 1.8 degrees on the shared meshes for
                                   //!< ~20% more mapping time; patches and seam edges unchanged, invisible seams
                                   //!< (< 1 px) untouched, every moved face within max_stretch (docs/mapping.md)
  uint32_t threads = 0;  //!< threads: chunked, one chunk per thread (0 = one per core); whole, those of the crack
                         //!< closing, the relaxation and symmetry 4's fields (0 = one per 10k / 20k faces, at most the
                         //!< cores and 8; the growth is sequential); the result is identical for any count
  uint32_t min_patch_faces = 16;    //!< patches with fewer faces are absorbed into a neighbouring patch by rigid
                                    //!< unfolding (0 = keep all; isolated components stay whole)
  uint32_t symmetry = 1;            //!< 1: the growth above; 4 (experimental): an integer-grid map in place of
                                    //!< the growth (seam shortening, crack closing and relaxation follow), for a
                                    //!< square tile that looks the same turned by 90 degrees (4-RoSy and lattice
                                    //!< position fields, coordinates relaxed with the lattice maps held; seams
                                    //!< that are quarter turns plus whole repeats are invisible; faces keep their
                                    //!< lattice chart up to 6x max_stretch). Visible seams 1.5 % of edge length
                                    //!< when the tile repeats ~15 times across the mesh, 2.8 % at ~1.5 times
                                    //!< (docs/mapping.md). Measure it with MetricsOptions::symmetry 4 too
  float texture_period_px = 512.f;  //!< the texture's width in pixels, the lattice period in u (symmetry 4: its
                                    //!< square side): the relaxation holds seams whose sides differ by whole
                                    //!< repeats (invisible), and with symmetry 4 the seam shortening counts
                                    //!< only the visible seams
  float texture_period_v_px = 0.f;  //!< the texture's height in pixels, the period in v (0: texture_period_px)
  // kThesis -------------------------------------------------------------------------------------
  float threshold_px = 25.f;       //!< initial absolute error threshold, pixels (thesis: 25 at scale 800)
  float threshold_step_px = 10.f;  //!< added when every waiting face exceeds the threshold (thesis: 10)
  // Both ------------------------------------------------------------------------------------------
  std::span<const uint8_t> seam_faces;  //!< empty, or #F flags: 1 = user-marked seam face (deferred to the end)
  ProgressCallback progress;            //!< optional; see ProgressCallback
};

//! Flags and help of the MappingOptions a user sets (option_doc.h): the tailor CLI shows these, with
//! the defaults of a default-constructed MappingOptions.
inline constexpr OptionDoc kMappingOptionDocs[] = {
    {"mode", "--mode",
     "patches: per-corner UVs, bounded per-face stretch, no inverted face; thesis: the thesis as written, one UV "
     "per vertex (reference)"},
    {"scale", "--scale", "Texture pixels per unit of the mesh normalised into the unit cube"},
    {"max_stretch", "--max-stretch", "patches mode: per-face singular values must stay within [1/(1+x), 1+x]"},
    {"field_following", "--field-following",
     "patches mode: 1 = texture direction follows the orientation field (thesis), 0 = faces are unfolded rigidly "
     "(fewer seams, direction drifts); values between blend; auto (tailor map) = 0 for a texture without a "
     "direction (gravel, grass: 20-30% less seam), else 1 (texture_direction.h)"},
    {"min_patch_faces", "--min-patch-faces",
     "patches mode: smaller patches are absorbed into a neighbour (0 keeps all)"},
    {"hop_age", "--hop-age",
     "patches mode: growth-order age per face of path from the seed, radians; keeps the order local so "
     "removing part of a mesh changes little elsewhere; 0 = the thesis's global counter"},
    {"shorten_seams", "--no-seam-shortening",
     "patches mode: seam shortening re-places faces along the seams after the growth where that shortens them; "
     "off, the seams stay as the growth left them"},
    {"close_cracks", "--no-crack-closing",
     "patches mode: crack closing zips the cracks (cuts inside a patch) shut, last; off, the mapping is 3-10x "
     "faster with about twice the seam length"},
    {"crack_rings", "--crack-rings",
     "patches mode: effort of the crack closing, the largest region (rings of faces) a zip may relax; more "
     "closes wider cracks and takes longer. Fewest seams: --field-following 0 --crack-rings 32"},
    {"relax_iterations", "--relax-iterations",
     "patches mode: last, iterations of a local/global ARAP relaxation of the UVs (0 = off): the "
     "median angle distortion of the shared meshes falls from 6.7 to 1.8 degrees for ~20% more time; invisible "
     "seams and the per-face bound are kept"},
    {"threshold_px", "--threshold", "thesis mode: initial error threshold in pixels"},
    {"seed_point", "--seed-point",
     "X,Y,Z: start at the face nearest this point (same point = stable results when parts of the mesh are "
     "removed)"},
    {"seam_faces", "--seam-faces",
     "File of face indices (one per line) where seams should go (PLY 'seam' property also works)"},
    {"symmetry", "--symmetry",
     "1: patch discovery; 4, experimental: an integer-grid map for a square tile that looks the same turned by "
     "90 degrees (needs a square texture, e.g. from 'tailor tile --symmetry 4'): seams away from the field's "
     "cones are quarter turns plus whole repeats, invisible under such a tile. Best when the tile repeats many "
     "times across the mesh (--scale 8000: 1.5% of edge length visible vs 4.0% with 1); see docs/mapping.md"},
};

struct MappingStats {
  uint32_t patches = 0;                //!< patches in the atlas (after absorption)
  uint32_t patches_before_absorb = 0;  //!< patches grown before tiny ones were absorbed (kPatches)
  uint32_t components = 0;             //!< connected components (each has at least one patch)
  uint64_t deferrals = 0;              //!< pops that failed the bound and were put back
  uint32_t threshold_raises = 0;       //!< kThesis: times the threshold was raised
  float final_threshold_px = 0.f;      //!< kThesis: threshold at the end
  float max_error_px = 0.f;            //!< largest accepted |c_A - c_B| (two-prediction disagreement), pixels
  float max_stretch_accepted = 0.f;    //!< kPatches: largest accepted max(sigma_max - 1, 1/sigma_min - 1)
  uint64_t faces_three_textured = 0;   //!< faces accepted with all three corners already known (thesis fig. 2.4)
  uint64_t faces_unfolded = 0;         //!< faces placed from one or two known corners
  uint64_t faces_rigid = 0;            //!< kPatches: faces placed rigidly (patch seeds, absorbed faces)
  uint64_t faces_cut = 0;              //!< kPatches: faces joined across one edge while disagreeing with another
                                       //!< placed neighbour of their patch (each leaves at least one cut edge)
  uint64_t faces_reseamed = 0;         //!< kPatches: re-placements after the growth that shortened the seams (a face
                                       //!< can move more than once)
  uint64_t cracks_closed = 0;          //!< kPatches: crack vertices zipped shut (one UV where there were two)
  uint64_t relax_moves = 0;            //!< kPatches: UV vertex moves the relaxation kept (relax_iterations)
  uint64_t faces_seam = 0;             //!< faces flagged in seam_faces
  uint64_t inverted_accepted = 0;      //!< kThesis: faces accepted with a non-positive UV area (always 0 in kPatches)
  double seconds = 0.0;                //!< wall time of the growth, seam shortening and crack closing (steps 2-4);
                                       //!< chunked: of the whole per-chunk pipeline (orientation included)
  // Each stage's time, seconds: wall time when the mesh is mapped whole; in chunks, the sum over
  // the chunks (thread time: on N busy threads about N times the wall time).
  double orientation_seconds = 0.0;  //!< step 1, the orientation field
  double growth_seconds = 0.0;       //!< steps 2-3, the growth (or the integer-grid map) and seam shortening
  double closing_seconds = 0.0;      //!< step 4, the crack closing
  double relaxing_seconds = 0.0;     //!< step 5, the relaxation
  // The chunked engine (tailor/chunks.h); chunks = 0 when the mesh was mapped whole.
  uint32_t chunks = 0;         //!< chunks mapped
  double chunk_cell_size = 0;  //!< the chunk grid's cell side, world units (a power of two)
  double texels_per_unit = 0;  //!< texture pixels per world unit every chunk was mapped at
  double locality_radius = 0;  //!< world units: corners farther than this from every edited face keep
                               //!< their UVs bit for bit when the mesh is mapped again (ChunkPlan)
};

//! Seed face of every edge component: the face whose centroid is nearest to the seed point (the
//! option, or the centre of the bounding box), components ordered by that distance (then id).
TAILOR_API std::vector<uint32_t> component_seed_faces(const Mesh& mesh, const Topology& topology,
                                                      const FaceFrames& frames, const MappingOptions& options);

//! The options of the whole pipeline, one struct per stage (each with its defaults).
struct MapTextureOptions {
  OrientationOptions orientation;  //!< step 1, the orientation field
  MappingOptions mapping;          //!< steps 2-4: growth, seam shortening, crack closing (and the progress)
  MetricsOptions metrics;          //!< step 5 (the texture size, for the seam gap)
  ChunkOptions chunks;             //!< the chunked engine: whether and how the mesh is cut into chunks
  bool measure = true;             //!< false skips step 5 (TextureMap::metrics stays empty)
  //! Optional, beside mapping.progress: each stage's own progress ("orientation", "mapping" (the
  //! growth and seam shortening), "closing", "relaxing", "metrics"); return false to cancel.
  StageProgressCallback stage_progress;
};

//! What map_texture computes, stage by stage.
struct TextureMap {
  FaceFrames frames;   //!< step 1: per-face frames and the orientation field (frames.seconds: its time)
  Atlas atlas;         //!< steps 2-4: per-corner UVs in pixels and patch ids
  MappingStats stats;  //!< steps 2-4: what they did (stats.seconds: their time)
  UvMetrics metrics;   //!< step 5: quality of the atlas as a file holds it (compute_stored_uv_metrics: UVs in
                       //!< repeats, patches as the UVs join faces, not atlas.patch; metrics.seconds: its time)
};

//! Maps the texture, as `tailor map` does: 0. from options.chunks.min_faces faces on (kAuto), the
//! mesh is cut into chunks by the chunk rule (tailor/chunks.h) and each chunk runs steps 1-4 on its
//! own, in parallel (map.frames then stays empty; map.stats sums the chunks and reports the grid);
//! a smaller mesh is one piece. Either way the mesh is rebuilt in a canonical order first, so the
//! same surface in any order of faces, vertices and corners maps to the same UV bits.
//! 1. the orientation field (compute_orientation),
//! 2. the growth (patches mode: the patch-discovery front; thesis mode: the reference algorithm),
//! 3. seam shortening, 4. crack closing and relaxation (patches mode, each unless switched off),
//! 5. the metrics of the result as an exported file holds it (compute_stored_uv_metrics, unless
//! options.measure is false: `tailor eval` of the file reports the same figures). With
//! mapping.symmetry 4 the integer-grid map (experimental) takes the place of step 2.
//! Fills map.atlas: corner_uv (#F*3 by 2, pixels), patch (#F) and patch_count; every face is
//! placed and every UV is finite. Precondition: topology = build_topology(mesh); only step 5 reads
//! it, so with options.measure false it may be empty (Topology{}): a caller short of memory maps
//! first and builds the topology for measure_texture_map afterwards, when the mapping's own
//! memory is back (`tailor map` does, unless it chooses the axis).
//! Fails as compute_orientation does, then with kInvalidArgument on bad mapping options (scale <= 0
//! or non-finite, max_stretch, field_following, hop_age, crack_rings, max_seed_rotation_deg or
//! factor_step out of range, seam_faces of the wrong size, a non-finite seed point, symmetry not 1
//! or 4, symmetry 4 outside the patches mode, with texture_period_px < 1 or with faces narrower
//! on average than 2^-18 of the period at this scale: floats modulo the period), kInvalidMesh
//! when the topology does not match the mesh, kCancelled when the progress callback returns false
//! (the atlas is then empty), and as compute_stored_uv_metrics does.
//! Cost: the orientation and the metrics O(F); the growth O(F log front) time; the crack closing
//! O(F) plus, per crack vertex tried, a relaxation of O(crack_rings^2) faces (in practice 3-10x
//! the growth; vertices of valence > 64 are not zipped, so a huge fan cannot make it quadratic);
//! O(F + V) memory, allocated before the loops (the capacity of `map` is reused). Deterministic,
//! the same bits with or without SIMD and for any thread count. Safe for any mesh that passed
//! finalize_mesh (non-manifold and inconsistent edges act as boundaries).
TAILOR_API Status map_texture(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                              TextureMap& map);

//! Step 5 of map_texture alone (map_texture runs it when options.measure is true; here
//! options.measure is not read): fills map.metrics from map.atlas (progress "metrics" to
//! options.stage_progress). For a map made with options.measure false. Fails with kInvalidMesh when the topology or the
//! atlas does not match the mesh, kCancelled, and as compute_stored_uv_metrics does. Cost: O(F).
TAILOR_API Status measure_texture_map(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                                      TextureMap& map);

//! The checks `tailor map` makes on its options before any work, with its messages (the Python
//! module raises the same): symmetry 4 only in the patches mode, and every number MappingLimits
//! and OrientationLimits bound within its range (a scale below 1e-3 rounds every UV to the same
//! float; above 1e7 faces span millions of pixels), each message naming the flag. Fails with
//! kInvalidArgument. map_texture's own checks still apply. O(1).
TAILOR_API Status check_map_options(const MapTextureOptions& options);

//! The options only the patches mode reads, as their kMappingOptionDocs entries: `tailor map`, the
//! Python module and `tailor edit`'s API refuse them with the thesis mode, where they would be taken
//! and do nothing.
inline constexpr const OptionDoc* kPatchesOnlyOptions[] = {
    &option_doc(kMappingOptionDocs, "max_stretch"),     &option_doc(kMappingOptionDocs, "field_following"),
    &option_doc(kMappingOptionDocs, "min_patch_faces"), &option_doc(kMappingOptionDocs, "hop_age"),
    &option_doc(kMappingOptionDocs, "shorten_seams"),   &option_doc(kMappingOptionDocs, "close_cracks"),
    &option_doc(kMappingOptionDocs, "crack_rings"),     &option_doc(kMappingOptionDocs, "relax_iterations")};

//! Refuses an option the mode does not read, which would be taken and do nothing, by its flag
//! (the Python module raises the same): `patches_only`, the flag of the first given of
//! kPatchesOnlyOptions ("" when none), with the thesis mode; `threshold_given` (--threshold, read
//! by the thesis mode only) with the patches mode. Fails with kInvalidArgument. O(1).
TAILOR_API Status check_mode_options(MappingMode mode, std::string_view patches_only, bool threshold_given);

//! Sets what the texture's size and the thread count decide, as `tailor map` does: the lattice
//! period of symmetry 4 (texture_period_px), the metrics' texture size and symmetry, and
//! mapping.threads for the orientation and the metrics too. Fails with kInvalidArgument when a
//! size is not positive or symmetry 4 meets a texture that is not square. O(1).
TAILOR_API Status set_map_texture_size(MapTextureOptions& options, int texture_width, int texture_height);

//! The largest texture size in pixels a user may give (--texture-size of map and eval): what the
//! metrics measure in float pixels with sub-pixel gaps.
inline constexpr int kMaxTextureSize = 65536;

//! Refuses a --texture-size (the square texture assumed without a texture) that is not positive or
//! above kMaxTextureSize, as `tailor map` and the Python module do. Fails with kInvalidArgument. O(1).
TAILOR_API Status check_texture_size(int texture_size);

//! The name of a mode, "patches" or "thesis" (CLI --mode).
TAILOR_API const char* mapping_mode_name(MappingMode mode);

//! Parses "patches" or "thesis"; false for anything else.
TAILOR_API bool mapping_mode_from_name(std::string_view name, MappingMode& mode);

//! Per-face check used by kPatches and by tests: singular values of the Jacobian of the map from
//! the face's frame (corner positions `local`, 6 floats, normalised units, times `scale`) to the
//! UV triangle `uv` (6 floats, pixels). Returns max(sigma_max - 1, 1/sigma_min - 1), or +inf when
//! the UV triangle is inverted or degenerate, or the face's own triangle has no positive area. O(1).
TAILOR_API float face_stretch_error(std::span<const float, 6> local, float scale, std::span<const float, 6> uv);

}  // namespace tailor
