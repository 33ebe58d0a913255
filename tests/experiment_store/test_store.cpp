// The SQLite session store (docs/session-store.md): schema and version,
// migrations, round trips, append-only trials, the writer lock (same process,
// dead process, a live second process), and bad files left untouched.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "fixtures.hpp"
#include "texel/error.hpp"
#include "texel/experiment/store.hpp"

namespace ex = texel::experiment;
using texel::test_support::file_bytes;
using texel::test_support::full_trial;
using texel::test_support::RawDb;
using texel::test_support::TempDir;

namespace {

std::int64_t new_session(ex::Store& s, const std::string& who = "S01") {
  return s.create_session(who, "texel-length", "texel-length", R"({"name":"texel-length"})", 18446744073709551615ull, "", 40);
}

using texel::test_support::message_of;

}  // namespace

TEST(Store, CreatesVersionedWalSchema) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    EXPECT_EQ(s.schema_version(), ex::Store::current_schema_version);
    EXPECT_EQ(s.path(), path);
    EXPECT_TRUE(s.sessions().empty());
    EXPECT_TRUE(s.participants().empty());
  }
  RawDb raw(path);
  EXPECT_EQ(raw.one("PRAGMA user_version"), "2");
  EXPECT_EQ(raw.one("PRAGMA application_id"), std::to_string(0x54584558));
  EXPECT_EQ(raw.one("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(raw.one("SELECT group_concat(name, ',') FROM (SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name)"),
            "events,finger_traces,participants,sessions,trials,writers");
}

TEST(Store, MigratesAnEmptyFileFromVersionZero) {
  TempDir dir("store");
  // Version 0: a zero-byte file, and an SQLite file with no tables.
  const auto empty = dir.write("empty.db", "");
  const auto bare = dir.at("bare.db");
  { RawDb(bare).exec("PRAGMA page_size = 4096; VACUUM"); }
  for (const auto& path : {empty, bare}) {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    EXPECT_EQ(s.schema_version(), 2) << path;
    EXPECT_GT(new_session(s), 0);
  }
  // read_only never migrates: an empty file has nothing to read.
  const auto empty2 = dir.write("empty2.db", "");
  EXPECT_NE(
      message_of<texel::FormatError>([&] { (void)ex::Store::open(empty2, ex::StoreMode::read_only); }).find("empty database"),
      std::string::npos);
  EXPECT_EQ(file_bytes(empty2), "");
}

TEST(Store, CurrentVersionReopensUnchanged) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    const auto id = new_session(s);
    auto lock = s.acquire_writer(id);
    s.append_trial(lock, full_trial(0));
  }
  const auto before = file_bytes(path);
  ASSERT_FALSE(before.empty());
  ASSERT_FALSE(std::filesystem::exists(path + "-wal"));  // checkpointed on close
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    EXPECT_EQ(s.schema_version(), 2);
    ASSERT_EQ(s.trials(1).size(), 1u);
  }
  {
    const auto s = ex::Store::open(path, ex::StoreMode::read_only);
    EXPECT_EQ(s.schema_version(), 2);
    EXPECT_EQ(s.sessions().size(), 1u);
  }
  EXPECT_EQ(file_bytes(path), before);
}

// Version 1 → 2 (finger_traces): a version-1 file with a stored trial is
// migrated on opening for writing, in one transaction; its trial reads back
// unchanged (no trace), a read-only opening refuses it untouched, and new
// trials then store their traces.
TEST(Store, MigratesVersionOneAddingFingerTraces) {
  TempDir dir("store");
  const auto path = dir.at("v1.db");
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    const auto id = new_session(s);
    auto lock = s.acquire_writer(id);
    auto t = full_trial(0);
    t.trace = {};
    s.append_trial(lock, t);
  }
  // The version-1 layout: migration 0 → 1 is what created every other table.
  RawDb(path).exec("DROP TABLE finger_traces; PRAGMA user_version = 1");
  const auto v1_bytes = file_bytes(path);
  {
    const auto msg = message_of<texel::FormatError>([&] { (void)ex::Store::open(path, ex::StoreMode::read_only); });
    EXPECT_NE(msg.find("older schema version 1"), std::string::npos) << msg;
  }
  EXPECT_EQ(file_bytes(path), v1_bytes);
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    EXPECT_EQ(s.schema_version(), 2);
    const auto trials = s.trials(1);
    ASSERT_EQ(trials.size(), 1u);
    EXPECT_EQ(trials[0].question_json, full_trial(0).question_json);
    EXPECT_EQ(trials[0].trace.source, ex::TraceSource::none);
    EXPECT_TRUE(trials[0].trace.samples.empty());
    auto lock = s.acquire_writer(1);
    s.append_trial(lock, full_trial(1));
    s.append_trial(lock, full_trial(2));
  }
  RawDb raw(path);
  EXPECT_EQ(raw.one("PRAGMA user_version"), "2");
  EXPECT_EQ(raw.one("SELECT COUNT(*) FROM finger_traces"), "1");  // trial 2's; trial 1 has none
  const auto s = ex::Store::open(path, ex::StoreMode::read_only);
  EXPECT_EQ(s.trials(1)[2].trace.samples.size(), full_trial(2).trace.samples.size());
}

// A trace the store is asked to keep that the schema refuses (a mode that
// is none of the three) stores nothing of the trial.
TEST(Store, TraceRowIsPartOfTheTrialsTransaction) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  auto s = ex::Store::open(path, ex::StoreMode::read_write);
  const auto id = new_session(s);
  auto lock = s.acquire_writer(id);
  s.append_trial(lock, full_trial(0));
  RawDb(path).exec(
      "DROP TABLE finger_traces; CREATE TABLE finger_traces (session_id INTEGER, trial INTEGER CHECK (trial < 1), "
      "source TEXT, mode TEXT, samples INTEGER, trace TEXT)");
  auto t1 = full_trial(1);
  t1.trace = full_trial(0).trace;
  EXPECT_THROW(s.append_trial(lock, t1), texel::Error);  // trial 1's trace row is refused, so trial 1 is not stored
  EXPECT_EQ(s.trials(id).size(), 1u);
}

TEST(Store, RefusesFutureVersionAndForeignFiles) {
  TempDir dir("store");
  const auto future = dir.at("future.db");
  {
    { auto s = ex::Store::open(future, ex::StoreMode::read_write); }
    RawDb(future).exec("PRAGMA user_version = 3");
  }
  const auto future_bytes = file_bytes(future);
  for (auto mode : {ex::StoreMode::read_write, ex::StoreMode::read_only}) {
    const auto msg = message_of<texel::FormatError>([&] { (void)ex::Store::open(future, mode); });
    EXPECT_NE(msg.find("schema version 3, newer than this build's 2"), std::string::npos) << msg;
    EXPECT_NE(msg.find(future), std::string::npos) << msg;
  }
  EXPECT_EQ(file_bytes(future), future_bytes);

  const auto foreign = dir.at("foreign.db");
  { RawDb(foreign).exec("CREATE TABLE notes(x); INSERT INTO notes VALUES (1)"); }
  const auto foreign_bytes = file_bytes(foreign);
  const auto msg = message_of<texel::FormatError>([&] { (void)ex::Store::open(foreign, ex::StoreMode::read_write); });
  EXPECT_NE(msg.find("is not a Texel experiment database"), std::string::npos) << msg;
  EXPECT_EQ(file_bytes(foreign), foreign_bytes);
}

TEST(Store, CorruptFileIsRefusedAndLeftByteIdentical) {
  TempDir dir("store");
  std::string garbage;
  for (int i = 0; i < 5000; ++i) garbage += static_cast<char>((i * 7919 + 13) % 256);
  const auto path = dir.write("garbage.db", garbage);
  for (auto mode : {ex::StoreMode::read_write, ex::StoreMode::read_only}) {
    const auto msg = message_of<texel::FormatError>([&] { (void)ex::Store::open(path, mode); });
    EXPECT_EQ(msg, path + " is not a Texel experiment database (file is not a database)");
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  EXPECT_EQ(file_bytes(path), garbage);
  EXPECT_EQ(dir.listing(), std::set<std::string>{"garbage.db"});
}

TEST(Store, MissingFileReadOnlyIsAnErrorAndNothingIsCreated) {
  TempDir dir("store");
  const auto path = dir.at("none.db");
  const auto msg = message_of<texel::IoError>([&] { (void)ex::Store::open(path, ex::StoreMode::read_only); });
  EXPECT_NE(msg.find(path + " does not exist"), std::string::npos) << msg;
  EXPECT_TRUE(dir.listing().empty());
  EXPECT_THROW((void)ex::Store::open(dir.at("no/such/dir/x.db"), ex::StoreMode::read_write), texel::IoError);
}

TEST(Store, ReadOnlyModeNeverWrites) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    (void)new_session(s);
  }
  const auto before = file_bytes(path);
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_only);
    EXPECT_THROW((void)s.acquire_writer(1), texel::InvalidArgument);
    const auto msg = message_of<texel::IoError>([&] { (void)new_session(s, "S02"); });
    EXPECT_NE(msg.find("read-only"), std::string::npos) << msg;
    EXPECT_EQ(s.participants(), std::vector<std::string>{"S01"});
  }
  EXPECT_EQ(file_bytes(path), before);
}

// Issue #25: status, export and analyze open read-only and must leave no
// -wal/-shm beside the database, while reading a running study stays safe.
TEST(Store, ReaderLeavesNoWalOrShmFiles) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    auto lock = s.acquire_writer(new_session(s));
    s.append_trial(lock, full_trial(0));
  }
  ASSERT_FALSE(std::filesystem::exists(path + "-wal"));
  const auto before = file_bytes(path);
  {
    const auto s = ex::Store::open(path, ex::StoreMode::read_only);
    EXPECT_EQ(s.rows().size(), 1u);
    EXPECT_EQ(s.trials(1).size(), 1u);
  }
  EXPECT_FALSE(std::filesystem::exists(path + "-wal"));
  EXPECT_FALSE(std::filesystem::exists(path + "-shm"));
  EXPECT_EQ(file_bytes(path), before);
}

TEST(Store, AnSqliteFileIsNoStation) {
  TempDir dir("store");
  auto s = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  EXPECT_FALSE(s.is_station());
  EXPECT_FALSE(ex::is_postgres(dir.at("exp.db")));
  EXPECT_EQ(ex::stations_json(s), R"({"multi_station":false,"this_station":null,"server_error":"","stations":[]})");
  EXPECT_THROW((void)s.shipping(), texel::InvalidArgument);
}

TEST(Store, ReaderBesideARunningWriterSeesItsCommitsAndLeavesItsFiles) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  auto w = ex::Store::open(path, ex::StoreMode::read_write);
  auto lock = w.acquire_writer(new_session(w));
  w.append_trial(lock, full_trial(0));
  {
    // The writer's -wal/-shm exist: the reader opens read-only, as before.
    const auto r = ex::Store::open(path, ex::StoreMode::read_only);
    EXPECT_EQ(r.rows().size(), 1u);
    w.append_trial(lock, full_trial(1));
    EXPECT_EQ(r.rows().size(), 2u);
  }
  EXPECT_TRUE(std::filesystem::exists(path + "-wal"));  // still the writer's
  w.append_trial(lock, full_trial(2));
  // A reader that opens first (no files yet) and a writer that comes later:
  // the reader sees the writer's commits and the last to close cleans up.
  w = ex::Store::open(dir.at("other.db"), ex::StoreMode::read_write);  // closes the writer of exp.db
  lock = w.acquire_writer(new_session(w));
  EXPECT_FALSE(std::filesystem::exists(path + "-wal"));
  auto r = ex::Store::open(path, ex::StoreMode::read_only);
  {
    auto w2 = ex::Store::open(path, ex::StoreMode::read_write);
    auto lock2 = w2.acquire_writer(1);
    w2.append_trial(lock2, full_trial(3));
    EXPECT_EQ(r.rows().size(), 4u);
  }
  EXPECT_EQ(r.rows().size(), 4u);
  r = ex::Store::open(dir.at("other.db"), ex::StoreMode::read_only);
  EXPECT_FALSE(std::filesystem::exists(path + "-wal"));
  EXPECT_FALSE(std::filesystem::exists(path + "-shm"));
  EXPECT_EQ(ex::Store::open(path, ex::StoreMode::read_only).rows().size(), 4u);
}

TEST(Store, WriteProtectedFileOpenedForWritingIsRefused) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    (void)new_session(s);
  }
  const auto before = file_bytes(path);
  ::chmod(path.c_str(), 0444);
  const std::string want = path + " is read-only (no write permission); nothing was stored";
  if (::access(path.c_str(), W_OK) == 0) {
    // Root ignores the mode bits: check from a child that drops to nobody.
    if (::geteuid() != 0) {
      ::chmod(path.c_str(), 0644);
      GTEST_SKIP() << "this user can write a 0444 file (CAP_DAC_OVERRIDE) and is not root, so cannot drop to nobody; "
                      "read-only semantics are covered by ReadOnlyModeNeverWrites";
    }
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      int code = 0;
      if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(3);
      try {
        (void)ex::Store::open(path, ex::StoreMode::read_write);
        code = 1;
      } catch (const texel::IoError& e) {
        code = e.what() == want ? 0 : 2;
      } catch (...) {
        code = 2;
      }
      ::_exit(code);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "1: opened for writing, 2: wrong error, 3: could not drop to nobody";
    EXPECT_EQ(file_bytes(path), before);
    ::chmod(path.c_str(), 0644);
    return;
  }
  const auto msg = message_of<texel::IoError>([&] { (void)ex::Store::open(path, ex::StoreMode::read_write); });
  EXPECT_EQ(msg, want);
  {
    const auto s = ex::Store::open(path, ex::StoreMode::read_only);  // reading still works
    EXPECT_EQ(s.sessions().size(), 1u);
  }
  EXPECT_EQ(file_bytes(path), before);
  ::chmod(path.c_str(), 0644);
}

TEST(Store, SessionsAndParticipants) {
  TempDir dir("store");
  auto s = ex::Store::open(dir.at("exp.db"), ex::StoreMode::read_write);
  const auto a = new_session(s, "S02");
  const auto b = s.create_session("S01", "coarse", "coarse-features", "{}", 7, "psychometric:threshold=0.3", -1);
  const auto c = new_session(s, "S02");
  EXPECT_EQ(s.participants(), (std::vector<std::string>{"S01", "S02"}));
  ASSERT_EQ(s.sessions().size(), 3u);
  const auto info = s.session(b);
  EXPECT_EQ(info.participant, "S01");
  EXPECT_EQ(info.protocol, "coarse");
  EXPECT_EQ(info.study, "coarse-features");
  EXPECT_EQ(info.protocol_json, "{}");
  EXPECT_EQ(info.seed, 7u);
  EXPECT_EQ(info.simulate, "psychometric:threshold=0.3");
  EXPECT_EQ(info.status, "running");
  EXPECT_EQ(info.trials_done, 0);
  EXPECT_EQ(info.trials_planned, -1);
  EXPECT_EQ(info.created_at.size(), 24u) << info.created_at;  // 2026-11-23T10:00:00.000Z
  EXPECT_EQ(info.created_at.back(), 'Z');
  EXPECT_EQ(s.session(a).seed, 18446744073709551615ull);          // the full uint64 range survives
  EXPECT_EQ(s.unfinished_session("S02", "texel-length")->id, c);  // the newest
  EXPECT_FALSE(s.unfinished_session("S03", "texel-length"));
  {
    auto lock = s.acquire_writer(c);
    s.finish_session(lock);
    EXPECT_THROW(s.append_trial(lock, full_trial(0)), texel::InvalidArgument);
  }
  EXPECT_EQ(s.session(c).status, "finished");
  EXPECT_EQ(s.unfinished_session("S02", "texel-length")->id, a);
  EXPECT_THROW((void)s.session(99), texel::InvalidArgument);

  for (const std::string& bad : std::vector<std::string>{"", "Jane Doe", "a/b", std::string(33, 'x'), "émile"}) {
    const auto msg = message_of<texel::InvalidArgument>([&] { (void)new_session(s, bad); });
    EXPECT_NE(msg.find("participant code"), std::string::npos) << bad << ": " << msg;
  }
  EXPECT_NO_THROW((void)new_session(s, std::string(32, 'x') + ""));
  EXPECT_EQ(s.participants().size(), 3u);
}

TEST(Store, TrialsRoundTripWithEventsAndEveryRowField) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    (void)new_session(s, "S09");
    const auto id = new_session(s, "S01");
    auto lock = s.acquire_writer(id);
    for (int i = 0; i < 3; ++i) s.append_trial(lock, full_trial(i));
    auto t3 = full_trial(3);
    t3.events.clear();
    t3.row = ex::TrialRow{};  // every optional field missing
    s.append_trial(lock, t3);
  }
  const auto s = ex::Store::open(path, ex::StoreMode::read_only);
  const auto trials = s.trials(2);
  ASSERT_EQ(trials.size(), 4u);
  EXPECT_EQ(s.session(2).trials_done, 4);
  for (int i = 0; i < 3; ++i) {
    const auto want = full_trial(i);
    const auto& got = trials[static_cast<std::size_t>(i)];
    EXPECT_EQ(got.trial, i);
    EXPECT_EQ(got.question_json, want.question_json);
    EXPECT_EQ(got.response_json, want.response_json);
    EXPECT_EQ(got.state_json, want.state_json);
    auto want_row = want.row;
    want_row.session_id = 2;
    TEXEL_EXPECT_ROW_EQ(got.row, want_row);
    // The finger trace, sample for sample (µs and nm resolution).
    EXPECT_EQ(got.trace.source, want.trace.source);
    EXPECT_EQ(got.trace.mode, want.trace.mode);
    ASSERT_EQ(got.trace.samples.size(), want.trace.samples.size());
    for (std::size_t k = 0; k < want.trace.samples.size(); ++k) {
      EXPECT_NEAR(got.trace.samples[k].t_s, want.trace.samples[k].t_s, 5e-7);
      EXPECT_NEAR(got.trace.samples[k].x_mm, want.trace.samples[k].x_mm, 5e-7);
      EXPECT_EQ(got.trace.samples[k].touch, want.trace.samples[k].touch);
    }
    ASSERT_EQ(got.events.size(), want.events.size());
    for (std::size_t e = 0; e < want.events.size(); ++e) {
      EXPECT_EQ(got.events[e].t_s, want.events[e].t_s);
      EXPECT_EQ(got.events[e].kind, want.events[e].kind);
      EXPECT_EQ(got.events[e].detail, want.events[e].detail);
      EXPECT_EQ(got.events[e].at, want.events[e].at);
    }
  }
  // Who-and-where come from the session, whatever the caller put in the row.
  ex::TrialRow blank;
  blank.participant = "S01";
  blank.session_id = 2;
  blank.protocol = blank.study = "texel-length";
  blank.trial = 3;
  TEXEL_EXPECT_ROW_EQ(trials[3].row, blank);
  EXPECT_TRUE(trials[3].events.empty());

  const auto rows = s.rows();
  ASSERT_EQ(rows.size(), 4u);
  TEXEL_EXPECT_ROW_EQ(rows[3], blank);
  EXPECT_EQ(s.rows(2).size(), 4u);
  EXPECT_TRUE(s.rows(1).empty());
  EXPECT_TRUE(s.trials(1).empty());
}

TEST(Store, DuplicateAndGapIndicesAreRefusedWithNothingWritten) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  auto s = ex::Store::open(path, ex::StoreMode::read_write);
  const auto id = new_session(s);
  auto lock = s.acquire_writer(id);
  s.append_trial(lock, full_trial(0));
  s.append_trial(lock, full_trial(1));
  const auto updated = s.session(id).updated_at;
  for (int bad : {0, 1, 3, 7, -1}) {
    const auto msg = message_of<texel::InvalidArgument>([&] { s.append_trial(lock, full_trial(bad)); });
    EXPECT_NE(msg.find("the next must be trial 2; nothing was written"), std::string::npos) << msg;
  }
  const auto trials = s.trials(id);
  ASSERT_EQ(trials.size(), 2u);
  EXPECT_EQ(trials[1].events.size(), 3u);
  EXPECT_EQ(s.session(id).updated_at, updated);
  RawDb raw(path);
  EXPECT_EQ(raw.one("SELECT COUNT(*) FROM events"), "6");
  s.append_trial(lock, full_trial(2));  // the right index still works
  EXPECT_EQ(s.session(id).trials_done, 3);
}

TEST(Store, WriterLockInOneProcess) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  auto s = ex::Store::open(path, ex::StoreMode::read_write);
  const auto id = new_session(s);
  const auto other = new_session(s, "S02");
  {
    auto lock = s.acquire_writer(id);
    const auto msg = message_of<texel::IoError>([&] { (void)s.acquire_writer(id); });
    EXPECT_NE(msg.find("session 1 (S01, texel-length) is already being written by this process"), std::string::npos) << msg;
    // A second connection in the same process is refused the same way.
    auto s2 = ex::Store::open(path, ex::StoreMode::read_write);
    EXPECT_THROW((void)s2.acquire_writer(id), texel::IoError);
    // ... and cannot use a lock it does not own.
    EXPECT_THROW(s2.append_trial(lock, full_trial(0)), texel::InvalidArgument);
    // Another session is free.
    auto lock2 = s2.acquire_writer(other);
    s2.append_trial(lock2, full_trial(0));
    // The lock survives moves of itself and of the store.
    ex::WriterLock moved = std::move(lock);
    ex::Store s3 = std::move(s);
    s3.append_trial(moved, full_trial(0));
    EXPECT_THROW(s3.append_trial(lock, full_trial(1)), texel::InvalidArgument);  // NOLINT: moved-from on purpose
    s = std::move(s3);
  }
  // Released on destruction.
  RawDb raw(path);
  EXPECT_EQ(raw.one("SELECT COUNT(*) FROM writers"), "0");
  auto again = s.acquire_writer(id);
  s.append_trial(again, full_trial(1));
}

TEST(Store, LockOfADeadProcessIsTakenOver) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  auto s = ex::Store::open(path, ex::StoreMode::read_write);
  const auto id = new_session(s);
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  // A pid above the kernel's pid_max cannot be running; so is our own pid
  // with another start time (a recycled pid).
  {
    RawDb raw(path);
    raw.exec("INSERT INTO writers VALUES (1, 2147483000, 12345, '" + std::string(host) + "', '2026-01-01T00:00:00.000Z')");
  }
  {
    auto lock = s.acquire_writer(id);
    s.append_trial(lock, full_trial(0));
  }
  {
    RawDb raw(path);
    raw.exec("INSERT INTO writers VALUES (1, " + std::to_string(::getpid()) + ", 1, '" + std::string(host) +
             "', '2026-01-01T00:00:00.000Z')");
  }
  auto lock = s.acquire_writer(id);
  s.append_trial(lock, full_trial(1));
  // A lock from another machine cannot be checked, so it is refused.
  auto s2 = ex::Store::open(path, ex::StoreMode::read_write);
  const auto id2 = new_session(s2, "S02");
  {
    RawDb raw(path);
    raw.exec("INSERT INTO writers VALUES (" + std::to_string(id2) + ", 1, 1, 'lab-pc-7', '2026-01-01T00:00:00.000Z')");
  }
  const auto msg = message_of<texel::IoError>([&] { (void)s2.acquire_writer(id2); });
  EXPECT_NE(msg.find("on host lab-pc-7"), std::string::npos) << msg;
}

TEST(Store, SecondLiveProcessIsRefused) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  std::int64_t id = 0;
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    id = new_session(s);
  }
  // No connection is open across fork(): the child opens its own.
  int ready[2], release[2];
  ASSERT_EQ(::pipe(ready), 0);
  ASSERT_EQ(::pipe(release), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    int code = 0;
    try {
      auto s = ex::Store::open(path, ex::StoreMode::read_write);
      auto lock = s.acquire_writer(id);
      s.append_trial(lock, full_trial(0));
      char c = 1;
      if (::write(ready[1], &c, 1) != 1) code = 3;
      if (::read(release[0], &c, 1) != 1) code = 4;
    } catch (...) {
      code = 2;
    }
    ::_exit(code);  // lock and store released by their destructors above
  }
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  {
    auto s = ex::Store::open(path, ex::StoreMode::read_write);
    const auto msg = message_of<texel::IoError>([&] { (void)s.acquire_writer(id); });
    EXPECT_NE(msg.find("session 1 (S01, texel-length) is being written by process " + std::to_string(child) + " since "),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("; stop it first"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
    EXPECT_EQ(s.session(id).trials_done, 1);  // nothing touched
    // Readers are not blocked by the writer.
    EXPECT_EQ(ex::Store::open(path, ex::StoreMode::read_only).trials(id).size(), 1u);
  }
  ASSERT_EQ(::write(release[1], &c, 1), 1);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  auto s = ex::Store::open(path, ex::StoreMode::read_write);
  auto lock = s.acquire_writer(id);  // free again
  s.append_trial(lock, full_trial(1));
  for (int fd : {ready[0], ready[1], release[0], release[1]}) ::close(fd);
}

TEST(Store, LockedDatabaseGivesAOneLineErrorAfterTheBusyTimeout) {
  TempDir dir("store");
  const auto path = dir.at("exp.db");
  auto s = ex::Store::open(path, ex::StoreMode::read_write);
  RawDb raw(path);
  raw.exec("BEGIN IMMEDIATE; INSERT INTO participants VALUES ('X1', 'now')");
  const auto msg = message_of<texel::IoError>([&] { (void)new_session(s); });
  EXPECT_EQ(msg, path + " is locked by another process (waited 5 s): creating a session for S01 refused");
  raw.exec("ROLLBACK");
  EXPECT_TRUE(s.participants().empty());
  EXPECT_GT(new_session(s), 0);
}
