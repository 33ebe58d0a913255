// Running a session against the store: the part every front door shares
// (terminal runner, studio, Python). open_session() starts a new session or
// resumes the participant's unfinished one (taking the writer lock and
// replaying the stored trials, so the engine is exactly where it stopped);
// record() answers the current question and commits the trial before the
// next question exists; simulate_cohort() runs simulated participants end
// to end (demos, planning, tests).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

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

/// A session being run: its record, the writer lock and the engine.
struct ActiveSession {
  SessionInfo info;
  WriterLock lock;
  Session session;
  std::string simulate;  ///< spec in force ("" = a person answers)
};

/// Starts or resumes (see OpenOptions). A resumed session runs the protocol
/// copy stored with it, not `protocol` (only its name is used to find it).
/// Throws InvalidArgument: no unfinished session to resume, or one exists
/// and resume was not asked for; Error: another process is writing it.
ActiveSession open_session(Store& store, const Protocol& protocol, const OpenOptions& options);

/// Answers the current question with `r`, stores the trial durably and, if
/// that was the last one, marks the session finished. Returns the trial.
/// InvalidArgument (bad response) leaves everything untouched.
StoredTrial record(Store& store, ActiveSession& active, const Response& r);

/// The simulated participant for an active session (its simulate spec over
/// the protocol's observer). Throws InvalidArgument for a bad spec.
SimulatedParticipant simulated_participant(const ActiveSession& active);

/// Runs `participants` (codes) through `protocol` with simulated observers,
/// each to the end (resuming unfinished ones). Returns the session ids.
std::vector<std::int64_t> simulate_cohort(Store& store, const Protocol& protocol, const std::vector<std::string>& participants,
                                          const std::string& spec = "default");

}  // namespace texel::experiment
