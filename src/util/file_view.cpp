// Whole-file views by mmap with a read() fallback (see internal/file_view.h).
#include "util/file_view.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "util/atomic_file.h"

namespace tailor::internal {

FileView::FileView(FileView&& other) noexcept
    : map_(std::exchange(other.map_, nullptr)),
      map_bytes_(std::exchange(other.map_bytes_, 0)),
      copy_(std::move(other.copy_)) {
  other.copy_.clear();
}

FileView& FileView::operator=(FileView&& other) noexcept {
  if (this != &other) {
    release();
    map_ = std::exchange(other.map_, nullptr);
    map_bytes_ = std::exchange(other.map_bytes_, 0);
    copy_ = std::move(other.copy_);
    other.copy_.clear();
  }
  return *this;
}

FileView::~FileView() { release(); }

void FileView::release() noexcept {
  if (map_ != nullptr) munmap(map_, map_bytes_);
  map_ = nullptr;
  map_bytes_ = 0;
  copy_.clear();
}

std::span<const char> FileView::bytes() const {
  if (map_ != nullptr) return {static_cast<const char*>(map_), map_bytes_};
  return {copy_.data(), copy_.size()};
}

Status view_file(const std::string& path, FileView& view) {
  view.release();
  int fd = -1;
  size_t size = 0;
  TAILOR_RETURN_IF_ERROR(open_input(path, fd, size));  // regular files only
  if (size > 0 && size >= kMapMinBytes) {
    const size_t n = size;
    int flags = MAP_PRIVATE;
#if defined(MAP_POPULATE)
    // Maps the (usually cached) pages now, in one call, instead of one fault per 64 KiB later.
    flags |= MAP_POPULATE;
#endif
    void* p = mmap(nullptr, n, PROT_READ, flags, fd, 0);
    if (p != MAP_FAILED) {
      close(fd);
      view.map_ = p;
      view.map_bytes_ = n;
      return Status::ok();
    }
  }
  close(fd);
  // Small or not mappable: read it (read_file also handles growing files).
  Status s = read_file(path, view.copy_);
  if (!s.is_ok()) view.copy_.clear();
  return s;
}

}  // namespace tailor::internal
