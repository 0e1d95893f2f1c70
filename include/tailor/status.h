// tailor: error reporting without exceptions.
//
// Every library entry point that can fail on user input returns a Status (or fills an output and
// returns Status). A Status carries a code, the file it concerns, what went wrong and where
// (line, element index or byte offset), so that the CLI can print exactly one line:
//     tailor: error: <file>: <what> (<where>)
// The library never prints, never exits and never lets an exception escape.
#pragma once

#include <string>
#include <utility>

namespace tailor {

//! What kind of failure a Status reports. The CLI maps kInvalidArgument to exit code 2 (usage)
//! and every other error to exit code 1 (bad input or environment).
enum class ErrorCode {
  kOk = 0,
  kIo,               //!< file cannot be opened, read, written or renamed
  kParse,            //!< malformed content (bad header, bad token, truncated data)
  kInvalidMesh,      //!< well-formed file whose mesh is unusable (NaN, index out of range, empty)
  kInvalidImage,     //!< unreadable, empty or absurdly large image
  kUnsupported,      //!< valid but unsupported variant (format feature, file extension)
  kLimit,            //!< a count exceeds what tailor can index (> 2^32 - 1 elements) or what the file holds
  kInvalidArgument,  //!< bad option value given by the caller
  kCancelled,        //!< a progress callback asked to stop
};

//! Result of an operation: ok, or an error with context. Cheap to copy when ok.
class Status {
 public:
  Status() = default;

  static Status ok() { return Status(); }

  //! file: the path the error concerns (may be empty); what: a short lowercase phrase;
  //! where: "line 12", "face 3071", "byte 4096"... (may be empty).
  static Status error(ErrorCode code, std::string file, std::string what, std::string where = {}) {
    Status s;
    s.code_ = code;
    s.file_ = std::move(file);
    s.what_ = std::move(what);
    s.where_ = std::move(where);
    return s;
  }

  bool is_ok() const { return code_ == ErrorCode::kOk; }
  explicit operator bool() const { return is_ok(); }
  ErrorCode code() const { return code_; }
  const std::string& file() const { return file_; }
  const std::string& what() const { return what_; }
  const std::string& where() const { return where_; }

  //! "<file>: <what> (<where>)", leaving out the parts that are empty.
  std::string message() const {
    std::string m;
    if (!file_.empty()) m += file_ + ": ";
    m += what_;
    if (!where_.empty()) m += " (" + where_ + ")";
    return m;
  }

  //! Returns a copy with the file set when none was set (readers of memory buffers leave it empty).
  Status with_file(const std::string& file) const {
    Status s = *this;
    if (s.file_.empty()) s.file_ = file;
    return s;
  }

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string file_;
  std::string what_;
  std::string where_;
};

//! Propagates a failed Status to the caller.
#define TAILOR_RETURN_IF_ERROR(expr)                    \
  do {                                                  \
    ::tailor::Status tailor_status_ = (expr);           \
    if (!tailor_status_.is_ok()) return tailor_status_; \
  } while (0)

}  // namespace tailor
