// Files written by the MPEG-I Haptics reference software (third-party test
// data, read from $TEXEL_THIRD_PARTY/mpeg-haptics-rm-outputs, which .ci/run
// sets; skipped with a message without it): every one imports, and the
// spatial ones give back the Texel map of texel-fine-seed7-id1.hjif within the
// stated tolerance (docs/interchange.md "Round trips through the reference
// software").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "interchange_support.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/signal.hpp"
#include "texel/surface.hpp"

using namespace texel;

namespace {

std::string rm_dir() {
  const char* root = std::getenv("TEXEL_THIRD_PARTY");
  if (!root || !*root) return "";
  const std::string dir = std::string(root) + "/mpeg-haptics-rm-outputs";
  return std::filesystem::is_directory(dir) ? dir : "";
}

#define NEED_THIRD_PARTY()                                                                  \
  const std::string dir = rm_dir();                                                         \
  if (dir.empty())                                                                          \
  GTEST_SKIP() << "TEXEL_THIRD_PARTY is not set (or has no mpeg-haptics-rm-outputs/): the " \
                  "reference software's files are not checked"

/// Max |file's samples − the original Texel map| on the original's device grid.
double error_against_original(const hjif::Experience& e, const std::string& dir) {
  const hjif::Experience original = hjif::load_hjif(dir + "/texel-fine-seed7-id1.hjif");
  EXPECT_TRUE(original.carried.has_value()) << original.carried_rejected;
  if (!original.carried) return 1.0;
  return test_support::max_map_error(e, *original.carried);
}

}  // namespace

TEST(ReferenceSoftware, ItsJsonReEncodingReproducesTheMapWithinTheExportTolerance) {
  NEED_THIRD_PARTY();
  const hjif::Experience e = hjif::load_hjif(dir + "/rm-reencoded.hjif");  // no phase, id or base_signal in its effects
  const double err = error_against_original(e, dir);
  std::cout << "[ rm ] rm-reencoded.hjif: max error " << err << ", carried document " << (e.carried ? "used" : e.carried_rejected)
            << "\n";
  // 1/512, plus the reference software's single-precision amplitudes (≤ 6e-8).
  EXPECT_LE(err, hjif::default_tolerance + 1e-6);
  EXPECT_TRUE(e.carried.has_value()) << e.carried_rejected;
}

TEST(ReferenceSoftware, ItsBinaryStreamReproducesTheMapWithinTheToleranceAndTheAmplitudeCode) {
  NEED_THIRD_PARTY();
  const hjif::Experience e = hmpg::load(dir + "/rm-binary.hmpg");
  const double err = error_against_original(e, dir);
  std::cout << "[ rm ] rm-binary.hmpg: max error " << err << "\n";
  // The reference writer truncates to the 8-bit code below (up to one whole step, 2/255), and its
  // gain code for 1, computed in single precision, reads 1.000164.
  EXPECT_LE(err, hjif::default_tolerance + hmpg::amplitude_step + 1.7e-4);
  EXPECT_NE(e.description.find("texel-document:"), std::string::npos);  // its 525-byte description, length wrapped
  const std::string bytes = read_file(dir + "/rm-binary.hmpg");
  const std::string text = hmpg::decode(std::as_bytes(std::span(bytes.data(), bytes.size())));
  EXPECT_EQ(hjif::conformance_errors(text).size(), 1u);  // its date, a day without a time (Texel's old export)
}

TEST(ReferenceSoftware, ItsTemporalFileImportsAtASwipeSpeed) {
  NEED_THIRD_PARTY();
  const std::string path = dir + "/rm-from-ahap.hjif";
  EXPECT_THROW((void)load_signal(path, SignalOptions{}), InvalidArgument);  // a speed is needed
  SignalOptions o;
  o.swipe_speed = MmPerSecond(100.0);
  const Signal s = load_signal(path, o);
  ASSERT_GT(s.samples.size(), 100u);
  EXPECT_TRUE(std::all_of(s.samples.begin(), s.samples.end(), [](double v) { return std::isfinite(v); }));
  EXPECT_GT(*std::max_element(s.samples.begin(), s.samples.end()), 0.0);
  // Its transient (0 … 22 ms) and its vectorial wave (100 … 600 ms): 60 mm at 100 mm/s.
  EXPECT_NEAR(hjif::extent_mm(hjif::load_hjif(path), MmPerSecond(100.0)), 60.0, 0.01);
}

TEST(ReferenceSoftware, TheCheckerAndTheReaderJudgeItsFilesAsDocumented) {
  NEED_THIRD_PARTY();
  for (const char* name : {"texel-fine-seed7-id1.hjif", "rm-reencoded.hjif", "rm-from-ahap.hjif"}) {
    SCOPED_TRACE(name);
    const std::string text = read_file(dir + "/" + name);
    EXPECT_NO_THROW((void)hjif::parse_hjif(text, name));  // read: the liberal reader
    // Not RFC 3339 (a day, or a space before the time): refused by the strict reading, as by a format-checking validator.
    const auto errors = hjif::schema_errors(text);
    ASSERT_FALSE(errors.empty());
    EXPECT_EQ(errors.front().rfind("date is", 0), 0u) << errors.front();
  }
}
