// Distributed irregularity (docs/experiments.md "Distributed irregularity"):
// the playback oddity's design (every cell balanced, the odd interval's
// playback counterbalanced, controls), stimuli that are what they claim
// (pair identical, the odd one in the other playback, the sequential one
// shifted), the refusals, resume, and the simulated cohort through the
// analysis: the PSE recovered with its bootstrap CI under the observer's
// hypothesis and under the null one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "../support/expect.hpp"
#include "../support/sessions.hpp"
#include "../support/temp_dir.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/io.hpp"
#include "texel/multichannel.hpp"

namespace ex = texel::experiment;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const fs::path shipped_path = fs::path(TEXEL_TEST_SOURCE_DIR) / "examples" / "protocols" / "distributed-irregularity.json";

using texel::test_support::session_of;

std::string playback_of(const std::string& document) { return json::parse(document)["playback"]["mode"].get<std::string>(); }
double irregularity_of(const std::string& document) {
  return json::parse(document)["regions"][0]["texture"]["irregularity_db"].get<double>();
}

std::vector<ex::TrialRow> cohort(const ex::Protocol& p, const std::string& spec, int participants) {
  std::vector<ex::TrialRow> rows;
  for (int k = 0; k < participants; ++k) {
    auto s = session_of(p, "P" + std::to_string(k + 1));
    const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, spec), s);
    while (!s.finished()) rows.push_back(s.answer(sim.respond(s)).row);
  }
  return rows;
}

}  // namespace

TEST(DistributedIrregularity, EveryCellIsBalancedAndTheStimuliAreWhatTheyClaim) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  ASSERT_EQ(p.device, "pad-4");
  auto s = session_of(p);
  const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "default"), s);
  std::map<std::tuple<double, double, std::string>, int> cells;  // (level, shift, arrangement) → trials
  std::map<std::string, int> odd_positions;
  int trials = 0;
  while (!s.finished()) {
    const ex::Question& q = s.question();
    const ex::TrialTruth& t = s.truth();
    ASSERT_EQ(q.stimuli.size(), 3u);
    const int odd = std::stoi(t.correct_answer) - 1;
    const std::string& pair = q.stimuli[static_cast<std::size_t>((odd + 1) % 3)].document_json;
    const std::string& odd_doc = q.stimuli[static_cast<std::size_t>(odd)].document_json;
    EXPECT_EQ(q.stimuli[static_cast<std::size_t>((odd + 2) % 3)].document_json, pair) << "the pair is one texture shown twice";
    EXPECT_NE(odd_doc, pair);
    const double level = t.rendering->irregularity_db;
    if (t.condition == "control") {
      EXPECT_EQ(playback_of(pair), "sequential");
      EXPECT_EQ(playback_of(odd_doc), "sequential");
      EXPECT_EQ(irregularity_of(pair), level);
      EXPECT_EQ(irregularity_of(odd_doc), level);
    } else {
      const bool odd_simultaneous = t.condition == "odd-simultaneous";
      ASSERT_TRUE(odd_simultaneous || t.condition == "odd-sequential") << t.condition;
      const std::string& simultaneous = odd_simultaneous ? odd_doc : pair;
      const std::string& sequential = odd_simultaneous ? pair : odd_doc;
      EXPECT_EQ(playback_of(simultaneous), "simultaneous");
      EXPECT_EQ(playback_of(sequential), "sequential");
      EXPECT_EQ(irregularity_of(simultaneous), level);
      EXPECT_DOUBLE_EQ(irregularity_of(sequential), level + t.intensity);
    }
    // Nothing of the condition reaches the participant's screen (the task's
    // name does, as every task's: the same on every trial).
    const std::string screen = q.participant_json();
    for (const char* word : {"simultaneous", "sequential", "control", "irregularity", "shift"})
      EXPECT_EQ(screen.find(word), std::string::npos) << word << " in " << screen;
    if (!q.practice) {
      ++cells[{level, t.condition == "control" ? 0.0 : t.intensity, t.condition}];
      ++odd_positions[t.correct_answer];
      ++trials;
    }
    (void)s.answer(sim.respond(s));
  }
  EXPECT_EQ(trials, 2 * (6 * 4 + 4));
  for (double level : {0.7918, 6.3347}) {
    for (double shift : {-9.0, -6.0, -3.0, 0.0, 3.0, 6.0}) {
      EXPECT_EQ((cells[{level, shift, "odd-simultaneous"}]), 2) << level << " " << shift;
      EXPECT_EQ((cells[{level, shift, "odd-sequential"}]), 2) << level << " " << shift;
    }
    EXPECT_EQ((cells[{level, 0.0, "control"}]), 4) << level;
  }
  for (const char* position : {"1", "2", "3"}) EXPECT_GE(odd_positions[position], 10) << position;
}

// Simultaneous channels each play a chain of their own; sequential ones the
// texture's one chain on every actuator.
TEST(DistributedIrregularity, SimultaneousStimuliDrawEveryActuatorsOwnTexels) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  auto s = session_of(p);
  for (int n = 0; n < 8 && !s.finished(); ++n) {
    for (const auto& st : s.question().stimuli) {
      const auto channels = texel::prepare_channels(texel::parse_document(st.document_json));
      ASSERT_EQ(channels.size(), 4u);
      const auto first = texel::channel_texel_frequencies(channels[0]);
      ASSERT_FALSE(first.empty());
      for (std::size_t c = 1; c < 4; ++c) {
        if (playback_of(st.document_json) == "simultaneous")
          EXPECT_NE(texel::channel_texel_frequencies(channels[c]), first) << c;
        else
          EXPECT_EQ(texel::channel_texel_frequencies(channels[c]), first) << c;
      }
    }
    ex::Response r;
    r.choice = "1";
    (void)s.answer(r);
  }
}

TEST(DistributedIrregularity, BadProtocolsNameTheField) {
  json base = json::parse(texel::read_file(shipped_path.string()));
  const auto error = [&](const std::function<void(json&)>& edit) {
    json p = base;
    edit(p);
    return texel::test_support::message_of([&] { (void)ex::parse_protocol(p.dump(), "d.json"); });
  };
  EXPECT_NE(error([](json& p) { p["device"] = "tpad"; })
                .find("device is 'tpad', which has 1 actuator; task 'playback-oddity' plays texels side by side and needs a "
                      "device with 2 or more actuators (e.g. pad-4)"),
            std::string::npos);
  EXPECT_NE(error([](json& p) {
              p["blocks"][1]["shifts_db"] = {-9, 40};
            }).find("blocks[1].shifts_db: level 0.7918 dB + shift 40 dB is 40.7918 dB, outside Irregularity's -60 … 40 dB"),
            std::string::npos);
  EXPECT_NE(error([](json& p) {
              p["blocks"][1]["shifts_db"] = {3, 3};
            }).find("blocks[1].shifts_db[1] is 3, listed twice"),
            std::string::npos);
  EXPECT_NE(error([](json& p) {
              p["blocks"][1]["irregularity_levels_db"] = json::array();
            }).find("blocks[1].irregularity_levels_db must be an array of 1 … 16 numbers"),
            std::string::npos);
  EXPECT_NE(error([](json& p) { p["blocks"][1]["repeats"] = 0; }).find("blocks[1].repeats is 0; allowed: 1 … 1000"),
            std::string::npos);
  EXPECT_NE(error([](json& p) { p["blocks"][1]["variable"] = "irregularity_db"; }).find("variable"), std::string::npos);
  EXPECT_NE(error([](json& p) {
              p["blocks"][1]["texture"]["coarse"] = {{"kind", "reference"}, {"name", "4sin"}};
            }).find("must be a texel texture without a coarse profile"),
            std::string::npos);
}

TEST(DistributedIrregularity, ResumeIsReplay) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  auto s = session_of(p, "R1");
  const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "default"), s);
  std::vector<ex::StoredTrial> trials;
  while (!s.finished()) trials.push_back(s.answer(sim.respond(s)));
  ASSERT_EQ(trials.size(), 60u);
  auto r = session_of(p, "R1");
  for (std::size_t i = 0; i < 31; ++i) r.replay(trials[i]);
  const ex::SimulatedParticipant sim2(ex::simulation_observer(p.observer, "default"), r);
  for (std::size_t i = 31; i < trials.size(); ++i) {
    const ex::StoredTrial t = r.answer(sim2.respond(r));
    EXPECT_EQ(t.question_json, trials[i].question_json) << i;
    EXPECT_EQ(t.row.correct, trials[i].row.correct) << i;
  }
}

// The observer's hypothesis (full pooling on four actuators: −3.01 dB) is
// what the analysis finds, within its CI, at both levels; with no pooling
// the CI holds 0. The seed-only controls stay at chance.
TEST(DistributedIrregularity, SimulatedCohortThroughTheAnalysisRecoversThePse) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  texel::test_support::TempDir dir("distributed");
  ex::AnalysisOptions o;
  o.out_dir = dir.at("figures");
  const std::vector<ex::TrialRow> pooled_rows = cohort(p, "default", 12);
  const ex::AnalysisReport report = ex::analyze(pooled_rows, o);
  const json s = json::parse(report.summary)["distributed-irregularity"];
  ASSERT_EQ(s["levels"].size(), 2u) << report.summary;
  const double expected = 5.0 * std::log10(0.25);  // −3.01 dB
  for (const auto& level : s["levels"]) {
    SCOPED_TRACE(level.dump());
    EXPECT_EQ(level["participants"], 12);
    const json& pse = level["pse"];
    EXPECT_LE(pse["ci_low"].get<double>(), expected);
    EXPECT_GE(pse["ci_high"].get<double>(), expected);
    EXPECT_NEAR(pse["pse_db"].get<double>(), expected, 1.0);
    EXPECT_TRUE(pse["differs_from_zero"].get<bool>());
    EXPECT_FALSE(level["control"]["above_chance"].get<bool>());
    EXPECT_EQ(level["shifts"].size(), 6u);
  }
  EXPECT_NE(report.text.find("PSE -"), std::string::npos) << report.text;
  EXPECT_NE(report.text.find("simultaneous texels are felt at another Irregularity than sequential ones"), std::string::npos);
  const std::string figure = dir.at("figures") + "/distributed-irregularity-pse.png";
  ASSERT_TRUE(fs::exists(figure));
  EXPECT_EQ(texel::read_file(figure).substr(1, 3), "PNG");

  const json null = json::parse(ex::analyze(cohort(p, "integration=0", 12), {}).summary)["distributed-irregularity"];
  for (const auto& level : null["levels"]) {
    SCOPED_TRACE(level.dump());
    EXPECT_LE(level["pse"]["ci_low"].get<double>(), 0.0);
    EXPECT_GE(level["pse"]["ci_high"].get<double>(), 0.0);
    EXPECT_FALSE(level["pse"]["differs_from_zero"].get<bool>());
  }
  // The same rows always give the same interval (a seeded bootstrap).
  EXPECT_EQ(json::parse(ex::analyze(pooled_rows, {}).summary)["distributed-irregularity"]["levels"][0]["pse"],
            s["levels"][0]["pse"]);
}

TEST(DistributedIrregularity, ObserverSpecAndSectionAreValidated) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  EXPECT_NE(json::parse(ex::simulation_observer(p.observer, "integration=0.5"))["playback"]["integration"], nullptr);
  EXPECT_THROW((void)ex::simulation_observer(p.observer, "integration=2"), texel::InvalidArgument);
  EXPECT_THROW(ex::validate_observer(R"({"playback": {"threshold_db": 0}})"), texel::FormatError);
  EXPECT_THROW(ex::validate_observer(R"({"playback": {"pooling": 1}})"), texel::FormatError);
  auto s = session_of(p);
  const ex::SimulatedParticipant none(ex::simulation_observer(p.observer, "integration=0"), s);
  const ex::SimulatedParticipant full(ex::simulation_observer(p.observer, "integration=1"), s);
  EXPECT_DOUBLE_EQ(none.playback_shift_db(4), 0.0);
  EXPECT_NEAR(full.playback_shift_db(4), -3.0103, 1e-4);
  EXPECT_NEAR(full.playback_shift_db(2), -1.5051, 1e-4);
}
