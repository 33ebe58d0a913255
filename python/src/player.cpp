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

PlayerConfig player_config(double rate_hz, const std::string& output, double carrier_hz, double prediction_s, double gain,
                           const std::string& response, const Document& doc) {
  PlayerConfig c;
  c.response = doc.device.response;  // the display's, as `texel swipe` takes it
  c.response_handling = parse_response_handling(response, "response");
  c.rate_hz = rate_hz;
  c.mode = parse_output_mode(output, "output");
  c.carrier_hz = carrier_hz;
  c.prediction_s = prediction_s;
  c.extrapolate_s = std::max(c.extrapolate_s, prediction_s);
  c.gain = gain;
  validate(c);
  return c;
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

#define TEXEL_PATH_2D_ARGS                                                                                          \
  py::arg("path") = "line", py::arg("speed_mm_s") = 100.0, py::arg("angle_deg") = 0.0, py::arg("start_x_mm") = 0.0, \
  py::arg("start_y_mm") = 0.0, py::arg("radius_mm") = 20.0, py::arg("leg_mm") = 10.0, py::arg("zigzag_deg") = 90.0

#define TEXEL_PLAYER_ARGS                                                                                                      \
  py::arg("rate_hz") = 48000.0, py::arg("output") = "vibration", py::arg("carrier_hz") = 250.0, py::arg("prediction_s") = 0.0, \
  py::arg("gain") = 1.0, py::arg("response") = "limit"

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
         const std::string& response) {
        const auto trace = trace_of(t_s, x_mm, touch);
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, doc);
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

Returns (output, positions_mm): float32 arrays of one value per output sample. The GIL is released.)doc");
  m.def(
      "swipe",
      [](const Document& doc, double speed_mm_s, const std::string& pattern, std::optional<double> start_mm,
         std::optional<double> extent_mm, double turn_s, double duration_s, double rate_hz, const std::string& output,
         double carrier_hz, double prediction_s, double gain, const std::string& response) {
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, doc);
        if (!(std::isfinite(speed_mm_s) && speed_mm_s > 0))
          throw InvalidArgument("speed_mm_s is " + std::to_string(speed_mm_s) + "; it must be > 0 mm/s");
        if (!(std::isfinite(duration_s) && duration_s > 0 && duration_s <= 86400))
          throw InvalidArgument("duration_s is " + std::to_string(duration_s) + "; allowed > 0 … 86400 s");
        const auto map = map_of(doc);
        SwipeConfig s;
        s.pattern = parse_swipe_pattern(pattern, "pattern");
        s.speed_mm_s = speed_mm_s;
        s.start_mm = start_mm.value_or(0.0);
        s.extent_mm = extent_mm.value_or(0.0);
        s.surface_mm = map->grid().length().value();
        s.turn_s = turn_s;
        s.duration_s = duration_s;
        return play(*map, c, simulate_swipe(s), duration_s);
      },
      py::arg("document"), py::kw_only(), py::arg("speed_mm_s") = 100.0, py::arg("pattern") = "constant",
      py::arg("start_mm") = py::none(), py::arg("extent_mm") = py::none(), py::arg("turn_s") = 0.1, py::arg("duration_s") = 2.0,
      TEXEL_PLAYER_ARGS,
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
      py::kw_only(), TEXEL_PATH_2D_ARGS, py::arg("duration_s") = 1.0, py::arg("rate_hz") = 1000.0,
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
         double gain, const std::string& response) {
        const auto t = trace_2d_of(trace);
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, doc);
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
         double gain, const std::string& response) {
        const PlayerConfig c = player_config(rate_hz, output, carrier_hz, prediction_s, gain, response, doc);
        const auto trace = simulate_path_2d(
            path_2d(path, speed_mm_s, angle_deg, start_x_mm, start_y_mm, radius_mm, leg_mm, zigzag_deg, duration_s, 1000.0));
        return play_2d(doc, mode, path_at_lift, c, trace, duration_s);
      },
      py::arg("document"), py::kw_only(), TEXEL_PATH_2D_ARGS, py::arg("duration_s") = 2.0, py::arg("mode") = "path",
      py::arg("path_at_lift") = "keep", TEXEL_PLAYER_ARGS,
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
