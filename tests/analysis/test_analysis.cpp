// Per-study analysis: synthetic trial rows of a few simulated participants
// with known values, for every study, against hand-computed summaries
// (convergent values, reversal means, matched means and distances, rating
// changes and their t statistics, the similarity matrix, working-memory
// accuracies and the outlier rule), the tests reported or skipped, every
// expected figure written as a PNG, and the empty / bad-option cases.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/io.hpp"

using namespace texel;
using namespace texel::experiment;
using json = nlohmann::ordered_json;

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
  o.format = "jpg";
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
  // Paired narrow − wide: differences −2, −8, −2.5.
  const json& t = s["paired_t_test"];
  EXPECT_EQ(t["n"], 3);
  EXPECT_NEAR(t["t"].get<double>(), t_of({-2, -8, -2.5}), 1e-9);
  EXPECT_GT(t["p"].get<double>(), 0.0);
  EXPECT_LT(t["p"].get<double>(), 1.0);
}

TEST(Analysis, CoarseFeaturesAnovaOverFineStrength) {
  const json s = summary_of(analyze(coarse_rows(), {}))["coarse-features"];
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

TEST(Analysis, FreeExplorationConfidenceAgainstDistance) {
  const json s = summary_of(analyze(mapping_rows("free-exploration"), {}))["free-exploration"];
  const json& c = s["confidence_vs_distance"];
  EXPECT_EQ(c["n"], 6);
  // Hand computation of Pearson's r.
  std::vector<double> dist, conf;
  for (const auto& m : s["matches"])
    dist.push_back(m["distance_db"].get<double>()), conf.push_back(m["confidence"].get<double>());
  const double md = mean(dist), mc = mean(conf);
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    sxy += (conf[i] - mc) * (dist[i] - md);
    sxx += (conf[i] - mc) * (conf[i] - mc);
    syy += (dist[i] - md) * (dist[i] - md);
  }
  EXPECT_NEAR(c["pearson_r"].get<double>(), sxy / std::sqrt(sxx * syy), 1e-12);
  EXPECT_LT(c["pearson_r"].get<double>(), 0.0);  // confident matches lie closer to the mean
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
  EXPECT_NEAR(q5["t_test"]["t"].get<double>(), t_of({-2, -1.5, -1}), 1e-9);
  EXPECT_EQ(q5["t_test"]["df"].get<double>(), 2.0);
  EXPECT_LT(q5["t_test"]["p"].get<double>(), 0.05);
  EXPECT_LT(q5["t_test"]["ci_high"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(s["conditions"][0]["rating"]["mean"].get<double>(), 4.0);

  // One participant: the t-test reports why it was skipped, nothing throws.
  std::vector<TrialRow> one;
  for (const auto& r : quantization_rows())
    if (r.participant == "S01") one.push_back(r);
  const json s1 = summary_of(analyze(one, {}))["quantization"];
  EXPECT_TRUE(s1["changes"][1]["t_test"].contains("skipped"));
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
  const json s = summary_of(analyze(memory_rows(), {}))["working-memory"];
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
  AnalysisOptions off;
  off.memory_recall_chance = -1;
  off.memory_accuracy_sd = 0;
  EXPECT_EQ(summary_of(analyze(memory_rows(), off))["working-memory"]["included"], 5);
  // The SD rule alone, at 1.2 SD: accuracies 0.75, 0.8125, 0.5625, 0.8125,
  // 0.5 (mean 0.6875, SD 0.1466): S05 lies 1.28 SD below, the others within 0.86.
  AnalysisOptions sd_only;
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
      "free-exploration-matched-vs-reference",
      "free-exploration-matched-boxes",
      "free-exploration-ellipses",
      "free-exploration-confidence",
      "quantization-rating-change",
      "guided-exploration-matched-vs-reference",
      "guided-exploration-matched-boxes",
      "guided-exploration-ellipses",
      "guided-exploration-convergence",
      "guided-exploration-similarity",
      "coarse-features-tracks",
      "coarse-features-convergent",
      "working-memory-performance",
  };
  ASSERT_EQ(r.figures.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(std::filesystem::path(r.figures[i]).filename().string(), expected[i] + ".png");
    const std::string bytes = read_file(r.figures[i]);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << expected[i];
  }
  // Nothing but the figures (no temporaries left behind).
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(o.out_dir)) files += e.is_regular_file();
  EXPECT_EQ(files, expected.size());
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
  EXPECT_TRUE(summary_of(r)["texel-length"]["paired_t_test"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["coarse-features"]["rm_anova"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["working-memory"]["rm_anova"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["guided-exploration"]["references"][0]["ellipse"].contains("skipped"));
  EXPECT_TRUE(summary_of(r)["guided-exploration"]["similarity"]["own_vs_other_t_test"].contains("skipped"));
  EXPECT_EQ(r.figures.size(), 20u);
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
  o.format = "svg";
  const AnalysisReport r = analyze(memory_rows(), o);
  ASSERT_EQ(r.figures.size(), 1u);
  EXPECT_NE(read_file(r.figures[0]).find("</svg>"), std::string::npos);
}
