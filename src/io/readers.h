// Per-format mesh parsers behind load_mesh/read_mesh (io_mesh.cpp). Each one parses `data`, fills
// positions/indices (and corner_uvs / seam_faces where the format has them) and the format fields
// of `report`; io_mesh.cpp then runs finalize_mesh. `name` is used in error messages only.
// Contract: never read outside `data`, never allocate from an unchecked count, never throw.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "io/polygon_fans.h"
#include "tailor/image.h"
#include "tailor/mesh.h"
#include "tailor/progress.h"
#include "tailor/status.h"
#include "util/text_scan.h"

namespace tailor::internal {

// Adds one item to LoadReport::not_read ("; " between items).
inline void add_not_read(LoadReport& report, const std::string& what) {
  report.not_read += (report.not_read.empty() ? "" : "; ") + what;
}

// What a text reader leaves after the records its header declares (blank lines and, where the
// scanner skips them, comments aside): "" or "N lines after the <declared> (from line L)", L
// counted from line_offset + the scanner's line. Advances the scanner to the end.
inline std::string lines_after(TextScanner& s, size_t line_offset, const std::string& declared) {
  s.skip_space();
  if (s.at_end()) return "";
  const size_t from = s.line() + line_offset;
  size_t lines = 0;
  for (; !s.at_end(); s.skip_space()) {
    ++lines;
    s.next_line();
  }
  return std::to_string(lines) + (lines == 1 ? " line" : " lines") + " after the " + declared + " (from line " +
         std::to_string(from) + ")";
}

//! `text` without the blanks (spaces, tabs, carriage returns) at either end: names on the rest of
//! a header line (an .mtl's map_Kd, a PLY's TextureFile).
inline std::string_view trimmed(std::string_view text) {
  const size_t b = text.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  return text.substr(b, text.find_last_not_of(" \t\r") + 1 - b);
}

//! A reader's progress, as the share of its input parsed, for load_mesh's callback: at() is cheap
//! enough to call per element, and calls the callback only every kStep units (bytes, or whatever
//! `total` counts). The parse takes the share [0, kParseShare] of the bar, the repairs the rest.
class ReadProgress {
 public:
  static constexpr float kParseShare = 0.8f;
  ReadProgress() = default;
  ReadProgress(const ProgressCallback* callback, size_t total) : callback_(callback), total_(total) {
    if (callback_ && *callback_) next_ = 0;
  }
  //! `done` of `total` parsed; false: the callback cancelled.
  bool at(size_t done) { return done < next_ || report(done); }
  //! The repairs' share (after parsing): `done` in [0, 1].
  bool repairs(float done) const {
    return !callback_ || !*callback_ || (*callback_)(kParseShare + (1.f - kParseShare) * done);
  }
  Status cancelled(const std::string& name) const {
    return Status::error(ErrorCode::kCancelled, name, "loading cancelled");
  }

 private:
  static constexpr size_t kStep = size_t{4} << 20;
  bool report(size_t done) {
    next_ = done + (total_ > 100 * kStep ? total_ / 100 : kStep);
    const float share = total_ > 0 ? static_cast<float>(std::min(done, total_)) / static_cast<float>(total_) : 1.f;
    return (*callback_)(kParseShare * share);
  }
  const ProgressCallback* callback_ = nullptr;
  size_t total_ = 0;
  size_t next_ = SIZE_MAX;
};

//! progress (optional) is told the bytes parsed (PLY: per element and every 64k items of the generic
//! loops; OBJ, OFF and ascii STL: every few MB; binary STL: the welding, every 64k corners; glTF: per
//! primitive, in faces).
//! PLY, OBJ, OFF: fans (optional) records the triangles of each polygon's fan, for
//! retriangulate_concave_fans once the positions are all read.
//! PLY: texture_file (optional) gets the first `comment TextureFile NAME` line's name (MeshLab's
//! convention, which tailor's writer follows), empty when there is none.
Status read_ply(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress = nullptr, std::string* texture_file = nullptr, PolygonFans* fans = nullptr);
//! OBJ: material_library (optional) gets the first `mtllib` statement's file name (the rest of its
//! line, blanks trimmed), empty when there is none.
Status read_obj(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress = nullptr, std::string* material_library = nullptr, PolygonFans* fans = nullptr);
Status read_off(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress = nullptr, PolygonFans* fans = nullptr);
Status read_stl(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress = nullptr);
//! glTF 2.0 (.glb or .gltf): the default scene's mesh instances in world space, TEXCOORD_0 into
//! corner_uvs (read_gltf.cpp). Buffer URIs are looked up in `base_dir` (empty: none is opened).
Status read_gltf(std::span<const char> data, const std::string& name, const std::string& base_dir, Mesh& mesh,
                 LoadReport& report, ReadProgress* progress = nullptr);

//! The size an image's header claims, read without decoding anything: PNG (IHDR), JPEG (the first
//! start-of-frame marker) and BMP directly, whatever the size; other formats stb_image reads (TGA,
//! GIF, PSD, HDR, PNM) through stbi_info_from_memory. False when no header is recognised (a JPEG
//! whose frame header lies beyond `bytes`, a truncated PNG) or it claims no pixels. exif_orientation:
//! a JPEG that EXIF turns a quarter has its sides swapped (as load_image reads a file; a glTF's
//! textures are shown as stored).
bool image_header_size(std::span<const unsigned char> bytes, long& width, long& height, bool exif_orientation);

//! Checks the size an image header claims (width x height, read by stbi_info_from_memory) before
//! decoding `bytes`: each side within kMaxImageSide, width x height within options.max_pixels, and
//! for uncompressed TGA, BMP and binary PPM/PGM the file long enough for that many pixels (RLE TGA:
//! at least 2 bytes per 128 pixels). kInvalidImage with one line otherwise (image_io.cpp).
Status check_image_header(std::span<const unsigned char> bytes, long width, long height,
                          const ImageLoadOptions& options, const std::string& name);

}  // namespace tailor::internal
