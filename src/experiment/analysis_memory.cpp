// The working-memory study's analysis (docs/analysis.md §7): the outlier
// rules, the 2 × 2 RM-ANOVA, the source's R².
#include "analysis_common.hpp"

#include <map>

namespace texel::experiment::analysis_common {

namespace {

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

}  // namespace

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

}  // namespace texel::experiment::analysis_common
