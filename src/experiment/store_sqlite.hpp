// The experiment store's SQLite layer (internal; store.cpp,
// docs/session-store.md): the connection with its one-line errors, the
// statement and transaction wrappers, and what the store's sources share —
// the schema's migrations (store_schema.cpp) and the writer lock's process
// checks (store_writer.cpp). SQLite types stay behind these wrappers.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include "store_pg.hpp"
#include "texel/error.hpp"
#include "texel/experiment/store.hpp"

namespace texel::experiment {

inline constexpr int busy_timeout_ms = 5000;
// PRAGMA application_id: 'T' 'X' 'E' 'X' — marks the file as a Texel
// experiment database, so another application's SQLite file is refused.
inline constexpr std::int64_t texel_application_id = 0x54584558;

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

namespace store_parts {

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

inline void exec(const StoreImpl& s, const char* sql, const std::string& op) {
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

inline std::int64_t pragma_int(const StoreImpl& s, const char* sql, const std::string& op) {
  Stmt st(s, sql, op);
  return st.step() ? st.i64(0) : 0;
}

/// Takes the database from its schema version to the current one, one
/// numbered migration per transaction (store_schema.cpp).
void migrate(StoreImpl& s);

// The writer lock (store_writer.cpp).

/// This machine's host name ("unknown" if unreadable): the writer row's
/// host, and a PostgreSQL station's (store_pg_station.cpp).
std::string host_name();

/// This process's start time (clock ticks since boot), the writer row's
/// proof that a pid is still the process that wrote it.
std::int64_t own_start();

/// Inside a write transaction: is `lock` still this process's hold on its
/// session (not taken over by someone who judged us dead)?
void check_lock(const StoreImpl& s, const std::shared_ptr<StoreImpl>& mine, const WriterLock& lock,
                const std::shared_ptr<StoreImpl>& lock_impl, const std::string& op);

}  // namespace store_parts
}  // namespace texel::experiment
