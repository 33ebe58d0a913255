// The real-time player: analytic spectra, interpolation, prediction, ramps,
// crossfades, regions, off-surface positions; finger sources and measures;
// file sinks and the null backend; who may outlive whom (player vs backend).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <numbers>
#include <numeric>
#include <thread>

#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/finger.hpp"
#include "texel/player.hpp"
#include "texel/signal.hpp"
#include "texel/sinks.hpp"
#include "texel/spsc_queue.hpp"

using namespace texel;

namespace {

constexpr double pi = std::numbers::pi;

std::unique_ptr<const PlayerMap> make_map(double length_mm, double spacing_mm, const std::function<double(double)>& f) {
  Grid g{Millimetres(0.0), Millimetres(spacing_mm), static_cast<std::int64_t>(std::llround(length_mm / spacing_mm))};
  std::vector<float> v(static_cast<std::size_t>(g.count));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(f(g.position(static_cast<std::int64_t>(i)).value()));
  return std::make_unique<const PlayerMap>(g, std::move(v));
}

std::vector<FingerSample> line(double t0, double t1, double x0, double v, double rate, bool touch = true) {
  std::vector<FingerSample> s;
  for (double t = t0; t <= t1 + 1e-12; t += 1.0 / rate) s.push_back({t, x0 + v * (t - t0), touch});
  return s;
}

float max_step(std::span<const float> y, std::size_t from = 0, std::size_t to = SIZE_MAX) {
  float m = 0;
  for (std::size_t i = std::max<std::size_t>(from, 1); i < std::min(to, y.size()); ++i)
    m = std::max(m, std::fabs(y[i] - y[i - 1]));
  return m;
}

}  // namespace

// ------------------------------------------------------------------ queue

TEST(SpscQueue, FifoFullEmpty) {
  SpscQueue<int> q(4);
  EXPECT_EQ(q.capacity(), 4u);
  int v = 0;
  EXPECT_FALSE(q.try_pop(v));
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(q.try_push(i));
  EXPECT_FALSE(q.try_push(9));
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(q.try_pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_EQ(q.front(), nullptr);
}

TEST(SpscQueue, CapacityIsAPowerOfTwoChosenAtConstruction) {
  for (std::size_t bad : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{100}, SpscQueue<int>::max_capacity * 2})
    EXPECT_THROW(SpscQueue<int>{bad}, InvalidArgument) << bad;
  SpscQueue<int> q(1024);
  int pushed = 0;
  while (q.try_push(pushed)) ++pushed;
  EXPECT_EQ(pushed, 1024);
  EXPECT_EQ(q.size(), 1024u);
}

TEST(SpscQueue, TwoThreadsKeepOrder) {
  SpscQueue<std::uint64_t> q(64);
  constexpr std::uint64_t n = 50000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < n;) {
      if (q.try_push(i))
        ++i;
      else
        std::this_thread::yield();  // 2 shared cores: do not starve the consumer
    }
  });
  std::uint64_t expect = 0, v = 0;
  while (expect < n) {
    if (q.try_pop(v)) {
      ASSERT_EQ(v, expect++);
    } else {
      std::this_thread::yield();
    }
  }
  producer.join();
}

// --------------------------------------------------------------- spectra

TEST(Player, PureFiveCpmAt100MmPerSecondIs500Hz) {
  // a(x) = (1 + sin 2π·5x)/2 over 300 mm; a constant 100 mm/s swipe feels 500 Hz.
  auto map = make_map(300, 0.005, [](double x) { return 0.5 + 0.5 * std::sin(2 * pi * 5 * x); });
  const auto trace = line(0.0, 2.5, 10.0, 100.0, 1000.0);
  for (OutputMode mode : {OutputMode::amplitude, OutputMode::vibration}) {
    PlayerConfig c;
    c.rate_hz = 48000;
    c.mode = mode;
    const auto out = render_trace(*map, c, trace, 2 * 48000);
    const auto spec = signal_spectrum(std::span(out).subspan(4800), c.rate_hz);
    const double bin = spec.frequency_hz[1];
    EXPECT_NEAR(spec.peak_hz(50.0), 500.0, bin) << to_string(mode);
  }
}

TEST(Player, VibrationIsZeroMeanAndBounded) {
  auto map = make_map(300, 0.005, [](double x) { return 0.7 + 0.3 * std::sin(2 * pi * 3 * x); });
  PlayerConfig c;
  c.mode = OutputMode::vibration;
  const auto out = render_trace(*map, c, line(0, 2, 5, 100, 1000), 96000);
  const double mean = std::accumulate(out.begin() + 9600, out.end(), 0.0) / static_cast<double>(out.size() - 9600);
  EXPECT_LT(std::fabs(mean), 0.01);
  for (float y : out) ASSERT_LE(std::fabs(y), 1.0f);
  // Unit gain: 0.3 sin → amplitude 0.3 in the pass band.
  const auto spec = signal_spectrum(std::span(out).subspan(9600), c.rate_hz);
  const double peak = *std::max_element(spec.magnitude.begin(), spec.magnitude.end());
  EXPECT_NEAR(peak, 0.3, 0.015);
}

TEST(Player, CarrierIsAmplitudeModulatedSine) {
  auto map = make_map(300, 0.01, [](double) { return 1.0; });
  PlayerConfig c;
  c.mode = OutputMode::carrier;
  c.carrier_hz = 1000;
  const auto out = render_trace(*map, c, line(0, 1, 5, 100, 1000), 48000);
  const auto spec = signal_spectrum(std::span(out).subspan(4800), c.rate_hz);
  EXPECT_NEAR(spec.peak_hz(), 1000.0, spec.frequency_hz[1]);
  EXPECT_NEAR(*std::max_element(out.begin() + 4800, out.end()), 1.0f, 1e-3);
}

// ------------------------------------------------------- finger handling

TEST(Player, InterpolatesPositionsBetweenSamples) {
  // Samples at 100 Hz with a changing speed; every output position must lie
  // on the straight line between the two samples around it.
  std::vector<FingerSample> trace;
  for (int k = 0; k <= 100; ++k) {
    const double t = k / 100.0;
    trace.push_back({t, 10 + 20 * t + 15 * t * t, true});
  }
  auto map = make_map(100, 0.01, [](double) { return 0.5; });
  PlayerConfig c;
  c.rate_hz = 8000;
  std::vector<float> pos;
  render_trace(*map, c, trace, 7999, &pos);
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const double t = static_cast<double>(i) / c.rate_hz;
    const auto k = static_cast<std::size_t>(std::floor(t * 100.0 + 1e-9));
    const auto& a = trace[k];
    const auto& b = trace[std::min(k + 1, trace.size() - 1)];
    const double expect = b.t_s > a.t_s ? a.x_mm + (b.x_mm - a.x_mm) * (t - a.t_s) / (b.t_s - a.t_s) : a.x_mm;
    ASSERT_NEAR(pos[i], expect, 1e-4) << "t=" << t;
  }
}

TEST(Player, PredictorCompensatesLatency) {
  // Real-time feed: a 1 kHz sensor whose samples reach the player only once
  // their time has passed. With a 20 ms look-ahead the played position
  // tracks where the finger is 20 ms later (constant speed: exactly).
  auto map = make_map(200, 0.01, [](double) { return 0.5; });
  PlayerConfig c;
  c.rate_hz = 48000;
  c.prediction_s = 0.02;
  c.extrapolate_s = 0.03;
  Player p(c, std::make_unique<const PlayerMap>(*map));
  std::vector<float> out(48), pos(48);
  std::size_t next = 0;
  const auto trace = line(0, 1, 10, 100, 1000);
  double worst = 0;
  for (int b = 0; b < 900; ++b) {
    const double now = p.time_s();
    while (next < trace.size() && trace[next].t_s <= now) p.push(trace[next++]);
    p.process(out, pos);
    if (b > 100)
      for (std::size_t i = 0; i < pos.size(); ++i) {
        const double t = now + static_cast<double>(i) / c.rate_hz;
        worst = std::max(worst, std::fabs(pos[i] - (10 + 100 * (t + 0.02))));
      }
  }
  EXPECT_LT(worst, 0.02);  // mm; float positions
}

TEST(Player, TouchAndLiftRampWithoutClicks) {
  auto map = make_map(100, 0.01, [](double) { return 1.0; });
  PlayerConfig c;
  c.rate_hz = 48000;
  c.touch_ramp_s = 0.005;
  std::vector<FingerSample> trace{{0.0, 10, false}, {0.1, 10, true}, {0.3, 30, true}, {0.30001, 30, false}};
  const auto out = render_trace(*map, c, trace, 24000);
  // Raised-cosine ramp of N samples: largest step π/(2N) of the full scale.
  const float bound = static_cast<float>(pi / (2 * c.touch_ramp_s * c.rate_hz)) * 1.01f;
  EXPECT_LE(max_step(out), bound);
  EXPECT_EQ(out[4799], 0.0f);                     // before touch
  EXPECT_NEAR(out[4800 + 240 + 10], 1.0f, 1e-6);  // fully on after the ramp
  EXPECT_EQ(out.back(), 0.0f);                    // at rest after lift
  // Vibration mode over a textured map: lift and touch stay within the same bound plus the texture's own slope.
  auto tex = make_map(100, 0.005, [](double x) { return 0.5 + 0.5 * std::sin(2 * pi * 2 * x); });
  c.mode = OutputMode::vibration;
  const auto vib = render_trace(*tex, c, trace, 24000);
  const float texture_step = static_cast<float>(2 * pi * 2 * 100 / c.rate_hz);  // 2·0.5·2π f v / rate
  EXPECT_LE(max_step(vib), bound + texture_step);
}

TEST(Player, OffTheSurfaceIsAtRest) {
  auto map = make_map(50, 0.01, [](double) { return 0.8; });
  PlayerConfig c;
  c.rate_hz = 10000;
  // Lands at 40 mm, runs off the right end at 50 mm (0.1 s), keeps going.
  const auto out = render_trace(*map, c, line(0, 0.3, 40, 100, 1000), 3000);
  EXPECT_NEAR(out[900], 0.8f, 1e-6);
  EXPECT_EQ(out[2000], 0.0f);
  EXPECT_LE(max_step(out), static_cast<float>(pi / (2 * c.touch_ramp_s * c.rate_hz) * 0.8 * 1.01));
  // Left of the surface: never touches.
  const auto left = render_trace(*map, c, line(0, 0.1, -20, 10, 1000), 1000);
  EXPECT_EQ(*std::max_element(left.begin(), left.end()), 0.0f);
}

TEST(Player, RegionBoundaryMatchesTheSurfaceMap) {
  // tpad's layout: a different texture on each half; the player's output is
  // each region's texture at the finger across the boundary at 50.88 mm
  // (evaluated texel by texel: nothing is faded at 50 mm/s and 48 kHz), and
  // with the band limit off the surface map, linearly interpolated.
  Document doc = make_document(load_device("tpad"), TexelSpec{});
  doc.regions.clear();
  RegionSpec left, right;
  left.name = "left";
  left.length = Millimetres(50.88);
  left.texel.central_pitch = Decibels(5);
  right.name = "right";
  right.start = Millimetres(50.88);
  right.length = Millimetres(50.88);
  right.texel.central_pitch = Decibels(15);
  right.texel.seed = 7;
  doc.regions = {left, right};
  const Surface surface = prepare_surface(doc);
  const auto map = PlayerMap::from_surface(surface);
  const std::vector<double> ref = surface.render();
  PlayerConfig c;
  c.rate_hz = 48000;
  std::vector<float> pos;
  const auto out = render_trace(*map, c, line(0, 0.2, 45, 50, 1000), 9600, &pos);
  c.band_limit = BandLimit::off;
  const auto lerp = render_trace(*map, c, line(0, 0.2, 45, 50, 1000), 9600);
  for (std::size_t i = 1000; i < out.size(); ++i) {
    const double x = 45 + 50 * static_cast<double>(i) / c.rate_hz;
    ASSERT_NEAR(pos[i], x, 1e-4);
    const Region& r = surface.regions()[x < 50.88 ? 0 : 1];
    ASSERT_NEAR(out[i], r.texture->sample(Millimetres(x - r.start.value())), 1e-5) << "x=" << x;
    const double u = x / surface.grid().spacing.value();
    const auto k = static_cast<std::size_t>(u);
    const double expect = ref[k] + (ref[k + 1] - ref[k]) * (u - static_cast<double>(k));
    ASSERT_NEAR(lerp[i], expect, 1e-5) << "x=" << x;
  }
  // Both textures are felt: 3.16 cpm and 31.6 cpm at 50 mm/s.
  const auto before = signal_spectrum(std::span(out).subspan(1000, 4000), c.rate_hz);
  const auto after = signal_spectrum(std::span(out).subspan(9600 - 2400), c.rate_hz);
  EXPECT_NEAR(before.peak_hz(50), 158, 40);
  EXPECT_NEAR(after.peak_hz(50), 1581, 100);
}

TEST(Player, CrossfadesOnSwapAndRetiresTheOldMap) {
  PlayerConfig c;
  c.rate_hz = 48000;
  c.crossfade_s = 0.02;
  Player p(c, make_map(100, 0.01, [](double) { return 0.2; }));
  p.push({0.0, 50, true});
  std::vector<float> out(64), all;
  for (int b = 0; b < 100; ++b) {
    if (b == 50) p.set_map(make_map(100, 0.01, [](double) { return 0.8; }));
    p.process(out);
    all.insert(all.end(), out.begin(), out.end());
  }
  EXPECT_NEAR(all[3199], 0.2f, 1e-6);
  EXPECT_NEAR(all.back(), 0.8f, 1e-6);
  const float bound = static_cast<float>(pi / (2 * c.crossfade_s * c.rate_hz) * 0.6 * 1.01);
  EXPECT_LE(max_step(all, 3200), bound);
  for (std::size_t i = 3201; i < all.size(); ++i) ASSERT_GE(all[i], all[i - 1] - 1e-7f);  // monotonic
  EXPECT_EQ(p.collect(), 1u);
}

TEST(Player, RapidSwapsCoalesceAndNeverLeak) {
  PlayerConfig c;
  Player p(c);
  p.push({0.0, 5, true});
  std::vector<float> out(64);
  for (int i = 0; i < 200; ++i) {
    p.set_map(make_map(10, 0.01, [i](double) { return (i % 10) / 10.0; }));
    p.process(out);
  }
  for (int i = 0; i < 100; ++i) p.process(out);
  p.collect();
  EXPECT_NEAR(out.back(), 0.9f, 1e-6);
}

TEST(Player, GainChangesAreRampedOverOneBlock) {
  PlayerConfig c;
  Player p(c, make_map(100, 0.01, [](double) { return 1.0; }));
  p.push({0.0, 50, true});
  std::vector<float> out(64);
  for (int b = 0; b < 20; ++b) p.process(out);
  p.set_gain(0.5);
  p.process(out);
  EXPECT_NEAR(out.front(), 1.0f - 0.5f / 64, 1e-5);
  EXPECT_NEAR(out.back(), 0.5f, 1e-5);
  EXPECT_LE(max_step(out), 0.5f / 64 + 1e-6f);
  p.set_gain(7.0);  // clamped, not thrown
  p.process(out);
  EXPECT_NEAR(out.back(), 1.0f, 1e-5);
}

// The display's frequency response (player.hpp, [choice] limit): content the
// display cannot reproduce is not driven; its pass band is untouched.
TEST(Player, ResponseLimitAttenuatesWhatTheDisplayCannotReproduce) {
  // Amplitude 0.4 around 0.5 of a sinusoid at f·v Hz; the output's amplitude
  // at that frequency, measured after the touch-down.
  auto gain = [](double f_hz, ResponseHandling h, OutputMode mode) {
    const double f_cpm = f_hz / 100.0;  // at 100 mm/s
    auto map = make_map(120, 0.001, [&](double x) { return 0.5 + 0.4 * std::sin(2 * pi * f_cpm * x); });
    PlayerConfig c;
    c.rate_hz = 48000;
    c.mode = mode;
    c.response.corner = Hertz(400.0);  // tpad: first order, 400 Hz → limit (20 dB down) at 3.98 kHz
    c.response.order = 1;
    c.response_handling = h;
    c.band_limit = BandLimit::off;  // the response's filter alone (the band limit would remove 12 kHz)
    const auto out = render_trace(*map, c, line(0.0, 0.6, 5.0, 100.0, 1000.0), 24000);
    double s = 0, cc = 0;  // single-bin DFT over whole periods after 0.1 s
    const std::size_t from = 4800, n = 19200;
    for (std::size_t i = from; i < from + n; ++i) {
      const double t = static_cast<double>(i) / c.rate_hz;
      s += out[i] * std::sin(2 * pi * f_hz * t);
      cc += out[i] * std::cos(2 * pi * f_hz * t);
    }
    return 2.0 * std::hypot(s, cc) / static_cast<double>(n) / 0.4;
  };
  EXPECT_NEAR(response_limit_hz([] {
                PlayerConfig c;
                c.response.corner = Hertz(400.0);
                return c;
              }()),
              3980.0, 1.0);
  for (OutputMode mode : {OutputMode::amplitude, OutputMode::vibration}) {
    // Pass band (200 Hz, below the 400 Hz corner): within 0.1 dB of off.
    const double pass = gain(200.0, ResponseHandling::limit, mode) / gain(200.0, ResponseHandling::off, mode);
    EXPECT_NEAR(20 * std::log10(pass), 0.0, 0.1);
    // At the corner: within 0.2 dB (the limit is ten times higher).
    const double corner = gain(400.0, ResponseHandling::limit, mode) / gain(400.0, ResponseHandling::off, mode);
    EXPECT_NEAR(20 * std::log10(corner), 0.0, 0.2);
    // 12 kHz, where the display passes 3 %: the Butterworth at 3.98 kHz takes
    // 19.2 dB off (asserted 15 … 23 dB).
    const double stop = gain(12000.0, ResponseHandling::limit, mode) / gain(12000.0, ResponseHandling::off, mode);
    EXPECT_LT(20 * std::log10(stop), -15.0);
    EXPECT_GT(20 * std::log10(stop), -23.0);
  }
  // Amplitude output stays in [0, 1] (the filter's overshoot is clipped).
  {
    auto steps = make_map(120, 0.001, [](double x) { return std::fmod(x, 2.0) < 1.0 ? 0.0 : 1.0; });
    PlayerConfig c;
    c.response.corner = Hertz(400.0);
    const auto out = render_trace(*steps, c, line(0.0, 0.5, 5.0, 100.0, 1000.0), 24000);
    for (float y : out) ASSERT_TRUE(y >= 0.0f && y <= 1.0f) << y;
  }
  // Not applied when the limit is above 0.45·rate (the tpad's 8,333 Hz
  // refresh: 3.98 kHz > 3.75 kHz), or for a flat response.
  PlayerConfig slow;
  slow.rate_hz = 8333;
  slow.response.corner = Hertz(400.0);
  EXPECT_EQ(response_limit_hz(slow), 0.0);
  EXPECT_EQ(response_limit_hz(PlayerConfig{}), 0.0);
  // Off and flat give the bytes of a player without a response.
  auto map = make_map(50, 0.005, [](double x) { return 0.5 + 0.4 * std::sin(2 * pi * 30 * x); });
  PlayerConfig plain;
  PlayerConfig off = plain;
  off.response.corner = Hertz(400.0);
  off.response_handling = ResponseHandling::off;
  const auto trace = line(0.0, 0.2, 5.0, 100.0, 1000.0);
  EXPECT_EQ(render_trace(*map, plain, trace, 4800), render_trace(*map, off, trace, 4800));
}

// A map made for a device carries its response (PlayerMap::from_document):
// the player respects it in place of the config's, and switches at the swap.
TEST(Player, ResponseTravelsWithTheMap) {
  FrequencyResponse tpad;
  tpad.corner = Hertz(400.0);
  auto wave = [](double x) { return 0.5 + 0.4 * std::sin(2 * pi * 100 * x); };  // 10 kHz at 100 mm/s
  auto base = make_map(60, 0.001, wave);
  const auto with = [&](std::optional<FrequencyResponse> r) {
    return std::make_unique<const PlayerMap>(base->grid(), std::vector<float>(base->values().begin(), base->values().end()),
                                             std::move(r));
  };
  const auto trace = line(0.0, 0.3, 5.0, 100.0, 1000.0);
  PlayerConfig config_tpad;
  config_tpad.mode = OutputMode::vibration;
  config_tpad.response = tpad;
  PlayerConfig config_flat = config_tpad;
  config_flat.response = {};
  // The map's response in place of the config's: the same bytes both ways.
  EXPECT_EQ(render_trace(*with(tpad), config_flat, trace, 9600), render_trace(*base, config_tpad, trace, 9600));
  EXPECT_EQ(render_trace(*with(FrequencyResponse{}), config_tpad, trace, 9600), render_trace(*base, config_flat, trace, 9600));
  // Off ignores it.
  PlayerConfig off = config_flat;
  off.response_handling = ResponseHandling::off;
  EXPECT_EQ(render_trace(*with(tpad), off, trace, 9600), render_trace(*base, config_flat, trace, 9600));
  EXPECT_THROW(with(FrequencyResponse{Hertz(-1.0), 1, {}}), InvalidArgument);

  // Swapped while playing: flat → tpad → flat, 0.1 s each, RMS of the last 0.06 s of each.
  Player p(config_flat, with(FrequencyResponse{}));
  for (const auto& s : trace) ASSERT_TRUE(p.push(s));
  std::vector<double> rms;
  std::vector<float> out(4800);
  for (int k = 0; k < 3; ++k) {
    if (k > 0) p.set_map(with(k == 1 ? std::optional(tpad) : std::optional(FrequencyResponse{})));
    p.process(std::span(out).first(1920));
    p.process(std::span(out).subspan(1920, 2880));
    double sum = 0;
    for (std::size_t i = 1920; i < out.size(); ++i) sum += static_cast<double>(out[i]) * out[i];
    rms.push_back(std::sqrt(sum / 2880.0));
  }
  EXPECT_GT(rms[0], 0.1);
  EXPECT_LT(20 * std::log10(rms[1] / rms[0]), -12.0);  // the 3.98 kHz Butterworth at 10 kHz: −16 dB
  EXPECT_NEAR(20 * std::log10(rms[2] / rms[0]), 0.0, 0.5);
  p.collect();
}

TEST(Player, ConfigIsValidated) {
  PlayerConfig c;
  c.rate_hz = 10;
  EXPECT_THROW(Player{c}, InvalidArgument);
  c = {};
  c.crossfade_s = 0;
  EXPECT_THROW(validate(c), InvalidArgument);
  c = {};
  c.lowpass_hz = 30000;
  EXPECT_THROW(validate(c), InvalidArgument);
  for (std::size_t n : {std::size_t{0}, std::size_t{8}, std::size_t{1000}, std::size_t{1} << 21}) {
    c = {};
    c.event_capacity = n;
    EXPECT_THROW(Player{c}, InvalidArgument) << n;
  }
  EXPECT_THROW(parse_output_mode("loud"), InvalidArgument);
  c = {};
  c.response_limit_db = 1.0;
  EXPECT_THROW(validate(c), InvalidArgument);
  c = {};
  c.response.corner = Hertz(-3.0);
  EXPECT_THROW(validate(c), InvalidArgument);
  c = {};
  c.response.corner = Hertz(400.0);
  c.response.order = 0;
  EXPECT_THROW(validate(c), InvalidArgument);
  EXPECT_EQ(parse_response_handling("off"), ResponseHandling::off);
  EXPECT_THROW(parse_response_handling("equalize"), InvalidArgument);
  EXPECT_THROW(PlayerMap(Grid{Millimetres(0), Millimetres(0.1), 3}, std::vector<float>(2)), InvalidArgument);
}

TEST(Player, EventCapacityIsChosenAtPrepare) {
  PlayerConfig c;
  c.event_capacity = 64;
  Player p(c);
  EXPECT_EQ(p.event_capacity(), 64u);
  std::size_t queued = 0;
  while (p.push({static_cast<double>(queued) * 1e-3, 1.0, true})) ++queued;
  EXPECT_EQ(queued, 64u);
  EXPECT_FALSE(p.set_gain(0.5));
  EXPECT_EQ(p.event_space(), 0u);
  std::vector<float> out(64);
  p.process(out);  // 64 samples at 48 kHz: consumes the samples due by then
  EXPECT_GT(p.event_space(), 0u);
  EXPECT_EQ(Player(PlayerConfig{}).event_capacity(), 4096u);
}

// -------------------------------------------------------- finger sources

TEST(Finger, ConstantSwipeAndMeasures) {
  SwipeConfig s;
  s.speed_mm_s = 100;
  s.surface_mm = 101.76;
  s.duration_s = 3;
  const auto trace = simulate_swipe(s);
  const SwipeMeasures m = swipe_measures(trace);
  EXPECT_NEAR(m.mean_speed_mm_s, 100, 1e-6);
  EXPECT_NEAR(m.sd_speed_mm_s, 0, 1e-6);
  EXPECT_DOUBLE_EQ(m.directional_proportion, 1.0);
  // Lifts at the far end and lands again at the start.
  EXPECT_FALSE(trace[1050].touch);
  EXPECT_TRUE(trace[1200].touch);
}

TEST(Finger, BackAndForthTurnsSmoothly) {
  SwipeConfig s;
  s.pattern = SwipePattern::back_and_forth;
  s.speed_mm_s = 100;
  s.start_mm = 10;
  s.extent_mm = 80;
  s.turn_s = 0.1;
  s.duration_s = 10;
  const auto trace = simulate_swipe(s);
  double lo = 1e9, hi = -1e9, max_acc = 0;
  for (std::size_t i = 2; i < trace.size(); ++i) {
    lo = std::min(lo, trace[i].x_mm);
    hi = std::max(hi, trace[i].x_mm);
    const double a = (trace[i].x_mm - 2 * trace[i - 1].x_mm + trace[i - 2].x_mm) * 1e6;
    max_acc = std::max(max_acc, std::fabs(a));
  }
  EXPECT_NEAR(lo, 10, 1e-4);
  EXPECT_NEAR(hi, 90, 1e-3);
  EXPECT_LT(max_acc, 1.05 * pi * 100 / 0.1);  // peak π·v/turn mm/s²
  const SwipeMeasures m = swipe_measures(trace);
  EXPECT_NEAR(m.directional_proportion, 0.0, 0.02);
  EXPECT_GT(m.sd_speed_mm_s, 5);
  EXPECT_LT(m.mean_speed_mm_s, 100);
  EXPECT_GT(m.mean_speed_mm_s, 80);
}

TEST(Finger, MeasuresSkipLiftedIntervalsAndStillSamples) {
  std::vector<FingerSample> t{{0, 0, true}, {1, 10, true}, {2, 10, true}, {3, 0, true}, {4, 50, false}, {5, 60, false}};
  const SwipeMeasures m = swipe_measures(t, 1.0);
  EXPECT_EQ(m.intervals, 3u);
  EXPECT_EQ(m.moving_right, 1u);
  EXPECT_EQ(m.moving_left, 1u);
  EXPECT_NEAR(m.mean_speed_mm_s, 20.0 / 3, 1e-12);
  EXPECT_DOUBLE_EQ(m.directional_proportion, 0.0);
  EXPECT_EQ(swipe_measures(std::vector<FingerSample>{}).intervals, 0u);
}

TEST(Finger, TraceCsvRoundTripAndErrors) {
  SwipeConfig s;
  s.surface_mm = 50;
  s.duration_s = 0.05;
  s.lead_in_s = 0.01;
  const auto trace = simulate_swipe(s);
  const auto back = parse_trace_csv(trace_csv(trace), "t.csv");
  ASSERT_EQ(back.size(), trace.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].t_s, trace[i].t_s);
    EXPECT_EQ(back[i].x_mm, trace[i].x_mm);
    EXPECT_EQ(back[i].touch, trace[i].touch);
  }
  EXPECT_EQ(parse_trace_csv("0,1\n0.1,2\n", "x").size(), 2u);  // touch defaults to 1
  EXPECT_THROW(parse_trace_csv("", "x"), FormatError);
  EXPECT_THROW(parse_trace_csv("0,1\n-1,2\n", "x"), FormatError);  // time goes back
  EXPECT_THROW(parse_trace_csv("0,1,3\n", "x"), FormatError);      // touch not 0/1
  EXPECT_THROW(parse_trace_csv("0,1\n1,abc\n", "x"), FormatError);
  EXPECT_THROW(parse_trace_csv("0,1,1,1\n", "x"), FormatError);
  EXPECT_THROW(parse_trace_csv("0,nan\n", "x"), FormatError);
  SwipeConfig bad;
  bad.speed_mm_s = 0;
  bad.surface_mm = 10;
  EXPECT_THROW(simulate_swipe(bad), InvalidArgument);
  EXPECT_THROW(parse_swipe_pattern("zigzag"), InvalidArgument);
}

// ----------------------------------------------------------------- sinks

TEST(Sinks, WavRoundTripIsAtomic) {
  const auto dir = std::filesystem::temp_directory_path() / ("texel-wav-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::vector<float> s(4800);
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = 0.5f * std::sin(2 * pi * 440 * i / 48000.0);
  const std::string path = (dir / "a.wav").string();
  write_wav(path, s, 48000, WavEncoding::float32);
  const Recording rec = read_recording(path);
  const auto& back = rec.samples;
  EXPECT_EQ(rec.rate.value(), 48000);
  ASSERT_EQ(back.size(), s.size());
  for (std::size_t i = 0; i < s.size(); ++i) ASSERT_EQ(back[i], s[i]);
  write_wav(path, s, 48000);  // pcm16 over the old file
  EXPECT_NEAR(read_recording(path).samples[100], s[100], 1.0 / 32768);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);  // no temporaries left
  EXPECT_THROW(write_wav((dir / "no" / "b.wav").string(), s, 48000), IoError);
  std::filesystem::remove_all(dir);
}

TEST(Sinks, SignalCsvHasOneRowPerSample) {
  const std::vector<float> pos{1, 2}, out{0.25f, 0.5f};
  EXPECT_EQ(signal_csv(1000, pos, out), "time_s,position_mm,output\n0,1,0.25\n0.001,2,0.5\n");
}

TEST(Sinks, NullBackendRunsInRealTime) {
  PlayerConfig c;
  Player p(c, make_map(100, 0.01, [](double) { return 0.5; }));
  p.push({0.0, 10, true});
  auto backend = make_null_backend(48000, 64);
  backend->start(p);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  backend->stop();
  const BackendStats s = backend->stats();
  EXPECT_GT(s.blocks, 50u);
  EXPECT_LT(s.blocks, 400u);
  EXPECT_GT(s.worst_block_s, 0.0);
  EXPECT_TRUE(s.touching);
}

// ---------------------------------------------------------------- lifetime
// player.hpp, "Lifetime": a backend and the player it drives may be
// destroyed in either order. Run under ASan (make test-asan) a dangling
// process() call would be a heap-use-after-free.

// The queues' rings live on the heap, so a Player fits on any thread's stack
// (it was 160 KiB with its 4096-event ring inline).
static_assert(sizeof(Player) <= 1024, "a Player must stay small enough for any stack");

TEST(PlayerLifetime, PlayerIsSmallAndLivesOnTheStack) {
  EXPECT_LE(sizeof(Player), 1024u);
  PlayerConfig c;
  c.event_capacity = 1 << 20;  // a large queue costs heap, not stack
  Player p(c, make_map(100, 0.01, [](double) { return 0.5; }));
  EXPECT_EQ(p.event_capacity(), std::size_t{1} << 20);
  p.push({0.0, 10, true});
  std::vector<float> out(480);
  EXPECT_GT(p.process(out).peak, 0.0f);
}

TEST(PlayerLifetime, BackendDestroyedFirstLeavesThePlayerUsable) {
  Player p(PlayerConfig{}, make_map(100, 0.01, [](double) { return 0.5; }));
  p.push({0.0, 10, true});
  {
    auto backend = make_null_backend(48000, 64);
    backend->start(p);
    EXPECT_TRUE(p.attached());
    EXPECT_EQ(backend->player(), &p);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }  // destroyed while running: stops its thread, then detaches
  EXPECT_FALSE(p.attached());
  const std::uint64_t n = p.samples();
  EXPECT_GT(n, 0u);
  std::vector<float> out(64);
  p.process(out);  // this thread may drive it now
  EXPECT_EQ(p.samples(), n + 64);
  auto again = make_null_backend(48000, 64);  // and a new backend may too
  again->start(p);
  EXPECT_TRUE(p.attached());
  again->stop();
  EXPECT_FALSE(p.attached());
}

TEST(PlayerLifetime, PlayerDestroyedFirstStopsTheBackend) {
  auto backend = make_null_backend(48000, 16);
  {
    auto p = std::make_unique<Player>(PlayerConfig{}, make_map(100, 0.01, [](double) { return 0.5; }));
    p->push({0.0, 10, true});
    backend->start(*p);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_EQ(backend->player(), p.get());
  }  // ~Player stops the backend's thread before freeing its maps and rings
  EXPECT_EQ(backend->player(), nullptr);
  const std::uint64_t blocks = backend->stats().blocks;
  EXPECT_GT(blocks, 0u);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(backend->stats().blocks, blocks) << "the backend still runs after its player went away";
  backend->stop();  // still safe, and the backend is reusable
  Player q(PlayerConfig{});
  backend->start(q);
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_GT(backend->stats().blocks, blocks);
}  // q goes before backend here too: stopped by ~Player, then ~Backend finds nothing to do

TEST(PlayerLifetime, OnePlayerTakesOneBackend) {
  Player p(PlayerConfig{});
  auto first = make_null_backend(48000, 64);
  auto second = make_null_backend(48000, 64);
  first->start(p);
  EXPECT_THROW(second->start(p), InvalidArgument);  // two real-time threads would break the SPSC queues
  EXPECT_EQ(second->player(), nullptr);
  EXPECT_EQ(first->player(), &p);
  // Restarting on another player releases the first.
  Player q(PlayerConfig{});
  first->start(q);
  EXPECT_EQ(first->player(), &q);
  second->start(p);
  EXPECT_EQ(second->player(), &p);
  first->start(q);  // restart on the same player
  EXPECT_EQ(first->player(), &q);
}

TEST(PlayerLifetime, ManyStartsStopsAndDestructionsInEitherOrder) {
  for (int k = 0; k < 20; ++k) {
    auto backend = make_null_backend(48000, 8);
    auto p = std::make_unique<Player>(PlayerConfig{}, make_map(10, 0.01, [](double) { return 1.0; }));
    p->push({0.0, 5, true});
    backend->start(*p);
    std::this_thread::sleep_for(std::chrono::microseconds(500 * (k % 4)));
    if (k % 2)
      p.reset();
    else
      backend.reset();
  }
}

TEST(Backends, OneSpellingForEveryFrontDoor) {
  EXPECT_EQ(parse_backend("null").kind, BackendChoice::Kind::null);
  EXPECT_EQ(parse_backend("audio").kind, BackendChoice::Kind::audio);
  const BackendChoice s = parse_backend("serial:/dev/ttyACM0");
  EXPECT_EQ(s.kind, BackendChoice::Kind::serial);
  EXPECT_EQ(s.serial_path, "/dev/ttyACM0");
  for (const char* bad : {"", "serial:", "Audio", "serial", "null "}) {
    try {
      (void)parse_backend(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const FieldError& e) {
      EXPECT_EQ(e.field(), "backend");
      EXPECT_NE(std::string(e.what()).find("allowed: null, audio, serial:PATH"), std::string::npos) << e.what();
    }
  }
  // make_backend opens what the choice names (null needs no device).
  const PlayerMap map(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f});
  BackendOptions o;
  o.rate_hz = 8000.0;
  o.block_frames = 32;
  const auto backend = make_backend(parse_backend("null"), o, map);
  Player player(PlayerConfig{});
  backend->start(player);
  backend->stop();
  EXPECT_THROW((void)make_backend(parse_backend("serial:/nonexistent/tty"), o, map), Error);
}
