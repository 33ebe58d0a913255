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

#include <boost/math/distributions/students_t.hpp>

#include "json_views.hpp"
#include "studies.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/stats.hpp"

namespace texel::experiment {

// Figures of one study from its summary (as analyze() builds it) and its
// non-practice rows; writes into options.out_dir and returns the paths.
// Defined in analysis_figures.cpp; declared in both files rather than in the
// public header, which keeps a second `detail` namespace out of
// texel::experiment (it would hide texel::detail from unqualified lookups).
namespace analysis_figures {
std::vector<std::string> study_figures(const Study& study, const nlohmann::ordered_json& summary,
                                       const std::vector<const TrialRow*>& rows, const AnalysisOptions& options);
}  // namespace analysis_figures

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

json staircase_summary(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  const bool coarse = find_study(study)->blocks_by_fine_strength;
  json out;
  out["variable"] = rows.empty() ? std::string() : rows.front()->variable;
  out["reversals_k"] = o.reversals_k;
  json runs = json::array();
  Ordered blocks;
  // block → participant → values (averaged over that participant's runs)
  std::map<std::string, std::map<std::string, std::vector<double>>> conv, thr;
  std::map<std::string, double> block_fine;
  for (const Run& run : staircase_runs(rows)) {
    blocks.add(run.block);
    std::vector<double> rev;
    double dir = 0, speed = 0, speed_sd = 0;
    std::vector<double> dirs, speeds, sds;
    for (const TrialRow* r : run.rows) {
      if (r->reversal) rev.push_back(r->intensity);
      dirs.push_back(r->directional_proportion);
      speeds.push_back(r->swipe_mean_speed_mm_s);
      sds.push_back(r->swipe_sd_speed_mm_s);
    }
    dir = mean_of(dirs), speed = mean_of(speeds), speed_sd = mean_of(sds);
    const TrialRow& last = *run.rows.back();
    // The convergent value is the one computed after the last answer; a run
    // stopped before that was stored falls back to the last presented value.
    const double convergent = std::isfinite(last.next_intensity) ? last.next_intensity : last.intensity;
    const std::size_t used = std::min(o.reversals_k, rev.size());
    std::vector<double> tail(rev.end() - static_cast<std::ptrdiff_t>(used), rev.end());
    const double threshold = mean_of(tail);
    json j{{"participant", run.participant}, {"session_id", run.session_id}, {"block", run.block}};
    if (coarse) {
      j["fine_strength"] = num(last.fine_strength);
      block_fine[run.block] = last.fine_strength;
    }
    j["trials"] = run.rows.size();
    j["finished"] = last.procedure_finished;
    j["reversals"] = rev.size();
    j["reversal_intensities"] = rev;
    j["convergent"] = num(convergent);
    j["threshold_last_k"] = num(threshold);
    j["threshold_reversals_used"] = used;
    if (!coarse) {
      j["directional_proportion"] = num(dir);
      j["swipe_mean_speed_mm_s"] = num(speed);
      j["swipe_sd_speed_mm_s"] = num(speed_sd);
    }
    runs.push_back(std::move(j));
    conv[run.block][run.participant].push_back(convergent);
    thr[run.block][run.participant].push_back(threshold);
  }
  out["runs"] = runs;
  json bj = json::array();
  std::vector<stats::Observation> obs;
  std::map<std::string, std::map<std::string, double>> per_participant;  // block → participant → convergent
  text += study + ": " + std::to_string(runs.size()) + " staircase runs\n";
  for (const std::string& b : blocks.names) {
    std::vector<double> cv, tv;
    for (const auto& [p, v] : conv[b]) {
      cv.push_back(mean_of(v));
      per_participant[b][p] = cv.back();
      obs.push_back({p, {b}, cv.back()});
    }
    for (const auto& [p, v] : thr[b]) tv.push_back(mean_of(v));
    json e{{"block", b}};
    if (coarse) e["fine_strength"] = num(block_fine[b]);
    e["participants"] = cv.size();
    e["convergent"] = describe_json(cv);
    e["threshold_last_k"] = describe_json(tv);
    const auto d = stats::describe(cv);
    text += "  " + b + ": convergent " + fmt(d.mean) + " ± " + fmt(d.sd) + " (mean ± SD, n = " + std::to_string(d.n) + ")\n";
    bj.push_back(std::move(e));
  }
  out["blocks"] = bj;
  // Group test across blocks: a paired t-test for two blocks (narrow vs
  // wide), a one-factor RM-ANOVA for more (fine strength 0/50/100 %).
  if (blocks.names.size() == 2) {
    const std::string &a = blocks.names[0], &b = blocks.names[1];
    std::vector<double> va, vb;
    for (const auto& [p, v] : per_participant[a])
      if (per_participant[b].count(p)) va.push_back(v), vb.push_back(per_participant[b][p]);
    json t = guarded([&] { return ttest_json(stats::t_test_paired(va, vb, o.level)); });
    t["comparison"] = a + " − " + b;
    out["paired_t_test"] = t;
    if (t.contains("p"))
      text += "  paired t-test " + a + " − " + b + ": " + fmt_p(t["p"].is_null() ? missing : t["p"].get<double>()) + "\n";
  } else if (blocks.names.size() > 2) {
    // Only participants with every block enter the ANOVA.
    std::vector<stats::Observation> complete;
    for (const auto& ob : obs) {
      bool all = true;
      for (const auto& b : blocks.names) all = all && per_participant[b].count(ob.subject);
      if (all) complete.push_back(ob);
    }
    out["rm_anova"] = guarded([&] { return anova_json(stats::rm_anova(complete, {coarse ? "fine_strength" : "block"})); });
  }
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
  for (const TrialRow* r : matches) {
    const auto [cp, ci] = centre[r->reference];
    const double d = std::hypot(r->pitch_db - cp, r->irregularity_db - ci);
    json m{{"participant", r->participant},
           {"session_id", r->session_id},
           {"reference", r->reference},
           {"pitch_db", num(r->pitch_db)},
           {"irregularity_db", num(r->irregularity_db)},
           {"reference_pitch_db", num(r->reference_pitch_db)},
           {"reference_irregularity_db", num(r->reference_irregularity_db)},
           {"distance_db", num(d)}};
    if (std::isfinite(r->slider_p)) m["slider_p"] = r->slider_p;
    if (std::isfinite(r->slider_i)) m["slider_i"] = r->slider_i;
    if (std::isfinite(r->confidence)) {
      m["confidence"] = r->confidence;
      if (std::isfinite(d)) dist.push_back(d), conf.push_back(r->confidence);
    }
    mj.push_back(std::move(m));
  }
  out["matches"] = mj;
  if (!conf.empty()) {
    // Pearson r of confidence with distance, t-test of r = 0 (n − 2 df).
    json c{{"n", conf.size()}};
    const double mc = mean_of(conf), md = mean_of(dist);
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t k = 0; k < conf.size(); ++k) {
      sxy += (conf[k] - mc) * (dist[k] - md);
      sxx += (conf[k] - mc) * (conf[k] - mc);
      syy += (dist[k] - md) * (dist[k] - md);
    }
    if (conf.size() < 3 || sxx <= 0 || syy <= 0) {
      c["skipped"] = "needs at least 3 matches with varying confidence and distance; got " + std::to_string(conf.size());
    } else {
      const double r = std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
      const double df = static_cast<double>(conf.size() - 2);
      c["pearson_r"] = r;
      if (std::abs(r) < 1) {
        const double t = r * std::sqrt(df / (1 - r * r));
        const boost::math::students_t dist_t(df);
        c["t"] = t;
        c["df"] = df;
        c["p"] = 2 * boost::math::cdf(boost::math::complement(dist_t, std::abs(t)));
      } else {
        c["p"] = 0.0;
      }
      text += "  confidence vs distance: r = " + fmt(r) + ", " + fmt_p(c["p"].get<double>()) + "\n";
    }
    out["confidence_vs_distance"] = c;
  }
}

json ratings_by_reference(const Rows& ratings) {
  Ordered refs;
  std::map<std::string, std::map<std::string, std::vector<double>>> v;  // reference → participant → ratings
  for (const TrialRow* r : ratings) {
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

json match_study(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  Rows matches, ratings;
  for (const TrialRow* r : rows) {
    if (r->task == "match") matches.push_back(r);
    if (r->task == "rating") ratings.push_back(r);
  }
  json out = json::object();
  matching_summary(matches, o, out, text, study);
  if (!ratings.empty()) out["ratings"] = ratings_by_reference(ratings);
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
  // Change = rating(level) − rating(unquantized) per participant × reference,
  // averaged over references per participant, tested against 0.
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
    json e{{"condition", c}, {"quantization_db", num(level_db[c])}, {"change", describe_json(changes)}};
    e["t_test"] = guarded([&] { return ttest_json(stats::t_test_one_sample(changes, 0.0, o.level)); });
    std::string line = "  " + c + " vs unquantized: change " + fmt(mean_of(changes));
    if (e["t_test"].contains("p") && !e["t_test"]["p"].is_null())
      line += ", t(" + fmt(e["t_test"]["df"].get<double>(), 0) + ") = " + fmt(e["t_test"]["t"].get<double>()) + ", " +
              fmt_p(e["t_test"]["p"].get<double>());
    text += line + "\n";
    ch.push_back(std::move(e));
  }
  out["changes"] = ch;
  for (auto& [p, j] : per_participant) pj.push_back(json{{"participant", p}, {"changes", j}});
  out["participants"] = pj;
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
    matches.push_back(last[k]);
    if (!last[k]->procedure_finished) unfinished.push_back(json{{"participant", std::get<0>(k)}, {"reference", std::get<2>(k)}});
  }
  json out = json::object();
  matching_summary(matches, o, out, text, "guided-exploration");
  if (!unfinished.empty()) out["unfinished"] = unfinished;
  if (ratings.empty()) return out;

  // Similarity matrix: rows = reference felt, columns = whose optimized
  // rendering was shown; a participant's repeated ratings are averaged first.
  const std::string prefix = "rendering:";
  Ordered rendering_names = names;
  for (const TrialRow* r : ratings) {
    names.add(r->reference);
    rendering_names.add(r->condition.rfind(prefix, 0) == 0 ? r->condition.substr(prefix.size()) : r->condition);
  }
  std::map<std::string, std::map<std::pair<std::size_t, std::size_t>, std::vector<double>>> cell;  // participant → (row, col)
  for (const TrialRow* r : ratings) {
    const std::string rend = r->condition.rfind(prefix, 0) == 0 ? r->condition.substr(prefix.size()) : r->condition;
    cell[r->participant][{names.add(r->reference), rendering_names.add(rend)}].push_back(r->rating);
  }
  const std::size_t nr = names.names.size(), nc = rendering_names.names.size();
  json mean = json::array(), count = json::array();
  for (std::size_t i = 0; i < nr; ++i) {
    json mrow = json::array(), crow = json::array();
    for (std::size_t j = 0; j < nc; ++j) {
      std::vector<double> m;
      for (auto& [p, c] : cell)
        if (c.count({i, j})) m.push_back(mean_of(c[{i, j}]));
      mrow.push_back(num(mean_of(m)));
      crow.push_back(m.size());
    }
    mean.push_back(mrow);
    count.push_back(crow);
  }
  // Does a reference's own optimized rendering feel more like it than the
  // others' do? Per participant: mean diagonal vs mean off-diagonal rating.
  std::vector<double> diag, off;
  for (auto& [p, c] : cell) {
    std::vector<double> d, f;
    for (auto& [ij, x] : c) {
      const bool same = names.names[ij.first] == rendering_names.names[ij.second];
      (same ? d : f).push_back(mean_of(x));
    }
    if (!d.empty() && !f.empty()) diag.push_back(mean_of(d)), off.push_back(mean_of(f));
  }
  json sim{{"references", names.names}, {"renderings", rendering_names.names}, {"mean_rating", mean}, {"participants", count}};
  json t = guarded([&] { return ttest_json(stats::t_test_paired(diag, off, o.level)); });
  t["comparison"] = "own rendering − other renderings";
  sim["own_vs_other_t_test"] = t;
  out["similarity"] = sim;
  text += "  similarity: own rendering " + fmt(mean_of(diag)) + " vs others " + fmt(mean_of(off));
  if (t.contains("p") && !t["p"].is_null()) text += ", paired " + fmt_p(t["p"].get<double>());
  text += "\n";
  return out;
}

// ----------------------------------------------------------- working memory

json memory_summary(const Rows& rows, const AnalysisOptions& o, std::string& text) {
  struct Person {
    std::vector<double> all, recall;
    std::map<std::string, std::vector<double>> cond;
  };
  std::map<std::string, Person> people;
  Ordered conditions;
  for (const TrialRow* r : rows) {
    if (r->task != "same-different") continue;
    Person& p = people[r->participant];
    conditions.add(r->condition);
    p.all.push_back(r->correct);
    p.cond[r->condition].push_back(r->correct);
    if (r->condition.ends_with("-distractor")) p.recall.push_back(r->digit_correct);
  }
  json out = json::object();
  out["outlier_rule"] = json{{"recall_chance", o.memory_recall_chance}, {"accuracy_sd", o.memory_accuracy_sd}};
  // Rule 1: distractor recall at or below chance → the distractor was ignored.
  std::map<std::string, std::string> excluded;
  for (auto& [id, p] : people) {
    const double rec = mean_of(p.recall);
    if (o.memory_recall_chance >= 0 && std::isfinite(rec) && rec <= o.memory_recall_chance + 1e-12)
      excluded[id] = "distractor recall " + fmt(rec) + " <= chance " + fmt(o.memory_recall_chance, 3);
  }
  // Rule 2: overall accuracy beyond k SD of the remaining group (one pass).
  if (o.memory_accuracy_sd > 0) {
    std::vector<double> acc;
    for (auto& [id, p] : people)
      if (!excluded.count(id)) acc.push_back(mean_of(p.all));
    const auto d = stats::describe(acc);
    if (d.n >= 3 && d.sd > 0)
      for (auto& [id, p] : people) {
        const double z = (mean_of(p.all) - d.mean) / d.sd;
        if (!excluded.count(id) && std::abs(z) > o.memory_accuracy_sd)
          excluded[id] = "accuracy " + fmt(mean_of(p.all)) + " is " + fmt(z) + " SD from the group mean";
      }
  }
  json pj = json::array();
  for (auto& [id, p] : people) {
    json c = json::object();
    for (const auto& n : conditions.names) c[n] = num(mean_of(p.cond[n]));
    pj.push_back(json{{"participant", id},
                      {"trials", p.all.size()},
                      {"accuracy", num(mean_of(p.all))},
                      {"recall_accuracy", num(mean_of(p.recall))},
                      {"conditions", c},
                      {"excluded", excluded.count(id) ? json(excluded[id]) : json(false)}});
  }
  out["participants"] = pj;
  out["included"] = people.size() - excluded.size();
  // Conditions in a fixed 2 × 2 order where they are the standard labels.
  std::vector<std::string> cnames = conditions.names;
  const auto split = [](const std::string& c) {
    const auto dash = c.rfind('-');
    return dash == std::string::npos ? std::pair{c, std::string()} : std::pair{c.substr(0, dash), c.substr(dash + 1)};
  };
  json cj = json::array();
  std::vector<stats::Observation> obs;
  for (const auto& c : cnames) {
    std::vector<double> v;
    for (auto& [id, p] : people)
      if (!excluded.count(id) && p.cond.count(c)) {
        v.push_back(mean_of(p.cond[c]));
        const auto [spacing, distractor] = split(c);
        obs.push_back({id, {spacing, distractor}, v.back()});
      }
    const auto [spacing, distractor] = split(c);
    cj.push_back(json{{"condition", c}, {"spacing", spacing}, {"distractor", distractor}, {"accuracy", describe_json(v)}});
  }
  out["conditions"] = cj;
  out["rm_anova"] = guarded([&] { return anova_json(stats::rm_anova(obs, {"spacing", "distractor"})); });
  text +=
      "working-memory: " + std::to_string(people.size()) + " participants, " + std::to_string(excluded.size()) + " excluded\n";
  for (const auto& c : cj)
    text += "  " + c["condition"].get<std::string>() + ": " +
            fmt(c["accuracy"]["mean"].is_null() ? missing : c["accuracy"]["mean"].get<double>()) + " correct\n";
  if (out["rm_anova"].contains("effects"))
    for (const auto& e : out["rm_anova"]["effects"])
      text += "  " + e["effect"].get<std::string>() + ": F(" + fmt(e["df"].is_null() ? missing : e["df"].get<double>(), 0) +
              ", " + fmt(e["df_error"].is_null() ? missing : e["df_error"].get<double>(), 0) +
              ") = " + fmt(e["f"].is_null() ? missing : e["f"].get<double>()) + ", " +
              fmt_p(e["p"].is_null() ? missing : e["p"].get<double>()) + "\n";
  return out;
}

void check_options(const AnalysisOptions& o) {
  if (o.format != "png" && o.format != "svg") throw InvalidArgument("analysis format is '" + o.format + "'; allowed: png, svg");
  if (o.reversals_k < 1) throw InvalidArgument("analysis reversals_k is 0; must be >= 1");
  if (!(o.level > 0 && o.level < 1))
    throw InvalidArgument("analysis level is " + texel::detail::num(o.level) + "; allowed (0, 1)");
  if (!std::isfinite(o.memory_recall_chance) || o.memory_recall_chance >= 1)
    throw InvalidArgument("analysis memory_recall_chance is " + texel::detail::num(o.memory_recall_chance) +
                          "; allowed < 1 (negative = rule off)");
  if (!(o.memory_accuracy_sd >= 0) || !std::isfinite(o.memory_accuracy_sd))
    throw InvalidArgument("analysis memory_accuracy_sd is " + texel::detail::num(o.memory_accuracy_sd) +
                          "; allowed >= 0 (0 = rule off)");
}

}  // namespace

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
    summary[study] = std::move(head);
    if (!options.out_dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(options.out_dir, ec);
      if (ec) throw IoError("cannot create figure directory '" + options.out_dir + "': " + ec.message());
      for (auto& f : analysis_figures::study_figures(st, summary[study], rs, options)) report.figures.push_back(std::move(f));
    }
  }
  report.summary = summary.dump();
  return report;
}

}  // namespace texel::experiment
