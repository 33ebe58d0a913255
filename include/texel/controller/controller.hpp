// The reference display controller: the firmware side of the serial protocol
// (docs/serial-protocol.md). It receives maps from the host, reads the
// finger position (from its own sensor or from the host's stream) and writes
// the friction amplitude at the display's refresh rate (8,333 Hz on `tpad`),
// as the TPaD's microcontroller does (docs/algorithm.md §8).
//
// Portable C++20 for a microcontroller: no heap, no exceptions, no RTTI
// needed at run time, no standard library beyond <cstdint>/<cstring>. All
// storage is inside the object (sized by the template parameters), so
// firmware declares one `static Controller<…> c(hal, info);` and calls
// c.poll() in its main loop. The hardware is reached only through Hal.
//
// Robustness: a corrupted or partial frame is dropped and the decoder
// resynchronises on the next sync; a map is uploaded into a staging buffer
// and only installed when its CRC-32 checks, so the controller always keeps
// its last good map; a link that goes down is counted and retried, and
// puts the output at rest (the selection is cleared, the maps are kept).
//
// Safe by default: only frames from the host refresh the watchdog. Streamed
// positions or drive values older than stream_timeout_us (200 ms) put the
// output at rest, even on a display whose own sensor still senses the finger
// — a host that dies (SIGKILL, a cut cable) cannot leave the plate driven.
// A display playing its selected map from its own sensor needs no stream: it
// outputs the map under the finger, and 0 while the finger is lifted; a host
// that arms the host watchdog (HOST_WATCHDOG, 1.2) and then goes silent for
// its timeout puts it at rest as a lost link does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "texel/serial_protocol.hpp"

namespace texel::controller {

struct Status;

/// The hardware abstraction: everything the controller touches.
class Hal {
 public:
  /// Monotonic microseconds (wraps at 2³²; the controller handles the wrap).
  virtual std::uint32_t micros() = 0;
  /// Non-blocking read of up to `max` bytes: the count read (0 = none),
  /// or < 0 if the link is down (unplugged cable, closed pty).
  virtual int serial_read(std::uint8_t* buf, int max) = 0;
  /// Writes all `n` bytes; false if the link is down.
  virtual bool serial_write(const std::uint8_t* buf, int n) = 0;
  /// The display's own finger sensor: true and the position if it has one;
  /// false to use positions streamed by the host.
  virtual bool read_position(std::int32_t& x_nm, bool& touch) = 0;
  /// The sensor of a 2-D display: true and the position (x, y) if it has one.
  /// The default is the 1-D sensor with y = 0, so 1-D firmware needs nothing.
  virtual bool read_position_2d(std::int32_t& x_nm, std::int32_t& y_nm, bool& touch) {
    y_nm = 0;
    return read_position(x_nm, touch);
  }
  /// Sets the friction amplitude (0 = at rest, 65535 = full).
  virtual void write_amplitude(std::uint16_t amplitude) = 0;
  /// Idles until about `t_us` (or returns early when bytes arrive).
  virtual void idle_until(std::uint32_t t_us) = 0;
  /// Called after every output update with the controller's state (a log,
  /// a test probe). The default does nothing; keep it short, it runs on
  /// every tick.
  virtual void on_tick(std::uint32_t /*t_us*/, const Status& /*status*/) {}

 protected:
  ~Hal() = default;
};

/// Deliberate misbehaviour, for testing a host's conformance check
/// (`texel display-check`) against displays that break the protocol. Never
/// set in firmware.
enum Fault : std::uint8_t {
  fault_none = 0,
  fault_wrong_crc = 0x01,        ///< installs an uploaded map whatever MAP_END's CRC-32 says
  fault_ignore_watchdog = 0x02,  ///< keeps playing streamed values however old
  fault_drop_reports = 0x04,     ///< loses every 7th FINGER report (its seq is skipped)
};

struct Info {
  const char* name = "texel-reference";      ///< reported in HELLO_REPLY (≤ 32 bytes used)
  std::uint32_t refresh_mhz = 8333000;       ///< output rate in millihertz (8,333,000 mHz = 8,333 Hz)
  std::uint32_t stream_timeout_us = 200000;  ///< streamed position/drive older than this: output at rest
  /// The largest payload the display accepts, announced in HELLO_REPLY:
  /// serial::min_max_payload … serial::max_payload. Longer frames are
  /// refused (NACK bad_length, detail = this), streamed ones counted.
  std::uint16_t max_payload = static_cast<std::uint16_t>(serial::max_payload);
  std::uint8_t slots = 0;            ///< slots announced and used, 1 … Slots; 0 = Slots
  std::uint32_t max_samples = 0;     ///< samples per map announced and accepted, 1 … MaxSamples; 0 = MaxSamples
  std::uint8_t faults = fault_none;  ///< Fault bits (tests only)
};

enum class Mode : std::uint8_t { idle = 0, position = 1, drive = 2 };

/// Counters and state, for STATUS and for tests.
struct Status {
  std::uint8_t selected = serial::no_map;
  Mode mode = Mode::idle;
  std::uint16_t amplitude = 0;
  std::int32_t x_nm = 0;
  std::int32_t y_nm = 0;  ///< a 2-D sensor's y (0 on a 1-D display)
  bool touch = false;
  std::uint32_t frames_ok = 0;
  std::uint32_t drive_values = 0;  ///< DRIVE frames taken (a local count; the STATUS reply does not carry it)
  std::uint32_t frames_bad = 0;    ///< frames dropped unanswered: CRC and length errors, malformed streamed frames
  std::uint32_t nacks = 0;
  std::uint32_t link_errors = 0;         ///< times the link was found down
  std::uint32_t ticks = 0;               ///< output updates
  std::uint32_t reports = 0;             ///< FINGER reports sent
  std::uint32_t report_interval_us = 0;  ///< 0: not reporting
  std::uint32_t host_timeout_us = 0;     ///< the armed host watchdog (0: off)
  std::uint32_t host_timeouts = 0;       ///< times the host went silent past it
  bool stale = false;                    ///< streamed values expired: the output is at rest
  /// The latest error (NACK sent or frame dropped) since the last STATUS
  /// reply, which reports and clears it.
  serial::ErrorCode last_error = serial::ErrorCode::none;
};

template <std::size_t MaxSamples = 32768, std::size_t Slots = 2>
class Controller {
  static_assert(Slots >= 1 && Slots < serial::no_map, "1 … 254 map slots");

 public:
  static constexpr std::size_t max_samples = MaxSamples;
  static constexpr std::size_t slots = Slots;

  Controller(Hal& hal, const Info& info) : hal_(hal), info_(info) {
    if (info_.slots == 0 || info_.slots > Slots) info_.slots = static_cast<std::uint8_t>(Slots);
    if (info_.max_samples == 0 || info_.max_samples > MaxSamples) info_.max_samples = static_cast<std::uint32_t>(MaxSamples);
    if (info_.max_payload < serial::min_max_payload) info_.max_payload = static_cast<std::uint16_t>(serial::min_max_payload);
    if (info_.max_payload > serial::max_payload) info_.max_payload = static_cast<std::uint16_t>(serial::max_payload);
    start_us_ = hal_.micros();
    next_tick_us_ = start_us_;
    stream_us_ = start_us_ - info_.stream_timeout_us - 1;  // nothing streamed yet: stale
  }

  /// One pass of the main loop: drains the serial port, answers frames and,
  /// when a refresh tick is due, updates the output. Never blocks.
  void poll() {
    // A loop that fell behind by more than two ticks (a host that did not
    // schedule it; a firmware's timer never does) first brings its output up
    // to this moment — the watchdog included — so the frames it now drains,
    // a STATUS request among them, meet the output as it is, not as it was
    // before the gap.
    if (static_cast<std::int32_t>(hal_.micros() - next_tick_us_) > static_cast<std::int32_t>(tick_offset_us(2))) step();
    drain_serial();
    if (static_cast<std::int32_t>(hal_.micros() - next_tick_us_) >= 0) step();
  }

  /// Runs poll() until should_stop() is true, idling between ticks.
  template <class Stop>
  void run(Stop&& should_stop) {
    while (!should_stop()) {
      poll();
      hal_.idle_until(next_tick_us_);
    }
  }

  [[nodiscard]] const Status& status() const { return status_; }
  [[nodiscard]] bool link_up() const { return link_up_; }
  /// The limits in force (Info's, bounded by the template's).
  [[nodiscard]] const Info& info() const { return info_; }
  /// Samples held in slot `id` (0 if empty or out of range).
  [[nodiscard]] std::uint32_t map_samples(std::uint8_t id) const { return id < Slots ? maps_[id].samples : 0; }
  /// Sample i of slot id (for tests).
  [[nodiscard]] std::uint16_t map_value(std::uint8_t id, std::uint32_t i) const {
    return id < Slots && i < maps_[id].samples ? maps_[id].data[i] : 0;
  }

 private:
  struct Map {
    std::uint32_t samples = 0;  // 0 = empty
    std::uint32_t spacing_nm = 0;
    std::int32_t origin_nm = 0;
    std::uint16_t data[MaxSamples];
  };

  // One output update at the time now, then the next tick's time; a loop that
  // fell behind (host scheduling, a long map copy) skips the missed ticks
  // instead of bursting through them.
  void step() {
    const std::uint32_t now = hal_.micros();
    tick(now);
    ++tick_count_;
    next_tick_us_ = start_us_ + tick_offset_us(tick_count_);
    if (static_cast<std::int32_t>(now - next_tick_us_) > 0) {
      const std::uint64_t behind = (static_cast<std::uint64_t>(now - next_tick_us_) * info_.refresh_mhz) / 1000000000ull + 1;
      tick_count_ += behind;
      next_tick_us_ = start_us_ + tick_offset_us(tick_count_);
    }
  }

  [[nodiscard]] std::uint32_t tick_offset_us(std::uint64_t k) const {
    return static_cast<std::uint32_t>((k * 1000000000ull) / info_.refresh_mhz);
  }

  void drain_serial() {
    std::uint8_t buf[256];
    for (int rounds = 0; rounds < 64; ++rounds) {  // bounded work per poll
      const int n = hal_.serial_read(buf, static_cast<int>(sizeof buf));
      if (n < 0) {
        if (link_up_) link_lost();
        return;
      }
      link_up_ = true;
      if (n == 0) break;
      last_byte_us_ = hal_.micros();
      decoder_.feed(
          buf, static_cast<std::size_t>(n), [this](const serial::Frame& f) { handle(f); },
          [this](serial::ErrorCode e) { bad_frame(e); });
    }
    // A partial frame that has stalled for 50 ms will never complete.
    if (decoder_.buffered() > 0 && static_cast<std::int32_t>(hal_.micros() - last_byte_us_) > 50000) {
      decoder_.expire([this](const serial::Frame& f) { handle(f); }, [this](serial::ErrorCode e) { bad_frame(e); });
      last_byte_us_ = hal_.micros();
    }
  }

  // The host is gone (or the cable): nothing it asked for stands. The output
  // goes to rest until a host selects or streams again; the maps are kept.
  void link_lost() {
    ++status_.link_errors;
    link_up_ = false;
    decoder_.reset();  // a half frame from before the break is worthless
    rest_now();
  }
  void rest_now() {
    status_.host_timeout_us = 0;  // disarmed: the next host arms it again
    upload_active_ = false;
    status_.selected = serial::no_map;
    status_.mode = Mode::idle;
    drive_ = 0;
    stream_us_ = hal_.micros() - info_.stream_timeout_us - 1;
  }

  void bad_frame(serial::ErrorCode e) {
    ++status_.frames_bad;
    status_.last_error = e;
  }

  void tick(std::uint32_t now) {
    if (status_.host_timeout_us != 0 && static_cast<std::uint32_t>(now - last_host_us_) > status_.host_timeout_us) {
      // The host that armed the watchdog went silent: as if the link were lost.
      ++status_.host_timeouts;
      rest_now();
    }
    std::int32_t x = 0, y = 0;
    bool touch = false;
    // Only host frames refresh the watchdog: a sensor reading says where the
    // finger is, not that the host still wants the plate driven.
    const bool stale =
        (info_.faults & fault_ignore_watchdog) == 0 && static_cast<std::uint32_t>(now - stream_us_) > info_.stream_timeout_us;
    const bool sensed = hal_.read_position_2d(x, y, touch);
    if (sensed) {
      if (status_.report_interval_us != 0 && static_cast<std::int32_t>(now - next_report_us_) >= 0) report(now, x, y, touch);
    } else {
      x = stream_x_nm_;
      touch = stream_touch_;
    }
    std::uint16_t a = 0;
    if (status_.mode == Mode::drive) {
      a = stale ? 0 : drive_;
      status_.stale = stale;
    } else if (touch && (sensed || !stale) && status_.selected < info_.slots) {
      const Map& m = maps_[status_.selected];
      // Nearest sample, as the TPaD's firmware does: its sensor resolution
      // equals the map spacing.
      const std::int64_t rel = static_cast<std::int64_t>(x) - m.origin_nm;
      if (rel >= 0) {
        const std::int64_t idx = (rel + m.spacing_nm / 2) / m.spacing_nm;
        if (idx < static_cast<std::int64_t>(m.samples)) a = m.data[idx];
      }
      status_.stale = false;
    } else {
      // Position mode from streamed positions that stopped arriving, or
      // lifted, off the map, nothing selected.
      status_.stale = status_.mode == Mode::position && !sensed && stale;
    }
    status_.x_nm = x;
    status_.y_nm = y;
    status_.touch = touch;
    status_.amplitude = a;
    ++status_.ticks;
    hal_.write_amplitude(a);
    hal_.on_tick(now, status_);
  }

  // A FINGER report of the sensor's reading at `now`; its seq counts reports,
  // so the host sees any it lost. Reports stay on the interval's grid and
  // skip, rather than burst, when the loop fell behind.
  void report(std::uint32_t now, std::int32_t x, std::int32_t y, bool touch) {
    std::uint8_t p[serial::finger_payload];
    serial::put_u32(p, now);
    serial::put_i32(p + 4, x);
    serial::put_i32(p + 8, y);
    p[12] = touch ? 1 : 0;
    const std::uint32_t k = status_.reports++;
    if ((info_.faults & fault_drop_reports) == 0 || k % 7 != 3)
      send(serial::Type::finger, static_cast<std::uint8_t>(k), p, sizeof p);
    next_report_us_ += status_.report_interval_us;
    if (static_cast<std::int32_t>(now - next_report_us_) >= 0) next_report_us_ = now + status_.report_interval_us;
  }

  void send(serial::Type type, std::uint8_t seq, const std::uint8_t* payload, std::size_t n) {
    const std::size_t len = serial::encode_frame(type, seq, payload, n, tx_);
    if (!hal_.serial_write(tx_, static_cast<int>(len)) && link_up_) link_lost();
  }
  void ack(const serial::Frame& f) {
    const std::uint8_t p[1] = {static_cast<std::uint8_t>(f.type)};
    send(serial::Type::ack, f.seq, p, 1);
  }
  void nack(const serial::Frame& f, serial::ErrorCode e, std::uint32_t detail = 0) {
    std::uint8_t p[6] = {static_cast<std::uint8_t>(f.type), static_cast<std::uint8_t>(e)};
    serial::put_u32(p + 2, detail);
    ++status_.nacks;
    status_.last_error = e;
    send(serial::Type::nack, f.seq, p, 6);
  }

  void handle(const serial::Frame& f) {
    using serial::ErrorCode;
    using serial::Type;
    ++status_.frames_ok;
    last_host_us_ = hal_.micros();  // any valid frame feeds the host watchdog
    const std::uint8_t* p = f.payload;
    if (f.length > info_.max_payload) {
      if (f.type == Type::position || f.type == Type::drive || f.type == Type::keepalive) return bad_stream(f);
      return nack(f, ErrorCode::bad_length, info_.max_payload);
    }
    switch (f.type) {
      case Type::hello: {
        if (f.length != 1) return nack(f, ErrorCode::bad_length, 1);
        if (p[0] != serial::protocol_version) return nack(f, ErrorCode::bad_version, serial::protocol_version);
        std::uint8_t r[12 + 32];
        r[0] = serial::protocol_version;
        r[1] = info_.slots;
        serial::put_u32(r + 2, info_.max_samples);
        serial::put_u32(r + 6, info_.refresh_mhz);
        serial::put_u16(r + 10, info_.max_payload);
        std::size_t name_len = std::strlen(info_.name);
        if (name_len > 32) name_len = 32;
        std::memcpy(r + 12, info_.name, name_len);
        return send(Type::hello_reply, f.seq, r, 12 + name_len);
      }
      case Type::map_begin: {
        if (f.length != 14) return nack(f, ErrorCode::bad_length, 14);
        const std::uint8_t id = p[0];
        const std::uint32_t samples = serial::get_u32(p + 2);
        const std::uint32_t spacing = serial::get_u32(p + 6);
        upload_active_ = false;  // a MAP_BEGIN abandons any open upload, whatever its answer
        if (id >= info_.slots) return nack(f, ErrorCode::unknown_map, info_.slots);
        if (p[1] != 0) return nack(f, ErrorCode::unsupported_format);
        if (samples > info_.max_samples) return nack(f, ErrorCode::oversize_map, info_.max_samples);
        if (samples == 0 || spacing == 0) return nack(f, ErrorCode::bad_value);
        staging_.samples = samples;
        staging_.spacing_nm = spacing;
        staging_.origin_nm = serial::get_i32(p + 10);
        upload_id_ = id;
        upload_next_ = 0;
        upload_crc_ = 0;
        upload_active_ = true;
        return ack(f);
      }
      case Type::map_data: {
        if (f.length < 7 || (f.length - 5) % 2 != 0) return nack(f, ErrorCode::bad_length);
        if (!upload_active_ || p[0] != upload_id_) return nack(f, ErrorCode::no_upload);
        const std::uint32_t first = serial::get_u32(p + 1);
        const std::uint32_t n = (f.length - 5u) / 2u;
        if (first != upload_next_) return nack(f, ErrorCode::out_of_order, upload_next_);
        if (n > staging_.samples - upload_next_) return nack(f, ErrorCode::oversize_map, staging_.samples);
        for (std::uint32_t i = 0; i < n; ++i) staging_.data[first + i] = serial::get_u16(p + 5 + 2 * i);
        upload_crc_ = serial::crc32(p + 5, 2u * n, upload_crc_);
        upload_next_ += n;
        return ack(f);
      }
      case Type::map_end: {
        if (f.length != 5) return nack(f, ErrorCode::bad_length, 5);
        if (!upload_active_ || p[0] != upload_id_) return nack(f, ErrorCode::no_upload);
        upload_active_ = false;
        if (upload_next_ != staging_.samples) return nack(f, ErrorCode::out_of_order, upload_next_);
        if (serial::get_u32(p + 1) != upload_crc_ && (info_.faults & fault_wrong_crc) == 0)
          return nack(f, ErrorCode::map_checksum, upload_crc_);
        Map& dst = maps_[upload_id_];
        dst.samples = staging_.samples;
        dst.spacing_nm = staging_.spacing_nm;
        dst.origin_nm = staging_.origin_nm;
        std::memcpy(dst.data, staging_.data, sizeof(std::uint16_t) * staging_.samples);
        return ack(f);
      }
      case Type::select: {
        if (f.length != 1) return nack(f, ErrorCode::bad_length, 1);
        if (p[0] != serial::no_map && (p[0] >= info_.slots || maps_[p[0]].samples == 0))
          return nack(f, ErrorCode::unknown_map, info_.slots);
        status_.selected = p[0];
        status_.mode = Mode::position;
        return ack(f);
      }
      case Type::position: {
        if (f.length != 5) return bad_stream(f);
        stream_x_nm_ = serial::get_i32(p);
        stream_touch_ = p[4] != 0;
        stream_us_ = hal_.micros();
        status_.mode = Mode::position;
        return;
      }
      case Type::drive: {
        if (f.length != 2) return bad_stream(f);
        drive_ = serial::get_u16(p);
        ++status_.drive_values;
        stream_us_ = hal_.micros();
        status_.mode = Mode::drive;
        return;
      }
      case Type::reports: {
        if (f.length != 4) return nack(f, ErrorCode::bad_length, 4);
        const std::uint32_t interval = serial::get_u32(p);
        if (interval != 0 && interval < serial::min_report_interval_us)
          return nack(f, ErrorCode::bad_value, serial::min_report_interval_us);
        std::int32_t x = 0, y = 0;
        bool touch = false;
        if (interval != 0 && !hal_.read_position_2d(x, y, touch)) return nack(f, ErrorCode::no_sensor);
        status_.report_interval_us = interval;
        next_report_us_ = hal_.micros();
        return ack(f);
      }
      case Type::host_watchdog: {
        if (f.length != 4) return nack(f, ErrorCode::bad_length, 4);
        const std::uint32_t ms = serial::get_u32(p);
        if (ms != 0 && (ms < serial::min_host_timeout_ms || ms > serial::max_host_timeout_ms))
          return nack(f, ErrorCode::bad_value, serial::min_host_timeout_ms);
        status_.host_timeout_us = ms * 1000u;
        return ack(f);
      }
      case Type::keepalive: {
        if (f.length != 0) return bad_stream(f);
        return;  // fed above
      }
      case Type::status_request: {
        if (f.length != 0) return nack(f, ErrorCode::bad_length, 0);
        std::uint8_t r[serial::status_payload];
        r[0] = status_.selected;
        r[1] = static_cast<std::uint8_t>(status_.mode);
        serial::put_u16(r + 2, status_.amplitude);
        serial::put_i32(r + 4, status_.x_nm);
        r[8] = status_.touch ? 1 : 0;
        serial::put_u32(r + 9, status_.frames_ok);
        serial::put_u32(r + 13, status_.frames_bad);
        r[17] = static_cast<std::uint8_t>(status_.last_error);
        serial::put_u32(r + 18, status_.selected < Slots ? maps_[status_.selected].samples : 0);
        serial::put_u32(r + 22, static_cast<std::uint32_t>(hal_.micros() - start_us_) / 1000u);
        // Revision 1.2: appended, so a 1.0 host reads the 26 bytes it knows.
        serial::put_u32(r + 26, status_.link_errors);
        std::int32_t sx = 0, sy = 0;
        bool st = false;
        r[30] = static_cast<std::uint8_t>((hal_.read_position_2d(sx, sy, st) ? serial::status_flag_sensor : 0) |
                                          (status_.report_interval_us != 0 ? serial::status_flag_reporting : 0) |
                                          (status_.stale ? serial::status_flag_stale : 0));
        status_.last_error = ErrorCode::none;  // reported: cleared
        return send(Type::status, f.seq, r, sizeof r);
      }
      default: return nack(f, ErrorCode::unknown_type);
    }
  }

  // Streamed frames are never answered (the host does not wait); a malformed
  // one is only counted.
  void bad_stream(const serial::Frame&) {
    ++status_.frames_bad;
    status_.last_error = serial::ErrorCode::bad_length;
  }

  Hal& hal_;
  Info info_;
  Status status_{};
  serial::Decoder decoder_{};
  std::uint8_t tx_[serial::max_frame]{};
  Map maps_[Slots]{};
  Map staging_{};
  bool upload_active_ = false;
  std::uint8_t upload_id_ = 0;
  std::uint32_t upload_next_ = 0;
  std::uint32_t upload_crc_ = 0;
  std::int32_t stream_x_nm_ = 0;
  bool stream_touch_ = false;
  std::uint32_t stream_us_ = 0;
  std::uint16_t drive_ = 0;
  std::uint32_t next_report_us_ = 0;
  std::uint32_t last_host_us_ = 0;
  bool link_up_ = true;
  std::uint32_t start_us_ = 0;
  std::uint32_t last_byte_us_ = 0;
  std::uint32_t next_tick_us_ = 0;
  std::uint64_t tick_count_ = 0;
};

}  // namespace texel::controller
