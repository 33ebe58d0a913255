// The serial protocol and the reference controller, host ↔ controller over a
// pseudo-terminal: upload, select, stream; corrupted frames, wrong
// checksums, oversize maps and unplugged links are detected and reported,
// never crash, and the controller keeps its last good map.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <set>
#include <thread>
#include <vector>

#include <pty.h>
#include <unistd.h>

#include "../support/display_rig.hpp"
#include "texel/controller/controller.hpp"
#include "texel/controller/host_hal.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
#include "texel/serial_protocol.hpp"
#include "texel/sinks.hpp"

using namespace texel;
using namespace std::chrono_literals;
namespace ser = texel::serial;

// ------------------------------------------------------------- protocol

TEST(Protocol, ChecksumCheckValues) {
  const std::uint8_t s[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(ser::crc16(s, 9), 0x29B1);
  EXPECT_EQ(ser::crc32(s, 9), 0xCBF43926u);
  EXPECT_EQ(ser::crc32(s + 4, 5, ser::crc32(s, 4)), 0xCBF43926u);  // continues
}

TEST(Protocol, GoldenHelloFrame) {
  // docs/serial-protocol.md, "Example": HELLO, seq 7, version 1.
  const std::uint8_t payload[] = {1};
  std::uint8_t f[ser::max_frame];
  const std::size_t n = ser::encode_frame(ser::Type::hello, 7, payload, 1, f);
  const std::vector<std::uint8_t> bytes(f, f + n);
  const std::uint16_t crc = ser::crc16(f + 2, 5);
  EXPECT_EQ(bytes, (std::vector<std::uint8_t>{0xA5, 0x5A, 0x01, 0x07, 0x01, 0x00, 0x01, 0x61, 0xCD}));
  EXPECT_EQ(crc, 0xCD61) << std::hex << crc;
}

TEST(Protocol, DecoderResynchronisesAfterGarbageAndCorruption) {
  std::uint8_t good[ser::max_frame];
  const std::uint8_t p[] = {9, 8, 7};
  const std::size_t n = ser::encode_frame(ser::Type::select, 3, p, 3, good);
  std::vector<std::uint8_t> stream{0x00, 0xA5, 0xA5, 0x13};  // garbage, false syncs
  std::vector<std::uint8_t> bad(good, good + n);
  bad[7] ^= 0x40;  // payload bit flip
  stream.insert(stream.end(), bad.begin(), bad.end());
  stream.insert(stream.end(), good, good + 5);                        // truncated frame…
  stream.insert(stream.end(), good, good + n);                        // …then a whole one
  stream.insert(stream.end(), {0xA5, 0x5A, 0x01, 0x00, 0xFF, 0xFF});  // length 65535
  stream.insert(stream.end(), good, good + n);
  ser::Decoder d;
  int frames = 0, crc_errors = 0, length_errors = 0;
  // Byte by byte and in one go must agree.
  for (int pass = 0; pass < 2; ++pass) {
    frames = crc_errors = length_errors = 0;
    auto on_frame = [&](const ser::Frame& f) {
      ++frames;
      EXPECT_EQ(f.type, ser::Type::select);
      EXPECT_EQ(f.length, 3);
      EXPECT_EQ(f.payload[2], 7);
    };
    auto on_error = [&](ser::ErrorCode e) { (e == ser::ErrorCode::bad_checksum ? crc_errors : length_errors)++; };
    d.reset();
    if (pass == 0)
      for (auto b : stream) d.feed(&b, 1, on_frame, on_error);
    else
      d.feed(stream.data(), stream.size(), on_frame, on_error);
    EXPECT_EQ(frames, 2) << "pass " << pass;
    EXPECT_EQ(crc_errors, 1) << "pass " << pass;     // the flipped frame
    EXPECT_EQ(length_errors, 2) << "pass " << pass;  // the truncated one (its length is read from the next frame) and 65535
  }
}

TEST(Protocol, DecoderSurvivesRandomBytes) {
  std::mt19937 rng(5);
  ser::Decoder d;
  std::vector<std::uint8_t> junk(200000);
  for (auto& b : junk) b = static_cast<std::uint8_t>(rng() % 4 == 0 ? 0xA5 : rng());
  int frames = 0;
  d.feed(
      junk.data(), junk.size(), [&](const ser::Frame& f) { frames += f.length <= ser::max_payload; }, [](ser::ErrorCode) {});
  std::uint8_t good[ser::max_frame];
  const std::size_t n = ser::encode_frame(ser::Type::hello, 1, nullptr, 0, good);
  for (int i = 0; i < 3; ++i)
    d.feed(
        good, n, [&](const ser::Frame&) { ++frames; }, [](ser::ErrorCode) {});
  EXPECT_GE(frames, 1);
}

// ------------------------------------------------- host ↔ controller (pty)

namespace {

using Rig = test_support::DisplayRig;  // the controller on a pty, on its own thread

std::vector<float> ramp_map(std::size_t n) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<float>(0.5 + 0.5 * std::sin(0.01 * static_cast<double>(i)));
  return v;
}

std::uint16_t u16(float a) { return static_cast<std::uint16_t>(std::clamp(static_cast<double>(a), 0.0, 1.0) * 65535.0 + 0.5); }

bool wait_for(const std::function<bool()>& ok, std::chrono::milliseconds limit = 1000ms) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (ok()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return ok();
}

}  // namespace

TEST(HostController, HelloUploadSelectStream) {
  Rig rig;
  SerialLink link(rig.path);
  const DisplayInfo info = link.hello();
  EXPECT_EQ(info.version, 1);
  EXPECT_EQ(info.slots, 2);
  EXPECT_EQ(info.max_samples, 32768u);
  EXPECT_NEAR(info.refresh_hz, 8333.0, 1e-9);
  EXPECT_EQ(info.name, "texel-reference");

  const auto map = ramp_map(19200);
  link.upload_map(0, map, 0.0053);
  link.select(0);
  for (double x : {1.0, 25.3, 50.88, 101.7}) {
    link.stream_position(x, true);
    const auto expect = u16(map[static_cast<std::size_t>(std::lround(x / 0.0053))]);
    EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == expect; }))
        << "x=" << x << " got " << rig.hal->amplitude.load();
  }
  link.stream_position(30, false);  // lifted: at rest
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == 0; }));
  link.stream_position(200, true);  // beyond the map: at rest
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == 0; }));
  link.stream_drive(0.25);
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == u16(0.25f); }));
  const DisplayStatus s = link.status();
  EXPECT_EQ(s.selected, 0);
  EXPECT_EQ(s.mode, 2);
  EXPECT_EQ(s.map_samples, 19200u);
  EXPECT_EQ(s.frames_bad, 0u);
  // The controller refreshes at about 8,333 Hz (a loaded host may skip ticks:
  // the bound is loose; a microcontroller's timer interrupt is exact).
  const auto w0 = rig.hal->writes.load();
  std::this_thread::sleep_for(200ms);
  const double rate = static_cast<double>(rig.hal->writes.load() - w0) / 0.2;
  EXPECT_GT(rate, 8333 * 0.25);
  EXPECT_LT(rate, 8333 * 1.1);
  // Streamed values that stop arriving put the output at rest.
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == 0; }, 1000ms));
}

TEST(HostController, RefusesBadRequestsAndKeepsTheLastGoodMap) {
  Rig rig;
  SerialLink link(rig.path);
  link.timeout_ms = 200;
  link.hello();
  const auto map = ramp_map(1000);
  link.upload_map(1, map, 0.01);
  link.select(1);

  // Oversize map: refused with a NACK naming the display's limit.
  try {
    link.upload_map(1, std::vector<float>(40000, 1.0f), 0.0053);
    FAIL() << "oversize map accepted";
  } catch (const SerialError& e) {
    EXPECT_EQ(e.code, ser::ErrorCode::oversize_map);
    EXPECT_EQ(e.detail, 32768u);
  }
  // Wrong map checksum: refused, previous map kept.
  std::vector<std::uint16_t> other(500, 12345);
  try {
    link.upload_raw(1, other, 10000, 0, /*corrupt_crc=*/true);
    FAIL() << "corrupt map accepted";
  } catch (const SerialError& e) {
    EXPECT_EQ(e.code, ser::ErrorCode::map_checksum);
  }
  EXPECT_THROW(link.select(5), SerialError);  // no such slot
  EXPECT_THROW(link.select(0), SerialError);  // empty slot

  // Corrupted and partial frames on the wire: dropped, counted, no reply.
  std::uint8_t f[ser::max_frame];
  const std::uint8_t sel[1] = {0xFF};
  std::size_t n = ser::encode_frame(ser::Type::select, 99, sel, 1, f);
  f[n - 1] ^= 0xFF;  // wrong checksum: must NOT take effect
  link.send_raw(std::as_bytes(std::span(f, n)));
  const std::vector<std::uint8_t> partial{0xA5, 0x5A, 0x05, 0x01, 0x01};
  link.send_raw(std::as_bytes(std::span(partial)));  // partial header
  const std::vector<std::uint8_t> noise{0x00, 0x11, 0xA5, 0x22};
  link.send_raw(std::as_bytes(std::span(noise)));  // noise
  std::uint8_t unknown[ser::max_frame];
  n = ser::encode_frame(static_cast<ser::Type>(0x42), 1, nullptr, 0, unknown);
  link.send_raw(std::as_bytes(std::span(unknown, n)));

  // The link recovers and the last good map is still selected and intact.
  const DisplayStatus s = link.status();
  EXPECT_EQ(s.selected, 1);
  EXPECT_EQ(s.map_samples, 1000u);
  EXPECT_GE(s.frames_bad, 1u);
  link.stream_position(5.0, true);
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == u16(map[500]); }));
  rig.halt();
  EXPECT_EQ(rig.ctl->map_samples(1), 1000u);
  for (std::uint32_t i = 0; i < 1000; ++i) ASSERT_EQ(rig.ctl->map_value(1, i), u16(map[i]));
  // Checksum, 2 selects, unknown type (the oversize map was refused by the
  // host, which knows the display's max_samples from HELLO).
  EXPECT_GE(rig.ctl->status().nacks, 4u);
}

TEST(HostController, UnpluggedDisplayIsAnErrorNotACrash) {
  Rig rig;
  SerialLink link(rig.path);
  link.timeout_ms = 100;
  link.attempts = 1;
  link.hello();
  link.upload_map(0, ramp_map(100), 0.01);
  // Unplug: the display end of the link goes away.
  rig.halt();
  rig.hal->close_link();
  EXPECT_THROW(link.hello(), IoError);
  EXPECT_THROW(
      {
        for (int i = 0; i < 100000; ++i) link.stream_position(1.0, true);  // fills the pty, then fails
      },
      IoError);
}

TEST(HostController, HostGoingAwayIsCountedTheOutputRestsAndTheMapIsKept) {
  Rig rig;
  {
    SerialLink link(rig.path);
    link.rest_on_close = false;  // the host vanishes without a word
    link.hello();
    link.upload_map(0, ramp_map(300), 0.01);
    link.select(0);
    EXPECT_EQ(link.status().selected, 0);
  }
  ::close(rig.slave);  // the last handle on the host side: the master now reads EIO
  rig.slave = -1;
  std::this_thread::sleep_for(50ms);
  rig.halt();
  EXPECT_GE(rig.ctl->status().link_errors, 1u);
  EXPECT_EQ(rig.ctl->map_samples(0), 300u);
  EXPECT_EQ(rig.ctl->status().selected, ser::no_map) << "a lost link rests the output";
  EXPECT_EQ(rig.hal->amplitude.load(), 0);
}

TEST(HostController, PlayerDrivesTheDisplayThroughTheSerialBackend) {
  Rig rig;
  auto map = std::make_unique<const PlayerMap>(Grid{Millimetres(0), Millimetres(0.01), 5000}, ramp_map(5000));
  SerialOptions o;
  o.path = rig.path;
  o.rate_hz = 1000;
  auto backend = make_serial_backend(o, *map);
  PlayerConfig c;
  c.rate_hz = 1000;
  Player player(c, std::make_unique<const PlayerMap>(*map));
  for (int k = 0; k <= 300; ++k) player.push({k / 1000.0, 10 + 0.1 * k, true});
  backend->start(player);
  std::this_thread::sleep_for(150ms);
  const auto a = rig.hal->amplitude.load();
  backend->stop();
  EXPECT_TRUE(backend->error().empty()) << backend->error();
  EXPECT_GT(backend->stats().blocks, 100u);
  EXPECT_GT(a, 0);
}

// ------------------------------------------ finger reports (protocol 1.1)

namespace {

/// A 2-D sensor: the finger circles (20 mm radius about (50, 40) mm) once a
/// second, lifted for the last 100 ms of each turn.
bool circling_finger(controller::HostHal& hal, std::int32_t& x, std::int32_t& y, bool& touch) {
  const double t = hal.micros() * 1e-6;
  const double turn = t - std::floor(t);
  x = static_cast<std::int32_t>(std::lround((50.0 + 20.0 * std::cos(2 * std::numbers::pi * turn)) * 1e6));
  y = static_cast<std::int32_t>(std::lround((40.0 + 20.0 * std::sin(2 * std::numbers::pi * turn)) * 1e6));
  touch = turn < 0.9;
  return true;
}

// The rig's sensor: lifted until the test has the rig's HAL (its controller
// thread starts in the constructor), then the circling finger.
auto circling_sensor(std::atomic<controller::HostHal*>& hal_ptr) {
  return [&hal_ptr](std::int32_t& x, std::int32_t& y, bool& touch) {
    controller::HostHal* hal = hal_ptr.load();
    if (hal == nullptr) {
      x = y = 0;
      touch = false;
      return true;
    }
    return circling_finger(*hal, x, y, touch);
  };
}

}  // namespace

TEST(FingerReports, ADisplayWithASensorReportsItsFingerAtTheIntervalAskedFor) {
  std::atomic<controller::HostHal*> hal_ptr{nullptr};
  Rig rig(circling_sensor(hal_ptr));
  hal_ptr = rig.hal.get();
  SerialLink link(rig.path);
  link.hello();
  // Too short an interval is refused; the display says the shortest.
  try {
    link.start_reports(50);
    ADD_FAILURE() << "an interval of 50 µs was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find(">= 100"), std::string::npos) << e.what();
  }
  link.start_reports(1000);
  std::vector<FingerReport> got;
  std::array<FingerReport, 64> buf;
  const auto end = std::chrono::steady_clock::now() + 400ms;
  while (std::chrono::steady_clock::now() < end) {
    const std::size_t n = link.read_reports(buf, 20);
    got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  }
  // About one report per millisecond (a loaded host may skip some ticks).
  EXPECT_GT(got.size(), 100u);
  EXPECT_LT(got.size(), 450u);
  ASSERT_GE(got.size(), 2u);
  EXPECT_EQ(link.reports_lost(), 0u);
  for (std::size_t i = 1; i < got.size(); ++i) {
    EXPECT_EQ(got[i].seq, static_cast<std::uint8_t>(got[i - 1].seq + 1));
    EXPECT_GT(static_cast<std::int32_t>(got[i].t_us - got[i - 1].t_us), 0) << i;
  }
  // Never faster than asked: the reports keep to the interval's grid (a late
  // tick delays one report, the next keeps its slot).
  const double mean_us = static_cast<double>(got.back().t_us - got.front().t_us) / static_cast<double>(got.size() - 1);
  EXPECT_GT(mean_us, 990.0);
  // Every report lies on the circle, and the reported times place it there.
  for (const FingerReport& r : got) {
    EXPECT_NEAR(std::hypot(r.x_mm - 50.0, r.y_mm - 40.0), 20.0, 1e-5);
    // t_us is the tick's time; the sensor is read a few µs later (126 mm/s).
    const double turn = r.t_us * 1e-6 - std::floor(r.t_us * 1e-6);
    EXPECT_NEAR(r.x_mm, 50.0 + 20.0 * std::cos(2 * std::numbers::pi * turn), 0.005);
    if (std::abs(turn - 0.9) > 1e-4) {
      EXPECT_EQ(r.touch, turn < 0.9);
    }
  }
  // Stopping: no more reports once the ACK is in and the pipe drained.
  link.start_reports(0);
  (void)link.read_reports(buf, 20);
  std::this_thread::sleep_for(20ms);
  while (link.read_reports(buf, 0) > 0) {
  }
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(link.read_reports(buf, 10), 0u);
  EXPECT_EQ(rig.ctl->status().report_interval_us, 0u);
}

TEST(FingerReports, ADisplayWithoutASensorSaysSo) {
  Rig rig;  // positions come from the host
  SerialLink link(rig.path);
  link.hello();
  try {
    link.start_reports(1000);
    ADD_FAILURE() << "a display without a sensor accepted REPORTS";
  } catch (const SerialError& e) {
    EXPECT_EQ(e.code, serial::ErrorCode::no_sensor);
    EXPECT_NE(std::string(e.what()).find("no finger sensor"), std::string::npos) << e.what();
  }
}

TEST(FingerReports, TheTimelineNeverPlacesAReportAfterItArrivedAndFollowsASlowClock) {
  ReportTimeline tl;
  // Reports every ms on a display clock near the 32-bit wrap, arriving 2–7 ms
  // later on a host clock that runs 0.05 % faster.
  std::uint32_t t_us = 0xFFFFFFFFu - 5000u;
  double prev = -1.0;
  for (int k = 0; k < 20000; ++k, t_us += 1000) {
    const double arrival = k * 1e-3 * 1.0005 + 0.002 + 0.005 * ((k * 7919) % 13) / 13.0;
    const double placed = tl.place(t_us, arrival);
    EXPECT_LE(placed, arrival + 1e-12);
    EXPECT_GT(placed, prev);
    prev = placed;
    if (k > 5000) {
      EXPECT_GT(placed, arrival - 0.0075) << k;  // delay stays bounded: the drift is followed
    }
  }
}

TEST(FingerReports, A2DPlayerDrivesTheDisplayThatReportsTheFinger) {
  std::atomic<controller::HostHal*> hal_ptr{nullptr};
  Rig rig(circling_sensor(hal_ptr));
  hal_ptr = rig.hal.get();
  SerialOptions o;
  o.path = rig.path;
  o.rate_hz = 1000;
  o.stream = SerialStream::drive;
  const PlayerMap stand_in(Grid{Millimetres(0), Millimetres(1), 1}, std::vector<float>{0.0f});
  auto backend = make_serial_backend(o, stand_in);
  ASSERT_NE(backend->serial_link(), nullptr);
  PlayerConfig c;
  c.rate_hz = 1000;
  c.mode = OutputMode::amplitude;
  // A friction bitmap: 1 where y > 40 mm, 0.2 below.
  Raster2D bitmap;
  bitmap.width = 200;
  bitmap.height = 160;
  bitmap.pitch = Millimetres(0.5);
  bitmap.values.resize(200 * 160);
  for (int r = 0; r < 160; ++r)
    for (int k = 0; k < 200; ++k)
      bitmap.values[static_cast<std::size_t>(r) * 200 + static_cast<std::size_t>(k)] = r * 0.5 > 40 ? 1.0f : 0.2f;
  Player2D player(c, PlayerMap2D::bitmap(std::move(bitmap)));
  SerialLink& link = *backend->serial_link();
  link.start_reports(1000);
  backend->start(player);
  ReportTimeline tl;
  std::array<FingerReport, 64> buf;
  std::size_t reports = 0;
  std::set<std::uint16_t> seen;
  const auto end = std::chrono::steady_clock::now() + 1200ms;
  while (std::chrono::steady_clock::now() < end) {
    const std::size_t n = link.read_reports(buf, 5);
    for (std::size_t i = 0; i < n; ++i)
      player.push({tl.place(buf[i].t_us, player.time_s()), buf[i].x_mm, buf[i].y_mm, buf[i].touch});
    reports += n;
    seen.insert(rig.hal->amplitude.load());
  }
  backend->stop();
  EXPECT_TRUE(backend->error().empty()) << backend->error();
  EXPECT_GT(reports, 300u);
  // Over a turn the finger crosses both halves of the bitmap: the display was
  // driven at both frictions.
  const auto near = [&](float a) {
    return std::any_of(seen.begin(), seen.end(), [&](std::uint16_t v) { return std::abs(v - u16(a)) <= 66; });
  };
  EXPECT_TRUE(near(1.0f)) << seen.size();
  EXPECT_TRUE(near(0.2f)) << seen.size();
}
