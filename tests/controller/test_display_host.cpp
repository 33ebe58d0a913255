// The host side against the reference controller over a pseudo-terminal:
// the limits a display announces are honoured (a 256-byte payload and one
// slot take a whole upload and select), documents upload with `texel
// render`'s exact bytes, rest() and the serial backend's stop() leave the
// display at rest, the scripted 1-D finger, and `texel display-check`
// passing the reference and naming what each broken display breaks.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include <csignal>

#include <fcntl.h>

#include <sys/wait.h>
#include <unistd.h>

#include "../support/controller_process.hpp"
#include "../support/display_rig.hpp"
#include "../support/specs.hpp"
#include "../support/temp_dir.hpp"
#include "texel/device.hpp"
#include "texel/display_check.hpp"
#include "texel/document.hpp"
#include "texel/finger.hpp"
#include "texel/player.hpp"
#include "texel/serial_link.hpp"
#include "texel/sinks.hpp"
#include "texel/stroke_script.hpp"
#include "texel/surface.hpp"

using namespace texel;
using namespace std::chrono_literals;
namespace ser = texel::serial;
using Rig = test_support::DisplayRig;

namespace {

bool wait_for(const std::function<bool()>& ok, std::chrono::milliseconds limit = 1000ms) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (ok()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return ok();
}

Document tpad_document() { return make_document(load_device("tpad"), test_support::fine_spec(10.0, 3.0, 0.5, 7)); }

controller::Info small_display() {
  controller::Info info;
  info.max_payload = 256;
  info.slots = 1;
  return info;
}

}  // namespace

// ------------------------------------------------------------ limits, bytes

TEST(HostLimits, ADisplayAnnouncing256BytesAndOneSlotTakesAWholeUploadAndSelect) {
  Rig rig(small_display(), {});
  SerialLink link(rig.path);
  const DisplayInfo info = link.hello();
  EXPECT_EQ(info.max_payload, 256u);
  EXPECT_EQ(info.slots, 1);
  EXPECT_EQ(link.payload_limit(), 256u);
  const NativeMap map = native_map(tpad_document());
  ASSERT_EQ(map.samples.size(), 19200u);
  EXPECT_EQ(map.spacing_nm, 5300u);
  link.upload(0, map);  // 154 MAP_DATA frames of 125 samples (255 bytes)
  link.select(0);
  for (double x : {1.0, 50.0, 100.0}) {
    link.stream_position(x, true);
    const auto expect = map.samples[static_cast<std::size_t>(std::lround(x / 0.0053))];
    EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == expect; })) << x;
  }
  const DisplayStatus s = link.status();
  EXPECT_EQ(s.frames_bad, 0u);
  EXPECT_EQ(s.last_error, ser::ErrorCode::none);
  // A second slot does not exist: refused by the host, as the display would.
  try {
    link.upload(1, map);
    ADD_FAILURE() << "an upload into slot 1 of a 1-slot display was sent";
  } catch (const SerialError& e) {
    EXPECT_EQ(e.code, ser::ErrorCode::unknown_map);
    EXPECT_NE(std::string(e.what()).find("the display has 1"), std::string::npos) << e.what();
  }
  rig.halt();
  EXPECT_EQ(rig.ctl->status().nacks, 0u);
}

TEST(HostLimits, TheSerialBackendUploadsWithinASmallDisplaysLimits) {
  Rig rig(small_display(), {});
  const Document doc = tpad_document();
  SerialOptions o;
  o.path = rig.path;
  o.map = std::make_shared<const NativeMap>(native_map(doc));
  auto blank = PlayerMap::from_document(doc);
  auto backend = make_serial_backend(o, *blank);
  const DisplayStatus s = backend->serial_link()->status();
  EXPECT_EQ(s.selected, 0);
  EXPECT_EQ(s.map_samples, 19200u);
  EXPECT_EQ(s.frames_bad, 0u);
  backend.reset();
}

TEST(HostLimits, TheSerialBackendNeverStreamsFasterThanTheDisplayRefreshes) {
  controller::Info info;
  info.refresh_mhz = 500000;  // 500 Hz
  Rig rig(info, {});
  SerialOptions o;
  o.path = rig.path;
  o.rate_hz = 1000;
  o.stream = SerialStream::drive;
  const PlayerMap stand_in(Grid{Millimetres(0), Millimetres(1), 1}, std::vector<float>{0.0f});
  auto backend = make_serial_backend(o, stand_in);
  EXPECT_NE(backend->describe().find("500 Hz refresh), streaming drive values at 500 Hz"), std::string::npos)
      << backend->describe();
}

TEST(HostLimits, ADocumentUploadsWithTexelRendersExactBytes) {
  Rig rig;
  const Document doc = tpad_document();
  const std::vector<std::byte> bytes = prepare_surface(doc).render_native(SampleFormat::u16le);  // texel render --format bin
  const NativeMap map = native_map(doc);
  ASSERT_EQ(bytes.size(), 2 * map.samples.size());
  SerialLink link(rig.path);
  link.hello();
  link.upload(0, map);
  rig.halt();
  for (std::size_t i = 0; i < map.samples.size(); ++i) {
    const auto want =
        static_cast<std::uint16_t>(std::to_integer<unsigned>(bytes[2 * i]) | (std::to_integer<unsigned>(bytes[2 * i + 1]) << 8));
    ASSERT_EQ(rig.ctl->map_value(0, static_cast<std::uint32_t>(i)), want) << "sample " << i;
  }
}

// --------------------------------------------------------------------- rest

TEST(HostRest, RestLeavesTheDisplayAtRestAndNeverThrowsOnADeadLink) {
  Rig rig;
  SerialLink link(rig.path);
  link.hello();
  link.upload_raw(0, std::vector<std::uint16_t>(100, 30000), 100000, 0);
  link.select(0);
  link.stream_drive(0.8);
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() != 0; }));
  EXPECT_TRUE(link.rest());
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == 0; }, 50ms));
  const DisplayStatus s = link.status();
  EXPECT_EQ(s.selected, -1);
  EXPECT_EQ(s.amplitude, 0);
  rig.halt();
  rig.hal->close_link();  // unplugged
  link.timeout_ms = 50;
  EXPECT_FALSE(link.rest());
}

TEST(HostRest, TheSerialBackendRestsTheDisplayOnStopAndSelectsAgainOnStart) {
  Rig rig;
  auto map = std::make_unique<const PlayerMap>(Grid{Millimetres(0), Millimetres(0.01), 5000}, std::vector<float>(5000, 0.5f));
  SerialOptions o;
  o.path = rig.path;
  o.rate_hz = 1000;
  auto backend = make_serial_backend(o, *map);
  PlayerConfig c;
  c.rate_hz = 1000;
  Player player(c, std::make_unique<const PlayerMap>(*map));
  for (int k = 0; k <= 3000; ++k) player.push({k / 1000.0, 10 + 0.01 * k, true});
  for (int run = 0; run < 2; ++run) {
    backend->start(player);
    EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() != 0; })) << "run " << run;
    backend->stop();
    // At rest at once, not after the 200 ms watchdog: rest() was sent.
    EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == 0; }, 20ms)) << "run " << run;
  }
  EXPECT_TRUE(backend->error().empty()) << backend->error();
  rig.halt();
  EXPECT_EQ(rig.ctl->status().selected, ser::no_map);
}

TEST(HostThreads, RequestsGoThroughWhileAReportReaderReadsTheSameLink) {
  // A display that plays its own map: the host SELECTs per interval while
  // its finger reports arrive on another thread.
  const StrokeScript script(StrokeScriptConfig{});
  std::atomic<controller::HostHal*> hal{nullptr};
  Rig rig(controller::Info{}, [&](std::int32_t& x, bool& touch) {
    controller::HostHal* h = hal.load();  // null until the test has the rig's HAL: lifted
    const FingerSample f = h ? script.at(h->micros() * 1e-6) : FingerSample{0.0, 0.0, false};
    x = static_cast<std::int32_t>(std::lround(f.x_mm * 1e6));
    touch = f.touch;
    return true;
  });
  hal = rig.hal.get();
  SerialLink link(rig.path);
  link.hello();
  link.upload_raw(0, std::vector<std::uint16_t>(1000, 20000), 100000, 0);
  link.upload_raw(1, std::vector<std::uint16_t>(1000, 40000), 100000, 0);
  link.start_reports(1000);
  std::atomic<std::size_t> reports{0};
  std::uint8_t last_seq = 0;
  bool have = false;
  std::atomic<int> gaps{0};
  ReportReader reader(link, [&](std::span<const FingerReport> batch) {
    for (const FingerReport& r : batch) {
      if (have && r.seq != static_cast<std::uint8_t>(last_seq + 1)) ++gaps;
      have = true;
      last_seq = r.seq;
    }
    reports += batch.size();
  });
  for (int k = 0; k < 60; ++k) {
    link.select(static_cast<std::uint8_t>(k % 2));
    const DisplayStatus s = link.status();
    EXPECT_EQ(s.selected, k % 2) << k;
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_TRUE(link.rest());
  reader.stop();
  EXPECT_TRUE(reader.error().empty()) << reader.error();
  EXPECT_GT(reports.load(), 100u);
  EXPECT_EQ(gaps.load(), 0);
  EXPECT_EQ(link.reports_lost(), 0u);
}

TEST(HostThreads, AReportReadersKeepalivesHoldTheHostWatchdogAndItsSilenceRestsTheDisplay) {
  // A display playing its own map, finger always down: nothing but the host
  // watchdog can rest it when the host dies without the link going down.
  Rig rig(controller::Info{}, [](std::int32_t& x, bool& touch) {
    x = 5000000;
    touch = true;
    return true;
  });
  {
    SerialLink link(rig.path);
    link.rest_on_close = false;  // the host dies without a word
    link.hello();
    link.upload_raw(0, std::vector<std::uint16_t>(1000, 20000), 100000, 0);
    link.select(0);
    ASSERT_TRUE(link.arm_host_watchdog(300));  // roomy: a loaded CI host may stall for 100 ms
    link.start_reports(1000);
    ReportReader reader(
        link, [](std::span<const FingerReport>) {}, 25);
    std::this_thread::sleep_for(700ms);  // over 2 timeouts: the keepalives hold it
    EXPECT_EQ(rig.hal->amplitude.load(), 20000);
    reader.stop();
  }
  EXPECT_TRUE(wait_for([&] { return rig.hal->amplitude.load() == 0; }, 2000ms));
  rig.halt();
  EXPECT_EQ(rig.ctl->status().selected, ser::no_map);
  EXPECT_EQ(rig.ctl->status().host_timeouts, 1u);
}

// ------------------------------------------------------ the scripted finger

TEST(StrokeScript, IsDeterministicStrokesBackAndForthAndLifts) {
  StrokeScriptConfig c;
  c.seed = 3;
  c.duration_s = 30;
  const StrokeScript a(c), b(c);
  const auto ta = a.trace(1000, 0, a.period_s()), tb = b.trace(1000, 0, b.period_s());
  ASSERT_EQ(ta.size(), tb.size());
  for (std::size_t i = 0; i < ta.size(); ++i) ASSERT_EQ(ta[i].x_mm, tb[i].x_mm) << i;
  c.seed = 4;
  EXPECT_NE(StrokeScript(c).at(1.234).x_mm, a.at(1.234).x_mm);
  // Within its ends, no jump while touching, some lifts, both directions,
  // the median speed near the one asked for.
  std::size_t lifted = 0;
  double fastest = 0;
  for (std::size_t i = 1; i < ta.size(); ++i) {
    EXPECT_GE(ta[i].x_mm, 10.0 - 1e-9);
    EXPECT_LE(ta[i].x_mm, 90.0 + 1e-9);
    lifted += !ta[i].touch;
    if (ta[i].touch && ta[i - 1].touch) fastest = std::max(fastest, std::abs(ta[i].x_mm - ta[i - 1].x_mm) * 1000);
  }
  EXPECT_GT(lifted, 0u);
  EXPECT_LT(fastest, 1000.0);  // a jump while touching (>= 1 mm in 1 ms) would show as >= 1,000 mm/s
  EXPECT_FALSE(ta.back().touch) << "a period ends lifted, so the repeat is a new touch";
  const SwipeMeasures m = swipe_measures(ta);
  EXPECT_GT(m.moving_left, 0u);
  EXPECT_GT(m.moving_right, 0u);
  EXPECT_GT(m.mean_speed_mm_s, 50.0);
  EXPECT_LT(m.mean_speed_mm_s, 150.0);
  EXPECT_GT(m.sd_speed_mm_s, 5.0);  // the speed varies
  EXPECT_THROW(StrokeScript({.from_mm = 10, .to_mm = 10.5}), InvalidArgument);
  EXPECT_THROW(StrokeScript({.speed_mm_s = 0}), InvalidArgument);
}

TEST(StrokeScript, TheDisplaysReportsGiveTheScriptsSwipeMeasures) {
  StrokeScriptConfig c;
  c.seed = 11;
  c.duration_s = 20;
  const StrokeScript script(c);
  std::atomic<controller::HostHal*> hal{nullptr};
  std::atomic<std::uint32_t> t0{0};
  Rig rig(controller::Info{}, [&](std::int32_t& x, bool& touch) {
    controller::HostHal* h = hal.load();
    if (h == nullptr) {  // the rig's thread runs before the test has its HAL: lifted until then
      x = 0;
      touch = false;
      return true;
    }
    const FingerSample f = script.at(static_cast<std::uint32_t>(h->micros() - t0.load()) * 1e-6);
    x = static_cast<std::int32_t>(std::lround(f.x_mm * 1e6));
    touch = f.touch;
    return true;
  });
  t0 = rig.hal->micros();
  hal = rig.hal.get();
  SerialLink link(rig.path);
  link.hello();
  link.start_reports(1000);
  std::vector<FingerSample> got;
  std::array<FingerReport, 64> buf;
  ReportClock clock;
  double first_t = -1;
  // 1,500 reports (1.5 s at 1 kHz; longer on a loaded machine, where a late loop skips reports).
  const auto end = std::chrono::steady_clock::now() + 15s;
  while (got.size() < 1500 && std::chrono::steady_clock::now() < end) {
    const std::size_t n = link.read_reports(buf, 20);
    for (std::size_t i = 0; i < n; ++i) {
      if (first_t < 0) first_t = static_cast<std::uint32_t>(buf[i].t_us - t0) * 1e-6;
      got.push_back({first_t + clock.seconds(buf[i].t_us), buf[i].x_mm, buf[i].touch});
    }
  }
  link.start_reports(0);
  ASSERT_GT(got.size(), 1000u);
  // Each report is the script at the report's own time (the sensor is read
  // a few µs after the tick's time stamp: at most 2 mm/s·ms of travel off).
  for (const FingerSample& f : got) {
    const FingerSample s = script.at(f.t_s);
    if (s.touch == f.touch && s.touch) {
      EXPECT_NEAR(f.x_mm, s.x_mm, 0.05) << f.t_s;
    }
  }
  // Swipe measures from the reports equal the script's sampled at the
  // reports' own times. (Against the script at a regular 1 kHz they differ
  // when a loaded host skips ticks: the measures weigh every interval alike,
  // so irregular sampling moves the directional proportion by a few 0.01.)
  std::vector<FingerSample> at_reports;
  for (const FingerSample& f : got) at_reports.push_back(script.at(f.t_s));
  const SwipeMeasures from_reports = swipe_measures(got);
  const SwipeMeasures from_script = swipe_measures(at_reports);
  EXPECT_NEAR(from_reports.mean_speed_mm_s, from_script.mean_speed_mm_s, 0.02 * from_script.mean_speed_mm_s);
  EXPECT_NEAR(from_reports.sd_speed_mm_s, from_script.sd_speed_mm_s, 0.02 * from_script.sd_speed_mm_s);
  EXPECT_NEAR(from_reports.directional_proportion, from_script.directional_proportion, 0.02);
}

// ------------------------------------------------------------- display-check

namespace {

DisplayCheckReport check(const Rig& rig) {
  DisplayCheckOptions o;
  o.path = rig.path;
  return check_display(o);
}

std::string outcome(const DisplayCheckReport& r, const std::string& name) {
  const CheckResult* c = r.find(name);
  return c ? std::string(to_string(c->outcome)) : "missing";
}

// The rig's controller thread starts inside the rig's constructor, so it may
// read the sensor before the test has the rig's HAL: until then, lifted.
bool strokes(std::atomic<controller::HostHal*>& hal, const StrokeScript& script, std::int32_t& x, bool& touch) {
  controller::HostHal* h = hal.load();
  if (h == nullptr) {
    x = 0;
    touch = false;
    return true;
  }
  const FingerSample f = script.at(h->micros() * 1e-6);
  x = static_cast<std::int32_t>(std::lround(f.x_mm * 1e6));
  touch = f.touch;
  return true;
}

}  // namespace

TEST(DisplayCheck, TheReferenceControllerPassesWithAndWithoutASensor) {
  {
    Rig rig;
    const DisplayCheckReport r = check(rig);
    EXPECT_TRUE(r.passed()) << r.to_text();
    EXPECT_EQ(outcome(r, "playback.position"), "pass");
    EXPECT_EQ(outcome(r, "watchdog.drive"), "pass");
    EXPECT_EQ(outcome(r, "reports"), "skipped") << "no sensor: not applicable";
    EXPECT_EQ(outcome(r, "playback.sensor"), "skipped");
  }
  {
    const StrokeScript script(StrokeScriptConfig{});
    std::atomic<controller::HostHal*> hal{nullptr};
    Rig rig(controller::Info{}, [&](std::int32_t& x, bool& touch) { return strokes(hal, script, x, touch); });
    hal = rig.hal.get();
    const DisplayCheckReport r = check(rig);
    EXPECT_TRUE(r.passed()) << r.to_text();
    EXPECT_EQ(outcome(r, "playback.sensor"), "pass") << r.to_text();
    EXPECT_EQ(outcome(r, "reports"), "pass") << r.to_text();
    EXPECT_EQ(outcome(r, "watchdog.drive"), "pass") << "the sensor must not keep a stale drive going";
    EXPECT_EQ(outcome(r, "playback.position"), "skipped");
  }
}

TEST(DisplayCheck, ASmallDisplayPassesWhatItClaims) {
  controller::Info info = small_display();
  info.max_samples = 600;
  Rig rig(info, {});
  const DisplayCheckReport r = check(rig);
  EXPECT_TRUE(r.passed()) << r.to_text();
  EXPECT_EQ(r.info.max_payload, 256u);
  EXPECT_NE(r.find("limits.max_payload")->detail.find("256"), std::string::npos) << r.to_text();
  EXPECT_EQ(outcome(r, "limits.slots"), "pass");
}

TEST(DisplayCheck, EachBrokenDisplayFailsTheCheckNamedForWhatItBreaks) {
  const StrokeScript script(StrokeScriptConfig{});
  struct Case {
    controller::Fault fault;
    const char* check;
  };
  for (const Case k :
       {Case{controller::fault_wrong_crc, "upload.bad_crc"}, Case{controller::fault_ignore_watchdog, "watchdog.drive"},
        Case{controller::fault_drop_reports, "reports"}}) {
    controller::Info info;
    info.faults = k.fault;
    std::atomic<controller::HostHal*> hal{nullptr};
    Rig rig(info, [&](std::int32_t& x, bool& touch) { return strokes(hal, script, x, touch); });
    hal = rig.hal.get();
    const DisplayCheckReport r = check(rig);
    EXPECT_FALSE(r.passed()) << k.check;
    EXPECT_EQ(outcome(r, k.check), "fail") << r.to_text();
    EXPECT_EQ(outcome(r, "handshake"), "pass");
  }
}

// --------------------------------------------------------------- the CLI

namespace {

struct CliRun {
  int code = -1;
  std::string out;
};
CliRun run(const std::string& cmd) {
  CliRun r;
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = ::pclose(p);
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

}  // namespace

TEST(DisplayCheckCli, PassesTheReferenceAndFailsABrokenOneByName) {
  {
    test_support::ControllerProcess display(TEXEL_CLI,
                                            {"--sensor", "strokes", "--max-payload", "256", "--slots", "1", "--quiet"});
    ASSERT_FALSE(display.pty().empty());
    const CliRun r = run(std::string(TEXEL_CLI) + " display-check serial:" + display.pty());
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("PASS  reports"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("conformant"), std::string::npos) << r.out;
  }
  {
    test_support::ControllerProcess display(TEXEL_CLI, {"--fault", "ignore-watchdog", "--quiet"});
    const CliRun r = run(std::string(TEXEL_CLI) + " display-check serial:" + display.pty() + " --json");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find(R"({"name": "watchdog.drive", "outcome": "fail")"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(R"("passed": false)"), std::string::npos) << r.out;
  }
  const CliRun bad = run(std::string(TEXEL_CLI) + " display-check /dev/null");
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("serial:PATH"), std::string::npos) << bad.out;
}

TEST(ControllerCli, TheStrokeSensorsScriptAndLogShowTheMapPlayedUnderTheFinger) {
  test_support::TempDir tmp;
  const std::string script_csv = tmp.at("script.csv"), log_csv = tmp.at("log.csv");
  std::vector<std::uint16_t> map(1000);
  for (std::size_t i = 0; i < map.size(); ++i) map[i] = static_cast<std::uint16_t>(100 + 60 * i);
  {
    test_support::ControllerProcess display(TEXEL_CLI, {"--sensor", "strokes", "--seed", "5", "--sensor-duration", "10",
                                                        "--sensor-trace-out", script_csv, "--log", log_csv, "--quiet"});
    ASSERT_FALSE(display.pty().empty());
    SerialLink link(display.pty());
    link.hello();
    link.upload_raw(0, map, 100000, 0);  // 0.1 mm spacing, 0 … 100 mm
    link.select(0);
    std::this_thread::sleep_for(1500ms);
    link.rest_on_close = false;
  }
  // The script: what --sensor strokes --seed 5 senses.
  StrokeScriptConfig c;
  c.seed = 5;
  c.duration_s = 10;
  const StrokeScript script(c);
  const std::vector<FingerSample> written = load_trace_csv(script_csv);
  ASSERT_EQ(written.size(), script.trace(1000, 0, script.period_s()).size());
  EXPECT_NEAR(written[1234].x_mm, script.at(1.234).x_mm, 1e-3);
  // The log: every row while selected and touching outputs the map at x.
  std::ifstream in(log_csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "t_s,t_us,x_mm,touch,selected,mode,amplitude");
  int played = 0, lifted = 0;
  while (std::getline(in, line)) {
    double t = 0, x = 0;
    unsigned t_us = 0, amp = 0;
    int touch = 0, sel = 0, mode = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%u,%lf,%d,%d,%d,%u", &t, &t_us, &x, &touch, &sel, &mode, &amp), 7) << line;
    if (sel != 0) continue;
    EXPECT_NEAR(x, script.at(t).x_mm, 0.05) << line;
    if (touch) {
      EXPECT_EQ(amp, map[static_cast<std::size_t>(std::lround(x / 0.1))]) << line;
      ++played;
    } else {
      EXPECT_EQ(amp, 0u) << line;
      ++lifted;
    }
  }
  EXPECT_GT(played, 200);
  (void)lifted;
}

// ------------------------------------------------- the host going away (CLI)

namespace {

// The display's clock (HostHal::micros: steady_clock µs, 32 bits) read here:
// the same clock on the same machine, so the log's t_us place the kill.
std::uint32_t display_clock_us() {
  using namespace std::chrono;
  return static_cast<std::uint32_t>(duration_cast<microseconds>(steady_clock::now().time_since_epoch()).count());
}

struct LogRow {
  std::uint32_t t_us = 0;
  int selected = -1, mode = 0;
  unsigned amplitude = 0;
};

std::vector<LogRow> read_log(const std::string& path) {
  std::vector<LogRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    double t = 0, x = 0;
    int touch = 0;
    LogRow r;
    if (std::sscanf(line.c_str(), "%lf,%u,%lf,%d,%d,%d,%u", &t, &r.t_us, &x, &touch, &r.selected, &r.mode, &r.amplitude) == 7)
      rows.push_back(r);
  }
  return rows;
}

}  // namespace

TEST(HostSafety, AKilledHostLeavesTheDisplayAtRestWithin200MsAndCtrlCRestsItAtOnce) {
  test_support::TempDir tmp;
  const std::string doc = tmp.at("d.texel.json");
  { std::ofstream(doc) << document_json(tpad_document()); }
  for (const int sig : {SIGKILL, SIGINT}) {
    const std::string log = tmp.at("log" + std::to_string(sig) + ".csv");
    // A display with a sensor that always touches: the case where a sensor
    // reading used to keep the stale drive going.
    test_support::ControllerProcess display(TEXEL_CLI, {"--sensor", "strokes", "--sensor-lift-probability", "0", "--sensor-pause",
                                                        "0", "--log", log, "--log-every", "1", "--quiet"});
    ASSERT_FALSE(display.pty().empty());
    const pid_t host = ::fork();
    if (host == 0) {
      const std::string backend = "serial:" + display.pty();
      ::execl(TEXEL_CLI, TEXEL_CLI, "play", doc.c_str(), "--backend", backend.c_str(), "--stream", "drive", "--pattern",
              "back-and-forth", "--speed", "50", "--duration", "30", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    std::this_thread::sleep_for(1500ms);
    const std::uint32_t t_stop = display_clock_us();
    ::kill(host, sig);
    int status = 0;
    ::waitpid(host, &status, 0);
    std::this_thread::sleep_for(400ms);
    (void)display.stop();
    const std::vector<LogRow> rows = read_log(log);
    const auto after_ms = [&](const LogRow& r) { return static_cast<std::int32_t>(r.t_us - t_stop) / 1000.0; };
    int driven_before = 0, rows_after = 0;
    double last_driven_ms = -1e9;
    for (const LogRow& r : rows) {
      const double ms = after_ms(r);
      if (ms > -200 && ms <= 0 && r.amplitude != 0) ++driven_before;
      if (ms > 0) {
        ++rows_after;
        if (r.amplitude != 0) last_driven_ms = ms;
      }
    }
    EXPECT_GT(driven_before, 100) << "signal " << sig << ": the host was driving the display";
    EXPECT_GT(rows_after, 1000) << "signal " << sig;
    if (sig == SIGKILL) {
      // Nobody sent rest: the watchdog (200 ms after the last DRIVE).
      EXPECT_LE(last_driven_ms, 230.0) << "still driven " << last_driven_ms << " ms after kill -9";
    } else {
      // texel play stops and sends rest: at once, and SELECT none.
      EXPECT_LE(last_driven_ms, 100.0) << "still driven " << last_driven_ms << " ms after Ctrl-C";
      EXPECT_EQ(rows.back().selected, -1);
      EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 0);
    }
  }
}

// A study in display-plays streams nothing: the display plays its stored map
// under its own finger, so no stream watchdog covers it. A host that hangs
// with the link open (SIGSTOP: a frozen host, a debugger) is caught only by
// the host watchdog the presenter arms and feeds from a thread of its own.
TEST(HostSafety, AHungHostOfADisplayPlaysStudyLeavesTheDisplayAtRestWithin200Ms) {
  test_support::TempDir tmp;
  const std::string log = tmp.at("log.csv");
  test_support::ControllerProcess display(TEXEL_CLI, {"--sensor", "strokes", "--sensor-lift-probability", "0", "--sensor-pause",
                                                      "0", "--log", log, "--log-every", "1", "--quiet"});
  ASSERT_FALSE(display.pty().empty());
  const std::string backend = "serial:" + display.pty(), db = tmp.at("s.db");
  const std::string protocol = std::string(TEXEL_PROTOCOLS_DIR) + "/texel-length.json";
  const pid_t host = ::fork();
  if (host == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execl(TEXEL_CLI, TEXEL_CLI, "experiment", "run", protocol.c_str(), "--participant", "P01", "--db", db.c_str(), "--backend",
            backend.c_str(), "--simulate", "default", "--pace", "3", "--mode", "display-plays", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Until the display plays a stimulus of the study (its log's latest row selects one), then a little longer.
  bool playing = false;
  for (int i = 0; i < 200 && !playing; ++i) {
    std::this_thread::sleep_for(50ms);
    const std::vector<LogRow> rows = read_log(log);
    playing = !rows.empty() && rows.back().selected >= 0;
  }
  std::this_thread::sleep_for(300ms);
  const std::uint32_t t_stop = display_clock_us();
  ::kill(host, SIGSTOP);
  std::this_thread::sleep_for(600ms);
  const std::vector<LogRow> rows = read_log(log);
  ::kill(host, SIGKILL);
  int status = 0;
  ::waitpid(host, &status, 0);
  (void)display.stop();
  ASSERT_TRUE(playing) << "the study never selected a stimulus on the display";
  // The first logged tick from which the display stays at rest (a display
  // stalled writing reports nobody reads logs no ticks: its rest comes late).
  int selected_before = 0;
  double rest_ms = 1e9;
  for (const LogRow& r : rows) {
    const double ms = static_cast<std::int32_t>(r.t_us - t_stop) / 1000.0;
    if (ms > -100 && ms <= 0 && r.selected >= 0) ++selected_before;
    const bool at_rest = r.selected < 0 && r.amplitude == 0;
    if (!at_rest)
      rest_ms = 1e9;
    else if (ms > 0 && rest_ms == 1e9)
      rest_ms = ms;
  }
  EXPECT_GT(selected_before, 100) << "the display was playing a stimulus when the host hung";
  EXPECT_LE(rest_ms, 230.0) << "at rest " << rest_ms << " ms after the host hung";
}

TEST(ControllerCli, ARecorded1DTraceIsTheSensorAndBadOptionsAreRefusedWithTheirRange) {
  test_support::TempDir tmp;
  const std::string trace = tmp.at("trace.csv"), log_csv = tmp.at("log.csv");
  {
    std::ofstream out(trace);
    out << "time_s,position_mm,touch\n0,20,1\n0.5,70,1\n1.0,20,1\n";
  }
  {
    test_support::ControllerProcess display(TEXEL_CLI,
                                            {"--sensor", "1d:" + trace, "--sensor-lift", "0.2", "--log", log_csv, "--quiet"});
    ASSERT_FALSE(display.pty().empty());
    SerialLink link(display.pty());
    link.hello();
    link.start_reports(1000);  // a 1-D display with a sensor reports it
    std::array<FingerReport, 64> buf;
    std::size_t n = 0;
    for (int i = 0; i < 20 && n == 0; ++i) n = link.read_reports(buf, 20);
    ASSERT_GT(n, 0u);
    EXPECT_EQ(buf[0].y_mm, 0.0);
    link.start_reports(0);
    std::this_thread::sleep_for(1300ms);  // more than a pass and its lift
  }
  int touching = 0, lifted = 0;
  std::ifstream in(log_csv);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    double t = 0, x = 0;
    unsigned t_us = 0, amp = 0;
    int touch = 0, sel = 0, mode = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%u,%lf,%d,%d,%d,%u", &t, &t_us, &x, &touch, &sel, &mode, &amp), 7) << line;
    const double phase = std::fmod(t, 1.2);  // 1 s pass + 0.2 s lifted
    if (phase < 0.999) {
      EXPECT_EQ(touch, 1) << line;
      EXPECT_NEAR(x, phase < 0.5 ? 20 + 100 * phase : 70 - 100 * (phase - 0.5), 0.05) << line;
      ++touching;
    } else if (phase > 1.001 && phase < 1.199) {
      EXPECT_EQ(touch, 0) << line;
      ++lifted;
    }
  }
  EXPECT_GT(touching, 500);
  EXPECT_GT(lifted, 50);
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"--max-payload 10", "--max-payload is 10; allowed 14 … 1024 bytes"},
           {"--slots 3", "--slots is 3; allowed 1 … 2"},
           {"--fault bogus", "--fault is 'bogus'; allowed: wrong-crc, ignore-watchdog, drop-reports"},
           {"--sensor-trace-out x.csv", "--sensor-trace-out needs --sensor strokes"},
           {"--sensor strokes --sensor-speed-variation 2", "speed variation is 2; allowed 0 … 1"}}) {
    const CliRun r = run(std::string(TEXEL_CLI) + " controller --pty --duration 1 " + args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(says), std::string::npos) << args << "\n" << r.out;
  }
}
