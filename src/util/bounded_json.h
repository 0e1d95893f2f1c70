// JSON parsed with its nesting bounded. nlohmann's parser keeps its own stack, but copying or
// printing a value recurses once per level: a file of 100,000 nested brackets (a few hundred KB)
// parses, then overflows the stack where the value is copied or printed (a glTF's extras, a
// material JSON's field quoted in an error). Every file or request the tools parse goes through
// here.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>

namespace tailor::internal {

//! Deeper than any glTF, material, stroke, tileset or edit request needs; far from the stack's limit.
inline constexpr int kMaxJsonDepth = 256;

//! What parse_json_bounded found.
enum class JsonParse { kOk, kInvalid, kTooDeep };

namespace json_detail {
template <class Parse>
JsonParse parse_bounded(Parse&& parse, nlohmann::json& out) {
  bool too_deep = false;
  // A value deeper than the bound is dropped as it is read (the callback's false), so the document
  // built stays shallow whatever the input holds.
  out = parse([&too_deep](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > kMaxJsonDepth) too_deep = true;
    return depth <= kMaxJsonDepth;
  });
  if (too_deep) {
    out = nlohmann::json(nlohmann::json::value_t::discarded);
    return JsonParse::kTooDeep;
  }
  return out.is_discarded() ? JsonParse::kInvalid : JsonParse::kOk;
}
}  // namespace json_detail

//! Parses `input` (a string, a string_view or a stream) into `out` without exceptions: kInvalid
//! when it is not JSON, kTooDeep when arrays and objects nest more than kMaxJsonDepth levels (out
//! is discarded in both cases).
template <class Input>
JsonParse parse_json_bounded(Input&& input, nlohmann::json& out) {
  return json_detail::parse_bounded(
      [&input](auto callback) { return nlohmann::json::parse(std::forward<Input>(input), callback, false); }, out);
}

//! The same over the characters [first, last).
template <class Iterator>
JsonParse parse_json_bounded(Iterator first, Iterator last, nlohmann::json& out) {
  return json_detail::parse_bounded(
      [first, last](auto callback) { return nlohmann::json::parse(first, last, callback, false); }, out);
}

//! The words an error says for a document that is not kOk.
inline std::string json_problem(JsonParse result) {
  return result == JsonParse::kTooDeep ? "JSON nested more than " + std::to_string(kMaxJsonDepth) + " levels deep"
                                       : "not valid JSON";
}

}  // namespace tailor::internal
