// texel controller: runs the reference friction-display controller
// (include/texel/controller/) on this computer, on a serial port or on a new
// pseudo-terminal (--pty prints its path for `texel play --backend
// serial:PATH`). The "actuator" is a status line showing the amplitude.
// --sensor gives it a finger sensor (a simulated 2-D stroke, or a recorded
// x, y trace, played in a loop, the finger lifted between passes), so it
// acts as a 2-D display that reports its finger (protocol 1.1) for
// `texel play --finger serial:PATH`.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <thread>
#include <vector>

#include <pty.h>
#include <unistd.h>

#include "commands.hpp"
#include "texel/controller/controller.hpp"
#include "texel/controller/host_hal.hpp"
#include "texel/detail/format.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"
#include "texel/player2d.hpp"

namespace texel::cli {
namespace {

std::atomic<bool> stop_requested{false};
extern "C" void on_signal(int) { stop_requested = true; }

struct ControllerArgs {
  std::optional<std::string> serial;
  bool pty = false;
  std::string device = "tpad";
  int baud = 921600;
  double duration_s = 0.0;
  bool quiet = false;
  std::optional<std::string> sensor;  // line | circle | zigzag | a trace CSV
  double sensor_speed_mm_s = 100.0;
  double sensor_angle_deg = 0.0;
  double sensor_radius_mm = 20.0;
  double sensor_period_s = 2.0;
  double sensor_lift_s = 0.1;
  std::vector<double> sensor_start_mm;  // x, y
};

// The simulated sensor: a 2-D trace played in a loop, linearly interpolated
// at the controller's clock. Between two passes the finger is lifted for
// `lift_s` (reported with touch 0 where the pass ended), as a finger lifts
// to go back to where its stroke starts: the host sees the end of one
// stroke and the touch of the next (docs/serial-protocol.md), not a jump.
class LoopedSensor {
 public:
  LoopedSensor(std::vector<FingerSample2D> trace, double lift_s) : trace_(std::move(trace)), lift_s_(lift_s) {
    if (trace_.size() < 2 || !(trace_.back().t_s > trace_.front().t_s))
      throw InvalidArgument("--sensor: the trace must span some time (at least two samples)");
    if (!(lift_s_ >= 0.001 && lift_s_ <= 10.0))
      throw InvalidArgument("--sensor-lift is " + detail::num(lift_s_) + "; allowed: 0.001 … 10 s");
    period_s_ = trace_.back().t_s - trace_.front().t_s;
  }
  bool operator()(std::uint32_t t_us, std::int32_t& x_nm, std::int32_t& y_nm, bool& touch) const {
    const double phase = std::fmod(static_cast<double>(t_us) * 1e-6, period_s_ + lift_s_);
    if (phase >= period_s_) {  // lifted, above where the pass ended
      x_nm = static_cast<std::int32_t>(std::lround(trace_.back().x_mm * 1e6));
      y_nm = static_cast<std::int32_t>(std::lround(trace_.back().y_mm * 1e6));
      touch = false;
      return true;
    }
    const double t = trace_.front().t_s + phase;
    auto it = std::upper_bound(trace_.begin(), trace_.end(), t, [](double v, const FingerSample2D& s) { return v < s.t_s; });
    const FingerSample2D& a = *std::prev(it == trace_.begin() ? std::next(it) : it);
    const FingerSample2D& b = it == trace_.end() ? a : *it;
    const double f = b.t_s > a.t_s ? (t - a.t_s) / (b.t_s - a.t_s) : 0.0;
    x_nm = static_cast<std::int32_t>(std::lround((a.x_mm + (b.x_mm - a.x_mm) * f) * 1e6));
    y_nm = static_cast<std::int32_t>(std::lround((a.y_mm + (b.y_mm - a.y_mm) * f) * 1e6));
    touch = a.touch;
    return true;
  }

 private:
  std::vector<FingerSample2D> trace_;
  double lift_s_ = 0.1;
  double period_s_ = 0.0;
};

std::vector<FingerSample2D> sensor_trace(const ControllerArgs& a) {
  const std::string& s = *a.sensor;
  if (s.size() > 4 && s.ends_with(".csv")) return load_trace_2d_csv(s);
  Path2DConfig c;
  c.shape = parse_path_shape(s, "--sensor");
  c.speed_mm_s = a.sensor_speed_mm_s;
  c.angle_deg = a.sensor_angle_deg;
  c.radius_mm = a.sensor_radius_mm;
  c.duration_s = a.sensor_period_s;
  if (!a.sensor_start_mm.empty()) {
    if (a.sensor_start_mm.size() != 2) throw InvalidArgument("--sensor-start takes two numbers: x,y (mm)");
    c.start_x_mm = a.sensor_start_mm[0];
    c.start_y_mm = a.sensor_start_mm[1];
  }
  return simulate_path_2d(c);  // validates speed, radius, period
}

void run(const ControllerArgs& a) {
  if (a.serial.has_value() == a.pty) throw InvalidArgument("controller: give exactly one of --serial PATH or --pty");
  if (!(a.duration_s >= 0))
    throw InvalidArgument("--duration is " + detail::num(a.duration_s) + "; it must be >= 0 s (0 = until Ctrl-C)");
  const DeviceProfile d = load_device(a.device);
  // The sensor is read and checked before the port opens.
  std::optional<LoopedSensor> sensor;
  if (a.sensor) sensor.emplace(sensor_trace(a), a.sensor_lift_s);
  int fd = -1;
  int keep_slave = -1;
  std::string where;
  if (a.pty) {
    char name[256];
    if (openpty(&fd, &keep_slave, name, nullptr, nullptr) != 0) throw IoError("controller: cannot create a pseudo-terminal");
    controller::make_raw(keep_slave);
    where = name;
    std::cout << where << std::endl;  // the host connects here
  } else {
    fd = controller::open_serial_port(*a.serial, a.baud);
    where = *a.serial;
  }
  controller::HostHal hal(fd);
  if (sensor)
    hal.sensor_2d = [&hal, &sensor](std::int32_t& x, std::int32_t& y, bool& touch) {
      return (*sensor)(hal.micros(), x, y, touch);
    };
  controller::Info info;
  info.name = "texel-reference (host)";
  info.refresh_mhz = static_cast<std::uint32_t>(std::llround(d.refresh.value() * 1000.0));
  // ~200 KB of static map storage: allocated once, before the loop.
  auto ctl = std::make_unique<controller::Controller<>>(hal, info);

  stop_requested = false;
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  const auto t0 = std::chrono::steady_clock::now();
  auto stop = [&] {
    return stop_requested.load() ||
           (a.duration_s > 0 && std::chrono::steady_clock::now() - t0 > std::chrono::duration<double>(a.duration_s));
  };
  std::thread loop([&] { ctl->run(stop); });
  const bool tty = ::isatty(STDERR_FILENO) == 1 && !a.quiet;
  if (!a.quiet) std::cerr << "controller: " << where << ", refresh " << detail::num(d.refresh.value()) << " Hz; Ctrl-C stops\n";
  while (!stop()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (tty) {
      const std::uint16_t amp = hal.amplitude.load();
      std::fprintf(stderr, "\ramplitude %5u %-20s writes %llu", amp, std::string(amp * 20u / 65535u, '#').c_str(),
                   static_cast<unsigned long long>(hal.writes.load()));
      std::fflush(stderr);
    }
  }
  loop.join();
  if (tty) std::fprintf(stderr, "\n");
  const controller::Status& s = ctl->status();
  std::cout << "controller stopped: frames ok " << s.frames_ok << ", bad " << s.frames_bad << ", nacks " << s.nacks
            << ", link errors " << s.link_errors << ", output updates " << s.ticks << ", finger reports " << s.reports
            << ", selected map " << (s.selected == serial::no_map ? std::string("none") : std::to_string(s.selected)) << "\n";
  if (keep_slave >= 0) ::close(keep_slave);
}

}  // namespace

void register_controller(CLI::App& app) {
  auto a = std::make_shared<ControllerArgs>();
  auto* cmd = app.add_subcommand("controller", "Run the reference friction-display controller on a serial port or a new pty");
  cmd->add_option("--serial", a->serial, "Serial device or pty path to serve");
  cmd->add_flag("--pty", a->pty, "Create a pseudo-terminal and print its path (connect with play --backend serial:PATH)");
  cmd->add_option("--device", a->device, "Device profile giving the refresh rate [tpad]");
  cmd->add_option("--baud", a->baud, "Baud rate [921600]");
  cmd->add_option("--duration", a->duration_s, "Stop after this many seconds (0 = until Ctrl-C) [0]");
  cmd->add_flag("--quiet", a->quiet, "No status line");
  cmd->add_option("--sensor", a->sensor,
                  "A finger sensor, so the controller reports its finger (2-D): line, circle or zigzag (simulated "
                  "strokes in a loop) or a trace CSV time_s,x_mm,y_mm[,touch] [none: positions come from the host]");
  cmd->add_option("--sensor-speed", a->sensor_speed_mm_s, "Sensor stroke speed (mm/s) [100]");
  cmd->add_option("--sensor-angle", a->sensor_angle_deg, "Sensor line / zigzag direction (degrees) [0]");
  cmd->add_option("--sensor-radius", a->sensor_radius_mm, "Sensor circle radius (mm) [20]");
  cmd->add_option("--sensor-period", a->sensor_period_s, "Length of one simulated stroke before the finger lifts (s) [2]");
  cmd->add_option("--sensor-lift", a->sensor_lift_s,
                  "How long the sensor's finger stays lifted between two strokes (s), reported with touch 0 [0.1]");
  cmd->add_option("--sensor-start", a->sensor_start_mm, "Where a sensor stroke starts (circle: its centre), x,y in mm [0,0]")
      ->delimiter(',')
      ->expected(2);
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
