// detmath: Texel's own exp/log/sin/normal quantile (docs/algorithm.md §9).
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
#include <initializer_list>
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

namespace {

/// detmath::log as it was written before its core became
/// log_normal_generic (shared with the lane-wise draws): the reference.
double log_before_generic(double x) {
  if (std::isnan(x) || x < 0.0) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return -std::numeric_limits<double>::infinity();
  if (std::isinf(x)) return x;
  int e = 0;
  std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  if ((bits >> 52) == 0) {
    x *= 0x1.0p54;
    e -= 54;
    bits = std::bit_cast<std::uint64_t>(x);
  }
  e += static_cast<int>((bits >> 52) & 0x7FF) - 1023;
  double m = std::bit_cast<double>((bits & 0x000FFFFFFFFFFFFFULL) | 0x3FF0000000000000ULL);
  if (m > 1.4142135623730951) {
    m *= 0.5;
    e += 1;
  }
  const double s = (m - 1.0) / (m + 1.0);
  const double s2 = s * s;
  double p = 1.0 / 23.0;
  for (double c :
       {1.0 / 21.0, 1.0 / 19.0, 1.0 / 17.0, 1.0 / 15.0, 1.0 / 13.0, 1.0 / 11.0, 1.0 / 9.0, 1.0 / 7.0, 1.0 / 5.0, 1.0 / 3.0})
    p = p * s2 + c;
  const double log_m = 2.0 * s + 2.0 * s * s2 * p;
  const double de = static_cast<double>(e);
  return de * 6.93147180369123816490e-01 + (log_m + de * 1.90821492927058770002e-10);
}

/// A polynomial in r by Horner's rule, highest coefficient first.
double horner(std::initializer_list<double> c, double r) {
  auto it = c.begin();
  double p = *it++;
  for (; it != c.end(); ++it) p = p * r + *it;
  return p;
}

/// detmath::normal_quantile as it was written before its branches became
/// generic definitions (AS241, PPND16): the reference.
double normal_quantile_before_generic(double p) {
  if (!(p > 0.0 && p < 1.0)) return std::numeric_limits<double>::quiet_NaN();
  const double q = p - 0.5;
  if (std::fabs(q) <= 0.425) {
    const double r = 0.180625 - q * q;
    const double num =
        horner({2.5090809287301226727e+3, 3.3430575583588128105e+4, 6.7265770927008700853e+4, 4.5921953931549871457e+4,
                1.3731693765509461125e+4, 1.9715909503065514427e+3, 1.3314166789178437745e+2, 3.3871328727963666080e+0},
               r);
    const double den =
        horner({5.2264952788528545610e+3, 2.8729085735721942674e+4, 3.9307895800092710610e+4, 2.1213794301586595867e+4,
                5.3941960214247511077e+3, 6.8718700749205790830e+2, 4.2313330701600911252e+1, 1.0},
               r);
    return q * num / den;
  }
  double r = q < 0.0 ? p : 1.0 - p;
  r = std::sqrt(-log_before_generic(r));
  double value = 0.0;
  if (r <= 5.0) {
    r -= 1.6;
    value = horner({7.74545014278341407640e-4, 2.27238449892691845833e-2, 2.41780725177450611770e-1, 1.27045825245236838258e+0,
                    3.64784832476320460504e+0, 5.76949722146069140550e+0, 4.63033784615654529590e+0, 1.42343711074968357734e+0},
                   r) /
            horner({1.05075007164441684324e-9, 5.47593808499534494600e-4, 1.51986665636164571966e-2, 1.48103976427480074590e-1,
                    6.89767334985100004550e-1, 1.67638483018380384940e+0, 2.05319162663775882187e+0, 1.0},
                   r);
  } else {
    r -= 5.0;
    value = horner({2.01033439929228813265e-7, 2.71155556874348757815e-5, 1.24266094738807843860e-3, 2.65321895265761230930e-2,
                    2.96560571828504891230e-1, 1.78482653991729133580e+0, 5.46378491116411436990e+0, 6.65790464350110377720e+0},
                   r) /
            horner({2.04426310338993978564e-15, 1.42151175831644588870e-7, 1.84631831751005468180e-5, 7.86869131145613259100e-4,
                    1.48753612908506148525e-2, 1.36929880922735805310e-1, 5.99832206555887937690e-1, 1.0},
                   r);
  }
  return q < 0.0 ? -value : value;
}

}  // namespace

TEST(Detmath, LogAndNormalQuantileAreBitIdenticalToTheirFormerCode) {
  // Their cores became generic definitions shared with the lane-wise draws;
  // not a bit of what they return changed: over the whole positive range
  // (subnormals included) and, for the quantile, both tails densely.
  Sweep s;
  std::vector<double> xs = {1.0,
                            0.5,
                            2.0,
                            1.4142135623730951,
                            1.4142135623730954,
                            4.9406564584124654e-324,
                            1e-310,
                            std::numeric_limits<double>::min(),
                            std::numeric_limits<double>::max(),
                            0x1.0p-54,
                            0x1.0p-53};
  for (int i = 0; i < 300000; ++i) xs.push_back(std::ldexp(s(0.5, 1.0), static_cast<int>(s(-1074, 1024))));
  for (int i = 0; i < 100000; ++i) xs.push_back(s(0.0, 1.0));
  for (double x : xs) ASSERT_EQ(bits_of(dm::log(x)), bits_of(log_before_generic(x))) << "x = " << x;
  std::vector<double> ps = {
      0.5, 0.075, 0.925, 0.07499999999999996, 0.925000000000000003, 0x1.0p-54, 1.0 - 0x1.0p-53, 1e-300, 1.3e-11, 1.5e-11, 1e-12};
  for (int i = 0; i < 300000; ++i) ps.push_back(s(0.0, 1.0));
  for (int i = 0; i < 100000; ++i) ps.push_back(std::ldexp(s(0.5, 1.0), static_cast<int>(s(-60, -3))));        // lower tail
  for (int i = 0; i < 100000; ++i) ps.push_back(1.0 - std::ldexp(s(0.5, 1.0), static_cast<int>(s(-53, -3))));  // upper tail
  for (double p : ps) {
    if (p > 0.0 && p < 1.0) {
      ASSERT_EQ(bits_of(dm::normal_quantile(p)), bits_of(normal_quantile_before_generic(p))) << "p = " << p;
    }
  }
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
