// `texel encode` on a recording dominated by content above the felt band,
// through the real binary (docs/encoder.md §2, "Version 3"): the share is in
// `--json` ("felt_band"), the warning on standard error as "texel: warning:",
// the exit status 0; `--model 3` gives that content no weight.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/temp_dir.hpp"

using texel::test_support::run_cli;
using texel::test_support::TempDir;

namespace {

const std::string cli = TEXEL_CLI_PATH;

/// A 1 s recording at 44.1 kHz (time CSV): 300 Hz, and 3 kHz 20 dB stronger.
std::string recording(TempDir& dir) {
  std::ostringstream text;
  text.precision(17);
  text << "time_s,value\n";
  for (int i = 0; i < 44100; ++i) {
    const double t = i / 44100.0;
    const double y = 0.05 * std::sin(2.0 * std::numbers::pi * 300.0 * t) + 0.5 * std::sin(2.0 * std::numbers::pi * 3000.0 * t);
    text << t << "," << y << "\n";
  }
  return dir.write("rec.csv", text.str());
}

}  // namespace

TEST(FeltBandCli, AnInputDominatedByWhatIsNotFeltIsReportedAndFlagged) {
  TempDir dir("felt-band-cli");
  const std::string rec = recording(dir);
  for (const char* model : {"2", "3"}) {
    SCOPED_TRACE(std::string("model ") + model);
    const auto j = run_cli(cli, "encode " + rec + " --swipe-speed 100 --model " + model + " --json", false);
    ASSERT_EQ(j.status, 0) << j.out;
    const auto doc = nlohmann::json::parse(j.out);
    EXPECT_NEAR(doc["felt_band"]["power_beyond"].get<double>(), 0.99, 0.005);
    EXPECT_EQ(doc["felt_band"]["top_hz"].get<double>(), 1000.0);
    ASSERT_EQ(doc["warnings"].size(), 1u);
    const double p = doc["estimate"]["central_pitch_db"].get<double>();
    if (std::string(model) == "3")
      EXPECT_NEAR(p, 10.0 * std::log10(3.0), 0.3);  // the 300 Hz component: 3 cpm at 100 mm/s
    else
      EXPECT_GT(p, 10.0);  // model 2 follows the 3 kHz one
    // The text form warns on standard error, one line, and succeeds.
    const auto t = run_cli(cli, "encode " + rec + " --swipe-speed 100 --model " + model);
    ASSERT_EQ(t.status, 0) << t.out;
    EXPECT_NE(t.out.find("texel: warning: 99 % of the input's power lies above the felt band (1000 Hz at 100 mm/s"),
              std::string::npos)
        << t.out;
  }
}
