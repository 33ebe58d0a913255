// The session store on PostgreSQL (store_pg.hpp, docs/session-store.md
// "Many stations"): connecting to the server — libpq opened on first use,
// the connection target and its TLS rule, the result wrapper and the schema
// checks. The other parts share these through store_pg_parts.hpp:
// store_pg_schema.cpp (the server schema's migrations, texel store init),
// store_pg_reader.cpp (reading the server) and store_pg_station.cpp (a
// station's journal and shipper). libpq types stay in these files.
//
//  * Connections follow libpq's conventions: a postgresql:// URI or
//    service=NAME; the password comes from ~/.pgpass (PGPASSFILE) or the
//    service file, never from the URI (refused) or a command line, and no
//    message here prints one.
//  * TLS: a host that is not loopback or a Unix socket gets sslmode=require
//    unless the URI asks for verify-ca/verify-full; sslmode=disable/allow/
//    prefer for such a host is refused. After connecting, a non-loopback
//    connection without TLS is closed (a service file may name the host).
#include <pwd.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "store_pg_parts.hpp"
#include "texel/error.hpp"
#include "texel/experiment/store.hpp"

namespace texel::experiment {

bool is_postgres(std::string_view db) {
  return db.rfind("postgresql://", 0) == 0 || db.rfind("postgres://", 0) == 0 || db.rfind("service=", 0) == 0;
}

namespace pg {
namespace {

bool loopback_host(const std::string& h) {
  return h.empty() || h[0] == '/' || h[0] == '@' || h == "localhost" || h == "::1" || h.rfind("127.", 0) == 0;
}

std::string login_name() {
  if (const char* u = std::getenv("PGUSER"); u && *u) return u;
  if (const passwd* pw = ::getpwuid(::getuid())) return pw->pw_name;
  return "unknown";
}

}  // namespace

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

namespace {

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

}  // namespace

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

Result run(PGconn* c, const std::string& sql, const std::vector<std::string>& params) {
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

}  // namespace pg
}  // namespace texel::experiment
