// The durable session store over SQLite's C API (store.hpp,
// docs/session-store.md). SQLite types stay behind three small RAII
// wrappers (connection, statement, transaction: store_sqlite.hpp); the
// schema's migrations are store_schema.cpp, the writer lock store_writer.cpp.
//
// Durability settings and where their guarantees are stated:
//  * journal_mode=WAL (https://www.sqlite.org/wal.html): a commit appends to
//    the write-ahead log; readers never block the writer, and a crash leaves
//    the database at the last commit ("transactions ... are atomic even if
//    the program crashes"). The mode is persistent in the file.
//  * synchronous=FULL (https://www.sqlite.org/pragma.html#pragma_synchronous):
//    "WAL mode is always consistent with synchronous=NORMAL, but WAL mode does
//    lose durability. [...] With synchronous=FULL in WAL mode, an additional
//    sync operation of the WAL file happens after each transaction commit.
//    The extra WAL sync following each transaction helps ensure that
//    transactions are durable across a power loss." NORMAL would be enough
//    for a killed process; FULL is what makes a power cut lose nothing that
//    append_trial() reported as stored. It costs one fsync per answer, which
//    is milliseconds against a trial that lasts seconds.
//  * foreign_keys=ON: events cannot outlive their trial, trials their session.
//  * busy_timeout: a second process (an `export` while a run writes) waits up
//    to 5 s for a lock before we give up with a one-line error.
#include "texel/experiment/store.hpp"

#include <signal.h>
#include <sqlite3.h>
#include <sys/types.h>
#include <unistd.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include "store_pg.hpp"
#include "store_sqlite.hpp"
#include "texel/error.hpp"

namespace texel::experiment {

using namespace store_parts;

namespace {

bool valid_code(const std::string& code) {
  if (code.empty() || code.size() > 32) return false;
  for (const unsigned char c : code)
    if (!std::isalnum(c) && c != '_' && c != '.' && c != '-') return false;
  return true;
}

constexpr const char* session_columns =
    "SELECT s.id, s.participant, s.protocol, s.study, s.protocol_json, s.seed, s.simulate, s.status, s.created_at, "
    "s.updated_at, (SELECT COUNT(*) FROM trials t WHERE t.session_id = s.id), s.trials_planned FROM sessions s ";

SessionInfo read_session(const Stmt& st) {
  SessionInfo i;
  i.id = st.i64(0);
  i.participant = st.text(1);
  i.protocol = st.text(2);
  i.study = st.text(3);
  i.protocol_json = st.text(4);
  i.seed = std::stoull(st.text(5));
  i.simulate = st.text(6);
  i.status = st.text(7);
  i.created_at = st.text(8);
  i.updated_at = st.text(9);
  i.trials_done = st.i32(10);
  i.trials_planned = st.i32(11);
  return i;
}

}  // namespace

// ---------------------------------------------------------------------------
// Store

Store::Store(std::shared_ptr<StoreConnection> impl) : impl_(std::move(impl)) {}
Store::~Store() = default;
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;

Store Store::open(const std::string& path, StoreMode mode, const StoreOptions& options) {
  if (!is_postgres(path)) return open(path, mode);
  if (mode == StoreMode::read_only) {
    auto s = std::make_shared<StoreConnection>();
    s->reader = pg::open_reader(path);
    s->path = s->reader->label();
    s->version = s->reader->schema_version();
    return Store(std::move(s));
  }
  // A station: the journal first (created if new), then the server link.
  std::string journal = options.journal;
  if (journal.empty()) {
    journal = default_journal(path);
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(journal).parent_path(), ec);
  }
  if (is_postgres(journal)) throw InvalidArgument("--journal " + journal + ": a journal is a local SQLite file");
  Store store = open(journal, StoreMode::read_write);
  store.impl_->station = pg::start_station(path, journal);
  return store;
}

bool Store::is_station() const { return impl_->station != nullptr; }

ShipStatus Store::shipping() const {
  if (!impl_->station) throw InvalidArgument(impl_->path + " is not a station's journal (no PostgreSQL server behind it)");
  return impl_->station->status();
}

bool Store::sync(double timeout_s) {
  if (!impl_->station) throw InvalidArgument(impl_->path + " is not a station's journal (no PostgreSQL server behind it)");
  return impl_->station->sync(timeout_s);
}

std::string Store::station_rows_json() const {
  if (impl_->reader) return impl_->reader->stations();
  if (impl_->station) return impl_->station->stations();
  return "[]";
}

Store Store::open(const std::string& path, StoreMode mode) {
  namespace fs = std::filesystem;
  if (is_postgres(path)) return open(path, mode, StoreOptions{});
  auto s = std::make_shared<StoreConnection>();
  s->path = path;
  std::error_code ec;
  const bool exists = fs::exists(path, ec);
  if (mode == StoreMode::read_only && !exists) throw IoError(path + " does not exist (no experiment database there)");
  if (exists && fs::is_directory(path, ec)) throw IoError(path + " is a directory, not an experiment database");

  // An existing file is never created anew (no SQLITE_OPEN_CREATE), so a
  // path that vanishes between the check and the open is not recreated.
  //
  // A reader leaves no files behind. A WAL database read through a
  // read-only connection gets a -wal and a -shm file that the reader cannot
  // remove: only the last connection to close removes them, after a final
  // checkpoint, and only if it can write (sqlite.org/wal.html). So when no
  // -wal/-shm exists (no writer is connected and the last one closed
  // cleanly), the reader opens the file read-write with query_only=1 (no
  // statement can change it) and, if it is the last to close, removes the
  // files its reading created; the checkpoint then moves at most frames a
  // writer committed meanwhile, which changes no stored value. When they
  // exist, a writer is running (or died): the reader opens read-only and
  // leaves them to that writer, exactly as before.
  const bool reader_may_clean = mode == StoreMode::read_only && !fs::exists(path + "-wal", ec) && !fs::exists(path + "-shm", ec);
  int flags = SQLITE_OPEN_FULLMUTEX;
  if (reader_may_clean)
    flags |= SQLITE_OPEN_READWRITE;
  else if (mode == StoreMode::read_only)
    flags |= SQLITE_OPEN_READONLY;
  else
    flags |= SQLITE_OPEN_READWRITE | (exists ? 0 : SQLITE_OPEN_CREATE);
  const int rc = sqlite3_open_v2(path.c_str(), &s->db, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string why = s->db ? sqlite3_errmsg(s->db) : sqlite3_errstr(rc);
    throw IoError("cannot open " + path + " (" + why + ")");
  }
  sqlite3_extended_result_codes(s->db, 0);
  sqlite3_busy_timeout(s->db, busy_timeout_ms);

  // SQLITE_OPEN_READWRITE silently falls back to read-only on a
  // write-protected file; refuse it here, before anything is written.
  if (mode == StoreMode::read_write && sqlite3_db_readonly(s->db, "main") == 1)
    throw IoError(path + " is read-only (no write permission); nothing was stored");
  s->writable = mode == StoreMode::read_write;
  if (reader_may_clean) exec(*s, "PRAGMA query_only = 1", "opening the database for reading");

  // Identify the file before changing anything: garbage fails here with
  // SQLITE_NOTADB and is left byte-identical.
  const auto app = pragma_int(*s, "PRAGMA application_id", "reading the database header");
  s->version = static_cast<int>(pragma_int(*s, "PRAGMA user_version", "reading the schema version"));
  const auto tables = pragma_int(*s, "SELECT COUNT(*) FROM sqlite_master", "reading the schema");
  if (s->version == 0 && app == 0 && tables != 0)
    throw FormatError(path + " is not a Texel experiment database (an SQLite file of another application)");
  if (s->version != 0 && app != texel_application_id)
    throw FormatError(path + " is not a Texel experiment database (application id " + std::to_string(app) + ")");
  if (s->version > current_schema_version)
    throw FormatError(path + " has schema version " + std::to_string(s->version) + ", newer than this build's " +
                      std::to_string(current_schema_version) + "; use a newer texel");

  if (mode == StoreMode::read_only) {
    if (s->version == 0) throw FormatError(path + " is an empty database (no Texel schema); nothing to read");
    if (s->version < current_schema_version)
      throw FormatError(path + " has the older schema version " + std::to_string(s->version) +
                        "; open it once for writing (e.g. texel experiment run) to migrate it");
    exec(*s, "PRAGMA foreign_keys = ON", "configuring the connection");
    return Store(std::move(s));
  }

  // journal_mode=WAL is stored in the file; the others are per connection.
  {
    Stmt st(*s, "PRAGMA journal_mode = WAL", "switching to WAL journal mode");
    if (!st.step() || st.text(0) != "wal") throw IoError(path + ": cannot use WAL journal mode (got '" + st.text(0) + "')");
  }
  exec(*s, "PRAGMA synchronous = FULL; PRAGMA foreign_keys = ON", "configuring the connection");
  migrate(*s);
  return Store(std::move(s));
}

int Store::schema_version() const { return impl_->version; }
const std::string& Store::path() const { return impl_->path; }

std::int64_t Store::create_session(const std::string& participant, const std::string& protocol, const std::string& study,
                                   const std::string& protocol_json, std::uint64_t seed, const std::string& simulate,
                                   int trials_planned) {
  if (!valid_code(participant))
    throw InvalidArgument("participant code '" + participant +
                          "' is not allowed: use 1-32 characters A-Z a-z 0-9 _ . - (a pseudonymous code, never a name)");
  if (protocol.empty()) throw InvalidArgument("create_session: the protocol name is empty");
  if (trials_planned < -1) throw InvalidArgument("trials_planned " + std::to_string(trials_planned) + " is below -1 (adaptive)");
  const std::string op = "creating a session for " + participant;
  if (impl_->reader) throw IoError(impl_->path + " is open read-only: " + op + " refused");
  Transaction tx(*impl_, op);
  const std::string now = utc_timestamp();
  Stmt(*impl_, "INSERT OR IGNORE INTO participants(code, created_at) VALUES (?, ?)", op).bind(1, participant).bind(2, now).run();
  Stmt(*impl_,
       "INSERT INTO sessions(participant, protocol, study, protocol_json, seed, simulate, status, trials_planned, created_at, "
       "updated_at) VALUES (?, ?, ?, ?, ?, ?, 'running', ?, ?, ?)",
       op)
      .bind(1, participant)
      .bind(2, protocol)
      .bind(3, study)
      .bind(4, protocol_json)
      .bind(5, std::to_string(seed))
      .bind(6, simulate)
      .bind(7, trials_planned)
      .bind(8, now)
      .bind(9, now)
      .run();
  const std::int64_t id = sqlite3_last_insert_rowid(impl_->db);
  tx.commit();
  return id;
}

std::optional<SessionInfo> Store::unfinished_session(const std::string& participant, const std::string& protocol) const {
  if (impl_->reader) {
    std::optional<SessionInfo> found;
    for (auto& s : impl_->reader->sessions())
      if (s.participant == participant && s.protocol == protocol && s.status == "running") found = std::move(s);
    return found;
  }
  Stmt st(*impl_,
          (std::string(session_columns) +
           "WHERE s.participant = ? AND s.protocol = ? AND s.status = 'running' ORDER BY s.id DESC LIMIT 1")
              .c_str(),
          "looking up unfinished sessions");
  st.bind(1, participant).bind(2, protocol);
  if (!st.step()) return std::nullopt;
  return read_session(st);
}

SessionInfo Store::session(std::int64_t id) const {
  if (impl_->reader) {
    for (auto& s : impl_->reader->sessions())
      if (s.id == id) return std::move(s);
    throw InvalidArgument(impl_->path + " has no session " + std::to_string(id));
  }
  Stmt st(*impl_, (std::string(session_columns) + "WHERE s.id = ?").c_str(), "reading session " + std::to_string(id));
  st.bind(1, id);
  if (!st.step()) throw InvalidArgument(impl_->path + " has no session " + std::to_string(id));
  return read_session(st);
}

std::vector<SessionInfo> Store::sessions() const {
  if (impl_->reader) return impl_->reader->sessions();
  Stmt st(*impl_, (std::string(session_columns) + "ORDER BY s.id").c_str(), "listing sessions");
  std::vector<SessionInfo> out;
  while (st.step()) out.push_back(read_session(st));
  return out;
}

std::vector<std::string> Store::participants() const {
  if (impl_->reader) return impl_->reader->participants();
  Stmt st(*impl_, "SELECT code FROM participants ORDER BY code", "listing participants");
  std::vector<std::string> out;
  while (st.step()) out.push_back(st.text(0));
  return out;
}

void Store::append_trial(const WriterLock& lock, const StoredTrial& t) {
  const std::int64_t sid = lock.session_id();
  const std::string op = "storing trial " + std::to_string(t.trial) + " of session " + std::to_string(sid);
  if (!impl_->db) throw InvalidArgument(impl_->path + ": " + op + ": the store is open read-only");
  Transaction tx(*impl_, op);
  check_lock(*impl_, impl_, lock, lock.impl_, op);
  const SessionInfo info = session(sid);
  if (info.status != "running") throw InvalidArgument(impl_->path + ": " + op + ": the session is finished");
  if (t.trial != info.trials_done)
    throw InvalidArgument(impl_->path + ": " + op + ": trial indices are append-only and " + std::to_string(info.trials_done) +
                          " trials are stored, so the next must be trial " + std::to_string(info.trials_done) +
                          "; nothing was written");
  for (const auto& e : t.events)
    if (!std::isfinite(e.t_s))
      throw InvalidArgument(impl_->path + ": " + op + ": event '" + e.kind + "' has a non-finite time; nothing was written");
  // The row's who-and-where fields are the session's, whatever the caller set.
  TrialRow row = t.row;
  row.participant = info.participant;
  row.session_id = sid;
  row.protocol = info.protocol;
  row.study = info.study;
  row.trial = t.trial;
  const std::string now = utc_timestamp();
  Stmt(*impl_,
       "INSERT INTO trials(session_id, trial, question_json, response_json, state_json, row_json, stored_at) "
       "VALUES (?, ?, ?, ?, ?, ?, ?)",
       op)
      .bind(1, sid)
      .bind(2, t.trial)
      .bind(3, t.question_json)
      .bind(4, t.response_json)
      .bind(5, t.state_json)
      .bind(6, row_json(row))
      .bind(7, now)
      .run();
  Stmt ev(*impl_, "INSERT INTO events(session_id, trial, seq, t_s, kind, detail, at) VALUES (?, ?, ?, ?, ?, ?, ?)", op);
  for (std::size_t i = 0; i < t.events.size(); ++i) {
    const auto& e = t.events[i];
    ev.bind(1, sid)
        .bind(2, t.trial)
        .bind(3, static_cast<std::int64_t>(i))
        .bind(4, e.t_s)
        .bind(5, e.kind)
        .bind(6, e.detail)
        .bind(7, e.at);
    ev.run();
    ev.reset();
  }
  if (t.trace.source != TraceSource::none)
    Stmt(*impl_, "INSERT INTO finger_traces(session_id, trial, source, mode, samples, trace) VALUES (?, ?, ?, ?, ?, ?)", op)
        .bind(1, sid)
        .bind(2, t.trial)
        .bind(3, std::string(to_string(t.trace.source)))
        .bind(4, t.trace.mode ? std::string(to_string(*t.trace.mode)) : std::string())
        .bind(5, static_cast<std::int64_t>(t.trace.samples.size()))
        .bind(6, trace_samples_text(t.trace.samples))
        .run();
  Stmt(*impl_, "UPDATE sessions SET updated_at = ? WHERE id = ?", op).bind(1, now).bind(2, sid).run();
  tx.commit();                                 // synchronous=FULL: the WAL is fsynced before COMMIT returns
  if (impl_->station) impl_->station->poke();  // shipped in the background
}

void Store::finish_session(const WriterLock& lock) {
  const std::int64_t sid = lock.session_id();
  const std::string op = "finishing session " + std::to_string(sid);
  Transaction tx(*impl_, op);
  check_lock(*impl_, impl_, lock, lock.impl_, op);
  Stmt(*impl_, "UPDATE sessions SET status = 'finished', updated_at = ? WHERE id = ?", op)
      .bind(1, utc_timestamp())
      .bind(2, sid)
      .run();
  tx.commit();
  if (impl_->station) impl_->station->poke();  // the completion record
}

std::vector<StoredTrial> Store::trials(std::int64_t session_id) const {
  if (impl_->reader) return impl_->reader->trials(session_id);
  const std::string op = "reading the trials of session " + std::to_string(session_id);
  // One read transaction, so trials and events come from the same snapshot.
  exec(*impl_, "BEGIN", op);
  struct End {
    const StoreImpl& s;
    ~End() { sqlite3_exec(s.db, "COMMIT", nullptr, nullptr, nullptr); }
  } end{*impl_};
  std::vector<StoredTrial> out;
  {
    Stmt st(*impl_,
            "SELECT trial, question_json, response_json, state_json, row_json FROM trials WHERE session_id = ? ORDER BY trial",
            op);
    st.bind(1, session_id);
    while (st.step()) {
      StoredTrial t;
      t.trial = st.i32(0);
      t.question_json = st.text(1);
      t.response_json = st.text(2);
      t.state_json = st.text(3);
      t.row = row_from_json(st.text(4),
                            impl_->path + ": session " + std::to_string(session_id) + " trial " + std::to_string(t.trial));
      out.push_back(std::move(t));
    }
  }
  Stmt ev(*impl_, "SELECT trial, t_s, kind, detail, at FROM events WHERE session_id = ? ORDER BY trial, seq", op);
  ev.bind(1, session_id);
  while (ev.step()) {
    const auto trial = static_cast<std::size_t>(ev.i64(0));
    if (trial >= out.size() || out[trial].trial != static_cast<int>(trial))
      throw FormatError(impl_->path + ": session " + std::to_string(session_id) + " has events for a missing trial " +
                        std::to_string(trial));
    out[trial].events.push_back(TrialEvent{ev.dbl(1), ev.text(2), ev.text(3), ev.text(4)});
  }
  Stmt tr(*impl_, "SELECT trial, source, mode, trace FROM finger_traces WHERE session_id = ? ORDER BY trial", op);
  tr.bind(1, session_id);
  while (tr.step()) {
    const auto trial = static_cast<std::size_t>(tr.i64(0));
    const std::string where = impl_->path + ": session " + std::to_string(session_id) + " trial " + std::to_string(trial);
    if (trial >= out.size()) throw FormatError(where + ": a finger trace for a missing trial");
    FingerTrace& f = out[trial].trace;
    f.source = parse_trace_source(tr.text(1));
    if (!tr.text(2).empty()) f.mode = parse_presentation_mode(tr.text(2));
    f.samples = parse_trace_samples(tr.text(3), where);
  }
  return out;
}

std::vector<TrialRow> Store::rows(std::optional<std::int64_t> session_id) const {
  if (impl_->reader) return impl_->reader->rows(session_id);
  std::string sql =
      "SELECT t.session_id, t.trial, t.row_json, s.participant, s.protocol, s.study FROM trials t JOIN sessions s ON s.id = "
      "t.session_id ";
  if (session_id) sql += "WHERE t.session_id = ? ";
  sql += "ORDER BY t.session_id, t.trial";
  Stmt st(*impl_, sql.c_str(), "reading trial rows");
  if (session_id) st.bind(1, *session_id);
  std::vector<TrialRow> out;
  while (st.step()) {
    TrialRow r =
        row_from_json(st.text(2), impl_->path + ": session " + std::to_string(st.i64(0)) + " trial " + std::to_string(st.i64(1)));
    r.session_id = st.i64(0);
    r.trial = st.i32(1);
    r.participant = st.text(3);
    r.protocol = st.text(4);
    r.study = st.text(5);
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace texel::experiment
