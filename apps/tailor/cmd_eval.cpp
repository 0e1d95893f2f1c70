// tailor eval: UV quality metrics of any UV-mapped mesh (.obj vt, .ply s/t, .glb TEXCOORD_0).
// Definitions: docs/metrics.md.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>

#include "cli.h"
#include "map_shared.h"
#include "memory_policy.h"
#include "tailor/export.h"
#include "tailor/gltf.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/metrics.h"
#include "tailor/report.h"
#include "tailor/stability.h"
#include "tailor/topology.h"

namespace tailor::cli {
namespace {

struct EvalOptions {
  std::string input;
  int texture_size = 0;  // 0 = not given: a glTF texture's header size, else MetricsOptions' default
  bool json = false;
  bool quiet = false;
  bool stability = false;
  std::string seed_point;
  uint32_t symmetry = MetricsOptions{}.symmetry;
  bool symmetry_given = false;  // else the file's record of a 4-fold map (LoadReport::texture_symmetry) decides
  StabilityOptions stability_options;
  std::string chunks = "auto", chunk_cell = "auto";  // --chunks, --chunk-cell: the mapping --stability runs
  uint32_t threads = 0;                              // --threads: the metrics', and the mappings of --stability
};

// --stability: the remove-a-ball experiment of thesis 2.6 on tailor's own mapping of the mesh.
int run_stability(const EvalOptions& opt) {
  Mesh mesh;
  {
    const ReadingInput reading(opt.input);
    if (Status s = load_mesh(opt.input, mesh); !s) return report_error(s);
  }
  MapTextureOptions mapping;
  mapping.mapping.threads = opt.threads;
  if (Status s = parse_chunk_args(opt.chunks, opt.chunk_cell, mapping.chunks); !s) return report_error(s);
  if (!opt.seed_point.empty()) {
    if (!parse_vec3(opt.seed_point, mapping.mapping.seed_point))
      return report_error(Status::error(ErrorCode::kInvalidArgument, "",
                                        "--seed-point must be three numbers X,Y,Z, got '" + opt.seed_point + "'"));
    mapping.mapping.use_seed_point = true;
  }
  StabilityReport r;
  {
    const KeepScratch keep;  // three chunked mappings: each chunk's scratch reused
    if (Status s = measure_stability(mesh, mapping, r, opt.stability_options); !s)
      return report_error(s.with_file(opt.input));
  }
  if (opt.json)
    std::fputs(stability_report_json(opt.input, r).c_str(), stdout);
  else if (!opt.quiet)
    std::fputs(stability_summary(opt.input, r).c_str(), stdout);
  return kExitOk;
}

int run_eval(const EvalOptions& opt) {
  if (opt.stability) return run_stability(opt);
  const auto start = std::chrono::steady_clock::now();
  Mesh mesh;
  LoadReport report;
  const MeshFormat input_format = mesh_format_from_path(opt.input);
  const bool glb = input_format == MeshFormat::kGlb || input_format == MeshFormat::kGltf;
  // A glTF's texture is never decoded: its size comes from its header (LoadReport), any size.
  const Status status = [&] {
    const ReadingInput reading(opt.input);
    return glb ? read_glb_file(opt.input, mesh, nullptr, &report) : load_mesh(opt.input, mesh, &report);
  }();
  if (!status) return report_error(status);
  if (mesh.corner_uvs.empty() && report.faces_without_uv > 0) {
    // glTF: UVs are all or nothing across the triangle primitives; name the first that lacks them.
    const std::string which = report.primitive_without_uv.empty()
                                  ? "OBJ vt"
                                  : report.primitive_without_uv + " has none of the TEXCOORD set the others have";
    return report_error(Status::error(ErrorCode::kInvalidMesh, opt.input,
                                      std::to_string(report.faces_without_uv) + " of " +
                                          std::to_string(report.source_faces) + " faces have no texture coordinates (" +
                                          which + "): a map must give every corner one to be evaluated"));
  }
  if (mesh.corner_uvs.empty())
    return report_error(
        Status::error(ErrorCode::kInvalidMesh, opt.input,
                      "mesh has no texture coordinates to evaluate (OBJ vt on every corner, PLY s/t, or the glTF "
                      "TEXCOORD set its base colour texture reads)"));

  warn_texture_transform(opt.quiet || opt.json, opt.input, report.texture_transform);

  int width = static_cast<int>(MetricsOptions{}.texture_width_px);
  int height = static_cast<int>(MetricsOptions{}.texture_height_px);
  const char* size_source = "default";
  if (opt.texture_size > 0) {
    width = height = opt.texture_size;
    size_source = "option";
  } else if (report.texture_width > 0) {
    width = report.texture_width;
    height = report.texture_height;
    size_source = report.texture_file ? "texture file" : "embedded texture";
  } else if (!report.texture_named.empty()) {
    warn(opt.quiet || opt.json, opt.input + ": the texture it names (" + report.texture_named +
                                    ") could not be read: measured at " + std::to_string(width) + "x" +
                                    std::to_string(height) + " px (give --texture-size)");
  }
  // A 4-fold map says so in its .glb's material or its .obj's .mtl (tailor map --symmetry 4):
  // measured as the map was.
  const uint32_t symmetry = opt.symmetry_given ? opt.symmetry : report.texture_symmetry;
  if (Status s = check_quarter_turn_texture(symmetry, width, height); !s) return report_error(s);

  // The figures of the file as `tailor map` reports them for the file it writes: UVs in repeats
  // scaled to pixels, vertices at identical positions joined, patches as the UVs join faces.
  UvMetrics m;
  MetricsOptions options{static_cast<float>(width), static_cast<float>(height)};
  options.symmetry = symmetry;
  options.threads = opt.threads;
  StoredSurface surface;
  const Status metrics_status =
      compute_stored_uv_metrics(mesh, nullptr, std::move(mesh.corner_uvs), options, m, &surface);
  if (!metrics_status) return report_error(metrics_status.with_file(opt.input));
  const double seconds = seconds_since(start);

  // The file's split vertices are joined where their positions are identical (so that seams are
  // edges again); a face whose corners were distinct vertices at one position then repeats a
  // vertex and is dropped, where map, which had the mesh's own vertices, measured it.
  if (report.faces_collapsed_by_weld > 0)
    warn(opt.quiet || opt.json, opt.input + ": dropped " + std::to_string(report.faces_collapsed_by_weld) +
                                    " faces whose corners share a position once its vertices at identical "
                                    "positions were joined (tailor map measured them on the mesh it mapped)");
  if (m.degenerate_faces > 0)
    warn(opt.quiet || opt.json,
         std::to_string(m.degenerate_faces) +
             " faces with no 3D area that 32-bit floats resolve skipped by the per-face metrics");
  if (m.zero_uv_area_faces > 0)
    warn(opt.quiet || opt.json, std::to_string(m.zero_uv_area_faces) + " faces with zero UV area (counted as flipped)");

  EvalRun run;
  run.file = opt.input;
  run.format = report.format;
  run.vertices = mesh.vertex_count();
  run.welded_vertices = report.welded_vertices + surface.welded_vertices;
  run.texture_width = width;
  run.texture_height = height;
  run.texture_size_from = size_source;
  run.symmetry = symmetry;
  run.metrics = m;
  run.boundary_edges = surface.boundary_edges;
  run.nonmanifold_edges = surface.nonmanifold_edges;
  run.seconds = seconds;
  std::fputs((opt.json ? eval_report_json(run) : eval_summary(run)).c_str(), stdout);
  return kExitOk;
}

}  // namespace

void register_eval(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<EvalOptions>();
  auto* cmd = app.add_subcommand("eval", "Print UV quality metrics of a UV-mapped mesh (.obj .ply .glb)");
  cmd->add_option("mesh", opt->input,
                  "UV-mapped mesh: .obj (vt), .ply (s,t) or .glb (TEXCOORD_0); any mesh with --stability")
      ->required();
  cmd->add_option(
         "--texture-size", opt->texture_size,
         "Texture size in pixels (UVs are in repeats; this gives pixels). Default: the size of the texture the "
         "file names, read from its header (a .glb or .gltf's base colour texture, embedded or a file next "
         "to it; an .obj's map_Kd in its .mtl; a .ply's comment TextureFile), else " +
             std::to_string(static_cast<int>(MetricsOptions{}.texture_width_px)))
      ->check(CLI::Range(1, kMaxTextureSize));
  add_symmetry_option(cmd, option_doc(kMetricsOptionDocs, "symmetry"), opt->symmetry);
  cmd->add_flag("--json", opt->json, "Print the full report as a JSON object");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but the result and errors");
  auto* stability = cmd->add_flag(
      "--stability", opt->stability,
      "Instead: map the mesh afresh with tailor's defaults three times (as given; with its faces, vertices "
      "and corners in another order; with the faces in a ball holding ~10% of them removed) and report the "
      "share of corners whose UVs keep their bits (all, and farther than the locality radius from the "
      "cut) and how far the others moved (thesis 2.6)");
  // The options of --stability's mappings: refused without it, where they would do nothing.
  add_stability_options(cmd, stability, opt->stability_options.pin_frame, opt->stability_options.remove_fraction);
  with_stability(add_documented(cmd, option_doc(kChunkOptionDocs, "mode"), opt->chunks), stability);
  with_stability(add_documented(cmd, option_doc(kChunkOptionDocs, "cell_exponent"), opt->chunk_cell), stability);
  with_stability(
      cmd->add_option("--seed-point", opt->seed_point, std::string(option_doc(kMappingOptionDocs, "seed_point").help)),
      stability);
  cmd->add_option("--threads", opt->threads,
                  "Threads of the metrics (0 = one per 100k faces, up to the cores and 8) and, with --stability, of "
                  "the mappings (0 = one per core); the figures are the same for any count")
      ->capture_default_str()
      ->check(CLI::Range(0u, 64u));
  cmd->footer(
      "Metrics (docs/metrics.md): patches, seams (share of edge length), flipped faces, stretch\n"
      "(coefficient of variation of UV/3D area ratio, 0 ideal), L2/Linf stretch (Sander 2001, 1 ideal),\n"
      "median angle distortion, seam gap (px, modulo the texture) and share of invisible seams.\n"
      "Example:\n  tailor eval bunny.glb\n  tailor eval spot.obj --texture-size 1024 --json\n"
      "  tailor eval bunny_grid.obj --symmetry 4   (a map made with tailor map --symmetry 4; its .glb or .mtl says so "
      "itself)\n"
      "  tailor eval bunny.ply --stability --seed-point 0,0.1,0\n"
      "  tailor eval scan.ply --stability --remove-fraction 0.01 --chunks on\n");
  cmd->callback([&run, opt, cmd] {
    opt->symmetry_given = cmd->count("--symmetry") > 0;
    run = [opt] { return run_eval(*opt); };
  });
}

}  // namespace tailor::cli
