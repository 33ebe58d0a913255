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

/// Fastest speed a finger exploring a texture plausibly reaches (mm/s): a
/// faster interval is a sensor glitch, a missed lift or a clock error.
inline constexpr double max_plausible_speed_mm_s = 2000.0;
/// Intervals slower than this move neither way (sensor noise; mm/s).
inline constexpr double still_speed_mm_s = 1.0;

/// The swipe measures of a trace, or why there are none.
struct TraceMeasures {
  std::optional<SwipeMeasures> measures;  ///< none when flagged or never touched
  /// "" (measured), "no_touch", "time_not_increasing" (a sample older than the
  /// one before it), "implausible_speed" (an interval faster than
  /// max_plausible_speed_mm_s).
  std::string flag;
  double max_speed_mm_s = 0.0;  ///< fastest touched interval seen
};
TraceMeasures measure_trace(const FingerTrace& trace);

/// The samples as stored: one "t_s,x_mm,touch" line each (µs and nm
/// resolution), and back (FormatError naming `origin` and the line).
std::string trace_samples_text(std::span<const FingerSample> samples);
std::vector<FingerSample> parse_trace_samples(std::string_view text, std::string_view origin);

}  // namespace texel::experiment
