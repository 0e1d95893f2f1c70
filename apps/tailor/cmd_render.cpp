// tailor render: a preview picture of a UV-mapped mesh (textured, patches, distortion or checker),
// rendered headlessly on the CPU (OSMesa).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "cli.h"
#include "tailor/gltf.h"
#include "tailor/image.h"
#include "tailor/io.h"
#include "tailor/render.h"
#include "tailor/tiling.h"

namespace tailor::cli {
namespace {

// The command line: --yaw, --pitch and --checker are bound to `options` (defaults: RenderOptions');
// the options given as text default to the names of RenderOptions' defaults.
struct RenderArgs {
  std::string input;
  std::string output;
  std::string texture;
  std::string normal_map;
  bool no_material = false;
  ImageLoadOptions image_options;  // --max-image-pixels: the .glb's images, --texture, --normal-map
  RenderOptions options;
  std::string view = preview_view_name(RenderOptions{}.view);
  std::string size = std::to_string(RenderOptions{}.width) + "x" + std::to_string(RenderOptions{}.height);
  std::string up = up_axis_name(RenderOptions{}.up);
  bool quiet = false;
  bool symmetry_given = false;  // else a .glb's record of a 4-fold map (LoadReport::texture_symmetry) decides
};

//! "WIDTHxHEIGHT" -> width, height; false when malformed.
bool parse_size(const std::string& text, int& width, int& height) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X')) return false;
  width = w;
  height = h;
  return true;
}

int run_render(const RenderArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  RenderOptions options = args.options;
  if (!preview_view_from_name(args.view, options.view)) {
    return report_error(Status::error(ErrorCode::kInvalidArgument, "", "unknown view '" + args.view + "'",
                                      "use texture, patches, distortion, checker or seams"));
  }
  if (!parse_size(args.size, options.width, options.height)) {
    return report_error(Status::error(ErrorCode::kInvalidArgument, "", "bad --size '" + args.size + "'",
                                      "expected WIDTHxHEIGHT, e.g. 1024x768"));
  }
  if (!up_axis_from_name(args.up, options.up)) {
    return report_error(
        Status::error(ErrorCode::kInvalidArgument, "", "bad --up '" + args.up + "'", "use x, y, z, -x, -y or -z"));
  }

  // Before any work, as map and tile do: a picture never replaces the mesh, a texture or a normal
  // map it was drawn from, and lands where it can be written.
  if (!ends_with_png(args.output))
    return report_error(Status::error(ErrorCode::kInvalidArgument, args.output, "output must be a .png file"));
  if (Status s = check_outputs({{args.output, "--output"}}, {args.input, args.texture, args.normal_map}); !s)
    return report_error(s);

  Mesh mesh;
  Image texture;
  GltfMaterialMaps maps;  // a .glb's normal and occlusion maps, and its tangents
  LoadReport report;
  const MeshFormat format = mesh_format_from_path(args.input);
  // The file's base colour image is decoded only where it is drawn (the texture view) or sized (the
  // seams view) and --texture does not replace it.
  const bool file_texture =
      args.texture.empty() && (options.view == PreviewView::kTexture || options.view == PreviewView::kSeams);
  Status status = [&] {
    const ReadingInput reading(args.input);
    return format == MeshFormat::kGlb || format == MeshFormat::kGltf
               ? read_glb_with_material(args.input, mesh, file_texture ? &texture : nullptr,
                                        args.no_material ? nullptr : &maps, &report, args.image_options)
               : load_mesh(args.input, mesh, &report);
  }();
  if (!status) return report_error(status.with_file(args.input));
  if (!args.symmetry_given) options.seam_symmetry = report.texture_symmetry;  // a 4-fold map's .glb says so
  if (!args.texture.empty()) {
    status = load_image(args.texture, texture, args.image_options);
    if (!status) return report_error(status.with_file(args.texture));
    // The seams view shows what is visible under the texture drawn: another texture than the
    // map's has its own symmetry (4 when a quarter turn about its centre leaves it unchanged).
    if (!args.symmetry_given) {
      int shift_x = 0, shift_y = 0;
      const int difference = quarter_turn_difference(texture, &shift_x, &shift_y);
      options.seam_symmetry =
          difference >= 0 && difference <= kQuarterTurnNoiseLevels && shift_x == 0 && shift_y == 0 ? 4 : 1;
    }
  }
  // The texture file the mesh names (.mtl, a .ply's TextureFile, a .gltf's image URI) is an input too.
  if (Status s = check_outputs({{args.output, "--output"}}, {report.texture_path}); !s) return report_error(s);
  if (args.texture.empty() && texture.empty() && !report.texture_path.empty()) {
    // The texture an .obj's .mtl or a .ply's TextureFile names, next to it (as tailor map writes), or
    // a .gltf's image file: glTF viewers show a texture's stored rows, whatever its EXIF says.
    ImageLoadOptions image_options = args.image_options;
    image_options.exif_orientation = format != MeshFormat::kGlb && format != MeshFormat::kGltf;
    status = load_image(report.texture_path, texture, image_options);
    if (!status) {
      texture = Image{};
      warn(args.quiet, "cannot read the texture " + args.input + " names (" + status.message() + ")");
    }
  }
  if (!args.normal_map.empty()) {  // replaces the file's; tangents then come from the UVs
    status = load_image(args.normal_map, maps.normal, args.image_options);
    if (!status) return report_error(status.with_file(args.normal_map));
    if (maps.normal.channels < 3)
      return report_error(Status::error(ErrorCode::kInvalidImage, args.normal_map, "a normal map needs RGB channels"));
    maps.corner_tangents.clear();
  }
  PreviewMaterial material;
  if (!maps.normal.empty()) material.normal = &maps.normal;
  if (!maps.occlusion.empty()) material.occlusion = &maps.occlusion;
  material.corner_tangents = maps.corner_tangents;
  if (mesh.corner_uvs.empty() && options.view != PreviewView::kPatches) {
    const std::string lacking =
        report.primitive_without_uv.empty() ? "" : " (" + report.primitive_without_uv + " has none, others have)";
    return report_error(Status::error(ErrorCode::kInvalidMesh, args.input, "mesh has no texture coordinates" + lacking,
                                      "run 'tailor map' first, or use --view patches"));
  }
  if (options.view == PreviewView::kTexture) warn_texture_transform(args.quiet, args.input, report.texture_transform);
  if (options.view == PreviewView::kTexture && texture.empty()) {
    if (!report.texture_problem.empty())  // embedded, but its bytes do not decode
      warn(args.quiet, "cannot read the texture " + args.input + " names (" + report.texture_named + ": " +
                           report.texture_problem + "): showing a neutral checker");
    else if (report.texture_path.empty() && !report.texture_named.empty())  // named, but its header unread
      warn(args.quiet, "cannot read the texture " + args.input + " names (" + report.texture_named +
                           "): showing a neutral checker");
    else if (report.texture_path.empty())
      warn(args.quiet, "no texture in " + args.input + " and no --texture: showing a neutral checker");
  }

  if (options.view == PreviewView::kSeams && !texture.empty())
    if (Status s = check_quarter_turn_texture(options.seam_symmetry, texture.width, texture.height); !s)
      return report_error(s);
  Image picture;
  status = render_preview(mesh, mesh.corner_uvs, {}, texture.empty() ? nullptr : &texture, material, options, picture);
  if (!status) return report_error(status);
  status = write_png(args.output, picture);
  if (!status) return report_error(status.with_file(args.output));
  if (!args.quiet) {
    std::printf("wrote %s (%dx%d, %s view, %s) in %.2f s\n", args.output.c_str(), picture.width, picture.height,
                preview_view_name(options.view), counted(mesh.face_count(), "face", "faces").c_str(),
                seconds_since(start));
  }
  return kExitOk;
}

}  // namespace

void register_render(CLI::App& app, Runner& run) {
  auto* cmd = app.add_subcommand("render", "Render a preview picture of a UV-mapped mesh (CPU, no display needed)");
  auto args = std::make_shared<RenderArgs>();
  cmd->add_option(
         "mesh", args->input,
         "UV-mapped mesh: .glb (texture embedded) or .obj/.ply with UVs (texture: the .mtl's map_Kd, the .ply's "
         "comment TextureFile)")
      ->required();
  cmd->add_option("-o,--output", args->output, "PNG picture to write")->required();
  add_documented(cmd, option_doc(kRenderOptionDocs, "view"), args->view)
      ->check(CLI::IsMember({"texture", "patches", "distortion", "checker", "seams"}));
  add_documented(cmd, option_doc(kRenderOptionDocs, "width"), args->size);
  cmd->add_option("--texture", args->texture, "texture image to use instead of the one the file names");
  cmd->add_option("--normal-map", args->normal_map,
                  "tangent-space normal map (OpenGL convention, +Y up) to shade the texture view with, instead of "
                  "the .glb's normalTexture (tangents from the UVs)");
  cmd->add_flag("--no-material", args->no_material,
                "texture view: ignore the .glb's normal and occlusion maps (only the base colour)");
  add_documented(cmd, option_doc(kRenderOptionDocs, "up"), args->up);
  add_documented(cmd, option_doc(kRenderOptionDocs, "yaw_degrees"), args->options.yaw_degrees);
  add_documented(cmd, option_doc(kRenderOptionDocs, "pitch_degrees"), args->options.pitch_degrees);
  add_documented(cmd, option_doc(kRenderOptionDocs, "checker_squares"), args->options.checker_squares);
  add_symmetry_option(cmd, option_doc(kRenderOptionDocs, "seam_symmetry"), args->options.seam_symmetry,
                      "; with --texture, 4 when that texture is unchanged by a quarter turn");
  add_documented(cmd, option_doc(kImageLoadOptionDocs, "max_pixels"), args->image_options.max_pixels)
      ->check(kAtLeastOne);
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing but errors");
  cmd->footer(
      "Examples:\n"
      "  tailor render spot.glb -o spot.png\n"
      "  tailor render spot.glb -o spot_patches.png --view patches --size 800x600\n"
      "  tailor render spot.glb -o spot_checker.png --view checker --checker 16\n"
      "  tailor render spot4.obj -o spot4_seams.png --view seams --symmetry 4   # a 4-fold map (a .glb says so)\n"
      "A .glb written by 'tailor map --material' is shaded with its normal map (tangent space, the file's\n"
      "TANGENT) and occlusion map.");
  cmd->callback([&run, args, cmd] {
    args->symmetry_given = cmd->count("--symmetry") > 0;
    run = [args] { return run_render(*args); };
  });
}

}  // namespace tailor::cli
