// The reports of map, eval and tile (tailor/report.h): the JSON keys and values the CLI writes, and
// the summary lines it prints.
#include "tailor/report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace tailor {
namespace {

std::vector<std::string> keys(const nlohmann::json& j) {
  std::vector<std::string> out;
  for (const auto& item : j.items()) out.push_back(item.key());
  return out;
}

TEST(Report, MapJsonHoldsTheOptionsAndResults) {
  MapRun run;
  run.input = "in.ply";
  run.output = "out.glb";
  run.texture_width = run.texture_height = 512;
  run.axis = "pca";
  run.faces = 12;
  run.metrics.patches = 2;
  run.metrics.seam_length_ratio = 0.05;
  run.mapping.seconds = 0.002;
  run.previews = {"a.png"};
  const std::string text = map_report_json(run);
  ASSERT_EQ(text.back(), '\n');
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(keys(j), (std::vector<std::string>{"input", "mapping", "mesh", "metrics", "options", "output", "previews",
                                               "texture", "texture_size", "time_ms"}));
  // The options come from the struct: its defaults, with their types (floats stay floats).
  const MappingOptions defaults;
  EXPECT_EQ(j["options"]["mode"], "patches");
  EXPECT_EQ(j["options"]["scale"].get<double>(), double{defaults.scale});
  EXPECT_TRUE(j["options"]["scale"].is_number_float());
  EXPECT_EQ(j["options"]["crack_rings"], defaults.crack_rings);
  EXPECT_EQ(j["options"]["close_cracks"], true);
  EXPECT_EQ(j["options"]["axis"], "pca");
  EXPECT_EQ(j["options"]["symmetry"], defaults.symmetry);
  EXPECT_EQ(j["mesh"]["faces"], 12);
  EXPECT_EQ(j["mesh"]["not_read"], "");
  EXPECT_EQ(j["metrics"]["patches"], 2);
  EXPECT_DOUBLE_EQ(j["time_ms"]["mapping"].get<double>(), 2.0);
  EXPECT_EQ(j["previews"], nlohmann::json::array({"a.png"}));

  // What the map warns of the input, the report keeps.
  run.load.not_read = "1 line after the 1 face the OFF header declares (from line 8)";
  run.load.not_kept = "TANGENT";
  const nlohmann::json warned = nlohmann::json::parse(map_report_json(run));
  EXPECT_EQ(warned["mesh"]["not_read"], run.load.not_read);
  EXPECT_EQ(warned["mesh"]["not_kept"], "TANGENT");

  run.stability = StabilityReport{};
  run.stability->removed_faces = 3;
  EXPECT_EQ(nlohmann::json::parse(map_report_json(run))["stability"]["removed_faces"], 3);
}

TEST(Report, MapSummaryIsOneLinePlusStability) {
  MapRun run;
  run.input = "in.ply";
  run.output = "out.glb";
  run.faces = 12;
  run.metrics.patches = 2;
  run.metrics.seam_length_ratio = 0.0512;
  std::string text = map_summary(run);
  // The default scale (800 px across the mesh) of a 512 px texture: 1.56 repeats.
  EXPECT_EQ(text.find("in.ply: 12 faces, 2 patches, 1.56 repeats across the mesh, seams 5.12% of edge length"), 0u)
      << text;
  EXPECT_EQ(text.find("axis choice"), std::string::npos);
  EXPECT_EQ(text.find("peak"), std::string::npos);  // not measured: not said
  EXPECT_EQ(map_report_json(run).find("peak_resident_mib"), std::string::npos);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);
  run.peak_resident_bytes = size_t{157} << 20;
  EXPECT_NE(map_summary(run).find(" ms, peak 157 MiB -> out.glb\n"), std::string::npos) << map_summary(run);
  EXPECT_NE(map_report_json(run).find("\"peak_resident_mib\": 157"), std::string::npos);
  run.axis_auto = true;
  run.axis_choice_seconds = 0.0421;
  run.stability = StabilityReport{};
  text = map_summary(run);
  EXPECT_NE(text.find("axis choice 42, orientation"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2);
  EXPECT_NE(text.find("\nstability: removed 0 faces"), std::string::npos) << text;
}

// The repeats across the mesh: its longest side in texture periods at the density the map used.
TEST(Report, MapSummaryStatesTheRepeatsAcrossTheMesh) {
  MapRun run;
  run.input = "in.ply";
  run.faces = 12;
  run.metrics.patches = 2;
  run.longest_side = 4.0;
  run.options.mapping.texture_period_px = 512.f;
  run.options.mapping.scale = 1024.f;  // normalised: the scale spans the longest side
  EXPECT_DOUBLE_EQ(map_repeats_across(run), 2.0);
  std::string text = map_summary(run);
  EXPECT_EQ(text.find("in.ply: 12 faces, 2 patches, 2.00 repeats across the mesh, seams "), 0u) << text;
  EXPECT_EQ(text.find("texels per unit"), std::string::npos) << text;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(map_report_json(run))["mapping"]["repeats_across_mesh"].get<double>(), 2.0);
  // World units (--tile-size 2 of a 512 px texture): 256 texels per unit, 4 units = 2 repeats.
  run.texels_per_unit = 256.0;
  run.options.orientation.fixed_unit_scale = 0.25f;
  run.options.mapping.scale = 1024.f;
  text = map_summary(run);
  EXPECT_NE(text.find(", 2.00 repeats across the mesh (256 texels per unit), seams"), std::string::npos) << text;
  // Chunked: the density per world unit every chunk was mapped at (a power of two), not the scale.
  run.texels_per_unit = 0.0;
  run.options.orientation.fixed_unit_scale = 0.f;
  run.mapping.chunks = 3;
  run.mapping.texels_per_unit = 64.0;
  EXPECT_DOUBLE_EQ(map_repeats_across(run), 0.5);
  EXPECT_NE(map_summary(run).find(", 0.50 repeats across the mesh, seams"), std::string::npos);
}

TEST(Report, FileNamesThatAreNotUtf8DoNotBreakTheJson) {
  EvalRun run;
  run.file = "bad\xff.obj";
  const nlohmann::json j = nlohmann::json::parse(eval_report_json(run));
  EXPECT_EQ(j["file"], "bad\xef\xbf\xbd.obj");
  EXPECT_TRUE(j.contains("visible_seam_ratio") && j.contains("visible_dangling_ends"));
  EXPECT_EQ(j.size(), 31u);
  EXPECT_EQ(eval_summary(run).find("bad\xff.obj: 0 faces"), 0u);
  const nlohmann::json s = nlohmann::json::parse(stability_report_json(run.file, StabilityReport{}));
  EXPECT_EQ(keys(s),
            (std::vector<std::string>{"compared_corners", "corners_beyond_radius", "faces", "file",
                                      "identical_beyond_radius_ratio", "identical_ratio", "locality_radius",
                                      "max_difference_px", "mean_difference_px", "order_identical_ratio", "patches_cut",
                                      "patches_full", "removed_faces", "seconds", "within_1px_ratio"}));
}

TEST(Report, EvalSummaryCountsInTheSingularForOne) {
  EvalRun run;
  run.file = "one.obj";
  run.metrics.faces = 1;
  run.metrics.patches = 1;
  run.metrics.seam_edges = 1;
  run.metrics.visible_dangling_ends = 1;
  run.metrics.visible_branch_points = 1;
  std::string text = eval_summary(run);
  EXPECT_EQ(text.find("one.obj: 1 face, 1 patch (0 single-face)"), 0u) << text;
  EXPECT_NE(text.find("(1 edge)"), std::string::npos) << text;
  EXPECT_NE(text.find("1 dangling end, 1 branch point)"), std::string::npos) << text;
  run.metrics.faces = 2;
  run.metrics.patches = 0;
  run.metrics.seam_edges = 2;
  text = eval_summary(run);
  EXPECT_EQ(text.find("one.obj: 2 faces, 0 patches"), 0u) << text;
  EXPECT_NE(text.find("(2 edges)"), std::string::npos) << text;
  StabilityReport r;
  r.faces = 1;
  r.corners_beyond_radius = 1;
  r.identical_beyond_radius_ratio = 1;
  text = stability_summary("one.obj", r);
  EXPECT_NE(text.find("removed 0 of 1 face,"), std::string::npos) << text;
  EXPECT_NE(text.find("of the 1 surviving corner farther than"), std::string::npos) << text;
  EXPECT_NE(text.find("from the cut is bit-identical"), std::string::npos) << text;
}

TEST(Report, TileReportsTheWorstVariant) {
  TileRun run;
  run.input = "in.png";
  run.output = "out_{0..1}.png";
  run.variants = 2;
  run.tiles.resize(2);
  run.tiles[0].file = "dir/out_0.png";
  run.tiles[1].file = "dir/out_1.png";
  run.tiles[0].metrics.wrap_ratio_x = 1.1;
  run.tiles[1].metrics.wrap_ratio_x = 0.7;
  run.tiles[0].metrics.gradient_ratio = 0.99;
  run.tiles[1].metrics.gradient_ratio = 1.02;
  run.tiles[1].metrics.has_exemplar = true;
  run.tiles[1].targets_failed = "wrap ratio x outside [0.8, 1.2]";
  const TileMetrics worst = worst_tile_metrics(run.tiles);
  EXPECT_DOUBLE_EQ(worst.wrap_ratio_x, 0.7);
  EXPECT_DOUBLE_EQ(worst.gradient_ratio, 0.99);
  run.worst.metrics = worst;
  run.worst.targets_failed = "wrap ratio x outside [0.8, 1.2]";
  EXPECT_NE(tile_summary(run).find("-> out_{0..1}.png 0x0: wrap 0.70 x"), std::string::npos);
  EXPECT_NE(tile_summary(run).find(", targets NOT met: wrap ratio x outside [0.8, 1.2], 0.00 s\n"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(tile_report_json(run));
  EXPECT_EQ(j["tiles"][0]["file"], "dir/out_0.png");
  EXPECT_FALSE(j["tiles"][0].contains("histogram_l1"));  // no exemplar
  EXPECT_TRUE(j["tiles"][1].contains("histogram_l1"));
  EXPECT_EQ(j["tiles"][1]["targets_failed"], "wrap ratio x outside [0.8, 1.2]");
  EXPECT_FALSE(j.contains("period"));  // only with fit_period
  const nlohmann::json v = nlohmann::json::parse(tile_variants_json(run));
  EXPECT_EQ(v["files"], nlohmann::json::array({"out_0.png", "out_1.png"}));  // beside the JSON
  EXPECT_EQ(v["count"], 2);
  const nlohmann::json e = nlohmann::json::parse(eval_tile_report_json(run.tiles[0], 64, 32, ""));
  EXPECT_EQ(e["width"], 64);
  EXPECT_FALSE(e.contains("exemplar"));
}

}  // namespace
}  // namespace tailor
