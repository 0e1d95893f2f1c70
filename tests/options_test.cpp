// One place for options (tailor/option_doc.h): every option of the library's tables reaches the
// CLI's --help with the table's text, and the defaults shown are the option structs' own.
#include <gtest/gtest.h>

#include <cstdio>
#include <span>
#include <sstream>
#include <string>

#include "tailor/export.h"
#include "tailor/mapping.h"
#include "tailor/metrics.h"
#include "tailor/orientation.h"
#include "tailor/render.h"
#include "tailor/stability.h"
#include "tailor/tiling.h"

namespace tailor {
namespace {

std::string help_of(const std::string& command) {
  std::string text;
  FILE* pipe = popen((std::string(TAILOR_BINARY) + " " + command + " --help").c_str(), "r");
  if (!pipe) return text;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) text.append(buffer, n);
  pclose(pipe);
  return text;
}

// Whether `help` shows `prefix` followed by the default `value` as CLI11 does ("=" and the streamed
// value, capture_default_str), then `suffix`.
template <class T>
bool shows(const std::string& help, const std::string& prefix, const T& value, const std::string& suffix = "") {
  std::ostringstream needle;
  needle << prefix << '=' << value << suffix;
  return help.find(needle.str()) != std::string::npos;
}

void expect_documented(const std::string& help, std::span<const OptionDoc> docs, const std::string& command) {
  for (const OptionDoc& doc : docs) {
    EXPECT_NE(help.find(std::string(doc.help)), std::string::npos) << command << ": " << doc.field;
    if (doc.flag != "--up") {  // tailor map names it --preview-up
      EXPECT_NE(help.find(std::string(doc.flag)), std::string::npos) << command << ": " << doc.flag;
    }
  }
}

TEST(Options, TheTablesNameEachFieldOnce) {
  for (const std::span<const OptionDoc> docs :
       {std::span<const OptionDoc>(kMappingOptionDocs), std::span<const OptionDoc>(kOrientationOptionDocs),
        std::span<const OptionDoc>(kStabilityOptionDocs), std::span<const OptionDoc>(kTileOptionDocs),
        std::span<const OptionDoc>(kRenderOptionDocs), std::span<const OptionDoc>(kMetricsOptionDocs),
        std::span<const OptionDoc>(kExportOptionDocs)}) {
    for (size_t i = 0; i < docs.size(); ++i) {
      EXPECT_FALSE(docs[i].help.empty()) << docs[i].field;
      EXPECT_EQ(docs[i].flag.substr(0, 2), "--") << docs[i].field;
      for (size_t j = 0; j < i; ++j) EXPECT_NE(docs[i].field, docs[j].field);
    }
  }
  static_assert(option_doc(kMappingOptionDocs, "crack_rings").flag == "--crack-rings");
}

TEST(Options, MapHelpShowsTheTablesAndTheStructsDefaults) {
  const std::string help = help_of("map");
  expect_documented(help, kMappingOptionDocs, "map");
  expect_documented(help, kOrientationOptionDocs, "map");
  expect_documented(help, kExportOptionDocs, "map");
  EXPECT_TRUE(shows(help, "--compress TEXT", mesh_compression_name(ExportOptions{}.compression)));
  EXPECT_NE(help.find(std::string(option_doc(kRenderOptionDocs, "up").help)), std::string::npos);
  const MappingOptions m;
  EXPECT_TRUE(shows(help, "--mode TEXT", mapping_mode_name(m.mode)));
  EXPECT_TRUE(shows(help, "--scale FLOAT", m.scale));
  EXPECT_TRUE(shows(help, "--max-stretch FLOAT", m.max_stretch));
  EXPECT_TRUE(shows(help, "--hop-age FLOAT", m.hop_age));
  EXPECT_TRUE(shows(help, "--min-patch-faces UINT", m.min_patch_faces));
  EXPECT_TRUE(shows(help, "--crack-rings UINT", m.crack_rings));
  EXPECT_TRUE(shows(help, "--threshold FLOAT", m.threshold_px));
  EXPECT_TRUE(shows(help, "--symmetry UINT:{1,4}", m.symmetry));
  EXPECT_TRUE(shows(help, "--smooth UINT", OrientationOptions{}.smooth_passes));
  EXPECT_TRUE(shows(help, "--preview-up TEXT", up_axis_name(RenderOptions{}.up)));
}

TEST(Options, TileRenderAndEvalHelpShowTheTablesAndTheStructsDefaults) {
  const std::string tile = help_of("tile");
  expect_documented(tile, kTileOptionDocs, "tile");
  EXPECT_TRUE(shows(tile, "]", TileOptions{}.block));
  EXPECT_TRUE(shows(tile, "--seed UINT", TileOptions{}.seed));
  const std::string render = help_of("render");
  expect_documented(render, kRenderOptionDocs, "render");
  const RenderOptions r;
  EXPECT_TRUE(shows(render, "--yaw FLOAT", r.yaw_degrees));
  EXPECT_TRUE(shows(render, "--size TEXT", std::to_string(r.width) + 'x' + std::to_string(r.height)));
  EXPECT_TRUE(shows(render, "}", preview_view_name(r.view)));
  const std::string eval = help_of("eval");
  expect_documented(eval, kStabilityOptionDocs, "eval");
  expect_documented(eval, kMetricsOptionDocs, "eval");
  EXPECT_TRUE(shows(eval, "--symmetry UINT:{1,4}", MetricsOptions{}.symmetry));
  EXPECT_TRUE(shows(eval, "]", StabilityOptions{}.remove_fraction));
}

}  // namespace
}  // namespace tailor
