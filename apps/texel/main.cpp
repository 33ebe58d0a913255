// texel — the command-line front door to libtexel.
//
// Exit status: 0 success; 2 bad input of any kind (a flag, a file, a value
// out of range, an unwritable output), with a one-line message on stderr and
// no output file written; 1 an internal error (a bug: please report it).
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "texel/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"texel: render, analyse and play multi-scale virtual haptic textures"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "texel 0.1.0");
  texel::cli::register_render(app);
  texel::cli::register_info(app);
  texel::cli::register_demo(app);
  texel::cli::register_devices(app);
  texel::cli::register_reference(app);
  texel::cli::register_spectrum(app);
  texel::cli::register_atlas(app);
  texel::cli::register_encode(app);
  texel::cli::register_decode(app);
  texel::cli::register_export(app);
  texel::cli::register_swipe(app);
  texel::cli::register_play(app);
  texel::cli::register_controller(app);
  texel::cli::register_display_check(app);
  texel::cli::register_experiment(app);
  texel::cli::register_store(app);
  texel::cli::register_staircase(app);
  texel::cli::register_stats(app);
  texel::cli::register_studio(app);
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
