// tailor: texture-map large triangle meshes by homogeneous patch discovery, and make textures
// self-tileable. This file only wires the subcommands (one per cmd_<name>.cpp) together.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "cli.h"
#include "memory_policy.h"
#include "tailor/version.h"
#include "util/atomic_file.h"
#include "util/text_scan.h"

namespace {

// An option given an empty value ('--texture "$TEX"' with TEX unset) would read as the option left
// out, and the run would go on without what was asked for: none of tailor's options takes an empty
// value. Returns the first such option's name, or "".
std::string option_given_empty(const CLI::App& app) {
  for (const CLI::Option* option : app.get_options()) {
    if (option->get_positional() || option->get_expected_min() == 0) continue;  // flags take no value
    for (const std::string& value : option->results())
      if (value.empty()) return option->get_name();
  }
  // The command run, and its option groups (CLI11 keeps a group's options in an App of its own).
  for (const CLI::App* part :
       app.get_subcommands([](const CLI::App* a) { return a->parsed() || a->get_name().empty(); }))
    if (const std::string name = option_given_empty(*part); !name.empty()) return name;
  return {};
}

// '--texture=' with nothing after '=' ('--texture="$TEX"' with TEX unset): CLI11 reads it as the
// option without a value and takes the next argument for it ('--texture= -o out.glb' takes -o for
// the texture). Returns the first such option of the command named by argv[1] that takes a value
// (a flag given '--json=' is the flag), or "" (also when an argument names no option of the
// command: CLI11 names that one first).
std::string option_with_empty_equals(CLI::App& app, int argc, char** argv) {
  if (argc < 2) return {};
  const std::string_view command_name = argv[1];
  const std::vector<CLI::App*> commands =
      app.get_subcommands([&](CLI::App* a) { return !a->get_name().empty() && a->get_name() == command_name; });
  if (commands.empty()) return {};
  std::string found;
  for (int i = 2; i < argc; ++i) {
    const std::string_view argument = argv[i];
    if (argument == "--") break;
    if (argument.size() < 3 || !argument.starts_with("--")) continue;
    const std::string name(argument.substr(0, argument.find('=')));
    const CLI::Option* option = commands.front()->get_option_no_throw(name);
    if (option == nullptr) return {};
    if (found.empty() && argument.find('=') == argument.size() - 1 && option->get_expected_min() > 0) found = name;
  }
  return found;
}

void say_empty_value(const std::string& option, const std::string& command) {
  std::fprintf(stderr,
               "tailor: error: %s was given an empty value: give one, or leave the option out (run 'tailor %s "
               "--help')\n",
               option.c_str(), command.c_str());
}

// Says so and returns true when an option of the command was given an empty value.
bool refused_empty_value(const CLI::App& app) {
  const std::string empty = option_given_empty(app);
  const std::vector<CLI::App*> commands = app.get_subcommands();
  if (empty.empty() || commands.empty()) return false;
  say_empty_value(empty, commands.back()->get_name());
  return true;
}

int run_command(int argc, char** argv) {
  using namespace tailor::cli;
  CLI::App app{
      "tailor: texture-map large triangle meshes by homogeneous patch discovery, in parallel chunks,\n"
      "and make texture images self-tileable so the mapping needs no atlas."};
  app.name("tailor");
  app.require_subcommand(1);
  app.set_version_flag("--version", "tailor " TAILOR_VERSION_STRING, "Print the version and exit");
  app.footer(
      "Examples:\n"
      "  tailor map bunny.ply --texture bricks.png -o bunny.glb   # UVs + textured glTF\n"
      "  tailor tile bricks.jpg -o bricks_tile.png                # self-tileable texture\n"
      "  tailor eval bunny.glb                                    # UV quality metrics\n"
      "  tailor info bunny.ply                                    # what a mesh file holds\n"
      "  tailor edit bunny.ply --texture bricks.png               # paint seams in the browser\n"
      "Run 'tailor <command> --help' for the options of each command.");

  Runner run;
  register_info(app, run);
  register_map(app, run);
  register_eval(app, run);
  register_tile(app, run);
  register_eval_tile(app, run);
  register_render(app, run);
  register_view(app, run);
  register_edit(app, run);

  if (const std::string empty = option_with_empty_equals(app, argc, argv); !empty.empty()) {
    say_empty_value(empty, argv[1]);
    return kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // Point to the help of the command whose options were wrong: 'tailor map --help'.
    const std::vector<CLI::App*> commands = app.get_subcommands();
    const std::string help = commands.empty() ? "tailor --help" : "tailor " + commands.back()->get_name() + " --help";
    if (commands.empty() && argc > 1 && argv[1][0] != '-') {  // 'tailor mpa x.ply': a command misspelt
      std::string names;
      for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; }))
        names += (names.empty() ? "" : ", ") + command->get_name();
      std::fprintf(stderr, "tailor: error: unknown command %s (commands: %s)\n",
                   tailor::internal::quote_input(argv[1]).c_str(), names.c_str());
      return kExitUsage;
    }
    // CLI11 checks the required options before the unknown ones: 'tailor map m.ply --ouput o.glb'
    // would say "--output is required", 'tailor --bogus' "A subcommand is required". The argument
    // it did not know is the cause, so it is named first, in the same words as any unknown one.
    std::string message = e.what();
    if (const size_t own = message.find(tailor::cli::kOwnWords); own != std::string::npos) {
      std::fprintf(stderr, "tailor: error: %s\n", message.substr(own + tailor::cli::kOwnWords.size()).c_str());
      return kExitUsage;
    }
    std::vector<std::string> unknown;
    if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr || dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr)
      unknown = commands.empty() ? app.remaining() : commands.back()->remaining();
    if (!unknown.empty()) {
      message = unknown.size() > 1 ? "unknown arguments" : "unknown argument";
      for (const std::string& argument : unknown) message += " " + tailor::internal::quote_input(argument);
    } else if (refused_empty_value(app)) {
      // Said before CLI11's check of the option's range or file, which names the value instead
      // (--port '': "Value  not in range").
      return kExitUsage;
    }
    std::fprintf(stderr, "tailor: error: %s (run '%s')\n", message.c_str(), help.c_str());
    return kExitUsage;
  }
  if (refused_empty_value(app)) return kExitUsage;
  if (!run) return kExitUsage;
  // The library returns Status and never throws; this is the last line of defence (out of memory,
  // a bug) so that a failure is still one line and exit 1, never an abort.
  try {
    return run();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "tailor: error: out of memory\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tailor: error: internal error: %s\n", e.what());
  }
  return kExitBadInput;
}

// Whatever went to stdout must have arrived: a full disk or a closed pipe (`tailor info m.ply >
// /dev/full`) is an error, found when the buffer is flushed and the stream closed.
int check_stdout(int code) {
  using namespace tailor::cli;
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0 && std::ferror(stdout) == 0;
  int err = flushed ? 0 : errno;
  if (std::fclose(stdout) != 0 && err == 0 && flushed) err = errno;
  const bool failed = !flushed || err != 0;
  if (!failed) return code;
  std::fprintf(stderr, "tailor: error: cannot write standard output%s%s\n", err != 0 ? ": " : "",
               err != 0 ? std::strerror(err) : "");
  return code == kExitOk ? kExitBadInput : code;
}

}  // namespace

int main(int argc, char** argv) {
  tailor::cli::release_large_blocks();
  // Temporary output files are removed on Ctrl-C, SIGTERM and SIGHUP (the signal still ends tailor).
  tailor::internal::install_signal_cleanup();
  return check_stdout(run_command(argc, argv));
}
