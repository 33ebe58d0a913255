// texel_bench_store_pg: many stations, one PostgreSQL server (issue #27;
// docs/session-store.md "Many stations"). N station processes each store T
// trials in their own SQLite journal (synchronous=FULL, as a study does) as
// fast as they can while their shippers copy them to one local server. It
// reports
//   * trials per second: all N×T trials from the first local commit to the
//     last server commit;
//   * the time from a trial's local commit (its stored_at) to its server
//     commit (pg_xact_commit_timestamp of its row: the server runs with
//     track_commit_timestamp=on) — median, p99, max;
//   * the server's peak memory: the sum over its processes of RSS and of
//     PSS (shared pages split between the processes that map them), sampled
//     every 20 ms.
//
//   texel_bench_store_pg --env PG_ENV_FILE [--stations 50] [--trials 1000] [--json PATH]
//
// PG_ENV_FILE is written by scripts/pg-test-server.sh start (`make bench`
// starts and stops the server).
#include <libpq-fe.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "texel/experiment/store.hpp"

namespace ex = texel::experiment;

namespace {

std::map<std::string, std::string> read_env(const std::string& file) {
  std::map<std::string, std::string> env;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (const auto eq = line.find('='); eq != std::string::npos) env[line.substr(0, eq)] = line.substr(eq + 1);
  return env;
}

[[noreturn]] void die(const std::string& why) {
  std::cerr << "texel_bench_store_pg: " << why << "\n";
  std::exit(2);
}

std::string admin_sql(const std::map<std::string, std::string>& env, const std::string& db, const std::string& sql) {
  const std::string ci =
      "host=" + env.at("TEXEL_PG_SOCKET") + " port=" + env.at("TEXEL_PG_PORT") + " user=texel_admin dbname=" + db;
  PGconn* c = PQconnectdb(ci.c_str());
  if (PQstatus(c) != CONNECTION_OK) die(PQerrorMessage(c));
  PGresult* r = PQexec(c, sql.c_str());
  const auto st = PQresultStatus(r);
  if (st != PGRES_COMMAND_OK && st != PGRES_TUPLES_OK) die(sql + ": " + PQresultErrorMessage(r));
  std::string out = st == PGRES_TUPLES_OK && PQntuples(r) > 0 ? PQgetvalue(r, 0, 0) : "";
  for (int i = 1; st == PGRES_TUPLES_OK && i < PQnfields(r); ++i) out += std::string(" ") + PQgetvalue(r, 0, i);
  PQclear(r);
  PQfinish(c);
  return out;
}

// Sum of RSS and PSS (kB) of the server: its postmaster and the processes
// it started (backends, checkpointer, …), not any other server's.
std::pair<long, long> server_memory_kb(long postmaster) {
  long rss = 0, pss = 0;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string pid = e.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (std::stol(pid) != postmaster) {
      std::ifstream status(e.path() / "status");
      std::string line;
      long ppid = -1;
      while (std::getline(status, line))
        if (line.rfind("PPid:", 0) == 0) ppid = std::atol(line.c_str() + 5);
      if (ppid != postmaster) continue;
    }
    std::ifstream sm(e.path() / "smaps_rollup");
    std::string line;
    while (std::getline(sm, line)) {
      if (line.rfind("Rss:", 0) == 0) rss += std::atol(line.c_str() + 4);
      if (line.rfind("Pss:", 0) == 0) pss += std::atol(line.c_str() + 4);
    }
  }
  return {rss, pss};
}

// One station: T trials as fast as the journal commits them, then waits
// for its shipper to have everything on the server.
int station(const std::string& uri, const std::string& journal, int index, int trials) {
  try {
    ex::Store s = ex::Store::open(uri, ex::StoreMode::read_write, ex::StoreOptions{journal});
    char code[16];
    std::snprintf(code, sizeof code, "B%03d", index);
    const auto id = s.create_session(code, "bench", "working-memory", R"({"name":"bench"})", 1000u + static_cast<unsigned>(index),
                                     "default", trials);
    auto lock = s.acquire_writer(id);
    for (int i = 0; i < trials; ++i) {
      ex::StoredTrial t;
      t.trial = i;
      t.question_json = R"({"question":{"trial":)" + std::to_string(i) + R"(,"stimuli":[{"document":"texel 1","seed":)" +
                        std::to_string(i * 7919) + "}]}}";
      t.response_json = R"({"choice":")" + std::to_string(i % 3) + R"("})";
      t.state_json = R"({"intensity":)" + std::to_string(0.5 + 0.01 * i) + "}";
      t.row.block = "test";
      t.row.task = "oddity";
      t.row.response = std::to_string(i % 3);
      t.row.rt_ms = 800 + i % 400;
      t.events = {{0.0, "show", "A", ""}, {0.4, "select", "B", ""}, {0.8, "answer", "B", ""}};
      s.append_trial(lock, t);
    }
    s.finish_session(lock);
    return s.sync(300) ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "station " << index << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string env_file, json_path;
  int stations = 50, trials = 1000;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) die(a + " needs a value");
      return argv[++i];
    };
    if (a == "--env")
      env_file = next();
    else if (a == "--stations")
      stations = std::atoi(next().c_str());
    else if (a == "--trials")
      trials = std::atoi(next().c_str());
    else if (a == "--json")
      json_path = next();
    else
      die("unknown argument " + a);
  }
  if (env_file.empty()) die("--env PG_ENV_FILE is required (scripts/pg-test-server.sh start)");
  if (stations < 1 || stations > 150 || trials < 1) die("--stations 1 … 150, --trials ≥ 1");
  const auto env = read_env(env_file);
  if (!env.count("TEXEL_PG_PORT")) die(env_file + " is not a server's connection file");
  if (admin_sql(env, "postgres", "SHOW track_commit_timestamp") != "on")
    die("the server needs track_commit_timestamp=on (TEXEL_PG_EXTRA_OPTS, see make bench)");

  const std::string db = "bench";
  admin_sql(env, "postgres", "DROP DATABASE IF EXISTS " + db + " WITH (FORCE)");
  admin_sql(env, "postgres", "CREATE DATABASE " + db);
  std::vector<std::string> names;
  for (int i = 0; i < stations; ++i) {
    char n[16];
    std::snprintf(n, sizeof n, "bench%03d", i);
    names.emplace_back(n);
  }
  (void)ex::init_postgres(
      "postgresql://texel_admin@/" + db + "?host=" + env.at("TEXEL_PG_SOCKET") + "&port=" + env.at("TEXEL_PG_PORT"), names, {});
  const auto work = std::filesystem::temp_directory_path() / ("texel-bench-store-" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  std::string sql, pgpass;
  for (const auto& n : names) {
    sql += "ALTER ROLE " + n + " PASSWORD 'pw-" + n + "';";
    pgpass += "127.0.0.1:" + env.at("TEXEL_PG_PORT") + ":" + db + ":" + n + ":pw-" + n + "\n";
  }
  admin_sql(env, db, sql);
  const std::string pgpass_path = (work / "pgpass").string();
  std::ofstream(pgpass_path) << pgpass;
  ::chmod(pgpass_path.c_str(), 0600);
  ::setenv("PGPASSFILE", pgpass_path.c_str(), 1);

  long postmaster = 0;
  {
    std::ifstream pidfile(env.at("TEXEL_PG_DIR") + "/data/postmaster.pid");
    pidfile >> postmaster;
    if (postmaster <= 0) die("cannot read the server's postmaster.pid");
  }
  std::atomic<bool> sampling{true};
  long peak_rss = 0, peak_pss = 0;
  std::thread sampler([&] {
    while (sampling) {
      const auto [rss, pss] = server_memory_kb(postmaster);
      peak_rss = std::max(peak_rss, rss);
      peak_pss = std::max(peak_pss, pss);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  const auto idle = server_memory_kb(postmaster);

  const auto t0 = std::chrono::steady_clock::now();
  std::vector<pid_t> kids;
  for (int i = 0; i < stations; ++i) {
    const pid_t pid = ::fork();
    if (pid < 0) die("fork failed");
    if (pid == 0) {
      const std::string uri =
          "postgresql://" + names[static_cast<std::size_t>(i)] + "@127.0.0.1:" + env.at("TEXEL_PG_PORT") + "/" + db;
      std::_Exit(station(uri, (work / (names[static_cast<std::size_t>(i)] + ".db")).string(), i, trials));
    }
    kids.push_back(pid);
  }
  int failed = 0;
  for (const pid_t k : kids) {
    int status = 0;
    ::waitpid(k, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) ++failed;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sampling = false;
  sampler.join();
  std::filesystem::remove_all(work);
  if (failed) die(std::to_string(failed) + " stations failed");

  // From the server: how many, and local commit → server commit per trial.
  const std::string q = admin_sql(
      env, db,
      "WITH d AS (SELECT extract(epoch FROM pg_xact_commit_timestamp(xmin) - stored_at::timestamptz) * 1000 AS ms, "
      "stored_at::timestamptz AS local, pg_xact_commit_timestamp(xmin) AS server FROM texel.trials) "
      "SELECT count(*), percentile_cont(0.5) WITHIN GROUP (ORDER BY ms), percentile_cont(0.99) WITHIN GROUP (ORDER BY ms), "
      "max(ms), extract(epoch FROM max(server) - min(local)) FROM d");
  long n = 0;
  double p50 = 0, p99 = 0, worst = 0, span_s = 0;
  if (std::sscanf(q.c_str(), "%ld %lf %lf %lf %lf", &n, &p50, &p99, &worst, &span_s) != 5) die("unexpected answer: " + q);
  const long expected = static_cast<long>(stations) * trials;
  const double rate = span_s > 0 ? static_cast<double>(n) / span_s : 0;
  std::printf("store on PostgreSQL: %d stations x %d trials = %ld trials on the server (expected %ld)\n", stations, trials, n,
              expected);
  std::printf("  throughput: %.0f trials/s (first local commit to last server commit, %.2f s; whole run %.2f s)\n", rate, span_s,
              wall_s);
  std::printf("  local commit -> server commit: median %.1f ms, p99 %.1f ms, max %.1f ms\n", p50, p99, worst);
  std::printf(
      "  server memory (postgres processes): peak sum RSS %.1f MiB, peak sum PSS %.1f MiB (idle before: RSS %.1f, PSS %.1f "
      "MiB)\n",
      static_cast<double>(peak_rss) / 1024, static_cast<double>(peak_pss) / 1024, static_cast<double>(idle.first) / 1024,
      static_cast<double>(idle.second) / 1024);
  if (!json_path.empty()) {
    std::ofstream out(json_path);
    out << "{\"stations\":" << stations << ",\"trials_per_station\":" << trials << ",\"trials_on_server\":" << n
        << ",\"trials_per_s\":" << rate << ",\"span_s\":" << span_s << ",\"wall_s\":" << wall_s << ",\"lag_ms_p50\":" << p50
        << ",\"lag_ms_p99\":" << p99 << ",\"lag_ms_max\":" << worst
        << ",\"server_peak_rss_mib\":" << static_cast<double>(peak_rss) / 1024
        << ",\"server_peak_pss_mib\":" << static_cast<double>(peak_pss) / 1024 << "}\n";
  }
  return n == expected ? 0 : 1;
}
