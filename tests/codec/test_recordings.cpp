// Recorded inputs (docs/encoder.md, "Measured behaviour", recordings):
// vibration recordings taken at a known finger speed, synthesised here with
// known spectra, sensor noise and 60 Hz mains hum, are read as time CSV files
// through the one signal loader (`texel encode REC.csv --swipe-speed V`),
// encoded (a recording: the centroid target, docs/encoder.md §3 "Targets"),
// decoded and swiped at the same speed; the swiped vibration's log-spectral
// centroid must equal the recording's within 1 dB. The centroid here is the
// test's own measurement (Welch, 4096-sample segments), not the encoder's.
#include <gtest/gtest.h>

#include "../support/log_centroid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "texel/codec.hpp"
#include "texel/spectrum.hpp"
#include "texel/texture.hpp"

namespace {

using namespace texel;

constexpr double fs = 10000.0;  // recording rate, Hz
constexpr double seconds = 2.0;

using test_support::log_centroid_db;

/// A recording: the texture's vibration at `speed` (spatial spectrum
/// `kind`), sensor noise `noise_db` below it and 60 Hz hum `hum_db` below it
/// (RMS).
std::vector<double> recording(const std::string& kind, double speed, unsigned seed, double noise_db, double hum_db) {
  const auto n = static_cast<std::size_t>(fs * seconds);
  std::vector<double> y(n, 0.0);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  // Spatial components (cycles/mm) felt at f·speed Hz.
  auto add = [&](double cpm, double amplitude) {
    const double hz = cpm * speed, ph = phase(rng);
    if (hz >= 0.45 * fs) return;
    for (std::size_t i = 0; i < n; ++i)
      y[i] += amplitude * std::sin(2.0 * std::numbers::pi * hz * static_cast<double>(i) / fs + ph);
  };
  if (kind == "band") {  // a log-normal band around 3 cpm, 0.4 octave SD
    for (int k = 0; k < 200; ++k) add(3.0 * std::exp2(0.4 * normal(rng)), 1.0);
  } else if (kind == "ridges") {  // regular ridges at 2 cpm with two harmonics, plus fine grit
    add(2.0, 1.0), add(4.0, 0.5), add(6.0, 0.25);
    for (int k = 0; k < 100; ++k) add(2.0 * std::exp2(1.5 + 0.5 * normal(rng)), 0.05);
  } else if (kind == "grating") {  // a square-wave grating at 3 cpm: odd harmonics 1, 1/3, 1/5
    add(3.0, 1.0), add(9.0, 1.0 / 3.0), add(15.0, 0.2);
  } else if (kind == "narrow") {  // a narrow band around 8 cpm, 0.15 octave SD
    for (int k = 0; k < 100; ++k) add(8.0 * std::exp2(0.15 * normal(rng)), 1.0);
  } else if (kind == "white") {  // flat in cycles/mm, 0.5 … 20 cpm
    for (int k = 0; k < 400; ++k) add(0.5 + 19.5 * (k + 0.5) / 400.0, 1.0);
  } else {  // "rough": a wide band, 1 … 12 cpm, power ∝ 1/f
    for (int k = 0; k < 300; ++k) {
      const double cpm = std::exp(std::log(1.0) + (std::log(12.0) - std::log(1.0)) * (k + 0.5) / 300.0);
      add(cpm, 1.0);
    }
  }
  double rms = 0;
  for (double v : y) rms += v * v;
  rms = std::sqrt(rms / static_cast<double>(n));
  const double hum = rms * std::pow(10.0, -hum_db / 20.0) * std::sqrt(2.0);
  const double noise = rms * std::pow(10.0, -noise_db / 20.0);
  for (std::size_t i = 0; i < n; ++i)
    y[i] += hum * std::sin(2.0 * std::numbers::pi * 60.0 * static_cast<double>(i) / fs) + noise * normal(rng);
  return y;
}

struct Case {
  std::string kind;
  double speed;
  double noise_db = 30.0;  ///< sensor noise, dB below the texture
  double hum_db = 20.0;    ///< 60 Hz hum, dB below the texture
};

class RecordedInputs : public ::testing::TestWithParam<Case> {};

TEST_P(RecordedInputs, SwipedDecodedTextureKeepsTheRecordingsLogSpectralCentroid) {
  const Case c = GetParam();
  const std::vector<double> y = recording(c.kind, c.speed, 7, c.noise_db, c.hum_db);
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("texel_rec_" + c.kind + "_" + std::to_string(static_cast<int>(c.speed)) + ".csv");
  {
    std::ofstream f(path);
    f << "time_s,value\n";
    f.precision(17);
    for (std::size_t i = 0; i < y.size(); ++i) f << static_cast<double>(i) / fs << "," << y[i] << "\n";
  }
  SignalOptions o;
  o.swipe_speed = MmPerSecond(c.speed);
  const Signal sig = codec::load_signal(path.string(), o);
  std::filesystem::remove(path);
  codec::EncoderConfig cfg;
  cfg.model.swipe_speed = MmPerSecond(c.speed);  // as `texel encode --swipe-speed`
  const codec::Signal input = codec::encoder_signal(sig);
  ASSERT_TRUE(input.recording);
  const codec::EncodeResult r = codec::encode(input, cfg);
  EXPECT_EQ(r.target, codec::EncoderConfig::Target::centroid);  // automatic: a recording
  // Swipe the decoded texture at the recording's speed: the map value under
  // a finger moving at `speed`, sampled at the recording's rate.
  const double dx = c.speed / fs;
  const auto n = static_cast<std::int64_t>(y.size());
  const TexelTexture t(r.spec, Millimetres(static_cast<double>(n) * dx),
                       Sampling{Grid{Millimetres(0.0), Millimetres(dx), 0}, r.spec.band_max});
  std::vector<double> swiped(y.size());
  t.render(Grid{Millimetres(0.0), Millimetres(dx), n}, 0, swiped);
  const double in = log_centroid_db(y, fs), out = log_centroid_db(swiped, fs);
  std::printf(
      "%s at %g mm/s (noise %g dB, hum %g dB below): recording %.2f dB re 1 Hz, swiped decoded %.2f dB, %+.2f dB "
      "(P %.2f dB, I %.2f dB, model %d, %s)\n",
      c.kind.c_str(), c.speed, c.noise_db, c.hum_db, in, out, out - in, r.spec.central_pitch.value(), r.spec.irregularity.value(),
      r.model_version, r.coarse ? "two-scale" : "fine-only");
  EXPECT_NEAR(out, in, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Synthesised, RecordedInputs,
                         ::testing::Values(Case{"band", 50}, Case{"band", 100}, Case{"band", 200}, Case{"ridges", 50},
                                           Case{"ridges", 100}, Case{"ridges", 200}, Case{"rough", 50}, Case{"rough", 100},
                                           Case{"rough", 200}, Case{"band", 400}, Case{"grating", 75},
                                           Case{"grating", 150, 20.0, 10.0}, Case{"narrow", 30}, Case{"narrow", 300, 20.0},
                                           Case{"white", 120, 30.0, 10.0}),
                         [](const auto& info) {
                           return info.param.kind + "_" + std::to_string(static_cast<int>(info.param.speed)) +
                                  (info.param.noise_db != 30.0 || info.param.hum_db != 20.0 ? "_noisy" : "");
                         });

// A map (no time axis) keeps the felt target; a recording can ask for it.
TEST(RecordedInputs, MapsKeepTheFeltTargetAndRecordingsMayChooseIt) {
  const std::vector<double> y = recording("ridges", 100, 7, 30.0, 20.0);
  double lo = y[0], hi = y[0];
  for (double v : y) lo = std::min(lo, v), hi = std::max(hi, v);
  codec::Signal map;
  for (double v : y) map.amplitude.push_back((v - lo) / (hi - lo));
  map.spacing = Millimetres(100.0 / fs);
  codec::EncoderConfig cfg;
  cfg.model.swipe_speed = MmPerSecond(100.0);
  const codec::EncodeResult felt = codec::encode(map, cfg);
  EXPECT_EQ(felt.target, codec::EncoderConfig::Target::felt);
  EXPECT_EQ(felt.input.log_centroid_db, 0.0);  // not measured: the felt model as before
  codec::Signal rec = map;
  rec.recording = true;
  cfg.target = codec::EncoderConfig::Target::felt;
  const codec::EncodeResult chosen = codec::encode(rec, cfg);
  EXPECT_EQ(chosen.target, codec::EncoderConfig::Target::felt);
  EXPECT_EQ(chosen.bytes, felt.bytes);
  EXPECT_NE(codec::to_json(chosen).find("\"target\":\"felt\""), std::string::npos);
}

}  // namespace
