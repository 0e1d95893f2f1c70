// The orientation a JPEG's EXIF block asks viewers to show it in (cameras and phones store the
// sensor's rows and record the turn), and the pixels turned so.
#pragma once

#include <cstdint>
#include <span>

#include "tailor/image.h"

namespace tailor::internal {

//! EXIF Orientation (tag 0x0112 of IFD0 in the APP1 "Exif" segment) of a JPEG file's bytes: 1..8
//! as EXIF numbers them (1: as stored, 6: turn a quarter clockwise to show), 1 when the file is
//! not a JPEG, has no such tag, or the block is malformed. Reads only within `bytes`. O(markers).
int jpeg_exif_orientation(std::span<const unsigned char> bytes);

//! Turns and mirrors `image` as EXIF orientation `orientation` says to show it (2..8; 1 or any
//! other value leaves it). Orientations 5..8 swap the width and height.
void apply_exif_orientation(int orientation, Image& image);

}  // namespace tailor::internal
