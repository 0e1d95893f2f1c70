// The option checks and the texture-size settings `tailor map` applies before map_texture, shared
// with the Python module so both refuse the same options with the same message.
#include <cstdio>
#include <string>
#include <string_view>

#include "tailor/mapping.h"

namespace tailor {
namespace {
Status usage_error(const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); }
}  // namespace

std::string limit_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  std::string s = text;
  if (const size_t e = s.find("e+"); e != std::string::npos) {
    size_t digits = e + 2;
    while (digits + 1 < s.size() && s[digits] == '0') ++digits;
    s = s.substr(0, e + 1) + s.substr(digits);
  }
  return s;
}

Status check_map_options(const MapTextureOptions& options) {
  using L = MappingLimits;
  const MappingOptions& mapping = options.mapping;
  if (mapping.symmetry == 4 && mapping.mode != MappingMode::kPatches)
    return usage_error("--symmetry 4 needs --mode patches");
  if (!(mapping.scale >= L::min_scale && mapping.scale <= L::max_scale))
    return usage_error("--scale must be between " + limit_text(L::min_scale) + " and " + limit_text(L::max_scale) +
                       " pixels per unit");
  if (!(mapping.hop_age >= 0.f && mapping.hop_age <= L::max_hop_age))
    return usage_error("--hop-age must be between 0 and " + limit_text(L::max_hop_age) + " radians");
  if (options.chunks.split_above != 0 && options.chunks.split_above < 64)
    return usage_error("--chunk-split must be 0 (never cut) or at least 64 faces");
  return Status::ok();
}

Status check_mode_options(MappingMode mode, std::string_view patches_only, bool threshold_given) {
  if (mode == MappingMode::kThesis && !patches_only.empty())
    return usage_error(std::string(patches_only) +
                       " has no effect with --mode thesis (one UV per vertex, placed by --threshold; no seam work)");
  if (mode != MappingMode::kThesis && threshold_given)
    return usage_error("--threshold is read by --mode thesis only (--mode patches bounds its faces by --max-stretch)");
  return Status::ok();
}

Status check_texture_size(int texture_size) {
  if (texture_size <= 0) return usage_error("--texture-size must be positive");
  if (texture_size > kMaxTextureSize)
    return usage_error("--texture-size must be at most 65536 (what tailor eval reads), got " +
                       std::to_string(texture_size));
  return Status::ok();
}

Status set_map_texture_size(MapTextureOptions& options, int texture_width, int texture_height) {
  if (texture_width <= 0 || texture_height <= 0) return usage_error("--texture-size must be positive");
  MappingOptions& mapping = options.mapping;
  // Symmetry 4: the lattice is the texture's square period; the metrics count quarter turns as invisible.
  if (mapping.symmetry == 4 && texture_width != texture_height)
    return usage_error("--symmetry 4 needs a square texture, got " + std::to_string(texture_width) + "x" +
                       std::to_string(texture_height));
  mapping.texture_period_px = static_cast<float>(texture_width);
  mapping.texture_period_v_px = static_cast<float>(texture_height);
  options.metrics.symmetry = mapping.symmetry;
  options.metrics.texture_width_px = static_cast<float>(texture_width);
  options.metrics.texture_height_px = static_cast<float>(texture_height);
  // --threads is one count for every stage that has threads.
  options.orientation.threads = options.metrics.threads = mapping.threads;
  return Status::ok();
}

}  // namespace tailor
