// The token rule (runner.hpp, docs/studio.md "The token rule"): an answer is
// stored only for the current token of a running session. The issue's
// reproduction (Z1 stopped, Z2 started, Z1's answer sent) and its variants:
// suspend, switch, restart in a new process, two screens answering the same
// trial, a replayed message. Then honest timing: onset kept per token,
// suspended time left out of rt_ms, the export flags, and a database whose
// rows were stored before the flags existed still resumes and exports.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>

#include <cmath>
#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "fixtures.hpp"
#include "texel/error.hpp"
#include "texel/experiment/runner.hpp"

namespace ex = texel::experiment;
namespace fs = std::filesystem;
using texel::test_support::RawDb;
using texel::test_support::TempDir;

namespace {

const fs::path protocols = fs::path(TEXEL_TEST_SOURCE_DIR) / "examples" / "protocols";

// The shipped texel-length protocol without its untimed practice block, so
// the first question is a timed (30 s) staircase trial.
ex::Protocol texel_length(const std::string& on_reload = "") {
  auto j = nlohmann::json::parse(ex::load_protocol((protocols / "texel-length.json").string()).json);
  auto& blocks = j["blocks"];
  blocks.erase(std::remove_if(blocks.begin(), blocks.end(), [](const auto& b) { return b.value("practice", false); }),
               blocks.end());
  if (!on_reload.empty()) j["on_reload"] = on_reload;
  return ex::parse_protocol(j.dump(), "test protocol");
}

// A fake monotonic clock the tests move by hand.
struct FakeClock {
  double t = 1000.0;
};

ex::ActiveSession open(ex::Store& st, const std::string& who, FakeClock& clock, bool resume = false,
                       const ex::Protocol& p = texel_length()) {
  ex::OpenOptions o;
  o.participant = who;
  o.resume = resume;
  ex::ActiveSession a = ex::open_session(st, p, o);
  a.now = [&clock] { return clock.t; };
  return a;
}

// A valid answer to the current question (the first choice).
ex::Response answer_of(const ex::ActiveSession& a) {
  ex::Response r;
  r.choice = a.session.question().choices.at(0);
  return r;
}

ex::Refusal refusal_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ex::AnswerRefused& e) {
    EXPECT_FALSE(std::string(e.what()).empty());
    return e.reason();
  }
  ADD_FAILURE() << "the answer was not refused";
  return ex::Refusal::malformed;
}

}  // namespace

TEST(AnswerToken, TheIssuesReproductionWrongSessionIsRefusedAndNothingStored) {
  TempDir dir("token");
  auto st = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  FakeClock clock;
  std::optional<ex::ActiveSession> active(open(st, "Z1", clock));
  const ex::Handout z1 = ex::hand_out(*active);
  const ex::Response z1_answer = answer_of(*active);
  const auto z1_id = active->info.id;
  active.reset();  // the experimenter stops Z1

  // Z1's screen answers while nothing runs: refused, session stopped.
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, nullptr, z1.token, z1_answer); }), ex::Refusal::session_stopped);

  active.emplace(open(st, "Z2", clock));  // ... and starts Z2
  (void)ex::hand_out(*active);
  clock.t += 2.0;
  const std::string msg =
      texel::test_support::message_of<ex::AnswerRefused>([&] { (void)ex::record(st, &*active, z1.token, z1_answer); });
  EXPECT_NE(msg.find("another session is running"), std::string::npos) << msg;
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &*active, z1.token, z1_answer); }), ex::Refusal::other_session);
  EXPECT_TRUE(st.trials(active->info.id).empty());
  EXPECT_TRUE(st.trials(z1_id).empty());
  EXPECT_EQ(active->session.trials_done(), 0);

  // Z2's own answer goes through, to Z2.
  const ex::Handout z2 = ex::hand_out(*active);
  const auto t = ex::record(st, &*active, z2.token, answer_of(*active));
  EXPECT_EQ(t.row.participant, "Z2");
  EXPECT_EQ(st.trials(active->info.id).size(), 1u);
}

TEST(AnswerToken, SuspendedSessionRefusesAndTheSameTokenWorksAfterResume) {
  TempDir dir("token");
  auto st = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  FakeClock clock;
  auto a = open(st, "S01", clock);
  const ex::Handout h = ex::hand_out(a);
  clock.t += 5.0;
  ex::suspend(a);
  clock.t += 30.0;
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &a, h.token, answer_of(a)); }), ex::Refusal::session_suspended);
  EXPECT_TRUE(st.trials(a.info.id).empty());
  const ex::Handout during = ex::hand_out(a);
  EXPECT_TRUE(during.suspended);
  EXPECT_NEAR(during.elapsed_s, 5.0, 1e-6);  // the clock stops while suspended
  clock.t += 8.2;
  ex::resume(a);
  clock.t += 3.0;
  const ex::Handout after = ex::hand_out(a);
  EXPECT_EQ(after.token, h.token);  // the same trial, its clock intact
  EXPECT_EQ(after.onset_at, h.onset_at);
  EXPECT_NEAR(after.elapsed_s, 8.0, 1e-6);
  const auto t = ex::record(st, &a, h.token, answer_of(a));
  // 46.2 s on the wall, 38.2 s of it suspended: 8 s reaction time, flagged interrupted, not over the 30 s limit.
  EXPECT_NEAR(t.row.rt_ms, 8000.0, 1e-6);
  EXPECT_NEAR(t.row.suspended_ms, 38200.0, 1e-6);
  EXPECT_EQ(t.row.interrupted, 1.0);
  EXPECT_EQ(t.row.over_time_limit, 0.0);
  EXPECT_EQ(t.row.time_limit_s, 30.0);
  EXPECT_EQ(t.row.shown_at, h.onset_at);
  const auto stored = st.trials(a.info.id);
  std::vector<std::string> kinds;
  for (const auto& e : stored.at(0).events) kinds.push_back(e.kind);
  ASSERT_EQ(kinds, (std::vector<std::string>{"onset", "suspend", "resume", "answer"}));
  EXPECT_NEAR(stored[0].events[1].t_s, 5.0, 1e-9);
  EXPECT_NEAR(stored[0].events[3].t_s, 46.2, 1e-9);
}

TEST(AnswerToken, OverTheLimitIsFlagged) {
  TempDir dir("token");
  auto st = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  FakeClock clock;
  auto a = open(st, "S01", clock);
  const ex::Handout h = ex::hand_out(a);
  EXPECT_EQ(h.time_limit_s, 30.0);
  EXPECT_EQ(h.trial_number, 1);
  clock.t += 43.2;
  const auto t = ex::record(st, &a, h.token, answer_of(a));
  EXPECT_NEAR(t.row.rt_ms, 43200.0, 1e-6);
  EXPECT_EQ(t.row.over_time_limit, 1.0);
  EXPECT_EQ(t.row.interrupted, 0.0);
  const std::string csv = ex::trials_csv(st.rows());
  const auto header = csv.substr(0, csv.find('\n'));
  for (const char* col : {"trial_number", "time_limit_s", "over_time_limit", "interrupted", "suspended_ms"})
    EXPECT_NE(header.find(col), std::string::npos) << col;
  const auto back = ex::parse_trials_csv(csv, "export");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].over_time_limit, 1.0);
  EXPECT_EQ(back[0].trial, 0);
}

TEST(AnswerToken, TwoScreensAnsweringTheSameTrialAndAReplayedMessage) {
  TempDir dir("token");
  auto st = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  FakeClock clock;
  auto a = open(st, "S01", clock);
  const ex::Handout screen1 = ex::hand_out(a);
  const ex::Handout screen2 = ex::hand_out(a);  // a second screen (or a reload) gets the same question
  EXPECT_EQ(screen1.token, screen2.token);
  const ex::Response r = answer_of(a);
  (void)ex::record(st, &a, screen1.token, r);
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &a, screen2.token, r); }), ex::Refusal::stale_trial);
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &a, screen1.token, r); }), ex::Refusal::stale_trial);  // replayed
  EXPECT_EQ(st.trials(a.info.id).size(), 1u);
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &a, "q1.junk", r); }), ex::Refusal::malformed);
  std::string other_db = ex::hand_out(a).token;
  other_db[3] = other_db[3] == 'a' ? 'b' : 'a';
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &a, other_db, r); }), ex::Refusal::other_database);
  EXPECT_EQ(st.trials(a.info.id).size(), 1u);
}

TEST(AnswerToken, RestartInANewProcessRefusesTheOldTokenAndFlagsTheTrial) {
  TempDir dir("token");
  const auto path = dir.at("exp.db");
  std::string old_token;
  {
    auto st = ex::Store::open(path, ex::StoreMode::read_write);
    FakeClock clock;
    auto a = open(st, "S01", clock);
    old_token = ex::hand_out(a).token;
  }
  // The new server is another process (the writer lock is per process).
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    int code = 0;
    try {
      auto st = ex::Store::open(path, ex::StoreMode::read_write);
      FakeClock clock;
      auto a = open(st, "S01", clock, /*resume=*/true);
      try {
        (void)ex::record(st, &a, old_token, answer_of(a));
        code = 10;  // stored: wrong
      } catch (const ex::AnswerRefused& e) {
        if (e.reason() != ex::Refusal::restarted) code = 11;
      }
      if (code == 0) {
        const ex::Handout h = ex::hand_out(a);
        if (h.token == old_token) code = 12;
        clock.t += 2.0;
        const auto t = ex::record(st, &a, h.token, answer_of(a));
        if (t.row.interrupted != 1.0) code = 13;
        if (st.trials(a.info.id).size() != 1u) code = 14;
      }
    } catch (...) {
      code = 20;
    }
    _exit(code);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  auto st = ex::Store::open(path, ex::StoreMode::read_only);
  const auto stored = st.trials(1);
  ASSERT_EQ(stored.size(), 1u);
  std::vector<std::string> kinds;
  for (const auto& e : stored[0].events) kinds.push_back(e.kind);
  EXPECT_EQ(kinds, (std::vector<std::string>{"onset", "restart", "answer"}));
}

TEST(AnswerToken, ReloadKeepsTheClockOrRestartsTheTrialAsTheProtocolSays) {
  TempDir dir("token");
  auto st = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  FakeClock clock;
  {
    auto a = open(st, "K01", clock);
    const ex::Handout h = ex::hand_out(a);
    clock.t += 12.0;
    const ex::Handout again = ex::reload(a);
    EXPECT_EQ(again.token, h.token);
    EXPECT_EQ(again.onset_at, h.onset_at);
    EXPECT_NEAR(again.elapsed_s, 12.0, 1e-6);
  }
  auto a = open(st, "R01", clock, false, texel_length("restart_trial"));
  const ex::Handout h = ex::hand_out(a);
  clock.t += 12.0;
  const ex::Handout again = ex::reload(a);
  EXPECT_NE(again.token, h.token);
  EXPECT_EQ(again.attempt, 1);
  EXPECT_NEAR(again.elapsed_s, 0.0, 1e-6);
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &a, h.token, answer_of(a)); }), ex::Refusal::stale_trial);
  clock.t += 1.5;
  const auto t = ex::record(st, &a, again.token, answer_of(a));
  EXPECT_NEAR(t.row.rt_ms, 1500.0, 1e-6);
  EXPECT_EQ(t.row.interrupted, 1.0);
  EXPECT_THROW_MSG((void)texel_length("sometimes"), texel::FormatError,
                   "on_reload is 'sometimes'; allowed: keep_clock, restart_trial");
}

TEST(AnswerToken, ThePlainRecordStillWorksBesideTheTokenPath) {
  TempDir dir("token");
  auto st = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  FakeClock clock;
  auto a = open(st, "S01", clock);
  const ex::Handout h = ex::hand_out(a);
  ex::Response r = answer_of(a);
  r.rt_ms = 31000;
  const auto t = ex::record(st, a, r);
  EXPECT_EQ(t.row.over_time_limit, 1.0);
  EXPECT_TRUE(std::isnan(t.row.interrupted));
  EXPECT_EQ(refusal_of([&] { (void)ex::record(st, &a, h.token, answer_of(a)); }), ex::Refusal::stale_trial);
}

TEST(AnswerToken, RowsStoredBeforeTheFlagsResumeAndExport) {
  // A database as main's code wrote it: rows without trial_number and the flag columns.
  TempDir dir("token");
  const auto path = dir.at("old.db");
  {
    auto st = ex::Store::open(path, ex::StoreMode::read_write);
    FakeClock clock;
    auto a = open(st, "S01", clock);
    for (int i = 0; i < 3; ++i) (void)ex::record(st, a, answer_of(a));
  }
  {
    RawDb raw(path);
    raw.exec(
        "UPDATE trials SET row_json = json_remove(row_json, '$.trial_number', '$.time_limit_s', '$.over_time_limit', "
        "'$.interrupted', '$.suspended_ms')");
    EXPECT_EQ(raw.one("SELECT COUNT(*) FROM trials WHERE row_json LIKE '%trial_number%'"), "0");
  }
  auto st = ex::Store::open(path, ex::StoreMode::read_write);
  FakeClock clock;
  auto a = open(st, "S01", clock, /*resume=*/true);
  EXPECT_EQ(a.session.trials_done(), 3);
  const ex::Handout h = ex::hand_out(a);
  EXPECT_EQ(h.trial_number, 4);
  (void)ex::record(st, &a, h.token, answer_of(a));
  const auto rows = st.rows();
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_TRUE(std::isnan(rows[0].over_time_limit));
  EXPECT_TRUE(std::isnan(rows[0].time_limit_s));
  EXPECT_EQ(rows[3].interrupted, 1.0);  // resumed: the trial on screen spanned the stop
  const std::string csv = ex::trials_csv(rows);
  EXPECT_NE(csv.find("trial_number"), std::string::npos);
  EXPECT_EQ(ex::parse_trials_csv(csv, "export").size(), 4u);
}

TEST(AnswerToken, PeekingDoesNotStartTheClock) {
  // The experimenter's view peeks; the clock starts when a screen is handed the question.
  TempDir dir("token");
  auto st = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  FakeClock clock;
  auto a = open(st, "S01", clock);
  const ex::Handout seen = ex::peek(a);
  EXPECT_TRUE(seen.onset_at.empty());
  clock.t += 100.0;  // the participant's screen opens late
  const ex::Handout h = ex::hand_out(a);
  EXPECT_EQ(h.token, seen.token);
  EXPECT_NEAR(h.elapsed_s, 0.0, 1e-9);
  clock.t += 2.0;
  EXPECT_NEAR(ex::peek(a).elapsed_s, 2.0, 1e-9);
  EXPECT_NEAR(ex::record(st, &a, h.token, answer_of(a)).row.rt_ms, 2000.0, 1e-6);
  // Answered with a peeked token before any screen had it: stored, without a reaction time.
  const ex::Handout next = ex::peek(a);
  const auto t = ex::record(st, &a, next.token, answer_of(a));
  EXPECT_TRUE(std::isnan(t.row.rt_ms));
  EXPECT_EQ(t.row.trial, 1);
}
