// libFuzzer target for the serial protocol (serial_protocol.hpp,
// docs/serial-protocol.md) on both ends of the link; the first byte picks
// the side and the chunking, the rest is the byte stream that side receives:
//   0: the frame decoder alone, fed in chunks of 1 … 64 bytes: every frame
//      it hands out is whole (length ≤ max_payload, CRC correct, payload
//      readable), and a stream cannot yield more frames than it has bytes
//      for;
//   1: the display firmware (controller.hpp, Controller<1024, 2>) over a
//      scripted Hal: it never reads or writes outside its maps, keeps its
//      state in range, and every frame it answers with is well formed;
//   2: the host (serial_link.hpp, SerialLink over a socketpair whose other
//      end plays the display): HELLO then STATUS either return or throw a
//      texel::Error (IoError / SerialError), never anything else.
// A crash, a sanitizer report or an abort here is a bug.
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <vector>

#include "texel/controller/controller.hpp"
#include "texel/error.hpp"
#include "texel/serial_link.hpp"
#include "texel/serial_protocol.hpp"

namespace {

namespace serial = texel::serial;

void check_frame(const serial::Frame& f) {
  if (f.length > serial::max_payload) std::abort();
  // Re-encode: the CRC must be the one the frame carried (the decoder checked
  // it), and reading every payload byte must stay inside the decoder (ASan).
  std::uint8_t out[serial::max_frame];
  if (serial::encode_frame(f.type, f.seq, f.payload, f.length, out) != serial::header_size + f.length + serial::crc_size)
    std::abort();
}

void decoder(std::span<const std::uint8_t> in, std::size_t chunk) {
  serial::Decoder d;
  std::size_t frames = 0;
  for (std::size_t at = 0; at < in.size(); at += chunk) {
    const std::size_t n = std::min(chunk, in.size() - at);
    d.feed(
        in.data() + at, n,
        [&](const serial::Frame& f) {
          check_frame(f);
          ++frames;
        },
        [](serial::ErrorCode e) {
          if (e != serial::ErrorCode::bad_checksum && e != serial::ErrorCode::bad_length) std::abort();
        });
  }
  while (d.buffered() > 0)
    d.expire(
        [&](const serial::Frame& f) {
          check_frame(f);
          ++frames;
        },
        [](serial::ErrorCode) {});
  if (frames * (serial::header_size + serial::crc_size) > in.size()) std::abort();
}

/// A display whose serial port delivers the fuzz input in chunks and whose
/// clock advances 100 µs per reading; what the controller sends is decoded
/// and checked.
class ScriptedHal final : public texel::controller::Hal {
 public:
  ScriptedHal(std::span<const std::uint8_t> in, std::size_t chunk) : in_(in), chunk_(chunk) {}
  std::uint32_t micros() override { return now_ += 100; }
  int serial_read(std::uint8_t* buf, int max) override {
    const std::size_t n = std::min({chunk_, in_.size() - at_, static_cast<std::size_t>(max)});
    std::copy_n(in_.data() + at_, n, buf);
    at_ += n;
    return static_cast<int>(n);
  }
  bool serial_write(const std::uint8_t* buf, int n) override {
    if (n <= 0 || static_cast<std::size_t>(n) > serial::max_frame) std::abort();
    std::size_t frames = 0;
    replies_.feed(
        buf, static_cast<std::size_t>(n),
        [&](const serial::Frame& f) {
          check_frame(f);
          ++frames;
        },
        [](serial::ErrorCode) { std::abort(); });
    if (frames != 1 || replies_.buffered() != 0) std::abort();  // one whole frame per write
    return true;
  }
  bool read_position(std::int32_t&, bool&) override { return false; }
  void write_amplitude(std::uint16_t a) override { last_ = a; }
  void idle_until(std::uint32_t) override {}
  [[nodiscard]] bool drained() const { return at_ == in_.size(); }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t chunk_;
  std::size_t at_ = 0;
  std::uint32_t now_ = 0;
  std::uint16_t last_ = 0;
  serial::Decoder replies_;
};

void firmware(std::span<const std::uint8_t> in, std::size_t chunk) {
  using Controller = texel::controller::Controller<1024, 2>;
  ScriptedHal hal(in, chunk);
  const auto c = std::make_unique<Controller>(hal, texel::controller::Info{});
  while (!hal.drained()) c->poll();
  for (int i = 0; i < 300; ++i) c->poll();  // past 50 ms: a stalled partial frame expires
  const auto& s = c->status();
  if (s.selected != serial::no_map && s.selected >= Controller::slots) std::abort();
  for (std::uint8_t id = 0; id < Controller::slots; ++id)
    if (c->map_samples(id) > Controller::max_samples) std::abort();
}

void host(std::span<const std::uint8_t> in) {
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) != 0) return;
  // The display's bytes are all written up front (they fit the socket
  // buffer), then its end stops sending: the host reads them, then EOF.
  std::size_t at = 0;
  while (at < in.size()) {
    const ssize_t w = ::write(fds[1], in.data() + at, in.size() - at);
    if (w <= 0) break;
    at += static_cast<std::size_t>(w);
  }
  ::shutdown(fds[1], SHUT_WR);
  try {
    texel::SerialLink link(fds[0], "fuzz");
    link.timeout_ms = 50;
    link.attempts = 1;
    (void)link.hello();
    (void)link.status();
  } catch (const texel::Error&) {
    // Refused or disconnected, with a message: expected.
  }
  ::close(fds[1]);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> in(data + 1, size - 1);
  const std::size_t chunk = 1 + (data[0] >> 2) % 64;
  switch (data[0] % 3) {
    case 0: decoder(in, chunk); break;
    case 1: firmware(in, chunk); break;
    default: host(in.size() > 65536 ? in.first(65536) : in); break;
  }
  return 0;
}
