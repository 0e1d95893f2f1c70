// map_warnings: the checks `tailor map` and tailor.map make before mapping.
#include "tailor/map_warnings.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "tailor/tiling.h"
#include "util/shell_word.h"

namespace tailor {

double map_repeats(const Mesh& mesh, const MapTextureOptions& options) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    for (size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * v + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * v + k]);
    }
  const double longest = std::max({double{hi[0]} - lo[0], double{hi[1]} - lo[1], double{hi[2]} - lo[2]});
  // In the mapping's units: the unit cube, or the fixed normalisation's.
  const double extent =
      options.orientation.fixed_unit_scale > 0.f ? longest * options.orientation.fixed_unit_scale : 1.0;
  return options.mapping.scale * extent / options.mapping.texture_period_px;
}

namespace {

// The median length of the nonzero edges of up to 65,536 faces spread over the mesh (0: none).
double sampled_median_edge(const Mesh& mesh) {
  const size_t faces = mesh.face_count();
  const size_t stride = std::max<size_t>(1, faces / 65536);
  std::vector<double> lengths;
  lengths.reserve(3 * std::min<size_t>(faces, 65536 + 1));
  for (size_t f = 0; f < faces; f += stride)
    for (size_t k = 0; k < 3; ++k) {
      const float* a = &mesh.positions[3 * size_t{mesh.indices[3 * f + k]}];
      const float* b = &mesh.positions[3 * size_t{mesh.indices[3 * f + (k + 1) % 3]}];
      const double dx = double{a[0]} - b[0], dy = double{a[1]} - b[1], dz = double{a[2]} - b[2];
      const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
      if (length > 0.0) lengths.push_back(length);
    }
  if (lengths.empty()) return 0.0;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  return lengths[lengths.size() / 2];
}

}  // namespace

std::string far_from_origin_warning(const Mesh& mesh) {
  float largest = 0.f;
  for (const float x : mesh.positions) largest = std::max(largest, std::fabs(x));
  return far_from_origin_warning(largest, sampled_median_edge(mesh));
}

std::string far_from_origin_warning(double largest, double median) {
  if (!(largest > 0.0) || !std::isfinite(largest) || !(median > 0.0) || !std::isfinite(median)) return {};
  // Floats in [2^e, 2^(e+1)) are 2^(e-23) apart: the step every coordinate there was rounded to.
  const double step = std::ldexp(1.0, std::ilogb(static_cast<float>(largest)) - 23);
  if (step <= kFarFromOriginStep * median) return {};
  const double ratio = step / median;
  char share[64];
  if (ratio < 1.0)
    std::snprintf(share, sizeof share, "%.0f %% of", 100.0 * ratio);
  else
    std::snprintf(share, sizeof share, "%.3g times", ratio);
  char line[480];
  std::snprintf(line, sizeof line,
                "positions reach %.3g units from the origin, where 32-bit floats are %.3g apart (%s the median "
                "edge, %.3g): the shape is rounded to that step and the map follows it; give the mesh in a frame "
                "near its own centre (a local origin, as scanning tools export with a coordinate offset)",
                static_cast<double>(largest), step, share, median);
  return line;
}

std::string texture_wrap_warning(const Image& texture, const std::string& texture_name) {
  // A texture whose wrap is a cut (eval-tile's wrap ratio above its target): every repeat shows it.
  double wrap_x = 0.0, wrap_y = 0.0;
  if (texture.empty() || !wrap_ratios(texture, wrap_x, wrap_y).is_ok() ||
      (wrap_x <= kWrapRatioSeamless && wrap_y <= kWrapRatioSeamless))
    return {};
  const std::filesystem::path name = std::filesystem::path(texture_name).lexically_normal();
  std::string tile = name.stem().string() + "_tile.png";
  tile = name.has_parent_path() ? (name.parent_path() / tile).string() : tile;
  char figures[160];
  std::snprintf(figures, sizeof figures, " does not wrap (wrap ratio %.2f in x, %.2f in y; seamless is 0.8-1.2)",
                wrap_x, wrap_y);
  return texture_name + figures + ": every repeat shows a cut; make it tileable with: tailor tile " +
         internal::shell_path(name.string()) + " -o " + internal::shell_path(tile);
}

std::vector<std::string> map_warnings(const Mesh& mesh, const MapTextureOptions& options, const Image& texture,
                                      const std::string& texture_name) {
  std::vector<std::string> warnings;
  if (std::string far = far_from_origin_warning(mesh); !far.empty()) warnings.push_back(std::move(far));
  const MappingOptions& mapping = options.mapping;
  if (std::string wrap = texture_wrap_warning(texture, texture_name); !wrap.empty())
    warnings.push_back(std::move(wrap));
  // The texture repeats less than once across the mesh's longest side: part of the picture is
  // never seen, and with symmetry 4 quarter-turn seams land on the lattice less often.
  const double repeats = map_repeats(mesh, options);
  if (mapping.symmetry != 4) {
    if (std::isfinite(repeats) && repeats > 0.0 && repeats < 1.0) {
      char line[320];
      std::snprintf(line, sizeof line,
                    "the %.0f px texture repeats %.2f times across the mesh: part of it is never seen (a larger "
                    "--scale, or a smaller --tile-size, repeats it more)",
                    static_cast<double>(mapping.texture_period_px), repeats);
      warnings.emplace_back(line);
    }
    return warnings;
  }
  // The map turns the tile about lattice points: a tile unchanged only about another point (or
  // none) shows its quarter-turn seams.
  if (!texture.empty()) {
    int shift_x = 0, shift_y = 0;
    const int difference = quarter_turn_difference(texture, &shift_x, &shift_y);
    if (difference > kQuarterTurnNoiseLevels)
      warnings.push_back(texture_name + ": --symmetry 4 but the texture is not unchanged by a quarter turn (up to " +
                         std::to_string(difference) +
                         " levels apart): seams that turn will show; make it with 'tailor tile --symmetry 4'");
    else if (shift_x != 0 || shift_y != 0)
      warnings.push_back(texture_name +
                         ": --symmetry 4 but the texture turns into itself about a point off its centre and corner "
                         "(a tile from tailor before 2026-11-26?): seams that turn will jump by half a repeat; "
                         "make it again with 'tailor tile --symmetry 4'");
  }
  // Cones go to lattice points, so the 4-fold seams land on the lattice less often the fewer
  // lattice points the mesh spans (docs/mapping.md: 3.5 % visible seams at 0.8 repeats across the
  // mesh, 2.9 % at 1.6, 1.5 % at 16).
  if (std::isfinite(repeats) && repeats > 0.0 && repeats < 1.0) {
    char line[320];
    std::snprintf(line, sizeof line,
                  "--symmetry 4: the %.0f px texture repeats %.2f times across the mesh; quarter-turn seams land on "
                  "the lattice less often the fewer the repeats (a larger --scale, or a tile made with 'tailor tile "
                  "--symmetry 4 --same-size', repeats more)",
                  static_cast<double>(mapping.texture_period_px), repeats);
    warnings.emplace_back(line);
  }
  return warnings;
}

}  // namespace tailor
