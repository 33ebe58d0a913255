// Proves the real-time path allocates nothing: global operator new/delete are
// replaced by counting versions, and every allocation or free made while the
// audio thread is inside Player::process() is counted. 10^6 blocks of 64
// frames at 48 kHz run on one thread while another streams finger samples,
// changes gain and swaps maps (with their allocations and frees) as fast as
// the player takes them.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <optional>
#include <thread>

#include "../support/alloc_counter.hpp"
#include "../support/grids.hpp"
#include "texel/document.hpp"
#include "texel/player.hpp"

namespace {
using texel::test_support::alloc::all_allocations;
// Counting is on while the audio thread is inside process().
using texel::test_support::alloc::counted_allocations;
using texel::test_support::alloc::counted_frees;
}  // namespace

using namespace texel;

TEST(PlayerAlloc, CountingAllocatorWorks) { EXPECT_TRUE(texel::test_support::alloc::counter_works()); }

// The event and retire rings are allocated by the constructor (prepare) and
// nowhere else: pushing, commands, processing and collecting allocate
// nothing on any thread, whatever the queue's capacity.
TEST(PlayerAlloc, QueuesAllocateAtPrepareOnly) {
  for (std::size_t capacity : {std::size_t{16}, std::size_t{4096}, std::size_t{1} << 20}) {
    PlayerConfig c;
    c.event_capacity = capacity;
    auto map = std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(0.01), 1000}, std::vector<float>(1000, 0.5f));
    std::vector<float> out(64);  // caller-supplied memory
    const std::uint64_t before = all_allocations.load();
    Player player(c, std::move(map));
    const std::uint64_t prepared = all_allocations.load();
    EXPECT_EQ(prepared - before, 2u) << "prepare: one event ring and one retire ring, capacity " << capacity;
    double t = 0;
    for (int block = 0; block < 200; ++block) {
      while (player.push({t, 1.0 + 5.0 * t, true})) t += 1e-4;
      (void)player.set_gain(0.5);
      (void)player.set_carrier(100.0);
      player.process(out);
      (void)player.collect();
    }
    EXPECT_EQ(all_allocations.load(), prepared) << "allocated after prepare, capacity " << capacity;
    EXPECT_EQ(player.event_capacity(), capacity);
  }
}

// The band limit's two paths (docs/player.md §5) while they fade: a Texel
// map (texel by texel, neighbours' weights) and a map of raw values (the
// pyramid), swiped at 100 mm/s on a 1 kHz drive, swapped back and forth.
TEST(PlayerAlloc, BandLimitedProcessAllocatesNothing) {
  TexelSpec spec;
  spec.central_pitch = Decibels(6.0);  // 4 cpm: 400 Hz at 100 mm/s, around the 450 Hz limit
  spec.irregularity = Decibels(1.0);
  const Document doc = make_document(load_device("tpad"), spec);
  std::vector<float> raw(19200);
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = static_cast<float>(0.5 + 0.5 * std::sin(0.05 * static_cast<double>(i)));
  PlayerConfig c;
  c.rate_hz = 1000;
  c.crossfade_s = 0.002;
  Player player(c, PlayerMap::from_document(doc));
  std::vector<float> out(16);
  const std::uint64_t allocations = counted_allocations.load(), frees = counted_frees.load();
  double t = 0;
  for (int block = 0; block < 4000; ++block) {
    while (t < 0.016 * block + 0.05 && player.push({t, 50 + 45 * std::sin(2.2 * t), true})) t += 0.001;
    if (block % 100 == 0) {
      if ((block / 100) % 2 == 0)
        player.set_map(std::make_unique<const PlayerMap>(texel::test_support::tpad_grid(), raw));
      else
        player.set_map(PlayerMap::from_document(doc));
    }
    {
      texel::test_support::alloc::CountingScope scope;
      player.process(out);
    }
    player.collect();
  }
  EXPECT_EQ(counted_allocations.load() - allocations, 0u);
  EXPECT_EQ(counted_frees.load() - frees, 0u);
}

TEST(PlayerAlloc, ProcessNeverAllocatesOverAMillionBlocksWhileSwapping) {
  constexpr std::uint64_t blocks = 1000000;
  constexpr std::size_t frames = 64;
  // Maps carrying no response (the config's), a flat one and the tpad's in
  // turn, so process() also switches its response limit off and on.
  auto make = [](double level, std::uint64_t k = 0) {
    std::vector<float> v(19200);
    for (std::size_t i = 0; i < v.size(); ++i)
      v[i] = static_cast<float>(level * (0.5 + 0.5 * std::sin(0.05 * static_cast<double>(i))));
    std::optional<FrequencyResponse> r;
    if (k % 3 == 1) r = FrequencyResponse{};
    if (k % 3 == 2) r = FrequencyResponse{Hertz(300.0), 2, "a second-order display"};
    return std::make_unique<const PlayerMap>(texel::test_support::tpad_grid(), std::move(v), std::move(r));
  };
  for (OutputMode mode : {OutputMode::vibration, OutputMode::carrier, OutputMode::amplitude}) {
    PlayerConfig c;
    c.rate_hz = 48000;
    c.mode = mode;
    c.crossfade_s = 0.002;  // short, so many swaps complete within the run
    c.prediction_s = 0.02;
    c.response.corner = Hertz(400.0);  // the tpad's: the response limit runs in process() too
    c.response.order = 1;
    Player player(c, make(1.0));
    std::atomic<std::uint64_t> done{0};
    std::atomic<bool> stop{false};
    std::uint64_t swaps = 0;
    std::thread control([&] {
      double t = 0;
      int k = 0;
      while (!stop.load(std::memory_order_relaxed)) {
        // Finger: back-and-forth over the map at ~100 mm/s, lifting every 0.5 s.
        const double now = static_cast<double>(done.load(std::memory_order_relaxed)) * frames / c.rate_hz;
        while (t < now + 0.05 && player.push({t, 50 + 40 * std::sin(2 * t), std::fmod(t, 0.5) < 0.45})) t += 0.001;
        if (++k % 4 == 0) player.set_gain(0.5 + 0.5 * std::sin(t));
        player.set_map(make(0.3 + 0.7 * std::fabs(std::sin(t)), swaps));  // allocates here, on the control thread
        ++swaps;
        player.collect();
        std::this_thread::yield();
      }
    });
    std::vector<float> out(frames);
    const double sum = texel::test_support::alloc::count_blocks(blocks, done, [&] { return player.process(out).peak; });
    stop = true;
    control.join();
    EXPECT_EQ(counted_allocations.load(), 0u) << to_string(mode);
    EXPECT_EQ(counted_frees.load(), 0u) << to_string(mode);
    EXPECT_GT(swaps, 100u) << to_string(mode);
    EXPECT_GT(sum, 0.0) << to_string(mode);
  }
}
