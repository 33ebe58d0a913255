// The player's band limit (docs/player.md "Band limit", issue #36): Texel
// regions evaluated texel by texel reproduce the rendered map; at a 1 kHz,
// 8.333 kHz and 48 kHz drive a swipe puts no energy at frequencies the
// texture does not hold at that speed (no aliases), and where nothing is
// faded its log-spectral centroid is the texture's; maps without texels are
// band-limited through their pyramid; the switch turns it all off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "texel/document.hpp"
#include "texel/player.hpp"
#include "texel/surface.hpp"

using namespace texel;

namespace {

constexpr double pi = std::numbers::pi;
constexpr double inf = std::numeric_limits<double>::infinity();

// A constant swipe at v mm/s from x0, sampled like a 1 kHz position sensor.
std::vector<FingerSample> swipe(double x0, double v, double duration_s) {
  std::vector<FingerSample> s;
  for (int k = 0; k <= static_cast<int>(std::lround(duration_s * 1000.0)); ++k) {
    const double t = k / 1000.0;
    s.push_back({t, x0 + v * t, true});
  }
  return s;
}

// A one-region tpad document of a narrow texture (SD 0.3 × the mean, as the
// texel-length study's narrow group: 4 cpm ± 1.2 cpm) at `pitch_db`.
Document narrow_document(double pitch_db, std::uint64_t seed = 3) {
  TexelSpec spec;
  spec.central_pitch = Decibels(pitch_db);
  spec.irregularity = Decibels(pitch_db + 10.0 * std::log10(0.3));
  spec.seed = seed;
  Document doc = make_document(load_device("tpad"), spec);
  doc.regions.resize(1);
  doc.regions[0].start = Millimetres(0.0);
  doc.regions[0].length = Millimetres(101.76);
  return doc;
}

// Band powers (mean-square content per band, Parseval-normalised, so a
// sinusoid of amplitude A gives A²/2) of `y` at `rate` over [edges[b], edges[b+1]).
struct Bands {
  std::vector<double> power;
  double centroid_db = 0.0;  // log-spectral centroid below `top` (10·log10 Hz)
};

Bands bands(std::span<const float> y, double rate, const std::vector<double>& edges, double top) {
  const double mean = std::accumulate(y.begin(), y.end(), 0.0) / static_cast<double>(y.size());
  std::vector<float> ac(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) ac[i] = static_cast<float>(y[i] - mean);
  const SignalSpectrum s = signal_spectrum(ac, rate);
  const double m = static_cast<double>(y.size());
  double wsum = 0, w2 = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double w = 0.5 - 0.5 * std::cos(2 * pi * static_cast<double>(i) / (m - 1));
    wsum += w, w2 += w * w;
  }
  const double n = 2.0 * static_cast<double>(s.magnitude.size() - 1);
  const double scale = wsum * wsum / (2.0 * n * w2);
  Bands b;
  b.power.assign(edges.size() - 1, 0.0);
  double p = 0, pl = 0;
  for (std::size_t k = 1; k < s.magnitude.size(); ++k) {
    const double f = s.frequency_hz[k];
    const double pk = s.magnitude[k] * s.magnitude[k] * scale;
    const auto it = std::upper_bound(edges.begin(), edges.end(), f);
    if (it != edges.begin() && it != edges.end()) b.power[static_cast<std::size_t>(it - edges.begin() - 1)] += pk;
    if (f < top) p += pk, pl += pk * std::log(f);
  }
  b.centroid_db = p > 0 ? 10.0 * std::log10(std::exp(pl / p)) : 0.0;
  return b;
}

double rms_ac(std::span<const float> y) {
  const double mean = std::accumulate(y.begin(), y.end(), 0.0) / static_cast<double>(y.size());
  double s = 0;
  for (float v : y) s += (v - mean) * (v - mean);
  return std::sqrt(s / static_cast<double>(y.size()));
}

struct AliasCheck {
  double worst_excess = 0.0;  // largest band RMS above the reference's, × texture RMS
  double worst_hz = 0.0;
  double centroid_out_db = 0.0, centroid_ref_db = 0.0;
};

// The output (rate `rate`, from `from` s on, `seconds` long) against the
// texture itself along the same path, evaluated at 2^k × the rate (at least
// 8 × and 384 kHz) without any band limit: bands of rate/80 below the output's Nyquist.
AliasCheck check_against_texture(std::span<const float> out, double rate, const PlayerMap& map, double x0, double v, double from,
                                 double seconds) {
  const auto first = static_cast<std::size_t>(std::lround(from * rate));
  const auto count = static_cast<std::size_t>(std::lround(seconds * rate));
  const std::span<const float> y = out.subspan(first, count);
  // A power-of-two multiple of the rate: both spectra then have the same
  // zero-padded length in time, so the same bins (a band's sum of a strong
  // peak's leakage is then the same in both).
  double high = 8.0 * rate;
  while (high < 384000.0) high *= 2.0;
  std::vector<float> ref(count * static_cast<std::size_t>(high / rate));
  for (std::size_t i = 0; i < ref.size(); ++i)
    ref[i] = static_cast<float>(map.band_limited(x0 + v * (from + static_cast<double>(i) / high), inf));
  std::vector<double> edges;
  for (int b = 0; b <= 40; ++b) edges.push_back(rate / 2.0 * b / 40.0);
  const double rms = rms_ac(ref);
  const Bands o = bands(y, rate, edges, rate / 2.0);
  const Bands r = bands(ref, high, edges, rate / 2.0);
  AliasCheck c;
  c.worst_excess = -inf;
  for (std::size_t b = 0; b < o.power.size(); ++b) {
    const double excess = (std::sqrt(o.power[b]) - std::sqrt(r.power[b])) / rms;
    if (excess > c.worst_excess) c.worst_excess = excess, c.worst_hz = edges[b];
  }
  c.centroid_out_db = o.centroid_db;
  c.centroid_ref_db = r.centroid_db;
  return c;
}

double max_texel_cpm(const Document& doc) {
  const Surface surface = prepare_surface(doc);
  const auto& t = dynamic_cast<const TexelTexture&>(*surface.regions()[0].texture);
  double f = 0;
  for (const Texel& k : t.texels()) f = std::max(f, k.frequency.value());
  return f;
}

void no_aliases_at(double rate);

}  // namespace

// The map keeps what TexelTexture::render computes: evaluated at every grid
// sample with nothing faded it gives the rendered map's values (float
// rounding apart), for a surface of two Texel regions with coarse profiles
// and strengths, and a reference region that has no texels.
TEST(BandLimit, TexelRegionsReproduceTheRenderedMap) {
  Document doc = make_document(load_device("tpad"), TexelSpec{});
  doc.regions.resize(3);
  RegionSpec& a = doc.regions[0];
  a.start = Millimetres(0.0);
  a.length = Millimetres(40.0);
  a.texel.central_pitch = Decibels(7.5);
  a.texel.coarse_strength = 0.6;
  a.texel.fine_strength = 0.8;
  a.texel.coarse = SineProfile{Millimetres(10.0), 30.0};
  RegionSpec& b = doc.regions[1];
  b.start = Millimetres(40.0);
  b.length = Millimetres(30.0);
  b.texel = TexelSpec{};
  b.texel.central_pitch = Decibels(19.7);
  b.texel.phase = PhaseMode::reset;
  b.texel.fill = Fill::partial_final_texel;
  b.texel.texel_length = Millimetres(0.3);
  b.texel.seed = 9;
  RegionSpec& c = doc.regions[2];
  c.start = Millimetres(75.0);
  c.length = Millimetres(20.0);
  c.reference = ReferenceSpec{};
  const Surface surface = prepare_surface(doc);
  const auto map = PlayerMap::from_surface(surface);
  EXPECT_EQ(map->texel_regions(), 2u);
  const std::vector<double> rendered = surface.render();
  double worst = 0;
  for (std::int64_t i = 0; i < surface.grid().count; ++i) {
    const double x = surface.grid().position(i).value();
    const auto k = static_cast<std::size_t>(i);
    // Texel regions: the texture's own value; a finite limit far above the
    // texture fades nothing either. Elsewhere (reference, gaps): the map.
    for (double limit : {inf, 1e6}) {
      const double got = map->band_limited(x, limit);
      worst = std::max(worst, std::fabs(got - rendered[k]));
      ASSERT_NEAR(got, rendered[k], 1e-6) << "sample " << i << " x=" << x << " limit " << limit;
    }
  }
  EXPECT_LT(worst, 1e-6);
  // from_texture keeps the texels too.
  const auto& texture = *surface.regions()[0].texture;
  const auto single = PlayerMap::from_texture(texture, Grid{Millimetres(0.0), Millimetres(0.0053), 7000});
  EXPECT_EQ(single->texel_regions(), 1u);
  for (std::size_t i = 0; i < 7000; i += 7)
    ASSERT_NEAR(single->band_limited(0.0053 * static_cast<double>(i), inf), single->values()[i], 1e-6);
  // A map of raw values has no texels: its pyramid serves.
  const PlayerMap raw(Grid{Millimetres(0.0), Millimetres(0.01), 1000}, std::vector<float>(1000, 0.25f));
  EXPECT_EQ(raw.texel_regions(), 0u);
  EXPECT_GE(raw.pyramid_levels(), 9u);
  EXPECT_NEAR(raw.band_limited(3.0, 0.01), 0.25, 1e-6);  // a constant stays itself at every level
}

// Issue #36's acceptance: textures from 0 to 19.7 dB swiped at 100 mm/s
// through the player (render_trace: `texel swipe`'s path, the real-time
// Player in 64-frame blocks) at 1 kHz, 8.333 kHz and 48 kHz. In no band
// (rate/80 wide) below the Nyquist frequency does the output carry more than
// the texture itself (evaluated at ≥ 384 kHz, no band limit) by over 1 % of
// the texture's RMS: nothing is folded down. Where the texture lies wholly
// under the pass band (0.8 × 0.45·rate at 100 mm/s: no texel is faded) its
// log-spectral centroid below Nyquist is the texture's within 0.1 dB.
namespace {

void no_aliases_at(double rate) {
  const double v = 100.0, x0 = 5.0;
  for (double pitch : {0.0, 5.0, 7.5, 10.0, 15.0, 19.7}) {
    const Document doc = narrow_document(pitch);
    const auto map = PlayerMap::from_surface(prepare_surface(doc));  // flat response: the rate's limit alone
    PlayerConfig c;
    c.rate_hz = rate;
    const auto out = render_trace(*map, c, swipe(x0, v, 0.6), static_cast<std::size_t>(0.56 * rate));
    const AliasCheck a = check_against_texture(out, rate, *map, x0, v, 0.05, 0.5);
    const bool whole = max_texel_cpm(doc) * v <= 0.8 * 0.45 * rate;
    std::printf("  %5.0f Hz, %4.1f dB: worst band %+.4f × RMS at %.0f Hz; centroid %.3f dB, texture %.3f dB%s\n", rate, pitch,
                a.worst_excess, a.worst_hz, a.centroid_out_db, a.centroid_ref_db, whole ? "" : " (texels faded)");
    const std::string what = std::to_string(pitch) + " dB at " + std::to_string(rate) + " Hz";
    EXPECT_LE(a.worst_excess, 0.01) << what << ": " << a.worst_hz << " Hz band";
    if (whole) {
      EXPECT_NEAR(a.centroid_out_db, a.centroid_ref_db, 0.1) << what;
    }
  }
}

}  // namespace

TEST(BandLimit, NoAliasesOnA1kHzDrive) { no_aliases_at(1000.0); }
TEST(BandLimit, NoAliasesOnTheTpadsRefresh) { no_aliases_at(8333.0); }
TEST(BandLimit, NoAliasesAt48kHz) { no_aliases_at(48000.0); }

// The figure: a 7.5 dB texture (5.62 cpm) at 100 mm/s on a 1 kHz
// drive was streamed at full strength at an alias; with the switch off it
// still is (the old behaviour), on it is not.
TEST(BandLimit, SwitchOffGivesTheUnlimitedMap) {
  const Document doc = narrow_document(7.5);
  const auto map = PlayerMap::from_surface(prepare_surface(doc));
  PlayerConfig c;
  c.rate_hz = 1000;
  const auto trace = swipe(5.0, 100.0, 0.9);
  c.band_limit = BandLimit::off;
  std::vector<float> pos;
  const auto off = render_trace(*map, c, trace, 850, &pos);
  for (std::size_t i = 20; i < off.size(); ++i)
    ASSERT_NEAR(off[i], map->sample(5.0 + 100.0 * static_cast<double>(i) / 1000.0), 1e-6) << i;
  const AliasCheck aliased = check_against_texture(off, 1000, *map, 5.0, 100.0, 0.05, 0.8);
  EXPECT_GT(aliased.worst_excess, 0.05);
  c.band_limit = BandLimit::on;
  const AliasCheck limited = check_against_texture(render_trace(*map, c, trace, 850), 1000, *map, 5.0, 100.0, 0.05, 0.8);
  EXPECT_LE(limited.worst_excess, 0.01);
  EXPECT_EQ(parse_band_limit("off"), BandLimit::off);
  EXPECT_EQ(to_string(BandLimit::on), "on");
  EXPECT_THROW(parse_band_limit("maybe"), InvalidArgument);
}

// A map without texels (raw values: two gratings, 1.5 and 43 cpm) swiped at
// 100 mm/s on a 1 kHz drive: 43 cpm (4.3 kHz) is removed through the
// pyramid rather than folded down to 300 Hz; 1.5 cpm (150 Hz, a third of
// the limit: within the pyramid's pass band) stays within 3 dB. Nothing
// else reaches 1 % of the texture's RMS (the levels are stored twice
// oversampled, so the cubic read's images stay far down).
TEST(BandLimit, MapsWithoutTexelsAreLimitedThroughThePyramid) {
  const auto f = [](double x) { return 0.5 + 0.2 * std::sin(2 * pi * 1.5 * x) + 0.2 * std::sin(2 * pi * 43.0 * x + 1.0); };
  Grid g{Millimetres(0.0), Millimetres(0.0053), 19200};
  std::vector<float> values(static_cast<std::size_t>(g.count));
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<float>(f(g.position(static_cast<std::int64_t>(i)).value()));
  const PlayerMap map(g, std::move(values));
  EXPECT_EQ(map.texel_regions(), 0u);
  PlayerConfig c;
  c.rate_hz = 1000;
  // Single-bin amplitudes over 0.8 s (whole periods of 150 and 300 Hz).
  auto amplitude = [&](const std::vector<float>& out, double hz) {
    double s = 0, cc = 0;
    for (std::size_t i = 50; i < 850; ++i) {
      const double t = static_cast<double>(i) / 1000.0;
      s += (out[i] - 0.5) * std::sin(2 * pi * hz * t);
      cc += (out[i] - 0.5) * std::cos(2 * pi * hz * t);
    }
    return 2.0 * std::hypot(s, cc) / 800.0;
  };
  c.band_limit = BandLimit::off;
  const auto off = render_trace(map, c, swipe(5.0, 100.0, 0.9), 850);
  EXPECT_GT(amplitude(off, 300.0), 0.1);  // 4.3 kHz folded to 300 Hz
  c.band_limit = BandLimit::on;
  const auto out = render_trace(map, c, swipe(5.0, 100.0, 0.9), 850);
  EXPECT_LT(amplitude(out, 300.0), 0.01 * 0.2);  // 1 % of the texture's RMS (0.2)
  EXPECT_GT(amplitude(out, 150.0), 0.2 * 0.708);
  EXPECT_LT(amplitude(out, 150.0), 0.2 * 1.01);
  const SignalSpectrum s = signal_spectrum(std::span(out).subspan(50, 800), 1000.0);
  for (std::size_t k = 0; k < s.magnitude.size(); ++k) {
    const double hz = s.frequency_hz[k];
    if (hz < 15.0 || std::fabs(hz - 150.0) < 15.0) continue;  // the mean's and the grating's Hann leakage
    ASSERT_LT(s.magnitude[k], 0.01 * 0.2) << hz << " Hz";
  }
}
