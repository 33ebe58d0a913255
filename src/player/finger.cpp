// Finger sources (simulated swipes, CSV traces) and swipe measures.
#include "texel/finger.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/player_parts.hpp"

namespace texel {

using detail::num;

std::string_view to_string(SwipePattern p) { return p == SwipePattern::constant ? "constant" : "back-and-forth"; }

SwipePattern parse_swipe_pattern(std::string_view text, std::string_view field) {
  if (text == "constant") return SwipePattern::constant;
  if (text == "back-and-forth" || text == "back_and_forth") return SwipePattern::back_and_forth;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: constant, back-and-forth");
}

namespace {

void require(bool ok, std::string_view field, double v, std::string_view allowed) {
  if (!ok) throw InvalidArgument("swipe: " + std::string(field) + " is " + num(v) + "; " + std::string(allowed));
}

// One stroke from 0 to `extent` with a half-cosine speed profile at both ends
// (rest → v over turn/2, cruise, v → rest over turn/2). Distance covered while
// accelerating: d = v·turn/π. If the extent is too short for that, the turn
// is shortened so the finger just reaches full speed at the middle.
struct Stroke {
  double v, turn, d, cruise, duration;
  Stroke(double speed, double extent, double turn_s) : v(speed), turn(turn_s) {
    d = v * turn / std::numbers::pi;
    if (2 * d > extent) {
      turn = extent * std::numbers::pi / (2 * v);
      d = extent / 2;
    }
    cruise = extent - 2 * d;
    duration = turn + cruise / v;
  }
  [[nodiscard]] double at(double u) const {
    const double half = turn / 2;
    if (u <= 0) return 0;
    if (u < half) return d * (1 - std::cos(std::numbers::pi * u / turn));
    if (u < half + cruise / v) return d + v * (u - half);
    if (u < duration) return d + cruise + d * std::sin(std::numbers::pi * (u - half - cruise / v) / turn);
    return 2 * d + cruise;
  }
};

}  // namespace

std::vector<FingerSample> simulate_swipe(const SwipeConfig& c) {
  require(std::isfinite(c.speed_mm_s) && c.speed_mm_s > 0, "speed_mm_s", c.speed_mm_s, "it must be a finite speed > 0 mm/s");
  require(std::isfinite(c.duration_s) && c.duration_s > 0 && c.duration_s <= 86400, "duration_s", c.duration_s,
          "allowed: > 0 … 86400 s");
  require(std::isfinite(c.rate_hz) && c.rate_hz > 0 && c.rate_hz <= 1e6, "rate_hz", c.rate_hz, "allowed: > 0 … 1e6 Hz");
  require(std::isfinite(c.turn_s) && c.turn_s >= 0 && c.turn_s <= 10, "turn_s", c.turn_s, "allowed: 0 … 10 s");
  require(std::isfinite(c.lead_in_s) && c.lead_in_s >= 0, "lead_in_s", c.lead_in_s, "it must be >= 0 s");
  require(std::isfinite(c.start_mm), "start_mm", c.start_mm, "it must be finite");
  const double extent = c.extent_mm > 0 ? c.extent_mm : c.surface_mm - c.start_mm;
  require(std::isfinite(extent) && extent > 0, "extent_mm", extent,
          "the swipe's extent must be > 0 mm (set extent_mm, or a start inside the surface)");
  const double samples_d = std::floor(c.duration_s * c.rate_hz) + 1;
  require(samples_d <= 5e7, "duration_s·rate_hz", samples_d, "at most 5e7 trace samples");

  std::vector<FingerSample> trace(static_cast<std::size_t>(samples_d));
  const double v = c.speed_mm_s;
  // Constant: repeated one-way strokes at speed v; between strokes the finger
  // is lifted for max(turn_s, 2 samples) and lands again at start_mm.
  const double stroke_s = extent / v;
  const double gap_s = std::max(c.turn_s, 2.0 / c.rate_hz);
  const Stroke stroke(v, extent, c.turn_s);
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const double t = static_cast<double>(i) / c.rate_hz;
    FingerSample& s = trace[i];
    s.t_s = t;
    const double u = t - c.lead_in_s;
    if (u < 0) {
      s.x_mm = c.start_mm;
      s.touch = false;
      continue;
    }
    if (c.pattern == SwipePattern::constant) {
      const double period = stroke_s + gap_s;
      const double in = u - std::floor(u / period) * period;
      if (in < stroke_s) {
        s.x_mm = c.start_mm + v * in;
        s.touch = true;
      } else {
        s.x_mm = c.start_mm + extent;
        s.touch = false;
      }
    } else {
      const double period = 2 * stroke.duration;
      const double in = u - std::floor(u / period) * period;
      s.x_mm = c.start_mm + (in < stroke.duration ? stroke.at(in) : extent - stroke.at(in - stroke.duration));
      s.touch = true;
    }
  }
  return trace;
}

namespace player_parts {

void read_trace_rows(std::string_view text, std::string_view origin, std::size_t positions, const char* expected,
                     const std::function<void(double t, std::span<const double> position, bool touch)>& row) {
  const std::string where(origin);
  bool any = false;
  double last_t = 0.0;
  read_numeric_csv(text, origin, 1 + positions, 2 + positions, expected, [&](std::size_t line, std::span<const double> cols) {
    const std::string at = where + ":" + std::to_string(line) + ": ";
    for (std::size_t i = 0; i <= positions; ++i)
      if (!std::isfinite(cols[i])) throw FormatError(at + "time and position must be finite");
    if (any && cols[0] < last_t)
      throw FormatError(at + "time " + num(cols[0]) + " s is earlier than the previous " + num(last_t) +
                        " s; times must not decrease");
    const bool has_touch = cols.size() == 2 + positions;
    if (has_touch && cols[1 + positions] != 0 && cols[1 + positions] != 1)
      throw FormatError(at + "touch is " + num(cols[1 + positions]) + "; allowed 0 or 1");
    row(cols[0], cols.subspan(1, positions), !has_touch || cols[1 + positions] != 0);
    any = true;
    last_t = cols[0];
  });
  if (!any) throw FormatError(where + ": no samples; expected rows of " + expected);
}

}  // namespace player_parts

std::vector<FingerSample> parse_trace_csv(std::string_view text, std::string_view origin) {
  std::vector<FingerSample> trace;
  player_parts::read_trace_rows(text, origin, 1, "time_s,position_mm[,touch]",
                                [&](double t, std::span<const double> p, bool touch) {
                                  trace.push_back({t, p[0], touch});
                                });
  return trace;
}

std::vector<FingerSample> load_trace_csv(const std::string& path) { return parse_trace_csv(read_file(path), path); }

std::string trace_csv(std::span<const FingerSample> trace) {
  std::string out = "time_s,position_mm,touch\n";
  for (const auto& s : trace) out += num(s.t_s) + "," + num(s.x_mm) + "," + (s.touch ? "1\n" : "0\n");
  return out;
}

SwipeMeasures swipe_measures(std::span<const FingerSample> trace, double still_below_mm_s) {
  SwipeMeasures m;
  double sum = 0, sum2 = 0;
  for (std::size_t i = 1; i < trace.size(); ++i) {
    const FingerSample& a = trace[i - 1];
    const FingerSample& b = trace[i];
    const double dt = b.t_s - a.t_s;
    if (!a.touch || !b.touch || !(dt > 0)) continue;
    const double v = (b.x_mm - a.x_mm) / dt;
    const double speed = std::fabs(v);
    ++m.intervals;
    sum += speed;
    sum2 += speed * speed;
    m.touched_s += dt;
    m.distance_mm += std::fabs(b.x_mm - a.x_mm);
    if (speed >= still_below_mm_s && speed > 0) (v > 0 ? m.moving_right : m.moving_left)++;
  }
  if (m.intervals == 0) return m;
  const auto n = static_cast<double>(m.intervals);
  m.mean_speed_mm_s = sum / n;
  m.sd_speed_mm_s = m.intervals > 1 ? std::sqrt(std::max(0.0, (sum2 - sum * sum / n) / (n - 1))) : 0.0;
  m.directional_proportion = (static_cast<double>(m.moving_right) - static_cast<double>(m.moving_left)) / n;
  return m;
}

}  // namespace texel
