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
#include "texel/player2d.hpp"

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

/// 2-D surfaces (issue #26): a 2-D finger (simulated path or recorded x, y
/// trace) on a path-indexed texture with an optional coarse raster, or on a
/// friction bitmap. Any of these options switches the command to 2-D.
struct Surface2DOptions {
  std::optional<std::string> path;  ///< line | circle | zigzag
  double angle_deg = 0.0;
  double radius_mm = 20.0;
  double leg_mm = 10.0;
  double zigzag_deg = 90.0;
  std::optional<double> start_y_mm;
  std::optional<std::string> trace_2d;       ///< CSV time_s,x_mm,y_mm[,touch]
  std::optional<std::string> coarse_raster;  ///< .npy coarse profile c(x, y)
  std::optional<std::string> bitmap;         ///< .npy friction bitmap
  double raster_pitch_mm = 0.1;
  std::vector<double> raster_origin_mm;  ///< x, y
  std::string path_at_lift = "keep";
  [[nodiscard]] bool active() const { return path || trace_2d || coarse_raster || bitmap; }
};

void add_surface2d_options(CLI::App& cmd, Surface2DOptions& o);
/// The 2-D map the options describe for `doc`: a friction bitmap, or the
/// document's texture laid along the path with the coarse raster; a 2-D
/// document (version 4) brings its own texture and coarse profile.
std::unique_ptr<const PlayerMap2D> player_map_2d(const Surface2DOptions& o, const Document& doc);
/// The 2-D trace: the --trace-2d file or a simulated --path (default a line
/// at --angle) at --speed from (--start, --start-y), sampled at 1 kHz.
std::vector<FingerSample2D> finger_trace_2d(const FingerOptions& f, const Surface2DOptions& o, double& duration_s);

}  // namespace texel::cli
