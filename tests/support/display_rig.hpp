// The reference display controller running in-process on the master side of
// a pty, on its own thread; the host talks to the slave side by path, as
// `texel play --backend serial:PATH` and `texel studio --backend serial:PATH`
// do (tests/controller, tests/studio).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <pty.h>
#include <unistd.h>

#include "texel/controller/controller.hpp"
#include "texel/controller/host_hal.hpp"

namespace texel::test_support {

struct DisplayRig {
  using SmallController = controller::Controller<32768, 2>;
  int master = -1;
  int slave = -1;
  std::string path;
  std::unique_ptr<controller::HostHal> hal;
  std::unique_ptr<SmallController> ctl;
  std::atomic<bool> stop{false};
  std::thread thread;

  /// One output update of the display: the amplitude it put out and how many
  /// DRIVE values it had taken by then (so a test can tell one host step from
  /// a burst of values that a loaded machine delivered at once).
  struct Tick {
    std::uint16_t amplitude = 0;
    std::uint32_t drive_values = 0;
  };
  /// Starts logging every output update (from the display's own thread).
  void start_log() {
    const std::lock_guard lock(log_mutex_);
    log_.clear();
    logging_ = true;
  }
  /// Stops logging and returns the updates since start_log().
  std::vector<Tick> take_log() {
    const std::lock_guard lock(log_mutex_);
    logging_ = false;
    return std::move(log_);
  }

  /// `sensor_2d`: the display's own 2-D finger sensor (none: positions from the host).
  explicit DisplayRig(std::function<bool(std::int32_t&, std::int32_t&, bool&)> sensor_2d = {})
      : DisplayRig(controller::Info{}, {}, std::move(sensor_2d)) {}
  /// A display with the limits and faults of `info` and optionally a 1-D
  /// (`sensor_1d`) or 2-D finger sensor.
  DisplayRig(const controller::Info& info, std::function<bool(std::int32_t&, bool&)> sensor_1d,
             std::function<bool(std::int32_t&, std::int32_t&, bool&)> sensor_2d = {}) {
    char name[256];
    if (openpty(&master, &slave, name, nullptr, nullptr) != 0) throw std::runtime_error("openpty failed");
    path = name;
    controller::make_raw(slave);
    hal = std::make_unique<controller::HostHal>(master);
    hal->sensor = std::move(sensor_1d);
    hal->sensor_2d = std::move(sensor_2d);
    hal->tick_observer = [this](std::uint32_t, const controller::Status& st) {
      const std::lock_guard lock(log_mutex_);
      if (logging_ && log_.size() < max_log) log_.push_back({st.amplitude, st.drive_values});
    };
    ctl = std::make_unique<SmallController>(*hal, info);
    thread = std::thread([this] { ctl->run([this] { return stop.load(); }); });
  }
  ~DisplayRig() {
    halt();
    if (slave >= 0) ::close(slave);
  }
  DisplayRig(const DisplayRig&) = delete;
  DisplayRig& operator=(const DisplayRig&) = delete;
  void halt() {
    stop = true;
    if (thread.joinable()) thread.join();
  }

 private:
  static constexpr std::size_t max_log = 1u << 20;
  std::mutex log_mutex_;
  bool logging_ = false;
  std::vector<Tick> log_;
};

}  // namespace texel::test_support
