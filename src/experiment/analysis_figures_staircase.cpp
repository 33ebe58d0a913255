// The staircase studies' figures (analysis_figures_common.hpp): the tracks,
// box plots of the convergent values, each participant's values across the
// blocks, and swiping direction against the result.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "analysis_figures_common.hpp"

namespace texel::experiment::analysis_figures {

/// Intensity against trial, one line per block, reversals marked; one panel
/// per participant (and session). Only presented trials: the value computed
/// after the last answer was never felt, so it is no point of the track.
Figure staircase_tracks(const Study& study, const Rows& rows) {
  std::map<std::pair<std::string, std::int64_t>, std::map<std::string, Rows>> runs;
  std::vector<std::string> blocks;
  std::map<std::string, std::set<std::int64_t>> sessions;
  for (const TrialRow* r : rows) {
    runs[{r->participant, r->session_id}][r->block].push_back(r);
    sessions[r->participant].insert(r->session_id);
    if (std::find(blocks.begin(), blocks.end(), r->block) == blocks.end()) blocks.push_back(r->block);
  }
  const int cols = static_cast<int>(std::min<std::size_t>(3, runs.size()));
  const int nrows = static_cast<int>((runs.size() + 2) / 3);
  Figure f = figure(std::string(study.title) + " staircases", 420 * cols + 40, std::min(16000, 60 + 300 * nrows), cols);
  for (const auto& [key, by_block] : runs) {
    Panel p;
    p.title = key.first + (sessions[key.first].size() > 1 ? " (session " + std::to_string(key.second) + ")" : "");
    p.x.label = "trial in block";
    p.y.label = variable_label(study);
    for (const auto& [block, rs] : by_block) {
      const auto colour =
          palette_colour(static_cast<std::size_t>(std::find(blocks.begin(), blocks.end(), block) - blocks.begin()));
      LineSeries line;
      StemSeries rev;
      rev.stems = false;
      rev.colour = line.colour = colour;
      rev.marker_radius_px = 4.0;
      for (const TrialRow* r : rs) {
        line.x.push_back(r->trial_in_block + 1);
        line.y.push_back(r->intensity);
        if (r->reversal) rev.x.push_back(r->trial_in_block + 1), rev.y.push_back(r->intensity);
      }
      const bool finished = std::any_of(rs.begin(), rs.end(), [](const TrialRow* r) { return r->procedure_finished; });
      line.width_px = 1.6;
      line.label = finished ? block : block + " (not finished)";
      if (!finished) {
        line.dashed = true;
        p.title += " — not finished: " + block;
      }
      p.lines.push_back(std::move(line));
      p.stems.push_back(std::move(rev));
    }
    for (auto& st : p.stems)
      if (!st.x.empty()) {
        st.label = "reversal";
        break;
      }
    f.panels.push_back(std::move(p));
  }
  return f;
}

/// Box plots of the per-participant convergent values per block, with the
/// group mean ± 95 % CI beside each box.
Figure convergent_boxes(const Study& study, const json& s) {
  const bool coarse = study.blocks_by_fine_strength;
  std::vector<std::string> cats;
  std::map<std::string, std::map<std::string, std::vector<double>>> per;  // block → participant → values
  std::size_t left_out = 0;
  for (const auto& r : s["runs"]) {
    // The runs of the group statistics (unfinished ones only when asked).
    if (!r["in_group_statistics"].get<bool>()) {
      ++left_out;
      continue;
    }
    per[r.contains("group") ? r["group"].get<std::string>() : r["block"].get<std::string>()][r["participant"].get<std::string>()]
        .push_back(d(r["end_value"]));
  }
  BoxSeries box;
  box.colour = palette_colour(0);
  box.label = "participants";
  box.offset = -0.12;
  box.box_width = 0.4;
  box.show_points = true;
  ErrorBarSeries ci;
  ci.colour = palette_colour(3);
  ci.label = "mean ± 95 % CI";
  std::size_t i = 0;
  for (const auto& b : s["blocks"]) {
    const std::string name = b["block"].get<std::string>();
    cats.push_back(coarse ? "fine " + percent(d(b["fine_strength"])) : name);
    std::vector<double> v;
    for (const auto& [p, x] : per[name]) v.push_back(mean_of(x));
    box.groups.push_back(v);
    const auto& c = b["convergent"];
    ci.x.push_back(static_cast<double>(i++) + 0.25);
    ci.y.push_back(d(c["mean"]));
    ci.error.push_back((d(c["ci95_high"]) - d(c["ci95_low"])) / 2);
  }
  Figure f = figure(coarse ? "Convergent coarse strength per fine strength" : "Convergent texel length per group", 640, 480);
  Panel p;
  // The group test beside the boxes it is about.
  if (s.contains("between_groups") && s["between_groups"]["anova"].contains("p"))
    p.title = "between groups, one-way ANOVA: " + p_text(s["between_groups"]["anova"]);
  if (s.contains("rm_anova") && s["rm_anova"].contains("effects")) p.title = "RM-ANOVA p: " + anova_text(s["rm_anova"]);
  // In the figure's title (the panel's holds the group test), wide enough to read.
  if (!s["unfinished_runs"].empty()) f.width_px = 860;
  if (left_out)
    f.title += " (" + std::to_string(left_out) + " run(s) not finished, left out)";
  else if (!s["unfinished_runs"].empty())
    f.title += " (" + std::to_string(s["unfinished_runs"].size()) + " run(s) not finished, included)";
  p.x = Axis{coarse ? "fine-texture strength" : "group (frequency distribution, practice)",
             AxisScale::linear,
             std::nullopt,
             std::nullopt,
             false,
             cats};
  p.y.label = "convergent " + variable_label(study);
  p.boxes.push_back(std::move(box));
  p.error_bars.push_back(std::move(ci));
  f.panels.push_back(std::move(p));
  return f;
}

/// Each participant's convergent value per block as one line across the
/// blocks (the coarse-feature segments, in fine-strength order): the
/// source's per-participant figure beside the box plots.
Figure participant_lines(const Study& study, const json& s) {
  std::vector<std::string> cats, names;
  for (const auto& b : s["blocks"]) {
    names.push_back(b["block"].get<std::string>());
    cats.push_back(study.blocks_by_fine_strength ? "fine " + percent(d(b["fine_strength"])) : names.back());
  }
  std::map<std::string, std::map<std::string, std::vector<double>>> per;  // participant → block → values
  for (const auto& r : s["runs"])
    if (r["in_group_statistics"].get<bool>())
      per[r["participant"].get<std::string>()][r["block"].get<std::string>()].push_back(d(r["end_value"]));
  Figure f = figure(std::string(study.title) + ": each participant across the segments", 720, 480);
  Panel p;
  p.x = Axis{study.blocks_by_fine_strength ? "fine-texture strength" : "block",
             AxisScale::linear,
             std::nullopt,
             std::nullopt,
             false,
             cats};
  p.y.label = "convergent " + variable_label(study);
  std::size_t k = 0;
  for (const auto& [who, blocks] : per) {
    ErrorBarSeries line;
    line.connect = true;
    line.colour = palette_colour(k++);
    line.label = per.size() <= 12 ? who : std::string();
    for (std::size_t i = 0; i < names.size(); ++i)
      if (blocks.count(names[i])) {
        line.x.push_back(static_cast<double>(i));
        line.y.push_back(mean_of(blocks.at(names[i])));
        line.error.push_back(std::nan(""));
      }
    p.error_bars.push_back(std::move(line));
  }
  p.legend = per.size() <= 12;
  f.panels.push_back(std::move(p));
  return f;
}

/// Swiping behaviour against the result: directional proportion of each run
/// against its convergent texel length, one colour per distribution.
std::optional<Figure> directional_scatter(const json& s) {
  std::map<std::string, StemSeries> series;
  std::vector<std::string> order;
  for (const auto& r : s["runs"]) {
    if (!r["in_group_statistics"].get<bool>()) continue;
    const double x = d(r["end_value"]), y = d(r["directional_proportion"]);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    const std::string b = r.contains("group") ? r["group"].get<std::string>() : r["block"].get<std::string>();
    if (!series.count(b)) order.push_back(b);
    auto& st = series[b];
    st.stems = false;
    st.marker_radius_px = 4.5;
    st.label = b;
    st.x.push_back(x);
    st.y.push_back(y);
  }
  if (order.empty()) return std::nullopt;
  Figure f = figure("Directional proportion against convergent texel length", 640, 480);
  Panel p;
  p.x.label = "convergent texel length (mm)";
  p.y = Axis{"directional proportion (right − left) / all", AxisScale::linear, -1.05, 1.05, false};
  for (const auto& b : order) p.stems.push_back(series[b]);
  f.panels.push_back(std::move(p));
  return f;
}

}  // namespace texel::experiment::analysis_figures
