#include "finger_options.hpp"

#include <cmath>
#include <cstring>
#include <utility>

#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/surface2d.hpp"

namespace texel::cli {

void add_player_options(CLI::App& cmd, FingerOptions& finger, const SwipeOptions& defaults, DeviceOptions& device,
                        TextureOptions& texture) {
  add_finger_options(cmd, finger, defaults);
  add_device_options(cmd, device);
  add_texture_options(cmd, texture);
}

void add_finger_options(CLI::App& cmd, FingerOptions& o, const SwipeOptions& defaults) {
  const auto help = [&](std::string_view key) { return option_help(defaults, key); };
  cmd.add_option("--speed", o.speed_mm_s, help("speed_mm_s"));
  cmd.add_option("--pattern", o.pattern, help("pattern"));
  cmd.add_option("--trace", o.trace, "Recorded finger trace, CSV of time_s,position_mm[,touch] (replaces the simulated swipe)");
  cmd.add_option("--duration", o.duration_s, help("duration_s"));
  cmd.add_option("--start", o.start_mm, help("start_mm"));
  cmd.add_option("--extent", o.extent_mm, help("extent_mm"));
  cmd.add_option("--turn", o.turn_s, help("turn_s"));
  cmd.add_option("--rate", o.rate_hz, help("rate_hz"));
  cmd.add_option("--output", o.output, help("output"));
  cmd.add_option("--carrier", o.carrier_hz, help("carrier_hz"));
  cmd.add_option("--prediction", o.prediction_s, help("prediction_s"));
  cmd.add_option("--gain", o.gain, help("gain"));
  cmd.add_option("--response", o.response, help("response"));
  cmd.add_option("--band-limit", o.band_limit, help("band_limit"));
}

PlayerConfig player_config(const FingerOptions& o, double default_rate_hz, const FrequencyResponse& response) {
  SwipeOptions s;
  s.response = parse_response_handling(o.response, "--response");
  s.rate = Hertz(o.rate_hz.value_or(default_rate_hz));
  s.output = parse_output_mode(o.output, "--output");
  s.carrier = Hertz(o.carrier_hz);
  s.prediction = Seconds(o.prediction_s);
  s.gain = o.gain;
  s.band_limit = parse_band_limit(o.band_limit, "--band-limit");
  return player_config(s, response);
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
  SwipeOptions s;
  s.pattern = parse_swipe_pattern(o.pattern, "--pattern");
  if (!(std::isfinite(o.speed_mm_s) && o.speed_mm_s > 0))
    throw InvalidArgument("--speed is " + detail::num(o.speed_mm_s) + "; it must be > 0 mm/s");
  s.speed = MmPerSecond(o.speed_mm_s);
  s.start = Millimetres(o.start_mm.value_or(0.0));
  s.extent = Millimetres(o.extent_mm.value_or(0.0));
  s.turn = Seconds(o.turn_s);
  s.duration = Seconds(duration_s);
  return simulate_swipe(swipe_config(s, Millimetres(surface_mm)));
}

void add_surface2d_options(CLI::App& cmd, Surface2DOptions& o) {
  const char* g = "2-D surface";
  const Path2DConfig path_defaults;
  const auto help = [&](std::string_view key) { return option_help(path_defaults, key); };
  cmd.add_option("--path", o.path, help("path") + " (switches to the 2-D player)")->group(g);
  cmd.add_option("--angle", o.angle_deg, help("angle_deg"))->group(g);
  cmd.add_option("--radius", o.radius_mm, help("radius_mm") + "; the circle is centred on (--start, --start-y)")->group(g);
  cmd.add_option("--leg", o.leg_mm, help("leg_mm"))->group(g);
  cmd.add_option("--zigzag-angle", o.zigzag_deg, help("zigzag_deg"))->group(g);
  cmd.add_option("--start-y", o.start_y_mm, help("start_y_mm"))->group(g);
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
