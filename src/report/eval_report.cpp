// The reports of `tailor eval` (tailor/report.h): the metrics of a UV-mapped mesh, and the
// stability experiment.
#include "report/report_text.h"
#include "tailor/report.h"

namespace tailor {

using internal::counted;
using internal::format_text;

std::string eval_report_json(const EvalRun& run) {
  const UvMetrics& m = run.metrics;
  nlohmann::json j;
  j["file"] = run.file;
  j["format"] = run.format;
  j["vertices"] = run.vertices;
  j["faces"] = m.faces;
  j["welded_vertices"] = run.welded_vertices;
  j["texture_width"] = run.texture_width;
  j["texture_height"] = run.texture_height;
  j["texture_size_from"] = run.texture_size_from;
  j["symmetry"] = run.symmetry;
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
  j["boundary_edges"] = run.boundary_edges;
  j["nonmanifold_edges"] = run.nonmanifold_edges;
  j["seconds"] = run.seconds;
  return internal::json_text(j);
}

std::string eval_summary(const EvalRun& run) {
  const UvMetrics& m = run.metrics;
  return format_text(
      "%s: %s, %s (%zu single-face), seams %.2f%% of edge length (%s), %zu flipped, "
      "stretch %.4f (area-weighted %.4f), L2 %.4f, Linf %.4f, distortion %.2f deg (median), "
      "seam gap %.2f px, %.1f%% invisible, visible seams %.2f%% of edge length (%.2f%% off sharp edges, "
      "%s, %s) (texture %dx%d px, %s%s)\n",
      run.file.c_str(), counted(m.faces, "face", "faces").c_str(), counted(m.patches, "patch", "patches").c_str(),
      m.single_face_patches, 100.0 * m.seam_length_ratio, counted(m.seam_edges, "edge", "edges").c_str(), m.flipped,
      m.stretch, m.stretch_area_weighted, m.l2_stretch, m.linf_stretch, m.distortion_deg, m.seam_gap_px,
      100.0 * m.seam_invisible_ratio, 100.0 * m.visible_seam_ratio, 100.0 * m.visible_off_sharp_ratio,
      counted(m.visible_dangling_ends, "dangling end", "dangling ends").c_str(),
      counted(m.visible_branch_points, "branch point", "branch points").c_str(), run.texture_width, run.texture_height,
      run.texture_size_from.c_str(), run.symmetry == 4 ? ", symmetry 4" : "");
}

std::string stability_report_json(const std::string& file, const StabilityReport& r) {
  nlohmann::json j;
  j["file"] = file;
  j["faces"] = r.faces;
  j["removed_faces"] = r.removed_faces;
  j["compared_corners"] = r.compared_corners;
  j["mean_difference_px"] = r.mean_difference_px;
  j["max_difference_px"] = r.max_difference_px;
  j["identical_ratio"] = r.identical_ratio;
  j["within_1px_ratio"] = r.within_1px_ratio;
  j["patches_full"] = r.patches_full;
  j["patches_cut"] = r.patches_cut;
  j["order_identical_ratio"] = r.order_identical_ratio;
  j["locality_radius"] = r.locality_radius;
  j["corners_beyond_radius"] = r.corners_beyond_radius;
  j["identical_beyond_radius_ratio"] = r.identical_beyond_radius_ratio;
  j["seconds"] = r.seconds;
  return internal::json_text(j);
}

std::string stability_summary(const std::string& file, const StabilityReport& r) {
  std::string text;
  if (r.order_identical_ratio >= 0)
    text += format_text("%s: stability: another face, vertex and corner order: %.1f%% of corners bit-identical\n",
                        file.c_str(), 100.0 * r.order_identical_ratio);
  text += format_text(
      "%s: stability: removed %zu of %s, surviving corners moved %.3f px on average (max %.2f px), "
      "%.1f%% bit-identical, %.1f%% within 1 px; patches %u -> %u (%.0f ms)\n",
      file.c_str(), r.removed_faces, counted(r.faces, "face", "faces").c_str(), r.mean_difference_px,
      r.max_difference_px, 100.0 * r.identical_ratio, 100.0 * r.within_1px_ratio, r.patches_full, r.patches_cut,
      r.seconds * 1e3);
  if (r.identical_beyond_radius_ratio >= 0)
    text += format_text("%s: stability: %.1f%% of the %s farther than %g units from the cut %s bit-identical\n",
                        file.c_str(), 100.0 * r.identical_beyond_radius_ratio,
                        counted(r.corners_beyond_radius, "surviving corner", "surviving corners").c_str(),
                        r.locality_radius, r.corners_beyond_radius == 1 ? "is" : "are");
  return text;
}

}  // namespace tailor
