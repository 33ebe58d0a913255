// The Texel serial protocol between a host and a friction display
// (docs/serial-protocol.md is the byte-by-byte reference; keep them in step).
//
// Frame:  A5 5A | type u8 | seq u8 | length u16le | payload (length bytes) | crc u16le
// The CRC is CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection,
// no final xor) over type, seq, length and payload. All integers are
// little-endian. A whole map additionally carries a CRC-32 (IEEE 802.3) in
// MAP_END, so a map assembled from many frames is checked end to end.
//
// This header is portable C++20 with no heap, no exceptions and no
// dependency beyond <cstdint>/<cstddef>/<cstring>, so the display's
// microcontroller firmware (include/texel/controller/) and the host share it.
// The Decoder resynchronises by itself: a frame whose CRC fails is dropped one
// byte at a time, so a valid frame hidden inside a corrupted or truncated one
// is still found.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace texel::serial {

inline constexpr std::uint8_t sync0 = 0xA5;
inline constexpr std::uint8_t sync1 = 0x5A;
inline constexpr std::uint8_t protocol_version = 1;
/// The revision this header implements (docs/serial-protocol.md): 1.0 the
/// maps and streams, 1.1 the finger reports, 1.2 the longer STATUS. A
/// revision only appends (messages, error codes, STATUS fields at the end),
/// so HELLO still carries version 1 and every revision talks to every other.
inline constexpr std::uint8_t protocol_revision_minor = 2;
inline constexpr std::size_t header_size = 6;  ///< sync0 sync1 type seq len(2)
inline constexpr std::size_t crc_size = 2;
inline constexpr std::size_t max_payload = 1024;
inline constexpr std::size_t max_frame = header_size + max_payload + crc_size;
/// Samples per MAP_DATA frame whose payload may be at most `payload` bytes
/// (5-byte header + 2 bytes each): 509 at 1,024 bytes, 125 at 256.
constexpr std::size_t samples_per_chunk_for(std::size_t payload) { return payload >= 7 ? (payload - 5) / 2 : 0; }
/// Samples per MAP_DATA frame at the protocol's largest payload.
inline constexpr std::size_t samples_per_chunk = samples_per_chunk_for(max_payload);
/// The smallest max_payload a display may announce: room for MAP_BEGIN (14
/// bytes) and a MAP_DATA of one sample.
inline constexpr std::size_t min_max_payload = 14;
/// STATUS payload sizes: 26 bytes in revisions 1.0 and 1.1; 1.2 appends
/// link_errors u32 and flags u8 (a host reads what is there).
inline constexpr std::size_t status_payload_1_0 = 26;
inline constexpr std::size_t status_payload = 31;
/// STATUS flags (1.2, byte 30).
inline constexpr std::uint8_t status_flag_sensor = 0x01;     ///< the display has a finger sensor
inline constexpr std::uint8_t status_flag_reporting = 0x02;  ///< FINGER reports are on
inline constexpr std::uint8_t status_flag_stale = 0x04;      ///< streamed values expired: output at rest
inline constexpr std::uint8_t no_map = 0xFF;
/// FINGER payload: t_us u32, x_nm i32, y_nm i32, touch u8.
inline constexpr std::size_t finger_payload = 13;
/// The host watchdog's timeout range (ms), HOST_WATCHDOG (1.2).
inline constexpr std::uint32_t min_host_timeout_ms = 20;
inline constexpr std::uint32_t max_host_timeout_ms = 60000;
/// The shortest interval between finger reports a display accepts (µs).
inline constexpr std::uint32_t min_report_interval_us = 100;

enum class Type : std::uint8_t {
  hello = 0x01,           ///< host → display: [version u8]
  map_begin = 0x02,       ///< [id u8][format u8][samples u32][spacing_nm u32][origin_nm i32]
  map_data = 0x03,        ///< [id u8][first u32][samples u16 × n]
  map_end = 0x04,         ///< [id u8][crc32 of the sample bytes u32]
  select = 0x05,          ///< [id u8] (0xFF: none, output at rest)
  position = 0x06,        ///< [x_nm i32][touch u8] — streamed, no reply
  drive = 0x07,           ///< [amplitude u16] — streamed, no reply
  status_request = 0x08,  ///< empty
  reports = 0x09,         ///< host → display: [interval_us u32] (0 = stop) — the display's finger reports (1.1)
  host_watchdog = 0x0A,   ///< host → display: [timeout_ms u32] (0 = off): rest if the host goes silent (1.2)
  keepalive = 0x0B,       ///< host → display: empty — streamed, no reply; keeps the host watchdog fed (1.2)
  ack = 0x7E,             ///< display → host: [type u8]
  nack = 0x7F,            ///< display → host: [type u8][error u8][detail u32]
  hello_reply = 0x81,     ///< [version u8][slots u8][max_samples u32][refresh_mhz u32][max_payload u16][name…]
  status = 0x88,          ///< see docs/serial-protocol.md
  finger = 0x89,          ///< display → host, streamed: [t_us u32][x_nm i32][y_nm i32][touch u8] (1.1)
};

enum class ErrorCode : std::uint8_t {
  none = 0,
  bad_checksum = 1,  ///< frame CRC failed (counted; cannot be answered reliably)
  unknown_type = 2,
  bad_length = 3,          ///< payload length wrong for the type
  oversize_map = 4,        ///< detail: the display's max samples
  unknown_map = 5,         ///< id out of range, or selecting an empty slot
  out_of_order = 6,        ///< MAP_DATA not contiguous, or MAP_END before all samples; detail: next expected index
  map_checksum = 7,        ///< MAP_END CRC-32 mismatch; the previous map is kept
  unsupported_format = 8,  ///< only format 0 (u16le) exists in version 1
  no_upload = 9,           ///< MAP_DATA / MAP_END without a MAP_BEGIN for that id
  bad_version = 10,        ///< detail: the display's version
  bad_value = 11,          ///< e.g. spacing 0
  no_sensor = 12,          ///< REPORTS asked of a display without a finger sensor (1.1)
};

inline const char* describe(ErrorCode e) {
  switch (e) {
    case ErrorCode::none: return "no error";
    case ErrorCode::bad_checksum: return "frame checksum mismatch";
    case ErrorCode::unknown_type: return "unknown message type";
    case ErrorCode::bad_length: return "payload length wrong for the message type";
    case ErrorCode::oversize_map: return "map larger than the display can hold";
    case ErrorCode::unknown_map: return "unknown or empty map slot";
    case ErrorCode::out_of_order: return "map samples out of order or missing";
    case ErrorCode::map_checksum: return "map CRC-32 mismatch";
    case ErrorCode::unsupported_format: return "unsupported sample format";
    case ErrorCode::no_upload: return "no map upload in progress for that slot";
    case ErrorCode::bad_version: return "protocol version not supported";
    case ErrorCode::bad_value: return "field value out of range";
    case ErrorCode::no_sensor: return "the display has no finger sensor";
  }
  return "unknown error";
}

// ------------------------------------------------------------------ checksums

/// CRC-16/CCITT-FALSE; check value for "123456789" is 0x29B1.
constexpr std::uint16_t crc16(const std::uint8_t* p, std::size_t n, std::uint16_t crc = 0xFFFF) {
  for (std::size_t i = 0; i < n; ++i) {
    crc = static_cast<std::uint16_t>(crc ^ (p[i] << 8));
    for (int b = 0; b < 8; ++b) crc = static_cast<std::uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
  }
  return crc;
}

/// CRC-32 (IEEE 802.3, reflected, poly 0xEDB88320); check value for
/// "123456789" is 0xCBF43926. Pass the previous result as `crc` to continue.
constexpr std::uint32_t crc32(const std::uint8_t* p, std::size_t n, std::uint32_t crc = 0) {
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int b = 0; b < 8; ++b) crc = (crc & 1u) ? (crc >> 1) ^ 0xEDB88320u : crc >> 1;
  }
  return ~crc;
}

// ------------------------------------------------------------ little endian

inline void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_i32(std::uint8_t* p, std::int32_t v) { put_u32(p, static_cast<std::uint32_t>(v)); }
inline std::uint16_t get_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
inline std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) | (static_cast<std::uint32_t>(p[2]) << 16) |
         (static_cast<std::uint32_t>(p[3]) << 24);
}
inline std::int32_t get_i32(const std::uint8_t* p) { return static_cast<std::int32_t>(get_u32(p)); }

// ------------------------------------------------------------------- framing

/// Writes a frame into `out` (room for length + 8 bytes); returns its size,
/// or 0 if length > max_payload.
inline std::size_t encode_frame(Type type, std::uint8_t seq, const std::uint8_t* payload, std::size_t length, std::uint8_t* out) {
  if (length > max_payload) return 0;
  out[0] = sync0;
  out[1] = sync1;
  out[2] = static_cast<std::uint8_t>(type);
  out[3] = seq;
  put_u16(out + 4, static_cast<std::uint16_t>(length));
  if (length) std::memcpy(out + header_size, payload, length);
  put_u16(out + header_size + length, crc16(out + 2, 4 + length));
  return header_size + length + crc_size;
}

/// A decoded frame; `payload` points into the decoder and is valid only
/// during the callback.
struct Frame {
  Type type;
  std::uint8_t seq;
  std::uint16_t length;
  const std::uint8_t* payload;
};

/// Byte-stream decoder with a fixed buffer (2 frames). feed() calls
/// on_frame(const Frame&) for each valid frame and on_error(ErrorCode) for
/// each rejected one (bad_checksum, bad_length). Garbage between frames is
/// skipped silently (counted in skipped()).
class Decoder {
 public:
  template <class OnFrame, class OnError>
  void feed(const std::uint8_t* data, std::size_t n, OnFrame&& on_frame, OnError&& on_error) {
    while (n > 0) {
      if (start_ > 0 && end_ + n > sizeof buf_) compact();
      const std::size_t room = sizeof buf_ - end_;
      const std::size_t take = n < room ? n : room;
      std::memcpy(buf_ + end_, data, take);
      end_ += take;
      data += take;
      n -= take;
      parse(on_frame, on_error);
    }
  }

  /// Gives up on a partial frame that has stalled (call when no byte has
  /// arrived for a while): drops its first byte and rescans the rest.
  template <class OnFrame, class OnError>
  void expire(OnFrame&& on_frame, OnError&& on_error) {
    if (end_ > start_) {
      ++start_;
      ++skipped_;
      parse(on_frame, on_error);
    }
  }

  void reset() { start_ = end_ = 0; }
  [[nodiscard]] std::size_t buffered() const { return end_ - start_; }
  [[nodiscard]] std::uint32_t skipped() const { return skipped_; }

 private:
  void compact() {
    std::memmove(buf_, buf_ + start_, end_ - start_);
    end_ -= start_;
    start_ = 0;
  }

  template <class OnFrame, class OnError>
  void parse(OnFrame& on_frame, OnError& on_error) {
    while (end_ > start_) {
      const std::uint8_t* p = buf_ + start_;
      const std::size_t avail = end_ - start_;
      if (p[0] != sync0 || (avail >= 2 && p[1] != sync1)) {
        ++start_;
        ++skipped_;
        continue;
      }
      if (avail < header_size) break;
      const std::size_t length = get_u16(p + 4);
      if (length > max_payload) {
        on_error(ErrorCode::bad_length);
        ++start_;
        continue;
      }
      const std::size_t total = header_size + length + crc_size;
      if (avail < total) {
        if (start_ > 0 && end_ == sizeof buf_) compact();
        break;
      }
      if (crc16(p + 2, 4 + length) != get_u16(p + header_size + length)) {
        on_error(ErrorCode::bad_checksum);
        ++start_;  // resync: a frame may start inside this one
        continue;
      }
      const Frame f{static_cast<Type>(p[2]), p[3], static_cast<std::uint16_t>(length), p + header_size};
      start_ += total;
      on_frame(f);
    }
    if (start_ == end_) start_ = end_ = 0;
  }

  std::uint8_t buf_[2 * max_frame]{};
  std::size_t start_ = 0;
  std::size_t end_ = 0;
  std::uint32_t skipped_ = 0;
};

}  // namespace texel::serial
