// Shared pieces of the tailor command-line tool: exit codes, the one-line error format, a progress
// bar on stderr, and the registration hook of each subcommand (one file per subcommand).
#pragma once

#include <CLI/CLI.hpp>
#include <array>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "tailor/mapping.h"
#include "tailor/option_doc.h"
#include "tailor/status.h"

namespace tailor::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 1;       //!< unreadable or invalid input, I/O failure
inline constexpr int kExitUsage = 2;          //!< bad command line
inline constexpr int kExitTargetsMissed = 3;  //!< tailor tile: the tile is written but misses its quality targets

//! Prints "tailor: error: <file>: <what> (<where>)" on stderr; returns the exit code for `status`.
int report_error(const Status& status);

//! While alive, a SIGBUS (what reading a mapped input raises once another program truncates the
//! file) ends the process with "tailor: error: <path>: the file changed while it was read ..."
//! and exit code 1 instead of a crash. Inputs are read before any output is written, so nothing is
//! left behind. Outside such a scope SIGBUS keeps its default action (a crash to debug). Scopes do
//! not nest (each wraps one load).
class ReadingInput {
 public:
  explicit ReadingInput(const std::string& path);
  ~ReadingInput();
  ReadingInput(const ReadingInput&) = delete;
  ReadingInput& operator=(const ReadingInput&) = delete;
};

//! Prints "tailor: warning: <text>" on stderr unless quiet.
void warn(bool quiet, const std::string& text);

//! Warns, unless quiet, when `transformed` (LoadReport::texture_transform): the glTF's base colour
//! texture carries KHR_texture_transform, which eval, render and map do not apply. One sentence
//! for the three.
void warn_texture_transform(bool quiet, const std::string& input, bool transformed);

//! A bad command line: reported by report_error with exit code 2.
Status usage_error(const std::string& what);

//! Refuses symmetry 4 with a texture that is not square, as map's set_map_texture_size does: a
//! quarter turn maps the lattice onto itself only when it is square (eval, render).
Status check_quarter_turn_texture(uint32_t symmetry, int width, int height);

//! `option` as one of --stability's: its help starts "With --stability: " and it is refused
//! without `stability` (where it would do nothing).
CLI::Option* with_stability(CLI::Option* option, CLI::Option* stability);

//! --pin-frame and --remove-fraction (StabilityOptions), with_stability (tailor map, tailor eval).
void add_stability_options(CLI::App* cmd, CLI::Option* stability, bool& pin_frame, float& remove_fraction);

//! "dir/a.B.glb" -> "a.B.glb", "dir", "glb" (lower case, without the dot; "" when there is none).
std::string base_name(const std::string& path);
std::string dir_name(const std::string& path);
std::string extension_of(const std::string& path);

//! The flag SIGINT and SIGTERM set (Ctrl-C), installing their handlers on the first call: the
//! servers of `tailor view` and `tailor edit` poll it to stop cleanly.
std::atomic<bool>& stop_requested();

//! JSON text that never throws: bytes that are not UTF-8 (file names can hold any) become U+FFFD.
inline std::string json_text(const nlohmann::json& j, int indent = 2) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

//! An output file and the option that names it, for check_outputs.
struct OutputPath {
  std::string path;
  std::string option;  //!< e.g. "--output", "--preview"
};

//! Whether a path ends in .png, in any case (what tile and render write).
bool ends_with_png(const std::string& path);

//! Before any work: every output goes to an existing directory and is not itself a directory, no
//! two outputs share a path, and no output overwrites one of `inputs` (empty entries ignored).
//! Fails with kInvalidArgument (exit 2), so a refused run writes nothing.
Status check_outputs(const std::vector<OutputPath>& outputs, const std::vector<std::string>& inputs);

//! A validator's message that starts with this is the library's whole message: main prints it as
//! the library words it, without CLI11's "--flag: " before it nor the pointer to --help (a value
//! out of range is refused in the same words whether it parses or not).
inline const std::string kOwnWords = "\x01";

//! Adds the option `doc` names (flag and help from the library's table, tailor/option_doc.h), bound
//! to `field`; the default shown is the field's value now: its options struct's default, or for a
//! text option, that default's name. A number with a range (MappingLimits, OrientationLimits) shows
//! it in the help; check_map_options refuses a value outside it after parsing, in the words the
//! Python module uses too, and a whole number the field cannot even hold (-1) is refused here with
//! the range.
template <class T>
CLI::Option* add_documented(CLI::App* app, const OptionDoc& doc, T& field) {
  CLI::Option* option = app->add_option(std::string(doc.flag), field, help_with_range(doc))->capture_default_str();
  if constexpr (std::is_integral_v<T>) {
    if (option_range_text(doc.flag).empty()) return option;  // no range in the library's table
    option->check(CLI::Validator(
        [flag = std::string(doc.flag)](std::string& text) -> std::string {
          char* end = nullptr;
          const double value = std::strtod(text.c_str(), &end);
          if (text.empty() || *end != '\0') return "";  // not a number: CLI11's conversion names it
          const bool fits = value >= static_cast<double>(std::numeric_limits<T>::min()) &&
                            value <= static_cast<double>(std::numeric_limits<T>::max());
          const Status s = check_option_range(flag, value);
          // The library's message whole: main prints it as check_map_options' (kOwnWords).
          return fits || s ? "" : kOwnWords + s.message();
        },
        ""));
  }
  return option;
}

//! Whether `text` is a whole number that fits 64 bits unsigned (CLI11 reads "-1" into one as
//! 2^64 - 1, and saturates a longer one).
inline bool whole_uint64(const std::string& text, uint64_t& value) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  return !text.empty() && error == std::errc() && stop == end;
}
//! A whole number of 64 bits (--seed).
inline const CLI::Validator kWholeNumber(
    [](std::string& text) -> std::string {
      uint64_t value = 0;
      return whole_uint64(text, value) ? std::string() : "must be a whole number, 0 to 2^64 - 1";
    },
    "");
//! A whole number of at least 1 (--max-image-pixels; CLI11's PositiveNumber said "Value 0 not in
//! range 0.000000 to 1797...").
inline const CLI::Validator kAtLeastOne(
    [](std::string& text) -> std::string {
      uint64_t value = 0;
      return whole_uint64(text, value) && value > 0 ? std::string() : "must be a whole number, at least 1";
    },
    "POSITIVE");

//! Adds --symmetry (1 or 4) of eval and render, documented by `doc`: when it is not given, a .glb
//! from tailor map --symmetry 4 decides (LoadReport::texture_symmetry; the caller reads
//! count("--symmetry")).
inline CLI::Option* add_symmetry_option(CLI::App* app, const OptionDoc& doc, uint32_t& field,
                                        const std::string& more_default = "") {
  return add_documented(app, doc, field)
      ->check(CLI::IsMember({1u, 4u}))
      ->description(std::string(doc.help) +
                    "; default: 4 for a .glb from tailor map --symmetry 4 (its material says so)" + more_default +
                    ", else 1");
}

//! Adds the switch `doc` names ("--no-..."), which turns `field` (on by default) off.
inline CLI::Option* add_off_switch(CLI::App* app, const OptionDoc& doc, bool& field) {
  return app->add_flag_callback(
      std::string(doc.flag), [&field] { field = false; }, std::string(doc.help));
}

//! Parses "X,Y,Z" into three finite floats; false when the text is anything else.
bool parse_vec3(const std::string& text, std::array<float, 3>& v);

//! Parses a number in [0, 1] into `value`; false (value unchanged) when the text is anything else.
bool parse_unit_float(const std::string& text, float& value);

//! A progress bar on stderr, drawn only when stderr is a terminal and not quiet, and only once the
//! work has run for more than ~1 s. update() is cheap enough to call per percent of work.
class Progress {
 public:
  Progress(std::string label, bool quiet);
  ~Progress();
  //! fraction in [0, 1]; returns true (never cancels: the hook matches the library's callbacks).
  bool update(double fraction);
  //! The same for the stage `label` of a pipeline: a new label clears the bar and starts its own
  //! (drawn once that stage has run for ~1 s).
  bool update(std::string_view label, double fraction);
  void done();

 private:
  std::string label_;
  bool enabled_ = false;
  bool drawn_ = false;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point start_;
};

//! A count and its noun, singular for exactly one: counted(1, "file", "files") is "1 file".
inline std::string counted(size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

//! Seconds since `start`.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

//! The web pages' folder of `tailor view` and `tailor edit`: `given` (--web-root), else the installed
//! share/tailor/web relative to the executable, else web/ beside or above it (a build tree's link to
//! the source tree's web/). Fails with kIo when none holds index.html, or three.js is not installed
//! there.
Status find_web_root(const std::string& given, std::string& root);

//! What a subcommand's CLI11 callback sets: the work to run once parsing succeeded.
using Runner = std::function<int()>;

// One registration function per subcommand, each in its own file cmd_<name>.cpp.
void register_info(CLI::App& app, Runner& run);
void register_map(CLI::App& app, Runner& run);
void register_eval(CLI::App& app, Runner& run);
void register_tile(CLI::App& app, Runner& run);
void register_eval_tile(CLI::App& app, Runner& run);
void register_render(CLI::App& app, Runner& run);
void register_view(CLI::App& app, Runner& run);
void register_edit(CLI::App& app, Runner& run);

}  // namespace tailor::cli
