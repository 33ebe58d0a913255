// The PostgreSQL store (docs/session-store.md "Many stations") against a real
// server that scripts/pg-test-server.sh started (ctest fixture pg_server;
// TEXEL_PG_ENV names its connection file): set-up and migrations, a station
// shipping its journal, repeated shipping, the study-wide lock (also after a
// SIGKILLed station), the roles' rights with real credentials, and the
// one-line errors.
#include <gtest/gtest.h>
#include <libpq-fe.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "fixtures.hpp"
#include "texel/error.hpp"
#include "texel/experiment/store.hpp"

namespace ex = texel::experiment;
using texel::test_support::full_trial;
using texel::test_support::message_of;
using texel::test_support::TempDir;

namespace {

std::map<std::string, std::string> server() {
  std::map<std::string, std::string> env;
  const char* file = std::getenv("TEXEL_PG_ENV");
  if (!file) return env;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (const auto eq = line.find('='); eq != std::string::npos) env[line.substr(0, eq)] = line.substr(eq + 1);
  return env;
}

class PgStore : public ::testing::Test {
 protected:
  void SetUp() override {
    env_ = server();
    ASSERT_FALSE(env_.empty()) << "TEXEL_PG_ENV does not name a running test server (scripts/pg-test-server.sh)";
    std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    db_ = "t_";
    for (const char c : name) db_ += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    admin_sql("postgres", "DROP DATABASE IF EXISTS " + db_ + " WITH (FORCE)");
    admin_sql("postgres", "CREATE DATABASE " + db_);
    (void)ex::init_postgres(admin_uri(), {"st1", "st2"}, {"an1"});
    // Passwords are the lab's to set (psql \password); the test sets them
    // as the admin and hands them to libpq in a .pgpass file only.
    admin_sql(db_, "ALTER ROLE st1 PASSWORD 'pw-st1'; ALTER ROLE st2 PASSWORD 'pw-st2'; ALTER ROLE an1 PASSWORD 'pw-an1'");
    const std::string port = env_["TEXEL_PG_PORT"];
    pgpass_ = dir_.write("pgpass", "127.0.0.1:" + port + ":*:st1:pw-st1\n127.0.0.1:" + port + ":*:st2:pw-st2\n127.0.0.1:" + port +
                                       ":*:an1:pw-an1\n127.0.0.1:" + port + ":*:st3:wrong\n");
    ::chmod(pgpass_.c_str(), 0600);
    ::setenv("PGPASSFILE", pgpass_.c_str(), 1);
  }

  [[nodiscard]] std::string admin_uri() const {
    return "postgresql://texel_admin@/" + db_ + "?host=" + env_.at("TEXEL_PG_SOCKET") + "&port=" + env_.at("TEXEL_PG_PORT");
  }
  [[nodiscard]] std::string uri(const std::string& role) const {
    return "postgresql://" + role + "@127.0.0.1:" + env_.at("TEXEL_PG_PORT") + "/" + db_;
  }
  void admin_sql(const std::string& db, const std::string& sql) {
    const std::string ci =
        "host=" + env_["TEXEL_PG_SOCKET"] + " port=" + env_["TEXEL_PG_PORT"] + " user=texel_admin dbname=" + db;
    PGconn* c = PQconnectdb(ci.c_str());
    ASSERT_EQ(PQstatus(c), CONNECTION_OK) << PQerrorMessage(c);
    PGresult* r = PQexec(c, sql.c_str());
    const auto st = PQresultStatus(r);
    EXPECT_TRUE(st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) << sql << ": " << PQresultErrorMessage(r);
    PQclear(r);
    PQfinish(c);
  }
  // As a role over TCP (password from .pgpass): "" or the error text.
  std::string as(const std::string& role, const std::string& sql, std::string* value = nullptr) {
    PGconn* c = PQconnectdb(uri(role).c_str());
    EXPECT_EQ(PQstatus(c), CONNECTION_OK) << PQerrorMessage(c);
    PGresult* r = PQexec(c, sql.c_str());
    const auto st = PQresultStatus(r);
    std::string out = st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK ? "" : PQresultErrorMessage(r);
    if (value && out.empty() && PQntuples(r) > 0) *value = PQgetvalue(r, 0, 0);
    PQclear(r);
    PQfinish(c);
    return out;
  }

  ex::Store station(const std::string& role, const std::string& journal) {
    return ex::Store::open(uri(role), ex::StoreMode::read_write, ex::StoreOptions{dir_.at(journal)});
  }

  std::int64_t run_session(ex::Store& s, const std::string& who, int trials, bool finish) {
    const auto id =
        s.create_session(who, "texel-length", "texel-length", R"({"name":"texel-length"})", 18446744073709551615ull, "", trials);
    auto lock = s.acquire_writer(id);
    for (int i = 0; i < trials; ++i) s.append_trial(lock, full_trial(i));
    if (finish) s.finish_session(lock);
    return id;
  }

  std::map<std::string, std::string> env_;
  std::string db_, pgpass_;
  TempDir dir_{"store-pg"};
};

}  // namespace

TEST_F(PgStore, InitMigratesOnceAndCreatesTheRoles) {
  const auto again = ex::init_postgres(admin_uri(), {"st1"}, {});
  ASSERT_FALSE(again.empty());
  EXPECT_EQ(again[0], "schema texel is at version 2");
  EXPECT_EQ(again[1], "role st1 is a member of texel_station");
  std::string v;
  EXPECT_EQ(as("an1", "SELECT value FROM texel.meta WHERE key = 'schema_version'", &v), "");
  EXPECT_EQ(v, "2");
  EXPECT_THROW((void)ex::init_postgres(admin_uri(), {"Bad Name"}, {}), texel::InvalidArgument);
}

TEST_F(PgStore, StationShipsItsJournalAndTheAnalystReadsTheSame) {
  auto s = station("st1", "st1.db");
  const auto id = run_session(s, "S01", 12, true);
  ASSERT_TRUE(s.sync(20)) << s.shipping().last_error;
  const ex::ShipStatus st = s.shipping();
  EXPECT_TRUE(st.connected);
  EXPECT_EQ(st.station, "st1");
  EXPECT_EQ(st.trials_local, 12);
  EXPECT_EQ(st.trials_shipped, 12);
  EXPECT_EQ(st.completions_pending, 0);
  EXPECT_EQ(st.lag_s, 0.0);

  const auto journal = ex::Store::open(dir_.at("st1.db"), ex::StoreMode::read_only);
  const auto server = ex::Store::open(uri("an1"), ex::StoreMode::read_only);
  const auto sessions = server.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, "finished");
  EXPECT_EQ(sessions[0].trials_done, 12);
  EXPECT_EQ(sessions[0].seed, 18446744073709551615ull);
  EXPECT_EQ(server.participants(), std::vector<std::string>{"S01"});
  const auto a = journal.trials(id), b = server.trials(sessions[0].id);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].question_json, b[i].question_json);
    EXPECT_EQ(a[i].response_json, b[i].response_json);
    EXPECT_EQ(a[i].state_json, b[i].state_json);
    ASSERT_EQ(a[i].events.size(), b[i].events.size());
    for (std::size_t e = 0; e < a[i].events.size(); ++e) {
      EXPECT_EQ(a[i].events[e].kind, b[i].events[e].kind);
      EXPECT_EQ(a[i].events[e].t_s, b[i].events[e].t_s);
    }
    // The finger traces (even trials have one) arrive sample for sample.
    EXPECT_EQ(a[i].trace.source, b[i].trace.source);
    EXPECT_EQ(a[i].trace.mode, b[i].trace.mode);
    EXPECT_EQ(ex::trace_samples_text(a[i].trace.samples), ex::trace_samples_text(b[i].trace.samples));
    EXPECT_EQ(b[i].trace.samples.size(), i % 2 == 0 ? full_trial(0).trace.samples.size() : 0u);
  }
  const auto ra = journal.rows(), rb = server.rows();
  ASSERT_EQ(ra.size(), rb.size());
  for (std::size_t i = 0; i < ra.size(); ++i) {
    auto x = ra[i], y = rb[i];
    x.session_id = y.session_id = 0;  // ids are the server's
    EXPECT_EQ(ex::row_json(x), ex::row_json(y));
  }
}

TEST_F(PgStore, RepeatedShippingStoresNothingTwice) {
  {
    auto s = station("st1", "st1.db");
    (void)run_session(s, "S01", 5, true);
    ASSERT_TRUE(s.sync(20));
  }
  // Forget what the server confirmed: everything is shipped again.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(dir_.at("st1.db-shipping.db").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE journal_ship SET session_shipped = 0, trials_shipped = 0, finished_shipped = 0", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  // Even without its shipping record (lost, deleted) the journal ships under
  // the same keys.
  std::filesystem::remove(dir_.at("st1.db-shipping.db"));
  auto s = station("st1", "st1.db");
  ASSERT_TRUE(s.sync(20));
  std::string n;
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.trials", &n), "");
  EXPECT_EQ(n, "5");
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.completions", &n), "");
  EXPECT_EQ(n, "1");
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.sessions", &n), "");
  EXPECT_EQ(n, "1");
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.finger_traces", &n), "");
  EXPECT_EQ(n, "3");  // trials 0, 2 and 4
}

// A journal deleted and started again at the same path numbers its sessions
// from 1 again, while the shipping record beside it (JOURNAL-shipping.db)
// still says session 1 is on the server: the record must not vouch for the
// new journal's sessions. And a record written before the records named
// their session (no uuid column) vouches for nothing: shipped again.
TEST_F(PgStore, AJournalStartedAgainBesideAnOldShippingRecordIsShippedWhole) {
  {
    auto s = station("st1", "st1.db");
    (void)run_session(s, "S01", 5, true);
    ASSERT_TRUE(s.sync(20));
  }
  for (const char* suffix : {"", "-wal", "-shm"}) std::filesystem::remove(dir_.at(std::string("st1.db") + suffix));
  std::string n;
  {
    auto s = station("st1", "st1.db");
    (void)run_session(s, "S02", 3, true);
    ASSERT_TRUE(s.sync(20)) << s.shipping().last_error;
    EXPECT_EQ(s.shipping().trials_local, 3);
    EXPECT_EQ(s.shipping().trials_shipped, 3);
  }
  EXPECT_EQ(as("an1",
               "SELECT count(*) FROM texel.trials t JOIN texel.sessions s ON s.uuid = t.session_uuid WHERE "
               "s.participant = 'S02'",
               &n),
            "");
  EXPECT_EQ(n, "3");
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.completions", &n), "");
  EXPECT_EQ(n, "2");

  // A new journal (written as a plain store: nothing shipped yet) beside an
  // older build's record file that says session 1 is on the server.
  for (const char* file :
       {"st1.db", "st1.db-wal", "st1.db-shm", "st1.db-shipping.db", "st1.db-shipping.db-wal", "st1.db-shipping.db-shm"})
    std::filesystem::remove(dir_.at(file));
  {
    auto journal = ex::Store::open(dir_.at("st1.db"), ex::StoreMode::read_write);
    (void)run_session(journal, "S03", 4, true);
  }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(dir_.at("st1.db-shipping.db").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db,
                         "CREATE TABLE journal_ship (session_id INTEGER PRIMARY KEY, session_shipped INTEGER NOT NULL DEFAULT "
                         "0, trials_shipped INTEGER NOT NULL DEFAULT 0, finished_shipped INTEGER NOT NULL DEFAULT 0); "
                         "INSERT INTO journal_ship VALUES (1, 1, 5, 1)",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  {
    auto s = station("st1", "st1.db");
    ASSERT_TRUE(s.sync(20)) << s.shipping().last_error;
    EXPECT_EQ(s.shipping().trials_shipped, 4);
  }
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.trials", &n), "");
  EXPECT_EQ(n, "12");  // 5 + 3 + 4, nothing twice
}

// Server version 1 → 2 (texel.finger_traces): store init migrates a server
// of the previous version, its trials kept, and the analyst reads the new table.
TEST_F(PgStore, InitMigratesAVersionOneServerAddingFingerTraces) {
  {
    auto s = station("st1", "st1.db");
    (void)run_session(s, "S01", 1, false);
    ASSERT_TRUE(s.sync(20));
  }
  admin_sql(db_, "DROP TABLE texel.finger_traces; UPDATE texel.meta SET value = '1' WHERE key = 'schema_version'");
  EXPECT_THROW((void)ex::Store::open(uri("an1"), ex::StoreMode::read_only), texel::FormatError);
  const auto report = ex::init_postgres(admin_uri(), {}, {});
  ASSERT_FALSE(report.empty());
  EXPECT_EQ(report[0], "schema texel migrated from version 1 to 2");
  std::string n;
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.trials", &n), "");
  EXPECT_EQ(n, "1");
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.finger_traces", &n), "");
  EXPECT_EQ(n, "0");  // the trace shipped before went with the dropped table
}

TEST_F(PgStore, SecondStationIsRefusedTheSameParticipantUntilTheFirstLetsGo) {
  auto a = station("st1", "st1.db");
  const auto ida = a.create_session("S07", "texel-length", "texel-length", "{}", 1, "", 4);
  std::optional<ex::WriterLock> la(a.acquire_writer(ida));
  auto b = station("st2", "st2.db");
  const auto idb = b.create_session("S07", "texel-length", "texel-length", "{}", 1, "", 4);
  const auto msg = message_of<texel::IoError>([&] { (void)b.acquire_writer(idb); });
  EXPECT_NE(msg.find("participant S07's 'texel-length' session is being run by station st1"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos);
  // Another participant is fine; and once st1 lets go, st2 may.
  const auto other = b.create_session("S08", "texel-length", "texel-length", "{}", 1, "", 4);
  EXPECT_NO_THROW((void)b.acquire_writer(other));
  la.reset();
  ASSERT_TRUE(a.sync(20));
  EXPECT_NO_THROW((void)b.acquire_writer(idb));
}

TEST_F(PgStore, LeaseOfAKilledStationIsTakenOverAfterItsTimeToLive) {
  admin_sql(db_, "UPDATE texel.meta SET value = '2' WHERE key = 'lease_ttl_s'");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      auto a = station("st1", "st1.db");
      const auto id = a.create_session("S09", "texel-length", "texel-length", "{}", 1, "", 4);
      auto lock = a.acquire_writer(id);
      std::raise(SIGKILL);  // no release, no goodbye
    } catch (...) {
    }
    std::_Exit(3);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  auto b = station("st2", "st2.db");
  const auto id = b.create_session("S09", "texel-length", "texel-length", "{}", 1, "", 4);
  EXPECT_THROW((void)b.acquire_writer(id), texel::IoError);  // st1's heartbeat is fresh
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  EXPECT_NO_THROW((void)b.acquire_writer(id));  // silent longer than the lease: taken over
  // The killed station itself resumes at once (its own lease, its local lock decides).
  auto a = station("st1", "st1.db");
  EXPECT_NO_THROW((void)a.acquire_writer(1));
}

TEST_F(PgStore, RolesStationsInsertOnlyTheirOwnAnalystsOnlyRead) {
  {
    auto a = station("st1", "st1.db");
    (void)run_session(a, "S01", 3, true);
    ASSERT_TRUE(a.sync(20));
    auto b = station("st2", "st2.db");
    (void)run_session(b, "S02", 3, false);
    ASSERT_TRUE(b.sync(20));
  }
  std::string n;
  // A station sees only its own participants.
  EXPECT_EQ(as("st1", "SELECT string_agg(participant, ',') FROM texel.sessions", &n), "");
  EXPECT_EQ(n, "S01");
  EXPECT_EQ(as("st1", "SELECT count(*) FROM texel.trials", &n), "");
  EXPECT_EQ(n, "3");
  EXPECT_EQ(ex::Store::open(uri("st2"), ex::StoreMode::read_only).participants(), std::vector<std::string>{"S02"});
  // It cannot delete, update, alter or create, nor insert as another station.
  EXPECT_NE(as("st1", "DELETE FROM texel.trials").find("permission denied"), std::string::npos);
  EXPECT_NE(as("st1", "UPDATE texel.trials SET response_json = '{}'").find("permission denied"), std::string::npos);
  EXPECT_NE(as("st1", "DELETE FROM texel.sessions").find("permission denied"), std::string::npos);
  EXPECT_NE(as("st1", "ALTER TABLE texel.trials ADD COLUMN x integer").find("must be owner"), std::string::npos);
  EXPECT_NE(as("st1", "DROP TABLE texel.events").find("must be owner"), std::string::npos);
  EXPECT_NE(as("st1", "CREATE TABLE texel.mine (x integer)").find("permission denied"), std::string::npos);
  EXPECT_NE(as("st1", "TRUNCATE texel.trials").find("permission denied"), std::string::npos);
  EXPECT_NE(as("st1",
               "INSERT INTO texel.sessions(station, uuid, local_id, participant, protocol, study, protocol_json, seed, "
               "created_at) VALUES ('st2', gen_random_uuid(), 1, 'X', 'p', 'p', '{}', '1', 'now')")
                .find("row-level security"),
            std::string::npos);
  EXPECT_NE(as("st1", "DELETE FROM texel.leases").find("permission denied"), std::string::npos);
  // Analysts read everything and write nothing.
  EXPECT_EQ(as("an1", "SELECT count(*) FROM texel.trials", &n), "");
  EXPECT_EQ(n, "6");
  EXPECT_NE(as("an1", "DELETE FROM texel.trials").find("permission denied"), std::string::npos);
  EXPECT_NE(as("an1", "INSERT INTO texel.completions VALUES ('st1', gen_random_uuid(), 1, 'x')").find("permission denied"),
            std::string::npos);
  EXPECT_EQ(ex::Store::open(uri("an1"), ex::StoreMode::read_only).sessions().size(), 2u);
  // Every station's progress is visible to every station (no participant data in it).
  EXPECT_EQ(as("st1", "SELECT count(*) FROM texel.station_progress", &n), "");
  EXPECT_EQ(n, "2");
  // The experimenter's view (the studio's experiment.stations) from a station.
  auto a = station("st1", "st1.db");
  const auto view = nlohmann::json::parse(ex::stations_json(a));
  EXPECT_TRUE(view["multi_station"].get<bool>());
  EXPECT_EQ(view["this_station"]["station"], "st1");
  EXPECT_EQ(view["server_error"], "");
  ASSERT_EQ(view["stations"].size(), 2u);
  EXPECT_EQ(view["stations"][1]["station"], "st2");
  EXPECT_EQ(view["stations"][1]["trials_local"], 3);
  EXPECT_EQ(view["stations"][1]["trials_shipped"], 3);
  EXPECT_EQ(view["stations"][1]["lag_s"], 0);
  EXPECT_GE(view["stations"][1]["last_report_s"].get<double>(), 0.0);
}

TEST_F(PgStore, BadInputIsOneLineAndLosesNothing) {
  auto one_line = [](const std::string& m) { return !m.empty() && m.find('\n') == std::string::npos; };
  // Wrong URI; a password in the URI; plain text to a remote host.
  auto m = message_of<texel::InvalidArgument>(
      [&] { (void)ex::Store::open("postgresql://st1@127.0.0.1/x?nosuchoption=1", ex::StoreMode::read_only); });
  EXPECT_NE(m.find("not a valid PostgreSQL connection URI"), std::string::npos) << m;
  m = message_of<texel::InvalidArgument>(
      [&] { (void)ex::Store::open("postgresql://st1:secret@127.0.0.1/x", ex::StoreMode::read_only); });
  EXPECT_NE(m.find("~/.pgpass"), std::string::npos) << m;
  EXPECT_EQ(m.find("secret"), std::string::npos) << m;
  m = message_of<texel::InvalidArgument>(
      [&] { (void)ex::Store::open("postgresql://st1@192.0.2.1/x?sslmode=disable", ex::StoreMode::read_only); });
  EXPECT_NE(m.find("TLS is required"), std::string::npos) << m;
  // Wrong password: refused at start, no journal left.
  m = message_of<texel::IoError>([&] { (void)station("st3", "st3.db"); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("password authentication failed"), std::string::npos) << m;
  EXPECT_EQ(m.find("wrong"), std::string::npos) << m;
  // No Texel schema; a newer one.
  admin_sql("postgres", "DROP DATABASE IF EXISTS " + db_ + "_empty WITH (FORCE)");
  admin_sql("postgres", "CREATE DATABASE " + db_ + "_empty");
  m = message_of<texel::FormatError>([&] {
    (void)ex::Store::open(
        "postgresql://texel_admin@/" + db_ + "_empty?host=" + env_["TEXEL_PG_SOCKET"] + "&port=" + env_["TEXEL_PG_PORT"],
        ex::StoreMode::read_only);
  });
  EXPECT_NE(m.find("no texel schema"), std::string::npos) << m;
  admin_sql("postgres", "DROP DATABASE " + db_ + "_empty WITH (FORCE)");
  admin_sql(db_, "UPDATE texel.meta SET value = '3' WHERE key = 'schema_version'");
  m = message_of<texel::FormatError>([&] { (void)ex::Store::open(uri("an1"), ex::StoreMode::read_only); });
  EXPECT_NE(m.find("has schema version 3, newer than this build's 2; use a newer texel"), std::string::npos) << m;
  EXPECT_THROW((void)station("st1", "st1.db"), texel::FormatError);
  admin_sql(db_, "UPDATE texel.meta SET value = '2' WHERE key = 'schema_version'");
  // Server down at start: the station runs on its journal and says so; a reader cannot.
  const std::string down = "postgresql://st1@127.0.0.1:1/" + db_;
  m = message_of<texel::IoError>([&] { (void)ex::Store::open(down, ex::StoreMode::read_only); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("cannot connect to postgresql://st1@127.0.0.1:1/"), std::string::npos) << m;
  {
    auto s = ex::Store::open(down, ex::StoreMode::read_write, ex::StoreOptions{dir_.at("down.db")});
    EXPECT_FALSE(s.shipping().connected);
    EXPECT_NE(s.shipping().last_error.find("Connection refused"), std::string::npos) << s.shipping().last_error;
    (void)run_session(s, "S03", 4, true);
    EXPECT_FALSE(s.sync(1));
    EXPECT_EQ(s.shipping().trials_local, 4);
    EXPECT_EQ(s.shipping().trials_shipped, 0);
  }
  // Pointed at the right server later, the same journal catches up.
  auto s = ex::Store::open(uri("st1"), ex::StoreMode::read_write, ex::StoreOptions{dir_.at("down.db")});
  ASSERT_TRUE(s.sync(20)) << s.shipping().last_error;
  EXPECT_EQ(ex::Store::open(uri("an1"), ex::StoreMode::read_only).rows().size(), 4u);
}
