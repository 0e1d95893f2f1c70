// Whole-file reads and atomic writes (see internal/atomic_file.h).
#include "util/atomic_file.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "util/huge_pages.h"

namespace tailor::internal {
namespace {
thread_local FileBatch* active_batch = nullptr;

// The signals that remove the temporary files before ending the process.
constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

// The registry of live temporary files, for the signal handler: fixed slots (no allocation), each
// claimed with a lock-free compare-exchange (0 free, 1 being filled, 2 live: the handler unlinks
// only live ones). Paths longer than a slot, or a 257th live file, are simply not registered (the
// file is then only removed on the ordinary paths).
constexpr int kSlots = 256;
constexpr size_t kSlotPath = 4096;
struct Slot {
  std::atomic<int> state{0};
  char path[kSlotPath];
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");
Slot slots[kSlots];

int register_temporary(const std::string& path) {
  if (path.size() >= kSlotPath) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (slots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(slots[i].path, path.c_str(), path.size() + 1);
      slots[i].state.store(2);
      return i;
    }
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot >= 0 && slot < kSlots) slots[slot].state.store(0);
}

// Removes a temporary file, then forgets it (in this order: a signal in between only unlinks a
// name that is already gone).
void discard_temporary(const std::string& temporary, int slot) {
  unlink(temporary.c_str());
  unregister_temporary(slot);
}

extern "C" void on_terminating_signal(int signal) {
  const int saved_errno = errno;
  remove_temporaries_on_signal();
  // The default action only now, after the clean-up: a second signal meanwhile (Ctrl-C twice,
  // `timeout` signalling the process and then its group) is blocked here or runs this handler on
  // another thread, where a default action reset on entry let it end the process half-way through
  // (temporary files left). The signal is blocked while this handler runs, so it is delivered (and
  // ends the process) as soon as the handler returns.
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  sigaction(signal, &default_action, nullptr);
  raise(signal);
  errno = saved_errno;
}

// The process umask, read without changing it (umask() can only be read by setting it, which races
// with other threads creating files): /proc/self/status, else the set-and-restore fallback, once.
mode_t process_umask() {
  static const mode_t mask = [] {
    if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
      char line[256];
      unsigned value = 0;
      bool found = false;
      while (!found && std::fgets(line, sizeof line, f)) found = std::sscanf(line, "Umask: %o", &value) == 1;
      std::fclose(f);
      if (found) return static_cast<mode_t>(value & 0777);
    }
    const mode_t m = umask(022);
    umask(m);
    return m;
  }();
  return mask;
}

Status io_error(const std::string& path, const std::string& what, int err) {
  return Status::error(ErrorCode::kIo, path, what + ": " + std::strerror(err));
}

// The file that writing `path` replaces: `path` itself, or for a symlink to a regular file, the
// file it points to (so the link is kept). Refuses what exists and is not a regular file.
Status resolve_target(const std::string& path, std::string& target) {
  struct stat st;
  if (lstat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) return io_error(path, "cannot create file", errno);
    target = path;
    return Status::ok();
  }
  if (S_ISLNK(st.st_mode)) {
    if (stat(path.c_str(), &st) != 0) {  // a dangling link: replaced by the file, like a missing path
      if (errno != ENOENT) return io_error(path, "cannot create file", errno);
      target = path;
      return Status::ok();
    }
    if (S_ISREG(st.st_mode)) {
      char* resolved = realpath(path.c_str(), nullptr);
      if (!resolved) return io_error(path, "cannot create file", errno);
      target = resolved;
      std::free(resolved);
      return Status::ok();
    }
  }
  if (S_ISDIR(st.st_mode)) return Status::error(ErrorCode::kIo, path, "cannot create file: is a directory");
  if (!S_ISREG(st.st_mode))
    return Status::error(ErrorCode::kIo, path, "not a regular file (a device, FIFO or socket): not replaced");
  target = path;
  return Status::ok();
}
}  // namespace

std::string temporary_template(const std::string& target) {
  const size_t slash = target.rfind('/');
  return (slash == std::string::npos ? std::string() : target.substr(0, slash + 1)) + ".tailor-XXXXXX";
}

void remove_temporaries_on_signal() {
  for (Slot& slot : slots)
    if (slot.state.load() == 2) unlink(slot.path);
}

void install_signal_cleanup() {
  // A write beyond the file size limit (ulimit -f) then fails with EFBIG on the ordinary error path
  // (one error line, the temporary removed) instead of the process being killed mid-write.
  struct sigaction size_limit {};
  if (sigaction(SIGXFSZ, nullptr, &size_limit) == 0 && size_limit.sa_handler == SIG_DFL) std::signal(SIGXFSZ, SIG_IGN);
  for (const int signal : kCleanupSignals) {
    struct sigaction old {};
    if (sigaction(signal, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;  // nohup, background jobs
    struct sigaction action {};
    action.sa_handler = on_terminating_signal;
    sigemptyset(&action.sa_mask);  // the three blocked while one is handled on this thread
    for (const int other : kCleanupSignals) sigaddset(&action.sa_mask, other);
    sigaction(signal, &action, nullptr);
  }
}

FileBatch::FileBatch() : outer_(active_batch) { active_batch = this; }

FileBatch::~FileBatch() {
  for (const Staged& s : staged_) discard_temporary(s.temporary, s.slot);
  active_batch = outer_;
}

void FileBatch::add(std::string temporary, int slot, std::string target, std::string path) {
  // The same file written twice in one batch: the last bytes win, at the place of the first write.
  for (Staged& s : staged_) {
    if (s.target == target) {
      discard_temporary(s.temporary, s.slot);
      s.temporary = std::move(temporary);
      s.slot = slot;
      return;
    }
  }
  staged_.push_back({std::move(temporary), slot, std::move(target), std::move(path)});
}

Status FileBatch::commit() {
  std::vector<Staged> staged;
  staged.swap(staged_);
  for (size_t i = 0; i < staged.size(); ++i) {
    if (std::rename(staged[i].temporary.c_str(), staged[i].target.c_str()) != 0) {
      const int err = errno;
      for (size_t j = i; j < staged.size(); ++j) discard_temporary(staged[j].temporary, staged[j].slot);
      return io_error(staged[i].path, "cannot rename temporary file", err);
    }
    unregister_temporary(staged[i].slot);
  }
  return Status::ok();
}

AtomicFileWriter::AtomicFileWriter(std::string path) : path_(std::move(path)) {}

AtomicFileWriter::~AtomicFileWriter() {
  if (file_) std::fclose(file_);
  if (!temporary_.empty()) discard_temporary(temporary_, slot_);
}

Status AtomicFileWriter::open() {
  if (file_ || !temporary_.empty()) return Status::error(ErrorCode::kIo, path_, "cannot create file: already open");
  if (Status s = resolve_target(path_, target_); !s) {
    error_ = s;
    return error_;
  }
  // A file already there keeps its mode, and one the user may not write is not replaced (a plain
  // open for writing would fail): the rename would swap in a new file whatever its permissions.
  mode_t mode = 0666 & ~process_umask();  // what a plain open(O_CREAT, 0666) gives
  struct stat existing;
  if (::stat(target_.c_str(), &existing) == 0) {
    if (access(target_.c_str(), W_OK) != 0) {
      error_ = io_error(path_, "cannot write file", errno);
      return error_;
    }
    mode = existing.st_mode & 07777;
  }
  // Created and registered with the cleanup signals blocked: a signal in between would leave it.
  std::string tmp = temporary_template(target_);
  sigset_t cleanup_signals, previous;
  sigemptyset(&cleanup_signals);
  for (const int signal : kCleanupSignals) sigaddset(&cleanup_signals, signal);
  pthread_sigmask(SIG_BLOCK, &cleanup_signals, &previous);
  const int fd = mkstemp(tmp.data());  // O_CREAT|O_EXCL, mode 0600, a random name
  const int mkstemp_errno = errno;
  const int slot = fd >= 0 ? register_temporary(tmp) : -1;
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  if (fd < 0) {
    error_ = io_error(path_, "cannot create file", mkstemp_errno);
    return error_;
  }
  temporary_ = tmp;
  slot_ = slot;
  if (fchmod(fd, mode) != 0 || !(file_ = fdopen(fd, "wb"))) {
    const int err = errno;
    close(fd);
    discard_temporary(temporary_, slot_);
    temporary_.clear();
    slot_ = -1;
    error_ = io_error(path_, "cannot create file", err);
    return error_;
  }
  return Status::ok();
}

Status AtomicFileWriter::fail(int err) {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  if (!temporary_.empty()) discard_temporary(temporary_, slot_);
  temporary_.clear();
  slot_ = -1;
  error_ = io_error(path_, "cannot write file", err);
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
  // The first failure's errno: fclose sets its own (or none) after a failed fflush. The bytes reach
  // the disk (fsync) before the rename makes them the target: after a power cut the target is the
  // old file or the whole new one, never a renamed empty one.
  int write_error = std::fflush(file_) == 0 ? 0 : (errno != 0 ? errno : EIO);
  if (write_error == 0 && fsync(fileno(file_)) != 0 && errno != EINVAL && errno != EROFS) write_error = errno;
  if (std::fclose(file_) != 0 && write_error == 0) write_error = errno != 0 ? errno : EIO;
  file_ = nullptr;
  if (write_error != 0) return fail(write_error);
  std::string tmp;
  tmp.swap(temporary_);  // from here on the batch or the rename owns the temporary file
  const int slot = std::exchange(slot_, -1);
  if (active_batch) {
    active_batch->add(tmp, slot, target_, path_);
    return Status::ok();
  }
  if (std::rename(tmp.c_str(), target_.c_str()) != 0) {
    const int err = errno;
    discard_temporary(tmp, slot);
    error_ = io_error(path_, "cannot rename temporary file", err);
    return error_;
  }
  unregister_temporary(slot);
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

Status open_input(const std::string& path, int& fd, size_t& size) {
  fd = -1;
  size = 0;
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer. O_NOCTTY: a
  // terminal never becomes the controlling one. Both only matter until the type is checked.
  const int f = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (f < 0) return Status::error(ErrorCode::kIo, path, std::string("cannot open file: ") + std::strerror(errno));
  struct stat st;
  if (fstat(f, &st) != 0) {
    const int err = errno;
    close(f);
    return Status::error(ErrorCode::kIo, path, std::string("cannot stat file: ") + std::strerror(err));
  }
  if (!S_ISREG(st.st_mode)) {
    close(f);
    return Status::error(ErrorCode::kIo, path,
                         S_ISDIR(st.st_mode)
                             ? "is a directory, not a regular file"
                             : "not a regular file (a device, FIFO or socket); inputs must be regular files");
  }
  const int flags = fcntl(f, F_GETFL);
  if (flags < 0 || fcntl(f, F_SETFL, flags & ~O_NONBLOCK) != 0) {
    const int err = errno;
    close(f);
    return Status::error(ErrorCode::kIo, path, std::string("cannot open file: ") + std::strerror(err));
  }
  fd = f;
  size = static_cast<size_t>(st.st_size);
  return Status::ok();
}

Status read_file(const std::string& path, std::string& bytes) {
  bytes.clear();
  int fd = -1;
  size_t size = 0;
  TAILOR_RETURN_IF_ERROR(open_input(path, fd, size));
  std::FILE* f = fdopen(fd, "rb");
  if (!f) {
    const int err = errno;
    close(fd);
    return Status::error(ErrorCode::kIo, path, std::string("cannot open file: ") + std::strerror(err));
  }
  // One read into a buffer of the right size (a chunked append costs 5x more on large meshes).
  // Then read on in chunks, which covers files that grew meanwhile.
  if (size > 0) {
    const size_t n = size;
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
    // A file that keeps growing while it is read is stopped at the cap too.
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

Status read_file_head(const std::string& path, size_t max_bytes, std::string& bytes) {
  bytes.clear();
  int fd = -1;
  size_t size = 0;
  TAILOR_RETURN_IF_ERROR(open_input(path, fd, size));
  bytes.resize(std::min(size, max_bytes));
  size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      close(fd);
      bytes.clear();
      return Status::error(ErrorCode::kIo, path, std::string("read error: ") + std::strerror(err));
    }
    if (n == 0) break;  // the file shrank meanwhile
    got += static_cast<size_t>(n);
  }
  close(fd);
  bytes.resize(got);
  return Status::ok();
}

}  // namespace tailor::internal
