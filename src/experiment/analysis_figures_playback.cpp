// The distributed-irregularity study's figure (analysis_figures_common.hpp):
// proportion correct against the shift, the fitted dip and the PSE.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "analysis_common.hpp"
#include "analysis_figures_common.hpp"

namespace texel::experiment::analysis_figures {

// Distributed irregularity: one panel per Irregularity level, proportion
// correct against the shift with Wilson CIs, the fitted dip, the PSE and its
// bootstrap CI, the seed-only control at the left, chance dashed.
Figure playback_figure(const Study& study, const json& s, double level) {
  const json& levels = s["levels"];
  Figure f = figure(std::string(study.title) + ": proportion correct against the sequential texture's shift", 900,
                    std::max<int>(320, 300 * static_cast<int>(levels.size())));
  for (const auto& lj : levels) {
    Panel p;
    p.title = "simultaneous at Irregularity " + texel::detail::fixed(d(lj["irregularity_db"]), 1) + " dB; " + percent(level) +
              " Wilson CIs; dashed: chance";
    double lo = 0, hi = 0;
    for (const auto& c : lj["shifts"]) lo = std::min(lo, d(c["shift_db"])), hi = std::max(hi, d(c["shift_db"]));
    const double left = lo - 3;  // the control's column
    p.x = Axis{"shift: sequential minus simultaneous Irregularity (dB)", AxisScale::linear, left - 1.5, hi + 1.5, false};
    p.y = Axis{"proportion correct", AxisScale::linear, 0.0, 1.05, false};
    ErrorBarSeries e;
    e.label = "pooled over participants";
    e.colour = palette_colour(0);
    e.cap_px = 0;
    for (const auto& c : lj["shifts"]) {
      const double x = d(c["shift_db"]);
      e.x.push_back(x);
      e.y.push_back(d(c["proportion"]));
      e.error.push_back(std::nan(""));
      p.lines.push_back(LineSeries{{x, x}, {d(c["ci_low"]), d(c["ci_high"])}, palette_colour(0), 2.0, "", false});
    }
    p.error_bars.push_back(std::move(e));
    if (lj.contains("control")) {
      const json& c = lj["control"];
      ErrorBarSeries ce;
      ce.label = "control (seeds differ only)";
      ce.colour = palette_colour(2);
      ce.cap_px = 0;
      ce.x = {left};
      ce.y = {d(c["proportion"])};
      ce.error = {std::nan("")};
      p.lines.push_back(LineSeries{{left, left}, {d(c["ci_low"]), d(c["ci_high"])}, palette_colour(2), 2.0, "", false});
      p.error_bars.push_back(std::move(ce));
      p.notes.push_back(TextNote{left, 0.06, "control", palette_colour(2), 0.0});
    }
    const json& pj = lj["pse"];
    if (pj.contains("pse_db")) {
      const double pse = d(pj["pse_db"]), alpha = d(pj["alpha_db"]);
      LineSeries curve;
      curve.colour = palette_colour(1);
      curve.label = "fitted dip";
      for (int i = 0; i <= 200; ++i) {
        const double x = lo - 1 + (hi - lo + 2) * i / 200.0;
        curve.x.push_back(x);
        curve.y.push_back(analysis_common::playback_dip(x, pse, alpha));
      }
      p.lines.push_back(std::move(curve));
      std::string label = "PSE " + texel::detail::fixed(pse, 2) + " dB";
      if (pj.contains("ci_low")) {
        label += " [" + texel::detail::fixed(d(pj["ci_low"]), 2) + ", " + texel::detail::fixed(d(pj["ci_high"]), 2) + "]";
        p.lines.push_back(LineSeries{{d(pj["ci_low"]), d(pj["ci_high"])}, {0.97, 0.97}, palette_colour(1), 4.0, "", false});
      }
      p.markers.push_back(VerticalMarker{pse, label, palette_colour(1), true});
    }
    p.lines.push_back(LineSeries{{left - 1.5, hi + 1.5}, {1.0 / 3.0, 1.0 / 3.0}, Rgb{0.5, 0.5, 0.5}, 1.0, "chance", true});
    f.panels.push_back(std::move(p));
  }
  return f;
}

}  // namespace texel::experiment::analysis_figures
