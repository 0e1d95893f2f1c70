// tailor: the result of texture mapping, shared by mapping, metrics, export and rendering.
//
// UVs live per corner (corner c = 3f + k), so a vertex may carry different UVs in different
// patches and seams are real cuts. UVs are in texture pixels: the mapping works at a fixed scale
// (--scale pixels per unit of the mesh normalised into the unit cube) and export divides by the
// texture size to get glTF/OBJ coordinates in texture repeats.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tailor {

struct Atlas {
  std::vector<float> corner_uv;  //!< #F*3 by 2: u, v of each corner, in texture pixels
  std::vector<uint32_t> patch;   //!< #F: patch id of each face (0-based, dense)
  uint32_t patch_count = 0;

  size_t face_count() const { return patch.size(); }
};

}  // namespace tailor
