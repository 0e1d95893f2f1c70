// tailor: does a texture look different when turned? (chooses how the mapping treats direction)
//
// A seam that turns the texture by some angle is visible under a texture with a direction (bark,
// ripples, bricks) and not under one without (gravel, sand, grass, caustics). The mapping's
// field following (MappingOptions::field_following) keeps every face's texture direction on the
// orientation field at the price of more seams; for a texture without direction that price buys
// nothing, and unfolding rigidly (field_following 0) gives 20-30 % less seam length.
#pragma once

#include <cstdint>

#include "tailor/api.h"
#include "tailor/image.h"
#include "tailor/mapping.h"

namespace tailor {

//! Isotropy of a texture, in [0, 1]: 1 minus the strongest angular harmonic (orders 2, 4 and 6:
//! one preferred direction, two axes, three axes) of its gradient energy relative to the total,
//! at half and quarter resolution (the lower; single-pixel noise and JPEG blocks are averaged out
//! first). 1: the energy is spread evenly over the directions; 0: stripes. Measured on photos:
//! grass 0.91, gravel 0.89, water caustics 0.82; bark 0.73, tiles 0.65, weave 0.59, sand ripples
//! 0.35, bricks 0.25. A flat image reads 1. The image must pass check_image.
TAILOR_API float texture_isotropy(const Image& texture);
//! The same, telling `progress` the share measured every 64 rows (it cannot cancel).
TAILOR_API float texture_isotropy(const Image& texture, const ProgressCallback& progress);

//! Textures at or above this isotropy have no direction worth following: less than a fifth of
//! their gradient energy prefers a direction.
inline constexpr float kIsotropicTextureAbove = 0.8f;

//! Whether the texture has a direction worth following: isotropy below kIsotropicTextureAbove,
//! or no texture at all (an empty image: the mapping cannot know, so it follows the field).
TAILOR_API bool texture_has_direction(const Image& texture);

//! Crack rings for rigid unfolding: it closes cracks faster than field following, and twice the
//! rings cost about what the field following did (horse x16: 1.2x the cpu time of following the
//! field with 16 rings) for 7 % less seam length on the shared meshes.
inline constexpr uint32_t kUndirectedCrackRings = 32;

//! What `tailor map` does by default (--field-following auto): for a texture without direction,
//! rigid unfolding (field_following 0) with kUndirectedCrackRings crack rings, which gives 20-30 %
//! less seam length and fewer dangling seam ends (docs/mapping.md section 7); for any other
//! texture, or none, the options stay as they are. Returns the texture's isotropy (measured once,
//! for reports), or -1 for an empty image. keep_crack_rings: the user chose options.crack_rings
//! (--crack-rings, crack_rings=), so only field_following changes; the CLI and the Python module
//! both pass it. progress: texture_isotropy's (optional).
TAILOR_API float adapt_mapping_to_texture(const Image& texture, MappingOptions& options, bool keep_crack_rings = false,
                                          const ProgressCallback& progress = {});

}  // namespace tailor
