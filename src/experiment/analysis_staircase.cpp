// The staircase studies' analysis (texel length, coarse features;
// docs/analysis.md §1, §6): runs, convergent values, group tests.
#include "analysis_common.hpp"

#include <map>
#include <tuple>

namespace texel::experiment::analysis_common {

namespace {

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

}  // namespace

json staircase_summary(const std::string& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  const bool coarse = find_study(study)->blocks_by_fine_strength;
  json out;
  out["variable"] = rows.empty() ? std::string() : rows.front()->variable;
  out["reversals_k"] = o.reversals_k;
  out["convergent_rule"] = std::string(to_string(o.convergent));
  json runs = json::array(), unfinished = json::array();
  // Every run that stopped before its stopping rule is named first, so the
  // reader meets the warning before the numbers.
  std::string run_text;
  Ordered blocks;
  // group (block, or for texel length the block's condition) → participant → values
  std::map<std::string, std::map<std::string, std::vector<double>>> conv, thr;
  std::map<std::string, std::map<std::string, std::vector<double>>> swipe[3];
  std::map<std::string, double> block_fine;
  // The fingers behind the swipe measures (trials of counted runs): a
  // display's or a pointer's, the simulated sweep of a passive presentation
  // or the simulated observer's draws (finger_source "simulated"), flagged
  // traces (no measures) and trials without any.
  std::map<std::string, std::size_t> fingers;
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
    const double end_value =
        o.convergent == ConvergentValue::next && std::isfinite(last.next_intensity) ? last.next_intensity : last.intensity;
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
      for (const TrialRow* r : run.rows)
        ++fingers[!r->swipe_flag.empty()                     ? "flagged"
                  : !std::isfinite(r->swipe_mean_speed_mm_s) ? "none"
                  : r->finger_source.empty()                 ? "unlabelled"
                  : r->presentation_mode == "passive"        ? "simulated (passive)"
                                                             : r->finger_source];
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
  text += study + ": " + std::to_string(runs.size()) + " staircase runs (end value: " + std::string(to_string(o.convergent)) +
          ")" + (unfinished.empty() ? std::string() : ", " + std::to_string(unfinished.size()) + " not finished") + "\n" +
          run_text;
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
    // What the swipe measures are: a correlation over simulated sweeps says
    // nothing of how participants explore, so the report names the fingers.
    json f = json::object();
    std::string listed;
    for (const auto& [source, n] : fingers) {
      f[source] = n;
      listed += (listed.empty() ? "" : ", ") + std::to_string(n) + " " + source;
    }
    out["swipe_fingers"] = f;
    text += "  swipe measures (trials by finger): " + (listed.empty() ? std::string("none") : listed) + "\n";
    if (fingers.count("simulated (passive)") || fingers.count("simulated"))
      text +=
          "  (simulated: a passive presentation's sweep or the simulated observer's draws, not a participant's "
          "exploration)\n";
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

}  // namespace texel::experiment::analysis_common
