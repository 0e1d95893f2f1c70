// PLY writer: binary little endian, one vertex per split vertex with float x y z s t (texture
// repeats, t up as in OBJ) and uchar red green blue alpha when the mesh kept colours (COLOR_0), faces as `list uchar
// uint vertex_indices`. A `comment TextureFile` line names the texture the way MeshLab does, by its bare file name
// (texture_name_beside: copied beside the .ply when it lies elsewhere), and `comment tailor symmetry 4` marks a
// 4-fold map (ExportOptions::symmetry 4), as the .mtl's line does for an .obj. Vertices are split on UV,
// so the faces of different patches do not share vertices in the file; tailor's readers of split files weld identical
// positions back when they need the connectivity (weld_identical_positions).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "export/writers.h"
#include "util/atomic_file.h"

namespace tailor::internal {
namespace {

// A colour component in [0, 1] as the byte it was read from (x / 255 round trips).
uint8_t unit_to_byte(float x) { return static_cast<uint8_t>(std::lround(std::clamp(double{x}, 0.0, 1.0) * 255.0)); }

}  // namespace

Status write_ply(const std::string& path, const ExportData& data, const ExportOptions& options) {
  static_assert(std::endian::native == std::endian::little, "ply writer assumes a little-endian host");
  const SplitMesh& split = data.split;
  const size_t vertex_count = split.xref.size();
  const size_t face_count = split.indices.size() / 3;
  std::string texture_bytes, texture_name;
  bool copy_texture = false;
  if (!options.texture_path.empty()) {
    std::string mime_type;  // fail on a missing or non-image texture like the other writers
    TAILOR_RETURN_IF_ERROR(read_texture_bytes(options.texture_path, texture_bytes, mime_type));
    const std::vector<std::string> own_file =
        names_in_folder(std::filesystem::path(path).parent_path(), options.other_outputs,
                        {std::filesystem::path(path).filename().string()});
    // The name the header gives, decided now; the copy beside the .ply (if any) is written at the end.
    TAILOR_RETURN_IF_ERROR(texture_name_beside(options.texture_path, texture_bytes,
                                               std::filesystem::path(path).parent_path(), own_file, texture_name,
                                               copy_texture));
  }

  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by tailor\n";
  if (!texture_name.empty()) out += "comment TextureFile " + texture_name + "\n";
  if (options.symmetry == 4) out += "comment tailor symmetry 4\n";  // a 4-fold map (LoadReport::texture_symmetry)
  out += "element vertex " + std::to_string(vertex_count) + "\n";
  out += "property float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\n";
  const CornerAttribute* colour = nullptr;  // per source vertex (export_mesh kept it)
  for (const CornerAttribute& a : data.kept)
    if (a.name == "COLOR_0" && a.components == 4) colour = &a;
  if (colour) out += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  const size_t record = colour ? 24 : 20;
  out += "element face " + std::to_string(face_count) + "\n";
  out += "property list uchar uint vertex_indices\nend_header\n";
  // Streamed through one small buffer of whole records: the file is never held whole in memory.
  ExportProgress progress(options.progress, vertex_count * record + face_count * 13, path);
  AtomicFileWriter file(path);
  TAILOR_RETURN_IF_ERROR(file.open());
  TAILOR_RETURN_IF_ERROR(file.write(out));
  constexpr size_t kChunkRecords = 16384;
  std::vector<char> chunk(kChunkRecords * 24);
  const float* positions = data.mesh->positions.data();
  for (size_t begin = 0; begin < vertex_count; begin += kChunkRecords) {
    const size_t end = std::min(vertex_count, begin + kChunkRecords);
    char* p = chunk.data();
    for (size_t s = begin; s < end; ++s, p += record) {
      std::memcpy(p, &positions[3 * size_t{split.xref[s]}], 12);
      std::memcpy(p + 12, &split.uvs[2 * s], 8);
      if (colour)
        for (size_t k = 0; k < 4; ++k)
          p[20 + k] = static_cast<char>(unit_to_byte(colour->values[4 * size_t{split.xref[s]} + k]));
    }
    TAILOR_RETURN_IF_ERROR(file.write({chunk.data(), (end - begin) * record}));
    if (!progress.wrote((end - begin) * record)) return progress.cancelled();
  }
  for (size_t begin = 0; begin < face_count; begin += kChunkRecords) {
    const size_t end = std::min(face_count, begin + kChunkRecords);
    char* p = chunk.data();
    for (size_t f = begin; f < end; ++f, p += 13) {
      *p = 3;
      std::memcpy(p + 1, &split.indices[3 * f], 12);
    }
    TAILOR_RETURN_IF_ERROR(file.write({chunk.data(), (end - begin) * 13}));
    if (!progress.wrote((end - begin) * 13)) return progress.cancelled();
  }
  if (!progress.reached(1.f)) return progress.cancelled();
  if (copy_texture)  // before the .ply lands: a failure leaves neither
    TAILOR_RETURN_IF_ERROR(
        write_file_atomic((std::filesystem::path(path).parent_path() / texture_name).string(), texture_bytes));
  return file.commit();
}

}  // namespace tailor::internal
