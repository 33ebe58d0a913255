// Per-study summaries of the trial rows (analysis.hpp): what the thesis
// reports for each study, computed from the long-format rows alone so the
// same numbers come out of the session store and of an exported CSV.
//
// Unit of analysis: the participant. Repeated rows of one participant (two
// sessions, two matches of one reference) are averaged before a group
// statistic, so no test treats trials of one person as independent people
// (docs/analysis.md, "Unit of analysis" [choice]). Tests that cannot run
// (too few participants, no variance, an incomplete design) are reported as
// {"skipped": reason} from the stats layer's own message.
#include "texel/experiment/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/hypergeometric.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>

#include "analysis_figures.hpp"
#include "json_views.hpp"
#include "studies.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/stats.hpp"
#include "texel/io.hpp"

namespace texel::experiment {

namespace {

using json = nlohmann::ordered_json;
using Rows = std::vector<const TrialRow*>;

// ------------------------------------------------------------------ helpers

/// A number for JSON: non-finite values become null (JSON has no NaN).
json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

/// Mean of the finite values (NaN when there are none).
double mean_of(const std::vector<double>& v) { return stats::describe(v).mean; }

json describe_json(const std::vector<double>& v) { return stats::view(stats::describe(v)); }
json ttest_json(const stats::TTest& t) { return stats::view(t); }

json skipped(const std::string& why) { return json{{"skipped", why}}; }

/// Runs a statistic; the stats layer's InvalidArgument (too few values, no
/// variance, a missing cell) becomes {"skipped": message}.
template <class F>
json guarded(F&& f) {
  try {
    return f();
  } catch (const InvalidArgument& e) {
    return skipped(e.what());
  }
}

json anova_json(const stats::AnovaTable& a) { return stats::view(a); }

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

std::string fmt(double v, int digits = 2) { return std::isfinite(v) ? texel::detail::fixed(v, digits) : std::string("NA"); }
std::string fmt_p(double p) {
  if (!std::isfinite(p)) return "p = NA";
  return p < 0.001 ? std::string("p < 0.001") : "p = " + texel::detail::fixed(p, 3);
}

/// A number of a JSON summary (null → NaN).
double val(const json& j, const char* key) { return j.contains(key) && j[key].is_number() ? j[key].get<double>() : missing; }
/// Degrees of freedom: whole numbers as such, Welch's to two decimals.
std::string fmt_df(double df) { return std::abs(df - std::round(df)) < 1e-9 ? fmt(df, 0) : fmt(df, 2); }
std::string fmt_ci(const json& j, const char* lo = "ci_low", const char* hi = "ci_high") {
  const double level = j.contains("level") ? val(j, "level") : 0.95;
  return fmt(level * 100, 0) + " % CI [" + fmt(val(j, lo)) + ", " + fmt(val(j, hi)) + "]";
}
/// The source's forms: "t(df) = …, p = …, 95 % CI […]", "F(df1, df2) = …,
/// p = …", "r = …, p = …, 95 % CI […]"; "skipped: why" for a test that
/// could not run.
std::string t_text(const json& t) {
  if (t.contains("skipped")) return "skipped: " + t["skipped"].get<std::string>();
  return "t(" + fmt_df(val(t, "df")) + ") = " + fmt(val(t, "t")) + ", " + fmt_p(val(t, "p")) + ", " + fmt_ci(t);
}
std::string f_text(double df1, double df2, double f, double p) {
  return "F(" + fmt_df(df1) + ", " + fmt_df(df2) + ") = " + fmt(f) + ", " + fmt_p(p);
}
std::string r_text(const json& c) {
  if (c.contains("skipped")) return "skipped: " + c["skipped"].get<std::string>();
  return "r = " + fmt(val(c, "r")) + ", " + fmt_p(val(c, "p")) + " (n = " + std::to_string(c["n"].get<std::size_t>()) + "), " +
         fmt_ci(c);
}
/// One line per effect of an RM-ANOVA summary ("  effect: F(…) = …, p = …,
/// partial η² = …", Greenhouse–Geisser p where sphericity applies).
std::string anova_lines(const json& a, const std::string& indent) {
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

// --------------------------------------------------------------- staircases

/// One staircase run: one participant's block in one session.
struct Run {
  std::string participant;
  std::int64_t session_id = 0;
  std::string block;
  Rows rows;
};

std::vector<Run> staircase_runs(const Rows& rows) {
  std::vector<Run> runs;
  std::map<std::tuple<std::string, std::int64_t, std::string>, std::size_t> index;
  for (const TrialRow* r : rows) {
    const auto key = std::make_tuple(r->participant, r->session_id, r->block);
    auto [it, fresh] = index.try_emplace(key, runs.size());
    if (fresh) runs.push_back(Run{r->participant, r->session_id, r->block, {}});
    runs[it->second].rows.push_back(r);
  }
  return runs;
}

/// Texel length between groups: each participant belongs to the group of
/// their runs (the main block's condition). A participant found in more
/// than one group is listed and left out of the group tests, which assume
/// independent groups.
json between_groups(const std::vector<std::string>& groups,
                    const std::map<std::string, std::map<std::string, double>>& per_participant, const AnalysisOptions& o,
                    std::string& text) {
  std::map<std::string, std::vector<std::string>> groups_of;
  for (const auto& [g, m] : per_participant)
    for (const auto& [p, v] : m) groups_of[p].push_back(g);
  json several = json::array();
  for (const auto& [p, gs] : groups_of)
    if (gs.size() > 1) several.push_back(p);
  std::vector<std::vector<double>> values;
  for (const auto& g : groups) {
    values.emplace_back();
    for (const auto& [p, v] : per_participant.at(g))
      if (groups_of[p].size() == 1) values.back().push_back(v);
  }
  json out{{"groups", groups}, {"participants_in_several_groups", several}};
  out["anova"] = guarded([&] { return stats::view(stats::anova_one_way(values)); });
  const json& an = out["anova"];
  text += "  between groups (one-way ANOVA): " +
          (an.contains("skipped") ? "skipped: " + an["skipped"].get<std::string>()
                                  : f_text(val(an, "df_between"), val(an, "df_within"), val(an, "f"), val(an, "p")) +
                                        ", η² = " + fmt(val(an, "eta2"))) +
          "\n";
  json tests = json::array();
  for (std::size_t i = 0; i < groups.size(); ++i)
    for (std::size_t j = i + 1; j < groups.size(); ++j) {
      json t = guarded([&] { return stats::view(stats::t_test_two_sample(values[i], values[j], false, o.level)); });
      json w = guarded([&] { return stats::view(stats::t_test_two_sample(values[i], values[j], true, o.level)); });
      const std::string cmp = groups[i] + " − " + groups[j];
      text += "  " + cmp + " (independent t-test): " + t_text(t) + "\n";
      tests.push_back(json{{"comparison", cmp}, {"student", t}, {"welch", w}});
    }
  out["t_tests"] = tests;
  if (!several.empty())
    text += "  " + std::to_string(several.size()) + " participant(s) in several groups left out of the group tests\n";
  return out;
}

/// Swipe behaviour against the result: each participant's mean of the swipe
/// measure over their trials against their convergent texel length, Pearson's r.
json swipe_correlations(const std::vector<std::pair<std::string, std::vector<double>>>& measures,
                        const std::vector<double>& convergent, const AnalysisOptions& o, std::string& text) {
  json out = json::array();
  for (const auto& m : measures) {
    json c = guarded([&] { return stats::view(stats::pearson(m.second, convergent, o.level)); });
    text += "  " + m.first + " vs convergent: " + r_text(c) + "\n";
    out.push_back(json{{"measure", m.first}, {"correlation", c}});
  }
  return out;
}

json staircase_summary(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  const bool coarse = find_study(study)->blocks_by_fine_strength;
  json out;
  out["variable"] = rows.empty() ? std::string() : rows.front()->variable;
  out["reversals_k"] = o.reversals_k;
  out["convergent_rule"] = o.convergent;
  json runs = json::array(), unfinished = json::array();
  // Every run that stopped before its stopping rule is named first, so the
  // reader meets the warning before the numbers.
  std::string run_text;
  Ordered blocks;
  // group (block, or for texel length the block's condition) → participant → values
  std::map<std::string, std::map<std::string, std::vector<double>>> conv, thr;
  std::map<std::string, std::map<std::string, std::vector<double>>> swipe[3];
  std::map<std::string, double> block_fine;
  for (const Run& run : staircase_runs(rows)) {
    const TrialRow& last = *run.rows.back();
    // Texel length: the group is the block's condition (one group per participant).
    const std::string group = !coarse && !last.condition.empty() ? last.condition : run.block;
    blocks.add(group);
    std::vector<double> rev;
    std::vector<double> dirs, speeds, sds;
    for (const TrialRow* r : run.rows) {
      if (r->reversal) rev.push_back(r->intensity);
      dirs.push_back(r->directional_proportion);
      speeds.push_back(r->swipe_mean_speed_mm_s);
      sds.push_back(r->swipe_sd_speed_mm_s);
    }
    const double dir = mean_of(dirs), speed = mean_of(speeds), speed_sd = mean_of(sds);
    // The source's end value is the last one presented; "next" takes the one
    // computed after the last answer (falling back to the last presented
    // when it was not stored).
    const double end_value = o.convergent == "next" && std::isfinite(last.next_intensity) ? last.next_intensity : last.intensity;
    // A run that stopped before its stopping rule has an end value but no
    // convergent value: it is reported "not finished" and kept out of the
    // group statistics unless asked (AnalysisOptions::include_unfinished).
    const bool finished = std::any_of(run.rows.begin(), run.rows.end(), [](const TrialRow* r) { return r->procedure_finished; });
    const bool counted = finished || o.include_unfinished;
    const std::size_t used = std::min(o.reversals_k, rev.size());
    std::vector<double> tail(rev.end() - static_cast<std::ptrdiff_t>(used), rev.end());
    const double threshold = mean_of(tail);
    json j{{"participant", run.participant}, {"session_id", run.session_id}, {"block", run.block}};
    if (coarse) {
      j["fine_strength"] = num(last.fine_strength);
      block_fine[run.block] = last.fine_strength;
    } else {
      j["group"] = group;
    }
    j["trials"] = run.rows.size();
    j["finished"] = finished;
    j["status"] = finished ? "finished" : "not finished";
    j["in_group_statistics"] = counted;
    j["reversals"] = rev.size();
    j["reversal_intensities"] = rev;
    j["end_value"] = num(end_value);
    j["convergent"] = finished ? num(end_value) : json(nullptr);
    j["threshold_last_k"] = finished ? num(threshold) : json(nullptr);
    j["threshold_reversals_used"] = used;
    if (!coarse) {
      j["directional_proportion"] = num(dir);
      j["swipe_mean_speed_mm_s"] = num(speed);
      j["swipe_sd_speed_mm_s"] = num(speed_sd);
    }
    if (!finished) {
      run_text += "  " + run.participant + " " + run.block + " (session " + std::to_string(run.session_id) +
                  "): not finished, stopped after " + std::to_string(run.rows.size()) + " trials with " +
                  std::to_string(rev.size()) + (rev.size() == 1 ? " reversal" : " reversals") + "; its end value " +
                  fmt(end_value) + " is no convergent value" +
                  (counted ? " (in the group statistics: include_unfinished)\n" : "; left out of the group statistics\n");
      unfinished.push_back(json{{"participant", run.participant}, {"session_id", run.session_id}, {"block", run.block}});
    }
    runs.push_back(std::move(j));
    if (!counted) continue;
    if (!coarse) {
      swipe[0][group][run.participant].push_back(speed);
      swipe[1][group][run.participant].push_back(speed_sd);
      swipe[2][group][run.participant].push_back(dir);
    }
    conv[group][run.participant].push_back(end_value);
    thr[group][run.participant].push_back(threshold);
  }
  out["unfinished_runs"] = unfinished;
  out["include_unfinished"] = o.include_unfinished;
  out["runs"] = runs;
  json bj = json::array();
  std::vector<stats::Observation> obs;
  std::map<std::string, std::map<std::string, double>> per_participant;  // group → participant → convergent
  text += study + ": " + std::to_string(runs.size()) + " staircase runs (end value: " + o.convergent + ")" +
          (unfinished.empty() ? std::string() : ", " + std::to_string(unfinished.size()) + " not finished") + "\n" + run_text;
  for (const std::string& b : blocks.names) {
    std::vector<double> cv, tv;
    for (const auto& [p, v] : conv[b]) {
      cv.push_back(mean_of(v));
      per_participant[b][p] = cv.back();
      obs.push_back({p, {b}, cv.back()});
    }
    for (const auto& [p, v] : thr[b]) tv.push_back(mean_of(v));
    std::size_t left_out = 0, let_in = 0;
    for (const auto& r : runs)
      if ((r.contains("group") ? r["group"] : r["block"]) == b && !r["finished"].get<bool>())
        ++(r["in_group_statistics"].get<bool>() ? let_in : left_out);
    json e{{"block", b}};
    if (coarse) e["fine_strength"] = num(block_fine[b]);
    e["participants"] = cv.size();
    e["unfinished_runs_left_out"] = left_out;
    e["unfinished_runs_included"] = let_in;
    e["convergent"] = describe_json(cv);
    e["threshold_last_k"] = describe_json(tv);
    const auto d = stats::describe(cv);
    text += "  " + b + ": convergent " + fmt(d.mean) + " ± " + fmt(d.sd) + " (mean ± SD, n = " + std::to_string(d.n) + ", " +
            fmt(0.95 * 100, 0) + " % CI [" + fmt(d.ci95_low) + ", " + fmt(d.ci95_high) + "])" +
            (left_out ? ", " + std::to_string(left_out) + " unfinished run(s) left out" : std::string()) +
            (let_in ? ", " + std::to_string(let_in) + " unfinished run(s) included (their end values)" : std::string()) + "\n";
    bj.push_back(std::move(e));
  }
  out["blocks"] = bj;
  if (!coarse) {
    // Texel length: separate groups of participants (narrow, wide, wide with
    // visual practice), so the tests are between groups, never paired.
    if (blocks.names.size() >= 2) out["between_groups"] = between_groups(blocks.names, per_participant, o, text);
    std::vector<double> cv;
    std::vector<std::pair<std::string, std::vector<double>>> m{
        {"swipe_mean_speed_mm_s", {}}, {"swipe_sd_speed_mm_s", {}}, {"directional_proportion", {}}};
    for (const auto& b : blocks.names)
      for (const auto& [p, v] : per_participant[b]) {
        cv.push_back(v);
        for (int k = 0; k < 3; ++k) m[static_cast<std::size_t>(k)].second.push_back(mean_of(swipe[k][b][p]));
      }
    out["swipe_vs_convergent"] = swipe_correlations(m, cv, o, text);
    return out;
  }
  // Coarse features: one-factor RM-ANOVA over the fine strengths on the
  // participants who completed every block.
  std::vector<stats::Observation> complete;
  for (const auto& ob : obs) {
    bool all = true;
    for (const auto& b : blocks.names) all = all && per_participant[b].count(ob.subject);
    if (all) complete.push_back(ob);
  }
  out["rm_anova"] = guarded([&] { return anova_json(stats::rm_anova(complete, {"fine_strength"})); });
  text += anova_lines(out["rm_anova"], "  ");
  return out;
}

// ---------------------------------------------------------------- matching

/// Per-reference summary of matched (pitch, irregularity) pairs, the match
/// list with each match's distance from its reference's mean match.
void matching_summary(const Rows& matches, const AnalysisOptions& o, json& out, std::string& text, const std::string& study) {
  Ordered refs;
  std::map<std::string, std::vector<const TrialRow*>> by_ref;
  for (const TrialRow* r : matches) {
    refs.add(r->reference);
    by_ref[r->reference].push_back(r);
  }
  json rj = json::array();
  std::map<std::string, std::pair<double, double>> centre;
  text += study + ": " + std::to_string(matches.size()) + " matches of " + std::to_string(refs.names.size()) + " references\n";
  for (const std::string& name : refs.names) {
    const auto& rs = by_ref[name];
    std::vector<double> p, i, pe, ie, rp, ri;
    for (const TrialRow* r : rs) {
      p.push_back(r->pitch_db);
      i.push_back(r->irregularity_db);
      pe.push_back(r->pitch_db - r->reference_pitch_db);
      ie.push_back(r->irregularity_db - r->reference_irregularity_db);
      rp.push_back(r->reference_pitch_db);
      ri.push_back(r->reference_irregularity_db);
    }
    centre[name] = {mean_of(p), mean_of(i)};
    json e{{"reference", name},
           {"n", rs.size()},
           {"reference_pitch_db", num(mean_of(rp))},
           {"reference_irregularity_db", num(mean_of(ri))},
           {"pitch_db", describe_json(p)},
           {"irregularity_db", describe_json(i)},
           {"pitch_error_db", describe_json(pe)},
           {"irregularity_error_db", describe_json(ie)}};
    e["ellipse"] = guarded([&] {
      const stats::Ellipse el = stats::mean_confidence_ellipse(p, i, o.level);
      return json{{"n", el.n},
                  {"level", el.level},
                  {"mean_pitch_db", num(el.mean_x)},
                  {"mean_irregularity_db", num(el.mean_y)},
                  {"cov_pp", num(el.cov_xx)},
                  {"cov_pi", num(el.cov_xy)},
                  {"cov_ii", num(el.cov_yy)},
                  {"t2_critical", num(el.t2_critical)},
                  {"semi_major_db", num(el.semi_major)},
                  {"semi_minor_db", num(el.semi_minor)},
                  {"angle_deg", num(el.angle_deg)}};
    });
    text += "  " + name + ": matched pitch " + fmt(mean_of(p)) + " dB (reference " + fmt(mean_of(rp)) + "), irregularity " +
            fmt(mean_of(i)) + " dB (reference " + fmt(mean_of(ri)) + "), n = " + std::to_string(rs.size()) + "\n";
    rj.push_back(std::move(e));
  }
  out["references"] = rj;
  json mj = json::array();
  std::vector<double> dist, conf;
  const bool to_rater = o.confidence_distance == "rater";
  for (const TrialRow* r : matches) {
    const auto [cp, ci] = centre[r->reference];
    const double d = std::hypot(r->pitch_db - cp, r->irregularity_db - ci);
    // The trained rater's match: the encoder's estimate of the reference stands in ([choice]).
    const double d_rater = std::hypot(r->pitch_db - r->reference_pitch_db, r->irregularity_db - r->reference_irregularity_db);
    json m{{"participant", r->participant},
           {"session_id", r->session_id},
           {"reference", r->reference},
           {"pitch_db", num(r->pitch_db)},
           {"irregularity_db", num(r->irregularity_db)},
           {"reference_pitch_db", num(r->reference_pitch_db)},
           {"reference_irregularity_db", num(r->reference_irregularity_db)},
           {"distance_db", num(d)},
           {"distance_to_rater_db", num(d_rater)}};
    if (std::isfinite(r->slider_p)) m["slider_p"] = r->slider_p;
    if (std::isfinite(r->slider_i)) m["slider_i"] = r->slider_i;
    if (std::isfinite(r->confidence)) {
      m["confidence"] = r->confidence;
      const double x = to_rater ? d_rater : d;
      if (std::isfinite(x)) dist.push_back(x), conf.push_back(r->confidence);
    }
    mj.push_back(std::move(m));
  }
  out["matches"] = mj;
  if (!conf.empty()) {
    // Pearson r of confidence with the distance (from the rater's match by
    // default), t-test of r = 0 (n − 2 df), Fisher-z CI.
    json c{{"distance_to", to_rater ? "rater" : "group-mean"}};
    c.update(guarded([&] { return stats::view(stats::pearson(conf, dist, o.level)); }));
    text += "  confidence vs distance to the " + std::string(to_rater ? "rater's match" : "mean match") + ": " + r_text(c) + "\n";
    out["confidence_vs_distance"] = c;
  }
}

/// The rendering a rating row shows: "rendering:<name>" = the match of
/// reference <name>; "match", "own" or empty = the participant's match of
/// the reference felt.
std::string rendering_of(const TrialRow& r) {
  const std::string prefix = "rendering:";
  if (r.condition.rfind(prefix, 0) == 0) return r.condition.substr(prefix.size());
  if (r.condition.empty() || r.condition == "match" || r.condition == "own") return r.reference;
  return r.condition;
}

/// Similarity matrix of rating rows: rows = reference felt, columns = whose
/// rendering was shown; mean over participants of each participant's mean;
/// own (diagonal) vs other renderings, paired per participant.
json similarity_matrix(const Rows& ratings, Ordered names, const AnalysisOptions& o, std::string& text) {
  Ordered rendering_names = names;
  for (const TrialRow* r : ratings) {
    names.add(r->reference);
    rendering_names.add(rendering_of(*r));
  }
  std::map<std::string, std::map<std::pair<std::size_t, std::size_t>, std::vector<double>>> cell;  // participant → (row, col)
  for (const TrialRow* r : ratings)
    cell[r->participant][{names.add(r->reference), rendering_names.add(rendering_of(*r))}].push_back(r->rating);
  const std::size_t nr = names.names.size(), nc = rendering_names.names.size();
  json mean = json::array(), count = json::array();
  std::size_t rated = 0;
  for (std::size_t i = 0; i < nr; ++i) {
    json mrow = json::array(), crow = json::array();
    for (std::size_t j = 0; j < nc; ++j) {
      std::vector<double> m;
      for (auto& [p, c] : cell)
        if (c.count({i, j})) m.push_back(mean_of(c[{i, j}]));
      mrow.push_back(num(mean_of(m)));
      crow.push_back(m.size());
      rated += m.empty() ? 0 : 1;
    }
    mean.push_back(mrow);
    count.push_back(crow);
  }
  // Does a reference's own rendering feel more like it than the others' do?
  // Per participant: mean diagonal vs mean off-diagonal rating.
  std::vector<double> diag, off;
  for (auto& [p, c] : cell) {
    std::vector<double> d, f;
    for (auto& [ij, x] : c) {
      const bool same = names.names[ij.first] == rendering_names.names[ij.second];
      (same ? d : f).push_back(mean_of(x));
    }
    if (!d.empty() && !f.empty()) diag.push_back(mean_of(d)), off.push_back(mean_of(f));
  }
  json sim{{"references", names.names}, {"renderings", rendering_names.names},
           {"pairs_rated", rated},      {"pairs_possible", nr * nc},
           {"mean_rating", mean},       {"participants", count}};
  text +=
      "  similarity ratings: " + std::to_string(rated) + " of " + std::to_string(nr * nc) + " reference/rendering pairs rated\n";
  if (diag.empty()) {
    sim["own_vs_other_t_test"] = skipped("no participant rated both own and other renderings");
    text += "  own vs other renderings: skipped (no participant rated both own and other renderings)\n";
  } else {
    json t = guarded([&] { return ttest_json(stats::t_test_paired(diag, off, o.level)); });
    t["comparison"] = "own rendering − other renderings";
    sim["own_vs_other_t_test"] = t;
    text += "  own rendering " + fmt(mean_of(diag)) + " vs others " + fmt(mean_of(off)) + " (paired): " + t_text(t) + "\n";
  }
  return sim;
}

/// Irregularity normalised per participant: each participant's matched
/// Irregularity (slider position where the rows have one, else dB) rescaled
/// to 0 … 1 over that participant's own matches (min → 0, max → 1), so
/// participants who used different parts of the slider compare.
json irregularity_normalised(const Rows& matches, std::string& text) {
  std::map<std::string, std::vector<const TrialRow*>> by_participant;
  Ordered refs;
  for (const TrialRow* r : matches) {
    by_participant[r->participant].push_back(r);
    refs.add(r->reference);
  }
  std::map<std::string, std::map<std::string, std::vector<double>>> v;  // reference → participant → values
  bool sliders = true;
  for (const TrialRow* r : matches) sliders = sliders && std::isfinite(r->slider_i);
  for (auto& [p, rs] : by_participant) {
    double lo = INFINITY, hi = -INFINITY;
    for (const TrialRow* r : rs) {
      const double x = sliders ? r->slider_i : r->irregularity_db;
      if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
    }
    for (const TrialRow* r : rs) {
      const double x = sliders ? r->slider_i : r->irregularity_db;
      v[r->reference][p].push_back(hi > lo ? (x - lo) / (hi - lo) : missing);
    }
  }
  json per = json::array();
  for (const auto& name : refs.names) {
    std::vector<double> m;
    for (const auto& [p, x] : v[name]) m.push_back(mean_of(x));
    per.push_back(json{{"reference", name}, {"irregularity_normalised", describe_json(m)}});
  }
  text += "  Irregularity normalised per participant (0 = their lowest match, 1 = their highest; from " +
          std::string(sliders ? "slider positions" : "dB") + ")\n";
  return json{{"from", sliders ? "slider_i" : "irregularity_db"}, {"references", per}};
}

json ratings_by_reference(const Rows& ratings) {
  Ordered refs;
  std::map<std::string, std::map<std::string, std::vector<double>>> v;  // reference → participant → ratings
  for (const TrialRow* r : ratings) {
    if (rendering_of(*r) != r->reference) continue;  // own match only; the matrix has the rest
    refs.add(r->reference);
    v[r->reference][r->participant].push_back(r->rating);
  }
  json out = json::array();
  for (const auto& name : refs.names) {
    std::vector<double> m;
    for (const auto& [p, x] : v[name]) m.push_back(mean_of(x));
    out.push_back(json{{"reference", name}, {"rating", describe_json(m)}});
  }
  return out;
}

/// The comparisons of two different references (the source's figure of
/// parameter mapping): every rated pair of a reference felt against the
/// match of another, both directions pooled, as "A vs B" (A first in the
/// matches' order); per participant the mean of their ratings of the pair,
/// described over participants.
json reference_comparisons(const Rows& ratings, Ordered names, std::string& text) {
  std::map<std::pair<std::size_t, std::size_t>, std::map<std::string, std::vector<double>>> v;  // pair → participant → ratings
  for (const TrialRow* r : ratings) {
    const std::string other = rendering_of(*r);
    if (other == r->reference) continue;
    std::size_t a = names.add(r->reference), b = names.add(other);
    if (a > b) std::swap(a, b);
    v[{a, b}][r->participant].push_back(r->rating);
  }
  json out = json::array();
  for (const auto& [ab, per] : v) {
    std::vector<double> m;
    for (const auto& [p, x] : per) m.push_back(mean_of(x));
    out.push_back(json{{"comparison", names.names[ab.first] + " vs " + names.names[ab.second]},
                       {"a", names.names[ab.first]},
                       {"b", names.names[ab.second]},
                       {"rating", describe_json(m)}});
  }
  if (!out.empty()) text += "  " + std::to_string(out.size()) + " comparisons of two different references rated\n";
  return out;
}

json match_study(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  Rows matches, ratings;
  for (const TrialRow* r : rows) {
    if (r->task == "match") matches.push_back(r);
    if (r->task == "rating") ratings.push_back(r);
  }
  json out = json::object();
  matching_summary(matches, o, out, text, study);
  if (study == "parameter-mapping" && !matches.empty()) out["irregularity_normalised"] = irregularity_normalised(matches, text);
  if (!ratings.empty()) {
    out["ratings"] = ratings_by_reference(ratings);
    Ordered names;
    for (const TrialRow* r : matches) names.add(r->reference);
    out["similarity"] = similarity_matrix(ratings, names, o, text);
    if (study == "parameter-mapping") out["comparisons"] = reference_comparisons(ratings, names, text);
  }
  return out;
}

// ------------------------------------------------------------ quantization

json quantization_summary(const Rows& rows, const AnalysisOptions& o, std::string& text) {
  // participant → reference → condition → ratings
  std::map<std::string, std::map<std::string, std::map<std::string, std::vector<double>>>> v;
  Ordered conditions;
  std::map<std::string, double> level_db;
  for (const TrialRow* r : rows) {
    if (r->task != "rating") continue;
    conditions.add(r->condition);
    level_db[r->condition] = r->quantization_db;
    v[r->participant][r->reference][r->condition].push_back(r->rating);
  }
  // Quantized levels in ascending dB; the unquantized baseline first.
  std::vector<std::string> levels;
  for (const auto& c : conditions.names)
    if (c != "unquantized") levels.push_back(c);
  std::stable_sort(levels.begin(), levels.end(), [&](const auto& a, const auto& b) { return level_db[a] < level_db[b]; });
  json out = json::object();
  json cj = json::array();
  std::vector<std::string> all{"unquantized"};
  all.insert(all.end(), levels.begin(), levels.end());
  for (const auto& c : all) {
    if (!level_db.count(c)) continue;
    std::vector<double> m;  // per participant mean rating over references
    for (auto& [p, refs] : v) {
      std::vector<double> x;
      for (auto& [ref, conds] : refs)
        if (conds.count(c)) x.push_back(mean_of(conds[c]));
      if (!x.empty()) m.push_back(mean_of(x));
    }
    cj.push_back(json{{"condition", c}, {"quantization_db", num(level_db[c])}, {"rating", describe_json(m)}});
  }
  out["conditions"] = cj;
  // Pooled over references, described only: the tests are per texture (below).
  json ch = json::array();
  json pj = json::array();
  std::map<std::string, json> per_participant;
  text += "quantization: " + std::to_string(v.size()) + " participants\n";
  for (const auto& c : levels) {
    std::vector<double> changes;
    for (auto& [p, refs] : v) {
      std::vector<double> x;
      for (auto& [ref, conds] : refs)
        if (conds.count(c) && conds.count("unquantized")) x.push_back(mean_of(conds[c]) - mean_of(conds["unquantized"]));
      if (x.empty()) continue;
      changes.push_back(mean_of(x));
      per_participant[p][c] = num(changes.back());
    }
    ch.push_back(json{{"condition", c}, {"quantization_db", num(level_db[c])}, {"change", describe_json(changes)}});
  }
  out["changes"] = ch;
  for (auto& [p, j] : per_participant) pj.push_back(json{{"participant", p}, {"changes", j}});
  out["participants"] = pj;

  // Per texture (a reference rated quantized): repeated-measures ANOVA of
  // the rating over the levels (unquantized first), on the participants who
  // rated every level of it, and per level a one-sample t-test of the change
  // rating(level) − rating(unquantized) against 0.
  Ordered textures;
  for (const TrialRow* r : rows)
    if (r->task == "rating" && r->condition != "unquantized") textures.add(r->reference);
  json tj = json::array();
  for (const auto& tex : textures.names) {
    std::vector<std::string> tex_levels;
    for (const auto& c : levels)
      for (auto& [p, refs] : v)
        if (refs.count(tex) && refs[tex].count(c)) {
          tex_levels.push_back(c);
          break;
        }
    std::vector<std::string> all_levels{"unquantized"};
    all_levels.insert(all_levels.end(), tex_levels.begin(), tex_levels.end());
    std::vector<stats::Observation> obs;
    for (auto& [p, refs] : v) {
      if (!refs.count(tex)) continue;
      auto& conds = refs[tex];
      bool complete = true;
      for (const auto& c : all_levels) complete = complete && conds.count(c);
      if (!complete) continue;
      for (const auto& c : all_levels) obs.push_back({p, {c}, mean_of(conds[c])});
    }
    json e{{"reference", tex}, {"levels", all_levels}};
    e["rm_anova"] = guarded([&] { return anova_json(stats::rm_anova(obs, {"quantization"})); });
    text += "  " + tex + ":\n" + anova_lines(e["rm_anova"], "    ");
    json lc = json::array();
    for (const auto& c : tex_levels) {
      std::vector<double> changes;
      for (auto& [p, refs] : v)
        if (refs.count(tex) && refs[tex].count(c) && refs[tex].count("unquantized"))
          changes.push_back(mean_of(refs[tex][c]) - mean_of(refs[tex]["unquantized"]));
      json l{{"condition", c}, {"quantization_db", num(level_db[c])}, {"change", describe_json(changes)}};
      l["t_test"] = guarded([&] { return ttest_json(stats::t_test_one_sample(changes, 0.0, o.level)); });
      text += "    " + c + " − unquantized: change " + fmt(mean_of(changes)) + ", " + t_text(l["t_test"]) + "\n";
      lc.push_back(std::move(l));
    }
    e["changes"] = lc;
    tj.push_back(std::move(e));
  }
  out["textures"] = tj;
  return out;
}

// ------------------------------------------------------ guided exploration

json guided_summary(const Rows& rows, const AnalysisOptions& o, std::string& text) {
  // The match of a participant × session × reference is its last guided row
  // with procedure_finished (else its last guided row: an unfinished run).
  std::map<std::tuple<std::string, std::int64_t, std::string>, const TrialRow*> last;
  std::vector<std::tuple<std::string, std::int64_t, std::string>> order;
  Rows ratings;
  Ordered names;
  for (const TrialRow* r : rows) {
    if (r->task == "guided") {
      const auto key = std::make_tuple(r->participant, r->session_id, r->reference);
      names.add(r->reference);
      auto [it, fresh] = last.try_emplace(key, r);
      if (fresh) order.push_back(key);
      if (!it->second->procedure_finished || r->procedure_finished) it->second = r;
    } else if (r->task == "rating") {
      ratings.push_back(r);
    }
  }
  Rows matches;
  json unfinished = json::array();
  for (const auto& k : order) {
    // An unfinished run's estimate is no match: reported, and left out of
    // the matches' statistics unless asked (include_unfinished).
    const bool finished = last[k]->procedure_finished;
    if (finished || o.include_unfinished) matches.push_back(last[k]);
    if (!finished)
      unfinished.push_back(json{{"participant", std::get<0>(k)},
                                {"session_id", std::get<1>(k)},
                                {"reference", std::get<2>(k)},
                                {"status", "not finished"},
                                {"in_group_statistics", o.include_unfinished}});
  }
  json out = json::object();
  matching_summary(matches, o, out, text, "guided-exploration");
  if (!unfinished.empty()) {
    out["unfinished"] = unfinished;
    text += "  " + std::to_string(unfinished.size()) + " guided run(s) not finished" +
            (o.include_unfinished ? " (their last estimates are in the statistics: include_unfinished)\n"
                                  : ", left out of the statistics\n");
  }
  if (ratings.empty()) return out;

  out["similarity"] = similarity_matrix(ratings, names, o, text);
  return out;
}

// ----------------------------------------------------------- working memory

struct MemoryPerson {
  std::vector<double> all, recall;
  std::map<std::string, std::vector<double>> cond;
  double main_errors = 0, distraction_errors = 0;
};
using Excluded = std::map<std::string, std::string>;  // participant → reason

/// The source's rule: main-task (same/different) errors "near two standard
/// deviations" or more above the group's mean, without any increase in
/// distraction-task (digit recall) errors — read as: their distraction
/// errors are not above the group's mean. Mean and SD over every
/// participant, computed once. "Near" [choice]: z >= k − tolerance
/// (memory_errors_limit), which reproduces the source's two exclusions from
/// its own mean and SD (docs/analysis.md).
Excluded source_rule(const std::map<std::string, MemoryPerson>& people, const AnalysisOptions& o, json& stats_out) {
  const double k = o.memory_errors_sd;
  std::vector<double> main, distraction;
  for (const auto& [id, p] : people) {
    main.push_back(p.main_errors);
    if (!p.recall.empty()) distraction.push_back(p.distraction_errors);
  }
  const auto dm = stats::describe(main), dd = stats::describe(distraction);
  const double limit = memory_errors_limit(dm.mean, dm.sd, o);
  stats_out = json{{"main_errors_mean", num(dm.mean)},
                   {"main_errors_sd", num(dm.sd)},
                   {"main_errors_z_min", k - o.memory_errors_sd_tolerance},
                   {"main_errors_limit", num(limit)},
                   {"distraction_errors_mean", num(dd.mean)}};
  Excluded out;
  if (!(dm.sd > 0)) return out;
  for (const auto& [id, p] : people) {
    if (!(p.main_errors >= limit)) continue;
    // No recall data: no increase can be shown, so the main-task errors stand alone.
    const bool increase = !p.recall.empty() && std::isfinite(dd.mean) && p.distraction_errors > dd.mean;
    if (increase) continue;
    out[id] = fmt(p.main_errors, 0) + " main-task errors (z " + fmt((p.main_errors - dm.mean) / dm.sd) + ") >= mean + " +
              fmt(k - o.memory_errors_sd_tolerance) + " SD = " + fmt(limit) + " without more distraction errors (" +
              fmt(p.distraction_errors, 0) + ") than the mean (" + fmt(dd.mean) + ")";
  }
  return out;
}

/// The earlier [choice]: digit recall at or below chance, then overall
/// accuracy beyond k SD of the remaining participants (one pass).
Excluded recall_accuracy_rule(const std::map<std::string, MemoryPerson>& people, const AnalysisOptions& o) {
  Excluded excluded;
  for (const auto& [id, p] : people) {
    const double rec = mean_of(p.recall);
    if (o.memory_recall_chance >= 0 && std::isfinite(rec) && rec <= o.memory_recall_chance + 1e-12)
      excluded[id] = "distractor recall " + fmt(rec) + " <= chance " + fmt(o.memory_recall_chance, 3);
  }
  if (o.memory_accuracy_sd > 0) {
    std::vector<double> acc;
    for (const auto& [id, p] : people)
      if (!excluded.count(id)) acc.push_back(mean_of(p.all));
    const auto d = stats::describe(acc);
    if (d.n >= 3 && d.sd > 0)
      for (const auto& [id, p] : people) {
        const double z = (mean_of(p.all) - d.mean) / d.sd;
        if (!excluded.count(id) && std::abs(z) > o.memory_accuracy_sd)
          excluded[id] = "accuracy " + fmt(mean_of(p.all)) + " is " + fmt(z) + " SD from the group mean";
      }
  }
  return excluded;
}

std::pair<std::string, std::string> split_condition(const std::string& c) {
  const auto dash = c.rfind('-');
  return dash == std::string::npos ? std::pair{c, std::string()} : std::pair{c.substr(0, dash), c.substr(dash + 1)};
}

/// The 2 × 2 analysis on the participants a rule keeps: RM-ANOVA (Type III),
/// per spacing a paired t-test distractor − control, and R².
json memory_tests(const std::map<std::string, MemoryPerson>& people, const std::vector<std::string>& conditions,
                  const Excluded& excluded, const AnalysisOptions& o) {
  std::vector<stats::Observation> obs;
  std::map<std::string, std::map<std::string, std::map<std::string, double>>> by;  // spacing → kind → participant → accuracy
  for (const auto& c : conditions) {
    const auto [spacing, kind] = split_condition(c);
    for (const auto& [id, p] : people)
      if (!excluded.count(id) && p.cond.count(c)) {
        const double acc = mean_of(p.cond.at(c));
        obs.push_back({id, {spacing, kind}, acc});
        by[spacing][kind][id] = acc;
      }
  }
  json out;
  out["rm_anova"] = guarded([&] { return anova_json(stats::rm_anova(obs, {"spacing", "distractor"})); });
  // The source's R² (its trend figure): across the kept participants, the
  // least-squares line of main-task errors on distraction-task errors and
  // its R² (= r², Pearson's r with its t-test and CI beside it).
  {
    std::vector<double> x, y;
    for (const auto& [id, p] : people)
      if (!excluded.count(id) && !p.recall.empty()) x.push_back(p.distraction_errors), y.push_back(p.main_errors);
    json r = guarded([&] {
      const stats::Correlation c = stats::pearson(x, y, o.level);
      const auto dx = stats::describe(x), dy = stats::describe(y);
      const double slope = c.r * dy.sd / dx.sd;
      json j{{"x", "distraction_errors"},
             {"y", "main_errors"},
             {"r2", c.r2},
             {"slope", slope},
             {"intercept", dy.mean - slope * dx.mean}};
      j.update(stats::view(c));
      return j;
    });
    out["r2"] = r;
  }
  // Effect share (formerly reported as R²): the share of the variance of
  // the participant × condition scores explained by the 2 × 2 effects
  // (SS_effects / SS_total, as a univariate model of the four cell means
  // reports it); with_subjects adds the participants' own levels.
  if (out["rm_anova"].contains("effects")) {
    std::vector<double> all;
    std::map<std::string, std::vector<double>> per;
    for (const auto& ob : obs) all.push_back(ob.value), per[ob.subject].push_back(ob.value);
    const double grand = mean_of(all);
    double ss_total = 0, ss_effects = 0, ss_subjects = 0;
    for (double x : all) ss_total += (x - grand) * (x - grand);
    for (const auto& e : out["rm_anova"]["effects"]) ss_effects += val(e, "ss");
    for (const auto& [id, v] : per) ss_subjects += static_cast<double>(v.size()) * (mean_of(v) - grand) * (mean_of(v) - grand);
    out["effect_share"] = json{{"share", num(ss_total > 0 ? ss_effects / ss_total : missing)},
                               {"share_with_subjects", num(ss_total > 0 ? (ss_effects + ss_subjects) / ss_total : missing)}};
  } else {
    out["effect_share"] = skipped("the ANOVA did not run");
  }
  json tests = json::array();
  for (auto& [spacing, kinds] : by) {
    std::vector<double> d, c;
    if (kinds.count("distractor") && kinds.count("control"))
      for (const auto& [id, x] : kinds["distractor"])
        if (kinds["control"].count(id)) d.push_back(x), c.push_back(kinds["control"][id]);
    json t = guarded([&] { return ttest_json(stats::t_test_paired(d, c, o.level)); });
    t["comparison"] = "distractor − control";
    tests.push_back(json{{"spacing", spacing}, {"t_test", t}});
  }
  out["spacing_t_tests"] = tests;
  return out;
}

json excluded_list(const Excluded& e) {
  json out = json::array();
  for (const auto& [id, why] : e) out.push_back(json{{"participant", id}, {"reason", why}});
  return out;
}

json memory_summary(const Rows& rows, const AnalysisOptions& o, std::string& text) {
  std::map<std::string, MemoryPerson> people;
  Ordered conditions;
  for (const TrialRow* r : rows) {
    if (r->task != "same-different") continue;
    MemoryPerson& p = people[r->participant];
    conditions.add(r->condition);
    p.all.push_back(r->correct);
    p.cond[r->condition].push_back(r->correct);
    if (r->correct == 0) p.main_errors += 1;
    if (r->condition.ends_with("-distractor") && std::isfinite(r->digit_correct)) {
      p.recall.push_back(r->digit_correct);
      if (r->digit_correct == 0) p.distraction_errors += 1;
    }
  }
  json out = json::object();
  json source_stats;
  const Excluded by_source = source_rule(people, o, source_stats);
  const Excluded by_recall = recall_accuracy_rule(people, o);
  const Excluded& excluded = o.memory_rule == "source" ? by_source : o.memory_rule == "none" ? Excluded{} : by_recall;
  out["outlier_rule"] = json{{"rule", o.memory_rule},
                             {"errors_sd", o.memory_errors_sd},
                             {"errors_sd_tolerance", o.memory_errors_sd_tolerance},
                             {"recall_chance", o.memory_recall_chance},
                             {"accuracy_sd", o.memory_accuracy_sd}};
  json pj = json::array();
  for (auto& [id, p] : people) {
    json c = json::object();
    for (const auto& n : conditions.names) c[n] = num(mean_of(p.cond[n]));
    pj.push_back(json{{"participant", id},
                      {"trials", p.all.size()},
                      {"accuracy", num(mean_of(p.all))},
                      {"recall_accuracy", num(mean_of(p.recall))},
                      {"main_errors", p.main_errors},
                      {"distraction_errors", p.recall.empty() ? json(nullptr) : json(p.distraction_errors)},
                      {"conditions", c},
                      {"excluded", excluded.count(id) ? json(excluded.at(id)) : json(false)}});
  }
  out["participants"] = pj;
  out["included"] = people.size() - excluded.size();
  json cj = json::array();
  for (const auto& c : conditions.names) {
    std::vector<double> v;
    for (auto& [id, p] : people)
      if (!excluded.count(id) && p.cond.count(c)) v.push_back(mean_of(p.cond[c]));
    const auto [spacing, distractor] = split_condition(c);
    cj.push_back(json{{"condition", c}, {"spacing", spacing}, {"distractor", distractor}, {"accuracy", describe_json(v)}});
  }
  out["conditions"] = cj;
  const json tests = memory_tests(people, conditions.names, excluded, o);
  out.update(tests);
  // What each rule excludes, and what the interaction test becomes under it.
  json rules = json::array();
  for (const auto& [name, ex] :
       {std::pair<std::string, const Excluded*>{"source", &by_source}, {"recall-accuracy", &by_recall}}) {
    json r{{"rule", name}, {"excluded", excluded_list(*ex)}, {"included", people.size() - ex->size()}};
    if (name == "source") r["thresholds"] = source_stats;
    r["rm_anova"] = memory_tests(people, conditions.names, *ex, o)["rm_anova"];
    rules.push_back(std::move(r));
  }
  out["rules_compared"] = rules;

  text += "working-memory: " + std::to_string(people.size()) + " participants, " + std::to_string(excluded.size()) +
          " excluded (rule: " + o.memory_rule + ")\n";
  for (const auto& [id, why] : excluded) text += "  excluded " + id + ": " + why + "\n";
  for (const auto& c : cj)
    text += "  " + c["condition"].get<std::string>() + ": " + fmt(val(c["accuracy"], "mean")) + " correct (SEM " +
            fmt(val(c["accuracy"], "sem")) + ")\n";
  text += anova_lines(out["rm_anova"], "  ");
  if (out["r2"].contains("r2"))
    text += "  main-task errors against distraction-task errors (across participants): R² = " + fmt(val(out["r2"], "r2"), 4) +
            ", slope " + fmt(val(out["r2"], "slope"), 3) + ", " + r_text(out["r2"]) + "\n";
  else
    text += "  R² (main-task against distraction-task errors) skipped: " + out["r2"]["skipped"].get<std::string>() + "\n";
  if (out["effect_share"].contains("share"))
    text += "  share of variance explained by the 2 × 2 effects: " + fmt(val(out["effect_share"], "share")) +
            " (with participants: " + fmt(val(out["effect_share"], "share_with_subjects")) + ")\n";
  for (const auto& t : out["spacing_t_tests"])
    text += "  " + t["spacing"].get<std::string>() + " spacing, distractor − control (paired): " + t_text(t["t_test"]) + "\n";
  for (const auto& r : rules) {
    std::string ids;
    for (const auto& e : r["excluded"]) ids += (ids.empty() ? "" : ", ") + e["participant"].get<std::string>();
    text += "  rule " + r["rule"].get<std::string>() + " excludes " + (ids.empty() ? std::string("nobody") : ids);
    if (r["rm_anova"].contains("effects"))
      for (const auto& e : r["rm_anova"]["effects"])
        if (e["effect"].get<std::string>().find(':') != std::string::npos)
          text += "; interaction " + f_text(val(e, "df"), val(e, "df_error"), val(e, "f"), val(e, "p"));
    text += "\n";
  }
  return out;
}

void check_options(const AnalysisOptions& o) {
  if (o.format != "png" && o.format != "svg") throw InvalidArgument("analysis format is '" + o.format + "'; allowed: png, svg");
  if (o.reversals_k < 1) throw InvalidArgument("analysis reversals_k is 0; must be >= 1");
  if (!(o.level > 0 && o.level < 1))
    throw InvalidArgument("analysis level is " + texel::detail::num(o.level) + "; allowed (0, 1)");
  if (o.convergent != "last-presented" && o.convergent != "next")
    throw InvalidArgument("analysis convergent is '" + o.convergent + "'; allowed: last-presented, next");
  if (o.memory_rule != "source" && o.memory_rule != "recall-accuracy" && o.memory_rule != "none")
    throw InvalidArgument("analysis memory_rule is '" + o.memory_rule + "'; allowed: source, recall-accuracy, none");
  if (!(o.memory_errors_sd > 0) || !std::isfinite(o.memory_errors_sd))
    throw InvalidArgument("analysis memory_errors_sd is " + texel::detail::num(o.memory_errors_sd) + "; allowed > 0");
  if (!(o.memory_errors_sd_tolerance >= 0) || !(o.memory_errors_sd_tolerance < o.memory_errors_sd))
    throw InvalidArgument("analysis memory_errors_sd_tolerance is " + texel::detail::num(o.memory_errors_sd_tolerance) +
                          "; allowed 0 … memory_errors_sd (" + texel::detail::num(o.memory_errors_sd) + "), excluded");
  if (!std::isfinite(o.memory_recall_chance) || o.memory_recall_chance >= 1)
    throw InvalidArgument("analysis memory_recall_chance is " + texel::detail::num(o.memory_recall_chance) +
                          "; allowed < 1 (negative = rule off)");
  if (!(o.memory_accuracy_sd >= 0) || !std::isfinite(o.memory_accuracy_sd))
    throw InvalidArgument("analysis memory_accuracy_sd is " + texel::detail::num(o.memory_accuracy_sd) +
                          "; allowed >= 0 (0 = rule off)");
  if (o.confidence_distance != "rater" && o.confidence_distance != "group-mean")
    throw InvalidArgument("analysis confidence_distance is '" + o.confidence_distance + "'; allowed: rater, group-mean");
}

/// Free vs guided exploration: for each reference matched in both studies,
/// the spread of the matches — each match's distance (dB) from its study's
/// mean match of that reference — compared between the studies (Welch's
/// t-test: the studies may have different participants and spreads).
json spread_comparison(const json& free, const json& guided, const AnalysisOptions& o, std::string& text) {
  std::map<std::string, std::vector<double>> f, g;
  for (const auto& m : free["matches"]) f[m["reference"].get<std::string>()].push_back(val(m, "distance_db"));
  json out = json::array();
  Ordered refs;
  for (const auto& m : guided["matches"]) {
    const std::string ref = m["reference"].get<std::string>();
    refs.add(ref);
    g[ref].push_back(val(m, "distance_db"));
  }
  text += "  spread of the matches, guided − free exploration (distance from the mean match, dB):\n";
  for (const auto& ref : refs.names) {
    if (!f.count(ref)) continue;
    json e{{"reference", ref}, {"free_distance_db", describe_json(f[ref])}, {"guided_distance_db", describe_json(g[ref])}};
    e["welch_t_test"] = guarded([&] { return stats::view(stats::t_test_two_sample(g[ref], f[ref], true, o.level)); });
    e["welch_t_test"]["comparison"] = "guided − free";
    text += "    " + ref + ": " + fmt(mean_of(g[ref])) + " vs " + fmt(mean_of(f[ref])) + ", " + t_text(e["welch_t_test"]) + "\n";
    out.push_back(std::move(e));
  }
  return out;
}

// --------------------------------------------------------- 2-D oddity studies

// Wilson score interval of k successes in n at `level` (two-sided).
std::pair<double, double> wilson(double k, double n, double level) {
  const double z = boost::math::quantile(boost::math::normal_distribution<>(), 0.5 + level / 2);
  const double p = k / n, z2 = z * z / n;
  const double centre = (p + z2 / 2) / (1 + z2), half = z * std::sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z2);
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

// Exact one-sided binomial test: P(X >= k) for X ~ Bin(n, p0).
double binomial_above(double k, double n, double p0) {
  if (k <= 0) return 1.0;
  return boost::math::cdf(boost::math::complement(boost::math::binomial_distribution<>(n, p0), k - 1));
}

// Fisher's exact test, one-sided: is the proportion correct of (k1 of n1)
// lower than that of (k0 of n0)? P(X <= k1), X hypergeometric given the margins.
double fisher_lower(unsigned k1, unsigned n1, unsigned k0, unsigned n0) {
  const boost::math::hypergeometric_distribution<> h(k1 + k0, n1, n1 + n0);
  return std::min(1.0, boost::math::cdf(h, k1));
}

json oddity_summary(const Study& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  struct Cell {
    std::string block, mode;
    double direction = missing;
    unsigned n = 0, k = 0;
    std::set<std::string> participants;
    // Strokes on a 2-D display (rows with direction_compliant).
    unsigned stroked = 0, compliant = 0, compliant_correct = 0;
    std::vector<double> deviations;
  };
  Ordered names;
  std::vector<Cell> cells;
  for (const TrialRow* r : rows) {
    if (r->task != "oddity-2d" || !std::isfinite(r->correct)) continue;
    const std::size_t i = names.add(r->condition);
    if (i == cells.size()) {
      Cell c;
      c.block = r->block;
      c.mode = r->reference;
      c.direction = r->intensity;
      cells.push_back(std::move(c));
    }
    cells[i].n += 1;
    cells[i].k += r->correct > 0.5 ? 1 : 0;
    cells[i].participants.insert(r->participant);
    if (std::isfinite(r->direction_compliant)) {
      cells[i].stroked += 1;
      const bool ok = r->direction_compliant > 0.5;
      cells[i].compliant += ok ? 1 : 0;
      cells[i].compliant_correct += ok && r->correct > 0.5 ? 1 : 0;
      if (std::isfinite(r->stroke_deviation_deg)) cells[i].deviations.push_back(r->stroke_deviation_deg);
    }
  }
  // In a fixed order: by block (as first met), mode, direction difference, name.
  Ordered blocks;
  for (const Cell& c : cells) blocks.add(c.block);
  std::vector<std::size_t> order(cells.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Cell &x = cells[a], &y = cells[b];
    return std::make_tuple(blocks.add(x.block), x.mode, x.direction, names.names[a]) <
           std::make_tuple(blocks.add(y.block), y.mode, y.direction, names.names[b]);
  });
  {
    std::vector<Cell> sorted;
    Ordered sorted_names;
    for (std::size_t i : order) sorted.push_back(cells[i]), sorted_names.names.push_back(names.names[i]);
    cells = std::move(sorted);
    names = std::move(sorted_names);
  }
  constexpr double chance = 1.0 / 3.0;
  json out = json::object();
  out["chance"] = chance;
  json cj = json::array();
  text += std::string(study.title) + " (oddity, chance 1/3; " + fmt(o.level * 100, 0) + " % Wilson CIs)\n";
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const Cell& c = cells[i];
    const auto [lo, hi] = wilson(c.k, c.n, o.level);
    const double p_chance = binomial_above(c.k, c.n, chance);
    cj.push_back(json{{"condition", names.names[i]},
                      {"block", c.block},
                      {"mode", c.mode},
                      {"direction_difference_deg", num(c.direction)},
                      {"participants", c.participants.size()},
                      {"trials", c.n},
                      {"correct", c.k},
                      {"proportion", num(static_cast<double>(c.k) / c.n)},
                      {"ci_low", lo},
                      {"ci_high", hi},
                      {"p_above_chance", p_chance},
                      {"above_chance", p_chance < 1 - o.level}});
    text += "  " + names.names[i] + ": " + std::to_string(c.k) + "/" + std::to_string(c.n) +
            " correct = " + fmt(static_cast<double>(c.k) / c.n) + " [" + fmt(lo) + ", " + fmt(hi) +
            "], above chance: " + fmt_p(p_chance) + "\n";
    if (c.stroked > 0) {
      // Direction compliance on a 2-D display (docs/experiments.md "The 2-D
      // display presenter"): trials whose every interval was stroked along
      // its line, the largest deviation per trial, and the proportion
      // correct among the compliant trials.
      const double median = c.deviations.empty() ? missing : stats::quantile(c.deviations, 0.5);
      cj.back()["direction_compliance"] =
          json{{"trials_stroked", c.stroked},
               {"compliant", c.compliant},
               {"proportion", num(static_cast<double>(c.compliant) / c.stroked)},
               {"deviation_deg_median", num(median)},
               {"deviation_deg_max",
                num(c.deviations.empty() ? missing : *std::max_element(c.deviations.begin(), c.deviations.end()))},
               {"correct_when_compliant", c.compliant_correct},
               {"proportion_correct_when_compliant",
                num(c.compliant ? static_cast<double>(c.compliant_correct) / c.compliant : missing)}};
      text +=
          "    strokes: " + std::to_string(c.compliant) + "/" + std::to_string(c.stroked) + " trials along the asked directions" +
          (c.deviations.empty() ? std::string(", no interval stroked") : ", median largest deviation " + fmt(median, 1) + "°") +
          (c.compliant ? ", correct when compliant " + std::to_string(c.compliant_correct) + "/" + std::to_string(c.compliant)
                       : std::string()) +
          "\n";
    }
  }
  out["conditions"] = std::move(cj);
  if (study.direction_effects) {
    // A direction pair is discriminated when the odd texture is found less
    // often than with both swipes along one direction (the mode's baseline,
    // direction difference 0 in the same block): the pair's two members then
    // differ too, and the participant picks one of them.
    json ej = json::array();
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const Cell& c = cells[i];
      if (!(c.direction > 0)) continue;
      for (std::size_t j = 0; j < cells.size(); ++j) {
        const Cell& b = cells[j];
        if (b.block != c.block || b.mode != c.mode || b.direction != 0.0) continue;
        const double p = fisher_lower(c.k, c.n, b.k, b.n);
        const double drop = static_cast<double>(b.k) / b.n - static_cast<double>(c.k) / c.n;
        ej.push_back(json{{"condition", names.names[i]},
                          {"baseline", names.names[j]},
                          {"mode", c.mode},
                          {"direction_difference_deg", c.direction},
                          {"drop", drop},
                          {"p_fisher", p},
                          {"directions_discriminated", p < 1 - o.level}});
        text += "  " + names.names[i] + " vs " + names.names[j] + ": drop " + fmt(drop) + ", Fisher exact (one-sided) " +
                fmt_p(p) + (p < 1 - o.level ? ": directions discriminated\n" : ": not discriminated\n");
        break;
      }
    }
    out["direction_effects"] = std::move(ej);
  }
  return out;
}

/// A CSV field: quoted when it holds a separator, a quote or a line break.
std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string q = "\"";
  for (const char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_number(const json& j) { return j.is_number() ? texel::detail::num(j.get<double>()) : std::string(); }

/// The staircase runs as CSV (one row per participant × session × block):
/// what the summary's `runs` hold, with `status` "finished" / "not
/// finished" and `convergent` empty for a run that is not finished.
std::string runs_csv(const json& summary) {
  std::string out =
      "participant,session_id,block,group,fine_strength,trials,reversals,status,in_group_statistics,end_value,convergent,"
      "threshold_last_k,threshold_reversals_used\n";
  for (const auto& r : summary["runs"]) {
    out += csv_field(r["participant"].get<std::string>()) + "," + std::to_string(r["session_id"].get<std::int64_t>()) + "," +
           csv_field(r["block"].get<std::string>()) + "," +
           (r.contains("group") ? csv_field(r["group"].get<std::string>()) : std::string()) + "," +
           (r.contains("fine_strength") ? csv_number(r["fine_strength"]) : std::string()) + "," +
           std::to_string(r["trials"].get<std::size_t>()) + "," + std::to_string(r["reversals"].get<std::size_t>()) + "," +
           r["status"].get<std::string>() + "," + (r["in_group_statistics"].get<bool>() ? "1" : "0") + "," +
           csv_number(r["end_value"]) + "," + csv_number(r["convergent"]) + "," + csv_number(r["threshold_last_k"]) + "," +
           std::to_string(r["threshold_reversals_used"].get<std::size_t>()) + "\n";
  }
  return out;
}

}  // namespace

double memory_errors_limit(double mean, double sd, const AnalysisOptions& o) {
  return mean + (o.memory_errors_sd - o.memory_errors_sd_tolerance) * sd;
}

AnalysisReport analyze(const std::vector<TrialRow>& rows, const AnalysisOptions& options) {
  check_options(options);
  std::map<std::string, Rows> by_study;
  for (const TrialRow& r : rows)
    if (!r.practice) by_study[r.study].push_back(&r);
  AnalysisReport report;
  json summary = json::object();
  for (const Study& st : studies()) {  // the summary's key order
    const std::string study(st.name);
    auto it = by_study.find(study);
    if (it == by_study.end()) continue;
    Rows& rs = it->second;
    // Trial order within each participant's session, whatever the input order.
    std::stable_sort(rs.begin(), rs.end(), [](const TrialRow* a, const TrialRow* b) {
      return std::tie(a->participant, a->session_id, a->trial) < std::tie(b->participant, b->session_id, b->trial);
    });
    std::set<std::string> participants;
    for (const TrialRow* r : rs) participants.insert(r->participant);
    json s;
    switch (st.design) {
      case StudyDesign::staircase: s = staircase_summary(study, rs, options, report.text); break;
      case StudyDesign::matching: s = match_study(study, rs, options, report.text); break;
      case StudyDesign::quantization: s = quantization_summary(rs, options, report.text); break;
      case StudyDesign::guided: s = guided_summary(rs, options, report.text); break;
      case StudyDesign::memory: s = memory_summary(rs, options, report.text); break;
      case StudyDesign::oddity: s = oddity_summary(st, rs, options, report.text); break;
    }
    json head{{"participants", participants.size()}, {"rows", rs.size()}};
    // Reaction times: each participant's median (robust to a trial left
    // open), described over participants.
    std::map<std::string, std::vector<double>> rts;
    for (const TrialRow* r : rs)
      if (std::isfinite(r->rt_ms)) rts[r->participant].push_back(r->rt_ms);
    if (!rts.empty()) {
      std::vector<double> medians;
      for (const auto& [p, v] : rts) medians.push_back(stats::quantile(v, 0.5));
      head["rt_ms_median"] = describe_json(medians);
    }
    head.update(s);
    if (st.design == StudyDesign::guided && summary.contains("free-exploration") && head.contains("matches"))
      head["spread_vs_free_exploration"] = spread_comparison(summary["free-exploration"], head, options, report.text);
    summary[study] = std::move(head);
    if (!options.out_dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(options.out_dir, ec);
      if (ec) throw IoError("cannot create figure directory '" + options.out_dir + "': " + ec.message());
      for (auto& f : analysis_figures::study_figures(st, summary[study], rs, options)) report.figures.push_back(std::move(f));
      if (st.design == StudyDesign::staircase) {
        const std::string path = (std::filesystem::path(options.out_dir) / (study + "-runs.csv")).string();
        write_file_atomic(path, runs_csv(summary[study]));
        report.tables.push_back(path);
      }
    }
  }
  report.summary = summary.dump();
  return report;
}

}  // namespace texel::experiment
