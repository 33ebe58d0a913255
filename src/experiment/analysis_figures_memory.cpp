// The working-memory studies' figures (analysis_figures_common.hpp):
// performance per condition, the components' effects, and main-task errors
// against distraction-task errors.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "analysis_figures_common.hpp"

namespace texel::experiment::analysis_figures {

Figure memory_figure(const Study& study, const json& s) {
  std::vector<std::string> spacings, kinds;
  for (const auto& c : s["conditions"]) {
    const auto sp = c["spacing"].get<std::string>(), kd = c["distractor"].get<std::string>();
    if (std::find(spacings.begin(), spacings.end(), sp) == spacings.end()) spacings.push_back(sp);
    if (std::find(kinds.begin(), kinds.end(), kd) == kinds.end()) kinds.push_back(kd);
  }
  Figure f = figure(std::string(study.title) + ": same/different accuracy (" + std::to_string(s["included"].get<std::size_t>()) +
                        " participants after exclusions)",
                    1280, 480, 2);
  Panel a;
  const std::string anova = anova_text(s["rm_anova"]);
  a.title = anova.empty() ? "Mean ± SEM per condition" : "RM-ANOVA p: " + anova;
  a.x = Axis{"texel spacing", AxisScale::linear, std::nullopt, std::nullopt, false, spacings};
  a.y = Axis{"proportion correct (mean ± SEM)", AxisScale::linear, 0.0, 1.05, false};
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    ErrorBarSeries e;
    e.connect = true;
    e.label = kinds[k];
    e.colour = palette_colour(k);
    for (const auto& c : s["conditions"]) {
      if (c["distractor"] != kinds[k]) continue;
      const auto it = std::find(spacings.begin(), spacings.end(), c["spacing"].get<std::string>());
      e.x.push_back(static_cast<double>(it - spacings.begin()) +
                    (static_cast<double>(k) - 0.5 * static_cast<double>(kinds.size() - 1)) * 0.08);
      e.y.push_back(d(c["accuracy"]["mean"]));
      e.error.push_back(d(c["accuracy"]["sem"]));
    }
    a.error_bars.push_back(std::move(e));
  }
  a.lines.push_back(
      LineSeries{{-0.5, static_cast<double>(spacings.size()) - 0.5}, {0.5, 0.5}, Rgb{0.5, 0.5, 0.5}, 1.0, "chance", true});
  f.panels.push_back(std::move(a));

  Panel b;
  b.title = "Participants (excluded ones left out)";
  std::vector<std::string> conds;
  BoxSeries box;
  box.show_points = true;
  for (const auto& c : s["conditions"]) {
    conds.push_back(c["condition"].get<std::string>());
    std::vector<double> g;
    for (const auto& p : s["participants"])
      if (p["excluded"] == false) g.push_back(d(p["conditions"][conds.back()]));
    box.groups.push_back(std::move(g));
  }
  b.x = Axis{"condition", AxisScale::linear, std::nullopt, std::nullopt, false, conds};
  b.y = Axis{"proportion correct", AxisScale::linear, 0.0, 1.05, false};
  b.boxes.push_back(std::move(box));
  f.panels.push_back(std::move(b));
  return f;
}

/// The components' figure (docs/experiments.md "Working-memory
/// components"): per spacing, each distractor's effect on same/different
/// accuracy — the paired difference distractor − control, mean and its CI
/// (the per-component t-tests) — zero dashed. Only when the distractors are
/// named components (the source's single distractor has its own figure).
std::optional<Figure> memory_components(const json& s, double level) {
  std::vector<std::string> spacings, kinds;
  for (const auto& t : s["spacing_t_tests"]) {
    const auto sp = t["spacing"].get<std::string>(), kd = t["distractor"].get<std::string>();
    if (std::find(spacings.begin(), spacings.end(), sp) == spacings.end()) spacings.push_back(sp);
    if (std::find(kinds.begin(), kinds.end(), kd) == kinds.end()) kinds.push_back(kd);
  }
  if (kinds.size() < 2) return std::nullopt;
  Figure f = figure("Working memory: effect of each distractor on same/different accuracy", 900, 520);
  Panel p;
  p.title = "Distractor − control (paired), mean and " + percent(level) + " CI; Holm p over the family";
  p.x = Axis{"texel spacing", AxisScale::linear, std::nullopt, std::nullopt, false, spacings};
  p.y = Axis{"change in proportion correct", AxisScale::linear, std::nullopt, std::nullopt, false};
  const double width = 0.22;
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    ErrorBarSeries e;
    e.label = kinds[k];
    e.colour = palette_colour(k + 1);  // colour 0 is the control's in the accuracy figure
    for (const auto& t : s["spacing_t_tests"]) {
      if (t["distractor"] != kinds[k] || t["t_test"].contains("skipped")) continue;
      const auto it = std::find(spacings.begin(), spacings.end(), t["spacing"].get<std::string>());
      const double x = static_cast<double>(it - spacings.begin()) +
                       (static_cast<double>(k) - 0.5 * static_cast<double>(kinds.size() - 1)) * width;
      const double mean = d(t["t_test"]["mean"]);
      e.x.push_back(x);
      e.y.push_back(mean);
      e.error.push_back(d(t["t_test"]["ci_high"]) - mean);
      const double ph = t["t_test"].contains("p_holm") ? d(t["t_test"]["p_holm"]) : d(t["t_test"]["p"]);
      if (std::isfinite(ph))
        p.notes.push_back(TextNote{x, d(t["t_test"]["ci_high"]) + 0.02,
                                   ph < 0.001 ? "p < 0.001" : "p = " + texel::detail::fixed(ph, 3), Rgb{0.1, 0.1, 0.1}, 0.0});
    }
    p.error_bars.push_back(std::move(e));
  }
  p.lines.push_back(
      LineSeries{{-0.5, static_cast<double>(spacings.size()) - 0.5}, {0.0, 0.0}, Rgb{0.5, 0.5, 0.5}, 1.0, "no effect", true});
  f.panels.push_back(std::move(p));
  return f;
}

/// The source's trend figure: each participant's main-task errors against
/// their distraction-task errors, the kept participants' least-squares line
/// and its R², the excluded participants marked apart.
std::optional<Figure> memory_errors_trend(const Study& study, const json& s) {
  StemSeries kept, out;
  kept.stems = out.stems = false;
  kept.marker_radius_px = out.marker_radius_px = 4.5;
  kept.label = "participants";
  out.label = "excluded (outlier rule)";
  out.colour = Rgb{0.8, 0.15, 0.1};
  for (const auto& p : s["participants"]) {
    const double x = d(p["distraction_errors"]), y = d(p["main_errors"]);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    StemSeries& to = p["excluded"].is_string() ? out : kept;
    to.x.push_back(x);
    to.y.push_back(y);
  }
  if (kept.x.empty() && out.x.empty()) return std::nullopt;
  const json& r = s["r2"];
  Figure f = figure(std::string(study.title) + ": main-task against distraction-task errors", 700, 520);
  Panel p;
  p.title = r.contains("r2") ? "R² = " + texel::detail::fixed(d(r["r2"]), 4) +
                                   " (kept participants, n = " + std::to_string(r["n"].get<std::size_t>()) + "), " + p_text(r)
                             : "R² skipped: " + r["skipped"].get<std::string>();
  p.x.label = "distraction-task errors (wrong recalls; n-back trials with a miss or false alarm)";
  p.y.label = "main-task (same/different) errors";
  if (r.contains("slope") && !kept.x.empty()) {
    double lo = *std::min_element(kept.x.begin(), kept.x.end()), hi = *std::max_element(kept.x.begin(), kept.x.end());
    for (double x : out.x) lo = std::min(lo, x), hi = std::max(hi, x);
    const double a = d(r["intercept"]), b = d(r["slope"]);
    p.lines.push_back(LineSeries{{lo, hi}, {a + b * lo, a + b * hi}, Rgb{0.3, 0.3, 0.3}, 1.4, "least-squares line (kept)", true});
  }
  p.stems.push_back(std::move(kept));
  if (!out.x.empty()) p.stems.push_back(std::move(out));
  f.panels.push_back(std::move(p));
  return f;
}

}  // namespace texel::experiment::analysis_figures
