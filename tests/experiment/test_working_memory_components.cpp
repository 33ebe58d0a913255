// Working-memory components (docs/experiments.md "Working-memory
// components"): the verbal and executive distractors beside the source's
// matrix, their controls, their scoring, the shipped protocol crossing
// distractor × coarse/fine, and the simulated cohort through the analysis
// (RM-ANOVA with the distractor factor, per-component paired t-tests, the
// source's exclusion rule, the figure).
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
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/io.hpp"

namespace ex = texel::experiment;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const fs::path shipped_path = fs::path(TEXEL_TEST_SOURCE_DIR) / "examples" / "protocols" / "working-memory-components.json";

using texel::test_support::session_of;

// The shipped protocol's test block with every component's own control, one
// trial per condition pair (same, different), short timings.
ex::Protocol with_every_control() {
  json p = json::parse(texel::read_file(shipped_path.string()));
  json test = p["blocks"][2];
  test["trials_per_condition"] = 2;
  test["conditions"] = json::array();
  for (const char* c : {"visuospatial", "verbal", "executive"})
    for (const bool load : {true, false})
      test["conditions"].push_back({{"name", std::string("coarse-") + c + (load ? "" : "-control")},
                                    {"stimulus", "coarse"},
                                    {"component", c},
                                    {"distractor", load}});
  p["blocks"] = json::array({test});
  return ex::parse_protocol(p.dump(), "components.json");
}

std::string error_of(const std::function<void()>& f) { return texel::test_support::message_of(f); }

// The shipped protocol with `edit` applied to its test block's JSON.
std::string protocol_error(const std::function<void(json&)>& edit) {
  json p = json::parse(texel::read_file(shipped_path.string()));
  edit(p["blocks"][2]);
  return error_of([&] { (void)ex::parse_protocol(p.dump(), "p.json"); });
}

std::vector<bool> two_back_targets(const std::vector<int>& s) {
  std::vector<bool> t(s.size(), false);
  for (std::size_t i = 2; i < s.size(); ++i) t[i] = s[i] == s[i - 2];
  return t;
}

}  // namespace

TEST(WorkingMemoryComponents, ShippedProtocolCrossesDistractorWithCoarseAndFine) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  EXPECT_EQ(p.study, "working-memory-components");  // its own study: analysed apart from the source's
  EXPECT_EQ(p.planned_trials(), 1 + 16 + 64);       // familiarisation, 2 training and 8 test trials per condition
  const ex::Block& test = *p.block("test");
  std::set<std::pair<std::string, std::string>> cells;
  for (const auto& c : test.conditions) {
    const std::string kind = c.distractor ? std::string(ex::to_string(c.component)) : "control";
    EXPECT_EQ(c.name, c.stimulus + "-" + kind);  // the analysis reads "<texture>-<distractor>"
    cells.insert({c.stimulus, kind});
  }
  EXPECT_EQ(cells.size(), 8u);
  for (const char* t : {"coarse", "fine"})
    for (const char* k : {"control", "visuospatial", "verbal", "executive"}) EXPECT_TRUE(cells.count({t, k})) << t << " " << k;
  // Timed as the source's matrix task: 10 s textures, 10 s distractor.
  EXPECT_EQ(test.texture_s, 10);
  EXPECT_EQ(test.matrix_s, 10);
  EXPECT_EQ(test.trials_per_condition, 8);
}

TEST(WorkingMemoryComponents, EachComponentAndItsControlShowTheirOwnTask) {
  const ex::Protocol p = with_every_control();
  auto s = session_of(p);
  const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "default"), s);
  std::map<std::string, int> seen;
  while (!s.finished()) {
    const ex::Question& q = s.question();
    const std::string cond = s.truth().condition;
    const bool control = cond.ends_with("-control");
    ++seen[cond];
    ASSERT_EQ(q.phases.size(), 3u);
    EXPECT_EQ(q.phases[1].duration_s, 10);  // the distractor lasts matrix_s whatever its kind
    const std::string screen = q.participant_json();
    EXPECT_EQ(screen.find("coarse"), std::string::npos) << screen;  // nothing of the condition on the screen
    EXPECT_EQ(screen.find("control"), std::string::npos) << screen;
    EXPECT_EQ(screen.find("verbal"), std::string::npos) << screen;
    EXPECT_EQ(screen.find("executive"), std::string::npos) << screen;
    if (cond.find("visuospatial") != std::string::npos) {
      EXPECT_EQ(q.phases[1].kind, ex::PhaseKind::matrix);
      ASSERT_TRUE(q.matrix);
      EXPECT_TRUE(q.sequence.empty());
    } else if (cond.find("verbal") != std::string::npos) {
      EXPECT_EQ(q.phases[1].kind, ex::PhaseKind::sequence);
      EXPECT_FALSE(q.matrix);
      EXPECT_FALSE(q.nback);
      ASSERT_EQ(q.sequence.size(), 5u);
      ASSERT_TRUE(q.recall);
      EXPECT_EQ(q.wording.sequence_instruction, "Remember these digits in their order.");
      if (control) {
        EXPECT_EQ(q.sequence, std::vector<int>(5, 1));
        EXPECT_FALSE(q.recall->position);
        EXPECT_EQ(q.wording.recall->question, "Which digit did the sequence show?");
      } else {
        EXPECT_EQ(std::set<int>(q.sequence.begin(), q.sequence.end()).size(), 5u);  // distinct digits
        for (int d : q.sequence) EXPECT_TRUE(d >= 1 && d <= 9);
        ASSERT_TRUE(q.recall->position);
        EXPECT_LT(*q.recall->position, 5);
        EXPECT_EQ(q.wording.recall->question,
                  "Which digit was number " + std::to_string(*q.recall->position + 1) + " of the 5 in the sequence?");
      }
      EXPECT_NE(screen.find("\"sequence\""), std::string::npos);
    } else {
      EXPECT_EQ(q.phases[1].kind, ex::PhaseKind::sequence);
      EXPECT_FALSE(q.recall);  // scored by its responses, not a recall
      ASSERT_TRUE(q.nback);
      ASSERT_EQ(q.sequence.size(), 10u);
      // A non-target never repeats the digit before it (two targets in a row
      // of the 0-back are two 1s, told apart by the blank between digits).
      for (std::size_t i = 1; i < q.sequence.size(); ++i)
        if (q.sequence[i] != 1 || q.nback->n != 0) EXPECT_NE(q.sequence[i], q.sequence[i - 1]);
      if (control) {
        EXPECT_EQ(q.nback->n, 0);
        EXPECT_EQ(std::count(q.sequence.begin(), q.sequence.end(), 1), 3);
        EXPECT_EQ(q.wording.sequence_instruction, "Respond whenever the digit is 1.");
      } else {
        EXPECT_EQ(q.nback->n, 2);
        const auto t = two_back_targets(q.sequence);
        EXPECT_EQ(std::count(t.begin(), t.end(), true), 3);  // exactly the planned targets, no accidental one
        EXPECT_EQ(q.wording.sequence_instruction, "Respond whenever the digit is the same as the one two before it.");
      }
    }
    (void)s.answer(sim.respond(s));
  }
  EXPECT_EQ(seen.size(), 6u);
  for (const auto& [c, n] : seen) EXPECT_EQ(n, 2) << c;
}

TEST(WorkingMemoryComponents, ResponsesAreScoredAndCheckedAtTheEdge) {
  const ex::Protocol p = with_every_control();
  auto s = session_of(p);
  const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "default"), s);
  int executive = 0, verbal = 0;
  while (!s.finished()) {
    const ex::Question q = s.question();
    const std::string cond = s.truth().condition;
    ex::Response r;
    r.choice = s.truth().correct_answer;
    if (q.nback) {
      std::vector<int> targets;
      for (std::size_t i = 0; i < q.sequence.size(); ++i)
        if (q.nback->n == 0 ? q.sequence[i] == 1 : i >= 2 && q.sequence[i] == q.sequence[i - 2])
          targets.push_back(static_cast<int>(i));
      // Out of range, not increasing: refused, naming the field; the session stays on the trial.
      r.presses = {static_cast<int>(q.sequence.size())};
      EXPECT_NE(error_of([&] { (void)s.answer(r); }).find("presses[0] is 10; allowed: increasing items 0 … 9"),
                std::string::npos);
      r.presses = {5, 3};
      EXPECT_THROW((void)s.answer(r), texel::InvalidArgument);
      EXPECT_EQ(s.question().trial, q.trial);
      // All targets but the last, and one non-target: 2 hits of 3, 1 false alarm.
      r.presses.assign(targets.begin(), targets.end() - 1);
      const int non_target = targets[0] == 0 ? 1 : 0;
      r.presses.push_back(non_target);
      std::sort(r.presses.begin(), r.presses.end());
      const ex::StoredTrial t = s.answer(r);
      EXPECT_EQ(t.row.nback_targets, 3);
      EXPECT_EQ(t.row.nback_hits, 2);
      EXPECT_EQ(t.row.nback_false_alarms, 1);
      EXPECT_TRUE(std::isnan(t.row.digit_correct));
      EXPECT_NE(t.response_json.find("\"presses\""), std::string::npos);
      ++executive;
      continue;
    }
    r.presses = {1};
    EXPECT_NE(error_of([&] { (void)s.answer(r); }).find("presses are given but this trial has no executive distractor task"),
              std::string::npos);
    r.presses.clear();
    if (!q.sequence.empty()) {
      const int expected = q.recall->position ? q.sequence[static_cast<std::size_t>(*q.recall->position)] : 1;
      r.digit = verbal % 2 == 0 ? expected : expected % 9 + 1;  // right, then wrong
      const ex::StoredTrial t = s.answer(r);
      EXPECT_EQ(t.row.digit_correct, verbal % 2 == 0 ? 1.0 : 0.0) << cond;
      EXPECT_EQ(t.row.digit_response, *r.digit);
      if (q.recall->position) EXPECT_EQ(t.row.digit_cell, *q.recall->position);  // the position asked
      EXPECT_TRUE(std::isnan(t.row.nback_hits));
      ++verbal;
      continue;
    }
    (void)s.answer(sim.respond(s));
  }
  EXPECT_EQ(executive, 4);
  EXPECT_EQ(verbal, 4);
  // The response's form: presses are whole item numbers.
  EXPECT_THROW((void)ex::Response::from_json(R"({"presses": [1.5]})"), texel::FormatError);
  EXPECT_THROW((void)ex::Response::from_json(R"({"presses": 3})"), texel::FormatError);
  EXPECT_EQ(ex::Response::from_json(R"({"presses": [0, 4]})").presses, (std::vector<int>{0, 4}));
}

TEST(WorkingMemoryComponents, ResumeIsReplay) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  auto s = session_of(p, "R1");
  const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "default"), s);
  std::vector<ex::StoredTrial> trials;
  while (!s.finished()) trials.push_back(s.answer(sim.respond(s)));
  ASSERT_EQ(trials.size(), 81u);
  for (const std::size_t prefix : {std::size_t{20}, std::size_t{57}}) {
    auto r = session_of(p, "R1");
    for (std::size_t i = 0; i < prefix; ++i) r.replay(trials[i]);
    const ex::SimulatedParticipant sim2(ex::simulation_observer(p.observer, "default"), r);
    for (std::size_t i = prefix; i < trials.size(); ++i) {
      const ex::StoredTrial t = r.answer(sim2.respond(r));
      EXPECT_EQ(t.question_json, trials[i].question_json) << i;
      EXPECT_EQ(t.response_json, trials[i].response_json) << i;
    }
  }
}

TEST(WorkingMemoryComponents, BadProtocolsNameTheField) {
  EXPECT_NE(protocol_error([](json& b) {
              b["conditions"][1]["component"] = "phonological";
            }).find("blocks[2].conditions[1].component is 'phonological'; allowed: visuospatial, verbal, executive"),
            std::string::npos);
  EXPECT_NE(protocol_error([](json& b) { b["sequence_length"] = 10; }).find("blocks[2].sequence_length"), std::string::npos);
  EXPECT_NE(protocol_error([](json& b) { b["nback_targets"] = 9; }).find("blocks[2].nback_targets"), std::string::npos);
  EXPECT_NE(protocol_error([](json& b) { b["nback_items"] = 3; }).find("blocks[2].nback_items"), std::string::npos);
  EXPECT_EQ(protocol_error([](json&) {}), "(no exception)");
}

TEST(WorkingMemoryComponents, SimulatedCohortThroughTheAnalysis) {
  // The observer's hypothesis (the protocol's description): coarse recall
  // drops under the matrix, fine recall under 2-back. 24 participants.
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  std::vector<ex::TrialRow> rows;
  for (int k = 1; k <= 24; ++k) {
    const std::string who = (k < 10 ? "P0" : "P") + std::to_string(k);
    auto s = session_of(p, who);
    const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "default"), s);
    while (!s.finished()) rows.push_back(s.answer(sim.respond(s)).row);
  }
  const fs::path out = fs::temp_directory_path() / ("texel-wm-components-" + std::to_string(::getpid()));
  ex::AnalysisOptions o;
  o.out_dir = out.string();
  const ex::AnalysisReport report = ex::analyze(rows, o);
  const json s = json::parse(report.summary)["working-memory-components"];
  // The RM-ANOVA has the distractor factor with its four levels.
  std::map<std::string, json> effects;
  for (const auto& e : s["rm_anova"]["effects"]) effects[e["effect"].get<std::string>()] = e;
  ASSERT_TRUE(effects.count("distractor")) << s["rm_anova"].dump();
  EXPECT_EQ(effects["distractor"]["df"], 3);
  EXPECT_EQ(effects["spacing:distractor"]["df"], 3);
  EXPECT_LT(effects["spacing:distractor"]["p"].get<double>(), 0.05);  // the hypothesis is a texture × component interaction
  // Per texture, each component against the control, Holm over the six.
  std::map<std::string, json> tests;
  for (const auto& t : s["spacing_t_tests"])
    tests[t["spacing"].get<std::string>() + "-" + t["distractor"].get<std::string>()] = t["t_test"];
  ASSERT_EQ(tests.size(), 6u);
  for (const auto& [name, t] : tests) EXPECT_TRUE(t.contains("p_holm")) << name;
  EXPECT_LT(tests["coarse-visuospatial"]["mean"].get<double>(), -0.05);
  EXPECT_LT(tests["coarse-visuospatial"]["p"].get<double>(), 0.05);
  EXPECT_LT(tests["fine-executive"]["mean"].get<double>(), -0.05);
  EXPECT_LT(tests["fine-executive"]["p"].get<double>(), 0.05);
  EXPECT_GT(tests["fine-verbal"]["p"].get<double>(), 0.05);
  EXPECT_GT(tests["fine-visuospatial"]["p"].get<double>(), 0.05);
  // The distraction tasks were scored: recall for the matrix and the sequence, hits for 2-back.
  std::map<std::string, json> tasks;
  for (const auto& t : s["distraction_tasks"]) tasks[t["distractor"].get<std::string>()] = t;
  EXPECT_NEAR(tasks["visuospatial"]["recall_accuracy"]["mean"].get<double>(), 0.8, 0.06);
  EXPECT_NEAR(tasks["verbal"]["recall_accuracy"]["mean"].get<double>(), 0.8, 0.06);
  EXPECT_NEAR(tasks["executive"]["hit_rate"]["mean"].get<double>(), 0.85, 0.06);
  EXPECT_NEAR(tasks["executive"]["false_alarms_per_trial"]["mean"].get<double>(), 7 * 0.05, 0.1);
  // The figure of the per-component effects.
  EXPECT_TRUE(fs::exists(out / "working-memory-components-effects.png"));
  EXPECT_TRUE(fs::exists(out / "working-memory-components-performance.png"));
  EXPECT_NE(report.text.find("fine spacing, executive − control (paired): t(23) = "), std::string::npos) << report.text;

  // The source's exclusion rule over every distractor's errors: a participant
  // with many main-task errors and no more distraction errors than the group
  // is excluded; one whose distraction errors rose with them is kept.
  for (auto& r : rows) {
    if (r.practice || r.task != "same-different") continue;
    if (r.participant == "P01" || r.participant == "P02") r.correct = 0;  // every same/different answer wrong
    if (r.participant == "P01") {
      if (std::isfinite(r.digit_correct) && r.condition.find("control") == std::string::npos) r.digit_correct = 1;
      if (std::isfinite(r.nback_hits)) r.nback_hits = r.nback_targets, r.nback_false_alarms = 0;
    }
    if (r.participant == "P02" && std::isfinite(r.nback_hits)) r.nback_false_alarms = 2;  // every 2-back trial an error
  }
  const json x = json::parse(ex::analyze(rows, {}).summary)["working-memory-components"];
  std::map<std::string, json> people;
  for (const auto& q : x["participants"]) people[q["participant"].get<std::string>()] = q;
  EXPECT_TRUE(people["P01"]["excluded"].is_string()) << people["P01"].dump();
  EXPECT_EQ(people["P02"]["excluded"], false) << people["P02"].dump();
  EXPECT_EQ(x["included"], 23);
  fs::remove_all(out);
}

TEST(WorkingMemoryComponents, SimulateSpecSetsTheTwoBackObserver) {
  const ex::Protocol p = ex::load_protocol(shipped_path.string());
  const json o = json::parse(ex::simulation_observer(p.observer, "hit=60%,false-alarm=0.2"));
  EXPECT_DOUBLE_EQ(o["memory"]["p_hit"].get<double>(), 0.6);
  EXPECT_DOUBLE_EQ(o["memory"]["p_false_alarm"].get<double>(), 0.2);
  EXPECT_EQ(o["memory"]["p_correct"]["fine-executive"], 0.62);  // the protocol's hypothesis kept
  EXPECT_NE(error_of([&] { (void)ex::simulation_observer(p.observer, "hit=1.5"); }).find("p_hit"), std::string::npos);
  // An observer who never responds scores no hit and no false alarm.
  auto s = session_of(p);
  const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "hit=0,false-alarm=0"), s);
  int executive = 0;
  while (!s.finished()) {
    const ex::StoredTrial t = s.answer(sim.respond(s));
    if (std::isfinite(t.row.nback_targets)) {
      ++executive;
      EXPECT_EQ(t.row.nback_hits, 0);
      EXPECT_EQ(t.row.nback_false_alarms, 0);
    }
  }
  EXPECT_EQ(executive, 20);  // coarse and fine, 2 training and 8 test trials each
}

TEST(WorkingMemoryComponents, NBackColumnsRoundTripAndOlderRowsReadThemEmpty) {
  ex::TrialRow row;
  row.task = "same-different";
  row.nback_targets = 3, row.nback_hits = 2, row.nback_false_alarms = 1;
  const ex::TrialRow back = ex::row_from_json(ex::row_json(row), "row");
  EXPECT_EQ(back.nback_targets, 3);
  EXPECT_EQ(back.nback_hits, 2);
  EXPECT_EQ(back.nback_false_alarms, 1);
  const auto csv = ex::parse_trials_csv(ex::trials_csv({row}), "csv");
  ASSERT_EQ(csv.size(), 1u);
  EXPECT_EQ(csv[0].nback_false_alarms, 1);
  // A row stored before the columns existed (the store keeps rows as their
  // JSON cells; nothing is migrated): the three read back missing.
  json old = json::parse(ex::row_json(row));
  for (const char* k : {"nback_targets", "nback_hits", "nback_false_alarms"}) old.erase(k);
  const ex::TrialRow before = ex::row_from_json(old.dump(), "row");
  EXPECT_TRUE(std::isnan(before.nback_targets) && std::isnan(before.nback_hits) && std::isnan(before.nback_false_alarms));
  EXPECT_EQ(before.task, "same-different");
}

TEST(WorkingMemoryComponents, EachComponentIsComparedWithItsOwnControlWhereItHasOne) {
  // Conditions "coarse-<component>" and "coarse-<component>-control".
  const ex::Protocol p = with_every_control();
  std::vector<ex::TrialRow> rows;
  for (const char* who : {"A1", "A2", "A3", "A4"}) {
    auto s = session_of(p, who);
    const ex::SimulatedParticipant sim(ex::simulation_observer(p.observer, "default"), s);
    while (!s.finished()) rows.push_back(s.answer(sim.respond(s)).row);
  }
  const json s = json::parse(ex::analyze(rows, {}).summary)["working-memory-components"];
  std::vector<std::string> comparisons;
  for (const auto& t : s["spacing_t_tests"]) {
    EXPECT_EQ(t["spacing"], "coarse");
    comparisons.push_back(t["t_test"]["comparison"].get<std::string>());
  }
  EXPECT_EQ(comparisons, (std::vector<std::string>{"visuospatial − visuospatial-control", "verbal − verbal-control",
                                                   "executive − executive-control"}));
  std::set<std::string> levels;
  for (const auto& c : s["conditions"]) levels.insert(c["distractor"].get<std::string>());
  EXPECT_EQ(levels.size(), 6u);  // one factor of six levels in the RM-ANOVA
}
