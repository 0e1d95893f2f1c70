// The --axis text and the export step of `tailor map`, shared with `tailor edit` (map_shared.h).
#include "map_shared.h"

#include <array>
#include <cstdio>

#include "cli.h"

namespace tailor::cli {

std::string axis_text(const OrientationOptions& o) {
  if (o.axis == AxisSource::kPca) return "pca";
  if (o.axis == AxisSource::kSkeleton) return "skeleton";
  const std::array<float, 3>& a = o.user_axis;
  if (a == std::array<float, 3>{1, 0, 0}) return "x";
  if (a == std::array<float, 3>{0, 1, 0}) return "y";
  if (a == std::array<float, 3>{0, 0, 1}) return "z";
  char text[64];
  std::snprintf(text, sizeof text, "%.9g,%.9g,%.9g", a[0], a[1], a[2]);
  return text;
}

Status parse_axis(const std::string& text, OrientationOptions& o) {
  if (text == "pca") {
    o.axis = AxisSource::kPca;
    return Status::ok();
  }
  if (text == "skeleton") {
    o.axis = AxisSource::kSkeleton;
    return Status::ok();
  }
  o.axis = AxisSource::kUser;
  if (text == "x")
    o.user_axis = {1, 0, 0};
  else if (text == "y")
    o.user_axis = {0, 1, 0};
  else if (text == "z")
    o.user_axis = {0, 0, 1};
  else if (!parse_vec3(text, o.user_axis))
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "--axis must be pca, skeleton, x, y, z or three numbers X,Y,Z, got '" + text + "'");
  return Status::ok();
}

Status write_mapped_mesh(const std::string& path, const Mesh& mesh, const Atlas& atlas, const MeshOutput& output,
                         const ProgressCallback& progress) {
  ExportOptions export_options;
  export_options.texture_path = output.texture_path;
  export_options.material = output.material;
  export_options.texture_width = output.texture_width;
  export_options.texture_height = output.texture_height;
  export_options.compression = output.compression;
  export_options.uv_set = output.uv_set;
  export_options.up = output.up;
  export_options.progress = progress;
  return export_mesh(path, mesh, atlas, export_options);
}

}  // namespace tailor::cli
