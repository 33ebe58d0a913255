// Host end of the serial protocol (see serial_link.hpp).
#include "texel/serial_link.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "texel/controller/host_hal.hpp"
#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/player.hpp"
#include "texel/surface.hpp"

namespace texel {

using serial::ErrorCode;
using serial::Type;

SerialLink::SerialLink(const std::string& path, int baud) : fd_(controller::open_serial_port(path, baud)), name_(path) {}

SerialLink::SerialLink(int fd, std::string name) : fd_(fd), name_(std::move(name)) {
  const int flags = fcntl(fd_, F_GETFL);
  if (flags >= 0) fcntl(fd_, F_SETFL, flags | O_NONBLOCK);
}

SerialLink::~SerialLink() {
  if (fd_ < 0) return;
  if (rest_on_close) send_rest_frames();
  ::close(fd_);
}

namespace {
// One write attempt that never raises SIGPIPE (a socket whose peer is gone)
// and never waits: for the rest frames of a link that may be dead.
bool write_once(int fd, const std::uint8_t* p, std::size_t n) noexcept {
  ssize_t w = ::send(fd, p, n, MSG_NOSIGNAL | MSG_DONTWAIT);
  if (w < 0 && errno == ENOTSOCK) w = ::write(fd, p, n);
  return w == static_cast<ssize_t>(n);
}
}  // namespace

void SerialLink::send_rest_frames() noexcept {
  std::lock_guard lock(write_mutex_);
  std::uint8_t frame[serial::header_size + 2 + serial::crc_size];
  const std::uint8_t drive0[2] = {0, 0};
  std::size_t len = serial::encode_frame(Type::drive, seq_++, drive0, 2, frame);
  write_once(fd_, frame, len);
  const std::uint8_t none[1] = {serial::no_map};
  len = serial::encode_frame(Type::select, seq_++, none, 1, frame);
  write_once(fd_, frame, len);
}

bool SerialLink::rest() noexcept {
  if (fd_ < 0) return false;
  try {
    stream_drive(0.0);
    const std::uint8_t none[1] = {serial::no_map};
    request(Type::select, none, 1, Type::ack, "SELECT", 1);
    return true;
  } catch (...) {
    return false;
  }
}

void SerialLink::write_all(const std::uint8_t* p, std::size_t n) {
  std::size_t done = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (done < n) {
    const ssize_t w = ::write(fd_, p + done, n - done);
    if (w > 0) {
      done += static_cast<std::size_t>(w);
      continue;
    }
    if (w < 0 && (errno == EAGAIN || errno == EINTR)) {
      if (std::chrono::steady_clock::now() > deadline)
        throw IoError("serial link " + name_ + ": the display is not reading (write timed out)");
      pollfd pf{fd_, POLLOUT, 0};
      ::poll(&pf, 1, 5);
      continue;
    }
    throw IoError("serial link " + name_ +
                  ": the display is disconnected (write: " + std::string(w < 0 ? std::strerror(errno) : "nothing written") + ")");
  }
}

std::uint8_t SerialLink::send(Type type, const std::uint8_t* payload, std::size_t n) {
  std::lock_guard lock(write_mutex_);
  std::uint8_t frame[serial::max_frame];
  const std::uint8_t seq = seq_++;
  const std::size_t len = serial::encode_frame(type, seq, payload, n, frame);
  write_all(frame, len);
  return seq;
}

void SerialLink::send_raw(std::span<const std::byte> bytes) {
  std::lock_guard lock(write_mutex_);
  write_all(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

std::string SerialLink::request(Type type, const std::uint8_t* payload, std::size_t n, Type expect, const char* what, int tries) {
  if (tries <= 0) tries = attempts;
  requests_waiting_.fetch_add(1);
  std::unique_lock read_lock(read_mutex_);  // the reply is read here, not by a report reader
  requests_waiting_.fetch_sub(1);
  for (int attempt = 0; attempt < tries; ++attempt) {
    const std::uint8_t seq = send(type, payload, n);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    bool got = false;
    std::string reply;
    Type reply_type{};
    while (!got) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) break;
      pollfd pf{fd_, POLLIN, 0};
      const int r = ::poll(&pf, 1, static_cast<int>(left));
      if (r < 0 && errno == EINTR) continue;
      if (r == 0) break;
      std::uint8_t buf[512];
      const ssize_t got_n = ::read(fd_, buf, sizeof buf);
      if (got_n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
      if (got_n <= 0)
        throw IoError("serial link " + name_ + ": the display is disconnected (read: " +
                      std::string(got_n < 0 ? std::strerror(errno) : "end of file") + ") during " + what);
      decoder_.feed(
          buf, static_cast<std::size_t>(got_n),
          [&](const serial::Frame& f) {
            if (f.type == Type::finger) return keep_report(f);
            if (got || f.seq != seq) return;  // a late reply to an earlier attempt
            if (f.type == expect || f.type == Type::nack) {
              got = true;
              reply_type = f.type;
              reply.assign(reinterpret_cast<const char*>(f.payload), f.length);
            }
          },
          [](ErrorCode) {});
    }
    if (!got) continue;  // timed out: retry
    if (reply_type == Type::nack) {
      const auto* p = reinterpret_cast<const std::uint8_t*>(reply.data());
      const auto code = reply.size() >= 2 ? static_cast<ErrorCode>(p[1]) : ErrorCode::none;
      const std::uint32_t detail = reply.size() >= 6 ? serial::get_u32(p + 2) : 0;
      throw SerialError("serial link " + name_ + ": the display refused " + what + ": " + serial::describe(code) + " (code " +
                            std::to_string(static_cast<int>(code)) + ", detail " + std::to_string(detail) + ")",
                        code, detail);
    }
    return reply;
  }
  throw IoError("serial link " + name_ + ": no reply to " + what + " after " + std::to_string(tries) + " attempt(s) of " +
                std::to_string(timeout_ms) + " ms (is the display connected and running?)");
}

DisplayInfo SerialLink::hello() {
  const std::uint8_t p[1] = {serial::protocol_version};
  const std::string r = request(Type::hello, p, 1, Type::hello_reply, "HELLO");
  if (r.size() < 12)
    throw IoError("serial link " + name_ + ": HELLO_REPLY has " + std::to_string(r.size()) + " bytes; expected >= 12");
  const auto* b = reinterpret_cast<const std::uint8_t*>(r.data());
  DisplayInfo info;
  info.version = b[0];
  info.slots = b[1];
  info.max_samples = serial::get_u32(b + 2);
  info.refresh_hz = serial::get_u32(b + 6) / 1000.0;
  info.max_payload = serial::get_u16(b + 10);
  info.name = r.substr(12);
  const auto bad = [&](const char* field, const std::string& value, const char* allowed) {
    return IoError("serial link " + name_ + ": HELLO_REPLY " + field + " is " + value + "; allowed " + allowed);
  };
  if (info.slots < 1) throw bad("slots", std::to_string(info.slots), "1 … 254");
  if (info.max_samples < 1) throw bad("max_samples", std::to_string(info.max_samples), ">= 1");
  if (!(info.refresh_hz > 0)) throw bad("refresh_mhz", "0", ">= 1 (millihertz)");
  if (info.max_payload < serial::min_max_payload) throw bad("max_payload", std::to_string(info.max_payload), "14 … 1024 bytes");
  info_ = info;
  // A display may announce more than a frame can carry; the frame's limit holds.
  payload_limit_ = std::min<std::size_t>(info.max_payload, serial::max_payload);
  return info;
}

NativeMap native_map(const Surface& surface) {
  const Grid& g = surface.grid();
  const double spacing_nm = g.spacing.value() * 1e6, origin_nm = g.origin.value() * 1e6;
  if (!(spacing_nm >= 0.5 && spacing_nm < 4294967295.5))
    throw InvalidArgument("serial: map spacing is " + detail::num(g.spacing.value()) + " mm; allowed 1e-6 … 4294 mm");
  if (!(std::abs(origin_nm) < 2.1e9))
    throw InvalidArgument("serial: map origin is " + detail::num(g.origin.value()) + " mm; allowed −2100 … 2100 mm");
  const std::vector<std::byte> bytes = surface.render_native(SampleFormat::u16le);  // `texel render`'s bytes
  NativeMap m;
  m.samples.resize(bytes.size() / 2);
  for (std::size_t i = 0; i < m.samples.size(); ++i)
    m.samples[i] =
        static_cast<std::uint16_t>(std::to_integer<unsigned>(bytes[2 * i]) | (std::to_integer<unsigned>(bytes[2 * i + 1]) << 8));
  m.spacing_nm = static_cast<std::uint32_t>(std::llround(spacing_nm));
  m.origin_nm = static_cast<std::int32_t>(std::llround(origin_nm));
  return m;
}

NativeMap native_map(const Document& doc) { return native_map(prepare_surface(doc)); }

void SerialLink::upload(std::uint8_t id, const NativeMap& map) { upload_raw(id, map.samples, map.spacing_nm, map.origin_nm); }

void SerialLink::upload_raw(std::uint8_t id, std::span<const std::uint16_t> samples, std::uint32_t spacing_nm,
                            std::int32_t origin_nm, bool corrupt_crc) {
  if (check_limits && info_.version != 0) {
    // What the display would answer, without the round trip.
    if (id >= info_.slots)
      throw SerialError("serial link " + name_ + ": slot " + std::to_string(id) + " does not exist; the display has " +
                            std::to_string(info_.slots) + " (0 … " + std::to_string(info_.slots - 1) + ")",
                        ErrorCode::unknown_map, static_cast<std::uint32_t>(info_.slots));
    if (samples.size() > info_.max_samples)
      throw SerialError("serial link " + name_ + ": the map has " + std::to_string(samples.size()) +
                            " samples; the display holds at most " + std::to_string(info_.max_samples) + " (oversize_map)",
                        ErrorCode::oversize_map, info_.max_samples);
  }
  std::uint8_t begin[14] = {id, 0};
  serial::put_u32(begin + 2, static_cast<std::uint32_t>(samples.size()));
  serial::put_u32(begin + 6, spacing_nm);
  serial::put_i32(begin + 10, origin_nm);
  request(Type::map_begin, begin, sizeof begin, Type::ack, "MAP_BEGIN");
  std::uint8_t chunk[serial::max_payload];
  std::uint32_t crc = 0;
  const std::size_t per_chunk = serial::samples_per_chunk_for(payload_limit_);  // >= 4 (payload >= 14)
  for (std::size_t first = 0; first < samples.size(); first += per_chunk) {
    const std::size_t n = std::min(per_chunk, samples.size() - first);
    chunk[0] = id;
    serial::put_u32(chunk + 1, static_cast<std::uint32_t>(first));
    for (std::size_t i = 0; i < n; ++i) serial::put_u16(chunk + 5 + 2 * i, samples[first + i]);
    crc = serial::crc32(chunk + 5, 2 * n, crc);
    try {
      request(Type::map_data, chunk, 5 + 2 * n, Type::ack, "MAP_DATA");
    } catch (const SerialError& e) {
      // A retried chunk whose first ACK was lost: the display already has it.
      if (!(e.code == ErrorCode::out_of_order && e.detail == first + n)) throw;
    }
  }
  std::uint8_t end[5] = {id};
  serial::put_u32(end + 1, corrupt_crc ? ~crc : crc);
  request(Type::map_end, end, sizeof end, Type::ack, "MAP_END");
}

void SerialLink::upload_map(std::uint8_t id, std::span<const float> amplitudes, double spacing_mm, double origin_mm) {
  if (!(std::isfinite(spacing_mm) && spacing_mm > 0 && spacing_mm * 1e6 < 4.2e9))
    throw InvalidArgument("serial: map spacing is " + std::to_string(spacing_mm) + " mm; allowed > 0 … 4200 mm");
  std::vector<std::uint16_t> s(amplitudes.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double a = std::isfinite(amplitudes[i]) ? std::clamp(static_cast<double>(amplitudes[i]), 0.0, 1.0) : 0.0;
    s[i] = static_cast<std::uint16_t>(a * 65535.0 + 0.5);
  }
  upload_raw(id, s, static_cast<std::uint32_t>(std::lround(spacing_mm * 1e6)),
             static_cast<std::int32_t>(std::lround(origin_mm * 1e6)));
}

void SerialLink::upload_map(std::uint8_t id, const PlayerMap& map) {
  upload_map(id, map.values(), map.grid().spacing.value(), map.grid().origin.value());
}

void SerialLink::select(std::uint8_t id) {
  const std::uint8_t p[1] = {id};
  request(Type::select, p, 1, Type::ack, "SELECT");
}

void SerialLink::stream_position(double x_mm, bool touch) {
  std::uint8_t p[5];
  const double nm = std::isfinite(x_mm) ? std::clamp(x_mm * 1e6, -2.1e9, 2.1e9) : 0.0;
  serial::put_i32(p, static_cast<std::int32_t>(std::lround(nm)));
  p[4] = touch ? 1 : 0;
  send(Type::position, p, sizeof p);
}

void SerialLink::stream_drive(double amplitude) {
  std::uint8_t p[2];
  const double a = std::isfinite(amplitude) ? std::clamp(amplitude, 0.0, 1.0) : 0.0;
  serial::put_u16(p, static_cast<std::uint16_t>(a * 65535.0 + 0.5));
  send(Type::drive, p, sizeof p);
}

DisplayStatus SerialLink::status() {
  const std::string r = request(Type::status_request, nullptr, 0, Type::status, "STATUS");
  if (r.size() < serial::status_payload_1_0)
    throw IoError("serial link " + name_ + ": STATUS has " + std::to_string(r.size()) + " bytes; expected >= 26");
  const auto* b = reinterpret_cast<const std::uint8_t*>(r.data());
  DisplayStatus s;
  s.selected = b[0] == serial::no_map ? -1 : b[0];
  s.mode = b[1];
  s.amplitude = serial::get_u16(b + 2);
  s.x_mm = serial::get_i32(b + 4) / 1e6;
  s.touch = b[8] != 0;
  s.frames_ok = serial::get_u32(b + 9);
  s.frames_bad = serial::get_u32(b + 13);
  s.last_error = static_cast<ErrorCode>(b[17]);
  s.map_samples = serial::get_u32(b + 18);
  s.uptime_ms = serial::get_u32(b + 22);
  if (r.size() >= serial::status_payload) {  // revision 1.2; longer: fields of a later revision, ignored
    s.link_errors = serial::get_u32(b + 26);
    s.flags = b[30];
  }
  return s;
}

void SerialLink::keep_report(const serial::Frame& f) {
  if (f.length != serial::finger_payload) return;  // malformed: not a report
  if (have_report_seq_ && f.seq != next_report_seq_)
    reports_lost_.fetch_add(static_cast<std::uint8_t>(f.seq - next_report_seq_), std::memory_order_relaxed);
  have_report_seq_ = true;
  next_report_seq_ = static_cast<std::uint8_t>(f.seq + 1);
  constexpr std::size_t max_pending = 4096;  // about 4 s at 1 kHz
  if (pending_.size() >= max_pending) {
    pending_.pop_front();
    reports_lost_.fetch_add(1, std::memory_order_relaxed);
  }
  FingerReport r;
  r.t_us = serial::get_u32(f.payload);
  r.x_mm = serial::get_i32(f.payload + 4) / 1e6;
  r.y_mm = serial::get_i32(f.payload + 8) / 1e6;
  r.touch = f.payload[12] != 0;
  r.seq = f.seq;
  pending_.push_back(r);
}

void SerialLink::start_reports(std::uint32_t interval_us) {
  if (interval_us != 0 && interval_us < serial::min_report_interval_us)
    throw InvalidArgument("serial link " + name_ + ": report interval is " + std::to_string(interval_us) +
                          " µs; allowed 0 or >= " + std::to_string(serial::min_report_interval_us));
  std::uint8_t p[4];
  serial::put_u32(p, interval_us);
  try {
    request(Type::reports, p, sizeof p, Type::ack, "REPORTS");
  } catch (const SerialError& e) {
    if (e.code != ErrorCode::unknown_type) throw;
    throw SerialError("serial link " + name_ +
                          ": the display does not report its finger (REPORTS is unknown to it: its firmware predates "
                          "protocol 1.1)",
                      e.code, e.detail);
  }
  std::lock_guard lock(read_mutex_);
  have_report_seq_ = false;
}

std::size_t SerialLink::read_reports(std::span<FingerReport> out, int wait_ms) {
  if (requests_waiting_.load() > 0) {  // let the request have the link (the mutex is not fair)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    return 0;
  }
  std::lock_guard lock(read_mutex_);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::max(0, wait_ms));
  while (pending_.size() < out.size()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    pollfd pf{fd_, POLLIN, 0};
    // Wait only while nothing is pending; then just drain what has arrived.
    const int r = ::poll(&pf, 1, pending_.empty() ? static_cast<int>(std::max<long long>(0, left)) : 0);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    std::uint8_t buf[512];
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n <= 0)
      throw IoError("serial link " + name_ + ": the display is disconnected (read: " +
                    std::string(n < 0 ? std::strerror(errno) : "end of file") + ") while reading finger reports");
    decoder_.feed(
        buf, static_cast<std::size_t>(n),
        [&](const serial::Frame& f) {
          if (f.type == Type::finger) keep_report(f);
        },
        [](ErrorCode) {});
  }
  const std::size_t k = std::min(out.size(), pending_.size());
  std::copy_n(pending_.begin(), k, out.begin());
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(k));
  return k;
}

ReportReader::ReportReader(SerialLink& link, Handler on_reports) : link_(link), on_reports_(std::move(on_reports)) {
  thread_ = std::thread([this] {
    std::array<FingerReport, 64> buf;
    try {
      while (!stop_) {
        const std::size_t n = link_.read_reports(buf, 5);
        if (n > 0) on_reports_(std::span<const FingerReport>(buf.data(), n));
      }
    } catch (const std::exception& e) {
      std::lock_guard lock(error_mutex_);
      error_ = e.what();
    }
  });
}

void ReportReader::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::string ReportReader::error() const {
  std::lock_guard lock(error_mutex_);
  return error_;
}

}  // namespace texel
