// The host end of the serial protocol (docs/serial-protocol.md): talks to a
// friction display (or the reference controller over a pseudo-terminal) to
// upload maps, select one, and stream finger positions or drive values.
//
// Requests (HELLO, MAP_*, SELECT, STATUS) wait for their reply with a
// timeout and are retried; a NACK becomes a SerialError carrying the
// display's error code; a link that goes away (unplugged cable, closed pty)
// becomes an IoError naming the port — never a crash.
//
// The host's session (docs/serial-protocol.md "The host's sequence"):
//   hello()                       learn the display's limits (kept: info())
//   start_reports(interval)       if the host wants the display's finger
//   upload(slot, native_map(doc)) per slot, the document's exact bytes
//   select(slot)                  the display plays it from its own sensor,
//   or stream_position / stream_drive at the host's rate
//   rest()                        on every way out: end, pause, error, signal
// After hello() every upload keeps to what the display announced: MAP_DATA
// payloads of at most max_payload bytes, slots, max_samples.
//
// Threads: one thread may read finger reports (read_reports, a ReportReader)
// while another sends requests (SELECT per interval, STATUS, rest()) and a
// third streams (the serial Backend): frames are written whole, one at a
// time, and a request waits for a report read in progress (at most its
// wait_ms: 5 ms in a ReportReader), then reads its reply itself, keeping the
// reports that arrive meanwhile. timeout_ms, attempts and check_limits are
// set before the threads start.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "texel/error.hpp"
#include "texel/serial_protocol.hpp"

namespace texel {

class PlayerMap;
class Surface;
struct Document;

/// The display refused a request (NACK).
class SerialError : public IoError {
 public:
  SerialError(const std::string& what, serial::ErrorCode error_code, std::uint32_t error_detail)
      : IoError(what), code(error_code), detail(error_detail) {}
  serial::ErrorCode code;
  std::uint32_t detail;
};

/// What a display announced in HELLO_REPLY.
struct DisplayInfo {
  int version = 0;
  int slots = 0;                  ///< map slots, >= 1
  std::uint32_t max_samples = 0;  ///< samples per map, >= 1
  double refresh_hz = 0.0;        ///< output rate (the wire carries millihertz: refresh_mhz / 1000)
  std::size_t max_payload = 0;    ///< the largest payload the display accepts, 14 … 1024 bytes
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
  /// Revision 1.2 (absent from older displays, whose STATUS is 26 bytes):
  std::optional<std::uint32_t> link_errors;  ///< times the display found its link down
  std::optional<std::uint8_t> flags;         ///< serial::status_flag_* bits
  /// The display says it has a finger sensor (1.2); absent: it did not say.
  [[nodiscard]] std::optional<bool> sensor() const {
    return flags ? std::optional<bool>((*flags & serial::status_flag_sensor) != 0) : std::nullopt;
  }
};

/// A map as the display stores it: format-0 samples (round(a·65535)) on a
/// grid in nanometres. native_map() gives a document's exact bytes — the
/// ones `texel render --format bin` writes — with no float rounding on the
/// way (a PlayerMap holds float32, which moves 10 of tpad's 19,200 samples by
/// one step).
struct NativeMap {
  std::vector<std::uint16_t> samples;
  std::uint32_t spacing_nm = 0;
  std::int32_t origin_nm = 0;
};
/// The whole map of `surface` (all regions, gaps at rest), as `texel render`
/// encodes it. Throws InvalidArgument if the spacing or origin do not fit
/// the protocol (spacing 1 nm … 4.29 m, origin within ±2.1 m).
NativeMap native_map(const Surface& surface);
/// The map of a 1-D document on its device (prepare_surface, then the above).
NativeMap native_map(const Document& doc);

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

  /// Host-side checks of the display's announced limits before a request
  /// is sent (slot < slots, samples <= max_samples: a SerialError with the
  /// code and detail the display would give). `texel display-check` turns
  /// them off to see the display refuse by itself.
  bool check_limits = true;

  /// HELLO: learns the display's limits (kept, see info()). Throws IoError
  /// if the reply is malformed or announces limits the protocol does not
  /// allow (max_payload below 14, no slot, no sample, refresh 0).
  DisplayInfo hello();
  /// The last HELLO_REPLY (version 0 before hello()).
  [[nodiscard]] const DisplayInfo& info() const noexcept { return info_; }
  /// The largest MAP_DATA payload sent: the display's max_payload after
  /// hello(), the protocol's 1,024 bytes before.
  [[nodiscard]] std::size_t payload_limit() const noexcept { return payload_limit_; }

  /// Uploads a map into slot `id` exactly as given: MAP_BEGIN, MAP_DATA in
  /// chunks that fit the display's max_payload, MAP_END with the CRC-32.
  /// The way to upload a document: upload(id, native_map(doc)).
  void upload(std::uint8_t id, const NativeMap& map);
  /// Uploads amplitudes (clamped to [0, 1], encoded round(a·65535)) into slot
  /// `id`. For signals that exist only as floats; a document goes through
  /// native_map() instead, which keeps `texel render`'s exact bytes.
  void upload_map(std::uint8_t id, std::span<const float> amplitudes, double spacing_mm, double origin_mm = 0.0);
  /// A PlayerMap's float32 values (not a document's exact bytes: see NativeMap).
  void upload_map(std::uint8_t id, const PlayerMap& map);
  /// Uploads raw u16 samples; `corrupt_crc` sends a wrong CRC-32 (tests of
  /// the display's checks: it must answer map_checksum and keep its map).
  void upload_raw(std::uint8_t id, std::span<const std::uint16_t> samples, std::uint32_t spacing_nm, std::int32_t origin_nm,
                  bool corrupt_crc = false);
  /// SELECT: the slot to play (serial::no_map: none, output at rest).
  void select(std::uint8_t id);

  /// Puts the display at rest: DRIVE 0, then SELECT none, waiting for its
  /// ACK (one attempt of timeout_ms). Best effort and safe on every exit
  /// path: never throws — a dead link, a refusal or no reply give false
  /// (the display's own 200 ms watchdog then rests a driven plate). True:
  /// the display acknowledged. Not from a signal handler (set a flag, call
  /// it from the thread that owns the link). A streaming serial Backend
  /// would overwrite the DRIVE 0: stop it instead (its stop() rests the
  /// display).
  bool rest() noexcept;
  /// The destructor sends DRIVE 0 and SELECT none without waiting (a link
  /// destroyed while unwinding still leaves the display at rest); false
  /// leaves the display as it is (a test that hands the display on).
  bool rest_on_close = true;
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
  /// while others stream and send requests (a request waiting for the link
  /// makes this call return 0 at once, so it is not starved). Throws IoError
  /// if the link is gone.
  std::size_t read_reports(std::span<FingerReport> out, int wait_ms);
  /// Reports the display sent that never arrived (gaps in their seq).
  [[nodiscard]] std::uint64_t reports_lost() const { return reports_lost_.load(std::memory_order_relaxed); }
  /// Sends raw bytes (tests: garbage, truncated frames).
  void send_raw(std::span<const std::byte> bytes);

  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  std::uint8_t send(serial::Type type, const std::uint8_t* payload, std::size_t n);
  /// Sends a request and waits for its reply; returns the reply's payload.
  std::string request(serial::Type type, const std::uint8_t* payload, std::size_t n, serial::Type expect, const char* what,
                      int tries = 0);  // 0: `attempts`
  void write_all(const std::uint8_t* p, std::size_t n);

  void send_rest_frames() noexcept;

  int fd_ = -1;
  std::string name_;
  std::uint8_t seq_ = 0;
  DisplayInfo info_{};
  std::size_t payload_limit_ = serial::max_payload;
  serial::Decoder decoder_{};
  // Finger reports read but not yet taken (bounded: the oldest are dropped,
  // in constant time).
  void keep_report(const serial::Frame& f);
  std::deque<FingerReport> pending_;
  bool have_report_seq_ = false;
  std::uint8_t next_report_seq_ = 0;
  std::atomic<std::uint64_t> reports_lost_{0};
  std::mutex write_mutex_;  // one frame at a time on the wire, and seq_
  std::mutex read_mutex_;   // the decoder, pending_ and the report seq: one reader at a time
  std::atomic<int> requests_waiting_{0};
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
