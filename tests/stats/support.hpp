// Shared pieces of tests/stats: the SciPy oracle (tests/stats/oracle.py run
// by Debian's /usr/bin/python3), the seeded data sets, and a process runner.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/temp_dir.hpp"

namespace texel_stats_test {

namespace fs = std::filesystem;

using ProcessResult = texel::test_support::CliRun;

// Runs a shell command; stdout (and stderr when merge) captured.
inline ProcessResult run_command(const std::string& cmd, bool merge = true) {
  return texel::test_support::run_cli(cmd, "", merge);
}

// Debian's interpreter, where python3-scipy is installed (not whatever
// python3 comes first on PATH).
inline const char* python = "/usr/bin/python3";

// Runs the oracle; a missing SciPy is a FAILURE (exit 3 from oracle.py), never a skip.
inline nlohmann::json oracle(const std::string& args) {
  const std::string script = std::string(TEXEL_TEST_SOURCE_DIR) + "/tests/stats/oracle.py";
  const ProcessResult r = run_command(std::string(python) + " " + script + " " + args, false);
  if (r.status != 0) {
    ADD_FAILURE() << "oracle failed (status " << r.status << "): " << python << " " << script << " " << args << "\n"
                  << r.out << "\nIs python3-scipy installed? (scripts/install-deps.sh)";
    return nlohmann::json::object();
  }
  return nlohmann::json::parse(r.out);
}

inline void write_file(const fs::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
}

// |a − b| ≤ 1e-6 · max(1, |b|): 1e-6 absolute for p-values, ε, t, F; relative for large sums of squares.
inline void expect_close(double actual, const nlohmann::json& expected, const std::string& what) {
  ASSERT_FALSE(expected.is_null()) << what << ": oracle has no value";
  const double e = expected.get<double>();
  EXPECT_NEAR(actual, e, 1e-6 * std::max(1.0, std::abs(e))) << what;
}

inline std::string fmt17(double v) {
  if (std::isnan(v)) return "NA";
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// A long-format data set: subject, factor columns, dv.
struct LongData {
  std::vector<std::string> factor_names;
  std::vector<std::string> subject;
  std::vector<std::vector<std::string>> levels;  // per row
  std::vector<double> value;

  std::string csv() const {
    std::string s = "participant";
    for (const auto& f : factor_names) s += "," + f;
    s += ",rt_ms\n";
    for (std::size_t i = 0; i < value.size(); ++i) {
      s += subject[i];
      for (const auto& l : levels[i]) s += "," + l;
      s += "," + (std::isnan(value[i]) ? std::string() : fmt17(value[i])) + "\n";
    }
    return s;
  }
};

// Seeded repeated-measures data with subject-specific slopes, so the cell
// covariance is not spherical and the Greenhouse–Geisser ε is well below 1.
// `replicates` rows per subject × cell (≥ 1); NaN rows sprinkled in when `gaps`.
inline LongData make_rm_data(std::vector<std::string> factor_names, std::vector<std::vector<std::string>> levels, int subjects,
                             int replicates, unsigned seed, bool gaps = false) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  LongData d;
  d.factor_names = factor_names;
  const std::size_t lb = levels.size() == 2 ? levels[1].size() : 1;
  for (int s = 0; s < subjects; ++s) {
    const std::string id = "S" + std::to_string(100 + s);
    const double base = 500 + 60 * z(rng), slope = 25 * z(rng), slope_b = 15 * z(rng);
    for (std::size_t a = 0; a < levels[0].size(); ++a)
      for (std::size_t b = 0; b < lb; ++b) {
        const int reps = replicates + ((s + static_cast<int>(a + b)) % 3 == 0 ? 1 : 0);
        for (int r = 0; r < reps; ++r) {
          std::vector<std::string> lv{levels[0][a]};
          if (levels.size() == 2) lv.push_back(levels[1][b]);
          const double effect = 45.0 * static_cast<double>(a) + slope * static_cast<double>(a * a) +
                                8.0 * static_cast<double>(b) + slope_b * static_cast<double>(b) +
                                4.0 * static_cast<double>(a * b);
          d.subject.push_back(id);
          d.levels.push_back(lv);
          d.value.push_back(base + effect + 20 * z(rng));
          if (gaps && r == 0 && (s * 7 + static_cast<int>(a * 3 + b)) % 11 == 0) {
            // a missing dv next to a real one: skipped, the cell still has data
            d.subject.push_back(id);
            d.levels.push_back(lv);
            d.value.push_back(std::nan(""));
          }
        }
      }
  }
  return d;
}

// Tests that write CSV files for the oracle and the CLI: a fresh directory per test.
class StatsFiles : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return tmp.at(name); }
  texel::test_support::TempDir tmp{"texel-stats"};
};

}  // namespace texel_stats_test
