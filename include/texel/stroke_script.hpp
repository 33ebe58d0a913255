// A scripted participant's finger on a 1-D display: strokes back and forth
// between two ends, the speed varying from stroke to stroke, still pauses at
// the turns, and lifts (after which the finger lands back where the stroke
// began and repeats its direction, as a finger returns in the air). It is the
// reference controller's simulated 1-D sensor (`texel controller --sensor
// strokes`), and a test computes the swipe measures a study should store
// (swipe_measures, finger.hpp) from the script itself: trace() gives the
// samples, at() the one position the display senses at a time.
//
// Deterministic: a pure function of the config (seed included); random draws
// are Texel's counter-based ones (random.hpp), one stream per quantity, so
// the script is the same on every platform. Within a stroke the speed rises
// and falls along half cosines (ramp_s), so acceleration stays finite; its
// mean over the stroke is the stroke's drawn speed.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "texel/finger.hpp"

namespace texel {

struct StrokeScriptConfig {
  std::uint64_t seed = 1;
  double from_mm = 10.0;          ///< one end of the strokes (mm); the finger lands here at t = 0
  double to_mm = 90.0;            ///< the other end (mm); |to − from| >= 1
  double speed_mm_s = 100.0;      ///< median stroke speed (mean over a stroke), 1 … 2000 mm/s
  double speed_variation = 0.25;  ///< SD of ln(stroke speed) across strokes, 0 … 1
  double extent_variation = 0.1;  ///< each stroke stops short of its end by up to this fraction of the span, 0 … 0.45
  double pause_s = 0.1;           ///< mean still, touching pause at a turn (uniform 0 … 2·pause_s), 0 … 5 s
  double lift_probability = 0.2;  ///< chance the finger lifts at the end of a stroke, 0 … 1
  double lift_s = 0.25;           ///< how long it stays lifted (s), 0.001 … 10
  double ramp_s = 0.05;           ///< speeding up and slowing down at each end of a stroke (s), 0 … 1
  double duration_s = 600.0;      ///< length of the script (s), 1 … 86400; it then repeats (see period_s)
};

/// Validates a config: InvalidArgument naming the field, value and range.
void validate(const StrokeScriptConfig& config);

class StrokeScript {
 public:
  /// Validates (see above) and lays out the strokes.
  explicit StrokeScript(const StrokeScriptConfig& config);

  /// The finger at `t_s` seconds from the start (t wraps at period_s()).
  [[nodiscard]] FingerSample at(double t_s) const noexcept;
  /// Samples at `rate_hz` (1 … 100,000) from `from_s` to `to_s` (inclusive of
  /// from, exclusive of to), each stamped with its time.
  [[nodiscard]] std::vector<FingerSample> trace(double rate_hz, double from_s, double to_s) const;
  /// The script's period: duration_s rounded up to the end of the stroke in
  /// progress, which always ends lifted (so the repeat is a new touch, not a
  /// jump while touching).
  [[nodiscard]] double period_s() const noexcept { return period_s_; }
  [[nodiscard]] const StrokeScriptConfig& config() const noexcept { return config_; }
  /// Strokes in one period.
  [[nodiscard]] std::size_t strokes() const noexcept { return strokes_; }

 private:
  enum class Kind : std::uint8_t { stroke, pause, lift };
  struct Segment {
    double t0 = 0.0, t1 = 0.0;  // s
    double x0 = 0.0, x1 = 0.0;  // mm
    double ramp_s = 0.0;
    Kind kind = Kind::stroke;
  };
  StrokeScriptConfig config_;
  std::vector<Segment> segments_;
  double period_s_ = 0.0;
  std::size_t strokes_ = 0;
};

}  // namespace texel
