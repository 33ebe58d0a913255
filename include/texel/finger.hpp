// Finger sources and swipe measures.
//
// A finger trace is a time-ordered list of samples (time in s, position in mm
// along the swipe axis, touching or lifted). Sources: simulated swipes
// (constant speed, or back-and-forth with smooth turns), recorded traces (CSV
// of time, position, touch) and a programmatic feed (Player::push, used by
// the studio). The same trace drives the real-time player, the offline
// `texel swipe` renderer and the experiments' swipe measures.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/option_spec.hpp"

namespace texel {

/// One finger sample.
struct FingerSample {
  double t_s = 0.0;    ///< time (s) on the player's clock (0 = first output sample)
  double x_mm = 0.0;   ///< position along the swipe axis (mm, device coordinates)
  bool touch = false;  ///< finger on the surface
};

enum class SwipePattern {
  constant,        ///< one pass at constant speed, then the finger lifts at the far end
  back_and_forth,  ///< to and fro over the extent, decelerating into each turn
};
std::string_view to_string(SwipePattern p);
SwipePattern parse_swipe_pattern(std::string_view text, std::string_view field = "pattern");
inline constexpr OptionChoice swipe_patterns[] = {{"constant", static_cast<int>(SwipePattern::constant)},
                                                  {"back-and-forth", static_cast<int>(SwipePattern::back_and_forth)}};

/// A simulated swipe.
struct SwipeConfig {
  SwipePattern pattern = SwipePattern::constant;
  double speed_mm_s = 100.0;  ///< cruising speed (mm/s), > 0; 100 mm/s is the studies' typical swipe
  double start_mm = 0.0;      ///< where the finger lands (mm)
  /// Travel before the finger lifts (constant) or turns (back-and-forth), mm;
  /// 0 = from start_mm to the end of `surface_mm`.
  double extent_mm = 0.0;
  double surface_mm = 0.0;  ///< surface length used when extent_mm is 0 (mm)
  /// Back-and-forth: time to decelerate to rest and accelerate back at a
  /// turn (s), >= 0. Speed follows a half cosine through each turn, so
  /// acceleration stays finite (peak π·v/turn_s: 3.1 m/s² at 100 mm/s, 0.1 s).
  double turn_s = 0.1;
  double duration_s = 1.0;  ///< length of the trace (s), > 0
  double rate_hz = 1000.0;  ///< trace sample rate (s⁻¹), > 0; 1 kHz ≈ a position sensor
  double lead_in_s = 0.0;   ///< lifted time before the finger lands (s), >= 0
};

/// Validates the config (InvalidArgument naming the field) and samples it.
std::vector<FingerSample> simulate_swipe(const SwipeConfig& config);

/// Reads a trace CSV: header optional, columns time_s, position_mm[, touch]
/// (touch 0/1, default 1). Times must be finite and non-decreasing; throws
/// FormatError naming the line.
std::vector<FingerSample> parse_trace_csv(std::string_view text, std::string_view origin);
std::vector<FingerSample> load_trace_csv(const std::string& path);
/// Writes "time_s,position_mm,touch" with one row per sample.
std::string trace_csv(std::span<const FingerSample> trace);

/// Swipe behaviour of a trace (docs/procedures.md §7). Speeds are taken
/// between consecutive samples that both touch: v_i = Δx/Δt.
struct SwipeMeasures {
  std::size_t intervals = 0;     ///< touched intervals used
  double mean_speed_mm_s = 0.0;  ///< mean of |v_i|
  double sd_speed_mm_s = 0.0;    ///< sample standard deviation of |v_i| (n−1)
  /// (intervals moving right − intervals moving left) / all intervals, in [−1, 1].
  double directional_proportion = 0.0;
  std::size_t moving_right = 0;
  std::size_t moving_left = 0;
  double touched_s = 0.0;    ///< total touched time (s)
  double distance_mm = 0.0;  ///< total path length (mm)
};
/// `still_below_mm_s`: intervals slower than this count as neither right nor
/// left (sensor noise); they still count in "all intervals" and in the speed.
SwipeMeasures swipe_measures(std::span<const FingerSample> trace, double still_below_mm_s = 0.0);

}  // namespace texel
