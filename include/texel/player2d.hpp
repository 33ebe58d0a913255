// The 2-D real-time player: finger samples (x, y, t) in, drive values out,
// for touch surfaces that sense the finger in two dimensions (docs/player.md
// "The 2-D player").
//
// Built from the same pieces as the 1-D Player (player_parts.hpp: event ring,
// finger track and velocity estimate, touch ramps, crossfade between maps,
// response limit, output modes) and driven by the same backends (sinks.hpp).
// Same threads and real-time rules: one control thread pushes samples and
// swaps maps, one real-time thread calls process(), which never allocates,
// locks or blocks.
//
// A PlayerMap2D is what plays, in one of two modes:
//
//   path-indexed  for displays driven in real time. The fine texture (a Texel
//                 texture) is evaluated at the finger's travelled path length
//                 s = ∫|dx| rather than at a position, so the felt frequency is
//                 speed × spatial frequency in every direction: a straight
//                 stroke at any angle, a circle or a zigzag at speed v feel
//                 like the 1-D texture swiped at v. Coarse features stay at
//                 their (x, y): the coarse profile c is a Raster2D looked up
//                 at the finger (bilinear) and mixed exactly as in 1-D
//                 (docs/algorithm.md §7): e = 1 − C·(1 − c),
//                 a = e·(1 − F·(1 − s)/2).
//                 The texture is evaluated texel by texel at the finger
//                 (texel k = floor(s/L), s(x) = sin(2π(φ_k + f_k·(s − k·L)))),
//                 not interpolated from a map, with its frequencies limited:
//                 a texel whose felt frequency f_k·|ds/dt| exceeds the limit
//                 (the display's response limit, else 0.45·rate, below the
//                 drive's Nyquist) is faded towards its mean with a raised
//                 cosine between 0.8 and 1 × the limit, so no content above
//                 the drive's Nyquist is ever produced at any speed.
//                 The path runs over a strip of the texture's texels
//                 (strip_mm, default 10 m: 100 s of stroking at 100 mm/s
//                 before it repeats) and wraps around at its end.
//                 [choice] path at lift: `keep` (default) continues s where
//                 the last stroke left it, so strokes never repeat the same
//                 texels; `reset` starts every stroke at s = 0, so each stroke
//                 feels the same. s grows by the distance between consecutive
//                 touching samples, computed when a sample is pushed.
//   bitmap        for friction bitmaps: a friction Raster2D in [0, 1]
//                 evaluated at (x, y) (bilinear). Its spatial content is the
//                 raster's (up to 1/(2·pitch)); the response limit applies in
//                 time as in 1-D.
//
// The finger beyond the map's extent counts as lifted (ramped out).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <type_traits>
#include <vector>

#include "texel/player.hpp"
#include "texel/raster2d.hpp"
#include "texel/texture.hpp"

namespace texel {

struct Document;
namespace detail {
struct MapAtFinger;  // a map's constants for one block (src/player/player2d.cpp)
}

/// One finger sample on a 2-D surface.
struct FingerSample2D {
  double t_s = 0.0;   ///< time (s) on the player's clock
  double x_mm = 0.0;  ///< position (mm, surface coordinates)
  double y_mm = 0.0;
  bool touch = false;  ///< finger on the surface
};

/// [choice] What the travelled path does when the finger lifts (see above).
enum class PathAtLift { keep, reset };
std::string_view to_string(PathAtLift p);
PathAtLift parse_path_at_lift(std::string_view text, std::string_view field = "path_at_lift");

/// The rectangle a 2-D map covers: [x, x + width) × [y, y + height), mm.
struct Extent2D {
  double x_mm = 0.0, y_mm = 0.0, width_mm = 0.0, height_mm = 0.0;
  [[nodiscard]] bool contains(double x, double y) const noexcept {
    return x >= x_mm && x < x_mm + width_mm && y >= y_mm && y < y_mm + height_mm;
  }
};
/// The extent a raster's samples cover: origin … origin + count·pitch on each axis.
Extent2D extent_of(const Raster2D& raster);

/// A raster from a 2-D .npy (rows along y, columns along x, C order; dtypes
/// as parse_npy, integers scaled to [0, 1]) with the given pitch and origin.
/// Throws FormatError naming the file for anything but a 2-D array.
Raster2D parse_raster_npy(std::string_view bytes, std::string_view origin, Millimetres pitch,
                          Millimetres origin_x = Millimetres(0.0), Millimetres origin_y = Millimetres(0.0));
Raster2D load_raster_npy(const std::string& path, Millimetres pitch, Millimetres origin_x = Millimetres(0.0),
                         Millimetres origin_y = Millimetres(0.0));

/// Bilinear interpolation of a raster at (x, y); positions beyond the edges
/// take the nearest edge value. Real-time safe.
float sample_bilinear(const Raster2D& raster, double x_mm, double y_mm) noexcept;

/// An immutable 2-D map for the Player2D (see above).
class PlayerMap2D {
 public:
  enum class Kind { path_indexed, bitmap };

  /// Path-indexed: the fine texture `fine` (its pitch distribution bounded
  /// as `sampling` says, like the 1-D renderer: the same seed gives the same
  /// texels), laid along the path over strip_mm (>= one texel); its coarse
  /// strength C and fine strength F mix with `coarse` (values in [0, 1];
  /// absent: c = 1, i.e. no coarse feature; fine.coarse itself is ignored).
  /// `extent`: where the surface is; absent = the coarse raster's extent
  /// (then a coarse raster is required). Throws InvalidArgument naming the field.
  static std::unique_ptr<const PlayerMap2D> path_indexed(const TexelSpec& fine, const Sampling& sampling,
                                                         std::optional<Raster2D> coarse, std::optional<Extent2D> extent,
                                                         double strip_mm = 10000.0,
                                                         std::optional<FrequencyResponse> response = std::nullopt);
  /// Path-indexed from a texture document. A 1-D document: the fine
  /// texture of its first Texel region (prepared for the device's grid, so
  /// the same seed gives the 1-D document's texels), `coarse` and `extent`
  /// as above (no coarse raster and no extent: a surface without edges). A
  /// 2-D document (version 4, one surface2d region; more are refused): that
  /// region's texture, with `coarse` its coarse raster (required:
  /// coarse_raster(doc), texel/surface2d.hpp), as `texel swipe DOC --path`
  /// plays it. Either way the device's frequency response.
  static std::unique_ptr<const PlayerMap2D> path_indexed(const Document& doc, std::optional<Raster2D> coarse,
                                                         std::optional<Extent2D> extent = std::nullopt);
  /// Bitmap: a friction raster, values in [0, 1], covering extent_of(friction).
  static std::unique_ptr<const PlayerMap2D> bitmap(Raster2D friction, std::optional<FrequencyResponse> response = std::nullopt);

  [[nodiscard]] Kind kind() const { return kind_; }
  [[nodiscard]] const Extent2D& extent() const { return extent_; }
  [[nodiscard]] const std::optional<FrequencyResponse>& response() const { return response_; }
  [[nodiscard]] bool on_surface(double x_mm, double y_mm) const noexcept { return extent_.contains(x_mm, y_mm); }
  /// Strip length along the path (mm; path-indexed), a whole number of texels.
  [[nodiscard]] double strip_mm() const { return strip_mm_; }

  /// The amplitude in [0, 1] at (x, y) with the finger at path length s
  /// moving at `speed_mm_s` along its path; texels felt above `limit_hz` are
  /// faded out (see above). Real-time safe.
  [[nodiscard]] double value(double x_mm, double y_mm, double s_mm, double speed_mm_s, double limit_hz) const noexcept;
  /// The fine oscillation alone at path length s, in [−1, 1], limited likewise.
  [[nodiscard]] double fine(double s_mm, double speed_mm_s, double limit_hz) const noexcept;

 private:
  friend struct detail::MapAtFinger;
  PlayerMap2D() = default;
  Kind kind_ = Kind::path_indexed;
  Extent2D extent_{};
  std::optional<FrequencyResponse> response_;
  std::optional<Raster2D> raster_;  // path-indexed: coarse profile; bitmap: friction
  double coarse_strength_ = 0.0, fine_strength_ = 1.0;
  double texel_mm_ = 0.0, inv_texel_ = 0.0, strip_mm_ = 0.0;
  std::vector<double> texels_;  // f_k, φ_k, f_k+1, …: a texel's pair in one cache line
};

/// What the event ring carries: the sample with its path length (computed by push).
struct PathSample {
  double t_s = 0.0, x_mm = 0.0, y_mm = 0.0, s_mm = 0.0;
  bool touch = false;
};
inline std::array<double, 3> coords(const PathSample& s) noexcept { return {s.x_mm, s.y_mm, s.s_mm}; }

class Player2D final : public PlayerBase {
 public:
  /// prepare: validates `config` and allocates all state; `map` may be null.
  explicit Player2D(const PlayerConfig& config, std::unique_ptr<const PlayerMap2D> map = nullptr,
                    PathAtLift at_lift = PathAtLift::keep);
  ~Player2D() override;

  [[nodiscard]] const PlayerConfig& config() const { return config_; }
  [[nodiscard]] PathAtLift path_at_lift() const { return at_lift_; }

  // -------------------------------------------------------- control thread
  void set_map(std::unique_ptr<const PlayerMap2D> map) { maps_.set(std::move(map)); }
  /// Queues a finger sample (time-ordered); false if the queue is full (the
  /// sample is then not counted in the path either: push it again).
  bool push(const FingerSample2D& s);
  bool set_gain(double gain);
  bool set_carrier(double hz);
  std::size_t collect() override { return maps_.collect(); }
  [[nodiscard]] std::size_t event_space() const { return events_.capacity() - events_.size(); }

  // ------------------------------------------------------- real-time thread
  /// As Player::process; `position_mm` receives x.
  BlockInfo process(std::span<float> out, std::span<float> position_mm = {}) noexcept override {
    return process(out, position_mm, {});
  }
  /// Also the y of each sample and, if given, the path length s.
  BlockInfo process(std::span<float> out, std::span<float> x_mm, std::span<float> y_mm, std::span<float> path_mm = {}) noexcept;

 private:
  using Event = player_parts::Event<PathSample>;
  void use_response_of(const PlayerMap2D* map) noexcept;

  PlayerConfig config_;
  PathAtLift at_lift_;
  SpscQueue<Event> events_;
  player_parts::MapExchange<PlayerMap2D> maps_;
  // Control thread: the path so far.
  PathSample pushed_{};
  bool have_pushed_ = false;
  // Real-time state.
  player_parts::FingerTrack<PathSample, 3> finger_;
  player_parts::OutputStage stage_;
  double last_s_ = 0.0;
  double last_x_ = 0.0, last_y_ = 0.0;  // the finger at the last block's end: its map cells are fetched first
  bool have_s_ = false;
  std::uint64_t n_ = 0;
};

/// Off-line rendering of a whole 2-D trace (as render_trace): queues the
/// trace ahead, processes `frames` samples; `x`, `y`, if given, receive the
/// position used for each sample.
std::vector<float> render_trace_2d(const PlayerMap2D& map, const PlayerConfig& config, std::span<const FingerSample2D> trace,
                                   std::size_t frames, std::vector<float>* x = nullptr, std::vector<float>* y = nullptr,
                                   std::size_t block = 64, PathAtLift at_lift = PathAtLift::keep);

/// Simulated 2-D strokes at constant speed (`texel swipe` paths).
enum class Path2DShape { line, circle, zigzag };
std::string_view to_string(Path2DShape s);
Path2DShape parse_path_shape(std::string_view text, std::string_view field = "path");
struct Path2DConfig {
  Path2DShape shape = Path2DShape::line;
  double speed_mm_s = 100.0;  ///< > 0
  double angle_deg = 0.0;     ///< line: direction; zigzag: overall direction
  double start_x_mm = 0.0;    ///< line / zigzag: where the finger lands; circle: centre
  double start_y_mm = 0.0;
  double radius_mm = 20.0;   ///< circle, > 0
  double leg_mm = 10.0;      ///< zigzag: length of one leg, > 0
  double zigzag_deg = 90.0;  ///< zigzag: angle between consecutive legs (0 < · < 180)
  double duration_s = 1.0;   ///< > 0
  double rate_hz = 1000.0;   ///< sample rate, > 0
};
inline constexpr OptionChoice path_shapes[] = {{"line", static_cast<int>(Path2DShape::line)},
                                               {"circle", static_cast<int>(Path2DShape::circle)},
                                               {"zigzag", static_cast<int>(Path2DShape::zigzag)}};

/// A simulated 2-D stroke's options (Python's simulate_path_2d(), C's
/// texel_path2d_config; `texel swipe --path` and Python's swipe_2d() take the
/// shape's from here and speed, duration and rate from SwipeOptions),
/// described once (texel/option_spec.hpp). An empty flag: not a CLI flag.
template <class Config, class Visit>
requires std::is_same_v<std::remove_const_t<Config>, Path2DConfig>
void visit_options(Config& c, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(c.shape, OptionSpec{"path", "path", "2-D finger path: line, circle or zigzag", -inf, inf, false, false, path_shapes});
  visit(c.speed_mm_s, OptionSpec{"speed_mm_s", "speed", "Finger speed (mm/s)", 0, inf, true});
  visit(c.angle_deg, OptionSpec{"angle_deg", "angle", "Direction of a line or zigzag, degrees from +x"});
  visit(c.start_x_mm, OptionSpec{"start_x_mm", "start", "x where the finger lands (mm); a circle: its centre"});
  visit(c.start_y_mm, OptionSpec{"start_y_mm", "start-y", "y where the finger lands (mm); a circle: its centre"});
  visit(c.radius_mm, OptionSpec{"radius_mm", "radius", "Circle radius (mm)", 0, inf, true});
  visit(c.leg_mm, OptionSpec{"leg_mm", "leg", "Zigzag leg length (mm)", 0, inf, true});
  visit(c.zigzag_deg, OptionSpec{"zigzag_deg", "zigzag-angle", "Angle between zigzag legs, degrees", 0, 180, true, true});
  visit(c.duration_s, OptionSpec{"duration_s", "", "Length of the stroke (s)", 0, inf, true});
  visit(c.rate_hz, OptionSpec{"rate_hz", "", "Samples per second of the stroke", 0, inf, true});
}

/// Samples the path (touching throughout, a lifted sample at the end).
std::vector<FingerSample2D> simulate_path_2d(const Path2DConfig& config);
/// A CSV trace of time_s, x_mm, y_mm[, touch]; header optional; times
/// non-decreasing. Throws FormatError naming the line.
std::vector<FingerSample2D> parse_trace_2d_csv(std::string_view text, std::string_view origin);
std::vector<FingerSample2D> load_trace_2d_csv(const std::string& path);

/// Speeds of a 2-D trace between consecutive touching samples: |Δ(x, y)|/Δt.
struct PathMeasures {
  std::size_t intervals = 0;
  double mean_speed_mm_s = 0.0;
  double sd_speed_mm_s = 0.0;  ///< sample standard deviation (n−1)
  double touched_s = 0.0;
  double path_mm = 0.0;  ///< total path length
};
PathMeasures path_measures(std::span<const FingerSample2D> trace);

}  // namespace texel
