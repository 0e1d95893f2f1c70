// Seam-face lists (thesis 2.5): which faces the user wants seams on.
#include <algorithm>
#include <charconv>

#include "tailor/io.h"
#include "util/atomic_file.h"
#include "util/text_scan.h"

namespace tailor {

Status load_seam_faces(const std::string& path, size_t face_count, std::vector<uint8_t>& seam_faces) {
  std::string text;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, text));
  seam_faces.assign(face_count, 0);
  size_t line = 0;
  size_t pos = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // a UTF-8 byte order mark, as editors may write
  while (pos < text.size()) {
    ++line;
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const char* first = text.data() + pos;
    const char* last = text.data() + end;
    pos = end + 1;
    last = std::find(first, last, '#');  // a comment, on its own line or after the index
    while (first < last && (*first == ' ' || *first == '\t')) ++first;
    while (last > first && (last[-1] == ' ' || last[-1] == '\t' || last[-1] == '\r')) --last;
    if (first == last) continue;
    uint64_t face = 0;
    const auto [ptr, ec] = std::from_chars(first, last, face);
    if (ec != std::errc() || ptr != last) {
      return Status::error(ErrorCode::kParse, path,
                           "expected one face index per line, got " +
                               internal::quote_input(std::string_view(first, static_cast<size_t>(last - first))),
                           "line " + std::to_string(line));
    }
    if (face >= face_count) {
      return Status::error(
          ErrorCode::kParse, path,
          "face index " + std::to_string(face) + " out of range (mesh has " + std::to_string(face_count) + " faces)",
          "line " + std::to_string(line));
    }
    seam_faces[face] = 1;
  }
  return Status::ok();
}

}  // namespace tailor
