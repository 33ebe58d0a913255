// `texel swipe` on a multi-channel document (issue #40): N-channel .wav and
// .npy [frames, channels], the same bytes for the same seed, --playback /
// --channel, and refusals that exit 2 leaving no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "../support/cli_run.hpp"
#include "../support/temp_dir.hpp"
#include "texel/io.hpp"

namespace {

using texel::test_support::CliRun;
CliRun run(const std::string& args) { return texel::test_support::run_cli(TEXEL_CLI, args); }

const std::string golden_doc = std::string(TEXEL_TEST_GOLDEN_DIR) + "/references/v6-simultaneous-4ch.texel.json";

std::uint16_t u16_at(const std::string& b, std::size_t at) {
  return static_cast<std::uint16_t>(static_cast<unsigned char>(b[at]) | (static_cast<unsigned char>(b[at + 1]) << 8));
}

TEST(MultichannelCli, SwipeWritesFourChannelWavAndNpy) {
  texel::test_support::TempDir tmp{"texel-mc-cli"};
  const CliRun w = run("swipe " + golden_doc + " --speed 50 --duration 0.2 --wav-format float -o " + tmp.at("s.wav"));
  ASSERT_EQ(w.status, 0) << w.out;
  EXPECT_NE(w.out.find("9600 samples × 4 channels (simultaneous)"), std::string::npos) << w.out;
  const CliRun n = run("swipe " + golden_doc + " --speed 50 --duration 0.2 -o " + tmp.at("s.npy"));
  ASSERT_EQ(n.status, 0) << n.out;
  const texel::NpyArray a = texel::parse_npy_array(texel::read_file(tmp.at("s.npy")), "s.npy", 2);
  ASSERT_EQ(a.rows, 9600u);
  ASSERT_EQ(a.columns, 4u);
  // The WAV holds the same frames, interleaved (float32, the RIFF fmt chunk's channel count).
  const std::string wav = texel::read_file(tmp.at("s.wav"));
  ASSERT_EQ(wav.compare(12, 4, "fmt "), 0);
  EXPECT_EQ(u16_at(wav, 22), 4u);
  const std::size_t data = wav.find("data");
  ASSERT_NE(data, std::string::npos);
  ASSERT_GE(wav.size(), data + 8 + 9600 * 4 * 4);
  double largest = 0.0;
  std::size_t channels_playing = 0;
  for (std::size_t c = 0; c < 4; ++c) {
    double peak = 0.0;
    for (std::size_t i = 0; i < 9600; ++i) {
      float v;
      std::memcpy(&v, wav.data() + data + 8 + (i * 4 + c) * 4, 4);
      largest = std::max(largest, std::fabs(static_cast<double>(v) - a.values[i * 4 + c]));
      peak = std::max(peak, std::fabs(a.values[i * 4 + c]));
    }
    channels_playing += peak > 1e-3;
  }
  EXPECT_LT(largest, 1e-6);
  EXPECT_EQ(channels_playing, 4u);
  // The same document and seed: the same bytes.
  ASSERT_EQ(run("swipe " + golden_doc + " --speed 50 --duration 0.2 -o " + tmp.at("again.npy")).status, 0);
  EXPECT_EQ(texel::read_file(tmp.at("again.npy")), texel::read_file(tmp.at("s.npy")));
}

TEST(MultichannelCli, SequentialOnOneChannelLeavesTheOthersAtRest) {
  texel::test_support::TempDir tmp{"texel-mc-cli"};
  const CliRun r =
      run("swipe " + golden_doc + " --playback sequential --channel 2 --speed 50 --duration 0.2 -o " + tmp.at("s.npy"));
  ASSERT_EQ(r.status, 0) << r.out;
  const texel::NpyArray a = texel::parse_npy_array(texel::read_file(tmp.at("s.npy")), "s.npy", 2);
  ASSERT_EQ(a.columns, 4u);
  for (std::size_t c = 0; c < 4; ++c) {
    double peak = 0.0;
    for (std::size_t i = 0; i < a.rows; ++i) peak = std::max(peak, std::fabs(a.values[i * 4 + c]));
    if (c == 2)
      EXPECT_GT(peak, 1e-3);
    else
      EXPECT_EQ(peak, 0.0) << "channel " << c;
  }
}

TEST(MultichannelCli, RenderWritesOneMapPerChannel) {
  texel::test_support::TempDir tmp{"texel-mc-cli"};
  const CliRun r = run("render " + golden_doc + " -o " + tmp.at("m.npy"));
  ASSERT_EQ(r.status, 0) << r.out;
  const texel::NpyArray a = texel::parse_npy_array(texel::read_file(tmp.at("m.npy")), "m.npy", 2);
  ASSERT_EQ(a.rows, 2000u);
  ASSERT_EQ(a.columns, 4u);
  // The bytes the golden digest holds (texel-golden's .f64 is the same array without the header).
  const std::string bytes = texel::read_file(tmp.at("m.npy"));
  ASSERT_EQ(run("render " + golden_doc + " -o " + tmp.at("m2.npy")).status, 0);
  EXPECT_EQ(texel::read_file(tmp.at("m2.npy")), bytes);
  std::size_t same = 0;
  for (std::size_t i = 0; i < a.rows; ++i) same += a.values[i * 4] == a.values[i * 4 + 1];
  EXPECT_LT(same, a.rows / 10) << "channels 0 and 1 are one map";
  const CliRun bin = run("render " + golden_doc + " -o " + tmp.at("m.bin"));
  EXPECT_EQ(bin.status, 2);
  EXPECT_NE(bin.out.find("a simultaneous document has one map per channel"), std::string::npos) << bin.out;
  EXPECT_FALSE(std::filesystem::exists(tmp.at("m.bin")));
}

TEST(MultichannelCli, RefusalsExit2AndLeaveNoOutput) {
  texel::test_support::TempDir tmp{"texel-mc-cli"};
  const auto refused = [&](const std::string& args, const std::string& message) {
    const CliRun r = run("swipe " + golden_doc + " " + args);
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << r.out;
    EXPECT_TRUE(tmp.listing().empty()) << args;
  };
  refused("--playback sequential --channel 4 -o " + tmp.at("s.wav"), "playback.channel is 4; allowed: 0 … 3");
  refused("--channel 1 -o " + tmp.at("s.wav"), "allowed only with mode sequential");
  refused("--playback together -o " + tmp.at("s.wav"), "--playback is 'together'; allowed: sequential, simultaneous");
  refused("-o " + tmp.at("s.csv"), "a multi-channel swipe writes .wav or .npy");
}

}  // namespace
