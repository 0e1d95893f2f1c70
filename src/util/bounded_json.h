// JSON parsed with its nesting bounded. nlohmann's parser keeps its own stack, but copying or
// printing a value recurses once per level: a file of 100,000 nested brackets (a few hundred KB)
// parses, then overflows the stack where the value is copied or printed (a glTF's extras, a
// material JSON's field quoted in an error). Every file or request the tools parse goes through
// here. The depth is counted in one pass over the text before the parse (a parser callback would
// do it too, but nlohmann's callback parser rescans a container's members each time an object in
// it closes: quadratic in an array of objects).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace tailor::internal {

//! Deeper than any glTF, material, stroke, tileset or edit request needs; far from the stack's limit.
inline constexpr int kMaxJsonDepth = 256;

//! What parse_json_bounded found.
enum class JsonParse { kOk, kInvalid, kTooDeep };

//! Whether arrays and objects in `text` nest more than `limit` levels, counted outside strings
//! (an invalid text is the parser's to refuse; this only bounds what it would build).
inline bool json_nests_deeper_than(std::string_view text, int limit) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // the escaped character, a quote included
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

//! Parses `text` into `out` without exceptions: kInvalid when it is not JSON, kTooDeep when arrays
//! and objects nest more than kMaxJsonDepth levels (out is discarded in both cases).
inline JsonParse parse_json_bounded(std::string_view text, nlohmann::json& out) {
  if (json_nests_deeper_than(text, kMaxJsonDepth)) {
    out = nlohmann::json(nlohmann::json::value_t::discarded);
    return JsonParse::kTooDeep;
  }
  out = nlohmann::json::parse(text, nullptr, false);
  return out.is_discarded() ? JsonParse::kInvalid : JsonParse::kOk;
}

//! The offset of the byte where `text` stops being JSON (a whole token that may not stand there:
//! its last byte; text.size() when it ends too early), or
//! SIZE_MAX when it is valid. For the error message only: a SAX pass that builds nothing, so a
//! deep or large text costs no memory.
inline size_t json_error_byte(std::string_view text) {
  struct Sax : nlohmann::json_sax<nlohmann::json> {
    size_t byte = SIZE_MAX;
    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool start_object(std::size_t) override { return true; }
    bool key(string_t&) override { return true; }
    bool end_object() override { return true; }
    bool start_array(std::size_t) override { return true; }
    bool end_array() override { return true; }
    bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception&) override {
      byte = position == 0 ? 0 : position - 1;  // nlohmann counts the characters read, the last one too
      return false;
    }
  } sax;
  nlohmann::json::sax_parse(text, &sax);
  return sax.byte;
}

//! The words an error says for a document that is not kOk.
inline std::string json_problem(JsonParse result) {
  return result == JsonParse::kTooDeep ? "JSON nested more than " + std::to_string(kMaxJsonDepth) + " levels deep"
                                       : "not valid JSON";
}

}  // namespace tailor::internal
