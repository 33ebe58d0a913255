// The 2-D oddity studies (task kind "oddity-2d", docs/experiments.md "2-D
// studies"): the shipped protocols validate; simulated observers perceive
// every interval through the encoder's perceptual model (perceive_document),
// so the oriented grating's two directions are told apart and the
// path-indexed texture's are not; a simulated session runs, exports and
// analyses through the real CLI.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/expect.hpp"
#include "../support/service_client.hpp"
#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/experiment/observer.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/runner.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/experiment/store.hpp"
#include "texel/io.hpp"
#include "texel/studio/service.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;

namespace {

const std::string dir = std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols/";

// A one-block protocol whose only condition is `pair` against `odd`; by
// default with the former direction assignment (the pair along its two
// directions, the odd interval along one of them), so the intervals in the
// order pair, pair, odd are along the pair's first and second directions.
std::string protocol(const json& pair, const json& odd, int trials = 1, const std::string& assignment = "pair-spans") {
  json p = json::parse(texel::read_file(dir + "direction-independence.json"));
  json& b = p["blocks"][1];
  b["trials_per_condition"] = trials;
  b["direction_assignment"] = assignment;
  b["conditions"] = json::array({json{{"name", "c"}, {"pair", pair}, {"odd", odd}}});
  p["blocks"].erase(0);
  return p.dump();
}

// The perceived (Central Pitch, Irregularity) of the three intervals of the
// first trial, in the order pair, pair, odd.
std::vector<ex::MatchPoint> perceived(const json& pair, const json& odd) {
  ex::Session s(ex::parse_protocol(protocol(pair, odd)), ex::SessionContext{});
  const auto& q = s.question();
  const int odd_index = std::stoi(s.truth().correct_answer) - 1;
  std::vector<ex::MatchPoint> out;
  for (int i = 0; i < 3; ++i)
    if (i != odd_index) out.push_back(ex::perceive_document(q.stimuli[static_cast<std::size_t>(i)].document_json, 100).value());
  out.push_back(ex::perceive_document(q.stimuli[static_cast<std::size_t>(odd_index)].document_json, 100).value());
  return out;
}

TEST(Oddity2D, ShippedProtocolsValidate) {
  const ex::Protocol d = ex::parse_protocol(texel::read_file(dir + "direction-independence.json"));
  EXPECT_EQ(d.planned_trials(), 62);
  const ex::Protocol r = ex::parse_protocol(texel::read_file(dir + "rendering-2d.json"));
  EXPECT_EQ(r.planned_trials(), 48);
  // Both shipped 2-D protocols have no cue in the directions (version 3).
  for (const char* f : {"direction-independence.json", "rendering-2d.json"}) {
    const json j = json::parse(texel::read_file(dir + f));
    EXPECT_EQ(j["version"], 3) << f;
    for (const auto& b : j["blocks"]) EXPECT_EQ(b.value("direction_assignment", "balanced"), "balanced") << f;
  }
  auto message = [](std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    return texel::test_support::message_of<texel::FormatError>([&] { (void)ex::parse_protocol(text); });
  };
  const std::string text = texel::read_file(dir + "direction-independence.json");
  EXPECT_NE(message(text, "\"device\": \"tablet-2d\"", "\"device\": \"tpad\"").find("no bitmap grid"), std::string::npos);
  EXPECT_NE(message(text, "\"mode\": \"spectral\"", "\"mode\": \"bitmap\"").find("conditions[2].pair.mode is 'bitmap'"),
            std::string::npos);
  EXPECT_NE(message(text, "\"pitch_shift_db\": -2", "\"pitch_shift_db\": -2, \"directions_deg\": [0, 1]")
                .find("odd.directions_deg applies to the pair only"),
            std::string::npos);
  EXPECT_NE(message(text, "\"trials_per_condition\": 10", "\"trials_per_condition\": 10, \"staircase\": {}")
                .find("staircase does not apply to task 'oddity-2d'"),
            std::string::npos);
}

// How the directions fall over the intervals of many trials of a 0°/60°
// condition: `lone_odd` counts the trials whose odd interval is the one
// swiped along a direction of its own; `odd_at[lone][odd]` the odd
// interval's position against that interval's.
struct DirectionCounts {
  int trials = 0, lone_odd = 0, lone_60 = 0, lone_60_odd = 0;
  int odd_at[3][3] = {};
};

DirectionCounts direction_counts(ex::Session s) {
  DirectionCounts c;
  while (!s.finished()) {
    const ex::Question& q = s.question();
    EXPECT_EQ(q.surfaces.size(), 3u);
    int lone = -1;
    for (int i = 0; i < 3; ++i) {
      const double d = q.surfaces[static_cast<std::size_t>(i)].direction_deg;
      const double a = q.surfaces[static_cast<std::size_t>((i + 1) % 3)].direction_deg;
      const double b = q.surfaces[static_cast<std::size_t>((i + 2) % 3)].direction_deg;
      if (d != a && d != b) lone = i;
    }
    EXPECT_GE(lone, 0) << "trial " << q.trial << ": both directions must be swiped";
    const int odd = std::stoi(s.truth().correct_answer) - 1;
    ++c.trials;
    c.lone_odd += lone == odd;
    const bool at_60 = lone >= 0 && q.surfaces[static_cast<std::size_t>(lone)].direction_deg == 60.0;
    c.lone_60 += at_60;
    c.lone_60_odd += at_60 && lone == odd;
    if (lone >= 0) ++c.odd_at[lone][odd];
    ex::Response r;
    r.choice = "1";
    (void)s.answer(r);
  }
  return c;
}

// The cue the former design gave (docs/experiments.md "Directions"): with
// the balanced assignment (the shipped protocol's, version 3's default) the
// interval with a direction of its own is the odd one in 1 trial in 3,
// whichever direction and position it has; so knowing the directions does
// not help find the odd one. A version-2 protocol keeps its former design,
// where that interval is never the odd one.
TEST(Oddity2D, TheDirectionsTellNothingAboutWhichIntervalIsOdd) {
  const json pair{{"mode", "1d"}, {"directions_deg", {0, 60}}};
  const json odd{{"mode", "1d"}, {"pitch_shift_db", -2}};
  constexpr int n = 900;  // 1-D intervals: a few ms a trial
  const DirectionCounts b = direction_counts(ex::Session(ex::parse_protocol(protocol(pair, odd, n, "balanced")), {}));
  ASSERT_EQ(b.trials, n);
  // Binomial(900, 1/3): sd 14; the bounds are 4 sd.
  EXPECT_NEAR(b.lone_odd, n / 3, 57);
  EXPECT_NEAR(b.lone_60, n / 2, 60);
  EXPECT_NEAR(b.lone_60_odd, b.lone_60 / 3, 40);
  for (int lone = 0; lone < 3; ++lone) {
    const int at = b.odd_at[lone][0] + b.odd_at[lone][1] + b.odd_at[lone][2];
    for (int o = 0; o < 3; ++o) EXPECT_NEAR(b.odd_at[lone][o], at / 3, 40) << "lone " << lone << ", odd " << o;
  }
  const DirectionCounts old = direction_counts(ex::Session(ex::parse_protocol(protocol(pair, odd, 60, "pair-spans")), {}));
  EXPECT_EQ(old.lone_odd, 0);
  // The default follows the version: 3 balanced, 2 the former design.
  json p = json::parse(protocol(pair, odd, 60));
  p["blocks"][0].erase("direction_assignment");
  EXPECT_GT(direction_counts(ex::Session(ex::parse_protocol(p.dump()), {})).lone_odd, 0);
  p["version"] = 2;
  EXPECT_EQ(direction_counts(ex::Session(ex::parse_protocol(p.dump()), {})).lone_odd, 0);
  p["blocks"][0]["direction_assignment"] = "alternate";
  EXPECT_NE(texel::test_support::message_of<texel::FormatError>([&] {
              (void)ex::parse_protocol(p.dump());
            }).find("blocks[0].direction_assignment is 'alternate'; allowed: balanced, pair-spans"),
            std::string::npos);
}

// A shipped protocol as it was before version 3 (tests/experiment/data):
// its questions keep their bytes. FNV-1a over the questions participant S01
// is asked (answering "1"; an oddity-2d trial's questions do not depend on
// the answers).
std::uint64_t questions_digest(const std::string& file, int& trials) {
  const ex::Protocol p = ex::load_protocol(std::string(TEXEL_TEST_SOURCE_DIR) + "/tests/experiment/data/" + file);
  ex::SessionContext context;
  context.participant = "S01";
  context.seed = ex::session_seed(p.seed, "S01");
  ex::Session s(p, context);
  std::uint64_t h = 1469598103934665603ull;
  trials = 0;
  while (!s.finished()) {
    ex::Response r;
    r.choice = "1";
    for (unsigned char c : s.answer(r).question_json) h = (h ^ c) * 1099511628211ull;
    ++trials;
  }
  return h;
}

// The digests are of questions checked against those a build before the
// balanced assignment stored for participant S01 (`texel experiment run
// --simulate`: identical questions, states, answers and rows but for their
// time stamps).
TEST(Oddity2D, AVersionTwoProtocolAsksTheSameQuestions) {
  int trials = 0;
  const std::uint64_t d = questions_digest("direction-independence-v2.json", trials);
  EXPECT_EQ(trials, 62);
  EXPECT_EQ(d, 0xbf3b0aabb0301c05ull) << "got 0x" << std::hex << d;
  const std::uint64_t r = questions_digest("rendering-2d-v2.json", trials);
  EXPECT_EQ(trials, 48);
  EXPECT_EQ(r, 0x80ac05f79f440177ull) << "got 0x" << std::hex << r;
}

// The pair's two swipes of an oriented grating (wave vector at 0°) along 0°
// and 60° are felt an octave apart (|cos 60°| = 1/2: −3 dB); the
// path-indexed texture's are felt alike, and so are the isotropic field's.
TEST(Oddity2D, ObserversFeelTheOrientedGratingsDirectionAndNotThePathIndexedOnes) {
  const json oriented{{"mode", "oriented"}, {"orientation_deg", 0}, {"directions_deg", {0, 60}}};
  const json path{{"mode", "path-indexed"}, {"directions_deg", {0, 60}}};
  const json spectral{{"mode", "spectral"}, {"directions_deg", {0, 60}}};
  const auto po = perceived(oriented, json{{"mode", "oriented"}, {"pitch_shift_db", -2}});
  const auto pp = perceived(path, json{{"mode", "path-indexed"}, {"pitch_shift_db", -2}});
  const auto ps = perceived(spectral, json{{"mode", "spectral"}, {"pitch_shift_db", -2}});
  EXPECT_NEAR(po[0].pitch_db - po[1].pitch_db, 3.0, 0.5);  // 0° against 60°
  EXPECT_LT(std::abs(pp[0].pitch_db - pp[1].pitch_db), 0.3);
  EXPECT_LT(std::abs(ps[0].pitch_db - ps[1].pitch_db), 1.5);
  // Every interval's percept is near its texture: 3 dB, the odd one 1 dB.
  EXPECT_NEAR(pp[0].pitch_db, 3.0, 0.3);
  EXPECT_NEAR(pp[2].pitch_db, 1.0, 0.3);

  // Noise-free observers pick the odd one of the path-indexed trial and a
  // pair member of the oriented one.
  ex::MatcherConfig c;
  c.noise_db = 0.0;
  const ex::Matcher m(c);
  EXPECT_EQ(m.odd_one(pp, 0), 2u);
  EXPECT_NE(m.odd_one(po, 0), 2u);
}

// Simulated sessions, stored, exported and analysed: the oriented control's
// direction pair is discriminated (proportion correct drops from the
// same-direction pair), the path-indexed one's is not.
TEST(Oddity2D, SimulatedRunExportAndAnalysisThroughTheCli) {
  texel::test_support::TempDir tmp("oddity-2d");
  json p = json::parse(texel::read_file(dir + "direction-independence.json"));
  p["blocks"].erase(0);  // no practice
  json& b = p["blocks"][0];
  b["trials_per_condition"] = 12;
  json kept = json::array();
  for (const auto& c : b["conditions"])
    if (c["name"].get<std::string>().rfind("spectral", 0) != 0) kept.push_back(c);  // spectral: the slow field
  b["conditions"] = kept;
  const std::string protocol_path = tmp.at("d.json");
  texel::write_file_atomic(protocol_path, p.dump(2));
  const std::string db = tmp.at("s.db");
  const auto run = texel::test_support::run_cli(
      TEXEL_CLI, "experiment run " + protocol_path + " --participant S01 --db " + db + " --simulate default");
  ASSERT_EQ(run.status, 0) << run.out;
  const auto csv_run = texel::test_support::run_cli(TEXEL_CLI, "experiment export --db " + db + " -o " + tmp.at("t.csv"));
  ASSERT_EQ(csv_run.status, 0) << csv_run.out;
  const std::string csv = texel::read_file(tmp.at("t.csv"));
  EXPECT_NE(csv.find(",oddity-2d,path-indexed 0/60,path-indexed,direction_difference_deg,60,"), std::string::npos)
      << csv.substr(0, 600);
  const auto an = texel::test_support::run_cli(TEXEL_CLI, "experiment analyze --db " + db + " --json -o " + tmp.at("fig"), false);
  ASSERT_EQ(an.status, 0) << an.out;
  const json s = json::parse(an.out);
  const json& d = s.contains("summary") ? s["summary"]["direction-independence"] : s["direction-independence"];
  ASSERT_EQ(d["conditions"].size(), 4u);
  std::map<std::string, double> prop;
  for (const auto& c : d["conditions"]) prop[c["condition"].get<std::string>()] = c["proportion"].get<double>();
  EXPECT_GT(prop["path-indexed 0/60"], 0.6);
  EXPECT_LT(prop["oriented 0/60"], prop["oriented 0/0"] - 0.3);
  for (const auto& e : d["direction_effects"])
    EXPECT_EQ(e["directions_discriminated"].get<bool>(), e["mode"] == "oriented") << e.dump();
  EXPECT_TRUE(std::filesystem::exists(tmp.at("fig") + "/direction-independence-proportion-correct.png"));
}

// Resume is replay: a session stopped after three trials reopens with the
// same questions (stored questions are compared with the ones the engine
// would ask now, scans of the static fields included) and continues.
TEST(Oddity2D, ResumesWhereItStopped) {
  texel::test_support::TempDir tmp("oddity-2d-resume");
  const ex::Protocol p = ex::parse_protocol(
      protocol(json{{"mode", "oriented"}, {"directions_deg", {0, 60}}}, json{{"mode", "cells"}, {"pitch_shift_db", -2}}, 5));
  std::string third;
  {
    ex::Store store = ex::Store::open(tmp.at("s.db"), ex::StoreMode::read_write);
    ex::ActiveSession a = ex::open_session(store, p, {"P01", false, "default"});
    const ex::SimulatedParticipant who(ex::simulation_observer(p.observer, "default"), a.session);
    for (int i = 0; i < 3; ++i) {
      if (i == 2) third = a.session.question().to_json();
      (void)ex::record(store, a, who.respond(a.session));
    }
  }
  ex::Store store = ex::Store::open(tmp.at("s.db"), ex::StoreMode::read_write);
  ex::ActiveSession a = ex::open_session(store, p, {"P01", true, std::nullopt});
  EXPECT_EQ(a.session.question().trial, 3);
  EXPECT_EQ(store.rows().size(), 3u);
  EXPECT_NE(third.find("\"points\""), std::string::npos);  // the scan is in the stored question
}

// The studio's experiment messages run the kind (simulated answers through
// experiment.answer); the question a participant's screen gets names
// neither the condition nor the mode nor the directions.
TEST(Oddity2D, RunsThroughTheStudio) {
  using namespace std::chrono_literals;
  texel::test_support::TempDir tmp("oddity-2d-studio");
  texel::studio::ServiceOptions o;
  o.db_path = tmp.at("s.db");
  texel::studio::Service service(o);
  texel::test_support::Client client(service);
  auto ask = [&](json msg) { return client.ask(std::move(msg), 60s); };
  const json p = json::parse(protocol(json{{"mode", "oriented"}, {"orientation_deg", 0}, {"directions_deg", {0, 60}}},
                                      json{{"mode", "path-indexed"}, {"pitch_shift_db", -2}}, 3));
  const json started = ask({{"type", "experiment.start"}, {"protocol", p}, {"participant", "P01"}, {"simulate", "default"}});
  ASSERT_EQ(started["type"], "experiment.started") << started.dump();
  EXPECT_EQ(started["progress"]["planned"], 3);
  json q = ask({{"type", "experiment.current"}});
  int answered = 0;
  while (q["type"] == "experiment.question") {
    const json& question = q["question"];
    EXPECT_EQ(question["task"], "oddity-2d");
    EXPECT_EQ(question["choices"], json({"1", "2", "3"}));
    const std::string shown = question.dump();
    for (const char* hidden : {"oriented", "path-indexed", "_deg", "reference", "\"condition\":\"c\"", "correct"})
      EXPECT_EQ(shown.find(hidden), std::string::npos) << hidden << " in " << shown.substr(0, 400);
    q = ask({{"type", "experiment.answer"}, {"trial", question["trial"]}, {"simulated", true}});
    ++answered;
  }
  EXPECT_EQ(q["type"], "experiment.finished") << q.dump();
  EXPECT_EQ(answered, 3);
}

}  // namespace
