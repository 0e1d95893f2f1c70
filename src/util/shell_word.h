// A word as a POSIX shell reads it back: the commands tailor prints for the user to paste (the
// `tailor tile` a warning suggests, `tailor edit`'s replay command).
#pragma once

#include <cctype>
#include <cstring>
#include <string>

namespace tailor::internal {

//! `word` itself when every character is one a shell leaves alone, else single-quoted (a quote
//! inside as '\'').
inline std::string shell_word(const std::string& word) {
  bool plain = !word.empty();
  for (const char c : word)
    plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || std::strchr("/._-+,=:@%", c) != nullptr);
  if (plain) return word;
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

//! A path as a word of a command: shell_word, with "./" before a relative path that starts with
//! '-' (the command would read it as an option).
inline std::string shell_path(const std::string& path) {
  return shell_word(!path.empty() && path[0] == '-' ? "./" + path : path);
}

}  // namespace tailor::internal
