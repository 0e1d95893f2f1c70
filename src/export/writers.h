// Per-format writers behind export_mesh (export.cpp). export.cpp validates the inputs, splits the
// vertices and computes normals once; each writer only serialises and writes atomically.
#pragma once

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "surface/vertex_split.h"
#include "tailor/export.h"
#include "tailor/mesh.h"
#include "tailor/status.h"

namespace tailor::internal {

//! Export's progress (ExportOptions::progress): the split takes [0, kSplitShare], the writer the
//! rest, told in bytes written (at most every few MB) or in steps of its own.
class ExportProgress {
 public:
  static constexpr float kSplitShare = 0.2f;
  ExportProgress(const ProgressCallback& callback, size_t total_bytes, const std::string& path)
      : callback_(callback), total_(total_bytes), path_(path) {}
  //! The writer's own share reached, in [0, 1]; false: cancelled.
  bool reached(float done) const { return !callback_ || callback_(kSplitShare + (1.f - kSplitShare) * done); }
  //! `bytes` more written; false: cancelled.
  bool wrote(size_t bytes) {
    written_ += bytes;
    if (!callback_ || written_ < next_) return true;
    next_ = written_ + std::min(size_t{4} << 20, std::max<size_t>(total_ / 100, 1));  // every 1 % or 4 MiB
    return reached(total_ > 0 ? static_cast<float>(std::min(written_, total_)) / static_cast<float>(total_) : 1.f);
  }
  static Status cancelled(const std::string& path) {
    return Status::error(ErrorCode::kCancelled, path, "export cancelled");
  }
  Status cancelled() const { return cancelled(path_); }

 private:
  const ProgressCallback& callback_;
  size_t total_ = 0, written_ = 0, next_ = 0;
  const std::string& path_;
};

//! The faces of one scene part (Mesh::scene.parts[part]) in the split mesh: faces are sorted by
//! part and vertices split on it, so each part is a range of split vertices and of indices.
struct ExportPart {
  uint32_t part = 0;
  size_t vertex_begin = 0, vertex_end = 0;  //!< split vertices
  size_t index_begin = 0, index_end = 0;    //!< into split.indices (global vertex ids)
};

//! What every writer gets: the source mesh, its vertices split on UV with uvs in texture repeats
//! (OBJ convention, t up: see export.h), and unit normals per SOURCE vertex (#V by 3, or empty).
//! split.positions is left EMPTY: writers read mesh->positions[3 * split.xref[s]] as they stream,
//! which saves an array of 12 bytes per split vertex.
struct ExportData {
  const Mesh* mesh = nullptr;
  SplitMesh split;
  std::vector<float> normals;
  //! The file's kept attributes (Mesh::corner_attributes but NORMAL, which is `normals`, and the
  //! UV set the mapping replaces), per SOURCE vertex like `normals`; glTF writers only.
  std::vector<CornerAttribute> kept;
  //! The mapped UVs' set: TEXCOORD_<uv_set> (ExportOptions::uv_set).
  int uv_set = 0;
  //! When the mesh has kept attributes: its copy with vertices split where corners of one vertex
  //! carry different values (mesh points here).
  Mesh attribute_split;
  //! #S by 4: unit tangent xyz and handedness w per SPLIT vertex (tangent_frames.cpp); empty unless
  //! the material has a normal map and the mesh has normals.
  std::vector<float> tangents;
  //! .glb of a glTF scene (Mesh::scene not empty): the parts in order, and the scene they come
  //! from; empty / null: one part, tailor's own node and material.
  std::vector<ExportPart> parts;
  const SceneParts* scene = nullptr;
  //! The mesh with its faces sorted by part (mesh points here, or attribute_split does).
  Mesh part_sorted;
};

//! The nodes, meshes, materials, scene and asset of a .glb: `primitives` holds one primitive per
//! ExportPart (attributes and indices set) or one in all when data.parts is empty; `root` is
//! the node that carries the file's transform (up axis, quantization). gltf["materials"] must hold
//! tailor's material (add_glb_material): input materials get its maps, keeping their own properties.
void add_glb_scene(nlohmann::json& gltf, const ExportData& data, nlohmann::json root,
                   std::vector<nlohmann::json> primitives);

//! Per-vertex tangents for the split mesh (ExportData::tangents), from its UVs (split.uvs, t up)
//! and the unit normals per source vertex.
void compute_tangents(const Mesh& mesh, const SplitMesh& split, std::span<const float> normals,
                      std::vector<float>& tangents);

//! A texture file's bytes and MIME type ("image/png" or "image/jpeg", from the magic bytes).
//! Fails with kIo (unreadable) or kInvalidImage (neither PNG nor JPEG).
Status read_texture_bytes(const std::string& path, std::string& bytes, std::string& mime_type);

//! What a .glb embeds of the base colour: read_texture_bytes of options.texture_path, or nothing
//! without a texture or when options.image_uris.color names it (the file is then not read).
Status glb_base_color(const ExportOptions& options, std::string& bytes, std::string& mime_type);

//! Appends the shortest decimal text that reads back as exactly `value` (std::to_chars).
void append_float(std::string& out, float value);

//! The names of the files the writer writes in `folder`: its own (`own`) and those of `others`
//! (ExportOptions::other_outputs) that lie there. The texture's copy must not take any of them.
std::vector<std::string> names_in_folder(const std::filesystem::path& folder, const std::vector<std::string>& others,
                                         std::initializer_list<std::string> own);

//! The file name by which an output in the folder `out_dir` names the texture `texture_path` (its file's bytes:
//! `bytes`): the .mtl's map_Kd, the .ply's TextureFile. The texture lies beside the output under that name, so the
//! output folder can be moved or sent on its own. `name` is the texture's own name when the texture already lies
//! there; else `copy` is set and the writer writes `bytes` to out_dir/name (write_file_atomic, staged with its other
//! files) under the texture's name (whitespace made '_'). A file of that name beside the output holding the same
//! bytes is used as it is; one holding anything else is never replaced (another output may name it): the copy
//! takes the first of "<stem>-2<ext>", "<stem>-3<ext>"... that is free or holds the same bytes. Names in `taken`
//! (the writer's own files and the run's other outputs: names_in_folder) are skipped. Fails with kIo.
Status texture_name_beside(const std::string& texture_path, const std::string& bytes,
                           const std::filesystem::path& out_dir, std::span<const std::string> taken, std::string& name,
                           bool& copy);

//! The material every .glb gets (named "tailor", not metallic, fully rough) and its images: the
//! base colour when options.texture_path is set (`base_color`: its PNG/JPEG bytes of type
//! mime_type) and the maps of options.material, each appended to `blob` (4-byte aligned), which the
//! caller places at byte blob_offset of buffer 0, or named by its options.image_uris entry; a
//! REPEAT sampler; textures read through TEXCOORD_<uv_set>; with options.symmetry 4, the extras
//! that say the map is 4-fold.
void add_glb_material(nlohmann::json& gltf, nlohmann::json& views, size_t blob_offset, std::string& blob,
                      const std::string& base_color, const std::string& mime_type, const ExportOptions& options,
                      int uv_set);

Status write_glb(const std::string& path, const ExportData& data, const ExportOptions& options);
//! .glb with options.compression (quantize, meshopt or draco): the arrays are built in memory.
Status write_glb_compressed(const std::string& path, const ExportData& data, const ExportOptions& options);
Status write_obj(const std::string& path, const ExportData& data, const ExportOptions& options);
Status write_ply(const std::string& path, const ExportData& data, const ExportOptions& options);

}  // namespace tailor::internal
