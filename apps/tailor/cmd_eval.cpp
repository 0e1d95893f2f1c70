// tailor eval: UV quality metrics of any UV-mapped mesh (.obj vt, .ply s/t, .glb TEXCOORD_0).
// Definitions: docs/metrics.md.
#include <chrono>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "tailor/export.h"
#include "tailor/gltf.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/metrics.h"
#include "tailor/stability.h"
#include "tailor/topology.h"

namespace tailor::cli {
namespace {

struct EvalOptions {
  std::string input;
  int texture_size = 0;  // 0 = not given: the embedded image size for .glb, else 512
  bool json = false;
  bool quiet = false;
  bool stability = false;
  std::string seed_point;
  float remove_fraction = 0.1f;
};

constexpr int kDefaultTextureSize = 512;

// --stability: the remove-a-ball experiment of thesis 2.6 on tailor's own mapping of the mesh.
int run_stability(const EvalOptions& opt) {
  Mesh mesh;
  {
    const ReadingInput reading(opt.input);
    if (Status s = load_mesh(opt.input, mesh); !s) return report_error(s);
  }
  MappingOptions mapping;
  if (!opt.seed_point.empty()) {
    if (!parse_vec3(opt.seed_point, mapping.seed_point))
      return report_error(Status::error(ErrorCode::kInvalidArgument, "",
                                        "--seed-point must be three numbers X,Y,Z, got '" + opt.seed_point + "'"));
    mapping.use_seed_point = true;
  }
  StabilityOptions options;
  options.remove_fraction = opt.remove_fraction;
  StabilityReport r;
  if (Status s = measure_stability(mesh, OrientationOptions{}, mapping, r, options); !s)
    return report_error(s.with_file(opt.input));
  if (opt.json) {
    nlohmann::json j;
    j["file"] = opt.input;
    j["faces"] = r.faces;
    j["removed_faces"] = r.removed_faces;
    j["compared_corners"] = r.compared_corners;
    j["mean_difference_px"] = r.mean_difference_px;
    j["max_difference_px"] = r.max_difference_px;
    j["identical_ratio"] = r.identical_ratio;
    j["within_1px_ratio"] = r.within_1px_ratio;
    j["patches_full"] = r.patches_full;
    j["patches_cut"] = r.patches_cut;
    j["seconds"] = r.seconds;
    std::printf("%s\n", json_text(j).c_str());
  } else if (!opt.quiet) {
    std::printf("%s: stability: removed %zu of %zu faces, surviving corners moved %.3f px on average (max %.2f px), "
                "%.1f%% bit-identical, %.1f%% within 1 px; patches %u -> %u (%.0f ms)\n",
                opt.input.c_str(), r.removed_faces, r.faces, r.mean_difference_px, r.max_difference_px,
                100.0 * r.identical_ratio, 100.0 * r.within_1px_ratio, r.patches_full, r.patches_cut,
                r.seconds * 1e3);
  }
  return kExitOk;
}

int run_eval(const EvalOptions& opt) {
  if (opt.stability) return run_stability(opt);
  const auto start = std::chrono::steady_clock::now();
  Mesh mesh;
  LoadReport report;
  Image texture;
  const bool glb = mesh_format_from_path(opt.input) == MeshFormat::kGlb;
  // Only decode the embedded texture when its size is needed.
  const Status status = [&] {
    const ReadingInput reading(opt.input);
    return glb ? read_glb_file(opt.input, mesh, opt.texture_size > 0 ? nullptr : &texture, &report)
               : load_mesh(opt.input, mesh, &report);
  }();
  if (!status) return report_error(status);
  if (mesh.corner_uvs.empty())
    return report_error(Status::error(ErrorCode::kInvalidMesh, opt.input,
                                      "mesh has no texture coordinates to evaluate (OBJ vt, PLY s/t or glTF TEXCOORD_0)"));
  // glb readers weld split vertices themselves; PLY files written after splitting need it here
  // so that seams are edges between faces again (corner UVs are unaffected).
  const size_t welded = glb ? 0 : weld_identical_positions(mesh);

  int width = kDefaultTextureSize, height = kDefaultTextureSize;
  const char* size_source = "default";
  if (opt.texture_size > 0) {
    width = height = opt.texture_size;
    size_source = "option";
  } else if (!texture.empty()) {
    width = texture.width;
    height = texture.height;
    size_source = "embedded texture";
  }

  // Texture repeats -> pixels.
  std::vector<float> uv_px(mesh.corner_uvs.size());
  for (size_t c = 0; c < uv_px.size() / 2; ++c) {
    uv_px[2 * c] = mesh.corner_uvs[2 * c] * static_cast<float>(width);
    uv_px[2 * c + 1] = mesh.corner_uvs[2 * c + 1] * static_cast<float>(height);
  }
  const Topology topology = build_topology(mesh);
  UvMetrics m;
  const MetricsOptions options{static_cast<float>(width), static_cast<float>(height)};
  const Status metrics_status = compute_uv_metrics(mesh, topology, uv_px, {}, options, m);
  if (!metrics_status) return report_error(metrics_status.with_file(opt.input));
  const double seconds = seconds_since(start);

  if (m.degenerate_faces > 0)
    warn(opt.quiet || opt.json, std::to_string(m.degenerate_faces) + " faces with zero 3D area skipped by the per-face metrics");
  if (m.zero_uv_area_faces > 0)
    warn(opt.quiet || opt.json, std::to_string(m.zero_uv_area_faces) + " faces with zero UV area (counted as flipped)");

  if (opt.json) {
    nlohmann::json j;
    j["file"] = opt.input;
    j["format"] = report.format;
    j["vertices"] = mesh.vertex_count();
    j["faces"] = m.faces;
    j["welded_vertices"] = glb ? report.welded_vertices : welded;
    j["texture_width"] = width;
    j["texture_height"] = height;
    j["texture_size_from"] = size_source;
    j["patches"] = m.patches;
    j["single_face_patches"] = m.single_face_patches;
    j["degenerate_faces"] = m.degenerate_faces;
    j["stretch"] = m.stretch;
    j["stretch_area_weighted"] = m.stretch_area_weighted;
    j["distortion_deg"] = m.distortion_deg;
    j["l2_stretch"] = m.l2_stretch;
    j["linf_stretch"] = m.linf_stretch;
    j["flipped"] = m.flipped;
    j["zero_uv_area_faces"] = m.zero_uv_area_faces;
    j["seam_edges"] = m.seam_edges;
    j["seam_length_ratio"] = m.seam_length_ratio;
    j["seam_gap_px"] = m.seam_gap_px;
    j["seam_invisible_ratio"] = m.seam_invisible_ratio;
    j["visible_seam_ratio"] = m.visible_seam_ratio;
    j["visible_off_sharp_ratio"] = m.visible_off_sharp_ratio;
    j["visible_dangling_ends"] = m.visible_dangling_ends;
    j["visible_branch_points"] = m.visible_branch_points;
    j["uv_scale_px2_per_unit2"] = m.uv_scale;
    j["boundary_edges"] = topology.boundary_edges;
    j["nonmanifold_edges"] = topology.nonmanifold_edges;
    j["seconds"] = seconds;
    std::printf("%s\n", json_text(j).c_str());
    return kExitOk;
  }
  std::printf(
      "%s: %zu faces, %u patches (%zu single-face), seams %.2f%% of edge length (%zu edges), %zu flipped, "
      "stretch %.4f (area-weighted %.4f), L2 %.4f, Linf %.4f, distortion %.2f deg (median), "
      "seam gap %.2f px, %.1f%% invisible (texture %dx%d px, %s)\n",
      opt.input.c_str(), m.faces, m.patches, m.single_face_patches, 100.0 * m.seam_length_ratio, m.seam_edges,
      m.flipped, m.stretch, m.stretch_area_weighted, m.l2_stretch, m.linf_stretch, m.distortion_deg, m.seam_gap_px,
      100.0 * m.seam_invisible_ratio, width, height, size_source);
  return kExitOk;
}

}  // namespace

void register_eval(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<EvalOptions>();
  auto* cmd = app.add_subcommand("eval", "Print UV quality metrics of a UV-mapped mesh (.obj .ply .glb)");
  cmd->add_option("mesh", opt->input, "UV-mapped mesh: .obj (vt), .ply (s,t) or .glb (TEXCOORD_0); any mesh with --stability")->required();
  cmd->add_option("--texture-size", opt->texture_size,
                  "Texture size in pixels (UVs are in repeats; this gives pixels). Default: the embedded "
                  "texture's size for .glb, else 512")
      ->check(CLI::Range(1, 1 << 16));
  cmd->add_flag("--json", opt->json, "Print the full report as a JSON object");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but the result and errors");
  cmd->add_flag("--stability", opt->stability,
                "Instead: map the mesh with tailor (default options), remove the faces in a ball holding "
                "~10% of them, re-map, and report how far the surviving UVs moved (thesis 2.6)");
  cmd->add_option("--seed-point", opt->seed_point, "With --stability: X,Y,Z where both mappings start");
  cmd->add_option("--remove-fraction", opt->remove_fraction, "With --stability: share of faces removed")
      ->check(CLI::Range(0.01f, 0.9f))
      ->capture_default_str();
  cmd->footer(
      "Metrics (docs/metrics.md): patches, seams (share of edge length), flipped faces, stretch\n"
      "(coefficient of variation of UV/3D area ratio, 0 ideal), L2/Linf stretch (Sander 2001, 1 ideal),\n"
      "median angle distortion, seam gap (px, modulo the texture) and share of invisible seams.\n"
      "Example:\n  tailor eval bunny.glb\n  tailor eval spot.obj --texture-size 1024 --json\n"
      "  tailor eval bunny.ply --stability --seed-point 0,0.1,0\n");
  cmd->callback([&run, opt] { run = [opt] { return run_eval(*opt); }; });
}

}  // namespace tailor::cli
