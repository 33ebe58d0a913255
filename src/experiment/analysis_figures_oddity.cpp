// The 2-D oddity studies' figure (analysis_figures_common.hpp): proportion
// correct per condition.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "analysis_figures_common.hpp"

namespace texel::experiment::analysis_figures {

// Proportion correct per condition with its Wilson CI, chance (1/3) dashed;
// conditions coloured by the pair's mode (direction study) or by block
// (the rendering study, whose pairs are all 1-D); for the direction study, the one-sided
// Fisher p of each direction pair against its same-direction baseline
// printed over it.
Figure oddity_figure(const Study& study, const json& s, double level) {
  const char* group = s.contains("direction_effects") ? "mode" : "block";
  std::vector<std::string> names, modes;
  for (const auto& c : s["conditions"]) {
    names.push_back(c["condition"].get<std::string>());
    const std::string m = c[group].get<std::string>();
    if (std::find(modes.begin(), modes.end(), m) == modes.end()) modes.push_back(m);
  }
  Figure f = figure(std::string(study.title) + ": proportion correct (oddity)", category_width(names, 720), 480);
  Panel p;
  p.title = "Proportion correct, " + percent(level) + " Wilson CI; dashed: chance" +
            (s.contains("direction_effects") ? "; p: drop from the same direction (Fisher)" : "");
  p.x = Axis{"condition", AxisScale::linear, std::nullopt, std::nullopt, false, names};
  p.y = Axis{"proportion correct", AxisScale::linear, 0.0, 1.15, false};
  for (std::size_t k = 0; k < modes.size(); ++k) {
    ErrorBarSeries e;
    e.label = modes[k];
    e.colour = palette_colour(k);
    e.cap_px = 0;
    for (std::size_t i = 0; i < names.size(); ++i) {
      const json& c = s["conditions"][i];
      if (c[group] != modes[k]) continue;
      e.x.push_back(static_cast<double>(i));
      e.y.push_back(d(c["proportion"]));
      e.error.push_back(std::nan(""));
      p.lines.push_back(LineSeries{{static_cast<double>(i), static_cast<double>(i)},
                                   {d(c["ci_low"]), d(c["ci_high"])},
                                   palette_colour(k),
                                   2.0,
                                   "",
                                   false});
    }
    p.error_bars.push_back(std::move(e));
  }
  const double n = static_cast<double>(names.size());
  p.lines.push_back(LineSeries{{-0.5, n - 0.5}, {1.0 / 3.0, 1.0 / 3.0}, Rgb{0.5, 0.5, 0.5}, 1.0, "chance", true});
  if (s.contains("direction_effects"))
    for (const auto& e : s["direction_effects"]) {
      const auto it = std::find(names.begin(), names.end(), e["condition"].get<std::string>());
      p.notes.push_back(TextNote{static_cast<double>(it - names.begin()), 1.09,
                                 d(e["p_fisher"]) < 0.001 ? "p < 0.001" : "p = " + texel::detail::fixed(d(e["p_fisher"]), 3),
                                 Rgb{0.1, 0.1, 0.1}, 0.0});
    }
  f.panels.push_back(std::move(p));
  return f;
}

}  // namespace texel::experiment::analysis_figures
