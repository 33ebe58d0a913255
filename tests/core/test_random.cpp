// CounterRng: Texel's specified generator (random.hpp, docs/algorithm.md §9).
//
// Pinned first values make any change to the generator fail loudly: every
// saved texture would otherwise silently re-render differently. The values
// below were computed by an independent Python transcription of the formulas
// in random.hpp (mix64 = SplitMix64's finalizer).
//
// Statistical tolerances: n = 10^6 uniforms (10^5 where stated); a sample
// moment is within 5 standard errors of its expectation. 5 SE is exceeded with
// probability < 6e-7 for a correct generator, and with fixed seeds each test
// is exact and repeatable.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "texel/random.hpp"

using texel::CounterRng;
using texel::SequentialRng;
using texel::Stream;

TEST(Mix64, IsTheSplitMix64Finalizer) {
  // SplitMix64 seeded with 0 returns mix64(0x9E3779B97F4A7C15) first: the
  // published first output 0xE220A8397B1DCDAF.
  EXPECT_EQ(texel::mix64(0x9E3779B97F4A7C15ULL), 0xE220A8397B1DCDAFULL);
  EXPECT_EQ(texel::mix64(0), 0u);
}

TEST(MulHigh, MatchesThe128BitProduct) {
  texel::SequentialRng rng(5, 5);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t a = rng.bits();
    const std::uint64_t b = rng.bits();
    __extension__ using u128 = unsigned __int128;
    const auto want = static_cast<std::uint64_t>((static_cast<u128>(a) * b) >> 64);
    ASSERT_EQ(texel::mul_high(a, b), want);
  }
  EXPECT_EQ(texel::mul_high(~0ULL, ~0ULL), ~0ULL - 1);
}

TEST(CounterRng, FirstValuesArePinned) {
  struct Case {
    std::uint64_t seed;
    std::uint64_t stream;
    std::array<std::uint64_t, 4> bits;
  };
  const Case cases[] = {
      {1, 1, {0x21a5715431dc4cc7, 0xe1a26c101cc38752, 0xa001a4cd852412c8, 0x0277fbdc8603f9a6}},
      {1, 2, {0x481c920d996fce04, 0x45755bbde008fe9b, 0xbfdda205eebccef0, 0xdac0b083a7c5fea9}},
      {0, 0, {0x568a9b0b1a2c05ec, 0x44e5b8b147ef718b, 0x458563ab55521133, 0x7aec644539b6c0f9}},
      {7, 1, {0xcc48a0e2d1c77be6, 0x828f1fde795e05d8, 0x56d130218c21b41e, 0x7a7412629fde2213}},
      {~0ULL, 16, {0xc20e1a0ddcbe8696, 0xe18964e361a5ee87, 0x0189eba7ace49602, 0xdd278aa3091f1742}},
  };
  for (const auto& c : cases) {
    const CounterRng rng(c.seed, c.stream);
    for (std::uint64_t i = 0; i < 4; ++i)
      EXPECT_EQ(rng.bits(i), c.bits[i]) << "seed " << c.seed << " stream " << c.stream << " counter " << i;
  }
  // The frequency stream of seed 1 (texel 0's first draw) as a uniform.
  EXPECT_EQ(CounterRng(1, Stream::frequency).uniform(0), 0.13143070512329408);
  static_assert(static_cast<std::uint64_t>(Stream::frequency) == 1 && static_cast<std::uint64_t>(Stream::phase) == 2,
                "stream numbers are part of the file format");
}

namespace {

// mix64 is a bijection, so a counter giving any chosen 64-bit word can be
// constructed: invert the finalizer, subtract the key, divide by the odd
// increment modulo 2^64. This reaches the extreme words, which random
// sampling never would (probability 2^-53).
std::uint64_t unxorshift(std::uint64_t z, int s) {
  std::uint64_t x = z;
  for (int i = 0; i < 64 / s + 1; ++i) x = z ^ (x >> s);
  return x;
}
std::uint64_t inverse_odd(std::uint64_t c) {
  std::uint64_t inv = c;  // Newton: each step doubles the correct low bits
  for (int i = 0; i < 6; ++i) inv *= 2 - c * inv;
  return inv;
}
std::uint64_t unmix64(std::uint64_t z) {
  z = unxorshift(z, 31);
  z *= inverse_odd(0x94D049BB133111EBULL);
  z = unxorshift(z, 27);
  z *= inverse_odd(0xBF58476D1CE4E5B9ULL);
  return unxorshift(z, 30);
}
/// The counter at which CounterRng(seed, stream).bits(counter) == word, from
/// the formulas documented in random.hpp.
std::uint64_t counter_for(std::uint64_t seed, std::uint64_t stream, std::uint64_t word) {
  constexpr std::uint64_t g = 0x9E3779B97F4A7C15ULL;
  const std::uint64_t key = texel::mix64(seed ^ texel::mix64(stream + g));
  return (unmix64(word) - key) * inverse_odd(g) - 1;
}

}  // namespace

TEST(CounterRng, UniformIsInTheOpenUnitIntervalEvenAtTheExtremeWords) {
  for (std::uint64_t w : {0x123456789ULL, ~0ULL}) ASSERT_EQ(unmix64(texel::mix64(w)), w);
  const std::uint64_t seed = 5;
  const auto stream = static_cast<std::uint64_t>(Stream::frequency);
  const CounterRng r(seed, stream);
  // All ones: the largest uniform must stay below 1 (Φ⁻¹(1) = +inf).
  const std::uint64_t top = counter_for(seed, stream, ~0ULL);
  ASSERT_EQ(r.bits(top), ~0ULL);
  EXPECT_LT(r.uniform(top), 1.0);
  EXPECT_TRUE(std::isfinite(r.normal(top)));
  // Words just below: still inside, and increasing with the word.
  const std::uint64_t next = counter_for(seed, stream, ~0ULL - (1ULL << 11));
  EXPECT_LT(r.uniform(next), 1.0);
  EXPECT_LE(r.uniform(next), r.uniform(top));
  // All zeros: the smallest uniform must stay above 0 (Φ⁻¹(0) = −inf).
  const std::uint64_t bottom = counter_for(seed, stream, 0);
  ASSERT_EQ(r.bits(bottom), 0u);
  EXPECT_GT(r.uniform(bottom), 0.0);
  EXPECT_TRUE(std::isfinite(r.normal(bottom)));
  // And over a million ordinary draws.
  const CounterRng rng(42, Stream::user);
  for (std::uint64_t i = 0; i < 1000000; ++i) {
    const double u = rng.uniform(i);
    ASSERT_GT(u, 0.0);
    ASSERT_LT(u, 1.0);
  }
}

TEST(CounterRng, UniformMoments) {
  // E[u] = 1/2, Var u = 1/12; SE(mean) = sqrt(1/12/n). Sample variance of a
  // uniform: Var(s²) ≈ (μ4 − σ⁴)/n with μ4 = 1/80, σ⁴ = 1/144.
  constexpr int n = 1000000;
  const CounterRng rng(2024, Stream::frequency);
  double sum = 0.0;
  double sum2 = 0.0;
  std::array<int, 10> deciles{};
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform(static_cast<std::uint64_t>(i));
    sum += u;
    sum2 += u * u;
    ++deciles[static_cast<std::size_t>(u * 10.0)];
  }
  const double mean = sum / n;
  const double var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR(var, 1.0 / 12.0, 5.0 * std::sqrt((1.0 / 80.0 - 1.0 / 144.0) / n));
  // Each decile holds n/10 ± 5·sqrt(n·0.1·0.9).
  for (int d : deciles) EXPECT_NEAR(d, n / 10, 5.0 * std::sqrt(n * 0.09));
}

TEST(CounterRng, NormalMoments) {
  // Standard normal by inversion: mean 0 (SE 1/√n), variance 1 (SE √(2/n)),
  // skewness 0 (SE √(6/n)), excess kurtosis 0 (SE √(24/n)).
  constexpr int n = 1000000;
  const CounterRng rng(99, Stream::phase);
  double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  for (int i = 0; i < n; ++i) {
    const double z = rng.normal(static_cast<std::uint64_t>(i));
    m1 += z;
    m2 += z * z;
    m3 += z * z * z;
    m4 += z * z * z * z;
  }
  m1 /= n;
  m2 /= n;
  m3 /= n;
  m4 /= n;
  EXPECT_NEAR(m1, 0.0, 5.0 / std::sqrt(n));
  EXPECT_NEAR(m2, 1.0, 5.0 * std::sqrt(2.0 / n));
  EXPECT_NEAR(m3, 0.0, 5.0 * std::sqrt(15.0 / n));  // Var(z³) = E z⁶ = 15
  EXPECT_NEAR(m4, 3.0, 5.0 * std::sqrt(96.0 / n));  // Var(z⁴) = E z⁸ − 9 = 96
}

TEST(CounterRng, StreamsAndSeedsAreIndependent) {
  // Pearson correlation of paired uniforms: under independence r has SE 1/√n.
  // Also the lag-1 correlation within one stream (counters i and i+1).
  constexpr int n = 200000;
  auto corr = [](const std::vector<double>& a, const std::vector<double>& b) {
    double ma = 0, mb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ma += a[i];
      mb += b[i];
    }
    ma /= static_cast<double>(a.size());
    mb /= static_cast<double>(b.size());
    double sab = 0, saa = 0, sbb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      sab += (a[i] - ma) * (b[i] - mb);
      saa += (a[i] - ma) * (a[i] - ma);
      sbb += (b[i] - mb) * (b[i] - mb);
    }
    return sab / std::sqrt(saa * sbb);
  };
  auto draws = [](std::uint64_t seed, Stream s, std::uint64_t offset) {
    std::vector<double> v(n);
    const CounterRng rng(seed, s);
    for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = rng.uniform(static_cast<std::uint64_t>(i) + offset);
    return v;
  };
  const double tol = 5.0 / std::sqrt(n);
  const auto f1 = draws(1, Stream::frequency, 0);
  EXPECT_NEAR(corr(f1, draws(1, Stream::phase, 0)), 0.0, tol) << "streams of one seed";
  EXPECT_NEAR(corr(f1, draws(2, Stream::frequency, 0)), 0.0, tol) << "adjacent seeds";
  EXPECT_NEAR(corr(f1, draws(1, Stream::frequency, 1)), 0.0, tol) << "lag 1 within a stream";
  // Different streams must not be the same sequence shifted (a classic flaw
  // of key = seed + stream designs): no equal values at small offsets.
  const CounterRng a(1, Stream::frequency);
  const CounterRng b(1, Stream::phase);
  for (std::uint64_t i = 0; i < 1000; ++i)
    for (std::uint64_t j = 0; j < 64; ++j) ASSERT_NE(a.bits(i), b.bits(j));
}

TEST(CounterRng, BelowIsUniformOverItsRange) {
  // Chi-square over 10 bins with n = 10^5: df = 9, mean 9, SD √18; reject
  // above mean + 5 SD.
  constexpr int n = 100000;
  std::array<int, 10> bins{};
  const CounterRng rng(3, Stream::reference);
  for (int i = 0; i < n; ++i) {
    const auto v = rng.below(static_cast<std::uint64_t>(i), 10);
    ASSERT_LT(v, 10u);
    ++bins[v];
  }
  double chi2 = 0.0;
  for (int b : bins) chi2 += (b - n / 10.0) * (b - n / 10.0) / (n / 10.0);
  EXPECT_LT(chi2, 9.0 + 5.0 * std::sqrt(18.0));
  EXPECT_EQ(rng.below(0, 1), 0u);
}

RC_GTEST_PROP(SequentialRng, MatchesCounterRngAtConsecutiveCounters, (std::uint64_t seed, std::uint64_t stream)) {
  SequentialRng seq(seed, stream);
  const CounterRng ctr(seed, stream);
  for (std::uint64_t i = 0; i < 8; ++i) RC_ASSERT(seq.uniform() == ctr.uniform(i));
  RC_ASSERT(seq.position() == 8u);
  RC_ASSERT(seq.bits() == ctr.bits(8));
  RC_ASSERT(seq.normal() == ctr.normal(9));
}

RC_GTEST_PROP(CounterRng, IsAPureFunctionOfSeedStreamCounter, (std::uint64_t seed, std::uint64_t counter)) {
  const CounterRng a(seed, Stream::frequency);
  const CounterRng b(seed, Stream::frequency);
  RC_ASSERT(a.bits(counter) == b.bits(counter));
  RC_ASSERT(a.normal(counter) == b.normal(counter));
  // A different seed gives a different word (mix64 is a bijection, so equality
  // would need a key collision).
  RC_ASSERT(CounterRng(seed + 1, Stream::frequency).bits(counter) != a.bits(counter));
}
