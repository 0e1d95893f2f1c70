// One chunk in canonical form (map_chunks.cpp maps it): its faces sorted by the Morton key of
// their centroid in the cell (then by their corners' coordinates), each face starting at its
// lexicographically smallest corner, its vertices numbered by first use. The mapping breaks every
// tie by ids (front keys, seed distances, sums over vertices), so a chunk's UVs are then a
// function of its geometry and connectivity alone, whatever order the file had.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "tailor/chunks.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"

namespace tailor::internal {

//! One face of a chunk in canonical form: its sort key, its id in the source mesh, the corner it
//! starts at (chunk corner k is source corner (rotation + k) % 3).
struct ChunkFace {
  uint64_t morton;
  uint32_t face;
  uint32_t rotation;
};

//! Source vertex id -> chunk vertex id, for one chunk at a time (open addressing, cleared by
//! stamping: no reallocation once it has grown to the largest chunk).
class VertexTable {
 public:
  //! Empties the table for about `expected` vertices (it grows past them when needed).
  void reset(size_t expected);
  //! The chunk id of source vertex v; `next` (then incremented) when v is new, with added = true.
  uint32_t find_or_add(uint32_t v, uint32_t& next, bool& added);

 private:
  static size_t slot(uint32_t v, size_t mask) { return (uint64_t{v} * 0x9E3779B97F4A7C15ull >> 20) & mask; }
  void grow();
  std::vector<uint32_t> keys_, values_, stamps_;
  uint32_t stamp_ = 0;
  size_t size_ = 0;
};

//! What one worker reuses from chunk to chunk.
struct ChunkWorker {
  std::vector<ChunkFace> faces;    //!< the chunk's faces in canonical order
  std::vector<ChunkFace> sorting;  //!< scratch of the radix sort
  VertexTable vertices;
  Mesh mesh;  //!< the chunk's canonical mesh
  std::vector<uint8_t> seam_flags;
  TextureMap map;  //!< the chunk's mapping, in canonical order
};

//! Builds the canonical mesh of the faces `faces` of `mesh` into w.mesh, w.faces and w.seam_flags
//! (when seam_faces is not empty). Their centroids lie in the cube of side `size` at `origin` (a
//! chunk's cell, or the whole mesh's bounding box): the Morton keys are taken there.
void build_chunk_mesh(const Mesh& mesh, std::span<const uint32_t> faces, const std::array<double, 3>& origin,
                      double size, std::span<const uint8_t> seam_faces, ChunkWorker& w);

//! Writes the chunk's UVs and patches (w.map.atlas, canonical order) back to the faces they came
//! from: chunk corner k of face i is corner (rotation + k) % 3 of face w.faces[i].face, its patch id
//! first_patch + the chunk's. `corner_uv` holds 6 floats and `patch` one id per source face.
void write_chunk_atlas(const ChunkWorker& w, uint32_t first_patch, float* corner_uv, uint32_t* patch);

//! Adds one chunk's mapping counters and stage times to `total` (counts summed, maxima kept).
//! Defined in map_chunks.cpp.
void add_stats(const MappingStats& s, MappingStats& total);

//! Maps a whole mesh (not cut into chunks) in canonical form, so that the same surface in any
//! file order gets the same UVs: build_chunk_mesh over its bounding box, map_texture on that (its
//! own normalisation, as the mesh's), then the atlas and the frames back to the mesh's faces and
//! corners (a rotated face's local corners re-expressed from its own corner 0). Defined in
//! map_chunks.cpp.
Status map_whole_canonical(const Mesh& mesh, const MapTextureOptions& options, TextureMap& map);

//! The options a chunk is mapped with (map_chunk; the edit session's local updates inside a chunk
//! too): its box's frame (origin at its corner, ChunkPlan::chunk_origin; unit its side,
//! chunk_size), texels_per_unit times the side as its scale, no chunks, metrics or progress, no
//! seam faces (the caller sets the chunk's own).
MapTextureOptions chunk_map_options(const MapTextureOptions& options, const std::array<double, 3>& origin, double size,
                                    double texels_per_unit);

//! Maps the chunk built in w (build_chunk_mesh) by map_texture with `options` (no metrics): its
//! frame is its box's (origin at its corner, unit its side), its density texels_per_unit, `threads`
//! for its own stages, `progress` its share (optional). Results in w.map, in w's canonical order.
//! Defined in map_chunks.cpp.
Status map_chunk(const MapTextureOptions& options, const std::array<double, 3>& origin, double size,
                 double texels_per_unit, uint32_t threads, ProgressCallback progress, ChunkWorker& w);

}  // namespace tailor::internal
