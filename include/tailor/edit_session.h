// tailor: interactive editing of a mapping (thesis 2.5 and chapter 4's texturing tool; issue 19).
//
// An EditSession holds one mesh and the state a user edits: the seam faces (faces where seams
// should go, MappingOptions::seam_faces), the orientation strokes (OrientationOptions::strokes)
// and the pipeline options. Each edit gives a new version at once by a fast local update: only
// the patches the edit touches and their neighbours are re-mapped, every other face keeps its
// UVs bit for bit. settle() then computes the full map_texture result for the current state, which
// is byte for byte what `tailor map --seam-faces F --strokes S` gives with the same options.
// `tailor edit` serves a session over HTTP (docs/edit-api.md).
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
  //! Maps `mesh` with `options` (a full map_texture run, version 0, settled). The mesh must have
  //! passed finalize_mesh. Fails as map_texture does.
  static Status open(Mesh mesh, const MapTextureOptions& options, std::unique_ptr<EditSession>& session);

  ~EditSession();
  EditSession(const EditSession&) = delete;
  EditSession& operator=(const EditSession&) = delete;

  //! Applies an edit by a fast local update (a new version, not settled unless nothing changed).
  //! Fails with kInvalidArgument, changing nothing, on a face id out of range, a stroke with fewer
  //! than 2 points, a non-finite point or radius <= 0, or options check_map_options refuses.
  Status apply(const EditRequest& edit, EditResult& result);

  //! Steps back / forward through the applied edits (each a new version number, with the state of
  //! the step it returns to; the UVs are the settled map of that state when it was settled).
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
  //! (#F), the strokes and the options.
  void snapshot(Atlas& atlas, std::vector<uint8_t>& seam_faces, std::vector<OrientationStroke>& strokes,
                MapTextureOptions& options) const;

  const Mesh& mesh() const;

 private:
  EditSession();
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace tailor
