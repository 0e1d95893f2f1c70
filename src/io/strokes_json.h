// The "strokes" array of the strokes JSON (read_strokes.cpp), for callers that have parsed a
// larger document themselves (the edit server's POST /api/edit).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tailor/orientation.h"
#include "tailor/status.h"

namespace tailor::internal {

//! Reads [{"points": [[x, y, z], ...], "radius": r}, ...] into `strokes`: kParse naming `name` and
//! where (strokes[i].points[k], ...) on a wrong type, an unknown key, fewer than 2 points, a
//! coordinate that is not a finite float, a radius not > 0. `strokes` is empty after a failure.
Status strokes_from_json(const nlohmann::json& array, const std::string& name, std::vector<OrientationStroke>& strokes);

}  // namespace tailor::internal
