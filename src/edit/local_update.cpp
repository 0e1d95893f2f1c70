// The fast local update of an EditSession (local_update.h).
#include "edit/local_update.h"

#include <algorithm>
#include <cstring>

#include "mapping/mapping_common.h"
#include "surface/stroke_field.h"
#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

// The region reaches this many edge rings beyond the edited faces (and no further than the
// patches they touch and their neighbours): enough for the growth to route around a brush of
// seam faces. Without the limit the region was the whole patch: 89% of nefertiti's faces for a
// 60-face brush, since its main patch covers most of it.
constexpr uint32_t kRegionRings = 24;

// Crack closing in the region needs its setup over the whole mesh (wedges, seed distances): 12 ms
// of CPU at 100k faces, 270 ms at 1.55 M (bench/bench_edit.cpp). Above this many faces the local
// update leaves the region's cracks to the settle, so that an edit stays near 0.1 s.
constexpr size_t kMaxClosingFaces = 500000;

}  // namespace

Status map_keeping_setup(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options, TextureMap& map,
                         LocalUpdate& local) {
  local.ready = false;
  MapTextureOptions o = options;
  o.measure = false;  // the session shows no metrics (the atlas does not depend on them)
  // The full map is map_texture's (the whole mesh in canonical order, as `tailor map --chunks off`
  // gives it: the local updates work at the whole mesh's texel density); the frames and the setup
  // the local updates need are then computed in the session's own order.
  o.chunks.mode = ChunkMode::kOff;
  TAILOR_RETURN_IF_ERROR(map_texture(mesh, topology, o, map));
  TAILOR_RETURN_IF_ERROR(compute_orientation_setup(mesh, topology, o.orientation, map.frames, &local.setup));
  local.seeds = component_seed_faces(mesh, topology, map.frames, o.mapping);
  local.region.assign(mesh.face_count(), 0);
  local.ring.resize(mesh.face_count());
  local.ready = true;
  return Status::ok();
}

bool can_update_locally(const MapTextureOptions& options, const LocalUpdate& local) {
  return local.ready && options.mapping.mode == MappingMode::kPatches && options.mapping.symmetry == 1 &&
         options.orientation.smooth_passes == 0;
}

void refresh_stroke_frames(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                           std::span<const OrientationStroke> changed_strokes, TextureMap& map, LocalUpdate& local,
                           std::vector<uint32_t>& affected) {
  affected.clear();
  const StrokeField field(changed_strokes);
  if (field.empty()) return;
  // Faces whose centroid a changed stroke reaches: one grid lookup per face (threads: fixed chunks,
  // each face's flag written by its chunk; the list is then made in face order).
  const size_t face_count = mesh.face_count();
  std::vector<uint8_t>& reached = local.region;  // zero between edits; cleared again below
  const float* pos = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();
  for_each_chunk(face_count, parallel_threads(face_count, options.orientation.threads),
                 [&](size_t begin, size_t end, size_t) {
                   for (size_t f = begin; f < end; ++f) {
                     double q[3] = {0, 0, 0};
                     for (int k = 0; k < 3; ++k)
                       for (int c = 0; c < 3; ++c) q[c] += pos[3 * size_t{idx[3 * f + k]} + c];
                     for (double& x : q) x /= 3;
                     double direction[3];
                     reached[f] = field.sample(q, direction) > 0 ? 1 : 0;
                   }
                 });
  for (uint32_t f = 0; f < face_count; ++f)
    if (reached[f]) affected.push_back(f), reached[f] = 0;
  refresh_face_frames(mesh, topology, options.orientation, local.setup, affected, map.frames);
}

Status update_region(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                     std::span<const uint32_t> flipped, std::span<const uint32_t> affected, TextureMap& map,
                     LocalUpdate& local, uint32_t& changed_faces) {
  changed_faces = 0;
  const size_t face_count = mesh.face_count();
  Atlas& atlas = map.atlas;
  // === The region: touched patches, then the patches across their borders ===
  std::vector<uint8_t>& mark = local.patch_mark;  // per patch: 1 touched, 2 bordering
  mark.assign(atlas.patch_count, 0);
  bool any = false;
  for (const std::span<const uint32_t> list : {flipped, affected})
    for (const uint32_t f : list) mark[atlas.patch[f]] = 1, any = true;
  if (!any) return Status::ok();
  const uint32_t* opposite = topology.opposite.data();
  for (size_t f = 0; f < face_count; ++f) {
    if (mark[atlas.patch[f]] != 1) continue;
    for (size_t e = 3 * f; e < 3 * f + 3; ++e) {
      if (opposite[e] == kInvalid) continue;
      uint8_t& m = mark[atlas.patch[opposite[e] / 3]];
      if (m == 0) m = 2;
    }
  }
  // ... within kRegionRings edge rings of the edited faces (breadth first from them, in the
  // order given, so the region does not depend on anything but the edit and the atlas).
  std::vector<uint8_t>& region = local.region;
  std::vector<uint32_t>& faces = local.faces;
  std::vector<uint32_t>& ring = local.ring;
  faces.clear();
  for (const std::span<const uint32_t> list : {flipped, affected})
    for (const uint32_t f : list)
      if (!region[f]) region[f] = 1, ring[f] = 0, faces.push_back(f);
  for (size_t head = 0; head < faces.size(); ++head) {
    const uint32_t f = faces[head];
    if (ring[f] == kRegionRings) continue;
    for (size_t e = 3 * size_t{f}; e < 3 * size_t{f} + 3; ++e) {
      if (opposite[e] == kInvalid) continue;
      const uint32_t g = opposite[e] / 3;
      if (region[g] || !mark[atlas.patch[g]]) continue;
      region[g] = 1;
      ring[g] = ring[f] + 1;
      faces.push_back(g);
    }
  }
  std::sort(faces.begin(), faces.end());
  // The region's UVs and patches before, to count what changed.
  std::vector<float> old_uv(6 * faces.size());
  std::vector<uint32_t> old_patch(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    std::memcpy(&old_uv[6 * i], &atlas.corner_uv[6 * size_t{faces[i]}], 6 * sizeof(float));
    old_patch[i] = atlas.patch[faces[i]];
  }

  // === Growth of the region, then its seams shortened and its cracks closed (the other faces
  // locked: they never move, and cracks next to them stay) ===
  const internal::MappingInput input{
      mesh, topology, map.frames, options.mapping, factor_step_for(options.mapping, face_count), local.seeds};
  MappingStats stats;
  Status status = regrow_patches(input, region, atlas, stats, local.on_seam);
  std::vector<uint8_t>& locked = local.locked;
  locked.resize(face_count);
  for (size_t f = 0; f < face_count; ++f) locked[f] = region[f] ^ 1;
  if (status.is_ok() && options.mapping.shorten_seams) shorten_seams(input, local.on_seam, atlas, locked);
  if (status.is_ok() && options.mapping.close_cracks && face_count <= kMaxClosingFaces) {
    // One thread: a region's zips are few, starting workers cost more (the result is the same).
    MappingOptions one_thread = options.mapping;
    one_thread.threads = 1;
    const internal::MappingInput closing{mesh, topology, map.frames, one_thread, input.factor_step, local.seeds};
    uint64_t zipped = 0;
    status = close_cracks(closing, nullptr, atlas, zipped, locked);
  }
  for (const uint32_t f : faces) region[f] = 0;
  TAILOR_RETURN_IF_ERROR(status);
  for (size_t i = 0; i < faces.size(); ++i) {
    const uint32_t f = faces[i];
    changed_faces +=
        same_face_bits(atlas.patch[f], &atlas.corner_uv[6 * size_t{f}], old_patch[i], &old_uv[6 * i]) ? 0u : 1u;
  }
  return Status::ok();
}

}  // namespace tailor::internal
