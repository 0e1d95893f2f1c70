// tailor: interactive editing of a mapping (thesis 2.5 and chapter 4's texturing tool; issue 19).
//
// An EditSession holds one mesh and the state a user edits: the seam faces (faces where seams
// should go, MappingOptions::seam_faces), the orientation strokes (OrientationOptions::strokes)
// and the pipeline options. Each edit gives a new version at once by a fast local update
// (src/edit/local_update.h): the region is the faces of the patches the edit touches (a face
// whose seam flag flipped, or whose orientation a stroke added or removed changes) and of the
// patches bordering them, within 24 edge rings of the edited faces; it is grown again from the
// faces around it, its seams shortened and (meshes up to 500k faces) its cracks closed, and every
// other face keeps its UVs and patch bit for bit. The relaxation, and the cracks next to the
// faces kept, are left to settle(), so an unsettled version shows somewhat more seam in the
// region. settle() then computes the full map_texture result for the current state,
// which is byte for byte what `tailor map --seam-faces F --strokes S` gives with the same options
// (any thread count). Edits that change the options, and sessions in the thesis mode, with
// symmetry 4 or with field smoothing, map the whole mesh at each edit instead.
//
// A mesh that map_texture cuts into chunks (tailor/chunks.h: from ChunkOptions::min_faces faces
// on, or --chunks on) is edited chunk by chunk (src/edit/chunk_edit.h): an edit touches the chunks
// holding a face whose seam flag flipped or a face a stroke added or removed reaches (a stroke acts
// within its radius only), and every other chunk keeps its UVs bit for bit, settled or not. The
// touched chunks get the local update above within the chunk (in its own frame and density) and
// settle() maps only them again by the whole pipeline, which gives the fresh chunked map_texture
// bit for bit (the same for any thread count). With the thesis mode, symmetry 4 or field smoothing
// the touched chunks are mapped again at once (the version is then settled). Patch ids are
// map_texture's: each chunk's after those of the chunks before it, so a chunk whose patch count
// changed shifts the later chunks' ids (counted in changed_faces).
// Measured (bench/bench_edit.cpp, docs/performance.md): apply about 20 ms on 100k faces; on
// 1.55 M faces (chunked) 45-75 ms per seam brush or stroke on 2 busy cores, the settle the touched
// chunks' map (0.3-4 s, by their size) where the full map takes 2.5 s of CPU.
// `tailor edit` serves a session over HTTP (docs/edit-api.md).
//
// Memory: besides the mesh and one TextureMap, the UVs of the last 8 versions (24 bytes per face
// each) and the atlases of the last 8 history states and one spare (28 bytes per face each); a
// chunked session keeps no frames for the whole mesh, but the canonical form of the last 8 chunks
// it edited (about 180 bytes per face of those chunks).
//
// Thread safety: every member may be called from several threads. settle() works on a snapshot
// of the state and publishes its result only if no edit came in meanwhile (it then reports false
// in EditResult::settled and the caller settles again later); readers never wait for a settle.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "tailor/api.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/status.h"

namespace tailor {

//! One edit, every part optional. Applied in this order: options, removed then added seam faces,
//! strokes (appended to the session's strokes).
struct EditRequest {
  std::vector<uint32_t> add_seam_faces;      //!< face ids (input face order) to mark as seam faces
  std::vector<uint32_t> remove_seam_faces;   //!< face ids to unmark
  std::vector<OrientationStroke> strokes;    //!< orientation strokes to add
  std::optional<MapTextureOptions> options;  //!< replaces the pipeline options when set (its spans are
                                             //!< ignored: seam faces and strokes are the session's)
};

//! What an edit, undo, redo or settle did.
struct EditResult {
  uint64_t version = 0;        //!< the version now current (starts at 0 for the first full map)
  uint32_t changed_faces = 0;  //!< faces whose UVs or patch differ from the previous version
  double ms = 0.0;             //!< wall time of the update, milliseconds
  bool settled = false;        //!< true when the current version is the full map_texture result
};

class TAILOR_API EditSession {
 public:
  //! Maps `mesh` with `options` (a full map_texture run, version 0, settled); its seam_faces and
  //! strokes are the session's first state, its progress callback reports this first map only.
  //! The mesh must have passed finalize_mesh. Fails as check_map_options and map_texture do.
  static Status open(Mesh mesh, const MapTextureOptions& options, std::unique_ptr<EditSession>& session);

  ~EditSession();
  EditSession(const EditSession&) = delete;
  EditSession& operator=(const EditSession&) = delete;

  //! Applies an edit by a fast local update (a new version, not settled), or, when the edit
  //! changes nothing, returns the current version (changed_faces 0) without making a new one.
  //! In an unsettled version patch ids may skip numbers (atlas.patch_count is the largest id + 1).
  //! Fails with kInvalidArgument, changing nothing, on a face id out of range, a stroke with fewer
  //! than 2 points, a non-finite point or radius <= 0, or options check_map_options or
  //! map_texture refuses. New options always map the whole mesh again.
  Status apply(const EditRequest& edit, EditResult& result);

  //! Steps back / forward through the applied edits (each a new version number, with the state of
  //! the step it returns to). The UVs are bit for bit those that state last showed (its settled
  //! map when it was settled) for the last 8 states visited; older ones are updated locally.
  //! History steps store what changed (flipped seam flags, added strokes, old and new options).
  //! Fails with kInvalidArgument when there is nothing to undo / redo.
  Status undo(EditResult& result);
  Status redo(EditResult& result);

  //! Computes the full map for the current state (see the thread-safety note above). Cancelled
  //! early (result.settled false, status ok) when an edit arrives while it runs.
  Status settle(EditResult& result);

  uint64_t version() const;
  bool settled() const;

  //! Corner UVs of `version` (3 per face, input face order, in texture repeats: pixels / texture
  //! size), as float32 u, v pairs. Recent versions are kept (at least the last 8); false when
  //! `version` is unknown or no longer kept.
  bool corner_uv_repeats(uint64_t version, std::vector<float>& out) const;

  //! A copy of the current state, for export and saving: the atlas (pixels), the seam-face flags
  //! (#F), the strokes and the options (as given, with empty spans and no progress callback:
  //! set seam_faces and strokes from the other two to map the state with map_texture).
  void snapshot(Atlas& atlas, std::vector<uint8_t>& seam_faces, std::vector<OrientationStroke>& strokes,
                MapTextureOptions& options) const;

  const Mesh& mesh() const;

 private:
  EditSession();
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace tailor
