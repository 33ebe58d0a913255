// Strokes on a 2-D display, per interval (strokes.hpp).
#include "texel/experiment/strokes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::experiment {

namespace {
constexpr double deg = 180.0 / std::numbers::pi;
}

void validate(const StrokeRules& r) {
  if (!(r.tolerance_deg >= 0 && r.tolerance_deg <= 90))
    throw InvalidArgument("direction tolerance is " + detail::num(r.tolerance_deg) + "°; allowed: 0 … 90°");
  if (!(r.min_stroke_mm > 0 && r.min_stroke_mm <= 1000))
    throw InvalidArgument("shortest stroke is " + detail::num(r.min_stroke_mm) + " mm; allowed: > 0 … 1000 mm");
  if (!(r.min_straightness >= 0 && r.min_straightness <= 1))
    throw InvalidArgument("straightness is " + detail::num(r.min_straightness) + "; allowed: 0 … 1");
  if (!(r.max_speed_mm_s > 0) || !(r.max_gap_s > 0))
    throw InvalidArgument("stroke jump limits must be > 0 (speed " + detail::num(r.max_speed_mm_s) + " mm/s, gap " +
                          detail::num(r.max_gap_s) + " s)");
}

double line_direction(double d) {
  double a = std::fmod(d, 180.0);
  if (a < 0) a += 180.0;
  return a >= 180.0 ? 0.0 : a;
}

double line_angle_difference(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 180.0);
  return std::min(d, 180.0 - d);
}

void StrokeRecorder::add(double t_s, double x_mm, double y_mm, bool touch) {
  if (!touch) {
    if (down_) end_stroke();
    return;
  }
  if (down_) {
    const double dx = x_mm - x_, dy = y_mm - y_;
    const double len = std::hypot(dx, dy), dt = t_s - t_;
    if (dt > rules_.max_gap_s || len > rules_.max_speed_mm_s * std::max(dt, 1e-3)) end_stroke();  // a jump: a new stroke
  }
  if (down_) {
    const double dx = x_mm - x_, dy = y_mm - y_;
    const double len = std::hypot(dx, dy);
    if (len > 0) {
      const double phi = std::atan2(dy, dx);
      stroke_.path += len;
      stroke_.c2 += len * std::cos(2 * phi);
      stroke_.s2 += len * std::sin(2 * phi);
    }
    if (t_s > t_) stroke_.seconds += t_s - t_;
  }
  down_ = true;
  t_ = t_s;
  x_ = x_mm;
  y_ = y_mm;
}

void StrokeRecorder::end_stroke() {
  down_ = false;
  if (stroke_.path >= rules_.min_stroke_mm) {
    done_.path += stroke_.path;
    done_.seconds += stroke_.seconds;
    done_.c2 += stroke_.c2;
    done_.s2 += stroke_.s2;
    done_.strokes += 1;
  }
  stroke_ = {};
}

IntervalStrokes StrokeRecorder::summary(const std::string& stimulus, double instructed_deg) const {
  StrokeRecorder r = *this;  // a stroke in progress ends here
  if (r.down_) r.end_stroke();
  const StrokeRules& rules = rules_;
  IntervalStrokes s;
  s.stimulus = stimulus;
  s.instructed_deg = line_direction(instructed_deg);
  s.tolerance_deg = rules.tolerance_deg;
  s.strokes = r.done_.strokes;
  s.path_mm = r.done_.path;
  s.touched_s = r.done_.seconds;
  if (s.strokes > 0) {
    s.direction_deg = line_direction(0.5 * std::atan2(r.done_.s2, r.done_.c2) * deg);
    s.straightness = std::hypot(r.done_.c2, r.done_.s2) / r.done_.path;
    s.deviation_deg = line_angle_difference(s.direction_deg, s.instructed_deg);
    if (s.touched_s > 0) s.mean_speed_mm_s = s.path_mm / s.touched_s;
    s.compliant = s.straightness >= rules.min_straightness && s.deviation_deg <= rules.tolerance_deg;
  }
  return s;
}

void fill_stroke_columns(const std::vector<IntervalStrokes>& intervals, std::size_t stimuli, TrialRow& row) {
  if (intervals.empty()) return;
  int strokes = 0;
  double worst = missing, path = 0.0, seconds = 0.0;
  std::size_t complied = 0;
  for (const auto& i : intervals) {
    strokes += i.strokes;
    path += i.path_mm;
    seconds += i.touched_s;
    if (std::isfinite(i.deviation_deg)) worst = std::isfinite(worst) ? std::max(worst, i.deviation_deg) : i.deviation_deg;
    if (i.compliant) ++complied;
  }
  row.strokes = strokes;
  row.stroke_deviation_deg = worst;
  row.direction_compliant = complied == stimuli && intervals.size() == stimuli ? 1.0 : 0.0;
  if (seconds > 0) row.swipe_mean_speed_mm_s = path / seconds;
}

std::string direction_words(double d) {
  const double a = line_direction(d);
  const auto whole = [](double v) { return std::to_string(static_cast<int>(std::lround(v))); };
  if (line_angle_difference(a, 0.0) < 0.5) return "↔ left–right (horizontal)";
  if (line_angle_difference(a, 90.0) < 0.5) return "↕ up–down (vertical)";
  // The surface's y axis points down the screen: an angle from +x towards +y
  // turns clockwise as the participant looks at the display.
  if (a < 90.0) return "⤡ falling to the right, " + whole(a) + "° from horizontal";
  return "⤢ rising to the right, " + whole(180.0 - a) + "° from horizontal";
}

}  // namespace texel::experiment
