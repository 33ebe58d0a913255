// Durability under SIGKILL: a child process appends trials in a loop and is
// killed at a random moment, again and again on the same session. After each
// kill the database opens, the trial indices are 0..n-1 with no gap or
// duplicate, every stored trial is complete, nothing the child was told had
// been stored is lost, and the next run takes the dead writer's lock over
// (the --resume path). A power cut is not simulated here: synchronous=FULL
// is SQLite's own guarantee for that (docs/session-store.md).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <random>
#include <thread>

#include "../support/temp_dir.hpp"
#include "fixtures.hpp"
#include "texel/experiment/store.hpp"

namespace ex = texel::experiment;
using texel::test_support::full_trial;
using texel::test_support::TempDir;

namespace {

constexpr int kill_iterations = 25;

// The child: resume the session where it stands and append until killed,
// reporting each index on `report` after append_trial() has returned.
[[noreturn]] void append_forever(const std::string& path, std::int64_t id, int report) {
  try {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    auto lock = s.acquire_writer(id);
    for (int i = s.session(id).trials_done;; ++i) {
      s.append_trial(lock, full_trial(i));
      if (::write(report, &i, sizeof i) != sizeof i) ::_exit(3);
    }
  } catch (const std::exception& e) {
    const std::string msg = std::string("child: ") + e.what() + "\n";
    (void)!::write(2, msg.data(), msg.size());
    ::_exit(2);
  }
}

}  // namespace

TEST(StoreCrash, SigkillAtRandomMomentsLosesAndDuplicatesNothing) {
  TempDir dir("store-crash");
  const auto path = dir.at("exp.db");
  std::int64_t id = 0;
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    id = s.create_session("S01", "texel-length", "texel-length", "{}", 1, "", -1);
  }
  std::mt19937 rng(20261123);
  std::uniform_int_distribution<int> delay_us(0, 60000);
  int confirmed = 0;  // trials the children were told are stored
  int stored_before = 0;
  int grew = 0;
  for (int iteration = 0; iteration < kill_iterations; ++iteration) {
    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(pipe_fds[0]);
      append_forever(path, id, pipe_fds[1]);
    }
    ::close(pipe_fds[1]);
    // Every other kill lands after the child has confirmed a trial: a loaded
    // machine (ASan, -j2) can start it later than any random delay.
    if (iteration % 2 == 0) {
      int first = 0;
      if (::read(pipe_fds[0], &first, sizeof first) == sizeof first) confirmed = std::max(confirmed, first + 1);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "iteration " << iteration << ": the child exited on its own (status " << status << ")";
    int index = 0;
    while (::read(pipe_fds[0], &index, sizeof index) == sizeof index) confirmed = std::max(confirmed, index + 1);
    ::close(pipe_fds[0]);

    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    const auto trials = s.trials(id);
    const int n = static_cast<int>(trials.size());
    EXPECT_EQ(s.session(id).trials_done, n);
    // Committed before append_trial returned: nothing confirmed is lost, and
    // at most the one trial in flight is stored without confirmation.
    EXPECT_GE(n, confirmed) << "iteration " << iteration;
    EXPECT_LE(n, confirmed + 1) << "iteration " << iteration;
    EXPECT_GE(n, stored_before);
    if (n > stored_before) ++grew;
    stored_before = n;
    confirmed = n;
    for (int i = 0; i < n; ++i) {
      const auto& t = trials[static_cast<std::size_t>(i)];
      const auto want = full_trial(i);
      ASSERT_EQ(t.trial, i) << "iteration " << iteration;
      EXPECT_EQ(t.question_json, want.question_json);
      EXPECT_EQ(t.response_json, want.response_json);
      EXPECT_EQ(t.state_json, want.state_json);
      EXPECT_EQ(t.row.block, want.row.block);
      EXPECT_EQ(t.row.rt_ms, want.row.rt_ms);
      EXPECT_EQ(t.row.answered_at, want.row.answered_at);
      ASSERT_EQ(t.events.size(), want.events.size()) << "trial " << i;
    }
    EXPECT_EQ(s.rows(id).size(), static_cast<std::size_t>(n));
  }
  // The kills landed while trials were being written, not all before the first.
  EXPECT_GE(grew, kill_iterations / 3);
  EXPECT_GT(stored_before, 0);
}
