// The reports of `tailor tile` and `tailor eval-tile` (tailor/report.h).
#include <algorithm>
#include <cmath>

#include "report/report_text.h"
#include "tailor/report.h"

namespace tailor {
namespace {

nlohmann::json period_json(const PeriodEstimate& p) {
  return {{"x", p.period_x},
          {"y", p.period_y},
          {"found_x", p.found_x},
          {"found_y", p.found_y},
          {"confidence_x", p.confidence_x},
          {"confidence_y", p.confidence_y}};
}

// The fields shared by `tile` and `eval-tile`: wrap ratios and worst seam; with an exemplar also
// its ratios, histogram L1, gradient ratio and patch coherences; then targets_met (and
// targets_failed when some are not).
nlohmann::json quality_json(const TileQuality& tile) {
  const TileMetrics& m = tile.metrics;
  nlohmann::json j;
  j["wrap_ratio_x"] = m.wrap_ratio_x;
  j["wrap_ratio_y"] = m.wrap_ratio_y;
  j["worst_seam_ratio"] = m.worst_seam_ratio;
  if (m.has_exemplar) {
    j["exemplar_worst_seam_ratio"] = m.exemplar_worst_seam_ratio;
    j["exemplar_wrap_ratio_x"] = m.exemplar_wrap_ratio_x;
    j["exemplar_wrap_ratio_y"] = m.exemplar_wrap_ratio_y;
    j["histogram_l1"] = m.histogram_l1;
    j["gradient_ratio"] = m.gradient_ratio;
    j["patch_coherence"] = m.patch_coherence;
    j["exemplar_patch_coherence"] = m.exemplar_patch_coherence;
  }
  j["quarter_turn_difference"] = m.quarter_turn_difference;
  if (m.quarter_turn_difference >= 0) {
    j["quarter_turn_symmetric"] = m.quarter_turn_difference == 0;
    j["quarter_turn_shift"] = {m.quarter_turn_shift_x, m.quarter_turn_shift_y};
  }
  if (m.has_exemplar) j["coherence_with_turns"] = m.coherence_with_turns;
  j["targets_met"] = tile.targets_met;
  if (!tile.targets_failed.empty()) j["targets_failed"] = tile.targets_failed;
  return j;
}

std::string base_name(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

TileMetrics worst_tile_metrics(std::span<const TileQuality> tiles) {
  TileMetrics worst = tiles.front().metrics;
  auto far = [](double a, double b) { return std::abs(a - 1.0) > std::abs(b - 1.0) ? a : b; };
  for (const TileQuality& tile : tiles) {
    const TileMetrics& m = tile.metrics;
    worst.wrap_ratio_x = far(m.wrap_ratio_x, worst.wrap_ratio_x);
    worst.wrap_ratio_y = far(m.wrap_ratio_y, worst.wrap_ratio_y);
    worst.worst_seam_ratio = std::max(worst.worst_seam_ratio, m.worst_seam_ratio);
    worst.histogram_l1 = std::max(worst.histogram_l1, m.histogram_l1);
    worst.gradient_ratio = std::min(worst.gradient_ratio, m.gradient_ratio);
    worst.patch_coherence = std::max(worst.patch_coherence, m.patch_coherence);
  }
  return worst;
}

std::string tile_report_json(const TileRun& run) {
  const TileReport& report = run.report;
  nlohmann::json j;
  j["input"] = run.input;
  j["input_width"] = run.input_width;
  j["input_height"] = run.input_height;
  j["width"] = report.width;
  j["height"] = report.height;
  j["block"] = report.block;
  j["overlap"] = report.overlap;
  j["seed"] = run.options.seed;
  j["border_px"] = report.border;
  j["blocks"] = report.blocks;
  j["seconds"] = run.seconds;
  if (run.options.fit_period || report.period_fitted) j["period"] = period_json(report.period);
  j["period_fitted"] = report.period_fitted;
  j["symmetry"] = report.symmetry;
  if (report.symmetry == 4) {
    // The check of the tile as written: rot90(tile) against the tile, 0 = exact.
    j["anisotropy"] = report.anisotropy;
    j["quarter_turn_difference"] = report.quarter_turn_difference;
    j["quarter_turn_exact"] = report.quarter_turn_difference == 0;
  }
  j["warnings"] = report.warnings;
  nlohmann::json list = nlohmann::json::array();
  for (const TileQuality& tile : run.tiles) {
    nlohmann::json t = quality_json(tile);
    t["file"] = tile.file;
    list.push_back(t);
  }
  j["tiles"] = list;
  j["targets_met"] = run.worst.targets_met;
  return internal::json_text(j);
}

std::string tile_variants_json(const TileRun& run) {
  const TileReport& report = run.report;
  nlohmann::json j;
  j["source"] = run.input;
  j["width"] = report.width;
  j["height"] = report.height;
  j["channels"] = run.input_channels;
  j["count"] = run.variants;
  j["seed"] = run.options.seed;
  j["block"] = report.block;
  j["overlap"] = report.overlap;
  j["border_px"] = report.border;
  j["period"] = period_json(report.period);
  nlohmann::json names = nlohmann::json::array();
  for (const TileQuality& tile : run.tiles) names.push_back(base_name(tile.file));  // next to the JSON
  j["files"] = names;
  return internal::json_text(j);
}

std::string tile_summary(const TileRun& run) {
  const TileMetrics& worst = run.worst.metrics;
  const std::string verdict = run.worst.targets_met ? "targets met" : "targets NOT met: " + run.worst.targets_failed;
  return internal::format_text(
      "%s %dx%d -> %s %dx%d: wrap %.2f x %.2f y, worst seam %.2f (exemplar %.2f), hist L1 %.3f, "
      "gradient %.2f, coherence %.3f (exemplar %.3f%s), %s%s, %.2f s\n",
      run.input.c_str(), run.input_width, run.input_height, run.output.c_str(), run.report.width, run.report.height,
      worst.wrap_ratio_x, worst.wrap_ratio_y, worst.worst_seam_ratio, worst.exemplar_worst_seam_ratio,
      worst.histogram_l1, worst.gradient_ratio, worst.patch_coherence, worst.exemplar_patch_coherence,
      worst.coherence_with_turns ? ", both with quarter turns" : "", verdict.c_str(),
      run.report.symmetry != 4                  ? ""
      : run.report.quarter_turn_difference == 0 ? ", quarter-turn symmetric (exact)"
                                                : ", quarter turn NOT exact",
      run.seconds);
}

std::string eval_tile_report_json(const TileQuality& tile, int width, int height, const std::string& exemplar) {
  nlohmann::json j = quality_json(tile);
  j["file"] = tile.file;
  j["width"] = width;
  j["height"] = height;
  j["gradient_energy"] = tile.metrics.gradient_energy;
  if (!exemplar.empty()) j["exemplar"] = exemplar;
  return internal::json_text(j);
}

}  // namespace tailor
