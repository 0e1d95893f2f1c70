// Shared pieces of the mapping stages (map_texture.cpp runs them in order; grow_patches.cpp,
// shorten_seams.cpp, close_cracks.cpp and thesis_mode.cpp implement them): the front key layout,
// the inputs, the stage functions.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "tailor/atlas.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/metrics.h"
#include "tailor/orientation.h"
#include "tailor/topology.h"

namespace tailor::internal {

// Corner k of a face: the next and previous corner (its edges are k -> kNext[k]).
inline constexpr int kNext[3] = {1, 2, 0};
inline constexpr int kPrev[3] = {2, 0, 1};

// === Front key =================================================================================
// One uint64, smaller = sooner:
//   bits 62-63  class: 0 waiting, 1 deferred (failed since its neighbourhood last changed),
//               2 user seam face (processed after everything else of the component)
//   bits 60-61  3 - placed edge neighbours (thesis queues 3, 2, 1, 0)
//   bits 32-59  age: the top 28 bits of the float's bit pattern (non-negative floats order like
//               their bits; dropping 3 mantissa bits keeps ~1e-6 relative precision)
//   bits 0-31   face id (unique keys, ties broken by face id)
enum FrontClass : uint64_t { kWaiting = 0, kDeferred = 1, kSeam = 2 };

inline uint64_t front_key(uint64_t front_class, uint32_t placed_neighbours, float age, uint32_t face) {
  const uint32_t rank = placed_neighbours >= 3 ? 0u : 3u - placed_neighbours;
  uint32_t bits = std::bit_cast<uint32_t>(age > 0.f ? age : 0.f);  // also maps NaN to 0
  bits = (bits >> 3) & 0x0FFFFFFFu;
  return (front_class << 62) | (uint64_t{rank} << 60) | (uint64_t{bits} << 32) | face;
}
inline uint64_t front_class(uint64_t key) { return key >> 62; }
inline uint64_t with_class(uint64_t key, uint64_t front_class) {
  return (key & ~(uint64_t{3} << 62)) | (front_class << 62);
}

// === Inputs shared by both modes ===============================================================
struct MappingInput {
  const Mesh& mesh;
  const Topology& topology;
  const FaceFrames& frames;
  const MappingOptions& options;
  double factor_step;                     // resolved for the mode; < 0 in kPatches = the hop rule
  std::vector<uint32_t> component_seeds;  // first face of each component, in processing order
};

//! The texture's lattice as the metrics measure seams on it (docs/metrics.md): its width and height
//! (MappingOptions::texture_period_px, texture_period_v_px) and symmetry.
inline MetricsOptions lattice_of(const MappingOptions& options) {
  MetricsOptions lattice;
  lattice.symmetry = options.symmetry;
  lattice.texture_width_px = options.texture_period_px;
  lattice.texture_height_px =
      options.texture_period_v_px > 0.f ? options.texture_period_v_px : options.texture_period_px;
  return lattice;
}

//! Steps 1-6 of map_texture on the mesh in the order given (the faces' and vertices' ids break the
//! mapping's ties): the orientation into map.frames, then map_texture_frames. map_texture runs it on
//! a canonical copy of the mesh or of each chunk (chunk_mesh.h).
Status map_texture_in_order(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                            TextureMap& map);

//! Steps 2-6 of map_texture on frames already in map.frames (computed by compute_orientation with
//! options.orientation): map_texture is compute_orientation then this, so the same bits.
Status map_texture_frames(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                          TextureMap& map);

//! The chunked engine (map_chunks.cpp): steps 1-4 of map_texture on each chunk of the chunk rule
//! (ChunkPlan), in parallel, written back to the mesh's corners; map.frames stays empty and
//! map.stats holds the chunks' counters summed and the chunk grid's figures. plan_out (optional)
//! receives the chunk plan the faces were mapped by.
Status map_chunks(const Mesh& mesh, const MapTextureOptions& options, TextureMap& map, ChunkPlan* plan_out = nullptr);

//! The texel density the chunks are mapped at, texture pixels per world unit: options.mapping.scale
//! times the fixed normalisation when one is given, else per the longest side of the referenced
//! vertices' bounding box rounded to a power of two (0 for a mesh without extent).
double chunk_texels_per_unit(const Mesh& mesh, const MapTextureOptions& options);

//! The option values map_texture refuses (kInvalidArgument naming the first), for callers that
//! check them before they have a mesh (ChunkedMapper::check).
Status check_mapping_values(const MappingOptions& options);
//! Whether chunks of side `size` (world units) map at texels_per_unit: their scale,
//! texels_per_unit * size pixels a cell, must be in the mapping's 0.001..1e7 (kInvalidArgument
//! saying what to change otherwise).
Status check_chunk_scale(double texels_per_unit, double size);

//! The growth's age per placed face: the option, or the mode's default (MappingOptions::factor_step).
double factor_step_for(const MappingOptions& options, size_t face_count);

//! The growth of the patches mode (step 2 of map_texture): the patch-discovery front, then the
//! absorption of small patches. on_seam gets #F flags, 1 on every face placed with a seam edge
//! (and some of their neighbours): where shorten_seams looks.
Status grow_patches(const MappingInput& input, Atlas& atlas, MappingStats& stats, std::vector<uint8_t>& on_seam);
//! The growth of grow_patches restricted to the faces flagged in `region` (#F): every other face
//! keeps its UVs and patch as `atlas` has them (they are the placed faces the region grows from:
//! the front starts at the region's faces next to them, which join a bordering patch where that
//! leaves no cut, and new patches start where it does). The new patches take the ids the region's
//! former patches left free, then ids after the kept ones, so atlas.patch may skip ids; small new
//! patches are absorbed as in the growth. on_seam: as grow_patches, region faces only.
Status regrow_patches(const MappingInput& input, std::span<const uint8_t> region, Atlas& atlas, MappingStats& stats,
                      std::vector<uint8_t>& on_seam);
//! Re-places faces on seams from their neighbours where that shortens the seams and keeps them
//! within options.max_stretch (patches mode, step 3, after the growth); drops emptied patches. seam_mark:
//! #F flags, 1 on every face with a seam edge (others may be 1 too), cleared on return. Returns the
//! number of moves. Deterministic; O(F) once, then O(faces on seams) per pass, bounded passes.
//! `locked` (empty or #F): faces flagged there never move, and patches are not renumbered (ids
//! left empty stay unused).
uint64_t shorten_seams(const MappingInput& input, std::vector<uint8_t>& seam_mark, Atlas& atlas,
                       std::span<const uint8_t> locked = {});

//! Zips cracks (seam edges between two faces of one patch) shut from their tips, relaxing the UVs
//! around each zip (ARAP); a zip is kept only if every face it moved stays within
//! options.max_stretch (patches mode, step 4). zipped: the number of zipped vertices.
//! progress (may be empty) gets the share done; false cancels (kCancelled, atlas half-zipped).
//! Deterministic; O(F) setup, then O(rings^2) per crack vertex tried.
//! locked (empty or #F): faces no zip moves (their UVs stay bit for bit; cracks next to them stay).
Status close_cracks(const MappingInput& input, const ProgressCallback& progress, Atlas& atlas, uint64_t& zipped,
                    std::span<const uint8_t> locked = {});

//! Relaxes the UVs by options.relax_iterations local/global ARAP iterations (patches mode, last
//! step): every UV vertex moves except both sides of a seam less than a pixel wide and the corners
//! of zero-area faces, and only where the faces around it stay within options.max_stretch. moves:
//! the accepted UV vertex moves. The same result for any thread count; O(F) per iteration.
//! progress (optional) gets the share of iterations done after each; false stops (kCancelled).
Status relax_patches(const MappingInput& input, Atlas& atlas, uint64_t& moves, const ProgressCallback& progress = {});

Status map_thesis(const MappingInput& input, Atlas& atlas, MappingStats& stats);

//! Progress reporting cadence (placed faces between callback calls).
inline constexpr uint32_t kProgressInterval = 1u << 16;

}  // namespace tailor::internal
