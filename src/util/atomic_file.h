// Writing output files so that a failure never leaves a half-written file behind: everything goes
// to a fresh temporary file ".tailor-XXXXXX" (mkstemp: O_CREAT|O_EXCL, a random name) in the
// directory of the file that will be replaced, and only a complete, flushed file is renamed onto it.
// The path may be a symlink to a regular file: the target is replaced, the link kept. A path that
// exists and is not a regular file (a device, FIFO or socket) is refused, untouched. Live temporary
// files are registered so that install_signal_cleanup()'s handler can remove them on a signal.
#pragma once

#include <cstdio>
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

//! The same for a file made of several pieces, written in order (a gather write: the caller need
//! not assemble the whole file in memory). Same temporary file, rename and FileBatch semantics.
Status write_file_atomic(const std::string& path, std::span<const std::span<const char>> pieces);

//! Writes one file atomically piece by piece, for writers that produce it in chunks:
//!     AtomicFileWriter file(path);
//!     TAILOR_RETURN_IF_ERROR(file.open());
//!     file.write(header); file.write(chunk); ...      // errors are sticky, checked by commit()
//!     return file.commit();
//! open() creates the temporary file (see the top of this file); commit() flushes, closes and renames it onto `path`
//! (or stages it in the active FileBatch, like write_file_atomic). When any step failed, or the writer is destroyed
//! without a commit (an early return), the temporary file is removed and `path` is left as it was. Error messages are
//! those of write_file_atomic. Not copyable; one thread.
class AtomicFileWriter {
 public:
  explicit AtomicFileWriter(std::string path);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  //! Creates the temporary file. Fails with kIo ("cannot create file").
  Status open();
  //! Appends bytes. After the first failure it writes nothing more and returns that error (kIo).
  Status write(std::span<const char> bytes);
  //! Flushes, closes and renames (or stages). Fails with kIo; the temporary file is then removed.
  Status commit();

 private:
  Status fail(int err);  // records the first write error, closes and removes the temporary file

  std::string path_;    // as given (for messages)
  std::string target_;  // what is replaced: path_ with its symlinks resolved
  std::string temporary_;
  int slot_ = -1;  // in the signal-cleanup registry
  std::FILE* file_ = nullptr;
  Status error_;
};

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

  //! Called by AtomicFileWriter::commit: records a staged file (its temporary name and registry
  //! slot, the file it replaces, the path as given). The batch owns the temporary file from then on.
  void add(std::string temporary, int slot, std::string target, std::string path);

 private:
  struct Staged {
    std::string temporary;
    int slot;
    std::string target;
    std::string path;
  };
  std::vector<Staged> staged_;
  FileBatch* outer_ = nullptr;
};

//! Installs handlers for SIGINT, SIGTERM and SIGHUP (those not ignored) that remove every live
//! temporary file (async-signal-safe unlink), then re-raise the signal with its default action, so
//! the process still dies of it (exit status 130, 143, 129 in a shell). For programs (the CLI); a
//! library user with its own handlers can call remove_temporaries_on_signal() from them instead.
void install_signal_cleanup();

//! Async-signal-safe: unlinks every temporary file still registered (staged or being written).
void remove_temporaries_on_signal();

//! The name a temporary file for `target` gets: "<directory of target>/.tailor-XXXXXX".
std::string temporary_template(const std::string& target);

//! Largest file read_file accepts (also what stops a regular file that keeps growing).
inline constexpr size_t kMaxReadBytes = size_t{4} << 30;

//! Opens an input file for reading: the one place every input goes through (read_file,
//! view_file). Only regular files (or symlinks to them) are accepted: a FIFO, socket, character or
//! block device or directory is refused with one kIo line ("not a regular file ...") before any
//! read, so a FIFO without a writer cannot block and /dev/zero cannot be read forever. The open
//! itself is non-blocking (O_NONBLOCK, cleared again for regular files), so a FIFO swapped in
//! after a stat cannot hang it either. On success `fd` is an open descriptor (O_CLOEXEC) the caller
//! closes, and `size` the file's size.
Status open_input(const std::string& path, int& fd, size_t& size);

//! Reads a whole regular file into `bytes` (open_input). Fails with kIo on open or read errors
//! and on inputs that are not regular files, kLimit above kMaxReadBytes.
Status read_file(const std::string& path, std::string& bytes);

//! Reads the first `max_bytes` of a regular file (all of it when shorter) into `bytes`, as
//! read_file opens it: for a header, without reading the rest of a large file.
Status read_file_head(const std::string& path, size_t max_bytes, std::string& bytes);

}  // namespace tailor::internal
