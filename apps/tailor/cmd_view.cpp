// tailor view: serve the web viewer (web/, three.js) and one .glb, or a 3D Tiles tileset and its
// folder, on 127.0.0.1 until Ctrl-C.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli.h"
#include "http_server.h"
#include "io/glb_format.h"
#include "tailor/image.h"
#include "util/atomic_file.h"
#include "util/bounded_json.h"

namespace tailor::cli {
namespace {

// Shader samplers the viewer sets aside for tile variants (web/viewer.js, kMaxVariants).
constexpr size_t kMaxVariants = 8;

struct ViewArgs {
  std::string input;
  std::string texture;
  std::string web_root;
  int port = 0;
  bool quiet = false;
};

bool file_exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

//! Cheap check that `path` is a binary glTF 2.0 file, so a wrong file fails here with one line
//! rather than in the browser.
Status check_glb(const std::string& path) {
  // A directory, FIFO or device gets the readers' own line (open_input), not "not a glTF file".
  int fd = -1;
  size_t size = 0;
  TAILOR_RETURN_IF_ERROR(internal::open_input(path, fd, size));
  std::array<unsigned char, 12> head{};
  const bool read = size >= 12 && ::read(fd, head.data(), head.size()) == static_cast<ssize_t>(head.size());
  ::close(fd);
  if (!read) {
    return Status::error(ErrorCode::kParse, path, "not a binary glTF file", "shorter than its 12-byte header");
  }
  const auto u32 = [&](size_t at) { return internal::load_u32(head.data() + at); };
  if (u32(0) != internal::kGlbMagic)
    return Status::error(ErrorCode::kParse, path, "not a binary glTF file", "bad magic");
  if (u32(4) != 2) return Status::error(ErrorCode::kUnsupported, path, "only glTF 2.0 is supported", "version field");
  if (u32(8) > size) return Status::error(ErrorCode::kParse, path, "truncated glTF file", "header length exceeds file");
  return Status::ok();
}

//! Adds routes and config entries for --texture: one image, or a variants.json from `tailor tile --variants`.
Status add_texture(const std::string& path, std::vector<Route>& routes, nlohmann::json& config, bool quiet) {
  const std::string ext = extension_of(path);
  if (ext != "json") {
    Image probe;
    TAILOR_RETURN_IF_ERROR(load_image(path, probe).with_file(path));
    const std::string url = "/files/texture." + ext;
    routes.push_back({url, path, "", ""});
    config["texture"] = url;
    return Status::ok();
  }
  std::string text;  // read_file: a FIFO or device is refused, not waited on
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, text));
  nlohmann::json j;
  if (const auto parsed = internal::parse_json_bounded(text, j); parsed == internal::JsonParse::kTooDeep)
    return Status::error(ErrorCode::kParse, path, internal::json_problem(parsed));
  if (j.is_discarded() || !j.is_object()) return Status::error(ErrorCode::kParse, path, "not a JSON object");
  if (!j.contains("files") || !j["files"].is_array() || j["files"].empty()) {
    return Status::error(ErrorCode::kParse, path, "no \"files\" list of tile variants");
  }
  nlohmann::json urls = nlohmann::json::array();
  const std::string dir = dir_name(path);
  size_t k = 0;
  for (const auto& f : j["files"]) {
    if (!f.is_string()) return Status::error(ErrorCode::kParse, path, "\"files\" must hold file names");
    if (k == kMaxVariants) {
      warn(quiet, path + ": the viewer uses the first " + std::to_string(kMaxVariants) + " variants");
      break;
    }
    const std::string name = f.get<std::string>();
    const std::string file = !name.empty() && name[0] == '/' ? name : dir + "/" + name;
    Image probe;
    TAILOR_RETURN_IF_ERROR(load_image(file, probe).with_file(file));
    const std::string url = "/files/variant_" + std::to_string(k) + "." + extension_of(file);
    routes.push_back({url, file, "", ""});
    urls.push_back(url);
    ++k;
  }
  const uint64_t seed = j.contains("seed") && j["seed"].is_number_unsigned() ? j["seed"].get<uint64_t>() : 1;
  config["variants"] = {{"files", urls}, {"seed", seed % 4294967296u}};
  return Status::ok();
}

//! The image files a .glb names by relative URI (a tile of `python3 -m tailor.tiles` names the
//! texture beside it): each served under /files/ where the page's loader asks for it, beside
//! /files/model.glb, unless a route has that URL already (the model, --texture's image). Only
//! files in or below the .glb's folder, by the reader's own rule; a JSON chunk that does not parse
//! names none (the model itself then fails in the page).
void add_glb_images(const std::string& path, std::vector<Route>& routes) {
  namespace fs = std::filesystem;
  constexpr size_t kMaxJsonChunk = size_t{64} << 20;
  std::string head;
  if (!internal::read_file_head(path, 20, head).is_ok() || head.size() < 20) return;
  const auto u32 = [&](size_t at) {
    return internal::load_u32(reinterpret_cast<const unsigned char*>(head.data()) + at);
  };
  const size_t length = u32(12);
  if (u32(16) != internal::kChunkJson || length > kMaxJsonChunk) return;
  std::string text;
  if (!internal::read_file_head(path, 20 + length, text).is_ok() || text.size() < 20 + length) return;
  nlohmann::json gltf;
  if (internal::parse_json_bounded(std::string_view(text).substr(20, length), gltf) != internal::JsonParse::kOk ||
      !gltf.is_object() || !gltf.contains("images") || !gltf["images"].is_array())
    return;
  const fs::path folder = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : fs::path(".");
  for (const nlohmann::json& image : gltf["images"]) {
    if (!image.is_object() || !image.contains("uri") || !image["uri"].is_string()) continue;
    std::string relative;
    if (!internal::relative_file_uri(image["uri"].get<std::string>(), relative)) continue;
    const std::string url = "/files/" + relative;
    if (std::any_of(routes.begin(), routes.end(), [&](const Route& r) { return r.url_path == url; })) continue;
    std::error_code error;
    const fs::path file = folder / relative;
    if (fs::is_regular_file(file, error)) routes.push_back({url, file.string(), "", ""});
  }
}

//! A 3D Tiles tileset (a tileset.json, e.g. from `python3 -m tailor.tiles`): the files in its
//! folder and below (tile contents, the shared texture) are served under /tileset/, as the
//! tileset names them; hidden files and folders are not.
Status add_tileset(const std::string& path, std::vector<Route>& routes, nlohmann::json& config) {
  namespace fs = std::filesystem;
  std::string text;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, text));
  nlohmann::json tileset;
  if (const auto parsed = internal::parse_json_bounded(text, tileset); parsed == internal::JsonParse::kTooDeep)
    return Status::error(ErrorCode::kParse, path, internal::json_problem(parsed));
  if (tileset.is_discarded() || !tileset.is_object() || !tileset.contains("asset") || !tileset.contains("root"))
    return Status::error(ErrorCode::kParse, path, "not a 3D Tiles tileset", "no \"asset\" and \"root\"");
  const fs::path folder = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : fs::path(".");
  std::error_code error;
  for (auto it = fs::recursive_directory_iterator(folder, error); !error && it != fs::recursive_directory_iterator();
       it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (!name.empty() && name[0] == '.') {
      if (it->is_directory(error)) it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file(error)) continue;
    const std::string relative = fs::relative(it->path(), folder, error).generic_string();
    if (!error && !relative.empty()) routes.push_back({"/tileset/" + relative, it->path().string(), "", ""});
  }
  if (error) return Status::error(ErrorCode::kIo, folder.string(), "cannot list the tileset's folder", error.message());
  config["tileset"] = "/tileset/" + fs::path(path).filename().string();
  config["model"] = nullptr;
  return Status::ok();
}

int run_view(const ViewArgs& args) {
  const bool tileset = extension_of(args.input) == "json";
  if (!tileset) {
    if (Status s = check_glb(args.input); !s) return report_error(s);
  }
  std::string root;
  if (Status s = find_web_root(args.web_root, root); !s) return report_error(s);

  std::vector<Route> routes;
  nlohmann::json config;
  config["model"] = "/files/model.glb";
  config["tileset"] = nullptr;
  config["name"] = base_name(args.input);
  config["texture"] = nullptr;
  config["variants"] = nullptr;
  if (tileset) {
    if (Status s = add_tileset(args.input, routes, config); !s) return report_error(s);
    config["name"] = base_name(dir_name(args.input)) + "/" + base_name(args.input);
  } else {
    routes.push_back({"/files/model.glb", args.input, "", ""});
  }
  if (!args.texture.empty()) {
    if (Status s = add_texture(args.texture, routes, config, args.quiet); !s) return report_error(s);
  }
  if (!tileset) add_glb_images(args.input, routes);  // after --texture's, which keeps its URL
  routes.push_back({"/config.json", "", json_text(config, -1), "application/json"});

  StaticServer server;
  if (Status s = server.start(root, routes, args.port); !s) return report_error(s);

  std::atomic<bool>& stop = stop_requested();

  // Always printed (also with --quiet): the URL is the point of the command, and scripts read it.
  std::printf("tailor view: http://127.0.0.1:%d/  (%s, viewer in %s; Ctrl-C to stop)\n", server.port(),
              base_name(args.input).c_str(), root.c_str());
  std::fflush(stdout);
  server.serve(stop);
  if (!args.quiet) std::fprintf(stderr, "tailor view: stopped\n");
  return kExitOk;
}

}  // namespace

//! The viewer's files: --web-root, else the installed share/tailor/web relative to the executable
//! (any prefix: the tree can be moved), else web/ next to the executable (a build tree: CMake links
//! <build>/web to the source tree's web/) or above it. The binary holds no absolute path.
Status find_web_root(const std::string& given, std::string& root) {
  std::vector<std::string> candidates;
  if (!given.empty()) {
    candidates.push_back(given);
  } else {
    std::array<char, 4096> exe{};
    const ssize_t n = ::readlink("/proc/self/exe", exe.data(), exe.size() - 1);
    if (n > 0) {
      const std::string dir = dir_name(std::string(exe.data(), static_cast<size_t>(n)));
      candidates.push_back(dir + "/" TAILOR_INSTALLED_DATA_DIR "/web");
      candidates.push_back(dir + "/web");
      candidates.push_back(dir + "/../web");
    }
  }
  for (const std::string& dir : candidates) {
    if (!file_exists(dir + "/index.html")) continue;
    if (!file_exists(dir + "/node_modules/three/build/three.module.js")) {
      return Status::error(ErrorCode::kIo, dir, "three.js is not installed", "run 'npm install' in that folder");
    }
    // Printed in the startup line: the absolute path, so that one can tell which copy is served.
    std::error_code error;
    const std::filesystem::path absolute = std::filesystem::canonical(dir, error);
    root = error ? dir : absolute.string();
    return Status::ok();
  }
  return Status::error(ErrorCode::kIo, given.empty() ? "" : given, "web viewer files (index.html) not found",
                       "pass --web-root DIR");
}

void register_view(CLI::App& app, Runner& run) {
  auto* cmd = app.add_subcommand("view",
                                 "Open a .glb or a 3D Tiles tileset.json in the web viewer (three.js) "
                                 "served on 127.0.0.1");
  auto args = std::make_shared<ViewArgs>();
  cmd->add_option("mesh", args->input,
                  "binary glTF file (.glb), e.g. from 'tailor map', or a 3D Tiles tileset.json (its folder is served), "
                  "e.g. from 'python3 -m tailor.tiles'")
      ->required();
  cmd->add_option("--texture", args->texture,
                  "texture to show instead of the embedded one: an image, or the variants .json written by "
                  "'tailor tile --variants K' (a random variant per tile cell)");
  cmd->add_option("--port", args->port, "port on 127.0.0.1 (default: a free one)")->check(CLI::Range(0, 65535));
  cmd->add_option("--web-root", args->web_root, "folder holding the viewer (index.html, node_modules)");
  cmd->add_flag("-q,--quiet", args->quiet, "print only the URL and errors");
  cmd->footer(
      "Examples:\n"
      "  tailor view spot.glb                       # prints http://127.0.0.1:PORT/ : open it in a browser\n"
      "  tailor view spot.glb --port 8080 --texture gravel_tile.png\n"
      "  tailor view spot.glb --texture gravel_tile.json   # tile variants from 'tailor tile --variants 4'\n"
      "  tailor view scan_tiles/tileset.json        # the tiles of 'python3 -m tailor.tiles' (3d-tiles-renderer)");
  cmd->callback([&run, args] { run = [args] { return run_view(*args); }; });
}

}  // namespace tailor::cli
