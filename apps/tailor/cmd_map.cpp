// tailor map: load -> [topology, axis choice] -> map_texture (orientation, mapping) -> topology ->
// metrics -> export (+ preview, stats).
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli.h"
#include "map_shared.h"
#include "memory_policy.h"
#include "tailor/axis_choice.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/io.h"
#include "tailor/map_warnings.h"
#include "tailor/mapping.h"
#include "tailor/material.h"
#include "tailor/metrics.h"
#include "tailor/orientation.h"
#include "tailor/render.h"
#include "tailor/report.h"
#include "tailor/stability.h"
#include "tailor/texture_direction.h"
#include "tailor/topology.h"
#include "util/atomic_file.h"

namespace tailor::cli {
namespace {

// The command line of `tailor map`. The library's options are bound to their flags in `options`
// (defaults: the structs' own); those given as text are parsed in run_map.
struct MapArgs {
  std::vector<std::string> inputs;  // as given: files or folders
  std::string input;                // the one being mapped
  std::string output;
  std::string texture;
  std::string material;            // --material: a folder of PBR maps or a JSON naming them (material.h)
  ImageLoadOptions image_options;  // --max-image-pixels (default: ImageLoadOptions')
  std::string compress = mesh_compression_name(ExportOptions{}.compression);
  int uv_set = ExportOptions{}.uv_set;
  std::string up = ExportOptions{}.up == SceneUp::kZ ? "z" : "y";
  double tile_size = 0;        // --tile-size: scene units per texture repeat (0: not given)
  double texels_per_unit = 0;  // --texels-per-unit (0: not given)
  bool tile_size_given = false, texels_per_unit_given = false;
  std::string preview_up = up_axis_name(RenderOptions{}.up);
  std::string stats;
  std::string preview;
  bool preview_all = false;
  MapTextureOptions options;
  MappingArgs mapping_args;  // the mapping options given as text (map_shared.h)
  bool stability = false;
  StabilityOptions stability_options;  // --pin-frame, --remove-fraction (with --stability)
  bool keep_winding = false;           // --keep-winding: faces wound against their neighbours stay as they are
  bool quiet = false;
};

// "out/a.png" + "patches" -> "out/a_patches.png"
std::string sibling_path(const std::string& path, const std::string& suffix) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "_" + suffix + p.extension().string())).string();
}

// The preview pictures to write: the texture view, plus the other views with --preview-all.
std::vector<std::pair<PreviewView, std::string>> preview_paths(const MapArgs& opt) {
  std::vector<std::pair<PreviewView, std::string>> views;
  if (opt.preview.empty()) return views;
  views.emplace_back(PreviewView::kTexture, opt.preview);
  if (opt.preview_all) {
    for (PreviewView v : {PreviewView::kPatches, PreviewView::kDistortion, PreviewView::kChecker, PreviewView::kSeams})
      views.emplace_back(v, sibling_path(opt.preview, preview_view_name(v)));
  }
  return views;
}

// Every file this run will write, with the option that names it.
std::vector<OutputPath> output_paths(const MapArgs& opt) {
  std::vector<OutputPath> outputs = {{opt.output, "--output"}};
  if (extension_of(opt.output) == "obj") outputs.push_back({obj_material_path(opt.output), "the .mtl of --output"});
  if (!opt.stats.empty()) outputs.push_back({opt.stats, "--stats"});
  for (const auto& view_path : preview_paths(opt)) outputs.push_back({view_path.second, "--preview"});
  return outputs;
}

int run_map(const MapArgs& opt) {
  const auto start = std::chrono::steady_clock::now();
  // === Options (checked before any work) ===
  const std::string ext = "." + extension_of(opt.output);  // lower case, as export_mesh reads it
  if (ext != ".glb" && ext != ".obj" && ext != ".ply")
    return report_error(usage_error("output must end in .glb, .obj or .ply, got '" + opt.output + "'"));
  MeshCompression compression = MeshCompression::kNone;
  if (!mesh_compression_from_name(opt.compress, compression))
    return report_error(usage_error("--compress must be none, quantize, meshopt or draco, got '" + opt.compress + "'"));
  if (compression != MeshCompression::kNone && ext != ".glb")
    return report_error(usage_error("--compress needs a .glb output, got '" + opt.output + "'"));
  if (opt.up != "y" && opt.up != "z") return report_error(usage_error("--up must be y or z, got '" + opt.up + "'"));
  if (opt.up == "z" && ext != ".glb")
    return report_error(usage_error("--up z needs a .glb output (OBJ and PLY keep the positions as they are), got '" +
                                    opt.output + "'"));
  // Given, each must be a length or density (0 would mean "not given" and be ignored silently).
  if ((opt.tile_size_given && !(opt.tile_size > 0 && std::isfinite(opt.tile_size))) ||
      (opt.texels_per_unit_given && !(opt.texels_per_unit > 0 && std::isfinite(opt.texels_per_unit))))
    return report_error(usage_error("--tile-size and --texels-per-unit must be positive"));
  if (opt.uv_set != 0 && ext != ".glb")
    return report_error(usage_error("--uv-set needs a .glb output, got '" + opt.output + "'"));
  const MappingArgs& args = opt.mapping_args;
  MapTextureOptions options = opt.options;
  if (Status s = apply_mapping_args(args, options); !s) return report_error(s);
  const bool auto_axis = args.auto_axis();
  MappingOptions& mapping = options.mapping;
  if (!opt.preview.empty() && !ends_with_png(opt.preview))
    return report_error(usage_error("--preview must name a .png file, got '" + opt.preview + "'"));
  UpAxis preview_up = RenderOptions{}.up;
  if (!up_axis_from_name(opt.preview_up, preview_up))
    return report_error(usage_error("--preview-up must be x, y, z, -x, -y or -z, got '" + opt.preview_up + "'"));
  if (!opt.material.empty() && !opt.texture.empty())
    return report_error(
        usage_error("give --texture or --material, not both (the material's colour map is the texture)"));
  if (!opt.material.empty() && ext != ".glb")
    return report_error(usage_error("--material needs a .glb output, got '" + opt.output + "'"));
  if (Status s = check_outputs(output_paths(opt), {opt.input, opt.texture, args.seam_faces, args.strokes}); !s)
    return report_error(s);
  std::vector<OrientationStroke> strokes;  // read first too: a bad file fails before any work
  if (!args.strokes.empty()) {
    if (Status s = load_strokes(args.strokes, strokes); !s) return report_error(s);
    options.orientation.strokes = strokes;
  }

  // === Texture and material (read first: a bad map should fail before minutes of work) ===
  MaterialMaps material;
  std::string texture_path = opt.texture;
  if (!opt.material.empty()) {
    if (Status s = load_material(opt.material, material, opt.image_options); !s) return report_error(s);
    // The material's files are inputs too: its JSON (a folder's material.json) and every map read.
    std::vector<std::string> material_inputs = {opt.material,
                                                (std::filesystem::path(opt.material) / "material.json").string()};
    for (const std::string& file : material.files) material_inputs.push_back(file.substr(file.find(": ") + 2));
    if (Status s = check_outputs(output_paths(opt), material_inputs); !s) return report_error(s);
    for (const std::string& note : material.notes) warn(opt.quiet, note);
    texture_path = material.color;
    // A set of quarter-turn tiles (`tailor tile --set --symmetry 4`) is mapped for them unless told.
    if (material.symmetry == 4 && !args.symmetry_given && mapping.mode == MappingMode::kPatches) {
      mapping.symmetry = 4;
      if (!opt.quiet)
        std::fprintf(stderr, "symmetry 4: %s records quarter-turn tiles (--symmetry 1 maps them as plain tiles)\n",
                     opt.material.c_str());
    }
  }
  Image texture;
  if (!texture_path.empty()) {
    if (Status s = load_image(texture_path, texture, opt.image_options); !s) return report_error(s);
  }
  // The UV lattice: the texture's size (a material's: its colour map's, which every map shares).
  const int tex_w = !texture.empty() ? texture.width : material.width > 0 ? material.width : args.texture_size;
  const int tex_h = !texture.empty() ? texture.height : material.height > 0 ? material.height : args.texture_size;
  // The lattice period, the metrics' texture size, the threads of every stage.
  if (Status s = set_map_texture_size(options, tex_w, tex_h); !s) return report_error(s);
  // auto: follow the field unless the texture has no direction to follow (texture_direction.h).
  float texture_isotropy = -1.f;
  if (args.auto_field_following()) {
    Progress measuring("texture", opt.quiet);
    texture_isotropy = adapt_mapping_to_texture(texture, mapping, args.crack_rings_given,
                                                [&measuring](float f) { return measuring.update(f); });
  }

  // === Load, topology, orientation ===
  Mesh mesh;
  LoadReport load;
  {
    const ReadingInput reading(opt.input);
    Progress loading("loading", opt.quiet);
    if (Status s = load_mesh(opt.input, mesh, &load, [&loading](float f) { return loading.update(f); }); !s)
      return report_error(s);
  }
  if (Status s = check_uv_set(mesh, opt.uv_set, opt.input); !s) return report_error(s);
  if (load.degenerate_faces)
    warn(opt.quiet, opt.input + ": dropped " + std::to_string(load.degenerate_faces) + " degenerate faces");
  if (load.duplicate_faces)
    warn(opt.quiet, opt.input + ": dropped " + std::to_string(load.duplicate_faces) + " duplicate faces");
  warn_unused_input(opt.input, load, opt.quiet);
  warn_texture_transform(opt.quiet, opt.input, load.texture_transform);
  std::vector<uint8_t> seam_faces;
  if (!args.seam_faces.empty()) {
    if (Status s = load_seam_faces(args.seam_faces, mesh.face_count(), seam_faces); !s) return report_error(s);
    mapping.seam_faces = seam_faces;
  } else if (!mesh.seam_faces.empty()) {
    mapping.seam_faces = mesh.seam_faces;
  }
  // The topology serves the axis choice and the metrics; the mapping builds its own per chunk (or
  // for the canonical whole), so unless the axis is chosen the mesh's is built after the mapping,
  // when the mapping's memory is back (16 bytes per face less at its peak).
  Topology topology;
  const auto connect = [&] {
    Progress connecting("topology", opt.quiet);
    topology = build_topology(
        mesh, [&connecting](float f) { return connecting.update(f); }, mapping.threads);
    connecting.done();
  };
  // Faces wound against their neighbours turn to run as the surface around them (unless
  // --keep-winding): mapped as they are, they would be cut apart with their edges counted as seams.
  // The topology that finds them is built after the mapping (unless the axis choice needs it first),
  // so a mesh that has them is mapped again after the turn: nothing is spent on meshes without.
  const auto turn_faces = [&]() -> bool {
    if (opt.keep_winding ||
        !turn_wound_faces(opt.input, mesh, topology, load, opt.quiet, " (--keep-winding keeps them as they are)"))
      return false;
    topology = Topology{};
    return true;
  };
  double turning_seconds = 0;  // the turn, and a mapping before it that found the faces (MapRun)
  const auto warn_unpaired = [&] {
    if (topology.nonmanifold_edges || topology.inconsistent_edges)
      warn(opt.quiet,
           opt.input + ": " + std::to_string(topology.nonmanifold_edges) + " non-manifold and " +
               std::to_string(topology.inconsistent_edges) + " inconsistently oriented edges treated as boundary" +
               (topology.inconsistent_edges
                    ? std::string(opt.keep_winding ? " (faces wound against their neighbours are mapped apart and "
                                                     "their edges counted as seams: without --keep-winding they turn)"
                                                   : " (a band whose two sides meet turned, as in a Moebius strip: "
                                                     "no winding runs one way across it)")
                    : std::string()));
  };
  if (auto_axis) {
    connect();
    const auto turning_start = std::chrono::steady_clock::now();
    if (turn_faces()) connect();
    turning_seconds = seconds_since(turning_start);
    warn_unpaired();
  }
  // World units: the texel density is per scene unit, the same for every mesh (the mapping works
  // in the unit cube: its scale becomes texels per unit times the normalisation's length).
  double texels_per_unit = opt.texels_per_unit;
  if (opt.tile_size > 0) texels_per_unit = tex_w / opt.tile_size;
  if (texels_per_unit > 0) {
    std::array<double, 3> lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
      for (size_t k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], double{mesh.positions[3 * v + k]});
        hi[k] = std::max(hi[k], double{mesh.positions[3 * v + k]});
      }
    const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-30});
    options.orientation.fixed_unit_scale = static_cast<float>(1.0 / longest);
    options.orientation.fixed_origin = {static_cast<float>(lo[0]), static_cast<float>(lo[1]),
                                        static_cast<float>(lo[2])};
    const double scale = texels_per_unit / options.orientation.fixed_unit_scale;
    if (!(scale >= MappingLimits::min_scale && scale <= MappingLimits::max_scale)) {
      char figure[32];
      std::snprintf(figure, sizeof figure, "%.3g", scale);  // std::to_string's %f printed 0.000000
      return report_error(usage_error("--tile-size / --texels-per-unit give " + std::string(figure) +
                                      " pixels per mesh size, outside " + limit_text(MappingLimits::min_scale) +
                                      " to " + limit_text(MappingLimits::max_scale)));
    }
    mapping.scale = static_cast<float>(scale);
  }
  // Symmetry 4: a texture that is not a 4-fold tile, or repeats less than once across the mesh.
  for (const std::string& line : map_warnings(mesh, options, texture, texture_path)) warn(opt.quiet, line);
  MapRun run;  // the report: what was asked, then what each step found
  run.texels_per_unit = texels_per_unit;
  run.up = opt.up;
  run.input = opt.input;
  run.output = opt.output;
  run.texture = texture_path;
  run.texture_width = tex_w;
  run.texture_height = tex_h;
  run.texture_isotropy = texture_isotropy;
  run.field_following_auto = args.auto_field_following();
  run.axis = args.axis;
  run.axis_auto = auto_axis;
  run.seed_point = args.seed_point;
  run.seam_faces = args.seam_faces;
  if (auto_axis) {
    const auto axis_start = std::chrono::steady_clock::now();
    Progress choosing("choosing axis", opt.quiet);
    mapping.progress = [&choosing](float f) { return choosing.update(f); };
    AxisChoice choice;
    if (Status s = choose_orientation_axis(mesh, topology, options, choice); !s)
      return report_error(s.with_file(opt.input));
    choosing.done();
    run.axis_choice_seconds = seconds_since(axis_start);
    options.orientation = orientation_for(choice.best, options.orientation);
    run.axis = std::string("auto:") + axis_candidate_name(choice.best);
    if (!opt.quiet) {
      std::string line =
          "axis auto: " + std::string(axis_candidate_name(choice.best)) + " (seams without crack closing:";
      for (int i = 0; i < kAxisCandidates; ++i) {
        char item[32];
        std::snprintf(item, sizeof item, " %s %.2f%%", axis_candidate_name(static_cast<AxisCandidate>(i)),
                      100.0 * choice.seam_ratio[static_cast<size_t>(i)]);
        line += item;
      }
      std::fprintf(stderr, "%s)\n", line.c_str());
    }
  }
  // === Orientation, mapping, metrics ===
  TextureMap map;
  mapping.progress = nullptr;
  MapTextureOptions unmeasured = options;
  unmeasured.measure = false;
  const auto map_mesh = [&]() -> Status {
    Progress progress("orientation", opt.quiet);  // then mapping, closing, relaxing: a bar each
    unmeasured.stage_progress = [&progress](std::string_view stage, float f) { return progress.update(stage, f); };
    const KeepScratch keep;  // every chunk's scratch reused, not faulted in again
    Status s = map_texture(mesh, topology, unmeasured, map);
    if (s) progress.done();
    return s;
  };
  const auto first_map_start = std::chrono::steady_clock::now();
  if (Status s = map_mesh(); !s) return report_error(s.with_file(opt.input));
  if (topology.opposite.empty()) {
    connect();
    if (turn_faces()) {
      turning_seconds = seconds_since(first_map_start);  // the mapping that found them, spent
      if (!opt.quiet) std::fprintf(stderr, "mapping again with the faces turned\n");
      if (Status s = map_mesh(); !s) return report_error(s.with_file(opt.input));
      connect();
    }
    warn_unpaired();
  }
  {
    Progress measuring("metrics", opt.quiet);
    MapTextureOptions measured = options;
    measured.stage_progress = [&measuring](std::string_view, float f) { return measuring.update(f); };
    if (Status s = measure_texture_map(mesh, topology, measured, map); !s) return report_error(s.with_file(opt.input));
    measuring.done();
  }
  const Atlas& atlas = map.atlas;
  run.options = options;
  run.turning_seconds = turning_seconds;
  add_map_results(mesh, load, topology, map, run);
  if (map.stats.chunks > 1 && mesh.face_count() / map.stats.chunks < 1000)  // one chunk has no border
    warn(opt.quiet, opt.input + ": " + std::to_string(map.stats.chunks) + " chunks of " +
                        std::to_string(mesh.face_count() / map.stats.chunks) +
                        " faces on average: every chunk border is a seam; a larger --chunk-cell keeps more of the "
                        "surface in one piece");
  topology = Topology{};  // 16 bytes per face nothing after the metrics reads: freed before the export

  // === Stability (optional: two more mappings) ===
  if (opt.stability) {
    StabilityReport stability;
    const KeepScratch keep;
    if (Status s = measure_stability(mesh, options, stability, opt.stability_options); !s)
      return report_error(s.with_file(opt.input));
    run.stability = stability;
  }

  // === Previews, rendered before anything is written ===
  std::vector<std::pair<std::string, Image>> pictures;
  if (!opt.preview.empty()) {
    const auto preview_start = std::chrono::steady_clock::now();
    std::vector<float> uv_repeats(atlas.corner_uv.size());
    for (size_t i = 0; i < uv_repeats.size(); i += 2) {
      uv_repeats[i] = atlas.corner_uv[i] / static_cast<float>(tex_w);
      uv_repeats[i + 1] = atlas.corner_uv[i + 1] / static_cast<float>(tex_h);
    }
    for (const auto& [view, path] : preview_paths(opt)) {
      RenderOptions render_options;
      render_options.view = view;
      render_options.up = preview_up;
      render_options.seam_texture_px = texture.empty() ? tex_w : 0;  // a material without colour: its maps' size
      render_options.seam_symmetry = mapping.symmetry;
      PreviewMaterial shading;  // a material's normal and occlusion maps (tangents as the .glb gets them)
      if (!material.normal_image.empty()) shading.normal = &material.normal_image;
      if (!material.occlusion_image.empty()) shading.occlusion = &material.occlusion_image;
      Image picture;
      if (Status s = render_preview(mesh, uv_repeats, atlas.patch, texture.empty() ? nullptr : &texture, shading,
                                    render_options, picture);
          !s)
        return report_error(s.with_file(path));
      pictures.emplace_back(path, std::move(picture));
    }
    run.preview_seconds = seconds_since(preview_start);
  }

  // === Export, then the pictures, then the report (every output was checked up front) ===
  std::vector<uint32_t>().swap(map.atlas.patch);  // the export writes UVs only: 4 bytes per face back first
  // Staged together: they land only when all of them were written (nothing on a late failure).
  internal::FileBatch batch;
  const auto export_start = std::chrono::steady_clock::now();
  MeshOutput output{texture_path,
                    std::move(material.textures),
                    tex_w,
                    tex_h,
                    compression,
                    opt.uv_set,
                    opt.up == "z" ? SceneUp::kZ : SceneUp::kY,
                    mapping.symmetry,
                    {}};
  for (const OutputPath& other : output_paths(opt)) output.other_outputs.push_back(other.path);
  if (!texture.empty()) output.texture_image = &texture;
  Progress exporting("export", opt.quiet);
  if (Status s =
          write_mapped_mesh(opt.output, mesh, atlas, output, [&exporting](float f) { return exporting.update(f); });
      !s)
    return report_error(s);
  exporting.done();
  run.export_seconds = seconds_since(export_start);
  for (const auto& [path, picture] : pictures) {
    if (Status s = write_png(path, picture); !s) return report_error(s);
    run.previews.push_back(path);
  }

  run.total_seconds = seconds_since(start);
  if (rusage usage{}; getrusage(RUSAGE_SELF, &usage) == 0)
    run.peak_resident_bytes = static_cast<size_t>(usage.ru_maxrss) * 1024;  // Linux: kilobytes

  // === Report ===
  if (!opt.stats.empty()) {
    if (Status s = internal::write_file_atomic(opt.stats, map_report_json(run)); !s) return report_error(s);
  }
  if (Status s = batch.commit(); !s) return report_error(s);
  if (!opt.quiet) {
    std::fputs(map_summary(run).c_str(), stdout);
    for (const std::string& p : run.previews) std::printf("preview: %s\n", p.c_str());
    if (!opt.stats.empty()) std::printf("stats: %s\n", opt.stats.c_str());
  }
  return kExitOk;
}

// Mesh files of a folder (not its subfolders), by the readers' extensions, sorted by name.
std::vector<std::string> meshes_in(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    if (entry.is_regular_file(error) && mesh_format_from_path(entry.path().string()) != MeshFormat::kUnknown)
      files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// `tailor map` over its inputs: one run_map for a single file; for several (or a folder) one per
// file into the output folder, a summary line each and a total, going on past a failed file.
int run_map_inputs(const MapArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const std::string& out = args.output;
  std::error_code error;
  const bool out_folder = (!out.empty() && out.back() == '/') || std::filesystem::is_directory(out, error);
  // One input and a file to write: a single map (a folder as input then fails as any non-file does).
  if (args.inputs.size() == 1 && !out_folder) {
    MapArgs one = args;
    one.input = args.inputs[0];
    return run_map(one);
  }
  if (!out_folder)
    return report_error(
        usage_error("-o must be a folder (ending in '/') for several inputs or a folder, got '" + out + "'"));
  if (!args.stats.empty() || !args.preview.empty())
    return report_error(usage_error("--stats and --preview name one file: give a single input"));
  std::vector<std::string> files;
  for (const std::string& input : args.inputs) {
    if (std::filesystem::is_directory(input, error)) {
      const std::vector<std::string> found = meshes_in(input);
      if (found.empty()) return report_error(usage_error("no mesh file in the folder '" + input + "'"));
      files.insert(files.end(), found.begin(), found.end());
    } else {
      files.push_back(input);
    }
  }
  // One output per input, named after it: two inputs of one name would write the same file.
  std::vector<std::pair<std::string, std::string>> outputs;  // (output, input)
  for (const std::string& file : files) {
    const std::string target = (std::filesystem::path(out) / std::filesystem::path(file).stem()).string() + ".glb";
    for (const auto& [other_out, other_in] : outputs)
      if (other_out == target)
        return report_error(usage_error("'" + other_in + "' and '" + file + "' would both write '" + target + "'"));
    outputs.emplace_back(target, file);
  }
  if (!std::filesystem::is_directory(out, error) && !std::filesystem::create_directory(out, error))
    return report_error(Status::error(ErrorCode::kIo, out, "cannot create the output folder: " + error.message()));
  const bool terminal = !args.quiet && isatty(STDERR_FILENO) == 1;
  size_t failed = 0;
  std::string failures;
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (terminal) std::fprintf(stderr, "tailor: [%zu/%zu] %s\n", i + 1, outputs.size(), outputs[i].second.c_str());
    MapArgs one = args;
    one.input = outputs[i].second;
    one.output = outputs[i].first;
    const int rc = run_map(one);
    std::fflush(stdout);
    if (rc == kExitUsage) return rc;  // the options are wrong for every file
    if (rc != kExitOk) {
      ++failed;
      failures += (failures.empty() ? "" : ", ") + outputs[i].second;
    }
  }
  if (!args.quiet)
    std::printf("batch: %s, %zu mapped, %zu failed%s in %.2f s -> %s\n",
                counted(outputs.size(), "file", "files").c_str(), outputs.size() - failed, failed,
                failures.empty() ? "" : (" (" + failures + ")").c_str(), seconds_since(start), out.c_str());
  return failed ? kExitBadInput : kExitOk;
}

}  // namespace

void register_map(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<MapArgs>();
  MappingOptions& mapping = opt->options.mapping;
  auto* cmd =
      app.add_subcommand("map", "Compute texture coordinates by homogeneous patch discovery and write a textured mesh");
  cmd->add_option("mesh", opt->inputs,
                  "Input meshes (.ply .obj .off .stl .glb .gltf; glTF: the default scene in world space); several "
                  "files or a folder map each into the folder -o names")
      ->required();
  cmd->add_option("-o,--output", opt->output,
                  "Output mesh: .glb (texture embedded), .obj (+ .mtl) or .ply; a symlink is written through (its "
                  "target replaced). With several inputs or a folder: an existing folder (or one ending in '/'), "
                  "where each input becomes <name>.glb")
      ->required();
  cmd->add_option("-t,--texture", opt->texture,
                  "Texture image (PNG/JPEG), ideally self-tileable (see 'tailor tile'); sets the texture size");
  cmd->add_option(
      "--material", opt->material,
      "PBR material instead of --texture (.glb output): a folder whose maps are recognised by name "
      "(NAME_color/albedo/basecolor/diffuse, _normal/_nor/_nrm, the first two with _gl or _dx, _roughness/_rough, "
      "_metallic/_metalness, _ao/_occlusion, _height/_disp), or a JSON naming them ({\"color\": "
      "\"a.png\", \"normal\": \"b.png\", ...}, or OUTDIR/material.json of 'tailor tile --set'). "
      "The colour map sets the texture size; all maps must share it. The .glb gets baseColor, normal "
      "(+ per-vertex tangents; a DX map's green is flipped), metallicRoughness (G roughness, B "
      "metallic) and occlusion (R); height is not a glTF map and is left out. The quarter-turn tiles "
      "of 'tailor tile --set --symmetry 4' are mapped with --symmetry 4 unless --symmetry says otherwise");
  cmd->add_option("--texture-size", opt->mapping_args.texture_size,
                  "Texture size in pixels when no --texture is given (at most 65536, as 'tailor eval' reads)")
      ->capture_default_str();
  add_documented(cmd, option_doc(kImageLoadOptionDocs, "max_pixels"), opt->image_options.max_pixels)
      ->check(kAtLeastOne);
  add_documented(cmd, option_doc(kExportOptionDocs, "compression"), opt->compress);
  add_documented(cmd, option_doc(kExportOptionDocs, "uv_set"), opt->uv_set)->check(CLI::Range(0, 7));
  add_documented(cmd, option_doc(kExportOptionDocs, "up"), opt->up);
  auto* tile_size = cmd->add_option("--tile-size", opt->tile_size,
                                    "World units: the texture repeats every LENGTH scene units (e.g. 0.5 for 50 cm "
                                    "in metres), the same for every mesh; replaces --scale");
  auto* texels = cmd->add_option("--texels-per-unit", opt->texels_per_unit,
                                 "World units: texture pixels per scene unit, the same for every mesh; replaces "
                                 "--scale");
  tile_size->excludes(texels);
  cmd->add_option("--stats", opt->stats, "Write a JSON report (mesh, mapping counters, metrics, timings)");
  auto* preview = cmd->add_option("--preview", opt->preview, "Render a 3/4 view of the textured mesh to this PNG");
  cmd->add_flag("--preview-all", opt->preview_all,
                "With --preview, also write <name>_patches.png, <name>_distortion.png, <name>_checker.png and "
                "<name>_seams.png")
      ->needs(preview);
  cmd->add_option("--preview-up", opt->preview_up, std::string(option_doc(kRenderOptionDocs, "up").help))
      ->capture_default_str();
  auto* group = cmd->add_option_group("Mapping");
  const MappingOptionHandles handles = add_mapping_options(group, opt->mapping_args, opt->options, true);
  tile_size->excludes(handles.scale);
  texels->excludes(handles.scale);
  auto* stability = cmd->add_flag(
      "--stability", opt->stability,
      "Also map the mesh again in another file order, and with ~10% of its faces removed (fresh runs, "
      "as tailor eval --stability), and report how many UVs kept their bits and how far the others moved");
  add_stability_options(cmd, stability, opt->stability_options.pin_frame, opt->stability_options.remove_fraction);
  cmd->add_option("--threads", mapping.threads,
                  "Threads: chunks (--chunks) are planned on them and mapped one per thread (0 = one per core); a "
                  "mesh mapped whole uses "
                  "them for its orientation, crack closing and metrics (0 = one per core, up to 8, where the mesh is "
                  "large enough); the output is the same for any count")
      ->capture_default_str()
      ->check(CLI::Range(0u, 64u));
  cmd->add_flag("--keep-winding", opt->keep_winding,
                "Keep faces wound against their neighbours as they are (mapped apart, their edges counted as "
                "seams); by default they turn to run as the surface around them, in the output too, and the "
                "mesh is mapped again");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but errors");
  cmd->footer(
      "Example:\n"
      "  tailor tile gravel.png -o gravel_tile.png\n"
      "  tailor map bunny.ply --texture gravel_tile.png -o bunny.glb --stats bunny.json --preview bunny.png\n"
      "  tailor map bunny.ply --material bricks/ -o bunny.glb   # bricks/bricks_color.png, _normal.png, ...\n"
      "Prints one summary line: faces, patches, repeats across the mesh, seam length, flipped faces, stretch,\n"
      "Sander L2/Linf, median angle distortion, visible seams, the time of each stage and the peak memory.\n"
      "Trade-offs: --no-crack-closing maps 3-10x faster and keeps more UVs bit-identical when parts of\n"
      "the mesh change, with about twice the seam length. --field-following auto (the default) maps a\n"
      "texture without a direction (gravel, grass; its isotropy is in the --stats) with rigid unfolding\n"
      "and 32 crack rings, the fewest seams; --field-following 1 keeps the orientation field, and\n"
      "the UVs of a mesh that is edited and re-mapped more stable (docs/mapping.md section 7).");
  cmd->callback([&run, opt, handles, tile_size, texels] {
    opt->tile_size_given = tile_size->count() > 0;
    opt->texels_per_unit_given = texels->count() > 0;
    note_given_options(handles, opt->mapping_args);
    run = [opt] { return run_map_inputs(*opt); };
  });
}

}  // namespace tailor::cli
