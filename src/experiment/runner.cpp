// Sessions against the store (runner.hpp).
#include "texel/experiment/runner.hpp"

#include "task.hpp"

#include <cmath>
#include <set>

#include "texel/error.hpp"

namespace texel::experiment {
namespace {

// Matches of the participant's finished sessions, for rating renderings
// that use them ("from_protocol").
std::map<std::string, std::map<std::string, MatchResult>> prior_matches(const Store& store, const Protocol& p,
                                                                        const std::string& participant) {
  std::map<std::string, std::map<std::string, MatchResult>> out;
  std::set<std::string> wanted;
  for (const auto& b : p.blocks)
    for (const auto& pair : b.pairs)
      if (!pair.rendering.from_protocol.empty()) wanted.insert(pair.rendering.from_protocol);
  if (wanted.empty()) return out;
  for (const auto& s : store.sessions()) {
    if (s.participant != participant || s.status != "finished" || !wanted.count(s.protocol)) continue;
    for (const auto& row : store.rows(s.id)) {
      const TaskType* kind = find_task_type(row.task);
      const bool match_row = kind && kind->holds_match(row);
      if (match_row && !row.practice && std::isfinite(row.pitch_db))
        out[s.protocol][row.reference] = MatchResult{row.pitch_db, row.irregularity_db};
    }
  }
  return out;
}

}  // namespace

ActiveSession open_session(Store& store, const Protocol& protocol, const OpenOptions& o) {
  const auto existing = store.unfinished_session(o.participant, protocol.name);
  SessionInfo info;
  if (o.resume) {
    if (!existing)
      throw InvalidArgument("participant '" + o.participant + "' has no unfinished '" + protocol.name + "' session in " +
                            store.path() + " to resume (start one without --resume)");
    info = *existing;
  } else if (existing) {
    throw InvalidArgument("participant '" + o.participant + "' has an unfinished '" + protocol.name + "' session (id " +
                          std::to_string(existing->id) + ", " + std::to_string(existing->trials_done) + " trials stored) in " +
                          store.path() + "; resume it (--resume)");
  }
  Protocol run = o.resume ? parse_protocol(info.protocol_json, store.path() + ": stored protocol") : protocol;
  const std::string simulate = o.simulate.value_or(o.resume ? info.simulate : std::string());
  if (!simulate.empty()) (void)simulation_observer(run.observer, simulate);  // validate before anything is stored
  if (!o.resume) {
    const auto id = store.create_session(o.participant, run.name, run.study, run.json, session_seed(run.seed, o.participant),
                                         simulate, run.planned_trials());
    info = store.session(id);
  }
  WriterLock lock = store.acquire_writer(info.id);
  SessionContext ctx;
  ctx.participant = o.participant;
  ctx.session_id = info.id;
  ctx.seed = info.seed;
  ctx.prior_matches = prior_matches(store, run, o.participant);
  Session session(std::move(run), std::move(ctx));
  for (const auto& t : store.trials(info.id)) session.replay(t);
  return ActiveSession{std::move(info), std::move(lock), std::move(session), simulate};
}

StoredTrial record(Store& store, ActiveSession& a, const Response& r) {
  StoredTrial t = a.session.answer(r);
  store.append_trial(a.lock, t);
  if (a.session.finished()) store.finish_session(a.lock);
  return t;
}

SimulatedParticipant simulated_participant(const ActiveSession& a) {
  return SimulatedParticipant(simulation_observer(a.session.protocol().observer, a.simulate.empty() ? "default" : a.simulate),
                              a.session);
}

std::vector<std::int64_t> simulate_cohort(Store& store, const Protocol& protocol, const std::vector<std::string>& participants,
                                          const std::string& spec) {
  std::vector<std::int64_t> ids;
  for (const auto& p : participants) {
    OpenOptions o;
    o.participant = p;
    o.simulate = spec;
    o.resume = store.unfinished_session(p, protocol.name).has_value();
    ActiveSession a = open_session(store, protocol, o);
    const SimulatedParticipant sim = simulated_participant(a);
    while (!a.session.finished()) (void)record(store, a, sim.respond(a.session));
    ids.push_back(a.info.id);
  }
  return ids;
}

}  // namespace texel::experiment
