// Allocation rules of the C ABI, with global operator new/delete replaced by
// counting versions (as tests/player/test_player_alloc.cpp does for Player):
//  - texel_player_process allocates and frees nothing, while the control
//    thread's calls around it (push, set_surface, collect) may;
//  - running out of memory inside any entry point is TEXEL_OUT_OF_MEMORY with
//    a message, never an exception across the boundary.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

#include "texel.h"

#include "../support/alloc_counter.hpp"  // the one counting allocator (defines operator new/delete)

namespace {
using texel::test_support::alloc::counted_allocations;
using texel::test_support::alloc::counted_frees;
using texel::test_support::alloc::counting;
// This thread's allocations throw std::bad_alloc while it is set.
using texel::test_support::alloc::fail;
}  // namespace

namespace {

TEST(CApiAlloc, CountingAllocatorWorks) { EXPECT_TRUE(texel::test_support::alloc::counter_works()); }

TEST(CApiAlloc, ProcessAllocatesNothing) {
  texel_params params = texel_params_default();
  texel_surface* surface = nullptr;
  texel_surface* flat = nullptr;
  ASSERT_EQ(texel_surface_from_params("tpad", &params, &surface), TEXEL_OK);
  ASSERT_EQ(texel_surface_from_params("generic", &params, &flat), TEXEL_OK);
  // 48 kHz: the tpad's response limit (3.98 kHz, below 0.45·rate) runs in
  // process(), and swapping in the generic (flat) surface and back switches
  // it off and on there (TEXEL_RESPONSE_LIMIT, the default).
  texel_player_config config = texel_player_config_default();
  config.rate_hz = 48000;
  config.mode = TEXEL_OUTPUT_VIBRATION;
  ASSERT_EQ(config.response_handling, TEXEL_RESPONSE_LIMIT);
  texel_player* player = nullptr;
  ASSERT_EQ(texel_player_create(&config, &player), TEXEL_OK);
  ASSERT_EQ(texel_player_set_surface(player, surface), TEXEL_OK);

  std::vector<float> out(384), pos(384);  // 8 ms at 48 kHz: the 8 finger samples pushed per block
  double t = 0.0;
  for (int block = 0; block < 2000; ++block) {
    // Control side: finger samples every block, a new map now and then.
    for (int k = 0; k < 8; ++k, t += 1.0 / 1000.0)
      ASSERT_EQ(texel_player_push(player, t, 5.0 + 40.0 * std::abs(std::sin(t)), block % 300 < 250), TEXEL_OK);
    if (block % 250 == 125) {
      ASSERT_EQ(texel_player_set_surface(player, block % 500 == 125 ? flat : surface), TEXEL_OK);
    }
    if (block % 100 == 0) {
      ASSERT_EQ(texel_player_collect(player, nullptr), TEXEL_OK);
    }
    // Real-time side.
    counting = true;
    const texel_status st = texel_player_process(player, out.data(), out.size(), block % 2 ? pos.data() : nullptr);
    counting = false;
    ASSERT_EQ(st, TEXEL_OK);
  }
  EXPECT_EQ(counted_allocations.load(), 0u);
  EXPECT_EQ(counted_frees.load(), 0u);
  counting = true;
  EXPECT_EQ(texel_player_process(nullptr, out.data(), out.size(), nullptr), TEXEL_INVALID_ARGUMENT);  // errors too
  counting = false;
  EXPECT_EQ(counted_allocations.load(), 0u);
  texel_player_destroy(player);
  texel_surface_destroy(surface);
  texel_surface_destroy(flat);
}

TEST(CApiAlloc, OutOfMemoryIsAStatus) {
  texel_params params = texel_params_default();
  texel_surface* surface = reinterpret_cast<texel_surface*>(&params);
  texel_player* player = reinterpret_cast<texel_player*>(&params);
  texel_player_config config = texel_player_config_default();
  texel_status a, b;
  {
    fail = true;
    a = texel_surface_from_params("tpad", &params, &surface);
    b = texel_player_create(&config, &player);
    fail = false;
  }
  EXPECT_EQ(a, TEXEL_OUT_OF_MEMORY);
  EXPECT_EQ(b, TEXEL_OUT_OF_MEMORY);
  EXPECT_STREQ(texel_last_error(), "out of memory");
  EXPECT_EQ(surface, nullptr);
  EXPECT_EQ(player, nullptr);
  // And the library works again afterwards.
  ASSERT_EQ(texel_surface_from_params("tpad", &params, &surface), TEXEL_OK);
  EXPECT_STREQ(texel_last_error(), "");
  texel_surface_destroy(surface);
}

}  // namespace
