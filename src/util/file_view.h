// Read-only view of a whole input file without copying it.
//
// load_mesh used to read the file into a fresh std::string: the kernel zeroes every new page, the
// string zero-fills it again, and read() copies the page cache into it -- about a quarter of the
// time of loading a 40 MB binary PLY. A private read-only mapping of a regular file shares the
// page-cache pages instead (no copy, no zeroing). Small files, pipes, devices and any mmap failure
// fall back to an ordinary read, so callers see the same bytes either way.
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include "tailor/status.h"

namespace tailor::internal {

//! The bytes of one file, mapped or copied. Move-only; unmaps on destruction.
//! Caveat of any mapping: if another process truncates the file while it is viewed, reading
//! past the new end raises SIGBUS (content, however malformed, is safe: parsers get a span). The
//! tailor CLI turns that signal into a one-line error (apps/tailor/cli.h, ReadingInput).
class FileView {
 public:
  FileView() = default;
  FileView(const FileView&) = delete;
  FileView& operator=(const FileView&) = delete;
  FileView(FileView&& other) noexcept;
  FileView& operator=(FileView&& other) noexcept;
  ~FileView();

  //! The whole file; valid until this view is destroyed, moved from or reassigned.
  std::span<const char> bytes() const;
  //! True when the bytes are a memory mapping (false: an in-memory copy).
  bool mapped() const { return map_ != nullptr; }

 private:
  friend Status view_file(const std::string& path, FileView& view);
  void release() noexcept;

  void* map_ = nullptr;   // mmap result, or nullptr
  size_t map_bytes_ = 0;  // length of the mapping
  std::string copy_;      // the bytes when not mapped
};

//! Regular files of at least this size are mapped; smaller ones are read (a read() of a few
//! pages costs less than setting up and tearing down a mapping).
inline constexpr size_t kMapMinBytes = size_t{1} << 20;

//! Makes `view` show the whole file at `path`. Fails with kIo on open or read errors (same
//! messages as read_file); on failure `view` is empty. Cost: O(1) copies for mapped files (the
//! page tables of the file are populated up front), one read otherwise.
Status view_file(const std::string& path, FileView& view);

}  // namespace tailor::internal
