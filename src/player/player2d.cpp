// The 2-D real-time player (see include/texel/player2d.hpp for the model).
#include "texel/player2d.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>

#include "texel/detail/format.hpp"
#include "texel/detail/lanes.hpp"
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

namespace {

// Bilinear reads of one raster with its constants computed once (a block's
// worth of reads share them). Beyond the edges the nearest edge value; NaN
// positions land on the origin sample. (Scalar: in SIMD lanes, with the four
// corners gathered lane by lane, a block's reads measured slower.)
class Bilinear {
 public:
  explicit Bilinear(const Raster2D& r) noexcept
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
  const float* values_;
  double inv_, ox_, oy_, umax_, vmax_;
  int imax_, jmax_, width_, height_;
};

}  // namespace

float sample_bilinear(const Raster2D& r, double x_mm, double y_mm) noexcept { return Bilinear(r)(x_mm, y_mm); }

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

// Raised-cosine fade of a texel felt at `hz` against the limit: 1 up to
// 0.8·limit, 0 from the limit on.
double limit_weight(double hz, double limit_hz) noexcept {
  // Well inside the limit (hz ≤ 0.79·limit puts r under 0.8 whatever the
  // rounding): 1 without the division.
  if (limit_hz > 0.0 && hz <= 0.79 * limit_hz) return 1.0;
  const double r = hz / limit_hz;
  if (r <= 0.8) return 1.0;
  if (!(r < 1.0)) return 0.0;
  return 0.5 + 0.5 * std::cos(std::numbers::pi * (r - 0.8) / 0.2);
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

namespace {

// What PlayerMap2D::values reads, gathered once per call.
struct MapView {
  bool bitmap = false;
  const Raster2D* raster = nullptr;  // path-indexed: coarse (or none); bitmap: friction
  const double* texels = nullptr;    // f_k, φ_k interleaved
  std::size_t last = 0;              // the last texel's index
  double strip = 0.0, inv_texel = 0.0, texel_mm = 0.0, coarse = 0.0, fine = 1.0, limit = 0.0;

  // The texel under path length s, wrapped around the strip: returns f_k and
  // sets the phase argument φ_k + f_k·(s − k·L) of its oscillation, cycles.
  double texel_at(double s_mm, double& cycles) const noexcept {
    // In the strip's first half (0 < s < strip/2, the quotient's floor is 0
    // whatever the rounding) s_mm − 0·strip is s_mm: the same value without
    // the division and the floor.
    const double s = s_mm > 0.0 && s_mm < 0.5 * strip ? s_mm : s_mm - std::floor(s_mm / strip) * strip;
    auto k = static_cast<std::size_t>(std::max(0.0, (s + TexelTexture::boundary_tolerance_mm) * inv_texel));
    k = std::min(k, last);
    const double f = texels[2 * k];
    cycles = texels[2 * k + 1] + f * (s - static_cast<double>(k) * texel_mm);
    return f;
  }
};

// PlayerMap2D::values for n ≤ block_max samples, pass by pass over the block
// (short loops of independent samples): the raster and the texels sample by
// sample, then the sine and the mix in W lanes, each lane doing the scalar's
// operations in the same order (IEEE, -ffp-contract=off), so every width,
// and value() (n = 1), gives the same bits. The sine is detmath's (an exact
// reduction and one polynomial, the 1-D renderer's).
template <int W>
[[gnu::always_inline]] inline void map_lanes(const MapView& m, const Bilinear* raster, const double* x, const double* y,
                                             const double* s, const double* speed, double* out, std::size_t n) noexcept {
  using V = typename detail::Lanes<W>::type;
  constexpr std::size_t most = PlayerMap2D::block_max;
  static_assert(most % W == 0);
  const std::size_t padded = (n + W - 1) / W * W;  // padding lanes: c = 1, no oscillation
  const V zero{}, one = zero + 1.0;
  alignas(64) double c[most], cycles[most], weight[most];
  for (std::size_t i = 0; i < padded; ++i) c[i] = raster && i < n ? static_cast<double>((*raster)(x[i], y[i])) : 1.0;
  if (m.bitmap) {
    for (std::size_t b = 0; b < n; b += W) {
      V v;
      std::memcpy(&v, c + b, sizeof v);
      v = v < zero ? zero : (one < v ? one : v);  // std::clamp(c, 0, 1)
      std::memcpy(out + b, &v, std::min<std::size_t>(W, n - b) * sizeof(double));
    }
    return;
  }
  for (std::size_t i = 0; i < padded; ++i) {
    cycles[i] = weight[i] = 0.0;
    if (i < n) weight[i] = limit_weight(m.texel_at(s[i], cycles[i]) * std::fabs(speed[i]), m.limit);
  }
  for (std::size_t b = 0; b < n; b += W) {
    V cv, w, u;
    std::memcpy(&cv, c + b, sizeof cv);
    std::memcpy(&u, cycles + b, sizeof u);
    std::memcpy(&w, weight + b, sizeof w);
    const V e = 1.0 - m.coarse * (1.0 - cv);  // texel_mix, docs/algorithm.md §7
    const V offset = e - e * m.fine * 0.5;
    const V gain = e * m.fine * 0.5;
    const V a = offset + gain * (w == zero ? zero : w * detmath::sin_cycles_generic(u));
    std::memcpy(out + b, &a, std::min<std::size_t>(W, n - b) * sizeof(double));
  }
}

template <int W>
[[gnu::always_inline]] inline void map_lanes(const MapView& m, const double* x, const double* y, const double* s,
                                             const double* speed, double* out, std::size_t n) noexcept {
  if (m.raster) {
    const Bilinear raster(*m.raster);
    map_lanes<W>(m, &raster, x, y, s, speed, out, n);
  } else {
    map_lanes<W>(m, nullptr, x, y, s, speed, out, n);
  }
}

using MapKernel = void (*)(const MapView&, const double*, const double*, const double*, const double*, double*,
                           std::size_t) noexcept;
// At most AVX2's 4 lanes: a block is 16–64 samples, and a real-time thread
// gains nothing from waking the AVX-512 units (their clock licence) for a
// few hundred nanoseconds.
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2"))) void map_avx2(const MapView& m, const double* x, const double* y, const double* s,
                                              const double* v, double* out, std::size_t n) noexcept {
  map_lanes<4>(m, x, y, s, v, out, n);
}
#endif
void map_generic(const MapView& m, const double* x, const double* y, const double* s, const double* v, double* out,
                 std::size_t n) noexcept {
  map_lanes<2>(m, x, y, s, v, out, n);
}

// Chosen before any real-time thread runs (simd_lanes reads the environment
// once): a namespace-scope constant, not a function-local static.
const MapKernel map_kernel = [] {
#if defined(__x86_64__) || defined(__i386__)
  if (detail::simd_lanes() >= 4) return &map_avx2;
#endif
  return &map_generic;
}();

}  // namespace

double PlayerMap2D::fine(double s_mm, double speed_mm_s, double limit_hz) const noexcept {
  MapView m;
  m.texels = texels_.data(), m.last = texels_.size() / 2 - 1;
  m.strip = strip_mm_, m.inv_texel = inv_texel_, m.texel_mm = texel_mm_;
  double cycles = 0.0;
  const double w = limit_weight(m.texel_at(s_mm, cycles) * std::fabs(speed_mm_s), limit_hz);
  if (w == 0.0) return 0.0;
  return w * detmath::sin_cycles(cycles);
}

double PlayerMap2D::value(double x_mm, double y_mm, double s_mm, double speed_mm_s, double limit_hz) const noexcept {
  double a = 0.0;
  values(&x_mm, &y_mm, &s_mm, &speed_mm_s, limit_hz, &a, 1);
  return a;
}

void PlayerMap2D::values(const double* x, const double* y, const double* s, const double* speed, double limit_hz, double* out,
                         std::size_t n) const noexcept {
  MapView m;
  m.bitmap = kind_ == Kind::bitmap;
  m.raster = raster_ ? &*raster_ : nullptr;
  if (!m.bitmap) {
    m.texels = texels_.data(), m.last = texels_.size() / 2 - 1;
    m.strip = strip_mm_, m.inv_texel = inv_texel_, m.texel_mm = texel_mm_;
    m.coarse = coarse_strength_, m.fine = fine_strength_, m.limit = limit_hz;
  }
  map_kernel(m, x, y, s, speed, out, std::min(n, block_max));
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

// Real-time safe, like Player::process. Each sample's operations are those
// of a sample-by-sample loop (finger, map value, output stage), done in three
// passes over chunks of up to PlayerMap2D::block_max samples so the map's
// sines run in SIMD lanes (PlayerMap2D::values) and the output stage's mode
// is chosen once: the finger for every sample of the chunk, the maps' values,
// the output stage. Nothing the output stage does reaches the finger or the
// map, so the order of the passes changes no value.
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
  const PlayerMap2D* current = maps_.current();  // fixed for the block (begin_block)
  constexpr std::size_t chunk = PlayerMap2D::block_max;
  alignas(64) double x[chunk], y[chunk], s[chunk], speed[chunk], a[chunk], old[chunk];
  bool touch[chunk];
  float peak = 0.0f;
  std::array<double, 3> p{};

  for (std::size_t done = 0; done < frames;) {
    const std::size_t n = std::min(chunk, frames - done);
    for (std::size_t i = 0; i < n; ++i, ++n_) {
      const double tau = static_cast<double>(n_) / rate + config_.prediction_s;
      player_parts::take_events(events_, tau, finger_, stage_, smoothing);
      p = finger_.position(tau, player_parts::next_finger(events_), config_.extrapolate_s);
      touch[i] = finger_.touching() && (current == nullptr || current->on_surface(p[0], p[1]));
      // Path speed from consecutive output samples (s is piecewise linear in
      // time between finger samples, so this is exact within a segment).
      speed[i] = have_s_ ? std::fabs(p[2] - last_s_) * rate : 0.0;
      last_s_ = p[2];
      have_s_ = touch[i];
      x[i] = p[0], y[i] = p[1], s[i] = p[2];
    }
    maps_.values([&](const PlayerMap2D& m, double* v) { m.values(x, y, s, speed, limit, v, n); }, a, old, n);
    const std::span<float> block = out.subspan(done, n);
    peak = std::max(peak, stage_.run(a, touch, block));
    if (x_mm.size() >= frames)
      for (std::size_t i = 0; i < n; ++i) x_mm[done + i] = static_cast<float>(x[i]);
    if (y_mm.size() >= frames)
      for (std::size_t i = 0; i < n; ++i) y_mm[done + i] = static_cast<float>(y[i]);
    if (path_mm.size() >= frames)
      for (std::size_t i = 0; i < n; ++i) path_mm[done + i] = static_cast<float>(s[i]);
    info.touching = touch[n - 1];
    done += n;
  }
  stage_.end_block();
  publish_samples(n_);

  info.peak = peak;
  info.position_mm = p[0];
  info.position_y_mm = p[1];
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
