// The fast render path against the slow, obviously-correct reference, bit for
// bit: TexelTexture::render (lane-wise kernel, run splitting, any window) must
// equal TexelTexture::amplitude_at (one sample, scalar detmath::sin_cycles) at
// every grid position, and the batch encoders must equal their per-sample
// rules. Bit-identity, not closeness: this is what keeps a texture file
// rendering to the same bytes on every build, -O level and instruction set.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "../support/grids.hpp"
#include "texel/device.hpp"
#include "texel/texture.hpp"

namespace texel {
namespace {

struct Case {
  const char* name;
  TexelSpec spec;
  double length_mm;
  Grid grid;
};

std::vector<Case> cases() {
  std::vector<Case> c;
  const Grid tpad = test_support::tpad_grid();
  {
    TexelSpec s;
    s.seed = 7;
    c.push_back({"tpad default seed 7", s, 19200 * 0.0053, tpad});
  }
  {
    TexelSpec s;
    s.seed = 1;
    s.texel_length = Millimetres(1.0);
    s.central_pitch = Decibels(6.0);
    s.irregularity = Decibels(3.0);
    c.push_back({"generic 2000 mm, 1 mm texels", s, 2000.0, Grid{Millimetres(0.0), Millimetres(0.005), 400000}});
  }
  {
    TexelSpec s;
    s.seed = 7;
    s.phase = PhaseMode::reset;
    c.push_back({"phase reset", s, 19200 * 0.0053, tpad});
  }
  {
    TexelSpec s;
    s.seed = 7;
    s.coarse = SineProfile{Millimetres(5.0), 0.0};
    s.coarse_strength = 0.5;
    s.fine_strength = 0.5;
    c.push_back({"coarse sine 5 mm, C = F = 0.5", s, 19200 * 0.0053, tpad});
  }
  {
    // Offset origin (samples before the texture), partial final texel, texels
    // shorter than a few samples, samples past the end.
    TexelSpec s;
    s.seed = 11;
    s.texel_length = Millimetres(0.01);
    s.fill = Fill::partial_final_texel;
    s.central_pitch = Decibels(15.0);
    c.push_back({"offset grid, partial texel, short texels", s, 33.33, Grid{Millimetres(-0.37), Millimetres(0.0013), 30000}});
  }
  return c;
}

std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }

// Renders [first, first + len) and compares every sample with amplitude_at.
void expect_window_exact(const TexelTexture& t, const Grid& g, std::int64_t first, std::int64_t len, const char* name) {
  std::vector<double> out(static_cast<std::size_t>(len), -1.0);
  t.render(g, first, out);
  std::int64_t mismatches = 0;
  for (std::int64_t j = 0; j < len; ++j) {
    const double x = g.position(first + j).value();
    const double want = t.amplitude_at(Millimetres(x));
    const double got = out[static_cast<std::size_t>(j)];
    if (bits(got) != bits(want) && ++mismatches <= 3)
      ADD_FAILURE() << name << ": sample " << first + j << " (x = " << x << " mm) rendered " << got << ", amplitude_at gives "
                    << want;
  }
  EXPECT_EQ(mismatches, 0) << name << ", window [" << first << ", " << first + len << ")";
}

TEST(RenderExact, WholeGridMatchesAmplitudeAt) {
  for (const Case& c : cases()) {
    const TexelTexture t(c.spec, Millimetres(c.length_mm), Sampling{c.grid});
    expect_window_exact(t, c.grid, 0, c.grid.count, c.name);
  }
}

TEST(RenderExact, EveryWindowMatchesAmplitudeAt) {
  // Windows that start and end mid-texel, mid-SIMD-block, at single samples.
  const std::int64_t firsts[] = {0, 1, 3, 7, 47, 1001};
  const std::int64_t lens[] = {1, 2, 3, 5, 8, 9, 17, 100, 4099};
  for (const Case& c : cases()) {
    const TexelTexture t(c.spec, Millimetres(c.length_mm), Sampling{c.grid});
    for (std::int64_t first : firsts)
      for (std::int64_t len : lens) expect_window_exact(t, c.grid, first, len, c.name);
    expect_window_exact(t, c.grid, c.grid.count - 9, 9, c.name);
  }
}

TEST(RenderExact, EncodersMatchPerSampleRules) {
  std::vector<double> a = {0.0,
                           -0.0,
                           1.0,
                           0.5,
                           -1e-300,
                           1e-300,
                           0.999999,
                           1.0000001,
                           2.0,
                           -3.0,
                           0.5 / 65535.0,
                           1.5 / 65535.0,
                           0.49999999 / 65535.0,
                           65534.5 / 65535.0,
                           std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::denorm_min()};
  for (int i = 0; i < 1000; ++i) a.push_back(std::fmod(i * 0.6180339887498949, 1.3) - 0.1);
  for (std::size_t n = 0; n <= a.size(); n += (n < 40 ? 1 : 97)) {  // every tail length
    const std::span<const double> in(a.data(), n);
    std::vector<std::uint16_t> u(n);
    std::vector<float> f(n);
    encode_u16(in, u);
    encode_f32(in, f);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(u[i], to_u16(a[i])) << "encode_u16 of " << a[i];
      const double clamped = a[i] > 0.0 ? (a[i] < 1.0 ? a[i] : 1.0) : 0.0;
      ASSERT_EQ(std::bit_cast<std::uint32_t>(f[i]), std::bit_cast<std::uint32_t>(static_cast<float>(clamped)))
          << "encode_f32 of " << a[i];
    }
  }
}

}  // namespace
}  // namespace texel
