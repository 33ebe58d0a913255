// Acceptance checks of issue #5 on the built CLI: `texel swipe` writes a
// 2-second WAV whose spectrum peaks at Central Pitch × speed; `texel play
// --backend null` runs and reports blocks and the worst block time; bad
// input exits 2 with one line and writes nothing.
#include <gtest/gtest.h>

#include "../support/cli_run.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "texel/player.hpp"
#include "texel/signal.hpp"
#include "texel/sinks.hpp"

namespace fs = std::filesystem;

namespace {

using texel::test_support::CliRun;
CliRun run(const std::string& args) { return texel::test_support::run_cli(TEXEL_CLI, args); }

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("texel-player-cli-" + std::to_string(::getpid()) + "-" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir);
    doc = (dir / "demo.texel.json").string();
    ASSERT_EQ(run("render --seed 1 -o " + doc).status, 0);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
  std::string doc;
};

}  // namespace

TEST_F(Cli, SwipeWavPeaksAtCentralPitchTimesSpeed) {
  const std::string wav = (dir / "s.wav").string();
  const CliRun r = run("swipe " + doc + " --speed 100 --duration 2 -o " + wav);
  ASSERT_EQ(r.status, 0) << r.out;
  const texel::Recording rec = texel::read_recording(wav);
  const std::vector<float> s(rec.samples.begin(), rec.samples.end());
  const double rate = rec.rate.value();
  EXPECT_EQ(rate, 48000);
  EXPECT_EQ(s.size(), 96000u);
  // Central Pitch 10 dB = 10 cycles/mm; at 100 mm/s: 1000 Hz (texel
  // frequencies spread about ±3 % at Irregularity −5 dB).
  const auto spec = texel::signal_spectrum(s, rate);
  EXPECT_NEAR(spec.peak_hz(1.0), 1000.0, 30.0);
}

TEST_F(Cli, SwipeCsvAndPlot) {
  const std::string csv = (dir / "s.csv").string(), png = (dir / "s.png").string();
  const CliRun r = run("swipe " + doc + " --pattern back-and-forth --duration 0.5 --rate 8333 --output amplitude -o " + csv +
                       " --plot " + png);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::exists(png));
  EXPECT_GT(fs::file_size(csv), 4000u * 10);
}

TEST_F(Cli, PlayNullReportsBlocksAndWorstTime) {
  const CliRun r = run("play " + doc + " --backend null --duration 1");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("blocks processed: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("worst block "), std::string::npos) << r.out;
}

TEST_F(Cli, BadInputExitsTwoAndWritesNothing) {
  const std::string wav = (dir / "bad.wav").string();
  for (const std::string& args : std::vector<std::string>{
           "swipe " + doc + " -o " + (dir / "x.mp3").string(), "swipe " + doc + " --speed -3 -o " + wav,
           "swipe " + doc + " --output loud -o " + wav, "swipe " + doc + " --trace " + (dir / "none.csv").string() + " -o " + wav,
           "swipe " + doc + " -o " + wav + " --plot " + (dir / "p.gif").string(), "play " + doc + " --backend floppy",
           "play " + doc + " --backend serial:" + (dir / "no-such-tty").string(),
           "controller --serial " + (dir / "no-such-tty").string()}) {
    const CliRun r = run(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  }
  EXPECT_FALSE(fs::exists(wav));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), {}), 1);  // only the document
}
