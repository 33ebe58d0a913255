// The host end of the serial protocol (docs/serial-protocol.md): talks to a
// friction display (or the reference controller over a pseudo-terminal) to
// upload maps, select one, and stream finger positions or drive values.
//
// Requests (HELLO, MAP_*, SELECT, STATUS) wait for their reply with a
// timeout and are retried; a NACK becomes a SerialError carrying the
// display's error code; a link that goes away (unplugged cable, closed pty)
// becomes an IoError naming the port — never a crash.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "texel/error.hpp"
#include "texel/serial_protocol.hpp"

namespace texel {

class PlayerMap;

/// The display refused a request (NACK).
class SerialError : public IoError {
 public:
  SerialError(const std::string& what, serial::ErrorCode error_code, std::uint32_t error_detail)
      : IoError(what), code(error_code), detail(error_detail) {}
  serial::ErrorCode code;
  std::uint32_t detail;
};

struct DisplayInfo {
  int version = 0;
  int slots = 0;
  std::uint32_t max_samples = 0;
  double refresh_hz = 0.0;
  std::size_t max_payload = 0;
  std::string name;
};

struct DisplayStatus {
  int selected = -1;  ///< -1: none
  int mode = 0;       ///< 0 idle, 1 position, 2 drive
  std::uint16_t amplitude = 0;
  double x_mm = 0.0;
  bool touch = false;
  std::uint32_t frames_ok = 0;
  std::uint32_t frames_bad = 0;
  serial::ErrorCode last_error = serial::ErrorCode::none;
  std::uint32_t map_samples = 0;
  std::uint32_t uptime_ms = 0;
};

/// One FINGER report of a display's own sensor (protocol 1.1).
struct FingerReport {
  std::uint32_t t_us = 0;  ///< the display's clock (µs, wraps at 2³²)
  double x_mm = 0.0, y_mm = 0.0;
  bool touch = false;
  std::uint8_t seq = 0;  ///< counts reports: a gap is a lost report
};

/// The display's report clock unwrapped into seconds since the first report
/// it is given, so a session may run for longer than the 71 minutes of the
/// 32-bit microsecond counter.
class ReportClock {
 public:
  double seconds(std::uint32_t t_us) noexcept {
    if (!started_) {
      started_ = true;
      last_ = t_us;
    }
    ticks_ += static_cast<std::uint32_t>(t_us - last_);  // modular difference: the wrap is free
    last_ = t_us;
    return static_cast<double>(ticks_) * 1e-6;
  }

 private:
  bool started_ = false;
  std::uint32_t last_ = 0;
  std::uint64_t ticks_ = 0;
};

/// Places a display's reports on the player's clock: t = display time +
/// offset, where the offset is the smallest (arrival − display time) seen —
/// the least-delayed report — so a report is never placed after it arrived.
/// The offset may rise by `drift` seconds per second, so a display clock
/// slower than the player's is followed instead of piling up delay.
class ReportTimeline {
 public:
  static constexpr double drift = 1e-3;
  /// `arrival_s`: when the report reached the host, on the player's clock.
  double place(std::uint32_t t_us, double arrival_s) noexcept {
    const double d = clock_.seconds(t_us);
    const double c = arrival_s - d;
    offset_ = have_ ? std::min(c, offset_ + drift * std::max(0.0, arrival_s - last_arrival_s_)) : c;
    have_ = true;
    last_arrival_s_ = arrival_s;
    return d + offset_;
  }

 private:
  ReportClock clock_;
  bool have_ = false;
  double offset_ = 0.0, last_arrival_s_ = 0.0;
};

class SerialLink {
 public:
  /// Opens `path` (a tty or pty), raw 8N1 at `baud`. Throws IoError.
  explicit SerialLink(const std::string& path, int baud = 921600);
  /// Adopts an open descriptor (closed by the destructor); `name` is used in messages.
  SerialLink(int fd, std::string name);
  ~SerialLink();
  SerialLink(const SerialLink&) = delete;
  SerialLink& operator=(const SerialLink&) = delete;

  /// Reply timeout per attempt (ms) and attempts per request.
  int timeout_ms = 300;
  int attempts = 3;

  DisplayInfo hello();
  /// Uploads amplitudes (clamped to [0, 1], encoded round(a·65535)) into slot `id`.
  void upload_map(std::uint8_t id, std::span<const float> amplitudes, double spacing_mm, double origin_mm = 0.0);
  void upload_map(std::uint8_t id, const PlayerMap& map);
  /// Uploads raw u16 samples (for tests of the display's checks).
  void upload_raw(std::uint8_t id, std::span<const std::uint16_t> samples, std::uint32_t spacing_nm, std::int32_t origin_nm,
                  bool corrupt_crc = false);
  void select(std::uint8_t id);
  /// Streams (no reply). Throw IoError if the link is gone.
  void stream_position(double x_mm, bool touch);
  void stream_drive(double amplitude);
  DisplayStatus status();

  /// Asks the display to report its finger sensor every `interval_us`
  /// (>= serial::min_report_interval_us; 0 stops). A display without a
  /// sensor refuses (SerialError no_sensor); one older than protocol 1.1
  /// does not know the request (SerialError naming that).
  void start_reports(std::uint32_t interval_us);
  /// Reads the finger reports that have arrived, waiting
  /// for the first (`wait_ms`); returns how many were written to `out`. Reports that
  /// came during a request are kept for this call. May run on one thread
  /// while another streams (stream_position/stream_drive); never together
  /// with a request. Throws IoError if the link is gone.
  std::size_t read_reports(std::span<FingerReport> out, int wait_ms);
  /// Reports the display sent that never arrived (gaps in their seq).
  [[nodiscard]] std::uint64_t reports_lost() const { return reports_lost_; }
  /// Sends raw bytes (tests: garbage, truncated frames).
  void send_raw(std::span<const std::byte> bytes);

  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  std::uint8_t send(serial::Type type, const std::uint8_t* payload, std::size_t n);
  /// Sends a request and waits for its reply; returns the reply's payload.
  std::string request(serial::Type type, const std::uint8_t* payload, std::size_t n, serial::Type expect, const char* what);
  void write_all(const std::uint8_t* p, std::size_t n);

  int fd_ = -1;
  std::string name_;
  std::uint8_t seq_ = 0;
  serial::Decoder decoder_{};
  // Finger reports read but not yet taken (bounded: the oldest are dropped,
  // in constant time).
  void keep_report(const serial::Frame& f);
  std::deque<FingerReport> pending_;
  bool have_report_seq_ = false;
  std::uint8_t next_report_seq_ = 0;
  std::uint64_t reports_lost_ = 0;
};

/// A display's finger reports read on a thread of their own (the display
/// was asked with SerialLink::start_reports): each batch that arrives is
/// handed to `on_reports` on that thread, until stop() or destruction. A link
/// error ends the thread and is kept (error()). The handler places reports on
/// its player's clock (ReportTimeline) and queues them; it may check
/// stopping() while it waits for a lock its stopper may hold.
class ReportReader {
 public:
  using Handler = std::function<void(std::span<const FingerReport>)>;
  ReportReader(SerialLink& link, Handler on_reports);
  ~ReportReader() { stop(); }
  ReportReader(const ReportReader&) = delete;
  ReportReader& operator=(const ReportReader&) = delete;
  /// Ends the thread (waits for the batch in hand). Idempotent.
  void stop();
  [[nodiscard]] bool stopping() const noexcept { return stop_.load(); }
  /// The link's error that ended the thread; empty while it runs.
  [[nodiscard]] std::string error() const;

 private:
  SerialLink& link_;
  Handler on_reports_;
  std::atomic<bool> stop_{false};
  mutable std::mutex error_mutex_;
  std::string error_;
  std::thread thread_;
};

}  // namespace texel
