// The analysis figures (analysis.hpp): each mirrors a figure of the thesis
// for its study, so a researcher can set them side by side — staircase
// tracks, box plots of convergent values with 95 % CIs, matched parameters
// against the references, confidence ellipses of the mean match, similarity
// matrices, rating changes under quantization, working-memory performance.
// docs/analysis.md says which question of the source each one answers.
//
// Figures are built from the study's summary (so a figure never disagrees
// with the numbers reported next to it) plus the rows where a figure shows
// every trial (tracks). Every file is written through save_figure, i.e.
// atomically (temporary + rename).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "analysis_common.hpp"
#include "analysis_figures.hpp"
#include "json_views.hpp"
#include "studies.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/stats.hpp"
#include "texel/plot.hpp"

namespace texel::experiment::analysis_figures {
namespace {

using json = nlohmann::ordered_json;
using Rows = std::vector<const TrialRow*>;

double d(const json& j) { return j.is_number() ? j.get<double>() : missing; }

const std::string pitch_label = "Central Pitch (dB re 1 cycle/mm)";
const std::string irregularity_label = "Irregularity (dB)";

struct Writer {
  const std::string& study;
  const AnalysisOptions& o;
  std::vector<std::string> paths;
  void save(const Figure& f, const std::string& name) {
    const std::string path =
        (std::filesystem::path(o.out_dir) / (study + "-" + name + "." + std::string(to_string(o.format)))).string();
    save_figure(f, path);
    paths.push_back(path);
  }
};

Figure figure(std::string title, int width, int height, int columns = 1) {
  Figure f;
  f.title = std::move(title);
  f.width_px = width;
  f.height_px = height;
  f.columns = columns;
  return f;
}

/// Mean of the finite values (NaN when there are none).
double mean_of(const std::vector<double>& v) { return stats::describe(v).mean; }

std::string p_text(const json& t) {
  if (!t.contains("p") || t["p"].is_null()) return "n/a";
  const double p = d(t["p"]);
  return p < 0.001 ? "p < 0.001" : "p = " + texel::detail::fixed(p, 3);
}

/// "spacing 0.012, distractor < 0.001, interaction 0.2": the p value of
/// each effect of an ANOVA summary (short enough for a panel title); empty
/// if the ANOVA was skipped.
std::string anova_text(const json& a) {
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
int category_width(const std::vector<std::string>& names, int min_px) {
  std::size_t longest = 0;
  for (const auto& n : names) longest = std::max(longest, n.size());
  const double per = std::max(90.0, 7.5 * static_cast<double>(longest) + 20.0);
  return std::clamp(static_cast<int>(per * static_cast<double>(names.size())) + 200, min_px, 16000);
}

std::string percent(double v) { return texel::detail::fixed(v * 100, 0) + " %"; }

// --------------------------------------------------------------- staircases

std::string variable_label(const Study& study) { return std::string(study.variable_label); }

}  // namespace

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

namespace {

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

// ---------------------------------------------------------------- matching

struct Match {
  std::string reference;
  double pitch, irr, ref_pitch, ref_irr, distance, confidence;
};

std::vector<Match> matches_of(const json& s) {
  std::vector<Match> out;
  if (!s.contains("matches")) return out;
  for (const auto& m : s["matches"])
    out.push_back({m["reference"].get<std::string>(), d(m["pitch_db"]), d(m["irregularity_db"]), d(m["reference_pitch_db"]),
                   d(m["reference_irregularity_db"]), d(m["distance_db"]),
                   m.contains("confidence") ? d(m["confidence"]) : missing});
  return out;
}

std::vector<std::string> reference_names(const json& s) {
  std::vector<std::string> names;
  for (const auto& r : s["references"]) names.push_back(r["reference"].get<std::string>());
  return names;
}

/// Matched against reference value, per parameter, with the identity line.
Figure matched_vs_reference(const std::string& title, const json& s) {
  const auto ms = matches_of(s);
  Figure f = figure(title + ": matched against reference parameters", 1000, 480, 2);
  for (int k = 0; k < 2; ++k) {
    Panel p;
    const std::string what = k == 0 ? "Central Pitch (dB)" : "Irregularity (dB)";
    p.title = k == 0 ? "Central Pitch" : "Irregularity";
    p.x.label = "reference " + what;
    p.y.label = "matched " + what;
    StemSeries pts;
    pts.stems = false;
    pts.marker_radius_px = 4.0;
    pts.label = "matches";
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& m : ms) {
      const double x = k == 0 ? m.ref_pitch : m.ref_irr, y = k == 0 ? m.pitch : m.irr;
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      pts.x.push_back(x);
      pts.y.push_back(y);
      lo = std::min({lo, x, y});
      hi = std::max({hi, x, y});
    }
    if (lo < hi) p.lines.push_back(LineSeries{{lo, hi}, {lo, hi}, Rgb{0.45, 0.45, 0.45}, 1.2, "matched = reference", true});
    p.stems.push_back(std::move(pts));
    f.panels.push_back(std::move(p));
  }
  return f;
}

/// Box plots of matched parameters per reference, reference values marked.
Figure matched_boxes(const std::string& title, const json& s) {
  const auto names = reference_names(s);
  const auto ms = matches_of(s);
  Figure f = figure(title + ": matched parameters per reference", category_width(names, 700), 760);
  for (int k = 0; k < 2; ++k) {
    Panel p;
    p.x = Axis{"reference", AxisScale::linear, std::nullopt, std::nullopt, false, names};
    p.y.label = "matched " + (k == 0 ? pitch_label : irregularity_label);
    BoxSeries box;
    box.colour = palette_colour(static_cast<std::size_t>(k));
    box.show_points = true;
    box.label = "matches";
    StemSeries ref;
    ref.stems = false;
    ref.colour = Rgb{0.1, 0.1, 0.1};
    ref.marker_radius_px = 4.5;
    ref.label = "reference";
    for (std::size_t i = 0; i < names.size(); ++i) {
      std::vector<double> v;
      for (const auto& m : ms)
        if (m.reference == names[i]) v.push_back(k == 0 ? m.pitch : m.irr);
      box.groups.push_back(std::move(v));
      const double rv = d(s["references"][i][k == 0 ? "reference_pitch_db" : "reference_irregularity_db"]);
      if (std::isfinite(rv)) ref.x.push_back(static_cast<double>(i) + 0.32), ref.y.push_back(rv);
    }
    p.boxes.push_back(std::move(box));
    if (!ref.x.empty()) p.stems.push_back(std::move(ref));
    f.panels.push_back(std::move(p));
  }
  return f;
}

/// The 2-D matches per reference and the confidence ellipse of their mean.
Figure match_ellipses(const std::string& title, const json& s, double level) {
  const auto names = reference_names(s);
  const auto ms = matches_of(s);
  Figure f =
      figure(title + ": matches and " + texel::detail::fixed(level * 100, 0) + " % confidence ellipses of the mean", 820, 680);
  Panel p;
  p.x.label = pitch_label;
  p.y.label = irregularity_label;
  StemSeries refs;
  refs.stems = false;
  refs.colour = Rgb{0.1, 0.1, 0.1};
  refs.marker_radius_px = 2.5;
  refs.label = "reference position";
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Rgb c = palette_colour(i);
    std::vector<double> x, y;
    for (const auto& m : ms)
      if (m.reference == names[i] && std::isfinite(m.pitch) && std::isfinite(m.irr)) x.push_back(m.pitch), y.push_back(m.irr);
    StemSeries pts;
    pts.stems = false;
    pts.colour = c;
    pts.marker_radius_px = 3.5;
    pts.label = names[i];
    pts.x = x;
    pts.y = y;
    p.stems.push_back(std::move(pts));
    try {
      const auto e = stats::mean_confidence_ellipse(x, y, level);
      LineSeries outline;
      for (const auto& pt : e.outline(96)) outline.x.push_back(pt[0]), outline.y.push_back(pt[1]);
      outline.x.push_back(outline.x.front());
      outline.y.push_back(outline.y.front());
      outline.colour = c;
      outline.width_px = 1.6;
      p.lines.push_back(std::move(outline));
    } catch (const InvalidArgument&) {
      // Fewer than three matches (or collinear ones): points only, as the summary says.
    }
    const double rx = d(s["references"][i]["reference_pitch_db"]), ry = d(s["references"][i]["reference_irregularity_db"]);
    if (std::isfinite(rx) && std::isfinite(ry)) {
      refs.x.push_back(rx), refs.y.push_back(ry);
      // Which reference position is whose: a dashed line to its mean match.
      if (!x.empty()) p.lines.push_back(LineSeries{{rx, mean_of(x)}, {ry, mean_of(y)}, c, 1.0, {}, true});
    }
    // The name just above the reference's highest match, clear of the points.
    if (!x.empty()) p.notes.push_back(TextNote{mean_of(x), *std::max_element(y.begin(), y.end()), names[i], c, -14.0});
  }
  if (!refs.x.empty()) p.stems.push_back(std::move(refs));
  f.panels.push_back(std::move(p));
  return f;
}

/// Confidence rating against the distance of the match from that
/// reference's mean match.
std::optional<Figure> confidence_vs_distance(const std::string& title, const json& s) {
  StemSeries pts;
  pts.stems = false;
  pts.marker_radius_px = 4.0;
  if (!s.contains("confidence_vs_distance")) return std::nullopt;
  const json& c = s["confidence_vs_distance"];
  const bool rater = c["distance_to"] == "rater";
  for (const auto& m : s["matches"]) {
    const double x = d(m[rater ? "distance_to_rater_db" : "distance_db"]);
    const double y = m.contains("confidence") ? d(m["confidence"]) : missing;
    if (std::isfinite(x) && std::isfinite(y)) pts.x.push_back(x), pts.y.push_back(y);
  }
  if (pts.x.empty()) return std::nullopt;
  std::string sub;
  if (c.contains("r")) sub = " (r = " + texel::detail::fixed(d(c["r"]), 2) + ", " + p_text(c) + ")";
  const std::string from = rater ? "the trained rater's match (encoder estimate)" : "the reference's mean match";
  Figure f = figure(title + ": confidence against distance" + sub, 700, 480);
  Panel p;
  p.x.label = "distance from " + from + " (dB)";
  p.y = Axis{"confidence (1 … 5)", AxisScale::linear, 0.5, 5.5, false};
  p.stems.push_back(std::move(pts));
  f.panels.push_back(std::move(p));
  return f;
}

/// Distance of the match from the one in use (rater's or mean) per
/// confidence bin — 1–2, 3, 4, 5 [choice: the two lowest ratings, the
/// rarest, share a bin] — as box plots: the source's binned figure.
std::optional<Figure> confidence_bins(const std::string& title, const json& s) {
  if (!s.contains("confidence_vs_distance")) return std::nullopt;
  const bool rater = s["confidence_vs_distance"]["distance_to"] == "rater";
  const std::vector<std::string> cats{"1–2", "3", "4", "5"};
  BoxSeries box;
  box.show_points = true;
  box.groups.resize(cats.size());
  bool any = false;
  for (const auto& m : s["matches"]) {
    const double x = d(m[rater ? "distance_to_rater_db" : "distance_db"]);
    const double c = m.contains("confidence") ? d(m["confidence"]) : missing;
    if (!std::isfinite(x) || !std::isfinite(c)) continue;
    const auto bin = static_cast<std::size_t>(std::clamp(std::lround(c) - 2, 0L, 3L));
    box.groups[bin].push_back(x);
    any = true;
  }
  if (!any) return std::nullopt;
  Figure f = figure(title + ": distance of the match per confidence", 700, 480);
  Panel p;
  p.x = Axis{"confidence (1 … 5, in four bins)", AxisScale::linear, std::nullopt, std::nullopt, false, cats};
  p.y.label = "distance from " +
              std::string(rater ? "the trained rater's match (encoder estimate)" : "the reference's mean match") + " (dB)";
  p.boxes.push_back(std::move(box));
  f.panels.push_back(std::move(p));
  return f;
}

/// A panel of box plots per reference (categories in `names`' order) of each
/// participant's mean value; `v`: reference → participant → values.
Panel reference_boxes(const std::vector<std::string>& names,
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

/// Rating per reference (box plots of per-participant ratings).
Figure rating_boxes(const std::string& title, const Rows& rows, const std::string& scale) {
  std::vector<std::string> names;
  std::map<std::string, std::map<std::string, std::vector<double>>> v;
  for (const TrialRow* r : rows) {
    if (r->task != "rating") continue;
    // The own-match ratings (the similarity matrix holds the others).
    const bool own =
        r->condition.empty() || r->condition == "match" || r->condition == "own" || r->condition == "rendering:" + r->reference;
    if (!own) continue;
    if (std::find(names.begin(), names.end(), r->reference) == names.end()) names.push_back(r->reference);
    v[r->reference][r->participant].push_back(r->rating);
  }
  Figure f = figure(title + ": similarity of match and reference", category_width(names, 640), 460);
  Panel p = reference_boxes(names, v);
  p.y.label = "similarity rating (" + scale + ")";
  f.panels.push_back(std::move(p));
  return f;
}

/// Parameter mapping: each participant's Irregularity normalised to their
/// own range (0 … 1), box plots per reference.
std::optional<Figure> irregularity_normalised_figure(const json& s, const Rows& rows) {
  if (!s.contains("irregularity_normalised")) return std::nullopt;
  const bool sliders = s["irregularity_normalised"]["from"] == "slider_i";
  std::vector<std::string> names;
  for (const auto& r : s["irregularity_normalised"]["references"]) names.push_back(r["reference"].get<std::string>());
  std::map<std::string, std::pair<double, double>> range;  // participant → (min, max)
  for (const TrialRow* r : rows) {
    if (r->task != "match") continue;
    const double x = sliders ? r->slider_i : r->irregularity_db;
    if (!std::isfinite(x)) continue;
    auto [it, fresh] = range.try_emplace(r->participant, x, x);
    it->second = {std::min(it->second.first, x), std::max(it->second.second, x)};
  }
  std::map<std::string, std::map<std::string, std::vector<double>>> v;  // reference → participant → values
  for (const TrialRow* r : rows) {
    if (r->task != "match" || !range.count(r->participant)) continue;
    const auto [lo, hi] = range[r->participant];
    const double x = sliders ? r->slider_i : r->irregularity_db;
    if (hi > lo && std::isfinite(x)) v[r->reference][r->participant].push_back((x - lo) / (hi - lo));
  }
  Figure f = figure("Parameter mapping: Irregularity normalised per participant", category_width(names, 700), 480);
  Panel p = reference_boxes(names, v);
  p.y = Axis{"normalised Irregularity (0 = participant's lowest match, 1 = highest)", AxisScale::linear, -0.05, 1.05, false};
  f.panels.push_back(std::move(p));
  return f;
}

/// Parameter mapping, the comparisons of two different references (the
/// source's figure built from them): mean rating ± 95 % CI over
/// participants per rated pair, the own-match ratings' mean dashed.
std::optional<Figure> comparisons_figure(const json& s) {
  if (!s.contains("comparisons") || s["comparisons"].empty()) return std::nullopt;
  // The references' common prefix ("bandpass-") left out of the labels, so
  // sixteen "A vs B" fit side by side.
  std::string prefix;
  {
    std::vector<std::string> all;
    for (const auto& c : s["comparisons"]) all.push_back(c["a"].get<std::string>()), all.push_back(c["b"].get<std::string>());
    prefix = all.front();
    for (const auto& n : all)
      prefix.resize(
          static_cast<std::size_t>(std::mismatch(prefix.begin(), prefix.end(), n.begin(), n.end()).first - prefix.begin()));
    prefix.resize(prefix.rfind('-') == std::string::npos ? 0 : prefix.rfind('-') + 1);
  }
  std::vector<std::string> names;
  ErrorBarSeries e;
  e.label = "reference felt against another's match (mean ± 95 % CI)";
  for (const auto& c : s["comparisons"]) {
    names.push_back(c["a"].get<std::string>().substr(prefix.size()) + " vs " + c["b"].get<std::string>().substr(prefix.size()));
    const json& r = c["rating"];
    e.x.push_back(static_cast<double>(names.size() - 1));
    e.y.push_back(d(r["mean"]));
    e.error.push_back((d(r["ci95_high"]) - d(r["ci95_low"])) / 2);
  }
  Figure f = figure("Parameter mapping: similarity of two different references" +
                        (prefix.empty() ? std::string() : " (" + prefix + "…)") + ", one felt against the other's match",
                    category_width(names, 900), 520);
  Panel p;
  p.x = Axis{"comparison", AxisScale::linear, std::nullopt, std::nullopt, false, names};
  p.y = Axis{"similarity rating (0 … 10)", AxisScale::linear, -0.2, 10.2, false};
  std::vector<double> own;
  if (s.contains("ratings"))
    for (const auto& r : s["ratings"]) own.push_back(d(r["rating"]["mean"]));
  const double own_mean = mean_of(own);
  if (std::isfinite(own_mean))
    p.lines.push_back(LineSeries{{-0.5, static_cast<double>(names.size()) - 0.5},
                                 {own_mean, own_mean},
                                 Rgb{0.45, 0.45, 0.45},
                                 1.0,
                                 "own match (mean over references)",
                                 true});
  p.error_bars.push_back(std::move(e));
  f.panels.push_back(std::move(p));
  return f;
}

// ------------------------------------------------------------ quantization

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

// ------------------------------------------------------ guided exploration

Figure similarity_heatmap(const json& sim, const std::string& title, double lo, double hi, const std::string& column_label) {
  const auto refs = sim["references"].get<std::vector<std::string>>();
  const auto rend = sim["renderings"].get<std::vector<std::string>>();
  HeatmapSeries h;
  h.rows = refs.size();
  h.cols = rend.size();
  for (const auto& row : sim["mean_rating"])
    for (const auto& v : row) h.values.push_back(d(v));
  h.row_labels = refs;
  h.column_labels = rend;
  h.min = lo;
  h.max = hi;
  h.decimals = 2;
  h.scale_label = "mean similarity rating (" + texel::detail::num(lo) + " … " + texel::detail::num(hi) + ")";
  Figure f = figure(title, std::max(760, 90 * static_cast<int>(rend.size()) + 300),
                    std::max(600, 60 * static_cast<int>(refs.size()) + 200));
  Panel p;
  p.x.label = column_label;
  p.y.label = "reference felt";
  p.heatmap = std::move(h);
  f.panels.push_back(std::move(p));
  return f;
}

/// The optimizer's estimate after each comparison, per reference, one line
/// per participant, the reference's own position dashed.
Figure guided_convergence(const Rows& rows) {
  std::vector<std::string> names;
  std::map<std::string, std::map<std::string, Rows>> runs;  // reference → participant/session → rows
  for (const TrialRow* r : rows) {
    if (r->task != "guided") continue;
    if (std::find(names.begin(), names.end(), r->reference) == names.end()) names.push_back(r->reference);
    runs[r->reference][r->participant + "#" + std::to_string(r->session_id)].push_back(r);
  }
  const int cols = static_cast<int>(std::max<std::size_t>(1, names.size()));
  Figure f = figure("Guided exploration: optimizer estimate per comparison", std::min(16000, 360 * cols + 40), 640, cols);
  for (int k = 0; k < 2; ++k)
    for (const auto& n : names) {
      Panel p;
      p.title = k == 0 ? n : std::string();
      p.x.label = "comparison";
      p.y.label = k == 0 ? "estimate: Central Pitch (dB)" : "estimate: Irregularity (dB)";
      double ref = missing, last_x = 1;
      std::size_t i = 0;
      for (const auto& [who, rs] : runs[n]) {
        LineSeries l;
        l.colour = palette_colour(i++);
        for (std::size_t t = 0; t < rs.size(); ++t) {
          l.x.push_back(static_cast<double>(t + 1));
          l.y.push_back(k == 0 ? rs[t]->pitch_db : rs[t]->irregularity_db);
          ref = k == 0 ? rs[t]->reference_pitch_db : rs[t]->reference_irregularity_db;
        }
        last_x = std::max(last_x, static_cast<double>(rs.size()));
        p.lines.push_back(std::move(l));
      }
      if (std::isfinite(ref)) p.lines.push_back(LineSeries{{1, last_x}, {ref, ref}, Rgb{0.2, 0.2, 0.2}, 1.2, "reference", true});
      p.legend = false;
      f.panels.push_back(std::move(p));
    }
  return f;
}

// ----------------------------------------------------------- working memory

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

// ------------------------------------------------------- 2-D oddity studies

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

}  // namespace

std::vector<std::string> study_figures(const Study& study, const nlohmann::ordered_json& summary, const Rows& rows,
                                       const AnalysisOptions& options) {
  const std::string name(study.name), title(study.title);
  Writer w{name, options, {}};
  switch (study.design) {
    case StudyDesign::staircase:
      w.save(staircase_tracks(study, rows), "tracks");
      w.save(convergent_boxes(study, summary), "convergent");
      if (study.blocks_by_fine_strength) w.save(participant_lines(study, summary), "participants");
      if (study.directional)
        if (auto f = directional_scatter(summary)) w.save(*f, "directional");
      break;
    case StudyDesign::matching:
    case StudyDesign::guided:
      if (!summary["matches"].empty()) {
        w.save(matched_vs_reference(title, summary), "matched-vs-reference");
        w.save(matched_boxes(title, summary), "matched-boxes");
        w.save(match_ellipses(title, summary, options.level), "ellipses");
      }
      if (auto f = confidence_vs_distance(title, summary)) w.save(*f, "confidence");
      if (auto f = confidence_bins(title, summary)) w.save(*f, "confidence-bins");
      if (study.ratings_figure && summary.contains("ratings")) w.save(rating_boxes(title, rows, "0 … 10"), "ratings");
      if (auto f = irregularity_normalised_figure(summary, rows)) w.save(*f, "irregularity-normalised");
      if (auto f = comparisons_figure(summary)) w.save(*f, "comparisons");
      // Beyond the own-match pairs (the source rated 25 of the 81): the matrix.
      if (study.design == StudyDesign::matching && summary.contains("similarity") &&
          summary["similarity"]["pairs_rated"].get<std::size_t>() > summary["similarity"]["references"].size())
        w.save(similarity_heatmap(summary["similarity"], title + ": similarity of references and matches", 0.0, 10.0, "match of"),
               "similarity");
      if (study.design == StudyDesign::guided) {
        w.save(guided_convergence(rows), "convergence");
        if (summary.contains("similarity"))
          w.save(
              similarity_heatmap(summary["similarity"], "Guided exploration: similarity of references and optimized renderings",
                                 1.0, 5.0, "optimized rendering of"),
              "similarity");
      }
      break;
    case StudyDesign::quantization:
      w.save(quantization_figure(summary, rows), "rating-change");
      if (auto f = match_similarity(rows)) w.save(*f, "match-similarity");
      break;
    case StudyDesign::memory:
      w.save(memory_figure(study, summary), "performance");
      if (auto f = memory_errors_trend(study, summary)) w.save(*f, "errors-trend");
      if (auto f = memory_components(summary, options.level)) w.save(*f, "effects");
      break;
    case StudyDesign::oddity: w.save(oddity_figure(study, summary, options.level), "proportion-correct"); break;
    case StudyDesign::playback:
      if (!summary["levels"].empty()) w.save(playback_figure(study, summary, options.level), "pse");
      break;
  }
  return w.paths;
}

}  // namespace texel::experiment::analysis_figures
