// tailor: the user-facing text of the library's options, shared by the tailor CLI and bindings.
//
// The rule: an option's default is the default member initialiser of its field in the library's
// options struct (MappingOptions, OrientationOptions, StabilityOptions, TileOptions,
// RenderOptions...) and nowhere else; its help text is one entry of the table of OptionDoc next to
// that struct (kMappingOptionDocs...). The CLI registers each flag with that text and shows the
// default by reading a default-constructed struct; a Python module or a Blender add-on can take
// its doc strings and tooltips from the same tables. The texts never state a default.
#pragma once

#include <span>
#include <string_view>

namespace tailor {

//! One user-facing option of an options struct.
struct OptionDoc {
  std::string_view field;  //!< the member it sets ("max_stretch"); for a flag that sets several (--axis:
                           //!< axis and user_axis; --size: width and height), the first
  std::string_view flag;   //!< the tailor CLI flag ("--max-stretch"); a switch for a field that is on by
                           //!< default turns it off ("--no-crack-closing")
  std::string_view help;   //!< what it does, its unit and range (never its default)
};

//! The entry of `field` in `docs`. consteval: a field missing from the table does not compile.
consteval const OptionDoc& option_doc(std::span<const OptionDoc> docs, std::string_view field) {
  for (const OptionDoc& doc : docs)
    if (doc.field == field) return doc;
  throw "option_doc: no such field in this table";  // not a constant expression: a compile error
}

}  // namespace tailor
