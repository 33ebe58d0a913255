// The 2-D real-time player (see include/texel/player2d.hpp for the model).
#include "texel/player2d.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel {

using detail::num;

std::string_view to_string(PathAtLift p) { return p == PathAtLift::reset ? "reset" : "keep"; }

PathAtLift parse_path_at_lift(std::string_view text, std::string_view field) {
  if (text == "keep") return PathAtLift::keep;
  if (text == "reset") return PathAtLift::reset;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: keep, reset");
}

Extent2D extent_of(const Raster2D& r) {
  const double p = r.pitch.value();
  return {r.origin_x.value(), r.origin_y.value(), p * r.width, p * r.height};
}

namespace detail {

// Bilinear reads of one raster with its constants computed once (a block's
// worth of reads share them). Beyond the edges the nearest edge value; NaN
// positions land on the origin sample.
class BilinearReader {
 public:
  BilinearReader() noexcept = default;  // reads nothing; for a map without a raster
  explicit BilinearReader(const Raster2D& r) noexcept
      : values_(r.values.data()),
        inv_(1.0 / r.pitch.value()),
        ox_(r.origin_x.value()),
        oy_(r.origin_y.value()),
        umax_(static_cast<double>(r.width - 1)),
        vmax_(static_cast<double>(r.height - 1)),
        imax_(std::max(0, r.width - 2)),
        jmax_(std::max(0, r.height - 2)),
        width_(r.width),
        height_(r.height) {}

  /// Asks for the cache lines a read at (x, y) needs (the finger moves a
  /// few µm per sample, so a block reads the cells the last one ended on):
  /// on a thread woken every period they are usually cold.
  void prefetch(double x_mm, double y_mm) const noexcept {
    if (values_ == nullptr) return;
    const double u = std::clamp((x_mm - ox_) * inv_, 0.0, umax_);
    const double v = std::clamp((y_mm - oy_) * inv_, 0.0, vmax_);
    const int i = std::isnan(u) ? 0 : std::min(static_cast<int>(u), imax_);
    const int j = std::isnan(v) ? 0 : std::min(static_cast<int>(v), jmax_);
    const float* row = values_ + static_cast<std::size_t>(j) * static_cast<std::size_t>(width_) + i;
    __builtin_prefetch(row);
    __builtin_prefetch(row + (j + 1 < height_ ? width_ : 0));
  }

  [[nodiscard]] float operator()(double x_mm, double y_mm) const noexcept {
    const double u = std::clamp((x_mm - ox_) * inv_, 0.0, umax_);
    const double v = std::clamp((y_mm - oy_) * inv_, 0.0, vmax_);
    const int i = std::isnan(u) ? 0 : std::min(static_cast<int>(u), imax_);
    const int j = std::isnan(v) ? 0 : std::min(static_cast<int>(v), jmax_);
    const double fu = std::isnan(u) ? 0.0 : u - i, fv = std::isnan(v) ? 0.0 : v - j;
    const int i1 = std::min(i + 1, width_ - 1), j1 = std::min(j + 1, height_ - 1);
    const float* row = values_ + static_cast<std::size_t>(j) * static_cast<std::size_t>(width_);
    const float* row1 = values_ + static_cast<std::size_t>(j1) * static_cast<std::size_t>(width_);
    const double a = row[i] + (row[i1] - row[i]) * fu;
    const double b = row1[i] + (row1[i1] - row1[i]) * fu;
    return static_cast<float>(a + (b - a) * fv);
  }

 private:
  const float* values_ = nullptr;
  double inv_ = 0.0, ox_ = 0.0, oy_ = 0.0, umax_ = 0.0, vmax_ = 0.0;
  int imax_ = 0, jmax_ = 0, width_ = 0, height_ = 0;
};

}  // namespace detail

float sample_bilinear(const Raster2D& r, double x_mm, double y_mm) noexcept { return detail::BilinearReader(r)(x_mm, y_mm); }

namespace {

void check_raster(const Raster2D& r, std::string_view what) {
  const std::string w(what);
  if (r.width < 1 || r.height < 1)
    throw InvalidArgument(w + ": raster is " + std::to_string(r.width) + " × " + std::to_string(r.height) +
                          " samples; it needs at least 1 × 1");
  if (r.values.size() != static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height))
    throw InvalidArgument(w + ": raster holds " + std::to_string(r.values.size()) + " values for " + std::to_string(r.width) +
                          " × " + std::to_string(r.height) + " samples; they must match");
  if (!(std::isfinite(r.pitch.value()) && r.pitch.value() > 0))
    throw InvalidArgument(w + ": pitch_mm is " + num(r.pitch.value()) + "; it must be a finite number > 0");
  if (!std::isfinite(r.origin_x.value()) || !std::isfinite(r.origin_y.value()))
    throw InvalidArgument(w + ": origin must be finite");
  for (std::size_t k = 0; k < r.values.size(); ++k)
    if (!(r.values[k] >= 0.0f && r.values[k] <= 1.0f))
      throw InvalidArgument(w + ": value " + std::to_string(k) + " is " + num(r.values[k]) + "; allowed 0 … 1");
}

void check_response(const std::optional<FrequencyResponse>& r, std::string_view what) {
  if (!r) return;
  try {
    validate(*r, "response");
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string(what) + ": " + e.what());
  }
}

}  // namespace

std::unique_ptr<const PlayerMap2D> PlayerMap2D::path_indexed(const TexelSpec& fine, const Sampling& sampling,
                                                             std::optional<Raster2D> coarse, std::optional<Extent2D> extent,
                                                             double strip_mm, std::optional<FrequencyResponse> response) {
  const char* what = "2-D player map";
  validate(fine);
  if (coarse) check_raster(*coarse, "2-D player map: coarse");
  if (!extent && !coarse) throw InvalidArgument("2-D player map: give the surface's extent or a coarse raster");
  const Extent2D ext = extent ? *extent : extent_of(*coarse);
  if (!(std::isfinite(ext.x_mm) && std::isfinite(ext.y_mm) && std::isfinite(ext.width_mm) && std::isfinite(ext.height_mm) &&
        ext.width_mm > 0 && ext.height_mm > 0))
    throw InvalidArgument("2-D player map: extent is " + num(ext.width_mm) + " × " + num(ext.height_mm) +
                          " mm; width and height must be finite and > 0");
  const double L = fine.texel_length.value();
  if (!(std::isfinite(strip_mm) && strip_mm >= L && strip_mm <= 1e7))
    throw InvalidArgument("2-D player map: strip_mm is " + num(strip_mm) + "; allowed one texel (" + num(L) + ") … 1e7 mm");
  check_response(response, what);

  // The texels alone (C = 0: the envelope comes from the raster at the finger).
  TexelSpec spec = fine;
  spec.coarse_strength = 0.0;
  spec.coarse = ConstantProfile{};
  spec.fill = Fill::whole_texels;
  const TexelTexture texture(spec, Millimetres(strip_mm), sampling);
  std::unique_ptr<PlayerMap2D> m(new PlayerMap2D());
  m->kind_ = Kind::path_indexed;
  m->extent_ = ext;
  m->response_ = std::move(response);
  m->raster_ = std::move(coarse);
  m->coarse_strength_ = fine.coarse_strength;
  m->fine_strength_ = fine.fine_strength;
  m->texel_mm_ = L;
  m->inv_texel_ = 1.0 / L;
  const std::size_t count = texture.texel_count();
  m->strip_mm_ = static_cast<double>(count) * L;
  m->texels_.reserve(2 * count);
  texture.for_each_texels([&](std::size_t, std::span<const Texel> run) {
    for (const Texel& t : run) m->texels_.insert(m->texels_.end(), {t.frequency.value(), t.phase_cycles});
  });
  return m;
}

std::unique_ptr<const PlayerMap2D> PlayerMap2D::path_indexed(const Document& doc, std::optional<Raster2D> coarse,
                                                             std::optional<Extent2D> extent) {
  if (doc.surface2d) {  // a 2-D document: its one region's texture along the path, its coarse profile at (x, y)
    if (doc.surface2d->regions.size() != 1)
      throw InvalidArgument("the 2-D player plays a surface of one region; the document has " +
                            std::to_string(doc.surface2d->regions.size()) + " (render it to a bitmap and play that)");
    if (!coarse) throw InvalidArgument("2-D player map: a 2-D document needs its coarse raster (coarse_raster(doc))");
    return path_indexed(doc.surface2d->regions[0].texel, Sampling{doc.device.grid(), CyclesPerMm(0.0)}, std::move(coarse), extent,
                        10000.0, doc.device.response);
  }
  const auto region = std::find_if(doc.regions.begin(), doc.regions.end(), [](const RegionSpec& r) { return !r.reference; });
  if (region == doc.regions.end())
    throw InvalidArgument("2-D player map: the document has no Texel region (a reference has no texels to lay along the path)");
  if (!extent && !coarse) extent = Extent2D{-1e7, -1e7, 2e7, 2e7};  // no edges
  return path_indexed(region->texel, Sampling{doc.device.grid(), CyclesPerMm(0.0)}, std::move(coarse), extent, 10000.0,
                      doc.device.response);
}

Raster2D parse_raster_npy(std::string_view bytes, std::string_view origin, Millimetres pitch, Millimetres origin_x,
                          Millimetres origin_y) {
  NpyArray a = parse_npy_array(bytes, origin, 2);
  if (a.rows > (1u << 20) || a.columns > (1u << 20))
    throw FormatError(std::string(origin) +
                      ": a raster must be a 2-D array (rows along y, columns along x) of 1 … 2^20 per side");
  const std::vector<double>& v = a.values;
  Raster2D r;
  r.height = static_cast<int>(a.rows);
  r.width = static_cast<int>(a.columns);
  r.pitch = pitch;
  r.origin_x = origin_x;
  r.origin_y = origin_y;
  r.values.assign(v.begin(), v.end());
  return r;
}

Raster2D load_raster_npy(const std::string& path, Millimetres pitch, Millimetres origin_x, Millimetres origin_y) {
  return parse_raster_npy(read_file(path), path, pitch, origin_x, origin_y);
}

std::unique_ptr<const PlayerMap2D> PlayerMap2D::bitmap(Raster2D friction, std::optional<FrequencyResponse> response) {
  check_raster(friction, "2-D player map: friction");
  check_response(response, "2-D player map");
  std::unique_ptr<PlayerMap2D> m(new PlayerMap2D());
  m->kind_ = Kind::bitmap;
  m->extent_ = extent_of(friction);
  m->raster_ = std::move(friction);
  m->response_ = std::move(response);
  return m;
}

namespace detail {

// A map's constants gathered once per block (the raster's, the texels', the
// strengths and the frequency limit), then its value at the finger sample by
// sample: what PlayerMap2D::value computes, in one pass, without tables (the
// sine is detmath's: an exact reduction and one polynomial, the 1-D
// renderer's) and without a division. Real-time safe.
struct MapAtFinger {
  MapAtFinger(const PlayerMap2D& m, double limit_hz) noexcept
      : raster(m.raster_ ? &*m.raster_ : nullptr),
        read(m.raster_ ? BilinearReader(*m.raster_) : BilinearReader()),
        bitmap(m.kind_ == PlayerMap2D::Kind::bitmap),
        texels(m.texels_.data()),
        last(m.texels_.size() / 2 - 1),
        strip(m.strip_mm_),
        inv_texel(m.inv_texel_),
        texel_mm(m.texel_mm_),
        coarse(m.coarse_strength_),
        fine_strength(m.fine_strength_),
        limit(limit_hz) {}

  // The index k of the texel under path length s_mm; `s` receives s_mm
  // wrapped around the strip.
  std::size_t texel_index(double s_mm, double& s) const noexcept {
    // In the strip's first half (0 < s < strip/2, the quotient's floor is 0
    // whatever the rounding) s_mm − 0·strip is s_mm: the same value without
    // the division and the floor.
    s = s_mm > 0.0 && s_mm < 0.5 * strip ? s_mm : s_mm - std::floor(s_mm / strip) * strip;
    const auto k = static_cast<std::size_t>(std::max(0.0, (s + TexelTexture::boundary_tolerance_mm) * inv_texel));
    return std::min(k, last);
  }

  // The texel under path length s, wrapped around the strip: returns f_k and
  // sets the phase argument φ_k + f_k·(s − k·L) of its oscillation, cycles.
  double texel_at(double s_mm, double& cycles) const noexcept {
    double s = 0.0;
    const std::size_t k = texel_index(s_mm, s);
    const double f = texels[2 * k];
    cycles = texels[2 * k + 1] + f * (s - static_cast<double>(k) * texel_mm);
    return f;
  }

  // The raster's cells at (x, y) and the texel at s into the cache.
  void prefetch(double x_mm, double y_mm, double s_mm) const noexcept {
    read.prefetch(x_mm, y_mm);
    if (bitmap) return;
    double s = 0.0;
    __builtin_prefetch(texels + 2 * texel_index(s_mm, s));
  }

  // The fine oscillation at path length s, in [−1, 1], limited (docs/player.md §2).
  double fine(double s_mm, double speed_mm_s) const noexcept {
    double cycles = 0.0;
    const double w = player_parts::limit_weight(texel_at(s_mm, cycles) * std::fabs(speed_mm_s), limit);
    if (w == 0.0) return 0.0;
    return w * detmath::sin_cycles(cycles);
  }

  double value(double x_mm, double y_mm, double s_mm, double speed_mm_s) const noexcept {
    if (bitmap) return std::clamp(static_cast<double>(read(x_mm, y_mm)), 0.0, 1.0);
    const double c = raster ? static_cast<double>(read(x_mm, y_mm)) : 1.0;
    const TexelMix mix = texel_mix(c, coarse, fine_strength);  // the 1-D rule, docs/algorithm.md §7
    return mix.offset + mix.gain * fine(s_mm, speed_mm_s);
  }

  const Raster2D* raster;  // path-indexed: coarse profile (or none); bitmap: friction
  BilinearReader read;
  bool bitmap;
  const double* texels;  // f_k, φ_k interleaved
  std::size_t last;      // the last texel's index
  double strip, inv_texel, texel_mm, coarse, fine_strength, limit;
};

}  // namespace detail

double PlayerMap2D::fine(double s_mm, double speed_mm_s, double limit_hz) const noexcept {
  return detail::MapAtFinger(*this, limit_hz).fine(s_mm, speed_mm_s);
}

double PlayerMap2D::value(double x_mm, double y_mm, double s_mm, double speed_mm_s, double limit_hz) const noexcept {
  return detail::MapAtFinger(*this, limit_hz).value(x_mm, y_mm, s_mm, speed_mm_s);
}

// ------------------------------------------------------------------- Player2D

Player2D::Player2D(const PlayerConfig& config, std::unique_ptr<const PlayerMap2D> map, PathAtLift at_lift)
    : PlayerBase(player_parts::validated(config).rate_hz),
      config_(config),
      at_lift_(at_lift),
      events_(config_.event_capacity),
      maps_(std::move(map), 1.0 / (config_.crossfade_s * config_.rate_hz)),
      stage_(config_) {
  use_response_of(maps_.current());
  stage_.clear_settle();
}

Player2D::~Player2D() { stop_driver(); }

void Player2D::use_response_of(const PlayerMap2D* map) noexcept {
  stage_.use_response(map && map->response() ? &*map->response() : nullptr);
}

bool Player2D::push(const FingerSample2D& f) {
  PathSample p{f.t_s, f.x_mm, f.y_mm, pushed_.s_mm, f.touch};
  if (have_pushed_ && pushed_.touch && f.touch)
    p.s_mm += std::hypot(f.x_mm - pushed_.x_mm, f.y_mm - pushed_.y_mm);
  else if (f.touch && at_lift_ == PathAtLift::reset)
    p.s_mm = 0.0;  // a new stroke
  if (!std::isfinite(p.s_mm)) p.s_mm = 0.0;
  if (!events_.try_push(Event{Event::Kind::finger, p, 0.0})) return false;
  pushed_ = p;
  have_pushed_ = true;
  return true;
}

bool Player2D::set_gain(double gain) {
  if (!std::isfinite(gain)) gain = 0.0;
  return events_.try_push(Event{Event::Kind::gain, {}, std::clamp(gain, 0.0, 1.0)});
}

bool Player2D::set_carrier(double hz) {
  if (!std::isfinite(hz)) hz = 0.0;
  return events_.try_push(Event{Event::Kind::carrier, {}, std::clamp(hz, 0.0, config_.rate_hz / 2)});
}

// Real-time safe, like Player::process. The maps' constants are gathered
// once per block (detail::MapAtFinger); each sample is then one compact pass
// (finger, value under it, output stage): on a real-time thread woken every
// period the caches are cold, and a block's cost is the cache lines it
// touches as much as its arithmetic.
BlockInfo Player2D::process(std::span<float> out, std::span<float> x_mm, std::span<float> y_mm,
                            std::span<float> path_mm) noexcept {
  BlockInfo info;
  const std::size_t frames = out.size();
  if (frames == 0) return info;
  if (const PlayerMap2D* next = maps_.begin_block()) use_response_of(next);

  const double rate = config_.rate_hz;
  const double smoothing = config_.velocity_smoothing_s;
  player_parts::take_events(events_, static_cast<double>(n_) / rate + config_.prediction_s, finger_, stage_, smoothing);
  stage_.begin_block(frames);
  // Felt frequencies are limited to the display's response limit, else to
  // 0.45·rate (below the drive's Nyquist).
  const double limit = stage_.limit_hz() > 0.0 ? stage_.limit_hz() : 0.45 * rate;
  // The maps are fixed for the block (begin_block); the one fading out may
  // only end its fade.
  const PlayerMap2D* current = maps_.current();
  const PlayerMap2D* fading = maps_.fading();
  const std::optional<detail::MapAtFinger> now_at =
      current ? std::optional<detail::MapAtFinger>(std::in_place, *current, limit) : std::nullopt;
  const std::optional<detail::MapAtFinger> old_at =
      fading ? std::optional<detail::MapAtFinger>(std::in_place, *fading, limit) : std::nullopt;
  if (now_at) now_at->prefetch(last_x_, last_y_, last_s_);
  float peak = 0.0f;
  std::array<double, 3> p{};
  bool touching = false;

  for (std::size_t i = 0; i < frames; ++i, ++n_) {
    const double tau = static_cast<double>(n_) / rate + config_.prediction_s;
    player_parts::take_events(events_, tau, finger_, stage_, smoothing);
    p = finger_.position(tau, player_parts::next_finger(events_), config_.extrapolate_s);
    touching = finger_.touching() && (current == nullptr || current->on_surface(p[0], p[1]));
    // Path speed from consecutive output samples (s is piecewise linear in
    // time between finger samples, so this is exact within a segment).
    const double speed = have_s_ ? std::fabs(p[2] - last_s_) * rate : 0.0;
    last_s_ = p[2];
    have_s_ = touching;
    const double a = maps_.value(
        [&](const PlayerMap2D& m) -> double { return (&m == current ? *now_at : *old_at).value(p[0], p[1], p[2], speed); });
    const auto yf = static_cast<float>(stage_.step(a, touching));
    out[i] = yf;
    if (x_mm.size() >= frames) x_mm[i] = static_cast<float>(p[0]);
    if (y_mm.size() >= frames) y_mm[i] = static_cast<float>(p[1]);
    if (path_mm.size() >= frames) path_mm[i] = static_cast<float>(p[2]);
    peak = std::max(peak, std::fabs(yf));
  }
  stage_.end_block();
  publish_samples(n_);
  last_x_ = p[0], last_y_ = p[1];

  info.peak = peak;
  info.position_mm = p[0];
  info.position_y_mm = p[1];
  info.touching = touching;
  info.crossfading = maps_.crossfading();
  return info;
}

std::vector<float> render_trace_2d(const PlayerMap2D& map, const PlayerConfig& config, std::span<const FingerSample2D> trace,
                                   std::size_t frames, std::vector<float>* x, std::vector<float>* y, std::size_t block,
                                   PathAtLift at_lift) {
  if (block == 0) throw InvalidArgument("render_trace_2d: block is 0; it must be >= 1");
  // A copy of the map for the player to own (maps are immutable and small
  // besides their texel lists).
  Player2D player(config, std::make_unique<const PlayerMap2D>(map), at_lift);
  std::vector<float> out(frames);
  if (x) x->assign(frames, 0.0f);
  if (y) y->assign(frames, 0.0f);
  std::size_t next = 0;
  for (std::size_t done = 0; done < frames;) {
    while (next < trace.size() && player.push(trace[next])) ++next;
    const std::size_t n = std::min(block, frames - done);
    player.process(std::span(out).subspan(done, n), x ? std::span(*x).subspan(done, n) : std::span<float>{},
                   y ? std::span(*y).subspan(done, n) : std::span<float>{});
    done += n;
  }
  return out;
}

// ---------------------------------------------------------------- 2-D paths

std::string_view to_string(Path2DShape s) {
  switch (s) {
    case Path2DShape::line: return "line";
    case Path2DShape::circle: return "circle";
    case Path2DShape::zigzag: return "zigzag";
  }
  return "line";
}

Path2DShape parse_path_shape(std::string_view text, std::string_view field) {
  if (text == "line") return Path2DShape::line;
  if (text == "circle") return Path2DShape::circle;
  if (text == "zigzag") return Path2DShape::zigzag;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: line, circle, zigzag");
}

std::vector<FingerSample2D> simulate_path_2d(const Path2DConfig& c) {
  const auto positive = [](const char* field, double v, double hi) {
    if (!(std::isfinite(v) && v > 0 && v <= hi))
      throw InvalidArgument(std::string("path: ") + field + " is " + num(v) + "; allowed > 0 … " + num(hi));
  };
  positive("speed_mm_s", c.speed_mm_s, 1e5);
  positive("duration_s", c.duration_s, 86400);
  positive("rate_hz", c.rate_hz, 1e6);
  positive("radius_mm", c.radius_mm, 1e6);
  positive("leg_mm", c.leg_mm, 1e6);
  if (!(c.zigzag_deg > 0 && c.zigzag_deg < 180))
    throw InvalidArgument("path: zigzag_deg is " + num(c.zigzag_deg) + "; allowed 0 < angle < 180");
  if (!std::isfinite(c.angle_deg) || !std::isfinite(c.start_x_mm) || !std::isfinite(c.start_y_mm))
    throw InvalidArgument("path: angle and start must be finite");
  const double n_d = std::floor(c.duration_s * c.rate_hz);
  if (n_d > 1e8) throw InvalidArgument("path: duration_s × rate_hz is " + num(n_d) + " samples; at most 1e8");
  const auto n = static_cast<std::size_t>(n_d);
  const double deg = std::numbers::pi / 180.0;
  const double th = c.angle_deg * deg;
  // Zigzag legs alternate ±half the turn away from the overall direction.
  const double half = (180.0 - c.zigzag_deg) / 2.0 * deg;
  std::vector<FingerSample2D> trace;
  trace.reserve(n + 2);
  for (std::size_t i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / c.rate_hz;
    const double d = c.speed_mm_s * t;  // path length so far
    FingerSample2D s{t, c.start_x_mm, c.start_y_mm, true};
    switch (c.shape) {
      case Path2DShape::line:
        s.x_mm += d * std::cos(th);
        s.y_mm += d * std::sin(th);
        break;
      case Path2DShape::circle: {
        const double a = th + d / c.radius_mm;
        s.x_mm += c.radius_mm * std::cos(a);
        s.y_mm += c.radius_mm * std::sin(a);
        break;
      }
      case Path2DShape::zigzag: {
        const double legs = std::floor(d / c.leg_mm);
        const double in = d - legs * c.leg_mm;
        // Each leg advances leg·cos(half) along the direction and
        // ±leg·sin(half) across it; even legs go left, odd legs right.
        const double along = (legs + in / c.leg_mm) * c.leg_mm * std::cos(half);
        const auto k = static_cast<long long>(legs);
        const double across = (k % 2 == 0 ? in : c.leg_mm - in) * std::sin(half);
        s.x_mm += along * std::cos(th) - across * std::sin(th);
        s.y_mm += along * std::sin(th) + across * std::cos(th);
        break;
      }
    }
    trace.push_back(s);
  }
  FingerSample2D lift = trace.back();
  lift.t_s += 1.0 / c.rate_hz;
  lift.touch = false;
  trace.push_back(lift);
  return trace;
}

std::vector<FingerSample2D> parse_trace_2d_csv(std::string_view text, std::string_view origin) {
  std::vector<FingerSample2D> trace;
  player_parts::read_trace_rows(text, origin, 2, "time_s,x_mm,y_mm[,touch]",
                                [&](double t, std::span<const double> p, bool touch) {
                                  trace.push_back({t, p[0], p[1], touch});
                                });
  return trace;
}

PathMeasures path_measures(std::span<const FingerSample2D> trace) {
  PathMeasures m;
  double sum = 0, sum2 = 0;
  for (std::size_t i = 1; i < trace.size(); ++i) {
    const FingerSample2D& a = trace[i - 1];
    const FingerSample2D& b = trace[i];
    const double dt = b.t_s - a.t_s;
    if (!a.touch || !b.touch || !(dt > 0)) continue;
    const double d = std::hypot(b.x_mm - a.x_mm, b.y_mm - a.y_mm);
    const double v = d / dt;
    ++m.intervals;
    sum += v, sum2 += v * v;
    m.touched_s += dt;
    m.path_mm += d;
  }
  if (m.intervals) m.mean_speed_mm_s = sum / static_cast<double>(m.intervals);
  if (m.intervals > 1) {
    const double n = static_cast<double>(m.intervals);
    m.sd_speed_mm_s = std::sqrt(std::max(0.0, (sum2 - sum * sum / n) / (n - 1)));
  }
  return m;
}

std::vector<FingerSample2D> load_trace_2d_csv(const std::string& path) { return parse_trace_2d_csv(read_file(path), path); }

}  // namespace texel
