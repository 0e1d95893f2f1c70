// Orientation strokes as JSON (tailor map --strokes FILE, the edit API's "strokes" key):
// {"strokes": [{"points": [[x, y, z], ...], "radius": r}, ...]}.
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "io/strokes_json.h"
#include "tailor/io.h"
#include "util/atomic_file.h"
#include "util/bounded_json.h"
#include "util/text_scan.h"

namespace tailor {
namespace internal {

Status strokes_from_json(const nlohmann::json& array, const std::string& name, std::vector<OrientationStroke>& out) {
  out.clear();
  auto fail = [&](const std::string& what, const std::string& where) {
    out.clear();
    return Status::error(ErrorCode::kParse, name, what, where);
  };
  if (!array.is_array()) return fail("\"strokes\" must be an array", "strokes");
  // A number that fits a float and is finite.
  auto finite_float = [](const nlohmann::json& v, float& x) {
    if (!v.is_number()) return false;
    const double d = v.get<double>();
    if (!std::isfinite(d) || std::abs(d) > std::numeric_limits<float>::max()) return false;
    x = static_cast<float>(d);
    return true;
  };
  out.reserve(array.size());
  for (size_t i = 0; i < array.size(); ++i) {
    const std::string where = "strokes[" + std::to_string(i) + "]";
    const nlohmann::json& s = array[i];
    if (!s.is_object()) return fail("a stroke must be an object with \"points\" and \"radius\"", where);
    for (const auto& item : s.items())
      if (item.key() != "points" && item.key() != "radius")
        return fail("unknown key " + quote_input(item.key()), where);
    const auto points = s.find("points");
    if (points == s.end() || !points->is_array()) return fail("\"points\" must be an array of [x, y, z]", where);
    if (points->size() < 2) return fail("a stroke needs at least 2 points", where + ".points");
    OrientationStroke stroke;
    stroke.points.reserve(3 * points->size());
    for (size_t k = 0; k < points->size(); ++k) {
      const nlohmann::json& p = (*points)[k];
      float x[3];
      if (!p.is_array() || p.size() != 3 || !finite_float(p[0], x[0]) || !finite_float(p[1], x[1]) ||
          !finite_float(p[2], x[2]))
        return fail("a point must be three finite numbers [x, y, z] within 32-bit floats (3.4e38)",
                    where + ".points[" + std::to_string(k) + "]");
      stroke.points.insert(stroke.points.end(), x, x + 3);
    }
    const auto radius = s.find("radius");
    if (radius == s.end() || !finite_float(*radius, stroke.radius) || !(radius->get<double>() > 0))
      return fail("\"radius\" must be a number > 0 within 32-bit floats (3.4e38)", where + ".radius");
    if (!(stroke.radius >= std::numeric_limits<float>::min()))  // 1e-300 would be 0 as a float
      return fail("\"radius\" must be at least 1.2e-38 (the smallest normal 32-bit float)", where + ".radius");
    out.push_back(std::move(stroke));
  }
  return Status::ok();
}

}  // namespace internal

Status parse_strokes(std::string_view text, const std::string& name, std::vector<OrientationStroke>& strokes) {
  strokes.clear();
  if (internal::json_nests_deeper_than(text, internal::kMaxJsonDepth))
    return Status::error(ErrorCode::kParse, name, internal::json_problem(internal::JsonParse::kTooDeep));
  nlohmann::json document;
  try {  // with exceptions: they say where it fails
    document = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    return Status::error(ErrorCode::kParse, name, "not valid JSON", "byte " + std::to_string(e.byte));
  } catch (const nlohmann::json::exception&) {  // a number out of range (1e400)
    return Status::error(ErrorCode::kParse, name, "not valid JSON (a number out of range)");
  }
  if (!document.is_object() || !document.contains("strokes"))
    return Status::error(ErrorCode::kParse, name, "expected an object {\"strokes\": [...]}", "top level");
  return internal::strokes_from_json(document["strokes"], name, strokes);
}

Status load_strokes(const std::string& path, std::vector<OrientationStroke>& strokes) {
  strokes.clear();
  std::string text;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, text));
  return parse_strokes(text, path, strokes);
}

std::string strokes_json(std::span<const OrientationStroke> strokes) {
  nlohmann::json array = nlohmann::json::array();
  for (const OrientationStroke& s : strokes) {
    nlohmann::json points = nlohmann::json::array();
    for (size_t k = 0; k + 2 < s.points.size(); k += 3)
      points.push_back({s.points[k], s.points[k + 1], s.points[k + 2]});
    array.push_back({{"points", std::move(points)}, {"radius", s.radius}});
  }
  return nlohmann::json{{"strokes", std::move(array)}}.dump() + "\n";
}

}  // namespace tailor
