// tailor edit: the texturing tool (thesis 2.5 and chapter 4). Maps a mesh as `tailor map` does, opens an
// EditSession and serves the editing page (web/edit.html) and its API (edit_api.h) on 127.0.0.1 until
// Ctrl-C. Edits are answered at once by a fast local update; a background thread settles to the full
// `tailor map` result when the user pauses.
#include <stdlib.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cli.h"
#include "edit_api.h"
#include "http_server.h"
#include "map_shared.h"
#include "memory_policy.h"
#include "tailor/axis_choice.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/texture_direction.h"

namespace tailor::cli {

namespace {

struct EditArgs {
  std::string input;
  std::string output;
  std::string texture;
  std::string web_root;
  int port = 0;
  bool quiet = false;
  std::string compress = mesh_compression_name(ExportOptions{}.compression);
  int uv_set = ExportOptions{}.uv_set;
  std::string up = ExportOptions{}.up == SceneUp::kZ ? "z" : "y";
  MapTextureOptions options;
  MappingArgs mapping_args;  // the mapping options given as text (map_shared.h)
};

// "out/a.glb" + "seam_faces.txt" -> "out/a_seam_faces.txt"
std::string beside(const std::string& path, const std::string& suffix) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "_" + suffix)).string();
}

// A private temporary folder, removed when the command ends.
struct ScratchDir {
  std::string path;
  ~ScratchDir() {
    if (!path.empty()) {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  }
};

int run_edit(const EditArgs& opt) {
  EditContext context;
  context.quiet = opt.quiet;
  context.input = opt.input;
  context.name = std::filesystem::path(opt.input).filename().string();
  context.texture_arg = opt.texture;
  // === Options, checked before any work, in the order `tailor map` takes them ===
  context.glb_path = opt.output.empty() ? std::filesystem::path(opt.input).stem().string() + "_edited.glb" : opt.output;
  if (extension_of(context.glb_path) != "glb")
    return report_error(usage_error("-o must end in .glb, got '" + context.glb_path + "'"));
  context.seam_faces_path = beside(context.glb_path, "seam_faces.txt");
  context.strokes_path = beside(context.glb_path, "strokes.json");
  MeshOutput& output = context.output;
  if (!mesh_compression_from_name(opt.compress, output.compression))
    return report_error(usage_error("--compress must be none, quantize, meshopt or draco, got '" + opt.compress + "'"));
  if (opt.up != "y" && opt.up != "z") return report_error(usage_error("--up must be y or z, got '" + opt.up + "'"));
  output.up = opt.up == "z" ? SceneUp::kZ : SceneUp::kY;
  output.uv_set = opt.uv_set;
  const MappingArgs& args = opt.mapping_args;
  MapTextureOptions options = opt.options;
  if (Status s = apply_mapping_args(args, options); !s) return report_error(s);
  const bool auto_axis = args.auto_axis();
  MappingOptions& mapping = options.mapping;
  if (Status s = check_outputs({{context.glb_path, "--output"},
                                {context.seam_faces_path, "the seam faces beside --output"},
                                {context.strokes_path, "the strokes beside --output"}},
                               {opt.input, opt.texture, args.seam_faces, args.strokes});
      !s)
    return report_error(s);
  std::vector<OrientationStroke> strokes;
  if (!args.strokes.empty()) {
    if (Status s = load_strokes(args.strokes, strokes); !s) return report_error(s);
    options.orientation.strokes = strokes;
  }
  std::string root;
  if (Status s = find_web_root(opt.web_root, root); !s) return report_error(s);
  if (!std::filesystem::exists(root + "/edit.html"))
    return report_error(Status::error(ErrorCode::kIo, root, "the editing page (edit.html) is missing"));

  // === Texture ===
  std::vector<Route> routes;
  if (!opt.texture.empty()) {
    if (Status s = load_image(opt.texture, context.texture); !s) return report_error(s);
    context.texture_url = "/files/texture." + extension_of(opt.texture);
    routes.push_back({context.texture_url, opt.texture, "", ""});
  }
  output.texture_path = opt.texture;
  if (!context.texture.empty()) output.texture_image = &context.texture;
  output.texture_width = !context.texture.empty() ? context.texture.width : args.texture_size;
  output.texture_height = !context.texture.empty() ? context.texture.height : args.texture_size;
  if (Status s = set_map_texture_size(options, output.texture_width, output.texture_height); !s) return report_error(s);
  if (args.auto_field_following()) {
    const uint32_t rings = mapping.crack_rings;
    adapt_mapping_to_texture(context.texture, mapping);
    if (args.crack_rings_given) mapping.crack_rings = rings;
  }

  // === Mesh, seam faces, the first full map ===
  Mesh mesh;
  LoadReport load;
  {
    const ReadingInput reading(opt.input);
    if (Status s = load_mesh(opt.input, mesh, &load); !s) return report_error(s);
  }
  if (load.degenerate_faces || load.duplicate_faces)
    warn(opt.quiet, opt.input + ": dropped " + std::to_string(load.degenerate_faces + load.duplicate_faces) +
                        " degenerate or duplicate faces (face ids are those of the loaded mesh)");
  warn_unused_input(opt.input, load, opt.quiet);
  std::vector<uint8_t> seam_faces;
  if (!args.seam_faces.empty()) {
    if (Status s = load_seam_faces(args.seam_faces, mesh.face_count(), seam_faces); !s) return report_error(s);
    mapping.seam_faces = seam_faces;
  } else if (!mesh.seam_faces.empty()) {
    seam_faces = mesh.seam_faces;
    mapping.seam_faces = seam_faces;
  }
  context.topology = build_topology(mesh);
  // As `tailor map` does (its replay command must give the same file): faces wound against their
  // neighbours turn; face ids do not change, so seam faces and strokes still name the same faces.
  if (turn_wound_faces(opt.input, mesh, context.topology, load, opt.quiet)) context.topology = build_topology(mesh);
  if (auto_axis) {
    AxisChoice choice;
    if (Status s = choose_orientation_axis(mesh, context.topology, options, choice); !s)
      return report_error(s.with_file(opt.input));
    options.orientation = orientation_for(choice.best, options.orientation);
    warn(opt.quiet, std::string("axis auto: ") + axis_candidate_name(choice.best));
  }
  const auto start = std::chrono::steady_clock::now();
  {
    const KeepScratch keep;  // the first map's chunks reuse each other's scratch
    if (Status s = EditSession::open(std::move(mesh), options, context.session); !s)
      return report_error(s.with_file(opt.input));
  }
  const double open_seconds = seconds_since(start);

  // === Serve ===
  ScratchDir scratch;
  {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/tailor-edit-XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr)
      return report_error(Status::error(ErrorCode::kIo, pattern, "cannot create a temporary folder"));
    scratch.path = pattern;
    context.scratch_dir = pattern;
  }
  routes.push_back({"/", root + "/edit.html", "", ""});
  StaticServer server;
  if (Status s = server.start(root, routes, opt.port); !s) return report_error(s);
  EditApi api(context);
  api.install(server);

  std::atomic<bool>& stop = stop_requested();

  std::atomic<bool> settler_done{false};
  std::thread settler([&api, &settler_done, &stop] {
    api.run_settler(stop);
    settler_done.store(true);
  });
  // Always printed (also with --quiet): the URL is the point of the command, and scripts read it.
  std::printf("tailor edit: http://127.0.0.1:%d/  (%s, %s mapped in %.2f s; saves to %s; Ctrl-C to stop)\n",
              server.port(), context.name.c_str(),
              counted(context.session->mesh().face_count(), "face", "faces").c_str(), open_seconds,
              context.glb_path.c_str());
  std::fflush(stdout);
  server.serve(stop);
  api.wake();
  // A settle of a large mesh cannot be interrupted (seconds at a million faces): Ctrl-C does not wait
  // for it. Nothing is being written then (saves run on the server's threads, which have ended).
  for (int i = 0; i < 50 && !settler_done.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (!opt.quiet) std::fprintf(stderr, "tailor edit: stopped\n");
  if (!settler_done.load()) {
    std::fflush(stdout);
    std::error_code ignored;
    std::filesystem::remove_all(scratch.path, ignored);
    std::_Exit(kExitOk);
  }
  settler.join();
  return kExitOk;
}

}  // namespace

void register_edit(CLI::App& app, Runner& run) {
  auto opt = std::make_shared<EditArgs>();
  MappingOptions& mapping = opt->options.mapping;
  auto* cmd = app.add_subcommand(
      "edit", "Texturing tool in the browser: paint seam faces and orientation strokes, see the map update live");
  cmd->add_option("mesh", opt->input, "Input mesh (.ply .obj .off .stl .glb .gltf), as 'tailor map' reads it")
      ->required();
  cmd->add_option("-o,--output", opt->output,
                  "Where Save writes the textured .glb (default: <mesh name>_edited.glb here); the seam faces "
                  "go beside it as <name>_seam_faces.txt, the strokes as <name>_strokes.json");
  cmd->add_option("-t,--texture", opt->texture,
                  "Texture image (PNG/JPEG), ideally self-tileable (see 'tailor tile'); sets the texture size");
  cmd->add_option("--texture-size", opt->mapping_args.texture_size, "Texture size in pixels when no --texture is given")
      ->capture_default_str();
  add_documented(cmd, option_doc(kMappingOptionDocs, "seam_faces"), opt->mapping_args.seam_faces);
  add_documented(cmd, option_doc(kOrientationOptionDocs, "strokes"), opt->mapping_args.strokes);
  add_documented(cmd, option_doc(kExportOptionDocs, "compression"), opt->compress);
  add_documented(cmd, option_doc(kExportOptionDocs, "uv_set"), opt->uv_set)->check(CLI::Range(0, 7));
  add_documented(cmd, option_doc(kExportOptionDocs, "up"), opt->up);
  cmd->add_option("--port", opt->port, "port on 127.0.0.1 (default: a free one)")->check(CLI::Range(0, 65535));
  cmd->add_option("--web-root", opt->web_root, "folder holding the pages (edit.html, node_modules)");
  auto* group = cmd->add_option_group("Mapping (as 'tailor map'; the page changes them too)");
  const MappingOptionHandles handles = add_mapping_options(group, opt->mapping_args, opt->options, false);
  cmd->add_option("--threads", mapping.threads,
                  "Threads for the chunk plan, the orientation, the crack closing and the metrics (0 = one per "
                  "core, up to 8); "
                  "the result is the same for any count")
      ->capture_default_str()
      ->check(CLI::Range(0u, 64u));
  cmd->add_flag("-q,--quiet", opt->quiet, "print only the URL and errors");
  cmd->footer(
      "Prints http://127.0.0.1:PORT/ : open it in a browser. In the page:\n"
      "  brush (b) / erase (e): paint seam faces, where the mapping should put its seams; the map is\n"
      "      redone around the faces as you paint, and settled to the full map when you pause;\n"
      "  stroke (s): draw a curve on the surface; the texture follows it within the stroke's reach;\n"
      "  axis, smoothing and the mapping options; views texture, patches, distortion, checker, seams;\n"
      "  undo / redo (Ctrl-Z / Ctrl-Y); Save writes the .glb, the seam faces and the strokes, and\n"
      "      prints the 'tailor map' command that replays them to the same bytes.\n"
      "Right-drag (or orbit mode, o) turns the view, the wheel zooms. Scripts can use the same HTTP API\n"
      "(docs/edit-api.md).\n"
      "Examples:\n"
      "  tailor edit bunny.ply --texture gravel_tile.png -o bunny.glb\n"
      "  tailor edit horse.ply --axis skeleton --port 8080");
  cmd->callback([&run, opt, handles] {
    note_given_options(handles, opt->mapping_args);
    run = [opt] { return run_edit(*opt); };
  });
}

}  // namespace tailor::cli
