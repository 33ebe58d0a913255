// Multi-channel rendering (issue #40; docs/rendering.md): device profiles with
// actuators, the version-6 document's playback, the channels' draws (the
// lognormal, by KS test on 10^4 draws), a 4-channel swipe whose channels are
// single-frequency segments of the texel length, determinism, and that a
// one-channel document's swipe is the one it always was.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "../support/alloc_counter.hpp"
#include "../support/expect.hpp"
#include "texel/distribution.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/finger.hpp"
#include "texel/multichannel.hpp"
#include "texel/multichannel_player.hpp"
#include "texel/player.hpp"
#include "texel/random.hpp"
#include "texel/sinks.hpp"

namespace {

using namespace texel;
using texel::test_support::message_of;

// A pad of four actuators 2 mm apart; `samples` at 0.01 mm.
std::string pad_device(std::int64_t samples, bool last_has_response = true) {
  return R"({"name": "pad-4", "samples": )" + std::to_string(samples) +
         R"(, "spacing_mm": 0.01, "format": "f32le", "refresh_hz": 48000, "actuators": [
      {"name": "a0", "offset_mm": -3.0},
      {"name": "a1", "offset_mm": -1.0},
      {"name": "a2", "offset_mm": 1.0},
      {"name": "a3", "offset_mm": 3.0)" +
         (last_has_response ? R"(, "response": {"corner_hz": 400, "order": 2})" : "") + "}]}";
}

std::string document(
    const std::string& device, const std::string& playback, int version = 6,
    const std::string& texture =
        R"({"kind": "texel", "central_pitch_db": 10, "irregularity_db": 5, "texel_length_mm": 0.25, "seed": 40})") {
  std::string s = R"({"format": "texel-document", "version": )" + std::to_string(version) + R"(, "device": )" + device +
                  R"(, "texture": )" + texture;
  if (!playback.empty()) s += R"(, "playback": )" + playback;
  return s + "}";
}

// ------------------------------------------------------------ device profile

TEST(MultichannelDevice, ActuatorsParseAndRoundTrip) {
  const DeviceProfile d = parse_device_profile(pad_device(1000), "pad");
  ASSERT_EQ(d.channels(), 4u);
  EXPECT_EQ(d.actuators[0].name, "a0");
  EXPECT_DOUBLE_EQ(d.actuators[0].offset.value(), -3.0);
  EXPECT_FALSE(d.actuators[0].response.has_value());
  EXPECT_TRUE(d.channel_response(0).flat());
  EXPECT_DOUBLE_EQ(d.channel_response(3).corner.value(), 400.0);
  const DeviceProfile again = parse_device_profile(device_profile_json(d), "again");
  EXPECT_EQ(device_profile_json(again), device_profile_json(d));
}

TEST(MultichannelDevice, ProfilesWithoutActuatorsAreOneChannelAndWriteTheirOldText) {
  for (const auto& name : builtin_device_names()) {
    const DeviceProfile d = load_device(name);
    if (name == "pad-4") {  // the one built-in array (the distributed-irregularity study's)
      EXPECT_EQ(d.channels(), 4u);
      continue;
    }
    EXPECT_EQ(d.channels(), 1u) << name;
    EXPECT_EQ(device_profile_json(d).find("actuators"), std::string::npos) << name;
  }
}

TEST(MultichannelDevice, EveryBadActuatorFieldIsNamedWithItsValueAndRange) {
  const auto error = [](const std::string& text) { return message_of<FormatError>([&] { parse_device_profile(text, "d"); }); };
  const std::string base = R"({"name": "x", "samples": 10, "spacing_mm": 0.01, "format": "f32le", "refresh_hz": 1000, )";
  EXPECT_NE(error(base + R"("actuators": []})").find("actuators must be an array of 1 … 64 actuators, got 0 entries"),
            std::string::npos);
  EXPECT_NE(error(base + R"("actuators": {}})").find("actuators must be an array"), std::string::npos);
  EXPECT_NE(
      error(base + R"("actuators": [{"name": "a", "offset_mm": 60}]})").find("actuators[0].offset_mm is 60; allowed: -50 … 50"),
      std::string::npos);
  EXPECT_NE(error(base + R"("actuators": [{"name": "a", "offset_mm": 0, "lateral_mm": -51}]})")
                .find("actuators[0].lateral_mm is -51; allowed: -50 … 50"),
            std::string::npos);
  EXPECT_NE(error(base + R"("actuators": [{"name": "a", "offset_mm": 0}, {"name": "a", "offset_mm": 1}]})")
                .find("actuators[1].name is 'a', already the name of actuators[0]"),
            std::string::npos);
  EXPECT_NE(error(base + R"("actuators": [{"name": "", "offset_mm": 0}]})").find("actuators[0].name is ''; allowed: 1 … 64"),
            std::string::npos);
  EXPECT_NE(error(base + R"("actuators": [{"name": "a"}]})").find("actuators[0].offset_mm is missing"), std::string::npos);
  EXPECT_NE(error(base + R"("actuators": [{"name": "a", "offset_mm": 0, "gain": 1}]})").find("gain"), std::string::npos);
  EXPECT_NE(error(base + R"("actuators": [{"name": "a", "offset_mm": 0, "response": {"corner_hz": 100, "order": 9}}]})")
                .find("actuators[0].response.order is 9; allowed: 1 … 4"),
            std::string::npos);
  std::string many = base + R"("actuators": [)";
  for (int i = 0; i < 65; ++i)
    many += (i ? "," : "") + std::string(R"({"name": "a)") + std::to_string(i) + R"(", "offset_mm": 0})";
  EXPECT_NE(error(many + "]}").find("got 65 entries"), std::string::npos);
}

// ------------------------------------------------------------------ document

TEST(MultichannelDocument, PlaybackNeedsVersion6AndAValidChannel) {
  const auto error = [](const std::string& text) { return message_of<FormatError>([&] { parse_document(text, "doc"); }); };
  EXPECT_NE(error(document(pad_device(1000), R"({"mode": "simultaneous"})", 5)).find("version 5 is a 2-D document"),
            std::string::npos)
      << "a version-5 document is 2-D";
  EXPECT_NE(error(document(pad_device(1000), R"({"mode": "simultaneous"})", 3))
                .find("playback needs version 6 (multi-channel playback); version is 3"),
            std::string::npos);
  EXPECT_NE(error(document(pad_device(1000), R"({"mode": "together"})"))
                .find("playback.mode is 'together'; allowed: sequential, simultaneous"),
            std::string::npos);
  EXPECT_NE(error(document(pad_device(1000), R"({"mode": "sequential", "channel": 4})"))
                .find("playback.channel is 4; allowed: 0 … 3 (device 'pad-4' has 4 channels)"),
            std::string::npos);
  EXPECT_NE(error(document(pad_device(1000), R"({"mode": "simultaneous", "channel": 1})"))
                .find("playback.channel is 1; allowed only with mode sequential"),
            std::string::npos);
  EXPECT_NE(error(document(pad_device(1000), R"({"mode": "simultaneous"})", 6, R"({"kind": "reference", "name": "white"})"))
                .find("region 0 holds a reference texture"),
            std::string::npos);
  EXPECT_NE(error(document(pad_device(1000), R"({"mode": "simultaneous", "k": 1})")).find("playback has unknown key 'k'"),
            std::string::npos)
      << error(document(pad_device(1000), R"({"mode": "simultaneous", "k": 1})"));
}

TEST(MultichannelDocument, RoundTripsAsVersion6) {
  const Document doc = parse_document(document(pad_device(1000), R"({"mode": "sequential", "channel": 2})"));
  ASSERT_TRUE(doc.playback);
  EXPECT_EQ(doc.playback->mode, ChannelMode::sequential);
  EXPECT_EQ(doc.playback->channel, 2u);
  const std::string text = document_json(doc);
  EXPECT_NE(text.find("\"version\": 6"), std::string::npos) << text;
  EXPECT_EQ(document_json(parse_document(text)), text);
  // Without a playback the lowest version is written, as before.
  Document plain = doc;
  plain.playback.reset();
  EXPECT_NE(document_json(plain).find("\"version\": 1"), std::string::npos);
}

// ----------------------------------------------------------------- channels

TEST(MultichannelChannels, SequentialChannelsReadTheDocumentsOwnMap) {
  const Document seq = parse_document(document(pad_device(1000), ""));
  const auto channels = prepare_channels(seq);
  ASSERT_EQ(channels.size(), 4u);
  const std::vector<double> one = prepare_surface(seq).render();
  std::vector<double> all(one.size() * 4);
  render_channels(channels, 0, all);
  for (std::size_t i = 0; i < one.size(); ++i)
    for (std::size_t c = 0; c < 4; ++c) ASSERT_EQ(all[i * 4 + c], one[i]) << "sample " << i << " channel " << c;
  EXPECT_DOUBLE_EQ(channels[3].offset.value(), 3.0);
  EXPECT_DOUBLE_EQ(channels[3].response.corner.value(), 400.0);

  const auto only2 = prepare_channels(parse_document(document(pad_device(1000), R"({"mode": "sequential", "channel": 2})")));
  for (std::size_t c = 0; c < 4; ++c) EXPECT_EQ(only2[c].surface != nullptr, c == 2) << c;
}

// A one-channel player (the studio's Feel-it, the experiments' presenter, the
// C API, Python) has no one map for a simultaneous document: refused, naming
// what plays it; a sequential one plays the document's own map.
TEST(MultichannelChannels, OneChannelPlayersRefuseASimultaneousDocument) {
  const Document sim = parse_document(document(pad_device(1000), R"({"mode": "simultaneous"})"));
  EXPECT_NE(message_of<InvalidArgument>([&] { (void)PlayerMap::from_document(sim); }).find("simultaneous texels on the 4"),
            std::string::npos);
  EXPECT_NO_THROW((void)PlayerMap::from_document(parse_document(document(pad_device(1000), R"({"mode": "sequential"})"))));
}

TEST(MultichannelChannels, SimultaneousChannelDrawsArePureFunctionsOfSeedChannelAndTexel) {
  const Document doc = parse_document(document(pad_device(1000), R"({"mode": "simultaneous"})"));
  const auto channels = prepare_channels(doc);
  const PitchDistribution dist(distribution_config(doc.regions[0].texel, doc.device.band_top()));
  std::vector<std::vector<double>> f(4);
  for (std::size_t c = 0; c < 4; ++c) {
    f[c] = channel_texel_frequencies(channels[c]);
    ASSERT_EQ(f[c].size(), 40u);  // 10 mm / 0.25 mm
    for (std::size_t k = 0; k < f[c].size(); ++k)
      ASSERT_EQ(f[c][k], dist.draw(channel_seed(40, c), k)) << "channel " << c << " texel " << k;
  }
  for (std::size_t c = 1; c < 4; ++c) EXPECT_NE(f[c], f[0]) << "channel " << c << " repeats channel 0's draws";
  EXPECT_NE(channel_seed(40, 0), 40u);
  // Another seed, other draws; the same seed, the same maps (any window).
  std::vector<double> a(1000 * 4), b(1000 * 4), w(200 * 4);
  render_channels(channels, 0, a);
  render_channels(prepare_channels(doc), 0, b);
  EXPECT_EQ(a, b);
  render_channels(channels, 300, w);
  EXPECT_TRUE(std::equal(w.begin(), w.end(), a.begin() + 300 * 4));
}

// Φ and the truncated lognormal's CDF, and the Kolmogorov distribution's tail.
double phi(double z) { return 0.5 * std::erfc(-z / std::numbers::sqrt2); }
double ks_p_value(double d, std::size_t n) {
  const double sn = std::sqrt(static_cast<double>(n));
  const double lambda = (sn + 0.12 + 0.11 / sn) * d;  // Stephens' correction
  double p = 0.0;
  for (int k = 1; k <= 100; ++k) p += 2.0 * ((k % 2) ? 1.0 : -1.0) * std::exp(-2.0 * k * k * lambda * lambda);
  return std::clamp(p, 0.0, 1.0);
}

TEST(MultichannelChannels, SimultaneousFrequenciesFollowTheLognormalOver10000Draws) {
  // 4 channels × 2500 texels of 0.25 mm = 10^4 draws, pooled over channels and position.
  const Document doc = parse_document(document(pad_device(62500), R"({"mode": "simultaneous"})"));
  const auto channels = prepare_channels(doc);
  std::vector<double> f;
  for (const auto& c : channels) {
    const auto fc = channel_texel_frequencies(c);
    f.insert(f.end(), fc.begin(), fc.end());
  }
  ASSERT_EQ(f.size(), 10000u);
  const PitchDistribution dist(distribution_config(doc.regions[0].texel, doc.device.band_top()));
  const double lo = dist.config().band_min.value(), hi = dist.config().band_max.value();
  const double za = phi((std::log(lo) - dist.mu()) / dist.sigma()), zb = phi((std::log(hi) - dist.mu()) / dist.sigma());
  std::sort(f.begin(), f.end());
  double d = 0.0;
  const double n = static_cast<double>(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    const double cdf = (phi((std::log(f[i]) - dist.mu()) / dist.sigma()) - za) / (zb - za);  // truncated to the band
    d = std::max({d, cdf - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - cdf});
  }
  const double p = ks_p_value(d, f.size());
  std::printf("KS: D = %.5f over %zu draws (4 channels), p = %.3f\n", d, f.size(), p);
  EXPECT_GT(p, 0.05) << "D = " << d;
  // A shifted distribution is rejected by the same test (the test can fail).
  double d_wrong = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const double cdf = phi((std::log(f[i]) - dist.mu() - 0.05) / dist.sigma());
    d_wrong = std::max({d_wrong, cdf - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - cdf});
  }
  EXPECT_LT(ks_p_value(d_wrong, f.size()), 0.05);
}

// ------------------------------------------------------------------- swipe

// Least-squares fit of a + b·sin(2πfx) + c·cos(2πfx) to (x, y); the residual's RMS.
double sinusoid_residual(const std::vector<double>& x, const std::vector<double>& y, double f) {
  double s[3][3] = {}, r[3] = {};
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double v[3] = {1.0, std::sin(2 * std::numbers::pi * f * x[i]), std::cos(2 * std::numbers::pi * f * x[i])};
    for (int a = 0; a < 3; ++a) {
      r[a] += v[a] * y[i];
      for (int b = 0; b < 3; ++b) s[a][b] += v[a] * v[b];
    }
  }
  // Solve the 3×3 normal equations by Cramer's rule.
  const auto det = [](double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double d = det(s);
  double coef[3];
  for (int k = 0; k < 3; ++k) {
    double m[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) m[a][b] = b == k ? r[a] : s[a][b];
    coef[k] = det(m) / d;
  }
  double e = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double fit =
        coef[0] + coef[1] * std::sin(2 * std::numbers::pi * f * x[i]) + coef[2] * std::cos(2 * std::numbers::pi * f * x[i]);
    e += (y[i] - fit) * (y[i] - fit);
  }
  return std::sqrt(e / static_cast<double>(x.size()));
}

struct Swipe {
  std::vector<Channel> channels;
  std::vector<float> out, positions;
};

Swipe swipe_4(const std::string& playback, std::uint64_t seed = 40) {
  // No response on the fourth actuator here: its limit filter would shape the sinusoids.
  const Document doc = parse_document(
      document(pad_device(6000, false), playback, 6,
               R"({"kind": "texel", "central_pitch_db": 10, "irregularity_db": 5, "texel_length_mm": 0.25, "seed": )" +
                   std::to_string(seed) + "}"));
  Swipe s;
  s.channels = prepare_channels(doc);
  PlayerConfig config;  // amplitude at 48 kHz
  SwipeConfig sw;
  sw.speed_mm_s = 100.0;
  sw.start_mm = 5.0;
  sw.extent_mm = 50.0;
  sw.duration_s = 0.5;
  const auto trace = simulate_swipe(sw);
  s.out = render_trace_channels(s.channels, config, trace, 24000, &s.positions);
  return s;
}

TEST(MultichannelSwipe, FourSimultaneousChannelsAreSingleFrequencySegmentsOfTheTexelLength) {
  const Swipe s = swipe_4(R"({"mode": "simultaneous"})");
  ASSERT_EQ(s.out.size(), 24000u * 4);
  std::size_t segments = 0;
  double worst_residual = 0.0, worst_error = 0.0;
  std::vector<double> estimates, drawn;
  for (std::size_t c = 0; c < 4; ++c) {
    const std::vector<double> f = channel_texel_frequencies(s.channels[c]);
    const double offset = s.channels[c].offset.value();
    // The texels channel c passes over (its actuator at finger + offset): 8 … 52 mm.
    for (std::size_t k = 40; k < 200; k += 3) {
      const double x0 = 0.25 * static_cast<double>(k), x1 = x0 + 0.25;
      std::vector<double> x, y;
      for (std::size_t i = 0; i < 24000; ++i) {
        const double at = s.positions[i] + offset;
        if (at > x0 + 0.03 && at < x1 - 0.03) {  // inside, away from the boundaries' fades
          x.push_back(at);
          y.push_back(s.out[i * 4 + c]);
        }
      }
      ASSERT_GT(x.size(), 80u) << "channel " << c << " texel " << k;
      // The drawn frequency explains the segment: one sinusoid, nothing left over.
      const double at_drawn = sinusoid_residual(x, y, f[k]);
      EXPECT_LT(at_drawn, 5e-4) << "channel " << c << " texel " << k << " f " << f[k];
      worst_residual = std::max(worst_residual, at_drawn);
      // … and it is the one frequency that does: a grid search finds it within 0.2 %.
      double best = 0.0, best_e = 1e9;
      for (double g = 0.5; g < 45.0; g *= 1.01) {
        const double e = sinusoid_residual(x, y, g);
        if (e < best_e) best_e = e, best = g;
      }
      for (double g = best / 1.01, top = best * 1.01; g < top; g *= 1.0005) {
        const double e = sinusoid_residual(x, y, g);
        if (e < best_e) best_e = e, best = g;
      }
      EXPECT_NEAR(best / f[k], 1.0, 0.002) << "channel " << c << " texel " << k;
      worst_error = std::max(worst_error, std::fabs(best / f[k] - 1.0));
      estimates.push_back(best);
      drawn.push_back(f[k]);
      ++segments;
    }
  }
  EXPECT_EQ(segments, 4u * 54u);
  std::printf("segments: %zu, RMS residual at the drawn frequency <= %.2e, estimated/drawn frequency within %.3f %%\n", segments,
              worst_residual, 100.0 * worst_error);
  // Over channels the segments' frequencies are not one chain played four times.
  std::size_t equal_across = 0;
  for (std::size_t i = 0; i < 54; ++i) equal_across += std::fabs(estimates[i] - estimates[54 + i]) < 1e-9;
  EXPECT_LT(equal_across, 5u);
}

TEST(MultichannelSwipe, SameSeedSameBytesAnotherSeedOthers) {
  const Swipe a = swipe_4(R"({"mode": "simultaneous"})");
  const Swipe b = swipe_4(R"({"mode": "simultaneous"})");
  EXPECT_EQ(a.out, b.out);
  EXPECT_NE(swipe_4(R"({"mode": "simultaneous"})", 41).out, a.out);
}

TEST(MultichannelSwipe, SequentialChannelsAreTheOneChannelSwipeAtEachActuatorsOffset) {
  const Swipe s = swipe_4("");
  // Channel c at offset o is the one-channel player with the finger moved by o.
  for (std::size_t c = 0; c < 4; ++c) {
    SwipeConfig sw;
    sw.speed_mm_s = 100.0;
    sw.start_mm = 5.0 + s.channels[c].offset.value();
    sw.extent_mm = 50.0;
    sw.duration_s = 0.5;
    PlayerConfig config;
    config.response = s.channels[c].response;
    const auto one = render_trace(*PlayerMap::from_surface(*s.channels[c].surface), config, simulate_swipe(sw), 24000);
    std::size_t differ = 0;
    float largest = 0;
    for (std::size_t i = 0; i < one.size(); ++i) {
      const float d = std::fabs(one[i] - s.out[i * 4 + c]);
      differ += d != 0.0f;
      largest = std::max(largest, d);
    }
    // Positions differ in their last bits (x + o computed once vs. each sample shifted).
    EXPECT_LT(largest, 1e-4f) << "channel " << c << ": " << differ << " samples differ";
  }
}

TEST(MultichannelSwipe, OneChannelDocumentPlaysExactlyAsTheOneChannelPlayer) {
  const Document doc = parse_document(R"({"format": "texel-document", "version": 1, "device": "generic",
      "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 7}})");
  const auto channels = prepare_channels(doc);
  ASSERT_EQ(channels.size(), 1u);
  SwipeConfig sw;
  sw.surface_mm = 100.0;
  sw.duration_s = 0.2;
  const auto trace = simulate_swipe(sw);
  PlayerConfig config;
  config.response = doc.device.response;
  const auto one = render_trace(*PlayerMap::from_surface(prepare_surface(doc)), config, trace, 9600);
  EXPECT_EQ(render_trace_channels(channels, config, trace, 9600), one);
}

TEST(MultichannelPlayer, ProcessAllocatesNothingOnEightChannels) {
  // 8 channels at 48 kHz, 64-frame blocks.
  std::string actuators;
  for (int c = 0; c < 8; ++c)
    actuators +=
        (c ? "," : "") + std::string(R"({"name": "a)") + std::to_string(c) + R"(", "offset_mm": )" + std::to_string(c - 4) + "}";
  const Document doc = parse_document(document(R"({"name": "pad-8", "samples": 10000, "spacing_mm": 0.01, "format": "f32le",
      "refresh_hz": 48000, "actuators": [)" + actuators +
                                                   "]}",
                                               R"({"mode": "simultaneous"})"));
  ChannelPlayer player(PlayerConfig{}, prepare_channels(doc), 64);
  ASSERT_EQ(player.channels(), 8u);
  std::vector<float> out(64 * 8), pos(64);
  double t = 0;
  float peak = 0.0f;
  const auto before = texel::test_support::alloc::counted_allocations.load();
  {
    const texel::test_support::alloc::CountingScope counting;
    for (int block = 0; block < 2000; ++block) {
      // Pushes are the control thread's (they allocate nothing either: the rings exist).
      if (block % 2 == 0) player.push(FingerSample{t, 10.0 + 50.0 * t, block < 1900});
      player.process(out, pos);
      for (const float v : out) peak = std::max(peak, v);
      t += 64.0 / 48000.0;
    }
  }
  EXPECT_EQ(texel::test_support::alloc::counted_allocations.load() - before, 0u);
  EXPECT_GT(peak, 0.1f) << "the channels played";
}

TEST(MultichannelPlayer, BackendsDriveAPlayerOfTheirOwnChannelCountOnly) {
  const Document doc = parse_document(document(pad_device(1000), R"({"mode": "simultaneous"})"));
  ChannelPlayer player(PlayerConfig{}, prepare_channels(doc), 64);
  const auto mono = make_null_backend(48000, 64);
  EXPECT_NE(message_of<InvalidArgument>([&] { mono->start(player); }).find("has 1 output channel; the player has 4"),
            std::string::npos);
  EXPECT_FALSE(player.attached());
  Player one(PlayerConfig{});
  const auto four = make_null_backend(48000, 64, 4);
  EXPECT_NE(message_of<InvalidArgument>([&] { four->start(one); }).find("has 4 output channels; the player has 1"),
            std::string::npos);
  EXPECT_NE(message_of<InvalidArgument>([] { (void)make_null_backend(48000, 64, 65); }).find("channels is 65; allowed 1 … 64"),
            std::string::npos);
  player.push(FingerSample{0.0, 5.0, true});
  four->start(player);
  // Wait for blocks (a loaded machine may take a while to schedule the thread), up to 5 s.
  for (int i = 0; i < 500 && player.samples() < 64 * 4; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  four->stop();
  EXPECT_GT(four->stats().blocks, 0u);
  EXPECT_GT(player.samples(), 0u);  // frames, not frames × channels
  EXPECT_EQ(player.samples() % 64, 0u);
}

}  // namespace
