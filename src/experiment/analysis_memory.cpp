// The working-memory study's analysis (docs/analysis.md §7): the outlier
// rules, the texture × distractor RM-ANOVA (2 × 2 in the source; 2 × 4 with
// the components' distractors, docs/experiments.md "Working-memory
// components"), per texture a paired t-test of each distractor against the
// control, the distraction tasks' own scores, the source's R².
#include "analysis_common.hpp"

#include <array>
#include <map>

namespace texel::experiment::analysis_common {

namespace {

// ----------------------------------------------------------- working memory

struct MemoryPerson {
  std::vector<double> all, recall;  // recall: digit recall (matrix, sequence), 1/0
  std::map<std::string, std::vector<double>> cond;
  double main_errors = 0, distraction_errors = 0;
  int distraction_trials = 0;  // loaded distractor trials scored (recall or n-back)
  // Per distractor kind: recall 1/0, and the n-back's summed counts.
  std::map<std::string, std::vector<double>> kind_recall;
  std::map<std::string, std::array<double, 4>> kind_nback;  // trials, targets, hits, false alarms
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
    if (p.distraction_trials > 0) distraction.push_back(p.distraction_errors);
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
    const bool increase = p.distraction_trials > 0 && std::isfinite(dd.mean) && p.distraction_errors > dd.mean;
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

bool is_component(const std::string& k) { return k == "visuospatial" || k == "verbal" || k == "executive"; }

/// "<spacing>-<distractor>" → (spacing, distractor); a component's own
/// control, "<spacing>-<component>-control", → (spacing, "<component>-control").
std::pair<std::string, std::string> split_condition(const std::string& c) {
  const auto dash = c.rfind('-');
  if (dash == std::string::npos) return {c, std::string()};
  std::pair<std::string, std::string> out{c.substr(0, dash), c.substr(dash + 1)};
  if (out.second == "control")
    if (const auto d2 = out.first.rfind('-'); d2 != std::string::npos && is_component(out.first.substr(d2 + 1)))
      return {out.first.substr(0, d2), out.first.substr(d2 + 1) + "-control"};
  return out;
}

/// Whether a condition's distractor part names a loaded task ("distractor"
/// in the source's protocol, a component otherwise), not a control.
bool loaded(const std::string& kind) { return !kind.empty() && kind != "control" && !kind.ends_with("-control"); }

/// What a loaded distractor is compared with: its component's own control
/// where the spacing has it, else the common one.
std::string control_of(const std::string& kind, const std::map<std::string, std::map<std::string, double>>& kinds) {
  return kinds.count(kind + "-control") ? kind + "-control" : "control";
}

/// The order the components are reported in: control, then the source's
/// matrix, then the new ones (each followed by its own control); other
/// names after them in first-seen order.
int kind_rank(const std::string& kind) {
  static const std::vector<std::string> order = {"control", "distractor",     "visuospatial", "visuospatial-control",
                                                 "verbal",  "verbal-control", "executive",    "executive-control"};
  const auto it = std::find(order.begin(), order.end(), kind);
  return it == order.end() ? static_cast<int>(order.size()) : static_cast<int>(it - order.begin());
}

/// Holm's step-down adjustment of a family of p values (NaN stays NaN).
std::vector<double> holm(const std::vector<double>& p) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::isfinite(p[i])) idx.push_back(i);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return p[a] < p[b]; });
  std::vector<double> out(p.size(), missing);
  double running = 0;
  for (std::size_t r = 0; r < idx.size(); ++r) {
    running = std::max(running, std::min(1.0, static_cast<double>(idx.size() - r) * p[idx[r]]));
    out[idx[r]] = running;
  }
  return out;
}

/// The analysis on the participants a rule keeps: RM-ANOVA (Type III,
/// spacing × distractor), per spacing a paired t-test of each distractor
/// against the control (Holm-adjusted over the family when there are
/// several), and R².
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
      if (!excluded.count(id) && p.distraction_trials > 0) x.push_back(p.distraction_errors), y.push_back(p.main_errors);
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
  std::vector<std::string> kind_names;
  for (const auto& c : conditions)
    if (const auto k = split_condition(c).second;
        loaded(k) && std::find(kind_names.begin(), kind_names.end(), k) == kind_names.end())
      kind_names.push_back(k);
  std::stable_sort(kind_names.begin(), kind_names.end(),
                   [](const auto& a, const auto& b) { return kind_rank(a) < kind_rank(b); });
  std::vector<double> ps;
  for (auto& [spacing, kinds] : by)
    for (const auto& kind : kind_names) {
      std::vector<double> d, c;
      const std::string control = control_of(kind, kinds);
      if (kinds.count(kind) && kinds.count(control))
        for (const auto& [id, x] : kinds[kind])
          if (kinds[control].count(id)) d.push_back(x), c.push_back(kinds[control][id]);
      json t = guarded([&] { return ttest_json(stats::t_test_paired(d, c, o.level)); });
      t["comparison"] = kind + " − " + control;
      ps.push_back(val(t, "p"));
      tests.push_back(json{{"spacing", spacing}, {"distractor", kind}, {"t_test", t}});
    }
  // Several components against one control are a family: Holm's adjusted p beside each.
  if (kind_names.size() > 1) {
    const auto adjusted = holm(ps);
    for (std::size_t i = 0; i < tests.size(); ++i) tests[i]["t_test"]["p_holm"] = num(adjusted[i]);
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

json memory_summary(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  std::map<std::string, MemoryPerson> people;
  Ordered conditions;
  for (const TrialRow* r : rows) {
    if (r->task != "same-different") continue;
    MemoryPerson& p = people[r->participant];
    conditions.add(r->condition);
    p.all.push_back(r->correct);
    p.cond[r->condition].push_back(r->correct);
    if (r->correct == 0) p.main_errors += 1;
    const std::string kind = split_condition(r->condition).second;
    if (!loaded(kind)) continue;
    // A loaded distractor trial: its task's own score. Recall (matrix,
    // sequence): the digit; n-back: an error is any miss or false alarm.
    if (std::isfinite(r->digit_correct)) {
      p.recall.push_back(r->digit_correct);
      p.kind_recall[kind].push_back(r->digit_correct);
      p.distraction_trials += 1;
      if (r->digit_correct == 0) p.distraction_errors += 1;
    } else if (std::isfinite(r->nback_targets) && std::isfinite(r->nback_hits) && std::isfinite(r->nback_false_alarms)) {
      auto& k = p.kind_nback[kind];
      k[0] += 1, k[1] += r->nback_targets, k[2] += r->nback_hits, k[3] += r->nback_false_alarms;
      p.distraction_trials += 1;
      if (r->nback_hits < r->nback_targets || r->nback_false_alarms > 0) p.distraction_errors += 1;
    }
  }
  // The source's order of first appearance, unless the distractors are
  // components: then spacing by first appearance, control first.
  bool components = false;
  for (const auto& c : conditions.names) components = components || is_component(split_condition(c).second);
  if (components) {
    Ordered spacings;
    for (const auto& c : conditions.names) spacings.add(split_condition(c).first);
    std::stable_sort(conditions.names.begin(), conditions.names.end(), [&](const std::string& a, const std::string& b) {
      const auto [sa, ka] = split_condition(a);
      const auto [sb, kb] = split_condition(b);
      const auto at = [&](const std::string& x) { return std::find(spacings.names.begin(), spacings.names.end(), x); };
      const auto ia = at(sa), ib = at(sb);
      return ia != ib ? ia < ib : kind_rank(ka) < kind_rank(kb);
    });
  }
  json out = json::object();
  json source_stats;
  const Excluded by_source = source_rule(people, o, source_stats);
  const Excluded by_recall = recall_accuracy_rule(people, o);
  const Excluded& excluded = o.memory_rule == MemoryRule::source ? by_source
                             : o.memory_rule == MemoryRule::none ? Excluded{}
                                                                 : by_recall;
  out["outlier_rule"] = json{{"rule", std::string(to_string(o.memory_rule))},
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
                      {"distraction_errors", p.distraction_trials == 0 ? json(nullptr) : json(p.distraction_errors)},
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
  // The distraction tasks' own scores per distractor (kept participants):
  // recall accuracy, or the n-back's hit rate and false alarms per trial —
  // whether each task was done, beside what it did to the main task.
  json dj = json::array();
  {
    Ordered kinds;
    for (const auto& c : conditions.names)
      if (const auto k = split_condition(c).second; loaded(k)) kinds.add(k);
    for (const auto& kind : kinds.names) {
      std::vector<double> recall, hit_rate, false_alarms;
      for (auto& [id, p] : people) {
        if (excluded.count(id)) continue;
        if (p.kind_recall.count(kind)) recall.push_back(mean_of(p.kind_recall[kind]));
        if (p.kind_nback.count(kind)) {
          const auto& k = p.kind_nback[kind];
          hit_rate.push_back(k[1] > 0 ? k[2] / k[1] : missing);
          false_alarms.push_back(k[3] / k[0]);
        }
      }
      json e{{"distractor", kind}};
      if (!recall.empty()) e["recall_accuracy"] = describe_json(recall);
      if (!hit_rate.empty()) {
        e["hit_rate"] = describe_json(hit_rate);
        e["false_alarms_per_trial"] = describe_json(false_alarms);
      }
      dj.push_back(std::move(e));
    }
  }
  out["distraction_tasks"] = dj;
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

  text += study + ": " + std::to_string(people.size()) + " participants, " + std::to_string(excluded.size()) +
          " excluded (rule: " + std::string(to_string(o.memory_rule)) + ")\n";
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
    text += "  share of variance explained by the spacing × distractor effects: " + fmt(val(out["effect_share"], "share")) +
            " (with participants: " + fmt(val(out["effect_share"], "share_with_subjects")) + ")\n";
  for (const auto& t : dj) {
    text += "  distraction task " + t["distractor"].get<std::string>() + ":";
    if (t.contains("recall_accuracy"))
      text +=
          " recall " + fmt(val(t["recall_accuracy"], "mean")) + " correct (SEM " + fmt(val(t["recall_accuracy"], "sem")) + ")";
    if (t.contains("hit_rate"))
      text += " hit rate " + fmt(val(t["hit_rate"], "mean")) + " (SEM " + fmt(val(t["hit_rate"], "sem")) + "), " +
              fmt(val(t["false_alarms_per_trial"], "mean")) + " false alarms per trial";
    text += "\n";
  }
  for (const auto& t : out["spacing_t_tests"]) {
    const json& tt = t["t_test"];
    text +=
        "  " + t["spacing"].get<std::string>() + " spacing, " + tt["comparison"].get<std::string>() + " (paired): " + t_text(tt);
    if (tt.contains("cohen_d")) text += ", d = " + fmt(val(tt, "cohen_d"));
    if (std::isfinite(val(tt, "p_holm"))) text += ", Holm " + fmt_p(val(tt, "p_holm"));
    text += "\n";
  }
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
