// The session store on PostgreSQL (store_pg.hpp, docs/session-store.md
// "Many stations"). libpq types stay in this file.
//
//  * Connections follow libpq's conventions: a postgresql:// URI or
//    service=NAME; the password comes from ~/.pgpass (PGPASSFILE) or the
//    service file, never from the URI (refused) or a command line, and no
//    message here prints one.
//  * TLS: a host that is not loopback or a Unix socket gets sslmode=require
//    unless the URI asks for verify-ca/verify-full; sslmode=disable/allow/
//    prefer for such a host is refused. After connecting, a non-loopback
//    connection without TLS is closed (a service file may name the host).
//  * A station (Station) ships its journal — the local SQLite store every
//    trial is committed to first — to the server from a background thread.
//    The server's keys are (station, session uuid, trial), every insert is
//    ON CONFLICT DO NOTHING, and the journal records how far the server has
//    confirmed: repeating or reordering a shipment is harmless.
#include "store_pg.hpp"

#include <libpq-fe.h>
#include <pwd.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <utility>

#include "texel/detail/shared_object.hpp"
#include "texel/error.hpp"
#include "texel/experiment/records.hpp"

namespace texel::experiment {

bool is_postgres(std::string_view db) {
  return db.rfind("postgresql://", 0) == 0 || db.rfind("postgres://", 0) == 0 || db.rfind("service=", 0) == 0;
}

namespace pg {
namespace {

// ---------------------------------------------------------------------------
// libpq, opened on first use (dlopen), not linked: it brings Kerberos, LDAP,
// SASL and GnuTLS, which every texel command would otherwise load at start-up
// whether or not it touches a server. <libpq-fe.h> still gives the types.

#ifndef TEXEL_LIBPQ_SONAME
#error "TEXEL_LIBPQ_SONAME (libpq's shared object name) is set by src/experiment/CMakeLists.txt"
#endif

// clang-format off
#define TEXEL_LIBPQ_FUNCTIONS(X) \
  X(PQclear) \
  X(PQconnectdbParams) \
  X(PQconninfoFree) \
  X(PQconninfoParse) \
  X(PQerrorMessage) \
  X(PQescapeIdentifier) \
  X(PQexec) \
  X(PQexecParams) \
  X(PQfinish) \
  X(PQfreemem) \
  X(PQgetisnull) \
  X(PQgetvalue) \
  X(PQhost) \
  X(PQntuples) \
  X(PQresultErrorField) \
  X(PQresultErrorMessage) \
  X(PQresultStatus) \
  X(PQsetNoticeProcessor) \
  X(PQsslInUse) \
  X(PQstatus) \
  X(PQuser)
// clang-format on

/// libpq, opened when the first postgresql:// or service= store is opened
/// (`libpq()`, from the caller's thread before a station's shipper starts);
/// without it SQLite stores work and a server is an IoError naming libpq.
TEXEL_SHARED_LIBRARY(LibPq, libpq, TEXEL_LIBPQ_SONAME, "PostgreSQL stores", TEXEL_LIBPQ_FUNCTIONS)

// ---------------------------------------------------------------------------
// The connection target.

struct Target {
  std::string db;     ///< as given (holds no password: refused)
  std::string label;  ///< postgresql://user@host:port/dbname or service=NAME, for messages
  std::string user, host, port, dbname, service, sslmode;
  bool force_ssl = false;
};

bool loopback_host(const std::string& h) {
  return h.empty() || h[0] == '/' || h[0] == '@' || h == "localhost" || h == "::1" || h.rfind("127.", 0) == 0;
}

std::string login_name() {
  if (const char* u = std::getenv("PGUSER"); u && *u) return u;
  if (const passwd* pw = ::getpwuid(::getuid())) return pw->pw_name;
  return "unknown";
}

Target parse_target(const std::string& db) {
  Target t;
  t.db = db;
  char* err = nullptr;
  PQconninfoOption* opts = libpq().PQconninfoParse(db.c_str(), &err);
  if (!opts) {
    std::string why = err ? err : "not a connection URI";
    libpq().PQfreemem(err);
    while (!why.empty() && std::isspace(static_cast<unsigned char>(why.back()))) why.pop_back();
    throw InvalidArgument("--db: not a valid PostgreSQL connection URI or service name (" + why + ")");
  }
  std::string hostaddr;
  bool password = false;
  for (PQconninfoOption* o = opts; o->keyword; ++o) {
    if (!o->val) continue;
    const std::string k = o->keyword, v = o->val;
    if (k == "user") t.user = v;
    if (k == "host") t.host = v;
    if (k == "hostaddr") hostaddr = v;
    if (k == "port") t.port = v;
    if (k == "dbname") t.dbname = v;
    if (k == "service") t.service = v;
    if (k == "sslmode") t.sslmode = v;
    if (k == "password" && !v.empty()) password = true;
  }
  libpq().PQconninfoFree(opts);
  if (password)
    throw InvalidArgument(
        "--db: the connection URI holds a password; refused (it would show in process lists and shell history): put it "
        "in ~/.pgpass or a service file");
  if (t.user.empty() && t.service.empty()) t.user = login_name();
  // Every host of a multi-host URI must be loopback for TLS to be optional.
  bool remote = false;
  for (const std::string& list : {t.host, hostaddr}) {
    std::size_t at = 0;
    while (at <= list.size() && !list.empty()) {
      const auto comma = list.find(',', at);
      if (!loopback_host(list.substr(at, comma == std::string::npos ? std::string::npos : comma - at))) remote = true;
      if (comma == std::string::npos) break;
      at = comma + 1;
    }
  }
  if (remote) {
    if (t.sslmode.empty())
      t.force_ssl = true;
    else if (t.sslmode != "require" && t.sslmode != "verify-ca" && t.sslmode != "verify-full")
      throw InvalidArgument("--db: sslmode=" + t.sslmode + " for the remote host " + t.host +
                            " is refused: TLS is required unless the host is loopback or a Unix socket (use sslmode=require or "
                            "verify-full)");
  }
  if (!t.service.empty() && t.host.empty()) {
    t.label = "service=" + t.service;
  } else {
    t.label = "postgresql://" + (t.user.empty() ? std::string() : t.user + "@") + (t.host.empty() ? "localhost" : t.host) +
              (t.port.empty() ? std::string() : ":" + t.port) + "/" + (t.dbname.empty() ? t.user : t.dbname);
  }
  return t;
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  // libpq messages may span lines (DETAIL, HINT): keep the first.
  if (const auto nl = s.find('\n'); nl != std::string::npos) s.resize(nl);
  return s;
}

// A server that is not there (refused, no socket, timed out, shutting down)
// as opposed to one that says no (password, role, database, schema).
bool is_outage(const std::string& why) {
  for (const char* s :
       {"Connection refused", "No such file or directory", "timeout expired", "could not translate host",
        "the database system is starting up", "the database system is shutting down", "the database system is in recovery",
        "not yet accepting connections", "recovery mode", "too many connections", "server closed the connection",
        "Network is unreachable", "No route to host", "Connection reset", "could not receive data", "could not send data",
        "terminating connection", "no connection to the server", "SSL SYSCALL"})
    if (why.find(s) != std::string::npos) return true;
  return false;
}

struct ConnectFailure {
  std::string why;
  bool outage = false;
};

// Connects, or says why not; the message names the server, never a secret.
PGconn* connect(const Target& t, ConnectFailure& failure) {
  std::vector<const char*> keys = {"connect_timeout", "application_name", "dbname"};
  std::vector<const char*> values = {"3", "texel", t.db.c_str()};
  if (t.force_ssl) {
    keys.push_back("sslmode");
    values.push_back("require");
  }
  keys.push_back(nullptr);
  values.push_back(nullptr);
  PGconn* c = libpq().PQconnectdbParams(keys.data(), values.data(), 1);
  if (c && libpq().PQstatus(c) == CONNECTION_OK) {
    const char* host = libpq().PQhost(c);
    if (!loopback_host(host ? host : "") && libpq().PQsslInUse(c) == 0) {
      libpq().PQfinish(c);
      failure = {"the connection to " + std::string(host) + " is not encrypted; TLS is required unless the host is loopback",
                 false};
      return nullptr;
    }
    libpq().PQsetNoticeProcessor(
        c, [](void*, const char*) {}, nullptr);
    return c;
  }
  failure.why = trim(c ? libpq().PQerrorMessage(c) : "out of memory");
  failure.outage = is_outage(failure.why);
  if (failure.why.rfind("connection to server", 0) == 0) {
    // "connection to server at "h" (addr), port p failed: REASON": keep REASON.
    if (const auto f = failure.why.find("failed: "); f != std::string::npos) failure.why = failure.why.substr(f + 8);
  }
  libpq().PQfinish(c);
  return nullptr;
}

// RAII over a PGresult; ok() for a command or rows.
class Result {
 public:
  explicit Result(PGresult* r) : r_(r) {}
  Result(Result&& o) noexcept : r_(std::exchange(o.r_, nullptr)) {}
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;
  ~Result() { libpq().PQclear(r_); }
  [[nodiscard]] bool ok() const {
    const auto s = r_ ? libpq().PQresultStatus(r_) : PGRES_FATAL_ERROR;
    return s == PGRES_COMMAND_OK || s == PGRES_TUPLES_OK;
  }
  [[nodiscard]] int rows() const { return libpq().PQntuples(r_); }
  [[nodiscard]] std::string text(int row, int col) const { return libpq().PQgetvalue(r_, row, col); }
  [[nodiscard]] bool null(int row, int col) const { return libpq().PQgetisnull(r_, row, col) == 1; }
  [[nodiscard]] std::int64_t i64(int row, int col) const { return std::strtoll(libpq().PQgetvalue(r_, row, col), nullptr, 10); }
  [[nodiscard]] std::string error() const { return r_ ? trim(libpq().PQresultErrorMessage(r_)) : "out of memory"; }
  [[nodiscard]] std::string sqlstate() const {
    const char* s = r_ ? libpq().PQresultErrorField(r_, PG_DIAG_SQLSTATE) : nullptr;
    return s ? s : "";
  }

 private:
  PGresult* r_;
};

Result run(PGconn* c, const std::string& sql, const std::vector<std::string>& params = {}) {
  if (params.empty()) return Result(libpq().PQexec(c, sql.c_str()));  // may hold several statements (migrations)
  std::vector<const char*> v;
  v.reserve(params.size());
  for (const auto& p : params) v.push_back(p.c_str());
  return Result(libpq().PQexecParams(c, sql.c_str(), static_cast<int>(v.size()), nullptr, v.data(), nullptr, nullptr, 0));
}

// The Texel schema's version on the server, 0 when there is none.
int server_version(PGconn* c, const std::string& label) {
  Result ns = run(c, "SELECT 1 FROM pg_namespace WHERE nspname = 'texel'");
  if (!ns.ok()) throw IoError(label + ": reading the schema failed (" + ns.error() + ")");
  if (ns.rows() == 0) return 0;
  Result m = run(c, "SELECT key, value FROM texel.meta WHERE key IN ('application', 'schema_version')");
  if (!m.ok() && libpq().PQstatus(c) != CONNECTION_OK)
    throw IoError(label + ": lost the server while reading the schema (" + m.error() + ")");
  if (!m.ok()) {
    if (m.sqlstate() == "42501")
      throw IoError(label + ": the role " + std::string(libpq().PQuser(c)) +
                    " may not read the Texel schema (it is neither a station nor an analyst role: texel store init)");
    throw FormatError(label + " is not a Texel experiment database (" + m.error() + ")");
  }
  std::string app, version;
  for (int r = 0; r < m.rows(); ++r) (m.text(r, 0) == "application" ? app : version) = m.text(r, 1);
  if (app != "texel-experiment")
    throw FormatError(label + " is not a Texel experiment database (its texel schema belongs to another application)");
  return std::atoi(version.c_str());
}

// A server schema this build cannot use, whoever opens it.
void refuse_newer(int v, const std::string& label) {
  if (v > current_server_schema)
    throw FormatError(label + " has schema version " + std::to_string(v) + ", newer than this build's " +
                      std::to_string(current_server_schema) + "; use a newer texel");
}

// Readers and stations need the server at this build's version.
void check_version(PGconn* c, const std::string& label) {
  const int v = server_version(c, label);
  if (v == 0)
    throw FormatError(label +
                      " is not a Texel experiment database (no texel schema): the migration owner runs texel store init "
                      "--postgres URI");
  refuse_newer(v, label);
  if (v < current_server_schema)
    throw FormatError(label + " has the older schema version " + std::to_string(v) +
                      ": the migration owner runs texel store init --postgres URI to migrate it");
}

// Every station's progress as a JSON array (one statement, built by the server).
std::string station_rows(PGconn* c, const std::string& label) {
  Result r = run(c,
                 "SELECT COALESCE(json_agg(json_build_object('station', station, 'host', host, 'trials_local', trials_local, "
                 "'trials_shipped', trials_shipped, 'sessions', sessions_local, 'completions_pending', completions_pending, "
                 "'lag_s', CASE WHEN trials_local > trials_shipped AND oldest_unshipped_at <> '' THEN round(extract(epoch FROM "
                 "reported_at - oldest_unshipped_at::timestamptz)::numeric, 3) ELSE 0 END, 'last_report_s', "
                 "round(extract(epoch FROM clock_timestamp() - reported_at)::numeric, 3)) ORDER BY station), '[]') FROM "
                 "texel.station_progress");
  if (!r.ok()) throw IoError(label + ": reading the stations' progress failed: " + r.error());
  return r.text(0, 0);
}

// Server migrations, numbered like the SQLite ones: migrations[v] takes the
// texel schema from version v to v + 1 in the owner's transaction. A
// released entry is never edited. Version 0 is no texel schema.
const std::array<const char*, 2> server_migrations = {
    R"sql(
CREATE SCHEMA texel;
CREATE TABLE texel.meta (key text PRIMARY KEY, value text NOT NULL);
INSERT INTO texel.meta VALUES ('application', 'texel-experiment'), ('schema_version', '0'), ('lease_ttl_s', '30');
CREATE TABLE texel.sessions (
  id             bigserial UNIQUE,
  station        text NOT NULL,
  uuid           uuid NOT NULL UNIQUE,
  local_id       bigint NOT NULL,
  participant    text NOT NULL CHECK (length(participant) BETWEEN 1 AND 32),
  protocol       text NOT NULL,
  study          text NOT NULL,
  protocol_json  text NOT NULL,
  seed           text NOT NULL,
  simulate       text NOT NULL DEFAULT '',
  trials_planned integer NOT NULL DEFAULT -1,
  created_at     text NOT NULL,
  server_at      timestamptz NOT NULL DEFAULT clock_timestamp(),
  PRIMARY KEY (station, uuid)
);
CREATE INDEX sessions_by_participant ON texel.sessions(participant, protocol);
CREATE TABLE texel.trials (
  station       text NOT NULL,
  session_uuid  uuid NOT NULL,
  trial         integer NOT NULL CHECK (trial >= 0),
  question_json text NOT NULL,
  response_json text NOT NULL,
  state_json    text NOT NULL,
  row_json      text NOT NULL,
  stored_at     text NOT NULL,
  server_at     timestamptz NOT NULL DEFAULT clock_timestamp(),
  PRIMARY KEY (station, session_uuid, trial),
  FOREIGN KEY (station, session_uuid) REFERENCES texel.sessions(station, uuid)
);
CREATE TABLE texel.events (
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  trial        integer NOT NULL,
  seq          integer NOT NULL,
  t_s          double precision NOT NULL,
  kind         text NOT NULL,
  detail       text NOT NULL,
  at           text NOT NULL,
  PRIMARY KEY (station, session_uuid, trial, seq),
  FOREIGN KEY (station, session_uuid, trial) REFERENCES texel.trials(station, session_uuid, trial)
);
CREATE TABLE texel.completions (
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  trials       integer NOT NULL,
  completed_at text NOT NULL,
  server_at    timestamptz NOT NULL DEFAULT clock_timestamp(),
  PRIMARY KEY (station, session_uuid),
  FOREIGN KEY (station, session_uuid) REFERENCES texel.sessions(station, uuid)
);
CREATE TABLE texel.leases (
  participant  text NOT NULL,
  protocol     text NOT NULL,
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  holder       text NOT NULL,
  taken_at     timestamptz NOT NULL,
  heartbeat    timestamptz NOT NULL,
  PRIMARY KEY (participant, protocol)
);
CREATE TABLE texel.station_progress (
  station             text PRIMARY KEY,
  host                text NOT NULL,
  trials_local        bigint NOT NULL,
  trials_shipped      bigint NOT NULL,
  sessions_local      integer NOT NULL,
  completions_pending integer NOT NULL,
  oldest_unshipped_at text NOT NULL,
  reported_at         timestamptz NOT NULL DEFAULT clock_timestamp()
);

-- The study-wide writer lock: one station per (participant, protocol). A
-- station takes it over from another only when that one's heartbeat is older
-- than meta.lease_ttl_s; the same station (its own local lock decides) always.
CREATE FUNCTION texel.take_lease(p_participant text, p_protocol text, p_session uuid, p_holder text) RETURNS text
LANGUAGE plpgsql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
DECLARE
  l texel.leases%ROWTYPE;
  ttl double precision := (SELECT value::double precision FROM texel.meta WHERE key = 'lease_ttl_s');
BEGIN
  INSERT INTO texel.leases VALUES (p_participant, p_protocol, session_user, p_session, p_holder, clock_timestamp(), clock_timestamp())
    ON CONFLICT DO NOTHING;
  IF FOUND THEN RETURN ''; END IF;
  SELECT * INTO l FROM texel.leases WHERE participant = p_participant AND protocol = p_protocol FOR UPDATE;
  IF l.station <> session_user AND l.heartbeat > clock_timestamp() - make_interval(secs => ttl) THEN
    RETURN 'station ' || l.station || ' (' || l.holder || ') since '
           || to_char(l.taken_at AT TIME ZONE 'UTC', 'YYYY-MM-DD"T"HH24:MI:SS"Z"');
  END IF;
  UPDATE texel.leases SET station = session_user, session_uuid = p_session, holder = p_holder,
         taken_at = CASE WHEN l.station = session_user THEN l.taken_at ELSE clock_timestamp() END, heartbeat = clock_timestamp()
   WHERE participant = p_participant AND protocol = p_protocol;
  RETURN '';
END $$;
CREATE FUNCTION texel.renew_lease(p_session uuid) RETURNS boolean
LANGUAGE sql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
  WITH r AS (UPDATE texel.leases SET heartbeat = clock_timestamp()
              WHERE session_uuid = p_session AND station = session_user RETURNING 1)
  SELECT EXISTS (SELECT 1 FROM r);
$$;
CREATE FUNCTION texel.release_lease(p_session uuid) RETURNS void
LANGUAGE sql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
  DELETE FROM texel.leases WHERE session_uuid = p_session AND station = session_user;
$$;

-- Rights: stations insert their own rows and read only those (they never
-- update, delete or alter); analysts read everything; every station sees
-- every station's progress (no participant data in it); the owner alone
-- changes the schema.
REVOKE ALL ON SCHEMA texel FROM PUBLIC;
GRANT USAGE ON SCHEMA texel TO texel_station, texel_analyst;
GRANT SELECT ON texel.meta TO texel_station, texel_analyst;
GRANT SELECT, INSERT ON texel.sessions, texel.trials, texel.events, texel.completions TO texel_station;
GRANT SELECT, INSERT, UPDATE ON texel.station_progress TO texel_station;
GRANT USAGE ON SEQUENCE texel.sessions_id_seq TO texel_station;
GRANT SELECT ON texel.sessions, texel.trials, texel.events, texel.completions, texel.station_progress TO texel_analyst;
REVOKE ALL ON FUNCTION texel.take_lease(text, text, uuid, text), texel.renew_lease(uuid), texel.release_lease(uuid) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION texel.take_lease(text, text, uuid, text), texel.renew_lease(uuid), texel.release_lease(uuid)
  TO texel_station;
ALTER TABLE texel.sessions ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.trials ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.events ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.completions ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.station_progress ENABLE ROW LEVEL SECURITY;
CREATE POLICY station_own ON texel.sessions TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_own ON texel.trials TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_own ON texel.events TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_own ON texel.completions TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_read ON texel.station_progress FOR SELECT TO texel_station USING (true);
CREATE POLICY station_write ON texel.station_progress FOR INSERT TO texel_station WITH CHECK (station = session_user);
CREATE POLICY station_update ON texel.station_progress FOR UPDATE TO texel_station USING (station = session_user)
  WITH CHECK (station = session_user);
CREATE POLICY analyst_read ON texel.sessions FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.trials FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.events FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.completions FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.station_progress FOR SELECT TO texel_analyst USING (true);
)sql",
    // 1 → 2: the finger that explored each trial (the journal's
    // finger_traces, schema version 2), with the same rights as events.
    R"sql(
CREATE TABLE texel.finger_traces (
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  trial        integer NOT NULL,
  source       text NOT NULL CHECK (source IN ('display', 'pointer', 'simulated')),
  mode         text NOT NULL CHECK (mode IN ('', 'display-plays', 'host-streams', 'passive')),
  samples      integer NOT NULL CHECK (samples >= 0),
  trace        text NOT NULL,
  PRIMARY KEY (station, session_uuid, trial),
  FOREIGN KEY (station, session_uuid, trial) REFERENCES texel.trials(station, session_uuid, trial)
);
GRANT SELECT, INSERT ON texel.finger_traces TO texel_station;
GRANT SELECT ON texel.finger_traces TO texel_analyst;
ALTER TABLE texel.finger_traces ENABLE ROW LEVEL SECURITY;
CREATE POLICY station_own ON texel.finger_traces TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY analyst_read ON texel.finger_traces FOR SELECT TO texel_analyst USING (true);
)sql",
};
static_assert(server_migrations.size() == current_server_schema);

bool valid_role(const std::string& r) {
  if (r.empty() || r.size() > 32) return false;
  if (r.rfind("pg_", 0) == 0 || r.rfind("texel_", 0) == 0) return false;
  return std::all_of(r.begin(), r.end(), [](unsigned char c) { return std::islower(c) || std::isdigit(c) || c == '_'; });
}

std::string ident(PGconn* c, const std::string& name) {
  char* q = libpq().PQescapeIdentifier(c, name.c_str(), name.size());
  std::string out = q ? q : "";
  libpq().PQfreemem(q);
  return out;
}

// ---------------------------------------------------------------------------
// Reading the server.

constexpr const char* server_session_columns =
    "SELECT s.id, s.participant, s.protocol, s.study, s.protocol_json, s.seed, s.simulate, "
    "CASE WHEN c.session_uuid IS NULL THEN 'running' ELSE 'finished' END, s.created_at, "
    "greatest(s.created_at, (SELECT max(t.stored_at) FROM texel.trials t WHERE t.station = s.station AND t.session_uuid = "
    "s.uuid), c.completed_at), "
    "(SELECT count(*) FROM texel.trials t WHERE t.station = s.station AND t.session_uuid = s.uuid), s.trials_planned "
    "FROM texel.sessions s LEFT JOIN texel.completions c ON c.station = s.station AND c.session_uuid = s.uuid ";

class ReaderImpl final : public Reader {
 public:
  explicit ReaderImpl(const std::string& db) : t_(parse_target(db)) {
    ConnectFailure f;
    c_ = connect(t_, f);
    if (!c_) throw IoError("cannot connect to " + t_.label + ": " + f.why);
    try {
      check_version(c_, t_.label);
    } catch (...) {
      libpq().PQfinish(c_);
      throw;
    }
  }
  ~ReaderImpl() override { libpq().PQfinish(c_); }
  ReaderImpl(const ReaderImpl&) = delete;
  ReaderImpl& operator=(const ReaderImpl&) = delete;

  [[nodiscard]] const std::string& label() const override { return t_.label; }
  [[nodiscard]] int schema_version() const override { return current_server_schema; }

  [[nodiscard]] std::vector<SessionInfo> sessions() const override {
    Result r = query(std::string(server_session_columns) + "ORDER BY s.id", {}, "listing sessions");
    std::vector<SessionInfo> out;
    for (int i = 0; i < r.rows(); ++i) {
      SessionInfo s;
      s.id = r.i64(i, 0);
      s.participant = r.text(i, 1);
      s.protocol = r.text(i, 2);
      s.study = r.text(i, 3);
      s.protocol_json = r.text(i, 4);
      s.seed = std::stoull(r.text(i, 5));
      s.simulate = r.text(i, 6);
      s.status = r.text(i, 7);
      s.created_at = r.text(i, 8);
      s.updated_at = r.text(i, 9);
      s.trials_done = static_cast<int>(r.i64(i, 10));
      s.trials_planned = static_cast<int>(r.i64(i, 11));
      out.push_back(std::move(s));
    }
    return out;
  }
  [[nodiscard]] std::vector<std::string> participants() const override {
    Result r = query("SELECT DISTINCT participant COLLATE \"C\" FROM texel.sessions ORDER BY 1", {}, "listing participants");
    std::vector<std::string> out;
    for (int i = 0; i < r.rows(); ++i) out.push_back(r.text(i, 0));
    return out;
  }
  [[nodiscard]] std::vector<StoredTrial> trials(std::int64_t id) const override {
    const std::string op = "reading the trials of session " + std::to_string(id);
    // One snapshot for trials and events.
    (void)query("BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY", {}, op);
    struct End {
      PGconn* c;
      ~End() { libpq().PQclear(libpq().PQexec(c, "COMMIT")); }
    } end{c_};
    Result t = query(
        "SELECT t.trial, t.question_json, t.response_json, t.state_json, t.row_json FROM texel.trials t JOIN texel.sessions s "
        "ON s.station = t.station AND s.uuid = t.session_uuid WHERE s.id = $1 ORDER BY t.trial",
        {std::to_string(id)}, op);
    std::vector<StoredTrial> out;
    for (int i = 0; i < t.rows(); ++i) {
      StoredTrial st;
      st.trial = static_cast<int>(t.i64(i, 0));
      st.question_json = t.text(i, 1);
      st.response_json = t.text(i, 2);
      st.state_json = t.text(i, 3);
      st.row = row_from_json(t.text(i, 4), t_.label + ": session " + std::to_string(id) + " trial " + std::to_string(st.trial));
      out.push_back(std::move(st));
    }
    Result e = query(
        "SELECT e.trial, e.t_s, e.kind, e.detail, e.at FROM texel.events e JOIN texel.sessions s ON s.station = e.station AND "
        "s.uuid = e.session_uuid WHERE s.id = $1 ORDER BY e.trial, e.seq",
        {std::to_string(id)}, op);
    for (int i = 0; i < e.rows(); ++i) {
      const auto trial = static_cast<std::size_t>(e.i64(i, 0));
      if (trial >= out.size())
        throw FormatError(t_.label + ": session " + std::to_string(id) + " has events for a missing trial " +
                          std::to_string(trial));
      out[trial].events.push_back(
          TrialEvent{std::strtod(e.text(i, 1).c_str(), nullptr), e.text(i, 2), e.text(i, 3), e.text(i, 4)});
    }
    Result f = query(
        "SELECT f.trial, f.source, f.mode, f.trace FROM texel.finger_traces f JOIN texel.sessions s ON s.station = f.station "
        "AND s.uuid = f.session_uuid WHERE s.id = $1 ORDER BY f.trial",
        {std::to_string(id)}, op);
    for (int i = 0; i < f.rows(); ++i) {
      const auto trial = static_cast<std::size_t>(f.i64(i, 0));
      const std::string where = t_.label + ": session " + std::to_string(id) + " trial " + std::to_string(trial);
      if (trial >= out.size()) throw FormatError(where + ": a finger trace for a missing trial");
      FingerTrace& ft = out[trial].trace;
      ft.source = parse_trace_source(f.text(i, 1));
      if (!f.text(i, 2).empty()) ft.mode = parse_presentation_mode(f.text(i, 2));
      ft.samples = parse_trace_samples(f.text(i, 3), where);
    }
    return out;
  }
  [[nodiscard]] std::string stations() const override {
    std::lock_guard<std::mutex> hold(mu_);
    return station_rows(c_, t_.label);
  }
  [[nodiscard]] std::vector<TrialRow> rows(std::optional<std::int64_t> id) const override {
    std::string sql =
        "SELECT s.id, t.trial, t.row_json, s.participant, s.protocol, s.study FROM texel.trials t JOIN texel.sessions s ON "
        "s.station = t.station AND s.uuid = t.session_uuid ";
    std::vector<std::string> params;
    if (id) {
      sql += "WHERE s.id = $1 ";
      params.push_back(std::to_string(*id));
    }
    sql += "ORDER BY s.id, t.trial";
    Result r = query(sql, params, "reading trial rows");
    std::vector<TrialRow> out;
    out.reserve(static_cast<std::size_t>(r.rows()));
    for (int i = 0; i < r.rows(); ++i) {
      TrialRow row = row_from_json(r.text(i, 2), t_.label + ": session " + r.text(i, 0) + " trial " + r.text(i, 1));
      row.session_id = r.i64(i, 0);
      row.trial = static_cast<int>(r.i64(i, 1));
      row.participant = r.text(i, 3);
      row.protocol = r.text(i, 4);
      row.study = r.text(i, 5);
      out.push_back(std::move(row));
    }
    return out;
  }

 private:
  Result query(const std::string& sql, const std::vector<std::string>& params, const std::string& op) const {
    std::lock_guard<std::mutex> hold(mu_);
    Result r = run(c_, sql, params);
    if (!r.ok()) {
      if (libpq().PQstatus(c_) != CONNECTION_OK)
        throw IoError(t_.label + ": " + op + " failed: the server went away (" + r.error() + ")");
      throw IoError(t_.label + ": " + op + " failed: " + r.error());
    }
    return r;
  }
  Target t_;
  PGconn* c_ = nullptr;
  mutable std::mutex mu_;
};

// ---------------------------------------------------------------------------
// The station: the journal's own connection and the shipper thread.

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

// A session's uuid on the server: derived from what identifies it for good —
// the station (its role), the journal's session id, creation time,
// participant, protocol and seed — two FNV-1a 64-bit hashes, marked as an
// RFC 9562 version 8 (custom) uuid. Nothing to store: a lost shipping
// record only means shipping again under the same keys.
std::string session_uuid(const std::vector<std::string>& parts) {
  std::uint64_t h[2] = {14695981039346656037ull, 0x6a09e667f3bcc909ull};
  for (auto& x : h)
    for (const auto& p : parts) {
      for (const char c : p) x = (x ^ static_cast<unsigned char>(c)) * 1099511628211ull;
      x = (x ^ 0x1f) * 1099511628211ull;  // separator
    }
  std::array<unsigned char, 16> b{};
  for (int i = 0; i < 8; ++i) {
    b[static_cast<std::size_t>(i)] = static_cast<unsigned char>(h[0] >> (56 - 8 * i));
    b[static_cast<std::size_t>(i + 8)] = static_cast<unsigned char>(h[1] >> (56 - 8 * i));
  }
  b[6] = static_cast<unsigned char>((b[6] & 0x0f) | 0x80);  // version 8
  b[8] = static_cast<unsigned char>((b[8] & 0x3f) | 0x80);  // RFC variant
  char out[37];
  std::snprintf(out, sizeof out, "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x", b[0], b[1], b[2], b[3],
                b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15]);
  return out;
}

// Seconds since the epoch of "YYYY-MM-DDTHH:MM:SS.mmmZ"; NaN if unreadable.
double iso_seconds(const std::string& s) {
  std::tm tm{};
  int ms = 0;
  if (std::sscanf(s.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec,
                  &ms) < 6)
    return std::nan("");
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<double>(::timegm(&tm)) + ms / 1000.0;
}

double now_seconds() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

std::string shipping_path(const std::string& journal) { return journal + "-shipping.db"; }

// The journal, through the shipper's own SQLite connection.
class Journal {
 public:
  explicit Journal(const std::string& path) : path_(path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr) !=
        SQLITE_OK) {  // CREATE: for the shipping record; the journal exists (the store opened it)
      const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close_v2(db_);
      throw IoError("cannot open the journal " + path + " (" + why + ")");
    }
    sqlite3_busy_timeout(db_, 5000);
    // The shipping record lives beside the journal (PATH-shipping.db), so
    // that shipping never takes the journal's write lock: the journal stays
    // a plain Texel database written only by the store, and a trial's commit
    // never waits for the shipper. Losing the record only means shipping
    // again, which the server ignores.
    exec(("ATTACH DATABASE '" + shipping_path(path) + "' AS ship").c_str());
    exec("PRAGMA ship.journal_mode = WAL; PRAGMA ship.synchronous = NORMAL");
    // `uuid`: the server session the row speaks for (see Station::check_records).
    // A record file from before it had the column gets it empty, so its rows
    // vouch for nothing and everything is shipped once more (harmless). No
    // transaction: BEGIN IMMEDIATE would lock the journal too; a second
    // process adding the column at the same moment is told apart below.
    exec(
        "CREATE TABLE IF NOT EXISTS ship.journal_ship (session_id INTEGER PRIMARY KEY, session_shipped INTEGER NOT NULL DEFAULT "
        "0, trials_shipped INTEGER NOT NULL DEFAULT 0, finished_shipped INTEGER NOT NULL DEFAULT 0, uuid TEXT NOT NULL DEFAULT "
        "'')");
    const char* has_uuid = "SELECT 1 FROM pragma_table_info('journal_ship', 'ship') WHERE name = 'uuid'";
    if (query(has_uuid).empty()) {
      try {
        exec("ALTER TABLE ship.journal_ship ADD COLUMN uuid TEXT NOT NULL DEFAULT ''");
      } catch (const Error&) {
        if (query(has_uuid).empty()) throw;
      }
    }
  }
  ~Journal() { sqlite3_close_v2(db_); }
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  void exec(const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string why = err ? err : sqlite3_errmsg(db_);
      sqlite3_free(err);
      throw IoError("journal " + path_ + ": " + why);
    }
  }
  // Rows of text (NULL → "").
  std::vector<std::vector<std::string>> query(const char* sql, const std::vector<std::string>& params = {}) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db_, sql, -1, &st, nullptr) != SQLITE_OK)
      throw IoError("journal " + path_ + ": " + sqlite3_errmsg(db_));
    for (std::size_t i = 0; i < params.size(); ++i)
      sqlite3_bind_text(st, static_cast<int>(i + 1), params[i].c_str(), static_cast<int>(params[i].size()), SQLITE_TRANSIENT);
    std::vector<std::vector<std::string>> out;
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
      std::vector<std::string> row;
      for (int c = 0; c < sqlite3_column_count(st); ++c) {
        if (sqlite3_column_type(st, c) == SQLITE_FLOAT) {  // every bit of a double, not SQLite's 15 digits
          char buf[32];
          std::snprintf(buf, sizeof buf, "%.17g", sqlite3_column_double(st, c));
          row.emplace_back(buf);
          continue;
        }
        const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(st, c));
        row.emplace_back(p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(st, c))) : std::string());
      }
      out.push_back(std::move(row));
    }
    const std::string why = sqlite3_errmsg(db_);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) throw IoError("journal " + path_ + ": " + why);
    return out;
  }
  // The session's uuid for `station` (session_uuid()).
  std::string uuid(std::int64_t sid, const std::string& station) {
    const auto r = query("SELECT id, created_at, participant, protocol, seed FROM sessions WHERE id = ?", {std::to_string(sid)});
    if (r.empty()) throw IoError("journal " + path_ + " has no session " + std::to_string(sid));
    return session_uuid({station, r[0][0], r[0][1], r[0][2], r[0][3], r[0][4]});
  }

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
};

struct Lease {
  std::string participant, protocol, uuid;
  bool granted = false;
  bool conflict_reported = false;
};

class StationImpl final : public Station {
 public:
  StationImpl(const std::string& db, const std::string& journal)
      : t_(parse_target(db)), journal_path_(journal), journal_(journal), host_(host_name()) {
    station_ = t_.user;
    {
      std::lock_guard<std::mutex> io(io_mu_);
      // A refusal (password, role, schema) stops the station before anything
      // is stored; a server that is not there does not.
      if (!ensure_connected(true)) {
        std::lock_guard<std::mutex> st(state_mu_);
        state_.connected = false;
      }
      check_records();
      refresh_counts();
    }
    thread_ = std::thread([this] { loop(); });
  }
  ~StationImpl() override {
    {
      std::lock_guard<std::mutex> f(flag_mu_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    if (pg_) libpq().PQfinish(pg_);
  }
  StationImpl(const StationImpl&) = delete;
  StationImpl& operator=(const StationImpl&) = delete;

  void poke() override {
    {
      std::lock_guard<std::mutex> f(flag_mu_);
      poked_ = true;
    }
    cv_.notify_all();
  }

  void take_lease(const SessionInfo& s) override {
    std::lock_guard<std::mutex> io(io_mu_);
    Lease l{s.participant, s.protocol, ""};
    if (ensure_connected(false)) {
      l.uuid = journal_.uuid(s.id, station_);
      const auto holder = lease_call(l);
      if (holder && !holder->empty())
        throw IoError("participant " + s.participant + "'s '" + s.protocol + "' session is being run by " + *holder +
                      "; stop it there first (a station silent for the lease time loses it)");
      l.granted = holder.has_value();
    }
    leases_[s.id] = l;
  }

  void release_lease(std::int64_t sid) override {
    std::lock_guard<std::mutex> io(io_mu_);
    const auto it = leases_.find(sid);
    if (it == leases_.end()) return;
    releases_.push_back(it->first);
    leases_.erase(it);
    poke();
  }

  [[nodiscard]] ShipStatus status() const override {
    std::lock_guard<std::mutex> st(state_mu_);
    ShipStatus s = state_;
    if (s.trials_shipped < s.trials_local && std::isfinite(oldest_unshipped_))
      s.lag_s = std::max(0.0, now_seconds() - oldest_unshipped_);
    return s;
  }

  [[nodiscard]] std::string stations() override {
    std::lock_guard<std::mutex> io(io_mu_);
    if (!pg_ || libpq().PQstatus(pg_) != CONNECTION_OK) throw IoError(t_.label + " is not reachable: " + status().last_error);
    return station_rows(pg_, t_.label);
  }

  bool sync(double timeout_s) override {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
      std::uint64_t seen;
      {
        std::lock_guard<std::mutex> f(flag_mu_);
        seen = passes_;
      }
      poke();
      std::unique_lock<std::mutex> f(flag_mu_);
      if (!pass_cv_.wait_until(f, end, [&] { return passes_ > seen; })) return false;
      f.unlock();
      const ShipStatus s = status();
      // Done when the server confirmed everything (the shipping record says so,
      // even while it is unreachable now).
      if (s.trials_shipped >= s.trials_local && s.completions_pending == 0) return true;
      if (std::chrono::steady_clock::now() >= end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

 private:
  // Under io_mu_. `at_start`: a refusal throws; later it is reported.
  bool ensure_connected(bool at_start) {
    if (pg_ && libpq().PQstatus(pg_) == CONNECTION_OK) return true;
    if (pg_) {
      libpq().PQfinish(pg_);
      pg_ = nullptr;
    }
    ConnectFailure f;
    pg_ = connect(t_, f);
    if (!pg_) {
      set_error(f.why);
      if (at_start && !f.outage) throw IoError("cannot connect to " + t_.label + ": " + f.why);
      return false;
    }
    try {
      check_version(pg_, t_.label);
    } catch (const Error& e) {
      // The link dropping during the check is an outage like any other.
      const bool outage = libpq().PQstatus(pg_) != CONNECTION_OK;
      libpq().PQfinish(pg_);
      pg_ = nullptr;
      set_error(e.what());
      if (at_start && !outage) throw;
      return false;
    }
    Result who = run(pg_, "SELECT session_user");
    if (who.ok() && who.rows() == 1) station_ = who.text(0, 0);
    {
      std::lock_guard<std::mutex> st(state_mu_);
      state_.connected = true;
      state_.last_error.clear();
      state_.station = station_;
    }
    return true;
  }

  void set_error(const std::string& why) {
    std::lock_guard<std::mutex> st(state_mu_);
    state_.connected = pg_ && libpq().PQstatus(pg_) == CONNECTION_OK;
    state_.last_error = why;
  }

  // A statement failed: a lost server closes the connection (reconnect on
  // the next pass); anything else is a refusal that stays reported.
  void failed(const Result& r, const std::string& op) {
    if (pg_ && libpq().PQstatus(pg_) != CONNECTION_OK) {
      libpq().PQfinish(pg_);
      pg_ = nullptr;
      set_error("lost the server while " + op + " (" + r.error() + ")");
    } else {
      libpq().PQclear(libpq().PQexec(pg_, "ROLLBACK"));
      set_error(op + " refused by the server: " + r.error());
    }
  }

  // take_lease on the server: "" granted, else who holds it; nullopt when
  // the call failed (reported).
  std::optional<std::string> lease_call(Lease& l) {
    Result r = run(pg_, "SELECT texel.take_lease($1, $2, $3, $4)",
                   {l.participant, l.protocol, l.uuid, "pid " + std::to_string(::getpid()) + " on host " + host_});
    if (!r.ok()) {
      failed(r, "taking the study-wide lock");
      return std::nullopt;
    }
    return r.text(0, 0);
  }

  void loop() {
    for (;;) {
      {
        std::unique_lock<std::mutex> f(flag_mu_);
        cv_.wait_for(f, std::chrono::seconds(1), [&] { return poked_ || stop_; });
        poked_ = false;
      }
      bool stopping;
      {
        std::lock_guard<std::mutex> f(flag_mu_);
        stopping = stop_;
      }
      {
        std::lock_guard<std::mutex> io(io_mu_);
        try {
          pass();
        } catch (const std::exception& e) {
          set_error(e.what());
        }
        refresh_counts();
      }
      {
        std::lock_guard<std::mutex> f(flag_mu_);
        ++passes_;
      }
      pass_cv_.notify_all();
      if (stopping) return;
    }
  }

  // The shipping record is keyed by the journal's session id, which starts
  // at 1 again in a journal deleted and created anew at the same path (the
  // record beside it survives): a row vouches for a session only when its
  // uuid is that session's for this station; any other row is dropped, so
  // the session is shipped (again — the server ignores what it has). Done
  // before anything is counted or shipped, again when the station's name
  // changes (a service's role is known once connected). Under io_mu_.
  void check_records() {
    if (station_.empty() || records_checked_for_ == station_) return;
    try {
      for (const auto& r :
           journal_.query("SELECT j.session_id, j.uuid, s.id IS NOT NULL FROM ship.journal_ship j LEFT JOIN sessions s ON s.id = "
                          "j.session_id"))
        if (r[2] != "1" || r[1] != journal_.uuid(std::stoll(r[0]), station_))
          (void)journal_.query("DELETE FROM ship.journal_ship WHERE session_id = ?", {r[0]});
      records_checked_for_ = station_;
    } catch (const Error& e) {
      set_error(e.what());  // the journal is busy: the next pass checks again, before shipping
    }
  }

  // One shipping pass, under io_mu_.
  void pass() {
    if (!ensure_connected(false)) return;
    check_records();
    if (records_checked_for_ != station_) return;
    // The study-wide locks: renew ours, take the ones asked for offline.
    for (auto& [sid, l] : leases_) {
      if (l.uuid.empty()) l.uuid = journal_.uuid(sid, station_);  // asked for offline
      if (l.granted) {
        Result r = run(pg_, "SELECT texel.renew_lease($1)", {l.uuid});
        if (!r.ok()) return failed(r, "renewing the study-wide lock");
        if (r.text(0, 0) == "t") continue;
        l.granted = false;
      }
      const auto holder = lease_call(l);
      if (!holder) return;
      if (holder->empty()) {
        l.granted = true;
      } else if (!l.conflict_reported) {
        l.conflict_reported = true;
        std::lock_guard<std::mutex> st(state_mu_);
        state_.conflicts.push_back("participant " + l.participant + "'s '" + l.protocol + "' session is also being run by " +
                                   *holder + " (this station's trials are kept as a session of their own)");
      }
    }
    while (!releases_.empty()) {
      Result r = run(pg_, "SELECT texel.release_lease($1)", {journal_.uuid(releases_.back(), station_)});
      if (!r.ok()) return failed(r, "releasing the study-wide lock");
      releases_.pop_back();
    }
    // Sessions with something the server has not confirmed.
    const auto todo = journal_.query(
        "SELECT s.id, s.participant, s.protocol, s.study, s.protocol_json, s.seed, s.simulate, s.status, s.trials_planned, "
        "s.created_at, s.updated_at, (SELECT COUNT(*) FROM trials t WHERE t.session_id = s.id), "
        "COALESCE(j.session_shipped, 0), COALESCE(j.trials_shipped, 0), COALESCE(j.finished_shipped, 0) "
        "FROM sessions s LEFT JOIN ship.journal_ship j ON j.session_id = s.id "
        "WHERE j.session_id IS NULL OR j.session_shipped = 0 OR j.trials_shipped < (SELECT COUNT(*) FROM trials t WHERE "
        "t.session_id = s.id) OR (s.status = 'finished' AND j.finished_shipped = 0) ORDER BY s.id");
    for (const auto& s : todo)
      if (!ship_session(s)) return;
    report();
  }

  // Ships up to a batch of one session's trials (and its completion) in one
  // server transaction, then records the server's confirmation in the
  // journal. False when the pass must stop (server gone, refused).
  bool ship_session(const std::vector<std::string>& s) {
    const std::string sid = s[0];
    const std::string uuid = journal_.uuid(std::stoll(sid), station_);
    const int total = std::stoi(s[11]);
    int shipped = std::stoi(s[13]);
    constexpr int batch = 200;
    do {
      const int upto = std::min(total, shipped + batch);
      Result b = run(pg_, "BEGIN");
      if (!b.ok()) return failed(b, "shipping"), false;
      Result ss = run(pg_,
                      "INSERT INTO texel.sessions(station, uuid, local_id, participant, protocol, study, protocol_json, seed, "
                      "simulate, trials_planned, created_at) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11) "
                      "ON CONFLICT DO NOTHING",
                      {station_, uuid, sid, s[1], s[2], s[3], s[4], s[5], s[6], s[8], s[9]});
      if (!ss.ok()) return failed(ss, "shipping session " + sid), false;
      const auto trials = journal_.query(
          "SELECT trial, question_json, response_json, state_json, row_json, stored_at FROM trials WHERE session_id = ? AND "
          "trial >= ? AND trial < ? ORDER BY trial",
          {sid, std::to_string(shipped), std::to_string(upto)});
      Result r = insert_rows(
          "INSERT INTO texel.trials(station, session_uuid, trial, question_json, response_json, state_json, row_json, stored_at)",
          uuid, trials);
      if (!r.ok()) return failed(r, "shipping the trials of session " + sid), false;
      const auto events = journal_.query(
          "SELECT trial, seq, t_s, kind, detail, at FROM events WHERE session_id = ? AND trial >= ? AND trial < ? "
          "ORDER BY trial, seq",
          {sid, std::to_string(shipped), std::to_string(upto)});
      Result ev = insert_rows("INSERT INTO texel.events(station, session_uuid, trial, seq, t_s, kind, detail, at)", uuid, events);
      if (!ev.ok()) return failed(ev, "shipping the events of session " + sid), false;
      // Finger traces one statement each: a trace may hold a minute of 1 kHz samples.
      const auto traced = journal_.query("SELECT trial FROM finger_traces WHERE session_id = ? AND trial >= ? AND trial < ?",
                                         {sid, std::to_string(shipped), std::to_string(upto)});
      for (const auto& tr : traced) {
        const auto trace = journal_.query(
            "SELECT trial, source, mode, samples, trace FROM finger_traces WHERE session_id = ? AND trial = ?", {sid, tr[0]});
        Result ft = insert_rows("INSERT INTO texel.finger_traces(station, session_uuid, trial, source, mode, samples, trace)",
                                uuid, trace);
        if (!ft.ok()) return failed(ft, "shipping the finger traces of session " + sid), false;
      }
      const bool complete = upto == total && s[7] == "finished";
      if (complete) {
        Result c = run(pg_,
                       "INSERT INTO texel.completions(station, session_uuid, trials, completed_at) VALUES ($1, $2, $3, $4) "
                       "ON CONFLICT DO NOTHING",
                       {station_, uuid, std::to_string(total), s[10]});
        if (!c.ok()) return failed(c, "shipping the completion of session " + sid), false;
        Result rl = run(pg_, "SELECT texel.release_lease($1)", {uuid});
        if (!rl.ok()) return failed(rl, "releasing the study-wide lock"), false;
      }
      Result e = run(pg_, "COMMIT");
      if (!e.ok()) return failed(e, "shipping session " + sid), false;
      // The server has it: record that (a crash before this line only means
      // shipping it again, which the server ignores).
      (void)journal_.query(
          "INSERT INTO ship.journal_ship(session_id, session_shipped, trials_shipped, finished_shipped, uuid) VALUES (?, 1, ?, "
          "?, ?) ON CONFLICT(session_id) DO UPDATE SET session_shipped = 1, trials_shipped = CASE WHEN uuid = excluded.uuid "
          "THEN max(trials_shipped, excluded.trials_shipped) ELSE excluded.trials_shipped END, finished_shipped = CASE WHEN "
          "uuid = excluded.uuid THEN max(finished_shipped, excluded.finished_shipped) ELSE excluded.finished_shipped END, "
          "uuid = excluded.uuid",
          {sid, std::to_string(upto), complete ? "1" : "0", uuid});
      shipped = upto;
    } while (shipped < total);
    return true;
  }

  // One statement for many rows: (station, uuid) are $1, $2 of every row,
  // the rows' own fields follow; ON CONFLICT DO NOTHING makes it idempotent.
  Result insert_rows(const std::string& head, const std::string& uuid, const std::vector<std::vector<std::string>>& rows) {
    if (rows.empty()) return run(pg_, "SELECT 1");
    std::string sql = head + " VALUES ";
    std::vector<std::string> params = {station_, uuid};
    for (std::size_t r = 0; r < rows.size(); ++r) {
      sql += r ? ", ($1, $2" : "($1, $2";
      for (const auto& v : rows[r]) {
        params.push_back(v);
        sql += ", $" + std::to_string(params.size());
      }
      sql += ")";
    }
    return run(pg_, sql + " ON CONFLICT DO NOTHING", params);
  }

  // This station's row in texel.station_progress (the experimenter's view).
  void report() {
    refresh_counts();
    ShipStatus s = status();
    std::string oldest;
    {
      std::lock_guard<std::mutex> st(state_mu_);
      oldest = oldest_text_;
    }
    Result r =
        run(pg_,
            "INSERT INTO texel.station_progress(station, host, trials_local, trials_shipped, sessions_local, "
            "completions_pending, oldest_unshipped_at, reported_at) VALUES ($1, $2, $3, $4, $5, $6, $7, clock_timestamp()) "
            "ON CONFLICT (station) DO UPDATE SET host = excluded.host, trials_local = excluded.trials_local, "
            "trials_shipped = excluded.trials_shipped, sessions_local = excluded.sessions_local, completions_pending = "
            "excluded.completions_pending, oldest_unshipped_at = excluded.oldest_unshipped_at, reported_at = "
            "excluded.reported_at",
            {station_, host_, std::to_string(s.trials_local), std::to_string(s.trials_shipped), std::to_string(s.sessions_local),
             std::to_string(s.completions_pending), oldest});
    if (!r.ok()) failed(r, "reporting progress");
  }

  // Counts from the journal, under io_mu_.
  void refresh_counts() {
    try {
      const auto c = journal_.query(
          "SELECT (SELECT COUNT(*) FROM trials), (SELECT COALESCE(SUM(trials_shipped), 0) FROM ship.journal_ship), (SELECT "
          "COUNT(*) "
          "FROM sessions), (SELECT COUNT(*) FROM sessions s LEFT JOIN ship.journal_ship j ON j.session_id = s.id WHERE s.status "
          "= "
          "'finished' AND COALESCE(j.finished_shipped, 0) = 0), (SELECT MIN(t.stored_at) FROM trials t LEFT JOIN "
          "ship.journal_ship "
          "j ON j.session_id = t.session_id WHERE t.trial >= COALESCE(j.trials_shipped, 0))");
      std::lock_guard<std::mutex> st(state_mu_);
      state_.trials_local = std::stoll(c[0][0]);
      state_.trials_shipped = std::stoll(c[0][1]);
      state_.sessions_local = std::stoi(c[0][2]);
      state_.completions_pending = std::stoi(c[0][3]);
      oldest_text_ = c[0][4];
      oldest_unshipped_ = c[0][4].empty() ? std::nan("") : iso_seconds(c[0][4]);
    } catch (const Error&) {
      // The journal is busy (a long write): the next pass counts again.
    }
  }

  Target t_;
  std::string journal_path_;
  Journal journal_;
  std::string host_, station_;
  std::string records_checked_for_;  // the station name check_records() last verified the shipping record for
  PGconn* pg_ = nullptr;
  std::map<std::int64_t, Lease> leases_;
  std::vector<std::int64_t> releases_;
  std::mutex io_mu_;  // pg_, journal_, leases_, releases_
  mutable std::mutex state_mu_;
  ShipStatus state_;
  double oldest_unshipped_ = std::nan("");
  std::string oldest_text_;
  std::mutex flag_mu_;
  std::condition_variable cv_, pass_cv_;
  bool poked_ = false, stop_ = false;
  std::uint64_t passes_ = 0;
  std::thread thread_;

 public:
  void init_state() {
    std::lock_guard<std::mutex> st(state_mu_);
    state_.server = t_.label;
    state_.station = station_;
    state_.journal = journal_path_;
  }
};

}  // namespace

std::shared_ptr<Reader> open_reader(const std::string& db) { return std::make_shared<ReaderImpl>(db); }

std::shared_ptr<Station> start_station(const std::string& db, const std::string& journal) {
  auto s = std::make_shared<StationImpl>(db, journal);
  s->init_state();
  return s;
}

}  // namespace pg

std::string default_journal(const std::string& db) {
  const pg::Target t = pg::parse_target(db);
  std::string base;
  if (const char* x = std::getenv("XDG_STATE_HOME"); x && *x) {
    base = x;
  } else {
    const char* home = std::getenv("HOME");
    base = std::string(home && *home ? home : ".") + "/.local/state";
  }
  std::string slug = t.service.empty() ? t.user + "@" + (t.host.empty() ? "local" : t.host) + "-" +
                                             (t.port.empty() ? "5432" : t.port) + "-" + (t.dbname.empty() ? t.user : t.dbname)
                                       : "service-" + t.service;
  for (char& c : slug)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '@' && c != '-' && c != '_' && c != '.') c = '_';
  return base + "/texel/journal-" + slug + ".db";
}

std::vector<std::string> init_postgres(const std::string& db, const std::vector<std::string>& stations,
                                       const std::vector<std::string>& analysts) {
  for (const auto& names : {stations, analysts})
    for (const auto& n : names)
      if (!pg::valid_role(n))
        throw InvalidArgument("role name '" + n +
                              "' is not allowed: use 1-32 characters a-z 0-9 _ (not starting with pg_ or texel_)");
  const pg::Target t = pg::parse_target(db);
  pg::ConnectFailure f;
  PGconn* c = pg::connect(t, f);
  if (!c) throw IoError("cannot connect to " + t.label + ": " + f.why);
  struct Close {
    PGconn* c;
    ~Close() { pg::libpq().PQfinish(c); }
  } close{c};
  std::vector<std::string> report;
  auto must = [&](const std::string& sql, const std::string& op) {
    pg::Result r = pg::run(c, sql);
    if (!r.ok()) {
      pg::libpq().PQclear(pg::libpq().PQexec(c, "ROLLBACK"));
      throw IoError(t.label + ": " + op + " failed: " + r.error());
    }
  };
  must("BEGIN", "starting the set-up");
  must("SELECT pg_advisory_xact_lock(1415071064)", "waiting for another set-up");  // 'TXEX'
  // Roles are the cluster's, shared by its databases: another database's
  // set-up may create them at the same moment.
  for (const char* group : {"texel_station", "texel_analyst"})
    must(std::string("DO $$ BEGIN CREATE ROLE ") + group +
             " NOLOGIN; EXCEPTION WHEN duplicate_object OR unique_violation THEN NULL; END $$",
         std::string("creating the role ") + group);
  int v = pg::server_version(c, t.label);
  pg::refuse_newer(v, t.label);
  const int from = v;
  for (; v < pg::current_server_schema; ++v) {
    must(pg::server_migrations[static_cast<std::size_t>(v)], "migrating the schema to version " + std::to_string(v + 1));
    must("UPDATE texel.meta SET value = '" + std::to_string(v + 1) + "' WHERE key = 'schema_version'",
         "setting the schema version");
  }
  report.push_back(from == v ? "schema texel is at version " + std::to_string(v)
                             : "schema texel migrated from version " + std::to_string(from) + " to " + std::to_string(v));
  auto add_role = [&](const std::string& name, const char* group) {
    const std::string id = pg::ident(c, name);
    pg::Result exists = pg::run(c, "SELECT 1 FROM pg_roles WHERE rolname = $1", {name});
    must("DO $$ BEGIN CREATE ROLE " + id + " LOGIN IN ROLE " + group +
             "; EXCEPTION WHEN duplicate_object OR unique_violation THEN GRANT " + group + " TO " + id + "; END $$",
         "creating the role " + name);
    if (exists.ok() && exists.rows() == 0)
      report.push_back("created login role " + name + " (" + group + "); set its password with psql's \\password " + name);
    else
      report.push_back("role " + name + " is a member of " + group);
  };
  for (const auto& s : stations) add_role(s, "texel_station");
  for (const auto& a : analysts) add_role(a, "texel_analyst");
  must("COMMIT", "committing the set-up");
  return report;
}

}  // namespace texel::experiment
