// The N-up/M-down staircase: PsychoPy's published test case, the thesis' two
// staircases over hand-worked answers, step types, clamping, nTrials, replay,
// bad input, and the 79.4 % convergence of 1-up/3-down with a simulated observer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../support/expect.hpp"

#include "texel/error.hpp"
#include "texel/experiment/observer.hpp"
#include "texel/experiment/staircase.hpp"

using namespace texel::experiment;

namespace {

// Like PsychoPy's own test (it rounds): 0.8 − 0.1 is not exactly 0.7.
constexpr double tol = 1e-9;

Staircase run(const StaircaseConfig& c, const std::vector<int>& answers) {
  Staircase s(c);
  for (int a : answers) s.answer(a == 1);
  return s;
}

void expect_near_all(const std::vector<double>& got, const std::vector<double>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(got[i], want[i], tol) << "index " << i;
}

std::vector<bool> to_bools(const std::vector<int>& v) { return {v.begin(), v.end()}; }

}  // namespace

TEST(Staircase, PublishedTestCase) {
  StaircaseConfig c;
  c.start_value = 0.8;
  c.step_sizes = {0.1, 0.01, 0.001};
  c.n_up = 1;
  c.n_down = 3;
  c.n_reversals = 4;
  c.n_trials = 20;
  Staircase s(c);
  const int pattern[] = {1, 1, 1, 1, 0, 0, 0, 0};
  int t = 0;
  while (!s.finished()) s.answer(pattern[t++ % 8] == 1);
  expect_near_all(s.intensities(), {0.8,  0.7,   0.6,   0.5,  0.4,   0.41,  0.42,  0.43,  0.44,  0.44,
                                    0.44, 0.439, 0.439, 0.44, 0.441, 0.442, 0.443, 0.443, 0.443, 0.442});
  EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{4, 10, 12, 18}));
  expect_near_all(s.reversal_intensities(), {0.4, 0.44, 0.439, 0.443});
  EXPECT_EQ(s.trials(), 20u);
  EXPECT_NEAR(s.convergent_value(), 0.442, tol);  // trial 19 answered 0 → up by 0.001
  EXPECT_NEAR(s.current_step(), 0.001, 0);
  EXPECT_THROW((void)s.next(), texel::Error);
  EXPECT_THROW(s.answer(true), texel::Error);
}

// Texel length (thesis): start 26 mm, seven steps of 2.5 mm then 1.25 mm,
// 1-up/3-down, 10 reversals, lin. Worked by hand:
//  trial value answer  → move (reversal #, new step)
//   0  26     1  down (initial rule)        → 23.5
//   1  23.5   1  down                       → 21
//   2  21     1  down                       → 18.5
//   3  18.5   0  up: reversal 1, step[1]=2.5 → 21   (rule is now 1-up/3-down)
//   4  21     1  run +1
//   5  21     1  run +2
//   6  21     1  run +3 down: reversal 2    → 18.5
//   7  18.5   0  up: reversal 3             → 21
//   8  21     1  run +1
//   9  21     0  run −1 up, same direction: no reversal → 23.5
//  10-12 23.5 1,1,1 down: reversal 4 (trial 12) → 21
//  13  21     0  up: reversal 5             → 23.5
//  14-16 23.5 1,1,1 down: reversal 6 (16)   → 21
//  17  21     0  up: reversal 7, step[7]=1.25 applies to this move → 22.25
//  18-20 22.25 1,1,1 down: reversal 8 (20)  → 21
//  21  21     0  up: reversal 9             → 22.25
//  22-24 22.25 1,1,1 down: reversal 10 (24) → 21: finished, convergent 21
TEST(Staircase, ThesisTexelLength) {
  StaircaseConfig c;
  c.start_value = 26;
  c.step_sizes = {2.5, 2.5, 2.5, 2.5, 2.5, 2.5, 2.5, 1.25};
  c.n_reversals = 10;
  const std::vector<int> answers = {1, 1, 1, 0, 1, 1, 1, 0, 1, 0, 1, 1, 1, 0, 1, 1, 1, 0, 1, 1, 1, 0, 1, 1, 1};
  const Staircase s = run(c, answers);
  expect_near_all(s.intensities(), {26, 23.5, 21,   18.5, 21, 21,    21,    18.5,  21, 21,    23.5,  23.5, 23.5,
                                    21, 23.5, 23.5, 23.5, 21, 22.25, 22.25, 22.25, 21, 22.25, 22.25, 22.25});
  EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{3, 6, 7, 12, 13, 16, 17, 20, 21, 24}));
  expect_near_all(s.reversal_intensities(), {18.5, 21, 18.5, 23.5, 21, 23.5, 21, 22.25, 21, 22.25});
  EXPECT_TRUE(s.finished());
  EXPECT_NEAR(s.convergent_value(), 21, tol);
  EXPECT_NEAR(s.current_step(), 1.25, 0);
  EXPECT_NEAR(s.mean_last_reversals(4), (22.25 + 21 + 22.25 + 21) / 4, tol);
  EXPECT_NEAR(s.mean_reversals_excluding_first(8), (21 + 22.25) / 2, tol);
  EXPECT_NEAR(s.mean_last_reversals(100), (18.5 + 21 + 18.5 + 23.5 + 21 + 23.5 + 21 + 22.25 + 21 + 22.25) / 10, tol);
}

// Coarse strength (thesis): start 1.0, steps [0.10, 0.05], 1-up/3-down,
// 3 reversals, min 0, max 1. Worked by hand:
//  0  1.0   0  up (initial rule) 1.1 → clamped to 1.0 (first move: no reversal)
//  1  1.0   1  down: reversal 1, step 0.05   → 0.95
//  2  0.95  1  run +1
//  3  0.95  0  run −1 up: reversal 2         → 1.0
//  4  1.0   0  up again: no reversal 1.05    → clamped 1.0
//  5-7 1.0  1,1,1 down: reversal 3 (trial 7) → 0.95; finished
TEST(Staircase, ThesisCoarseStrengthClampsAtMax) {
  StaircaseConfig c;
  c.start_value = 1.0;
  c.step_sizes = {0.10, 0.05};
  c.n_reversals = 3;
  c.min_value = 0;
  c.max_value = 1;
  const Staircase s = run(c, {0, 1, 1, 0, 0, 1, 1, 1});
  expect_near_all(s.intensities(), {1.0, 1.0, 0.95, 0.95, 1.0, 1.0, 1.0, 1.0});
  EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{1, 3, 7}));
  expect_near_all(s.reversal_intensities(), {1.0, 0.95, 1.0});
  EXPECT_TRUE(s.finished());
  EXPECT_NEAR(s.convergent_value(), 0.95, tol);
}

// Same staircase hitting the minimum: eleven correct answers walk 1.0 down by
// 0.1 to 0.0 (trial 10 at 0.0 moves to −0.1, clamped to 0); then
//  11  0.0   0  up: reversal 1, step 0.05 → 0.05
//  12-14 0.05 1,1,1 down: reversal 2 (14) → 0.0
//  15  0.0   0  up: reversal 3 → 0.05; finished after 16 trials.
TEST(Staircase, ThesisCoarseStrengthClampsAtMin) {
  StaircaseConfig c;
  c.start_value = 1.0;
  c.step_sizes = {0.10, 0.05};
  c.n_reversals = 3;
  c.min_value = 0;
  c.max_value = 1;
  const Staircase s = run(c, {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 1, 1, 1, 0});
  expect_near_all(s.intensities(), {1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0, 0.0, 0.05, 0.05, 0.05, 0.0});
  EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{11, 14, 15}));
  EXPECT_TRUE(s.finished());
  EXPECT_NEAR(s.convergent_value(), 0.05, tol);
}

TEST(Staircase, StartValueIsNeverClamped) {
  StaircaseConfig c;
  c.start_value = 5;
  c.max_value = 1;
  c.min_value = 0;
  c.step_sizes = {1};
  c.n_reversals = 5;
  Staircase s(c);
  EXPECT_EQ(s.next(), 5.0);
  s.answer(true);  // down to 4: within [0, 1] only after an up move is max applied
  EXPECT_NEAR(s.next(), 4.0, tol);
  s.answer(false);  // up: 5 → clamped to 1
  EXPECT_NEAR(s.next(), 1.0, tol);
}

TEST(Staircase, LogAndDbSteps) {
  StaircaseConfig c;
  c.start_value = 10;
  c.step_sizes = {0.5};
  c.n_down = 1;
  c.n_reversals = 2;
  c.step_type = StepType::log;
  Staircase s = run(c, {1, 0, 1});
  expect_near_all(s.intensities(), {10, 10 * std::pow(10, -0.5), 10});
  EXPECT_NEAR(s.convergent_value(), 10 * std::pow(10, -0.5), tol);
  EXPECT_TRUE(s.finished());

  c.start_value = 1;
  c.step_sizes = {6};
  c.step_type = StepType::db;
  s = run(c, {1, 1, 0});
  expect_near_all(s.intensities(), {1, std::pow(10, -6.0 / 20), std::pow(10, -12.0 / 20)});
  EXPECT_NEAR(s.convergent_value(), std::pow(10, -6.0 / 20), tol);
  EXPECT_EQ(parse_step_type("db"), StepType::db);
  EXPECT_EQ(to_string(StepType::log), "log");
  EXPECT_THROW((void)parse_step_type("linear"), texel::InvalidArgument);
}

TEST(Staircase, WithoutInitialRuleUsesNupNdownFromTheStart) {
  StaircaseConfig c;
  c.start_value = 10;
  c.step_sizes = {1};
  c.apply_initial_rule = false;
  const Staircase s = run(c, {1, 1, 1, 0});
  expect_near_all(s.intensities(), {10, 10, 10, 9});
  EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{3}));
  EXPECT_NEAR(s.convergent_value(), 10, tol);
}

TEST(Staircase, EndValueLastPresentedReportsTheFinalValueShown) {
  StaircaseConfig c;
  c.start_value = 10;
  c.step_sizes = {1};
  c.n_reversals = 1;
  const Staircase next = run(c, {1, 0});  // down (initial rule), then up: a reversal, finished
  ASSERT_TRUE(next.finished());
  EXPECT_NEAR(next.computed_value(), 10, tol);
  EXPECT_NEAR(next.convergent_value(), 10, tol);  // next: the value computed after the last answer
  c.end_value = EndValue::last_presented;
  const Staircase last = run(c, {1, 0});
  EXPECT_NEAR(last.computed_value(), 10, tol);
  EXPECT_NEAR(last.convergent_value(), 9, tol);  // the last intensity presented
  EXPECT_NE(last.state_json().find("\"end_value\":\"last-presented\""), std::string::npos);
  // The default's state has no end_value key (stored states keep their bytes).
  EXPECT_EQ(next.state_json().find("end_value"), std::string::npos);
  // Before any answer both report the start value.
  EXPECT_NEAR(Staircase(c).convergent_value(), 10, tol);
  EXPECT_EQ(parse_end_value("last-presented"), EndValue::last_presented);
  EXPECT_EQ(to_string(EndValue::next), "next");
  EXPECT_THROW((void)parse_end_value("final"), texel::InvalidArgument);
}

TEST(Staircase, NTrialsIsAMinimumAndNReversalsIsRaised) {
  StaircaseConfig c;
  c.start_value = 0;
  c.step_sizes = {1};
  c.n_reversals = 1;
  c.n_trials = 5;
  Staircase s(c);
  s.answer(true);
  s.answer(false);  // reversal 1 at trial 1
  EXPECT_EQ(s.reversal_trials().size(), 1u);
  EXPECT_FALSE(s.finished());
  s.answer(true);
  s.answer(true);
  EXPECT_FALSE(s.finished());
  s.answer(true);
  EXPECT_TRUE(s.finished());

  c.step_sizes = {1, 0.5, 0.25};
  c.n_reversals = 1;  // below len(steps): raised to 3
  EXPECT_EQ(Staircase(c).n_reversals(), 3);
  c.n_reversals.reset();
  EXPECT_EQ(Staircase(c).n_reversals(), 3);
  c.n_reversals = 7;
  EXPECT_EQ(Staircase(c).n_reversals(), 7);
}

TEST(Staircase, ReplayRebuildsTheSameState) {
  StaircaseConfig c;
  c.start_value = 26;
  c.step_sizes = {2.5, 2.5, 1.25};
  c.n_reversals = 6;
  Staircase live(c);
  std::vector<int> answers;
  for (int t = 0; !live.finished(); ++t) {
    const bool a = (t * 7 + 3) % 5 != 0;
    answers.push_back(a);
    live.answer(a);
    const Staircase again = Staircase::replay(c, to_bools(answers));  // the std::vector<bool> overload
    EXPECT_EQ(again.state_json(), live.state_json());
  }
  // One answer more than it took: alternating answers reverse every trial.
  std::unique_ptr<bool[]> extra(new bool[answers.size() + 1]);
  for (std::size_t i = 0; i <= answers.size(); ++i) extra[i] = i < answers.size() ? answers[i] == 1 : true;
  EXPECT_NO_THROW((void)Staircase::replay(c, std::span<const bool>(extra.get(), answers.size())));
  EXPECT_THROW((void)Staircase::replay(c, std::span<const bool>(extra.get(), answers.size() + 1)), texel::InvalidArgument);
}

TEST(Staircase, StateJsonHasTheRecordFields) {
  const Staircase s = run(StaircaseConfig{}, {1, 0});
  const auto j = nlohmann::json::parse(s.state_json());
  EXPECT_EQ(j["procedure"], "staircase");
  EXPECT_EQ(j["trials"], 2);
  EXPECT_EQ(j["reversal_trials"], nlohmann::json::array({1}));
  EXPECT_EQ(j["config"]["step_type"], "lin");
  EXPECT_EQ(j["direction"], "up");
}

TEST(Staircase, ReversalMeansNeedReversals) {
  const Staircase s(StaircaseConfig{});
  EXPECT_THROW((void)s.mean_last_reversals(3), texel::Error);
  EXPECT_THROW((void)s.mean_reversals_excluding_first(0), texel::Error);
  const Staircase t = run(StaircaseConfig{}, {1, 0});
  EXPECT_THROW((void)t.mean_last_reversals(0), texel::Error);
  EXPECT_THROW((void)t.mean_reversals_excluding_first(1), texel::Error);
  EXPECT_NEAR(t.mean_last_reversals(5), -1, tol);  // min(k, n) = 1 reversal at −1
}

TEST(Staircase, BadConfigNamesTheField) {
  auto message = [](StaircaseConfig c) {
    return texel::test_support::message_of<texel::InvalidArgument>([&] { Staircase s(c); });
  };
  StaircaseConfig c;
  c.step_sizes = {};
  EXPECT_NE(message(c).find("step_sizes"), std::string::npos);
  c = {};
  c.step_sizes = {0.1, -1};
  EXPECT_NE(message(c).find("step_sizes[1]"), std::string::npos);
  c = {};
  c.n_up = 0;
  EXPECT_NE(message(c).find("n_up"), std::string::npos);
  c = {};
  c.n_down = 0;
  EXPECT_NE(message(c).find("n_down"), std::string::npos);
  c = {};
  c.n_trials = -1;
  EXPECT_NE(message(c).find("n_trials"), std::string::npos);
  c = {};
  c.min_value = 2;
  c.max_value = 1;
  EXPECT_NE(message(c).find("min_value"), std::string::npos);
  c = {};
  c.step_type = StepType::log;
  c.start_value = 0;
  EXPECT_NE(message(c).find("start_value"), std::string::npos);
  c = {};
  c.start_value = std::nan("");
  EXPECT_NE(message(c).find("start_value"), std::string::npos);
}

// 1-up/3-down converges on p = 0.5^(1/3) = 0.794 (Levitt 1971). A logistic
// observer (slope 1/unit, no guess, no lapse) has that point at
// x = ln(0.794/0.206) = 1.349. 400 seeded staircases of 40 reversals with a
// 0.25 step after the first two; the mean over runs of the mean reversal
// intensity (excluding the first 6) must lie within 0.1 of it (the step is
// 0.25; the across-run standard error is about 0.02, the rest allows for
// the small bias of reversal averaging).
TEST(Staircase, OneUpThreeDownConvergesOn79Percent) {
  PsychometricConfig pc;
  pc.shape = PsychometricShape::logistic;
  pc.threshold = 0;
  pc.slope = 1;
  double total = 0;
  const int runs = 400;
  for (int r = 0; r < runs; ++r) {
    pc.seed = 100 + static_cast<std::uint64_t>(r);
    const PsychometricObserver obs(pc);
    StaircaseConfig c;
    c.start_value = 5;
    c.step_sizes = {1, 0.5, 0.25};
    c.n_reversals = 40;
    Staircase s(c);
    for (std::uint64_t t = 0; !s.finished(); ++t) s.answer(obs.respond(s.next(), t));
    total += s.mean_reversals_excluding_first(6);
  }
  const double target = std::log(std::pow(0.5, 1.0 / 3) / (1 - std::pow(0.5, 1.0 / 3)));
  EXPECT_NEAR(total / runs, target, 0.1);
  RecordProperty("mean_reversal_estimate", std::to_string(total / runs));
  std::printf("1-up/3-down estimate %.4f, 79.4 %% point %.4f\n", total / runs, target);
}
