// The fast local update of an EditSession (edit_session.cpp, issue 19 point 3): after an edit,
// only the patches it touches and their neighbours are grown again; every other face keeps its
// UVs and patch bit for bit.
//
// The region: the patches holding a face whose seam flag flipped or whose orientation changed (a
// face within reach of a stroke added or removed), plus every patch sharing an edge with those.
// Its faces are grown again from the faces around it (regrow_patches), then its seams shortened
// and its cracks closed (shorten_seams and close_cracks with the other faces locked: no zip moves
// them, so cracks next to them stay). The relaxation is left to the settle (its iterations run
// over the whole mesh). The frames are updated face by face (refresh_face_frames) where strokes
// changed.
// Only in the patches mode with symmetry 1 and no field smoothing; otherwise the session maps
// the whole mesh again.
#pragma once

#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "surface/orientation_setup.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/topology.h"

namespace tailor::internal {

//! True when a face has the same patch and bit-identical corner UVs (6 floats) in two atlases: what
//! EditResult::changed_faces counts the faces that are not.
inline bool same_face_bits(uint32_t patch_a, const float* uv_a, uint32_t patch_b, const float* uv_b) {
  if (patch_a != patch_b) return false;
  for (int k = 0; k < 6; ++k)
    if (std::bit_cast<uint32_t>(uv_a[k]) != std::bit_cast<uint32_t>(uv_b[k])) return false;
  return true;
}

//! What the local update keeps between edits: the orientation's setup and the components' seeds
//! of the current frames, and scratch arrays reused by every edit.
struct LocalUpdate {
  bool ready = false;  //!< setup and seeds belong to the current frames
  OrientationSetup setup;
  std::vector<uint32_t> seeds;   //!< component_seed_faces of the current frames and options
  std::vector<uint8_t> region;   //!< #F scratch, kept zero between edits
  std::vector<uint8_t> locked;   //!< #F scratch
  std::vector<uint8_t> on_seam;  //!< #F scratch
  std::vector<uint8_t> patch_mark;
  std::vector<uint32_t> faces;  //!< scratch: region faces
  std::vector<uint32_t> ring;   //!< #F scratch: ring of a region face (valid where region is 1)

  void reset() { ready = false; }
};

//! map_texture of `options` (spans set to the state's seam flags and strokes), without metrics,
//! keeping what a later local update needs in `local`. The same atlas as map_texture.
Status map_keeping_setup(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options, TextureMap& map,
                         LocalUpdate& local);

//! Whether an edit of a state mapped with `options` can be a local update.
bool can_update_locally(const MapTextureOptions& options, const LocalUpdate& local);

//! The frames of the faces within reach of `changed_strokes` (added or removed) computed again
//! with options.orientation.strokes (the state's, after the edit); `affected` gets those faces.
void refresh_stroke_frames(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                           std::span<const OrientationStroke> changed_strokes, TextureMap& map, LocalUpdate& local,
                           std::vector<uint32_t>& affected);

//! The local update after the seam flags of `flipped` changed and the frames of `affected`
//! (refresh_stroke_frames): map.atlas is grown again in the region. changed_faces: faces whose
//! UVs or patch differ afterwards. Precondition: can_update_locally.
Status update_region(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                     std::span<const uint32_t> flipped, std::span<const uint32_t> affected, TextureMap& map,
                     LocalUpdate& local, uint32_t& changed_faces);

}  // namespace tailor::internal
