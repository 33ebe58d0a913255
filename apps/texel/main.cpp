// texel — the command-line front door to libtexel.
//
// Exit status: 0 success; 2 bad input of any kind (a flag, a file, a value
// out of range, an unwritable output), with a one-line message on stderr and
// no output file written; 1 an internal error (a bug: please report it).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "texel/error.hpp"

namespace {

/// Each top-level command and the function that adds it to the app.
struct Command {
  std::string_view name;
  void (*add)(CLI::App&);
};
constexpr Command commands[] = {
    {"render", &texel::cli::register_render},
    {"info", &texel::cli::register_info},
    {"demo", &texel::cli::register_demo},
    {"devices", &texel::cli::register_devices},
    {"reference", &texel::cli::register_reference},
    {"spectrum", &texel::cli::register_spectrum},
    {"atlas", &texel::cli::register_atlas},
    {"encode", &texel::cli::register_encode},
    {"decode", &texel::cli::register_decode},
    {"export", &texel::cli::register_export},
    {"swipe", &texel::cli::register_swipe},
    {"play", &texel::cli::register_play},
    {"controller", &texel::cli::register_controller},
    {"display-check", &texel::cli::register_display_check},
    {"experiment", &texel::cli::register_experiment},
    {"store", &texel::cli::register_store},
    {"staircase", &texel::cli::register_staircase},
    {"stats", &texel::cli::register_stats},
    {"studio", &texel::cli::register_studio},
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"texel: render, analyse and play multi-scale virtual haptic textures"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "texel 0.1.0");
  // Only the command being run is built (building every command's options was a fifth of a short
  // command's start-up); without one (texel, texel --help, a mistyped name) every command is, so
  // help and the error list them all; `texel --version` needs none.
  const std::string_view first = argc > 1 ? argv[1] : "";
  const auto run = std::find_if(std::begin(commands), std::end(commands), [&](const Command& c) { return c.name == first; });
  if (run != std::end(commands))
    run->add(app);
  else if (!(argc == 2 && first == "--version"))
    for (const Command& c : commands) c.add(app);
  try {
    app.parse(argc, argv);
    return 0;
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string msg = e.what();
    for (auto& c : msg)
      if (c == '\n') c = ' ';
    std::cerr << "texel: " << msg << " (see texel --help)\n";
    return 2;
  } catch (const texel::FieldError& e) {
    std::cerr << "texel: " << texel::cli::flag_of_field(e.field()) << " " << e.detail() << "\n";
    return 2;
  } catch (const texel::Error& e) {
    std::cerr << "texel: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "texel: out of memory (is the requested grid too large?)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "texel: internal error: " << e.what() << "\n";
    return 1;
  }
}
