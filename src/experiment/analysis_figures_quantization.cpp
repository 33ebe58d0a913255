// The quantization study's figures (analysis_figures_common.hpp): the
// rating change per quantization step and how similar the matches feel.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "analysis_figures_common.hpp"

namespace texel::experiment::analysis_figures {

/// How similar the free-exploration matches feel: the unquantized ratings
/// of the quantization study (each reference against the participant's own
/// match, or the rater's), box plots per reference of each participant's
/// rating (the source's figure of match similarity).
std::optional<Figure> match_similarity(const Rows& rows) {
  std::vector<std::string> names;
  std::map<std::string, std::map<std::string, std::vector<double>>> v;
  for (const TrialRow* r : rows) {
    if (r->task != "rating" || r->condition != "unquantized") continue;
    if (std::find(names.begin(), names.end(), r->reference) == names.end()) names.push_back(r->reference);
    v[r->reference][r->participant].push_back(r->rating);
  }
  if (names.empty()) return std::nullopt;
  Figure f = figure("Free-exploration matches: similarity to the reference (unquantized)", category_width(names, 700), 480);
  Panel p = reference_boxes(names, v);
  p.y = Axis{"similarity rating (1 … 5)", AxisScale::linear, 0.8, 5.2, false};
  f.panels.push_back(std::move(p));
  return f;
}

Figure quantization_figure(const json& s, const Rows& rows) {
  // Per texture: mean change ± 95 % CI per quantization step, its p value above.
  std::vector<std::string> cats;
  for (const auto& t : s["textures"])
    for (const auto& c : t["changes"]) {
      const std::string cat = texel::detail::num(d(c["quantization_db"])) + " dB";
      if (std::find(cats.begin(), cats.end(), cat) == cats.end()) cats.push_back(cat);
    }
  Figure f = figure("Quantization: similarity rating change against unquantized, per texture", 1100, 480, 2);
  Panel a;
  a.title = "Change per quantization step and texture";
  a.x = Axis{"quantization step", AxisScale::linear, std::nullopt, std::nullopt, false, cats};
  a.y.label = "rating change (rating points, 1 … 5 scale)";
  const double n = static_cast<double>(cats.size());
  a.lines.push_back(LineSeries{{-0.5, n - 0.5}, {0, 0}, Rgb{0.45, 0.45, 0.45}, 1.0, {}, true});
  double lo = 0, hi = 0;
  const double textures = static_cast<double>(s["textures"].size());
  std::size_t k = 0;
  for (const auto& t : s["textures"]) {
    ErrorBarSeries eb;
    eb.colour = palette_colour(k);
    eb.label = t["reference"].get<std::string>() + " (mean ± 95 % CI)";
    const double offset = (static_cast<double>(k) - (textures - 1) / 2) * 0.25;
    for (const auto& c : t["changes"]) {
      const std::string cat = texel::detail::num(d(c["quantization_db"])) + " dB";
      const double x = static_cast<double>(std::find(cats.begin(), cats.end(), cat) - cats.begin()) + offset;
      const double m = d(c["change"]["mean"]);
      const double half = c["t_test"].contains("ci_high") ? (d(c["t_test"]["ci_high"]) - d(c["t_test"]["ci_low"])) / 2 : missing;
      eb.x.push_back(x);
      eb.y.push_back(m);
      eb.error.push_back(half);
      const double top = m + (std::isfinite(half) ? half : 0);
      if (std::isfinite(m)) {
        lo = std::min(lo, m - (std::isfinite(half) ? half : 0)), hi = std::max(hi, top);
        // Staggered per texture so neighbouring labels do not overlap.
        a.notes.push_back(TextNote{x, top, p_text(c["t_test"]), palette_colour(k), -12.0 - 13.0 * static_cast<double>(k)});
      }
    }
    a.error_bars.push_back(std::move(eb));
    ++k;
  }
  // Room above the highest bar for its p value.
  if (hi > lo) a.y.max = hi + (hi - lo) * (0.15 + 0.08 * textures);
  f.panels.push_back(std::move(a));

  // Ratings per condition (per-participant means over references).
  std::vector<std::string> conds;
  std::map<std::string, std::map<std::string, std::vector<double>>> v;
  for (const auto& c : s["conditions"]) conds.push_back(c["condition"].get<std::string>());
  for (const TrialRow* r : rows)
    if (r->task == "rating") v[r->condition][r->participant].push_back(r->rating);
  Panel b;
  b.title = "Ratings per condition";
  b.x = Axis{"rendering", AxisScale::linear, std::nullopt, std::nullopt, false, conds};
  b.y = Axis{"similarity rating (1 … 5)", AxisScale::linear, 0.8, 5.2, false};
  BoxSeries box;
  box.show_points = true;
  for (const auto& c : conds) {
    std::vector<double> g;
    for (const auto& [pp, x] : v[c]) g.push_back(mean_of(x));
    box.groups.push_back(std::move(g));
  }
  b.boxes.push_back(std::move(box));
  f.panels.push_back(std::move(b));
  return f;
}

}  // namespace texel::experiment::analysis_figures
