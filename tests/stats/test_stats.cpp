// texel::experiment::stats and the CSV table, checked against independent
// values: SciPy/NumPy through tests/stats/oracle.py (within 1e-6), and
// published textbook examples (at the precision they were published).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "../support/expect.hpp"
#include "support.hpp"
#include "texel/error.hpp"
#include "texel/experiment/stats.hpp"
#include "texel/experiment/table.hpp"

namespace st = texel::experiment::stats;
using texel::experiment::parse_csv_table;
using namespace texel_stats_test;

namespace {

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();

// Student's sleep data (Cushny & Peebles 1905, as R's `sleep` data set):
// extra hours of sleep of 10 patients under two drugs.
const std::vector<double> sleep1{0.7, -1.6, -0.2, -1.2, -0.1, 3.4, 3.7, 0.8, 0.0, 2.0};
const std::vector<double> sleep2{1.9, 0.8, 1.1, 0.1, -0.1, 4.4, 5.5, 1.6, 4.6, 3.4};

std::vector<st::Observation> observations(const LongData& d) {
  std::vector<st::Observation> obs;
  for (std::size_t i = 0; i < d.value.size(); ++i) obs.push_back({d.subject[i], d.levels[i], d.value[i]});
  return obs;
}

using texel::test_support::message_of;

// Checks against the SciPy / NumPy oracle (tests/stats/oracle.py) on CSV files.
class StatsOracle : public StatsFiles {};

}  // namespace

// ---------------------------------------------------------------- textbook

// R documentation of t.test (example `t.test(extra ~ group, data = sleep,
// paired = TRUE)`, also Student 1908): t = -4.0621, df = 9, p-value = 0.002833,
// 95 % CI -2.4598858 -0.7001142, mean difference -1.58.
TEST(Textbook, SleepPairedT) {
  const st::TTest r = st::t_test_paired(sleep1, sleep2);
  EXPECT_EQ(r.n, 10u);
  EXPECT_NEAR(r.mean, -1.58, 1e-12);
  EXPECT_NEAR(r.t, -4.0621, 5e-5);
  EXPECT_EQ(r.df, 9.0);
  EXPECT_NEAR(r.p, 0.002833, 5e-7);
  EXPECT_NEAR(r.ci_low, -2.4598858, 5e-8);
  EXPECT_NEAR(r.ci_high, -0.7001142, 5e-8);
}

// R: t.test(sleep$extra[1:10]) — t = 1.3257, df = 9, p-value = 0.2176,
// 95 % CI -0.5297804 2.0297804, mean 0.75.
TEST(Textbook, SleepOneSampleT) {
  const st::TTest r = st::t_test_one_sample(sleep1);
  EXPECT_NEAR(r.mean, 0.75, 1e-12);
  EXPECT_NEAR(r.t, 1.3257, 5e-5);
  EXPECT_NEAR(r.p, 0.2176, 5e-5);
  EXPECT_NEAR(r.ci_low, -0.5297804, 5e-8);
  EXPECT_NEAR(r.ci_high, 2.0297804, 5e-8);
}

// Winer (1971), Statistical Principles in Experimental Design, 2nd ed.: four
// drugs × five subjects, reaction time — the worked example of NCSS's
// "Repeated Measures Analysis of Variance" chapter (214). Expected values are
// worked by hand from the printed table, not by any code: grand mean 24.9;
// drug means 26.4, 25.6, 15.6, 32.0 → SS_drugs = 5·139.64 = 698.2; subject
// means 27, 16, 23, 34, 24.5 → SS_subjects = 4·170.2 = 680.8; Σy² = 13892 →
// SS_total = 13892 − 20·24.9² = 1491.8; SS_residual = 1491.8 − 698.2 − 680.8 =
// 112.8; F(3, 12) = (698.2/3)/(112.8/12) = 24.7589.
TEST(Textbook, WinerDrugsOneFactor) {
  const double y[5][4] = {{30, 28, 16, 34}, {14, 18, 10, 22}, {24, 20, 18, 30}, {38, 34, 20, 44}, {26, 28, 14, 30}};
  std::vector<st::Observation> obs;
  for (int s = 0; s < 5; ++s)
    for (int d = 0; d < 4; ++d) obs.push_back({"s" + std::to_string(s), {"drug" + std::to_string(d + 1)}, y[s][d]});
  const st::AnovaTable t = st::rm_anova(obs, {"drug"});
  ASSERT_EQ(t.effects.size(), 1u);
  const st::AnovaEffect& e = t.effects[0];
  EXPECT_EQ(t.subjects, 5u);
  EXPECT_EQ(e.effect, "drug");
  EXPECT_NEAR(e.ss, 698.2, 1e-9);
  EXPECT_EQ(e.df, 3.0);
  EXPECT_NEAR(e.ss_error, 112.8, 1e-9);
  EXPECT_EQ(e.df_error, 12.0);
  EXPECT_NEAR(e.f, 24.7589, 5e-5);
  EXPECT_TRUE(e.sphericity_applies);
  EXPECT_GE(e.gg_epsilon, 1.0 / 3.0);
  EXPECT_LE(e.gg_epsilon, 1.0);
}

// Type 7 quartiles by hand (Hyndman & Fan 1996): for 1..4, h = 3p.
// R documentation of t.test on the same data, unpaired: Welch t = -1.8608,
// df = 17.776, p-value = 0.07939, 95 % CI -3.3654832 0.2054832; with
// var.equal = TRUE, df = 18, p = 0.07919, CI -3.363874 0.203874. SciPy 1.10
// ttest_ind: t = -1.860813467, p = 0.07918671422 (Student), 0.07939414019 (Welch).
TEST(Textbook, SleepTwoSampleT) {
  const st::TwoSampleTTest w = st::t_test_two_sample(sleep1, sleep2, true);
  EXPECT_TRUE(w.welch);
  EXPECT_NEAR(w.t, -1.860813467, 1e-9);
  EXPECT_NEAR(w.df, 17.776, 5e-4);
  EXPECT_NEAR(w.p, 0.07939414019, 1e-10);
  EXPECT_NEAR(w.ci_low, -3.3654832, 5e-8);
  EXPECT_NEAR(w.ci_high, 0.2054832, 5e-8);
  const st::TwoSampleTTest s = st::t_test_two_sample(sleep1, sleep2, false);
  EXPECT_EQ(s.df, 18.0);
  EXPECT_NEAR(s.p, 0.07918671422, 1e-10);
  EXPECT_NEAR(s.ci_low, -3.363874, 5e-7);
  EXPECT_NEAR(s.ci_high, 0.203874, 5e-7);
  EXPECT_NEAR(s.diff, -1.58, 1e-12);
  EXPECT_THROW(st::t_test_two_sample(std::vector<double>{1.0}, sleep2), texel::InvalidArgument);
}

// SciPy 1.10: pearsonr(sleep1, sleep2) r = 0.7951702058, p = 0.005964995797,
// Fisher-z 95 % CI [0.3315254742, 0.9494465336] (R's cor.test gives the same
// interval); f_oneway(sleep1, sleep2, [2.1, 1.5, 3.0, 2.2, 0.4]) F = 2.058672651,
// p = 0.1515061102.
TEST(Textbook, SleepPearsonAndOneWayAnova) {
  const st::Correlation c = st::pearson(sleep1, sleep2);
  EXPECT_EQ(c.n, 10u);
  EXPECT_EQ(c.df, 8.0);
  EXPECT_NEAR(c.r, 0.7951702058, 1e-10);
  EXPECT_NEAR(c.p, 0.005964995797, 1e-12);
  EXPECT_NEAR(c.ci_low, 0.3315254742, 1e-10);
  EXPECT_NEAR(c.ci_high, 0.9494465336, 1e-10);
  EXPECT_THROW(st::pearson(std::vector<double>{1, 2}, std::vector<double>{1, 2}), texel::InvalidArgument);
  EXPECT_THROW(st::pearson(std::vector<double>{1, 1, 1}, std::vector<double>{1, 2, 3}), texel::InvalidArgument);
  const st::OneWayAnova a = st::anova_one_way({sleep1, sleep2, {2.1, 1.5, 3.0, 2.2, 0.4}});
  EXPECT_EQ(a.df_between, 2.0);
  EXPECT_EQ(a.df_within, 22.0);
  EXPECT_NEAR(a.f, 2.058672651, 1e-9);
  EXPECT_NEAR(a.p, 0.1515061102, 1e-10);
  EXPECT_THROW(st::anova_one_way({sleep1}), texel::InvalidArgument);
}

TEST(Describe, QuartilesType7ByHand) {
  const std::vector<double> x{4, NaN, 1, 3, 2};
  const st::Descriptive d = st::describe(x);
  EXPECT_EQ(d.n, 4u);
  EXPECT_DOUBLE_EQ(d.q1, 1.75);
  EXPECT_DOUBLE_EQ(d.median, 2.5);
  EXPECT_DOUBLE_EQ(d.q3, 3.25);
  EXPECT_DOUBLE_EQ(d.min, 1);
  EXPECT_DOUBLE_EQ(d.max, 4);
  EXPECT_DOUBLE_EQ(st::quantile(x, 0.0), 1);
  EXPECT_DOUBLE_EQ(st::quantile(x, 1.0), 4);
  EXPECT_THROW(st::quantile(x, 1.5), texel::InvalidArgument);
}

TEST(Describe, EmptyAndSingle) {
  const std::vector<double> none{NaN, NaN};
  EXPECT_EQ(st::describe(none).n, 0u);
  EXPECT_TRUE(std::isnan(st::describe(none).mean));
  const std::vector<double> one{3.0};
  const st::Descriptive d = st::describe(one);
  EXPECT_EQ(d.mean, 3.0);
  EXPECT_EQ(d.median, 3.0);
  EXPECT_TRUE(std::isnan(d.sd));
  EXPECT_TRUE(std::isnan(d.ci95_low));
}

// ---------------------------------------------------------------- oracle

TEST_F(StatsOracle, DescribeMatchesNumPy) {
  std::mt19937 rng(7);
  std::lognormal_distribution<double> dist(6.0, 0.4);
  std::string csv = "rt\n";
  std::vector<double> x;
  for (int i = 0; i < 37; ++i) {
    x.push_back(i % 9 == 4 ? NaN : dist(rng));
    csv += (std::isnan(x.back()) ? "NA" : fmt17(x.back())) + "\n";
  }
  write_file(path("d.csv"), csv);
  const auto o = oracle("describe " + path("d.csv") + " rt");
  const st::Descriptive d = st::describe(x);
  EXPECT_EQ(d.n, o["n"].get<std::size_t>());
  for (const auto& [k, v] : std::vector<std::pair<const char*, double>>{{"mean", d.mean},
                                                                        {"sd", d.sd},
                                                                        {"sem", d.sem},
                                                                        {"min", d.min},
                                                                        {"q1", d.q1},
                                                                        {"median", d.median},
                                                                        {"q3", d.q3},
                                                                        {"max", d.max},
                                                                        {"ci95_low", d.ci95_low},
                                                                        {"ci95_high", d.ci95_high}})
    expect_close(v, o[k], k);
}

TEST_F(StatsOracle, TTestsMatchSciPy) {
  std::mt19937 rng(11);
  std::normal_distribution<double> z(0.0, 1.0);
  std::string csv = "pitch_db,irregularity_db\n";
  std::vector<double> a, b;
  for (int i = 0; i < 23; ++i) {
    a.push_back(i == 5 ? NaN : 1.5 + 2.0 * z(rng));
    b.push_back(i == 9 ? NaN : 0.5 * a.back() + z(rng));
    if (std::isnan(b.back()) && std::isnan(a.back())) continue;
    csv += (std::isnan(a.back()) ? "" : fmt17(a.back())) + "," + (std::isnan(b.back()) ? "NA" : fmt17(b.back())) + "\n";
  }
  write_file(path("t.csv"), csv);
  {
    const st::TTest r = st::t_test_one_sample(a, 0.8, 0.9);
    const auto o = oracle("ttest " + path("t.csv") + " pitch_db 0.8 0.9");
    EXPECT_EQ(r.n, o["n"].get<std::size_t>());
    for (const auto& [k, v] : std::vector<std::pair<const char*, double>>{{"mean", r.mean},
                                                                          {"sd", r.sd},
                                                                          {"se", r.se},
                                                                          {"t", r.t},
                                                                          {"df", r.df},
                                                                          {"p", r.p},
                                                                          {"ci_low", r.ci_low},
                                                                          {"ci_high", r.ci_high},
                                                                          {"cohen_d", r.cohen_d}})
      expect_close(v, o[k], std::string("one-sample ") + k);
  }
  {
    const st::TTest r = st::t_test_paired(a, b);
    const auto o = oracle("paired " + path("t.csv") + " pitch_db irregularity_db 0.95");
    EXPECT_EQ(r.n, o["n"].get<std::size_t>());
    EXPECT_EQ(r.n, 21u);  // two pairs with a missing side dropped
    for (const auto& [k, v] : std::vector<std::pair<const char*, double>>{{"mean", r.mean},
                                                                          {"sd", r.sd},
                                                                          {"t", r.t},
                                                                          {"df", r.df},
                                                                          {"p", r.p},
                                                                          {"ci_low", r.ci_low},
                                                                          {"ci_high", r.ci_high},
                                                                          {"cohen_d", r.cohen_d}})
      expect_close(v, o[k], std::string("paired ") + k);
  }
}

void expect_anova_matches(const st::AnovaTable& t, const nlohmann::json& o) {
  EXPECT_EQ(t.subjects, o["subjects"].get<std::size_t>());
  ASSERT_EQ(t.effects.size(), o["effects"].size());
  for (std::size_t i = 0; i < t.effects.size(); ++i) {
    const st::AnovaEffect& e = t.effects[i];
    const auto& x = o["effects"][i];
    EXPECT_EQ(e.effect, x["effect"].get<std::string>());
    EXPECT_EQ(e.sphericity_applies, x["sphericity_applies"].get<bool>()) << e.effect;
    for (const auto& [k, v] : std::vector<std::pair<const char*, double>>{{"ss", e.ss},
                                                                          {"df", e.df},
                                                                          {"ss_error", e.ss_error},
                                                                          {"df_error", e.df_error},
                                                                          {"f", e.f},
                                                                          {"p", e.p},
                                                                          {"partial_eta2", e.partial_eta2},
                                                                          {"gg_epsilon", e.gg_epsilon},
                                                                          {"p_gg", e.p_gg}})
      expect_close(v, x[k], e.effect + " " + k);
    EXPECT_NEAR(e.df_gg, e.df * e.gg_epsilon, 1e-12);
    EXPECT_NEAR(e.df_error_gg, e.df_error * e.gg_epsilon, 1e-12);
  }
}

TEST_F(StatsOracle, OneFactorThreeLevelsWithGreenhouseGeisser) {
  const LongData d = make_rm_data({"length"}, {{"short", "medium", "long"}}, 9, 1, 3);
  write_file(path("a.csv"), d.csv());
  const st::AnovaTable t = st::rm_anova(observations(d), {"length"});
  expect_anova_matches(t, oracle("anova " + path("a.csv") + " participant rt_ms length"));
  ASSERT_EQ(t.effects.size(), 1u);
  EXPECT_LT(t.effects[0].gg_epsilon, 0.95);  // the data are built non-spherical: the correction is exercised
  EXPECT_GT(t.effects[0].p_gg, t.effects[0].p);
}

TEST_F(StatsOracle, TwoByTwoAnovaMatchesTheOracle) {
  const LongData d = make_rm_data({"width", "task"}, {{"narrow", "wide"}, {"match", "rate"}}, 7, 1, 5);
  write_file(path("a.csv"), d.csv());
  const st::AnovaTable t = st::rm_anova(observations(d), {"width", "task"});
  expect_anova_matches(t, oracle("anova " + path("a.csv") + " participant rt_ms width task"));
  ASSERT_EQ(t.effects.size(), 3u);
  EXPECT_EQ(t.effects[2].effect, "width:task");
  for (const auto& e : t.effects) {
    EXPECT_FALSE(e.sphericity_applies);
    EXPECT_EQ(e.gg_epsilon, 1.0);
    EXPECT_EQ(e.p_gg, e.p);
  }
}

TEST_F(StatsOracle, TwoByThreeWithReplicatesAndMissingValues) {
  const LongData d = make_rm_data({"width", "q"}, {{"narrow", "wide"}, {"q1", "q2", "q3"}}, 8, 2, 9, true);
  write_file(path("a.csv"), d.csv());
  const st::AnovaTable t = st::rm_anova(observations(d), {"width", "q"});
  expect_anova_matches(t, oracle("anova " + path("a.csv") + " participant rt_ms width q"));
  ASSERT_EQ(t.effects.size(), 3u);
  EXPECT_FALSE(t.effects[0].sphericity_applies);
  EXPECT_TRUE(t.effects[1].sphericity_applies);
  EXPECT_TRUE(t.effects[2].sphericity_applies);
}

// Replicates are averaged per subject × cell: the table equals the one of the cell means.
TEST(Anova, ReplicatesAreAveraged) {
  const LongData d = make_rm_data({"f"}, {{"a", "b", "c"}}, 6, 3, 21);
  std::map<std::pair<std::string, std::string>, std::pair<double, int>> acc;
  for (std::size_t i = 0; i < d.value.size(); ++i) {
    auto& [s, c] = acc[{d.subject[i], d.levels[i][0]}];
    s += d.value[i];
    ++c;
  }
  std::vector<st::Observation> means;
  for (const auto& [k, v] : acc) means.push_back({k.first, {k.second}, v.first / v.second});
  const st::AnovaTable full = st::rm_anova(observations(d), {"f"});
  const st::AnovaTable avg = st::rm_anova(means, {"f"});
  EXPECT_NEAR(full.effects[0].ss, avg.effects[0].ss, 1e-9 * avg.effects[0].ss);
  EXPECT_NEAR(full.effects[0].f, avg.effects[0].f, 1e-9);
  EXPECT_NEAR(full.effects[0].gg_epsilon, avg.effects[0].gg_epsilon, 1e-12);
}

TEST(Anova, UnbalancedDesignNamesTheMissingCell) {
  LongData d = make_rm_data({"width", "q"}, {{"narrow", "wide"}, {"q1", "q2", "q3"}}, 4, 1, 2);
  std::vector<st::Observation> obs;
  for (std::size_t i = 0; i < d.value.size(); ++i)
    if (!(d.subject[i] == "S102" && d.levels[i][0] == "wide" && d.levels[i][1] == "q2"))
      obs.push_back({d.subject[i], d.levels[i], d.value[i]});
  const std::string m = message_of([&] { st::rm_anova(obs, {"width", "q"}); });
  EXPECT_NE(m.find("unbalanced"), std::string::npos) << m;
  EXPECT_NE(m.find("'S102'"), std::string::npos) << m;
  EXPECT_NE(m.find("width=wide, q=q2"), std::string::npos) << m;
}

TEST(Anova, RejectsOneSubjectWrongFactorCountsAndOneLevelFactors) {
  std::vector<st::Observation> obs{{"a", {"x"}, 1}, {"a", {"y"}, 2}};
  EXPECT_THROW_MSG(st::rm_anova(obs, {"f"}), texel::Error, "at least 2 subjects");
  obs.push_back({"b", {"x"}, 1});
  obs.push_back({"b", {"x"}, 2});
  EXPECT_THROW_MSG(st::rm_anova(obs, {"f", "g"}), texel::Error, "expected one per factor");
  EXPECT_THROW_MSG(st::rm_anova(obs, {}), texel::Error, "one or two");
  EXPECT_THROW_MSG(st::rm_anova(obs, {"f", "g", "h"}), texel::Error, "one or two");
  const std::vector<st::Observation> one_level{{"a", {"x"}, 1}, {"b", {"x"}, 2}};
  EXPECT_THROW_MSG(st::rm_anova(one_level, {"f"}), texel::Error, "factor 'f' has 1 level");
}

TEST(TTest, RejectsTooFewConstantUnpairedOrNonFiniteInput) {
  const std::vector<double> one{1.0, NaN}, same{2, 2, 2}, three{1, 2, 3}, two{1, 2};
  EXPECT_THROW_MSG(st::t_test_one_sample(one), texel::Error, "at least 2");
  EXPECT_THROW_MSG(st::t_test_one_sample(same), texel::Error, "constant");
  EXPECT_THROW_MSG(st::t_test_one_sample(three, 0, 1.0), texel::Error, "level 1");
  EXPECT_THROW_MSG(st::t_test_one_sample(three, NaN), texel::Error, "mu");
  EXPECT_THROW_MSG(st::t_test_paired(three, two), texel::Error, "equal length");
}

TEST_F(StatsOracle, EllipseMatchesHotellingFormula) {
  std::mt19937 rng(17);
  std::normal_distribution<double> z(0.0, 1.0);
  std::vector<double> x, y;
  std::string csv = "pitch_db,irregularity_db\n";
  for (int i = 0; i < 14; ++i) {
    const double u = z(rng), v = z(rng);
    x.push_back(-3.0 + 2.0 * u);
    y.push_back(i == 3 ? NaN : 1.0 + 1.2 * u + 0.7 * v);
    csv += fmt17(x.back()) + "," + (std::isnan(y.back()) ? "" : fmt17(y.back())) + "\n";
  }
  write_file(path("e.csv"), csv);
  for (double level : {0.95, 0.5}) {
    const st::Ellipse e = st::mean_confidence_ellipse(x, y, level);
    const auto o = oracle("ellipse " + path("e.csv") + " pitch_db irregularity_db " + fmt17(level));
    EXPECT_EQ(e.n, 13u);
    for (const auto& [k, v] : std::vector<std::pair<const char*, double>>{{"mean_x", e.mean_x},
                                                                          {"mean_y", e.mean_y},
                                                                          {"cov_xx", e.cov_xx},
                                                                          {"cov_xy", e.cov_xy},
                                                                          {"cov_yy", e.cov_yy},
                                                                          {"t2_critical", e.t2_critical},
                                                                          {"semi_major", e.semi_major},
                                                                          {"semi_minor", e.semi_minor},
                                                                          {"angle_deg", e.angle_deg}})
      expect_close(v, o[k], k);
    // Every outline point lies on (m − x̄)ᵀ (S/n)⁻¹ (m − x̄) = T²_crit.
    const double det = e.cov_xx * e.cov_yy - e.cov_xy * e.cov_xy, n = static_cast<double>(e.n);
    const auto pts = e.outline(64);
    ASSERT_EQ(pts.size(), 64u);
    for (const auto& p : pts) {
      const double dx = p[0] - e.mean_x, dy = p[1] - e.mean_y;
      const double q = n * (e.cov_yy * dx * dx - 2 * e.cov_xy * dx * dy + e.cov_xx * dy * dy) / det;
      EXPECT_NEAR(q, e.t2_critical, 1e-9 * e.t2_critical);
    }
  }
}

TEST(Ellipse, RejectsFewerThanThreePairsUnequalLengthsAndLevelZero) {
  const std::vector<double> two{1, 2}, three{1, 2, 3}, y3{1, NaN, 2};
  EXPECT_THROW_MSG(st::mean_confidence_ellipse(two, two), texel::Error, "at least 3");
  EXPECT_THROW_MSG(st::mean_confidence_ellipse(three, y3), texel::Error, "2 complete pair");
  EXPECT_THROW_MSG(st::mean_confidence_ellipse(three, two), texel::Error, "equal length");
  EXPECT_THROW_MSG(st::mean_confidence_ellipse(three, three, 0.0), texel::Error, "level 0");
}

// ---------------------------------------------------------------- CSV table

TEST(Table, QuotesCrlfAndMissing) {
  const auto t = parse_csv_table(
      "\xEF\xBB\xBF"
      "participant,\"note, free\",rt\r\n"
      "S1,\"said \"\"rough\"\"\",412.5\r\n"
      "S2,\"two\nlines\",NA\r\n"
      "\r\n"
      "S3,,\r\n"
      "S4,plain, +1e3 \r\n",
      "t.csv");
  ASSERT_EQ(t.columns, (std::vector<std::string>{"participant", "note, free", "rt"}));
  ASSERT_EQ(t.rows(), 4u);
  EXPECT_EQ(t.cells[0][1], "said \"rough\"");
  EXPECT_EQ(t.cells[1][1], "two\nlines");
  EXPECT_EQ(t.cells[2][1], "");
  EXPECT_EQ(t.lines, (std::vector<std::size_t>{2, 3, 6, 7}));
  const auto rt = t.numbers("rt");
  EXPECT_EQ(rt[0], 412.5);
  EXPECT_TRUE(std::isnan(rt[1]));
  EXPECT_TRUE(std::isnan(rt[2]));
  EXPECT_EQ(rt[3], 1000.0);
  EXPECT_EQ(t.column("note, free"), 1u);
}

TEST(Table, LastLineWithoutNewlineAndEmptyHeaderName) {
  // R's write.csv writes an empty name for the row-name column.
  const auto t = parse_csv_table("\"\",\"x\"\n\"1\",2\n\"2\",3", "r.csv");
  EXPECT_EQ(t.columns, (std::vector<std::string>{"", "x"}));
  EXPECT_EQ(t.numbers("x"), (std::vector<double>{2, 3}));
}

TEST(Table, MalformedCsvAndMissingColumnsNameFileLineAndColumn) {
  EXPECT_THROW_MSG(parse_csv_table("a,b\n1,2\n3\n", "t.csv"), texel::Error, "t.csv:3: row has 1 field(s)");
  EXPECT_THROW_MSG(parse_csv_table("a,b\n1,2,3\n", "t.csv"), texel::Error, "t.csv:2:");
  EXPECT_THROW_MSG(parse_csv_table("a,b\n\"1,2\n", "t.csv"), texel::Error, "t.csv:2: a quoted field");
  EXPECT_THROW_MSG(parse_csv_table("a,b\n\"1\"x,2\n", "t.csv"), texel::Error, "after a closing quote");
  EXPECT_THROW_MSG(parse_csv_table("", "t.csv"), texel::Error, "header");
  EXPECT_THROW_MSG(parse_csv_table("a,a\n1,2\n", "t.csv"), texel::Error, "column 'a' appears twice");
  const auto t = parse_csv_table("subject,rt\nS1,fast\n", "t.csv");
  const std::string m = message_of([&] { t.numbers("rt"); });
  EXPECT_NE(m.find("t.csv:2: column 'rt' has 'fast'"), std::string::npos) << m;
  EXPECT_THROW(t.numbers("rt"), texel::FormatError);
  const std::string c = message_of([&] { t.column("pitch"); });
  EXPECT_NE(c.find("column 'pitch' is not in t.csv; available columns: 'subject', 'rt'"), std::string::npos) << c;
  EXPECT_THROW(t.column("pitch"), texel::InvalidArgument);
  EXPECT_THROW(texel::experiment::load_csv_table("/nonexistent/x.csv"), texel::IoError);
}

TEST(Table, MoreThanTenMillionCellsIsRefused) {
  // One more cell than allowed, cheaply: a single column of empty-ish rows.
  std::string big = "a\n";
  big.reserve(2 * texel::experiment::max_csv_cells + 8);
  for (std::size_t i = 0; i < texel::experiment::max_csv_cells; ++i) big += "1\n";
  const std::string m = message_of([&] { parse_csv_table(big, "big.csv"); });
  EXPECT_NE(m.find("more than 10000000 cells"), std::string::npos) << m;
}

// ---------------------------------------------------------------- properties

namespace {

std::string csv_field(const std::string& v, bool force_quotes) {
  // Quote when RFC 4180 requires it, when forced, and always for an empty
  // field (a line of one empty unquoted field is a blank line, which is skipped).
  if (!force_quotes && !v.empty() && v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

// Any table written by an RFC 4180 writer (quotes, commas, CR/LF inside fields,
// LF or CRLF line ends, with or without a final line end) reads back cell for cell.
RC_GTEST_PROP(TableProperty, WrittenTablesReadBack, ()) {
  const int ncol = *rc::gen::inRange(1, 6);
  const int nrow = *rc::gen::inRange(0, 12);
  const auto cell = rc::gen::container<std::string>(rc::gen::element('a', 'Z', '7', ' ', ',', '"', '\n', '\r', '.'));
  std::vector<std::string> cols;
  for (int c = 0; c < ncol; ++c) cols.push_back("c" + std::to_string(c) + *cell);
  std::vector<std::vector<std::string>> rows;
  for (int r = 0; r < nrow; ++r) {
    std::vector<std::string> row;
    for (int c = 0; c < ncol; ++c) row.push_back(*cell);
    rows.push_back(row);
  }
  const std::string eol = *rc::gen::element(std::string("\n"), std::string("\r\n"));
  const bool final_eol = *rc::gen::arbitrary<bool>();
  const bool force = *rc::gen::arbitrary<bool>();
  std::string text;
  const auto write_row = [&](const std::vector<std::string>& row, bool last) {
    for (std::size_t i = 0; i < row.size(); ++i) text += (i ? "," : "") + csv_field(row[i], force);
    if (!last || final_eol) text += eol;
  };
  write_row(cols, rows.empty());
  for (std::size_t r = 0; r < rows.size(); ++r) write_row(rows[r], r + 1 == rows.size());
  const auto t = parse_csv_table(text, "prop.csv");
  RC_ASSERT(t.columns == cols);
  RC_ASSERT(t.cells == rows);
}

// Arbitrary bytes either parse into a rectangular table or fail with a texel::Error.
RC_GTEST_PROP(TableProperty, ArbitraryTextNeverCrashes, ()) {
  const auto text =
      *rc::gen::container<std::string>(rc::gen::element('a', '1', ',', '"', '\n', '\r', ' ', '\xEF', '\xBB', '\xBF'));
  try {
    const auto t = parse_csv_table(text, "fuzz.csv");
    for (const auto& row : t.cells) RC_ASSERT(row.size() == t.columns.size());
    RC_ASSERT(t.lines.size() == t.rows());
  } catch (const texel::Error&) {
  }
}

// Within-subject effects ignore each subject's overall level: adding a
// per-subject constant changes no effect's SS, error SS, F or ε.
RC_GTEST_PROP(AnovaProperty, SubjectOffsetsDoNotChangeWithinEffects, ()) {
  const unsigned seed = *rc::gen::inRange(1u, 100000u);
  const LongData d = make_rm_data({"a", "b"}, {{"x", "y", "z"}, {"p", "q"}}, 5, 1, seed);
  std::vector<st::Observation> obs = observations(d), shifted = obs;
  for (auto& o : shifted) o.value += 100.0 * static_cast<double>(o.subject.back() - '0');
  const auto t1 = st::rm_anova(obs, {"a", "b"});
  const auto t2 = st::rm_anova(shifted, {"a", "b"});
  for (std::size_t i = 0; i < t1.effects.size(); ++i) {
    RC_ASSERT(std::abs(t1.effects[i].ss - t2.effects[i].ss) <= 1e-7 * (1 + t1.effects[i].ss));
    RC_ASSERT(std::abs(t1.effects[i].ss_error - t2.effects[i].ss_error) <= 1e-7 * (1 + t1.effects[i].ss_error));
    RC_ASSERT(std::abs(t1.effects[i].gg_epsilon - t2.effects[i].gg_epsilon) <= 1e-9);
  }
}
