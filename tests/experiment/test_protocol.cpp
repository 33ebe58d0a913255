// Protocol files: every shipped protocol validates; bad ones are refused with
// the field's path, the value and what is allowed.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "../support/expect.hpp"
#include "texel/error.hpp"
#include "texel/experiment/protocol.hpp"

namespace ex = texel::experiment;
namespace fs = std::filesystem;

namespace {
const fs::path protocols = fs::path(TEXEL_TEST_SOURCE_DIR) / "examples" / "protocols";

std::string error_of(const std::string& text) {
  return texel::test_support::message_of([&] { (void)ex::parse_protocol(text, "p.json"); });
}

const std::string minimal_oddity = R"({"format": "texel-protocol", "version": 1, "name": "t", "study": "texel-length",
  "blocks": [{"name": "b", "task": "oddity",
    "texture": {"kind": "texel", "central_pitch_db": 6, "irregularity_db": 0, "texel_length_mm": 26},
    "staircase": {"variable": "texel_length_mm", "start": 26, "step_sizes": [2.5], "n_up": 1, "n_down": 3}}]})";
}  // namespace

TEST(Protocol, EveryShippedProtocolValidates) {
  int n = 0;
  for (const auto& name : {"working-memory", "texel-length", "texel-length-wide", "texel-length-visual-practice",
                           "parameter-mapping", "free-exploration", "quantization", "guided-exploration", "coarse-features"}) {
    const auto p = ex::load_protocol((protocols / (std::string(name) + ".json")).string());
    EXPECT_EQ(p.name, name);
    EXPECT_FALSE(p.blocks.empty());
    ++n;
  }
  EXPECT_EQ(n, 9);
}

TEST(Protocol, SpecValuesOfTheShippedStudies) {
  const auto len = ex::load_protocol((protocols / "texel-length.json").string());
  ASSERT_TRUE(len.blocks[0].staircase);
  const auto& s = *len.blocks[0].staircase;
  EXPECT_EQ(s.start_value, 26);
  ASSERT_EQ(s.step_sizes.size(), 8u);
  EXPECT_EQ(s.step_sizes[6], 2.5);
  EXPECT_EQ(s.step_sizes[7], 1.25);
  EXPECT_EQ(*s.n_reversals, 10);
  EXPECT_EQ(len.blocks[0].time_limit_s, 30);
  const auto coarse = ex::load_protocol((protocols / "coarse-features.json").string());
  ASSERT_EQ(coarse.blocks.size(), 3u);
  EXPECT_EQ(coarse.blocks[1].texture.number("fine_strength"), 0.5);
  EXPECT_EQ(*coarse.blocks[0].staircase->max_value, 1.0);
  const auto wm = ex::load_protocol((protocols / "working-memory.json").string());
  EXPECT_EQ(wm.planned_trials(), 40);
  EXPECT_EQ(ex::load_protocol((protocols / "quantization.json").string()).planned_trials(), 27);
  EXPECT_EQ(ex::load_protocol((protocols / "guided-exploration.json").string()).planned_trials(), 3 * 20 + 9);
}

TEST(Protocol, BadProtocolsNameFieldValueAndAllowed) {
  EXPECT_NE(error_of("{"), "");
  EXPECT_NE(error_of(R"({"format": "texel-document"})").find("texel-protocol"), std::string::npos);
  std::string t = minimal_oddity;
  EXPECT_EQ(error_of(t), "(no exception)");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = t;
    s.replace(s.find(from), from.size(), to);
    return error_of(s);
  };
  EXPECT_NE(with("\"texel-length\"", "\"nosuch\"").find("study is 'nosuch'; allowed"), std::string::npos);
  EXPECT_NE(with("\"oddity\"", "\"dance\"").find("blocks[0].task is 'dance'"), std::string::npos);
  EXPECT_NE(with("\"n_up\": 1", "\"n_up\": 0").find("blocks[0].staircase.n_up is 0"), std::string::npos);
  EXPECT_NE(with("\"variable\": \"texel_length_mm\"", "\"variable\": \"colour\"").find("variable is 'colour'"),
            std::string::npos);
  EXPECT_NE(with("\"n_down\": 3", "\"n_down\": 3, \"typo\": 1").find("unknown key 'typo'"), std::string::npos);
  EXPECT_NE(with("\"texel_length_mm\": 26}", "\"texel_length_mm\": -1}").find("texel_length_mm"), std::string::npos);
  EXPECT_NE(with("\"version\": 1", "\"version\": 99").find("upgrade Texel"), std::string::npos);
  EXPECT_NE(with("\"name\": \"t\"", "\"name\": \"a b\"").find("name is 'a b'"), std::string::npos);
}
