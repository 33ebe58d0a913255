// The texel-frequency distribution (docs/algorithm.md §4, §5).
//
// Statistical tolerances (stated once, used throughout): each test draws
// n = 10^5 texel frequencies with a fixed seed and requires a sample statistic
// to lie within 5 standard errors (SE) of its theoretical value. For a
// correct implementation a 5-SE excursion has probability < 6e-7; with fixed
// seeds each check is exact and repeatable, and a wrong parameterization
// (e.g. mean and median confused, dB read as amplitude form, sigma² for sigma)
// moves the statistic by tens to thousands of SE. The SEs:
//   sample mean of X:            SD(X)/√n
//   sample SD of X:              SD(X)·√((β − 1)/(4n)), β = kurtosis of X
//                                (lognormal: β = e^{4σ²} + 2e^{3σ²} + 3e^{2σ²} − 3;
//                                 normal: β = 3, so SD(X)/√(2n))
//   sample median of normal Y:   √(π/2)·SD(Y)/√n
//   a proportion p:              √(p(1 − p)/n)
// The configurations are chosen so that the band [0.01, 94.34] cpm holds all
// but < 1e-6 of the distribution (checked), so untruncated formulas apply.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "../support/expect.hpp"
#include "texel/distribution.hpp"
#include "texel/error.hpp"

using namespace texel;

namespace {

constexpr int n_draws = 100000;
constexpr double tpad_nyquist = 0.5 / 0.0053;

PitchDistributionConfig config(double p_db, double i_db, Parameterization par = Parameterization::moments) {
  PitchDistributionConfig c;
  c.central_pitch = Decibels(p_db);
  c.irregularity = Decibels(i_db);
  c.parameterization = par;
  c.band_min = CyclesPerMm(0.01);
  c.band_max = CyclesPerMm(tpad_nyquist);
  return c;
}

std::vector<double> draws(const PitchDistribution& d, std::uint64_t seed, int n = n_draws) {
  std::vector<double> f(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) f[static_cast<std::size_t>(k)] = d.draw(seed, static_cast<std::uint64_t>(k));
  return f;
}

struct Moments {
  double mean = 0.0;
  double sd = 0.0;
};
Moments moments(const std::vector<double>& x) {
  double m = 0.0;
  for (double v : x) m += v;
  m /= static_cast<double>(x.size());
  double s2 = 0.0;
  for (double v : x) s2 += (v - m) * (v - m);
  return {m, std::sqrt(s2 / static_cast<double>(x.size() - 1))};
}

double phi(double z) { return 0.5 * std::erfc(-z / std::numbers::sqrt2); }  // C library reference

std::string message_of(const std::function<void()>& f) { return test_support::message_of<InvalidArgument>(f); }

}  // namespace

TEST(PitchDistribution, MomentParametersFollowLognrnd) {
  // sigma² = ln(1 + s²/m²), mu = ln m − sigma²/2 with m = 10 cpm, s = 10^-0.5 cpm.
  const PitchDistribution d(config(10.0, -5.0));
  const double m = 10.0;
  const double s = std::pow(10.0, -0.5);
  const double sigma2 = std::log(1.0 + s * s / (m * m));
  EXPECT_NEAR(d.sigma(), std::sqrt(sigma2), 1e-14);
  EXPECT_NEAR(d.mu(), std::log(m) - sigma2 / 2.0, 1e-14);
  EXPECT_NEAR(d.band_mass(), 1.0, 1e-12);
}

TEST(PitchDistribution, LogParametersAreMedianAndDecibelSpread) {
  const PitchDistribution d(config(5.0, 2.0, Parameterization::log));
  EXPECT_NEAR(d.mu(), std::log(std::pow(10.0, 0.5)), 1e-14);
  EXPECT_NEAR(d.sigma(), 2.0 * std::log(10.0) / 10.0, 1e-14);
}

class MomentDraws : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(MomentDraws, MeanAndSdOfFrequencyMatchCentralPitchAndIrregularity) {
  const auto [p_db, i_db] = GetParam();
  const PitchDistribution d(config(p_db, i_db));
  ASSERT_GT(d.band_mass(), 1.0 - 1e-6) << "configuration must be effectively untruncated";
  const double m = std::pow(10.0, p_db / 10.0);
  const double s = std::pow(10.0, i_db / 10.0);
  const double sig2 = std::log(1.0 + s * s / (m * m));
  const double kurtosis = std::exp(4 * sig2) + 2 * std::exp(3 * sig2) + 3 * std::exp(2 * sig2) - 3;
  const double se_mean = s / std::sqrt(n_draws);
  const double se_sd = s * std::sqrt((kurtosis - 1.0) / (4.0 * n_draws));
  for (std::uint64_t seed : {1u, 2u}) {
    const auto f = draws(d, seed);
    const Moments mo = moments(f);
    EXPECT_NEAR(mo.mean, m, 5.0 * se_mean) << "P=" << p_db << " I=" << i_db << " seed " << seed;
    EXPECT_NEAR(mo.sd, s, 5.0 * se_sd) << "P=" << p_db << " I=" << i_db << " seed " << seed;
    // ln f is normal(mu, sigma): its mean and SD are checked too (SE sigma/√n, sigma/√(2n)).
    std::vector<double> lf(f.size());
    std::transform(f.begin(), f.end(), lf.begin(), [](double v) { return std::log(v); });
    const Moments ml = moments(lf);
    EXPECT_NEAR(ml.mean, d.mu(), 5.0 * d.sigma() / std::sqrt(n_draws));
    EXPECT_NEAR(ml.sd, d.sigma(), 5.0 * d.sigma() / std::sqrt(2.0 * n_draws));
  }
}

// (P, I) in dB: the studies' default, the acceptance example, a wide
// distribution (s = m), and a low pitch where the log-space spread is large.
INSTANTIATE_TEST_SUITE_P(Configurations, MomentDraws,
                         ::testing::Values(std::pair{10.0, -5.0}, std::pair{6.0, 3.0}, std::pair{0.0, 0.0},
                                           std::pair{-10.0, -14.0}));

class LogDraws : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(LogDraws, MedianAndDecibelSdMatch) {
  const auto [p_db, i_db] = GetParam();
  const PitchDistribution d(config(p_db, i_db, Parameterization::log));
  ASSERT_GT(d.band_mass(), 1.0 - 1e-6);
  auto f = draws(d, 11);
  // Y = 10·log10 f is normal(P, I) in dB.
  std::vector<double> y(f.size());
  std::transform(f.begin(), f.end(), y.begin(), [](double v) { return 10.0 * std::log10(v); });
  const Moments my = moments(y);
  EXPECT_NEAR(my.mean, p_db, 5.0 * i_db / std::sqrt(n_draws));
  EXPECT_NEAR(my.sd, i_db, 5.0 * i_db / std::sqrt(2.0 * n_draws));
  // Median of f = 10^(P/10): compare in dB, SE √(π/2)·I/√n.
  std::nth_element(y.begin(), y.begin() + n_draws / 2, y.end());
  const double median_db = y[n_draws / 2];
  EXPECT_NEAR(median_db, p_db, 5.0 * std::sqrt(std::numbers::pi / 2.0) * i_db / std::sqrt(n_draws));
  std::nth_element(f.begin(), f.begin() + n_draws / 2, f.end());
  EXPECT_NEAR(std::log(f[n_draws / 2] / std::pow(10.0, p_db / 10.0)), 0.0,
              5.0 * std::sqrt(std::numbers::pi / 2.0) * d.sigma() / std::sqrt(n_draws));
}

INSTANTIATE_TEST_SUITE_P(Configurations, LogDraws,
                         ::testing::Values(std::pair{10.0, 1.0}, std::pair{5.0, 2.0}, std::pair{-5.0, 3.0}));

TEST(PitchDistribution, RedrawKeepsEveryDrawInBandWithTheTruncatedShape) {
  // m = 10 cpm, s = 10^0.8 = 6.3 cpm in a band [5, 20] cpm holding ~75 %.
  PitchDistributionConfig c = config(10.0, 8.0);
  c.band_min = CyclesPerMm(5.0);
  c.band_max = CyclesPerMm(20.0);
  const PitchDistribution d(c);
  const double a = (std::log(5.0) - d.mu()) / d.sigma();
  const double b = (std::log(20.0) - d.mu()) / d.sigma();
  const double mass = phi(b) - phi(a);
  EXPECT_NEAR(d.band_mass(), mass, 1e-12);
  ASSERT_LT(mass, 0.8);  // plenty of draws must be re-drawn for the test to mean anything
  const auto f = draws(d, 5);
  int below_10 = 0;
  for (double v : f) {
    ASSERT_GE(v, 5.0);
    ASSERT_LE(v, 20.0);
    ASSERT_NE(v, 5.0) << "redraw must not pile mass on the band edge";
    ASSERT_NE(v, 20.0);
    below_10 += v < 10.0;
  }
  // Shape of the truncated distribution: P(f < 10 | band).
  const double p = (phi((std::log(10.0) - d.mu()) / d.sigma()) - phi(a)) / mass;
  EXPECT_NEAR(below_10 / static_cast<double>(n_draws), p, 5.0 * std::sqrt(p * (1 - p) / n_draws));
}

TEST(PitchDistribution, ClampPilesTheOutOfBandMassOnTheEdges) {
  PitchDistributionConfig c = config(10.0, 8.0);
  c.band_min = CyclesPerMm(5.0);
  c.band_max = CyclesPerMm(20.0);
  c.out_of_band = OutOfBand::clamp;
  const PitchDistribution d(c);
  const auto f = draws(d, 5);
  int at_lo = 0;
  int at_hi = 0;
  for (double v : f) {
    ASSERT_GE(v, 5.0);
    ASSERT_LE(v, 20.0);
    at_lo += v == 5.0;
    at_hi += v == 20.0;
  }
  const double p_lo = phi((std::log(5.0) - d.mu()) / d.sigma());
  const double p_hi = 1.0 - phi((std::log(20.0) - d.mu()) / d.sigma());
  EXPECT_NEAR(at_lo / static_cast<double>(n_draws), p_lo, 5.0 * std::sqrt(p_lo * (1 - p_lo) / n_draws));
  EXPECT_NEAR(at_hi / static_cast<double>(n_draws), p_hi, 5.0 * std::sqrt(p_hi * (1 - p_hi) / n_draws));
}

TEST(PitchDistribution, BandHoldingAlmostNoneOfTheDistributionIsAnError) {
  // Log parameterization, median 1 cpm, 20 dB spread, band [1, 1.001] cpm:
  // about 9e-5 of the mass, below the 1e-3 minimum. Redraw would loop ~10^4
  // times per texel; it must be rejected up front, naming the problem.
  PitchDistributionConfig c = config(0.0, 20.0, Parameterization::log);
  c.band_min = CyclesPerMm(1.0);
  c.band_max = CyclesPerMm(1.001);
  const std::string msg = message_of([&] { PitchDistribution{c}; });
  EXPECT_NE(msg.find("mass"), std::string::npos) << msg;
  EXPECT_NE(msg.find("irregularity_db 20"), std::string::npos) << msg;
  // Clamping is a legitimate choice for the same distribution: no error, and
  // the draws sit on the edges.
  c.out_of_band = OutOfBand::clamp;
  const PitchDistribution d(c);
  EXPECT_LT(d.band_mass(), 1e-3);
  for (std::uint64_t k = 0; k < 1000; ++k) {
    const double f = d.draw(3, k);
    ASSERT_TRUE(f >= 1.0 && f <= 1.001);
  }
}

TEST(PitchDistribution, RejectsBadConfigurationsNamingTheField) {
  auto expect_error = [](PitchDistributionConfig c, const std::string& field) {
    const std::string msg = message_of([&] { PitchDistribution{c}; });
    EXPECT_NE(msg.find(field), std::string::npos) << "expected '" << field << "' in: " << msg;
  };
  auto c = config(10.0, -5.0);
  c.central_pitch = Decibels(std::nan(""));
  expect_error(c, "central_pitch_db");
  c = config(10.0, -5.0);
  c.irregularity = Decibels(INFINITY);
  expect_error(c, "irregularity_db");
  c = config(25.0, -5.0);  // 316 cpm, above the tpad's 94.3 cpm Nyquist
  expect_error(c, "outside the renderable band");
  c = config(10.0, -5.0);
  c.band_min = CyclesPerMm(0.0);
  expect_error(c, "band_min_cpm");
  c = config(10.0, -5.0);
  c.band_max = CyclesPerMm(0.005);
  expect_error(c, "band_max_cpm");
  c = config(10.0, -5.0);
  c.quantization_db = -1.0;
  expect_error(c, "quantization_db");
  expect_error(config(10.0, -1.0, Parameterization::log), "irregularity_db");  // log spread must be >= 0
}

TEST(PitchDistribution, DrawIsAPureFunctionOfSeedAndIndex) {
  const PitchDistribution d(config(10.0, -5.0));
  int differing = 0;
  for (std::uint64_t k = 0; k < 1000; ++k) {
    ASSERT_EQ(d.draw(1, k), d.draw(1, k));
    differing += d.draw(1, k) != d.draw(2, k);
  }
  EXPECT_EQ(differing, 1000);
  // Texel 0 of seed 1 from the pinned first uniform (test_random.cpp):
  // exp(mu + sigma·Φ⁻¹(0.13143070512329408)).
  // Φ⁻¹ from mpmath at 30 digits: -1.11965358775361904313.
  EXPECT_NEAR(d.draw(1, 0), std::exp(d.mu() + d.sigma() * -1.11965358775361904313), 1e-13);
}

TEST(PitchDistribution, RunsOfDrawsAreTheScalarDrawsBitForBit) {
  // The lane-wise run draw(seed, first, out) against draw(seed, k) one by
  // one: narrow and wide distributions (tails of the normal quantile, many
  // redraws), clamping, quantization, zero spread, a band holding little of
  // the distribution, and runs that start and end off the lane width.
  std::vector<PitchDistributionConfig> configs;
  configs.push_back(config(10.0, -5.0));
  configs.push_back(config(10.0, 10.0));  // wide: redraws at the band top
  auto clamp = config(10.0, 12.0);
  clamp.out_of_band = OutOfBand::clamp;
  configs.push_back(clamp);
  auto quantized = config(10.0, 10.0);
  quantized.quantization_db = 1.5;
  configs.push_back(quantized);
  configs.push_back(config(6.0, 0.0, Parameterization::log));  // sigma = 0
  configs.push_back(config(6.0, 8.0, Parameterization::log));
  auto narrow_band = config(0.0, 0.0, Parameterization::log);
  narrow_band.irregularity = Decibels(12.0);
  narrow_band.band_min = CyclesPerMm(0.9);
  narrow_band.band_max = CyclesPerMm(1.2);  // ~3% of the mass: most first attempts redraw
  configs.push_back(narrow_band);
  auto tiny = config(-30.0, -30.0);
  tiny.band_min = CyclesPerMm(1e-4);
  configs.push_back(tiny);
  for (std::size_t c = 0; c < configs.size(); ++c) {
    const PitchDistribution d(configs[c]);
    for (const auto& [first, count] : std::vector<std::pair<std::uint64_t, std::size_t>>{
             {0, 1}, {0, 7}, {3, 13}, {1000, 4096}, {(std::uint64_t{1} << 36) + 5, 1001}}) {
      for (std::uint64_t seed : {1u, 7u, 12345u}) {
        std::vector<double> run(count, -7.0);
        d.draw(seed, first, run);
        for (std::size_t i = 0; i < count; ++i)
          ASSERT_EQ(std::bit_cast<std::uint64_t>(run[i]), std::bit_cast<std::uint64_t>(d.draw(seed, first + i)))
              << "config " << c << " seed " << seed << " draw " << first + i;
      }
    }
  }
}

class Quantized : public ::testing::TestWithParam<double> {};

TEST_P(Quantized, FrequenciesLieOnTheDecibelGridAndInBand) {
  const double q = GetParam();
  // Wide distribution (m = s = 10 cpm) so draws reach the band top, where a
  // grid value above Nyquist must step down.
  auto c = config(10.0, 10.0);
  const PitchDistribution raw(c);
  c.quantization_db = q;
  const PitchDistribution d(c);
  const double hi = c.band_max.value();
  int stepped_down = 0;
  for (std::uint64_t k = 0; k < 20000; ++k) {
    const double f = d.draw(9, k);
    const double grid = 10.0 * std::log10(f) / q;
    ASSERT_NEAR(grid, std::round(grid), 1e-9) << "f = " << f << " q = " << q;
    ASSERT_GE(f, c.band_min.value());
    ASSERT_LE(f, hi);
    // It is the nearest grid value to the unquantized draw, unless that one
    // is above the band (then the next one down).
    const double f0 = raw.draw(9, k);
    const double diff_db = 10.0 * std::log10(f / f0);
    if (std::fabs(diff_db) > q / 2 + 1e-9) {
      ASSERT_LT(f, f0);
      ASSERT_GT(f * std::pow(10.0, q / 10.0), hi * (1 - 1e-12)) << "stepped down without need";
      ++stepped_down;
    }
  }
  EXPECT_GT(stepped_down, 0) << "the band-top case was not exercised";
}

INSTANTIATE_TEST_SUITE_P(Steps, Quantized, ::testing::Values(1.0, 3.0, 5.0));

TEST(PitchDistribution, QuantizeRoundsToTheNearestGridValue) {
  auto c = config(10.0, -5.0);
  c.quantization_db = 3.0;
  const PitchDistribution d(c);
  EXPECT_NEAR(d.quantize(10.0), std::pow(10.0, 0.9), 1e-12);    // 10 dB -> 9 dB (nearest multiple of 3)
  EXPECT_NEAR(d.quantize(12.0), std::pow(10.0, 1.2), 1e-12);    // 10.8 dB -> 12 dB
  EXPECT_NEAR(d.quantize(94.0), std::pow(10.0, 1.8), 1e-12);    // 19.7 dB -> 21 dB is above 94.3 cpm: 18 dB
  EXPECT_NEAR(d.quantize(0.011), std::pow(10.0, -1.8), 1e-15);  // -19.6 dB -> -21 dB is below 0.01: -18 dB
  c.quantization_db = 0.0;
  EXPECT_EQ(PitchDistribution(c).quantize(12.345), 12.345);  // off
}
