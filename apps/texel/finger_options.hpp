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

/// The finger and output flags of `texel swipe` and `texel play`: the
/// library's SwipeOptions (described once, texel/player.hpp), held as the CLI
/// reads them (an unset --duration/--rate/--start/--extent is the command's
/// default or the trace's).
struct FingerOptions {
  double speed_mm_s = SwipeOptions{}.speed.value();
  std::string pattern = std::string(to_string(SwipeOptions{}.pattern));
  std::optional<std::string> trace;
  std::optional<double> duration_s;
  std::optional<double> start_mm;
  std::optional<double> extent_mm;
  double turn_s = SwipeOptions{}.turn.value();
  std::optional<double> rate_hz;
  std::string output = std::string(to_string(SwipeOptions{}.output));
  double carrier_hz = SwipeOptions{}.carrier.value();
  double prediction_s = SwipeOptions{}.prediction.value();
  double gain = SwipeOptions{}.gain;
  std::string response = std::string(to_string(SwipeOptions{}.response));      ///< limit | off
  std::string band_limit = std::string(to_string(SwipeOptions{}.band_limit));  ///< on | off
};

/// The flags, their help and defaults from the library's description of
/// `defaults` (SwipeOptions{} for swipe, play_options() for play).
void add_finger_options(CLI::App& cmd, FingerOptions& o, const SwipeOptions& defaults);
/// The option groups of a command that plays a texture (swipe, play): finger,
/// device and texture, in that order.
void add_player_options(CLI::App& cmd, FingerOptions& finger, const SwipeOptions& defaults, DeviceOptions& device,
                        TextureOptions& texture);

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
  double angle_deg = Path2DConfig{}.angle_deg;
  double radius_mm = Path2DConfig{}.radius_mm;
  double leg_mm = Path2DConfig{}.leg_mm;
  double zigzag_deg = Path2DConfig{}.zigzag_deg;
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
