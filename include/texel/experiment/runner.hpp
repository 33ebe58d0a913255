// Running a session against the store: the part every front door shares
// (terminal runner, studio, Python). open_session() starts a new session or
// resumes the participant's unfinished one (taking the writer lock and
// replaying the stored trials, so the engine is exactly where it stopped);
// record() answers the current question and commits the trial before the
// next question exists; simulate_cohort() runs simulated participants end
// to end (demos, planning, tests).
//
// Answer binding (docs/studio.md "The token rule"). A front end that shows
// questions on screens it does not control (the studio's participant page,
// a notebook) takes each question with hand_out(): the question comes with
// an opaque token bound to (database, session, trial, attempt, this opening
// of the session). record(store, active, token, response) stores the answer
// only if the token is the current one of a running session and otherwise
// throws AnswerRefused saying why (stale trial, session stopped, suspended,
// another session, restarted). The same call keeps the trial's clock:
// onset (the first hand-out), suspend/resume and restart are events of the
// trial, the reaction time runs from onset without the suspended time, and
// the row is flagged when the trial ran over its limit or spanned an
// interruption (docs/experiments.md "Running a study with people").
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "texel/error.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/experiment/store.hpp"

namespace texel::experiment {

struct OpenOptions {
  std::string participant;
  bool resume = false;                  ///< continue the participant's unfinished session (error if none)
  std::optional<std::string> simulate;  ///< simulation spec; on resume, missing = the stored one
};

/// The clock of the trial on screen (kept by the library, per token).
struct TrialClock {
  int trial = -1;            ///< trial the clock belongs to (-1: not handed out yet)
  int attempt = 0;           ///< 0 on first hand-out; +1 per restart of the trial
  double onset_s = 0.0;      ///< ActiveSession::now() at onset
  std::string onset_at;      ///< UTC time stamp of onset
  double suspended_s = 0.0;  ///< closed suspended intervals
  std::optional<double> suspended_since;
  bool interrupted = false;        ///< suspended, resumed after a stop/restart, or restarted
  std::vector<TrialEvent> events;  ///< onset, suspend, resume, restart (t_s from onset)
};

/// A session being run: its record, the writer lock and the engine.
struct ActiveSession {
  SessionInfo info;
  WriterLock lock;
  Session session;
  std::string simulate;  ///< spec in force ("" = a person answers)

  // Answer binding and timing (token path; the plain record() ignores them).
  std::string database;       ///< identity of the store (its canonical path)
  std::uint64_t opening = 0;  ///< random number of this opening: tokens of an earlier process never match
  bool resumed = false;       ///< opened with resume: the first trial on screen spans an interruption
  bool suspended = false;     ///< the experimenter paused it: answers are refused, the clock stops
  TrialClock clock;
  /// Seconds on a monotonic clock (steady_clock by default; tests set their own).
  std::function<double()> now;
};

/// How a reload of a participant screen treats the trial (protocol
/// "on_reload"): keep_clock (default) hands the same token and onset out
/// again; restart_trial starts a new attempt with a new onset and a
/// "restart" event (the trial is flagged interrupted).
enum class ReloadRule { keep_clock, restart_trial };
ReloadRule reload_rule(const Protocol& protocol);

/// Why an answer was not stored.
enum class Refusal {
  malformed,
  other_database,
  other_session,
  session_stopped,
  session_finished,
  session_suspended,
  restarted,
  stale_trial
};
std::string_view to_string(Refusal r);  ///< "malformed", "other_database", … (the studio's reason field)

/// An answer refused by the token rule. what() is one plain sentence a
/// participant screen can show.
class AnswerRefused : public InvalidArgument {
 public:
  AnswerRefused(Refusal reason, const std::string& message) : InvalidArgument(message), reason_(reason) {}
  [[nodiscard]] Refusal reason() const { return reason_; }

 private:
  Refusal reason_;
};

/// open_session could not do what was asked: the participant already has an
/// unfinished session of the protocol (a new one was asked for), or has none
/// to resume. what() says so in the library's terms; each front door adds how
/// to do the other in its own (the CLI's --resume, Python's resume=True).
class SessionConflict : public InvalidArgument {
 public:
  enum class Kind { unfinished_exists, nothing_to_resume };
  SessionConflict(Kind kind, const std::string& message) : InvalidArgument(message), kind_(kind) {}
  [[nodiscard]] Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

/// The current question as handed to a screen.
struct Handout {
  std::string token;
  int trial = 0;         ///< 0-based
  int trial_number = 0;  ///< 1-based: what a participant is shown (the export's trial_number)
  int attempt = 0;
  std::string onset_at;       ///< UTC time stamp of onset
  double elapsed_s = 0.0;     ///< since onset, without suspended time
  double time_limit_s = 0.0;  ///< 0 = none
  bool suspended = false;
};
/// A screen's view of a hand-out (JSON text: token, trial_number, attempt,
/// onset_at, elapsed_s, time_limit_s, suspended — the studio's `handout`).
std::string to_json(const Handout& h);

/// Hands the current question out: starts its clock on the first call for a
/// trial (onset), later calls return the same token and onset. Throws Error
/// when the session is finished.
Handout hand_out(ActiveSession& active);
/// The hand-out as it stands, without starting the clock (for a view that
/// is not the participant's, e.g. the experimenter's): before the first
/// hand-out the token is the one it will give, onset_at empty, elapsed 0.
Handout peek(const ActiveSession& active);
/// A screen was reloaded: under ReloadRule::restart_trial the trial starts
/// again (new attempt, token and onset; the old token is refused), under
/// keep_clock it is hand_out(). Returns the hand-out in force.
Handout reload(ActiveSession& active);
/// Pauses / continues the session: events of the trial on screen; while
/// suspended answers are refused and the clock does not run. Idempotent.
void suspend(ActiveSession& active);
void resume(ActiveSession& active);

/// Throws AnswerRefused unless `token` is the current token of `active`
/// (nullptr: no session is running in this process) and it is running.
void check_token(const Store& store, const ActiveSession* active, std::string_view token);

/// Starts or resumes (see OpenOptions). A resumed session runs the protocol
/// copy stored with it, not `protocol` (only its name is used to find it).
/// Throws InvalidArgument: no unfinished session to resume, or one exists
/// and resume was not asked for; Error: another process is writing it.
ActiveSession open_session(Store& store, const Protocol& protocol, const OpenOptions& options);

/// Answers the current question with `r`, stores the trial durably and, if
/// that was the last one, marks the session finished. Returns the trial.
/// InvalidArgument (bad response) leaves everything untouched.
StoredTrial record(Store& store, ActiveSession& active, const Response& r);
/// The token path: check_token(), then the answer with the library's clock
/// (rt_ms from onset without suspended time and shown_at = onset unless `r`
/// has them — a front end with its own frame clock; the studio clears them —,
/// the trial's onset/suspend/resume/restart events before the screen's own) and the
/// export flags (over_time_limit, interrupted, suspended_ms). A refused
/// answer stores nothing.
StoredTrial record(Store& store, ActiveSession* active, std::string_view token, Response r);

/// The simulated participant for an active session (its simulate spec over
/// the protocol's observer). Throws InvalidArgument for a bad spec.
SimulatedParticipant simulated_participant(const ActiveSession& active);

/// Runs `participants` (codes) through `protocol` with simulated observers,
/// each to the end (resuming unfinished ones). Returns the session ids.
std::vector<std::int64_t> simulate_cohort(Store& store, const Protocol& protocol, const std::vector<std::string>& participants,
                                          const std::string& spec = "default");

}  // namespace texel::experiment
