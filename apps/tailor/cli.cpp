// Error lines, warnings and the progress bar of the tailor CLI.
#include "cli.h"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "tailor/stability.h"

namespace tailor::cli {

namespace {
// The input being read, for the SIGBUS handler (which may only call async-signal-safe functions:
// the message is assembled beforehand).
char reading_message[4200];
size_t reading_length = 0;
volatile sig_atomic_t reading_now = 0;

extern "C" void on_bus_error(int signal) {
  if (!reading_now) {  // not an input read: the default action, when the faulting access runs again
    std::signal(signal, SIG_DFL);
    return;
  }
  const ssize_t ignored = write(STDERR_FILENO, reading_message, reading_length);
  (void)ignored;
  _exit(kExitBadInput);
}
}  // namespace

ReadingInput::ReadingInput(const std::string& path) {
  const std::string message = "tailor: error: " + path.substr(0, 4000) +
                              ": the file changed while it was read (truncated by another program?)\n";
  std::memcpy(reading_message, message.data(), message.size());
  reading_length = message.size();
  std::atomic_signal_fence(std::memory_order_seq_cst);  // the message is complete before the flag
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_handler = on_bus_error;
    sigemptyset(&action.sa_mask);
    return sigaction(SIGBUS, &action, nullptr) == 0;
  }();
  (void)installed;
  reading_now = 1;
}

ReadingInput::~ReadingInput() { reading_now = 0; }

int report_error(const Status& status) {
  std::fprintf(stderr, "tailor: error: %s\n", status.message().c_str());
  return status.code() == ErrorCode::kInvalidArgument ? kExitUsage : kExitBadInput;
}

void warn(bool quiet, const std::string& text) {
  if (!quiet) std::fprintf(stderr, "tailor: warning: %s\n", text.c_str());
}

void warn_texture_transform(bool quiet, const std::string& input, bool transformed) {
  if (transformed)
    warn(quiet, input +
                    ": the base colour texture's KHR_texture_transform (offset, rotation, scale) is not applied: "
                    "its texture coordinates are used as stored");
}

Status usage_error(const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); }

Status check_quarter_turn_texture(uint32_t symmetry, int width, int height) {
  if (symmetry != 4 || width == height) return Status::ok();
  return usage_error("--symmetry 4 needs a square texture, got " + std::to_string(width) + "x" +
                     std::to_string(height));
}

CLI::Option* with_stability(CLI::Option* option, CLI::Option* stability) {
  const std::string prefix = "With --stability: ", text = option->get_description();
  return option->description(text.starts_with(prefix) ? text : prefix + text)->needs(stability);
}

void add_stability_options(CLI::App* cmd, CLI::Option* stability, bool& pin_frame, float& remove_fraction) {
  with_stability(cmd->add_flag("--pin-frame", pin_frame,
                               "the thesis's experiment instead: both runs keep the full mesh's axis, "
                               "normalisation and seed point (no reordered run)"),
                 stability);
  with_stability(add_documented(cmd, option_doc(kStabilityOptionDocs, "remove_fraction"), remove_fraction)
                     ->check(CLI::Range(0.01f, 0.9f)),
                 stability);
}

std::string base_name(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string dir_name(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

std::string extension_of(const std::string& path) {
  const std::string base = base_name(path);
  const size_t dot = base.rfind('.');
  std::string ext = dot == std::string::npos ? "" : base.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop.store(true); }
}  // namespace

std::atomic<bool>& stop_requested() {
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    return ::sigaction(SIGINT, &action, nullptr) == 0 && ::sigaction(SIGTERM, &action, nullptr) == 0;
  }();
  (void)installed;
  return g_stop;
}

bool ends_with_png(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".png";
}

Status check_outputs(const std::vector<OutputPath>& outputs, const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  auto key = [](const std::string& p) {
    std::error_code ec;
    const fs::path absolute = fs::absolute(fs::path(p), ec);
    return (ec ? fs::path(p) : absolute).lexically_normal().string();
  };
  // Two names of one existing file (a symlink, a symlinked directory, a hard link): same device
  // and inode. Names that do not exist yet are compared as normalized paths.
  auto same_file = [&key](const std::string& a, const std::string& b) {
    struct stat sa, sb;
    if (stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    return key(a) == key(b);
  };
  for (size_t i = 0; i < outputs.size(); ++i) {
    const auto& [path, option] = outputs[i];
    const fs::path parent = fs::path(path).parent_path();
    std::error_code ec;
    if (fs::is_directory(path, ec))
      return Status::error(ErrorCode::kInvalidArgument, path, "output (" + option + ") is a directory");
    // Only regular files are replaced (through a symlink: its target); a device, FIFO or socket
    // (/dev/null, a named pipe) would be swapped for a regular file.
    struct stat st;
    if (stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      return Status::error(ErrorCode::kInvalidArgument, path,
                           "output (" + option + ") is not a regular file (a device, FIFO or socket)");
    if (!parent.empty() && !fs::is_directory(parent, ec))
      return Status::error(ErrorCode::kInvalidArgument, path,
                           "directory of the output (" + option + ") does not exist");
    for (const std::string& in : inputs) {
      if (!in.empty() && same_file(in, path))
        return Status::error(ErrorCode::kInvalidArgument, path, "output (" + option + ") would overwrite an input");
    }
    for (size_t j = 0; j < i; ++j) {
      if (same_file(outputs[j].path, path))
        return Status::error(ErrorCode::kInvalidArgument, path,
                             "two outputs share this path (" + outputs[j].option + " and " + option + ")");
    }
  }
  return Status::ok();
}

bool parse_vec3(const std::string& text, std::array<float, 3>& v) {
  std::istringstream in(text);
  char comma1 = 0, comma2 = 0;
  if (!(in >> v[0] >> comma1 >> v[1] >> comma2 >> v[2]) || comma1 != ',' || comma2 != ',') return false;
  in >> std::ws;
  return in.eof() && std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

bool parse_unit_float(const std::string& text, float& value) {
  std::istringstream in(text);
  float parsed = 0.f;
  if (!(in >> parsed)) return false;
  in >> std::ws;
  if (!in.eof() || !(parsed >= 0.f && parsed <= 1.f)) return false;
  value = parsed;
  return true;
}

Progress::Progress(std::string label, bool quiet)
    : label_(std::move(label)),
      enabled_(!quiet && isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { done(); }

bool Progress::update(double fraction) {
  if (!enabled_) return true;
  const int percent = static_cast<int>(fraction * 100.0);
  if (percent == last_percent_) return true;
  // Short work gets no bar at all: it would only flicker.
  if (!drawn_ && seconds_since(start_) < 1.0) return true;
  last_percent_ = percent;
  constexpr int kWidth = 30;
  const int filled = percent * kWidth / 100;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", label_.c_str(), filled,
               "==============================", kWidth - filled, "", percent);
  std::fflush(stderr);
  drawn_ = true;
  return true;
}

bool Progress::update(std::string_view label, double fraction) {
  if (label != label_) {
    done();
    label_ = label;
    last_percent_ = -1;
    start_ = std::chrono::steady_clock::now();
  }
  return update(fraction);
}

void Progress::done() {
  if (drawn_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    drawn_ = false;
  }
}

}  // namespace tailor::cli
