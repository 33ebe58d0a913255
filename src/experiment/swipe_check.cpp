// Swipe measures a trial may store (swipe_check.hpp).
#include "texel/experiment/swipe_check.hpp"

#include "texel/detail/format.hpp"

namespace texel::experiment {

CheckedSwipe checked_swipe(std::span<const FingerSample> trace, const SwipeLimits& limits) {
  CheckedSwipe out;
  const SwipeMeasures m = swipe_measures(trace);
  if (m.intervals == 0) return out;  // never touched while moving: nothing to measure, nothing to flag
  if (m.intervals < limits.min_intervals || m.touched_s < limits.min_touched_s) {
    out.flag = "too_short: " + std::to_string(m.intervals) + " intervals over " + detail::fixed(m.touched_s, 3) +
               " s touched; needed: at least " + std::to_string(limits.min_intervals) + " intervals and " +
               detail::num(limits.min_touched_s) + " s";
    return out;
  }
  const double sustained = m.touched_s > 0 ? m.distance_mm / m.touched_s : 0.0;
  if (m.mean_speed_mm_s > limits.max_speed_mm_s || sustained > limits.max_speed_mm_s) {
    out.flag = "implausible_speed: mean " + detail::fixed(m.mean_speed_mm_s, 1) + " mm/s, sustained " +
               detail::fixed(sustained, 1) + " mm/s; allowed: at most " + detail::num(limits.max_speed_mm_s) + " mm/s";
    return out;
  }
  out.measures = m;
  return out;
}

}  // namespace texel::experiment
