// The matching studies' figures (free and guided exploration;
// analysis_figures_common.hpp): matches against the references, their
// confidence ellipses, confidence against distance, ratings, the
// comparisons of references, the similarity matrix and the guided
// optimizer's convergence.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "analysis_figures_common.hpp"
#include "texel/error.hpp"

namespace texel::experiment::analysis_figures {

namespace {

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

}  // namespace

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

}  // namespace texel::experiment::analysis_figures
