// PLY writer: binary little endian, one vertex per split vertex with float x y z s t (texture
// repeats, t up as in OBJ), faces as `list uchar uint vertex_indices`. A `comment TextureFile`
// line names the texture the way MeshLab does. Vertices are split on UV, so the faces of
// different patches do not share vertices in the file; tailor's readers of split files weld
// identical positions back when they need the connectivity (weld_identical_positions).
#include <bit>
#include <cstring>
#include <filesystem>

#include "internal/atomic_file.h"
#include "internal/export_writers.h"

namespace tailor::internal {

Status write_ply(const std::string& path, const ExportData& data, const ExportOptions& options) {
  static_assert(std::endian::native == std::endian::little, "ply writer assumes a little-endian host");
  const SplitMesh& split = data.split;
  const size_t vertex_count = split.xref.size();
  const size_t face_count = split.indices.size() / 3;
  if (!options.texture_path.empty()) {
    std::string bytes, mime_type;  // fail on a missing or non-image texture like the other writers
    TAILOR_RETURN_IF_ERROR(read_texture_bytes(options.texture_path, bytes, mime_type));
  }

  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by tailor\n";
  if (!options.texture_path.empty()) {
    std::string name = relative_path(options.texture_path, std::filesystem::path(path).parent_path());
    for (char& c : name)
      if (c == '\n' || c == '\r') c = ' ';
    out += "comment TextureFile " + name + "\n";
  }
  out += "element vertex " + std::to_string(vertex_count) + "\n";
  out += "property float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\n";
  out += "element face " + std::to_string(face_count) + "\n";
  out += "property list uchar uint vertex_indices\nend_header\n";
  const size_t header = out.size();
  out.resize(header + vertex_count * 20 + face_count * 13);
  char* p = out.data() + header;
  for (size_t s = 0; s < vertex_count; ++s) {
    std::memcpy(p, &split.positions[3 * s], 12);
    std::memcpy(p + 12, &split.uvs[2 * s], 8);
    p += 20;
  }
  for (size_t f = 0; f < face_count; ++f) {
    *p = 3;
    std::memcpy(p + 1, &split.indices[3 * f], 12);
    p += 13;
  }
  return write_file_atomic(path, out);
}

}  // namespace tailor::internal
