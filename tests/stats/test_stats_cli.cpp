// `texel stats` on the built CLI: anova / ttest / ellipse --json agree with
// the SciPy oracle (tests/stats/oracle.py) within 1e-6; the readable output is
// an aligned table; every class of bad input exits 2 with a single line.
#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "support.hpp"

using namespace texel_stats_test;

namespace {

ProcessResult texel_stats(const std::string& args, bool merge = true) {
  return run_command(std::string(TEXEL_CLI) + " stats " + args, merge);
}

nlohmann::json json_of(const ProcessResult& r) {
  EXPECT_EQ(r.status, 0) << r.out;
  if (r.status != 0) return nlohmann::json::object();
  return nlohmann::json::parse(r.out);
}

std::size_t count_lines(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

void expect_effects_match(const nlohmann::json& got, const nlohmann::json& want) {
  EXPECT_EQ(got["subjects"], want["subjects"]);
  ASSERT_EQ(got["effects"].size(), want["effects"].size());
  for (std::size_t i = 0; i < got["effects"].size(); ++i) {
    const auto& g = got["effects"][i];
    const auto& w = want["effects"][i];
    const std::string name = g["effect"].get<std::string>();
    EXPECT_EQ(name, w["effect"].get<std::string>());
    EXPECT_EQ(g["sphericity_applies"], w["sphericity_applies"]) << name;
    for (const char* k : {"ss", "df", "ss_error", "df_error", "f", "p", "partial_eta2", "gg_epsilon", "p_gg"})
      expect_close(g[k].get<double>(), w[k], name + " " + k);
  }
}

class StatsCli : public StatsFiles {};

}  // namespace

TEST_F(StatsCli, AnovaOneFactorMatchesOracle) {
  const LongData d = make_rm_data({"length"}, {{"short", "medium", "long"}}, 10, 1, 31);
  write_file(path("a.csv"), d.csv());
  const auto got =
      json_of(texel_stats("anova " + path("a.csv") + " --subject participant --within length --dv rt_ms --json", false));
  expect_effects_match(got, oracle("anova " + path("a.csv") + " participant rt_ms length"));
  EXPECT_EQ(got["factors"], nlohmann::json::array({"length"}));
}

TEST_F(StatsCli, AnovaTwoFactorsWithReplicatesMatchesOracle) {
  for (const auto& [lv, seed] : std::vector<std::pair<std::vector<std::vector<std::string>>, unsigned>>{
           {{{"narrow", "wide"}, {"a", "b"}}, 41}, {{{"narrow", "wide"}, {"q1", "q2", "q3"}}, 43}}) {
    const LongData d = make_rm_data({"width", "q"}, lv, 7, 2, seed, true);
    write_file(path("a.csv"), d.csv());
    const auto got =
        json_of(texel_stats("anova " + path("a.csv") + " --subject participant --within width,q --dv rt_ms --json", false));
    expect_effects_match(got, oracle("anova " + path("a.csv") + " participant rt_ms width q"));
  }
}

TEST_F(StatsCli, AnovaReadableTable) {
  const LongData d = make_rm_data({"width", "q"}, {{"narrow", "wide"}, {"q1", "q2", "q3"}}, 5, 1, 3);
  write_file(path("a.csv"), d.csv());
  const ProcessResult r = texel_stats("anova " + path("a.csv") + " --subject participant --within width,q --dv rt_ms");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("effect"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("width:q"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("GG_eps"), std::string::npos) << r.out;
  EXPECT_EQ(count_lines(r.out), 5u) << r.out;  // title, header, 3 effects
}

TEST_F(StatsCli, TTestsMatchOracle) {
  // Student's sleep data plus a gap: the paired test drops the incomplete pair.
  write_file(path("t.csv"),
             "patient,drug1,drug2\n1,0.7,1.9\n2,-1.6,0.8\n3,-0.2,1.1\n4,-1.2,0.1\n5,-0.1,-0.1\n6,3.4,4.4\n7,3.7,5.5\n"
             "8,0.8,1.6\n9,0.0,4.6\n10,2.0,3.4\n11,NA,2.2\n");
  const auto one = json_of(texel_stats("ttest " + path("t.csv") + " --column drug2 --mu 1 --level 0.9 --json", false));
  const auto o1 = oracle("ttest " + path("t.csv") + " drug2 1 0.9");
  for (const char* k : {"n", "mean", "sd", "se", "t", "df", "p", "ci_low", "ci_high", "cohen_d"})
    expect_close(one[k].get<double>(), o1[k], std::string("one-sample ") + k);
  EXPECT_EQ(one["test"], "one_sample_t");

  const auto pr = json_of(texel_stats("ttest " + path("t.csv") + " --column drug1 --paired drug2 --json", false));
  const auto o2 = oracle("paired " + path("t.csv") + " drug1 drug2 0.95");
  for (const char* k : {"n", "mean", "sd", "t", "df", "p", "ci_low", "ci_high", "cohen_d"})
    expect_close(pr[k].get<double>(), o2[k], std::string("paired ") + k);
  EXPECT_NEAR(pr["t"].get<double>(), -4.0621, 5e-5);  // R's documented sleep example
  EXPECT_EQ(pr["n"], 10);

  const ProcessResult readable = texel_stats("ttest " + path("t.csv") + " --column drug1 --paired drug2");
  ASSERT_EQ(readable.status, 0) << readable.out;
  EXPECT_NE(readable.out.find("Paired t-test of drug1 - drug2"), std::string::npos) << readable.out;
  EXPECT_NE(readable.out.find("-4.0621"), std::string::npos) << readable.out;
}

TEST_F(StatsCli, EllipsePerGroupMatchesOracle) {
  std::mt19937 rng(5);
  std::normal_distribution<double> z(0.0, 1.0);
  std::string all = "participant,reference,pitch_db,irregularity_db\n", ga = all, gb = all;
  for (int i = 0; i < 24; ++i) {
    const bool b = i % 2 == 1;
    const double u = z(rng), v = z(rng);
    const std::string row = "S" + std::to_string(i / 2) + "," + (b ? "\"ref, B\"" : "A") + "," +
                            fmt17((b ? 4.0 : -2.0) + 1.5 * u) + "," + fmt17((b ? 0.5 : 1.0) + (b ? -0.8 : 0.6) * u + 0.5 * v) +
                            "\n";
    all += row;
    (b ? gb : ga) += row;
  }
  write_file(path("e.csv"), all);
  write_file(path("a.csv"), ga);
  write_file(path("b.csv"), gb);
  const auto got = json_of(texel_stats(
      "ellipse " + path("e.csv") + " --x pitch_db --y irregularity_db --by reference --level 0.95 --outline 8 --json", false));
  ASSERT_EQ(got["ellipses"].size(), 2u);
  EXPECT_EQ(got["ellipses"][0]["group"], "A");
  EXPECT_EQ(got["ellipses"][1]["group"], "ref, B");
  EXPECT_EQ(got["ellipses"][0]["outline"].size(), 8u);
  for (int g = 0; g < 2; ++g) {
    const auto o = oracle("ellipse " + path(g == 0 ? "a.csv" : "b.csv") + " pitch_db irregularity_db 0.95");
    const auto& e = got["ellipses"][static_cast<std::size_t>(g)];
    for (const char* k :
         {"n", "mean_x", "mean_y", "cov_xx", "cov_xy", "cov_yy", "t2_critical", "semi_major", "semi_minor", "angle_deg"})
      expect_close(e[k].get<double>(), o[k], std::string("group ") + std::to_string(g) + " " + k);
  }
  const ProcessResult readable = texel_stats("ellipse " + path("e.csv") + " --x pitch_db --y irregularity_db");
  ASSERT_EQ(readable.status, 0) << readable.out;
  EXPECT_EQ(count_lines(readable.out), 3u) << readable.out;
}

// Bad input: exit 2, exactly one line, naming what was wrong.
TEST_F(StatsCli, BadInputExitsTwoWithOneLine) {
  const LongData d = make_rm_data({"width", "q"}, {{"narrow", "wide"}, {"q1", "q2"}}, 4, 1, 3);
  std::string csv = d.csv();
  write_file(path("ok.csv"), csv);
  // Drop S101's (wide, q1) row: unbalanced.
  std::string unbalanced;
  {
    std::istringstream in(csv);
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("S101,wide,q1,", 0) != 0) unbalanced += line + "\n";
  }
  write_file(path("unbalanced.csv"), unbalanced);
  write_file(path("ragged.csv"), "a,b\n1,2\n3\n");
  write_file(path("words.csv"), "a,b\n1,x\n2,3\n");
  write_file(path("const.csv"), "a\n2\n2\n2\n");
  write_file(path("two.csv"), "a,b\n1,2\n2,4\n");
  const std::string anova = "anova " + path("ok.csv") + " --subject participant --dv rt_ms ";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"anova " + path("unbalanced.csv") + " --subject participant --within width,q --dv rt_ms",
       "subject 'S101' has no value for cell width=wide, q=q1"},
      {anova + "--within width,nope", "column 'nope' is not in"},
      {anova + "--within width,q,participant", "--within"},
      {"anova " + path("ok.csv") + " --subject participant --within width --dv q", "column 'q' has 'q1'"},
      {"ttest " + path("ragged.csv") + " --column a", "ragged.csv':3: row has 1 field(s)"},
      {"ttest " + path("words.csv") + " --column b", "column 'b' has 'x'"},
      {"ttest " + path("const.csv") + " --column a", "column 'a' (--column) is constant"},
      {"ttest " + path("words.csv") + " --column a --level 2", "--level 2"},
      {"ttest " + path("missing.csv") + " --column a", "missing.csv"},
      {"ellipse " + path("two.csv") + " --x a --y b", "column 'a' (--x), column 'b' (--y) have 2 complete pair(s)"},
      {"ellipse " + path("ok.csv") + " --x rt_ms --y rt_ms --by nope", "column 'nope'"},
      {"ttest " + path("ok.csv"), "--column"},
  };
  for (const auto& [args, needle] : cases) {
    const ProcessResult r = texel_stats(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.out;
    EXPECT_EQ(count_lines(r.out), 1u) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(needle), std::string::npos) << args << "\n" << r.out;
  }
}
