// `texel staircase` on the built CLI: the published PsychoPy case as JSON and
// as a table, and every class of bad input exits 2 with one line on stderr
// naming the flag (answers after the staircase finished are an error).
#include <gtest/gtest.h>

#include "../support/cli_run.hpp"

#include <sys/wait.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

using texel::test_support::CliRun;
CliRun run(const std::string& args, bool merge_stderr = true) {
  return texel::test_support::run_cli(TEXEL_CLI, args, merge_stderr);
}

const std::string published =
    "staircase --start 0.8 --steps 0.1,0.01,0.001 --n-up 1 --n-down 3 --n-reversals 4 --n-trials 20 "
    "--responses 1,1,1,1,0,0,0,0,1,1,1,1,0,0,0,0,1,1,1,1";

void expect_one_line_error(const std::string& args, const std::string& flag) {
  const CliRun r = run(args);
  EXPECT_EQ(r.status, 2) << args << "\n" << r.out;
  ASSERT_FALSE(r.out.empty()) << args;
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << "more than one line: " << r.out;
  EXPECT_NE(r.out.find(flag), std::string::npos) << r.out;
}

}  // namespace

TEST(StaircaseCli, PublishedCaseAsJson) {
  const CliRun r = run(published + " --json", false);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  const std::vector<double> want = {0.8,  0.7,   0.6,   0.5,  0.4,   0.41,  0.42,  0.43,  0.44,  0.44,
                                    0.44, 0.439, 0.439, 0.44, 0.441, 0.442, 0.443, 0.443, 0.443, 0.442};
  ASSERT_EQ(j["intensities"].size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(j["intensities"][i].get<double>(), want[i], 1e-9) << i;
  EXPECT_EQ(j["reversal_trials"], nlohmann::json::array({4, 10, 12, 18}));
  EXPECT_EQ(j["finished"], true);
  EXPECT_NEAR(j["next_value"].get<double>(), 0.442, 1e-9);
  EXPECT_EQ(j["trials"], 20);
}

TEST(StaircaseCli, PublishedCaseAsTable) {
  const CliRun r = run(published, false);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("reversals: 4 of 4 (trials 4 10 12 18)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("finished: yes"), std::string::npos);
  EXPECT_NE(r.out.find("0.442"), std::string::npos);
}

TEST(StaircaseCli, UnfinishedAndOptions) {
  const CliRun r = run("staircase --start 10 --steps 6 --step-type db --n-down 1 --responses 1 --json", false);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["finished"], false);
  EXPECT_NEAR(j["next_value"].get<double>(), 10 * std::pow(10, -0.3), 1e-9);
  const CliRun c = run("staircase --start 1 --steps 0.1,0.05 --n-reversals 3 --min 0 --max 1 --responses 0 --json", false);
  ASSERT_EQ(c.status, 0) << c.out;
  EXPECT_NEAR(nlohmann::json::parse(c.out)["next_value"].get<double>(), 1.0, 1e-12);  // clamped at --max
}

TEST(StaircaseCli, BadInputExitsTwoWithOneLine) {
  expect_one_line_error("staircase --start 0.8 --steps 0.1,x --responses 1", "--steps");
  expect_one_line_error("staircase --start 0.8 --steps 0.1,-0.2 --responses 1", "--steps");
  expect_one_line_error("staircase --start 0.8 --steps 0.1 --responses 1,2", "--responses");
  expect_one_line_error("staircase --start 0.8 --steps 0.1 --n-up 0 --responses 1", "--n-up");
  expect_one_line_error("staircase --start 0.8 --steps 0.1 --step-type linear --responses 1", "--step-type");
  expect_one_line_error("staircase --start 0 --steps 0.1 --step-type log --responses 1", "--start");
  expect_one_line_error("staircase --start 0.8 --steps 0.1 --min 2 --max 1 --responses 1", "--min");
  expect_one_line_error("staircase --start 0.8 --steps 0.1", "--responses");
  // Answers after the staircase finished: an error, not silently dropped.
  expect_one_line_error(published + ",1", "--responses");
}
