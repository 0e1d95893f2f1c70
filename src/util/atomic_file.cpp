// Whole-file reads and atomic writes (see internal/atomic_file.h).
#include "util/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "util/huge_pages.h"

namespace tailor::internal {
namespace {
thread_local FileBatch* active_batch = nullptr;
}  // namespace

FileBatch::FileBatch() : outer_(active_batch) { active_batch = this; }

FileBatch::~FileBatch() {
  for (const auto& [temporary, path] : staged_) std::remove(temporary.c_str());
  active_batch = outer_;
}

void FileBatch::add(std::string temporary, std::string path) {
  // The same path written twice in one batch: its temporary file holds the last bytes already.
  for (const auto& staged : staged_)
    if (staged.second == path) return;
  staged_.emplace_back(std::move(temporary), std::move(path));
}

Status FileBatch::commit() {
  std::vector<std::pair<std::string, std::string>> staged;
  staged.swap(staged_);
  for (size_t i = 0; i < staged.size(); ++i) {
    if (std::rename(staged[i].first.c_str(), staged[i].second.c_str()) != 0) {
      const int err = errno;
      for (size_t j = i; j < staged.size(); ++j) std::remove(staged[j].first.c_str());
      return Status::error(ErrorCode::kIo, staged[i].second,
                           std::string("cannot rename temporary file: ") + std::strerror(err));
    }
  }
  return Status::ok();
}

AtomicFileWriter::AtomicFileWriter(std::string path) : path_(std::move(path)) {}

AtomicFileWriter::~AtomicFileWriter() {
  if (file_) std::fclose(file_);
  if (!temporary_.empty()) std::remove(temporary_.c_str());
}

Status AtomicFileWriter::open() {
  if (file_ || !temporary_.empty()) return Status::error(ErrorCode::kIo, path_, "cannot create file: already open");
  const std::string tmp = path_ + ".tmp-" + std::to_string(static_cast<long>(getpid()));
  file_ = std::fopen(tmp.c_str(), "wb");
  if (!file_) {
    error_ = Status::error(ErrorCode::kIo, path_, std::string("cannot create file: ") + std::strerror(errno));
    return error_;
  }
  temporary_ = tmp;
  return Status::ok();
}

Status AtomicFileWriter::fail(int err) {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  if (!temporary_.empty()) std::remove(temporary_.c_str());
  temporary_.clear();
  error_ = Status::error(ErrorCode::kIo, path_, std::string("cannot write file: ") + std::strerror(err));
  return error_;
}

Status AtomicFileWriter::write(std::span<const char> bytes) {
  if (!error_.is_ok()) return error_;
  if (!file_) return fail(EBADF);
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) return fail(errno);
  return Status::ok();
}

Status AtomicFileWriter::commit() {
  if (!error_.is_ok()) return error_;
  if (!file_) return fail(EBADF);
  // The first failure's errno: fclose sets its own (or none) after a failed fflush.
  int write_error = std::fflush(file_) == 0 ? 0 : (errno != 0 ? errno : EIO);
  if (std::fclose(file_) != 0 && write_error == 0) write_error = errno != 0 ? errno : EIO;
  file_ = nullptr;
  if (write_error != 0) return fail(write_error);
  std::string tmp;
  tmp.swap(temporary_);  // from here on the batch or the rename owns the temporary file
  if (active_batch) {
    active_batch->add(tmp, path_);
    return Status::ok();
  }
  if (std::rename(tmp.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    error_ = Status::error(ErrorCode::kIo, path_, std::string("cannot rename temporary file: ") + std::strerror(err));
    return error_;
  }
  return Status::ok();
}

Status write_file_atomic(const std::string& path, std::span<const std::span<const char>> pieces) {
  AtomicFileWriter file(path);
  TAILOR_RETURN_IF_ERROR(file.open());
  for (const std::span<const char> piece : pieces) TAILOR_RETURN_IF_ERROR(file.write(piece));
  return file.commit();
}

Status write_file_atomic(const std::string& path, std::span<const char> bytes) {
  return write_file_atomic(path, std::span<const std::span<const char>>(&bytes, 1));
}

Status read_file(const std::string& path, std::string& bytes) {
  bytes.clear();
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return Status::error(ErrorCode::kIo, path, std::string("cannot open file: ") + std::strerror(errno));
  // Regular files: one read into a buffer of the right size (a chunked append costs 5x more on
  // large meshes). Then read on in chunks, which also covers pipes and files that grew meanwhile.
  struct stat st;
  if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    const size_t n = static_cast<size_t>(st.st_size);
    if (n > kMaxReadBytes) {
      std::fclose(f);
      return Status::error(ErrorCode::kLimit, path,
                           "file is larger than " + std::to_string(kMaxReadBytes >> 30) + " GiB");
    }
    bytes.reserve(n);
    advise_huge_pages(bytes.data(), n);
    bytes.resize(n);
    bytes.resize(std::fread(bytes.data(), 1, n, f));
  }
  char chunk[1 << 16];
  size_t n = 0;
  while ((n = std::fread(chunk, 1, sizeof chunk, f)) > 0) {
    // Pipes and devices have no size: stop an endless stream (/dev/zero) before it eats memory.
    if (bytes.size() + n > kMaxReadBytes) {
      std::fclose(f);
      bytes.clear();
      return Status::error(ErrorCode::kLimit, path,
                           "file is larger than " + std::to_string(kMaxReadBytes >> 30) + " GiB");
    }
    bytes.append(chunk, n);
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) {
    bytes.clear();
    return Status::error(ErrorCode::kIo, path, "read error");
  }
  return Status::ok();
}

}  // namespace tailor::internal
