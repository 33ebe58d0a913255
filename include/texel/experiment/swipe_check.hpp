// Swipe measures a trial may store (docs/procedures.md §7): the measures of
// the finger trace the participant explored with, taken on the finger's own
// clock (a display's report times, the browser's PointerEvent.timeStamp), or
// none with the reason when the trace cannot be a hand's.
//
// Why a check at all: a trace stamped on the wrong clock (arrival at a
// server, a burst of queued messages) gives speeds of 10⁵–10⁶ mm/s that look
// like data; a few samples give a mean of nothing. Stored, either would enter
// the swipe-vs-threshold correlations silently. The limits are generous for a
// finger exploring a texture: 2,000 mm/s is twenty times the studies' typical
// swipe (100 mm/s), and 0.1 s of contact is shorter than any deliberate swipe.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include "texel/finger.hpp"

namespace texel::experiment {

struct SwipeLimits {
  double max_speed_mm_s = 2000.0;  ///< highest plausible mean or sustained speed (mm/s), > 0
  double min_touched_s = 0.1;      ///< least touched time for measures (s), >= 0
  std::size_t min_intervals = 5;   ///< least touched intervals (consecutive touching samples) for measures
};

/// The measures to store, or none and why. `flag` is empty when the measures
/// are stored or when the finger never touched (nothing to measure); otherwise
/// "too_short: …" or "implausible_speed: …" with the figures (the export's
/// swipe_flag column).
struct CheckedSwipe {
  std::optional<SwipeMeasures> measures;
  std::string flag;
};

/// Measures `trace` (swipe_measures) and applies `limits`. Speeds above the
/// limit are "sustained" when the path length over the touched time exceeds
/// it, and count as implausible also when only the mean of the interval
/// speeds does (the stored figure would be implausible either way).
CheckedSwipe checked_swipe(std::span<const FingerSample> trace, const SwipeLimits& limits = {});

}  // namespace texel::experiment
