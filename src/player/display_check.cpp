// The display conformance check (see display_check.hpp; the checks are
// listed in docs/serial-protocol.md "Conformance: texel display-check").
#include "texel/display_check.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <thread>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {

std::string_view to_string(CheckOutcome o) {
  switch (o) {
    case CheckOutcome::pass: return "pass";
    case CheckOutcome::fail: return "fail";
    case CheckOutcome::skipped: return "skipped";
  }
  return "skipped";
}

bool DisplayCheckReport::passed() const {
  return !checks.empty() &&
         std::none_of(checks.begin(), checks.end(), [](const CheckResult& c) { return c.outcome == CheckOutcome::fail; });
}

const CheckResult* DisplayCheckReport::find(std::string_view name) const {
  for (const CheckResult& c : checks)
    if (c.name == name) return &c;
  return nullptr;
}

std::string DisplayCheckReport::to_text() const {
  std::string out;
  if (info.version != 0)
    out += "display '" + info.name + "': protocol " + std::to_string(info.version) + ", " + std::to_string(info.slots) +
           " slot(s), " + std::to_string(info.max_samples) + " samples, refresh " + detail::num(info.refresh_hz) +
           " Hz, max payload " + std::to_string(info.max_payload) + " bytes\n";
  std::size_t pass = 0, fail = 0, skip = 0;
  for (const CheckResult& c : checks) {
    const char* tag = c.outcome == CheckOutcome::pass ? "PASS" : c.outcome == CheckOutcome::fail ? "FAIL" : "SKIP";
    out += std::string(tag) + "  " + c.name + std::string(c.name.size() < 20 ? 20 - c.name.size() : 1, ' ') + c.detail + "\n";
    (c.outcome == CheckOutcome::pass ? pass : c.outcome == CheckOutcome::fail ? fail : skip)++;
  }
  out += std::string(passed() ? "conformant" : "NOT conformant") + ": " + std::to_string(pass) + " passed, " +
         std::to_string(fail) + " failed, " + std::to_string(skip) + " skipped\n";
  return out;
}

namespace {

std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

}  // namespace

std::string DisplayCheckReport::to_json() const {
  std::string out = "{\"display\": {\"name\": " + json_string(info.name) + ", \"version\": " + std::to_string(info.version) +
                    ", \"slots\": " + std::to_string(info.slots) + ", \"max_samples\": " + std::to_string(info.max_samples) +
                    ", \"refresh_hz\": " + detail::num(info.refresh_hz) +
                    ", \"max_payload\": " + std::to_string(info.max_payload) + "}, \"checks\": [";
  for (std::size_t i = 0; i < checks.size(); ++i) {
    out += (i ? ", " : "") + std::string("{\"name\": ") + json_string(checks[i].name) +
           ", \"outcome\": " + json_string(to_string(checks[i].outcome)) + ", \"detail\": " + json_string(checks[i].detail) + "}";
  }
  out += std::string("], \"passed\": ") + (passed() ? "true" : "false") + "}\n";
  return out;
}

namespace {

using Clock = std::chrono::steady_clock;
using serial::ErrorCode;

void sleep_ms(double ms) { std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(ms)); }
double since_s(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
std::uint16_t u16(double a) { return static_cast<std::uint16_t>(std::clamp(a, 0.0, 1.0) * 65535.0 + 0.5); }

// The test map: values far from each other and from the corrupt map's, never
// 0, on a 0.5 mm grid from −250 mm, so a sensor anywhere on a display lies on it.
constexpr std::uint32_t map_spacing_nm = 500000;
constexpr std::int32_t map_origin_nm = -250000000;
std::vector<std::uint16_t> pattern(std::size_t n) {
  std::vector<std::uint16_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint16_t>(1000 + (i * 7919) % 40000);
  return v;
}
constexpr std::uint16_t corrupt_value = 60000;

class Checks {
 public:
  Checks(const DisplayCheckOptions& o, DisplayCheckReport& r) : o_(o), r_(r) {}

  void run() {
    link_.emplace(o_.path, o_.baud);
    link_->timeout_ms = o_.timeout_ms;
    if (!handshake()) return;
    const DisplayInfo& info = r_.info;
    tick_ms_ = std::max(3.0, 3000.0 / info.refresh_hz);
    n_ = std::min<std::size_t>(1000, info.max_samples);
    map_ = pattern(n_);
    run_check("status", [&] { return status_check(); });
    run_check("limits.max_samples", [&] { return max_samples_check(); });
    run_check("limits.max_payload", [&] { return max_payload_check(); });
    run_check("limits.slots", [&] { return slots_check(); });
    run_check("upload.bad_crc", [&] { return bad_crc_check(); });
    run_check("select", [&] { return select_check(); });
    probe_sensor();
    if (sensor_ == false) {
      run_check("playback.position", [&] { return position_check(); });
      run_check("watchdog.position", [&] { return position_watchdog_check(); });
      skip("playback.sensor", "the display has no finger sensor: it plays streamed positions");
    } else {
      skip("playback.position", "the display senses its own finger: streamed positions are not used");
      skip("watchdog.position", "the display senses its own finger");
      run_check("playback.sensor", [&] { return sensor_playback_check(); });
    }
    run_check("playback.drive", [&] { return drive_check(); });
    run_check("watchdog.drive", [&] { return drive_watchdog_check(); });
    if (sensor_ == true)
      run_check("reports", [&] { return reports_check(); });
    else
      skip("reports", reports_skip_);
    run_check("errors.last_error", [&] { return last_error_check(); });
    run_check("link.resync", [&] { return resync_check(); });
    run_check("link.reconnect", [&] { return reconnect_check(); });
    run_check("rest", [&] { return rest_check(); });
  }

 private:
  // A check returns its detail and passes, or throws Failed (or anything:
  // an exception from the link is a failure too).
  struct Failed {
    std::string why;
  };
  void run_check(const std::string& name, const std::function<std::string()>& body) {
    try {
      r_.checks.push_back({name, CheckOutcome::pass, body()});
    } catch (const Failed& f) {
      r_.checks.push_back({name, CheckOutcome::fail, f.why});
    } catch (const std::exception& e) {
      r_.checks.push_back({name, CheckOutcome::fail, e.what()});
    }
  }
  void skip(const std::string& name, const std::string& why) { r_.checks.push_back({name, CheckOutcome::skipped, why}); }
  [[noreturn]] static void fail(const std::string& why) { throw Failed{why}; }

  DisplayStatus status_after_tick() {
    sleep_ms(tick_ms_);
    return link_->status();
  }
  // The amplitude a display playing map_ in slot 0 outputs at x (nearest
  // sample; an interpolating display lies between the two neighbours).
  [[nodiscard]] bool plays(double x_mm, std::uint16_t a) const {
    const double u = (x_mm * 1e6 - map_origin_nm) / map_spacing_nm;
    if (u < -0.5 || u > static_cast<double>(n_) - 0.5) return a == 0;  // off the map
    const auto i = static_cast<std::size_t>(std::clamp(std::floor(u), 0.0, static_cast<double>(n_ - 1)));
    const std::size_t j = std::min(i + 1, n_ - 1);
    const auto k = static_cast<std::size_t>(std::clamp(std::lround(u), 0L, static_cast<long>(n_ - 1)));
    return a == map_[k] || (a >= std::min(map_[i], map_[j]) && a <= std::max(map_[i], map_[j]));
  }
  template <class F>
  SerialError expect_refusal(const char* what, F&& request) {
    try {
      request();
    } catch (const SerialError& e) {
      return e;
    }
    fail(std::string(what) + " was accepted");
  }

  bool handshake() {
    try {
      r_.info = link_->hello();
    } catch (const std::exception& e) {
      r_.checks.push_back({"handshake", CheckOutcome::fail, e.what()});
      for (const char* n : {"status", "limits.max_samples", "limits.max_payload", "limits.slots", "upload.bad_crc", "select",
                            "playback.position", "watchdog.position", "playback.sensor", "playback.drive", "watchdog.drive",
                            "reports", "errors.last_error", "link.resync", "link.reconnect", "rest"})
        skip(n, "no handshake");
      return false;
    }
    const DisplayInfo& i = r_.info;
    r_.checks.push_back({"handshake", CheckOutcome::pass,
                         "HELLO_REPLY: version " + std::to_string(i.version) + ", " + std::to_string(i.slots) + " slot(s), " +
                             std::to_string(i.max_samples) + " samples, refresh " + detail::num(i.refresh_hz) + " Hz, payload " +
                             std::to_string(i.max_payload) + " bytes"});
    return true;
  }

  std::string status_check() {
    const DisplayStatus s = link_->status();
    revision_12_ = s.link_errors.has_value();
    if (s.mode < 0 || s.mode > 2) fail("STATUS mode is " + std::to_string(s.mode) + "; allowed 0, 1, 2");
    return revision_12_ ? "31 bytes (revision 1.2): link_errors " + std::to_string(*s.link_errors) + ", sensor " +
                              (*s.sensor() ? "yes" : "no")
                        : "26 bytes (revision 1.0/1.1)";
  }

  std::string max_samples_check() {
    const std::uint32_t m = r_.info.max_samples;
    link_->check_limits = false;
    std::string detail;
    if (m < (1u << 20)) {  // the refused map is built in memory first
      const SerialError e = expect_refusal("a map of max_samples + 1 samples", [&] {
        link_->upload_raw(0, std::vector<std::uint16_t>(std::size_t{m} + 1, 1), map_spacing_nm, 0);
      });
      link_->check_limits = true;
      if (e.code != ErrorCode::oversize_map)
        fail("max_samples + 1 refused with " + std::string(serial::describe(e.code)) + "; expected oversize_map");
      if (e.detail != m)
        fail("oversize_map detail is " + std::to_string(e.detail) + "; expected max_samples " + std::to_string(m));
      detail = std::to_string(m + 1) + " samples refused (oversize_map, detail " + std::to_string(e.detail) + ")";
    }
    link_->check_limits = true;
    if (m <= 65536) {  // the whole claimed capacity (128 KiB at most)
      link_->upload_raw(0, std::vector<std::uint16_t>(m, 777), map_spacing_nm, map_origin_nm);
      detail += (detail.empty() ? "" : "; ") + std::to_string(m) + " samples accepted";
    }
    return detail;
  }

  std::string max_payload_check() {
    const DisplayStatus before = link_->status();
    link_->upload_raw(0, map_, map_spacing_nm, map_origin_nm);
    const DisplayStatus after = link_->status();
    if (after.frames_bad != before.frames_bad)
      fail("the display dropped " + std::to_string(after.frames_bad - before.frames_bad) + " frame(s) of an upload in " +
           std::to_string(link_->payload_limit()) + "-byte payloads");
    return std::to_string(n_) + " samples in MAP_DATA payloads of up to " + std::to_string(link_->payload_limit()) + " bytes (" +
           std::to_string(serial::samples_per_chunk_for(link_->payload_limit())) + " samples each)";
  }

  std::string slots_check() {
    const int slots = r_.info.slots;
    for (int id = 1; id < slots; ++id) link_->upload_raw(static_cast<std::uint8_t>(id), pattern(16), map_spacing_nm, 0);
    if (slots >= 254) return std::to_string(slots) + " slots uploaded";
    link_->check_limits = false;
    const SerialError e = expect_refusal("an upload into slot `slots`", [&] {
      link_->upload_raw(static_cast<std::uint8_t>(slots), pattern(16), map_spacing_nm, 0);
    });
    link_->check_limits = true;
    if (e.code != ErrorCode::unknown_map)
      fail("slot " + std::to_string(slots) + " refused with " + serial::describe(e.code) + "; expected unknown_map");
    return std::to_string(slots) + " slot(s) take a map; slot " + std::to_string(slots) + " refused (unknown_map)";
  }

  std::string bad_crc_check() {
    const SerialError e = expect_refusal("a map with a wrong CRC-32", [&] {
      link_->upload_raw(0, std::vector<std::uint16_t>(n_ / 2 + 1, corrupt_value), map_spacing_nm, map_origin_nm, true);
    });
    if (e.code != ErrorCode::map_checksum)
      fail("the wrong CRC-32 was refused with " + std::string(serial::describe(e.code)) + "; expected map_checksum");
    link_->select(0);
    const DisplayStatus s = status_after_tick();
    if (s.map_samples != n_)
      fail("after a refused upload slot 0 holds " + std::to_string(s.map_samples) + " samples; the previous map had " +
           std::to_string(n_));
    return "refused (map_checksum), the previous map (" + std::to_string(n_) + " samples) kept";
  }

  std::string select_check() {
    link_->select(0);
    DisplayStatus s = status_after_tick();
    if (s.selected != 0) fail("after SELECT 0 STATUS says selected " + std::to_string(s.selected));
    link_->select(serial::no_map);
    s = status_after_tick();
    if (s.selected != -1) fail("after SELECT none STATUS says selected " + std::to_string(s.selected));
    if (s.amplitude != 0) fail("nothing selected, yet the output is " + std::to_string(s.amplitude));
    if (r_.info.slots < 254) {
      const SerialError e = expect_refusal("SELECT of a slot that does not exist",
                                           [&] { link_->select(static_cast<std::uint8_t>(r_.info.slots)); });
      if (e.code != ErrorCode::unknown_map)
        fail("SELECT of a missing slot refused with " + std::string(serial::describe(e.code)));
    }
    link_->select(0);
    return "SELECT 0, none (output 0), a missing slot refused";
  }

  void probe_sensor() {
    sensor_ = false;
    try {
      link_->start_reports(100000);
      sensor_ = true;
      link_->start_reports(0);
    } catch (const SerialError& e) {
      if (e.code == ErrorCode::no_sensor) {
        sensor_ = false;
        reports_skip_ = "the display has no finger sensor (REPORTS: no_sensor)";
      } else {
        // A display older than 1.1 does not say; 1.2's STATUS flags do.
        const DisplayStatus s = link_->status();
        sensor_ = s.sensor().value_or(false);
        reports_skip_ = "the display does not report its finger (REPORTS: " + std::string(serial::describe(e.code)) + ")";
        if (sensor_ == true) reports_skip_.clear();
      }
    } catch (const std::exception& e) {
      reports_skip_ = std::string("REPORTS not answered: ") + e.what();
    }
    try {
      std::array<FingerReport, 64> drain;
      while (link_->read_reports(drain, 5) > 0) {
      }
    } catch (const std::exception&) {  // the link's failure shows in the next check
    }
  }

  std::string position_check() {
    link_->select(0);
    const double lo = map_origin_nm * 1e-6, span = static_cast<double>(n_) * map_spacing_nm * 1e-6;
    int checked = 0;
    struct Probe {
      double x;
      bool touch;
    };
    std::vector<Probe> probes;
    for (int k = 0; k < 8; ++k) probes.push_back({lo + span * (0.05 + 0.11 * k), true});
    probes.push_back({lo + span * 0.5, false});  // lifted: at rest
    probes.push_back({lo - 10.0, true});         // off the map: at rest
    probes.push_back({lo + span * 0.3, true});   // last: driven, for the watchdog
    for (const Probe& p : probes) {
      for (int i = 0; i < 4; ++i) {
        link_->stream_position(p.x, p.touch);
        sleep_ms(1);
      }
      const DisplayStatus s = status_after_tick();
      last_stream_ = Clock::now();
      const bool ok = p.touch ? plays(s.x_mm, s.amplitude) && std::abs(s.x_mm - p.x) < 1e-5 : s.amplitude == 0;
      if (!ok)
        fail("at x = " + detail::num(p.x) + " mm, touch " + (p.touch ? "1" : "0") + " the output is " +
             std::to_string(s.amplitude) + " (STATUS x " + detail::num(s.x_mm) + " mm)");
      ++checked;
    }
    return std::to_string(checked) + " positions: the map's sample under the finger, 0 lifted and off the map";
  }

  // After the last streamed position (driven), STATUS must reach rest within
  // the 200 ms watchdog (plus slack).
  std::string position_watchdog_check() { return watchdog(last_stream_, "position"); }

  // The display went to rest between the last STATUS that showed it driven
  // and the first that shows it at rest. Only the times the host sent those
  // requests bound that moment from its side (the replies may come late on a
  // loaded host), so the check fails only when a request sent after the limit
  // still found the output driven: that is certain, whatever the host's delays.
  std::string watchdog(Clock::time_point last, const char* what) {
    const double limit = 0.2 + o_.watchdog_slack_s;
    auto driven_sent = last;
    DisplayStatus s;
    for (bool first = true; first || since_s(last) < 1.0; first = false) {
      if (!first) sleep_ms(5);
      const auto sent = Clock::now();
      s = link_->status();
      if (s.amplitude != 0) {
        driven_sent = sent;
        continue;
      }
      // At rest at once, though asked well inside the watchdog: the output
      // never followed the stream (a host stalled past it proves nothing).
      if (first && std::chrono::duration<double>(sent - last).count() < 0.1)
        fail(std::string("the output was at rest before the ") + what + " stream stopped");
      const double driven_at = std::chrono::duration<double>(driven_sent - last).count();
      const double rest_by = std::chrono::duration<double>(Clock::now() - last).count();
      if (driven_at > limit)
        fail(std::string("still driven ") + detail::fixed(driven_at * 1e3, 0) + " ms after the last " + what +
             " frame; allowed " + detail::fixed(limit * 1e3, 0) + " ms");
      return std::string("at rest ") + detail::fixed(std::max(driven_at, 0.0) * 1e3, 0) + "–" + detail::fixed(rest_by * 1e3, 0) +
             " ms after the last " + what + " frame (allowed " + detail::fixed(limit * 1e3, 0) + " ms)";
    }
    fail(std::string("still driven (") + std::to_string(s.amplitude) + ") 1 s after the last " + what + " frame");
  }

  std::string sensor_playback_check() {
    link_->select(0);
    int touching = 0, lifted = 0, off = 0;
    const auto t0 = Clock::now();
    while (since_s(t0) < 2.0 && touching < 100) {
      const DisplayStatus s = status_after_tick();
      if (!s.touch) {
        if (s.amplitude != 0) fail("the finger is lifted, yet the output is " + std::to_string(s.amplitude));
        ++lifted;
        continue;
      }
      if (!plays(s.x_mm, s.amplitude))
        fail("at the sensed x = " + detail::num(s.x_mm) + " mm the output is " + std::to_string(s.amplitude) +
             "; the selected map has another value there");
      ++touching;
      if (s.amplitude == 0) ++off;
    }
    if (touching < 10) fail("the sensor touched in only " + std::to_string(touching) + " of its readings in 2 s");
    return std::to_string(touching) + " sensed positions play the map under the finger, " + std::to_string(lifted) +
           " lifted readings at rest";
  }

  std::string drive_check() {
    const auto t0 = Clock::now();
    while (since_s(t0) < 0.05) {
      link_->stream_drive(0.5);
      sleep_ms(1);
    }
    link_->stream_drive(0.5);
    last_stream_ = Clock::now();
    const DisplayStatus s = link_->status();
    if (s.mode != 2) fail("streaming DRIVE, STATUS mode is " + std::to_string(s.mode) + "; expected 2 (drive)");
    if (s.amplitude != u16(0.5)) fail("DRIVE 0.5 (32768) output as " + std::to_string(s.amplitude));
    return "DRIVE 32768 output as 32768 (mode 2)";
  }

  std::string drive_watchdog_check() { return watchdog(last_stream_, "DRIVE"); }

  std::string reports_check() {
    constexpr std::uint32_t interval_us = 1000;
    const std::uint64_t lost0 = link_->reports_lost();
    link_->start_reports(interval_us);
    std::vector<FingerReport> got;
    std::array<FingerReport, 64> buf;
    const auto t0 = Clock::now();
    while (since_s(t0) < o_.reports_s) {
      const std::size_t n = link_->read_reports(buf, 20);
      got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
    }
    link_->start_reports(0);
    sleep_ms(20);
    while (link_->read_reports(buf, 5) > 0) {
    }
    const std::uint64_t lost = link_->reports_lost() - lost0;
    if (got.size() < 2) fail("only " + std::to_string(got.size()) + " report(s) in " + detail::num(o_.reports_s) + " s");
    for (std::size_t i = 1; i < got.size(); ++i)
      if (static_cast<std::int32_t>(got[i].t_us - got[i - 1].t_us) <= 0)
        fail("t_us not increasing: report " + std::to_string(i) + " at " + std::to_string(got[i].t_us) + " after " +
             std::to_string(got[i - 1].t_us));
    if (lost > 0) fail(std::to_string(lost) + " report(s) lost (gaps in seq) of " + std::to_string(got.size() + lost));
    const double mean_us = static_cast<double>(got.back().t_us - got.front().t_us) / static_cast<double>(got.size() - 1);
    if (mean_us < 0.95 * interval_us) fail("reports every " + detail::fixed(mean_us, 0) + " µs; asked for 1000 µs");
    const double expected = o_.reports_s * 1e6 / interval_us;
    if (static_cast<double>(got.size()) < 0.5 * expected)
      fail(std::to_string(got.size()) + " reports in " + detail::num(o_.reports_s) + " s; expected about " +
           detail::fixed(expected, 0));
    return std::to_string(got.size()) + " reports, every " + detail::fixed(mean_us, 0) + " µs, none lost, t_us increasing";
  }

  std::string last_error_check() {
    (void)link_->status();  // clears an earlier error (1.2)
    (void)expect_refusal("SELECT of a slot that does not exist",
                         [&] { link_->select(static_cast<std::uint8_t>(std::min(r_.info.slots, 253))); });
    const DisplayStatus s = link_->status();
    if (s.last_error != ErrorCode::unknown_map)
      fail("after a NACK unknown_map STATUS last_error is " + std::to_string(static_cast<int>(s.last_error)));
    if (!revision_12_) return "last_error shows the NACK (revision 1.0/1.1: no clearing rule)";
    const DisplayStatus again = link_->status();
    if (again.last_error != ErrorCode::none)
      fail("last_error still " + std::to_string(static_cast<int>(again.last_error)) +
           " after a STATUS reported it (1.2 clears it)");
    return "last_error shows the NACK, cleared once reported";
  }

  std::string resync_check() {
    const DisplayStatus before = link_->status();
    std::uint8_t f[serial::max_frame];
    const std::uint8_t none[1] = {serial::no_map};
    const std::size_t n = serial::encode_frame(serial::Type::select, 200, none, 1, f);
    f[n - 1] ^= 0x5A;  // a SELECT none with a wrong CRC: must not take effect
    link_->send_raw(std::as_bytes(std::span(f, n)));
    const std::uint8_t noise[] = {0x00, 0xA5, 0x13, 0xA5, 0x5A, 0x05};
    link_->send_raw(std::as_bytes(std::span(noise)));
    sleep_ms(80);  // a stalled partial frame is given up after 50 ms
    const DisplayStatus s = link_->status();
    if (s.selected != before.selected) fail("a SELECT with a wrong frame CRC took effect");
    if (s.frames_bad <= before.frames_bad) fail("a frame with a wrong CRC was not counted in frames_bad");
    return "a corrupted frame dropped and counted, garbage skipped, the next request answered";
  }

  std::string reconnect_check() {
    // The host goes away mid-frame and comes back: the display must answer
    // the new host's HELLO (its decoder gives the half frame up).
    const std::uint8_t half[] = {serial::sync0, serial::sync1, 0x02, 0x01, 14, 0, 0};
    link_->send_raw(std::as_bytes(std::span(half)));
    link_->rest_on_close = false;
    link_.reset();
    sleep_ms(20);
    link_.emplace(o_.path, o_.baud);
    link_->timeout_ms = o_.timeout_ms;
    const DisplayInfo i = link_->hello();
    if (i.slots != r_.info.slots || i.max_payload != r_.info.max_payload) fail("HELLO after reconnecting announces other limits");
    return "HELLO answered after the host left mid-frame and reopened the port";
  }

  std::string rest_check() {
    link_->select(0);
    link_->stream_drive(0.4);
    if (!link_->rest()) fail("rest (DRIVE 0, SELECT none) was not acknowledged");
    const DisplayStatus s = status_after_tick();
    if (s.selected != -1 || s.amplitude != 0)
      fail("after rest: selected " + std::to_string(s.selected) + ", output " + std::to_string(s.amplitude));
    return "DRIVE 0 and SELECT none acknowledged; output 0";
  }

  const DisplayCheckOptions& o_;
  DisplayCheckReport& r_;
  std::optional<SerialLink> link_;
  double tick_ms_ = 3.0;
  std::size_t n_ = 0;
  std::vector<std::uint16_t> map_;
  std::optional<bool> sensor_;
  std::string reports_skip_ = "the display does not report its finger";
  bool revision_12_ = false;
  Clock::time_point last_stream_{};
};

}  // namespace

DisplayCheckReport check_display(const DisplayCheckOptions& options) {
  if (!(options.watchdog_slack_s >= 0 && options.watchdog_slack_s <= 1))
    throw InvalidArgument("display-check: watchdog slack is " + detail::num(options.watchdog_slack_s) + " s; allowed 0 … 1");
  if (!(options.reports_s >= 0.1 && options.reports_s <= 10))
    throw InvalidArgument("display-check: report time is " + detail::num(options.reports_s) + " s; allowed 0.1 … 10");
  if (!(options.timeout_ms >= 10 && options.timeout_ms <= 10000))
    throw InvalidArgument("display-check: timeout is " + std::to_string(options.timeout_ms) + " ms; allowed 10 … 10000");
  DisplayCheckReport report;
  Checks(options, report).run();
  return report;
}

}  // namespace texel
