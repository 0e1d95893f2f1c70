// Bounds-checked scanning of ASCII mesh files (OBJ, OFF, ASCII PLY, ASCII STL).
//
// A TextScanner walks a [begin, end) byte range and never reads outside it. It knows the current
// line number (1-based) so that parse errors can say "line 12003". Numbers are parsed with
// fast_float (floats, exact rounding, no locale, no allocation) and std::from_chars (integers);
// a leading '+' is accepted for both because some writers emit it.
//
// Safe for untrusted input: every function checks `p < end` before dereferencing; a number that
// does not parse leaves the scanner where it was and returns false.
// Cost: O(bytes scanned); nothing is allocated.
#pragma once

#include <fast_float/fast_float.h>

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace tailor::internal {

//! Space, tab, carriage return, vertical tab, form feed: separators that do not end a line.
inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

//! `input` in single quotes, safe to print in an error line: printable ASCII is kept, a backslash
//! becomes \\, every other byte (control characters, ESC, bytes >= 0x80) becomes \xNN, and at
//! most `max_chars` characters of the escaped text are kept ("..." marks a cut). Every reader
//! quotes file content through this, so no error line carries raw bytes or grows with the input.
inline std::string quote_input(std::string_view input, size_t max_chars = 200) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out = "'";
  size_t used = 0;
  for (const char c : input) {
    const auto b = static_cast<unsigned char>(c);
    const size_t width = b == '\\' ? 2 : (b >= 0x20 && b < 0x7f) ? 1 : 4;
    if (used + width > max_chars) {
      out += "...";
      break;
    }
    used += width;
    if (b == '\\') {
      out += "\\\\";
    } else if (width == 1) {
      out += c;
    } else {
      out += "\\x";
      out += kHex[b >> 4];
      out += kHex[b & 15];
    }
  }
  out += '\'';
  return out;
}

class TextScanner {
 public:
  TextScanner(const char* begin, const char* end) : p_(begin), end_(end) {}

  bool at_end() const { return p_ >= end_; }
  const char* pos() const { return p_; }
  const char* end() const { return end_; }
  size_t line() const { return line_; }
  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  //! "line N" for Status::error's `where`.
  std::string where() const { return "line " + std::to_string(line_); }

  //! When set, a backslash directly before a line end joins the two lines (OBJ continuation).
  void set_line_continuation(bool on) { continuation_ = on; }
  //! When set, '#' starts a comment running to the end of the line (OBJ, OFF).
  void set_hash_comments(bool on) { hash_comments_ = on; }

  //! Skips blanks (and continuations) on the current line; stops at '\n', a comment or the end.
  void skip_blanks() {
    while (p_ < end_) {
      const char c = *p_;
      if (is_blank(c)) {
        ++p_;
      } else if (continuation_ && c == '\\' && continuation_follows()) {
        skip_continuation();
      } else {
        break;
      }
    }
  }

  //! True when only blanks or a comment remain on the current line.
  bool at_line_end() {
    skip_blanks();
    return p_ >= end_ || *p_ == '\n' || (hash_comments_ && *p_ == '#');
  }

  //! Moves past the end of the current line (past '\n'), whatever it holds.
  void next_line() {
    while (p_ < end_) {
      const char c = *p_++;
      if (c == '\n') {
        ++line_;
        return;
      }
      if (continuation_ && c == '\\' && p_ < end_ && continuation_follows_at(p_ - 1)) {
        --p_;
        skip_continuation();
      }
    }
  }

  //! Skips blanks, line ends and comments: positions on the next token of the file, or the end.
  void skip_space() {
    for (;;) {
      skip_blanks();
      if (p_ >= end_) return;
      if (*p_ == '\n') {
        ++p_;
        ++line_;
      } else if (hash_comments_ && *p_ == '#') {
        next_line();
      } else {
        return;
      }
    }
  }

  //! The next run of non-blank characters on this line (empty at a line end), and moves past it.
  std::string_view word() {
    skip_blanks();
    const char* b = p_;
    while (p_ < end_ && !is_blank(*p_) && *p_ != '\n' && !(hash_comments_ && *p_ == '#')) ++p_;
    return {b, static_cast<size_t>(p_ - b)};
  }

  //! The first character of the next token on this line, or '\0' at a line end.
  char peek() {
    skip_blanks();
    return p_ < end_ ? *p_ : '\0';
  }

  //! True when the current position ends a token (blank, line end, comment, end of data).
  bool at_token_end() const { return ends_token(p_); }

  //! If the current position starts with `c`, consumes it and returns true.
  bool consume(char c) {
    if (p_ < end_ && *p_ == c) {
      ++p_;
      return true;
    }
    return false;
  }

  //! Parses a float on this line (after blanks). Accepts "nan"/"inf" (finalize_mesh rejects them).
  bool read_float(float& out) {
    skip_blanks();
    const char* b = p_;
    if (b < end_ && *b == '+') ++b;
    const auto r = fast_float::from_chars(b, end_, out);
    if (r.ptr == b || !ends_token(r.ptr)) return false;
    p_ = r.ptr;
    return true;
  }

  //! Parses a double on this line (after blanks).
  bool read_double(double& out) {
    skip_blanks();
    const char* b = p_;
    if (b < end_ && *b == '+') ++b;
    const auto r = fast_float::from_chars(b, end_, out);
    if (r.ptr == b || !ends_token(r.ptr)) return false;
    p_ = r.ptr;
    return true;
  }

  //! Parses a signed decimal integer on this line (after blanks); fails on overflow.
  //! When `whole_token` is false the number may be followed by any character (OBJ "3/1/2").
  bool read_int(int64_t& out, bool whole_token = true) {
    skip_blanks();
    const char* b = p_;
    if (b < end_ && *b == '+') ++b;
    const auto r = std::from_chars(b, end_, out);
    if (r.ec != std::errc() || r.ptr == b) return false;
    if (whole_token && !ends_token(r.ptr)) return false;
    p_ = r.ptr;
    return true;
  }

  //! Parses a non-negative integer on this line (after blanks); fails on overflow or a sign.
  bool read_uint(uint64_t& out) {
    skip_blanks();
    const char* b = p_;
    const auto r = std::from_chars(b, end_, out);
    if (r.ec != std::errc() || r.ptr == b || !ends_token(r.ptr)) return false;
    p_ = r.ptr;
    return true;
  }

 private:
  bool ends_token(const char* q) const {
    return q >= end_ || is_blank(*q) || *q == '\n' || (hash_comments_ && *q == '#') || (continuation_ && *q == '\\');
  }
  // A backslash at p_ followed by optional '\r' and '\n' (or the end of the file).
  bool continuation_follows() const { return continuation_follows_at(p_); }
  bool continuation_follows_at(const char* q) const {
    ++q;
    if (q < end_ && *q == '\r') ++q;
    return q >= end_ || *q == '\n';
  }
  void skip_continuation() {
    ++p_;
    if (p_ < end_ && *p_ == '\r') ++p_;
    if (p_ < end_ && *p_ == '\n') {
      ++p_;
      ++line_;
    }
  }

  const char* p_;
  const char* end_;
  size_t line_ = 1;
  bool continuation_ = false;
  bool hash_comments_ = false;
};

}  // namespace tailor::internal
