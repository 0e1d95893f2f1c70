// Shared pieces of the reports (tailor/report.h): JSON text that never throws, printf-style
// formatting into a string.
#pragma once

#include <cstdarg>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

namespace tailor::internal {

//! Indented JSON text plus a newline; bytes that are not UTF-8 (file names can hold any) become U+FFFD.
inline std::string json_text(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

//! std::string of printf(format, ...).
__attribute__((format(printf, 1, 2))) inline std::string format_text(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(size > 0 ? static_cast<size_t>(size) : 0, '\0');
  if (size > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  return text;
}

//! A count and its noun, singular for exactly one: counted(1, "patch", "patches") is "1 patch".
inline std::string counted(unsigned long long n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

//! Milliseconds of a time in seconds.
inline double ms(double seconds) { return seconds * 1e3; }

}  // namespace tailor::internal
