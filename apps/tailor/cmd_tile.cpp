// tailor tile: make a texture self-tileable (thesis chapter 3), optionally period-fitted and with
// variants sharing their borders; prints one summary line with the quality metrics and the time.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli.h"
#include "tailor/image.h"
#include "tailor/report.h"
#include "tailor/tiling.h"
#include "util/atomic_file.h"

namespace tailor::cli {
namespace {

struct TileCliOptions {
  std::string input;
  std::string output;
  std::string json;
  TileOptions options;             // bound to --block, --overlap, --seed, --fit-period (defaults: TileOptions')
  ImageLoadOptions image_options;  // --max-image-pixels (default: ImageLoadOptions')
  int variants = 1;
  bool quiet = false;
};

bool ends_with_png(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".png";
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
  if (Status s = load_image(opt.input, exemplar, opt.image_options); !s) return report_error(s);

  TileOptions options = opt.options;
  Progress progress("tile", opt.quiet);
  options.progress = [&progress](double f) { return progress.update(f); };

  TileRun run;  // the report
  run.input = opt.input;
  run.input_width = exemplar.width;
  run.input_height = exemplar.height;
  run.input_channels = exemplar.channels;
  run.output = opt.variants == 1 ? opt.output : stem + "_{0.." + std::to_string(opt.variants - 1) + "}.png";
  run.options = options;
  run.variants = opt.variants;
  const auto start = std::chrono::steady_clock::now();
  std::vector<Image> tiles;
  const Status status = make_tile_variants(exemplar, options, opt.variants, tiles, &run.report);
  run.seconds = seconds_since(start);
  progress.done();
  if (!status) return report_error(status.with_file(opt.input));
  for (const std::string& w : run.report.warnings) warn(opt.quiet, opt.input + ": " + w);

  // Output names: OUT itself, or OUT-without-.png + "_k.png" for variants. All outputs are staged
  // and land together at the end (none on a failure half-way).
  internal::FileBatch batch;
  run.tiles.resize(tiles.size());
  for (size_t k = 0; k < tiles.size(); ++k) {
    const std::string path = opt.variants == 1 ? opt.output : stem + "_" + std::to_string(k) + ".png";
    if (Status s = write_png(path, tiles[k]); !s) return report_error(s);
    run.tiles[k].file = path;
  }
  if (opt.variants > 1) {
    if (Status s = internal::write_file_atomic(stem + ".json", tile_variants_json(run)); !s) return report_error(s);
  }

  if (opt.quiet && opt.json.empty()) {
    if (Status s = batch.commit(); !s) return report_error(s);
    return kExitOk;
  }
  // Metrics against the input as given (also when the tile was period-fitted).
  for (size_t k = 0; k < tiles.size(); ++k) {
    TileQuality& tile = run.tiles[k];
    if (Status s = tile_metrics(tiles[k], &exemplar, tile.metrics); !s) return report_error(s.with_file(tile.file));
    tile.targets_met = meets_tile_targets(tile.metrics, &tile.targets_failed);
  }
  run.worst.metrics = worst_tile_metrics(run.tiles);  // worst value of each metric over the variants
  run.worst.targets_met = meets_tile_targets(run.worst.metrics, &run.worst.targets_failed);
  if (!opt.json.empty()) {
    if (Status s = internal::write_file_atomic(opt.json, tile_report_json(run)); !s) return report_error(s);
  }
  if (Status s = batch.commit(); !s) return report_error(s);
  if (!opt.quiet) std::fputs(tile_summary(run).c_str(), stdout);
  return kExitOk;
}

}  // namespace

void register_tile(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<TileCliOptions>();
  auto* cmd = app.add_subcommand("tile", "Make a texture image self-tileable (quadrant swap + image quilting)");
  cmd->add_option("input", opt->input, "Texture image (.png .jpg .tga .bmp, 8-bit or 16-bit PNG)")->required();
  cmd->add_option("-o,--output", opt->output,
                  "Output .png (with --variants: NAME_0.png ... and NAME.json); a symlink is written through (its "
                  "target replaced)")
      ->required();
  TileOptions& options = opt->options;
  add_documented(cmd, option_doc(kTileOptionDocs, "block"), options.block)->check(CLI::Range(8, 256));
  const OptionDoc& overlap = option_doc(kTileOptionDocs, "overlap");  // its default, 0, stands for block/4
  cmd->add_option(std::string(overlap.flag), options.overlap, std::string(overlap.help))->check(CLI::Range(1, 127));
  add_documented(cmd, option_doc(kTileOptionDocs, "seed"), options.seed);
  cmd->add_option("--variants", opt->variants, "Number of tiles with identical borders, different interiors")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  const OptionDoc& fit_period = option_doc(kTileOptionDocs, "fit_period");
  cmd->add_flag(std::string(fit_period.flag), options.fit_period, std::string(fit_period.help));
  add_documented(cmd, option_doc(kTileOptionDocs, "symmetry"), options.symmetry)->check(CLI::IsMember({1, 4}));
  add_documented(cmd, option_doc(kImageLoadOptionDocs, "max_pixels"), opt->image_options.max_pixels)
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", opt->json, "Write the metrics and settings as JSON to this file");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but errors");
  cmd->footer(
      "Examples:\n"
      "  tailor tile bricks.jpg -o bricks_tile.png\n"
      "  tailor tile bricks.jpg -o bricks.png --fit-period --variants 4   # bricks_0..3.png + bricks.json\n"
      "  tailor tile gravel.png -o gravel_tile.png --symmetry 4         # also unchanged by a quarter turn\n"
      "  tailor eval-tile bricks_tile.png bricks.jpg                     # check the result");
  cmd->callback([&run, opt] {
    run = [opt] {
      const TileOptions& o = opt->options;
      if (o.overlap != 0 && o.overlap > o.block / 2 - 1)
        return report_error(Status::error(ErrorCode::kInvalidArgument, "", "--overlap must be at most block/2 - 1",
                                          "block " + std::to_string(o.block)));
      if (o.symmetry == 4 && opt->variants > 1)
        return report_error(Status::error(ErrorCode::kInvalidArgument, "",
                                          "--symmetry 4 makes one tile: --variants cannot be used with it"));
      if (o.symmetry == 4 && o.fit_period)
        return report_error(
            Status::error(ErrorCode::kInvalidArgument, "", "--symmetry 4 cannot be combined with --fit-period"));
      return run_tile(*opt);
    };
  });
}

}  // namespace tailor::cli
