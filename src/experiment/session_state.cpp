// The session states (session_state.hpp).
#include "texel/experiment/session_state.hpp"

#include <string>

#include "texel/error.hpp"

namespace texel::experiment {

std::string_view to_string(SessionState s) {
  switch (s) {
    case SessionState::running: return "running";
    case SessionState::paused: return "paused";
    case SessionState::stopped: return "stopped";
    case SessionState::finished: return "finished";
  }
  return "stopped";
}

SessionState parse_session_state(std::string_view text, std::string_view field) {
  for (const SessionState s : {SessionState::running, SessionState::paused, SessionState::stopped, SessionState::finished})
    if (text == to_string(s)) return s;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) +
                        "' is not a session state (allowed: running, paused, stopped, finished)");
}

SessionState session_state(const SessionInfo& s, bool held, bool suspended) {
  if (s.status == "finished") return SessionState::finished;
  if (!held) return SessionState::stopped;
  return suspended ? SessionState::paused : SessionState::running;
}

}  // namespace texel::experiment
