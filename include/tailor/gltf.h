// tailor: reading a binary glTF 2.0 file (.glb) with its base colour texture, for `tailor eval`
// and `tailor render`.
//
// What is read: every triangle primitive (mode 4) of every mesh, concatenated, in the order of the
// meshes array (node transforms are NOT applied); POSITION (float vec3), indices (u8/u16/u32, or none)
// and TEXCOORD_0 (float, or normalized u8/u16), converted to Mesh::corner_uvs in the OBJ convention
// up to a whole repeat: t = -v_gltf (the inverse of what export writes, see export.h; for files
// from other tools t is the usual 1 - v_gltf minus one, the same texel under REPEAT).
// Vertices with bit-identical positions are welded (glTF files split vertices on UV seams) and
// counted in LoadReport::welded_vertices, so seams become real edges again.
//
// Safe for untrusted input: no URI is ever opened or decoded (only the GLB's embedded BIN chunk is
// used; buffers with a uri are kUnsupported, images with a uri are ignored), every accessor is
// bounds-checked against its buffer view and the BIN chunk before it is read, every index against
// the vertex count, output size is capped at a multiple of the file size, images larger than
// kMaxImageSide a side or ImageLoadOptions{}.max_pixels in all are rejected before decoding, and
// nothing throws (allocation failure -> kLimit). The texture's size is read from its header into
// LoadReport::texture_width/height whether or not it is decoded (`tailor eval` never decodes it).
#pragma once

#include <span>
#include <string>

#include "tailor/api.h"
#include "tailor/image.h"
#include "tailor/mesh.h"
#include "tailor/status.h"

namespace tailor {

//! Reads `path` (.glb) into `mesh` (finalized as load_mesh does) and, when `texture` is not null,
//! decodes the base colour texture of the first textured material (PNG or JPEG) into it (left
//! empty when there is none). report may be null. Fails with kIo, kParse (not a glb, bad chunk,
//! bad accessor), kUnsupported (no triangle primitive, sparse accessors, non-float positions),
//! kInvalidMesh, kInvalidImage (texture present but undecodable). Cost: O(file size).
TAILOR_API Status read_glb_file(const std::string& path, Mesh& mesh, Image* texture, LoadReport* report = nullptr);

//! Same from memory; `name` is used in error messages only.
TAILOR_API Status read_glb_memory(std::span<const char> data, const std::string& name, Mesh& mesh, Image* texture,
                                  LoadReport* report = nullptr);

}  // namespace tailor
