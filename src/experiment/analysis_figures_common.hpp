// What the analysis figures share (internal; analysis_figures.cpp,
// docs/analysis.md): the JSON number helper, axis labels, figure and panel
// builders, p-value and percentage text, and each study's figure builders
// (one study's figures per file: analysis_figures_staircase.cpp,
// analysis_figures_matching.cpp (free and guided matching),
// analysis_figures_quantization.cpp, analysis_figures_memory.cpp,
// analysis_figures_oddity.cpp, analysis_figures_playback.cpp;
// study_figures in analysis_figures.cpp chooses and writes them).
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis_figures.hpp"
#include "studies.hpp"
#include "texel/detail/format.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/stats.hpp"
#include "texel/plot.hpp"

namespace texel::experiment::analysis_figures {

using json = nlohmann::ordered_json;
using Rows = std::vector<const TrialRow*>;

inline double d(const json& j) { return j.is_number() ? j.get<double>() : missing; }

inline const std::string pitch_label = "Central Pitch (dB re 1 cycle/mm)";
inline const std::string irregularity_label = "Irregularity (dB)";

inline Figure figure(std::string title, int width, int height, int columns = 1) {
  Figure f;
  f.title = std::move(title);
  f.width_px = width;
  f.height_px = height;
  f.columns = columns;
  return f;
}

/// Mean of the finite values (NaN when there are none).
inline double mean_of(const std::vector<double>& v) { return stats::describe(v).mean; }

inline std::string p_text(const json& t) {
  if (!t.contains("p") || t["p"].is_null()) return "n/a";
  const double p = d(t["p"]);
  return p < 0.001 ? "p < 0.001" : "p = " + texel::detail::fixed(p, 3);
}

/// "spacing 0.012, distractor < 0.001, interaction 0.2": the p value of
/// each effect of an ANOVA summary (short enough for a panel title); empty
/// if the ANOVA was skipped.
inline std::string anova_text(const json& a) {
  if (!a.contains("effects")) return {};
  std::string out;
  for (const auto& e : a["effects"]) {
    if (!out.empty()) out += ", ";
    std::string name = e["effect"].get<std::string>();
    if (name.find(':') != std::string::npos) name = "interaction";
    const double p = d(e["p"]);
    out += name + " " +
           (!std::isfinite(p) ? std::string("n/a")
            : p < 0.001       ? std::string("< 0.001")
                              : texel::detail::fixed(p, 3));
  }
  return out;
}

/// A figure width that leaves every category label of `names` room to be
/// printed (tick labels that would overlap are thinned otherwise): about
/// 7.5 px per character at the tick font, at least `min_px`.
inline int category_width(const std::vector<std::string>& names, int min_px) {
  std::size_t longest = 0;
  for (const auto& n : names) longest = std::max(longest, n.size());
  const double per = std::max(90.0, 7.5 * static_cast<double>(longest) + 20.0);
  return std::clamp(static_cast<int>(per * static_cast<double>(names.size())) + 200, min_px, 16000);
}

inline std::string percent(double v) { return texel::detail::fixed(v * 100, 0) + " %"; }

inline std::string variable_label(const Study& study) { return std::string(study.variable_label); }

/// A panel of box plots per reference (categories in `names`' order) of each
/// participant's mean value; `v`: reference → participant → values.
inline Panel reference_boxes(const std::vector<std::string>& names,
                             std::map<std::string, std::map<std::string, std::vector<double>>>& v) {
  Panel p;
  p.x = Axis{"reference", AxisScale::linear, std::nullopt, std::nullopt, false, names};
  BoxSeries box;
  box.show_points = true;
  for (const auto& n : names) {
    std::vector<double> g;
    for (const auto& [pp, x] : v[n]) g.push_back(mean_of(x));
    box.groups.push_back(std::move(g));
  }
  p.boxes.push_back(std::move(box));
  return p;
}

// ---------------------------------------------------- each study's figures

// staircases (analysis_figures_staircase.cpp; staircase_tracks in analysis_figures.hpp)
Figure convergent_boxes(const Study& study, const json& s);
Figure participant_lines(const Study& study, const json& s);
std::optional<Figure> directional_scatter(const json& s);

// free and guided matching (analysis_figures_matching.cpp)
Figure matched_vs_reference(const std::string& title, const json& s);
Figure matched_boxes(const std::string& title, const json& s);
Figure match_ellipses(const std::string& title, const json& s, double level);
std::optional<Figure> confidence_vs_distance(const std::string& title, const json& s);
std::optional<Figure> confidence_bins(const std::string& title, const json& s);
Figure rating_boxes(const std::string& title, const Rows& rows, const std::string& scale);
std::optional<Figure> irregularity_normalised_figure(const json& s, const Rows& rows);
std::optional<Figure> comparisons_figure(const json& s);
Figure similarity_heatmap(const json& sim, const std::string& title, double lo, double hi, const std::string& column_label);
Figure guided_convergence(const Rows& rows);

// quantization (analysis_figures_quantization.cpp)
std::optional<Figure> match_similarity(const Rows& rows);
Figure quantization_figure(const json& s, const Rows& rows);

// working memory (analysis_figures_memory.cpp)
Figure memory_figure(const Study& study, const json& s);
std::optional<Figure> memory_components(const json& s, double level);
std::optional<Figure> memory_errors_trend(const Study& study, const json& s);

// 2-D oddity (analysis_figures_oddity.cpp) and distributed irregularity
// (analysis_figures_playback.cpp)
Figure oddity_figure(const Study& study, const json& s, double level);
Figure playback_figure(const Study& study, const json& s, double level);

}  // namespace texel::experiment::analysis_figures
