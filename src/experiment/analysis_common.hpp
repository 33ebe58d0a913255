// What the per-study analyses share (internal; analysis.hpp, docs/analysis.md):
// the JSON number and description helpers, the guard that turns a test the
// stats layer refuses into {"skipped": why}, names in order of first
// appearance, the source's printed forms of a test, and each study's
// summary function (one study's analysis per file: analysis_staircase.cpp,
// analysis_matching.cpp, analysis_quantization.cpp, analysis_memory.cpp,
// analysis_oddity.cpp, analysis_playback.cpp; analyze() in analysis.cpp calls them).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "json_views.hpp"
#include "studies.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/stats.hpp"

namespace texel::experiment::analysis_common {

using json = nlohmann::ordered_json;
using Rows = std::vector<const TrialRow*>;

/// A number for JSON: non-finite values become null (JSON has no NaN).
inline json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

/// Mean of the finite values (NaN when there are none).
inline double mean_of(const std::vector<double>& v) { return stats::describe(v).mean; }

inline json describe_json(const std::vector<double>& v) { return stats::view(stats::describe(v)); }
inline json ttest_json(const stats::TTest& t) { return stats::view(t); }

inline json skipped(const std::string& why) { return json{{"skipped", why}}; }

/// Runs a statistic; the stats layer's InvalidArgument (too few values, no
/// variance, a missing cell) becomes {"skipped": message}.
template <class F>
inline json guarded(F&& f) {
  try {
    return f();
  } catch (const InvalidArgument& e) {
    return skipped(e.what());
  }
}

inline json anova_json(const stats::AnovaTable& a) { return stats::view(a); }

/// Names in order of first appearance.
struct Ordered {
  std::vector<std::string> names;
  std::size_t add(const std::string& s) {
    const auto it = std::find(names.begin(), names.end(), s);
    if (it != names.end()) return static_cast<std::size_t>(it - names.begin());
    names.push_back(s);
    return names.size() - 1;
  }
};

inline std::string fmt(double v, int digits = 2) {
  return std::isfinite(v) ? texel::detail::fixed(v, digits) : std::string("NA");
}
inline std::string fmt_p(double p) {
  if (!std::isfinite(p)) return "p = NA";
  return p < 0.001 ? std::string("p < 0.001") : "p = " + texel::detail::fixed(p, 3);
}

/// A number of a JSON summary (null → NaN).
inline double val(const json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : missing;
}
/// Degrees of freedom: whole numbers as such, Welch's to two decimals.
inline std::string fmt_df(double df) { return std::abs(df - std::round(df)) < 1e-9 ? fmt(df, 0) : fmt(df, 2); }
inline std::string fmt_ci(const json& j, const char* lo = "ci_low", const char* hi = "ci_high") {
  const double level = j.contains("level") ? val(j, "level") : 0.95;
  return fmt(level * 100, 0) + " % CI [" + fmt(val(j, lo)) + ", " + fmt(val(j, hi)) + "]";
}
/// The source's forms: "t(df) = …, p = …, 95 % CI […]", "F(df1, df2) = …,
/// p = …", "r = …, p = …, 95 % CI […]"; "skipped: why" for a test that
/// could not run.
inline std::string t_text(const json& t) {
  if (t.contains("skipped")) return "skipped: " + t["skipped"].get<std::string>();
  return "t(" + fmt_df(val(t, "df")) + ") = " + fmt(val(t, "t")) + ", " + fmt_p(val(t, "p")) + ", " + fmt_ci(t);
}
inline std::string f_text(double df1, double df2, double f, double p) {
  return "F(" + fmt_df(df1) + ", " + fmt_df(df2) + ") = " + fmt(f) + ", " + fmt_p(p);
}
inline std::string r_text(const json& c) {
  if (c.contains("skipped")) return "skipped: " + c["skipped"].get<std::string>();
  return "r = " + fmt(val(c, "r")) + ", " + fmt_p(val(c, "p")) + " (n = " + std::to_string(c["n"].get<std::size_t>()) + "), " +
         fmt_ci(c);
}
/// One line per effect of an RM-ANOVA summary ("  effect: F(…) = …, p = …,
/// partial η² = …", Greenhouse–Geisser p where sphericity applies).
inline std::string anova_lines(const json& a, const std::string& indent) {
  if (a.contains("skipped")) return indent + "RM-ANOVA skipped: " + a["skipped"].get<std::string>() + "\n";
  std::string out;
  for (const auto& e : a["effects"]) {
    out += indent + e["effect"].get<std::string>() + ": " + f_text(val(e, "df"), val(e, "df_error"), val(e, "f"), val(e, "p")) +
           ", partial η² = " + fmt(val(e, "partial_eta2"));
    if (e["sphericity_applies"].get<bool>())
      out += " (Greenhouse–Geisser ε = " + fmt(val(e, "gg_epsilon")) + ", " + fmt_p(val(e, "p_gg")) + ")";
    out += "\n";
  }
  return out;
}

// ------------------------------------------------------ proportions correct

/// Wilson score interval of k successes in n at `level` (two-sided).
std::pair<double, double> wilson(double k, double n, double level);
/// Exact one-sided binomial test: P(X >= k) for X ~ Bin(n, p0).
double binomial_above(double k, double n, double p0);

// ------------------------------------------------------- the studies' summaries

/// Staircase studies (texel length, coarse features): runs, blocks, group tests.
json staircase_summary(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text);
/// Slider matching studies (parameter mapping, free exploration): matches, ellipses, ratings.
json match_study(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text);
/// Guided exploration: the optimizer's matches and the similarity matrix.
json guided_summary(const Rows& rows, const AnalysisOptions& o, std::string& text);
/// Free vs guided exploration: the spread of the matches per reference.
json spread_comparison(const json& free, const json& guided, const AnalysisOptions& o, std::string& text);
/// Quantization: rating changes per texture and level.
json quantization_summary(const Rows& rows, const AnalysisOptions& o, std::string& text);
/// Working memory (and its components' study): the outlier rules, the
/// spacing × distractor RM-ANOVA, the per-distractor t-tests, R².
json memory_summary(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text);
/// The 2-D oddity studies: proportion correct against chance.
json oddity_summary(const Study& study, const Rows& rows, const AnalysisOptions& o, std::string& text);
/// Distributed irregularity: proportion correct per shift, the PSE with its bootstrap CI, the control.
json playback_summary(const Study& study, const Rows& rows, const AnalysisOptions& o, std::string& text);
/// The fitted oddity dip at `shift` (the figure's curve).
double playback_dip(double shift, double pse, double alpha);

}  // namespace texel::experiment::analysis_common
