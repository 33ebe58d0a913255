// A session of a protocol for one participant, as a front door opens it
// (session 1, the participant's seed mixed into the protocol's), for tests
// that drive the engine without a store.
#pragma once

#include <string>
#include <utility>

#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"

namespace texel::test_support {

inline experiment::Session session_of(const experiment::Protocol& p, const std::string& participant = "S01") {
  experiment::SessionContext c;
  c.participant = participant;
  c.session_id = 1;
  c.seed = experiment::session_seed(p.seed, participant);
  return experiment::Session(p, std::move(c));
}

}  // namespace texel::test_support
