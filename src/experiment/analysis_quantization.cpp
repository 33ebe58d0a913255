// The quantization study's analysis (docs/analysis.md §4): rating
// changes per texture and level.
#include "analysis_common.hpp"

#include <map>

namespace texel::experiment::analysis_common {

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

}  // namespace texel::experiment::analysis_common
