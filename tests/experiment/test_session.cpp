// The engine end to end in-process: every shipped protocol runs to its end
// with a simulated participant; a session rebuilt by replaying any prefix of
// its stored trials continues exactly as the uninterrupted one (resume is
// replay); responses are validated; questions never reveal the answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "texel/device.hpp"
#include "texel/error.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/io.hpp"
#include "texel/texture.hpp"

namespace ex = texel::experiment;
namespace fs = std::filesystem;

namespace {
const fs::path protocols = fs::path(TEXEL_TEST_SOURCE_DIR) / "examples" / "protocols";

ex::Session make(const std::string& name, const std::string& participant = "S01") {
  // "data/NAME": a fixture of tests/experiment/data (the version-1 protocols).
  const fs::path path = name.rfind("data/", 0) == 0 ? fs::path(TEXEL_TEST_SOURCE_DIR) / "tests/experiment" / (name + ".json")
                                                    : protocols / (name + ".json");
  ex::Protocol p = ex::load_protocol(path.string());
  ex::SessionContext c;
  c.participant = participant;
  c.session_id = 1;
  c.seed = ex::session_seed(p.seed, participant);
  return ex::Session(std::move(p), std::move(c));
}

std::vector<ex::StoredTrial> simulate(ex::Session& s, const std::string& spec, std::size_t limit = 100000) {
  const ex::SimulatedParticipant sim(ex::simulation_observer(s.protocol().observer, spec), s);
  std::vector<ex::StoredTrial> out;
  while (!s.finished() && out.size() < limit) out.push_back(s.answer(sim.respond(s)));
  return out;
}

void expect_same(const std::vector<ex::StoredTrial>& a, const std::vector<ex::StoredTrial>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].trial, b[i].trial);
    EXPECT_EQ(a[i].question_json, b[i].question_json) << "trial " << i;
    EXPECT_EQ(a[i].response_json, b[i].response_json) << "trial " << i;
    EXPECT_EQ(a[i].state_json, b[i].state_json) << "trial " << i;
  }
}
}  // namespace

TEST(Session, TexelLengthStaircaseRunsToTenReversals) {
  auto s = make("texel-length");
  const auto trials = simulate(s, "threshold=6mm");
  ASSERT_TRUE(s.finished());
  int reversals = 0;
  for (const auto& t : trials) {
    reversals += t.row.reversal ? 1 : 0;
    EXPECT_EQ(t.row.task, "oddity");
    EXPECT_EQ(t.row.variable, "texel_length_mm");
    EXPECT_TRUE(t.row.correct == 0.0 || t.row.correct == 1.0);
    EXPECT_TRUE(std::isfinite(t.row.directional_proportion));
  }
  EXPECT_GE(reversals, 10);
  EXPECT_TRUE(trials.back().row.procedure_finished);
  EXPECT_EQ(trials[0].row.intensity, 26.0);
  // The convergent value lands in the region of the simulated threshold.
  EXPECT_GT(trials.back().row.next_intensity, 1.0);
  EXPECT_LT(trials.back().row.next_intensity, 20.0);
}

TEST(Session, ResumeIsReplayAtEveryPrefix) {
  for (const std::string name : {"texel-length", "working-memory", "coarse-features", "data/texel-length-v1"}) {
    auto full = make(name);
    const auto all = simulate(full, "default");
    for (std::size_t k : {std::size_t{0}, std::size_t{1}, all.size() / 3, all.size() - 1}) {
      auto resumed = make(name);
      for (std::size_t i = 0; i < k; ++i) resumed.replay(all[i]);
      auto rest = simulate(resumed, "default");
      std::vector<ex::StoredTrial> joined(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k));
      joined.insert(joined.end(), rest.begin(), rest.end());
      expect_same(all, joined);
    }
  }
}

TEST(Session, ReplayRefusesAnotherSessionsData) {
  auto a = make("texel-length", "S01");
  const auto trials = simulate(a, "default", 3);
  auto b = make("texel-length", "S02");  // another participant: other seeds
  EXPECT_THROW(b.replay(trials[0]), texel::FormatError);
}

TEST(Session, QuestionsNeverRevealTheAnswer) {
  auto s = make("texel-length");
  const ex::Question& q = s.question();
  const std::string j = q.to_json();
  EXPECT_EQ(j.find("correct"), std::string::npos);
  EXPECT_EQ(q.stimuli.size(), 3u);
  // Two stimuli are identical documents, one differs (the odd one).
  const bool ab = q.stimuli[0].document_json == q.stimuli[1].document_json;
  const bool ac = q.stimuli[0].document_json == q.stimuli[2].document_json;
  const bool bc = q.stimuli[1].document_json == q.stimuli[2].document_json;
  EXPECT_EQ(int(ab) + int(ac) + int(bc), 1);
  const std::string odd = ab ? "3" : ac ? "2" : "1";
  EXPECT_EQ(s.truth().correct_answer, odd);
}

TEST(Session, ResponsesAreValidated) {
  auto s = make("texel-length");
  ex::Response r;
  r.choice = "4";
  EXPECT_THROW((void)s.answer(r), texel::InvalidArgument);
  EXPECT_EQ(s.trials_done(), 0);
  r.choice = "2";
  r.rt_ms = -5;
  EXPECT_THROW((void)s.answer(r), texel::InvalidArgument);
  r.rt_ms = 1200;
  EXPECT_NO_THROW((void)s.answer(r));
  EXPECT_EQ(s.trials_done(), 1);
}

TEST(Session, ResponseEventsFromAFrontEndAreKeptWithTheTrial) {
  const auto r = ex::Response::from_json(
      R"({"choice":"2","rt_ms":900,"events":[{"t_s":0,"kind":"show","detail":"","at":"2026-11-23T10:00:00.000Z"},)"
      R"({"t_s":0.4,"kind":"select","detail":"2"},{"t_s":0.9,"kind":"answer","detail":"2"}]})");
  ASSERT_EQ(r.events.size(), 3u);
  EXPECT_EQ(r.events[1].kind, "select");
  EXPECT_EQ(r.events[1].detail, "2");
  EXPECT_DOUBLE_EQ(r.events[2].t_s, 0.9);
  EXPECT_EQ(r.events[0].at, "2026-11-23T10:00:00.000Z");
  auto s = make("texel-length");
  const ex::StoredTrial t = s.answer(r);
  ASSERT_EQ(t.events.size(), 3u);
  EXPECT_EQ(t.events[2].kind, "answer");
  for (const char* bad :
       {R"({"events":{}})", R"({"events":[1]})", R"({"events":[{"kind":"show","t_s":-1}]})", R"({"events":[{"t_s":0}]})",
        R"({"events":[{"t_s":0,"kind":"show","extra":1}]})", R"({"events":[{"t_s":0,"kind":7}]})"})
    EXPECT_THROW((void)ex::Response::from_json(bad), texel::FormatError) << bad;
}

TEST(Session, WorkingMemoryTrialsAreBalancedWithTheSpecMatrix) {
  auto s = make("working-memory");
  std::map<std::string, int> same, total;
  int practice = 0;
  const ex::SimulatedParticipant sim(ex::simulation_observer(s.protocol().observer, "default"), s);
  while (!s.finished()) {
    const ex::Question& q = s.question();
    if (q.task == "familiarisation") {
      (void)s.answer(sim.respond(s));
      continue;
    }
    ASSERT_TRUE(q.matrix);
    int filled = 0, ones = 0;
    for (int d : *q.matrix) {
      filled += d != 0;
      ones += d == 1;
    }
    const std::string cond = s.truth().condition;
    if (cond.find("control") != std::string::npos) {
      EXPECT_EQ(ones, 16);
      ASSERT_TRUE(q.recall);
      EXPECT_FALSE(q.recall->cell);  // "the digit in the cells"
    } else {
      EXPECT_EQ(filled, 5);
      ASSERT_TRUE(q.recall && q.recall->cell);
      EXPECT_GE(*q.recall->cell, 0);
      EXPECT_NE((*q.matrix)[static_cast<std::size_t>(*q.recall->cell)], 0);
    }
    ASSERT_EQ(q.phases.size(), 3u);
    EXPECT_EQ(q.phases[1].kind, ex::PhaseKind::matrix);
    EXPECT_EQ(q.phases[1].duration_s, 10);
    practice += q.practice;
    if (!q.practice) {
      ++total[cond];
      same[cond] += s.truth().correct_answer == "same";
    }
    (void)s.answer(sim.respond(s));
  }
  EXPECT_EQ(practice, 8);
  ASSERT_EQ(total.size(), 4u);
  for (const auto& [cond, n] : total) {
    EXPECT_EQ(n, 8) << cond;
    EXPECT_EQ(same[cond], 4) << cond;
  }
}

TEST(Session, GuidedExplorationAsksTwentyComparisonsPerReferenceThenRates) {
  auto s = make("guided-exploration");
  const auto trials = simulate(s, "target=4sin");
  ASSERT_TRUE(s.finished());
  std::map<std::string, int> comparisons;
  int ratings = 0;
  for (const auto& t : trials) {
    if (t.row.task == "guided") ++comparisons[t.row.reference];
    if (t.row.task == "rating") ++ratings;
  }
  ASSERT_EQ(comparisons.size(), 3u);
  for (const auto& [ref, n] : comparisons) EXPECT_EQ(n, 20) << ref;
  EXPECT_EQ(ratings, 9);
  const auto matches = s.matches("guided");
  EXPECT_EQ(matches.size(), 3u);
  // Every reference was matched against the same hidden target (4sin).
  const auto target = s.reference_position("4sin");
  for (const auto& [ref, m] : matches)
    EXPECT_LT(std::hypot(m.pitch_db - target.pitch_db, m.irregularity_db - target.irregularity_db), 8.0) << ref;
}

TEST(Session, MatchingStudiesRunAndMapSliders) {
  // Study 2's mapping: P = 0 → m = 0.75 cpm; I = 10 → s = 3 cpm.
  const auto m = ex::slider_to_parameters(ex::SliderMapping::lognormal, 0, 10);
  EXPECT_NEAR(m.pitch_db, 10 * std::log10(0.75), 1e-12);
  EXPECT_NEAR(m.irregularity_db, 10 * std::log10(3.0), 1e-12);
  auto s = make("parameter-mapping");
  const auto trials = simulate(s, "default");
  int matches = 0, ratings = 0;
  for (const auto& t : trials) {
    matches += t.row.task == "match";
    ratings += t.row.task == "rating";
    if (t.row.task == "match") {
      EXPECT_GE(t.row.slider_p, 0);
      EXPECT_LE(t.row.slider_p, 100);
      EXPECT_TRUE(std::isfinite(t.row.reference_pitch_db));
    }
    if (t.row.task == "rating") {
      EXPECT_GE(t.row.rating, 0);
      EXPECT_LE(t.row.rating, 10);
    }
  }
  EXPECT_EQ(matches, 9);
  EXPECT_EQ(ratings, 25);  // 25 of the 81 pairs: 9 own-match, 16 cross
}

// ------------------------------------------------------------ versions and the source's designs (issue #23)

namespace {
// FNV-1a over the stored records: the bytes a session writes.
std::uint64_t digest(const std::vector<ex::StoredTrial>& trials) {
  std::uint64_t h = 1469598103934665603ull;
  for (const auto& t : trials)
    for (const std::string* s : {&t.question_json, &t.response_json, &t.state_json}) {
      for (unsigned char c : *s) h = (h ^ c) * 1099511628211ull;
      h = (h ^ 0xff) * 1099511628211ull;
    }
  return h;
}
}  // namespace

TEST(ProtocolVersions, AVersionOneSessionKeepsItsRecordsAndResumes) {
  // The version-1 protocols as shipped before version 2 (tests/experiment/data).
  // The digests are of the records those protocols wrote before version 2
  // existed (checked against a build of main without it: identical trials,
  // states and rows); a change here means old sessions would replay differently.
  const std::pair<const char*, std::uint64_t> cases[] = {
      {"data/texel-length-v1", 0x4a40ac8be5eff906ull},
      {"data/working-memory-v1", 0x63106750ea398e92ull},
  };
  for (const auto& [name, want] : cases) {
    auto s = make(name);
    const auto all = simulate(s, "default");
    EXPECT_EQ(digest(all), want) << name << ": got 0x" << std::hex << digest(all);
    // Version 1: the row that finishes the staircase carries the value
    // computed after the last answer, not the last one presented.
    for (const auto& t : all)
      if (t.row.procedure_finished && t.row.variable == "texel_length_mm") {
        EXPECT_NE(t.row.next_intensity, t.row.intensity);
      }
    // Resume (replay) from half way continues exactly.
    auto resumed = make(name);
    for (std::size_t i = 0; i < all.size() / 2; ++i) resumed.replay(all[i]);
    auto rest = simulate(resumed, "default");
    std::vector<ex::StoredTrial> joined(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(all.size() / 2));
    joined.insert(joined.end(), rest.begin(), rest.end());
    expect_same(all, joined);
  }
}

TEST(ProtocolVersions, VersionTwoStaircaseHasNoInitialRuleAndEndsOnTheLastValueShown) {
  auto s = make("texel-length");
  const auto trials = simulate(s, "threshold=6mm");
  ASSERT_TRUE(s.finished());
  std::vector<const ex::StoredTrial*> main;
  for (const auto& t : trials)
    if (!t.row.practice) main.push_back(&t);
  ASSERT_GT(main.size(), 3u);
  // No 1-up/1-down start: the first move comes after three correct answers
  // (or one wrong one), not after the first answer.
  if (main[0]->row.correct == 1.0) {
    EXPECT_EQ(main[1]->row.intensity, 26.0);
  }
  const auto& last = main.back()->row;
  EXPECT_TRUE(last.procedure_finished);
  EXPECT_NE(last.next_intensity, last.intensity);  // the row keeps the value computed after the last answer
  // The protocol's end rule (what the engine reports as the threshold) is the last length presented.
  const auto state = nlohmann::json::parse(main.back()->state_json);
  EXPECT_EQ(state["config"]["end_value"], "last-presented");
  EXPECT_EQ(state["config"]["apply_initial_rule"], false);
  EXPECT_EQ(last.condition, "narrow");
}

TEST(ProtocolVersions, TexelLengthPracticeIsUntimed) {
  for (const std::string name : {"texel-length", "texel-length-wide", "texel-length-visual-practice"}) {
    auto s = make(name);
    const auto trials = simulate(s, "default");
    int practice = 0;
    for (const auto& t : trials) practice += t.row.practice;
    EXPECT_EQ(practice, 10) << name;
    auto fresh = make(name);
    EXPECT_TRUE(fresh.question().practice);
    EXPECT_EQ(fresh.question().time_limit_s, 0) << name;
    EXPECT_EQ(fresh.question().show_maps, name == "texel-length-visual-practice");
  }
}

TEST(ProtocolVersions, WorkingMemoryPresentsPatchesAndTheFamiliarisation) {
  auto s = make("working-memory");
  const ex::SimulatedParticipant sim(ex::simulation_observer(s.protocol().observer, "default"), s);
  const ex::Question& f = s.question();
  EXPECT_EQ(f.task, "familiarisation");
  ASSERT_EQ(f.stimuli.size(), 4u);
  EXPECT_EQ(f.choices, std::vector<std::string>{"continue"});
  EXPECT_EQ(f.time_limit_s, 0);
  EXPECT_NE(f.prompt.find("5 minutes"), std::string::npos) << f.prompt;
  (void)s.answer(sim.respond(s));
  int wide_different = 0, narrow_first_46 = 0, narrow = 0;
  while (!s.finished()) {
    const ex::Question& q = s.question();
    ASSERT_EQ(q.stimuli.size(), 2u);
    const std::string& a = q.stimuli[0].document_json;
    const std::string& b = q.stimuli[1].document_json;
    EXPECT_EQ(a.find("\"texel\""), std::string::npos);  // no fine texture: patch references only
    const bool different = s.truth().correct_answer == "different";
    if (s.truth().condition.rfind("wide", 0) == 0) {
      EXPECT_NE(a.find("patch-13.5"), std::string::npos);
      EXPECT_NE(b.find("patch-13.5"), std::string::npos);
      if (different) {
        EXPECT_NE(a, b);  // the same patches, rearranged
        ++wide_different;
      }
    } else {
      ++narrow;
      narrow_first_46 += a.find("patch-4.6") != std::string::npos;
      if (different) {
        EXPECT_NE(a.find("patch-4.6") == std::string::npos, b.find("patch-4.6") == std::string::npos);
      }
    }
    if (!different) {
      EXPECT_EQ(a, b);
    }
    (void)s.answer(sim.respond(s));
  }
  EXPECT_EQ(wide_different, 10);  // (2 + 8 trials per condition) / 2 × 2 conditions
  // Which texture comes first is drawn per trial.
  EXPECT_GT(narrow_first_46, 0);
  EXPECT_LT(narrow_first_46, narrow);
}

TEST(ProtocolVersions, WideConditionFrequencyFloorRemovesTheDrawsBelowOneCpm) {
  // The wide group's distribution (4 cpm mean, 4.3 cpm SD) drawn with and
  // without the protocol's 1 cpm floor: 12.6 % of unfloored draws fall below.
  auto p = ex::load_protocol((protocols / "texel-length-wide.json").string());
  const auto& tex = p.blocks[1].texture;
  const texel::DeviceProfile device = texel::load_device(p.device);
  texel::TexelSpec spec;
  spec.central_pitch = texel::Decibels(*tex.number("central_pitch_db"));
  spec.irregularity = texel::Decibels(*tex.number("irregularity_db"));
  spec.texel_length = texel::Millimetres(0.1);  // many draws per texture
  for (const double floor : {0.01, *tex.number("band_min_cpm")}) {
    spec.band_min = texel::CyclesPerMm(floor);
    std::size_t below = 0, n = 0;
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      spec.seed = seed;
      const texel::TexelTexture t(spec, texel::Millimetres(1000.0), texel::Sampling{device.grid()});
      for (const auto& k : t.texels()) {
        below += k.frequency.value() < 1.0;
        ++n;
      }
    }
    const double fraction = static_cast<double>(below) / static_cast<double>(n);
    std::printf("band_min %g cpm: %zu of %zu texel draws below 1 cpm (%.2f %%)\n", floor, below, n, 100 * fraction);
    if (floor < 1.0) {
      EXPECT_NEAR(fraction, 0.126, 0.005);
    } else {
      EXPECT_EQ(below, 0u);
    }
  }
}

TEST(ProtocolVersions, EffectOfTheStaircaseRulesOnASimulatedCohort) {
  // The figures of docs/procedures.md §2 ("End value and start rule"): each
  // staircase study run by simulated participants (the protocol's observer)
  // under the four combinations of the two rules. The docs' figures are from
  // TEXEL_COHORT=200; the default keeps the test short.
  const char* env = std::getenv("TEXEL_COHORT");
  const int participants = env ? std::max(1, std::atoi(env)) : 30;
  for (const std::string name : {"texel-length", "texel-length-wide", "coarse-features"}) {
    const std::string text = texel::read_file((protocols / (name + ".json")).string());
    std::map<std::pair<bool, bool>, std::pair<double, double>> result;  // (initial rule, last) → (mean threshold, mean trials)
    for (const bool initial : {true, false})
      for (const bool last : {true, false}) {
        auto j = nlohmann::json::parse(text);
        for (auto& b : j["blocks"])
          if (b.contains("staircase")) {
            b["staircase"]["apply_initial_rule"] = initial;
            b["staircase"]["end_value"] = last ? "last-presented" : "next";
          }
        const ex::Protocol p = ex::parse_protocol(j.dump());
        double sum = 0, trials = 0, runs = 0;
        for (int i = 0; i < participants; ++i) {
          ex::SessionContext c;
          c.participant = "P" + std::to_string(i);
          c.session_id = 1;
          c.seed = ex::session_seed(p.seed, c.participant);
          ex::Session s(p, c);
          for (const auto& t : simulate(s, "default")) {
            if (t.row.practice) continue;
            trials += 1;
            if (!t.row.procedure_finished) continue;
            // The stored row keeps both readings: the last value shown
            // (intensity) and the one computed after the answer, one step
            // from it (next_intensity); the end rule picks one.
            EXPECT_NE(t.row.next_intensity, t.row.intensity);
            sum += last ? t.row.intensity : t.row.next_intensity;
            runs += 1;
          }
        }
        result[{initial, last}] = {sum / runs, trials / runs};
        std::printf("%s: initial rule %s, end value %s: mean threshold %.3f, %.1f trials per staircase (%g runs)\n", name.c_str(),
                    initial ? "on " : "off", last ? "last-presented" : "next          ", sum / runs, trials / runs, runs);
      }
    // Without the initial rule the staircase needs more trials to its reversals.
    EXPECT_GT(result[std::pair(false, true)].second, result[std::pair(true, true)].second) << name;
  }
}
