// tailor tile: make a texture self-tileable (thesis chapter 3), optionally period-fitted and with
// variants sharing their borders; prints one summary line with the quality metrics and the time.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "cli.h"
#include "tailor/image.h"
#include "tailor/material.h"
#include "tailor/report.h"
#include "tailor/tiling.h"
#include "util/atomic_file.h"
#include "util/bounded_json.h"
#include "util/text_scan.h"

namespace tailor::cli {
namespace {

struct TileCliOptions {
  std::string input;
  std::string output;
  std::vector<std::string> set;           // --set: the maps of a material set (-o is then a folder)
  std::string material;                   // --material: a JSON naming the maps (alternative to --set)
  std::vector<std::string> normal_maps;   // --normal-map: which of the set's maps are normal maps
  std::vector<std::string> directx_maps;  // --material: normal maps whose role says DirectX ("normal_dx")
  std::string normal_convention = "gl";   // --normal-convention gl|dx (recorded in OUTDIR/material.json)
  std::string json;
  TileOptions options;             // bound to --block, --overlap, --seed, --fit-period (defaults: TileOptions')
  ImageLoadOptions image_options;  // --max-image-pixels (default: ImageLoadOptions')
  int variants = 1;
  bool quiet = false;
  bool allow_misses = false;  // --allow-misses: a tile that misses its targets is a warning, exit 0
};

//! The verdict on the written tiles: each missed target on stderr, one line with its figure
//! (missed_tile_targets), and the exit code: kExitTargetsMissed when a tile misses one, unless
//! --allow-misses (then warnings, silenced by --quiet, and kExitOk).
int judge_tiles(const std::vector<TileQuality>& tiles, const TileCliOptions& opt) {
  bool missed = false;
  for (const TileQuality& tile : tiles)
    for (const std::string& target : missed_tile_targets(tile.metrics)) {
      missed = true;
      if (opt.allow_misses)
        warn(opt.quiet, tile.file + ": misses a target: " + target);
      else
        std::fprintf(stderr, "tailor: error: %s: misses a target, written anyway (--allow-misses accepts it): %s\n",
                     tile.file.c_str(), target.c_str());
    }
  return missed && !opt.allow_misses ? kExitTargetsMissed : kExitOk;
}

//! Whether the run measures its tiles: for the summary line, --json, or the verdict.
bool measures(const TileCliOptions& opt) { return !opt.quiet || !opt.json.empty() || !opt.allow_misses; }

int run_tile_set(TileCliOptions opt);

//! A 16-bit PNG input: tiled as a set of one map (make_tileable_set keeps the 16 bits).
int run_tile16(const TileCliOptions& opt, const Image16& input) {
  TileOptions options = opt.options;
  Progress progress("tile", opt.quiet);
  options.progress = [&progress](double f) { return progress.update(f); };
  std::vector<TileMap> maps(1);
  maps[0].image = input;
  TileRun run;
  run.input = opt.input;
  run.input_width = input.width;
  run.input_height = input.height;
  run.input_channels = input.channels;
  const std::string stem = opt.output.substr(0, opt.output.size() - 4);
  run.output = opt.variants == 1 ? opt.output : stem + "_{0.." + std::to_string(opt.variants - 1) + "}.png";
  run.options = options;
  run.variants = opt.variants;
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<Image16>> tiles;
  const Status status = make_tileable_set(maps, options, opt.variants, tiles, &run.report);
  run.seconds = seconds_since(start);
  progress.done();
  if (!status) return report_error(status.with_file(opt.input));
  for (const std::string& w : run.report.warnings) warn(opt.quiet, opt.input + ": " + w);
  internal::FileBatch batch;
  run.tiles.resize(tiles.size());
  for (size_t k = 0; k < tiles.size(); ++k) {
    const std::string path = opt.variants == 1 ? opt.output : stem + "_" + std::to_string(k) + ".png";
    if (Status s = write_png16(path, tiles[k][0]); !s) return report_error(s);
    run.tiles[k].file = path;
  }
  if (opt.variants > 1) {
    if (Status s = internal::write_file_atomic(stem + ".json", tile_variants_json(run)); !s) return report_error(s);
  }
  if (measures(opt)) {
    const Image input8 = to_image8(input);
    for (size_t k = 0; k < tiles.size(); ++k) {
      TileQuality& tile = run.tiles[k];
      if (Status s = tile_metrics(to_image8(tiles[k][0]), &input8, tile.metrics); !s)
        return report_error(s.with_file(tile.file));
      tile.targets_met = meets_tile_targets(tile.metrics, &tile.targets_failed);
    }
    run.worst.metrics = worst_tile_metrics(run.tiles);
    run.worst.targets_met = meets_tile_targets(run.worst.metrics, &run.worst.targets_failed);
    if (!opt.json.empty()) {
      if (Status s = internal::write_file_atomic(opt.json, tile_report_json(run)); !s) return report_error(s);
    }
  }
  if (Status s = batch.commit(); !s) return report_error(s);
  if (!opt.quiet) std::fputs(tile_summary(run).c_str(), stdout);
  return measures(opt) ? judge_tiles(run.tiles, opt) : kExitOk;
}

int run_tile(const TileCliOptions& opt) {
  if (!opt.set.empty() || !opt.material.empty()) return run_tile_set(opt);
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
  {
    Image16 deep;
    if (Status s = load_image16(opt.input, deep, opt.image_options); !s) return report_error(s);
    if (deep.bits == 16) return run_tile16(opt, deep);
    exemplar = to_image8(deep);
  }

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

  if (!measures(opt)) {
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
  return judge_tiles(run.tiles, opt);
}

//! A key of the material JSON that read_material does not know ("nomal": true) would be ignored
//! without a word: a warning names it. What tile writes in its material.json (source, bits, ...)
//! and map's "role" are known.
void warn_unknown_keys(const TileCliOptions& opt, const nlohmann::json& object,
                       std::initializer_list<std::string_view> known, const std::string& where) {
  for (const auto& item : object.items()) {
    if (std::find(known.begin(), known.end(), item.key()) != known.end()) continue;
    std::string list;
    for (const std::string_view key : known) list += (list.empty() ? "" : ", ") + std::string(key);
    warn(opt.quiet, opt.material + ": " + where + "unknown key " + internal::quote_input(item.key()) +
                        " ignored (known: " + list + ")");
  }
}

//! --material JSON: {"maps": [{"file": "color.png"}, {"file": "normal.png", "normal": true}, ...],
//! "normal_convention": "gl"}; files relative to the JSON's folder. Fills opt.set / normal_maps.
Status read_material(TileCliOptions& opt) {
  std::string text;  // read_file: a FIFO or device is refused, not waited on
  std::error_code ec;
  if (Status s = internal::read_file(opt.material, text); !s)
    return s.code() == ErrorCode::kIo && !std::filesystem::exists(std::filesystem::status(opt.material, ec))
               ? Status::error(ErrorCode::kIo, opt.material, "cannot open the material description")
               : s;
  nlohmann::json j;
  if (const auto parsed = internal::parse_json_bounded(text, j); parsed == internal::JsonParse::kTooDeep)
    return Status::error(ErrorCode::kInvalidArgument, opt.material, internal::json_problem(parsed));
  if (j.is_discarded() || !j.is_object() || !j.contains("maps") || !j["maps"].is_array() || j["maps"].empty())
    return Status::error(ErrorCode::kInvalidArgument, opt.material,
                         "not a material description (expected {\"maps\": [{\"file\": ...}, ...]})");
  const std::string dir = dir_name(opt.material);
  warn_unknown_keys(opt, j, {"maps", "normal_convention", "symmetry", "width", "height"}, "");
  for (size_t i = 0; i < j["maps"].size(); ++i) {
    const nlohmann::json& m = j["maps"][i];
    if (!m.is_object() || !m.contains("file") || !m["file"].is_string())
      return Status::error(ErrorCode::kInvalidArgument, opt.material, "map without a \"file\" string",
                           "maps[" + std::to_string(i) + "]");
    warn_unknown_keys(opt, m, {"file", "normal", "type", "role", "source", "bits", "channels", "variants"},
                      "maps[" + std::to_string(i) + "]: ");
    std::string file = m["file"].get<std::string>();
    if (file.empty() || file[0] != '/') file = dir + "/" + file;
    opt.set.push_back(file);
    // A "normal" that is not true or false ("yes") would silently tile a normal map as colour.
    if (m.contains("normal") && !m["normal"].is_boolean())
      return Status::error(ErrorCode::kInvalidArgument, opt.material, "\"normal\" must be true or false",
                           "maps[" + std::to_string(i) + "]");
    // "role" or "type" names the map as `tailor map --material` reads them (role words as in file
    // names: "normal", "normal_dx", "Normal"...).
    bool normal = m.contains("normal") && m["normal"].get<bool>(), directx = false;
    for (const char* key : {"role", "type"}) {
      if (!m.contains(key)) continue;
      if (!m[key].is_string())
        return Status::error(ErrorCode::kInvalidArgument, opt.material, std::string("\"") + key + "\" must be a string",
                             "maps[" + std::to_string(i) + "]");
      bool dx = false;
      if (material_role_from_name(m[key].get<std::string>(), &dx) == MaterialRole::kNormal) {
        normal = true;
        directx = directx || dx;
      }
    }
    if (normal) opt.normal_maps.push_back(file);
    if (normal && directx) opt.directx_maps.push_back(file);
  }
  if (j.contains("normal_convention"))  // not a string: "", which the check below refuses
    opt.normal_convention = j["normal_convention"].is_string() ? j["normal_convention"].get<std::string>() : "";
  if (opt.normal_convention != "gl" && opt.normal_convention != "dx")
    return Status::error(ErrorCode::kInvalidArgument, opt.material, "normal_convention must be \"gl\" or \"dx\"");
  return Status::ok();
}

//! tailor tile --set / --material: one cut for every map (make_tileable_set), outputs named as
//! the inputs inside the output folder, plus OUTDIR/material.json describing them.
int run_tile_set(TileCliOptions opt) {
  if (!opt.material.empty()) {
    if (Status s = read_material(opt); !s) return report_error(s);
  }
  // Without its trailing slashes ("tiled/" names the folder "tiled"): the names below join one.
  std::string outdir = opt.output;
  while (outdir.size() > 1 && outdir.back() == '/') outdir.pop_back();
  struct stat st {};
  const bool existed = ::stat(outdir.c_str(), &st) == 0;
  if (existed && !S_ISDIR(st.st_mode))
    return report_error(Status::error(ErrorCode::kInvalidArgument, outdir,
                                      "with --set or --material, -o names an output folder, not a file"));
  for (const std::string& n : opt.normal_maps)
    if (std::find(opt.set.begin(), opt.set.end(), n) == opt.set.end())
      return report_error(Status::error(ErrorCode::kInvalidArgument, n,
                                        "--normal-map must name one of the set's maps (the same path as in --set)"));
  // Output names (inside OUTDIR), checked before any work.
  std::vector<std::string> names;
  for (const std::string& in : opt.set) {
    const std::string name = tile_set_file_name(in);
    if (std::find(names.begin(), names.end(), name) != names.end())
      return report_error(Status::error(ErrorCode::kInvalidArgument, in,
                                        "two maps of the set would be written to the same file name",
                                        outdir + "/" + name));
    names.push_back(name);
  }
  auto file_of = [&](size_t m, int k) {
    const std::string stem = names[m].substr(0, names[m].size() - 4);
    return outdir + "/" + (opt.variants == 1 ? names[m] : stem + "_" + std::to_string(k) + ".png");
  };
  // The inputs: the maps, and the material description that named them.
  std::vector<std::string> inputs = opt.set;
  if (!opt.material.empty()) inputs.push_back(opt.material);
  if (existed) {
    std::vector<OutputPath> outputs;
    for (size_t m = 0; m < names.size(); ++m)
      for (int k = 0; k < opt.variants; ++k) outputs.push_back({file_of(m, k), "--output"});
    outputs.push_back({outdir + "/material.json", "the material description"});
    if (!opt.json.empty()) outputs.push_back({opt.json, "--json"});
    if (Status s = check_outputs(outputs, inputs); !s) return report_error(s);
  } else if (!opt.json.empty()) {
    if (Status s = check_outputs({{opt.json, "--json"}}, inputs); !s) return report_error(s);
  }
  std::vector<TileMap> maps(opt.set.size());
  for (size_t m = 0; m < opt.set.size(); ++m) {
    if (Status s = load_image16(opt.set[m], maps[m].image, opt.image_options); !s) return report_error(s);
    maps[m].normal = std::find(opt.normal_maps.begin(), opt.normal_maps.end(), opt.set[m]) != opt.normal_maps.end();
    // DirectX normal maps (their +y down) turn the other way round with --symmetry 4.
    bool dx_name = false;
    material_role_from_name(opt.set[m], &dx_name);
    maps[m].directx = maps[m].normal && (opt.normal_convention == "dx" || dx_name ||
                                         std::find(opt.directx_maps.begin(), opt.directx_maps.end(), opt.set[m]) !=
                                             opt.directx_maps.end());
    if (maps[m].normal && maps[m].image.channels < 3)  // make_tileable_set says "map N": name the file
      return report_error(Status::error(ErrorCode::kInvalidArgument, opt.set[m],
                                        "marked as a normal map (--normal-map) but has " +
                                            std::to_string(maps[m].image.channels) + " channel(s), not 3 or 4"));
    if (maps[m].image.width != maps[0].image.width || maps[m].image.height != maps[0].image.height)
      return report_error(
          Status::error(ErrorCode::kInvalidImage, opt.set[m], "every map of a set must have the same size",
                        std::to_string(maps[m].image.width) + "x" + std::to_string(maps[m].image.height) + ", but " +
                            base_name(opt.set[0]) + " is " + std::to_string(maps[0].image.width) + "x" +
                            std::to_string(maps[0].image.height)));
  }
  TileOptions options = opt.options;
  Progress progress("tile", opt.quiet);
  options.progress = [&progress](double f) { return progress.update(f); };
  TileRun run;
  run.input = opt.set[0];
  run.input_width = maps[0].image.width;
  run.input_height = maps[0].image.height;
  run.input_channels = maps[0].image.channels;
  run.output = outdir + "/";
  run.options = options;
  run.variants = opt.variants;
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<Image16>> tiles;
  const Status status = make_tileable_set(maps, options, opt.variants, tiles, &run.report);
  run.seconds = seconds_since(start);
  progress.done();
  if (!status) return report_error(status.with_file(opt.material.empty() ? opt.set[0] : opt.material));
  for (const std::string& w : run.report.warnings) warn(opt.quiet, opt.set[0] + ": " + w);

  // Everything is staged and lands together; a folder this run created is removed on failure.
  bool created = false;
  if (!existed) {
    if (::mkdir(outdir.c_str(), 0777) != 0)
      return report_error(Status::error(ErrorCode::kIo, outdir, "cannot create the output folder"));
    created = true;
  }
  // The writes, with their batch: on a failure the batch is gone (its staged files removed)
  // before the folder is.
  const Status written = [&]() -> Status {
    internal::FileBatch batch;
    TileSetRecord record;
    record.normal_convention = opt.normal_convention;
    record.symmetry = options.symmetry;
    record.width = run.report.width;
    record.height = run.report.height;
    for (size_t m = 0; m < maps.size(); ++m) {
      TileSetRecord::Map& entry = record.maps.emplace_back();
      entry.file = names[m];
      entry.source = opt.set[m];
      entry.normal = maps[m].normal;
      entry.directx = maps[m].directx;
      entry.bits = maps[m].image.bits;
      entry.channels = maps[m].image.channels;
      if (opt.variants > 1)
        for (int k = 0; k < opt.variants; ++k) entry.variants.push_back(base_name(file_of(m, k)));
    }
    for (int k = 0; k < opt.variants; ++k)
      for (size_t m = 0; m < maps.size(); ++m) {
        const std::string path = file_of(m, k);
        if (Status s = write_png16(path, tiles[static_cast<size_t>(k)][m]); !s) return s;
        TileQuality q;
        q.file = path;
        run.tiles.push_back(q);
      }
    if (Status s = write_tile_set_record(outdir, record); !s) return s;
    if (measures(opt)) {
      // Metrics of every output map against its input (8-bit reductions of 16-bit maps).
      bool all_met = true;
      std::string failed;
      std::vector<TileQuality> first_map;
      for (int k = 0; k < opt.variants; ++k)
        for (size_t m = 0; m < maps.size(); ++m) {
          TileQuality& q = run.tiles[static_cast<size_t>(k) * maps.size() + m];
          const Image tile8 = to_image8(tiles[static_cast<size_t>(k)][m]);
          const Image input8 = to_image8(maps[m].image);
          if (Status s = tile_metrics(tile8, &input8, q.metrics); !s) return s.with_file(q.file);
          q.targets_met = meets_tile_targets(q.metrics, &q.targets_failed);
          if (!q.targets_met) {
            all_met = false;
            failed += (failed.empty() ? "" : "; ") + names[m] + ": " + q.targets_failed;
          }
          if (m == 0) first_map.push_back(q);
        }
      run.worst.metrics = worst_tile_metrics(first_map);
      run.worst.targets_met = all_met;
      run.worst.targets_failed = failed;
      if (!opt.json.empty()) {
        if (Status s = internal::write_file_atomic(opt.json, tile_report_json(run)); !s) return s;
      }
    }
    return batch.commit();
  }();
  if (!written) {
    if (created) ::rmdir(outdir.c_str());
    return report_error(written);
  }
  if (!opt.quiet) std::fputs(tile_summary(run).c_str(), stdout);
  return measures(opt) ? judge_tiles(run.tiles, opt) : kExitOk;
}

}  // namespace

void register_tile(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<TileCliOptions>();
  auto* cmd = app.add_subcommand("tile", "Make a texture image self-tileable (quadrant swap + image quilting)");
  cmd->add_option("input", opt->input,
                  "Texture image (.png .jpg .tga .bmp; a 16-bit PNG gives a 16-bit tile); not with --set");
  cmd->add_option("-o,--output", opt->output,
                  "Output .png (with --variants: NAME_0.png ... and NAME.json); a symlink is written through (its "
                  "target replaced). With --set or --material: the output folder (created if missing)")
      ->required();
  cmd->add_option("--set", opt->set,
                  "Maps of one material (colour, normal, roughness, height...), all the same size: one cut for "
                  "all, written under their own names (as .png) into the -o folder with material.json")
      ->expected(1, -1);
  cmd->add_option("--material", opt->material,
                  "JSON naming the maps instead of --set: {\"maps\": [{\"file\": \"color.png\"}, {\"file\": "
                  "\"normal.png\", \"normal\": true}], \"normal_convention\": \"gl\"} (files relative to it)");
  cmd->add_option("--normal-map", opt->normal_maps,
                  "A map of the set that is a normal map (its path as given to --set): blended as vectors and "
                  "renormalised; may be repeated");
  cmd->add_option("--normal-convention", opt->normal_convention,
                  "Normal map convention, gl (+Y up) or dx (-Y): recorded in material.json (blending and "
                  "renormalising do not depend on it)")
      ->capture_default_str()
      ->check(CLI::IsMember({"gl", "dx"}));
  TileOptions& options = opt->options;
  add_documented(cmd, option_doc(kTileOptionDocs, "block"), options.block)->check(CLI::Range(8, 256));
  const OptionDoc& overlap = option_doc(kTileOptionDocs, "overlap");  // its default, 0, stands for block/4
  cmd->add_option(std::string(overlap.flag), options.overlap, std::string(overlap.help))->check(CLI::Range(1, 127));
  add_documented(cmd, option_doc(kTileOptionDocs, "seed"), options.seed)->check(kWholeNumber);
  cmd->add_option("--variants", opt->variants, "Number of tiles with identical borders, different interiors")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  const OptionDoc& fit_period = option_doc(kTileOptionDocs, "fit_period");
  cmd->add_flag(std::string(fit_period.flag), options.fit_period, std::string(fit_period.help));
  add_off_switch(cmd, option_doc(kTileOptionDocs, "auto_period"), options.auto_period);
  add_documented(cmd, option_doc(kTileOptionDocs, "symmetry"), options.symmetry)->check(CLI::IsMember({1, 4}));
  const OptionDoc& same_size = option_doc(kTileOptionDocs, "same_size");
  cmd->add_flag(std::string(same_size.flag), options.same_size, std::string(same_size.help));
  add_documented(cmd, option_doc(kImageLoadOptionDocs, "max_pixels"), opt->image_options.max_pixels)
      ->check(kAtLeastOne);
  cmd->add_option("--json", opt->json, "Write the metrics and settings as JSON to this file");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but errors");
  cmd->add_flag("--allow-misses", opt->allow_misses,
                "Accept a tile that misses its quality targets (those of 'tailor eval-tile'): exit 0 with a "
                "warning per missed target. Without it each missed target is one error line on stderr with "
                "its figure and the exit code is 3; the tile is written either way");
  cmd->footer(
      "Exit codes: 0 done, 1 bad input or I/O error, 2 bad command line, 3 the tile is written but misses "
      "a quality target (see --allow-misses).\n"
      "Examples:\n"
      "  tailor tile bricks.jpg -o bricks_tile.png\n"
      "  tailor tile bricks.jpg -o bricks.png --fit-period --variants 4   # bricks_0..3.png + bricks.json\n"
      "  tailor tile gravel.png -o gravel_tile.png --symmetry 4         # also unchanged by a quarter turn (2x the "
      "side)\n"
      "  tailor tile --set color.png normal.png rough.png --normal-map normal.png -o tiled/   # one cut for all\n"
      "  tailor eval-tile bricks_tile.png bricks.jpg                     # check the result");
  cmd->callback([&run, opt] {
    run = [opt] {
      const TileOptions& o = opt->options;
      const bool is_set = !opt->set.empty() || !opt->material.empty();
      if (is_set == !opt->input.empty() || (!opt->set.empty() && !opt->material.empty()))
        return report_error(Status::error(ErrorCode::kInvalidArgument, "",
                                          "give one input image, or --set MAPS..., or --material JSON"));
      if (!opt->normal_maps.empty() && opt->set.empty())
        return report_error(Status::error(ErrorCode::kInvalidArgument, "", "--normal-map needs --set"));
      if (o.overlap != 0 && o.overlap > o.block / 2 - 1)
        return report_error(Status::error(ErrorCode::kInvalidArgument, "", "--overlap must be at most block/2 - 1",
                                          "block " + std::to_string(o.block)));
      if (o.symmetry == 4 && opt->variants > 1)
        return report_error(Status::error(ErrorCode::kInvalidArgument, "",
                                          "--symmetry 4 makes one tile: --variants cannot be used with it"));
      if (o.symmetry == 4 && o.fit_period)
        return report_error(
            Status::error(ErrorCode::kInvalidArgument, "", "--symmetry 4 cannot be combined with --fit-period"));
      if (o.same_size && o.symmetry != 4)
        return report_error(Status::error(ErrorCode::kInvalidArgument, "", "--same-size needs --symmetry 4"));
      return run_tile(*opt);
    };
  });
}

}  // namespace tailor::cli
