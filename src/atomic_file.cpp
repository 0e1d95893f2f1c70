// Whole-file reads and atomic writes (see internal/atomic_file.h).
#include "internal/atomic_file.h"
#include "internal/huge_pages.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

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

Status write_file_atomic(const std::string& path, std::span<const char> bytes) {
  const std::string tmp = path + ".tmp-" + std::to_string(static_cast<long>(getpid()));
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) return Status::error(ErrorCode::kIo, path, std::string("cannot create file: ") + std::strerror(errno));
  const bool written = bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  const bool flushed = std::fflush(f) == 0;
  const bool closed = std::fclose(f) == 0;
  if (!written || !flushed || !closed) {
    const int err = errno;
    std::remove(tmp.c_str());
    return Status::error(ErrorCode::kIo, path, std::string("cannot write file: ") + std::strerror(err));
  }
  if (active_batch) {
    active_batch->add(tmp, path);
    return Status::ok();
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    return Status::error(ErrorCode::kIo, path, std::string("cannot rename temporary file: ") + std::strerror(err));
  }
  return Status::ok();
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
