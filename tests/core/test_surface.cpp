// Surfaces (surface.hpp, docs/algorithm.md §8): a device split into regions, each
// with its own texture. Each half of the studies' left/right layout must equal
// its texture rendered alone; samples in no region are at rest; regions must
// not overlap; any window equals the whole map.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "../support/expect.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"
#include "texel/surface.hpp"

using namespace texel;

namespace {

std::shared_ptr<const Texture> texture(double p_db, std::uint64_t seed, double length_mm, const Grid& g) {
  TexelSpec s;
  s.central_pitch = Decibels(p_db);
  s.seed = seed;
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  s.coarse_strength = 0.4;
  return std::make_shared<TexelTexture>(s, Millimetres(length_mm), Sampling{g});
}

}  // namespace

TEST(Surface, EachHalfEqualsItsTextureRenderedAlone) {
  const DeviceProfile d = load_device("tpad");
  const Grid g = d.grid();
  const double half = 50.88;
  auto left = texture(10.0, 1, half, g);
  auto right = texture(15.0, 2, half, g);
  const Surface surface(g, {Region{"left", Millimetres(0.0), Millimetres(half), left},
                            Region{"right", Millimetres(half), Millimetres(half), right}});
  const auto map = surface.render();
  ASSERT_EQ(map.size(), 19200u);

  // Left: the same grid positions, so the same bits.
  std::vector<double> alone(9600);
  left->render(g, 0, alone);
  EXPECT_EQ(std::memcmp(map.data(), alone.data(), 9600 * sizeof(double)), 0);
  // Right: rendered alone on its own 50.88 mm device (positions j·Δx from its
  // left edge). On the surface the positions are i·Δx − 50.88 mm, equal up to
  // rounding (< 1e-13 mm), so amplitudes agree within 2π·f·1e-13 < 1e-10.
  const Grid own{Millimetres(0.0), g.spacing, 9600};
  right->render(own, 0, alone);
  double worst = 0.0;
  for (std::size_t j = 0; j < 9600; ++j) worst = std::max(worst, std::fabs(map[9600 + j] - alone[j]));
  EXPECT_LT(worst, 1e-10);
  // The split is really there: the two halves are different textures.
  EXPECT_NE(std::memcmp(map.data(), map.data() + 9600, 9600 * sizeof(double)), 0);
}

TEST(Surface, SamplesInNoRegionAreAtRest) {
  const Grid g{Millimetres(0.0), Millimetres(0.01), 1000};  // 10 mm
  const Surface s(g, {Region{"mid", Millimetres(3.0), Millimetres(4.0), texture(10.0, 1, 4.0, g)}});
  const auto map = s.render();
  for (std::size_t i = 0; i < map.size(); ++i) {
    const double x = g.position(static_cast<std::int64_t>(i)).value();
    if (x < 3.0 - 1e-9 || x >= 7.0 - 1e-9) {
      ASSERT_EQ(map[i], 0.0) << "x = " << x;
    }
  }
  double inside = 0.0;
  for (std::size_t i = 300; i < 700; ++i) inside += map[i];
  EXPECT_GT(inside / 400.0, 0.2);
}

TEST(Surface, EveryWindowZeroesItsSamplesAtRestWhateverTheBufferHeld) {
  // Render zeroes only the gaps between regions (no pass over the whole
  // window): windows into a buffer of garbage, starting and ending in gaps,
  // in regions and across both, equal the whole map, gaps included.
  const Grid g{Millimetres(0.0), Millimetres(0.01), 1000};  // 10 mm
  const Surface s(g, {Region{"a", Millimetres(1.0), Millimetres(2.0), texture(10.0, 1, 2.0, g)},
                      Region{"b", Millimetres(3.0), Millimetres(1.5), texture(12.0, 2, 1.5, g)},
                      Region{"c", Millimetres(6.0), Millimetres(3.0), texture(8.0, 3, 3.0, g)}});
  const auto whole = s.render();
  for (std::size_t first : {0, 50, 100, 250, 299, 300, 420, 500, 598, 950}) {
    for (std::size_t len : {1, 7, 60, 333, 1000}) {
      if (first + len > whole.size()) continue;
      std::vector<double> win(len, std::nan(""));
      s.render(static_cast<std::int64_t>(first), win);
      ASSERT_EQ(std::memcmp(win.data(), whole.data() + first, len * sizeof(double)), 0) << first << " + " << len;
    }
  }
  const Surface empty(g, {});
  std::vector<double> win(100, 0.5);
  empty.render(10, win);
  for (double v : win) ASSERT_EQ(v, 0.0);
}

TEST(Surface, RejectsOverlappingAndOutOfRangeRegions) {
  const Grid g{Millimetres(0.0), Millimetres(0.01), 1000};
  auto t = texture(10.0, 1, 6.0, g);
  auto message = [&](std::vector<Region> r) {
    return test_support::message_of<InvalidArgument>([&] { Surface s(g, std::move(r)); });
  };
  EXPECT_NE(message({Region{"a", Millimetres(0.0), Millimetres(6.0), t}, Region{"b", Millimetres(5.0), Millimetres(5.0), t}})
                .find("overlap"),
            std::string::npos);
  EXPECT_NE(message({Region{"a", Millimetres(5.0), Millimetres(6.0), t}}).find("past the device"), std::string::npos);
  EXPECT_NE(message({Region{"a", Millimetres(-1.0), Millimetres(2.0), t}}).find("start_mm"), std::string::npos);
  EXPECT_NE(message({Region{"a", Millimetres(0.0), Millimetres(0.0), t}}).find("length_mm"), std::string::npos);
  EXPECT_NE(message({Region{"a", Millimetres(0.0), Millimetres(1.0), nullptr}}).find("no texture"), std::string::npos);
  EXPECT_EQ(message({Region{"a", Millimetres(0.0), Millimetres(5.0), t}, Region{"b", Millimetres(5.0), Millimetres(5.0), t}}),
            "(no exception)");  // touching is fine
}

RC_GTEST_PROP(Surface, AnyWindowEqualsTheWholeMap, ()) {
  const Grid g = load_device("tpad").grid();
  const auto seed = *rc::gen::arbitrary<std::uint64_t>();
  const Surface s(g, {Region{"left", Millimetres(0.0), Millimetres(50.88), texture(10.0, seed, 50.88, g)},
                      Region{"right", Millimetres(50.88), Millimetres(50.88), texture(12.0, seed + 1, 50.88, g)}});
  const auto full = s.render();
  for (int w = 0; w < 10; ++w) {
    const auto first = *rc::gen::inRange<std::size_t>(0, full.size());
    const auto len = *rc::gen::inRange<std::size_t>(1, full.size() - first + 1);
    std::vector<double> win(len);
    s.render(static_cast<std::int64_t>(first), win);
    RC_ASSERT(std::memcmp(win.data(), full.data() + first, len * sizeof(double)) == 0);
  }
  // The chunked native encoder gives the bytes of the whole map encoded at once.
  std::vector<std::byte> whole(full.size() * 2);
  encode_samples(SampleFormat::u16le, full, whole);
  RC_ASSERT(s.render_native(SampleFormat::u16le) == whole);
}
