// A conformance check for friction displays that speak the serial protocol
// (docs/serial-protocol.md): what `texel display-check serial:PATH` runs
// against a display a device maker built from the documentation alone.
//
// Each check exercises one promise of the protocol and is named (the names
// are stable: scripts and tests match them). A check that does not apply to
// what the display announced (finger reports on a display without a sensor,
// the position stream on a display that senses its own finger) is reported
// as skipped, not failed: a display with a small payload or no sensor passes
// what it claims. The display is left at rest at the end.
//
// The checks talk to the display and wait for it (STATUS polled every few
// ms), so a run takes a few seconds; no check writes anything but the
// display's map slots.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "texel/serial_link.hpp"

namespace texel {

enum class CheckOutcome { pass, fail, skipped };
std::string_view to_string(CheckOutcome outcome);

struct CheckResult {
  std::string name;  ///< e.g. "upload.bad_crc" (docs/serial-protocol.md "Conformance")
  CheckOutcome outcome = CheckOutcome::skipped;
  std::string detail;  ///< what was measured, or why it failed / was skipped
};

struct DisplayCheckOptions {
  std::string path;  ///< the display's tty or pty
  int baud = 921600;
  int timeout_ms = 300;  ///< per request attempt
  /// The longest a display may take to put a driven output at rest after
  /// the host stops streaming: its 200 ms watchdog plus this much for the
  /// link and the STATUS round trip (s), 0 … 1.
  double watchdog_slack_s = 0.05;
  /// How long finger reports are read (s), 0.1 … 10.
  double reports_s = 0.5;
};

struct DisplayCheckReport {
  DisplayInfo info;  ///< what HELLO_REPLY announced (version 0: no handshake)
  std::vector<CheckResult> checks;
  /// Every check passed or was skipped.
  [[nodiscard]] bool passed() const;
  /// The check named `name`, or null.
  [[nodiscard]] const CheckResult* find(std::string_view name) const;
  /// One line per check ("PASS  upload.crc  …") and a summary line.
  [[nodiscard]] std::string to_text() const;
  /// {"display": {...}, "checks": [{"name", "outcome", "detail"}], "passed": bool}
  [[nodiscard]] std::string to_json() const;
};

/// Runs every check against the display at options.path. Throws IoError only
/// if the port cannot be opened; everything the display does wrong, including
/// not answering, is a failed check.
DisplayCheckReport check_display(const DisplayCheckOptions& options);

}  // namespace texel
