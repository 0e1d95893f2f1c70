// map_warnings: the symmetry-4 checks `tailor map` and tailor.map make before mapping.
#include "tailor/map_warnings.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tailor/tiling.h"

namespace tailor {

std::vector<std::string> map_warnings(const Mesh& mesh, const MapTextureOptions& options, const Image& texture,
                                      const std::string& texture_name) {
  std::vector<std::string> warnings;
  const MappingOptions& mapping = options.mapping;
  if (mapping.symmetry != 4) return warnings;
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
  const double repeats = mapping.scale * extent / mapping.texture_period_px;
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
