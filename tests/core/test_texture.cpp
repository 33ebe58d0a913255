// The Texel texture (docs/algorithm.md §6, §7): phase continuity at texel
// boundaries, the strength formulas and their corner cases, the seed's effect
// on fine but not coarse layout, determinism and window independence, fill.
//
// Reference computations use the C library (std::sin on the exact phase), so
// an amplitude is compared with a slow, obviously-correct formula rather than
// with the renderer's own arithmetic; the tolerance 1e-12 covers std::sin's
// argument rounding for phases up to ~100 cycles (|u|·2π·2^-53 < 1e-13).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "../support/expect.hpp"
#include "../support/grids.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"
#include "texel/reference.hpp"
#include "texel/texture.hpp"

using namespace texel;

namespace {

using test_support::tpad_dx;
constexpr double tpad_nyquist = 0.5 / tpad_dx;

TexelTexture make(const TexelSpec& spec, double length_mm = 101.76) {
  return TexelTexture(spec, Millimetres(length_mm), Sampling{Grid{}, CyclesPerMm(tpad_nyquist)});
}

std::vector<double> render(const TexelTexture& t, const Grid& g) {
  std::vector<double> out(static_cast<std::size_t>(g.count));
  t.render(g, 0, out);
  return out;
}

Grid tpad_grid(double length_mm = 101.76) { return test_support::tpad_grid(length_mm); }

double ref_sin(double cycles) { return std::sin(2.0 * std::numbers::pi * cycles); }

/// c_k for a sine coarse profile, from its definition (coarse.hpp).
double ref_sine_profile(const SineProfile& p, double L, std::size_t k) {
  const double x = (static_cast<double>(k) + 0.5) * L;
  return std::clamp(0.5 + 0.5 * ref_sin(x / p.period.value() + p.phase_deg / 360.0), 0.0, 1.0);
}

struct BoundaryJumps {
  int boundaries = 0;
  int over_bound = 0;      // steps across a boundary larger than slope × spacing
  double worst_ratio = 0;  // largest step / bound
};

/// Samples the texture finely (spacing δ) across every texel boundary and
/// compares each step with the largest slope either texel can have:
/// |da/dx| <= gain·2π·f, gain = e·F/2, so a step over δ is at most
/// gain·2π·max(f_k, f_k+1)·δ. A 1e-12 allowance covers rounding.
BoundaryJumps boundary_jumps(const TexelTexture& t, double delta = 1e-4) {
  BoundaryJumps j;
  const auto& tx = t.texels();
  const double L = t.spec().texel_length.value();
  for (std::size_t k = 0; k + 1 < tx.size(); ++k) {
    const double b = static_cast<double>(k + 1) * L;
    const Grid g{Millimetres(b - 4.5 * delta), Millimetres(delta), 9};
    const auto a = render(t, g);
    const double gain = std::max(tx[k].envelope, tx[k + 1].envelope) * t.spec().fine_strength / 2.0;
    const double slope = gain * 2.0 * std::numbers::pi * std::max(tx[k].frequency.value(), tx[k + 1].frequency.value());
    const double bound = slope * delta * (1.0 + 1e-9) + 1e-12;
    double step = 0.0;
    for (std::size_t i = 0; i + 1 < a.size(); ++i) step = std::max(step, std::fabs(a[i + 1] - a[i]));
    ++j.boundaries;
    j.over_bound += step > bound;
    j.worst_ratio = std::max(j.worst_ratio, step / bound);
  }
  return j;
}

}  // namespace

struct ContinuityCase {
  double p_db;
  double i_db;
  double L;
  std::uint64_t seed;
};

class Continuity : public ::testing::TestWithParam<ContinuityCase> {};

TEST_P(Continuity, NoPhaseJumpAtTexelBoundaries) {
  const auto c = GetParam();
  TexelSpec s;
  s.central_pitch = Decibels(c.p_db);
  s.irregularity = Decibels(c.i_db);
  s.texel_length = Millimetres(c.L);
  s.seed = c.seed;
  const auto t = make(s);
  const auto j = boundary_jumps(t);
  ASSERT_GT(j.boundaries, 90);
  EXPECT_EQ(j.over_bound, 0) << "worst step is " << j.worst_ratio << " × the slope bound";
  // Continuity of the stored phases: texel k+1 starts where texel k ends.
  const auto& tx = t.texels();
  for (std::size_t k = 0; k + 1 < tx.size(); ++k) {
    const double end = tx[k].phase_cycles + tx[k].frequency.value() * c.L;
    const double d = std::fabs(tx[k + 1].phase_cycles - (end - std::floor(end)));
    ASSERT_LT(std::min(d, 1.0 - d), 1e-12) << "texel " << k;
  }
}

// The studies' textures; a high pitch near Nyquist; a low pitch whose period
// (3 mm) is far longer than a texel; long texels with a wide spread.
INSTANTIATE_TEST_SUITE_P(Textures, Continuity,
                         ::testing::Values(ContinuityCase{10, -5, 0.25, 1}, ContinuityCase{10, -5, 0.25, 2},
                                           ContinuityCase{19, 5, 0.25, 3}, ContinuityCase{-5, -15, 0.25, 4},
                                           ContinuityCase{6, 3, 1.0, 5}));

TEST(Texture, PhaseResetJumpsAtBoundaries) {
  TexelSpec s;  // P = 10 dB, I = -5 dB, L = 0.25 mm
  s.phase = PhaseMode::reset;
  const auto j = boundary_jumps(make(s));
  // Each texel starts at its own random phase: nearly every boundary jumps by
  // far more than the slope allows (a jump below the bound needs the two
  // phases within ~1e-3 cycles of matching).
  EXPECT_GT(j.over_bound, j.boundaries * 9 / 10) << j.over_bound << " of " << j.boundaries;
  EXPECT_GT(j.worst_ratio, 100.0);
  // And the same spec in continuous mode does not: the difference is the mode.
  s.phase = PhaseMode::continuous;
  EXPECT_EQ(boundary_jumps(make(s)).over_bound, 0);
}

RC_GTEST_PROP(Texture, AmplitudesObeyTheStrengthFormulas, ()) {
  TexelSpec s;
  s.coarse_strength = *rc::gen::inRange(0, 1001) / 1000.0;
  s.fine_strength = *rc::gen::inRange(0, 1001) / 1000.0;
  s.seed = *rc::gen::arbitrary<std::uint64_t>();
  s.central_pitch = Decibels(*rc::gen::inRange(-100, 190) / 10.0);
  s.irregularity = Decibels(*rc::gen::inRange(-200, 50) / 10.0);
  s.texel_length = Millimetres(*rc::gen::inRange(10, 101) / 100.0);
  SineProfile profile{Millimetres(*rc::gen::inRange(5, 200) / 10.0), static_cast<double>(*rc::gen::inRange(-360, 360))};
  s.coarse = profile;
  const double C = s.coarse_strength;
  const double F = s.fine_strength;
  const double L = s.texel_length.value();
  const auto t = make(s, 12.0);
  const auto a = render(t, tpad_grid(12.0));
  const auto& tx = t.texels();
  RC_ASSERT(!tx.empty());
  for (std::size_t k = 0; k < tx.size(); ++k) {
    const double e_ref = 1.0 - C * (1.0 - ref_sine_profile(profile, L, k));
    RC_ASSERT(std::fabs(tx[k].envelope - e_ref) <= 1e-12);
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = static_cast<double>(i) * tpad_dx;
    RC_ASSERT(a[i] >= 0.0);
    RC_ASSERT(a[i] <= 1.0);
    const std::int64_t k = t.texel_at(Millimetres(x));
    if (k < 0) {
      RC_ASSERT(a[i] == 0.0);
      continue;
    }
    const Texel& tk = tx[static_cast<std::size_t>(k)];
    const double sine = ref_sin(tk.phase_cycles + tk.frequency.value() * (x - tk.start.value()));
    const double a_ref = tk.envelope * (1.0 - F * (1.0 - sine) / 2.0);
    RC_ASSERT(std::fabs(a[i] - a_ref) <= 1e-12);
    // The fine oscillation stays under the texel's envelope and above e·(1 − F).
    RC_ASSERT(a[i] <= tk.envelope + 1e-15);
    RC_ASSERT(a[i] >= tk.envelope * (1.0 - F) - 1e-15);
  }
}

TEST(Texture, CornerCaseFineOnlyIsFullRangeSinusoid) {
  // C = 0, F = 1: a = (1 + s)/2 whatever the coarse profile.
  TexelSpec s;
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  s.coarse_strength = 0.0;
  s.fine_strength = 1.0;
  const auto t = make(s);
  const auto a = render(t, tpad_grid());
  double lo = 1.0, hi = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = static_cast<double>(i) * tpad_dx;
    const auto k = t.texel_at(Millimetres(x));
    if (k < 0) {  // past the 407 whole texels (101.75 mm): at rest
      ASSERT_GE(x, 101.75 - 1e-9);
      ASSERT_EQ(a[i], 0.0);
      continue;
    }
    const Texel& tk = t.texels()[static_cast<std::size_t>(k)];
    ASSERT_EQ(tk.envelope, 1.0);
    ASSERT_NEAR(a[i], (1.0 + ref_sin(tk.phase_cycles + tk.frequency.value() * (x - tk.start.value()))) / 2.0, 1e-12);
    lo = std::min(lo, a[i]);
    hi = std::max(hi, a[i]);
  }
  EXPECT_LT(lo, 1e-3);  // full range: the sinusoid reaches both ends
  EXPECT_GT(hi, 1.0 - 1e-3);
}

TEST(Texture, CornerCaseCoarseOnlyIsTheBareCoarseMap) {
  // C = 1, F = 0: a = c_k, constant over each texel.
  TexelSpec s;
  s.texel_length = Millimetres(0.5);
  ValuesProfile v;
  for (int k = 0; k < 20; ++k) v.values.push_back((k % 5) / 4.0);  // 0, .25, .5, .75, 1, ...
  s.coarse = v;
  s.coarse_strength = 1.0;
  s.fine_strength = 0.0;
  const auto t = make(s, 10.0);
  ASSERT_EQ(t.texels().size(), 20u);
  const auto a = render(t, tpad_grid(10.0));
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto k = t.texel_at(Millimetres(static_cast<double>(i) * tpad_dx));
    const double want = k < 0 ? 0.0 : v.values[static_cast<std::size_t>(k)];
    ASSERT_EQ(a[i], want) << "sample " << i;  // dyadic values: exact
  }
}

TEST(Texture, CornerCaseNoStrengthIsAFlatSurface) {
  // C = 0, F = 0: constant 1 over the textured span, rest beyond it.
  TexelSpec s;
  s.texel_length = Millimetres(0.3);
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  s.coarse_strength = 0.0;
  s.fine_strength = 0.0;
  const auto t = make(s, 10.0);  // 33 whole texels = 9.9 mm, then 0.1 mm at rest
  ASSERT_NEAR(t.textured_end().value(), 9.9, 1e-12);
  const auto a = render(t, tpad_grid(10.0));
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = static_cast<double>(i) * tpad_dx;
    ASSERT_EQ(a[i], x < 9.9 - 1e-9 ? 1.0 : 0.0) << "x = " << x;
  }
}

TEST(Texture, PartialFillRendersTheFinalTexel) {
  TexelSpec s;
  s.texel_length = Millimetres(0.3);
  s.fine_strength = 0.0;
  s.fill = Fill::partial_final_texel;
  const auto t = make(s, 10.0);
  EXPECT_EQ(t.texels().size(), 34u);
  EXPECT_EQ(t.textured_end().value(), 10.0);
  const auto a = render(t, tpad_grid(10.0));
  EXPECT_EQ(a.back(), 1.0);  // x = 9.9958 mm, inside the partial texel
  EXPECT_EQ(texel_count(Millimetres(10.0), Millimetres(0.3), Fill::whole_texels), 33u);
  EXPECT_EQ(texel_count(Millimetres(0.3), Millimetres(0.1), Fill::whole_texels), 3u);  // 2.9999999999999996
  EXPECT_EQ(texel_count(Millimetres(0.3), Millimetres(0.1), Fill::partial_final_texel), 3u);
}

TEST(Texture, CoarseLayoutDoesNotDependOnTheSeedButFineLayoutDoes) {
  TexelSpec s;
  s.coarse = SineProfile{Millimetres(5.0), 30.0};
  s.coarse_strength = 0.8;
  s.fine_strength = 0.6;
  s.seed = 1;
  const auto t1 = make(s);
  s.seed = 2;
  const auto t2 = make(s);
  ASSERT_EQ(t1.texels().size(), t2.texels().size());
  std::size_t freq_differ = 0;
  for (std::size_t k = 0; k < t1.texels().size(); ++k) {
    ASSERT_EQ(t1.texels()[k].envelope, t2.texels()[k].envelope) << "texel " << k;
    freq_differ += t1.texels()[k].frequency.value() != t2.texels()[k].frequency.value();
  }
  EXPECT_EQ(freq_differ, t1.texels().size());
  EXPECT_NE(t1.texels()[0].phase_cycles, t2.texels()[0].phase_cycles);
  EXPECT_NE(render(t1, tpad_grid()), render(t2, tpad_grid()));
}

TEST(Texture, SameSpecRendersIdenticalBytes) {
  TexelSpec s;
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  s.coarse_strength = 0.5;
  s.fine_strength = 0.5;
  s.seed = 77;
  const auto a = render(make(s), tpad_grid());
  const auto b = render(make(s), tpad_grid());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
}

RC_GTEST_PROP(Texture, AnyWindowEqualsTheFullRender, ()) {
  TexelSpec s;
  s.seed = *rc::gen::arbitrary<std::uint64_t>();
  s.central_pitch = Decibels(*rc::gen::inRange(-50, 195) / 10.0);
  s.irregularity = Decibels(*rc::gen::inRange(-200, 30) / 10.0);
  s.texel_length = Millimetres(*rc::gen::inRange(5, 101) / 100.0);
  s.phase = *rc::gen::element(PhaseMode::continuous, PhaseMode::reset);
  s.fill = *rc::gen::element(Fill::whole_texels, Fill::partial_final_texel);
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  s.coarse_strength = 0.5;
  const Grid g = tpad_grid();
  const auto t = make(s);
  const auto full = render(t, g);
  // Cover the grid with windows of random sizes, including size 1 and runs
  // that start and end mid-texel; then a few windows at random places.
  std::vector<double> pieced(full.size());
  std::size_t at = 0;
  while (at < full.size()) {
    const auto len = std::min<std::size_t>(*rc::gen::inRange<std::size_t>(1, 3000), full.size() - at);
    t.render(g, static_cast<std::int64_t>(at), std::span<double>(pieced.data() + at, len));
    at += len;
  }
  RC_ASSERT(std::memcmp(pieced.data(), full.data(), full.size() * sizeof(double)) == 0);
  for (int w = 0; w < 5; ++w) {
    const auto first = *rc::gen::inRange<std::size_t>(0, full.size());
    const auto len = *rc::gen::inRange<std::size_t>(1, full.size() - first + 1);
    std::vector<double> win(len);
    t.render(g, static_cast<std::int64_t>(first), win);
    RC_ASSERT(std::memcmp(win.data(), full.data() + first, len * sizeof(double)) == 0);
  }
}

TEST(Texture, OutsideTheTexturedSpanIsAtRest) {
  const auto t = make(TexelSpec{}, 10.0);
  EXPECT_EQ(t.amplitude_at(Millimetres(-0.001)), 0.0);
  EXPECT_EQ(t.amplitude_at(Millimetres(10.0)), 0.0);
  EXPECT_EQ(t.amplitude_at(Millimetres(1e9)), 0.0);
  std::vector<double> out(100, -1.0);
  t.render(Grid{Millimetres(-1.0), Millimetres(0.005), 100}, 0, out);  // positions -1 … -0.505 mm
  EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](double v) { return v == 0.0; }));
}

TEST(Texture, RejectsBadSpecsNamingTheField) {
  auto message = [](const TexelSpec& s) { return texel::test_support::message_of<InvalidArgument>([&] { make(s); }); };
  TexelSpec s;
  s.texel_length = Millimetres(-0.25);
  EXPECT_NE(message(s).find("texel_length_mm"), std::string::npos);
  s = TexelSpec{};
  s.texel_length = Millimetres(NAN);
  EXPECT_NE(message(s).find("texel_length_mm"), std::string::npos);
  s = TexelSpec{};
  s.coarse_strength = 1.5;
  EXPECT_NE(message(s).find("coarse_strength"), std::string::npos);
  s = TexelSpec{};
  s.fine_strength = -0.1;
  EXPECT_NE(message(s).find("fine_strength"), std::string::npos);
  s = TexelSpec{};
  s.central_pitch = Decibels(25.0);
  EXPECT_NE(message(s).find("outside the renderable band"), std::string::npos);
  s = TexelSpec{};
  s.coarse = SineProfile{Millimetres(0.0), 0.0};
  EXPECT_NE(message(s).find("coarse.period_mm"), std::string::npos);
}

TEST(Texture, SampleIsTheRenderersValueAtAnyPosition) {
  // sample(x) is the renderer's own value (not the slow reference path), for
  // every kind of texture and through the one prepare() signature.
  const DeviceProfile tpad = load_device("tpad");
  const Sampling sampling{tpad.grid(), tpad.band_top()};
  TexelSpec spec;
  spec.seed = 11;
  spec.coarse = SineProfile{Millimetres(7.0), 30.0};
  spec.coarse_strength = 0.3;
  ReferenceSpec pink;
  pink.name = "pink";
  ReferenceSpec patch;
  patch.name = "patch-4.6";
  const std::vector<std::shared_ptr<const Texture>> textures{
      prepare(spec, tpad.length(), sampling), prepare(pink, tpad.length(), sampling), prepare(patch, tpad.length(), sampling)};
  for (const auto& t : textures) {
    std::vector<double> map(static_cast<std::size_t>(tpad.samples));
    t->render(tpad.grid(), 0, map);
    for (std::int64_t i = 0; i < tpad.samples; i += 97)
      ASSERT_EQ(t->sample(tpad.grid().position(i)), map[static_cast<std::size_t>(i)]) << t->describe() << " sample " << i;
    EXPECT_EQ(t->sample(Millimetres(-1.0)), 0.0) << t->describe();
    EXPECT_EQ(t->sample(tpad.length() + Millimetres(1.0)), 0.0) << t->describe();
  }
}

TEST(Texture, PrepareIsTheConstructorUnderOneSignature) {
  const DeviceProfile tpad = load_device("tpad");
  const Sampling sampling{tpad.grid(), tpad.band_top()};
  TexelSpec spec;
  spec.seed = 5;
  const auto prepared = prepare(spec, Millimetres(20.0), sampling);
  const TexelTexture direct(spec, Millimetres(20.0), sampling);
  const auto* t = dynamic_cast<const TexelTexture*>(prepared.get());
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->texels().size(), direct.texels().size());
  for (std::size_t k = 0; k < direct.texels().size(); ++k)
    EXPECT_EQ(t->texels()[k].frequency.value(), direct.texels()[k].frequency.value());
  // band_top 0 means the grid's Nyquist frequency.
  EXPECT_EQ((Sampling{tpad.grid()}.top().value()), tpad.nyquist().value());
  EXPECT_EQ(sampling.top().value(), tpad.band_top().value());
}
