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
  ASSERT_EQ(len.blocks.size(), 2u);  // the untimed practice, then the staircase
  ASSERT_TRUE(len.blocks[1].staircase);
  const auto& s = *len.blocks[1].staircase;
  EXPECT_EQ(s.start_value, 26);
  ASSERT_EQ(s.step_sizes.size(), 8u);
  EXPECT_EQ(s.step_sizes[6], 2.5);
  EXPECT_EQ(s.step_sizes[7], 1.25);
  EXPECT_EQ(*s.n_reversals, 10);
  EXPECT_EQ(len.blocks[1].time_limit_s, 30);
  const auto coarse = ex::load_protocol((protocols / "coarse-features.json").string());
  ASSERT_EQ(coarse.blocks.size(), 3u);
  EXPECT_EQ(coarse.blocks[1].texture.number("fine_strength"), 0.5);
  EXPECT_EQ(*coarse.blocks[0].staircase->max_value, 1.0);
  const auto wm = ex::load_protocol((protocols / "working-memory.json").string());
  EXPECT_EQ(wm.planned_trials(), 1 + 40);  // the familiarisation, then 8 training and 32 test trials
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

// ------------------------------------------------------------ versions (issue #23)

namespace {
ex::Protocol shipped(const std::string& name) { return ex::load_protocol((protocols / (name + ".json")).string()); }
std::string with_version(std::string text, int version) {
  const std::string from = "\"version\": 1";
  text.replace(text.find(from), from.size(), "\"version\": " + std::to_string(version));
  return text;
}
}  // namespace

TEST(ProtocolVersions, StaircaseDefaultsFollowTheVersion) {
  // Version 1 keeps PsychoPy's defaults: the initial 1-up/1-down rule and the
  // value computed after the last answer as the threshold.
  const auto v1 = ex::parse_protocol(minimal_oddity);
  EXPECT_EQ(v1.version, 1);
  EXPECT_TRUE(v1.blocks[0].staircase->apply_initial_rule);
  EXPECT_EQ(v1.blocks[0].staircase->end_value, ex::EndValue::next);
  // Version 2: the source's reading.
  const auto v2 = ex::parse_protocol(with_version(minimal_oddity, 2));
  EXPECT_EQ(v2.version, 2);
  EXPECT_FALSE(v2.blocks[0].staircase->apply_initial_rule);
  EXPECT_EQ(v2.blocks[0].staircase->end_value, ex::EndValue::last_presented);
  // Both switchable in either version.
  std::string t = with_version(minimal_oddity, 2);
  t.replace(t.find("\"n_down\": 3"), 11, R"("n_down": 3, "apply_initial_rule": true, "end_value": "next")");
  const auto v2psy = ex::parse_protocol(t);
  EXPECT_TRUE(v2psy.blocks[0].staircase->apply_initial_rule);
  EXPECT_EQ(v2psy.blocks[0].staircase->end_value, ex::EndValue::next);
  t.replace(t.find("\"next\""), 6, "\"final\"");
  EXPECT_NE(error_of(t).find("blocks[0].staircase.end_value: 'final' is not an end value (allowed: next, last-presented)"),
            std::string::npos)
      << error_of(t);
  // Version 3 changes only the 2-D oddity's direction assignment.
  const auto v3 = ex::parse_protocol(with_version(minimal_oddity, 3));
  EXPECT_FALSE(v3.blocks[0].staircase->apply_initial_rule);
  EXPECT_EQ(v3.blocks[0].staircase->end_value, ex::EndValue::last_presented);
  EXPECT_NE(error_of(with_version(minimal_oddity, 4)).find("version 4 is newer"), std::string::npos);
}

TEST(ProtocolVersions, ShippedProtocolsAreVersionTwoWithTheSourcesStaircase) {
  for (const auto& name : {"working-memory", "texel-length", "texel-length-wide", "texel-length-visual-practice",
                           "parameter-mapping", "free-exploration", "quantization", "guided-exploration", "coarse-features"}) {
    const auto p = shipped(name);
    EXPECT_EQ(p.version, 2) << name;
    for (const auto& b : p.blocks) {
      if (!b.staircase) continue;
      EXPECT_FALSE(b.staircase->apply_initial_rule) << name;
      EXPECT_EQ(b.staircase->end_value, ex::EndValue::last_presented) << name;
    }
  }
  // The version-1 originals (kept for stored sessions) read as before.
  const auto old = ex::load_protocol((fs::path(TEXEL_TEST_SOURCE_DIR) / "tests/experiment/data/texel-length-v1.json").string());
  EXPECT_EQ(old.version, 1);
  EXPECT_TRUE(old.blocks[0].staircase->apply_initial_rule);
  EXPECT_EQ(old.blocks[0].staircase->end_value, ex::EndValue::next);
  EXPECT_EQ(*old.blocks[0].staircase->min_value, 0.25);
}

TEST(ProtocolVersions, TexelLengthIsThreeGroupsWithUntimedPracticeAndChapterFourRendering) {
  const std::pair<const char*, const char*> groups[] = {
      {"texel-length", "narrow"}, {"texel-length-wide", "wide"}, {"texel-length-visual-practice", "wide-visual-practice"}};
  for (const auto& [name, group] : groups) {
    const auto p = shipped(name);
    ASSERT_EQ(p.blocks.size(), 2u) << name;
    const auto& practice = p.blocks[0];
    const auto& main = p.blocks[1];
    EXPECT_TRUE(practice.practice) << name;
    EXPECT_EQ(practice.time_limit_s, 0) << name;  // practice trials are untimed
    EXPECT_EQ(practice.trials, 10) << name;       // about five minutes
    EXPECT_EQ(practice.show_maps, std::string(group) == "wide-visual-practice") << name;
    EXPECT_FALSE(main.practice);
    EXPECT_EQ(main.condition, group);  // the analysis compares groups by this label
    EXPECT_EQ(main.time_limit_s, 30);
    const double irregularity = *main.texture.number("irregularity_db");
    EXPECT_NEAR(irregularity, std::string(group) == "narrow" ? 0.7918 : 6.3347, 1e-9) << name;  // 1.2 or 4.3 cpm
    for (const auto* b : {&practice, &main}) {
      EXPECT_EQ(b->texture.number("band_min_cpm"), 1.0) << name;                          // no texel frequency below 1 cpm
      EXPECT_NE(b->texture.json.find("\"phase\":\"reset\""), std::string::npos) << name;  // abrupt texel boundaries
    }
    // No bounds the source does not have: only the variable's own validity range.
    EXPECT_EQ(*main.staircase->min_value, 1e-3);
    EXPECT_EQ(*main.staircase->max_value, 1000.0);
  }
}

TEST(ProtocolVersions, SawIsTheWaveformExemplar) {
  for (const auto& name : {"quantization", "guided-exploration"}) {
    const auto p = shipped(name);
    int saw = 0, square = 0;
    for (const auto& b : p.blocks) {
      for (const auto& r : b.references) {
        saw += r == "saw";
        square += r == "square";
      }
      for (const auto& pair : b.pairs) {
        if (pair.condition == "unquantized") continue;  // all nine references once
        saw += pair.reference == "saw";
        square += pair.reference == "square" || pair.rendering.match_of == "square";
      }
    }
    EXPECT_GT(saw, 0) << name;
    EXPECT_EQ(square, 0) << name;
  }
}

TEST(ProtocolVersions, FallbackRenderingsStayInsideTheDeviceRanges) {
  const auto q = shipped("quantization");
  for (const auto& pair : q.blocks[0].pairs) {
    EXPECT_LE(*pair.rendering.texture.number("irregularity_db"), 5.0) << pair.reference;
    EXPECT_GE(*pair.rendering.texture.number("irregularity_db"), -30.0) << pair.reference;
  }
  // Version 2 refuses a fallback outside the ranges; version 1 (stored sessions) keeps reading it.
  const std::string v1 = R"({"format": "texel-protocol", "version": 1, "name": "q", "study": "quantization",
    "blocks": [{"name": "r", "task": "rating", "scale": [1, 5], "pairs": [{"reference": "pink", "rendering": {
      "match_of": "pink", "from_protocol": "free-exploration",
      "texture": {"kind": "texel", "central_pitch_db": 11, "irregularity_db": 9.93, "texel_length_mm": 0.25}}}]}]})";
  EXPECT_EQ(error_of(v1), "(no exception)");
  EXPECT_NE(
      error_of(with_version(v1, 2)).find("blocks[0].pairs[0].rendering.texture.irregularity_db is 9.93; allowed: -30 … 5 dB"),
      std::string::npos)
      << error_of(with_version(v1, 2));
}

TEST(ProtocolVersions, WorkingMemoryUsesPatchTexturesAndFamiliarisation) {
  const auto p = shipped("working-memory");
  ASSERT_EQ(p.blocks.size(), 3u);
  const auto& fam = p.blocks[0];
  EXPECT_EQ(fam.task, "familiarisation");
  EXPECT_TRUE(fam.practice);
  EXPECT_EQ(fam.time_limit_s, 0);
  EXPECT_EQ(fam.duration_s, 300);
  ASSERT_EQ(fam.textures.size(), 4u);  // the four textures of the study
  for (const auto* b : {&p.blocks[1], &p.blocks[2]}) {
    EXPECT_TRUE(b->balance_order);
    for (const auto& ms : b->memory_stimuli) {
      // Patch references (2.6 mm patches, no fine texture), not texel textures.
      EXPECT_NE(ms.texture.json.find("\"kind\":\"reference\""), std::string::npos) << ms.name;
      if (ms.name == "wide") {
        EXPECT_NE(ms.texture.json.find("patch-13.5"), std::string::npos);
        EXPECT_NE(ms.different.json.find("patch-13.5"), std::string::npos);     // the same patches …
        EXPECT_NE(ms.different.json.find("\"shuffle\":1"), std::string::npos);  // … rearranged
      } else {
        EXPECT_NE(ms.texture.json.find("patch-2.5"), std::string::npos);
        EXPECT_NE(ms.different.json.find("patch-4.6"), std::string::npos);
      }
    }
  }
  EXPECT_NE(error_of(R"({"format": "texel-protocol", "version": 2, "name": "f", "study": "working-memory",
    "blocks": [{"name": "f", "task": "familiarisation", "textures": {}}]})")
                .find("blocks[0].textures must be an object of 1 … 16 named textures"),
            std::string::npos);
}
