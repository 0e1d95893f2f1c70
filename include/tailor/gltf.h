// tailor: reading glTF 2.0 (.glb, or .gltf with its buffers as data: URIs or files next to it)
// with its base colour texture, for `tailor map`, `tailor eval` and `tailor render`.
//
// What is read: the default scene (`scene`, else scene 0; every mesh once when there is no scene),
// walked from its root nodes: each node that uses a mesh places an instance of it with the node's
// world transform applied (parents first; winding flipped under a mirroring transform), so the
// mesh is in world space; EXT_mesh_gpu_instancing places one instance per element. Triangle
// lists, strips and fans become triangles; points and lines are skipped and counted
// (LoadReport::skipped_primitives; only those is kUnsupported). POSITION and TEXCOORD_0 of any
// component type (KHR_mesh_quantization), sparse accessors, EXT_meshopt_compression buffer views
// (Debian's libmeshoptimizer) and KHR_draco_mesh_compression primitives (libdraco). A required
// extension other than these is kUnsupported, naming it. TEXCOORD_0 becomes Mesh::corner_uvs in
// the OBJ convention up to a whole repeat: t = -v_gltf (the inverse of what export writes, see
// export.h; for files from other tools t is the usual 1 - v_gltf minus one, the same texel under
// REPEAT). Vertices with bit-identical positions are welded (glTF files split vertices on UV
// seams) and counted in LoadReport::welded_vertices, so seams become real edges again.
// Kept for export (Mesh::corner_attributes, Mesh::face_parts, Mesh::scene): NORMAL, COLOR_0,
// TEXCOORD_1..7; per instance the node's and mesh's names and extras; per primitive its
// material's name, factors, alphaMode, alphaCutoff, doubleSided and extras; the scene's and the
// asset's extras (and copyright). The rest is named in LoadReport::not_kept.
//
// Safe for untrusted input: the only files opened are buffers named by a relative URI inside the
// .gltf's folder (no scheme, no absolute path, no '..'; none at all from memory) and, by the same
// rule, the base colour image's file for the first bytes of its header; image files are never
// decoded (an embedded or data: URI image is, when a texture is asked for); every accessor is
// bounds-checked against its buffer view and buffer before it is read, every index against the
// vertex count; all decoded output (accessors, meshopt and Draco data, instances) is charged
// against a budget of 64 times the input's size plus 64 MiB before it is allocated; images larger
// than kMaxImageSide a side or ImageLoadOptions{}.max_pixels in all are rejected before decoding,
// and nothing throws (allocation failure -> kLimit). The texture's size is read from its header
// into LoadReport::texture_width/height whether or not it is decoded, at any size: from the buffer
// view, a data: URI, or the first bytes of a file next to the .gltf (the buffers' rule: no scheme,
// no absolute path, no '..'), which is never decoded.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "tailor/api.h"
#include "tailor/image.h"
#include "tailor/mesh.h"
#include "tailor/status.h"

namespace tailor {

//! Reads `path` (.glb or .gltf) into `mesh` (finalized as load_mesh does) and, when `texture` is not null,
//! decodes the base colour texture of the first textured material (PNG or JPEG) into it (left
//! empty when there is none, and when its bytes do not decode: the reason is then in
//! LoadReport::texture_problem and the mesh is read). report may be null. Fails with kIo, kParse
//! (not a glb, bad chunk, bad accessor), kUnsupported (no triangle primitive, a required extension,
//! a URI outside the folder), kInvalidMesh, kInvalidImage (texture larger than image_options allow:
//! checked from its header before decoding). Cost: O(file size).
TAILOR_API Status read_glb_file(const std::string& path, Mesh& mesh, Image* texture, LoadReport* report = nullptr,
                                const ImageLoadOptions& image_options = {});

//! The maps of a glTF material beside its base colour, and the tangents its normal map needs: what a
//! preview shades with (render.h PreviewMaterial).
struct GltfMaterialMaps {
  Image normal;                        //!< normalTexture (tangent space, +Y up the image), 8 bits; empty: none
  Image occlusion;                     //!< occlusionTexture (ambient occlusion in R); empty: none
  Image metallic_roughness;            //!< metallicRoughnessTexture (G roughness, B metallic); empty: none
  std::vector<float> corner_tangents;  //!< the file's TANGENT per corner (#F*3 by 4: world-space unit xyz, w = +-1
                                       //!< the bitangent's sign); empty when the file has none on every primitive
};

//! read_glb_file, and the other maps of the same material (the first textured one; 16-bit PNGs
//! decoded to 8 bits) and its TANGENT attribute into `material` (may be null). TANGENT is not
//! kept in mesh.corner_attributes (a new mapping would make it wrong). Same errors; a map that
//! cannot be decoded is kInvalidImage.
TAILOR_API Status read_glb_with_material(const std::string& path, Mesh& mesh, Image* texture,
                                         GltfMaterialMaps* material, LoadReport* report = nullptr,
                                         const ImageLoadOptions& image_options = {});

//! Same from memory (.glb, or .gltf whose buffers are data: URIs); `name` is used in error messages only.
TAILOR_API Status read_glb_memory(std::span<const char> data, const std::string& name, Mesh& mesh, Image* texture,
                                  LoadReport* report = nullptr, const ImageLoadOptions& image_options = {});

}  // namespace tailor
