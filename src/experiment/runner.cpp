// Sessions against the store (runner.hpp).
#include "texel/experiment/runner.hpp"

#include "task.hpp"

#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

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

// The store's identity in a token: FNV-1a of its canonical path.
std::string database_identity(const Store& store) {
  std::error_code ec;
  const std::string path = std::filesystem::weakly_canonical(store.path(), ec).string();
  std::uint64_t h = 14695981039346656037ull;
  for (const char c : ec ? store.path() : path) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

std::uint64_t random_opening() {
  std::random_device rd;
  return (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
}

double steady_seconds() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

double now_s(const ActiveSession& a) { return a.now ? a.now() : steady_seconds(); }

// Token text: "q1.<database>.<session>.<trial>.<attempt>.<opening>" — opaque
// to front ends (they only hand it back); parsed here to say why it is refused.
struct Token {
  std::string database;
  std::int64_t session = 0;
  int trial = 0, attempt = 0;
  std::uint64_t opening = 0;
};

std::string token_text(const ActiveSession& a, int trial, int attempt) {
  char opening[17];
  std::snprintf(opening, sizeof opening, "%016" PRIx64, a.opening);
  return "q1." + a.database + "." + std::to_string(a.info.id) + "." + std::to_string(trial) + "." + std::to_string(attempt) +
         "." + opening;
}

std::optional<Token> parse_token(std::string_view text) {
  if (text.size() > 128 || text.substr(0, 3) != "q1.") return std::nullopt;
  std::vector<std::string> parts;
  std::string cur;
  for (const char c : text.substr(3)) {
    if (c == '.') {
      parts.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  parts.push_back(cur);
  if (parts.size() != 5 || parts[0].size() != 16 || parts[4].size() != 16) return std::nullopt;
  Token t;
  t.database = parts[0];
  try {
    std::size_t used = 0;
    t.session = std::stoll(parts[1], &used);
    if (used != parts[1].size()) return std::nullopt;
    t.trial = std::stoi(parts[2], &used);
    if (used != parts[2].size()) return std::nullopt;
    t.attempt = std::stoi(parts[3], &used);
    if (used != parts[3].size()) return std::nullopt;
    t.opening = std::stoull(parts[4], &used, 16);
    if (used != parts[4].size()) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return t;
}

void add_event(ActiveSession& a, double t, const char* kind, std::string detail) {
  a.clock.events.push_back(TrialEvent{std::max(0.0, t - a.clock.onset_s), kind, std::move(detail), utc_timestamp()});
}

// Starts the clock of the current trial (attempt `attempt`).
void start_clock(ActiveSession& a, int attempt, const char* why) {
  const double t = now_s(a);
  a.clock = TrialClock{};
  a.clock.trial = a.session.question().trial;
  a.clock.attempt = attempt;
  a.clock.onset_s = t;
  a.clock.onset_at = utc_timestamp();
  add_event(a, t, "onset", "attempt " + std::to_string(attempt));
  if (why) {
    a.clock.interrupted = true;
    add_event(a, t, "restart", why);
  }
  if (a.resumed) {
    a.clock.interrupted = true;
    if (!why) add_event(a, t, "restart", "the session was resumed; an earlier showing of this trial was lost");
    a.resumed = false;
  }
  if (a.suspended) {
    a.clock.suspended_since = t;
    add_event(a, t, "suspend", "");
  }
}

bool handed_out(const ActiveSession& a) { return !a.session.finished() && a.clock.trial == a.session.question().trial; }

// The row's timing flags (export columns time_limit_s, over_time_limit).
void flag_time_limit(TrialRow& row, double limit_s) {
  if (limit_s <= 0) return;
  row.time_limit_s = limit_s;
  if (std::isfinite(row.rt_ms)) row.over_time_limit = row.rt_ms > limit_s * 1000.0 ? 1.0 : 0.0;
}

}  // namespace

ReloadRule reload_rule(const Protocol& p) {
  return p.on_reload == "restart_trial" ? ReloadRule::restart_trial : ReloadRule::keep_clock;
}

std::string to_json(const Handout& h) {
  return nlohmann::ordered_json{{"token", h.token},        {"trial_number", h.trial_number}, {"attempt", h.attempt},
                                {"onset_at", h.onset_at},  {"elapsed_s", h.elapsed_s},       {"time_limit_s", h.time_limit_s},
                                {"suspended", h.suspended}}
      .dump();
}

std::string_view to_string(Refusal r) {
  switch (r) {
    case Refusal::malformed: return "malformed";
    case Refusal::other_database: return "other_database";
    case Refusal::other_session: return "other_session";
    case Refusal::session_stopped: return "session_stopped";
    case Refusal::session_finished: return "session_finished";
    case Refusal::session_suspended: return "session_suspended";
    case Refusal::restarted: return "restarted";
    case Refusal::stale_trial: return "stale_trial";
  }
  return "malformed";
}

Handout hand_out(ActiveSession& a) {
  if (a.session.finished()) throw Error("the session is finished; there is no question to hand out");
  if (!handed_out(a)) start_clock(a, 0, nullptr);
  return peek(a);
}

Handout peek(const ActiveSession& a) {
  if (a.session.finished()) throw Error("the session is finished; there is no question to hand out");
  Handout h;
  h.trial = a.session.question().trial;
  h.trial_number = h.trial + 1;
  h.time_limit_s = a.session.question().time_limit_s;
  h.suspended = a.suspended;
  if (!handed_out(a)) {  // not shown yet: attempt 0 is the token the first hand-out gives
    h.token = token_text(a, h.trial, 0);
    return h;
  }
  const double t = now_s(a);
  h.token = token_text(a, a.clock.trial, a.clock.attempt);
  h.attempt = a.clock.attempt;
  h.onset_at = a.clock.onset_at;
  h.elapsed_s = t - a.clock.onset_s - a.clock.suspended_s - (a.clock.suspended_since ? t - *a.clock.suspended_since : 0.0);
  return h;
}

Handout reload(ActiveSession& a) {
  if (handed_out(a) && reload_rule(a.session.protocol()) == ReloadRule::restart_trial)
    start_clock(a, a.clock.attempt + 1, "the screen was reloaded; the trial started again");
  return hand_out(a);
}

void suspend(ActiveSession& a) {
  if (a.suspended) return;
  a.suspended = true;
  if (!handed_out(a)) return;
  const double t = now_s(a);
  a.clock.suspended_since = t;
  a.clock.interrupted = true;
  add_event(a, t, "suspend", "");
}

void resume(ActiveSession& a) {
  if (!a.suspended) return;
  a.suspended = false;
  if (!handed_out(a) || !a.clock.suspended_since) return;
  const double t = now_s(a);
  a.clock.suspended_s += t - *a.clock.suspended_since;
  a.clock.suspended_since.reset();
  add_event(a, t, "resume", "");
}

void check_token(const Store& store, const ActiveSession* a, std::string_view text) {
  const std::optional<Token> tok = parse_token(text);
  if (!tok)
    throw AnswerRefused(Refusal::malformed,
                        "This answer does not carry a valid question token; nothing was stored. Reload the page.");
  // The running session's identity was taken when it opened: no path lookup per answer.
  if (tok->database != (a ? a->database : database_identity(store)))
    throw AnswerRefused(Refusal::other_database,
                        "This answer belongs to a question of another experiment database; nothing was stored.");
  if (!a || a->info.id != tok->session) {
    std::optional<SessionInfo> mine;
    try {
      mine = store.session(tok->session);
    } catch (const InvalidArgument&) {
    }
    if (!mine)
      throw AnswerRefused(Refusal::other_database,
                          "This answer belongs to a session this database does not hold; nothing was stored.");
    if (mine->status == "finished")
      throw AnswerRefused(Refusal::session_finished, "The session this question belonged to has finished; nothing was stored.");
    if (a)
      throw AnswerRefused(Refusal::other_session,
                          "This question belonged to a session that was stopped; another session is running now. "
                          "Nothing was stored.");
    throw AnswerRefused(
        Refusal::session_stopped,
        "The session this question belonged to was stopped; nothing was stored. Please wait for the experimenter.");
  }
  if (a->opening != tok->opening)
    throw AnswerRefused(
        Refusal::restarted,
        "The session was restarted after this question was shown; nothing was stored. The current question follows.");
  if (a->session.finished()) throw AnswerRefused(Refusal::session_finished, "The session has finished; nothing was stored.");
  if (a->suspended)
    throw AnswerRefused(Refusal::session_suspended, "The session is paused; your answer was not stored. Please wait.");
  const int attempt = handed_out(*a) ? a->clock.attempt : 0;  // not handed out yet: peek()'s token
  if (tok->trial != a->session.question().trial || tok->attempt != attempt)
    throw AnswerRefused(Refusal::stale_trial, "This question (trial " + std::to_string(tok->trial + 1) +
                                                  ") is no longer the current one; nothing was stored.");
}

ActiveSession open_session(Store& store, const Protocol& protocol, const OpenOptions& o) {
  const auto existing = store.unfinished_session(o.participant, protocol.name);
  SessionInfo info;
  if (o.resume) {
    if (!existing)
      throw SessionConflict(SessionConflict::Kind::nothing_to_resume, "participant '" + o.participant + "' has no unfinished '" +
                                                                          protocol.name + "' session in " + store.path() +
                                                                          " to resume");
    info = *existing;
  } else if (existing) {
    throw SessionConflict(SessionConflict::Kind::unfinished_exists,
                          "participant '" + o.participant + "' has an unfinished '" + protocol.name + "' session (id " +
                              std::to_string(existing->id) + ", " + std::to_string(existing->trials_done) +
                              " trials stored) in " + store.path() + "; resume it");
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
  return ActiveSession{std::move(info), std::move(lock), std::move(session), simulate, database_identity(store), random_opening(),
                       o.resume,        false,           TrialClock{},       {}};
}

StoredTrial record(Store& store, ActiveSession& a, const Response& r) {
  const double limit_s = a.session.finished() ? 0.0 : a.session.question().time_limit_s;
  StoredTrial t = a.session.answer(r);
  flag_time_limit(t.row, limit_s);
  store.append_trial(a.lock, t);
  if (a.session.finished()) store.finish_session(a.lock);
  return t;
}

StoredTrial record(Store& store, ActiveSession* active, std::string_view token, Response r) {
  check_token(store, active, token);
  ActiveSession& a = *active;
  // Answered from a peek(), before any screen was handed the question: no onset to time it from.
  const bool shown = handed_out(a);
  if (!shown) start_clock(a, 0, nullptr);
  const double t = now_s(a);
  const TrialClock& c = a.clock;
  const double limit_s = a.session.question().time_limit_s;
  // A front end that measured its own reaction time (PsychoPy's frame clock) keeps it.
  if (!std::isfinite(r.rt_ms) && shown) r.rt_ms = std::max(0.0, t - c.onset_s - c.suspended_s) * 1000.0;
  if (r.shown_at.empty()) r.shown_at = c.onset_at;
  if (r.answered_at.empty()) r.answered_at = utc_timestamp();
  std::vector<TrialEvent> events = c.events;
  events.push_back(TrialEvent{std::max(0.0, t - c.onset_s), "answer", "", utc_timestamp()});
  for (auto& e : r.events) events.push_back(std::move(e));  // the screen's own (t_s from its showing)
  r.events = std::move(events);
  const bool interrupted = c.interrupted;
  const double suspended_ms = c.suspended_s * 1000.0;
  StoredTrial st = a.session.answer(r);
  flag_time_limit(st.row, limit_s);
  st.row.interrupted = interrupted ? 1.0 : 0.0;
  st.row.suspended_ms = suspended_ms;
  store.append_trial(a.lock, st);
  if (a.session.finished()) store.finish_session(a.lock);
  return st;
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
