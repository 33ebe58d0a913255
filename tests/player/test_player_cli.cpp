// Acceptance checks of issue #5 on the built CLI: `texel swipe` writes a
// 2-second WAV whose spectrum peaks at Central Pitch × speed; `texel play
// --backend null` runs and reports blocks and the worst block time; bad
// input exits 2 with one line and writes nothing.
#include <gtest/gtest.h>

#include "../support/cli_run.hpp"
#include "../support/controller_process.hpp"
#include "../support/temp_dir.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "texel/io.hpp"
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
    doc = (dir / "demo.texel.json").string();
    ASSERT_EQ(run("render --seed 1 -o " + doc).status, 0);
  }
  texel::test_support::TempDir tmp{"texel-player-cli"};
  const fs::path& dir = tmp.path;
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

// Issue #36: a 7.5 dB texture (5.62 cpm) at 100 mm/s is 562 Hz, above a
// 1 kHz drive's Nyquist frequency. With the band limit (the default) it is
// faded to its mean, not folded down to about 440 Hz; --band-limit off
// gives the old, aliased stream.
TEST_F(Cli, SwipeAt1kHzFadesWhatTheDriveCannotCarry) {
  const std::string narrow = (dir / "narrow.texel.json").string();
  ASSERT_EQ(run("render --seed 1 --central-pitch 7.5 --irregularity -5 -o " + narrow).status, 0);
  const auto ac_rms = [&](const std::string& extra) {
    const std::string wav = (dir / "k.wav").string();
    const CliRun r = run("swipe " + narrow + " --speed 100 --duration 0.5 --rate 1000 --output amplitude " + extra +
                         " --wav-format float -o " + wav);
    EXPECT_EQ(r.status, 0) << r.out;
    const texel::Recording rec = texel::read_recording(wav);
    double mean = 0, sq = 0;
    const std::size_t from = 50;
    for (std::size_t i = from; i < rec.samples.size(); ++i) mean += rec.samples[i];
    mean /= static_cast<double>(rec.samples.size() - from);
    for (std::size_t i = from; i < rec.samples.size(); ++i) sq += (rec.samples[i] - mean) * (rec.samples[i] - mean);
    return std::sqrt(sq / static_cast<double>(rec.samples.size() - from));
  };
  const double off = ac_rms("--band-limit off"), on = ac_rms("");
  EXPECT_GT(off, 0.2);  // the aliased stream at full strength (0.5·sin: RMS 0.35)
  EXPECT_LT(on, 0.03);  // faded: every texel lies above 0.45 kHz (5.62 cpm ± 0.32)
  const CliRun bad = run("swipe " + narrow + " --band-limit maybe -o " + (dir / "b.wav").string());
  EXPECT_EQ(bad.status, 2) << bad.out;
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

// Issue #26: `texel swipe` along 2-D paths feels the 1-D texture at the same
// speed (spectrum peak at Central Pitch × speed on a line at an angle, a
// circle and a zigzag); a 2-D trace CSV, a coarse raster (.npy) and a bitmap
// play; `texel play` takes a 2-D path; bad 2-D input exits 2.
TEST_F(Cli, SwipeAlong2dPathsPeaksAtCentralPitchTimesSpeed) {
  for (const std::string path : {"--path line --angle 30", "--path circle --radius 10", "--path zigzag --leg 5"}) {
    const std::string wav = (dir / "p.wav").string();
    const CliRun r = run("swipe " + doc + " " + path + " --speed 100 --duration 1 -o " + wav);
    ASSERT_EQ(r.status, 0) << path << "\n" << r.out;
    const texel::Recording rec = texel::read_recording(wav);
    const std::vector<float> s(rec.samples.begin(), rec.samples.end());
    EXPECT_NEAR(texel::signal_spectrum(s, rec.rate.value()).peak_hz(1.0), 1000.0, 30.0) << path;
  }
}

TEST_F(Cli, Swipe2dTraceRasterAndBitmap) {
  // A 2 × 3 raster as .npy (float64, C order): rows along y.
  const std::string npy = (dir / "r.npy").string();
  {
    std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }";
    header.append(128 - 10 - header.size() - 1, ' ');  // NEP 1: data aligned to 64 bytes
    header.push_back('\n');
    std::string bytes("\x93NUMPY\x01\x00", 8);
    bytes.push_back(static_cast<char>(header.size()));
    bytes.push_back('\0');
    bytes += header;
    const double v[6] = {0.2, 0.4, 0.6, 0.8, 1.0, 0.0};
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
    std::FILE* f = std::fopen(npy.c_str(), "wb");
    ASSERT_TRUE(f);
    std::fwrite(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
  }
  const std::string trace = (dir / "t.csv").string();
  {
    std::FILE* f = std::fopen(trace.c_str(), "w");
    ASSERT_TRUE(f);
    std::fputs("time_s,x_mm,y_mm,touch\n", f);
    for (int i = 0; i <= 100; ++i) std::fprintf(f, "%g,%g,%g,1\n", i * 1e-3, 0.5 + 0.01 * i, 0.5);
    std::fclose(f);
  }
  const std::string csv = (dir / "o.csv").string();
  CliRun r = run("swipe " + doc + " --trace-2d " + trace + " --bitmap " + npy + " --raster-pitch 1 --output amplitude -o " + csv);
  ASSERT_EQ(r.status, 0) << r.out;
  std::FILE* in = std::fopen(csv.c_str(), "r");
  ASSERT_TRUE(in);
  char first[64] = {};
  ASSERT_TRUE(std::fgets(first, sizeof first, in));
  std::fclose(in);
  EXPECT_STREQ(first, "time_s,x_mm,y_mm,output\n");
  r = run("swipe " + doc + " --trace-2d " + trace + " --coarse-raster " + npy +
          " --raster-pitch 1 --coarse-strength 1 --json -o " + (dir / "o.wav").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("\"surface\": \"2d\""), std::string::npos) << r.out;
  r = run("play " + doc + " --path circle --radius 5 --backend null --duration 0.3 --block 16");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("2-D surface"), std::string::npos) << r.out;
  fs::remove(csv);
  fs::remove(dir / "o.wav");
  for (const std::string& args : std::vector<std::string>{
           "swipe " + doc + " --path spiral -o " + csv, "swipe " + doc + " --path circle --radius 0 -o " + csv,
           "swipe " + doc + " --bitmap " + trace + " -o " + csv,
           "swipe " + doc + " --coarse-raster " + npy + " --bitmap " + npy + " -o " + csv,
           "swipe " + doc + " --path line --trace-2d " + trace + " -o " + csv,
           "play " + doc + " --path line --backend serial:" + (dir / "tty").string()}) {
    const CliRun bad = run(args);
    EXPECT_EQ(bad.status, 2) << args << "\n" << bad.out;
    EXPECT_EQ(std::count(bad.out.begin(), bad.out.end(), '\n'), 1) << bad.out;
  }
  EXPECT_FALSE(fs::exists(csv));
}

// A version-4 2-D document plays directly: its region's texture laid along
// the path (felt frequency = Central Pitch × speed at any angle), and a
// surface of several regions is refused with one line.
TEST_F(Cli, SwipeOfATwoDimensionalDocumentPeaksAtCentralPitchTimesSpeedAlongAnyAngle) {
  const std::string doc2d = (dir / "surface.texel.json").string();
  texel::write_file_atomic(doc2d, R"({"format": "texel-document", "version": 4, "device": "tablet-2d",
    "surface2d": {"regions": [{"x_mm": 0, "y_mm": 0, "field": "spectral",
      "texture": {"kind": "texel", "central_pitch_db": 3, "irregularity_db": -5, "texel_length_mm": 1, "seed": 5}}]}})");
  for (const char* angle : {"0", "37", "90"}) {
    const std::string wav = (dir / (std::string("a") + angle + ".wav")).string();
    const CliRun r =
        run("swipe " + doc2d + " --path line --angle " + angle + " --start 20 --start-y 20 --speed 100 --duration 1 -o " + wav);
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("(2-D)"), std::string::npos) << r.out;
    const texel::Recording rec = texel::read_recording(wav);
    const std::vector<float> s(rec.samples.begin(), rec.samples.end());
    // 3 dB = 1.995 cycles/mm; at 100 mm/s: 199.5 Hz.
    EXPECT_NEAR(texel::signal_spectrum(s, rec.rate.value()).peak_hz(1.0), 199.5, 10.0) << "angle " << angle;
  }
  // `texel info` describes a 2-D document: its bitmap grid and its regions.
  const CliRun info = run("info " + doc2d + " --json");
  ASSERT_EQ(info.status, 0) << info.out;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["version"], 4);
  EXPECT_GT(j["bitmap"]["width_px"].get<int>(), 0);
  ASSERT_EQ(j["regions"].size(), 1u);
  EXPECT_EQ(j["regions"][0]["field"], "spectral");
  EXPECT_EQ(j["regions"][0]["central_pitch_db"], 3.0);
  const std::string two = (dir / "two.texel.json").string();
  texel::write_file_atomic(two, R"({"format": "texel-document", "version": 4, "device": "tablet-2d",
    "surface2d": {"regions": [
      {"x_mm": 0, "y_mm": 0, "width_mm": 50, "texture": {"kind": "texel", "central_pitch_db": 3, "irregularity_db": -5, "texel_length_mm": 1, "seed": 5}},
      {"x_mm": 50, "y_mm": 0, "texture": {"kind": "texel", "central_pitch_db": 6, "irregularity_db": -5, "texel_length_mm": 1, "seed": 6}}]}})");
  const std::string out = (dir / "two.wav").string();
  const CliRun bad = run("swipe " + two + " --path circle -o " + out);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.out.find("one region"), std::string::npos) << bad.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, PlayTakesTheFingerLiveFromADisplayThatReportsIt) {
  // The reference controller with a simulated 2-D sensor (a finger circling
  // over a disc-shaped coarse feature) reports the finger; `texel play`
  // computes the 2-D drive and streams it back over the same link.
  const std::string doc2d = (dir / "disc.texel.json").string();
  texel::write_file_atomic(doc2d, R"({"format": "texel-document", "version": 4, "device": "tablet-2d",
    "surface2d": {"regions": [{"x_mm": 0, "y_mm": 0, "field": "spectral",
      "texture": {"kind": "texel", "central_pitch_db": 6, "irregularity_db": 3, "texel_length_mm": 0.5, "seed": 3,
                  "coarse_strength": 0.7, "fine_strength": 0.5},
      "coarse2d": {"kind": "disc", "x_mm": 60, "y_mm": 40, "radius_mm": 10, "edge_mm": 1, "inside": 1, "outside": 0.2}}]}})");
  texel::test_support::ControllerProcess display(
      TEXEL_CLI, {"--sensor", "circle", "--sensor-start", "60,40", "--sensor-radius", "15", "--duration", "20", "--quiet"});
  ASSERT_FALSE(display.pty().empty());
  const std::string port = "serial:" + display.pty();
  const CliRun r = run("play " + doc2d + " --backend " + port + " --stream drive --finger " + port + " --duration 1 --json");
  const std::string counters = display.stop();
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  EXPECT_EQ(j["surface"], "2d");
  EXPECT_GT(j["finger_reports"].get<int>(), 100);  // about 1,000 on an idle host
  EXPECT_EQ(j["finger_reports_lost"].get<int>(), 0);
  EXPECT_EQ(j["finger_reports_dropped"].get<int>(), 0);
  EXPECT_NE(counters.find("bad 0, nacks 0, link errors 0"), std::string::npos) << counters;

  // A display without a sensor: one line, exit 2.
  texel::test_support::ControllerProcess blind(TEXEL_CLI, {"--duration", "20", "--quiet"});
  const CliRun no = run("play " + doc2d + " --backend null --finger serial:" + blind.pty() + " --duration 1");
  EXPECT_EQ(no.status, 2);
  EXPECT_NE(no.out.find("no finger sensor"), std::string::npos) << no.out;
  EXPECT_EQ(std::count(no.out.begin(), no.out.end(), '\n'), 1) << no.out;
}
