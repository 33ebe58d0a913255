// Adaptive N-up / M-down staircase (docs/procedures.md §2).
//
// Method: PsychoPy's StairHandler semantics, re-implemented from the facts
// the spec states (initial 1-up/1-down rule until the first reversal, a run
// counter of identical answers reset by every move, reversal = move opposite
// to the previous move, step index min(reversals so far, len − 1) applied to
// the move of that same trial, clamping after moves only, the start value is
// never clamped, finished when reversals >= nReversals and trials >= nTrials).
// 1-up/3-down converges on the 79.4 % correct point (Levitt 1971).
//
// Trade-off: a state machine you step (next / answer), not a loop that asks;
// no I/O, no randomness. State is the answers: replay() rebuilds it, which is
// also how a session resumes.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace texel::experiment {

/// How a step changes the value: lin adds/subtracts the step; log multiplies
/// or divides by 10^step; db by 10^(step/20).
enum class StepType { lin, log, db };
/// "lin" | "log" | "db"; throws InvalidArgument naming `field`.
StepType parse_step_type(std::string_view text, std::string_view field = "step_type");
std::string_view to_string(StepType t);

/// Which value a finished staircase reports as its threshold ("convergent
/// value"): the value computed after the last answer, never presented
/// (PsychoPy's reading), or the last value presented (the source's reading
/// for its two studies; docs/procedures.md §2).
enum class EndValue { next, last_presented };
/// "next" | "last-presented"; throws InvalidArgument naming `field`.
EndValue parse_end_value(std::string_view text, std::string_view field = "end_value");
std::string_view to_string(EndValue e);

struct StaircaseConfig {
  double start_value = 0;               ///< first intensity presented (never clamped); > 0 for log/db
  std::vector<double> step_sizes{1.0};  ///< non-empty, each finite and > 0 (units of step_type)
  int n_up = 1;                         ///< wrong answers in a row that move the value up, >= 1
  int n_down = 3;                       ///< correct answers in a row that move it down, >= 1
  std::optional<int> n_reversals;       ///< missing → len(step_sizes); raised to it if smaller
  int n_trials = 0;                     ///< minimum number of trials, >= 0
  StepType step_type = StepType::lin;
  std::optional<double> min_value, max_value;  ///< clamps after moves down / up; min <= max
  bool apply_initial_rule = true;              ///< 1-up/1-down until the first reversal
  EndValue end_value = EndValue::next;         ///< what convergent_value() reports
};

/// Throws InvalidArgument naming the field, the value and what is allowed.
void validate(const StaircaseConfig& config);

class Staircase {
 public:
  /// Validates the config (throws InvalidArgument).
  explicit Staircase(StaircaseConfig config);

  /// The intensity to present now; throws texel::Error if finished().
  [[nodiscard]] double next() const;
  /// The answer for the intensity next() returned; throws texel::Error if finished().
  void answer(bool correct);
  [[nodiscard]] bool finished() const;
  /// Answered trials.
  [[nodiscard]] std::size_t trials() const { return intensities_.size(); }

  /// Presented intensities, one per answered trial.
  [[nodiscard]] const std::vector<double>& intensities() const { return intensities_; }
  [[nodiscard]] const std::vector<bool>& responses() const { return responses_; }
  /// 0-based trial indices of the reversals.
  [[nodiscard]] const std::vector<std::size_t>& reversal_trials() const { return reversal_trials_; }
  /// The intensity presented on each reversal trial.
  [[nodiscard]] const std::vector<double>& reversal_intensities() const { return reversal_intensities_; }
  /// The last answer produced a reversal.
  [[nodiscard]] bool last_was_reversal() const { return last_was_reversal_; }
  /// The step size in force (units of step_type).
  [[nodiscard]] double current_step() const { return step_; }
  /// The value computed after the last answer (what next() would present),
  /// also when finished.
  [[nodiscard]] double computed_value() const { return value_; }
  /// The threshold by the config's end_value: computed_value() (next), or
  /// the last intensity presented (last_presented; computed_value() before
  /// the first answer).
  [[nodiscard]] double convergent_value() const;
  /// The effective number of reversals required (config, raised to len(step_sizes)).
  [[nodiscard]] int n_reversals() const { return n_reversals_; }

  /// Mean of the last min(k, n) reversal intensities; throws texel::Error
  /// when there is no reversal yet or k == 0.
  [[nodiscard]] double mean_last_reversals(std::size_t k) const;
  /// Mean of all reversal intensities except the first k; throws texel::Error
  /// when there are k or fewer reversals.
  [[nodiscard]] double mean_reversals_excluding_first(std::size_t k) const;

  /// Compact JSON snapshot for the record (config, value, step, run counter,
  /// direction, trials, reversals, finished).
  [[nodiscard]] std::string state_json() const;
  /// Rebuilds a staircase from its answers. Throws InvalidArgument
  /// ("answers") if an answer comes after the staircase finished.
  static Staircase replay(const StaircaseConfig& config, std::span<const bool> answers);
  /// The same for a std::vector<bool> (which has no contiguous storage), e.g. responses().
  static Staircase replay(const StaircaseConfig& config, const std::vector<bool>& answers);

  [[nodiscard]] const StaircaseConfig& config() const { return config_; }

 private:
  enum class Direction { none, up, down };
  StaircaseConfig config_;
  int n_reversals_ = 1;
  double value_ = 0;
  double step_ = 1;
  int run_ = 0;  // +n: n correct in a row since the last move; −n: n wrong
  Direction direction_ = Direction::none;
  bool last_was_reversal_ = false;
  std::vector<double> intensities_;
  std::vector<bool> responses_;
  std::vector<std::size_t> reversal_trials_;
  std::vector<double> reversal_intensities_;
};

}  // namespace texel::experiment
