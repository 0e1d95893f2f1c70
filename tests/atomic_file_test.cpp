// The guarantees of util/atomic_file (docs/hardening.md): only regular files are replaced, a
// symlink is written through, temporary files have fresh random names (O_EXCL) that fit any valid
// output name, get the umask's mode, and are removed on SIGINT, SIGTERM and SIGHUP.
#include "util/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <string>

#include "util/file_view.h"

namespace fs = std::filesystem;
using namespace tailor;

namespace {

struct TempDir {
  fs::path dir;
  explicit TempDir(const std::string& name) : dir(fs::path(::testing::TempDir()) / name) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~TempDir() { fs::remove_all(dir); }
  std::string operator/(const std::string& name) const { return (dir / name).string(); }
  size_t entries() const {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
  }
};

std::string content(const std::string& path) {
  std::string bytes;
  return internal::read_file(path, bytes).is_ok() ? bytes : std::string("<missing>");
}

}  // namespace

TEST(AtomicFile, RefusesADeviceOrFifoAndLeavesItAlone) {
  TempDir d("atomic_fifo");
  const std::string fifo = d / "out.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  const Status s = internal::write_file_atomic(fifo, std::string("x"));
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  EXPECT_NE(s.what().find("not a regular file"), std::string::npos) << s.what();
  struct stat st;
  ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(d.entries(), 1u);
  // A device: a private node (needs root) rather than /dev/null, which a regression would replace.
  const std::string device = d / "null.json";
  if (mknod(device.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
    EXPECT_FALSE(internal::write_file_atomic(device, std::string("x")).is_ok());
    ASSERT_EQ(lstat(device.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
  }
}

TEST(ReadInput, OnlyRegularFilesAreRead) {
  // A FIFO without a writer would block a plain open(); /dev/zero would be read forever; both are
  // refused at once with one line, by read_file and view_file (open_input).
  TempDir d("read_fifo");
  const std::string fifo = d / "in.obj";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& path : {fifo, std::string("/dev/zero"), d.dir.string()}) {
    std::string bytes;
    const Status s = internal::read_file(path, bytes);
    EXPECT_EQ(s.code(), ErrorCode::kIo) << path;
    EXPECT_NE(s.what().find("not a regular file"), std::string::npos) << s.what();
    EXPECT_TRUE(bytes.empty());
    internal::FileView view;
    const Status v = internal::view_file(path, view);
    EXPECT_EQ(v.code(), ErrorCode::kIo) << path;
    EXPECT_NE(v.what().find("not a regular file"), std::string::npos) << v.what();
  }
  // A symlink to a regular file is read through.
  const std::string file = d / "a.txt", link = d / "link.txt";
  ASSERT_TRUE(internal::write_file_atomic(file, std::string("abc")).is_ok());
  ASSERT_EQ(symlink(file.c_str(), link.c_str()), 0);
  EXPECT_EQ(content(link), "abc");
}

TEST(AtomicFile, WritesThroughASymlinkAndKeepsIt) {
  TempDir d("atomic_link");
  fs::create_directories(d.dir / "real");
  ASSERT_TRUE(internal::write_file_atomic(d / "real/target.txt", std::string("old\n")).is_ok());
  fs::create_symlink("real/target.txt", d.dir / "link.txt");
  ASSERT_TRUE(internal::write_file_atomic(d / "link.txt", std::string("new\n")).is_ok());
  EXPECT_TRUE(fs::is_symlink(d.dir / "link.txt"));
  EXPECT_EQ(content(d / "real/target.txt"), "new\n");
  EXPECT_EQ(d.entries(), 2u);  // no temporary file left in either directory
  EXPECT_EQ(std::distance(fs::directory_iterator(d.dir / "real"), fs::directory_iterator()), 1);
}

TEST(AtomicFile, DoesNotFollowAPlantedSymlinkAtTheOldTemporaryName) {
  TempDir d("atomic_plant");
  const std::string out = d / "out.txt", victim = d / "victim.txt";
  // The name tailor used to write to, "<out>.tmp-<pid>", planted as a link to another file.
  fs::create_symlink(victim, out + ".tmp-" + std::to_string(static_cast<long>(getpid())));
  ASSERT_TRUE(internal::write_file_atomic(out, std::string("data\n")).is_ok());
  EXPECT_FALSE(fs::exists(victim));
  EXPECT_EQ(content(out), "data\n");
  EXPECT_EQ(internal::temporary_template("a/b/c.glb"), "a/b/.tailor-XXXXXX");
  EXPECT_EQ(internal::temporary_template("c.glb"), ".tailor-XXXXXX");
}

TEST(AtomicFile, TakesTheModeFromTheUmask) {
  TempDir d("atomic_mode");
  const mode_t mask = umask(022);
  umask(mask);
  ASSERT_TRUE(internal::write_file_atomic(d / "m.txt", std::string("x")).is_ok());
  struct stat st;
  ASSERT_EQ(stat((d / "m.txt").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0666 & ~mask);
}

TEST(AtomicFile, AFileReplacedKeepsItsModeAndOneNotWritableIsKept) {
  TempDir d("atomic_keep_mode");
  const std::string path = d / "private.txt";
  ASSERT_TRUE(internal::write_file_atomic(path, std::string("old")).is_ok());
  ASSERT_EQ(chmod(path.c_str(), 0640), 0);
  ASSERT_TRUE(internal::write_file_atomic(path, std::string("new")).is_ok());
  struct stat st;
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);  // not the umask's 0644: a private file stays private
  // Read-only for this user: not replaced, as a plain open for writing would fail (root may write
  // any file, so this half needs another user).
  if (geteuid() != 0) {
    ASSERT_EQ(chmod(path.c_str(), 0444), 0);
    const Status s = internal::write_file_atomic(path, std::string("newer"));
    EXPECT_FALSE(s.is_ok());
    EXPECT_NE(s.message().find("cannot write file"), std::string::npos) << s.message();
    std::string bytes;
    ASSERT_TRUE(internal::read_file(path, bytes).is_ok());
    EXPECT_EQ(bytes, "new");
  }
}

TEST(AtomicFile, AnyValidNameWorks) {
  TempDir d("atomic_long");
  for (const size_t length : {246u, 250u, 255u}) {
    const std::string name(length, 'n');
    ASSERT_TRUE(internal::write_file_atomic(d / name, std::string("x")).is_ok()) << length;
    EXPECT_EQ(content(d / name), "x");
  }
  EXPECT_EQ(d.entries(), 3u);
}

TEST(AtomicFile, ErrorPathsLeaveNoTemporaryFile) {
  TempDir d("atomic_errors");
  {
    internal::AtomicFileWriter file(d / "a.txt");
    ASSERT_TRUE(file.open().is_ok());
    ASSERT_TRUE(file.write(std::string_view("partial")).is_ok());
    EXPECT_EQ(d.entries(), 1u);  // the temporary file
  }                              // destroyed without commit
  EXPECT_EQ(d.entries(), 0u);
  {
    internal::FileBatch batch;
    ASSERT_TRUE(internal::write_file_atomic(d / "b.txt", std::string("b")).is_ok());
  }
  EXPECT_EQ(d.entries(), 0u);
}

// A child writes a file half-way, then receives the signal: it dies of it, and no file is left.
TEST(AtomicFile, SignalsRemoveTemporaryFiles) {
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
    TempDir d("atomic_signal");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      std::signal(signal, SIG_DFL);
      internal::install_signal_cleanup();
      internal::FileBatch batch;
      if (!internal::write_file_atomic(d / "staged.txt", std::string("s")).is_ok()) _exit(3);
      internal::AtomicFileWriter file(d / "open.txt");
      if (!file.open().is_ok() || !file.write(std::string_view("partial")).is_ok()) _exit(3);
      raise(signal);
      _exit(4);  // not reached: the signal ends the process
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status)) << "signal " << signal << ", status " << status;
    if (WIFSIGNALED(status)) {
      EXPECT_EQ(WTERMSIG(status), signal);
    }
    EXPECT_EQ(d.entries(), 0u) << "signal " << signal;
  }
}
