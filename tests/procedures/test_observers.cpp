// Simulated observers: psychometric functions at known points, response
// rates with stated tolerances, determinism per (seed, trial), the matcher's
// choices, slider matches and confidence, the rater, and the perceptual
// target of a reference through the encoder.
#include <gtest/gtest.h>

#include <cmath>

#include "../support/expect.hpp"

#include "texel/error.hpp"
#include "texel/experiment/observer.hpp"

using namespace texel::experiment;

TEST(Psychometric, KnownPoints) {
  PsychometricConfig c;  // Weibull α = 1, β = 3
  c.guess = guess_oddity3;
  c.lapse = 0.02;
  const PsychometricObserver w(c);
  EXPECT_NEAR(w.p_correct(1.0), 1.0 / 3 + (1 - 1.0 / 3 - 0.02) * (1 - std::exp(-1.0)), 1e-12);
  EXPECT_NEAR(w.p_correct(0.0), 1.0 / 3, 1e-12);
  EXPECT_NEAR(w.p_correct(1e6), 0.98, 1e-12);
  for (double p : {0.4, 0.6, 0.794, 0.95}) EXPECT_NEAR(w.p_correct(w.inverse(p)), p, 1e-12);

  c = {};
  c.shape = PsychometricShape::logistic;
  c.threshold = 2;
  c.slope = 4;
  c.guess = guess_2afc;
  const PsychometricObserver l(c);
  EXPECT_NEAR(l.p_correct(2), 0.75, 1e-12);
  for (double p : {0.6, 0.794}) EXPECT_NEAR(l.p_correct(l.inverse(p)), p, 1e-12);
  c.log_x = true;
  c.threshold = 10;
  const PsychometricObserver lx(c);
  EXPECT_NEAR(lx.p_correct(10), 0.75, 1e-12);
  EXPECT_NEAR(lx.p_correct(lx.inverse(0.9)), 0.9, 1e-12);
  EXPECT_THROW((void)lx.inverse(0.4), texel::InvalidArgument);  // below the guess rate
}

// 20 000 Bernoulli draws at p = 0.794: SE = 0.0029; tolerance 4 SE.
TEST(Psychometric, ResponseRateMatchesPAndIsAFunctionOfSeedAndTrial) {
  PsychometricConfig c;
  c.seed = 77;
  const PsychometricObserver o(c);
  const double x = o.inverse(0.794);
  int correct = 0;
  for (std::uint64_t t = 0; t < 20000; ++t) correct += o.respond(x, t);
  EXPECT_NEAR(correct / 20000.0, 0.794, 4 * std::sqrt(0.794 * 0.206 / 20000));
  // Any trial can be re-drawn alone, in any order.
  EXPECT_EQ(o.respond(x, 12345), PsychometricObserver(c).respond(x, 12345));
  int differ = 0;
  c.seed = 78;
  const PsychometricObserver other(c);
  for (std::uint64_t t = 0; t < 200; ++t) differ += o.respond_with(0.5, t) != other.respond_with(0.5, t);
  EXPECT_GT(differ, 50);
}

TEST(Psychometric, BadConfigNamesTheField) {
  auto message = [](PsychometricConfig c) {
    return texel::test_support::message_of<texel::InvalidArgument>([&] { PsychometricObserver o(c); });
  };
  EXPECT_NE(message({.threshold = 0}).find("threshold"), std::string::npos);
  EXPECT_NE(message({.slope = -1}).find("slope"), std::string::npos);
  EXPECT_NE(message({.guess = 1}).find("guess"), std::string::npos);
  EXPECT_NE(message({.guess = 0.5, .lapse = 0.5}).find("lapse"), std::string::npos);
  EXPECT_EQ(parse_psychometric_shape("logistic"), PsychometricShape::logistic);
  EXPECT_THROW((void)parse_psychometric_shape("probit"), texel::InvalidArgument);
}

TEST(Matcher, ChoosesTheCloserPointOrUnsure) {
  MatcherConfig c;
  c.target = {0, -10};
  c.noise_db = 0;
  c.unsure_band_db = 1;
  const Matcher m(c);
  EXPECT_EQ(m.choose({{1, -10}, {5, -10}, 0, 0}, 0), MatchChoice::a);
  EXPECT_EQ(m.choose({{0, -20}, {0, -12}, 0, 0}, 1), MatchChoice::b);
  EXPECT_EQ(m.choose({{2, -10}, {-2.5, -10}, 0, 0}, 2), MatchChoice::unsure);
  // Axis weighting: Irregularity counts half.
  c.irregularity_weight = 0.5;
  const Matcher w(c);
  EXPECT_EQ(w.choose({{0, -16}, {4, -10}, 0, 0}, 0), MatchChoice::a);  // 3 vs 4
}

// With noise σ per distance, the choice rate for distances 2 and 4 dB apart
// is Φ((2 − band)/(σ√2)) = Φ(1/2.828) = 0.638 for σ = 2, band 1.
TEST(Matcher, NoisyChoiceRateFollowsTheModel) {
  MatcherConfig c;
  c.target = {0, 0};
  c.seed = 5;
  const Matcher m(c);
  const MatchQuestion q{{2, 0}, {4, 0}, 0, 0};
  int a = 0, unsure = 0;
  const int n = 20000;
  for (std::uint64_t t = 0; t < static_cast<std::uint64_t>(n); ++t) {
    const MatchChoice ch = m.choose(q, t);
    a += ch == MatchChoice::a;
    unsure += ch == MatchChoice::unsure;
  }
  const double pa = 0.5 * std::erfc(-(1 / (2 * std::sqrt(2.0))) / std::sqrt(2.0));
  EXPECT_NEAR(a / double(n), pa, 4 * std::sqrt(pa * (1 - pa) / n));
  EXPECT_GT(unsure, 0);
  EXPECT_EQ(m.choose(q, 17), Matcher(c).choose(q, 17));
}

TEST(Matcher, AdjustIsClampedAndConfidenceFallsWithNoise) {
  MatcherConfig c;
  c.target = {19, 4};
  c.noise_db = 3;
  const Matcher m(c);
  double sp = 0;
  int low_conf_far = 0, n_far = 0;
  for (std::uint64_t t = 0; t < 2000; ++t) {
    const MatchPoint p = m.adjust(t);
    EXPECT_LE(p.pitch_db, 19.7);
    EXPECT_LE(p.irregularity_db, 5);
    const int conf = m.confidence(t);
    EXPECT_GE(conf, 1);
    EXPECT_LE(conf, 5);
    sp += p.pitch_db;
    if (std::hypot(p.pitch_db - 19, p.irregularity_db - 4) > 6) {
      ++n_far;
      low_conf_far += conf <= 2;
    }
  }
  EXPECT_GT(n_far, 0);
  EXPECT_EQ(low_conf_far, n_far);  // far from the target (> 2σ) always means confidence 1 or 2
  MatcherConfig bad;
  bad.noise_db = -1;
  EXPECT_THROW(Matcher{bad}, texel::InvalidArgument);
}

TEST(Rater, RatingsAreOnTheScaleAndFallWithDistance) {
  RaterConfig c;
  c.scale_min = 0;
  c.scale_max = 10;
  const Rater r(c);
  EXPECT_NEAR(r.expected(0), 10, 1e-12);
  EXPECT_LT(r.expected(20), r.expected(5));
  double near_sum = 0, far_sum = 0;
  for (std::uint64_t t = 0; t < 500; ++t) {
    const int a = r.rate(1, t), b = r.rate(25, t);
    EXPECT_GE(a, 0);
    EXPECT_LE(a, 10);
    EXPECT_GE(b, 0);
    near_sum += a;
    far_sum += b;
  }
  EXPECT_GT(near_sum, far_sum + 500 * 5);
  EXPECT_THROW(Rater(RaterConfig{.scale_min = 5, .scale_max = 1}), texel::InvalidArgument);
}

TEST(PerceptualTarget, SimulatedObserversFeelWithTheEncodersDefaultModel) {
  // 2sin through the tpad: version 2 of the perceptual model puts it at
  // 5.41 dB (people: 4.8 dB), version 1 at 4.49 dB (docs/encoder.md §2).
  EXPECT_NEAR(perceptual_target("2sin").pitch_db, 5.41, 0.005);
}

TEST(PerceptualTarget, ReferenceThroughTheEncoderLiesInTheDeviceBox) {
  const MatchPoint p = perceptual_target("4sin");
  EXPECT_TRUE(std::isfinite(p.pitch_db));
  EXPECT_TRUE(std::isfinite(p.irregularity_db));
  EXPECT_GE(p.pitch_db, -20 - 1e-9);
  EXPECT_LE(p.pitch_db, 19.7 + 1e-9);
  EXPECT_EQ(perceptual_target("4sin"), p);  // deterministic, nothing cached
  EXPECT_THROW((void)perceptual_target("no-such-reference"), texel::InvalidArgument);
  EXPECT_THROW((void)perceptual_target("4sin", "no-such-device"), texel::InvalidArgument);
}
