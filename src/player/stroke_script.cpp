// The scripted 1-D finger (see stroke_script.hpp).
#include "texel/stroke_script.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"

namespace texel {

namespace {

// One stream per quantity (Stream::user + 60 …), counter = stroke index.
constexpr std::uint64_t stream_speed = static_cast<std::uint64_t>(Stream::user) + 60;
constexpr std::uint64_t stream_extent = static_cast<std::uint64_t>(Stream::user) + 61;
constexpr std::uint64_t stream_pause = static_cast<std::uint64_t>(Stream::user) + 62;
constexpr std::uint64_t stream_lift = static_cast<std::uint64_t>(Stream::user) + 63;

void check(const char* field, double v, double lo, double hi, const char* unit) {
  if (!(v >= lo && v <= hi))
    throw InvalidArgument(std::string("stroke script: ") + field + " is " + detail::num(v) + "; allowed " + detail::num(lo) +
                          " … " + detail::num(hi) + unit);
}

// Distance covered after τ seconds of a stroke of length T that cruises at
// v and ramps up and down over r seconds along half cosines.
double stroke_distance(double tau, double T, double r, double v) {
  const auto ramp = [&](double s) {
    return r > 0 ? v * (s / 2 - r / (2 * std::numbers::pi) * std::sin(std::numbers::pi * s / r)) : 0.0;
  };
  if (tau <= r) return ramp(tau);
  if (tau <= T - r) return v * r / 2 + v * (tau - r);
  return v * (T - r) - ramp(T - tau);  // symmetric: total v·(T − r)
}

}  // namespace

void validate(const StrokeScriptConfig& c) {
  check("from", c.from_mm, -2000, 2000, " mm");
  check("to", c.to_mm, -2000, 2000, " mm");
  if (!(std::abs(c.to_mm - c.from_mm) >= 1.0))
    throw InvalidArgument("stroke script: from and to are " + detail::num(c.from_mm) + " and " + detail::num(c.to_mm) +
                          " mm; they must be at least 1 mm apart");
  check("speed", c.speed_mm_s, 1, 2000, " mm/s");
  check("speed variation", c.speed_variation, 0, 1, "");
  check("extent variation", c.extent_variation, 0, 0.45, "");
  check("pause", c.pause_s, 0, 5, " s");
  check("lift probability", c.lift_probability, 0, 1, "");
  check("lift", c.lift_s, 0.001, 10, " s");
  check("ramp", c.ramp_s, 0, 1, " s");
  check("duration", c.duration_s, 1, 86400, " s");
}

StrokeScript::StrokeScript(const StrokeScriptConfig& config) : config_(config) {
  validate(config_);
  const CounterRng speed(config_.seed, stream_speed), extent(config_.seed, stream_extent), pause(config_.seed, stream_pause),
      lift(config_.seed, stream_lift);
  const double lo = std::min(config_.from_mm, config_.to_mm), hi = std::max(config_.from_mm, config_.to_mm);
  const double span = hi - lo;
  double t = 0.0, x = config_.from_mm;
  int dir = config_.to_mm > config_.from_mm ? 1 : -1;
  for (std::uint64_t k = 0;; ++k) {
    // The stroke: to the end it heads for, stopping short by a drawn amount.
    const double short_by = config_.extent_variation * span * extent.uniform(k);
    const double target = dir > 0 ? hi - short_by : lo + short_by;
    const double distance = std::abs(target - x);
    const double v = config_.speed_mm_s * std::exp(config_.speed_variation * speed.normal(k));
    const double T = std::max(distance / v, 1e-3);
    const double r = std::min(config_.ramp_s, T / 2);
    segments_.push_back({t, t + T, x, target, r, Kind::stroke});
    ++strokes_;
    t += T;
    x = target;
    const double p = 2.0 * config_.pause_s * pause.uniform(k);
    if (p > 0) {
      segments_.push_back({t, t + p, x, x, 0.0, Kind::pause});
      t += p;
    }
    const bool last = t >= config_.duration_s;
    if (last || lift.uniform(k) < config_.lift_probability) {
      // Lifted above where the stroke ended; lands where the next begins: the
      // start of this stroke's side (the same direction again), or at the
      // script's start after its last stroke.
      segments_.push_back({t, t + config_.lift_s, x, x, 0.0, Kind::lift});
      t += config_.lift_s;
      x = last ? config_.from_mm : (dir > 0 ? lo + short_by : hi - short_by);
      if (last) break;
    } else {
      dir = -dir;
    }
  }
  period_s_ = t;
}

FingerSample StrokeScript::at(double t_s) const noexcept {
  double t = std::fmod(t_s, period_s_);
  if (!(t >= 0)) t = t < 0 ? t + period_s_ : 0.0;  // negative or NaN
  auto it = std::upper_bound(segments_.begin(), segments_.end(), t, [](double v, const Segment& s) { return v < s.t0; });
  const Segment& s = *std::prev(it == segments_.begin() ? std::next(it) : it);
  FingerSample f{t_s, s.x1, s.kind != Kind::lift};
  if (s.kind == Kind::stroke) {
    const double T = s.t1 - s.t0, d = std::abs(s.x1 - s.x0);
    const double tau = std::clamp(t - s.t0, 0.0, T);
    const double v = d / (T - s.ramp_s);
    const double moved = std::min(d, stroke_distance(tau, T, s.ramp_s, v));
    f.x_mm = s.x0 + (s.x1 > s.x0 ? moved : -moved);
  }
  return f;
}

std::vector<FingerSample> StrokeScript::trace(double rate_hz, double from_s, double to_s) const {
  check("trace rate", rate_hz, 1, 100000, " Hz");
  if (!(std::isfinite(from_s) && std::isfinite(to_s) && to_s >= from_s && (to_s - from_s) * rate_hz <= 1e8))
    throw InvalidArgument("stroke script: trace from " + detail::num(from_s) + " to " + detail::num(to_s) +
                          " s; allowed from <= to, at most 10^8 samples");
  const auto n = static_cast<std::size_t>(std::ceil((to_s - from_s) * rate_hz - 1e-9));
  std::vector<FingerSample> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) out.push_back(at(from_s + static_cast<double>(i) / rate_hz));
  return out;
}

}  // namespace texel
