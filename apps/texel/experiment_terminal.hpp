// The terminal runner of `texel experiment run` (cmd_experiment_terminal.cpp):
// presents a Session's question on the terminal and collects the answer.
#pragma once

#include <atomic>
#include <optional>

#include "texel/experiment/presenter.hpp"
#include "texel/experiment/session.hpp"

namespace texel::cli {

/// Set by SIGINT / SIGTERM while a run is going (on_experiment_signal).
extern std::atomic<bool> experiment_interrupted;
extern "C" void on_experiment_signal(int);

/// Waits `seconds` while keeping the presenter fed; returns early on Ctrl-C.
void wait_pumping(texel::experiment::Presenter* presenter, double seconds);

/// Presents the session's question on the terminal and collects an answer
/// (the engine validates it). nullopt when the participant quits (q, end of
/// input, Ctrl-C).
std::optional<texel::experiment::Response> ask_terminal(const texel::experiment::Session& session,
                                                        texel::experiment::Presenter* presenter);

}  // namespace texel::cli
