// The finger that explored a trial: how the stimuli reached it (the
// presentation mode), where its samples came from, the samples themselves,
// and the swipe measures computed from them (docs/experiments.md "Running a
// study with a display").
//
// Presentation modes, chosen per display (presenter.hpp):
//   display_plays  a display that stores maps gets each stimulus uploaded and
//                  SELECTed; it plays it from its own sensed position at its
//                  own refresh rate, and reports the finger to the host.
//   host_streams   the host's player computes the output from a finger it is
//                  told about (a display's reports, the studio's pointer) and
//                  streams it; the link's rate bounds what it can carry.
//   passive        no finger exists (actuators on a passive hand): the host
//                  plays the stimulus under a simulated sweep.
//
// Every trial stores the trace it got with its source (a display's FINGER
// reports on the display's own clock, a pointer's events on the browser's
// clock, or the simulated finger), and speed, speed SD and directional
// proportion come from those samples' own time stamps — never from when the
// host received them. Implausible speeds are flagged, not stored as data.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/finger.hpp"

namespace texel::experiment {

/// How stimuli reach the participant's finger (see the banner).
enum class PresentationMode { display_plays, host_streams, passive };
std::string_view to_string(PresentationMode m);  ///< "display-plays", "host-streams", "passive"
/// Parses "display-plays" | "host-streams" | "passive" (FieldError naming `field`).
PresentationMode parse_presentation_mode(std::string_view text, std::string_view field = "mode");

/// Where a trace's samples came from.
enum class TraceSource { none, display, pointer, simulated };
std::string_view to_string(TraceSource s);  ///< "", "display", "pointer", "simulated"
TraceSource parse_trace_source(std::string_view text, std::string_view field = "finger_source");

/// The finger trace of one trial.
struct FingerTrace {
  TraceSource source = TraceSource::none;
  std::optional<PresentationMode> mode;  ///< how the trial's stimuli were presented
  /// Samples in time order: t_s on the source's own clock (s; any origin),
  /// x_mm along the display (mm), touch.
  std::vector<FingerSample> samples;
  [[nodiscard]] bool empty() const { return samples.empty(); }
};

/// What a trace must be to give swipe measures: the one rule every front
/// door applies (a display's reports, the studio's pointer, a simulated
/// finger). A trace stamped on the wrong clock (arrival at a server, a burst
/// of queued messages) gives speeds of 10⁵–10⁶ mm/s that look like data; a
/// few samples give a mean of nothing; stored, either would enter the
/// swipe-vs-threshold correlations silently. The limits are generous for a
/// finger exploring a texture: 2,000 mm/s is twenty times the studies'
/// typical swipe (100 mm/s), and 0.1 s of contact is shorter than any
/// deliberate swipe.
struct SwipeLimits {
  double max_speed_mm_s = 2000.0;  ///< fastest plausible speed (mm/s), > 0
  double min_touched_s = 0.1;      ///< least touched time for measures (s), >= 0
  std::size_t min_intervals = 5;   ///< least touched intervals (consecutive touching samples)
  double still_speed_mm_s = 1.0;   ///< intervals slower than this move neither way (sensor noise; mm/s)
  /// The coarsest clock a source may stamp with (s): a browser may round
  /// PointerEvent.timeStamp to 1 ms, so speeds are judged over spans of at
  /// least twice this, each timed as its stamps' difference plus this.
  double time_resolution_s = 0.001;
};
/// The defaults' fastest plausible speed (mm/s).
inline constexpr double max_plausible_speed_mm_s = SwipeLimits{}.max_speed_mm_s;

/// The swipe measures of a trace, or why there are none.
struct TraceMeasures {
  std::optional<SwipeMeasures> measures;  ///< none when flagged or never touched
  /// Empty when measured; otherwise a code, then ": " and the figures:
  ///   no_touch             the finger never touched while moving
  ///   time_not_increasing  a sample without a finite time or place, or older than the one before
  ///   too_short            fewer than min_intervals touched intervals or under min_touched_s of contact
  ///   implausible_speed    the mean, the sustained (path / touched time) or the fastest span's speed
  ///                        above max_speed_mm_s: a glitch, a missed lift or a clock error
  std::string flag;
  /// Fastest touched span (mm/s): a span's path over its stamps' time plus one
  /// clock tick, so a lower bound of the true speed.
  double max_speed_mm_s = 0.0;
};
/// The code of a flag ("implausible_speed" of "implausible_speed: mean …").
std::string_view flag_code(std::string_view flag);

/// Measures a trace and applies `limits` (InvalidArgument for bad limits).
TraceMeasures measure_trace(std::span<const FingerSample> samples, const SwipeLimits& limits = {});
TraceMeasures measure_trace(const FingerTrace& trace, const SwipeLimits& limits = {});

/// The samples as stored: one "t_s,x_mm,touch" line each (µs and nm
/// resolution), and back (FormatError naming `origin` and the line).
std::string trace_samples_text(std::span<const FingerSample> samples);
std::vector<FingerSample> parse_trace_samples(std::string_view text, std::string_view origin);

}  // namespace texel::experiment
