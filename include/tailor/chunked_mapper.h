// tailor: a mapping kept chunk by chunk, for streamed worlds and editing (the chunked engine's API,
// tailor/chunks.h).
//
// A client that loads a world piece by piece maps each chunk as it arrives and drops it when it
// leaves; an editor remaps only the chunks an edit touched. A chunk's UVs depend on its own faces
// only (its frame is its cell, the texel density is the mapper's), so they are the same bits as
// map_texture gives that chunk inside the whole mesh with the same options, cell and density,
// and setting, replacing or removing one chunk changes no other.
//
//   ChunkedMapper mapper(options, /*cell_exponent=*/4, /*texels_per_unit=*/512);
//   mapper.set_mesh(tile);                  // every chunk the tile touches, in parallel
//   mapper.set_chunk({1, 0, 2}, edited);    // one chunk replaced: the others keep their bits
//   const ChunkResult* r = mapper.chunk({1, 0, 2});
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "tailor/api.h"
#include "tailor/chunks.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/status.h"

namespace tailor {

//! The integer coordinates of a chunk's cell: the cell spans [x, x+1) * cell side on x, and so on.
using ChunkCell = std::array<int32_t, 3>;

//! One chunk's mapping.
struct ChunkResult {
  std::vector<uint32_t> faces;   //!< the chunk's faces: ids in the mesh given to set_chunk / set_mesh
  std::vector<float> corner_uv;  //!< #faces * 3 by 2: per corner of those faces (in their corner order), pixels
  std::vector<uint32_t> patch;   //!< #faces: patch ids of this chunk, 0..patch_count-1
  uint32_t patch_count = 0;
  MappingStats stats;  //!< the chunk's mapping counters (set_chunk; set_mesh sums them in its own map only)
};

class TAILOR_API ChunkedMapper {
 public:
  //! Chunks of side 2^cell_exponent world units (-60..60), mapped with `options` (of its chunk
  //! options only split_above is used: a cell holding more faces is mapped in parts, as map_texture
  //! does; its progress callbacks are not used) at texels_per_unit texture pixels per world unit.
  ChunkedMapper(const MapTextureOptions& options, int cell_exponent, double texels_per_unit);

  //! kInvalidArgument when the exponent, the density (positive, finite, and 1e-3..1e7 pixels per
  //! cell side) or the mapping options are out of range; every other call fails the same way. O(1).
  Status check() const;

  //! Maps `faces` as the chunk of `cell`, replacing what the chunk held: every face's centroid must
  //! lie in the cell (kInvalidArgument naming the first that does not); the mesh's seam_faces, when
  //! present, are its seam flags. Fails as map_texture does; the chunk is then left as it was.
  //! Time: map_texture on the chunk, on the calling thread (its own stages use options.mapping.threads).
  Status set_chunk(const ChunkCell& cell, const Mesh& faces);

  //! Cuts `mesh` by the chunk rule with this mapper's cell and sets every chunk it touches, mapped in
  //! parallel as map_texture does; `cells` (optional) gets them in cell order (z, y, x). Nothing is
  //! changed when it fails.
  Status set_mesh(const Mesh& mesh, std::vector<ChunkCell>* cells = nullptr);

  //! Drops a chunk; false when it held nothing (as a cell 2^20 or more from the origin always does).
  bool remove_chunk(const ChunkCell& cell);

  //! The chunk's mapping, or nullptr when it holds nothing (as a cell 2^20 or more from the origin
  //! always does). Valid until that chunk is set or removed.
  const ChunkResult* chunk(const ChunkCell& cell) const;

  //! The cells that hold a chunk, in cell order.
  std::vector<ChunkCell> cells() const;

  double cell_size() const { return cell_size_; }
  double texels_per_unit() const { return texels_per_unit_; }
  //! Corners farther than this from every face of a chunk that was set again keep their UVs: the
  //! cell's diagonal plus twice `longest_edge` (the longest edge of the faces mapped).
  double locality_radius(double longest_edge) const { return cell_size_ * 1.7320508075688772 + 2.0 * longest_edge; }

 private:
  MapTextureOptions options_;
  int cell_exponent_;
  double cell_size_;
  double texels_per_unit_;
  std::unordered_map<uint64_t, ChunkResult> chunks_;  // by packed cell; one entry per chunk, not per face
};

}  // namespace tailor
