// The experiments' Presenter on a multi-actuator display (issue #40;
// presenter.hpp, docs/experiments.md "Presentation"): a 4-channel presenter
// plays a simultaneous document (each actuator its own chain of texels) and a
// sequential one (the one chain at each actuator's offset), switches among
// stimuli with a crossfade per channel and no allocation on the real-time
// side, blanks every channel, and refuses in one line what it cannot play.
//
// Most tests drive the presenter through a backend of their own (Presenter's
// second constructor): the test's thread is the real-time thread, calling
// process() block by block with its allocations counted, and keeps every
// channel's output. Nothing is timed: the player's clock is the samples
// processed. One test runs the real null backend (a paced thread) with 4
// channels, as a session without hardware runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "../support/alloc_counter.hpp"
#include "../support/controller_process.hpp"
#include "../support/expect.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/finger.hpp"
#include "texel/multichannel.hpp"
#include "texel/multichannel_player.hpp"
#include "texel/player.hpp"
#include "texel/sinks.hpp"

namespace {

using namespace texel;
using texel::experiment::FingerSource;
using texel::experiment::Presenter;
using texel::experiment::PresenterOptions;
using texel::experiment::Question;
using texel::experiment::Stimulus;
using texel::test_support::message_of;
namespace alloc = texel::test_support::alloc;

constexpr double rate = 48000.0;
constexpr std::size_t block = 64;

// A pad of `n` actuators 2 mm apart (−3, −1, 1, 3 mm for four), 100 mm at
// 0.01 mm; the last actuator has a response of its own (2nd order, 400 Hz).
std::string pad_device(int n = 4) {
  std::string actuators;
  for (int c = 0; c < n; ++c)
    actuators += std::string(c ? ", " : "") + R"({"name": "a)" + std::to_string(c) + R"(", "offset_mm": )" +
                 std::to_string(2 * c - (n - 1)) +
                 (c == n - 1 && n > 1 ? R"(, "response": {"corner_hz": 400, "order": 2}})" : "}");
  return R"({"name": "pad-)" + std::to_string(n) +
         R"(", "samples": 10000, "spacing_mm": 0.01, "format": "f32le", "refresh_hz": 48000, "actuators": [)" + actuators + "]}";
}

// A texel texture of Central Pitch 10 dB (3.2 cycles/mm: 320 Hz at 100 mm/s).
std::string document(const std::string& device, const std::string& playback, int seed = 40) {
  std::string s = R"({"format": "texel-document", "version": 6, "device": )" + device +
                  R"(, "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": 5, "texel_length_mm": 0.25,
                  "seed": )" +
                  std::to_string(seed) + "}";
  if (!playback.empty()) s += R"(, "playback": )" + playback;
  return s + "}";
}

// A backend the test drives: its process() is the real-time side, on the
// test's thread, with this thread's allocations counted during the call.
class TestBackend final : public Backend {
 public:
  explicit TestBackend(std::size_t channels) : channels_(channels) {}
  ~TestBackend() override { stop(); }
  [[nodiscard]] std::string describe() const override { return "test backend"; }
  [[nodiscard]] std::size_t channels() const noexcept override { return channels_; }
  [[nodiscard]] bool driving() const { return player_ != nullptr; }
  BlockInfo process(std::span<float> out) {
    alloc::counting = true;
    const BlockInfo info = player_->process(out);
    alloc::counting = false;
    return info;
  }

 private:
  void do_start(PlayerBase& player) override { player_ = &player; }
  void do_stop() noexcept override { player_ = nullptr; }
  std::size_t channels_;
  PlayerBase* player_ = nullptr;
};

PresenterOptions options(std::size_t channels) {
  PresenterOptions o;
  o.rate_hz = rate;
  o.block_frames = block;
  o.swipe_speed_mm_s = 100.0;
  o.channels = channels;
  return o;
}

struct Rig {
  TestBackend* backend = nullptr;
  std::unique_ptr<Presenter> presenter;
  std::size_t channels = 0;
  explicit Rig(std::size_t n, PresenterOptions o = options(4)) : channels(n) {
    o.channels = n;
    auto b = std::make_unique<TestBackend>(n);
    backend = b.get();
    presenter = std::make_unique<Presenter>(o, std::move(b));
  }
  // `seconds` of output, frames × channels interleaved, pumping the presenter
  // before every block as a front end does; `crossfading` counts the blocks
  // that crossfaded.
  std::vector<float> run(double seconds, int* crossfading = nullptr) {
    const auto blocks = static_cast<std::size_t>(std::ceil(seconds * rate / block));
    std::vector<float> out(blocks * block * channels);
    for (std::size_t b = 0; b < blocks; ++b) {
      presenter->pump();
      const BlockInfo info = backend->process(std::span(out).subspan(b * block * channels, block * channels));
      if (crossfading && info.crossfading) ++*crossfading;
    }
    return out;
  }
};

float channel_rms(std::span<const float> out, std::size_t channels, std::size_t c, std::size_t from = 0) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = from; i * channels + c < out.size(); ++i, ++n) sum += out[i * channels + c] * out[i * channels + c];
  return n ? static_cast<float>(std::sqrt(sum / static_cast<double>(n))) : 0.0f;
}

// The presenter's simulated finger (presenter.cpp): from 10 mm at 100 mm/s,
// a sample every millisecond (it turns at 90 mm, 0.8 s: beyond these runs).
std::vector<FingerSample> simulated_finger(double seconds) {
  std::vector<FingerSample> trace;
  for (int k = 0; k <= static_cast<int>(seconds * 1000.0); ++k) {
    const double t = k / 1000.0;
    trace.push_back(FingerSample{t, 10.0 + 100.0 * t, true});
  }
  return trace;
}

// What the presenter's player does (presenter.cpp): vibration at 48 kHz,
// the response limit as the options say.
PlayerConfig vibration_config() {
  PlayerConfig config;
  config.rate_hz = rate;
  config.mode = OutputMode::vibration;
  return config;
}

// The off-line multi-channel render of `doc` (`frames` frames per channel)
// under `finger_s` seconds of the presenter's simulated finger.
std::vector<float> offline_render(const std::string& doc, std::size_t frames, double finger_s) {
  return render_trace_channels(prepare_channels(parse_document(doc)), vibration_config(), simulated_finger(finger_s), frames);
}

// The largest difference between the presenter's channels and the off-line
// multi-channel render of the same document under the same finger, from
// frame `from` on (before it the first show's fade-in and the offsets of
// the samples queued before it, presenter.hpp, have settled).
float largest_difference(std::span<const float> out, const std::vector<float>& reference, std::size_t channels, std::size_t c,
                         std::size_t from) {
  float largest = 0.0f;
  for (std::size_t i = from; i * channels + c < out.size(); ++i)
    largest = std::max(largest, std::fabs(out[i * channels + c] - reference[i * channels + c]));
  return largest;
}

TEST(PresenterChannels, CountingAllocatorIsInPlace) { ASSERT_TRUE(alloc::counter_works()); }

// Simultaneous: every actuator plays its own chain, at its offset, through
// its response — exactly what `texel swipe` renders off line (ChannelPlayer
// of the document's channels) — so the channels are all driven and differ.
TEST(PresenterChannels, SimultaneousDocumentPlaysEachActuatorsOwnTexels) {
  const std::string doc = document(pad_device(), R"({"mode": "simultaneous"})");
  Rig rig(4);
  rig.presenter->show(doc);
  const std::vector<float> out = rig.run(0.5);
  const std::vector<float> reference = offline_render(doc, out.size() / 4, 0.6);
  const std::size_t from = static_cast<std::size_t>(0.2 * rate);
  for (std::size_t c = 0; c < 4; ++c) {
    const float rms = channel_rms(out, 4, c, from);
    const float d = largest_difference(out, reference, 4, c, from);
    std::printf("channel %zu: RMS %.4f, largest difference from the off-line render %.2e\n", c, rms, d);
    EXPECT_GT(rms, 0.05f) << "channel " << c << " is not driven";
    EXPECT_LT(d, 1e-3f) << "channel " << c << " does not play its own chain";
  }
  // Pairwise different signals (different texel frequencies), not one chain.
  for (std::size_t a = 0; a < 4; ++a)
    for (std::size_t b = a + 1; b < 4; ++b) {
      float largest = 0.0f;
      for (std::size_t i = from; i < out.size() / 4; ++i) largest = std::max(largest, std::fabs(out[i * 4 + a] - out[i * 4 + b]));
      EXPECT_GT(largest, 0.1f) << "channels " << a << " and " << b << " play the same";
    }
}

// The session's first stimulus brings the actuators' offsets, while the
// simulated finger is already queued 50 ms ahead with none: its maps wait
// until those samples have played (presenter.hpp), so it starts from
// silence about 50 ms later (not at once, reading the finger without its
// offset until the jump), and 60 ms after its onset is what the off-line
// render plays.
TEST(PresenterChannels, FirstStimulusWaitsForTheFingerQueuedBeforeIt) {
  const std::string doc = document(pad_device(), R"({"mode": "simultaneous"})");
  Rig rig(4);
  rig.presenter->show(doc);
  const std::vector<float> out = rig.run(0.3);
  std::size_t onset = out.size() / 4;
  for (std::size_t i = 0; i < out.size() / 4 && onset == out.size() / 4; ++i)
    for (std::size_t c = 0; c < 4; ++c)
      if (out[i * 4 + c] != 0.0f) onset = i;
  std::printf("onset at %.1f ms\n", 1e3 * static_cast<double>(onset) / rate);
  EXPECT_GE(onset, static_cast<std::size_t>(0.045 * rate));
  EXPECT_LE(onset, static_cast<std::size_t>(0.06 * rate));
  const std::vector<float> reference = offline_render(doc, out.size() / 4, 0.4);
  // After the 20 ms crossfade from silence and 40 ms of the DC blocker's settling.
  const std::size_t from = onset + static_cast<std::size_t>(0.06 * rate);
  for (std::size_t c = 0; c < 4; ++c) {
    const float d = largest_difference(out, reference, 4, c, from);
    std::printf("channel %zu from onset + 60 ms: largest difference %.2e\n", c, d);
    EXPECT_LT(d, 5e-3f) << "channel " << c;
  }
}

// Sequential: the one chain on every channel, each at its actuator's
// offset: channel 1 (−1 mm) plays 20 ms (2 mm at 100 mm/s) after channel 2
// (+1 mm) what channel 2 played; every channel as the off-line render.
TEST(PresenterChannels, SequentialDocumentPlaysOneSignalShiftedByTheOffsets) {
  const std::string doc = document(pad_device(), "");
  Rig rig(4);
  rig.presenter->show(doc);
  const std::vector<float> out = rig.run(0.5);
  const std::vector<float> reference = offline_render(doc, out.size() / 4, 0.6);
  const std::size_t from = static_cast<std::size_t>(0.2 * rate);
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_GT(channel_rms(out, 4, c, from), 0.05f) << "channel " << c << " is not driven";
    EXPECT_LT(largest_difference(out, reference, 4, c, from), 1e-3f) << "channel " << c;
  }
  const std::size_t shift = static_cast<std::size_t>(0.02 * rate);  // 2 mm at 100 mm/s
  float shifted = 0.0f, unshifted = 0.0f;
  for (std::size_t i = from; i + shift < out.size() / 4; ++i) {
    shifted = std::max(shifted, std::fabs(out[(i + shift) * 4 + 1] - out[i * 4 + 2]));
    unshifted = std::max(unshifted, std::fabs(out[i * 4 + 1] - out[i * 4 + 2]));
  }
  std::printf("channel 1 against channel 2: shifted by 2 mm %.2e, not shifted %.2e\n", shifted, unshifted);
  EXPECT_LT(shifted, 1e-3f);
  EXPECT_GT(unshifted, 0.1f);
}

// A trial's stimuli, switched back and forth (sequential ↔ simultaneous, as
// the study does): every switch crossfades on the real-time side (about
// 20 ms), which neither allocates nor frees; blank() silences every channel.
TEST(PresenterChannels, SwitchingCrossfadesWithoutAllocationAndBlankSilencesEveryChannel) {
  Question q;
  q.task = "test";
  q.stimuli = {Stimulus{"A", document(pad_device(), R"({"mode": "simultaneous"})")},
               Stimulus{"B", document(pad_device(), R"({"mode": "sequential"})", 41)}};
  Rig rig(4);
  rig.presenter->prepare(q);  // both stimuli prepared before onset
  alloc::counted_allocations = 0;
  alloc::counted_frees = 0;
  rig.presenter->show(q, 0);
  (void)rig.run(0.2);
  for (int round = 0; round < 3; ++round) {
    const auto i = static_cast<std::size_t>(round % 2 == 0 ? 1 : 0);
    rig.presenter->show(q, i);
    int crossfading = 0;
    const std::vector<float> out = rig.run(0.15, &crossfading);
    // 20 ms = 15 blocks of 64 frames (the last ends it); one more if the channels took the maps a block apart.
    EXPECT_GE(crossfading, 14) << "switch " << round;
    EXPECT_LE(crossfading, 16) << "switch " << round;
    for (std::size_t c = 0; c < 4; ++c) EXPECT_GT(channel_rms(out, 4, c, out.size() / 8), 0.05f) << "channel " << c;
  }
  rig.presenter->blank();
  const std::vector<float> after = rig.run(0.2);
  float late = 0.0f;
  for (std::size_t i = after.size() / 2; i < after.size(); ++i) late = std::max(late, std::fabs(after[i]));
  EXPECT_LT(late, 1e-4f) << "blank() left a channel driven";
  EXPECT_EQ(alloc::counted_allocations.load(), 0u) << "process() allocated";
  EXPECT_EQ(alloc::counted_frees.load(), 0u) << "process() freed";
  EXPECT_EQ(rig.presenter->shown(), 4u);
  rig.presenter->stop();
  EXPECT_FALSE(rig.backend->driving());
  rig.presenter->stop();  // twice: safe
}

// A document of a device without actuators plays on every channel, the same
// signal (offset 0, the device's response).
TEST(PresenterChannels, OneChannelDocumentPlaysOnEveryChannel) {
  Rig rig(4);
  rig.presenter->show(document(R"("generic")", ""));
  const std::vector<float> out = rig.run(0.3);
  EXPECT_GT(channel_rms(out, 4, 0, out.size() / 8), 0.05f);
  for (std::size_t i = 0; i < out.size() / 4; ++i)
    for (std::size_t c = 1; c < 4; ++c) ASSERT_EQ(out[i * 4 + c], out[i * 4]) << "frame " << i << " channel " << c;
}

// A sequential document on one actuator: the others are at rest.
TEST(PresenterChannels, SequentialOnOneChannelLeavesTheOthersAtRest) {
  Rig rig(4);
  rig.presenter->show(document(pad_device(), R"({"mode": "sequential", "channel": 2})"));
  const std::vector<float> out = rig.run(0.3);
  for (std::size_t c = 0; c < 4; ++c)
    if (c == 2)
      EXPECT_GT(channel_rms(out, 4, c, out.size() / 8), 0.05f);
    else
      EXPECT_EQ(channel_rms(out, 4, c), 0.0f) << "channel " << c;
}

// The external finger (the studio's strip) and the channels: every channel
// follows the pushed finger.
TEST(PresenterChannels, ExternalFingerDrivesEveryChannel) {
  PresenterOptions o = options(4);
  o.finger = FingerSource::external;
  Rig rig(4, o);
  rig.presenter->show(document(pad_device(), R"({"mode": "simultaneous"})"));
  std::vector<float> out;
  for (int k = 0; k < 300; ++k) {  // 0.4 s of 64-frame blocks, a pointer sample per block
    ASSERT_TRUE(rig.presenter->push_finger(20.0 + 0.1 * k, true));
    const std::vector<float> b = rig.run(block / rate);
    out.insert(out.end(), b.begin(), b.end());
  }
  for (std::size_t c = 0; c < 4; ++c) EXPECT_GT(channel_rms(out, 4, c, out.size() / 8), 0.02f) << "channel " << c;
}

TEST(PresenterChannels, WhatCannotPlayIsRefusedInOneLine) {
  // A one-channel presenter and a 4-actuator document: the device, its count and the fix.
  PresenterOptions one = options(1);
  one.backend = "null";
  Presenter mono(one);
  Question q;
  q.task = "test";
  q.stimuli = {Stimulus{"A", document(pad_device(), R"({"mode": "simultaneous"})")}};
  for (const std::string& m :
       {message_of<InvalidArgument>([&] { mono.show(q.stimuli[0].document_json); }),
        message_of<InvalidArgument>([&] { mono.prepare(q); }), message_of<InvalidArgument>([&] { (void)mono.check(q); })}) {
    EXPECT_NE(m.find("device 'pad-4' has 4 actuators; this presenter plays 1 channel: open it with channels 4"),
              std::string::npos)
        << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  // … a sequential one too (it is four actuators' signal, not one).
  EXPECT_NE(message_of<InvalidArgument>([&] { mono.show(document(pad_device(), "")); }).find("has 4 actuators"),
            std::string::npos);
  EXPECT_EQ(mono.shown(), 0u);
  // More actuators than channels, or fewer (but one).
  Rig rig(4);
  EXPECT_NE(message_of<InvalidArgument>([&] {
              rig.presenter->show(document(pad_device(8), ""));
            }).find("device 'pad-8' has 8 actuators; this presenter plays 4 channels: open it with channels 8"),
            std::string::npos);
  EXPECT_NE(message_of<InvalidArgument>([&] {
              rig.presenter->show(document(pad_device(2), ""));
            }).find("device 'pad-2' has 2 actuators; this presenter plays 4 channels"),
            std::string::npos);
  EXPECT_EQ(rig.presenter->shown(), 0u);
  // A serial display is one plate; a 2-D display one channel; the count's range.
  PresenterOptions serial = options(4);
  serial.backend = "serial:/nonexistent/tty";
  EXPECT_NE(message_of<InvalidArgument>([&] { Presenter p(serial); })
                .find("channels is 4, but backend serial:/nonexistent/tty is a serial display: the serial protocol drives "
                      "one plate"),
            std::string::npos);
  PresenterOptions two_d = options(4);
  two_d.finger = FingerSource::display;
  two_d.finger_display = "serial:/nonexistent/tty";
  EXPECT_NE(message_of<InvalidArgument>([&] { Presenter p(two_d); }).find("2-D display"), std::string::npos);
  for (const std::size_t n : {std::size_t{0}, std::size_t{65}})
    EXPECT_NE(message_of<InvalidArgument>([&] {
                Presenter p(options(n));
              }).find("channels is " + std::to_string(n) + "; allowed: 1 … 64"),
              std::string::npos);
  // A given backend of another channel count.
  EXPECT_NE(message_of<InvalidArgument>([&] {
              Presenter p(options(4), std::make_unique<TestBackend>(2));
            }).find("has 2 channel(s); the presenter plays 4"),
            std::string::npos);
}

TEST(PresenterChannels, PresentationChannelsAreTheDevicesActuators) {
  EXPECT_EQ(texel::experiment::presentation_channels("tpad"), 1u);
  texel::experiment::Protocol p;
  p.device = "generic";
  EXPECT_EQ(texel::experiment::presentation_channels(p), 1u);
  EXPECT_THROW((void)texel::experiment::presentation_channels("no-such-device"), InvalidArgument);
}

#ifdef TEXEL_CLI
// A finger sensor on a link of its own (FingerSource::sensor: the reference
// controller's scripted strokes over 10 … 90 mm, `texel controller --sensor
// strokes`) while the 4 actuators play: host-streams, its reports drive
// every channel. Paced by the wall clock, since the reports are placed on
// the player's clock at their arrival (about 1 s).
TEST(PresenterChannels, SeparateSensorDrivesEveryChannel) {
  texel::test_support::ControllerProcess sensor(TEXEL_CLI, {"--sensor", "strokes", "--duration", "60", "--quiet"});
  ASSERT_FALSE(sensor.pty().empty());
  PresenterOptions o = options(4);
  o.finger = FingerSource::sensor;
  o.finger_display = "serial:" + sensor.pty();
  Rig rig(4, o);
  EXPECT_EQ(rig.presenter->mode(), texel::experiment::PresentationMode::host_streams);
  rig.presenter->show(document(pad_device(), R"({"mode": "simultaneous"})"));
  std::vector<float> out;
  const auto start = std::chrono::steady_clock::now();
  const auto period = std::chrono::duration<double>(block / rate);
  for (int b = 0; b < 750; ++b) {  // 1 s
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(b * period));
    const std::vector<float> one = rig.run(block / rate);
    out.insert(out.end(), one.begin(), one.end());
  }
  EXPECT_GT(rig.presenter->finger_counts().reports, 300u);
  for (std::size_t c = 0; c < 4; ++c) {
    const float rms = channel_rms(out, 4, c, out.size() / 40);
    std::printf("channel %zu: RMS %.4f under the sensor's finger\n", c, rms);
    EXPECT_GT(rms, 0.02f) << "channel " << c << " is not driven";
  }
  rig.presenter->stop();
  EXPECT_NE(sensor.stop().find("bad 0"), std::string::npos);
}
#endif

// The real null backend (a paced real-time thread), as a session without
// hardware runs: opened with 4 channels, it plays, blanks and stops.
TEST(PresenterChannels, NullBackendPlaysFourChannels) {
  PresenterOptions o = options(4);
  o.backend = "null";
  Presenter p(o);
  EXPECT_NE(p.describe().find("4 channels"), std::string::npos) << p.describe();
  EXPECT_EQ(p.channels(), 4u);
  p.show(document(pad_device(), R"({"mode": "simultaneous"})"));
  const auto play = [&](double seconds) {
    (void)p.stats();
    const std::uint64_t from = p.stats().blocks;
    const auto blocks = static_cast<std::uint64_t>(std::ceil(seconds / p.block_period_s()));
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    float peak = 0.0f;
    texel::BackendStats s;
    do {
      p.pump();
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      s = p.stats();
      peak = std::max(peak, s.peak);
    } while (s.blocks < from + blocks && std::chrono::steady_clock::now() < give_up);
    EXPECT_GE(s.blocks, from + blocks) << "the null backend did not run";
    return peak;
  };
  (void)play(0.05);
  EXPECT_GT(play(0.1), 0.05f);
  p.blank();
  (void)play(0.1);
  EXPECT_LT(play(0.05), 1e-4f);
  p.stop();
  const std::uint64_t blocks = p.stats().blocks;
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(p.stats().blocks, blocks) << "the backend still runs after stop()";
}

}  // namespace
