// tailor: the reports of the tailor commands, built once here from the library's result structs:
// the JSON of `tailor map --stats`, `tailor eval --json`, `tailor tile --json` (and the variants'
// NAME.json, `tailor eval-tile --json`), and the summary lines that map, eval and tile print. The
// CLI only writes the text; a Python module or a Blender add-on can show the same figures.
//
// Nothing here prints or writes a file: every function returns text ending in a newline. JSON
// objects are indented by 2 with their keys sorted; bytes of strings that are not UTF-8 (file
// names can hold any) become U+FFFD, so building a report never fails. Timings are the only values
// that differ between two runs with the same inputs.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tailor/api.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/metrics.h"
#include "tailor/stability.h"
#include "tailor/tiling.h"
#include "tailor/topology.h"

namespace tailor {

// === tailor map ==================================================================================

//! One run of `tailor map`: what was asked, what each stage found, how long each took.
struct MapRun {
  // What was asked
  std::string input;      //!< mesh file
  std::string output;     //!< mesh file written
  std::string texture;    //!< texture file, empty when none
  int texture_width = 0;  //!< texture size the UVs are in (px per repeat)
  int texture_height = 0;
  float texture_isotropy = -1.f;  //!< texture_isotropy of the texture when measured (--field-following auto), else -1
  bool field_following_auto = false;  //!< --field-following auto: options.mapping holds what it chose
  MapTextureOptions options;          //!< as map_texture ran them (after --axis auto: the chosen axis)
  std::string axis;                   //!< the axis as asked ("pca", "x", "0,1,0"...), or "auto:<chosen>"
  bool axis_auto = false;             //!< the axis was chosen by choose_orientation_axis (--axis auto)
  std::string seed_point;             //!< the seed point as asked ("X,Y,Z"), empty when none
  std::string seam_faces;             //!< seam-face file, empty when none
  double texels_per_unit = 0;         //!< > 0: world units (--tile-size, --texels-per-unit), texture pixels per scene
                               //!< unit; 0: options.mapping.scale is per unit of the mesh normalised into the unit cube
  std::string up = "y";  //!< the input's up axis (--up); a .glb output is turned Y-up
  // What the stages found (add_map_results fills these from the library's results)
  LoadReport load;  //!< what the reader saw and repaired, its time
  size_t vertices = 0;
  size_t faces = 0;
  double longest_side = 0;  //!< longest side of the mesh's bounding box, mesh (world) units
  uint32_t components = 0;  //!< Topology::vertex_components
  size_t boundary_edges = 0;
  size_t nonmanifold_edges = 0;
  size_t inconsistent_edges = 0;
  MappingStats mapping;                      //!< map_texture's counters and time
  UvMetrics metrics;                         //!< map_texture's metrics and time
  std::optional<StabilityReport> stability;  //!< measure_stability, when it ran (--stability)
  std::vector<std::string> previews;         //!< preview pictures written
  // Wall times of the other steps, seconds
  double topology_seconds = 0;
  double axis_choice_seconds = 0;
  double orientation_seconds = 0;
  double turning_seconds = 0;  //!< faces wound against their neighbours turned, and a mapping before it
                               //!< that found them (then done again), topology included
  double export_seconds = 0;
  double preview_seconds = 0;
  double total_seconds = 0;  //!< the whole command
  // The process's peak resident memory (`tailor map`: getrusage at the end), 0 = not measured: then
  // neither the JSON (`peak_resident_mib`) nor the summary says it.
  size_t peak_resident_bytes = 0;
};

//! The texture repeats across the longest side of the mesh's bounding box as mapped, from the
//! texel density the map used: per world unit when it was chunked (MappingStats::texels_per_unit)
//! or normalised by orientation.fixed_unit_scale (--tile-size, --texels-per-unit), else
//! options.mapping.scale across the mesh; in texture periods (options.mapping.texture_period_px).
//! 0 when unknown (no faces, no period).
TAILOR_API double map_repeats_across(const MapRun& run);

//! Fills the fields of `run` that come from the loaded mesh, its topology and map_texture's result.
TAILOR_API void add_map_results(const Mesh& mesh, const LoadReport& load, const Topology& topology,
                                const TextureMap& map, MapRun& run);

//! The JSON report of `tailor map --stats`: input, output, texture, texture_size, options, mesh,
//! mapping (MappingStats), metrics (UvMetrics), stability (when run), time_ms, previews.
TAILOR_API std::string map_report_json(const MapRun& run);

//! What `tailor map` prints: one line (faces, patches, seams, flipped, stretch, L2/Linf, angle
//! distortion, seam gap, the time of each stage, the output), and a second one on the stability.
TAILOR_API std::string map_summary(const MapRun& run);

// === tailor eval =================================================================================

//! One run of `tailor eval` on a UV-mapped mesh.
struct EvalRun {
  std::string file;    //!< mesh file
  std::string format;  //!< LoadReport::format
  size_t vertices = 0;
  size_t welded_vertices = 0;  //!< vertices merged to find the seams again (split files)
  int texture_width = 0;       //!< texture size the UVs were measured in (px per repeat)
  int texture_height = 0;
  std::string texture_size_from;  //!< "option", "embedded texture" or "default"
  uint32_t symmetry = 1;          //!< MetricsOptions::symmetry the metrics were measured with
  UvMetrics metrics;
  size_t boundary_edges = 0;     //!< Topology::boundary_edges
  size_t nonmanifold_edges = 0;  //!< Topology::nonmanifold_edges
  double seconds = 0;            //!< the whole command
};

//! The JSON of `tailor eval --json`: the metrics flat, with the file, sizes and edge counts.
TAILOR_API std::string eval_report_json(const EvalRun& run);

//! The line `tailor eval` prints.
TAILOR_API std::string eval_summary(const EvalRun& run);

//! The JSON of `tailor eval --stability --json`: the StabilityReport of `file`.
TAILOR_API std::string stability_report_json(const std::string& file, const StabilityReport& report);

//! The line `tailor eval --stability` prints.
TAILOR_API std::string stability_summary(const std::string& file, const StabilityReport& report);

// === tailor tile, tailor eval-tile ================================================================

//! A tile and its quality, with the verdict of meets_tile_targets (the caller's: it is part of
//! tailor::texture, which this module does not link).
struct TileQuality {
  std::string file;            //!< the tile's file
  TileMetrics metrics;         //!< tile_metrics, with the exemplar when there is one
  bool targets_met = false;    //!< meets_tile_targets(metrics)
  std::string targets_failed;  //!< the targets it misses, empty when met
};

//! One run of `tailor tile`.
struct TileRun {
  std::string input;  //!< exemplar file
  int input_width = 0;
  int input_height = 0;
  int input_channels = 0;
  std::string output;              //!< the output as the summary names it: the file, or NAME_{0..k}.png
  TileOptions options;             //!< as asked (seed, fit_period; block and overlap as used are in `report`)
  int variants = 1;                //!< tiles made (make_tile_variants' count)
  TileReport report;               //!< make_tile_variants' report
  double seconds = 0;              //!< time of make_tile_variants
  std::vector<TileQuality> tiles;  //!< one per variant (file always; metrics when measured)
  TileQuality worst;               //!< worst_tile_metrics over the tiles, with its own verdict (no file)
};

//! Each metric's worst value over the tiles: wrap ratios farthest from 1, the largest worst seam,
//! histogram L1 and patch coherence, the smallest gradient ratio; the other fields from the first
//! tile. Precondition: at least one tile.
TAILOR_API TileMetrics worst_tile_metrics(std::span<const TileQuality> tiles);

//! The JSON of `tailor tile --json`: the settings, the report, each tile's metrics and verdict,
//! targets_met of the worst.
TAILOR_API std::string tile_report_json(const TileRun& run);

//! The NAME.json written next to the variants of `tailor tile --variants N`: their shared size and
//! settings, and their file names (relative: the JSON sits beside them).
TAILOR_API std::string tile_variants_json(const TileRun& run);

//! The line `tailor tile` prints (the worst tile's metrics and verdict).
TAILOR_API std::string tile_summary(const TileRun& run);

//! The JSON of `tailor eval-tile --json`: `tile`'s metrics and verdict, its size, and the exemplar
//! (empty when there is none).
TAILOR_API std::string eval_tile_report_json(const TileQuality& tile, int width, int height,
                                             const std::string& exemplar);

}  // namespace tailor
