// texel_bench_multichannel_paced: the multi-channel player (ChannelPlayer,
// docs/rendering.md) on a JACK server with its dummy driver (started and
// stopped here), 48 kHz, 64-frame periods, N output ports (default 8), a
// simultaneous texture (one chain of texels per channel) under a finger
// pushed by a 1 kHz sensor thread. Reports per run: block times (the whole
// callback's work: N Player::process calls into the ports' buffers) p50 /
// p99 / p99.9 / max as % of the period, allocations inside the callback
// (the tests' counting allocator: must be 0), JACK's xruns and the
// scheduling the process thread had.
//
// The floor: in the same server, same period, same ports, a do-nothing
// client goes first — its callback writes zeros to its N ports, nothing
// else — and the player's p99.9 is reported beside it (ratio and difference
// in points of the period). What the floor shows is the machine's tail; a
// player within it costs nothing that shows.
//
// Usage: texel_bench_multichannel_paced [--seconds S] [--channels N] [--runs R]
// Needs jackd (Debian jackd2); without it the run is reported skipped (exit
// 0), never faked. Exit 1 if the callback allocated.
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
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "../tests/support/alloc_counter.hpp"
#include "jack_bench.hpp"
#include "texel/document.hpp"
#include "texel/multichannel.hpp"
#include "texel/multichannel_player.hpp"

using namespace texel;
namespace alloc = texel::test_support::alloc;
using namespace texel::bench;

namespace {

constexpr double rate = 48000.0;
constexpr std::size_t period = 64;
constexpr std::size_t max_ports = 64;

struct Run {
  jack_client_t* client = nullptr;
  std::size_t channels = 0;
  jack_port_t* ports[max_ports] = {};
  ChannelPlayer* player = nullptr;  // null: the floor
  std::vector<double> block_s;
  std::atomic<std::size_t> blocks{0};
  std::atomic<std::uint64_t> xruns{0};
  Scheduling scheduling;
};

int on_xrun(void* arg) {
  static_cast<Run*>(arg)->xruns.fetch_add(1, std::memory_order_relaxed);
  return 0;
}

// JACK's process thread: real-time safe (N port buffers, N Player::process
// calls or N fills, clock reads, a store into an array sized before activation).
int on_process(jack_nframes_t n, void* arg) {
  auto& r = *static_cast<Run*>(arg);
  r.scheduling.note();
  timespec a{}, b{};
  ::clock_gettime(CLOCK_MONOTONIC, &a);
  alloc::counting = true;
  std::span<float> outs[max_ports];
  for (std::size_t c = 0; c < r.channels; ++c) outs[c] = std::span(static_cast<float*>(jack_port_get_buffer(r.ports[c], n)), n);
  if (r.player)
    r.player->process_planar(std::span<const std::span<float>>(outs, r.channels));
  else
    for (std::size_t c = 0; c < r.channels; ++c) std::fill(outs[c].begin(), outs[c].end(), 0.0f);
  alloc::counting = false;
  ::clock_gettime(CLOCK_MONOTONIC, &b);
  const std::size_t k = r.blocks.load(std::memory_order_relaxed);
  if (k < r.block_s.size()) {
    r.block_s[k] = static_cast<double>(b.tv_sec - a.tv_sec) + 1e-9 * static_cast<double>(b.tv_nsec - a.tv_nsec);
    r.blocks.store(k + 1, std::memory_order_relaxed);
  }
  return 0;
}

struct Result {
  std::string what;
  std::size_t blocks = 0;
  Stats block_time;
  std::uint64_t allocations = 0, xruns = 0;
  std::string scheduling;
};

Result run_client(const std::string& server, std::size_t channels, double seconds, ChannelPlayer* player) {
  Result res;
  Run r;
  r.channels = channels;
  r.player = player;
  r.block_s.assign(static_cast<std::size_t>(seconds * rate / static_cast<double>(period)) + 2000, 0.0);
  r.client = open_client("texel-mc", server);
  if (!r.client) {
    res.scheduling = "JACK client failed to open";
    return res;
  }
  for (std::size_t c = 0; c < channels; ++c)
    r.ports[c] =
        jack_port_register(r.client, ("out_" + std::to_string(c + 1)).c_str(), JACK_DEFAULT_AUDIO_TYPE, JackPortIsOutput, 0);
  jack_set_process_callback(r.client, on_process, &r);
  jack_set_xrun_callback(r.client, on_xrun, &r);
  ::mlockall(MCL_CURRENT);
  jack_activate(r.client);
  // The dummy driver has 2 playback ports by default: connect what fits (the
  // others still run: JACK calls every client's process whatever its links).
  for (std::size_t c = 0; c < channels && c < 2; ++c)
    jack_connect(r.client, jack_port_name(r.ports[c]), ("system:playback_" + std::to_string(c + 1)).c_str());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const std::size_t warm = r.blocks.load();
  const std::uint64_t xruns0 = r.xruns.load();
  alloc::counted_allocations = 0;

  // The finger: 1 kHz on absolute deadlines, 100 mm/s to and fro over 5 … 45 mm.
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  for (std::size_t k = 0; static_cast<double>(k) < seconds * 1000.0; ++k) {
    t.tv_nsec += 1000000;
    if (t.tv_nsec >= 1000000000) t.tv_nsec -= 1000000000, ++t.tv_sec;
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr) == EINTR) {
    }
    if (player) {
      const double s = 0.1 * static_cast<double>(k % 800);  // mm along a 80 mm cycle
      const double x = 5.0 + (s < 40.0 ? s : 80.0 - s);
      player->push(FingerSample{player->player(0).time_s(), x, true});
      player->collect();
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  jack_deactivate(r.client);
  jack_client_close(r.client);

  const std::size_t done = r.blocks.load();
  res.blocks = done - warm;
  res.block_time = percentiles(std::vector<double>(r.block_s.begin() + static_cast<std::ptrdiff_t>(warm),
                                                   r.block_s.begin() + static_cast<std::ptrdiff_t>(done)),
                               static_cast<double>(period) / rate);
  res.allocations = alloc::counted_allocations.load();
  res.xruns = r.xruns.load() - xruns0;
  res.scheduling = r.scheduling.name();
  return res;
}

Document simultaneous_document(std::size_t channels) {
  std::string actuators;
  for (std::size_t c = 0; c < channels; ++c)
    actuators += (c ? "," : "") + std::string(R"({"name": "a)") + std::to_string(c) + R"(", "offset_mm": )" +
                 std::to_string(static_cast<double>(c) - static_cast<double>(channels) / 2.0) + "}";
  return parse_document(
      R"({"format": "texel-document", "version": 6, "device": {"name": "pad", "samples": 10000,
      "spacing_mm": 0.005, "format": "f32le", "refresh_hz": 48000, "actuators": [)" +
      actuators +
      R"(]}, "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": 5, "texel_length_mm": 0.25, "seed": 40},
      "playback": {"mode": "simultaneous"}})");
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  std::size_t channels = 8;
  int runs = 1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--seconds")
      seconds = std::atof(argv[i + 1]);
    else if (a == "--channels")
      channels = static_cast<std::size_t>(std::atoi(argv[i + 1]));
    else if (a == "--runs")
      runs = std::atoi(argv[i + 1]);
  }
  if (channels < 1 || channels > max_ports || !(seconds > 0) || runs < 1) {
    std::fprintf(stderr, "usage: texel_bench_multichannel_paced [--seconds S > 0] [--channels 1 … 64] [--runs R >= 1]\n");
    return 2;
  }
  JackServer jackd = start_jack("texel-mc", period, false);
  if (!jackd.started()) {
    std::printf("texel_bench_multichannel_paced: jackd did not start (see %s); skipped\n", jackd.log.c_str());
    return 0;
  }
  const std::string& server = jackd.name;
  const std::string& mode = jackd.mode;
  const auto plan = prepare_channels(simultaneous_document(channels));
  PlayerConfig config;
  config.rate_hz = rate;
  config.mode = OutputMode::vibration;
  std::printf(
      "texel_bench_multichannel_paced: JACK dummy driver (%s), 48 kHz, %zu-frame periods, %zu channels "
      "(simultaneous), %.0f s per run\n",
      mode.c_str(), period, channels, seconds);
  std::printf("%-8s %8s | %8s %8s %8s %8s | %6s %5s | %s\n", "client", "blocks", "p50 %", "p99 %", "p99.9 %", "max %", "allocs",
              "xruns", "scheduling");
  std::uint64_t allocations = 0;
  for (int k = 0; k < runs; ++k) {
    const Result floor = run_client(server, channels, seconds, nullptr);
    ChannelPlayer player(config, plan, period);
    const Result played = run_client(server, channels, seconds, &player);
    for (const Result* r : {&floor, &played})
      std::printf("%-8s %8zu | %8.3f %8.3f %8.3f %8.3f | %6llu %5llu | %s\n", r == &floor ? "floor" : "player", r->blocks,
                  r->block_time.p50, r->block_time.p99, r->block_time.p999, r->block_time.max,
                  static_cast<unsigned long long>(r->allocations), static_cast<unsigned long long>(r->xruns),
                  r->scheduling.c_str());
    std::printf("player beside the floor: p99.9 %.2fx (%+.3f points of the period), xruns %llu vs %llu\n",
                floor.block_time.p999 > 0 ? played.block_time.p999 / floor.block_time.p999 : 0.0,
                played.block_time.p999 - floor.block_time.p999, static_cast<unsigned long long>(played.xruns),
                static_cast<unsigned long long>(floor.xruns));
    allocations += played.allocations + floor.allocations;
  }
  stop(jackd.process);
  return allocations == 0 ? 0 : 1;
}
