// export_mesh: validation, vertex splitting and normals shared by the .glb, .obj and .ply writers.
#include "tailor/export.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "internal/atomic_file.h"
#include "internal/export_writers.h"

namespace tailor {
namespace internal {

Status read_texture_bytes(const std::string& path, std::string& bytes, std::string& mime_type) {
  TAILOR_RETURN_IF_ERROR(read_file(path, bytes));
  static constexpr unsigned char kPng[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  static constexpr unsigned char kJpeg[3] = {0xff, 0xd8, 0xff};
  if (bytes.size() >= sizeof kPng && std::memcmp(bytes.data(), kPng, sizeof kPng) == 0) {
    mime_type = "image/png";
  } else if (bytes.size() >= sizeof kJpeg && std::memcmp(bytes.data(), kJpeg, sizeof kJpeg) == 0) {
    mime_type = "image/jpeg";
  } else {
    bytes.clear();
    return Status::error(ErrorCode::kInvalidImage, path, "texture is neither PNG nor JPEG");
  }
  return Status::ok();
}

void append_float(std::string& out, float value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

// Path of `target` relative to `base_dir` when one exists, else `target` as given (absolute).
std::string relative_path(const std::string& target, const std::filesystem::path& base_dir) {
  std::error_code error;
  const std::filesystem::path absolute_target = std::filesystem::absolute(target, error);
  if (error) return target;
  const std::filesystem::path absolute_base = std::filesystem::absolute(base_dir.empty() ? "." : base_dir, error);
  if (error) return absolute_target.string();
  const std::filesystem::path relative = absolute_target.lexically_normal().lexically_relative(absolute_base.lexically_normal());
  return relative.empty() ? absolute_target.string() : relative.generic_string();
}


}  // namespace internal

namespace {

enum class ExportFormat { kUnknown, kGlb, kObj, kPly };

ExportFormat export_format(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return ExportFormat::kUnknown;
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  if (ext == "glb") return ExportFormat::kGlb;
  if (ext == "obj") return ExportFormat::kObj;
  if (ext == "ply") return ExportFormat::kPly;
  return ExportFormat::kUnknown;
}

// Area-weighted normals per source vertex (the unnormalised face normal is 2 * area * n), so that
// shading stays smooth across UV seams. Isolated or degenerate vertices get +z.
void vertex_normals(const Mesh& mesh, std::vector<float>& normals) {
  const size_t nv = mesh.vertex_count();
  std::vector<double> sum(3 * nv, 0.0);
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const uint32_t* t = &mesh.indices[3 * f];
    const float* a = &mesh.positions[3 * size_t{t[0]}];
    const float* b = &mesh.positions[3 * size_t{t[1]}];
    const float* c = &mesh.positions[3 * size_t{t[2]}];
    const double e1[3] = {double{b[0]} - a[0], double{b[1]} - a[1], double{b[2]} - a[2]};
    const double e2[3] = {double{c[0]} - a[0], double{c[1]} - a[1], double{c[2]} - a[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) sum[3 * size_t{t[k]} + i] += n[i];
  }
  normals.resize(3 * nv);
  for (size_t v = 0; v < nv; ++v) {
    const double* n = &sum[3 * v];
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (length > 0 && std::isfinite(length)) {
      for (int i = 0; i < 3; ++i) normals[3 * v + i] = static_cast<float>(n[i] / length);
    } else {
      normals[3 * v] = 0;
      normals[3 * v + 1] = 0;
      normals[3 * v + 2] = 1;
    }
  }
}

}  // namespace

Status export_mesh(const std::string& path, const Mesh& mesh, const Atlas& atlas, const ExportOptions& options) {
  const ExportFormat format = export_format(path);
  if (format == ExportFormat::kUnknown)
    return Status::error(ErrorCode::kInvalidArgument, path, "unsupported output format (use .glb, .obj or .ply)");
  const size_t nf = mesh.face_count();
  if (nf == 0) return Status::error(ErrorCode::kInvalidArgument, path, "mesh has no face to export");
  if (atlas.corner_uv.size() != 6 * nf)
    return Status::error(ErrorCode::kInvalidArgument, path, "atlas does not match the mesh",
                         std::to_string(atlas.corner_uv.size()) + " UV floats for " + std::to_string(nf) + " faces");
  if (options.texture_width <= 0 || options.texture_height <= 0)
    return Status::error(ErrorCode::kInvalidArgument, path, "texture size must be positive");
  for (size_t c = 0; c < mesh.indices.size(); ++c)
    if (mesh.indices[c] >= mesh.vertex_count())
      return Status::error(ErrorCode::kInvalidArgument, path, "vertex index out of range", "corner " + std::to_string(c));
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!std::isfinite(mesh.positions[i]))
      return Status::error(ErrorCode::kInvalidArgument, path, "position is not finite", "vertex " + std::to_string(i / 3));

  // Pixels -> texture repeats, OBJ convention (t up); the glTF writer flips t itself.
  std::vector<float> repeats(atlas.corner_uv.size());
  const double su = 1.0 / options.texture_width, sv = 1.0 / options.texture_height;
  for (size_t c = 0; c < 3 * nf; ++c) {
    const double u = atlas.corner_uv[2 * c] * su, v = atlas.corner_uv[2 * c + 1] * sv;
    if (!std::isfinite(u) || !std::isfinite(v))
      return Status::error(ErrorCode::kInvalidArgument, path, "UV is not finite", "corner " + std::to_string(c));
    repeats[2 * c] = static_cast<float>(u);
    repeats[2 * c + 1] = static_cast<float>(v);
  }

  internal::ExportData data;
  data.mesh = &mesh;
  split_vertices(mesh, repeats, data.split);
  if (options.normals && format != ExportFormat::kPly) vertex_normals(mesh, data.normals);

  switch (format) {
    case ExportFormat::kGlb: return internal::write_glb(path, data, options);
    case ExportFormat::kObj: return internal::write_obj(path, data, options);
    case ExportFormat::kPly: return internal::write_ply(path, data, options);
    case ExportFormat::kUnknown: break;
  }
  return Status::error(ErrorCode::kInvalidArgument, path, "unsupported output format");
}

}  // namespace tailor
