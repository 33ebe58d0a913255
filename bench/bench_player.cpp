// texel_bench_player: real-time cost of Player::process — time to process one
// 64-frame block at 48 kHz, over 10^6 blocks per output mode, reported as the
// median, 99.9th percentile and maximum, in µs and as a fraction of the block
// period (64 / 48000 s = 1.333 ms). Goal: 99.9th percentile below 1 %.
//
// Baseline measured in the same run: filling the same buffer with a constant
// (plain memory write) timed the same way, so the timer's own cost shows.
// The finger (back-and-forth over the tpad map, 1 kHz sensor) is fed between
// blocks and not timed; every output block is summed so nothing is elided.
//
// Usage: texel_bench_player [blocks] [--json FILE]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "texel/player.hpp"

using namespace texel;
using Clock = std::chrono::steady_clock;

namespace {

struct Result {
  std::string name;
  double median_us, p999_us, max_us, ns_per_sample;
};

Result summarize(std::string name, std::vector<double>& t_us, std::size_t frames) {
  std::sort(t_us.begin(), t_us.end());
  const auto at = [&](double q) {
    return t_us[std::min(t_us.size() - 1, static_cast<std::size_t>(q * static_cast<double>(t_us.size())))];
  };
  return {std::move(name), at(0.5), at(0.999), t_us.back(), at(0.5) * 1000.0 / static_cast<double>(frames)};
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t blocks = 1000000;
  std::string json;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json" && i + 1 < argc)
      json = argv[++i];
    else
      blocks = static_cast<std::size_t>(std::strtoull(argv[i], nullptr, 10));
  }
  constexpr std::size_t frames = 64;
  constexpr double rate = 48000.0;
  const double period_us = frames / rate * 1e6;

  std::vector<float> map(19200);
  for (std::size_t i = 0; i < map.size(); ++i) map[i] = static_cast<float>(0.5 + 0.5 * std::sin(0.37 * static_cast<double>(i)));
  const PlayerMap proto(Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, map);

  std::vector<Result> results;
  std::vector<float> out(frames);
  std::vector<double> t_us(blocks);
  double sink = 0;

  for (std::size_t b = 0; b < blocks; ++b) {
    const auto t0 = Clock::now();
    std::fill(out.begin(), out.end(), static_cast<float>(b & 1));
    const auto t1 = Clock::now();
    sink += out[b % frames];
    t_us[b] = std::chrono::duration<double, std::micro>(t1 - t0).count();
  }
  results.push_back(summarize("baseline fill", t_us, frames));

  for (OutputMode mode : {OutputMode::amplitude, OutputMode::vibration, OutputMode::carrier}) {
    PlayerConfig c;
    c.rate_hz = rate;
    c.mode = mode;
    c.prediction_s = 0.02;
    Player player(c, std::make_unique<const PlayerMap>(proto));
    double ft = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      const double now = static_cast<double>(b * frames) / rate;
      while (ft <= now) {  // 1 kHz sensor, back-and-forth at up to ~125 mm/s, lifting now and then
        player.push({ft, 50.0 + 40.0 * std::sin(3.0 * ft), std::fmod(ft, 2.0) < 1.9});
        ft += 0.001;
      }
      if (b % 20000 == 0) player.set_map(std::make_unique<const PlayerMap>(proto));  // swaps + crossfades
      const auto t0 = Clock::now();
      const BlockInfo info = player.process(out);
      const auto t1 = Clock::now();
      sink += info.peak;
      t_us[b] = std::chrono::duration<double, std::micro>(t1 - t0).count();
      if (b % 1024 == 0) player.collect();
    }
    results.push_back(summarize("process " + std::string(to_string(mode)), t_us, frames));
  }

  std::printf("texel_bench_player: %zu blocks of %zu frames at %.0f Hz (period %.1f µs)\n", blocks, frames, rate, period_us);
  std::printf("%-22s %10s %10s %10s %12s %12s %12s %10s\n", "", "median µs", "p99.9 µs", "max µs", "median %", "p99.9 %", "max %",
              "ns/sample");
  for (const auto& r : results)
    std::printf("%-22s %10.3f %10.3f %10.1f %11.4f%% %11.4f%% %11.3f%% %10.2f\n", r.name.c_str(), r.median_us, r.p999_us,
                r.max_us, 100 * r.median_us / period_us, 100 * r.p999_us / period_us, 100 * r.max_us / period_us,
                r.ns_per_sample);
  if (!json.empty()) {
    if (std::FILE* f = std::fopen(json.c_str(), "w")) {
      std::fprintf(f, "{\"blocks\": %zu, \"frames\": %zu, \"rate_hz\": %.0f, \"period_us\": %.4f, \"results\": [", blocks, frames,
                   rate, period_us);
      for (std::size_t i = 0; i < results.size(); ++i)
        std::fprintf(f, "%s{\"name\": \"%s\", \"median_us\": %.4f, \"p999_us\": %.4f, \"max_us\": %.4f}", i ? ", " : "",
                     results[i].name.c_str(), results[i].median_us, results[i].p999_us, results[i].max_us);
      std::fprintf(f, "]}\n");
      std::fclose(f);
    }
  }
  return sink == -1.0 ? 1 : 0;
}
