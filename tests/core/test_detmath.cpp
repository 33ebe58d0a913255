// detmath: Texel's own exp/log/sin/normal quantile (rendering.md §9).
//
// They exist for bit-identity across platforms, but they must still be the
// functions they claim to be: each is compared with the C library (or long
// double) over its working range, within a few ulp. The reductions that the
// renderer relies on for window independence (round_even, floor_exact, the
// whole-cycle reduction of sin_cycles) are checked to be exact.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "texel/detmath.hpp"
#include "texel/random.hpp"

namespace dm = texel::detmath;

namespace {

/// Distance in units in the last place between two finite doubles of the same sign.
double ulp_distance(double a, double b) {
  if (a == b) return 0.0;
  const double ulp = std::nextafter(std::fabs(b), std::numeric_limits<double>::infinity()) - std::fabs(b);
  return std::fabs(a - b) / ulp;
}

/// Uniform double in [lo, hi) from a fixed-seed generator (exact, repeatable).
struct Sweep {
  texel::SequentialRng rng{20240601, 99};
  double operator()(double lo, double hi) { return lo + (hi - lo) * rng.uniform(); }
};

}  // namespace

TEST(Detmath, RoundEvenIsExactAndTiesToEven) {
  EXPECT_EQ(dm::round_even(0.5), 0.0);
  EXPECT_EQ(dm::round_even(1.5), 2.0);
  EXPECT_EQ(dm::round_even(2.5), 2.0);
  EXPECT_EQ(dm::round_even(-0.5), 0.0);
  EXPECT_EQ(dm::round_even(-1.5), -2.0);
  EXPECT_EQ(dm::round_even(0.49999999999999994), 0.0);
  Sweep s;
  for (int i = 0; i < 100000; ++i) {
    const double scale = std::ldexp(1.0, static_cast<int>(s(0, 51)));
    const double x = s(-scale, scale);
    ASSERT_EQ(dm::round_even(x), std::nearbyint(x)) << "x = " << x;  // default rounding mode: ties to even
    ASSERT_EQ(dm::floor_exact(x), std::floor(x)) << "x = " << x;
  }
}

TEST(Detmath, ExpWithinTwoUlpOfTheCLibrary) {
  Sweep s;
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double x = s(-700.0, 700.0);
    worst = std::max(worst, ulp_distance(dm::exp(x), std::exp(x)));
  }
  // Small arguments, where the result is near 1 and the reduction is trivial.
  for (int i = 0; i < 20000; ++i) {
    const double x = s(-1e-3, 1e-3);
    worst = std::max(worst, ulp_distance(dm::exp(x), std::exp(x)));
  }
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(dm::exp(0.0), 1.0);
  EXPECT_EQ(dm::exp(1000.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(dm::exp(-1000.0), 0.0);
  EXPECT_TRUE(std::isnan(dm::exp(std::numeric_limits<double>::quiet_NaN())));
}

namespace {

/// detmath::exp as it was written before scale_pow2: the same reduction and
/// polynomial, scaled by std::ldexp. The reference the new scaling must
/// reproduce bit for bit.
double exp_with_ldexp(double x) {
  if (std::isnan(x)) return x;
  if (x > 709.782712893384) return std::numeric_limits<double>::infinity();
  if (x < -745.1332191019412) return 0.0;
  const double k = dm::round_even(x * 1.44269504088896338700e+00);
  const double r = (x - k * 6.93147180369123816490e-01) - k * 1.90821492927058770002e-10;
  double p = 1.0 / 87178291200.0;
  for (double c : {1.0 / 6227020800.0, 1.0 / 479001600.0, 1.0 / 39916800.0, 1.0 / 3628800.0, 1.0 / 362880.0, 1.0 / 40320.0,
                   1.0 / 5040.0, 1.0 / 720.0, 1.0 / 120.0, 1.0 / 24.0, 1.0 / 6.0, 0.5, 1.0, 1.0})
    p = p * r + c;
  return std::ldexp(p, static_cast<int>(k));
}

std::uint64_t bits_of(double v) { return std::bit_cast<std::uint64_t>(v); }

}  // namespace

TEST(Detmath, ScalePow2IsLdexpForEveryExponent) {
  // Every exponent exp can produce, with mantissas across [0.5, 2) and its
  // edges: normal, subnormal (rounded once, ties to even), zero and overflow
  // results all equal std::ldexp's.
  Sweep s;
  std::vector<double> mantissas = {0.5,
                                   0.7071067811865476,
                                   1.0,
                                   1.4142135623730951,
                                   std::nextafter(2.0, 0.0),
                                   std::nextafter(1.0, 0.0),
                                   std::nextafter(1.0, 2.0),
                                   1.5,
                                   0.75,
                                   1.0000000000000004};
  for (int i = 0; i < 200; ++i) mantissas.push_back(s(0.5, 2.0));
  for (int k = -1076; k <= 1024; ++k)
    for (double p : mantissas)
      ASSERT_EQ(bits_of(dm::scale_pow2(p, k)), bits_of(std::ldexp(p, k))) << "p = " << p << ", k = " << k;
  for (int k = -1022; k <= 1023; ++k) ASSERT_EQ(dm::pow2(k), std::ldexp(1.0, k)) << k;
}

TEST(Detmath, ExpIsBitIdenticalToTheLdexpFormula) {
  // The exact power-of-two scaling changed how exp multiplies by 2^k, never
  // a bit of what it returns: against the former formula over the whole
  // range, densely where the result is subnormal or overflows, and at the
  // thresholds, zeros, infinities and NaN.
  Sweep s;
  std::vector<double> xs = {0.0,
                            -0.0,
                            1.0,
                            -1.0,
                            1e-300,
                            -1e-300,
                            4.9406564584124654e-324,
                            709.782712893384,
                            std::nextafter(709.782712893384, 0.0),
                            std::nextafter(709.782712893384, 1000.0),
                            709.782712893383973096,
                            -745.1332191019412,
                            std::nextafter(-745.1332191019412, 0.0),
                            std::nextafter(-745.1332191019412, -1000.0),
                            -708.3964185322641,  // ~ the smallest normal result
                            -744.4400719213812,  // ~ the smallest subnormal
                            std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::max(),
                            std::numeric_limits<double>::lowest()};
  for (int i = 0; i < 1000000; ++i) xs.push_back(s(-746.0, 711.0));
  for (int i = 0; i < 200000; ++i) xs.push_back(s(-745.2, -707.0));  // subnormal and near-subnormal results
  for (int i = 0; i < 100000; ++i) xs.push_back(s(708.0, 709.8));    // k = 1022 … 1024, overflow
  for (int i = 0; i < 100000; ++i) xs.push_back(s(-1e-6, 1e-6));
  // Whole multiples of ln 2 and their neighbours, where k changes.
  for (int k = -1076; k <= 1025; ++k) {
    const double x = k * 0.6931471805599453;
    xs.insert(xs.end(), {x, std::nextafter(x, -1e9), std::nextafter(x, 1e9), x + 0.34657359027997264, x - 0.34657359027997264});
  }
  for (double x : xs) {
    const double got = dm::exp(x), want = exp_with_ldexp(x);
    if (std::isnan(want)) {
      ASSERT_TRUE(std::isnan(got)) << "x = " << x;
      continue;
    }
    ASSERT_EQ(bits_of(got), bits_of(want)) << "x = " << x;
  }
  EXPECT_TRUE(std::isnan(dm::exp(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_GT(dm::exp(-745.0), 0.0);  // a subnormal result, not flushed
  EXPECT_LT(dm::exp(-745.0), std::numeric_limits<double>::min());
}

TEST(Detmath, LogWithinTwoUlpOfTheCLibrary) {
  Sweep s;
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    // log-uniform over the whole normal range, plus values near 1 where
    // cancellation would show.
    const double x = std::ldexp(s(0.5, 1.0), static_cast<int>(s(-1020, 1020)));
    worst = std::max(worst, ulp_distance(dm::log(x), std::log(x)));
    const double y = 1.0 + s(-0.01, 0.01);
    if (y != 1.0) worst = std::max(worst, ulp_distance(dm::log(y), std::log(y)));
  }
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(dm::log(1.0), 0.0);
  EXPECT_NEAR(dm::log(4.9406564584124654e-324), std::log(4.9406564584124654e-324), 1e-12);  // subnormal
  EXPECT_NEAR(dm::log(1e-310), std::log(1e-310), 1e-12);
  EXPECT_EQ(dm::log(0.0), -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(dm::log(-1.0)));
  EXPECT_EQ(dm::log(std::numeric_limits<double>::infinity()), std::numeric_limits<double>::infinity());
}

TEST(Detmath, Pow10MatchesTheCLibraryOverTheDecibelRange) {
  // pow10(x) = exp(y), y = x·ln10 in double. The relative error of the result
  // is the absolute error of y plus exp's own: rounding the product and the
  // constant ln10 each contribute up to |y|·2^-53, exp 2 ulp (<= 4·2^-53),
  // std::pow's reference 1 ulp (<= 2·2^-53). So
  //   |pow10(x)/10^x − 1| <= (2|y| + 6)·2^-53,
  // about 24·2^-53 at |x| = 4 (±40 dB, the widest pitch a document accepts).
  Sweep s;
  double worst = 0.0;  // error / bound
  for (int i = 0; i < 100000; ++i) {
    const double x = s(-4.0, 4.0);
    const double rel = std::fabs(dm::pow10(x) / std::pow(10.0, x) - 1.0);
    worst = std::max(worst, rel / ((2.0 * std::fabs(x) * 2.302585092994046 + 6.0) * 0x1.0p-53));
  }
  EXPECT_LE(worst, 1.0);
  EXPECT_NEAR(dm::pow10(1.0), 10.0, 1e-14);
  EXPECT_NEAR(dm::pow10(-1.0), 0.1, 1e-16);
}

TEST(Detmath, SinCyclesMatchesLongDoubleWithin1e14) {
  // Reference: the exact fractional cycle r = u − round(u) (exact in double
  // for |u| < 2^51), then sinl(2π·r) in long double.
  const long double two_pi = 6.283185307179586476925286766559005768L;
  Sweep s;
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double u = i % 2 ? s(-2.0, 2.0) : s(-1e6, 1e6);
    const double r = u - std::nearbyint(u);
    const auto ref = static_cast<double>(std::sin(two_pi * static_cast<long double>(r)));
    worst = std::max(worst, std::fabs(dm::sin_cycles(u) - ref));
  }
  EXPECT_LE(worst, 1e-14);
  EXPECT_EQ(dm::sin_cycles(0.0), 0.0);
  EXPECT_EQ(dm::sin_cycles(0.5), 0.0);
  EXPECT_NEAR(dm::sin_cycles(0.25), 1.0, 1e-15);
  EXPECT_NEAR(dm::sin_cycles(-0.25), -1.0, 1e-15);
  EXPECT_NEAR(dm::cos_cycles(0.0), 1.0, 1e-15);
  EXPECT_NEAR(dm::cos_cycles(1.0 / 3.0), -0.5, 1e-15);
}

RC_GTEST_PROP(Detmath, SinCyclesReductionIsExactOverWholeCycles, ()) {
  // u and u + k (k whole cycles) give bit-identical sines when u + k is exact:
  // this is what makes a texture the same whatever window renders it.
  const auto k = static_cast<double>(*rc::gen::inRange<std::int64_t>(-(std::int64_t{1} << 40), std::int64_t{1} << 40));
  const auto frac_bits = *rc::gen::inRange<std::int64_t>(-(std::int64_t{1} << 12), std::int64_t{1} << 12);
  const double u = static_cast<double>(frac_bits) * 0x1.0p-12;  // dyadic: u + k is exact
  RC_ASSERT(dm::sin_cycles(u + k) == dm::sin_cycles(u));
  // Odd symmetry is exact too (the polynomial is odd, the reduction symmetric).
  RC_ASSERT(dm::sin_cycles(-u) == -dm::sin_cycles(u));
}

RC_GTEST_PROP(Detmath, SinCyclesStaysInUnitInterval, ()) {
  const double u = *rc::gen::map(rc::gen::arbitrary<std::int64_t>(),
                                 [](std::int64_t v) { return static_cast<double>(v % (std::int64_t{1} << 53)) * 0x1.0p-20; });
  const double y = dm::sin_cycles(u);
  RC_ASSERT(y >= -1.0);
  RC_ASSERT(y <= 1.0);
}

TEST(Detmath, NormalQuantileKnownValues) {
  // Reference values from mpmath at 30 digits: sqrt(2)·erfinv(2p − 1).
  EXPECT_EQ(dm::normal_quantile(0.5), 0.0);
  EXPECT_NEAR(dm::normal_quantile(0.975), 1.9599639845400542355, 1e-14);
  EXPECT_NEAR(dm::normal_quantile(0.3), -0.52440051270804078404, 1e-14);
  EXPECT_NEAR(dm::normal_quantile(1e-10), -6.3613409024040562047, 1e-13);
  EXPECT_EQ(dm::normal_quantile(0.0), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(dm::normal_quantile(1.0), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(dm::normal_quantile(1.5)));
  EXPECT_TRUE(std::isnan(dm::normal_quantile(-0.1)));
}

TEST(Detmath, NormalQuantileInvertsTheCLibraryCdf) {
  // Φ(Φ⁻¹(p)) = p with Φ from the C library's erfc. A relative error ε in z
  // (or in erfc's argument z/√2) becomes a relative error of about
  // (φ(z)·|z|/Φ(z))·ε ≈ (1 + z²)·ε in p. With AS241's ~1e-16 (≈ 2 ulp), erfc's
  // 1–2 ulp and the division by √2 (2 ulp), ε <= 8·2^-53, so the bound is
  // |Φ(Φ⁻¹(p)) − p| / p <= (1 + z²)·8·2^-53: 4e-15 centrally, 1.2e-12 at z = −37.
  Sweep s;
  double worst_central = 0.0;  // error / bound
  double worst_tail = 0.0;
  auto bound = [](double z) { return (1.0 + z * z) * 8.0 * 0x1.0p-53; };
  for (int i = 0; i < 100000; ++i) {
    const double p = s(0.03, 0.97);
    const double z = dm::normal_quantile(p);
    const double back = 0.5 * std::erfc(-z / std::sqrt(2.0));
    worst_central = std::max(worst_central, std::fabs(back - p) / p / bound(z));
    const double tail_p = std::ldexp(s(0.5, 1.0), -static_cast<int>(s(5, 1000)));
    const double tz = dm::normal_quantile(tail_p);
    const double tail_back = 0.5 * std::erfc(-tz / std::sqrt(2.0));
    worst_tail = std::max(worst_tail, std::fabs(tail_back - tail_p) / tail_p / bound(tz));
    // Symmetry: Φ⁻¹(1 − p) = −Φ⁻¹(p) where 1 − p is exact.
    ASSERT_NEAR(dm::normal_quantile(1.0 - p), -z, 1e-14 * std::max(1.0, std::fabs(z)));
  }
  EXPECT_LE(worst_central, 1.0);
  EXPECT_LE(worst_tail, 1.0);
}

TEST(Detmath, NormalCdf) {
  EXPECT_EQ(dm::normal_cdf(0.0), 0.5);
  EXPECT_NEAR(dm::normal_cdf(1.9599639845400542355), 0.975, 1e-15);
  EXPECT_NEAR(dm::normal_cdf(-6.3613409024040562047), 1e-10, 1e-22);
}
