// texel controller: runs the reference friction-display controller
// (include/texel/controller/) on this computer, on a serial port or on a new
// pseudo-terminal (--pty prints its path for `texel play --backend
// serial:PATH`). The "actuator" is a status line showing the amplitude.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <thread>

#include <pty.h>
#include <unistd.h>

#include "commands.hpp"
#include "texel/controller/controller.hpp"
#include "texel/controller/host_hal.hpp"
#include "texel/detail/format.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"

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
};

void run(const ControllerArgs& a) {
  if (a.serial.has_value() == a.pty) throw InvalidArgument("controller: give exactly one of --serial PATH or --pty");
  if (!(a.duration_s >= 0))
    throw InvalidArgument("--duration is " + detail::num(a.duration_s) + "; it must be >= 0 s (0 = until Ctrl-C)");
  const DeviceProfile d = load_device(a.device);
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
            << ", link errors " << s.link_errors << ", output updates " << s.ticks << ", selected map "
            << (s.selected == serial::no_map ? std::string("none") : std::to_string(s.selected)) << "\n";
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
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
