// What the paced benchmarks (texel_bench_player_paced,
// texel_bench_multichannel_paced) share: the processes they start and stop
// (jackd with its dummy driver, stress-ng), a JACK client opened on a loaded
// machine, the scheduling its process thread got, and block-time
// percentiles as % of the period.
#pragma once

#include <fcntl.h>
#include <jack/jack.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace texel::bench {

// ---------------------------------------------------------------- processes

struct Child {
  pid_t pid = -1;
  bool own_group = false;
};

/// args[0] from PATH, stdout and stderr to `log`; own_group: a process group
/// of its own, so that stop() ends its workers too (stress-ng).
inline Child spawn(const std::vector<std::string>& args, const std::string& log, bool own_group) {
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawnattr_t at;
  posix_spawnattr_init(&at);
  if (own_group) {
    posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&at, 0);
  }
  Child c;
  if (posix_spawnp(&c.pid, argv[0], &fa, &at, argv.data(), environ) != 0) c.pid = -1;
  c.own_group = own_group;
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&at);
  return c;
}

inline bool running(const Child& c) { return c.pid > 0 && ::waitpid(c.pid, nullptr, WNOHANG) == 0; }

/// SIGTERM (to the group it started, if any), SIGKILL after 5 s.
inline void stop(Child& c) {
  if (c.pid <= 0) return;
  ::kill(c.own_group ? -c.pid : c.pid, SIGTERM);
  for (int i = 0; i < 50 && ::waitpid(c.pid, nullptr, WNOHANG) == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  if (::waitpid(c.pid, nullptr, WNOHANG) == 0) {
    ::kill(c.own_group ? -c.pid : c.pid, SIGKILL);
    ::waitpid(c.pid, nullptr, 0);
  }
  c.pid = -1;
}

inline bool on_path(const char* tool) {
  const std::string cmd = std::string("command -v ") + tool + " >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

// -------------------------------------------------------------------- JACK

/// A jackd of our own (-n name) on the dummy driver at 48 kHz: real-time
/// (-R -P 80: its clients run just below the server, above anything else
/// here) where the machine allows, else without (-r), and `mode` says which.
struct JackServer {
  Child process;
  std::string name, log, mode;
  bool started() const { return running(process); }
};

inline JackServer start_jack(const std::string& prefix, std::size_t period, bool sync) {
  JackServer s;
  s.name = prefix + "-" + std::to_string(::getpid());
  s.log = "/tmp/" + s.name + "-jackd.log";
  const auto args = [&](std::vector<std::string> scheduling) {
    std::vector<std::string> a{"jackd", "-n", s.name};
    if (sync) a.emplace_back("-S");
    a.insert(a.end(), scheduling.begin(), scheduling.end());
    a.insert(a.end(), {"-d", "dummy", "-r", "48000", "-p", std::to_string(period)});
    return a;
  };
  const std::string sync_flag = sync ? " -S" : "";
  s.process = spawn(args({"-R", "-P", "80"}), s.log, false);
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  s.mode = "jackd" + sync_flag + " -R -P 80";
  if (!s.started()) {  // real-time refused: run without it and say so
    stop(s.process);
    s.process = spawn(args({"-r"}), s.log, false);
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    s.mode = "jackd" + sync_flag + " -r (no real-time)";
  }
  return s;
}

/// A client of `server`, never starting one: a loaded machine may take a
/// while to bring the server up, so this tries for up to 5 s (null after).
inline jack_client_t* open_client(const char* name, const std::string& server) {
  jack_status_t status{};
  jack_client_t* client = nullptr;
  for (int attempt = 0; attempt < 25 && !client; ++attempt) {
    if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(200));
    client = jack_client_open(name, static_cast<jack_options_t>(JackNoStartServer | JackServerName), &status, server.c_str());
  }
  return client;
}

/// The calling (process) thread's scheduling, once: real-time safe.
struct Scheduling {
  std::atomic<int> policy{-1}, priority{0};

  void note() {
    if (policy.load(std::memory_order_relaxed) >= 0) return;
    int pol = 0;
    sched_param sp{};
    pthread_getschedparam(pthread_self(), &pol, &sp);
    priority.store(sp.sched_priority, std::memory_order_relaxed);
    policy.store(pol, std::memory_order_relaxed);
  }

  std::string name() const {
    const int pol = policy.load();
    return pol == SCHED_FIFO ? "SCHED_FIFO " + std::to_string(priority.load())
           : pol == SCHED_RR ? "SCHED_RR " + std::to_string(priority.load())
           : pol < 0         ? "no callback"
                             : "SCHED_OTHER (JACK not real-time)";
  }
};

// -------------------------------------------------------------- statistics

struct Stats {
  double p50 = 0, p99 = 0, p999 = 0, max = 0;  // % of the period
};

/// Block times (s) as % of a period of `period_s`.
inline Stats percentiles(std::vector<double> v, double period_s) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    return 100.0 * v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))] / period_s;
  };
  s.p50 = at(0.5), s.p99 = at(0.99), s.p999 = at(0.999), s.max = 100.0 * v.back() / period_s;
  return s;
}

}  // namespace texel::bench
