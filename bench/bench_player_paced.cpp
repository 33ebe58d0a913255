// texel_bench_player_paced: the players on a paced audio device — a JACK
// server with its dummy driver (started and stopped here), 48 kHz, 16- and
// 64-frame periods, the 1-D Player and the 2-D Player2D, idle and with every
// core busy (stress-ng, started and stopped here). Reports per run:
//   - block times (process() alone) p50 / p99 / p99.9 / max as % of the period;
//   - end-to-end latency from a finger sample to the drive value that contains
//     it: from the sample's push to the time JACK's driver plays the first
//     output sample computed from it: the start of the callback that computes
//     it (standing for its cycle's start) + the port's playback latency + the
//     sample's offset in the block, all on CLOCK_MONOTONIC. Samples arrive from a 1 kHz sensor thread with
//     no prediction and no extrapolation, so "contains" is exact: the output
//     position equals the pushed position from that sample on;
//   - allocations inside process() (the tests' counting allocator): must be 0;
//   - xruns JACK reported, and the scheduling the process thread had;
// then the null backend (texel play --backend null) under the same loads:
// underruns in 5 s, worst block, and the scheduling its paced thread got.
//
// The floor: in every JACK run (same server, same period, same load, same
// 1 kHz sensor thread) a do-nothing client goes first — its process callback
// writes zeros and shows the newest pushed marker, nothing else — and the
// players' p99.9 block time, xruns and latency are reported beside it as
// ratios. What the floor shows is the machine's (scheduler, timer, VM) tail:
// a player cannot beat it, and a player within it costs nothing that shows.
//
// Usage: texel_bench_player_paced [--seconds S] [--json FILE] [--costs] [--sync]
// (--costs: only the block costs without JACK, warm and with the caches
// evicted between blocks, which tell whether the tail is the work's own;
// --sync: jackd in synchronous mode, -S)
// Needs jackd (Debian jackd2) and stress-ng on PATH; a missing tool is
// reported and its part skipped (exit 0), never faked.
#include <fcntl.h>
#include <jack/jack.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "../tests/support/alloc_counter.hpp"
#include "jack_bench.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/sinks.hpp"

using namespace texel;
namespace alloc = texel::test_support::alloc;
using namespace texel::bench;

namespace {

constexpr double rate = 48000.0;
constexpr double step_mm = 0.004;  // finger advance per sensor sample (4 mm/s … a marker, not a swipe)

// ------------------------------------------------------------------ one run

struct Result {
  std::string load, dim;
  std::size_t block = 0;
  std::size_t blocks = 0;
  Stats block_time;  // % of the period
  double lat_p50_ms = 0, lat_p99_ms = 0, lat_max_ms = 0;
  // What the largest latency is made of: push → start of the callback that
  // computed it, the sample's offset in its block, and the declared playback
  // latency; and the longest time between two callback starts (a driver
  // cycle that came late: the dummy driver's thread or the client woke late).
  double max_wait_ms = 0, max_offset_ms = 0, longest_gap_ms = 0;
  std::size_t latencies = 0;
  std::uint64_t allocations = 0;
  std::uint64_t xruns = 0;
  std::string scheduling;
  double playback_latency_frames = 0;
  double playback_latency_min_frames = 0;
};

struct Run {
  jack_client_t* client = nullptr;
  jack_port_t* port = nullptr;
  PlayerBase* player = nullptr;
  std::vector<double> block_s;
  std::atomic<std::size_t> blocks{0};
  std::vector<float> positions;
  std::vector<double> push_us;     // per marker k: CLOCK_MONOTONIC at push (µs)
  std::vector<double> latency_us;  // per marker k (0 = not yet played)
  std::vector<double> wait_us;     // per marker k: push → start of the callback that played it first
  std::vector<double> offset_us;   // per marker k: its offset in that block
  double last_cycle_us = 0, longest_gap_us = 0;
  std::atomic<std::size_t> pushed{0};
  long last_marker = -1;
  std::atomic<jack_nframes_t> playback_latency{0};
  std::atomic<std::uint64_t> xruns{0};
  Scheduling scheduling;
};

int on_xrun(void* arg) {
  static_cast<Run*>(arg)->xruns.fetch_add(1, std::memory_order_relaxed);
  return 0;
}

// JACK's process thread: real-time safe (process(), clock reads, stores into
// arrays sized before activation).
int on_process(jack_nframes_t n, void* arg) {
  auto& r = *static_cast<Run*>(arg);
  auto* out = static_cast<float*>(jack_port_get_buffer(r.port, n));
  r.scheduling.note();
  const std::size_t frames = std::min<std::size_t>(n, r.positions.size());
  timespec a{}, b{};
  ::clock_gettime(CLOCK_MONOTONIC, &a);
  const double cycle_us = 1e6 * static_cast<double>(a.tv_sec) + 1e-3 * static_cast<double>(a.tv_nsec);
  if (r.last_cycle_us > 0) r.longest_gap_us = std::max(r.longest_gap_us, cycle_us - r.last_cycle_us);
  r.last_cycle_us = cycle_us;
  alloc::counting = true;
  r.player->process(std::span(out, frames), std::span(r.positions.data(), frames));
  alloc::counting = false;
  ::clock_gettime(CLOCK_MONOTONIC, &b);
  const std::size_t k = r.blocks.load(std::memory_order_relaxed);
  if (k < r.block_s.size()) {
    r.block_s[k] = static_cast<double>(b.tv_sec - a.tv_sec) + 1e-9 * static_cast<double>(b.tv_nsec - a.tv_nsec);
    r.blocks.store(k + 1, std::memory_order_relaxed);
  }
  // Which markers (pushed positions) appear first in this block, and when
  // the driver plays them.
  const double first_us = cycle_us + 1e6 * static_cast<double>(r.playback_latency.load(std::memory_order_relaxed)) / rate;
  for (std::size_t i = 0; i < frames; ++i) {
    // The newest marker this position has reached (a position between two
    // markers has reached only the earlier one).
    const auto m = static_cast<long>(std::floor((static_cast<double>(r.positions[i]) - 1.0) / step_mm + 1e-3));
    if (m <= r.last_marker || m < 0 || static_cast<std::size_t>(m) >= r.latency_us.size()) continue;
    const double played = first_us + 1e6 * static_cast<double>(i) / rate;
    for (long q = r.last_marker + 1; q <= m; ++q) {
      const auto mk = static_cast<std::size_t>(q);
      r.latency_us[mk] = played - r.push_us[mk];
      r.wait_us[mk] = cycle_us - r.push_us[mk];
      r.offset_us[mk] = 1e6 * static_cast<double>(i) / rate;
    }
    r.last_marker = m;
  }
  return 0;
}

template <class PushFn>
Result run_client(const std::string& server, std::size_t block, double seconds, PlayerBase& player, PushFn push) {
  Result res;
  res.block = block;
  Run r;
  r.player = &player;
  const auto max_blocks = static_cast<std::size_t>(seconds * rate / static_cast<double>(block)) + 1000;
  r.block_s.assign(max_blocks, 0.0);
  r.positions.assign(8192, 0.0f);
  const auto markers = static_cast<std::size_t>(seconds * 1000.0) + 100;
  r.push_us.assign(markers, 0.0);
  r.latency_us.assign(markers, 0.0);
  r.wait_us.assign(markers, 0.0);
  r.offset_us.assign(markers, 0.0);
  r.client = open_client("texel-bench", server);
  if (!r.client) {
    res.scheduling = "JACK client failed to open";
    return res;
  }
  r.port = jack_port_register(r.client, "out", JACK_DEFAULT_AUDIO_TYPE, JackPortIsOutput, 0);
  jack_set_process_callback(r.client, on_process, &r);
  jack_set_xrun_callback(r.client, on_xrun, &r);
  // Warm the pages the callback touches (the tests' mlockall-less stand-in).
  ::mlockall(MCL_CURRENT);
  jack_activate(r.client);
  const std::string me = std::string(jack_get_client_name(r.client)) + ":out";
  jack_connect(r.client, me.c_str(), "system:playback_1");
  jack_recompute_total_latencies(r.client);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  jack_latency_range_t range{};
  jack_port_get_latency_range(r.port, JackPlaybackLatency, &range);
  r.playback_latency = range.max;
  res.playback_latency_frames = range.max;
  res.playback_latency_min_frames = range.min;
  const std::size_t warm_blocks = r.blocks.load();
  const std::uint64_t xruns0 = r.xruns.load();
  alloc::counted_allocations = 0;

  // The finger: a 1 kHz sensor thread on absolute deadlines, each sample at
  // the player's current time (live, no queued future).
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  for (std::size_t k = 0; k + 1 < markers && static_cast<double>(k) < seconds * 1000.0; ++k) {
    t.tv_nsec += 1000000;
    if (t.tv_nsec >= 1000000000) t.tv_nsec -= 1000000000, ++t.tv_sec;
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr) == EINTR) {
    }
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);
    r.push_us[k] = 1e6 * static_cast<double>(now.tv_sec) + 1e-3 * static_cast<double>(now.tv_nsec);
    push(player.time_s(), 1.0 + step_mm * static_cast<double>(k));
    r.pushed = k + 1;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  jack_deactivate(r.client);
  jack_client_close(r.client);

  const std::size_t done = r.blocks.load();
  std::vector<double> bs(r.block_s.begin() + static_cast<std::ptrdiff_t>(warm_blocks),
                         r.block_s.begin() + static_cast<std::ptrdiff_t>(done));
  res.blocks = bs.size();
  res.block_time = percentiles(bs, static_cast<double>(block) / rate);
  std::vector<double> lat;
  std::size_t worst = 0;
  for (std::size_t k = 0; k < r.pushed; ++k)
    if (r.latency_us[k] != 0.0) {
      lat.push_back(r.latency_us[k] / 1000.0);
      if (r.latency_us[k] > r.latency_us[worst]) worst = k;
    }
  res.max_wait_ms = r.wait_us[worst] / 1000.0;
  res.max_offset_ms = r.offset_us[worst] / 1000.0;
  res.longest_gap_ms = r.longest_gap_us / 1000.0;
  res.latencies = lat.size();
  if (!lat.empty()) {
    std::sort(lat.begin(), lat.end());
    res.lat_p50_ms = lat[lat.size() / 2];
    res.lat_p99_ms = lat[std::min(lat.size() - 1, lat.size() * 99 / 100)];
    res.lat_max_ms = lat.back();
  }
  res.allocations = alloc::counted_allocations.load();
  res.xruns = r.xruns.load() - xruns0;
  res.scheduling = r.scheduling.name();
  return res;
}

/// The floor (see the banner): a client that does nothing but write zeros
/// and show the newest marker (so the latency is measured the same way: the
/// marker shows at the start of the first callback after its push, the least
/// any client can do). Real-time safe: two fills and an atomic load.
class FloorClient final : public PlayerBase {
 public:
  FloorClient() : PlayerBase(rate) {}
  ~FloorClient() override { stop_driver(); }
  void push(double x_mm) { newest_.store(static_cast<float>(x_mm), std::memory_order_relaxed); }
  BlockInfo process(std::span<float> out, std::span<float> position_mm) noexcept override {
    std::fill(out.begin(), out.end(), 0.0f);
    if (position_mm.size() >= out.size()) std::fill_n(position_mm.begin(), out.size(), newest_.load(std::memory_order_relaxed));
    frames_ += out.size();
    publish_samples(frames_);
    return {};
  }
  std::size_t collect() override { return 0; }

 private:
  std::atomic<float> newest_{0.0f};
  std::uint64_t frames_ = 0;
};

PlayerConfig live_config() {
  PlayerConfig c;
  c.rate_hz = rate;
  c.mode = OutputMode::vibration;
  c.prediction_s = 0.0;
  c.extrapolate_s = 0.0;  // the output position is the newest sample's: "contains" is exact
  return c;
}

std::unique_ptr<const PlayerMap> map_1d() {
  std::vector<float> v(19200);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(0.5 + 0.5 * std::sin(0.37 * static_cast<double>(i)));
  return std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, std::move(v));
}

std::unique_ptr<const PlayerMap2D> map_2d() {
  Raster2D disc;
  disc.width = disc.height = 512;
  disc.pitch = Millimetres(0.25);
  disc.values.resize(512 * 512);
  for (int j = 0; j < 512; ++j)
    for (int i = 0; i < 512; ++i)
      disc.values[static_cast<std::size_t>(j * 512 + i)] = std::hypot(i - 256, j - 256) < 150 ? 1.0f : 0.3f;
  TexelSpec spec;
  spec.coarse_strength = 0.5;
  return PlayerMap2D::path_indexed(spec, Sampling{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, {}}, disc, std::nullopt);
}

// ------------------------------------------------------- where the tail is

/// process() of 16- or 64-frame blocks in a loop on this thread, no JACK:
/// the finger advancing as in the paced runs (one sample per 48 frames). Per
/// block: warm (back to back) and cold (an 8 MB buffer written between
/// blocks, as other processes do between two periods).
/// Returns {p50 warm, p99.9 warm, p50 cold, p99.9 cold} in µs.
std::array<double, 4> block_costs(PlayerBase& player, const std::function<void(double, double)>& push, std::size_t block) {
  constexpr std::size_t blocks = 2000;
  std::vector<float> out(block), pos(block);
  std::vector<double> warm, cold;
  warm.reserve(blocks);
  cold.reserve(blocks);
  std::vector<unsigned char> evict(std::size_t{8} << 20);  // over a core's L2, part of the shared L3
  std::size_t frames = 0, k = 0;
  for (std::size_t b = 0; b < 2 * blocks; ++b) {
    const bool is_cold = b >= blocks;
    if (is_cold)
      for (std::size_t i = 0; i < evict.size(); i += 64) evict[i] = static_cast<unsigned char>(evict[i] + 1);
    while (frames >= 48 * k) push(static_cast<double>(48 * k) / rate, 1.0 + step_mm * static_cast<double>(k)), ++k;
    timespec a{}, c{};
    ::clock_gettime(CLOCK_MONOTONIC, &a);
    player.process(std::span(out), std::span(pos));
    ::clock_gettime(CLOCK_MONOTONIC, &c);
    frames += block;
    const double us = 1e6 * static_cast<double>(c.tv_sec - a.tv_sec) + 1e-3 * static_cast<double>(c.tv_nsec - a.tv_nsec);
    (is_cold ? cold : warm).push_back(us);
  }
  const auto q = [](std::vector<double>& v, double f) {
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(f * static_cast<double>(v.size())))];
  };
  return {q(warm, 0.5), q(warm, 0.999), q(cold, 0.5), q(cold, 0.999)};
}

void print_block_costs() {
  std::printf(
      "block cost without JACK (µs; period 333 µs at 16 frames, 1333 µs at 64): warm p50 / p99.9, caches evicted p50 / p99.9\n");
  for (std::size_t block : {std::size_t{16}, std::size_t{64}}) {
    Player p1(live_config(), map_1d());
    const auto one = block_costs(
        p1,
        [&](double t, double x) {
          p1.push({t, x, true});
        },
        block);
    Player2D p2(live_config(), map_2d());
    const auto two = block_costs(
        p2,
        [&](double t, double x) {
          p2.push({t, x, 0.3 * x, true});
        },
        block);
    std::printf("  %2zu frames: 1-D %.2f / %.2f, cold %.2f / %.2f; 2-D %.2f / %.2f, cold %.2f / %.2f\n", block, one[0], one[1],
                one[2], one[3], two[0], two[1], two[2], two[3]);
  }
}

/// jackd's synchronous mode (-S, `--sync`): the server waits for its clients
/// within the cycle, so their output goes out with that cycle, one period
/// sooner than in the default asynchronous mode, at the risk of an xrun when
/// a client is late. Which one ran is printed with every result.
bool jack_sync = false;

std::vector<Result> jack_runs(const std::string& load, std::size_t block, double seconds) {
  std::vector<Result> out;
  JackServer jackd = start_jack("texel-bench", block, jack_sync);
  if (!jackd.started()) {
    std::fprintf(stderr, "jackd did not start (see %s); JACK runs skipped\n", jackd.log.c_str());
    return out;
  }
  const std::string& server = jackd.name;
  const std::string& mode = jackd.mode;
  {
    FloorClient f;
    Result r = run_client(server, block, seconds, f, [&](double, double x) { f.push(x); });
    r.load = load, r.dim = "floor", r.scheduling += ", " + mode;
    out.push_back(r);
  }
  {
    Player p(live_config(), map_1d());
    Result r = run_client(server, block, seconds, p, [&](double t, double x) { p.push({t, x, true}); });
    r.load = load, r.dim = "1-D", r.scheduling += ", " + mode;
    out.push_back(r);
  }
  {
    Player2D p(live_config(), map_2d());
    Result r = run_client(server, block, seconds, p, [&](double t, double x) { p.push({t, x, 0.3 * x, true}); });
    r.load = load, r.dim = "2-D", r.scheduling += ", " + mode;
    out.push_back(r);
  }
  stop(jackd.process);
  return out;
}

struct NullResult {
  std::string load;
  std::uint64_t blocks = 0, underruns = 0;
  double worst_pct = 0;
  std::string scheduling;
};

NullResult null_run(const std::string& load) {
  NullResult n;
  n.load = load;
  Player p(live_config(), map_1d());
  auto backend = make_null_backend(rate, 64);
  backend->start(p);
  for (int k = 0; k < 5000; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    p.push({p.time_s(), 1.0 + 0.01 * k, true});
  }
  backend->stop();
  const BackendStats s = backend->stats();
  n.blocks = s.blocks, n.underruns = s.underruns, n.worst_pct = 100.0 * s.worst_block_s / (64.0 / rate);
  n.scheduling = backend->scheduling();
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  std::string json;
  bool costs_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json" && i + 1 < argc)
      json = argv[++i];
    else if (a == "--costs")
      costs_only = true;
    else if (a == "--sync")
      jack_sync = true;
    else if (a == "--seconds" && i + 1 < argc)
      seconds = std::atof(argv[++i]);
  }
  print_block_costs();
  if (costs_only) return 0;
  const bool have_jack = on_path("jackd"), have_stress = on_path("stress-ng");
  if (!have_jack) std::fprintf(stderr, "jackd not found (Debian jackd2): JACK runs skipped\n");
  if (!have_stress) std::fprintf(stderr, "stress-ng not found: busy runs skipped\n");
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());

  std::vector<Result> results;
  std::vector<NullResult> nulls;
  for (const char* load : {"idle", "busy"}) {
    const bool busy = std::string(load) == "busy";
    if (busy && !have_stress) continue;
    Child stress;
    if (busy) {
      stress = spawn({"stress-ng", "--cpu", std::to_string(cores), "--timeout", "900"}, "/tmp/texel-bench-stress.log", true);
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    if (have_jack)
      for (std::size_t block : {std::size_t{16}, std::size_t{64}})
        for (auto& r : jack_runs(load, block, seconds)) results.push_back(r);
    nulls.push_back(null_run(load));
    stop(stress);
  }

  std::printf("texel_bench_player_paced: JACK dummy driver, 48 kHz, %.0f s per run, %u cores%s\n", seconds, cores,
              have_stress ? "; busy = stress-ng --cpu <cores>" : "");
  std::printf("%-5s %-5s %5s %8s | %8s %8s %8s %8s | %8s %8s %8s | %6s %5s | %s\n", "load", "dim", "block", "blocks", "p50 %",
              "p99 %", "p99.9 %", "max %", "lat p50", "lat p99", "lat max", "allocs", "xruns", "scheduling");
  for (const auto& r : results)
    std::printf(
        "%-5s %-5s %5zu %8zu | %8.3f %8.3f %8.3f %8.3f | %6.3fms %6.3fms %6.3fms | %6llu %5llu | %s (playback latency "
        "%.0f…%.0f frames; latency max = %.3f ms push → callback + %.3f ms in the block + the playback latency; longest "
        "gap between callbacks %.3f ms)\n",
        r.load.c_str(), r.dim.c_str(), r.block, r.blocks, r.block_time.p50, r.block_time.p99, r.block_time.p999, r.block_time.max,
        r.lat_p50_ms, r.lat_p99_ms, r.lat_max_ms, static_cast<unsigned long long>(r.allocations),
        static_cast<unsigned long long>(r.xruns), r.scheduling.c_str(), r.playback_latency_min_frames, r.playback_latency_frames,
        r.max_wait_ms, r.max_offset_ms, r.longest_gap_ms);
  // Beside the floor: each player's figures over the do-nothing client's
  // of the same run (same load, same period); the block time also as the
  // difference in points of the period (the floor's own block is a fill of
  // zeros, so the ratio alone is large whatever the player costs).
  std::printf("\nbeside the floor (player / do-nothing client of the same run; xruns: player vs floor):\n");
  std::printf("%-5s %-5s %5s | %10s %12s | %10s %10s %10s | %s\n", "load", "dim", "block", "p99.9", "p99.9 − floor", "lat p50",
              "lat p99", "lat max", "xruns");
  const auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  for (const auto& r : results) {
    if (r.dim == "floor") continue;
    const auto floor = std::find_if(results.begin(), results.end(),
                                    [&](const Result& f) { return f.dim == "floor" && f.load == r.load && f.block == r.block; });
    if (floor == results.end()) continue;
    std::printf("%-5s %-5s %5zu | %9.2fx %+10.3f %% | %9.3fx %9.3fx %9.3fx | %llu vs %llu\n", r.load.c_str(), r.dim.c_str(),
                r.block, ratio(r.block_time.p999, floor->block_time.p999), r.block_time.p999 - floor->block_time.p999,
                ratio(r.lat_p50_ms, floor->lat_p50_ms), ratio(r.lat_p99_ms, floor->lat_p99_ms),
                ratio(r.lat_max_ms, floor->lat_max_ms), static_cast<unsigned long long>(r.xruns),
                static_cast<unsigned long long>(floor->xruns));
  }
  for (const auto& n : nulls)
    std::printf(
        "null backend (texel play --backend null), 64 frames, 5 s, %s: %llu blocks, %llu underruns, worst block %.2f %% of the "
        "period; %s\n",
        n.load.c_str(), static_cast<unsigned long long>(n.blocks), static_cast<unsigned long long>(n.underruns), n.worst_pct,
        n.scheduling.c_str());
  if (!json.empty()) {
    if (std::FILE* f = std::fopen(json.c_str(), "w")) {
      std::fprintf(f, "{\"seconds\": %.1f, \"cores\": %u, \"jack\": [", seconds, cores);
      for (std::size_t i = 0; i < results.size(); ++i) {
        const auto& r = results[i];
        std::fprintf(
            f,
            "%s{\"load\": \"%s\", \"dim\": \"%s\", \"block\": %zu, \"blocks\": %zu, \"p50_pct\": %.4f, \"p99_pct\": %.4f, "
            "\"p999_pct\": %.4f, \"max_pct\": %.4f, \"latency_p50_ms\": %.4f, \"latency_p99_ms\": %.4f, "
            "\"latency_max_ms\": %.4f, \"latency_max_wait_ms\": %.4f, \"longest_gap_ms\": %.4f, \"playback_latency_frames\": "
            "%.0f, \"allocations\": %llu, \"xruns\": %llu, \"scheduling\": \"%s\"}",
            i ? ", " : "", r.load.c_str(), r.dim.c_str(), r.block, r.blocks, r.block_time.p50, r.block_time.p99,
            r.block_time.p999, r.block_time.max, r.lat_p50_ms, r.lat_p99_ms, r.lat_max_ms, r.max_wait_ms, r.longest_gap_ms,
            r.playback_latency_frames, static_cast<unsigned long long>(r.allocations), static_cast<unsigned long long>(r.xruns),
            r.scheduling.c_str());
      }
      std::fprintf(f, "], \"null\": [");
      for (std::size_t i = 0; i < nulls.size(); ++i)
        std::fprintf(f,
                     "%s{\"load\": \"%s\", \"blocks\": %llu, \"underruns\": %llu, \"worst_pct\": %.3f, \"scheduling\": \"%s\"}",
                     i ? ", " : "", nulls[i].load.c_str(), static_cast<unsigned long long>(nulls[i].blocks),
                     static_cast<unsigned long long>(nulls[i].underruns), nulls[i].worst_pct, nulls[i].scheduling.c_str());
      std::fprintf(f, "]}\n");
      std::fclose(f);
    }
  }
  std::uint64_t allocs = 0;
  for (const auto& r : results) allocs += r.allocations;
  return allocs == 0 ? 0 : 1;
}
