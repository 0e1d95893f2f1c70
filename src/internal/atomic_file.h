// Writing output files so that a failure never leaves a half-written file behind: everything goes
// to "<path>.tmp-<pid>" first, and only a complete, flushed file is renamed onto <path>.
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tailor/status.h"

namespace tailor::internal {

//! Writes `bytes` to `path` atomically. On any failure the temporary file is removed and `path`
//! is left as it was. While a FileBatch is alive on this thread, the file is only staged (written
//! to its temporary name) and lands when the batch commits.
Status write_file_atomic(const std::string& path, std::span<const char> bytes);

//! Makes the outputs of one command land together. While it is alive on this thread (batches nest:
//! the innermost one collects), write_file_atomic stages each file under its temporary name;
//! commit() renames them all onto their paths, in the order written, once every write succeeded.
//! The destructor removes whatever was not committed, so a command that fails half-way (a full
//! disk while writing its third output) leaves none of its outputs and the old files as they
//! were. Only a rename failing in the middle of commit() (rare: paths were checked, same
//! directory) can leave the earlier ones renamed. Not thread-safe across threads (one per thread).
class FileBatch {
 public:
  FileBatch();
  ~FileBatch();
  FileBatch(const FileBatch&) = delete;
  FileBatch& operator=(const FileBatch&) = delete;

  //! Renames every staged file onto its path. Fails with kIo naming the first that could not be
  //! renamed (the ones not yet renamed are removed).
  Status commit();

  //! Called by write_file_atomic: records a staged file (temporary name, final path).
  void add(std::string temporary, std::string path);

 private:
  std::vector<std::pair<std::string, std::string>> staged_;
  FileBatch* outer_ = nullptr;
};

//! Largest file read_file accepts (also what stops an endless pipe or device).
inline constexpr size_t kMaxReadBytes = size_t{4} << 30;

//! Reads a whole file into `bytes`. Fails with kIo on open or read errors.
Status read_file(const std::string& path, std::string& bytes);

}  // namespace tailor::internal
