// Units as types (units.hpp): literals, same-unit arithmetic, the dB scale of
// docs/algorithm.md §2 (power form, re 1 cpm), and that different units do not mix.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <type_traits>

#include "texel/level.hpp"
#include "texel/units.hpp"

using namespace texel;
using namespace texel::literals;

// Distinct units must not convert into one another, nor from a bare double.
static_assert(!std::is_convertible_v<Millimetres, Decibels>);
static_assert(!std::is_constructible_v<Decibels, Millimetres>);
static_assert(!std::is_constructible_v<CyclesPerMm, Decibels>);
static_assert(!std::is_convertible_v<double, Millimetres>);
static_assert(!std::is_convertible_v<Hertz, CyclesPerMm>);
template <class A, class B>
concept Addable = requires(A a, B b) {
  a + b;
};
static_assert(Addable<Millimetres, Millimetres>);
static_assert(!Addable<Millimetres, Decibels>);
static_assert(!Addable<CyclesPerMm, Hertz>);
// A level in dB (a gain, a peak below the highest) is not a frequency in dB.
static_assert(!std::is_convertible_v<DecibelsLevel, Decibels>);
static_assert(!std::is_constructible_v<Decibels, DecibelsLevel>);
static_assert(!std::is_constructible_v<DecibelsLevel, Decibels>);
static_assert(!Addable<Decibels, DecibelsLevel>);

TEST(Units, LiteralsCarryTheirValue) {
  EXPECT_EQ((0.25_mm).value(), 0.25);
  EXPECT_EQ((3_mm).value(), 3.0);
  EXPECT_EQ((10_dB).value(), 10.0);
  EXPECT_EQ((-12.5_dB).value(), -12.5);
  EXPECT_EQ((94.3_cpm).value(), 94.3);
  EXPECT_EQ((440_Hz).value(), 440.0);
  EXPECT_EQ((0.5_s).value(), 0.5);
  EXPECT_EQ((100_mm_per_s).value(), 100.0);
  static_assert(std::is_same_v<decltype(1_mm), Millimetres>);
  static_assert(std::is_same_v<decltype(-40.0_level_dB), DecibelsLevel>);
  EXPECT_EQ((-40.0_level_dB).value(), -40.0);
  static_assert(std::is_same_v<decltype(1.0_dB), Decibels>);
}

TEST(Units, SameUnitArithmetic) {
  Millimetres x = 1.5_mm + 0.25_mm;
  EXPECT_EQ(x.value(), 1.75);
  x -= 0.75_mm;
  EXPECT_EQ(x.value(), 1.0);
  x += 2_mm;
  EXPECT_EQ(x, 3_mm);
  EXPECT_EQ((2.0 * x).value(), 6.0);
  EXPECT_EQ((x * 2.0).value(), 6.0);
  EXPECT_EQ((x / 4.0).value(), 0.75);
  EXPECT_EQ(x / 1.5_mm, 2.0);  // a ratio of like quantities is a plain number
  EXPECT_EQ((-x).value(), -3.0);
  EXPECT_LT(1_mm, 2_mm);
  EXPECT_GT(10_dB, 9.5_dB);
}

TEST(Units, DecibelScaleIsPowerFormRe1Cpm) {
  // docs/algorithm.md §2: 10 cpm = 10 dB, 1 cpm = 0 dB, 0.1 cpm = −10 dB, 94 cpm ≈ 19.7 dB.
  EXPECT_NEAR(to_cpm(10_dB).value(), 10.0, 1e-14);
  EXPECT_NEAR(to_cpm(0_dB).value(), 1.0, 1e-15);
  EXPECT_NEAR(to_cpm(-10_dB).value(), 0.1, 1e-16);
  EXPECT_NEAR(to_cpm(-20_dB).value(), 0.01, 1e-17);
  EXPECT_NEAR(to_cpm(6_dB).value(), std::pow(10.0, 0.6), 1e-14);
  EXPECT_NEAR(to_db(10_cpm).value(), 10.0, 1e-14);
  EXPECT_NEAR(to_db(0.1_cpm).value(), -10.0, 1e-14);
  EXPECT_NEAR(to_db(94_cpm).value(), 19.731278535996985, 1e-12);
  EXPECT_EQ(to_db(1_cpm).value(), 0.0);
}

RC_GTEST_PROP(Units, DecibelRoundTrip, ()) {
  const double db = *rc::gen::inRange(-400000, 400000) / 10000.0;  // -40 … 40 dB
  const double back = to_db(to_cpm(Decibels(db))).value();
  RC_ASSERT(std::fabs(back - db) <= 1e-12);
  RC_ASSERT(std::fabs(to_cpm(Decibels(db)).value() / std::pow(10.0, db / 10.0) - 1.0) <= 1e-14);
}

TEST(Units, TemporalFrequencyAndTravel) {
  // A finger at 100 mm/s over 10 cpm feels 1000 Hz; in 0.5 s it moves 50 mm.
  EXPECT_EQ(temporal(10_cpm, 100_mm_per_s), 1000_Hz);
  EXPECT_EQ(travelled(100_mm_per_s, 0.5_s), 50_mm);
}
