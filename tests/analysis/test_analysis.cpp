// Per-study analysis: synthetic trial rows of a few simulated participants
// with known values, for every study, against hand-computed summaries
// (convergent values, reversal means, matched means and distances, rating
// changes and their t statistics, the similarity matrix, working-memory
// accuracies and the outlier rule), the tests reported or skipped, every
// expected figure written as a PNG, and the empty / bad-option cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/io.hpp"
// The figure builders a test inspects (internal).
#include "analysis_figures.hpp"

using namespace texel;
using namespace texel::experiment;
using json = nlohmann::ordered_json;
namespace analysis_figures = texel::experiment::analysis_figures;

// The report's summary (JSON text) as JSON.
static json summary_of(const AnalysisReport& r) { return json::parse(r.summary); }

namespace {

TrialRow base(const std::string& study, const std::string& participant, int trial) {
  TrialRow r;
  r.study = study;
  r.protocol = study;
  r.participant = participant;
  r.session_id = 1;
  r.trial = trial;
  return r;
}

/// One staircase run: intensities presented, which trials reversed, the
/// value computed after the last answer.
void staircase(std::vector<TrialRow>& rows, const std::string& study, const std::string& who, const std::string& block,
               const std::vector<double>& intensities, const std::vector<int>& reversals, double convergent,
               double directional = missing, double fine = missing) {
  const int start = static_cast<int>(rows.size());
  for (std::size_t i = 0; i < intensities.size(); ++i) {
    TrialRow r = base(study, who, start + static_cast<int>(i));
    r.block = block;
    r.trial_in_block = static_cast<int>(i);
    r.task = study == "texel-length" ? "oddity" : "two-alternative";
    r.variable = study == "texel-length" ? "texel_length_mm" : "coarse_strength";
    r.intensity = intensities[i];
    r.reversal = std::find(reversals.begin(), reversals.end(), static_cast<int>(i)) != reversals.end();
    r.correct = 1;
    r.fine_strength = fine;
    r.directional_proportion = directional;
    r.swipe_mean_speed_mm_s = 50;
    const bool last = i + 1 == intensities.size();
    r.next_intensity = last ? convergent : intensities[i + 1];
    r.procedure_finished = last;
    rows.push_back(r);
  }
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (const double x : v) s += x;
  return s / static_cast<double>(v.size());
}
double sd(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (const double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}
double t_of(const std::vector<double>& v, double mu = 0) {
  return (mean(v) - mu) / (sd(v) / std::sqrt(static_cast<double>(v.size())));
}

std::vector<TrialRow> texel_length_rows() {
  std::vector<TrialRow> rows;
  // A practice row far off, which must not count.
  TrialRow practice = base("texel-length", "S01", 0);
  practice.practice = true;
  practice.block = "narrow";
  practice.intensity = 999;
  practice.next_intensity = 999;
  rows.push_back(practice);
  staircase(rows, "texel-length", "S01", "narrow", {26, 23.5, 21, 23.5, 21, 22.25, 21}, {2, 3, 4, 5}, 20.0, 0.2);
  staircase(rows, "texel-length", "S01", "wide", {26, 23.5, 26, 23.5}, {1, 2}, 22.0, 0.4);
  staircase(rows, "texel-length", "S02", "narrow", {26, 23.5, 21, 18.5, 21}, {3}, 19.0, 0.1);
  staircase(rows, "texel-length", "S02", "wide", {26, 28.5, 26}, {1, 2}, 27.0, 0.5);
  staircase(rows, "texel-length", "S03", "narrow", {26, 23.5}, {}, 24.0, 0.3);
  staircase(rows, "texel-length", "S03", "wide", {26, 23.5, 26}, {1}, 26.5, 0.6);
  return rows;
}

std::vector<TrialRow> coarse_rows() {
  std::vector<TrialRow> rows;
  const double conv[3][3] = {{0.30, 0.40, 0.55}, {0.25, 0.45, 0.60}, {0.35, 0.42, 0.70}};
  const char* blocks[3] = {"fine-0", "fine-50", "fine-100"};
  for (int p = 0; p < 3; ++p)
    for (int b = 0; b < 3; ++b)
      staircase(rows, "coarse-features", "S0" + std::to_string(p + 1), blocks[b], {1.0, 0.9, 0.8, 0.85}, {2}, conv[p][b], missing,
                b * 0.5);
  return rows;
}

TrialRow match(const std::string& study, const std::string& who, const std::string& ref, double p, double i, double rp, double ri,
               double confidence = missing) {
  TrialRow r = base(study, who, 0);
  r.task = "match";
  r.reference = ref;
  r.pitch_db = p;
  r.irregularity_db = i;
  r.reference_pitch_db = rp;
  r.reference_irregularity_db = ri;
  r.confidence = confidence;
  return r;
}

TrialRow rating(const std::string& study, const std::string& who, const std::string& ref, const std::string& condition,
                double value, double q = missing) {
  TrialRow r = base(study, who, 100);
  r.task = "rating";
  r.reference = ref;
  r.condition = condition;
  r.rating = value;
  r.quantization_db = q;
  return r;
}

std::vector<TrialRow> mapping_rows(const std::string& study) {
  const bool conf = study == "free-exploration";
  std::vector<TrialRow> rows{
      match(study, "S01", "noise-a", 1.0, -10.0, 2.0, -9.0, conf ? 5 : missing),
      match(study, "S02", "noise-a", 3.0, -8.0, 2.0, -9.0, conf ? 4 : missing),
      match(study, "S03", "noise-a", 2.0, -12.0, 2.0, -9.0, conf ? 2 : missing),
      match(study, "S01", "noise-b", -5.0, 0.0, -4.0, 1.0, conf ? 3 : missing),
      match(study, "S02", "noise-b", -3.0, 2.0, -4.0, 1.0, conf ? 5 : missing),
      match(study, "S03", "noise-b", -7.0, 1.0, -4.0, 1.0, conf ? 1 : missing),
  };
  if (study == "parameter-mapping")
    for (const char* who : {"S01", "S02", "S03"}) {
      rows.push_back(rating(study, who, "noise-a", "match", 7));
      rows.push_back(rating(study, who, "noise-b", "match", who[2] == '1' ? 4 : 6));
    }
  return rows;
}

std::vector<TrialRow> quantization_rows() {
  std::vector<TrialRow> rows;
  // changes (q − unquantized) per participant, averaged over two references:
  // q1: S01 0, S02 −0.5, S03 0; q5: S01 −2, S02 −1.5, S03 −1
  const double unq = 4;
  const std::vector<std::vector<double>> q1{{4, 4}, {3, 4}, {4, 4}};
  const std::vector<std::vector<double>> q5{{2, 2}, {2, 3}, {3, 3}};
  for (int p = 0; p < 3; ++p) {
    const std::string who = "S0" + std::to_string(p + 1);
    for (int ref = 0; ref < 2; ++ref) {
      const std::string name = ref == 0 ? "fine" : "coarse";
      rows.push_back(rating("quantization", who, name, "unquantized", unq, 0));
      rows.push_back(rating("quantization", who, name, "q1", q1[static_cast<std::size_t>(p)][static_cast<std::size_t>(ref)], 1));
      rows.push_back(rating("quantization", who, name, "q5", q5[static_cast<std::size_t>(p)][static_cast<std::size_t>(ref)], 5));
    }
  }
  return rows;
}

std::vector<TrialRow> guided_rows() {
  std::vector<TrialRow> rows;
  const std::vector<std::string> refs{"fam-a", "fam-b", "fam-c"};
  const double final_p[3][3] = {{0, 5, -5}, {1, 6, -4}, {-1, 4, -7}};
  for (int p = 0; p < 3; ++p) {
    const std::string who = "S0" + std::to_string(p + 1);
    for (int k = 0; k < 3; ++k) {
      for (int it = 0; it < 4; ++it) {
        TrialRow r = base("guided-exploration", who, k * 4 + it);
        r.task = "guided";
        r.reference = refs[static_cast<std::size_t>(k)];
        r.iteration = it / 4;
        r.response = "A";
        r.pitch_db = it == 3 ? final_p[p][k] : 0.0;
        r.irregularity_db = it == 3 ? -10.0 + p + k : -12.5;
        r.reference_pitch_db = k * 5.0;
        r.reference_irregularity_db = -10;
        r.procedure_finished = it == 3;
        rows.push_back(r);
      }
      for (int j = 0; j < 3; ++j) {
        // Own rendering rated 5 (S03: 4), others 2.
        const double v = j == k ? (p == 2 ? 4.0 : 5.0) : 2.0;
        TrialRow r = rating("guided-exploration", who, refs[static_cast<std::size_t>(k)],
                            "rendering:" + refs[static_cast<std::size_t>(j)], v);
        r.trial = 20 + k * 3 + j;
        rows.push_back(r);
      }
    }
  }
  return rows;
}

/// Working memory: 5 participants × 4 conditions × 4 trials; S05 never
/// recalls a digit (excluded by the chance rule).
std::vector<TrialRow> memory_rows() {
  std::vector<TrialRow> rows;
  const std::vector<std::string> conds{"wide-control", "wide-distractor", "narrow-control", "narrow-distractor"};
  // correct answers out of 4 per condition
  const int correct[5][4] = {{4, 3, 3, 2}, {4, 3, 4, 2}, {3, 2, 3, 1}, {4, 4, 3, 2}, {2, 2, 2, 2}};
  for (int p = 0; p < 5; ++p) {
    const std::string who = "S0" + std::to_string(p + 1);
    for (int t = 0; t < 8; ++t) {
      TrialRow r = base("working-memory", who, t);
      r.practice = true;
      r.task = "same-different";
      r.condition = "wide-control";
      r.correct = 0;
      rows.push_back(r);
    }
    for (std::size_t c = 0; c < 4; ++c)
      for (int t = 0; t < 4; ++t) {
        TrialRow r = base("working-memory", who, 8 + static_cast<int>(c) * 4 + t);
        r.task = "same-different";
        r.condition = conds[c];
        r.correct = t < correct[p][c] ? 1 : 0;
        if (conds[c].ends_with("distractor")) r.digit_correct = p == 4 ? 0 : (t < 3 ? 1 : 0);
        rows.push_back(r);
      }
  }
  return rows;
}

std::vector<TrialRow> all_rows() {
  std::vector<TrialRow> rows;
  for (auto part : {texel_length_rows(), coarse_rows(), mapping_rows("parameter-mapping"), mapping_rows("free-exploration"),
                    quantization_rows(), guided_rows(), memory_rows()})
    rows.insert(rows.end(), part.begin(), part.end());
  return rows;
}

const json& run_of(const json& s, const std::string& who, const std::string& block) {
  for (const auto& r : s["runs"])
    if (r["participant"] == who && r["block"] == block) return r;
  throw std::runtime_error("no run " + who + "/" + block);
}

}  // namespace

TEST(Analysis, EmptyInputIsAnEmptySummary) {
  test_support::TempDir dir("texel-analysis");
  AnalysisOptions o;
  o.out_dir = dir.at("figs");
  const AnalysisReport r = analyze({}, o);
  EXPECT_TRUE(summary_of(r).empty());
  EXPECT_TRUE(r.figures.empty());
}

TEST(Analysis, BadOptionsThrowInvalidArgument) {
  AnalysisOptions o;
  o.format = static_cast<FigureFormat>(7);  // not one of its values (a C++ caller casting)
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.reversals_k = 0;
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.level = 1.0;
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.memory_accuracy_sd = -1;
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.memory_rule = static_cast<MemoryRule>(7);
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.memory_errors_sd = 0;
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.convergent = static_cast<ConvergentValue>(7);
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.confidence_distance = static_cast<ConfidenceDistance>(7);
  EXPECT_THROW(analyze({}, o), InvalidArgument);
  o = {};
  o.reversals_k = 1001;
  EXPECT_THROW(analyze({}, o), InvalidArgument);
}

// Every option the front doors offer is described once, with the rule analyze() applies:
// the description's own default is in range, and one step past each finite bound is refused.
TEST(Analysis, TheOptionsDescriptionIsTheRuleAnalyzeApplies) {
  const AnalysisOptions defaults;
  int described = 0;
  visit_options(defaults, [&](const auto& v, const texel::OptionSpec& spec) {
    ++described;
    using T = std::remove_cvref_t<decltype(v)>;
    SCOPED_TRACE(std::string(spec.key));
    if constexpr (std::is_enum_v<T>) {
      EXPECT_FALSE(texel::choice_name(spec.choices, static_cast<int>(v)).empty());
    } else if constexpr (!std::is_same_v<T, bool>) {
      EXPECT_NO_THROW(texel::check_option_value(spec, static_cast<double>(v), spec.key));
      for (const double edge : {spec.min, spec.max}) {
        if (!std::isfinite(edge)) continue;
        const double step = std::is_integral_v<T> ? 1.0 : 1e-3;
        const double past = edge == spec.min ? edge - step : edge + step;
        const bool excl = edge == spec.min ? spec.min_exclusive : spec.max_exclusive;
        AnalysisOptions o;
        visit_options(o, [&](auto& member, const texel::OptionSpec& s) {
          if constexpr (std::is_same_v<std::remove_cvref_t<decltype(member)>, T>)
            if (s.key == spec.key) member = static_cast<T>(excl ? edge : past);
        });
        EXPECT_THROW(analyze({}, o), InvalidArgument) << "past " << edge;
        EXPECT_THROW(texel::check_option_value(spec, excl ? edge : past, spec.key), InvalidArgument);
      }
    }
  });
  EXPECT_EQ(described, 11);
}

TEST(Analysis, StudiesInSpecOrderAndOnlyThoseWithData) {
  const AnalysisReport r = analyze(all_rows(), {});
  std::vector<std::string> keys;
  const json all = summary_of(r);
  for (const auto& [k, v] : all.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"texel-length", "parameter-mapping", "free-exploration", "quantization",
                                            "guided-exploration", "coarse-features", "working-memory"}));
  const AnalysisReport only = analyze(quantization_rows(), {});
  EXPECT_EQ(summary_of(only).size(), 1u);
  EXPECT_FALSE(r.text.empty());
}

TEST(Analysis, TexelLengthConvergentValuesAndReversalMeans) {
  AnalysisOptions o;
  o.reversals_k = 2;
  o.convergent = ConvergentValue::next;  // the value computed after the last answer
  const json s = summary_of(analyze(texel_length_rows(), o))["texel-length"];
  EXPECT_EQ(s["participants"], 3);
  EXPECT_EQ(s["variable"], "texel_length_mm");
  const json& a = run_of(s, "S01", "narrow");
  EXPECT_EQ(a["trials"], 7);  // the practice row is not part of the run
  EXPECT_EQ(a["reversals"], 4);
  EXPECT_DOUBLE_EQ(a["convergent"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(a["threshold_last_k"].get<double>(), (21 + 22.25) / 2);  // reversals 23.5? no: last two are trials 4, 5
  EXPECT_EQ(a["threshold_reversals_used"], 2);
  EXPECT_TRUE(a["finished"].get<bool>());
  // Fewer reversals than k: the mean of those there are; none: null.
  EXPECT_DOUBLE_EQ(run_of(s, "S02", "narrow")["threshold_last_k"].get<double>(), 18.5);
  EXPECT_TRUE(run_of(s, "S03", "narrow")["threshold_last_k"].is_null());
  EXPECT_DOUBLE_EQ(run_of(s, "S01", "narrow")["directional_proportion"].get<double>(), 0.2);

  const json& narrow = s["blocks"][0];
  EXPECT_EQ(narrow["block"], "narrow");
  EXPECT_DOUBLE_EQ(narrow["convergent"]["mean"].get<double>(), (20.0 + 19.0 + 24.0) / 3);
  EXPECT_NEAR(narrow["convergent"]["sd"].get<double>(), sd({20, 19, 24}), 1e-12);
  EXPECT_DOUBLE_EQ(s["blocks"][1]["convergent"]["mean"].get<double>(), (22.0 + 27.0 + 26.5) / 3);
  // Everyone ran both blocks (no condition stored: the block is the group),
  // so nobody enters the between-groups tests, and none is paired.
  EXPECT_FALSE(s.contains("paired_t_test"));
  EXPECT_EQ(s["between_groups"]["participants_in_several_groups"].size(), 3u);
  EXPECT_TRUE(s["between_groups"]["anova"].contains("skipped"));

  // Default end value: the source's final value, the last one presented.
  const json d = summary_of(analyze(texel_length_rows(), {}))["texel-length"];
  EXPECT_EQ(d["convergent_rule"], "last-presented");
  EXPECT_DOUBLE_EQ(run_of(d, "S01", "narrow")["convergent"].get<double>(), 21.0);
  EXPECT_DOUBLE_EQ(run_of(d, "S02", "wide")["convergent"].get<double>(), 26.0);
}

TEST(Analysis, CoarseFeaturesAnovaOverFineStrength) {
  AnalysisOptions o;
  o.convergent = ConvergentValue::next;  // the rows' stored convergent values
  const json s = summary_of(analyze(coarse_rows(), o))["coarse-features"];
  ASSERT_EQ(s["blocks"].size(), 3u);
  EXPECT_DOUBLE_EQ(s["blocks"][2]["fine_strength"].get<double>(), 1.0);
  EXPECT_NEAR(s["blocks"][2]["convergent"]["mean"].get<double>(), (0.55 + 0.60 + 0.70) / 3, 1e-12);
  ASSERT_TRUE(s["rm_anova"].contains("effects")) << s["rm_anova"].dump();
  EXPECT_EQ(s["rm_anova"]["effects"][0]["effect"], "fine_strength");
  EXPECT_EQ(s["rm_anova"]["effects"][0]["df"].get<double>(), 2.0);
  EXPECT_LT(s["rm_anova"]["effects"][0]["p"].get<double>(), 0.01);
}

TEST(Analysis, MatchingMeansEllipsesAndDistances) {
  const json s = summary_of(analyze(mapping_rows("parameter-mapping"), {}))["parameter-mapping"];
  ASSERT_EQ(s["references"].size(), 2u);
  const json& a = s["references"][0];
  EXPECT_EQ(a["reference"], "noise-a");
  EXPECT_DOUBLE_EQ(a["pitch_db"]["mean"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(a["irregularity_db"]["mean"].get<double>(), -10.0);
  EXPECT_DOUBLE_EQ(a["pitch_error_db"]["mean"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(a["irregularity_error_db"]["mean"].get<double>(), -1.0);
  EXPECT_EQ(a["ellipse"]["n"], 3);
  EXPECT_DOUBLE_EQ(a["ellipse"]["mean_pitch_db"].get<double>(), 2.0);
  EXPECT_GT(a["ellipse"]["semi_major_db"].get<double>(), a["ellipse"]["semi_minor_db"].get<double>());
  // Matches in participant order; S02's match of noise-a: (3, −8) against the mean (2, −10).
  EXPECT_EQ(s["matches"][2]["participant"], "S02");
  EXPECT_EQ(s["matches"][2]["reference"], "noise-a");
  EXPECT_DOUBLE_EQ(s["matches"][2]["distance_db"].get<double>(), std::hypot(1.0, 2.0));
  ASSERT_EQ(s["ratings"].size(), 2u);
  EXPECT_DOUBLE_EQ(s["ratings"][1]["rating"]["mean"].get<double>(), (4 + 6 + 6) / 3.0);
}

TEST(Analysis, FreeExplorationConfidenceAgainstDistanceToTheRater) {
  const json s = summary_of(analyze(mapping_rows("free-exploration"), {}))["free-exploration"];
  const json& c = s["confidence_vs_distance"];
  EXPECT_EQ(c["distance_to"], "rater");
  EXPECT_EQ(c["n"], 6);
  // Distances to the reference's own position (the rater's stand-in):
  // √2, √2, 3, √2, √2, 3 with confidences 5, 4, 2, 3, 5, 1. SciPy 1.10
  // pearsonr: r = −0.8696263565, p = 0.02438793125, Fisher CI
  // [−0.9855973211, −0.1973358711].
  EXPECT_EQ(s["matches"][4]["participant"], "S03");  // matches in participant order
  EXPECT_DOUBLE_EQ(s["matches"][4]["distance_to_rater_db"].get<double>(), 3.0);
  EXPECT_NEAR(c["r"].get<double>(), -0.8696263565, 1e-9);
  EXPECT_NEAR(c["p"].get<double>(), 0.02438793125, 1e-9);
  EXPECT_NEAR(c["ci_low"].get<double>(), -0.9855973211, 1e-9);
  EXPECT_NEAR(c["ci_high"].get<double>(), -0.1973358711, 1e-9);
  EXPECT_EQ(c["df"].get<double>(), 4.0);

  // The switch: distance from the reference's mean match, as before.
  AnalysisOptions o;
  o.confidence_distance = ConfidenceDistance::group_mean;
  const json g = summary_of(analyze(mapping_rows("free-exploration"), o))["free-exploration"];
  std::vector<double> dist, conf;
  for (const auto& m : g["matches"])
    dist.push_back(m["distance_db"].get<double>()), conf.push_back(m["confidence"].get<double>());
  const double md = mean(dist), mc = mean(conf);
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    sxy += (conf[i] - mc) * (dist[i] - md);
    sxx += (conf[i] - mc) * (conf[i] - mc);
    syy += (dist[i] - md) * (dist[i] - md);
  }
  EXPECT_EQ(g["confidence_vs_distance"]["distance_to"], "group-mean");
  EXPECT_NEAR(g["confidence_vs_distance"]["r"].get<double>(), sxy / std::sqrt(sxx * syy), 1e-12);
}

TEST(Analysis, QuantizationChangesAndOneSampleTTests) {
  const json s = summary_of(analyze(quantization_rows(), {}))["quantization"];
  ASSERT_EQ(s["changes"].size(), 2u);
  const json& q1 = s["changes"][0];
  const json& q5 = s["changes"][1];
  EXPECT_EQ(q1["condition"], "q1");
  EXPECT_EQ(q5["condition"], "q5");
  EXPECT_NEAR(q1["change"]["mean"].get<double>(), -0.5 / 3, 1e-12);
  EXPECT_NEAR(q5["change"]["mean"].get<double>(), -1.5, 1e-12);
  EXPECT_FALSE(q5.contains("t_test"));  // no test pooled over textures
  EXPECT_DOUBLE_EQ(s["conditions"][0]["rating"]["mean"].get<double>(), 4.0);
  // Per texture: "coarse" q5 changes −2, −1, −1 (S01, S02, S03).
  ASSERT_EQ(s["textures"].size(), 2u);
  const json& coarse = s["textures"][1];
  EXPECT_EQ(coarse["reference"], "coarse");
  EXPECT_EQ(coarse["changes"][1]["condition"], "q5");
  EXPECT_NEAR(coarse["changes"][1]["t_test"]["t"].get<double>(), t_of({-2, -1, -1}), 1e-9);
  EXPECT_EQ(coarse["changes"][1]["t_test"]["df"].get<double>(), 2.0);

  // One participant: the t-test reports why it was skipped, nothing throws.
  std::vector<TrialRow> one;
  for (const auto& r : quantization_rows())
    if (r.participant == "S01") one.push_back(r);
  const json s1 = summary_of(analyze(one, {}))["quantization"];
  EXPECT_TRUE(s1["textures"][0]["changes"][1]["t_test"].contains("skipped"));
  EXPECT_TRUE(s1["textures"][0]["rm_anova"].contains("skipped"));
}

TEST(Analysis, GuidedMatchesAndSimilarityMatrix) {
  const json s = summary_of(analyze(guided_rows(), {}))["guided-exploration"];
  ASSERT_EQ(s["references"].size(), 3u);
  // The match is the last (finished) row per participant × reference.
  EXPECT_NEAR(s["references"][1]["pitch_db"]["mean"].get<double>(), 5.0, 1e-12);
  EXPECT_NEAR(s["references"][2]["pitch_db"]["mean"].get<double>(), -16.0 / 3, 1e-12);
  EXPECT_FALSE(s.contains("unfinished"));
  const json& sim = s["similarity"];
  EXPECT_EQ(sim["references"], (std::vector<std::string>{"fam-a", "fam-b", "fam-c"}));
  EXPECT_NEAR(sim["mean_rating"][0][0].get<double>(), 14.0 / 3, 1e-12);
  EXPECT_DOUBLE_EQ(sim["mean_rating"][0][1].get<double>(), 2.0);
  EXPECT_EQ(sim["participants"][2][2], 3);
  // Own vs other: differences 3, 3, 2.
  EXPECT_NEAR(sim["own_vs_other_t_test"]["t"].get<double>(), t_of({3, 3, 2}), 1e-9);
}

TEST(Analysis, WorkingMemoryOutlierRuleAndAnova) {
  AnalysisOptions old;
  old.memory_rule = MemoryRule::recall_accuracy;
  const json s = summary_of(analyze(memory_rows(), old))["working-memory"];
  EXPECT_EQ(s["participants"].size(), 5u);
  EXPECT_EQ(s["included"], 4);
  EXPECT_TRUE(s["participants"][4]["excluded"].is_string());
  EXPECT_EQ(s["participants"][0]["excluded"], false);
  EXPECT_DOUBLE_EQ(s["participants"][0]["recall_accuracy"].get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(s["participants"][0]["accuracy"].get<double>(), 12.0 / 16);  // practice rows left out
  // wide-distractor over S01–S04: 3, 3, 2, 4 of 4.
  const json& wd = s["conditions"][1];
  EXPECT_EQ(wd["condition"], "wide-distractor");
  EXPECT_EQ(wd["spacing"], "wide");
  EXPECT_EQ(wd["distractor"], "distractor");
  EXPECT_DOUBLE_EQ(wd["accuracy"]["mean"].get<double>(), 0.75);
  EXPECT_NEAR(wd["accuracy"]["sem"].get<double>(), sd({0.75, 0.75, 0.5, 1.0}) / 2, 1e-12);
  ASSERT_TRUE(s["rm_anova"].contains("effects")) << s["rm_anova"].dump();
  ASSERT_EQ(s["rm_anova"]["effects"].size(), 3u);
  EXPECT_EQ(s["rm_anova"]["effects"][0]["effect"], "spacing");
  EXPECT_EQ(s["rm_anova"]["subjects"], 4);

  // Rules off: everyone stays in.
  AnalysisOptions off = old;
  off.memory_recall_chance = -1;
  off.memory_accuracy_sd = 0;
  EXPECT_EQ(summary_of(analyze(memory_rows(), off))["working-memory"]["included"], 5);
  AnalysisOptions none;
  none.memory_rule = MemoryRule::none;
  EXPECT_EQ(summary_of(analyze(memory_rows(), none))["working-memory"]["included"], 5);
  // The source's rule (default): S05's 8 errors are within mean + 2 SD
  // (4.8 + 2 · 2.17), so nobody is excluded; the comparison names S05 under
  // the other rule.
  const json src = summary_of(analyze(memory_rows(), {}))["working-memory"];
  EXPECT_EQ(src["included"], 5);
  EXPECT_EQ(src["rules_compared"][1]["rule"], "recall-accuracy");
  EXPECT_EQ(src["rules_compared"][1]["excluded"][0]["participant"], "S05");
  // The SD rule alone, at 1.2 SD: accuracies 0.75, 0.8125, 0.5625, 0.8125,
  // 0.5 (mean 0.6875, SD 0.1466): S05 lies 1.28 SD below, the others within 0.86.
  AnalysisOptions sd_only = old;
  sd_only.memory_recall_chance = -1;
  sd_only.memory_accuracy_sd = 1.2;
  const json s2 = summary_of(analyze(memory_rows(), sd_only))["working-memory"];
  EXPECT_EQ(s2["included"], 4);
  EXPECT_TRUE(s2["participants"][4]["excluded"].is_string());
}

TEST(Analysis, EveryStudyWritesItsFiguresAsPng) {
  test_support::TempDir dir("texel-analysis");
  AnalysisOptions o;
  o.out_dir = dir.at("figures");
  const AnalysisReport r = analyze(all_rows(), o);
  const std::vector<std::string> expected{
      "texel-length-tracks",
      "texel-length-convergent",
      "texel-length-directional",
      "parameter-mapping-matched-vs-reference",
      "parameter-mapping-matched-boxes",
      "parameter-mapping-ellipses",
      "parameter-mapping-ratings",
      "parameter-mapping-irregularity-normalised",
      "free-exploration-matched-vs-reference",
      "free-exploration-matched-boxes",
      "free-exploration-ellipses",
      "free-exploration-confidence",
      "free-exploration-confidence-bins",
      "quantization-rating-change",
      "quantization-match-similarity",
      "guided-exploration-matched-vs-reference",
      "guided-exploration-matched-boxes",
      "guided-exploration-ellipses",
      "guided-exploration-convergence",
      "guided-exploration-similarity",
      "coarse-features-tracks",
      "coarse-features-convergent",
      "coarse-features-participants",
      "working-memory-performance",
      "working-memory-errors-trend",
  };
  ASSERT_EQ(r.figures.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(std::filesystem::path(r.figures[i]).filename().string(), expected[i] + ".png");
    const std::string bytes = read_file(r.figures[i]);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << expected[i];
  }
  // The staircase studies' runs tables beside them.
  ASSERT_EQ(r.tables.size(), 2u);
  EXPECT_EQ(std::filesystem::path(r.tables[0]).filename().string(), "texel-length-runs.csv");
  EXPECT_EQ(std::filesystem::path(r.tables[1]).filename().string(), "coarse-features-runs.csv");
  // Nothing but the figures and tables (no temporaries left behind).
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(o.out_dir)) files += e.is_regular_file();
  EXPECT_EQ(files, expected.size() + r.tables.size());
  if (const char* keep = std::getenv("TEXEL_ANALYSIS_KEEP"))
    for (const auto& f : r.figures)
      std::filesystem::copy_file(f, std::filesystem::path(keep) / std::filesystem::path(f).filename(),
                                 std::filesystem::copy_options::overwrite_existing);
}

TEST(Analysis, SingleParticipantReportsSkippedTestsAndStillDraws) {
  test_support::TempDir dir("texel-analysis");
  std::vector<TrialRow> one;
  for (const auto& r : all_rows())
    if (r.participant == "S01") one.push_back(r);
  AnalysisOptions o;
  o.out_dir = dir.at("one");
  AnalysisReport r;
  ASSERT_NO_THROW(r = analyze(one, o));
  EXPECT_EQ(summary_of(r).size(), 7u);
  EXPECT_TRUE(summary_of(r)["texel-length"]["between_groups"]["anova"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["coarse-features"]["rm_anova"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["working-memory"]["rm_anova"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["guided-exploration"]["references"][0]["ellipse"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["guided-exploration"]["similarity"]["own_vs_other_t_test"].contains("skipped"));
  EXPECT_EQ(r.figures.size(), 25u);
}

TEST(Analysis, ReactionTimesAreParticipantMedians) {
  std::vector<TrialRow> rows = quantization_rows();
  for (auto& r : rows) r.rt_ms = r.participant == "S01" ? (r.condition == "q5" ? 5000 : 1000) : 2000;
  const json s = summary_of(analyze(rows, {}))["quantization"];
  EXPECT_EQ(s["rt_ms_median"]["n"], 3);
  EXPECT_DOUBLE_EQ(s["rt_ms_median"]["min"].get<double>(), 1000);  // S01's median ignores its slow q5 trials
  EXPECT_DOUBLE_EQ(s["rt_ms_median"]["max"].get<double>(), 2000);
}

namespace {
/// Same structure, strings and booleans; numbers within 1e-9 relative.
void expect_same(const json& a, const json& b, const std::string& at) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    EXPECT_NEAR(x, y, 1e-9 * std::max(1.0, std::abs(x))) << at;
    return;
  }
  ASSERT_EQ(a.type(), b.type()) << at;
  if (a.is_object()) {
    ASSERT_EQ(a.size(), b.size()) << at;
    for (const auto& [k, v] : a.items()) {
      ASSERT_TRUE(b.contains(k)) << at << "/" << k;
      expect_same(v, b[k], at + "/" + k);
    }
  } else if (a.is_array()) {
    ASSERT_EQ(a.size(), b.size()) << at;
    for (std::size_t i = 0; i < a.size(); ++i) expect_same(a[i], b[i], at + "/" + std::to_string(i));
  } else {
    EXPECT_EQ(a, b) << at;
  }
}
}  // namespace

// The summary is a function of the rows alone: analysing the exported CSV
// read back gives the same numbers as analysing the rows themselves.
TEST(Analysis, ExportedCsvGivesTheSameSummary) {
  const std::vector<TrialRow> rows = all_rows();
  const std::vector<TrialRow> back = parse_trials_csv(trials_csv(rows), "export.csv");
  ASSERT_EQ(back.size(), rows.size());
  expect_same(summary_of(analyze(rows, {})), summary_of(analyze(back, {})), "");
}

TEST(Analysis, SvgFiguresOnRequest) {
  test_support::TempDir dir("texel-analysis");
  AnalysisOptions o;
  o.out_dir = dir.at("svg");
  o.format = FigureFormat::svg;
  const AnalysisReport r = analyze(memory_rows(), o);
  ASSERT_EQ(r.figures.size(), 2u);  // performance, errors trend
  for (const auto& f : r.figures) EXPECT_NE(read_file(f).find("</svg>"), std::string::npos) << f;
}

// ------------------------------------------- the source's situations, replayed
// Expected numbers below were computed independently with SciPy 1.10 /
// NumPy 1.24 (Debian's /usr/bin/python3) at development time; the scripts'
// arithmetic is described next to each block.

namespace {

/// Working memory, a cohort built like the source's: 16 participants, 32
/// test trials (8 per condition), 16 digit questions. Errors per condition
/// (wide-control, wide-distractor, narrow-control, narrow-distractor); the
/// last two are the source's situation: 17 and 18 main-task errors with no
/// rise in distraction-task errors (2 and 3, the group's mean being 3.25).
std::vector<TrialRow> source_memory_cohort(int last_distraction_errors = 3) {
  const int errors[16][4] = {{1, 1, 1, 3}, {1, 2, 1, 3}, {1, 2, 2, 3}, {2, 1, 1, 4}, {1, 2, 2, 4}, {2, 2, 1, 4},
                             {1, 1, 2, 5}, {2, 2, 2, 4}, {1, 2, 2, 5}, {2, 3, 1, 4}, {2, 2, 2, 5}, {2, 3, 2, 4},
                             {2, 3, 2, 5}, {3, 2, 2, 5}, {5, 4, 5, 3}, {5, 4, 5, 4}};
  int distraction[16] = {3, 4, 2, 5, 3, 4, 3, 2, 4, 5, 3, 3, 4, 2, 2, 3};
  distraction[15] = last_distraction_errors;
  const std::vector<std::string> conds{"wide-control", "wide-distractor", "narrow-control", "narrow-distractor"};
  std::vector<TrialRow> rows;
  for (int p = 0; p < 16; ++p) {
    const std::string who = (p < 9 ? "P0" : "P") + std::to_string(p + 1);
    int digit_trial = 0;
    for (std::size_t c = 0; c < 4; ++c)
      for (int t = 0; t < 8; ++t) {
        TrialRow r = base("working-memory", who, static_cast<int>(c) * 8 + t);
        r.task = "same-different";
        r.condition = conds[c];
        r.correct = t < errors[p][c] ? 0 : 1;
        if (conds[c].ends_with("distractor")) r.digit_correct = digit_trial++ < distraction[p] ? 0 : 1;
        rows.push_back(r);
      }
  }
  return rows;
}

const json& effect(const json& anova, const std::string& name) {
  for (const auto& e : anova["effects"])
    if (e["effect"] == name) return e;
  throw std::runtime_error("no effect " + name);
}

}  // namespace

TEST(Analysis, WorkingMemorySourceRuleExcludesTheSourcesTwoOutliers) {
  const AnalysisReport report = analyze(source_memory_cohort(), {});
  const json s = summary_of(report)["working-memory"];
  // Main-task errors: mean 10.4375, SD 3.2242570204, limit (z 1.85)
  // 16.4024; 17 and 18 reach it, their 2 and 3 distraction errors are not above 3.25.
  EXPECT_EQ(s["outlier_rule"]["rule"], "source");
  EXPECT_EQ(s["included"], 14);
  EXPECT_TRUE(s["participants"][14]["excluded"].is_string());
  EXPECT_TRUE(s["participants"][15]["excluded"].is_string());
  EXPECT_EQ(s["participants"][14]["main_errors"].get<double>(), 17.0);
  EXPECT_EQ(s["participants"][15]["main_errors"].get<double>(), 18.0);
  for (int p = 0; p < 14; ++p) EXPECT_EQ(s["participants"][p]["excluded"], false) << p;
  const json& th = s["rules_compared"][0]["thresholds"];
  EXPECT_NEAR(th["main_errors_mean"].get<double>(), 10.4375, 1e-12);
  EXPECT_NEAR(th["main_errors_sd"].get<double>(), 3.2242570204, 1e-9);
  EXPECT_NEAR(th["main_errors_limit"].get<double>(), 10.4375 + 1.85 * 3.2242570203588508, 1e-9);
  EXPECT_NEAR(th["distraction_errors_mean"].get<double>(), 3.25, 1e-12);

  // On the 14 kept: 2 × 2 RM-ANOVA (each F(1, 13) = t² of the effect's
  // contrast, scipy ttest_1samp), R² = SS_effects / SS_total of the 56
  // accuracies, paired t-tests distractor − control per spacing (ttest_rel).
  const json& a = s["rm_anova"];
  EXPECT_EQ(a["subjects"], 14);
  EXPECT_NEAR(effect(a, "spacing")["f"].get<double>(), 38.48684211, 1e-7);
  EXPECT_NEAR(effect(a, "spacing")["p"].get<double>(), 3.199482218e-05, 1e-13);
  EXPECT_NEAR(effect(a, "distractor")["f"].get<double>(), 192.5925926, 1e-6);
  EXPECT_NEAR(effect(a, "spacing:distractor")["f"].get<double>(), 47.17741935, 1e-7);
  EXPECT_NEAR(effect(a, "spacing:distractor")["p"].get<double>(), 1.137901131e-05, 1e-13);
  EXPECT_EQ(effect(a, "spacing:distractor")["df_error"].get<double>(), 13.0);
  EXPECT_NEAR(s["effect_share"]["share"].get<double>(), 0.7327586207, 1e-9);
  EXPECT_NEAR(s["effect_share"]["share_with_subjects"].get<double>(), 0.8577586207, 1e-9);
  // The source's R²: main-task errors against distraction-task errors over
  // the 14 kept (scipy.stats.linregress(distraction, main)).
  EXPECT_EQ(s["r2"]["n"], 14);
  EXPECT_NEAR(s["r2"]["r2"].get<double>(), 0.018042870456663553, 1e-12);
  EXPECT_NEAR(s["r2"]["slope"].get<double>(), -0.2378378378378378, 1e-12);
  EXPECT_NEAR(s["r2"]["intercept"].get<double>(), 10.227027027027027, 1e-12);
  EXPECT_NEAR(s["r2"]["p"].get<double>(), 0.6470822245991925, 1e-10);
  const json& narrow = s["spacing_t_tests"][0]["spacing"] == "narrow" ? s["spacing_t_tests"][0] : s["spacing_t_tests"][1];
  const json& wide = s["spacing_t_tests"][0]["spacing"] == "wide" ? s["spacing_t_tests"][0] : s["spacing_t_tests"][1];
  EXPECT_NEAR(narrow["t_test"]["t"].get<double>(), -14.38117456, 1e-7);
  EXPECT_NEAR(narrow["t_test"]["p"].get<double>(), 2.318871751e-09, 1e-17);
  EXPECT_NEAR(narrow["t_test"]["ci_low"].get<double>(), -0.3594443718, 1e-9);
  EXPECT_NEAR(wide["t_test"]["t"].get<double>(), -1.793828805, 1e-8);
  EXPECT_NEAR(wide["t_test"]["p"].get<double>(), 0.09612115802, 1e-9);
  EXPECT_NEAR(wide["t_test"]["ci_high"].get<double>(), 0.009122044519, 1e-9);

  // The earlier rule keeps both: recall 14/16 and 13/16 is far above chance
  // and their accuracy z is −2.04 and −2.35, inside 2.5 SD.
  const json& old = s["rules_compared"][1];
  EXPECT_EQ(old["rule"], "recall-accuracy");
  EXPECT_EQ(old["included"], 16);
  EXPECT_TRUE(old["excluded"].empty());
  EXPECT_NEAR(effect(old["rm_anova"], "spacing:distractor")["f"].get<double>(), 25.90349076, 1e-7);
  EXPECT_NEAR(effect(old["rm_anova"], "spacing:distractor")["p"].get<double>(), 0.000133206898, 1e-12);
  AnalysisOptions o;
  o.memory_rule = MemoryRule::recall_accuracy;
  const json k = summary_of(analyze(source_memory_cohort(), o))["working-memory"];
  EXPECT_EQ(k["included"], 16);
  EXPECT_NEAR(k["effect_share"]["share"].get<double>(), 0.3941694915, 1e-9);
  EXPECT_NEAR(k["r2"]["r2"].get<double>(), 0.09301269205076819, 1e-12);  // all 16
  EXPECT_NEAR(effect(k["rm_anova"], "distractor")["f"].get<double>(), 19.65240642, 1e-7);

  // The text prints the source's forms and names who each rule excludes.
  EXPECT_NE(report.text.find("spacing:distractor: F(1, 13) = 47.18, p < 0.001"), std::string::npos) << report.text;
  EXPECT_NE(report.text.find("narrow spacing, distractor − control (paired): t(13) = -14.38, p < 0.001, 95 % CI [-0.36, -0.27]"),
            std::string::npos)
      << report.text;
  EXPECT_NE(report.text.find("rule source excludes P15, P16"), std::string::npos) << report.text;
  EXPECT_NE(report.text.find("rule recall-accuracy excludes nobody"), std::string::npos) << report.text;
}

TEST(Analysis, WorkingMemorySourceRuleKeepsAnOutlierWhoseDistractionErrorsRose) {
  // P16 with 18 main-task errors but 6 distraction errors (above the mean,
  // now 3.4375): the errors came with the distractor, so P16 stays.
  const json s = summary_of(analyze(source_memory_cohort(6), {}))["working-memory"];
  EXPECT_EQ(s["included"], 15);
  EXPECT_TRUE(s["participants"][14]["excluded"].is_string());
  EXPECT_EQ(s["participants"][15]["excluded"], false);
}

namespace {

/// Texel length, three separate groups (the main block's condition), one
/// run each: convergent (last presented) values and per-run swipe measures.
std::vector<TrialRow> texel_length_groups() {
  const std::vector<std::pair<std::string, std::vector<double>>> groups{
      {"narrow", {6.5, 8.0, 7.25, 9.0}}, {"wide", {4.0, 5.5, 3.75, 5.0}}, {"wide-visual-practice", {4.5, 3.5, 5.25}}};
  const double speed[11] = {80, 95, 70, 110, 60, 75, 55, 90, 65, 50, 72};
  const double sdev[11] = {20, 25, 18, 30, 15, 22, 14, 26, 19, 12, 21};
  const double dir[11] = {0.1, 0.3, -0.1, 0.2, 0.0, -0.2, 0.1, 0.05, -0.05, 0.15, 0.0};
  std::vector<TrialRow> rows;
  int k = 0;
  for (const auto& [group, values] : groups)
    for (const double v : values) {
      const std::string who = "T" + std::to_string(10 + k);
      staircase(rows, "texel-length", who, "main", {26, 23.5, v}, {1}, v - 1.25, dir[k]);
      for (auto it = rows.end() - 3; it != rows.end(); ++it) {
        it->condition = group;
        it->swipe_mean_speed_mm_s = speed[k];
        it->swipe_sd_speed_mm_s = sdev[k];
      }
      ++k;
    }
  return rows;
}

}  // namespace

TEST(Analysis, TexelLengthBetweenGroupsAndSwipeCorrelations) {
  const AnalysisReport report = analyze(texel_length_groups(), {});
  const json s = summary_of(report)["texel-length"];
  EXPECT_FALSE(s.contains("paired_t_test"));
  ASSERT_EQ(s["blocks"].size(), 3u);
  EXPECT_EQ(s["blocks"][2]["block"], "wide-visual-practice");
  const json& bg = s["between_groups"];
  EXPECT_TRUE(bg["participants_in_several_groups"].empty());
  // scipy.stats.f_oneway: F(2, 8) = 14.77725247, p = 0.002059262843.
  EXPECT_EQ(bg["anova"]["df_between"].get<double>(), 2.0);
  EXPECT_EQ(bg["anova"]["df_within"].get<double>(), 8.0);
  EXPECT_NEAR(bg["anova"]["f"].get<double>(), 14.77725247, 1e-7);
  EXPECT_NEAR(bg["anova"]["p"].get<double>(), 0.002059262843, 1e-11);
  // ttest_ind narrow vs wide: Student t(6) = 4.629100499, p = 0.003581066245
  // (CI of the difference [1.473145708, 4.776854292]); Welch df 5.643254200,
  // p = 0.004190008279. wide vs wide-visual-practice: t = 0.2253846897, p = 0.8306024562.
  const json& nw = bg["t_tests"][0];
  EXPECT_EQ(nw["comparison"], "narrow − wide");
  EXPECT_NEAR(nw["student"]["t"].get<double>(), 4.629100499, 1e-8);
  EXPECT_NEAR(nw["student"]["p"].get<double>(), 0.003581066245, 1e-11);
  EXPECT_NEAR(nw["student"]["ci_low"].get<double>(), 1.473145708, 1e-8);
  EXPECT_NEAR(nw["student"]["ci_high"].get<double>(), 4.776854292, 1e-8);
  EXPECT_NEAR(nw["welch"]["df"].get<double>(), 5.643254200, 1e-8);
  EXPECT_NEAR(nw["welch"]["p"].get<double>(), 0.004190008279, 1e-11);
  EXPECT_NEAR(bg["t_tests"][1]["welch"]["t"].get<double>(), 4.442407905, 1e-8);
  EXPECT_NEAR(bg["t_tests"][1]["welch"]["p"].get<double>(), 0.007118114438, 1e-11);
  EXPECT_NEAR(bg["t_tests"][2]["student"]["t"].get<double>(), 0.2253846897, 1e-9);
  EXPECT_NEAR(bg["t_tests"][2]["student"]["p"].get<double>(), 0.8306024562, 1e-9);
  // The fingers behind the swipe measures are named: these rows predate the finger columns...
  EXPECT_EQ(s["swipe_fingers"], json({{"unlabelled", 33}}));
  EXPECT_NE(report.text.find("swipe measures (trials by finger): 33 unlabelled\n"), std::string::npos) << report.text;
  {
    // ...and a passive presentation's simulated sweep is said to be one, beside a display's finger.
    std::vector<TrialRow> rows = texel_length_groups();
    for (std::size_t i = 0; i < rows.size(); ++i) {
      rows[i].finger_source = i % 3 ? "display" : "simulated";
      rows[i].presentation_mode = i % 3 ? "display-plays" : "passive";
    }
    rows[1].swipe_flag = "too_short: 2 intervals over 0.004 s touched";
    const AnalysisReport labelled = analyze(rows, {});
    EXPECT_EQ(summary_of(labelled)["texel-length"]["swipe_fingers"],
              json({{"display", 21}, {"flagged", 1}, {"simulated (passive)", 11}}));
    EXPECT_NE(labelled.text.find("swipe measures (trials by finger): 21 display, 1 flagged, 11 simulated (passive)\n  "
                                 "(simulated: a passive presentation's sweep"),
              std::string::npos)
        << labelled.text;
  }
  // scipy.stats.pearsonr against the 11 convergent values, Fisher CI.
  const json& sw = s["swipe_vs_convergent"];
  ASSERT_EQ(sw.size(), 3u);
  EXPECT_EQ(sw[0]["measure"], "swipe_mean_speed_mm_s");
  EXPECT_NEAR(sw[0]["correlation"]["r"].get<double>(), 0.8550217809, 1e-9);
  EXPECT_NEAR(sw[0]["correlation"]["p"].get<double>(), 0.0007954278683, 1e-12);
  EXPECT_NEAR(sw[0]["correlation"]["ci_low"].get<double>(), 0.5238144452, 1e-9);
  EXPECT_NEAR(sw[0]["correlation"]["ci_high"].get<double>(), 0.96165697, 1e-8);
  EXPECT_NEAR(sw[1]["correlation"]["r"].get<double>(), 0.7647468686, 1e-9);
  EXPECT_NEAR(sw[1]["correlation"]["p"].get<double>(), 0.00611299589, 1e-11);
  EXPECT_NEAR(sw[2]["correlation"]["r"].get<double>(), 0.3264463937, 1e-9);
  EXPECT_NEAR(sw[2]["correlation"]["p"].get<double>(), 0.3271904328, 1e-9);
  EXPECT_NEAR(sw[2]["correlation"]["ci_low"].get<double>(), -0.3400122011, 1e-9);
  EXPECT_NE(report.text.find("between groups (one-way ANOVA): F(2, 8) = 14.78, p = 0.002"), std::string::npos) << report.text;
  EXPECT_NE(report.text.find("swipe_mean_speed_mm_s vs convergent: r = 0.86, p < 0.001 (n = 11), 95 % CI [0.52, 0.96]"),
            std::string::npos)
      << report.text;
}

TEST(Analysis, QuantizationPerTextureAnovaAndTTests) {
  // Two textures, four participants; ratings unquantized (once) and at 1, 3,
  // 5 dB (twice each). Expected: one-way RM-ANOVA by hand in NumPy (SS_error =
  // SS_total − SS_levels − SS_subjects), scipy.stats.f.sf; ttest_1samp.
  struct Ratings {
    double unq;
    double q[3][2];
  };
  const Ratings sin4[4] = {
      {5, {{5, 4}, {4, 3}, {2, 3}}}, {4, {{4, 4}, {3, 3}, {2, 2}}}, {5, {{4, 5}, {4, 4}, {3, 2}}}, {4, {{4, 3}, {3, 2}, {2, 1}}}};
  const Ratings saw[4] = {
      {4, {{4, 4}, {4, 5}, {4, 3}}}, {4, {{5, 4}, {4, 4}, {4, 4}}}, {3, {{3, 3}, {4, 3}, {3, 3}}}, {5, {{4, 5}, {5, 4}, {4, 5}}}};
  std::vector<TrialRow> rows;
  for (int p = 0; p < 4; ++p)
    for (const auto& [name, data] : {std::pair{"4sin", sin4}, std::pair{"saw", saw}}) {
      const std::string who = "Q0" + std::to_string(p + 1);
      rows.push_back(rating("quantization", who, name, "unquantized", data[p].unq, 0));
      for (int l = 0; l < 3; ++l)
        for (int k = 0; k < 2; ++k)
          rows.push_back(rating("quantization", who, name, "q" + std::to_string(2 * l + 1), data[p].q[l][k], 2 * l + 1));
    }
  const AnalysisReport report = analyze(rows, {});
  const json s = summary_of(report)["quantization"];
  ASSERT_EQ(s["textures"].size(), 2u);
  const json& a = s["textures"][0];
  EXPECT_EQ(a["reference"], "4sin");
  EXPECT_EQ(a["levels"], (std::vector<std::string>{"unquantized", "q1", "q3", "q5"}));
  const json& fa = a["rm_anova"]["effects"][0];
  EXPECT_EQ(fa["df"].get<double>(), 3.0);
  EXPECT_EQ(fa["df_error"].get<double>(), 9.0);
  EXPECT_NEAR(fa["f"].get<double>(), 160.5, 1e-9);
  EXPECT_NEAR(fa["p"].get<double>(), 3.941941777e-08, 1e-16);
  EXPECT_NEAR(a["changes"][0]["t_test"]["t"].get<double>(), -3.0, 1e-9);
  EXPECT_NEAR(a["changes"][0]["t_test"]["p"].get<double>(), 0.05766888562, 1e-10);
  EXPECT_NEAR(a["changes"][1]["t_test"]["p"].get<double>(), 0.003239037077, 1e-11);
  EXPECT_NEAR(a["changes"][2]["t_test"]["t"].get<double>(), -19.0, 1e-9);
  EXPECT_NEAR(a["changes"][2]["t_test"]["p"].get<double>(), 0.0003183434401, 1e-12);
  const json& b = s["textures"][1];
  EXPECT_NEAR(b["rm_anova"]["effects"][0]["f"].get<double>(), 1.163265306, 1e-8);
  EXPECT_NEAR(b["rm_anova"]["effects"][0]["p"].get<double>(), 0.37625218, 1e-8);
  EXPECT_NEAR(b["changes"][1]["t_test"]["t"].get<double>(), 0.5222329679, 1e-9);
  EXPECT_NEAR(b["changes"][2]["t_test"]["p"].get<double>(), 0.1816901138, 1e-9);
  EXPECT_NE(report.text.find("quantization: F(3, 9) = 160.50, p < 0.001"), std::string::npos) << report.text;
  EXPECT_NE(report.text.find("q5 − unquantized: change -2.38, t(3) = -19.00, p < 0.001"), std::string::npos) << report.text;
}

TEST(Analysis, ParameterMappingRatedPairsAndNormalisedIrregularity) {
  // Three references; every participant rates the own match of each and,
  // for "a", the matches of "b" and "c" (condition "rendering:<name>").
  std::vector<TrialRow> rows;
  const double slider[2][3] = {{10, 30, 50}, {40, 60, 100}};
  for (int p = 0; p < 2; ++p) {
    const std::string who = "M0" + std::to_string(p + 1);
    const char* refs[3] = {"a", "b", "c"};
    for (int r = 0; r < 3; ++r) {
      TrialRow m = match("parameter-mapping", who, refs[r], 0, -10 + r, 0, -10);
      m.slider_i = slider[p][r];
      rows.push_back(m);
      rows.push_back(rating("parameter-mapping", who, refs[r], "match", 8 - p));
    }
    rows.push_back(rating("parameter-mapping", who, "a", "rendering:b", 4));
    rows.push_back(rating("parameter-mapping", who, "a", "rendering:c", 2 + p));
  }
  test_support::TempDir dir("texel-analysis");
  AnalysisOptions o;
  o.out_dir = dir.at("pm");
  const AnalysisReport report = analyze(rows, o);
  const json s = summary_of(report)["parameter-mapping"];
  const json& sim = s["similarity"];
  EXPECT_EQ(sim["pairs_rated"], 5);
  EXPECT_EQ(sim["pairs_possible"], 9);
  EXPECT_DOUBLE_EQ(sim["mean_rating"][0][2].get<double>(), 2.5);
  EXPECT_TRUE(sim["mean_rating"][1][0].is_null());
  // own − other per participant: M01 8 − 3 = 5, M02 7 − 3.5 = 3.5.
  EXPECT_NEAR(sim["own_vs_other_t_test"]["mean"].get<double>(), 4.25, 1e-12);
  EXPECT_EQ(s["ratings"][0]["rating"]["n"], 2);  // own-match ratings only
  EXPECT_DOUBLE_EQ(s["ratings"][0]["rating"]["mean"].get<double>(), 7.5);
  // Irregularity slider normalised per participant: M01 (10, 30, 50) →
  // (0, 0.5, 1); M02 (40, 60, 100) → (0, 1/3, 1).
  const json& n = s["irregularity_normalised"];
  EXPECT_EQ(n["from"], "slider_i");
  EXPECT_NEAR(n["references"][1]["irregularity_normalised"]["mean"].get<double>(), (0.5 + 1.0 / 3) / 2, 1e-12);
  EXPECT_DOUBLE_EQ(n["references"][2]["irregularity_normalised"]["mean"].get<double>(), 1.0);
  bool heatmap = false, normalised = false;
  for (const auto& f : report.figures) {
    heatmap |= f.ends_with("parameter-mapping-similarity.png");
    normalised |= f.ends_with("parameter-mapping-irregularity-normalised.png");
  }
  EXPECT_TRUE(heatmap);
  EXPECT_TRUE(normalised);
  // The comparisons of two different references (the source's figure): a vs b, a vs c.
  ASSERT_EQ(s["comparisons"].size(), 2u);
  EXPECT_EQ(s["comparisons"][0]["comparison"], "a vs b");
  EXPECT_DOUBLE_EQ(s["comparisons"][1]["rating"]["mean"].get<double>(), 2.5);
  EXPECT_TRUE(std::any_of(report.figures.begin(), report.figures.end(),
                          [](const std::string& f) { return f.ends_with("parameter-mapping-comparisons.png"); }));
}

TEST(Analysis, GuidedAgainstFreeExplorationSpread) {
  // Matches of "4sin" in both studies; spread = distance from the study's
  // mean match. Free: (0,0), (2,0), (0,2), (3,3); guided: (1,1), (1.5,1),
  // (1,0.5), (0.5,1.5). scipy.stats.ttest_ind(guided, free, equal_var=False).
  std::vector<TrialRow> rows;
  const double f[4][2] = {{0, 0}, {2, 0}, {0, 2}, {3, 3}};
  const double g[4][2] = {{1, 1}, {1.5, 1}, {1, 0.5}, {0.5, 1.5}};
  for (int p = 0; p < 4; ++p) {
    const std::string who = "G0" + std::to_string(p + 1);
    rows.push_back(match("free-exploration", who, "4sin", f[p][0], f[p][1], 1, 1));
    TrialRow r = base("guided-exploration", who, 0);
    r.task = "guided";
    r.reference = "4sin";
    r.pitch_db = g[p][0];
    r.irregularity_db = g[p][1];
    r.procedure_finished = true;
    rows.push_back(r);
  }
  const json s = summary_of(analyze(rows, {}))["guided-exploration"];
  ASSERT_EQ(s["spread_vs_free_exploration"].size(), 1u);
  const json& t = s["spread_vs_free_exploration"][0]["welch_t_test"];
  EXPECT_EQ(t["test"], "welch");
  EXPECT_NEAR(t["t"].get<double>(), -4.813576553, 1e-8);
  EXPECT_NEAR(t["p"].get<double>(), 0.004717043796, 1e-11);
}

// ------------------------------------------------ issue #37: what the data hold

TEST(Analysis, TracksDrawOnlyThePresentedTrials) {
  // Six answered trials; the row of the last one carries the value computed
  // after it (38.5 mm), which was never presented: six points, not seven.
  std::vector<TrialRow> rows;
  staircase(rows, "texel-length", "S01", "narrow", {26, 28.5, 31, 33.5, 36, 36}, {}, 38.5);
  std::vector<const TrialRow*> ptrs;
  for (const auto& r : rows) ptrs.push_back(&r);
  const Figure f = analysis_figures::staircase_tracks(*find_study("texel-length"), ptrs);
  ASSERT_EQ(f.panels.size(), 1u);
  ASSERT_EQ(f.panels[0].lines.size(), 1u);
  EXPECT_EQ(f.panels[0].lines[0].x.size(), 6u);
  EXPECT_EQ(f.panels[0].lines[0].y.back(), 36.0);
  EXPECT_EQ(f.panels[0].lines[0].label, "narrow");
}

namespace {
/// S09's staircase stopped after 6 trials with 0 of its 10 reversals
/// (procedure_finished never set), beside two finished runs.
std::vector<TrialRow> with_unfinished_run() {
  std::vector<TrialRow> rows;
  staircase(rows, "texel-length", "S01", "narrow", {26, 23.5, 21, 23.5}, {2}, 22.0);
  staircase(rows, "texel-length", "S02", "narrow", {26, 23.5, 26, 23.5}, {1, 2}, 25.0);
  staircase(rows, "texel-length", "S09", "narrow", {26, 28.5, 31, 33.5, 36, 36}, {}, 38.5);
  for (auto& r : rows)
    if (r.participant == "S09") r.procedure_finished = false;
  return rows;
}
}  // namespace

TEST(Analysis, AnUnfinishedStaircaseReadsNotFinishedEverywhere) {
  test_support::TempDir dir("texel-analysis");
  AnalysisOptions o;
  o.out_dir = dir.at("unfinished");
  const AnalysisReport report = analyze(with_unfinished_run(), o);
  const json s = summary_of(report)["texel-length"];
  const json& run = run_of(s, "S09", "narrow");
  EXPECT_EQ(run["status"], "not finished");
  EXPECT_FALSE(run["finished"].get<bool>());
  EXPECT_TRUE(run["convergent"].is_null());         // no convergent value …
  EXPECT_EQ(run["end_value"].get<double>(), 36.0);  // … only where it stopped
  EXPECT_FALSE(run["in_group_statistics"].get<bool>());
  EXPECT_EQ(run_of(s, "S01", "narrow")["status"], "finished");
  ASSERT_EQ(s["unfinished_runs"].size(), 1u);
  // Group statistics over the two finished runs only.
  EXPECT_EQ(s["blocks"][0]["participants"], 2);
  EXPECT_EQ(s["blocks"][0]["unfinished_runs_left_out"], 1);
  EXPECT_DOUBLE_EQ(s["blocks"][0]["convergent"]["mean"].get<double>(), (23.5 + 23.5) / 2);
  // The text says so, and never calls 36 convergent.
  EXPECT_NE(report.text.find("S09 narrow (session 1): not finished, stopped after 6 trials with 0 reversals"), std::string::npos)
      << report.text;
  EXPECT_EQ(report.text.find("convergent 36"), std::string::npos) << report.text;
  // The runs table: a status column.
  ASSERT_EQ(report.tables.size(), 1u);
  const std::string csv = read_file(report.tables[0]);
  EXPECT_NE(csv.find(",status,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("S09,1,narrow,narrow,,6,0,not finished,0,36,,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("S01,1,narrow,narrow,,4,1,finished,1,23.5,23.5,21,1"), std::string::npos) << csv;
  // The figure: the run's line is labelled, and its panel titled, "not finished".
  std::vector<const TrialRow*> ptrs;
  const auto rows = with_unfinished_run();
  for (const auto& r : rows) ptrs.push_back(&r);
  const Figure f = analysis_figures::staircase_tracks(*find_study("texel-length"), ptrs);
  bool labelled = false;
  for (const auto& p : f.panels)
    for (const auto& l : p.lines)
      if (l.label == "narrow (not finished)") labelled = p.title.find("not finished") != std::string::npos;
  EXPECT_TRUE(labelled);

  // Asked for: its end value joins the group statistics, still labelled.
  AnalysisOptions with = o;
  with.include_unfinished = true;
  with.out_dir.clear();
  const json w = summary_of(analyze(with_unfinished_run(), with))["texel-length"];
  EXPECT_EQ(run_of(w, "S09", "narrow")["status"], "not finished");
  EXPECT_EQ(w["blocks"][0]["participants"], 3);
  EXPECT_EQ(w["blocks"][0]["unfinished_runs_included"], 1);
  EXPECT_DOUBLE_EQ(w["blocks"][0]["convergent"]["mean"].get<double>(), (23.5 + 23.5 + 36.0) / 3);
}

TEST(Analysis, AnUnfinishedGuidedRunIsLeftOutOfTheMatches) {
  std::vector<TrialRow> rows;
  for (int p = 0; p < 3; ++p) {
    TrialRow r = base("guided-exploration", "G0" + std::to_string(p + 1), 0);
    r.task = "guided";
    r.reference = "4sin";
    r.pitch_db = p;
    r.irregularity_db = -p;
    r.procedure_finished = p != 2;
    rows.push_back(r);
  }
  const json s = summary_of(analyze(rows, {}))["guided-exploration"];
  EXPECT_EQ(s["references"][0]["n"], 2);
  ASSERT_EQ(s["unfinished"].size(), 1u);
  EXPECT_EQ(s["unfinished"][0]["status"], "not finished");
  AnalysisOptions with;
  with.include_unfinished = true;
  EXPECT_EQ(summary_of(analyze(rows, with))["guided-exploration"]["references"][0]["n"], 3);
}

TEST(Analysis, TheSourceRuleReproducesTheSourcesExclusionsFromItsOwnFigures) {
  // The source: main-task errors mean 10.63, SD 3.36; it excluded the
  // participants with 17 (z 1.90) and 18 (z 2.19) errors, "near two
  // standard deviations". The literal mean + 2 SD (17.35) would keep 17.
  const AnalysisOptions o;
  const double limit = memory_errors_limit(10.63, 3.36, o);
  EXPECT_GE(17.0, limit);
  EXPECT_GE(18.0, limit);
  EXPECT_LT(16.0, limit);  // z 1.60: kept
  AnalysisOptions literal;
  literal.memory_errors_sd_tolerance = 0;
  EXPECT_NEAR(memory_errors_limit(10.63, 3.36, literal), 17.35, 1e-12);
  EXPECT_LT(17.0, memory_errors_limit(10.63, 3.36, literal));
  // A tolerance at or beyond the SD count is refused.
  AnalysisOptions bad;
  bad.memory_errors_sd_tolerance = 2.0;
  EXPECT_THROW(analyze(memory_rows(), bad), InvalidArgument);
}

// Figures land in out_dir only when every one was drawn; nothing of the run is left otherwise.
TEST(Analysis, FiguresAppearWholeOrNotAtAll) {
  test_support::TempDir dir("texel-analysis");
  AnalysisOptions o;
  o.out_dir = dir.at("new/figures");
  const AnalysisReport r = analyze(with_unfinished_run(), o);
  ASSERT_FALSE(r.figures.empty());
  for (const auto& f : r.figures) {
    EXPECT_EQ(std::filesystem::path(f).parent_path(), std::filesystem::path(o.out_dir)) << f;
    EXPECT_TRUE(std::filesystem::exists(f)) << f;
  }
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(o.out_dir)) {
    EXPECT_EQ(e.path().filename().string().rfind(".texel-analysis-", 0), std::string::npos) << "the staging folder was left";
    ++files;
  }
  EXPECT_EQ(files, r.figures.size() + r.tables.size());
  // A folder that cannot be made (a file is in its way): one IoError, and the file untouched.
  const std::string blocked = dir.at("blocked");
  texel::write_file_atomic(blocked, "x");
  o.out_dir = blocked + "/figures";
  EXPECT_THROW(analyze(with_unfinished_run(), o), IoError);
  EXPECT_EQ(read_file(blocked), "x");
}
