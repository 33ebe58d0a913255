// A station of the PostgreSQL store (store_pg.hpp: pg::Station,
// docs/session-store.md "Many stations"): the journal's own connection, the
// shipper thread and the study-wide leases, and where a station's journal
// lives by default.
//
//  * A station (Station) ships its journal — the local SQLite store every
//    trial is committed to first — to the server from a background thread.
//    The server's keys are (station, session uuid, trial), every insert is
//    ON CONFLICT DO NOTHING, and the journal records how far the server has
//    confirmed: repeating or reordering a shipment is harmless.
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "store_pg_parts.hpp"
#include "store_sqlite.hpp"
#include "texel/error.hpp"

namespace texel::experiment {
namespace pg {
namespace {

// This machine's name (store_writer.cpp): the lease holder and progress row's host.
using store_parts::host_name;

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

}  // namespace texel::experiment
