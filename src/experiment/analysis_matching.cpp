// The matching studies' analysis (parameter mapping, free and guided
// exploration; docs/analysis.md §2, §3, §5): matches, ellipses, similarity.
#include "analysis_common.hpp"

#include <map>
#include <tuple>

namespace texel::experiment::analysis_common {

namespace {

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
  const bool to_rater = o.confidence_distance == ConfidenceDistance::rater;
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

}  // namespace

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

}  // namespace texel::experiment::analysis_common
