// texel controller: runs the reference friction-display controller
// (include/texel/controller/) on this computer, on a serial port or on a new
// pseudo-terminal (--pty prints its path for `texel play --backend
// serial:PATH`). The "actuator" is a status line showing the amplitude.
// --sensor gives it a finger sensor (a simulated 2-D stroke, or a recorded
// x, y trace, played in a loop, the finger lifted between passes), so it
// acts as a 2-D display that reports its finger (protocol 1.1) for
// `texel play --finger serial:PATH`; `--sensor strokes` (the scripted 1-D
// finger, stroke_script.hpp) or `--sensor 1d:TRACE.csv` make it a 1-D
// display that plays its selected map under that finger at its own rate.
// --log records what it outputs; --max-payload/--slots/--max-samples give it
// a small device's limits and --fault deliberate misbehaviour (tests of
// `texel display-check`).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <thread>
#include <variant>
#include <vector>

#include <pty.h>
#include <unistd.h>

#include "commands.hpp"
#include "texel/controller/controller.hpp"
#include "texel/controller/host_hal.hpp"
#include "texel/detail/format.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"
#include "texel/finger.hpp"
#include "texel/io.hpp"
#include "texel/player2d.hpp"
#include "texel/stroke_script.hpp"

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
  std::optional<double> sensor_lift_s;  // 0.1 s; strokes: the script's default
  std::vector<double> sensor_start_mm;  // x, y
  // The 1-D stroke script (--sensor strokes).
  std::uint64_t seed = 1;
  // The script's defaults are the library's (StrokeScriptConfig).
  std::vector<double> sensor_range_mm{StrokeScriptConfig{}.from_mm, StrokeScriptConfig{}.to_mm};
  double sensor_speed_variation = StrokeScriptConfig{}.speed_variation;
  double sensor_pause_s = StrokeScriptConfig{}.pause_s;
  double sensor_lift_probability = StrokeScriptConfig{}.lift_probability;
  double sensor_duration_s = StrokeScriptConfig{}.duration_s;
  std::optional<std::string> sensor_trace_out;
  std::optional<std::string> log;
  int log_every = 0;  // ticks between log rows; 0 = about 1 kHz
  // A small device's limits, and faults.
  int max_payload = static_cast<int>(serial::max_payload);
  int slots = 2;
  long long max_samples = 32768;
  std::vector<std::string> faults;
};

// A 1-D trace (recorded) played in a loop like the 2-D one: lifted for
// `lift_s` between passes, at the position where the pass ended.
class LoopedTrace1D {
 public:
  LoopedTrace1D(std::vector<FingerSample> trace, double lift_s) : trace_(std::move(trace)), lift_s_(lift_s) {
    if (trace_.size() < 2 || !(trace_.back().t_s > trace_.front().t_s))
      throw InvalidArgument("--sensor 1d: the trace must span some time (at least two samples)");
    if (!(lift_s_ >= 0.001 && lift_s_ <= 10.0))
      throw InvalidArgument("--sensor-lift is " + detail::num(lift_s_) + "; allowed: 0.001 … 10 s");
    period_s_ = trace_.back().t_s - trace_.front().t_s;
  }
  [[nodiscard]] FingerSample at(double t_s) const {
    const double phase = std::fmod(t_s, period_s_ + lift_s_);
    if (phase >= period_s_) return {t_s, trace_.back().x_mm, false};
    const double t = trace_.front().t_s + phase;
    auto it = std::upper_bound(trace_.begin(), trace_.end(), t, [](double v, const FingerSample& s) { return v < s.t_s; });
    const FingerSample& a = *std::prev(it == trace_.begin() ? std::next(it) : it);
    const FingerSample& b = it == trace_.end() ? a : *it;
    const double f = b.t_s > a.t_s ? (t - a.t_s) / (b.t_s - a.t_s) : 0.0;
    return {t_s, a.x_mm + (b.x_mm - a.x_mm) * f, a.touch};
  }

 private:
  std::vector<FingerSample> trace_;
  double lift_s_ = 0.1;
  double period_s_ = 0.0;
};

StrokeScriptConfig stroke_config(const ControllerArgs& a) {
  if (a.sensor_range_mm.size() != 2) throw InvalidArgument("--sensor-range takes two numbers: from,to (mm)");
  StrokeScriptConfig c;
  c.seed = a.seed;
  c.from_mm = a.sensor_range_mm[0];
  c.to_mm = a.sensor_range_mm[1];
  c.speed_mm_s = a.sensor_speed_mm_s;
  c.speed_variation = a.sensor_speed_variation;
  c.pause_s = a.sensor_pause_s;
  c.lift_probability = a.sensor_lift_probability;
  c.lift_s = a.sensor_lift_s.value_or(c.lift_s);
  c.duration_s = a.sensor_duration_s;
  return c;
}

controller::Fault parse_fault(const std::string& name) {
  if (name == "wrong-crc") return controller::fault_wrong_crc;
  if (name == "ignore-watchdog") return controller::fault_ignore_watchdog;
  if (name == "drop-reports") return controller::fault_drop_reports;
  throw InvalidArgument("--fault is '" + name + "'; allowed: wrong-crc, ignore-watchdog, drop-reports");
}

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
  if (!(a.max_payload >= static_cast<int>(serial::min_max_payload) && a.max_payload <= static_cast<int>(serial::max_payload)))
    throw InvalidArgument("--max-payload is " + std::to_string(a.max_payload) + "; allowed 14 … 1024 bytes");
  if (!(a.slots >= 1 && a.slots <= 2)) throw InvalidArgument("--slots is " + std::to_string(a.slots) + "; allowed 1 … 2");
  if (!(a.max_samples >= 1 && a.max_samples <= 32768))
    throw InvalidArgument("--max-samples is " + std::to_string(a.max_samples) + "; allowed 1 … 32768");
  if (!(a.log_every >= 0 && a.log_every <= 1000000))
    throw InvalidArgument("--log-every is " + std::to_string(a.log_every) + "; allowed 0 … 1000000 ticks");
  std::uint8_t faults = 0;
  for (const std::string& f : a.faults) faults |= parse_fault(f);
  // The sensor is read and checked before the port opens.
  std::optional<LoopedSensor> sensor;
  std::optional<StrokeScript> strokes;
  std::optional<LoopedTrace1D> trace_1d;
  if (a.sensor && *a.sensor == "strokes") {
    strokes.emplace(stroke_config(a));
    if (a.sensor_trace_out) {
      // The script at 1 kHz, one period: what the display will sense.
      const std::vector<FingerSample> t = strokes->trace(1000.0, 0.0, strokes->period_s());
      write_file_atomic(*a.sensor_trace_out, trace_csv(t));
    }
  } else if (a.sensor && a.sensor->starts_with("1d:")) {
    trace_1d.emplace(load_trace_csv(a.sensor->substr(3)), a.sensor_lift_s.value_or(0.1));
  } else if (a.sensor) {
    sensor.emplace(sensor_trace(a), a.sensor_lift_s.value_or(0.1));
  }
  if (a.sensor_trace_out && !strokes) throw InvalidArgument("--sensor-trace-out needs --sensor strokes");
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
  // The sensor's clock: seconds since the controller started (its t = 0 is
  // the script's t = 0; the log gives both clocks).
  const std::uint32_t t0_us = hal.micros();
  const auto sensor_s = [&hal, t0_us] { return static_cast<std::uint32_t>(hal.micros() - t0_us) * 1e-6; };
  const auto to_nm = [](double mm) { return static_cast<std::int32_t>(std::lround(mm * 1e6)); };
  if (sensor)
    hal.sensor_2d = [&hal, &sensor](std::int32_t& x, std::int32_t& y, bool& touch) {
      return (*sensor)(hal.micros(), x, y, touch);
    };
  if (strokes)
    hal.sensor = [&strokes, &sensor_s, &to_nm](std::int32_t& x, bool& touch) {
      const FingerSample f = strokes->at(sensor_s());
      x = to_nm(f.x_mm);
      touch = f.touch;
      return true;
    };
  if (trace_1d)
    hal.sensor = [&trace_1d, &sensor_s, &to_nm](std::int32_t& x, bool& touch) {
      const FingerSample f = trace_1d->at(sensor_s());
      x = to_nm(f.x_mm);
      touch = f.touch;
      return true;
    };
  // The log: one row every `every` ticks, buffered on the controller's
  // thread and written by this one.
  std::ofstream log;
  std::mutex log_mutex;
  std::string log_buffer;
  if (a.log) {
    log.open(*a.log, std::ios::trunc);
    if (!log) throw IoError("--log: cannot write '" + *a.log + "'");
    log << "t_s,t_us,x_mm,touch,selected,mode,amplitude\n";
    const int every = a.log_every > 0 ? a.log_every : std::max(1, static_cast<int>(std::lround(d.refresh.value() / 1000.0)));
    hal.tick_observer = [&, every, n = std::uint64_t{0}](std::uint32_t t_us, const controller::Status& st) mutable {
      if (n++ % static_cast<std::uint64_t>(every) != 0) return;
      char row[128];
      const int len =
          std::snprintf(row, sizeof row, "%.6f,%u,%.6f,%d,%d,%d,%u\n", static_cast<std::uint32_t>(t_us - t0_us) * 1e-6, t_us,
                        st.x_nm * 1e-6, st.touch ? 1 : 0, st.selected == serial::no_map ? -1 : st.selected,
                        static_cast<int>(st.mode), static_cast<unsigned>(st.amplitude));
      std::lock_guard lock(log_mutex);
      log_buffer.append(row, static_cast<std::size_t>(len));
    };
  }
  const auto flush_log = [&] {
    if (!a.log) return;
    std::string out;
    {
      std::lock_guard lock(log_mutex);
      out.swap(log_buffer);
    }
    log << out;
    log.flush();
  };
  controller::Info info;
  info.name = "texel-reference (host)";
  info.refresh_mhz = static_cast<std::uint32_t>(std::llround(d.refresh.value() * 1000.0));
  info.max_payload = static_cast<std::uint16_t>(a.max_payload);
  info.slots = static_cast<std::uint8_t>(a.slots);
  info.max_samples = static_cast<std::uint32_t>(a.max_samples);
  info.faults = faults;
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
    flush_log();
    if (tty) {
      const std::uint16_t amp = hal.amplitude.load();
      std::fprintf(stderr, "\ramplitude %5u %-20s writes %llu", amp, std::string(amp * 20u / 65535u, '#').c_str(),
                   static_cast<unsigned long long>(hal.writes.load()));
      std::fflush(stderr);
    }
  }
  loop.join();
  flush_log();
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
                  "A finger sensor, so the controller plays its selected map under that finger and reports it: 1-D "
                  "'strokes' (a scripted participant: strokes back and forth, speed varying, pauses, lifts; "
                  "deterministic from --seed) or '1d:TRACE.csv' (time_s,x_mm[,touch] in a loop); 2-D line, circle or "
                  "zigzag (simulated strokes in a loop) or a trace CSV time_s,x_mm,y_mm[,touch] [none: positions come "
                  "from the host]");
  cmd->add_option("--sensor-speed", a->sensor_speed_mm_s, "Sensor stroke speed (mm/s; strokes: the median) [100]");
  cmd->add_option("--seed", a->seed, "strokes: the script's seed [1]");
  cmd->add_option("--sensor-range", a->sensor_range_mm,
                  "strokes: the two ends of the strokes, from,to in mm [" + detail::num(StrokeScriptConfig{}.from_mm) + "," +
                      detail::num(StrokeScriptConfig{}.to_mm) + "]")
      ->delimiter(',')
      ->expected(2);
  cmd->add_option(
      "--sensor-speed-variation", a->sensor_speed_variation,
      "strokes: SD of ln(stroke speed) from stroke to stroke, 0 … 1 [" + detail::num(StrokeScriptConfig{}.speed_variation) + "]");
  cmd->add_option("--sensor-pause", a->sensor_pause_s,
                  "strokes: mean still pause at a turn (s), 0 … 5 [" + detail::num(StrokeScriptConfig{}.pause_s) + "]");
  cmd->add_option("--sensor-lift-probability", a->sensor_lift_probability,
                  "strokes: chance the finger lifts after a stroke (it then repeats the direction), 0 … 1 [" +
                      detail::num(StrokeScriptConfig{}.lift_probability) + "]");
  cmd->add_option("--sensor-duration", a->sensor_duration_s,
                  "strokes: the script's length before it repeats (s) [" + detail::num(StrokeScriptConfig{}.duration_s) + "]");
  cmd->add_option("--sensor-trace-out", a->sensor_trace_out,
                  "strokes: write the script (one period at 1 kHz, time_s,position_mm,touch; t = 0 when the controller "
                  "starts) to this CSV");
  cmd->add_option("--log", a->log,
                  "Write what the display outputs to this CSV as it runs: t_s,t_us,x_mm,touch,selected,mode,amplitude "
                  "(t_us: the clock of its FINGER reports)");
  cmd->add_option("--log-every", a->log_every, "Log one output update in this many [0: about 1 kHz]");
  cmd->add_option("--max-payload", a->max_payload, "The largest payload it accepts and announces (bytes), 14 … 1024 [1024]");
  cmd->add_option("--slots", a->slots, "Map slots it announces, 1 … 2 [2]");
  cmd->add_option("--max-samples", a->max_samples, "Samples per map it announces, 1 … 32768 [32768]");
  cmd->add_option("--fault", a->faults,
                  "Misbehave on purpose (tests of texel display-check; repeatable): wrong-crc (installs a map whatever "
                  "its CRC-32), ignore-watchdog (plays stale streamed values), drop-reports (loses every 7th finger "
                  "report)");
  cmd->add_option("--sensor-angle", a->sensor_angle_deg, "Sensor line / zigzag direction (degrees) [0]");
  cmd->add_option("--sensor-radius", a->sensor_radius_mm, "Sensor circle radius (mm) [20]");
  cmd->add_option("--sensor-period", a->sensor_period_s, "Length of one simulated stroke before the finger lifts (s) [2]");
  cmd->add_option("--sensor-lift", a->sensor_lift_s,
                  "How long the sensor's finger stays lifted between two strokes (s), reported with touch 0 [0.1; strokes: " +
                      detail::num(StrokeScriptConfig{}.lift_s) + "]");
  cmd->add_option("--sensor-start", a->sensor_start_mm, "Where a sensor stroke starts (circle: its centre), x,y in mm [0,0]")
      ->delimiter(',')
      ->expected(2);
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
