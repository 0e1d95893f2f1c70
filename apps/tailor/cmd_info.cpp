// tailor info: what a mesh file holds (counts, topology, repairs, bounding box, timings).
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "tailor/io.h"
#include "tailor/topology.h"

namespace tailor::cli {
namespace {

struct InfoOptions {
  std::string input;
  bool json = false;
  bool quiet = false;
};

int run_info(const InfoOptions& opt) {
  Mesh mesh;
  LoadReport report;
  const Status status = [&] {
    const ReadingInput reading(opt.input);
    return load_mesh(opt.input, mesh, &report);
  }();
  if (!status) return report_error(status);
  const Topology topology = build_topology(mesh);
  const size_t nonmanifold_vertices = count_nonmanifold_vertices(mesh);

  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<float>::max();
    hi[k] = std::numeric_limits<float>::lowest();
  }
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * v + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * v + k]);
    }
  }

  if (opt.json) {
    nlohmann::json j;
    j["file"] = opt.input;
    j["format"] = report.format;
    j["bytes"] = report.file_bytes;
    j["vertices"] = mesh.vertex_count();
    j["faces"] = mesh.face_count();
    j["source_faces"] = report.source_faces;
    j["polygons_triangulated"] = report.polygons_triangulated;
    j["concave_polygons"] = report.concave_polygons;
    j["components"] = topology.vertex_components;
    j["edge_components"] = topology.edge_components;
    j["edges"] = topology.edges;
    j["boundary_edges"] = topology.boundary_edges;
    j["nonmanifold_edges"] = topology.nonmanifold_edges;
    j["nonmanifold_vertices"] = nonmanifold_vertices;
    j["inconsistent_edges"] = topology.inconsistent_edges;
    j["degenerate_faces"] = report.degenerate_faces;
    j["duplicate_faces"] = report.duplicate_faces;
    j["zero_area_faces"] = report.zero_area_faces;
    j["unreferenced_vertices"] = report.unreferenced_vertices;
    j["welded_vertices"] = report.welded_vertices;
    if (!report.not_read.empty()) j["not_read"] = report.not_read;
    if (report.mesh_instances) {  // a glTF scene: what `tailor map` warns of
      j["mesh_instances"] = report.mesh_instances;
      j["skipped_primitives"] = report.skipped_primitives;
      j["not_kept"] = report.not_kept;
    }
    j["has_uvs"] = !mesh.corner_uvs.empty();
    j["seam_faces_marked"] = !mesh.seam_faces.empty();
    j["bbox_min"] = {lo[0], lo[1], lo[2]};
    j["bbox_max"] = {hi[0], hi[1], hi[2]};
    j["load_ms"] = report.load_seconds * 1e3;
    j["topology_ms"] = topology.build_seconds * 1e3;
    std::printf("%s\n", json_text(j).c_str());
    return kExitOk;
  }

  std::printf("%s\n", opt.input.c_str());
  std::printf("  format                 %s (%zu bytes)\n", report.format.c_str(), report.file_bytes);
  std::printf("  vertices               %zu\n", mesh.vertex_count());
  std::printf("  faces                  %zu (after triangulation; %zu in file, %zu polygons split, %zu concave)\n",
              mesh.face_count(), report.source_faces, report.polygons_triangulated, report.concave_polygons);
  std::printf("  components             %u (faces sharing a vertex; %u through manifold edges)\n",
              topology.vertex_components, topology.edge_components);
  std::printf("  edges                  %zu\n", topology.edges);
  std::printf("  boundary edges         %zu\n", topology.boundary_edges);
  std::printf("  non-manifold edges     %zu (three or more faces)\n", topology.nonmanifold_edges);
  std::printf("  non-manifold vertices  %zu (faces not one fan, or on a non-manifold edge)\n", nonmanifold_vertices);
  std::printf("  inconsistent edges     %zu (shared by two faces running the same way)\n", topology.inconsistent_edges);
  std::printf("  degenerate faces       %zu (dropped)\n", report.degenerate_faces);
  std::printf("  duplicate faces        %zu (dropped)\n", report.duplicate_faces);
  std::printf("  zero-area faces        %zu (kept)\n", report.zero_area_faces);
  std::printf("  unreferenced vertices  %zu (kept)\n", report.unreferenced_vertices);
  if (report.welded_vertices) std::printf("  welded corners         %zu\n", report.welded_vertices);
  if (!report.not_read.empty()) std::printf("  not read               %s\n", report.not_read.c_str());
  if (report.mesh_instances) {  // a glTF scene: what `tailor map` warns of
    std::printf("  mesh instances         %zu (placed by the scene's nodes, in world space)\n", report.mesh_instances);
    if (report.skipped_primitives)
      std::printf("  skipped primitives     %zu (points and lines, not read)\n", report.skipped_primitives);
    if (!report.not_kept.empty()) std::printf("  not kept in outputs    %s\n", report.not_kept.c_str());
  }
  std::printf("  texture coordinates    %s\n", mesh.corner_uvs.empty() ? "no" : "yes");
  std::printf("  bounding box           [%g, %g, %g] - [%g, %g, %g]\n", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  std::printf("  time                   load %.1f ms, topology %.1f ms\n", report.load_seconds * 1e3,
              topology.build_seconds * 1e3);
  return kExitOk;
}

}  // namespace

void register_info(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<InfoOptions>();
  auto* cmd = app.add_subcommand("info", "Print what a mesh file holds: counts, topology, repairs, bounding box");
  cmd->add_option("mesh", opt->input, "Mesh file (.ply .obj .off .stl .glb)")->required();
  cmd->add_flag("--json", opt->json, "Print a JSON object instead of text");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but the result and errors");
  cmd->footer("Example:\n  tailor info bunny.ply --json");
  cmd->callback([&run, opt] { run = [opt] { return run_info(*opt); }; });
}

}  // namespace tailor::cli
