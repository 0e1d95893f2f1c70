// Wavefront OBJ writer: `v` per source vertex (`v x y z r g b` when the mesh kept colours, COLOR_0) (so the reloaded
// mesh keeps its connectivity), `vt` per split vertex (one per distinct (vertex, uv) pair, in texture repeats, t up),
// `vn` per source vertex when normals are on, faces `f v/vt[/vn]` (1-based). With a texture, a <stem>.mtl
// (obj_material_path) next to the .obj holds one material whose map_Kd is the texture's bare file name: the texture
// lies beside the .mtl (copied there when it is elsewhere, texture_name_beside), so the output folder can be moved
// whole; a 4-fold map (ExportOptions::symmetry 4) adds the comment line `# tailor symmetry 4` to it. Numbers are
// written with std::to_chars (shortest text that reads back bit-exact).
#include <filesystem>

#include "export/writers.h"
#include "util/atomic_file.h"

namespace tailor::internal {
namespace {

void append_decimal(std::string& out, uint32_t value) { out += std::to_string(value); }

}  // namespace

Status write_obj(const std::string& path, const ExportData& data, const ExportOptions& options) {
  const Mesh& mesh = *data.mesh;
  const SplitMesh& split = data.split;
  const std::filesystem::path obj_path(path);
  const bool textured = !options.texture_path.empty();
  const std::string mtl_name = std::filesystem::path(obj_material_path(path)).filename().string();
  std::string texture_bytes;
  if (textured) {
    std::string mime_type;  // fail early on a missing or non-image texture
    TAILOR_RETURN_IF_ERROR(read_texture_bytes(options.texture_path, texture_bytes, mime_type));
  }

  // The text goes out in pieces of about kFlushBytes through one reused string: the file is never
  // held whole in memory.
  AtomicFileWriter file(path);
  TAILOR_RETURN_IF_ERROR(file.open());
  constexpr size_t kFlushBytes = size_t{1} << 20;
  std::string out;
  out.reserve(kFlushBytes + 4096);
  // Progress in lines: v and vn per vertex, vt per split vertex, f per face.
  const size_t lines = mesh.vertex_count() * (data.normals.empty() ? 1 : 2) + split.xref.size() + mesh.face_count();
  ExportProgress progress(options.progress, lines, path);
  auto flush_if_full = [&]() -> Status {
    if (!progress.wrote(1)) return progress.cancelled();
    if (out.size() < kFlushBytes) return Status::ok();
    Status s = file.write(out);
    out.clear();
    return s;
  };
  out += "# written by tailor: ";
  out += std::to_string(mesh.vertex_count()) + " vertices, " + std::to_string(mesh.face_count()) + " faces\n";
  if (textured) out += "mtllib " + mtl_name + "\n";
  const CornerAttribute* colour = nullptr;  // per source vertex (export_mesh kept it)
  for (const CornerAttribute& a : data.kept)
    if (a.name == "COLOR_0" && a.components == 4) colour = &a;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    out += "v ";
    append_float(out, mesh.positions[3 * v]);
    out += ' ';
    append_float(out, mesh.positions[3 * v + 1]);
    out += ' ';
    append_float(out, mesh.positions[3 * v + 2]);
    for (size_t k = 0; colour && k < 3; ++k) {
      out += ' ';
      append_float(out, colour->values[4 * v + k]);
    }
    out += '\n';
    TAILOR_RETURN_IF_ERROR(flush_if_full());
  }
  for (size_t s = 0; s < split.xref.size(); ++s) {
    out += "vt ";
    append_float(out, split.uvs[2 * s]);
    out += ' ';
    append_float(out, split.uvs[2 * s + 1]);
    out += '\n';
    TAILOR_RETURN_IF_ERROR(flush_if_full());
  }
  const bool normals = !data.normals.empty();
  for (size_t v = 0; normals && v < mesh.vertex_count(); ++v) {
    out += "vn ";
    append_float(out, data.normals[3 * v]);
    out += ' ';
    append_float(out, data.normals[3 * v + 1]);
    out += ' ';
    append_float(out, data.normals[3 * v + 2]);
    out += '\n';
    TAILOR_RETURN_IF_ERROR(flush_if_full());
  }
  if (textured) out += "usemtl tailor\n";
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      const size_t c = 3 * f + k;
      out += ' ';
      append_decimal(out, mesh.indices[c] + 1);
      out += '/';
      append_decimal(out, split.indices[c] + 1);
      if (normals) {
        out += '/';
        append_decimal(out, mesh.indices[c] + 1);
      }
    }
    out += '\n';
    TAILOR_RETURN_IF_ERROR(flush_if_full());
  }
  TAILOR_RETURN_IF_ERROR(file.write(out));
  if (!progress.reached(1.f)) return progress.cancelled();
  if (textured) {  // after the .obj's text, before it lands: a failure leaves none of the three
    std::string texture_name;
    bool copy = false;
    const std::filesystem::path folder = obj_path.parent_path();
    const std::vector<std::string> own_files =
        names_in_folder(folder, options.other_outputs, {obj_path.filename().string(), mtl_name});
    TAILOR_RETURN_IF_ERROR(
        texture_name_beside(options.texture_path, texture_bytes, folder, own_files, texture_name, copy));
    if (copy) TAILOR_RETURN_IF_ERROR(write_file_atomic((folder / texture_name).string(), texture_bytes));
    std::string mtl = "# written by tailor\nnewmtl tailor\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\nmap_Kd ";
    mtl += texture_name + "\n";
    if (options.symmetry == 4) mtl += "# tailor symmetry 4\n";  // a 4-fold map (LoadReport::texture_symmetry)
    TAILOR_RETURN_IF_ERROR(write_file_atomic((folder / mtl_name).string(), mtl));
  }
  return file.commit();
}

}  // namespace tailor::internal
