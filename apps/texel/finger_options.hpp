// Options shared by `texel swipe` and `texel play`: the finger source
// (simulated swipe or recorded trace) and the player's output settings.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "common.hpp"
#include "texel/finger.hpp"
#include "texel/player.hpp"

namespace texel::cli {

struct FingerOptions {
  double speed_mm_s = 100.0;
  std::string pattern = "constant";
  std::optional<std::string> trace;
  std::optional<double> duration_s;
  std::optional<double> start_mm;
  std::optional<double> extent_mm;
  double turn_s = 0.1;
  std::optional<double> rate_hz;
  std::string output = "vibration";
  double carrier_hz = 250.0;
  double prediction_s = 0.0;
  double gain = 1.0;
  std::string response = "limit";  ///< how the display's frequency response is respected: limit | off
};

void add_finger_options(CLI::App& cmd, FingerOptions& o);
/// The option groups of a command that plays a texture (swipe, play): finger,
/// device and texture, in that order.
void add_player_options(CLI::App& cmd, FingerOptions& finger, DeviceOptions& device, TextureOptions& texture);

/// The player configuration the options describe (validated); `response` is
/// the display's (DeviceProfile::response of the document's device).
PlayerConfig player_config(const FingerOptions& o, double default_rate_hz, const FrequencyResponse& response);
/// The trace: the --trace file, or a simulated swipe over `surface_mm`
/// sampled at 1 kHz. `duration_s` is the length asked for (or the trace's).
std::vector<FingerSample> finger_trace(const FingerOptions& o, double surface_mm, double& duration_s);

}  // namespace texel::cli
