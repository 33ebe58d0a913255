// The durable session store over SQLite's C API (store.hpp,
// docs/session-store.md). SQLite types stay in this file, behind three small
// RAII wrappers (connection, statement, transaction).
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
#include "texel/error.hpp"

namespace texel::experiment {

namespace {

constexpr int busy_timeout_ms = 5000;
// PRAGMA application_id: 'T' 'X' 'E' 'X' — marks the file as a Texel
// experiment database, so another application's SQLite file is refused.
constexpr std::int64_t texel_application_id = 0x54584558;

// Schema migrations, numbered: migrations[v] takes a database from schema
// version v to v + 1, in one transaction that also sets user_version. A
// released entry is never edited; a change to the schema appends one.
// Version 0 is an empty file.
const std::array<const char*, 2> migrations = {
    // 0 → 1: the first schema.
    R"sql(
CREATE TABLE participants (
  code       TEXT PRIMARY KEY CHECK (length(code) BETWEEN 1 AND 32),
  created_at TEXT NOT NULL
);
CREATE TABLE sessions (
  id             INTEGER PRIMARY KEY,
  participant    TEXT NOT NULL REFERENCES participants(code),
  protocol       TEXT NOT NULL,
  study          TEXT NOT NULL,
  protocol_json  TEXT NOT NULL,
  seed           TEXT NOT NULL,
  simulate       TEXT NOT NULL DEFAULT '',
  status         TEXT NOT NULL DEFAULT 'running' CHECK (status IN ('running', 'finished')),
  trials_planned INTEGER NOT NULL DEFAULT -1,
  created_at     TEXT NOT NULL,
  updated_at     TEXT NOT NULL
);
CREATE INDEX sessions_by_participant ON sessions(participant, protocol);
CREATE TABLE trials (
  session_id    INTEGER NOT NULL REFERENCES sessions(id),
  trial         INTEGER NOT NULL CHECK (trial >= 0),
  question_json TEXT NOT NULL,
  response_json TEXT NOT NULL,
  state_json    TEXT NOT NULL,
  row_json      TEXT NOT NULL,
  stored_at     TEXT NOT NULL,
  PRIMARY KEY (session_id, trial)
);
CREATE TABLE events (
  session_id INTEGER NOT NULL,
  trial      INTEGER NOT NULL,
  seq        INTEGER NOT NULL,
  t_s        REAL NOT NULL,
  kind       TEXT NOT NULL,
  detail     TEXT NOT NULL,
  at         TEXT NOT NULL,
  PRIMARY KEY (session_id, trial, seq),
  FOREIGN KEY (session_id, trial) REFERENCES trials(session_id, trial)
);
CREATE TABLE writers (
  session_id    INTEGER PRIMARY KEY REFERENCES sessions(id),
  pid           INTEGER NOT NULL,
  process_start INTEGER NOT NULL,
  host          TEXT NOT NULL,
  acquired_at   TEXT NOT NULL
);
)sql",
    // 1 → 2: the finger that explored each trial (finger_trace.hpp): its
    // source, the presentation mode and the samples ("t_s,x_mm,touch" lines
    // on the source's own clock). Trials stored before have no row here.
    R"sql(
CREATE TABLE finger_traces (
  session_id INTEGER NOT NULL,
  trial      INTEGER NOT NULL,
  source     TEXT NOT NULL CHECK (source IN ('display', 'pointer', 'simulated')),
  mode       TEXT NOT NULL CHECK (mode IN ('', 'display-plays', 'host-streams', 'passive')),
  samples    INTEGER NOT NULL CHECK (samples >= 0),
  trace      TEXT NOT NULL,
  PRIMARY KEY (session_id, trial),
  FOREIGN KEY (session_id, trial) REFERENCES trials(session_id, trial)
);
)sql",
};
static_assert(migrations.size() == Store::current_schema_version);

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

// /proc/<pid>/stat: the state (field 3) and the start time in clock ticks
// since boot (field 22). The start time tells a recycled pid from the writer.
struct ProcStat {
  bool readable = false;
  char state = '?';
  std::int64_t start = 0;
};
ProcStat proc_stat(std::int64_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ProcStat s;
  const auto close = text.rfind(')');  // the command name may hold spaces and parentheses
  if (close == std::string::npos) return s;
  std::istringstream rest(text.substr(close + 1));
  std::string field;
  // After ')': field 3 is the state; field 22 is 20 further on.
  rest >> s.state;
  for (int f = 4; f <= 22; ++f) {
    if (!(rest >> field)) return s;
  }
  try {
    s.start = std::stoll(field);
  } catch (const std::exception&) {
    return s;
  }
  s.readable = true;
  return s;
}

// Our own start time; recomputed after a fork(), where the child inherits
// the parent's cached value.
std::int64_t own_start() {
  static pid_t cached_pid = 0;
  static std::int64_t start = 0;
  if (cached_pid != ::getpid()) {
    cached_pid = ::getpid();
    start = proc_stat(cached_pid).start;
  }
  return start;
}

// Is `pid` (started at `start` ticks) still running on this machine? A
// zombie counts as dead: it holds nothing and will never write again.
bool process_alive(std::int64_t pid, std::int64_t start) {
  if (pid <= 0 || pid > std::numeric_limits<pid_t>::max()) return false;
  if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno != EPERM) return false;
  const ProcStat s = proc_stat(pid);
  if (!s.readable) return true;  // no /proc: trust kill()
  if (s.state == 'Z' || s.state == 'X') return false;
  return s.start == start;
}

bool valid_code(const std::string& code) {
  if (code.empty() || code.size() > 32) return false;
  for (const unsigned char c : code)
    if (!std::isalnum(c) && c != '_' && c != '.' && c != '-') return false;
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------
// The connection and its wrappers.

struct StoreConnection {
  sqlite3* db = nullptr;
  std::string path;
  bool writable = false;
  int version = 0;
  // PostgreSQL (store_pg.hpp): a reader of the server (db is null), or a
  // station whose db is its local journal.
  std::shared_ptr<pg::Reader> reader;
  std::shared_ptr<pg::Station> station;

  StoreConnection() = default;
  StoreConnection(const StoreConnection&) = delete;
  StoreConnection& operator=(const StoreConnection&) = delete;
  ~StoreConnection() {
    if (db) sqlite3_close_v2(db);
  }

  // One line: the operation, the path and SQLite's reason, as the error
  // family a caller can act on.
  [[noreturn]] void fail(const std::string& op, int rc) const {
    const std::string why = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    const int primary = rc & 0xff;
    switch (primary) {
      case SQLITE_NOTADB: throw FormatError(path + " is not a Texel experiment database (" + why + ")");
      case SQLITE_CORRUPT: throw FormatError(path + " is corrupt (" + why + "); " + op + " refused");
      case SQLITE_BUSY:
      case SQLITE_LOCKED:
        throw IoError(path + " is locked by another process (waited " + std::to_string(busy_timeout_ms / 1000) + " s): " + op +
                      " refused");
      case SQLITE_READONLY: throw IoError(path + " is read-only (" + why + "): " + op + " refused");
      case SQLITE_CONSTRAINT: throw InvalidArgument(path + ": " + op + ": " + why);
      default: throw IoError(path + ": " + op + " failed: " + why);
    }
  }
};

namespace {

using StoreImpl = StoreConnection;

class Stmt {
 public:
  Stmt(const StoreImpl& s, const char* sql, std::string op) : s_(s), op_(std::move(op)) {
    const int rc = sqlite3_prepare_v2(s.db, sql, -1, &st_, nullptr);
    if (rc != SQLITE_OK) s.fail(op_, rc);
  }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  ~Stmt() { sqlite3_finalize(st_); }

  Stmt& bind(int i, std::int64_t v) {
    check(sqlite3_bind_int64(st_, i, v));
    return *this;
  }
  Stmt& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
  Stmt& bind(int i, double v) {
    check(sqlite3_bind_double(st_, i, v));
    return *this;
  }
  Stmt& bind(int i, const std::string& v) {
    check(sqlite3_bind_text(st_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
    return *this;
  }
  /// True while there is a row.
  bool step() {
    const int rc = sqlite3_step(st_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    s_.fail(op_, rc);
  }
  void run() {
    while (step()) {
    }
  }
  /// Ready to run again with new bindings.
  void reset() {
    sqlite3_reset(st_);
    sqlite3_clear_bindings(st_);
  }
  [[nodiscard]] std::int64_t i64(int c) const { return sqlite3_column_int64(st_, c); }
  [[nodiscard]] int i32(int c) const { return sqlite3_column_int(st_, c); }
  [[nodiscard]] double dbl(int c) const { return sqlite3_column_double(st_, c); }
  [[nodiscard]] std::string text(int c) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(st_, c));
    return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(st_, c))) : std::string();
  }

 private:
  void check(int rc) const {
    if (rc != SQLITE_OK) s_.fail(op_, rc);
  }
  const StoreImpl& s_;
  std::string op_;
  sqlite3_stmt* st_ = nullptr;
};

void exec(const StoreImpl& s, const char* sql, const std::string& op) {
  char* err = nullptr;
  const int rc = sqlite3_exec(s.db, sql, nullptr, nullptr, &err);
  sqlite3_free(err);
  if (rc != SQLITE_OK) s.fail(op, rc);
}

// BEGIN IMMEDIATE takes the write lock up front, so the checks made inside
// the transaction (trial count, writer row) still hold at COMMIT.
class Transaction {
 public:
  Transaction(const StoreImpl& s, std::string op) : s_(s), op_(std::move(op)) { exec(s_, "BEGIN IMMEDIATE", op_); }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  ~Transaction() {
    if (!done_) sqlite3_exec(s_.db, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  void commit() {
    exec(s_, "COMMIT", op_);
    done_ = true;
  }

 private:
  const StoreImpl& s_;
  std::string op_;
  bool done_ = false;
};

std::int64_t pragma_int(const StoreImpl& s, const char* sql, const std::string& op) {
  Stmt st(s, sql, op);
  return st.step() ? st.i64(0) : 0;
}

void migrate(StoreImpl& s) {
  while (s.version < Store::current_schema_version) {
    const int from = s.version;
    Transaction tx(s, "migrating the schema from version " + std::to_string(from));
    // Re-read inside the write lock: another process may have migrated meanwhile.
    const auto v = static_cast<int>(pragma_int(s, "PRAGMA user_version", "reading the schema version"));
    if (v != from) {
      s.version = v;
      continue;
    }
    exec(s, migrations[static_cast<std::size_t>(from)], "migrating the schema to version " + std::to_string(from + 1));
    const std::string set =
        "PRAGMA application_id = " + std::to_string(texel_application_id) + "; PRAGMA user_version = " + std::to_string(from + 1);
    exec(s, set.c_str(), "setting the schema version");
    tx.commit();
    s.version = from + 1;
  }
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

std::string session_label(const SessionInfo& s) {
  return "session " + std::to_string(s.id) + " (" + s.participant + ", " + s.protocol + ")";
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

WriterLock Store::acquire_writer(std::int64_t session_id) {
  if (!impl_->writable || impl_->reader)
    throw InvalidArgument(impl_->path + " is open read-only; cannot write session " + std::to_string(session_id));
  const SessionInfo info = session(session_id);
  const std::string op = "taking the writer lock of " + session_label(info);
  Transaction tx(*impl_, op);
  const std::string host = host_name();
  {
    Stmt st(*impl_, "SELECT pid, process_start, host, acquired_at FROM writers WHERE session_id = ?", op);
    st.bind(1, session_id);
    if (st.step()) {
      const std::int64_t pid = st.i64(0), start = st.i64(1);
      const std::string other_host = st.text(2), since = st.text(3);
      if (other_host != host)
        throw IoError(session_label(info) + " is being written by process " + std::to_string(pid) + " on host " + other_host +
                      " since " + since +
                      "; stop it first (a lock from another machine is not checked; if that run is gone, "
                      "delete its row from the writers table)");
      if (pid == ::getpid() && start == own_start())
        throw IoError(session_label(info) + " is already being written by this process (since " + since + ")");
      if (process_alive(pid, start))
        throw IoError(session_label(info) + " is being written by process " + std::to_string(pid) + " since " + since +
                      "; stop it first");
      // Otherwise the row is left by a dead run (killed, crashed): take it over.
    }
  }
  Stmt(*impl_,
       "INSERT INTO writers(session_id, pid, process_start, host, acquired_at) VALUES (?, ?, ?, ?, ?) "
       "ON CONFLICT(session_id) DO UPDATE SET pid = excluded.pid, process_start = excluded.process_start, "
       "host = excluded.host, acquired_at = excluded.acquired_at",
       op)
      .bind(1, session_id)
      .bind(2, static_cast<std::int64_t>(::getpid()))
      .bind(3, own_start())
      .bind(4, host)
      .bind(5, utc_timestamp())
      .run();
  tx.commit();
  WriterLock lock(impl_, session_id);
  // A station also holds the study-wide lock (a refusal releases ours).
  if (impl_->station) impl_->station->take_lease(info);
  return lock;
}

namespace {

// Inside a write transaction: is `lock` still this process's hold on its
// session (not taken over by someone who judged us dead)?
void check_lock(const StoreImpl& s, const std::shared_ptr<StoreImpl>& mine, const WriterLock& lock,
                const std::shared_ptr<StoreImpl>& lock_impl, const std::string& op) {
  if (!lock_impl) throw InvalidArgument(op + ": the writer lock was released or moved from");
  if (lock_impl != mine) throw InvalidArgument(op + ": the writer lock belongs to another Store");
  Stmt st(s, "SELECT pid, process_start FROM writers WHERE session_id = ?", op);
  st.bind(1, lock.session_id());
  if (!st.step() || st.i64(0) != ::getpid() || st.i64(1) != own_start())
    throw IoError(s.path + ": " + op + ": this process no longer holds the writer lock of session " +
                  std::to_string(lock.session_id()));
}

}  // namespace

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

// ---------------------------------------------------------------------------
// WriterLock

WriterLock::WriterLock(std::shared_ptr<StoreConnection> impl, std::int64_t session_id)
    : impl_(std::move(impl)), session_id_(session_id) {}
WriterLock::WriterLock(WriterLock&& o) noexcept : impl_(std::move(o.impl_)), session_id_(o.session_id_) {}
WriterLock& WriterLock::operator=(WriterLock&& o) noexcept {
  if (this != &o) {
    WriterLock old(std::move(*this));
    impl_ = std::move(o.impl_);
    session_id_ = o.session_id_;
  }
  return *this;
}
WriterLock::~WriterLock() {
  if (!impl_ || !impl_->db) return;
  // Only our own row: if another process took the session over, leave it.
  sqlite3_stmt* st = nullptr;
  if (sqlite3_prepare_v2(impl_->db, "DELETE FROM writers WHERE session_id = ? AND pid = ? AND process_start = ?", -1, &st,
                         nullptr) == SQLITE_OK) {
    sqlite3_bind_int64(st, 1, session_id_);
    sqlite3_bind_int64(st, 2, ::getpid());
    sqlite3_bind_int64(st, 3, own_start());
    sqlite3_step(st);  // a failure leaves a row that the next run recognises as dead
  }
  sqlite3_finalize(st);
  if (impl_->station) impl_->station->release_lease(session_id_);
}

}  // namespace texel::experiment
