// The terminal runner of `texel experiment run` (cmd_experiment_terminal.cpp):
// presents a Session's question to the participant on the terminal, collects
// the answer, and reports everything the participant must not see to the
// experimenter's monitor stream (docs/experiments.md "The terminal runner").
#pragma once

#include <atomic>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "texel/experiment/presenter.hpp"
#include "texel/experiment/session.hpp"

namespace texel::cli {

/// Set by SIGINT / SIGTERM while a run is going (on_experiment_signal).
extern std::atomic<bool> experiment_interrupted;
extern "C" void on_experiment_signal(int);

/// Waits `seconds` while keeping the presenter fed; returns early on Ctrl-C.
void wait_pumping(texel::experiment::Presenter* presenter, double seconds);

/// The experimenter's stream (`--monitor PATH`): one line per event,
/// `<UTC time> <event> key=value …` (fields without a value left out), values
/// with spaces or quotes in JSON string quotes. PATH "-" is stderr; a regular file is appended to; a FIFO
/// is written without blocking the run (a line the reader cannot take is
/// dropped, and a reader that goes away ends the stream, never the run).
class Monitor {
 public:
  using Field = std::pair<std::string_view, std::string>;
  Monitor() = default;
  ~Monitor();
  Monitor(const Monitor&) = delete;
  Monitor& operator=(const Monitor&) = delete;

  /// Opens PATH (throws IoError naming --monitor). Returns whether it created
  /// the file (so a run that fails to start can remove it again).
  bool open(const std::string& path);
  void close();
  [[nodiscard]] bool enabled() const { return fd_ >= 0; }
  /// Writes one event line (one write() call, so `tail -f` sees whole lines).
  void event(std::string_view name, std::initializer_list<Field> fields);

 private:
  int fd_ = -1;
  bool owned_ = false;
};

/// Tells the monitor the session's current question: trial_number, block,
/// the value presented, the correct answer, … (the "question" event).
void report_question(Monitor& monitor, const texel::experiment::Session& session);

/// Why the terminal runner stopped asking.
enum class StopReason { none, quit, end_of_input, interrupt };
std::string_view to_string(StopReason r);

/// Presents the session's question on the terminal and collects an answer
/// (validated here against the question, and again by the engine). nullopt
/// when the participant quits ('q', end of input, Ctrl-C); `stop` says which.
/// The participant sees nothing that depends on correctness or on the
/// procedure's state; the monitor gets the question, every stimulus played,
/// time-outs, refused input and the answer.
std::optional<texel::experiment::Response> ask_terminal(const texel::experiment::Session& session,
                                                        texel::experiment::Presenter* presenter, Monitor& monitor,
                                                        StopReason& stop);

/// Participant-facing text between and after trials (stdout).
void tell_participant(const std::string& text);

/// The participant's name for a stimulus label: "texture 2", "texture A",
/// "the test texture", "the reference (left half) and the rendering (right half)".
std::string stimulus_name(const std::string& label);

}  // namespace texel::cli
