// The finger that explored a trial (finger_trace.hpp).
#include "texel/experiment/finger_trace.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::experiment {

std::string_view to_string(PresentationMode m) {
  switch (m) {
    case PresentationMode::display_plays: return "display-plays";
    case PresentationMode::host_streams: return "host-streams";
    case PresentationMode::passive: return "passive";
  }
  return "passive";
}

PresentationMode parse_presentation_mode(std::string_view text, std::string_view field) {
  for (const auto m : {PresentationMode::display_plays, PresentationMode::host_streams, PresentationMode::passive})
    if (text == to_string(m)) return m;
  throw FieldError(std::string(field), "is '" + std::string(text) + "'; allowed: display-plays, host-streams, passive");
}

std::string_view to_string(TraceSource s) {
  switch (s) {
    case TraceSource::none: return "";
    case TraceSource::display: return "display";
    case TraceSource::pointer: return "pointer";
    case TraceSource::simulated: return "simulated";
  }
  return "";
}

TraceSource parse_trace_source(std::string_view text, std::string_view field) {
  for (const auto s : {TraceSource::none, TraceSource::display, TraceSource::pointer, TraceSource::simulated})
    if (text == to_string(s)) return s;
  throw FieldError(std::string(field), "is '" + std::string(text) + "'; allowed: display, pointer, simulated (or empty)");
}

std::string_view flag_code(std::string_view flag) { return flag.substr(0, flag.find(':')); }

TraceMeasures measure_trace(std::span<const FingerSample> s, const SwipeLimits& limits) {
  if (!(limits.max_speed_mm_s > 0) || !(limits.min_touched_s >= 0) || !(limits.still_speed_mm_s >= 0) ||
      !(limits.time_resolution_s > 0 && limits.time_resolution_s < 1))
    throw InvalidArgument("swipe limits: max_speed_mm_s is " + detail::num(limits.max_speed_mm_s) + ", min_touched_s " +
                          detail::num(limits.min_touched_s) + ", still_speed_mm_s " + detail::num(limits.still_speed_mm_s) +
                          ", time_resolution_s " + detail::num(limits.time_resolution_s) +
                          "; allowed: > 0, >= 0, >= 0, 0 < … < 1");
  TraceMeasures out;
  bool touched = false;
  // Spans of consecutive touching samples at least two clock ticks long,
  // timed generously: a source's rounding cannot make a hand look fast; a
  // jump (a missed lift) or a burst stamped at one instant still does.
  const double min_span = 2 * limits.time_resolution_s;
  std::size_t span_from = 0;
  double span_path = 0.0;
  const auto close_span = [&](std::size_t to) {
    if (to > span_from) {
      // The span lasted at least its stamps' difference less one tick and at most plus one: only the
      // longer time is certain not to exaggerate the speed.
      const double dt = s[to].t_s - s[span_from].t_s + limits.time_resolution_s;
      out.max_speed_mm_s = std::max(out.max_speed_mm_s, span_path / dt);
    }
    span_from = to;
    span_path = 0.0;
  };
  for (std::size_t i = 0; i < s.size(); ++i) {
    touched = touched || s[i].touch;
    if (!std::isfinite(s[i].t_s) || !std::isfinite(s[i].x_mm)) {
      out.flag = "time_not_increasing: sample " + std::to_string(i + 1) + " has no finite time or place";
      return out;
    }
    if (i == 0) continue;
    if (s[i].t_s < s[i - 1].t_s) {
      out.flag = "time_not_increasing: sample " + std::to_string(i + 1) + " at " + detail::fixed(s[i].t_s, 6) +
                 " s follows one at " + detail::fixed(s[i - 1].t_s, 6) + " s";
      return out;
    }
    if (!s[i].touch || !s[i - 1].touch) {
      close_span(i - 1);
      span_from = i;
      continue;
    }
    span_path += std::fabs(s[i].x_mm - s[i - 1].x_mm);
    if (s[i].t_s - s[span_from].t_s >= min_span) close_span(i);
  }
  if (!s.empty()) close_span(s.size() - 1);
  const SwipeMeasures m = swipe_measures(s, limits.still_speed_mm_s);
  if (!touched || (m.intervals == 0 && out.max_speed_mm_s == 0)) {
    out.flag = "no_touch";  // touched in single samples only, or never: nothing to measure
    return out;
  }
  const double sustained = m.touched_s > 0 ? m.distance_mm / m.touched_s : 0.0;
  const double fastest = std::max({m.mean_speed_mm_s, sustained, out.max_speed_mm_s});
  if (fastest > limits.max_speed_mm_s) {
    out.flag = "implausible_speed: mean " + detail::fixed(m.mean_speed_mm_s, 1) + " mm/s, sustained " +
               detail::fixed(sustained, 1) + " mm/s, fastest span " + detail::fixed(out.max_speed_mm_s, 1) +
               " mm/s; allowed: at most " + detail::num(limits.max_speed_mm_s) + " mm/s";
    return out;
  }
  if (m.intervals < limits.min_intervals || m.touched_s < limits.min_touched_s) {
    out.flag = "too_short: " + std::to_string(m.intervals) + " intervals over " + detail::fixed(m.touched_s, 3) +
               " s touched; needed: at least " + std::to_string(limits.min_intervals) + " intervals and " +
               detail::num(limits.min_touched_s) + " s";
    return out;
  }
  out.measures = m;
  return out;
}

TraceMeasures measure_trace(const FingerTrace& trace, const SwipeLimits& limits) {
  return measure_trace(std::span<const FingerSample>(trace.samples), limits);
}

std::string trace_samples_text(std::span<const FingerSample> samples) {
  std::string out;
  out.reserve(samples.size() * 24);
  char line[96];
  for (const FingerSample& s : samples) {
    const int n = std::snprintf(line, sizeof line, "%.6f,%.6f,%d\n", s.t_s, s.x_mm, s.touch ? 1 : 0);
    out.append(line, static_cast<std::size_t>(n));
  }
  return out;
}

std::vector<FingerSample> parse_trace_samples(std::string_view text, std::string_view origin) {
  std::vector<FingerSample> out;
  std::size_t at = 0;
  int line_no = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    const std::string line(text.substr(at, end - at));
    at = end + 1;
    ++line_no;
    if (line.empty()) continue;
    FingerSample s;
    int touch = 0;
    char tail = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%d%c", &s.t_s, &s.x_mm, &touch, &tail) != 3 || (touch != 0 && touch != 1))
      throw FormatError(std::string(origin) + ": finger trace line " + std::to_string(line_no) + " is '" + line +
                        "'; expected t_s,x_mm,touch (touch 0 or 1)");
    s.touch = touch == 1;
    out.push_back(s);
  }
  return out;
}

}  // namespace texel::experiment
