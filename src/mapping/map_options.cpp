// The option checks and the texture-size settings `tailor map` applies before map_texture, shared
// with the Python module so both refuse the same options with the same message.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <string_view>

#include "tailor/mapping.h"

namespace tailor {
namespace {
Status usage_error(const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); }

// An option MappingLimits or OrientationLimits bounds: its flag, its range and the range's unit.
struct LimitedOption {
  std::string_view flag;
  double low, high;
  std::string_view unit;
};
using L = MappingLimits;
constexpr LimitedOption kLimitedOptions[] = {
    {"--scale", L::min_scale, L::max_scale, " pixels per unit"},
    {"--max-stretch", L::min_max_stretch, L::max_max_stretch, ""},
    {"--hop-age", 0., L::max_hop_age, " radians"},
    {"--crack-rings", L::min_crack_rings, L::max_crack_rings, " rings"},
    {"--relax-iterations", 0., L::max_relax_iterations, " iterations"},
    {"--smooth", 0., OrientationLimits::max_smooth_passes, " passes"},
};

// A value as a message shows it: a whole number in full (4000000000, not 4e9), a float in the
// fewest digits that read back as it (0.0009999, not 0.000999900047), else as a limit is written.
std::string value_text(double value) {
  char digits[64];
  if (value == std::trunc(value) && std::abs(value) < 0x1p53) {
    std::snprintf(digits, sizeof digits, "%.0f", value);
    return digits;
  }
  const float single = static_cast<float>(value);
  if (std::abs(value) <= std::numeric_limits<float>::max() && static_cast<double>(single) == value) {
    const auto end = std::to_chars(digits, digits + sizeof digits, single).ptr;
    return std::string(digits, end);
  }
  return limit_text(value);
}
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

std::string option_range_text(std::string_view flag) {
  for (const LimitedOption& option : kLimitedOptions)
    if (option.flag == flag)
      return limit_text(option.low) + " to " + limit_text(option.high) + std::string(option.unit);
  return {};
}

std::string help_with_range(const OptionDoc& doc) {
  const std::string range = option_range_text(doc.flag);
  return range.empty() ? std::string(doc.help) : std::string(doc.help) + " (" + range + ")";
}

Status check_option_range(std::string_view flag, double value) {
  for (const LimitedOption& option : kLimitedOptions) {
    if (option.flag != flag) continue;
    if (value >= option.low && value <= option.high) return Status::ok();  // NaN is outside
    return usage_error(std::string(flag) + " must be between " + limit_text(option.low) + " and " +
                       limit_text(option.high) + std::string(option.unit) + ", got " + value_text(value));
  }
  // A misspelt flag in a caller's list would turn its check off without this.
  return usage_error("no range is known for " + std::string(flag));
}

Status check_map_options(const MapTextureOptions& options) {
  const MappingOptions& mapping = options.mapping;
  if (mapping.symmetry == 4 && mapping.mode != MappingMode::kPatches)
    return usage_error("--symmetry 4 needs --mode patches");
  // Every bounded number, before any work (map_texture checks them again, for callers that skip this).
  for (const auto& [flag, value] : {std::pair<std::string_view, double>{"--scale", mapping.scale},
                                    {"--max-stretch", mapping.max_stretch},
                                    {"--hop-age", mapping.hop_age},
                                    {"--crack-rings", mapping.crack_rings},
                                    {"--relax-iterations", mapping.relax_iterations},
                                    {"--smooth", options.orientation.smooth_passes}})
    if (Status s = check_option_range(flag, value); !s) return s;
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
