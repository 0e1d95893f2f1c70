// An EditSession on a mesh that map_texture cuts into chunks (tailor/chunks.h): an edit changes
// only the chunks it touches, and every other chunk keeps its UVs bit for bit.
//
// A chunk's map depends on its own faces, their seam flags and the strokes that reach them, nothing
// else (the chunked engine's promise). So an edit touches the chunks holding a face whose seam flag
// flipped, or a face whose centroid a stroke added or removed reaches (a stroke's weight is 0 from
// its radius on: its reach is bounded by its capsule). Those chunks get a local update (the
// local_update.h region, in the chunk's own canonical mesh, frame and density) at once and are
// marked dirty; a settle maps each dirty chunk again by the whole pipeline (map_chunk, as the
// engine and ChunkedMapper::set_chunk do), which gives the bits a fresh map_texture of the mesh
// gives. Options the local update cannot follow (thesis mode, symmetry 4, field smoothing) map the
// touched chunks again at once.
//
// The canonical form of the 8 chunks edited last (mesh, topology, frames, atlas, seeds) is kept, so
// that painting on in the same place costs the region's update only; the chunks an edit touches
// are updated on parallel threads (each on its own form: the result is the same for any count). Patch ids: each chunk's
// after those of the chunks before it in cell order, as map_texture numbers them.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "edit/local_update.h"
#include "mapping/chunk_mesh.h"
#include "tailor/chunks.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/topology.h"

namespace tailor::internal {

//! True when map_texture with these options cuts a mesh of face_count faces into chunks.
bool session_uses_chunks(const MapTextureOptions& options, size_t face_count);

class ChunkedEdits {
 public:
  ChunkedEdits();
  ~ChunkedEdits();
  ChunkedEdits(ChunkedEdits&&) noexcept;
  ChunkedEdits& operator=(ChunkedEdits&&) noexcept;

  //! The chunk plan and texel density of `options` on the mesh (map_texture's), every chunk clean,
  //! no canonical form kept; the atlas is not touched.
  Status prepare(const Mesh& mesh, const MapTextureOptions& options);

  //! The full map of a state (`options` with its seam flags and strokes set): map_texture's atlas
  //! bit for bit (no metrics, no frames), the chunk plan and each chunk's patch count. Every chunk
  //! clean, no canonical form kept.
  Status map_all(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options, Atlas& atlas);

  //! The chunks an edit touches (ascending): those holding a face of `flipped`, or a face whose
  //! centroid a stroke of `changed_strokes` reaches (tested against the strokes grown by a
  //! thousandth of their radius, so that no face the field reaches is missed).
  std::vector<uint32_t> touched(const Mesh& mesh, std::span<const uint32_t> flipped,
                                std::span<const OrientationStroke> changed_strokes) const;

  //! After the session's seam flags flipped at `flipped` and the strokes `changed_strokes` were
  //! added or removed (`options` has the new state): the touched chunks updated in `atlas`, by a
  //! local update (then dirty) or, when the options do not allow one, mapped again (clean).
  //! changed: faces whose UVs or patch id changed (a chunk whose patch count changed shifts the
  //! ids of the chunks after it).
  Status update(const Mesh& mesh, const MapTextureOptions& options, std::span<const uint32_t> flipped,
                std::span<const OrientationStroke> changed_strokes, Atlas& atlas, uint32_t& changed);

  //! The atlas was replaced by one kept for a history state (undo, redo) whose per-chunk dirty
  //! flags and patch counts are `dirty`, `patches`; `flipped` and `changed_strokes` are what moved
  //! the state there. The kept canonical forms follow.
  void restore(const MapTextureOptions& options, std::span<const uint32_t> flipped,
               std::span<const OrientationStroke> changed_strokes, const Atlas& atlas, std::vector<uint8_t> dirty,
               std::vector<uint32_t> patches);

  //! The chunks whose UVs are a local update (ascending): what a settle maps again.
  std::vector<uint32_t> dirty_chunks() const;
  bool any_dirty() const;
  const std::vector<uint8_t>& dirty_flags() const { return dirty_; }
  const std::vector<uint32_t>& patch_counts() const { return patches_; }

  //! The plan and density (immutable: a settle maps chunks with it outside the session's lock).
  struct Layout {
    ChunkPlan plan;
    double texels_per_unit = 0;
    std::vector<uint32_t> chunk_of;  //!< #F: the face's chunk
  };
  std::shared_ptr<const Layout> layout() const { return layout_; }

  //! One chunk of `layout` mapped by the whole pipeline for the state `options` (its seam flags
  //! and strokes set) with `threads` for its stages, cancelled when `progress` says so: what
  //! map_texture gives that chunk, in its canonical order (w.faces).
  static Status map_chunk_fresh(const Layout& layout, const Mesh& mesh, const MapTextureOptions& options,
                                uint32_t chunk, uint32_t threads, ProgressCallback progress, ChunkWorker& w);

  //! Puts the maps of `chunks` (ascending) from map_chunk_fresh for the state `options` into
  //! `atlas` (each chunk clean afterwards); changed as for update.
  void adopt(const MapTextureOptions& options, std::span<const uint32_t> chunks, std::span<ChunkWorker> maps,
             Atlas& atlas, uint32_t& changed);

  size_t chunk_count() const { return layout_ ? layout_->plan.chunk_count() : 0; }

 private:
  struct Kept;
  // The kept form of a chunk (a new, empty one when there is none: build it).
  Kept* find_or_add(uint32_t chunk);
  // A form's canonical mesh, topology, frames (the state's strokes), atlas (from `atlas`) and seeds.
  Status build(const Mesh& mesh, const MapTextureOptions& options, const Atlas& atlas, Kept* k);
  void drop(uint32_t chunk);
  void trim();
  void load_atlas(Kept& k, const Atlas& atlas) const;
  void write_chunk(uint32_t chunk, const Atlas& chunk_atlas, const std::vector<ChunkFace>& faces, Atlas& atlas,
                   uint32_t& changed) const;
  void renumber(Atlas& atlas, std::span<const uint32_t> touched, uint32_t& changed);

  std::shared_ptr<const Layout> layout_;
  std::vector<uint32_t> position_;  // #F: the face's index in its chunk's canonical order (where one was built)
  std::vector<uint32_t> first_;     // #chunks + 1: first global patch id of each chunk, as the atlas numbers them
  std::vector<uint32_t> patches_;   // #chunks: each chunk's patch count (largest local id + 1)
  std::vector<uint8_t> dirty_;      // #chunks: UVs from a local update, not the chunk's map
  std::vector<std::unique_ptr<Kept>> kept_;  // canonical forms of recently edited chunks
  uint64_t clock_ = 0;
};

}  // namespace tailor::internal
