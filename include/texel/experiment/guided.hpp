// Matching optimizers: the common interface and the guided-exploration
// optimizer (docs/procedures.md §3.1).
//
// A matching optimizer hands out one pair of textures (A, B) in
// (Central Pitch dB, Irregularity dB), takes one choice ("which feels more
// like the reference": A, B or unsure) and keeps a current best match. Like
// every procedure it is a state machine you step, with no I/O; every random
// draw is a function of (seed, comparison index), so it is rebuilt from its
// answers alone (replay).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace texel::experiment {

/// A point of the matching space: Central Pitch (dB re 1 cpm), Irregularity (dB).
struct MatchPoint {
  double pitch_db = 0;
  double irregularity_db = 0;
  friend bool operator==(const MatchPoint&, const MatchPoint&) = default;
};

/// A participant's answer to one comparison.
enum class MatchChoice { a, b, unsure };
/// "a" | "b" | "unsure" (also "A", "B"); throws InvalidArgument naming `field`.
MatchChoice parse_match_choice(std::string_view text, std::string_view field = "choice");
std::string_view to_string(MatchChoice c);

/// One comparison: which of a, b feels more like the reference?
struct MatchQuestion {
  MatchPoint a, b;
  int iteration = 0;  ///< guided: iteration (0-based); Bayesian: equals index
  int index = 0;      ///< comparison number (0-based)
};

/// The interface both matching optimizers implement.
class MatchOptimizer {
 public:
  virtual ~MatchOptimizer() = default;
  /// The next comparison; throws texel::Error if finished().
  [[nodiscard]] virtual MatchQuestion next() const = 0;
  /// The answer to next(); throws texel::Error if finished().
  virtual void answer(MatchChoice choice) = 0;
  [[nodiscard]] virtual bool finished() const = 0;
  /// Current best match (dB).
  [[nodiscard]] virtual MatchPoint estimate() const = 0;
  /// Per axis: the box half-width (guided) or the posterior SD (Bayesian), dB.
  [[nodiscard]] virtual MatchPoint uncertainty() const = 0;
  /// Answered comparisons.
  [[nodiscard]] virtual int comparisons() const = 0;
  /// Planned comparisons: guided 4 × iterations (unsure = repeat adds up to
  /// one per unsure answer), Bayesian its budget (sd_stop may end earlier).
  [[nodiscard]] virtual int budget() const = 0;
  /// Compact JSON snapshot of the state, for the record.
  [[nodiscard]] virtual std::string state_json() const = 0;
  /// "guided" | "bayesian".
  [[nodiscard]] virtual std::string name() const = 0;
};

/// Answers `choices` in order. Throws InvalidArgument ("answers") if the
/// optimizer finishes before all are used.
void replay(MatchOptimizer& optimizer, std::span<const MatchChoice> choices);

/// The matching optimizers a protocol may name.
enum class OptimizerKind { guided, bayesian };
/// "guided" | "bayesian"; throws InvalidArgument naming `field` and the allowed names.
OptimizerKind parse_optimizer_kind(std::string_view text, std::string_view field = "kind");
std::string_view to_string(OptimizerKind k);

/// Builds an optimizer from a protocol's parameters: `params_json` is the
/// text of a JSON object whose keys are the config fields below (unknown
/// keys, wrong types and bad values throw InvalidArgument naming the key).
/// "", "null" or "{}" give the defaults.
std::unique_ptr<MatchOptimizer> make_optimizer(OptimizerKind kind, std::string_view params_json = {});

// --- guided exploration ------------------------------------------------------

/// What an "unsure" answer does.
///   ignore  contributes nothing to the pursuit vector (the source's rule; default)
///   repeat  asks the same pair once more (A and B swapped); a second unsure
///           is ignored. Costs up to one extra comparison per unsure answer.
/// (A "midpoint" rule would be ignore in disguise: the two points of a
/// question are opposite about the centroid, so their midpoint is c.)
enum class UnsureMode { ignore, repeat };
UnsureMode parse_unsure_mode(std::string_view text, std::string_view field = "unsure");
std::string_view to_string(UnsureMode m);

/// How the pursuit gain k is bounded so the new box lies in the old one.
///   per_axis  one gain per axis: the largest possible shift on each axis is
///             half that axis' shrink per iteration ([choice], default; the
///             spec's rule). With both axes shrinking by the same fraction of
///             their initial lengths the two gains are equal, so the pursuit
///             direction is kept; a diagonal answer pattern moves up to √2
///             further than an axis-aligned one.
///   joint     one gain bounding the Euclidean length of the longest possible
///             pursuit vector by the smaller axis' half-shrink: isotropic
///             moves (no diagonal advantage) but shorter ones (about 0.6 of
///             per_axis for the device box).
enum class BoundMode { per_axis, joint };
BoundMode parse_bound_mode(std::string_view text, std::string_view field = "bound");
std::string_view to_string(BoundMode m);

struct GuidedConfig {
  double pitch_min_db = -20;  ///< initial box, Central Pitch (dB re 1 cpm); min < max
  double pitch_max_db = 19.7;
  double irregularity_min_db = -30;  ///< initial box, Irregularity (dB); min < max
  double irregularity_max_db = 5;
  int iterations = 5;        ///< >= 1; four comparisons each
  double shrink_rate = 0.2;  ///< fraction of the initial lengths removed per iteration, (0, 1];
                             ///< iterations × shrink_rate <= 1 (at 1 the last box is a point)
  UnsureMode unsure = UnsureMode::ignore;
  BoundMode bound = BoundMode::per_axis;
  std::uint64_t seed = 1;  ///< question order and A/B sides
};
void validate(const GuidedConfig& config);

/// An axis-aligned box in the matching space.
struct MatchBox {
  MatchPoint center;
  double pitch_half_db = 0;
  double irregularity_half_db = 0;
  [[nodiscard]] bool contains(const MatchBox& inner, double tolerance = 1e-9) const;
};

/// Guided exploration (Vardar's thesis; docs/procedures.md §3.1): from the box
/// centroid c with half-widths (hP, hI), eight points at c ± (hP/2, 0),
/// c ± (0, hI/2), c ± (hP/2, ±hI/2); four questions, one per pair of
/// opposite points, in an order drawn from (seed, iteration), A/B sides from
/// (seed, comparison index). Pursuit vector k·Σ(chosen − c); the box shrinks
/// by shrink_rate × initial lengths and moves by the pursuit vector, which is
/// bounded so the new box lies inside the old one (enforced exactly).
/// Trade-off: simple and predictable for participants, but it discards
/// everything but the last box, and a wrong early answer cannot be undone.
class GuidedOptimizer final : public MatchOptimizer {
 public:
  explicit GuidedOptimizer(GuidedConfig config);

  [[nodiscard]] MatchQuestion next() const override;
  void answer(MatchChoice choice) override;
  [[nodiscard]] bool finished() const override { return iteration_ >= config_.iterations; }
  /// The box centroid (after the last iteration: the match).
  [[nodiscard]] MatchPoint estimate() const override { return box_.center; }
  /// The box half-widths.
  [[nodiscard]] MatchPoint uncertainty() const override { return {box_.pitch_half_db, box_.irregularity_half_db}; }
  [[nodiscard]] int comparisons() const override { return static_cast<int>(choices_.size()); }
  [[nodiscard]] int budget() const override { return 4 * config_.iterations; }
  [[nodiscard]] std::string state_json() const override;
  [[nodiscard]] std::string name() const override { return "guided"; }

  /// The current box (the one the pending questions are placed in).
  [[nodiscard]] const MatchBox& box() const { return box_; }
  /// Every box so far: the initial one, then one per completed iteration.
  [[nodiscard]] const std::vector<MatchBox>& boxes() const { return boxes_; }
  /// Completed iterations.
  [[nodiscard]] int iteration() const { return iteration_; }
  [[nodiscard]] const std::vector<MatchChoice>& choices() const { return choices_; }
  [[nodiscard]] const GuidedConfig& config() const { return config_; }

  static GuidedOptimizer replay(const GuidedConfig& config, std::span<const MatchChoice> choices);

 private:
  void start_iteration();
  void finish_iteration();
  [[nodiscard]] MatchPoint pair_point(int pair, bool plus) const;

  GuidedConfig config_;
  MatchBox box_;
  std::vector<MatchBox> boxes_;
  int iteration_ = 0;
  int pair_in_iteration_ = 0;    // 0..3: position in order_
  bool repeating_ = false;       // the pending question repeats an unsure one
  int order_[4] = {0, 1, 2, 3};  // pair indices in asking order
  MatchPoint sum_{0, 0};         // Σ(chosen − c) this iteration
  std::vector<MatchChoice> choices_;
};

}  // namespace texel::experiment
