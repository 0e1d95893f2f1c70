// The HTTP API of `tailor edit` (edit_api.h, docs/edit-api.md).
#include "edit_api.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <thread>

#include "cli.h"
#include "tailor/axis_choice.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/texture_direction.h"
#include "util/atomic_file.h"
#include "util/bounded_json.h"
#include "util/shell_word.h"
#include "util/text_scan.h"

namespace tailor::cli {
namespace {

static_assert(std::endian::native == std::endian::little,
              "/api/uv and /api/mesh send little-endian arrays as they are");

using json = nlohmann::json;

HttpResponse json_answer(const json& j) {
  HttpResponse r;
  r.body = json_text(j, -1);
  return r;
}

json result_json(const EditResult& r) {
  return {{"version", r.version}, {"changed_faces", r.changed_faces}, {"ms", r.ms}, {"settled", r.settled}};
}

// A JSON value as a finite float; false otherwise.
bool as_float(const json& v, float& out) {
  if (!v.is_number()) return false;
  const double d = v.get<double>();
  if (!std::isfinite(d) || std::fabs(d) > 3.0e38) return false;
  out = static_cast<float>(d);
  return true;
}

// A JSON value as an unsigned integer in [lo, hi]; false otherwise.
bool as_uint(const json& v, uint64_t lo, uint64_t hi, uint32_t& out) {
  if (!v.is_number_unsigned()) return false;
  const uint64_t x = v.get<uint64_t>();
  if (x < lo || x > hi) return false;
  out = static_cast<uint32_t>(x);
  return true;
}

std::string field_name(const std::string& key) { return "options." + key; }

// Applies the "options" object of an edit to `options` (the session's current ones), as `tailor map`
// applies its flags. Returns "" or the reason it is refused.
std::string apply_options(const json& j, const EditContext& context, const std::vector<uint8_t>& seam_faces,
                          MapTextureOptions& options) {
  if (!j.is_object()) return "\"options\" must be an object";
  using L = MappingLimits;
  MappingOptions& m = options.mapping;
  OrientationOptions& o = options.orientation;
  bool auto_axis = false, auto_following = false;
  for (const auto& [key, v] : j.items()) {
    if (key == "axis") {
      if (!v.is_string()) return field_name(key) + " must be a string";
      const std::string text = v.get<std::string>();
      if (text == "auto") {
        auto_axis = true;
      } else if (Status s = parse_axis(text, o); !s) {
        return "options.axis must be pca, skeleton, auto, x, y, z or \"X,Y,Z\", got '" + text + "'";
      }
    } else if (key == "smooth_passes") {
      if (!as_uint(v, 0, OrientationLimits::max_smooth_passes, o.smooth_passes))
        return field_name(key) + " must be an integer 0.." + std::to_string(OrientationLimits::max_smooth_passes);
    } else if (key == "mode") {
      if (!v.is_string() || !mapping_mode_from_name(v.get<std::string>(), m.mode))
        return "options.mode must be \"patches\" or \"thesis\"";
    } else if (key == "scale") {
      if (!as_float(v, m.scale) || !(m.scale >= L::min_scale && m.scale <= L::max_scale))
        return field_name(key) + " must be a number of pixels per unit, " + limit_text(L::min_scale) + " to " +
               limit_text(L::max_scale);
    } else if (key == "max_stretch") {
      if (!as_float(v, m.max_stretch) || !(m.max_stretch >= L::min_max_stretch && m.max_stretch <= L::max_max_stretch))
        return field_name(key) + " must be a number in [" + limit_text(L::min_max_stretch) + ", " +
               limit_text(L::max_max_stretch) + "]";
    } else if (key == "field_following") {
      if (v.is_string() && v.get<std::string>() == "auto") {
        auto_following = true;
      } else if (!as_float(v, m.field_following) || !(m.field_following >= 0.f && m.field_following <= 1.f)) {
        return "options.field_following must be \"auto\" or a number in [0, 1]";
      }
    } else if (key == "min_patch_faces") {
      if (!as_uint(v, 0, UINT32_MAX, m.min_patch_faces)) return field_name(key) + " must be an unsigned integer";
    } else if (key == "hop_age") {
      if (!as_float(v, m.hop_age) || !(m.hop_age >= 0.f && m.hop_age <= L::max_hop_age))
        return field_name(key) + " must be a number of radians in [0, " + limit_text(L::max_hop_age) + "]";
    } else if (key == "shorten_seams" || key == "close_cracks") {
      if (!v.is_boolean()) return field_name(key) + " must be true or false";
      (key == "shorten_seams" ? m.shorten_seams : m.close_cracks) = v.get<bool>();
    } else if (key == "crack_rings") {
      if (!as_uint(v, L::min_crack_rings, L::max_crack_rings, m.crack_rings))
        return field_name(key) + " must be an integer " + std::to_string(L::min_crack_rings) + ".." +
               std::to_string(L::max_crack_rings);
    } else if (key == "relax_iterations") {
      if (!as_uint(v, 0, L::max_relax_iterations, m.relax_iterations))
        return field_name(key) + " must be an integer 0.." + std::to_string(L::max_relax_iterations);
    } else if (key == "threshold_px") {
      if (!as_float(v, m.threshold_px) || !(m.threshold_px > 0.f))
        return field_name(key) + " must be a positive number of pixels";
    } else if (key == "symmetry") {
      if (!as_uint(v, 1, 4, m.symmetry) || (m.symmetry != 1 && m.symmetry != 4))
        return "options.symmetry must be 1 or 4";
    } else if (key == "seed_point") {
      if (v.is_null()) {
        m.use_seed_point = false;
      } else {
        if (!v.is_array() || v.size() != 3) return "options.seed_point must be [x, y, z] or null";
        for (size_t k = 0; k < 3; ++k)
          if (!as_float(v[k], m.seed_point[k])) return "options.seed_point must hold three finite numbers";
        m.use_seed_point = true;
      }
    } else {
      return "unknown option '" + key + "'";
    }
  }
  // As tailor map refuses such flags: a key the resulting mode does not read would be taken and do
  // nothing. Only the keys this request gives are checked (the session's stored values stay), and
  // field_following "auto" passes, as tailor.map's default does.
  if (m.mode == MappingMode::kThesis) {
    for (const OptionDoc* doc : kPatchesOnlyOptions) {
      const std::string key(doc->field);
      if (j.contains(key) && !(auto_following && key == "field_following"))
        return field_name(key) +
               " has no effect in thesis mode (one UV per vertex, placed by threshold_px; no seam work)";
    }
  } else if (j.contains("threshold_px")) {
    return "options.threshold_px is read in thesis mode only (patches mode bounds its faces by max_stretch)";
  }
  if (Status s = check_map_options(options); !s) return s.message();
  const int width = context.output.texture_width, height = context.output.texture_height;
  if (Status s = set_map_texture_size(options, width, height); !s) return s.message();
  if (auto_following) {  // as `tailor map --field-following auto`: from the defaults, then the texture
    m.field_following = MappingOptions{}.field_following;
    if (!j.contains("crack_rings")) m.crack_rings = MappingOptions{}.crack_rings;
    const uint32_t rings = m.crack_rings;
    adapt_mapping_to_texture(context.texture, m);
    if (j.contains("crack_rings")) m.crack_rings = rings;
  }
  if (auto_axis) {  // resolved now, on the current seam faces, as `tailor map --axis auto` does
    MapTextureOptions probe = options;
    probe.mapping.seam_faces = seam_faces;
    AxisChoice choice;
    if (Status s = choose_orientation_axis(context.session->mesh(), context.topology, probe, choice); !s)
      return s.message();
    o = orientation_for(choice.best, o);
  }
  return {};
}

// For the requests that take nothing (undo, redo, save): an answer refusing a body other than
// none, whitespace or {}, else nothing.
std::optional<HttpResponse> body_refused(const HttpRequest& request) {
  if (request.body.find_first_not_of(" \t\r\n") == std::string::npos) return std::nullopt;
  json j;
  if (internal::parse_json_bounded(request.body, j) == internal::JsonParse::kOk && j.is_object() && j.empty())
    return std::nullopt;
  return HttpResponse::error(
      400, "POST " + request.path + " takes no body (or {}), got " + internal::quote_input(request.body.substr(0, 80)));
}

// Reads a JSON array of face ids into `out`; "" or the reason.
std::string face_list(const json& j, const char* key, std::vector<uint32_t>& out) {
  if (!j.is_array()) return std::string("\"") + key + "\" must be an array of face ids";
  out.reserve(j.size());
  for (const json& v : j) {
    if (!v.is_number_unsigned() || v.get<uint64_t>() > UINT32_MAX)
      return std::string("\"") + key + "\" must hold face ids (unsigned integers)";
    out.push_back(static_cast<uint32_t>(v.get<uint64_t>()));
  }
  return {};
}

// The strokes of an edit, read by the library's reader (the messages of `tailor map --strokes`).
std::string stroke_list(const json& j, std::vector<OrientationStroke>& out) {
  if (!j.is_array()) return "\"strokes\" must be an array";
  if (Status s = parse_strokes(json_text(json{{"strokes", j}}, -1), "strokes", out); !s) return s.message();
  return {};
}

// A float as the shortest decimal that reads back to it (0.02f is 0.02, not 0.0199999995529...).
json json_float(float x) { return json(std::strtod(float_text(x).c_str(), nullptr)); }

json options_json(const MapTextureOptions& options) {
  const MappingOptions& m = options.mapping;
  json j = {{"axis", axis_text(options.orientation)},
            {"smooth_passes", options.orientation.smooth_passes},
            {"mode", mapping_mode_name(m.mode)},
            {"scale", json_float(m.scale)},
            {"max_stretch", json_float(m.max_stretch)},
            {"field_following", json_float(m.field_following)},
            {"min_patch_faces", m.min_patch_faces},
            {"hop_age", json_float(m.hop_age)},
            {"shorten_seams", m.shorten_seams},
            {"close_cracks", m.close_cracks},
            {"crack_rings", m.crack_rings},
            {"relax_iterations", m.relax_iterations},
            {"threshold_px", json_float(m.threshold_px)},
            {"symmetry", m.symmetry}};
  j["seed_point"] = m.use_seed_point
                        ? json{json_float(m.seed_point[0]), json_float(m.seed_point[1]), json_float(m.seed_point[2])}
                        : json(nullptr);
  return j;
}

// The option keys the thesis mode does not read (kPatchesOnlyOptions): the page greys their inputs.
json patches_only_keys() {
  json keys = json::array();
  for (const OptionDoc* doc : kPatchesOnlyOptions) keys.push_back(doc->field);
  return keys;
}

json strokes_array(const std::vector<OrientationStroke>& strokes) {
  json list = json::array();
  for (const OrientationStroke& s : strokes) {
    json points = json::array();
    for (size_t i = 0; i + 2 < s.points.size(); i += 3)
      points.push_back({s.points[i], s.points[i + 1], s.points[i + 2]});
    list.push_back({{"points", std::move(points)}, {"radius", s.radius}});
  }
  return list;
}

Status read_file(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(ErrorCode::kIo, path, "cannot read the exported file");
  out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return Status::ok();
}

}  // namespace

std::string replay_command(const EditContext& c, const MapTextureOptions& options) {
  const MappingOptions& m = options.mapping;
  std::string cmd = "tailor map " + internal::shell_path(c.input);
  if (!c.texture_arg.empty())
    cmd += " --texture " + internal::shell_path(c.texture_arg);
  else
    cmd += " --texture-size " + std::to_string(c.output.texture_width);
  cmd +=
      " --seam-faces " + internal::shell_path(c.seam_faces_path) + " --strokes " + internal::shell_path(c.strokes_path);
  // Every mapping option the mode reads, explicitly (--field-following as a number: auto was
  // resolved when chosen).
  cmd += " --mode " + std::string(mapping_mode_name(m.mode)) + " --scale " + float_text(m.scale);
  if (m.mode == MappingMode::kThesis) {
    cmd += " --threshold " + float_text(m.threshold_px);
  } else {
    cmd += " --max-stretch " + float_text(m.max_stretch) + " --field-following " + float_text(m.field_following) +
           " --min-patch-faces " + std::to_string(m.min_patch_faces) + " --hop-age " + float_text(m.hop_age) +
           " --crack-rings " + std::to_string(m.crack_rings) + " --relax-iterations " +
           std::to_string(m.relax_iterations);
    if (!m.shorten_seams) cmd += " --no-seam-shortening";
    if (!m.close_cracks) cmd += " --no-crack-closing";
  }
  cmd += " --axis " + internal::shell_word(axis_text(options.orientation)) + " --smooth " +
         std::to_string(options.orientation.smooth_passes) + " --symmetry " + std::to_string(m.symmetry);
  // The session maps as map_texture does with its chunk options (chunked from the threshold on).
  const ChunkOptions& chunks = options.chunks;
  cmd += chunks.mode == ChunkMode::kOn    ? " --chunks on"
         : chunks.mode == ChunkMode::kOff ? " --chunks off"
                                          : " --chunks auto";
  if (chunks.cell_exponent != kAutoCellExponent) cmd += " --chunk-cell " + std::to_string(chunks.cell_exponent);
  if (m.use_seed_point)
    cmd += " --seed-point " + float_text(m.seed_point[0]) + "," + float_text(m.seed_point[1]) + "," +
           float_text(m.seed_point[2]);
  if (c.output.compression != MeshCompression::kNone)
    cmd += " --compress " + std::string(mesh_compression_name(c.output.compression));
  if (c.output.uv_set != 0) cmd += " --uv-set " + std::to_string(c.output.uv_set);
  if (c.output.up == SceneUp::kZ) cmd += " --up z";
  return cmd + " -o " + internal::shell_path(c.glb_path);
}

EditApi::EditApi(EditContext& context) : context_(context) {
  // GET /api/mesh: vertex count, face count (uint32), positions (float32), indices (uint32).
  const Mesh& mesh = context_.session->mesh();
  const auto v = static_cast<uint32_t>(mesh.vertex_count()), f = static_cast<uint32_t>(mesh.face_count());
  mesh_bytes_.resize(8 + 4 * mesh.positions.size() + 4 * mesh.indices.size());
  char* out = mesh_bytes_.data();
  std::memcpy(out, &v, 4);
  std::memcpy(out + 4, &f, 4);
  std::memcpy(out + 8, mesh.positions.data(), 4 * mesh.positions.size());
  std::memcpy(out + 8 + 4 * mesh.positions.size(), mesh.indices.data(), 4 * mesh.indices.size());
}

void EditApi::install(StaticServer& server) {
  server.add_handler("GET", "/api/state", [this](const HttpRequest&) { return state(); });
  server.add_handler("GET", "/api/mesh", [this](const HttpRequest&) {
    HttpResponse r;
    r.content_type = "application/octet-stream";
    r.body = mesh_bytes_;
    return r;
  });
  server.add_handler("GET", "/api/status", [this](const HttpRequest&) { return status(); });
  server.add_handler("GET", "/api/uv", [this](const HttpRequest& r) { return uv(r); });
  server.add_handler("GET", "/api/model.glb", [this](const HttpRequest&) { return model(); });
  server.add_handler("POST", "/api/edit", [this](const HttpRequest& r) { return edit(r); });
  // These take nothing: a body that asks for something (a key of /api/edit sent here by mistake)
  // is refused rather than ignored.
  const auto taking_nothing = [](auto answer) {
    return [answer](const HttpRequest& r) {
      if (std::optional<HttpResponse> refused = body_refused(r)) return *refused;
      return answer();
    };
  };
  server.add_handler("POST", "/api/undo", taking_nothing([this] { return undo_redo(false); }));
  server.add_handler("POST", "/api/redo", taking_nothing([this] { return undo_redo(true); }));
  server.add_handler("POST", "/api/save", taking_nothing([this] { return save(); }));
}

HttpResponse EditApi::edit(const HttpRequest& request) {
  json j;
  if (const auto parsed = internal::parse_json_bounded(request.body, j); parsed == internal::JsonParse::kTooDeep)
    return HttpResponse::error(400, "the body is " + internal::json_problem(parsed));
  if (j.is_discarded()) return HttpResponse::error(400, "the body is not JSON");
  if (!j.is_object()) return HttpResponse::error(400, "the body must be a JSON object");
  EditRequest edit;
  bool join = false;
  for (const auto& [key, v] : j.items()) {
    std::string reason;
    if (key == "join") {
      if (!v.is_boolean()) reason = "\"join\" must be true or false";
      join = v.is_boolean() && v.get<bool>();
    } else if (key == "add_seam_faces") {
      reason = face_list(v, "add_seam_faces", edit.add_seam_faces);
    } else if (key == "remove_seam_faces") {
      reason = face_list(v, "remove_seam_faces", edit.remove_seam_faces);
    } else if (key == "strokes") {
      reason = stroke_list(v, edit.strokes);
    } else if (key == "options") {
      Atlas atlas;
      std::vector<uint8_t> seam_faces;
      std::vector<OrientationStroke> strokes;
      MapTextureOptions options;
      context_.session->snapshot(atlas, seam_faces, strokes, options);
      reason = apply_options(v, context_, seam_faces, options);
      edit.options = options;
    } else {
      reason = "unknown key '" + key + "' (add_seam_faces, remove_seam_faces, strokes, options, join)";
    }
    if (!reason.empty()) return HttpResponse::error(400, reason);
  }
  EditResult result;
  {
    const std::lock_guard<std::mutex> lock(edit_mutex_);
    const uint64_t before = context_.session->version();
    if (Status s = context_.session->apply(edit, result); !s) {
      return HttpResponse::error(s.code() == ErrorCode::kInvalidArgument ? 400 : 500, s.message());
    }
    if (result.version != before) {  // a session step (an edit that changed nothing makes none)
      if (join && step_open_ && !undo_steps_.empty())
        ++undo_steps_.back();
      else
        undo_steps_.push_back(1);
      redo_steps_.clear();
      step_open_ = true;
    }
  }
  edited();
  return json_answer(result_json(result));
}

HttpResponse EditApi::undo_redo(bool redo) {
  EditResult result;
  {
    const std::lock_guard<std::mutex> lock(edit_mutex_);
    std::vector<uint32_t>& from = redo ? redo_steps_ : undo_steps_;
    std::vector<uint32_t>& to = redo ? undo_steps_ : redo_steps_;
    if (from.empty()) return HttpResponse::error(409, redo ? "nothing to redo" : "nothing to undo");
    step_open_ = false;
    const uint32_t steps = from.back();
    EditResult one;
    for (uint32_t i = 0; i < steps; ++i) {
      const Status s = redo ? context_.session->redo(one) : context_.session->undo(one);
      if (!s) return HttpResponse::error(s.code() == ErrorCode::kInvalidArgument ? 409 : 500, s.message());
      result.changed_faces += one.changed_faces;
      result.ms += one.ms;
    }
    result.version = one.version;
    result.settled = one.settled;
    from.pop_back();
    to.push_back(steps);
  }
  edited();
  return json_answer(result_json(result));
}

HttpResponse EditApi::status() const {
  return json_answer({{"version", context_.session->version()}, {"settled", context_.session->settled()}});
}

HttpResponse EditApi::state() const {
  Atlas atlas;
  std::vector<uint8_t> seam_faces;
  std::vector<OrientationStroke> strokes;
  MapTextureOptions options;
  const uint64_t version = context_.session->version();
  const bool settled = context_.session->settled();
  context_.session->snapshot(atlas, seam_faces, strokes, options);
  json marked = json::array();
  for (size_t f = 0; f < seam_faces.size(); ++f)
    if (seam_faces[f]) marked.push_back(f);
  const Mesh& mesh = context_.session->mesh();
  json j = {{"name", context_.name},
            {"faces", mesh.face_count()},
            {"vertices", mesh.vertex_count()},
            {"texture", context_.texture_url.empty() ? json(nullptr) : json(context_.texture_url)},
            {"texture_width", context_.output.texture_width},
            {"texture_height", context_.output.texture_height},
            {"version", version},
            {"settled", settled},
            {"options", options_json(options)},
            {"patches_only", patches_only_keys()},
            {"seam_faces", std::move(marked)},
            {"strokes", strokes_array(strokes)},
            {"output", context_.glb_path},
            {"seam_faces_file", context_.seam_faces_path},
            {"strokes_file", context_.strokes_path}};
  return json_answer(j);
}

HttpResponse EditApi::uv(const HttpRequest& request) const {
  uint64_t version = context_.session->version();
  std::string text;
  if (query_value(request.query, "version", text)) {
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), version);
    if (text.empty() || error != std::errc() || end != text.data() + text.size())
      return HttpResponse::error(400, "version must be an unsigned integer, got '" + text + "'");
  }
  std::vector<float> uvs;
  if (!context_.session->corner_uv_repeats(version, uvs))
    return HttpResponse::error(404, "version " + std::to_string(version) + " is not kept (only recent ones are)");
  HttpResponse r;
  r.content_type = "application/octet-stream";
  // &since=M: only the faces whose UVs differ from version M (count K, K face ids, 6K floats; header
  // X-Tailor-Delta: 1); all of them as without it when M is no longer kept.
  const std::lock_guard<std::mutex> lock(uv_mutex_);
  bool delta = false;
  std::vector<uint32_t> faces;
  if (query_value(request.query, "since", text)) {
    uint64_t since = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), since);
    if (text.empty() || error != std::errc() || end != text.data() + text.size())
      return HttpResponse::error(400, "since must be an unsigned integer, got '" + text + "'");
    std::vector<float> copy;
    const std::vector<float>* base = &uv_last_;  // the version served last: no copy out of the session
    if (since != uv_version_) base = context_.session->corner_uv_repeats(since, copy) ? &copy : nullptr;
    if (since != version && base != nullptr && base->size() == uvs.size()) {
      delta = true;
      for (size_t f = 0; 6 * f < uvs.size(); ++f)
        if (std::memcmp(&uvs[6 * f], &(*base)[6 * f], 24) != 0) faces.push_back(static_cast<uint32_t>(f));
    }
  }
  if (delta) {
    const auto count = static_cast<uint32_t>(faces.size());
    r.body.resize(4 + 4 * faces.size() + 24 * faces.size());
    char* out = r.body.data();
    std::memcpy(out, &count, 4);
    std::memcpy(out + 4, faces.data(), 4 * faces.size());
    out += 4 + 4 * faces.size();
    for (size_t i = 0; i < faces.size(); ++i) std::memcpy(out + 24 * i, &uvs[6 * faces[i]], 24);
    r.headers.emplace_back("X-Tailor-Delta", "1");
  } else {
    r.body.assign(reinterpret_cast<const char*>(uvs.data()), 4 * uvs.size());
  }
  r.headers.emplace_back("X-Tailor-Version", std::to_string(version));
  uv_version_ = version;
  uv_last_ = std::move(uvs);
  return r;
}

HttpResponse EditApi::model() {
  const std::lock_guard<std::mutex> lock(model_mutex_);
  Atlas atlas;
  std::vector<uint8_t> seam_faces;
  std::vector<OrientationStroke> strokes;
  MapTextureOptions options;
  const uint64_t before = context_.session->version();
  if (before != model_version_) {
    context_.session->snapshot(atlas, seam_faces, strokes, options);
    const std::string path = context_.scratch_dir + "/model.glb";
    MeshOutput output = context_.output;
    output.symmetry = options.mapping.symmetry;
    if (Status s = write_mapped_mesh(path, context_.session->mesh(), atlas, output); !s)
      return HttpResponse::error(500, s.message());
    if (Status s = read_file(path, model_bytes_); !s) return HttpResponse::error(500, s.message());
    std::remove(path.c_str());
    // Cached only when no edit slipped in between (the snapshot is then exactly `before`).
    model_version_ = context_.session->version() == before ? before : UINT64_MAX;
  }
  HttpResponse r;
  r.content_type = "model/gltf-binary";
  r.body = model_bytes_;
  r.headers.emplace_back("X-Tailor-Version", std::to_string(before));
  return r;
}

bool EditApi::settled_snapshot(Atlas& atlas, std::vector<uint8_t>& seam_faces, std::vector<OrientationStroke>& strokes,
                               MapTextureOptions& options, uint64_t& version) {
  for (int attempt = 0; attempt < 8; ++attempt) {
    if (!context_.session->settled()) {
      EditResult result;
      if (Status s = context_.session->settle(result); !s) return false;
      if (!result.settled) continue;
    }
    version = context_.session->version();
    context_.session->snapshot(atlas, seam_faces, strokes, options);
    if (context_.session->version() == version && context_.session->settled()) return true;
  }
  return false;
}

HttpResponse EditApi::save() {
  Atlas atlas;
  std::vector<uint8_t> seam_faces;
  std::vector<OrientationStroke> strokes;
  MapTextureOptions options;
  uint64_t version = 0;
  if (!settled_snapshot(atlas, seam_faces, strokes, options, version))
    return HttpResponse::error(409, "edits keep coming in: save again once they stop");
  std::string faces = "# tailor edit: seam faces of " + context_.name + " (tailor map --seam-faces)\n";
  for (size_t f = 0; f < seam_faces.size(); ++f)
    if (seam_faces[f]) faces += std::to_string(f) + "\n";
  const std::string stroke_text = strokes_json(strokes) + "\n";
  // The three files land together or not at all.
  internal::FileBatch batch;
  MeshOutput output = context_.output;
  output.symmetry = options.mapping.symmetry;
  if (Status s = write_mapped_mesh(context_.glb_path, context_.session->mesh(), atlas, output); !s)
    return HttpResponse::error(500, s.message());
  if (Status s = internal::write_file_atomic(context_.seam_faces_path, faces); !s)
    return HttpResponse::error(500, s.message());
  if (Status s = internal::write_file_atomic(context_.strokes_path, stroke_text); !s)
    return HttpResponse::error(500, s.message());
  if (Status s = batch.commit(); !s) return HttpResponse::error(500, s.message());
  const std::string command = replay_command(context_, options);
  if (!context_.quiet)
    std::fprintf(stderr, "tailor edit: saved version %llu; replay: %s\n", static_cast<unsigned long long>(version),
                 command.c_str());
  return json_answer({{"version", version},
                      {"glb", context_.glb_path},
                      {"seam_faces", context_.seam_faces_path},
                      {"strokes", context_.strokes_path},
                      {"command", command}});
}

void EditApi::edited() {
  {
    const std::lock_guard<std::mutex> lock(settle_mutex_);
    last_edit_ = std::chrono::steady_clock::now();
    settle_pending_ = true;
  }
  settle_wake_.notify_one();
}

void EditApi::wake() { settle_wake_.notify_all(); }

void EditApi::run_settler(const std::atomic<bool>& stop) {
  std::unique_lock<std::mutex> lock(settle_mutex_);
  while (!stop.load()) {
    if (!settle_pending_) {
      settle_wake_.wait_for(lock, std::chrono::milliseconds(200));
      continue;
    }
    const auto due = last_edit_ + kSettlePause;
    if (std::chrono::steady_clock::now() < due) {
      settle_wake_.wait_until(lock, due);
      continue;  // an edit may have moved the due time
    }
    settle_pending_ = false;
    lock.unlock();
    // A settle cancelled by a new edit is retried after that edit's pause (it set settle_pending_).
    if (!context_.session->settled()) {
      EditResult result;
      if (Status s = context_.session->settle(result); !s) warn(context_.quiet, "settle failed: " + s.message());
    }
    lock.lock();
  }
}

}  // namespace tailor::cli
