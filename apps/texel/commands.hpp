// Every subcommand registers itself here; main() calls them in order.
// A subcommand's callback runs the work and throws texel::Error on bad input.
#pragma once

#include <CLI/CLI.hpp>

namespace texel::cli {

void register_render(CLI::App& app);
void register_info(CLI::App& app);
void register_demo(CLI::App& app);
void register_devices(CLI::App& app);
void register_reference(CLI::App& app);
void register_spectrum(CLI::App& app);
void register_atlas(CLI::App& app);
void register_encode(CLI::App& app);
void register_decode(CLI::App& app);
void register_export(CLI::App& app);
void register_swipe(CLI::App& app);
void register_play(CLI::App& app);
void register_controller(CLI::App& app);
void register_display_check(CLI::App& app);
void register_staircase(CLI::App& app);
void register_stats(CLI::App& app);
void register_experiment(CLI::App& app);
void register_store(CLI::App& app);
void register_studio(CLI::App& app);

}  // namespace texel::cli
