// Coarse profiles (coarse.hpp, docs/algorithm.md §7): c_k sampled at texel centres
// for each kind, validation, and the position_mm,value CSV reader.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <unistd.h>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "texel/coarse.hpp"
#include "texel/error.hpp"

using namespace texel;
namespace fs = std::filesystem;

namespace {

using texel::test_support::TempDir;

std::string format_error(const std::string& path) {
  return test_support::message_of<FormatError>([&] { read_profile_csv(path); });
}

}  // namespace

TEST(Coarse, ConstantProfile) {
  const auto c = sample_at_texel_centres(ConstantProfile{0.3}, Millimetres(0.25), 5);
  EXPECT_EQ(c, std::vector<double>(5, 0.3));
}

TEST(Coarse, SineProfileIsSampledAtTexelCentres) {
  // c(x) = 0.5 + 0.5·sin(2π(x/period + phase/360)), x = (k + 0.5)·L.
  const SineProfile p{Millimetres(5.0), 90.0};
  const auto c = sample_at_texel_centres(p, Millimetres(0.25), 40);
  ASSERT_EQ(c.size(), 40u);
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double x = (static_cast<double>(k) + 0.5) * 0.25;
    EXPECT_NEAR(c[k], 0.5 + 0.5 * std::sin(2 * std::numbers::pi * (x / 5.0 + 0.25)), 1e-14) << k;
    EXPECT_GE(c[k], 0.0);
    EXPECT_LE(c[k], 1.0);
  }
}

TEST(Coarse, ValuesProfileNeedsOneValuePerTexel) {
  const ValuesProfile v{{0.1, 0.2, 0.3}};
  EXPECT_EQ(sample_at_texel_centres(v, Millimetres(1.0), 2), (std::vector<double>{0.1, 0.2}));
  EXPECT_THROW(sample_at_texel_centres(v, Millimetres(1.0), 4), InvalidArgument);
}

TEST(Coarse, PointsProfileInterpolatesLinearlyAndHoldsBeyondTheEnds) {
  const PointsProfile p{{{1.0, 0.0}, {3.0, 1.0}}};
  // Centres at 0.5, 1.5, 2.5, 3.5 mm.
  const auto c = sample_at_texel_centres(p, Millimetres(1.0), 4);
  EXPECT_EQ(c, (std::vector<double>{0.0, 0.25, 0.75, 1.0}));
}

TEST(Coarse, SampledProfileInterpolates) {
  const SampledProfile p{Millimetres(0.5), {0.0, 1.0, 0.0}};
  const auto c = sample_at_texel_centres(p, Millimetres(0.5), 3);  // centres 0.25, 0.75, 1.25
  EXPECT_EQ(c, (std::vector<double>{0.5, 0.5, 0.0}));
}

TEST(Coarse, ValidationNamesTheField) {
  auto msg = [](const CoarseProfile& p) { return test_support::message_of<InvalidArgument>([&] { validate(p); }); };
  EXPECT_NE(msg(ConstantProfile{1.5}).find("coarse.value"), std::string::npos);
  EXPECT_NE(msg(SineProfile{Millimetres(-5.0), 0.0}).find("coarse.period_mm"), std::string::npos);
  EXPECT_NE(msg(ValuesProfile{{0.5, -0.1}}).find("coarse.values[1]"), std::string::npos);
  EXPECT_NE(msg(PointsProfile{{{0.0, 0.5}, {0.0, 0.6}}}).find("strictly increasing"), std::string::npos);
  EXPECT_EQ(msg(PointsProfile{{{0.0, 0.5}, {1.0, 0.6}}}), "(no exception)");
}

TEST(Coarse, ReadsCsvWithOptionalHeaderCommentsAndCrlf) {
  TempDir d;
  const auto path = d.write("p.csv", "position_mm,value\r\n# comment\r\n0,0.5\r\n10, 1\r\n20;0\r\n\r\n");
  const auto p = read_profile_csv(path);
  ASSERT_EQ(p.points.size(), 3u);
  EXPECT_EQ(p.points[0], (std::pair{0.0, 0.5}));
  EXPECT_EQ(p.points[1], (std::pair{10.0, 1.0}));
  EXPECT_EQ(p.points[2], (std::pair{20.0, 0.0}));
}

TEST(Coarse, RejectsMalformedCsvNamingFileAndLine) {
  TempDir d;
  const auto bad_number = d.write("a.csv", "0,0.5\n1,abc\n");
  EXPECT_NE(format_error(bad_number).find("a.csv:2"), std::string::npos) << format_error(bad_number);
  const auto one_column = d.write("b.csv", "0,0.5\n1\n");
  EXPECT_NE(format_error(one_column).find("b.csv:2"), std::string::npos);
  const auto decreasing = d.write("c.csv", "0,0.5\n2,0.6\n1,0.7\n");
  EXPECT_NE(format_error(decreasing).find("increasing"), std::string::npos) << format_error(decreasing);
  const auto out_of_range = d.write("d.csv", "0,0.5\n1,1.5\n");
  EXPECT_NE(format_error(out_of_range).find("0 … 1"), std::string::npos) << format_error(out_of_range);
  const auto empty = d.write("e.csv", "position_mm,value\n");
  EXPECT_NE(format_error(empty).find("no position_mm,value rows"), std::string::npos);
  EXPECT_THROW(read_profile_csv((d.path / "missing.csv").string()), IoError);
}
