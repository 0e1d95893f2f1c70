// tailor tile: make a texture self-tileable (thesis chapter 3), optionally period-fitted and with
// variants sharing their borders; prints one summary line with the quality metrics and the time.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "util/atomic_file.h"
#include "tailor/image.h"
#include "tailor/tiling.h"

namespace tailor::cli {
namespace {

struct TileCliOptions {
  std::string input;
  std::string output;
  std::string json;
  int block = 32;
  int overlap = 0;
  uint64_t seed = 1;
  int variants = 1;
  bool fit_period = false;
  bool quiet = false;
};

bool ends_with_png(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".png";
}

std::string base_name(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

nlohmann::json period_json(const PeriodEstimate& p) {
  return {{"x", p.period_x},
          {"y", p.period_y},
          {"found_x", p.found_x},
          {"found_y", p.found_y},
          {"confidence_x", p.confidence_x},
          {"confidence_y", p.confidence_y}};
}

int run_tile(const TileCliOptions& opt) {
  if (!ends_with_png(opt.output))
    return report_error(Status::error(ErrorCode::kInvalidArgument, opt.output, "output must be a .png file"));
  // Every file this run writes, checked before any work so that a refused run writes nothing.
  const std::string stem = opt.output.substr(0, opt.output.size() - 4);
  std::vector<OutputPath> outputs;
  for (int k = 0; k < opt.variants; ++k)
    outputs.push_back({opt.variants == 1 ? opt.output : stem + "_" + std::to_string(k) + ".png", "--output"});
  if (opt.variants > 1) outputs.push_back({stem + ".json", "the variants' JSON"});
  if (!opt.json.empty()) outputs.push_back({opt.json, "--json"});
  if (opt.variants >= 1 && opt.variants <= 64) {  // other counts: make_tile_variants refuses them
    if (Status s = check_outputs(outputs, {opt.input}); !s) return report_error(s);
  }
  Image exemplar;
  if (Status s = load_image(opt.input, exemplar); !s) return report_error(s);

  TileOptions options;
  options.block = opt.block;
  options.overlap = opt.overlap;
  options.seed = opt.seed;
  options.fit_period = opt.fit_period;
  Progress progress("tile", opt.quiet);
  options.progress = [&progress](double f) { return progress.update(f); };

  const auto start = std::chrono::steady_clock::now();
  std::vector<Image> tiles;
  TileReport report;
  const Status status = make_tile_variants(exemplar, options, opt.variants, tiles, &report);
  const double seconds = seconds_since(start);
  progress.done();
  if (!status) return report_error(status.with_file(opt.input));
  for (const std::string& w : report.warnings) warn(opt.quiet, opt.input + ": " + w);

  // Output names: OUT itself, or OUT-without-.png + "_k.png" for variants. All outputs are staged
  // and land together at the end (none on a failure half-way).
  internal::FileBatch batch;
  std::vector<std::string> files;
  for (size_t k = 0; k < tiles.size(); ++k) {
    const std::string path = opt.variants == 1 ? opt.output : stem + "_" + std::to_string(k) + ".png";
    if (Status s = write_png(path, tiles[k]); !s) return report_error(s);
    files.push_back(path);
  }
  if (opt.variants > 1) {
    nlohmann::json j;
    j["source"] = opt.input;
    j["width"] = report.width;
    j["height"] = report.height;
    j["channels"] = exemplar.channels;
    j["count"] = opt.variants;
    j["seed"] = opt.seed;
    j["block"] = report.block;
    j["overlap"] = report.overlap;
    j["border_px"] = report.border;
    j["period"] = period_json(report.period);
    nlohmann::json names = nlohmann::json::array();
    for (const std::string& f : files) names.push_back(base_name(f));  // next to the JSON
    j["files"] = names;
    if (Status s = internal::write_file_atomic(stem + ".json", json_text(j) + "\n"); !s) return report_error(s);
  }

  if (opt.quiet && opt.json.empty()) {
    if (Status s = batch.commit(); !s) return report_error(s);
    return kExitOk;
  }
  // Metrics against the input as given (also when the tile was period-fitted).
  std::vector<TileMetrics> metrics(tiles.size());
  for (size_t k = 0; k < tiles.size(); ++k)
    if (Status s = tile_metrics(tiles[k], &exemplar, metrics[k]); !s) return report_error(s.with_file(files[k]));
  TileMetrics worst = metrics[0];  // worst value of each metric over the variants
  for (const TileMetrics& m : metrics) {
    auto far = [](double a, double b) { return std::abs(a - 1.0) > std::abs(b - 1.0) ? a : b; };
    worst.wrap_ratio_x = far(m.wrap_ratio_x, worst.wrap_ratio_x);
    worst.wrap_ratio_y = far(m.wrap_ratio_y, worst.wrap_ratio_y);
    worst.worst_seam_ratio = std::max(worst.worst_seam_ratio, m.worst_seam_ratio);
    worst.histogram_l1 = std::max(worst.histogram_l1, m.histogram_l1);
    worst.gradient_ratio = std::min(worst.gradient_ratio, m.gradient_ratio);
    worst.patch_coherence = std::max(worst.patch_coherence, m.patch_coherence);
  }
  if (!opt.json.empty()) {
    nlohmann::json j;
    j["input"] = opt.input;
    j["input_width"] = exemplar.width;
    j["input_height"] = exemplar.height;
    j["width"] = report.width;
    j["height"] = report.height;
    j["block"] = report.block;
    j["overlap"] = report.overlap;
    j["seed"] = opt.seed;
    j["border_px"] = report.border;
    j["blocks"] = report.blocks;
    j["seconds"] = seconds;
    if (opt.fit_period) j["period"] = period_json(report.period);
    j["warnings"] = report.warnings;
    nlohmann::json list = nlohmann::json::array();
    for (size_t k = 0; k < tiles.size(); ++k) {
      nlohmann::json t = tile_metrics_json(metrics[k], true);
      t["file"] = files[k];
      list.push_back(t);
    }
    j["tiles"] = list;
    j["targets_met"] = meets_tile_targets(worst);
    if (Status s = internal::write_file_atomic(opt.json, json_text(j) + "\n"); !s) return report_error(s);
  }
  if (Status s = batch.commit(); !s) return report_error(s);
  if (!opt.quiet) {
    std::string out = opt.variants == 1 ? opt.output : stem + "_{0.." + std::to_string(opt.variants - 1) + "}.png";
    std::string failed;
    const bool met = meets_tile_targets(worst, &failed);
    std::printf(
        "%s %dx%d -> %s %dx%d: wrap %.2f x %.2f y, worst seam %.2f (exemplar %.2f), hist L1 %.3f, "
        "gradient %.2f, coherence %.3f (exemplar %.3f), %s, %.2f s\n",
        opt.input.c_str(), exemplar.width, exemplar.height, out.c_str(), report.width, report.height,
        worst.wrap_ratio_x, worst.wrap_ratio_y, worst.worst_seam_ratio, worst.exemplar_worst_seam_ratio,
        worst.histogram_l1, worst.gradient_ratio, worst.patch_coherence, worst.exemplar_patch_coherence,
        met ? "targets met" : ("targets NOT met: " + failed).c_str(), seconds);
  }
  return kExitOk;
}

}  // namespace

void register_tile(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<TileCliOptions>();
  auto* cmd = app.add_subcommand("tile", "Make a texture image self-tileable (quadrant swap + image quilting)");
  cmd->add_option("input", opt->input, "Texture image (.png .jpg .tga .bmp, 8-bit or 16-bit PNG)")->required();
  cmd->add_option("-o,--output", opt->output, "Output .png (with --variants: NAME_0.png ... and NAME.json)")
      ->required();
  cmd->add_option("--block", opt->block, "Quilting block size in px")->default_val(32)->check(CLI::Range(8, 256));
  cmd->add_option("--overlap", opt->overlap, "Block overlap in px (default block/4)")->check(CLI::Range(1, 127));
  cmd->add_option("--seed", opt->seed, "Seed of the random block choice (same seed, same output)")->default_val(1);
  cmd->add_option("--variants", opt->variants, "Number of tiles with identical borders, different interiors")
      ->default_val(1)
      ->check(CLI::Range(1, 64));
  cmd->add_flag("--fit-period", opt->fit_period,
                "Crop or extend to a whole number of texel periods (regular patterns)");
  cmd->add_option("--json", opt->json, "Write the metrics and settings as JSON to this file");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but errors");
  cmd->footer(
      "Examples:\n"
      "  tailor tile bricks.jpg -o bricks_tile.png\n"
      "  tailor tile bricks.jpg -o bricks.png --fit-period --variants 4   # bricks_0..3.png + bricks.json\n"
      "  tailor eval-tile bricks_tile.png bricks.jpg                     # check the result");
  cmd->callback([&run, opt] {
    run = [opt] {
      if (opt->overlap != 0 && opt->overlap > opt->block / 2 - 1)
        return report_error(Status::error(ErrorCode::kInvalidArgument, "", "--overlap must be at most block/2 - 1",
                                          "block " + std::to_string(opt->block)));
      return run_tile(*opt);
    };
  });
}

}  // namespace tailor::cli
