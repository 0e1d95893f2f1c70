// tailor map: load -> topology -> orientation -> mapping -> metrics -> export (+ preview, stats).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "util/atomic_file.h"
#include "tailor/axis_choice.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/metrics.h"
#include "tailor/orientation.h"
#include "tailor/render.h"
#include "tailor/stability.h"
#include "tailor/topology.h"

namespace tailor::cli {
namespace {

struct MapOptions {
  std::string input;
  std::string output;
  std::string texture;
  int texture_size = 512;
  std::string preview_up = "y";
  std::string stats;
  std::string preview;
  bool preview_all = false;
  std::string mode = "patches";
  float scale = 800.f;
  float threshold = 25.f;
  float max_stretch = 0.25f;
  float field_following = 1.f;
  uint32_t min_patch_faces = 16;
  bool keep_seams = false;
  bool keep_cracks = false;
  uint32_t crack_rings = 16;
  uint32_t relax_iterations = 10;
  float hop_age = 0.02f;
  std::string axis = "pca";
  uint32_t smooth = 0;
  std::string seed_point;
  std::string seam_faces;
  bool stability = false;
  uint32_t threads = 0;
  bool quiet = false;
};

Status usage_error(const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); }

Status parse_axis(const std::string& text, OrientationOptions& o) {
  if (text == "pca") {
    o.axis = AxisSource::kPca;
    return Status::ok();
  }
  o.axis = AxisSource::kUser;
  if (text == "x") o.user_axis = {1, 0, 0};
  else if (text == "y") o.user_axis = {0, 1, 0};
  else if (text == "z") o.user_axis = {0, 0, 1};
  else if (!parse_vec3(text, o.user_axis))
    return usage_error("--axis must be pca, x, y, z or three numbers X,Y,Z, got '" + text + "'");
  return Status::ok();
}

// "out/a.png" + "patches" -> "out/a_patches.png"
std::string sibling_path(const std::string& path, const std::string& suffix) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "_" + suffix + p.extension().string())).string();
}

double ms(double seconds) { return seconds * 1e3; }

// The preview pictures to write: the texture view, plus the other views with --preview-all.
std::vector<std::pair<PreviewView, std::string>> preview_paths(const MapOptions& opt) {
  std::vector<std::pair<PreviewView, std::string>> views;
  if (opt.preview.empty()) return views;
  views.emplace_back(PreviewView::kTexture, opt.preview);
  if (opt.preview_all) {
    for (PreviewView v : {PreviewView::kPatches, PreviewView::kDistortion, PreviewView::kChecker})
      views.emplace_back(v, sibling_path(opt.preview, preview_view_name(v)));
  }
  return views;
}

// Every file this run will write, with the option that names it.
std::vector<OutputPath> output_paths(const MapOptions& opt) {
  std::vector<OutputPath> outputs = {{opt.output, "--output"}};
  if (std::filesystem::path(opt.output).extension() == ".obj")
    outputs.push_back({std::filesystem::path(opt.output).replace_extension(".mtl").string(), "the .mtl of --output"});
  if (!opt.stats.empty()) outputs.push_back({opt.stats, "--stats"});
  for (const auto& view_path : preview_paths(opt)) outputs.push_back({view_path.second, "--preview"});
  return outputs;
}

int run_map(const MapOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  // === Options (checked before any work) ===
  const std::string ext = std::filesystem::path(opt.output).extension().string();
  if (ext != ".glb" && ext != ".obj" && ext != ".ply")
    return report_error(usage_error("output must end in .glb, .obj or .ply, got '" + opt.output + "'"));
  OrientationOptions orientation_options;
  const bool auto_axis = opt.axis == "auto";
  if (!auto_axis) {
    if (Status s = parse_axis(opt.axis, orientation_options); !s) return report_error(s);
  }
  orientation_options.smooth_passes = opt.smooth;
  orientation_options.threads = opt.threads;
  MappingOptions mapping_options;
  mapping_options.threads = opt.threads;
  if (opt.mode == "patches") mapping_options.mode = MappingMode::kPatches;
  else if (opt.mode == "thesis") mapping_options.mode = MappingMode::kThesis;
  else return report_error(usage_error("--mode must be patches or thesis, got '" + opt.mode + "'"));
  mapping_options.scale = opt.scale;
  mapping_options.threshold_px = opt.threshold;
  mapping_options.max_stretch = opt.max_stretch;
  mapping_options.field_following = opt.field_following;
  mapping_options.min_patch_faces = opt.min_patch_faces;
  mapping_options.shorten_seams = !opt.keep_seams;
  mapping_options.close_cracks = !opt.keep_cracks;
  mapping_options.crack_rings = opt.crack_rings;
  mapping_options.relax_iterations = opt.relax_iterations;
  mapping_options.hop_age = opt.hop_age;
  if (!opt.seed_point.empty()) {
    if (!parse_vec3(opt.seed_point, mapping_options.seed_point))
      return report_error(usage_error("--seed-point must be three numbers X,Y,Z, got '" + opt.seed_point + "'"));
    mapping_options.use_seed_point = true;
  }
  if (opt.texture_size <= 0) return report_error(usage_error("--texture-size must be positive"));
  // Below ~1e-3 px per unit every UV rounds to the same float; above 1e7 faces span millions of px.
  if (!(opt.scale >= 1e-3f && opt.scale <= 1e7f))
    return report_error(usage_error("--scale must be between 0.001 and 1e7 pixels per unit"));
  UpAxis preview_up = UpAxis::kPosY;
  if (!up_axis_from_name(opt.preview_up, preview_up))
    return report_error(usage_error("--preview-up must be x, y, z, -x, -y or -z, got '" + opt.preview_up + "'"));
  if (!(opt.hop_age >= 0.f && opt.hop_age <= 1.f))
    return report_error(usage_error("--hop-age must be between 0 and 1 radians"));
  if (Status s = check_outputs(output_paths(opt), {opt.input, opt.texture, opt.seam_faces}); !s)
    return report_error(s);

  // === Texture (read first: a bad texture should fail before minutes of work) ===
  Image texture;
  if (!opt.texture.empty()) {
    if (Status s = load_image(opt.texture, texture); !s) return report_error(s);
  }
  const int tex_w = texture.empty() ? opt.texture_size : texture.width;
  const int tex_h = texture.empty() ? opt.texture_size : texture.height;

  // === Load, topology, orientation ===
  Mesh mesh;
  LoadReport load;
  {
    const ReadingInput reading(opt.input);
    if (Status s = load_mesh(opt.input, mesh, &load); !s) return report_error(s);
  }
  if (load.degenerate_faces) warn(opt.quiet, opt.input + ": dropped " + std::to_string(load.degenerate_faces) + " degenerate faces");
  if (load.duplicate_faces) warn(opt.quiet, opt.input + ": dropped " + std::to_string(load.duplicate_faces) + " duplicate faces");
  std::vector<uint8_t> seam_faces;
  if (!opt.seam_faces.empty()) {
    if (Status s = load_seam_faces(opt.seam_faces, mesh.face_count(), seam_faces); !s) return report_error(s);
    mapping_options.seam_faces = seam_faces;
  } else if (!mesh.seam_faces.empty()) {
    mapping_options.seam_faces = mesh.seam_faces;
  }
  const Topology topology = build_topology(mesh);
  if (topology.nonmanifold_edges || topology.inconsistent_edges)
    warn(opt.quiet, opt.input + ": " + std::to_string(topology.nonmanifold_edges) + " non-manifold and " +
                        std::to_string(topology.inconsistent_edges) + " inconsistently oriented edges treated as boundary");
  std::string axis_used = opt.axis;
  double axis_seconds = 0;
  if (auto_axis) {
    const auto axis_start = std::chrono::steady_clock::now();
    Progress choosing("choosing axis", opt.quiet);
    MappingOptions trial = mapping_options;
    trial.progress = [&choosing](float f) { return choosing.update(f); };
    AxisChoice choice;
    if (Status s = choose_orientation_axis(mesh, topology, orientation_options, trial, choice); !s)
      return report_error(s.with_file(opt.input));
    choosing.done();
    axis_seconds = seconds_since(axis_start);
    orientation_options = orientation_for(choice.best, orientation_options);
    axis_used = std::string("auto:") + axis_candidate_name(choice.best);
    if (!opt.quiet) {
      std::string line = "axis auto: " + std::string(axis_candidate_name(choice.best)) + " (seams without crack closing:";
      for (int i = 0; i < kAxisCandidates; ++i) {
        char item[32];
        std::snprintf(item, sizeof item, " %s %.2f%%", axis_candidate_name(static_cast<AxisCandidate>(i)),
                      100.0 * choice.seam_ratio[static_cast<size_t>(i)]);
        line += item;
      }
      std::fprintf(stderr, "%s)\n", line.c_str());
    }
  }
  FaceFrames frames;
  if (Status s = compute_orientation(mesh, topology, orientation_options, frames); !s)
    return report_error(s.with_file(opt.input));

  // === Mapping ===
  Progress progress("mapping", opt.quiet);
  mapping_options.progress = [&progress](float f) { return progress.update(f); };
  Atlas atlas;
  MappingStats stats;
  if (Status s = map_texture(mesh, topology, frames, mapping_options, atlas, &stats); !s)
    return report_error(s.with_file(opt.input));
  progress.done();

  // === Metrics ===
  const auto metrics_start = std::chrono::steady_clock::now();
  MetricsOptions metrics_options;
  metrics_options.texture_width_px = static_cast<float>(tex_w);
  metrics_options.texture_height_px = static_cast<float>(tex_h);
  metrics_options.threads = opt.threads;
  UvMetrics metrics;
  if (Status s = compute_uv_metrics(mesh, topology, atlas.corner_uv, atlas.patch, metrics_options, metrics); !s)
    return report_error(s.with_file(opt.input));
  const double metrics_seconds = seconds_since(metrics_start);

  // === Stability (optional: two more mappings) ===
  StabilityReport stability;
  if (opt.stability) {
    MappingOptions quiet_mapping = mapping_options;
    quiet_mapping.progress = nullptr;
    if (Status s = measure_stability(mesh, orientation_options, quiet_mapping, stability); !s)
      return report_error(s.with_file(opt.input));
  }

  // === Previews, rendered before anything is written ===
  std::vector<std::pair<std::string, Image>> pictures;
  double preview_seconds = 0;
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
      Image picture;
      if (Status s = render_preview(mesh, uv_repeats, atlas.patch, texture.empty() ? nullptr : &texture,
                                    render_options, picture);
          !s)
        return report_error(s.with_file(path));
      pictures.emplace_back(path, std::move(picture));
    }
    preview_seconds = seconds_since(preview_start);
  }

  // === Export, then the pictures, then the report (every output was checked up front) ===
  // Staged together: they land only when all of them were written (nothing on a late failure).
  internal::FileBatch batch;
  const auto export_start = std::chrono::steady_clock::now();
  ExportOptions export_options;
  export_options.texture_path = opt.texture;
  export_options.texture_width = tex_w;
  export_options.texture_height = tex_h;
  if (Status s = export_mesh(opt.output, mesh, atlas, export_options); !s) return report_error(s);
  const double export_seconds = seconds_since(export_start);
  std::vector<std::string> previews;
  for (const auto& [path, picture] : pictures) {
    if (Status s = write_png(path, picture); !s) return report_error(s);
    previews.push_back(path);
  }

  const double total_seconds = seconds_since(start);

  // === Report ===
  if (!opt.stats.empty()) {
    nlohmann::json j;
    j["input"] = opt.input;
    j["output"] = opt.output;
    j["texture"] = opt.texture;
    j["texture_size"] = {tex_w, tex_h};
    j["options"] = {{"mode", opt.mode}, {"scale", opt.scale}, {"threshold_px", opt.threshold},
                    {"max_stretch", opt.max_stretch},
                    {"field_following", opt.field_following}, {"min_patch_faces", opt.min_patch_faces},
                    {"shorten_seams", !opt.keep_seams}, {"close_cracks", !opt.keep_cracks}, {"crack_rings", opt.crack_rings}, {"hop_age", opt.hop_age},
                    {"relax_iterations", opt.relax_iterations},
                    {"axis", axis_used}, {"smooth", opt.smooth}, {"seed_point", opt.seed_point},
                    {"seam_faces", opt.seam_faces}};
    j["mesh"] = {{"format", load.format}, {"vertices", mesh.vertex_count()}, {"faces", mesh.face_count()},
                 {"components", topology.vertex_components}, {"boundary_edges", topology.boundary_edges},
                 {"nonmanifold_edges", topology.nonmanifold_edges},
                 {"inconsistent_edges", topology.inconsistent_edges},
                 {"degenerate_faces_dropped", load.degenerate_faces},
                 {"duplicate_faces_dropped", load.duplicate_faces},
                 {"unreferenced_vertices", load.unreferenced_vertices}};
    j["mapping"] = {{"patches", stats.patches}, {"patches_before_absorb", stats.patches_before_absorb},
                    {"deferrals", stats.deferrals}, {"threshold_raises", stats.threshold_raises},
                    {"final_threshold_px", stats.final_threshold_px}, {"max_error_px", stats.max_error_px},
                    {"max_stretch_accepted", stats.max_stretch_accepted},
                    {"faces_three_textured", stats.faces_three_textured},
                    {"faces_unfolded", stats.faces_unfolded}, {"faces_rigid", stats.faces_rigid},
                    {"faces_reseamed", stats.faces_reseamed}, {"cracks_closed", stats.cracks_closed},
                    {"relax_moves", stats.relax_moves},
                    {"faces_seam", stats.faces_seam}, {"inverted_accepted", stats.inverted_accepted}};
    j["metrics"] = {{"patches", metrics.patches}, {"single_face_patches", metrics.single_face_patches},
                    {"stretch", metrics.stretch}, {"stretch_area_weighted", metrics.stretch_area_weighted},
                    {"distortion_deg", metrics.distortion_deg}, {"l2_stretch", metrics.l2_stretch},
                    {"linf_stretch", metrics.linf_stretch}, {"flipped", metrics.flipped},
                    {"seam_edges", metrics.seam_edges}, {"seam_length_ratio", metrics.seam_length_ratio},
                    {"seam_gap_px", metrics.seam_gap_px}, {"seam_invisible_ratio", metrics.seam_invisible_ratio},
                    {"uv_scale", metrics.uv_scale}};
    if (opt.stability)
      j["stability"] = {{"removed_faces", stability.removed_faces}, {"compared_corners", stability.compared_corners},
                        {"mean_difference_px", stability.mean_difference_px},
                        {"max_difference_px", stability.max_difference_px},
                        {"identical_ratio", stability.identical_ratio},
                        {"within_1px_ratio", stability.within_1px_ratio}};
    j["time_ms"] = {{"load", ms(load.load_seconds)}, {"topology", ms(topology.build_seconds)},
                    {"axis_choice", ms(axis_seconds)}, {"orientation", ms(frames.seconds)}, {"mapping", ms(stats.seconds)},
                    {"metrics", ms(metrics_seconds)}, {"export", ms(export_seconds)},
                    {"preview", ms(preview_seconds)}, {"total", ms(total_seconds)}};
    j["previews"] = previews;
    const std::string text = json_text(j) + "\n";
    if (Status s = internal::write_file_atomic(opt.stats, text); !s) return report_error(s);
  }
  if (Status s = batch.commit(); !s) return report_error(s);
  if (!opt.quiet) {
    std::printf(
        "%s: %zu faces, %u patches, seams %.2f%% of edge length, %zu flipped, stretch %.3f, L2 %.3f, "
        "Linf %.2f, median angle %.2f deg, seam gap %.1f px (%.0f%% invisible) | load %.1f ms, topology %.1f, "
        "%sorientation %.1f, mapping %.1f, export %.1f ms -> %s\n",
        opt.input.c_str(), mesh.face_count(), metrics.patches, 100.0 * metrics.seam_length_ratio, metrics.flipped,
        metrics.stretch, metrics.l2_stretch, metrics.linf_stretch, metrics.distortion_deg, metrics.seam_gap_px,
        100.0 * metrics.seam_invisible_ratio, ms(load.load_seconds), ms(topology.build_seconds),
        auto_axis ? ("axis choice " + std::to_string(static_cast<long>(ms(axis_seconds))) + ", ").c_str() : "",
        ms(frames.seconds), ms(stats.seconds), ms(export_seconds), opt.output.c_str());
    if (opt.stability)
      std::printf("stability: removed %zu faces, surviving corners moved %.3f px on average (max %.2f px), "
                  "%.1f%% bit-identical, %.1f%% within 1 px\n",
                  stability.removed_faces, stability.mean_difference_px, stability.max_difference_px,
                  100.0 * stability.identical_ratio, 100.0 * stability.within_1px_ratio);
    for (const std::string& p : previews) std::printf("preview: %s\n", p.c_str());
    if (!opt.stats.empty()) std::printf("stats: %s\n", opt.stats.c_str());
  }
  return kExitOk;
}

}  // namespace

void register_map(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<MapOptions>();
  auto* cmd = app.add_subcommand(
      "map", "Compute texture coordinates by homogeneous patch discovery and write a textured mesh");
  cmd->add_option("mesh", opt->input, "Input mesh (.ply .obj .off .stl)")->required();
  cmd->add_option("-o,--output", opt->output, "Output mesh: .glb (texture embedded), .obj (+ .mtl) or .ply")
      ->required();
  cmd->add_option("-t,--texture", opt->texture,
                   "Texture image (PNG/JPEG), ideally self-tileable (see 'tailor tile'); sets the texture size");
  cmd->add_option("--texture-size", opt->texture_size, "Texture size in pixels when no --texture is given")
      ->capture_default_str();
  cmd->add_option("--stats", opt->stats, "Write a JSON report (mesh, mapping counters, metrics, timings)");
  cmd->add_option("--preview", opt->preview, "Render a 3/4 view of the textured mesh to this PNG");
  cmd->add_flag("--preview-all", opt->preview_all,
                "With --preview, also write <name>_patches.png, <name>_distortion.png and <name>_checker.png");
  cmd->add_option("--preview-up", opt->preview_up,
                  "Mesh axis that points up in the previews: y (default, glTF), z (most scans), x, -x, -y, -z")
      ->capture_default_str();
  auto* group = cmd->add_option_group("Mapping");
  group->add_option("--mode", opt->mode,
                    "patches: per-corner UVs, bounded per-face stretch, no inverted face (default); "
                    "thesis: the thesis as written, one UV per vertex (reference)")
      ->capture_default_str();
  group->add_option("--scale", opt->scale, "Texture pixels per unit of the mesh normalised into the unit cube")
      ->capture_default_str();
  group->add_option("--max-stretch", opt->max_stretch,
                    "patches mode: per-face singular values must stay within [1/(1+x), 1+x]")
      ->capture_default_str();
  group->add_option("--field-following", opt->field_following,
                    "patches mode: 1 = texture direction follows the orientation field (thesis), 0 = faces are "
                    "unfolded rigidly (fewer seams, direction drifts); values between blend")
      ->capture_default_str();
  group->add_option("--min-patch-faces", opt->min_patch_faces,
                    "patches mode: smaller patches are absorbed into a neighbour (0 keeps all)")
      ->capture_default_str();
  group->add_option("--hop-age", opt->hop_age,
                    "patches mode: growth-order age per face of path from the seed, radians (0..1); keeps the "
                    "order local so removing part of a mesh changes little elsewhere; 0 = the thesis's global counter")
      ->capture_default_str();
  group->add_flag("--no-seam-shortening", opt->keep_seams,
                  "patches mode: keep the seams as the growth left them (no re-placing of faces along them)");
  group->add_flag("--no-crack-closing", opt->keep_cracks,
                  "patches mode: leave the cracks (cuts inside a patch) open; 3-10x faster mapping, about twice the seam "
                  "length");
  group->add_option("--crack-rings", opt->crack_rings,
                    "patches mode: effort of the crack closing, the largest region (rings of faces) a zip may "
                    "relax (2..64); more closes wider cracks and takes longer. Fewest seams: --field-following 0 "
                    "--crack-rings 32")
      ->check(CLI::Range(2u, 64u))
      ->capture_default_str();
  group->add_option("--relax-iterations", opt->relax_iterations,
                    "patches mode: last, local/global ARAP iterations over the UV vertices (0 = off, ..1000): less "
                    "angle distortion within --max-stretch; patches and seams stay, invisible seams stay invisible")
      ->check(CLI::Range(0u, 1000u))
      ->capture_default_str();
  group->add_option("--threshold", opt->threshold, "thesis mode: initial error threshold in pixels")
      ->capture_default_str();
  group->add_option("--axis", opt->axis,
                    "Orientation field: pca, x, y, z, X,Y,Z, or auto (maps with each of pca, x, y, z first and "
                    "keeps the one with the least seam: halves the seams of CAD parts, 4 growths more time)")
      ->capture_default_str();
  group->add_option("--smooth", opt->smooth, "Orientation smoothing passes over face neighbours")
      ->capture_default_str();
  group->add_option("--seed-point", opt->seed_point,
                    "X,Y,Z: start at the face nearest this point (same point = stable results when parts of "
                    "the mesh are removed)");
  group->add_option("--seam-faces", opt->seam_faces,
                    "File of face indices (one per line) where seams should go (PLY 'seam' property also works)");
  cmd->add_flag("--stability", opt->stability,
                "Also remove ~10% of the faces, re-map and report how much the remaining UVs moved");
  cmd->add_option("--threads", opt->threads,
                  "Threads for the orientation, the crack closing and the metrics (0 = one per core, up to 8, "
                  "where the mesh is large enough); the output is the same for any count")
      ->capture_default_str()
      ->check(CLI::Range(0u, 64u));
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but errors");
  cmd->footer(
      "Example:\n"
      "  tailor tile gravel.png -o gravel_tile.png\n"
      "  tailor map bunny.ply --texture gravel_tile.png -o bunny.glb --stats bunny.json --preview bunny.png\n"
      "Prints one summary line: faces, patches, seam length, flipped faces, stretch, Sander L2/Linf,\n"
      "median angle distortion, seam gap, and the time of each stage.\n"
      "Trade-offs: --no-crack-closing maps 3-10x faster and keeps more UVs bit-identical when parts of\n"
      "the mesh change, with about twice the seam length; --field-following 0 --crack-rings 32 gives the\n"
      "fewest seams (one patch per component) for stochastic textures whose direction does not matter.");
  cmd->callback([&run, opt] { run = [opt] { return run_map(*opt); }; });
}

}  // namespace tailor::cli
