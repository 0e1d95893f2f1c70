// tailor: writing a textured mesh (.glb, .obj + .mtl, .ply) and the vertex splitting behind it.
//
// UV convention. The Atlas holds per-corner UVs in texture pixels with u to the right and v UP the
// texture image (the mapping's local frame is right-handed: u along the orientation field, v along
// the bitangent, so a front-facing triangle has positive signed UV area and the texture appears
// upright and unmirrored seen from outside). In texture repeats (OBJ vt, PLY s/t, Mesh::corner_uvs):
//     s = u / texture_width,  t = v / texture_height            (OBJ convention: t = 0 at the image bottom)
// and in glTF, whose v axis points down the image (0 = top row):
//     TEXCOORD_0 = (s, -t)
// which is the usual OBJ -> glTF conversion (s, 1 - t) shifted by one whole repeat: identical on
// screen with the REPEAT sampler tailor writes, and exact in floating point, so UVs round-trip
// bit for bit (1 - (1 - t) does not). Both files show the texture the same way.
//
// All writes are atomic (temporary file, then rename): on failure the previous file is untouched and
// no temporary file is left behind.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tailor/api.h"
#include "tailor/atlas.h"
#include "tailor/image.h"
#include "tailor/mesh.h"
#include "tailor/option_doc.h"
#include "tailor/progress.h"
#include "tailor/status.h"

namespace tailor {

//! How a .glb's geometry is stored (ExportOptions::compression).
enum class MeshCompression {
  kNone,      //!< float positions, normals and UVs, uint32 indices
  kQuantize,  //!< KHR_mesh_quantization: int16 positions (the node's scale and offset undo it), int16
              //!< normals, float UVs, uint16 indices where the vertices allow
  kMeshopt,   //!< the quantized arrays, vertex-cache ordered and EXT_meshopt_compression coded
  kDraco,     //!< KHR_draco_mesh_compression (positions 16 bits, normals 12, UVs 16)
};

//! "none", "quantize", "meshopt" or "draco".
inline const char* mesh_compression_name(MeshCompression c) {
  switch (c) {
    case MeshCompression::kQuantize: return "quantize";
    case MeshCompression::kMeshopt: return "meshopt";
    case MeshCompression::kDraco: return "draco";
    case MeshCompression::kNone: break;
  }
  return "none";
}

//! The inverse of mesh_compression_name; false for any other text.
inline bool mesh_compression_from_name(std::string_view name, MeshCompression& c) {
  for (MeshCompression v :
       {MeshCompression::kNone, MeshCompression::kQuantize, MeshCompression::kMeshopt, MeshCompression::kDraco})
    if (name == mesh_compression_name(v)) {
      c = v;
      return true;
    }
  return false;
}

//! The up axis of the mesh's coordinates (ExportOptions::up).
enum class SceneUp { kY, kZ };

//! A glTF PBR material's maps beyond the base colour (.glb only; see material.h for building them
//! from a folder of maps). Each image is an encoded PNG (8 or 16 bit), embedded as is unless
//! ExportOptions::image_uris names it.
struct MaterialTextures {
  std::string normal_png;               //!< tangent-space normal map, glTF (GL) convention; adds per-vertex TANGENT
  std::string orm_png;                  //!< glTF packing: R occlusion, G roughness, B metallic
  bool orm_roughness_metallic = false;  //!< orm_png is the metallicRoughnessTexture
  bool orm_occlusion = false;           //!< orm_png's R channel is the occlusionTexture
  bool empty() const { return normal_png.empty() && orm_png.empty(); }
};

//! Where a .glb's images are when they are not embedded: a URI relative to the .glb per map (empty
//! = embedded). Many files that share one material (the tiles of a 3D Tiles set) name its files
//! once instead of each carrying a copy, and need not read them.
struct ImageUris {
  std::string color;   //!< the base colour: needs ExportOptions::texture_path (then not read)
  std::string normal;  //!< the normal map (MaterialTextures::normal_png may then be empty): adds TANGENT
  std::string orm;     //!< the packed map (orm_png may then be empty): needs one of its two roles set
  bool empty() const { return color.empty() && normal.empty() && orm.empty(); }
};

struct ExportOptions {
  std::string texture_path;  //!< PNG or JPEG: embedded as is (.glb) or referenced by map_Kd (.mtl); empty = no texture
  const Image* texture_image = nullptr;  //!< optional: texture_path's pixels as the caller loaded them (load_image):
                                         //!< a JPEG that EXIF turns is embedded in a .glb from them, as PNG (else
                                         //!< the file is decoded again)
  int texture_width = 512;               //!< pixels per texture repeat along u (> 0), usually the texture's width
  int texture_height = 512;              //!< pixels per texture repeat along v (> 0), usually the texture's height
  bool normals = true;  //!< .glb/.obj: write smooth per-vertex normals (area-weighted, shared across seams)
  MeshCompression compression = MeshCompression::kNone;  //!< .glb only (kInvalidArgument for .obj/.ply)
  int uv_set = 0;             //!< .glb: the mapped UVs go to TEXCOORD_<uv_set> (0..7); the file's other sets are kept
  SceneUp up = SceneUp::kY;   //!< .glb: kZ turns the scene Y-up as glTF wants (-90 degrees about x, on the node)
  MaterialTextures material;  //!< .glb: normal, metallic-roughness and occlusion maps (kInvalidArgument otherwise)
  ImageUris image_uris;       //!< .glb: maps named by URI instead of embedded (kInvalidArgument for a colour
                              //!< URI without texture_path, an ORM URI without a role, another format)
  std::vector<std::string> other_outputs;  //!< .obj/.ply: files the caller writes beside (stats, previews): the
                                           //!< texture's copy beside the output never takes their names
  bool has_normal_map() const { return !material.normal_png.empty() || !image_uris.normal.empty(); }
  bool has_orm_map() const { return !material.orm_png.empty() || !image_uris.orm.empty(); }
  uint32_t symmetry = 1;      //!< .glb: 4 records in the material ("extras": {"tailor": {"symmetry": 4}}) that
                              //!< the map is 4-fold (MappingOptions::symmetry), so that eval, render and the
                              //!< viewer count quarter-turn seams as invisible without being told; .obj with a
                              //!< texture: a `# tailor symmetry 4` line in its .mtl (for eval)
  ProgressCallback progress;  //!< optional: the vertex split, then the bytes written (every few MB) or the
                              //!< codec's steps; false cancels (kCancelled, nothing written)
};

//! Flags and help of the ExportOptions a user sets (option_doc.h).
inline constexpr OptionDoc kExportOptionDocs[] = {
    {"compression", "--compress",
     "geometry compression of a .glb output: none, quantize (KHR_mesh_quantization), meshopt "
     "(EXT_meshopt_compression) or draco (KHR_draco_mesh_compression); three.js and Blender read all of them"},
    {"up", "--up",
     "up axis of the input's coordinates: y, or z (scans, CAD), which a .glb output turns Y-up by its node's "
     "rotation"},
    {"uv_set", "--uv-set",
     "glTF texture coordinate set N (0-7, TEXCOORD_N) that receives the new UVs; the input's other sets, "
     "normals and vertex colours are kept"},
};

//! The mesh's corner_attributes are written back (.glb: all of them but the mapped set's namesake,
//! vertices split where they differ; .obj: NORMAL), its NORMAL instead of computed normals.
//! Writes `mesh` with the UVs of `atlas` (atlas.corner_uv: #F*3 by 2 pixels) to `path`, the format
//! chosen by the extension (case-insensitive): .glb (binary glTF 2.0, texture embedded, sampler
//! REPEAT), .obj (+ obj_material_path's .mtl when a texture is given, map_Kd relative to the .obj),
//! .ply (binary little endian, per-vertex x y z s t after splitting).
//! Fails with kInvalidArgument on an unsupported extension, mismatched atlas size or a texture size
//! <= 0; kInvalidImage when the texture is neither PNG nor JPEG; kIo when a file cannot be read or
//! written. Cost: O(F) time, output-sized memory.
TAILOR_API Status export_mesh(const std::string& path, const Mesh& mesh, const Atlas& atlas,
                              const ExportOptions& options);

//! kInvalidArgument naming `path` when the .glb written from `mesh` with the mapped UVs in
//! TEXCOORD_<uv_set> would leave a gap in its texture coordinate sets (glTF numbers them from 0
//! without gaps): uv_set N > 0 needs TEXCOORD_0..N-1 among the mesh's kept attributes (a glTF
//! input's). export_mesh checks it; `tailor map` before mapping. O(attributes).
TAILOR_API Status check_uv_set(const Mesh& mesh, int uv_set, const std::string& path);

//! The .mtl export_mesh writes beside the .obj at `obj_path` when it has a texture: the .obj's stem
//! with blanks and tabs as '_' (`mtllib` takes a list of names, so most readers would split a
//! blank), then .mtl, in the .obj's folder.
TAILOR_API std::string obj_material_path(const std::string& obj_path);

//! A mesh whose vertices are split so that each vertex has one UV.
struct SplitMesh {
  std::vector<float> positions;   //!< #S by 3
  std::vector<float> uvs;         //!< #S by 2, copied bit for bit from the corner UVs
  std::vector<uint32_t> indices;  //!< #F by 3, into the split vertices
  std::vector<uint32_t> xref;     //!< #S: source vertex of each split vertex
};

//! Splits vertices on (vertex index, uv bits): corners with the same vertex and bit-identical UV
//! (-0 and +0 are merged) share one split vertex; split vertices are numbered in order of first
//! corner. corner_uv_repeats: #F*3 by 2 (any unit; copied as is). Cost: O(F): one chain of split
//! vertices per source vertex, falling back to a flat hash table for huge fans; no per-element
//! allocation. Deterministic.
TAILOR_API void split_vertices(const Mesh& mesh, std::span<const float> corner_uv_repeats, SplitMesh& out);

//! Per-corner tangents (#F*3 by 4: unit xyz, w = +-1 the bitangent's sign, glTF TANGENT) for a
//! normal map on corner_uv (#F*3 by 2, v up, any unit): the frames export_mesh writes with a
//! material's normal map, per corner. Fails with kInvalidArgument (sizes) or kInvalidMesh (an index
//! out of range). Cost: O(F).
TAILOR_API Status corner_tangents(const Mesh& mesh, std::span<const float> corner_uv, std::vector<float>& tangents);

//! The inverse, for readers of split files (.glb, .ply): merges vertices with bit-identical
//! positions (-0 and +0 merged), keeping the first one, and rewrites mesh.indices; corner UVs are
//! per corner and stay as they are. Returns the number of vertices removed. Cost: O(V + F).
TAILOR_API size_t weld_identical_positions(Mesh& mesh);

}  // namespace tailor
