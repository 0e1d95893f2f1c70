// Writing output files so that a failure never leaves a half-written file behind: everything goes
// to "<path>.tmp-<pid>" first, and only a complete, flushed file is renamed onto <path>.
#pragma once

#include <span>
#include <string>

#include "tailor/status.h"

namespace tailor::internal {

//! Writes `bytes` to `path` atomically. On any failure the temporary file is removed and `path`
//! is left as it was.
Status write_file_atomic(const std::string& path, std::span<const char> bytes);

//! Largest file read_file accepts (also what stops an endless pipe or device).
inline constexpr size_t kMaxReadBytes = size_t{4} << 30;

//! Reads a whole file into `bytes`. Fails with kIo on open or read errors.
Status read_file(const std::string& path, std::string& bytes);

}  // namespace tailor::internal
