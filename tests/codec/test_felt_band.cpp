// The felt band (docs/encoder.md §2, "Version 3"): what touch cannot feel
// must not move the encoder. Recordings of a texture's vibration are
// synthesised without held-out data: a Texel texture rendered on the tpad
// and swiped at 100 mm/s (the map value under the finger, 44.1 kHz, sensor
// noise 40 dB below), plus content above 1.2 kHz that a microphone or a
// tool's resonance adds (airborne broadband noise 1.2–9 kHz; a 2–4 kHz
// resonance) at 0, +10 and +20 dB relative to the tactile part. Model 3's
// estimate must not move with it (Central Pitch ≤ 0.3 dB, Irregularity
// ≤ 0.5 dB, never at a search bound); every model reports the share of the
// input above the felt band and warns when it is most of the input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "texel/codec.hpp"
#include "texel/error.hpp"

namespace {

using namespace texel;

constexpr double fs = 44100.0;   // recording rate, Hz
constexpr double speed = 100.0;  // mm/s, the model's nominal speed
constexpr double seconds = 1.0;  // the tpad's 101.76 mm at 100 mm/s
constexpr double lowest_hz = 1200.0;

std::size_t samples() { return static_cast<std::size_t>(fs * seconds); }

double rms(const std::vector<double>& y) {
  double s = 0.0;
  for (double v : y) s += v * v;
  return std::sqrt(s / static_cast<double>(y.size()));
}

/// The vibration of a Texel texture swiped at `speed`: the texture rendered
/// on the tpad's grid, read under a finger moving at `speed` (linear
/// interpolation, as `texel swipe` reads a map), zero mean, with sensor
/// noise 40 dB below it.
std::vector<double> tactile(const TexelSpec& spec) {
  const DeviceProfile d = load_device("tpad");
  const std::vector<double> map = prepare_surface(make_document(d, spec)).render();
  const double dx = d.spacing.value();
  std::vector<double> y(samples());
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double x = static_cast<double>(i) * speed / fs / dx;
    const auto k = std::min(static_cast<std::size_t>(x), map.size() - 2);
    const double t = x - static_cast<double>(k);
    y[i] = map[k] + t * (map[k + 1] - map[k]);
  }
  double mean = 0.0;
  for (double v : y) mean += v;
  mean /= static_cast<double>(y.size());
  for (double& v : y) v -= mean;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  const double noise = rms(y) * 0.01;
  for (double& v : y) v += noise * normal(rng);
  return y;
}

/// Content above 1.2 kHz, unit RMS: `airborne`, a flat broadband noise
/// 1.2–9 kHz (the sound of the contact reaching a microphone); else a
/// resonance between 2 and 4 kHz (a tool's or sensor mount's), 0.25 octave
/// wide. Sums of 300 sinusoids at random frequencies and phases.
std::vector<double> high(bool airborne, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal;
  std::vector<double> y(samples(), 0.0);
  for (int c = 0; c < 300; ++c) {
    double hz = airborne ? lowest_hz + (9000.0 - lowest_hz) * uniform(rng) : 2828.0 * std::exp2(0.25 * normal(rng));
    if (hz < lowest_hz) hz = lowest_hz;
    const double phase = 2.0 * std::numbers::pi * uniform(rng);
    const double w = 2.0 * std::numbers::pi * hz / fs;
    for (std::size_t i = 0; i < y.size(); ++i) y[i] += std::sin(w * static_cast<double>(i) + phase);
  }
  const double r = rms(y);
  for (double& v : y) v /= r;
  return y;
}

/// tactile + high at `ratio_db` (RMS, relative to the tactile part), read as
/// the signal loader reads a recording: a = 0.5 + 0.5·y/max|y|.
codec::Signal recording(const std::vector<double>& t, const std::vector<double>* h, double ratio_db) {
  std::vector<double> y = t;
  if (h) {
    const double g = rms(t) * std::pow(10.0, ratio_db / 20.0);
    for (std::size_t i = 0; i < y.size(); ++i) y[i] += g * (*h)[i];
  }
  double peak = 0.0;
  for (double v : y) peak = std::max(peak, std::fabs(v));
  codec::Signal s;
  s.amplitude.resize(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) s.amplitude[i] = 0.5 + 0.5 * y[i] / peak;
  s.spacing = Millimetres(speed / fs);
  s.recording = true;
  s.description = "synthesised recording";
  return s;
}

codec::EncoderConfig config(int version, codec::EncoderConfig::Target target = codec::EncoderConfig::Target::automatic) {
  codec::EncoderConfig c;
  c.model = codec::model_defaults(version);
  c.model.swipe_speed = MmPerSecond(speed);
  c.target = target;
  return c;
}

struct Texture {
  const char* name;
  double p_db, i_db;
};

class FeltBand : public ::testing::TestWithParam<Texture> {};

TEST_P(FeltBand, ContentAboveTheFeltBandDoesNotMoveModelThree) {
  const Texture tex = GetParam();
  TexelSpec spec;
  spec.central_pitch = Decibels(tex.p_db);
  spec.irregularity = Decibels(tex.i_db);
  spec.seed = 5;
  const std::vector<double> t = tactile(spec);
  const std::vector<double> airborne = high(true, 21), resonance = high(false, 22);
  using Target = codec::EncoderConfig::Target;
  double as_recorded[2] = {};
  for (const Target target : {Target::centroid, Target::felt}) {
    const codec::EncodeResult clean = codec::encode(recording(t, nullptr, 0.0), config(3, target));
    as_recorded[target == Target::felt] = clean.spec.central_pitch.value();
    const double p0 = clean.spec.central_pitch.value(), i0 = clean.spec.irregularity.value();
    std::printf("%s, model 3, %s target, as recorded: P %.2f dB, I %.2f dB, %.1f %% beyond the felt band%s, F %.2f\n", tex.name,
                std::string(codec::to_string(target)).c_str(), p0, i0, 100.0 * clean.beyond_felt_band,
                clean.coarse ? ", two-scale" : "", clean.spec.fine_strength);
    EXPECT_FALSE(clean.at_bound.any());
    EXPECT_LT(clean.beyond_felt_band, 0.05);  // the texture itself is felt
    EXPECT_TRUE(clean.warnings.empty());
    for (const bool air : {true, false})
      for (const double ratio : {0.0, 10.0, 20.0}) {
        const codec::EncodeResult r = codec::encode(recording(t, air ? &airborne : &resonance, ratio), config(3, target));
        const double p = r.spec.central_pitch.value(), i = r.spec.irregularity.value();
        std::printf("  + %s %+.0f dB: P %.2f dB (%+.2f), I %.2f dB (%+.2f), %.1f %% beyond%s%s, F %.2f\n",
                    air ? "airborne 1.2-9 kHz" : "resonance 2-4 kHz", ratio, p, p - p0, i, i - i0, 100.0 * r.beyond_felt_band,
                    r.warnings.empty() ? "" : ", warned", r.coarse ? ", two-scale" : "", r.spec.fine_strength);
        SCOPED_TRACE(std::string(air ? "airborne " : "resonance ") + std::to_string(ratio) + " dB, " +
                     std::string(codec::to_string(target)));
        EXPECT_NEAR(p, p0, 0.3);  // the tolerances
        EXPECT_NEAR(i, i0, 0.5);
        EXPECT_FALSE(r.at_bound.any());
        // Reported whatever its level; flagged once it is most of the input.
        const double expected = std::pow(10.0, ratio / 10.0) / (1.0 + std::pow(10.0, ratio / 10.0));
        EXPECT_NEAR(r.beyond_felt_band, expected, 0.05);
        EXPECT_EQ(r.warnings.size(), r.beyond_felt_band > 0.5 ? 1u : 0u);
        if (ratio >= 10.0) {
          EXPECT_EQ(r.warnings.size(), 1u);
        }
      }
  }
  // On the felt band the two targets see the same content: for one band
  // (no harmonic ridges) people's pitch and the centroid agree closely.
  EXPECT_NEAR(as_recorded[1], as_recorded[0], 0.3);
}

INSTANTIATE_TEST_SUITE_P(Synthesised, FeltBand,
                         ::testing::Values(Texture{"P 5 dB, I -5 dB", 5.0, -5.0}, Texture{"P 2 dB, I 0 dB", 2.0, 0.0}),
                         [](const auto& info) {
                           return info.index == 0 ? std::string("narrow_316Hz") : std::string("wide_158Hz");
                         });

// The failure model 3 removes, shown on the same inputs: model 2 weighs the
// airborne content, and its estimate moves by more than a JND (the issue's
// real recordings: Central Pitch up by about 10 dB, Irregularity to the top
// of the box). Model 2 keeps its results (docs/encoder.md §2).
TEST(FeltBand, ModelTwoIsMovedByWhatIsNotFelt) {
  TexelSpec spec;
  spec.central_pitch = Decibels(5.0);
  spec.irregularity = Decibels(-5.0);
  spec.seed = 5;
  const std::vector<double> t = tactile(spec);
  const std::vector<double> airborne = high(true, 21);
  const codec::EncodeResult clean = codec::encode(recording(t, nullptr, 0.0), config(2));
  const codec::EncodeResult noisy = codec::encode(recording(t, &airborne, 20.0), config(2));
  std::printf("model 2: as recorded P %.2f / I %.2f dB; + airborne +20 dB: P %.2f / I %.2f dB\n",
              clean.spec.central_pitch.value(), clean.spec.irregularity.value(), noisy.spec.central_pitch.value(),
              noisy.spec.irregularity.value());
  EXPECT_GT(noisy.spec.central_pitch.value() - clean.spec.central_pitch.value(), 1.0);
  // Every model reports the share and warns, naming the model that weighs it.
  ASSERT_EQ(noisy.warnings.size(), 1u);
  EXPECT_NE(noisy.warnings[0].find("model 2 weighs it"), std::string::npos) << noisy.warnings[0];
  EXPECT_NE(codec::to_json(noisy).find("\"power_beyond\""), std::string::npos);
}

// The threshold curve of version 3 (docs/encoder.md §2, "Version 3").
TEST(FeltBand, VersionThreeThresholdHasNoFloorAboveThePacinianRangeAndNothingBeyondTheBand) {
  const Hertz top(1000.0);
  EXPECT_EQ(codec::felt_threshold_db(Hertz(250.0), top), 0.0);
  EXPECT_NEAR(codec::felt_threshold_db(Hertz(125.0), top), 12.0, 1e-9);
  EXPECT_EQ(codec::felt_threshold_db(Hertz(10.0), top), 30.0);            // the non-Pacinian floor stays
  EXPECT_NEAR(codec::felt_threshold_db(Hertz(1000.0), top), 24.0, 1e-9);  // version 2 capped this side at 30 dB (at 1.41 kHz)
  EXPECT_EQ(codec::threshold_db(Hertz(4000.0)), 30.0);
  EXPECT_EQ(codec::felt_threshold_db(Hertz(1000.5), top), std::numeric_limits<double>::infinity());
  // Averaged over the strokes' speeds (lognormal, SD 0.6 of ln speed): what
  // lies just above the top at the median speed is felt on the slower
  // strokes (4sin's 1.1 kHz, the 2 kHz band-pass references), ever more
  // weakly, and nothing beyond the slowest stroke's reach.
  const codec::PerceptualModel m3 = codec::model_defaults(3);
  EXPECT_EQ(m3.speed_spread, 0.6);
  const double t1100 = codec::felt_weight_threshold_db(Hertz(1100.0), m3);
  const double t2000 = codec::felt_weight_threshold_db(Hertz(2000.0), m3);
  const double t4000 = codec::felt_weight_threshold_db(Hertz(4000.0), m3);
  EXPECT_TRUE(std::isfinite(t1100) && std::isfinite(t4000));
  EXPECT_LT(codec::felt_weight_threshold_db(Hertz(250.0), m3), t1100);
  EXPECT_LT(t1100, t2000);
  EXPECT_LT(t2000 + 10.0, t4000);
  const double reach_hz = codec::felt_band_reach_cpm(m3).value() * speed;
  EXPECT_NEAR(reach_hz, 1000.0 * std::exp(3.0 * 0.6), 1e-6);
  EXPECT_EQ(codec::felt_weight_threshold_db(Hertz(reach_hz * 1.01), m3), std::numeric_limits<double>::infinity());
  // A percept does not see what lies beyond the reach, at any level: a
  // 200 Hz line alone, and with an 8 kHz line 40 dB stronger, feel the same.
  const double dx = speed / fs;
  std::vector<double> a(44100), b(44100);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = static_cast<double>(i) * dx;
    a[i] = 0.01 * std::sin(2.0 * std::numbers::pi * 2.0 * x);
    b[i] = a[i] + 1.0 * std::sin(2.0 * std::numbers::pi * 80.0 * x);
  }
  const codec::Percept qa = codec::perceive(a, dx, m3), qb = codec::perceive(b, dx, m3);
  EXPECT_NEAR(qb.pitch_db, qa.pitch_db, 1e-6);
  EXPECT_NEAR(qb.noisiness_db, qa.noisiness_db, 1e-6);
  EXPECT_NEAR(qb.mean_db, qa.mean_db, 1e-6);  // the physical tie-break too
  // Model 2 is pulled to the 8 kHz line.
  const codec::PerceptualModel m2 = codec::model_defaults(2);
  EXPECT_GT(codec::perceive(b, dx, m2).pitch_db, codec::perceive(a, dx, m2).pitch_db + 5.0);
  // Nothing in the felt band: the whole spectrum decides (the fit stays defined).
  std::vector<double> c(44100);
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = std::sin(2.0 * std::numbers::pi * 80.0 * static_cast<double>(i) * dx);
  EXPECT_NEAR(codec::perceive(c, dx, m3).pitch_db, 10.0 * std::log10(80.0), 0.05);
  codec::PerceptualModel bad = m3;
  bad.felt_band_top = Hertz(0.0);
  EXPECT_THROW((void)codec::perceive(a, dx, bad), InvalidArgument);
  bad = m3;
  bad.speed_spread = 2.0;
  EXPECT_THROW((void)codec::perceive(a, dx, bad), InvalidArgument);
}

}  // namespace
