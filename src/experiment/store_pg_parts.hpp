// What the PostgreSQL store's sources share (internal, never installed;
// store_pg.hpp, docs/session-store.md "Many stations"): libpq itself (opened
// on first use), the connection target, connecting, the result wrapper and
// the schema checks every connection makes — defined in store_pg.cpp, used by
// store_pg_schema.cpp (the server schema, texel store init),
// store_pg_reader.cpp (reading the server) and store_pg_station.cpp (a
// station's journal and shipper). libpq types stay in these files.
#pragma once

#include <libpq-fe.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "store_pg.hpp"
#include "texel/detail/shared_object.hpp"

namespace texel::experiment::pg {

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

/// The target of a postgresql:// URI or service=NAME: refuses a password in
/// it, and a remote host without TLS (force_ssl when no sslmode is given).
Target parse_target(const std::string& db);

/// libpq's message on one line (trailing space and DETAIL/HINT lines cut).
std::string trim(std::string s);

struct ConnectFailure {
  std::string why;
  bool outage = false;
};

// Connects, or says why not; the message names the server, never a secret.
PGconn* connect(const Target& t, ConnectFailure& failure);

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

Result run(PGconn* c, const std::string& sql, const std::vector<std::string>& params = {});

// The Texel schema's version on the server, 0 when there is none.
int server_version(PGconn* c, const std::string& label);
// A server schema this build cannot use, whoever opens it.
void refuse_newer(int v, const std::string& label);
// Readers and stations need the server at this build's version.
void check_version(PGconn* c, const std::string& label);
// Every station's progress as a JSON array (one statement, built by the server).
std::string station_rows(PGconn* c, const std::string& label);

}  // namespace texel::experiment::pg
