// The report of `tailor map` (tailor/report.h): the --stats JSON and the summary lines.
#include <algorithm>
#include <cmath>

#include "report/report_text.h"
#include "tailor/report.h"

namespace tailor {

using internal::format_text;
using internal::ms;

void add_map_results(const Mesh& mesh, const LoadReport& load, const Topology& topology, const TextureMap& map,
                     MapRun& run) {
  run.load = load;
  run.vertices = mesh.vertex_count();
  run.faces = mesh.face_count();
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    for (size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * v + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * v + k]);
    }
  run.longest_side =
      mesh.vertex_count() > 0 ? std::max({double{hi[0]} - lo[0], double{hi[1]} - lo[1], double{hi[2]} - lo[2]}) : 0.0;
  run.components = topology.vertex_components;
  run.boundary_edges = topology.boundary_edges;
  run.nonmanifold_edges = topology.nonmanifold_edges;
  run.inconsistent_edges = topology.inconsistent_edges;
  run.topology_seconds = topology.build_seconds;
  run.orientation_seconds = map.frames.seconds;
  run.mapping = map.stats;
  run.metrics = map.metrics;
}

std::string map_report_json(const MapRun& run) {
  const MappingOptions& mapping = run.options.mapping;
  const MappingStats& stats = run.mapping;
  const UvMetrics& metrics = run.metrics;
  nlohmann::json j;
  j["input"] = run.input;
  j["output"] = run.output;
  j["texture"] = run.texture;
  j["texture_size"] = {run.texture_width, run.texture_height};
  if (run.texture_isotropy >= 0.f) j["texture_isotropy"] = run.texture_isotropy;
  j["options"] = {
      {"mode", mapping_mode_name(mapping.mode)},
      {"scale", mapping.scale},
      {"threshold_px", mapping.threshold_px},
      {"max_stretch", mapping.max_stretch},
      {"field_following", mapping.field_following},
      {"field_following_auto", run.field_following_auto},
      {"min_patch_faces", mapping.min_patch_faces},
      {"shorten_seams", mapping.shorten_seams},
      {"close_cracks", mapping.close_cracks},
      {"crack_rings", mapping.crack_rings},
      {"relax_iterations", mapping.relax_iterations},
      {"hop_age", mapping.hop_age},
      {"axis", run.axis},
      {"smooth", run.options.orientation.smooth_passes},
      {"seed_point", run.seed_point},
      {"seam_faces", run.seam_faces},
      {"symmetry", mapping.symmetry},
      {"unit", run.texels_per_unit > 0 ? "scene" : "normalised"},
      {"texels_per_unit", run.texels_per_unit},
      {"tile_size", run.texels_per_unit > 0 && run.texture_width > 0 ? run.texture_width / run.texels_per_unit : 0.0},
      {"up", run.up}};
  j["mesh"] = {{"format", run.load.format},
               {"vertices", run.vertices},
               {"faces", run.faces},
               {"components", run.components},
               {"boundary_edges", run.boundary_edges},
               {"nonmanifold_edges", run.nonmanifold_edges},
               {"inconsistent_edges", run.inconsistent_edges},
               {"degenerate_faces_dropped", run.load.degenerate_faces},
               {"duplicate_faces_dropped", run.load.duplicate_faces},
               {"faces_turned", run.load.faces_turned},
               {"unreferenced_vertices", run.load.unreferenced_vertices},
               {"not_read", run.load.not_read},   // what the reader read past (the map's warning)
               {"not_kept", run.load.not_kept}};  // what the output does not carry (the map's warning)
  j["mapping"] = {{"patches", stats.patches},
                  {"patches_before_absorb", stats.patches_before_absorb},
                  {"deferrals", stats.deferrals},
                  {"threshold_raises", stats.threshold_raises},
                  {"final_threshold_px", stats.final_threshold_px},
                  {"max_error_px", stats.max_error_px},
                  {"max_stretch_accepted", stats.max_stretch_accepted},
                  {"faces_three_textured", stats.faces_three_textured},
                  {"faces_unfolded", stats.faces_unfolded},
                  {"faces_rigid", stats.faces_rigid},
                  {"faces_reseamed", stats.faces_reseamed},
                  {"cracks_closed", stats.cracks_closed},
                  {"relax_moves", stats.relax_moves},
                  {"faces_seam", stats.faces_seam},
                  {"inverted_accepted", stats.inverted_accepted},
                  {"chunks", stats.chunks},
                  {"chunk_cell_size", stats.chunk_cell_size},
                  {"texels_per_unit", stats.texels_per_unit},
                  {"locality_radius", stats.locality_radius},
                  {"repeats_across_mesh", map_repeats_across(run)}};  // the bounding box's longest side
  // Each stage's time: wall time mapped whole, thread time summed over the chunks in chunks.
  j["mapping"]["stage_ms"] = {{"orientation", ms(stats.orientation_seconds)},
                              {"growth", ms(stats.growth_seconds)},
                              {"closing", ms(stats.closing_seconds)},
                              {"relaxing", ms(stats.relaxing_seconds)}};
  j["metrics"] = {{"patches", metrics.patches},
                  {"single_face_patches", metrics.single_face_patches},
                  {"stretch", metrics.stretch},
                  {"stretch_area_weighted", metrics.stretch_area_weighted},
                  {"distortion_deg", metrics.distortion_deg},
                  {"l2_stretch", metrics.l2_stretch},
                  {"linf_stretch", metrics.linf_stretch},
                  {"flipped", metrics.flipped},
                  {"seam_edges", metrics.seam_edges},
                  {"seam_length_ratio", metrics.seam_length_ratio},
                  {"seam_gap_px", metrics.seam_gap_px},
                  {"seam_invisible_ratio", metrics.seam_invisible_ratio},
                  {"visible_seam_ratio", metrics.visible_seam_ratio},
                  {"visible_off_sharp_ratio", metrics.visible_off_sharp_ratio},
                  {"visible_dangling_ends", metrics.visible_dangling_ends},
                  {"visible_branch_points", metrics.visible_branch_points},
                  {"uv_scale", metrics.uv_scale}};
  if (run.stability) {
    const StabilityReport& s = *run.stability;
    j["stability"] = {{"removed_faces", s.removed_faces},
                      {"compared_corners", s.compared_corners},
                      {"mean_difference_px", s.mean_difference_px},
                      {"max_difference_px", s.max_difference_px},
                      {"identical_ratio", s.identical_ratio},
                      {"within_1px_ratio", s.within_1px_ratio},
                      {"order_identical_ratio", s.order_identical_ratio},
                      {"locality_radius", s.locality_radius},
                      {"corners_beyond_radius", s.corners_beyond_radius},
                      {"identical_beyond_radius_ratio", s.identical_beyond_radius_ratio}};
  }
  j["time_ms"] = {{"load", ms(run.load.load_seconds)},
                  {"topology", ms(run.topology_seconds)},
                  {"axis_choice", ms(run.axis_choice_seconds)},
                  {"turning", ms(run.turning_seconds)},
                  {"orientation", ms(run.orientation_seconds)},
                  {"mapping", ms(stats.seconds)},
                  {"metrics", ms(metrics.seconds)},
                  {"export", ms(run.export_seconds)},
                  {"preview", ms(run.preview_seconds)},
                  {"total", ms(run.total_seconds)}};
  if (run.peak_resident_bytes > 0) j["peak_resident_mib"] = static_cast<double>(run.peak_resident_bytes) / (1 << 20);
  j["previews"] = run.previews;
  return internal::json_text(j);
}

double map_repeats_across(const MapRun& run) {
  const double period = run.options.mapping.texture_period_px;
  if (!(period > 0)) return 0.0;
  double repeats = 0.0;
  if (run.mapping.chunks > 0 && run.mapping.texels_per_unit > 0)  // one density per world unit for every chunk
    repeats = run.longest_side * run.mapping.texels_per_unit / period;
  else if (run.options.orientation.fixed_unit_scale > 0.f)
    repeats = run.longest_side * run.options.orientation.fixed_unit_scale * run.options.mapping.scale / period;
  else  // normalised into the unit cube: the scale spans the longest side
    repeats = run.options.mapping.scale / period;
  return std::isfinite(repeats) && repeats > 0 ? repeats : 0.0;
}

std::string map_summary(const MapRun& run) {
  const UvMetrics& m = run.metrics;
  // The repeats across the mesh (and the texel density when it is per world unit): below one, part of
  // the texture is never seen.
  std::string repeats;
  if (const double r = map_repeats_across(run); r > 0) {
    repeats = format_text(r < 100 ? ", %.2f repeats across the mesh" : ", %.0f repeats across the mesh", r);
    if (run.texels_per_unit > 0) repeats += format_text(" (%g texels per unit)", run.texels_per_unit);
  }
  const std::string axis_choice =
      run.axis_auto ? "axis choice " + std::to_string(static_cast<long>(ms(run.axis_choice_seconds))) + ", " : "";
  // In chunks every chunk orients itself inside the mapping's time (the chunks line has the stages).
  const std::string peak =
      run.peak_resident_bytes > 0
          ? format_text(", peak %.0f MiB", static_cast<double>(run.peak_resident_bytes) / (1 << 20))
          : std::string();
  const std::string orientation = run.mapping.chunks > 0 ? "orientation in the chunks"
                                                         : format_text("orientation %.1f", ms(run.orientation_seconds));
  std::string text = format_text(
      "%s: %s, %s%s, seams %.2f%% of edge length, %zu flipped, stretch %.3f, L2 %.3f, "
      "Linf %.2f, median angle %.2f deg, visible seams %.2f%% (%.0f%% of seam length invisible%s, %zu dangling ends) | "
      "load %.1f ms, topology %.1f, "
      "%s%s, mapping %.1f, export %.1f ms%s -> %s\n",
      run.input.c_str(), internal::counted(run.faces, "face", "faces").c_str(),
      internal::counted(m.patches, "patch", "patches").c_str(), repeats.c_str(), 100.0 * m.seam_length_ratio, m.flipped,
      m.stretch, m.l2_stretch, m.linf_stretch, m.distortion_deg, 100.0 * m.visible_seam_ratio,
      100.0 * m.seam_invisible_ratio, run.options.metrics.symmetry == 4 ? " up to quarter turns" : "",
      m.visible_dangling_ends, ms(run.load.load_seconds), ms(run.topology_seconds), axis_choice.c_str(),
      orientation.c_str(), ms(run.mapping.seconds), ms(run.export_seconds), peak.c_str(), run.output.c_str());
  if (run.mapping.chunks > 0)
    text += format_text(
        "chunks: %s of side %g world units, mapped at %g texels per unit; corners farther than %g units from "
        "an edit keep their UVs; thread time orientation %.1f, growth %.1f, closing %.1f, relaxing %.1f ms\n",
        internal::counted(run.mapping.chunks, "chunk", "chunks").c_str(), run.mapping.chunk_cell_size,
        run.mapping.texels_per_unit, run.mapping.locality_radius, ms(run.mapping.orientation_seconds),
        ms(run.mapping.growth_seconds), ms(run.mapping.closing_seconds), ms(run.mapping.relaxing_seconds));
  if (run.stability) {
    const StabilityReport& s = *run.stability;
    text += format_text(
        "stability: removed %s, surviving corners moved %.3f px on average (max %.2f px), "
        "%.1f%% bit-identical, %.1f%% within 1 px\n",
        internal::counted(s.removed_faces, "face", "faces").c_str(), s.mean_difference_px, s.max_difference_px,
        100.0 * s.identical_ratio, 100.0 * s.within_1px_ratio);
    if (s.order_identical_ratio >= 0)
      text += format_text("stability: another face, vertex and corner order: %.1f%% of corners bit-identical\n",
                          100.0 * s.order_identical_ratio);
    if (s.identical_beyond_radius_ratio >= 0)
      text += format_text("stability: %.1f%% of the corners farther than %g units from the cut bit-identical\n",
                          100.0 * s.identical_beyond_radius_ratio, s.locality_radius);
  }
  return text;
}

}  // namespace tailor
