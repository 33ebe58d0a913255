// The finger that explored a trial (finger_trace.hpp).
#include "texel/experiment/finger_trace.hpp"

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

TraceMeasures measure_trace(const FingerTrace& trace) {
  TraceMeasures out;
  const auto& s = trace.samples;
  bool touched = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    touched = touched || s[i].touch;
    if (!std::isfinite(s[i].t_s) || !std::isfinite(s[i].x_mm)) {
      out.flag = "time_not_increasing";  // a sample without a usable time or place is no measurement
      return out;
    }
    if (i == 0) continue;
    const double dt = s[i].t_s - s[i - 1].t_s;
    if (dt < 0) {
      out.flag = "time_not_increasing";
      return out;
    }
    if (!s[i].touch || !s[i - 1].touch) continue;
    const double dx = std::fabs(s[i].x_mm - s[i - 1].x_mm);
    // Two touching samples at one instant in two places: an infinite speed.
    const double v = dt > 0 ? dx / dt : (dx > 0 ? INFINITY : 0.0);
    out.max_speed_mm_s = std::max(out.max_speed_mm_s, v);
  }
  if (!touched) {
    out.flag = "no_touch";
    return out;
  }
  if (out.max_speed_mm_s > max_plausible_speed_mm_s) {
    out.flag = "implausible_speed";
    return out;
  }
  const SwipeMeasures m = swipe_measures(s, still_speed_mm_s);
  if (m.intervals == 0) {
    out.flag = "no_touch";  // touched in single samples only: no interval to measure
    return out;
  }
  out.measures = m;
  return out;
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
