// The one vocabulary of a session's state (docs/experiments.md "Session
// states"): the CLI's `experiment list/status`, the studio's sessions table
// and Pause button, and Python all name a session's state with these words,
// from these functions, so one session never reads "suspended" in one front
// door, "running" in another and "paused" in a third.
//
// The store knows whether a session finished; whether one is being run now,
// and whether its experimenter paused it, only the front door that holds it
// knows (runner.hpp's ActiveSession). So a state is derived from both: the
// store alone gives `stopped` or `finished`; the holder says `running` or
// `paused`. Trade-off: the CLI, reading the database beside a running
// studio, reports that studio's session as `stopped` (resumable) — the
// pause lives in the studio's memory and is not stored.
#pragma once

#include <string_view>

#include "texel/experiment/store.hpp"

namespace texel::experiment {

enum class SessionState {
  running,   ///< a front door is running it now: questions are handed out, answers stored
  paused,    ///< held by a front door whose experimenter paused it: answers refused, the clock stopped
  stopped,   ///< not finished and held by nobody (stopped, interrupted or crashed): resumable where it stopped
  finished,  ///< every block done
};

/// "running", "paused", "stopped", "finished".
std::string_view to_string(SessionState s);
/// The state named `text`; InvalidArgument naming `field` and the allowed words otherwise.
SessionState parse_session_state(std::string_view text, std::string_view field = "state");

/// The state of a stored session: `finished`, else `stopped`, else — when
/// the caller holds it (`held`) — `paused` if `suspended`, else `running`.
SessionState session_state(const SessionInfo& s, bool held = false, bool suspended = false);

}  // namespace texel::experiment
