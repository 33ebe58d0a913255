// The durable session store (SQLite; PostgreSQL behind a local SQLite
// journal for several stations; docs/session-store.md).
//
// One file holds participants (pseudonymous codes only), sessions (with a
// copy of the protocol and the seed), and per answered trial: the question
// as shown (stimulus documents and seeds), the hidden truth, the response,
// the adaptive state after it, the long-format row, and the presentation and
// selection events with time stamps.
//
// Durability. The database runs in WAL mode with synchronous=FULL: "WAL mode
// is always consistent with synchronous=NORMAL, but WAL mode does lose
// durability. [...] With synchronous=FULL in WAL mode, an additional sync
// operation of the WAL file happens after each transaction commit", so a
// committed transaction survives a power cut (sqlite.org/pragma.html#
// pragma_synchronous, sqlite.org/wal.html). Each trial is one transaction,
// committed before append_trial() returns, i.e. before the front end shows
// the next question: a crash loses at most the trial in progress. Trial
// indices are append-only (primary key session, trial): a duplicate or a gap
// is refused and nothing is written.
//
// One writer per session. acquire_writer() records the writing process (pid,
// its start time from /proc so a recycled pid is not mistaken for it, host)
// in a `writers` row inside an IMMEDIATE transaction; a second live writer
// is refused with a message naming it; a row left by a dead process (a
// SIGKILLed run) is taken over, so --resume after a crash just works. The
// rule holds on one machine (pids are per host).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "texel/experiment/finger_trace.hpp"
#include "texel/experiment/records.hpp"

namespace texel::experiment {

struct TrialEvent {
  double t_s = 0.0;    ///< seconds since the trial was first shown
  std::string kind;    ///< "show", "select", "slider", "matrix", "timeout", "answer", …
  std::string detail;  ///< e.g. the stimulus label
  std::string at;      ///< ISO 8601 UTC with ms (may be empty for simulated events)
};

struct StoredTrial {
  int trial = 0;              ///< 0-based index in the session; append-only
  std::string question_json;  ///< what was shown (+ the hidden truth), as the engine describes it
  std::string response_json;  ///< the answer as given
  std::string state_json;     ///< adaptive procedure state after the answer
  TrialRow row;               ///< the long-format row
  std::vector<TrialEvent> events;
  /// The finger that explored the trial (finger_trace.hpp); empty when none
  /// was recorded. Stored in its own table (schema version 2).
  FingerTrace trace;
};

struct SessionInfo {
  std::int64_t id = 0;
  std::string participant, protocol, study, protocol_json;
  std::uint64_t seed = 0;
  std::string simulate;  ///< simulation spec, or empty for a person
  std::string status;    ///< "running" | "finished"
  std::string created_at, updated_at;
  int trials_done = 0;
  int trials_planned = -1;  ///< -1 = adaptive (open-ended)
};

/// The session as JSON object text, the one view every front door prints
/// (CLI --json, the studio's messages, Python): id, participant, protocol,
/// study, status, finished, trials_done, trials_planned (-1 = adaptive),
/// seed, simulate, simulated, created_at, updated_at (docs/format.md
/// "Result field names"). The protocol copy is not included.
std::string to_json(const SessionInfo& s);

enum class StoreMode { read_only, read_write };

/// True when `db` names a PostgreSQL server — a `postgresql://` or
/// `postgres://` URI, or `service=NAME` (libpq's conventions) — rather than
/// an SQLite file (docs/session-store.md "Many stations").
bool is_postgres(std::string_view db);

struct StoreOptions {
  /// A station's local journal (a PostgreSQL `db` opened read_write): every
  /// trial is committed here first, then shipped. Empty: default_journal(db).
  std::string journal;
};

/// `$XDG_STATE_HOME/texel/journal-<user>@<host>-<port>-<database>.db`
/// (`~/.local/state` without XDG_STATE_HOME): one journal per server,
/// database and station role.
std::string default_journal(const std::string& db);

/// A station's shipping state (Store::shipping()).
struct ShipStatus {
  std::string server;   ///< the server, as a URI without secrets
  std::string station;  ///< this station's id: its PostgreSQL role
  std::string journal;  ///< the local journal's path
  bool connected = false;
  std::string last_error;  ///< why the server is not reached (empty when it is)
  std::int64_t trials_local = 0, trials_shipped = 0;
  int sessions_local = 0;
  int completions_pending = 0;         ///< finished sessions whose completion record is not on the server yet
  double lag_s = 0.0;                  ///< age of the oldest trial not yet on the server; 0 when all are
  std::vector<std::string> conflicts;  ///< study-wide lock conflicts found when the server came back
};

/// The shipping state as JSON object text: station, server, journal,
/// connected, error, trials_local, trials_shipped, sessions_local,
/// completions_pending, lag_s, conflicts (CLI `sync --json`, the studio).
std::string to_json(const ShipStatus& s);

/// `texel store init --postgres URI`: as the migration owner (the role the
/// URI logs in as), create or migrate the `texel` schema, the group roles
/// texel_station and texel_analyst, and one login role per station and
/// analyst name (no password: the lab sets it, docs/session-store.md).
/// Returns the report lines.
std::vector<std::string> init_postgres(const std::string& db, const std::vector<std::string>& stations,
                                       const std::vector<std::string>& analysts);

class Store;
// The connection (store.cpp), shared by a Store and its locks. Declared here,
// not in a texel::experiment::detail namespace, which would hide texel::detail
// from code in texel::experiment.
struct StoreConnection;

/// Proof of being the session's only writer; releases on destruction. It
/// shares the Store's connection, so it stays valid if the Store is moved
/// (or destroyed first).
class WriterLock {
 public:
  WriterLock(WriterLock&&) noexcept;
  WriterLock& operator=(WriterLock&&) noexcept;
  ~WriterLock();
  [[nodiscard]] std::int64_t session_id() const { return session_id_; }

 private:
  friend class Store;
  WriterLock(std::shared_ptr<StoreConnection> impl, std::int64_t session_id);
  std::shared_ptr<StoreConnection> impl_;
  std::int64_t session_id_ = 0;
};

class Store {
 public:
  static constexpr int current_schema_version = 2;

  /// read_write creates the file if missing (and migrates older schemas);
  /// read_only never creates or writes. Throws IoError (missing, unreadable,
  /// read-only, locked) / FormatError (not a Texel database, or a schema
  /// newer than this build) naming the path; nothing stored is touched.
  static Store open(const std::string& path, StoreMode mode);
  /// `path` may also name a PostgreSQL server (is_postgres()): read_only
  /// reads the server (with the connecting role's rights); read_write makes
  /// this process a station that stores every trial in its local journal
  /// (options.journal) and ships it in the background. A server that cannot
  /// be reached at start is not an error for a station (shipping().connected
  /// says so); a wrong URI or password, a server without the Texel schema or
  /// with a newer one is (InvalidArgument / IoError / FormatError).
  static Store open(const std::string& path, StoreMode mode, const StoreOptions& options);
  ~Store();
  Store(Store&&) noexcept;
  Store& operator=(Store&&) noexcept;

  [[nodiscard]] int schema_version() const;
  /// The SQLite path; a station's journal; a PostgreSQL reader's server URI
  /// without secrets.
  [[nodiscard]] const std::string& path() const;

  /// A station (a PostgreSQL db opened read_write)?
  [[nodiscard]] bool is_station() const;
  /// Where shipping stands; InvalidArgument unless is_station().
  [[nodiscard]] ShipStatus shipping() const;
  /// Ships now and waits up to timeout_s for every stored trial and
  /// completion to be on the server; true when they are.
  bool sync(double timeout_s);
  /// stations_json()'s list, read from the server (PostgreSQL only).
  [[nodiscard]] std::string station_rows_json() const;

  /// Creates the participant if new (code: 1–32 of A–Z a–z 0–9 _ . -).
  std::int64_t create_session(const std::string& participant, const std::string& protocol, const std::string& study,
                              const std::string& protocol_json, std::uint64_t seed, const std::string& simulate,
                              int trials_planned);
  /// The participant's newest running session of `protocol`, if any.
  [[nodiscard]] std::optional<SessionInfo> unfinished_session(const std::string& participant, const std::string& protocol) const;
  /// Throws InvalidArgument if there is no such session.
  [[nodiscard]] SessionInfo session(std::int64_t id) const;
  [[nodiscard]] std::vector<SessionInfo> sessions() const;
  [[nodiscard]] std::vector<std::string> participants() const;

  /// Throws Error naming the other writer if a live process holds the session.
  WriterLock acquire_writer(std::int64_t session_id);
  /// One transaction, durable before return. Refuses (without writing) a
  /// trial index other than the number already stored, or a lock for
  /// another session.
  void append_trial(const WriterLock& lock, const StoredTrial& t);
  void finish_session(const WriterLock& lock);

  [[nodiscard]] std::vector<StoredTrial> trials(std::int64_t session_id) const;
  /// Rows of every session (or one), in (session, trial) order.
  [[nodiscard]] std::vector<TrialRow> rows(std::optional<std::int64_t> session_id = std::nullopt) const;

 private:
  explicit Store(std::shared_ptr<StoreConnection> impl);
  std::shared_ptr<StoreConnection> impl_;
};

/// Every station's progress and shipping lag (the experimenter's view), as
/// JSON object text: "multi_station" (false for an SQLite file: then
/// "stations" is empty), "this_station" (shipping(), or null when this
/// process is no station), "server_error" (why the list could not be read,
/// or "") and "stations": per station of texel.station_progress its station,
/// host, trials_local, trials_shipped, sessions, completions_pending,
/// lag_s (age of its oldest unshipped trial at its last report) and
/// last_report_s (seconds since that report).
std::string stations_json(const Store& store);

/// Where every session stands (`texel experiment status --json`), as JSON
/// object text: database (the `database` label given), schema_version,
/// participants, and sessions — each to_json(SessionInfo) plus "blocks": per
/// block its trials and, for staircase blocks, variable, current_value,
/// reversals and finished. `participant` limits the sessions to one.
std::string status_json(const Store& store, std::string_view database,
                        const std::optional<std::string>& participant = std::nullopt);

}  // namespace texel::experiment
