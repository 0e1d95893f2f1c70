// load_material (material.h): finds the maps, checks them, and builds the glTF images.
#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "tailor/material.h"
#include "util/atomic_file.h"
#include "util/bounded_json.h"
#include "util/text_scan.h"

namespace tailor {
namespace {

constexpr int kRoles = 7;
const char* role_name(MaterialRole r) {
  static const char* kNames[kRoles] = {"none", "color", "normal", "roughness", "metallic", "occlusion", "height"};
  return kNames[static_cast<int>(r)];
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The role of a JSON key or "role"/"type" value: a role word as in file names.
MaterialRole role_from_word(const std::string& word, bool* directx) { return material_role_from_name(word, directx); }

struct Found {
  std::string path;
  bool directx = false;
};

}  // namespace

MaterialRole material_role_from_name(const std::string& file_name, bool* directx) {
  std::string stem = lower(std::filesystem::path(file_name).stem().string());
  for (char& c : stem)
    if (c == '-' || c == '.' || c == ' ') c = '_';
  struct Word {
    const char* text;
    MaterialRole role;
    bool dx;
  };
  static const Word kWords[] = {
      {"base_color", MaterialRole::kColor, false},
      {"basecolor", MaterialRole::kColor, false},
      {"base_colour", MaterialRole::kColor, false},
      {"albedo", MaterialRole::kColor, false},
      {"diffuse", MaterialRole::kColor, false},
      {"colour", MaterialRole::kColor, false},
      {"color", MaterialRole::kColor, false},
      {"col", MaterialRole::kColor, false},
      {"normal_gl", MaterialRole::kNormal, false},
      {"normalgl", MaterialRole::kNormal, false},
      {"normal_dx", MaterialRole::kNormal, true},
      {"normaldx", MaterialRole::kNormal, true},
      {"normal_directx", MaterialRole::kNormal, true},
      {"normal_opengl", MaterialRole::kNormal, false},
      {"normal", MaterialRole::kNormal, false},
      {"nor_gl", MaterialRole::kNormal, false},
      {"nor_dx", MaterialRole::kNormal, true},
      {"nor", MaterialRole::kNormal, false},
      {"nrm", MaterialRole::kNormal, false},
      {"roughness", MaterialRole::kRoughness, false},
      {"rough", MaterialRole::kRoughness, false},
      {"metallic", MaterialRole::kMetallic, false},
      {"metalness", MaterialRole::kMetallic, false},
      {"metal", MaterialRole::kMetallic, false},
      {"ambientocclusion", MaterialRole::kOcclusion, false},
      {"ambient_occlusion", MaterialRole::kOcclusion, false},
      {"occlusion", MaterialRole::kOcclusion, false},
      {"ao", MaterialRole::kOcclusion, false},
      {"displacement", MaterialRole::kHeight, false},
      {"disp", MaterialRole::kHeight, false},
      {"height", MaterialRole::kHeight, false},
      {"bump", MaterialRole::kHeight, false},
  };
  for (const Word& w : kWords) {
    const std::string text = w.text;
    if (stem.size() < text.size() || stem.compare(stem.size() - text.size(), text.size(), text) != 0) continue;
    if (stem.size() > text.size() && stem[stem.size() - text.size() - 1] != '_') continue;
    if (directx) *directx = w.dx;
    return w.role;
  }
  return MaterialRole::kNone;
}

namespace {

//! The JSON in the file at `path` (discarded when it does not parse or nests too deep, which
//! `result` then says). read_file's error when it cannot be read: missing, a directory, or not a
//! regular file (a FIFO would block the read until a writer came).
Status read_json(const std::string& path, nlohmann::json& out, internal::JsonParse* result = nullptr) {
  std::string text;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, text));
  const internal::JsonParse parsed = internal::parse_json_bounded(text, out);
  if (result) *result = parsed;
  return Status::ok();
}

//! The "symmetry" a material JSON records (`tailor tile --set` writes 1 or 4), into `symmetry`;
//! left as it is when the JSON has none.
Status read_symmetry(const nlohmann::json& j, const std::string& file, int& symmetry) {
  if (!j.contains("symmetry")) return Status::ok();
  const nlohmann::json& value = j["symmetry"];
  if (!value.is_number_integer() || (value.get<int>() != 1 && value.get<int>() != 4))
    return Status::error(
        ErrorCode::kInvalidArgument, file, "\"symmetry\" must be 1 or 4",
        value.is_primitive() ? internal::quote_input(value.dump(), 40) : std::string(value.type_name()));
  symmetry = value.get<int>();
  return Status::ok();
}

}  // namespace

Status load_material(const std::string& dir_or_json, MaterialMaps& out, const ImageLoadOptions& options) {
  out = {};
  namespace fs = std::filesystem;
  std::array<Found, kRoles> found;
  bool directx = false;
  // Records a map for a role; two files for one role is an error naming both.
  auto claim = [&](MaterialRole role, const std::string& path, bool dx) -> Status {
    Found& f = found[static_cast<size_t>(role)];
    if (!f.path.empty())
      return Status::error(ErrorCode::kInvalidArgument, dir_or_json,
                           std::string("two files claim the ") + role_name(role) + " map: " + f.path + " and " + path);
    f = {path, dx};
    return Status::ok();
  };
  std::error_code ec;
  if (fs::is_directory(dir_or_json, ec)) {
    std::vector<std::string> names;
    for (const fs::directory_entry& e : fs::directory_iterator(dir_or_json, ec)) {
      const std::string ext = lower(e.path().extension().string());
      if (e.is_regular_file(ec) && (ext == ".png" || ext == ".jpg" || ext == ".jpeg"))
        names.push_back(e.path().filename().string());
    }
    if (ec) return Status::error(ErrorCode::kIo, dir_or_json, "cannot list the folder");
    // The folder of `tailor tile --set`: its material.json says whether the maps are quarter-turn
    // tiles (the maps themselves are found by name, as in any folder).
    const std::string record = dir_or_json + "/material.json";
    nlohmann::json j;
    if (fs::exists(fs::status(record, ec))) {  // absent (or a dangling link): no record
      TAILOR_RETURN_IF_ERROR(read_json(record, j));
      if (!j.is_discarded() && j.is_object()) TAILOR_RETURN_IF_ERROR(read_symmetry(j, record, out.symmetry));
    }
    std::sort(names.begin(), names.end());  // deterministic whatever the listing order
    for (const std::string& name : names) {
      bool dx = false;
      const MaterialRole role = material_role_from_name(name, &dx);
      if (role != MaterialRole::kNone) TAILOR_RETURN_IF_ERROR(claim(role, dir_or_json + "/" + name, dx));
    }
  } else {
    nlohmann::json j;
    internal::JsonParse parsed = internal::JsonParse::kOk;
    if (!fs::exists(fs::symlink_status(dir_or_json, ec)))
      return Status::error(ErrorCode::kIo, dir_or_json, "cannot open the material (a folder of maps or a JSON)");
    TAILOR_RETURN_IF_ERROR(read_json(dir_or_json, j, &parsed));
    if (parsed == internal::JsonParse::kTooDeep)
      return Status::error(ErrorCode::kInvalidArgument, dir_or_json, internal::json_problem(parsed));
    if (j.is_discarded() || !j.is_object())
      return Status::error(
          ErrorCode::kInvalidArgument, dir_or_json,
          "not a material JSON (expected {\"color\": \"a.png\", \"normal\": ...} or {\"maps\": [...]})");
    const std::string dir = fs::path(dir_or_json).parent_path().string();
    auto resolve = [&](std::string file) {
      return file.empty() || file[0] == '/' || dir.empty() ? file : dir + "/" + file;
    };
    if (j.contains("normal_convention") && j["normal_convention"].is_string()) {
      const std::string c = j["normal_convention"].get<std::string>();
      if (c != "gl" && c != "dx")
        return Status::error(ErrorCode::kInvalidArgument, dir_or_json, "normal_convention must be \"gl\" or \"dx\"");
      directx = c == "dx";
    }
    TAILOR_RETURN_IF_ERROR(read_symmetry(j, dir_or_json, out.symmetry));
    if (j.contains("maps") && j["maps"].is_array()) {  // tailor tile --set's material.json
      for (size_t i = 0; i < j["maps"].size(); ++i) {
        const nlohmann::json& m = j["maps"][i];
        if (!m.is_object() || !m.contains("file") || !m["file"].is_string())
          return Status::error(ErrorCode::kInvalidArgument, dir_or_json, "map without a \"file\" string",
                               "maps[" + std::to_string(i) + "]");
        const std::string file = m["file"].get<std::string>();
        bool dx = false;
        MaterialRole role = material_role_from_name(file, &dx);
        for (const char* key : {"role", "type"})
          if (m.contains(key) && m[key].is_string()) role = role_from_word(m[key].get<std::string>(), &dx);
        if (m.contains("normal") && m["normal"].is_boolean() && m["normal"].get<bool>()) role = MaterialRole::kNormal;
        if (role == MaterialRole::kNone)
          return Status::error(ErrorCode::kInvalidArgument, dir_or_json,
                               "no role for " + file + " (give \"role\": \"color\", \"normal\", \"roughness\", ...)");
        TAILOR_RETURN_IF_ERROR(claim(role, resolve(file), dx));
      }
    } else {
      for (const auto& [key, value] : j.items()) {
        if (key == "normal_convention" || key == "symmetry" || key == "width" ||
            (key == "height" && !value.is_string()))
          continue;
        bool dx = false;
        const MaterialRole role = role_from_word(key, &dx);
        if (role == MaterialRole::kNone)
          return Status::error(ErrorCode::kInvalidArgument, dir_or_json,
                               "unknown entry \"" + key +
                                   "\" (expected color, normal, roughness, metallic, "
                                   "occlusion or height naming a file)");
        if (!value.is_string())
          return Status::error(
              ErrorCode::kInvalidArgument, dir_or_json,
              "entry \"" + key + "\" must name a file (a string), not a " + std::string(value.type_name()));
        TAILOR_RETURN_IF_ERROR(claim(role, resolve(value.get<std::string>()), dx));
      }
    }
  }
  auto has = [&](MaterialRole r) { return !found[static_cast<size_t>(r)].path.empty(); };
  bool any = false;
  for (size_t r = 1; r < kRoles; ++r) any = any || !found[r].path.empty();
  if (!any)
    return Status::error(ErrorCode::kInvalidArgument, dir_or_json,
                         "no map recognised (name them NAME_color.png, NAME_normal.png, NAME_roughness.png, "
                         "NAME_metallic.png, NAME_ao.png, NAME_height.png)");

  // Every map is read (a broken height map is reported too) and must share the colour map's size.
  std::array<Image16, kRoles> images;
  std::string size_from;
  for (size_t r = 1; r < kRoles; ++r) {
    if (found[r].path.empty()) continue;
    TAILOR_RETURN_IF_ERROR(load_image16(found[r].path, images[r], options));
    out.files.push_back(std::string(role_name(static_cast<MaterialRole>(r))) + ": " + found[r].path);
  }
  for (size_t r = 1; r < kRoles; ++r) {  // the colour map first: it sets the size
    if (found[r].path.empty()) continue;
    if (size_from.empty()) {
      out.width = images[r].width;
      out.height = images[r].height;
      size_from = found[r].path;
    } else if (images[r].width != out.width || images[r].height != out.height) {
      return Status::error(ErrorCode::kInvalidArgument, found[r].path,
                           "map is " + std::to_string(images[r].width) + "x" + std::to_string(images[r].height) +
                               " but " + size_from + " is " + std::to_string(out.width) + "x" +
                               std::to_string(out.height) + " (all maps of a material must share one size)");
    }
  }
  out.color = found[static_cast<size_t>(MaterialRole::kColor)].path;
  if (has(MaterialRole::kHeight))
    out.notes.push_back(found[static_cast<size_t>(MaterialRole::kHeight)].path +
                        ": height map not embedded (glTF has no core height/displacement map)");

  const size_t pixels = static_cast<size_t>(out.width) * static_cast<size_t>(out.height);
  if (has(MaterialRole::kNormal)) {
    const Image16& n = images[static_cast<size_t>(MaterialRole::kNormal)];
    const bool dx = directx || found[static_cast<size_t>(MaterialRole::kNormal)].directx;
    if (n.channels < 3)
      return Status::error(ErrorCode::kInvalidArgument, found[static_cast<size_t>(MaterialRole::kNormal)].path,
                           "a normal map needs RGB channels");
    Image16 gl;
    gl.width = n.width;
    gl.height = n.height;
    gl.channels = 3;
    gl.bits = n.bits;
    gl.pixels.resize(3 * pixels);
    const uint16_t top = static_cast<uint16_t>((1 << n.bits) - 1);
    for (size_t i = 0; i < pixels; ++i) {
      const uint16_t* s = &n.pixels[size_t(n.channels) * i];
      gl.pixels[3 * i] = s[0];
      gl.pixels[3 * i + 1] = dx ? static_cast<uint16_t>(top - s[1]) : s[1];  // DirectX's green points down
      gl.pixels[3 * i + 2] = s[2];
    }
    TAILOR_RETURN_IF_ERROR(encode_png16(gl, out.textures.normal_png));
    out.normal_image = to_image8(gl);
  }
  const bool rough = has(MaterialRole::kRoughness), metal = has(MaterialRole::kMetallic),
             ao = has(MaterialRole::kOcclusion);
  if (rough || metal || ao) {
    // One RGB image in glTF's packing; 16 bits when any of its sources has 16.
    int bits = 8;
    for (MaterialRole r : {MaterialRole::kRoughness, MaterialRole::kMetallic, MaterialRole::kOcclusion})
      if (has(r)) bits = std::max(bits, images[static_cast<size_t>(r)].bits);
    Image16 orm;
    orm.width = out.width;
    orm.height = out.height;
    orm.channels = 3;
    orm.bits = bits;
    const uint16_t top = static_cast<uint16_t>((1 << bits) - 1);
    orm.pixels.resize(3 * pixels);
    // A missing map: occlusion none (1), roughness 1 (the factor's default), metallic 0.
    const uint16_t fill[3] = {top, top, 0};
    const MaterialRole channel_role[3] = {MaterialRole::kOcclusion, MaterialRole::kRoughness, MaterialRole::kMetallic};
    for (int c = 0; c < 3; ++c) {
      const Image16& src = images[static_cast<size_t>(channel_role[c])];
      const uint16_t scale = src.empty() || src.bits == bits ? 1 : 257;  // 8 -> 16 bits
      for (size_t i = 0; i < pixels; ++i)
        orm.pixels[3 * i + size_t(c)] =
            src.empty() ? fill[c] : static_cast<uint16_t>(src.pixels[size_t(src.channels) * i] * scale);
    }
    TAILOR_RETURN_IF_ERROR(encode_png16(orm, out.textures.orm_png));
    if (ao) {
      const Image16& src = images[static_cast<size_t>(MaterialRole::kOcclusion)];
      Image16 r{src.width, src.height, 1, src.bits, std::vector<uint16_t>(pixels)};
      for (size_t i = 0; i < pixels; ++i) r.pixels[i] = src.pixels[size_t(src.channels) * i];
      out.occlusion_image = to_image8(r);
    }
    out.textures.orm_roughness_metallic = rough || metal;
    out.textures.orm_occlusion = ao;
  }
  return Status::ok();
}

Status write_tile_set_record(const std::string& folder, const TileSetRecord& record) {
  nlohmann::json material;
  material["normal_convention"] = record.normal_convention;
  material["symmetry"] = record.symmetry;  // 4: `tailor map --material` maps with --symmetry 4
  material["maps"] = nlohmann::json::array();
  for (const TileSetRecord::Map& map : record.maps) {
    nlohmann::json entry;
    entry["file"] = map.file;
    entry["source"] = map.source;
    entry["normal"] = map.normal;
    if (map.normal && map.directx) entry["role"] = "normal_dx";  // load_material reads it so
    entry["bits"] = map.bits;
    entry["channels"] = map.channels;
    if (!map.variants.empty()) entry["variants"] = map.variants;
    material["maps"].push_back(entry);
  }
  material["width"] = record.width;
  material["height"] = record.height;
  return internal::write_file_atomic(folder + "/material.json",
                                     material.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

}  // namespace tailor
