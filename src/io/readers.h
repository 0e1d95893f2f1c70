// Per-format mesh parsers behind load_mesh/read_mesh (io_mesh.cpp). Each one parses `data`, fills
// positions/indices (and corner_uvs / seam_faces where the format has them) and the format fields
// of `report`; io_mesh.cpp then runs finalize_mesh. `name` is used in error messages only.
// Contract: never read outside `data`, never allocate from an unchecked count, never throw.
#pragma once

#include <span>
#include <string>

#include "tailor/image.h"
#include "tailor/mesh.h"
#include "tailor/status.h"

namespace tailor::internal {

Status read_ply(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report);
Status read_obj(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report);
Status read_off(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report);
Status read_stl(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report);
//! glTF 2.0 (.glb or .gltf): the default scene's mesh instances in world space, TEXCOORD_0 into
//! corner_uvs (read_gltf.cpp). Buffer URIs are looked up in `base_dir` (empty: none is opened).
Status read_gltf(std::span<const char> data, const std::string& name, const std::string& base_dir, Mesh& mesh,
                 LoadReport& report);

//! Checks the size an image header claims (width x height, read by stbi_info_from_memory) before
//! decoding `bytes`: each side within kMaxImageSide, width x height within options.max_pixels, and
//! for uncompressed TGA, BMP and binary PPM/PGM the file long enough for that many pixels (RLE TGA:
//! at least 2 bytes per 128 pixels). kInvalidImage with one line otherwise (image_io.cpp).
Status check_image_header(std::span<const unsigned char> bytes, long width, long height,
                          const ImageLoadOptions& options, const std::string& name);

}  // namespace tailor::internal
