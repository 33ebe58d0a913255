// texel display-check serial:PATH: the conformance check of a friction
// display (texel/display_check.hpp; docs/serial-protocol.md "Conformance"):
// a pass/fail line per check, or JSON; exit 0 only if every check the
// display's announced capabilities call for passes, 1 if one fails.
#include <cstdlib>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "texel/display_check.hpp"
#include "texel/error.hpp"

namespace texel::cli {
namespace {

struct DisplayCheckArgs {
  std::string display;
  int baud = 921600;
  bool json = false;
  int timeout_ms = 300;
};

void run(const DisplayCheckArgs& a) {
  if (!a.display.starts_with("serial:") || a.display.size() <= 7)
    throw InvalidArgument("display-check: the display is '" + a.display + "'; allowed: serial:PATH");
  DisplayCheckOptions o;
  o.path = a.display.substr(7);
  o.baud = a.baud;
  o.timeout_ms = a.timeout_ms;
  const DisplayCheckReport report = check_display(o);
  std::cout << (a.json ? report.to_json() : report.to_text()) << std::flush;
  if (!report.passed()) std::exit(1);
}

}  // namespace

void register_display_check(CLI::App& app) {
  auto a = std::make_shared<DisplayCheckArgs>();
  auto* cmd = app.add_subcommand("display-check",
                                 "Check that a friction display keeps the serial protocol (handshake, limits, upload "
                                 "and CRC, select, playback, watchdog, finger reports); exit 0 if it passes");
  cmd->add_option("display", a->display, "The display: serial:PATH (a tty or pty)")->required();
  cmd->add_option("--baud", a->baud, "Baud rate [921600]");
  cmd->add_option("--timeout", a->timeout_ms, "Reply timeout per request attempt (ms), 10 … 10000 [300]");
  cmd->add_flag("--json", a->json, "Print the report as JSON");
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
