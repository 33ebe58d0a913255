// Binding of the player over arrays: simulated finger traces, off-line
// rendering of a trace through the real-time Player (render_trace), and the
// swipe measures. swipe() composes them the way `texel swipe` does.
#include <cmath>

#include "common.hpp"
#include "texel/error.hpp"
#include "texel/finger.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/surface.hpp"
#include "texel/surface2d.hpp"

namespace texel::python {
namespace {

py::dict trace_dict(const std::vector<FingerSample>& trace) {
  std::vector<double> t(trace.size()), x(trace.size());
  std::vector<bool> touch(trace.size());
  for (std::size_t i = 0; i < trace.size(); ++i) {
    t[i] = trace[i].t_s;
    x[i] = trace[i].x_mm;
  }
  py::array_t<bool> tc(static_cast<py::ssize_t>(trace.size()));
  auto tv = tc.mutable_unchecked<1>();
  for (std::size_t i = 0; i < trace.size(); ++i) tv(static_cast<py::ssize_t>(i)) = trace[i].touch;
  py::dict d;
  d["t_s"] = to_numpy(std::move(t));
  d["x_mm"] = to_numpy(std::move(x));
  d["touch"] = tc;
  return d;
}

std::vector<FingerSample> trace_of(const py::object& t_s, const py::object& x_mm, const py::object& touch) {
  const auto t = as_doubles(t_s, "t_s");
  const auto x = as_doubles(x_mm, "x_mm");
  if (t.size() != x.size())
    throw InvalidArgument("x_mm has " + std::to_string(x.size()) + " samples and t_s " + std::to_string(t.size()) +
                          "; they must match");
  std::vector<FingerSample> trace(t.size());
  std::vector<double> on;
  if (!touch.is_none()) {
    on = as_doubles(touch, "touch");
    if (on.size() != t.size())
      throw InvalidArgument("touch has " + std::to_string(on.size()) + " samples and t_s " + std::to_string(t.size()) +
                            "; they must match");
  }
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (i > 0 && !(t[i] >= t[i - 1]))
      throw InvalidArgument("t_s[" + std::to_string(i) + "] is not >= the sample before; times must be non-decreasing");
    trace[i] = FingerSample{t[i], x[i], on.empty() ? true : on[i] != 0.0};
  }
  return trace;
}

/// The player a swipe's keyword arguments describe (SwipeOptions, the
/// library's; `texel swipe` makes it the same way).
PlayerConfig player_config(double rate_hz, const std::string& output, double carrier_hz, double prediction_s, double gain,
                           const std::string& response, const std::string& band_limit, const Document& doc) {
  SwipeOptions o;
  o.rate = Hertz(rate_hz);
  o.output = parse_output_mode(output, "output");
  o.carrier = Hertz(carrier_hz);
  o.prediction = Seconds(prediction_s);
  o.gain = gain;
  o.response = parse_response_handling(response, "response");
  o.band_limit = parse_band_limit(band_limit, "band_limit");
  return texel::player_config(o, doc.device.response);  // the display's response, as `texel swipe` takes it
}

std::unique_ptr<const PlayerMap> map_of(const Document& doc) { return PlayerMap::from_surface(prepare_surface(doc)); }

py::tuple play(const PlayerMap& map, const PlayerConfig& config, const std::vector<FingerSample>& trace, double duration_s) {
  if (!(std::isfinite(duration_s) && duration_s > 0 && duration_s <= 86400))
    throw InvalidArgument("duration_s is " + std::to_string(duration_s) + "; allowed > 0 … 86400 s");
  const double frames_d = std::round(duration_s * config.rate_hz);
  if (frames_d > 2e9) throw InvalidArgument("duration_s × rate_hz is " + std::to_string(frames_d) + " samples; at most 2e9");
  std::vector<float> out, positions;
  {
    py::gil_scoped_release release;
    out = render_trace(map, config, trace, static_cast<std::size_t>(frames_d), &positions);
  }
  return py::make_tuple(to_numpy(std::move(out)), to_numpy(std::move(positions)));
}

// ------------------------------------------------------------ 2-D surfaces

/// A 2-D trace from an (N, 3) array of x_mm, y_mm, t_s, or (N, 4) with touch
/// (non-zero = on the surface) as the fourth column.
std::vector<FingerSample2D> trace_2d_of(const py::handle& trace) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(trace);
  if (!a) throw py::type_error("trace must be an (N, 3) array of x_mm, y_mm, t_s (or (N, 4) with touch)");
  if (a.ndim() != 2 || (a.shape(1) != 3 && a.shape(1) != 4) || a.shape(0) < 1)
    throw InvalidArgument("trace has shape " + std::string(py::str(a.attr("shape"))) +
                          "; it must be (N, 3) of x_mm, y_mm, t_s or (N, 4) with touch, N >= 1");
  const auto n = static_cast<std::size_t>(a.shape(0)), columns = static_cast<std::size_t>(a.shape(1));
  const double* v = a.data();
  std::vector<FingerSample2D> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* row = v + i * columns;
    for (std::size_t c = 0; c < 3; ++c)
      if (!std::isfinite(row[c]))
        throw InvalidArgument("trace[" + std::to_string(i) + ", " + std::to_string(c) + "] is not finite");
    if (i > 0 && !(row[2] >= out[i - 1].t_s))
      throw InvalidArgument("trace[" + std::to_string(i) + ", 2] (t_s) is below the sample before; times must be non-decreasing");
    out[i] = FingerSample2D{row[2], row[0], row[1], columns == 4 ? row[3] != 0.0 : true};
  }
  return out;
}

/// The 2-D player's map of a document: `path` (path-indexed: the texture laid
/// along the finger's path, a 2-D document's coarse profile at (x, y)) or
/// `bitmap` (a 2-D document's friction bitmap at (x, y)), as `texel swipe`.
std::unique_ptr<const PlayerMap2D> map_2d(const Document& doc, const std::string& mode) {
  if (mode == "path") return PlayerMap2D::path_indexed(doc, doc.surface2d ? std::optional(coarse_raster(doc)) : std::nullopt);
  if (mode == "bitmap") return PlayerMap2D::bitmap(render_raster(prepare_surface2d(doc)), doc.device.response);
  throw InvalidArgument("mode is '" + mode + "'; allowed: path (path-indexed), bitmap");
}

py::tuple play_2d(const Document& doc, const std::string& mode, const std::string& path_at_lift, const PlayerConfig& config,
                  const std::vector<FingerSample2D>& trace, double duration_s) {
  const PathAtLift at_lift = parse_path_at_lift(path_at_lift, "path_at_lift");
  if (!(std::isfinite(duration_s) && duration_s > 0 && duration_s <= 86400))
    throw InvalidArgument("duration_s is " + std::to_string(duration_s) + "; allowed > 0 … 86400 s");
  const double frames_d = std::round(duration_s * config.rate_hz);
  if (frames_d > 2e9) throw InvalidArgument("duration_s × rate_hz is " + std::to_string(frames_d) + " samples; at most 2e9");
  const auto map = map_2d(doc, mode);
  std::vector<float> out, x, y;
  {
    py::gil_scoped_release release;
    out = render_trace_2d(*map, config, trace, static_cast<std::size_t>(frames_d), &x, &y, 64, at_lift);
  }
  return py::make_tuple(to_numpy(std::move(out)), to_numpy(std::move(x)), to_numpy(std::move(y)));
}

py::array_t<double> trace_2d_numpy(const std::vector<FingerSample2D>& trace) {
  py::array_t<double> a({static_cast<py::ssize_t>(trace.size()), py::ssize_t{4}});
  auto v = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const auto k = static_cast<py::ssize_t>(i);
    v(k, 0) = trace[i].x_mm;
    v(k, 1) = trace[i].y_mm;
    v(k, 2) = trace[i].t_s;
    v(k, 3) = trace[i].touch ? 1.0 : 0.0;
  }
  return a;
}

Path2DConfig path_2d(const std::string& path, double speed_mm_s, double angle_deg, double start_x_mm, double start_y_mm,
                     double radius_mm, double leg_mm, double zigzag_deg, double duration_s, double rate_hz) {
  Path2DConfig p;
  p.shape = parse_path_shape(path, "path");
  p.speed_mm_s = speed_mm_s;
  p.angle_deg = angle_deg;
  p.start_x_mm = start_x_mm;
  p.start_y_mm = start_y_mm;
  p.radius_mm = radius_mm;
  p.leg_mm = leg_mm;
  p.zigzag_deg = zigzag_deg;
  p.duration_s = duration_s;
  p.rate_hz = rate_hz;
  return p;
}

#define TEXEL_PATH_2D_ARGS                                                                                           \
  py::arg("path") = std::string(to_string(Path2DConfig{}.shape)), py::arg("speed_mm_s") = Path2DConfig{}.speed_mm_s, \
  py::arg("angle_deg") = Path2DConfig{}.angle_deg, py::arg("start_x_mm") = Path2DConfig{}.start_x_mm,                \
  py::arg("start_y_mm") = Path2DConfig{}.start_y_mm, py::arg("radius_mm") = Path2DConfig{}.radius_mm,                \
  py::arg("leg_mm") = Path2DConfig{}.leg_mm, py::arg("zigzag_deg") = Path2DConfig{}.zigzag_deg

#define TEXEL_PLAYER_ARGS                                                                                              \
  py::arg("rate_hz") = SwipeOptions{}.rate.value(), py::arg("output") = std::string(to_string(SwipeOptions{}.output)), \
  py::arg("carrier_hz") = SwipeOptions{}.carrier.value(), py::arg("prediction_s") = SwipeOptions{}.prediction.value(), \
  py::arg("gain") = SwipeOptions{}.gain, py::arg("response") = std::string(to_string(SwipeOptions{}.response)),        \
  py::arg("band_limit") = std::string(to_string(SwipeOptions{}.band_limit))

}  // namespace

void register_player(py::module_& m) {
  m.def(
      "simulate_swipe",
      [](double speed_mm_s, const std::string& pattern, double start_mm, double extent_mm, double surface_mm, double turn_s,
         double duration_s, double rate_hz, double lead_in_s) {
        SwipeConfig c;
        c.pattern = parse_swipe_pattern(pattern, "pattern");
        c.speed_mm_s = speed_mm_s;
        c.start_mm = start_mm;
        c.extent_mm = extent_mm;
        c.surface_mm = surface_mm;
        c.turn_s = turn_s;
        c.duration_s = duration_s;
        c.rate_hz = rate_hz;
        c.lead_in_s = lead_in_s;
        return trace_dict(simulate_swipe(c));
      },
      py::kw_only(), py::arg("speed_mm_s") = 100.0, py::arg("pattern") = "constant", py::arg("start_mm") = 0.0,
      py::arg("extent_mm") = 0.0, py::arg("surface_mm") = 0.0, py::arg("turn_s") = 0.1, py::arg("duration_s") = 1.0,
      py::arg("rate_hz") = 1000.0, py::arg("lead_in_s") = 0.0,
      R"doc(A simulated finger trace as numpy columns t_s (s), x_mm (mm), touch (bool).

speed_mm_s  cruising speed (mm/s) [100]
pattern     'constant' (one-way strokes) or 'back-and-forth' ['constant']
start_mm    landing position (mm) [0]
extent_mm   travel of one stroke (mm); 0 = to the end of surface_mm [0]
surface_mm  surface length used when extent_mm is 0 (mm)
turn_s      back-and-forth: time to stop and turn (s) [0.1]
duration_s  length of the trace (s) [1]
rate_hz     trace sample rate (Hz) [1000]
lead_in_s   lifted time before the finger lands (s) [0])doc");
  m.def(
      "render_trace",
      [](const Document& doc, const py::object& t_s, const py::object& x_mm, const py::object& touch, double duration_s,
         double rate_hz, const std::string& output, double carrier_hz, double prediction_s, double gain,
         const std::string& response, const std::string& band_limit) {
        const auto trace = trace_of(t_s, x_mm, touch);
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, band_limit, doc);
        return play(*map_of(doc), c, trace, duration_s);
      },
      py::arg("document"), py::arg("t_s"), py::arg("x_mm"), py::arg("touch") = py::none(), py::kw_only(), py::arg("duration_s"),
      TEXEL_PLAYER_ARGS,
      R"doc(Plays a document's map under a finger trace through the real-time Player, off line.

t_s, x_mm     finger sample times (s, non-decreasing) and positions (mm, device coordinates)
touch         finger on the surface per sample (default: always)
duration_s    output length (s); frames = round(duration_s · rate_hz)
rate_hz       output rate (Hz) [48000]; 8333 = the tpad's refresh rate
output        'amplitude', 'vibration' (zero-mean, band-limited) or 'carrier' ['vibration']
carrier_hz    carrier frequency for output='carrier' (Hz) [250]
prediction_s  latency compensation look-ahead (s) [0]
gain          output gain 0 … 1 [1]
response      the device's frequency response: 'limit' (never drive what the display attenuates by 20 dB or more)
              or 'off' ['limit']
band_limit    'on': no content above the output's limit at the finger's speed (texels faded); 'off': the map
              as sampled (aliases) ['on']

Returns (output, positions_mm): float32 arrays of one value per output sample. The GIL is released.)doc");
  m.def(
      "swipe",
      [](const Document& doc, double speed_mm_s, const std::string& pattern, double start_mm, double extent_mm, double turn_s,
         double duration_s, double rate_hz, const std::string& output, double carrier_hz, double prediction_s, double gain,
         const std::string& response, const std::string& band_limit) {
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, band_limit, doc);
        const auto map = map_of(doc);
        SwipeOptions o;
        o.speed = MmPerSecond(speed_mm_s);
        o.pattern = parse_swipe_pattern(pattern, "pattern");
        o.start = Millimetres(start_mm);
        o.extent = Millimetres(extent_mm);
        o.turn = Seconds(turn_s);
        o.duration = Seconds(duration_s);
        const SwipeConfig s = swipe_config(o, map->grid().length());
        return play(*map, c, simulate_swipe(s), duration_s);
      },
      py::arg("document"), py::kw_only(), py::arg("speed_mm_s") = SwipeOptions{}.speed.value(),
      py::arg("pattern") = std::string(to_string(SwipeOptions{}.pattern)), py::arg("start_mm") = SwipeOptions{}.start.value(),
      py::arg("extent_mm") = SwipeOptions{}.extent.value(), py::arg("turn_s") = SwipeOptions{}.turn.value(),
      py::arg("duration_s") = SwipeOptions{}.duration.value(), TEXEL_PLAYER_ARGS,
      "What a finger feels under a simulated swipe over a document, exactly as `texel swipe DOC -o x.wav`\n"
      "(same options, same defaults; see simulate_swipe and render_trace). Returns (output, positions_mm).");
  // ------------------------------------------------------------ 2-D surfaces
  m.def(
      "simulate_path_2d",
      [](const std::string& path, double speed_mm_s, double angle_deg, double start_x_mm, double start_y_mm, double radius_mm,
         double leg_mm, double zigzag_deg, double duration_s, double rate_hz) {
        return trace_2d_numpy(simulate_path_2d(
            path_2d(path, speed_mm_s, angle_deg, start_x_mm, start_y_mm, radius_mm, leg_mm, zigzag_deg, duration_s, rate_hz)));
      },
      py::kw_only(), TEXEL_PATH_2D_ARGS, py::arg("duration_s") = Path2DConfig{}.duration_s,
      py::arg("rate_hz") = Path2DConfig{}.rate_hz,
      R"doc(A simulated 2-D finger stroke at constant speed, as `texel swipe --path` simulates it: an (N, 4)
float64 array of x_mm, y_mm, t_s, touch (1 while touching; the last sample is lifted), ready for
render_trace_2d.

path        'line' (straight at angle_deg), 'circle' (centred on the start, radius_mm) or 'zigzag'
            (legs of leg_mm turning by zigzag_deg about angle_deg) ['line']
speed_mm_s  finger speed (mm/s) [100]
angle_deg   direction of a line or zigzag, degrees from +x [0]
start_x_mm, start_y_mm  where the finger lands (circle: its centre) [0, 0]
radius_mm   circle radius [20]; leg_mm zigzag leg [10]; zigzag_deg angle between legs, 0 … 180 [90]
duration_s  length of the stroke (s) [1]; rate_hz its sample rate (Hz) [1000])doc");
  m.def(
      "render_trace_2d",
      [](const Document& doc, const py::object& trace, std::optional<double> duration_s, const std::string& mode,
         const std::string& path_at_lift, double rate_hz, const std::string& output, double carrier_hz, double prediction_s,
         double gain, const std::string& response, const std::string& band_limit) {
        const auto t = trace_2d_of(trace);
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, band_limit, doc);
        return play_2d(doc, mode, path_at_lift, c, t, duration_s.value_or(t.back().t_s));
      },
      py::arg("document"), py::arg("trace"), py::kw_only(), py::arg("duration_s") = py::none(), py::arg("mode") = "path",
      py::arg("path_at_lift") = "keep", TEXEL_PLAYER_ARGS,
      R"doc(Plays a document under a 2-D finger trace through the 2-D real-time player, off line, as
`texel swipe DOC --trace-2d trace.csv` does.

trace         (N, 3) array of x_mm, y_mm, t_s (times non-decreasing, on the player's clock) or (N, 4)
              with touch (non-zero: on the surface) as the fourth column; simulate_path_2d makes one
duration_s    output length (s) [the trace's last time]
mode          'path': path-indexed, the texture laid along the finger's travelled path (felt frequency
              = speed × spatial frequency in every direction) with a 2-D document's coarse profile at
              (x, y); 'bitmap': a 2-D document's friction bitmap (render_2d) at (x, y) ['path']
path_at_lift  'keep' (the path continues across lifts) or 'reset' (every stroke starts over) ['keep']
rate_hz, output, carrier_hz, prediction_s, gain, response  as for render_trace

Returns (output, x_mm, y_mm): float32 arrays of one value per output sample. The GIL is released.)doc");
  m.def(
      "swipe_2d",
      [](const Document& doc, const std::string& path, double speed_mm_s, double angle_deg, double start_x_mm, double start_y_mm,
         double radius_mm, double leg_mm, double zigzag_deg, double duration_s, const std::string& mode,
         const std::string& path_at_lift, double rate_hz, const std::string& output, double carrier_hz, double prediction_s,
         double gain, const std::string& response, const std::string& band_limit) {
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, band_limit, doc);
        const auto trace = simulate_path_2d(
            path_2d(path, speed_mm_s, angle_deg, start_x_mm, start_y_mm, radius_mm, leg_mm, zigzag_deg, duration_s, 1000.0));
        return play_2d(doc, mode, path_at_lift, c, trace, duration_s);
      },
      py::arg("document"), py::kw_only(), TEXEL_PATH_2D_ARGS, py::arg("duration_s") = SwipeOptions{}.duration.value(),
      py::arg("mode") = "path", py::arg("path_at_lift") = "keep", TEXEL_PLAYER_ARGS,
      "What a finger feels on a surface under a simulated 2-D stroke, exactly as\n"
      "`texel swipe DOC --path PATH -o x.wav` (same options, same defaults; see simulate_path_2d and\n"
      "render_trace_2d). Returns (output, x_mm, y_mm).");
  m.def(
      "swipe_measures",
      [](const py::object& t_s, const py::object& x_mm, const py::object& touch, double still_below_mm_s) {
        const SwipeMeasures s = swipe_measures(trace_of(t_s, x_mm, touch), still_below_mm_s);
        py::dict d;
        d["intervals"] = s.intervals;
        d["mean_speed_mm_s"] = s.mean_speed_mm_s;
        d["sd_speed_mm_s"] = s.sd_speed_mm_s;
        d["directional_proportion"] = s.directional_proportion;
        d["moving_right"] = s.moving_right;
        d["moving_left"] = s.moving_left;
        d["touched_s"] = s.touched_s;
        d["distance_mm"] = s.distance_mm;
        return d;
      },
      py::arg("t_s"), py::arg("x_mm"), py::arg("touch") = py::none(), py::kw_only(), py::arg("still_below_mm_s") = 0.0,
      "Swipe behaviour of a trace: mean/SD speed (mm/s), directional proportion (−1 … 1), touched time (s), distance (mm).");
}

}  // namespace texel::python
