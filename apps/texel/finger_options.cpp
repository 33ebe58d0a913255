#include "finger_options.hpp"

#include <cmath>
#include <cstring>
#include <utility>

#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/surface2d.hpp"

namespace texel::cli {

void add_player_options(CLI::App& cmd, FingerOptions& finger, DeviceOptions& device, TextureOptions& texture) {
  add_finger_options(cmd, finger);
  add_device_options(cmd, device);
  add_texture_options(cmd, texture);
}

void add_finger_options(CLI::App& cmd, FingerOptions& o) {
  cmd.add_option("--speed", o.speed_mm_s, "Swipe speed (mm/s) [100]");
  cmd.add_option("--pattern", o.pattern, "Simulated swipe: constant (repeated one-way strokes) or back-and-forth [constant]");
  cmd.add_option("--trace", o.trace, "Recorded finger trace, CSV of time_s,position_mm[,touch] (replaces the simulated swipe)");
  cmd.add_option("--duration", o.duration_s, "Length (s) [swipe: 2, or the trace's; play: 5, or the trace's]");
  cmd.add_option("--start", o.start_mm, "Where the simulated finger lands (mm) [0]");
  cmd.add_option("--extent", o.extent_mm, "Travel of one stroke (mm) [to the end of the surface]");
  cmd.add_option("--turn", o.turn_s, "Back-and-forth: time to stop and turn (s) [0.1]");
  cmd.add_option("--rate", o.rate_hz,
                 "Output rate (Hz) [48000; play to a serial display: 1000]; e.g. 8333 for the tpad's refresh rate");
  cmd.add_option("--output", o.output,
                 "amplitude (friction map value), vibration (zero-mean, band-limited) or carrier [vibration]");
  cmd.add_option("--carrier", o.carrier_hz, "Carrier frequency for --output carrier (Hz) [250]");
  cmd.add_option("--prediction", o.prediction_s,
                 "Latency compensation: predict the finger this far ahead (s) [0; TPaD tablet: 0.02]");
  cmd.add_option("--gain", o.gain, "Output gain, 0 … 1 [1]");
  cmd.add_option("--response", o.response,
                 "The display's frequency response (device profile): limit (never drive what the display attenuates by "
                 "20 dB or more) or off [limit]");
}

PlayerConfig player_config(const FingerOptions& o, double default_rate_hz, const FrequencyResponse& response) {
  PlayerConfig c;
  c.response = response;
  c.response_handling = parse_response_handling(o.response, "--response");
  c.rate_hz = o.rate_hz.value_or(default_rate_hz);
  c.mode = parse_output_mode(o.output, "--output");
  c.carrier_hz = o.carrier_hz;
  c.prediction_s = o.prediction_s;
  c.extrapolate_s = std::max(c.extrapolate_s, o.prediction_s);
  c.gain = o.gain;
  validate(c);
  return c;
}

std::vector<FingerSample> finger_trace(const FingerOptions& o, double surface_mm, double& duration_s) {
  if (o.duration_s && !(std::isfinite(*o.duration_s) && *o.duration_s > 0 && *o.duration_s <= 86400))
    throw InvalidArgument("--duration is " + detail::num(*o.duration_s) + "; allowed > 0 … 86400 s");
  if (o.trace) {
    auto trace = load_trace_csv(*o.trace);
    duration_s = o.duration_s.value_or(trace.back().t_s);
    if (!(duration_s > 0)) throw InvalidArgument("--trace '" + *o.trace + "' lasts 0 s; give --duration");
    return trace;
  }
  duration_s = o.duration_s.value_or(duration_s);  // the caller passes its default
  SwipeConfig s;
  s.pattern = parse_swipe_pattern(o.pattern, "--pattern");
  s.speed_mm_s = o.speed_mm_s;
  s.start_mm = o.start_mm.value_or(0.0);
  s.extent_mm = o.extent_mm.value_or(0.0);
  s.surface_mm = surface_mm;
  s.turn_s = o.turn_s;
  s.duration_s = duration_s;
  if (!(std::isfinite(o.speed_mm_s) && o.speed_mm_s > 0))
    throw InvalidArgument("--speed is " + detail::num(o.speed_mm_s) + "; it must be > 0 mm/s");
  return simulate_swipe(s);
}

void add_surface2d_options(CLI::App& cmd, Surface2DOptions& o) {
  const char* g = "2-D surface";
  cmd.add_option("--path", o.path, "2-D finger path: line, circle or zigzag (switches to the 2-D player)")->group(g);
  cmd.add_option("--angle", o.angle_deg, "Direction of a line or zigzag, degrees from +x [0]")->group(g);
  cmd.add_option("--radius", o.radius_mm, "Circle radius (mm) [20]; the circle is centred on (--start, --start-y)")->group(g);
  cmd.add_option("--leg", o.leg_mm, "Zigzag leg length (mm) [10]")->group(g);
  cmd.add_option("--zigzag-angle", o.zigzag_deg, "Angle between zigzag legs, degrees [90]")->group(g);
  cmd.add_option("--start-y", o.start_y_mm, "y where the 2-D finger lands (mm) [0]")->group(g);
  cmd.add_option("--trace-2d", o.trace_2d, "Recorded 2-D finger trace, CSV of time_s,x_mm,y_mm[,touch]")->group(g);
  cmd.add_option("--coarse-raster", o.coarse_raster,
                 "2-D coarse profile c(x, y) in [0, 1]: .npy, rows along y; mixed by the document's coarse and fine strength")
      ->group(g);
  cmd.add_option("--bitmap", o.bitmap, "Friction bitmap in [0, 1] (.npy, rows along y) played instead of the document's texture")
      ->group(g);
  cmd.add_option("--raster-pitch", o.raster_pitch_mm, "Sample spacing of --coarse-raster / --bitmap (mm) [0.1]")->group(g);
  cmd.add_option("--raster-origin", o.raster_origin_mm, "Position of the raster's first sample: X Y (mm) [0 0]")
      ->expected(2)
      ->group(g);
  cmd.add_option("--path-at-lift", o.path_at_lift,
                 "Path-indexed texture at a lift: keep (continue the path) or reset (each stroke starts over) [keep]")
      ->group(g);
}

std::unique_ptr<const PlayerMap2D> player_map_2d(const Surface2DOptions& o, const Document& doc) {
  if (o.coarse_raster && o.bitmap) throw InvalidArgument("--coarse-raster and --bitmap exclude each other");
  if (!(std::isfinite(o.raster_pitch_mm) && o.raster_pitch_mm > 0))
    throw InvalidArgument("--raster-pitch is " + detail::num(o.raster_pitch_mm) + "; it must be > 0 mm");
  const Millimetres x0(o.raster_origin_mm.empty() ? 0.0 : o.raster_origin_mm[0]);
  const Millimetres y0(o.raster_origin_mm.size() < 2 ? 0.0 : o.raster_origin_mm[1]);
  const Millimetres pitch(o.raster_pitch_mm);
  if (o.bitmap) return PlayerMap2D::bitmap(load_raster_npy(*o.bitmap, pitch, x0, y0), doc.device.response);
  if (doc.surface2d) {  // a 2-D document: its region's texture along the path, its coarse profile at (x, y)
    if (o.coarse_raster) throw InvalidArgument("--coarse-raster: a 2-D document carries its own coarse profile");
    return PlayerMap2D::path_indexed(doc, coarse_raster(doc, 0));
  }
  std::optional<Raster2D> coarse;
  if (o.coarse_raster) coarse = load_raster_npy(*o.coarse_raster, pitch, x0, y0);
  return PlayerMap2D::path_indexed(doc, std::move(coarse));
}

std::vector<FingerSample2D> finger_trace_2d(const FingerOptions& f, const Surface2DOptions& o, double& duration_s) {
  if (f.duration_s && !(std::isfinite(*f.duration_s) && *f.duration_s > 0 && *f.duration_s <= 86400))
    throw InvalidArgument("--duration is " + detail::num(*f.duration_s) + "; allowed > 0 … 86400 s");
  if (f.trace) throw InvalidArgument("--trace is a 1-D trace; give a 2-D one with --trace-2d");
  if (o.trace_2d) {
    if (o.path) throw InvalidArgument("--path and --trace-2d exclude each other");
    auto trace = load_trace_2d_csv(*o.trace_2d);
    duration_s = f.duration_s.value_or(trace.back().t_s);
    if (!(duration_s > 0)) throw InvalidArgument("--trace-2d '" + *o.trace_2d + "' lasts 0 s; give --duration");
    return trace;
  }
  duration_s = f.duration_s.value_or(duration_s);
  Path2DConfig p;
  p.shape = parse_path_shape(o.path.value_or("line"), "--path");
  p.speed_mm_s = f.speed_mm_s;
  p.angle_deg = o.angle_deg;
  p.start_x_mm = f.start_mm.value_or(0.0);
  p.start_y_mm = o.start_y_mm.value_or(0.0);
  p.radius_mm = o.radius_mm;
  p.leg_mm = o.leg_mm;
  p.zigzag_deg = o.zigzag_deg;
  p.duration_s = duration_s;
  try {
    return simulate_path_2d(p);
  } catch (const InvalidArgument& e) {  // name the flags, not the struct's fields
    std::string m = e.what();
    for (const auto& [field, flag] : {std::pair{"speed_mm_s", "--speed"},
                                      {"duration_s", "--duration"},
                                      {"radius_mm", "--radius"},
                                      {"leg_mm", "--leg"},
                                      {"zigzag_deg", "--zigzag-angle"}})
      if (const auto at = m.find(field); at != std::string::npos) m.replace(at, std::strlen(field), flag);
    throw InvalidArgument(m);
  }
}

}  // namespace texel::cli
