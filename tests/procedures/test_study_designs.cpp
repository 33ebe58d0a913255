// The studies' designs against the source (docs/experiments.md "The studies
// against the source", issue #37): the working-memory textures are one base
// gap set per texture, rearranged every presentation, and the
// familiarisation feels other maps; parameter mapping rates the two
// comparisons the source's figure stresses; the session-state vocabulary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "texel/error.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/session_state.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/io.hpp"

namespace ex = texel::experiment;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const fs::path protocols = fs::path(TEXEL_TEST_SOURCE_DIR) / "examples" / "protocols";

ex::Session make(const fs::path& path, const std::string& participant = "S01") {
  ex::Protocol p = ex::load_protocol(path.string());
  ex::SessionContext c;
  c.participant = participant;
  c.session_id = 1;
  c.seed = ex::session_seed(p.seed, participant);
  return ex::Session(std::move(p), std::move(c));
}

/// The texture of a one-region stimulus document.
json texture_of(const std::string& document) {
  const json d = json::parse(document);
  return d.contains("regions") ? d["regions"][0]["texture"] : d["texture"];
}

}  // namespace

TEST(StudyDesigns, WorkingMemoryRearrangesOneBaseGapSetPerTexture) {
  auto s = make(protocols / "working-memory.json");
  const ex::SimulatedParticipant sim(ex::simulation_observer(s.protocol().observer, "default"), s);
  // Familiarisation: its maps' seeds.
  std::set<std::uint64_t> familiar;
  for (const auto& st : s.question().stimuli) familiar.insert(texture_of(st.document_json)["seed"].get<std::uint64_t>());
  (void)s.answer(sim.respond(s));
  std::map<std::string, std::set<std::uint64_t>> bases;  // reference → seeds presented
  std::set<std::pair<std::string, std::int64_t>> arrangements;
  int presentations = 0, test_trials = 0;
  while (!s.finished()) {
    const ex::Question& q = s.question();
    const json a = texture_of(q.stimuli[0].document_json), b = texture_of(q.stimuli[1].document_json);
    for (const json* t : {&a, &b}) {
      bases[(*t)["name"].get<std::string>()].insert((*t)["seed"].get<std::uint64_t>());
      EXPECT_GE((*t)["params"]["shuffle"].get<std::int64_t>(), 1);  // a rearrangement, never the drawn order
    }
    if (s.truth().correct_answer == "different") {
      EXPECT_NE(a, b);
    } else {
      EXPECT_EQ(a, b);
    }
    if (!q.practice) {
      ++test_trials;
      presentations += 2;
      arrangements.insert({a["name"].get<std::string>(), a["params"]["shuffle"].get<std::int64_t>()});
      arrangements.insert({b["name"].get<std::string>(), b["params"]["shuffle"].get<std::int64_t>()});
    }
    (void)s.answer(sim.respond(s));
  }
  // One base per texture for the whole session (training and test) …
  ASSERT_EQ(bases.size(), 3u);
  for (const auto& [name, seeds] : bases) {
    EXPECT_EQ(seeds.size(), 1u) << name;
    // … and the familiarisation felt other maps (friction maps not used in the experiment).
    EXPECT_EQ(familiar.count(*seeds.begin()), 0u) << name;
  }
  // 32 test trials, 64 presented textures, each trial its own arrangements.
  EXPECT_EQ(test_trials, 32);
  EXPECT_EQ(presentations, 64);
  EXPECT_GE(arrangements.size(), 48u);  // "same" trials repeat their first texture
}

TEST(StudyDesigns, WorkingMemoryVersionOneKeepsANewGapSetPerTrial) {
  auto s = make(fs::path(TEXEL_TEST_SOURCE_DIR) / "tests/experiment/data/working-memory-v1.json");
  const ex::SimulatedParticipant sim(ex::simulation_observer(s.protocol().observer, "default"), s);
  std::set<std::uint64_t> seeds;
  while (!s.finished()) {
    const ex::Question& q = s.question();
    if (q.task == "same-different") seeds.insert(texture_of(q.stimuli[0].document_json)["seed"].get<std::uint64_t>());
    (void)s.answer(sim.respond(s));
  }
  EXPECT_GT(seeds.size(), 30u);  // a fresh draw every trial, as before
}

TEST(StudyDesigns, BaseTexturesKeyIsValidated) {
  const std::string head = R"({"format": "texel-protocol", "version": 2, "name": "f", "study": "working-memory",
    "blocks": [{"name": "t", "task": "same-different", "trials_per_condition": 2,
      "conditions": [{"name": "c", "stimulus": "x"}], )";
  const auto error_of = [](const std::string& text) {
    try {
      (void)ex::parse_protocol(text, "p.json");
    } catch (const texel::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string patches = R"("stimuli": {"x": {"texture": {"kind": "reference", "name": "patch-2.5"},
                                                  "different": {"kind": "reference", "name": "patch-4.6"}}})";
  EXPECT_EQ(error_of(head + patches + R"(, "base_textures": "per-texture"}]})"), "");
  EXPECT_NE(error_of(head + patches + R"(, "base_textures": "sometimes"}]})")
                .find("base_textures is 'sometimes'; allowed: per-trial, per-texture"),
            std::string::npos);
  const std::string texels =
      R"("stimuli": {"x": {"texture": {"kind": "texel", "central_pitch_db": 6, "irregularity_db": 0, "texel_length_mm": 1},
                                                 "different": {"kind": "texel", "central_pitch_db": 7, "irregularity_db": 0, "texel_length_mm": 1}}})";
  EXPECT_NE(error_of(head + texels + R"(, "base_textures": "per-texture"}]})").find("not a patch-* reference"),
            std::string::npos);
}

TEST(StudyDesigns, ParameterMappingRatesTheComparisonsTheSourceStresses) {
  const ex::Protocol p = ex::load_protocol((protocols / "parameter-mapping.json").string());
  const json doc = json::parse(texel::read_file((protocols / "parameter-mapping.json").string()));
  const json& pairs = doc["blocks"][1]["pairs"];
  EXPECT_EQ(pairs.size(), 25u);  // 25 of the 81, as the source
  auto rated = [&](const std::string& a, const std::string& b) {
    for (const auto& x : pairs) {
      const std::string r = x["reference"], m = x["rendering"]["match_of"];
      if ((r == "bandpass-" + a && m == "bandpass-" + b) || (r == "bandpass-" + b && m == "bandpass-" + a)) return true;
    }
    return false;
  };
  EXPECT_TRUE(rated("f1-z5", "f20-z5"));
  EXPECT_TRUE(rated("f20-z0.05", "f20-z5"));
  for (const char* own : {"f1-z0.05", "f4-z0.5", "f20-z5"}) EXPECT_TRUE(rated(own, own)) << own;
  (void)p;
}

TEST(SessionStates, OneVocabularyWithParseAndDerivation) {
  for (const auto s :
       {ex::SessionState::running, ex::SessionState::paused, ex::SessionState::stopped, ex::SessionState::finished})
    EXPECT_EQ(ex::parse_session_state(ex::to_string(s)), s);
  try {
    (void)ex::parse_session_state("suspended", "state");
    FAIL();
  } catch (const texel::InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "state: 'suspended' is not a session state (allowed: running, paused, stopped, finished)");
  }
  ex::SessionInfo info;
  info.status = "running";  // stored: not finished
  EXPECT_EQ(ex::session_state(info), ex::SessionState::stopped);
  EXPECT_EQ(ex::session_state(info, true), ex::SessionState::running);
  EXPECT_EQ(ex::session_state(info, true, true), ex::SessionState::paused);
  info.status = "finished";
  EXPECT_EQ(ex::session_state(info, true, true), ex::SessionState::finished);
  EXPECT_EQ(json::parse(ex::to_json(info))["state"], "finished");
}

TEST(StudyDesigns, QuantizationFallbacksAreTodaysEncoderEstimates) {
  // The trained rater's match stands in as the encoder's estimate of each
  // reference (what the free-exploration rows carry as the reference's
  // position), limited to the device ranges: a fallback never goes stale.
  auto s = make(protocols / "free-exploration.json");
  const ex::SimulatedParticipant sim(ex::simulation_observer(s.protocol().observer, "default"), s);
  std::map<std::string, std::pair<double, double>> estimate;
  while (!s.finished()) {
    const ex::StoredTrial t = s.answer(sim.respond(s));
    if (t.row.task == "match") estimate[t.row.reference] = {t.row.reference_pitch_db, t.row.reference_irregularity_db};
  }
  ASSERT_EQ(estimate.size(), 9u);
  const json doc = json::parse(texel::read_file((protocols / "quantization.json").string()));
  for (const auto& pair : doc["blocks"][0]["pairs"]) {
    const std::string ref = pair["reference"];
    const json& t = pair["rendering"]["texture"];
    ASSERT_TRUE(estimate.count(ref)) << ref;
    const auto [p, i] = estimate[ref];
    EXPECT_NEAR(t["central_pitch_db"].get<double>(), std::clamp(p, -20.0, 19.7), 0.006) << ref;
    EXPECT_NEAR(t["irregularity_db"].get<double>(), std::clamp(i, -30.0, 5.0), 0.006) << ref;
  }
  // The source's rater put the waveforms near 0 dB and 4sin near 7.8 dB.
  for (const char* w : {"square", "tri", "saw"}) EXPECT_LT(std::abs(estimate[w].first), 1.5) << w;
  EXPECT_NEAR(estimate["4sin"].first, 7.8, 1.0);
}
