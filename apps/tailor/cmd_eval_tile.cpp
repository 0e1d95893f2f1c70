// tailor eval-tile: quality metrics of a (supposedly) self-tileable texture, optionally against
// the exemplar it was made from.
#include <cstdio>
#include <memory>
#include <string>

#include "cli.h"
#include "tailor/image.h"
#include "tailor/report.h"
#include "tailor/tiling.h"

namespace tailor::cli {
namespace {

struct EvalTileOptions {
  std::string tile;
  std::string exemplar;
  ImageLoadOptions image_options;  // --max-image-pixels
  bool json = false;
  bool quiet = false;
};

int run_eval_tile(const EvalTileOptions& opt) {
  Image tile, exemplar;
  if (Status s = load_image(opt.tile, tile, opt.image_options); !s) return report_error(s);
  const bool with_exemplar = !opt.exemplar.empty();
  if (with_exemplar)
    if (Status s = load_image(opt.exemplar, exemplar, opt.image_options); !s) return report_error(s);
  TileQuality quality;
  quality.file = opt.tile;
  const TileMetrics& m = quality.metrics;
  if (Status s = tile_metrics(tile, with_exemplar ? &exemplar : nullptr, quality.metrics); !s) {
    // Name the image the complaint is about ("exemplar ..." messages concern the exemplar).
    const bool about_exemplar = with_exemplar && s.what().rfind("exemplar", 0) == 0;
    return report_error(s.with_file(about_exemplar ? opt.exemplar : opt.tile));
  }
  quality.targets_met = meets_tile_targets(m, &quality.targets_failed);
  const bool met = quality.targets_met;
  const std::string& failed = quality.targets_failed;
  if (opt.json) {
    std::fputs(eval_tile_report_json(quality, tile.width, tile.height, opt.exemplar).c_str(), stdout);
    return kExitOk;
  }
  if (opt.quiet) {
    std::printf("%s\n", met ? "targets met" : ("targets NOT met: " + failed).c_str());
    return kExitOk;
  }
  std::printf("%s %dx%d\n", opt.tile.c_str(), tile.width, tile.height);
  std::printf("  wrap-seam ratio x / y   %.3f / %.3f   (~1 seamless; target [0.8, 1.2])\n", m.wrap_ratio_x,
              m.wrap_ratio_y);
  if (!with_exemplar) {
    std::printf("  worst straight seam     %.3f   (target <= 1.5)\n", m.worst_seam_ratio);
    std::printf("  gradient energy         %.3f   (mean |dx| + |dy|, 8-bit units)\n", m.gradient_energy);
  } else {
    std::printf("  exemplar wrap ratio     %.3f / %.3f   (%s)\n", m.exemplar_wrap_ratio_x, m.exemplar_wrap_ratio_y,
                opt.exemplar.c_str());
    std::printf("  worst straight seam     %.3f   (exemplar interior %.3f; target <= max of it and 1.5)\n",
                m.worst_seam_ratio, m.exemplar_worst_seam_ratio);
    std::printf("  histogram L1            %.4f  (target <= 0.1)\n", m.histogram_l1);
    std::printf("  gradient ratio          %.3f   (target >= 0.95; < 1 blurred or ghosted)\n", m.gradient_ratio);
    std::printf("  patch coherence         %.4f  (exemplar read toroidally %.4f; 0 = all copied)\n", m.patch_coherence,
                m.exemplar_patch_coherence);
  }
  if (m.quarter_turn_difference < 0)
    std::printf("  quarter turn            not square\n");
  else
    std::printf(
        "  quarter turn            max difference %d after the best shift (%d, %d)   (0 = unchanged by a quarter "
        "turn%s)\n",
        m.quarter_turn_difference, m.quarter_turn_shift_x, m.quarter_turn_shift_y,
        m.coherence_with_turns ? "; coherence measured against the exemplar's four turns" : "");
  std::printf("  targets                 %s\n", met ? "met" : ("NOT met: " + failed).c_str());
  return kExitOk;
}

}  // namespace

void register_eval_tile(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<EvalTileOptions>();
  auto* cmd =
      app.add_subcommand("eval-tile", "Quality metrics of a tileable texture (seams, histogram, gradients, coherence)");
  cmd->add_option("tile", opt->tile, "The tile to check (.png .jpg .tga .bmp)")->required();
  cmd->add_option("exemplar", opt->exemplar, "The exemplar it was made from (enables histogram, gradient, coherence)");
  add_documented(cmd, option_doc(kImageLoadOptionDocs, "max_pixels"), opt->image_options.max_pixels)
      ->check(kAtLeastOne);
  cmd->add_flag("--json", opt->json, "Print a JSON object instead of text");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print only whether the targets are met");
  cmd->footer("Example:\n  tailor tile bricks.jpg -o bricks_tile.png && tailor eval-tile bricks_tile.png bricks.jpg");
  cmd->callback([&run, opt] { run = [opt] { return run_eval_tile(*opt); }; });
}

}  // namespace tailor::cli
