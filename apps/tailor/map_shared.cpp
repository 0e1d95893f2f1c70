// The mapping options, the --axis text and the export step of `tailor map`, shared with `tailor edit`
// (map_shared.h).
#include "map_shared.h"

#include <array>
#include <charconv>
#include <cstdlib>

#include "cli.h"

namespace tailor::cli {

std::string axis_text(const OrientationOptions& o) {
  if (o.axis == AxisSource::kPca) return "pca";
  if (o.axis == AxisSource::kSkeleton) return "skeleton";
  const std::array<float, 3>& a = o.user_axis;
  if (a == std::array<float, 3>{1, 0, 0}) return "x";
  if (a == std::array<float, 3>{0, 1, 0}) return "y";
  if (a == std::array<float, 3>{0, 0, 1}) return "z";
  return float_text(a[0]) + "," + float_text(a[1]) + "," + float_text(a[2]);
}

std::string float_text(float x) {
  char text[32];
  const auto [end, error] = std::to_chars(text, text + sizeof text, x);
  return error == std::errc() ? std::string(text, end) : std::to_string(x);
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
                         "--axis must be auto, pca, skeleton, x, y, z or three numbers X,Y,Z, got '" + text + "'");
  return Status::ok();
}

Status parse_chunk_args(const std::string& mode, const std::string& cell, ChunkOptions& chunks) {
  const auto usage_error = [](const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); };
  if (mode == "auto")
    chunks.mode = ChunkMode::kAuto;
  else if (mode == "on")
    chunks.mode = ChunkMode::kOn;
  else if (mode == "off")
    chunks.mode = ChunkMode::kOff;
  else
    return usage_error("--chunks must be auto, on or off, got '" + mode + "'");
  if (cell != "auto") {
    char* end = nullptr;
    const long e = std::strtol(cell.c_str(), &end, 10);
    if (cell.empty() || *end != '\0' || e < -60 || e > 60)
      return usage_error(
          "--chunk-cell must be auto or a whole number in -60..60 (the cell side is 2^N world units), got '" + cell +
          "'");
    chunks.cell_exponent = static_cast<int>(e);
  }
  return Status::ok();
}

MappingOptionHandles add_mapping_options(CLI::Option_group* group, MappingArgs& args, MapTextureOptions& options,
                                         bool with_input_files) {
  MappingOptions& mapping = options.mapping;
  MappingOptionHandles handles;
  add_documented(group, option_doc(kMappingOptionDocs, "mode"), args.mode);
  handles.scale = add_documented(group, option_doc(kMappingOptionDocs, "scale"), mapping.scale);
  add_documented(group, option_doc(kMappingOptionDocs, "max_stretch"), mapping.max_stretch);
  group
      ->add_option("--field-following", args.field_following,
                   std::string(option_doc(kMappingOptionDocs, "field_following").help))
      ->capture_default_str();
  add_documented(group, option_doc(kMappingOptionDocs, "min_patch_faces"), mapping.min_patch_faces);
  add_documented(group, option_doc(kMappingOptionDocs, "hop_age"), mapping.hop_age);
  add_off_switch(group, option_doc(kMappingOptionDocs, "shorten_seams"), mapping.shorten_seams);
  add_off_switch(group, option_doc(kMappingOptionDocs, "close_cracks"), mapping.close_cracks);
  handles.crack_rings = add_documented(group, option_doc(kMappingOptionDocs, "crack_rings"), mapping.crack_rings);
  add_documented(group, option_doc(kMappingOptionDocs, "relax_iterations"), mapping.relax_iterations);
  for (const OptionDoc* doc : kPatchesOnlyOptions)
    handles.patches_only.push_back(group->get_option(std::string(doc->flag)));
  handles.threshold = add_documented(group, option_doc(kMappingOptionDocs, "threshold_px"), mapping.threshold_px);
  add_documented(group, option_doc(kOrientationOptionDocs, "axis"), args.axis);
  handles.smooth =
      add_documented(group, option_doc(kOrientationOptionDocs, "smooth_passes"), options.orientation.smooth_passes);
  add_documented(group, option_doc(kMappingOptionDocs, "seed_point"), args.seed_point);
  if (with_input_files) {
    add_documented(group, option_doc(kMappingOptionDocs, "seam_faces"), args.seam_faces);
    add_documented(group, option_doc(kOrientationOptionDocs, "strokes"), args.strokes);
  }
  handles.symmetry = add_documented(group, option_doc(kMappingOptionDocs, "symmetry"), mapping.symmetry)
                         ->check(CLI::IsMember({1u, 4u}));
  add_documented(group, option_doc(kChunkOptionDocs, "mode"), args.chunks);
  add_documented(group, option_doc(kChunkOptionDocs, "cell_exponent"), args.chunk_cell);
  add_documented(group, option_doc(kChunkOptionDocs, "split_above"), options.chunks.split_above);
  return handles;
}

void note_given_options(const MappingOptionHandles& handles, MappingArgs& args) {
  args.crack_rings_given = handles.crack_rings->count() > 0;
  args.symmetry_given = handles.symmetry->count() > 0;
  args.threshold_given = handles.threshold->count() > 0;
  args.patches_only_given.clear();
  for (const CLI::Option* o : handles.patches_only)
    if (o->count() > 0 && args.patches_only_given.empty()) args.patches_only_given = o->get_name();
}

Status apply_mapping_args(const MappingArgs& args, MapTextureOptions& options) {
  const auto usage_error = [](const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); };
  if (!args.auto_axis()) {
    if (Status s = parse_axis(args.axis, options.orientation); !s) return s;
  }
  MappingOptions& mapping = options.mapping;
  if (!mapping_mode_from_name(args.mode, mapping.mode))
    return usage_error("--mode must be patches or thesis, got '" + args.mode + "'");
  if (Status s = check_mode_options(mapping.mode, args.patches_only_given, args.threshold_given); !s) return s;
  if (!args.seed_point.empty()) {
    if (!parse_vec3(args.seed_point, mapping.seed_point))
      return usage_error("--seed-point must be three numbers X,Y,Z, got '" + args.seed_point + "'");
    mapping.use_seed_point = true;
  }
  if (Status s = check_texture_size(args.texture_size); !s) return s;
  if (Status s = parse_chunk_args(args.chunks, args.chunk_cell, options.chunks); !s) return s;
  if (Status s = check_map_options(options); !s) return s;  // scale, hop age, symmetry
  if (!args.auto_field_following() && !parse_unit_float(args.field_following, mapping.field_following))
    return usage_error("--field-following must be auto or a number in [0, 1], got '" + args.field_following + "'");
  return Status::ok();
}

Status write_mapped_mesh(const std::string& path, const Mesh& mesh, const Atlas& atlas, const MeshOutput& output,
                         const ProgressCallback& progress) {
  ExportOptions export_options;
  export_options.texture_path = output.texture_path;
  export_options.texture_image = output.texture_image;
  export_options.material = output.material;
  export_options.texture_width = output.texture_width;
  export_options.texture_height = output.texture_height;
  export_options.compression = output.compression;
  export_options.uv_set = output.uv_set;
  export_options.up = output.up;
  export_options.symmetry = output.symmetry;
  export_options.other_outputs = output.other_outputs;
  export_options.progress = progress;
  return export_mesh(path, mesh, atlas, export_options);
}

void warn_unused_input(const std::string& input, const LoadReport& load, bool quiet) {
  if (!load.not_kept.empty()) warn(quiet, input + ": not kept in the output: " + load.not_kept);
  if (!load.not_read.empty()) warn(quiet, input + ": not read: " + load.not_read);
  if (load.skipped_primitives)
    warn(quiet, input + ": skipped " + std::to_string(load.skipped_primitives) +
                    " point and line primitives (only triangles are mapped)");
}

bool turn_wound_faces(const std::string& input, Mesh& mesh, const Topology& topology, LoadReport& load, bool quiet,
                      const std::string& hint) {
  load.faces_turned = orient_faces_coherently(mesh, topology);
  if (load.faces_turned == 0) return false;
  warn(quiet, input + ": turned " + std::to_string(load.faces_turned) +
                  " faces wound against their neighbours, so that the surface runs one way" + hint);
  return true;
}

}  // namespace tailor::cli
