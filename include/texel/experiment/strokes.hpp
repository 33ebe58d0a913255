// A participant's strokes on a 2-D display, summarised per interval of a
// trial (docs/experiments.md "The 2-D display presenter"): how many strokes,
// along which direction, how fast and how far, and whether the direction is
// the one the participant was asked for.
//
// Directions are axial: a stroke along 60° and one back along 240° are the
// same line, so back-and-forth stroking is one direction. The mean direction
// is the doubled-angle mean of the strokes' segments weighted by their
// length (axial statistics): θ̄ = ½·atan2(Σ ℓ·sin 2φ, Σ ℓ·cos 2φ), in
// [0°, 180°), and its concentration R = |Σ ℓ·e^{2iφ}| / Σ ℓ in [0, 1] (1: one
// straight line; near 0: a circle or a scribble, which has no direction).
//
// [choice] An interval complies when it was stroked (at least one stroke of
// `min_stroke_mm`), R >= `min_straightness` and its mean direction is within
// `tolerance_deg` of the instructed one. The defaults and why they are what
// they are: docs/experiments.md.
#pragma once

#include <string>
#include <vector>

#include "texel/experiment/records.hpp"

namespace texel::experiment {

/// What a presenter asks of a stroke (see the banner).
struct StrokeRules {
  double tolerance_deg = 20.0;    ///< largest deviation of the mean direction, 0 … 90
  double min_stroke_mm = 5.0;     ///< shorter touches are taps, not strokes
  double min_straightness = 0.5;  ///< smallest R
  /// A step faster than this between two touching reports is a jump (the
  /// sensor lost a lift, or a second finger): the stroke ends there.
  double max_speed_mm_s = 3000.0;
  /// A gap longer than this between two touching reports ends the stroke too.
  double max_gap_s = 0.05;
};
/// Checks the rules (InvalidArgument naming the field).
void validate(const StrokeRules& rules);

/// One interval's strokes (stored with the trial's response).
struct IntervalStrokes {
  std::string stimulus;             ///< the stimulus label ("1", "2", "3")
  double instructed_deg = missing;  ///< the direction asked for, [0, 180)
  int strokes = 0;                  ///< strokes of at least min_stroke_mm
  double direction_deg = missing;   ///< mean direction, [0, 180); missing without strokes
  double straightness = missing;    ///< R, 0 … 1
  double deviation_deg = missing;   ///< |mean − instructed| as lines, 0 … 90
  double mean_speed_mm_s = missing;
  double path_mm = 0.0;    ///< length of the counted strokes
  double touched_s = 0.0;  ///< time the counted strokes lasted
  double tolerance_deg = missing;
  bool compliant = false;
};

/// The smallest angle between two lines of directions a and b (degrees): 0 … 90.
double line_angle_difference(double a_deg, double b_deg);
/// A direction as a line's: [0, 180).
double line_direction(double deg);

/// Accumulates one interval's finger samples (display time, surface mm,
/// touch) and summarises them. Not thread-safe: one writer.
class StrokeRecorder {
 public:
  explicit StrokeRecorder(const StrokeRules& rules = {}) : rules_(rules) {}
  void add(double t_s, double x_mm, double y_mm, bool touch);
  /// The summary so far (a stroke in progress counts if long enough).
  [[nodiscard]] IntervalStrokes summary(const std::string& stimulus, double instructed_deg) const;

 private:
  struct Sums {
    double path = 0.0, seconds = 0.0, c2 = 0.0, s2 = 0.0;
    int strokes = 0;
  };
  void end_stroke();
  StrokeRules rules_;
  Sums done_{}, stroke_{};
  bool down_ = false;
  double t_ = 0.0, x_ = 0.0, y_ = 0.0;
};

/// The trial's stroke columns of the row (records.hpp) from its intervals:
/// strokes (sum), stroke_deviation_deg (the largest deviation), and
/// direction_compliant (1 when every interval of the trial complied; an
/// interval never stroked does not comply). Nothing when `intervals` is empty.
void fill_stroke_columns(const std::vector<IntervalStrokes>& intervals, std::size_t stimuli, TrialRow& row);

/// How the participant is told a direction, for a display whose y axis
/// points down the screen (image rows): "↔ left–right", "⤡ falling to the
/// right at 60° from horizontal", … Nothing of the condition.
std::string direction_words(double deg);

}  // namespace texel::experiment
