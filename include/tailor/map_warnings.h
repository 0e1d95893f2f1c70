// What a user should hear before a map runs under a texture, shared by `tailor map`, the Python
// module (as UserWarning) and through it the Blender add-on, so all three say the same.
#pragma once

#include <string>
#include <vector>

#include "tailor/api.h"
#include "tailor/image.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"

namespace tailor {

//! How many times the texture repeats across the longest side of `mesh`'s bounding box when mapped
//! with `options` (complete, as for map_warnings): options.mapping.scale over the texture period,
//! in the units of the normalisation (the unit cube, or orientation.fixed_unit_scale's). A chunked
//! map without a fixed normalisation rounds the density to a power of two (within a factor of
//! sqrt(2) of this); MapRun's summary states the figure the map used. O(V).
TAILOR_API double map_repeats(const Mesh& mesh, const MapTextureOptions& options);

//! Coordinates above this share of the median edge apart (the float32 step at the largest |x|)
//! make far_from_origin_warning speak: at 1 % a face's normal already tilts by about half a degree.
constexpr double kFarFromOriginStep = 0.01;

//! The sentence about positions so far from the origin, against the size of the mesh's edges (the
//! median of a sample of up to 65,536 faces), that 32-bit floats round its shape by more than
//! kFarFromOriginStep of an edge: georeferenced scans (UTM or ECEF coordinates, a glTF node's
//! large translation applied on loading). Empty when the floats keep the shape. O(V).
TAILOR_API std::string far_from_origin_warning(const Mesh& mesh);
//! The same from the largest |coordinate| and the median edge length (tailor.tiles' survey of a
//! streamed file). Empty when either is not positive and finite.
TAILOR_API std::string far_from_origin_warning(double largest_coordinate, double median_edge);

//! The sentence about a texture whose wrap is a cut (a wrap ratio, eval-tile's measure, above
//! kWrapRatioSeamless: every repeat shows it), starting with texture_name and naming the `tailor
//! tile` command that fixes it; empty when it wraps or `texture` is empty. O(texture pixels).
TAILOR_API std::string texture_wrap_warning(const Image& texture, const std::string& texture_name);

//! The warnings of mapping `mesh` with `options` under `texture` (may be empty: not looked at),
//! one sentence each, empty when there is nothing to say. Any mode: positions far from the origin
//! (far_from_origin_warning); the texture does not wrap (texture_wrap_warning); the texture repeats less than once
//! across the mesh (map_repeats; part of it is never seen). With symmetry 4: the texture is not
//! unchanged by a quarter turn (quarter_turn_difference over kQuarterTurnNoiseLevels), or turns
//! into itself only about a point off its centre and corner (quarter-turn seams would show or jump
//! by half a repeat); the texture repeats less than once across the mesh's longest side (quarter-
//! turn seams land on the lattice less often the fewer the repeats; this one instead of the
//! any-mode sentence). Sentences about the texture
//! start with texture_name. Call with the options complete (set_map_texture_size, the final
//! scale and orientation.fixed_unit_scale). O(V + texture pixels).
TAILOR_API std::vector<std::string> map_warnings(const Mesh& mesh, const MapTextureOptions& options,
                                                 const Image& texture, const std::string& texture_name);

}  // namespace tailor
