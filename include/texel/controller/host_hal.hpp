// A host (POSIX) implementation of the controller's Hal: the serial port is
// a file descriptor (a real UART, or one end of a pseudo-terminal), the clock
// is std::chrono::steady_clock, and the "actuator" records the last amplitude
// written. Used by `texel controller` and by the host ↔ controller tests.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "texel/controller/controller.hpp"

namespace texel::controller {

class HostHal final : public Hal {
 public:
  /// Takes ownership of `fd` (set non-blocking here).
  explicit HostHal(int fd);
  ~HostHal();
  HostHal(const HostHal&) = delete;
  HostHal& operator=(const HostHal&) = delete;

  std::uint32_t micros() override;
  int serial_read(std::uint8_t* buf, int max) override;
  bool serial_write(const std::uint8_t* buf, int n) override;
  bool read_position(std::int32_t& x_nm, bool& touch) override;
  bool read_position_2d(std::int32_t& x_nm, std::int32_t& y_nm, bool& touch) override;
  void write_amplitude(std::uint16_t amplitude) override;
  void idle_until(std::uint32_t t_us) override;
  void on_tick(std::uint32_t t_us, const Status& status) override;

  /// Optional local finger sensor (tests); unset = positions come from the host.
  std::function<bool(std::int32_t&, bool&)> sensor;
  /// Optional local 2-D finger sensor (a 2-D display; `texel controller
  /// --sensor`); takes precedence over `sensor`.
  std::function<bool(std::int32_t&, std::int32_t&, bool&)> sensor_2d;
  /// Called on the controller's thread after every output update (a log:
  /// `texel controller --log`); unset = nothing.
  std::function<void(std::uint32_t t_us, const Status&)> tick_observer;
  /// The last amplitude written and how many writes.
  std::atomic<std::uint16_t> amplitude{0};
  std::atomic<std::uint64_t> writes{0};
  /// Frames dropped whole because the host stopped reading (the transmit
  /// queue was full).
  std::atomic<std::uint64_t> tx_dropped{0};
  /// Closes the descriptor (simulates unplugging the display).
  void close_link();

  /// The transmit queue (bytes): what the link has not taken yet waits here,
  /// so the output loop never blocks on a host that stopped reading — as a
  /// firmware's USB or UART transmit buffer. A frame that does not fit is
  /// dropped whole (the host sees the gap in the report sequence).
  static constexpr std::size_t tx_capacity = 16384;

 private:
  bool flush();  // writes what is queued, without blocking; false: the link is gone
  int fd_ = -1;
  bool down_ = false;
  std::vector<std::uint8_t> tx_;  // reserved to tx_capacity once: no allocation in the loop
  std::size_t tx_head_ = 0;       // the first byte not yet written
};

/// Opens a serial device or pty path read/write, non-blocking, raw 8N1 at
/// `baud` (ignored by pseudo-terminals). Throws IoError naming the path.
int open_serial_port(const std::string& path, int baud = 921600);
/// Puts a terminal descriptor in raw mode (no echo, no line discipline).
void make_raw(int fd, int baud = 921600);

}  // namespace texel::controller
