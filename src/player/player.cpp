// The real-time player (see include/texel/player.hpp for the model).
#include "texel/player.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/multichannel.hpp"
#include "texel/surface.hpp"
#include "texel/texture.hpp"

namespace texel {

using detail::num;

// ------------------------------------------------------------------ PlayerMap

PlayerMap::PlayerMap(Grid grid, std::vector<float> values, std::optional<FrequencyResponse> response)
    : PlayerMap(grid, std::move(values), std::move(response), true) {}

PlayerMap::PlayerMap(Grid grid, std::vector<float> values, std::optional<FrequencyResponse> response, bool pyramid)
    : grid_(grid), values_(std::move(values)), response_(std::move(response)) {
  if (grid_.count < 1 || static_cast<std::size_t>(grid_.count) != values_.size())
    throw InvalidArgument("player map: grid has " + std::to_string(grid_.count) + " samples but " +
                          std::to_string(values_.size()) + " values were given; they must match and be >= 1");
  if (!(std::isfinite(grid_.spacing.value()) && grid_.spacing.value() > 0))
    throw InvalidArgument("player map: spacing_mm is " + num(grid_.spacing.value()) + "; it must be a finite number > 0");
  if (response_) {
    try {
      validate(*response_, "response");
    } catch (const InvalidArgument& e) {
      throw InvalidArgument("player map: " + std::string(e.what()));
    }
  }
  inv_spacing_ = 1.0 / grid_.spacing.value();
  if (pyramid) build_pyramid();
}

std::unique_ptr<const PlayerMap> PlayerMap::from_surface(const Surface& surface, std::optional<FrequencyResponse> response) {
  const std::vector<double> map = surface.render();
  // Texel regions are kept texel by texel for the band limit (player.hpp);
  // a surface of Texel regions alone (gaps at rest) needs no pyramid.
  std::size_t total = 0;
  bool all_texels = true;
  for (const Region& r : surface.regions()) {
    const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get());
    all_texels = all_texels && t != nullptr;
    if (t) total += t->texel_count();
  }
  const bool keep = total <= max_texels;
  std::unique_ptr<PlayerMap> m(
      new PlayerMap(surface.grid(), std::vector<float>(map.begin(), map.end()), std::move(response), !(keep && all_texels)));
  if (keep)
    for (const Region& r : surface.regions())
      if (const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get()))
        m->lines_.push_back(texel_line(*t, r.start.value(), r.start.value() + r.length.value()));
  return m;
}

std::unique_ptr<const PlayerMap> PlayerMap::from_document(const Document& doc) {
  // One map plays one channel: a document whose channels each draw their own
  // texels has no one map (its base seed's chain is none of its channels).
  if (doc.playback && doc.playback->mode == ChannelMode::simultaneous)
    throw InvalidArgument("the document plays simultaneous texels on the " + std::to_string(doc.device.channels()) +
                          " actuators of device '" + doc.device.name +
                          "'; this player has one channel: play it with texel play or texel swipe (the multi-channel "
                          "player, multichannel_player.hpp), or give it \"playback\": {\"mode\": \"sequential\"}");
  return from_surface(prepare_surface(doc), doc.device.response);
}

std::unique_ptr<const PlayerMap> PlayerMap::from_texture(const Texture& texture, const Grid& grid) {
  std::vector<double> map(static_cast<std::size_t>(grid.count));
  texture.render(grid, 0, map);
  // Texture coordinates are grid positions: the texture starts at 0 and
  // reaches past the grid's end (positions below 0 are at rest, so a Texel
  // texture needs no pyramid).
  const auto* t = dynamic_cast<const TexelTexture*>(&texture);
  const bool keep = t != nullptr && t->texel_count() <= max_texels;
  std::unique_ptr<PlayerMap> m(new PlayerMap(grid, std::vector<float>(map.begin(), map.end()), std::nullopt, !keep));
  if (keep) m->lines_.push_back(texel_line(*t, 0.0, std::numeric_limits<double>::infinity()));
  return m;
}

// The same frequencies, phases and mix TexelTexture::render uses: offset and
// gain are texel_mix's from the texel's envelope (the same operations on the
// same double, so the same bits).
PlayerMap::TexelLine PlayerMap::texel_line(const TexelTexture& t, double start_mm, double end_mm) {
  TexelLine line;
  line.start_mm = start_mm;
  line.end_mm = end_mm;
  line.texel_mm = t.spec().texel_length.value();
  line.textured_end_mm = t.textured_end().value();
  line.texels.reserve(t.texel_count());
  const double F = t.spec().fine_strength;
  t.for_each_texels([&](std::size_t, std::span<const Texel> run) {
    for (const Texel& k : run) {
      const double e = k.envelope;
      line.texels.push_back({k.frequency.value(), k.phase_cycles, e - e * F * 0.5, e * F * 0.5});
    }
  });
  return line;
}

float PlayerMap::sample(double x_mm) const noexcept {
  const double u = (x_mm - grid_.origin.value()) * inv_spacing_;
  const std::int64_t last = grid_.count - 1;
  if (!(u > 0.0)) return values_.front();  // also NaN
  if (u >= static_cast<double>(last)) return values_[static_cast<std::size_t>(last)];
  const auto i = static_cast<std::int64_t>(u);
  const double frac = u - static_cast<double>(i);
  const float a = values_[static_cast<std::size_t>(i)];
  const float b = values_[static_cast<std::size_t>(i + 1)];
  return static_cast<float>(a + (b - a) * frac);
}

// The pyramid (player.hpp "Band limit"). Level j ≥ 1 holds the map with
// its content cut to N_0/2^j (N_0 = the map's Nyquist frequency, 1/(2·Δx)),
// stored twice oversampled (spacing 2^(j−1)·Δx), so that a cubic read of it
// leaves its images far down (a level at its own Nyquist rate read between
// samples left an image 25 dB down). Level 1 = the map low-passed at 0.2
// cycles per sample, not decimated; level j + 1 = level j low-passed at 0.1
// cycles per its sample, then decimated by 2 (sample i at level j's 2i).
// The filters: 129-tap Blackman-windowed sinc (transition 5.5/129 cycles per
// sample wide, −74 dB beyond), unit gain at 0, ends extended with their end
// values; so level j is flat (0.1 dB) to ~0.63 × N_0/2^j, −6 dB at 0.8 ×
// and −74 dB from 0.97 ×. Built once, at prepare: ~3 × 129 multiply-adds
// per map sample, twice the map's memory.
namespace {
std::vector<double> blackman_lowpass(double cut, int half) {
  std::vector<double> h(static_cast<std::size_t>(2 * half + 1));
  double sum = 0.0;
  for (int m = -half; m <= half; ++m) {
    const double sinc = m == 0 ? 2.0 * cut : std::sin(2.0 * std::numbers::pi * cut * m) / (std::numbers::pi * m);
    const double n = static_cast<double>(m + half) / (2.0 * half);
    const double window = 0.42 - 0.5 * std::cos(2.0 * std::numbers::pi * n) + 0.08 * std::cos(4.0 * std::numbers::pi * n);
    h[static_cast<std::size_t>(m + half)] = sinc * window;
    sum += sinc * window;
  }
  for (double& c : h) c /= sum;
  return h;
}

// Every `step`-th sample of `in` filtered by h (ends held).
std::vector<float> filter_decimate(const std::vector<float>& in, const std::vector<double>& h, std::int64_t step) {
  const auto n = static_cast<std::int64_t>(in.size());
  const auto half = static_cast<std::int64_t>(h.size() / 2);
  std::vector<float> out(static_cast<std::size_t>((n + step - 1) / step));
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(out.size()); ++i) {
    double acc = 0.0;
    for (std::int64_t m = -half; m <= half; ++m)
      acc +=
          h[static_cast<std::size_t>(m + half)] * in[static_cast<std::size_t>(std::clamp<std::int64_t>(step * i + m, 0, n - 1))];
    out[static_cast<std::size_t>(i)] = static_cast<float>(acc);
  }
  return out;
}
}  // namespace

void PlayerMap::build_pyramid() {
  if (values_.size() < 4) return;
  levels_.push_back(filter_decimate(values_, blackman_lowpass(0.2, 64), 1));
  const std::vector<double> h = blackman_lowpass(0.1, 64);
  while (levels_.back().size() > 4) levels_.push_back(filter_decimate(levels_.back(), h, 2));
}

// Reads between the two levels whose content lies under the output's
// Nyquist frequency, ≈ 1.11 × the limit (0.5·rate over 0.45·rate): level j
// stops at 0.97·N_j (N_j = N_0/2^j, N_0 the map's own Nyquist frequency;
// level 0 holds content up to N_0), so with λ = log2(N_0/limit) the finer
// level read must be j ≥ λ − 0.2: ℓ = λ + 0.8, and level 0 alone while
// N_0 ≤ 1.11 × the limit (λ ≤ −0.15), ℓ rising from 0 to 1 between λ =
// −0.15 and 0.2 so that it is continuous. Real-time safe.
// Level `level` at x by Catmull-Rom (cubic) interpolation: a level is read
// at up to ~0.5 cycles per its sample, where a straight line between
// samples would take 2 dB off and leave images a few dB down; the cubic
// keeps more of the pass band and folds less. Ends held. Real-time safe.
double PlayerMap::cubic_level(std::size_t level, double x_mm) const noexcept {
  const std::vector<float>& v = level == 0 ? values_ : levels_[level - 1];
  const double scale = level <= 1 ? 1.0 : static_cast<double>(std::uint64_t{1} << (level - 1));  // level j: 2^(j−1)·Δx
  const double u = (x_mm - grid_.origin.value()) * inv_spacing_ / scale;
  const auto last = static_cast<std::int64_t>(v.size()) - 1;
  if (!(u > 0.0)) return v.front();  // also NaN
  if (u >= static_cast<double>(last)) return v[static_cast<std::size_t>(last)];
  const auto i = static_cast<std::int64_t>(u);
  const double t = u - static_cast<double>(i);
  const auto at = [&](std::int64_t k) {
    return static_cast<double>(v[static_cast<std::size_t>(std::clamp<std::int64_t>(k, 0, last))]);
  };
  const double p0 = at(i - 1), p1 = at(i), p2 = at(i + 1), p3 = at(i + 2);
  return p1 + 0.5 * t * (p2 - p0 + t * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + t * (3.0 * (p1 - p2) + p3 - p0)));
}

double PlayerMap::pyramid_value(double x_mm, double limit_cpm) const noexcept {
  if (!(limit_cpm < std::numeric_limits<double>::infinity()) || levels_.empty()) return sample(x_mm);
  double a = 0.0;
  const double lambda = limit_cpm > 0.0 ? std::log2(0.5 * inv_spacing_ / limit_cpm) : std::numeric_limits<double>::infinity();
  const double l = !(lambda > -0.15) ? 0.0 : lambda >= 0.2 ? lambda + 0.8 : (lambda + 0.15) / 0.35;
  const auto top = static_cast<double>(levels_.size());
  if (l >= top) {
    a = cubic_level(levels_.size(), x_mm);
  } else {
    const auto j = static_cast<std::size_t>(l);
    const double frac = l - static_cast<double>(j);
    a = cubic_level(j, x_mm);
    if (frac > 0.0) a += (cubic_level(j + 1, x_mm) - a) * frac;
  }
  return std::clamp(a, 0.0, 1.0);  // the cubic's overshoot at steps
}

// One Texel region at region coordinate x: TexelTexture::render's value when
// nothing is faded (the same texel, phase argument, sine and mix). Real-time safe.
double PlayerMap::TexelLine::value(double x, double limit_cpm) const noexcept {
  constexpr double tol = TexelTexture::boundary_tolerance_mm;
  const double shifted = x + tol;
  if (!(shifted >= 0.0) || !(x < textured_end_mm - tol) || texels.empty()) return 0.0;
  const double kd = std::floor(shifted / texel_mm);
  if (kd >= static_cast<double>(texels.size())) return 0.0;
  const auto k = static_cast<std::size_t>(kd);
  const Texel& t = texels[k];
  const double s = detmath::sin_cycles(t.phase + t.frequency * (x - static_cast<double>(k) * texel_mm));
  if (!(limit_cpm < std::numeric_limits<double>::infinity())) return t.offset + t.gain * s;

  double w = player_parts::limit_weight(t.frequency, limit_cpm);
  // The fade reaches into the neighbours (player.hpp "Band limit"): within
  // δ of texel j the weight is at most max(w_j, ramp(distance/δ)), so it is
  // continuous and a faded texel leaves no step.
  const double delta = std::min(fade_reach_periods / limit_cpm, fade_reach_texels * texel_mm);
  if (w > 0.0 && delta > 0.0) {
    const double in = x - static_cast<double>(k) * texel_mm;  // into texel k from its left edge
    const auto ramp = [delta](double d) { return 0.5 - 0.5 * std::cos(std::numbers::pi * d / delta); };
    const auto reach = static_cast<std::size_t>(fade_reach_texels);
    for (std::size_t d = 1; d <= reach && d <= k && w > 0.0; ++d) {
      const double dist = in + static_cast<double>(d - 1) * texel_mm;  // to texel k − d's right edge
      if (dist >= delta) break;
      const double wj = player_parts::limit_weight(texels[k - d].frequency, limit_cpm);
      if (wj < w) w = std::min(w, std::max(wj, ramp(dist)));
    }
    for (std::size_t d = 1; d <= reach && k + d < texels.size() && w > 0.0; ++d) {
      const double dist = (texel_mm - in) + static_cast<double>(d - 1) * texel_mm;  // to texel k + d's left edge
      if (dist >= delta) break;
      const double wj = player_parts::limit_weight(texels[k + d].frequency, limit_cpm);
      if (wj < w) w = std::min(w, std::max(wj, ramp(dist)));
    }
  }
  if (w >= 1.0) return t.offset + t.gain * s;
  return t.offset + t.gain * (w * s);
}

double PlayerMap::band_limited(double x_mm, double limit_cpm) const noexcept {
  for (const TexelLine& line : lines_)
    if (x_mm >= line.start_mm && x_mm < line.end_mm) return line.value(x_mm - line.start_mm, limit_cpm);
  return pyramid_value(x_mm, limit_cpm);
}

bool PlayerMap::on_surface(double x_mm) const noexcept {
  return x_mm >= grid_.origin.value() && x_mm < grid_.origin.value() + grid_.length().value();
}

// --------------------------------------------------------------- PlayerConfig

std::string_view to_string(OutputMode m) {
  switch (m) {
    case OutputMode::amplitude: return "amplitude";
    case OutputMode::vibration: return "vibration";
    case OutputMode::carrier: return "carrier";
  }
  return "amplitude";
}

OutputMode parse_output_mode(std::string_view text, std::string_view field) {
  if (text == "amplitude") return OutputMode::amplitude;
  if (text == "vibration") return OutputMode::vibration;
  if (text == "carrier") return OutputMode::carrier;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: amplitude, vibration, carrier");
}

std::string_view to_string(BandLimit b) { return b == BandLimit::off ? "off" : "on"; }

BandLimit parse_band_limit(std::string_view text, std::string_view field) {
  if (text == "on") return BandLimit::on;
  if (text == "off") return BandLimit::off;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: on, off");
}

std::string_view to_string(ResponseHandling h) { return h == ResponseHandling::off ? "off" : "limit"; }

ResponseHandling parse_response_handling(std::string_view text, std::string_view field) {
  if (text == "limit") return ResponseHandling::limit;
  if (text == "off") return ResponseHandling::off;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: limit, off");
}

namespace {
void check_range(std::string_view field, double v, double lo, double hi, std::string_view unit) {
  if (!(std::isfinite(v) && v >= lo && v <= hi))
    throw InvalidArgument("player: " + std::string(field) + " is " + num(v) + "; allowed " + num(lo) + " … " + num(hi) +
                          (unit.empty() ? "" : " " + std::string(unit)));
}
}  // namespace

void validate(const PlayerConfig& c) {
  check_range("rate_hz", c.rate_hz, 100.0, 384000.0, "Hz");
  check_range("gain", c.gain, 0.0, 1.0, "");
  check_range("carrier_hz", c.carrier_hz, 0.0, c.rate_hz / 2, "Hz");
  check_range("prediction_s", c.prediction_s, 0.0, 0.1, "s");
  check_range("extrapolate_s", c.extrapolate_s, c.prediction_s, 1.0, "s");
  check_range("velocity_smoothing_s", c.velocity_smoothing_s, 1e-4, 1.0, "s");
  check_range("touch_ramp_s", c.touch_ramp_s, 0.0005, 1.0, "s");
  check_range("crossfade_s", c.crossfade_s, 0.0005, 1.0, "s");
  check_range("highpass_hz", c.highpass_hz, 0.1, c.rate_hz / 4, "Hz");
  if (c.lowpass_hz != 0.0) check_range("lowpass_hz", c.lowpass_hz, 1.0, 0.45 * c.rate_hz, "Hz (0 = 0.4·rate)");
  check_range("response_limit_db", c.response_limit_db, 3.0, 60.0, "dB");
  try {
    validate(c.response, "response");
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("player: " + std::string(e.what()));
  }
  const std::size_t n = c.event_capacity;
  if (n < 16 || n > (std::size_t{1} << 20) || (n & (n - 1)) != 0)
    throw InvalidArgument("player: event_capacity is " + std::to_string(n) + "; allowed a power of two, 16 … 1048576");
}

double response_limit_hz(const PlayerConfig& c, const FrequencyResponse& r) noexcept {
  if (c.response_handling == ResponseHandling::off || r.flat()) return 0.0;
  const double f = r.frequency_at_db(c.response_limit_db).value();
  return f <= 0.45 * c.rate_hz ? f : 0.0;
}

double response_limit_hz(const PlayerConfig& c) { return response_limit_hz(c, c.response); }

namespace player_parts {

Biquad Biquad::lowpass(double fc, double rate) noexcept {
  Biquad q;
  const double w0 = 2.0 * std::numbers::pi * fc / rate;
  const double alpha = std::sin(w0) / std::numbers::sqrt2;
  const double cw = std::cos(w0);
  const double a0 = 1.0 + alpha;
  q.b0 = (1.0 - cw) / 2.0 / a0;
  q.b1 = (1.0 - cw) / a0;
  q.b2 = q.b0;
  q.a1 = -2.0 * cw / a0;
  q.a2 = (1.0 - alpha) / a0;
  return q;
}

OutputStage::OutputStage(const PlayerConfig& config) : config_(&config) {
  const double rate = config.rate_hz;
  touch_step_ = 1.0 / (config.touch_ramp_s * rate);
  gain_ = gain_target_ = gain_end_ = config.gain;
  carrier_inc_ = carrier_inc_target_ = inc_end_ = config.carrier_hz / rate;
  dc_r_ = std::exp(-2.0 * std::numbers::pi * config.highpass_hz / rate);
  lowpass_ = Biquad::lowpass(config.lowpass_hz > 0 ? config.lowpass_hz : 0.4 * rate, rate);
}

void OutputStage::set_carrier_target(double hz) noexcept { carrier_inc_target_ = hz / config_->rate_hz; }

// The response limit for the map now playing (player.hpp): the map's own
// response if it carries one, else the config's. Real-time safe: arithmetic
// on members only; nothing changes while the limit stays the same, so maps
// of one display never disturb the filter.
void OutputStage::use_response(const FrequencyResponse* response) noexcept {
  const FrequencyResponse& r = response ? *response : config_->response;
  const double limit = response_limit_hz(*config_, r);
  if (limit == display_limit_hz_) return;
  display_limit_hz_ = limit;
  if (!(limit > 0.0)) {
    display_limit_ = false;
    return;
  }
  const Biquad q = Biquad::lowpass(limit, config_->rate_hz);
  display_lp_.b0 = q.b0;
  display_lp_.b1 = q.b1;
  display_lp_.b2 = q.b2;
  display_lp_.a1 = q.a1;
  display_lp_.a2 = q.a2;
  if (!display_limit_) display_settle_ = true;  // stale state: start settled on the next value
  display_limit_ = true;
}

double OutputStage::step(double a, bool touching) noexcept {
  // Touch / lift ramp (raised cosine: the largest step per sample is
  // π/2 · touch_step_ of the output, no click).
  const bool was_silent = touch_level_ <= 0.0;
  touch_level_ = touching ? std::min(1.0, touch_level_ + touch_step_) : std::max(0.0, touch_level_ - touch_step_);
  // At full touch and at rest the envelope is exactly 1 and 0 (cos π = −1 and
  // cos 0 = 1 in IEEE double): no cosine on the steady path.
  const double env = touch_level_ >= 1.0   ? 1.0
                     : touch_level_ <= 0.0 ? 0.0
                                           : 0.5 - 0.5 * std::cos(std::numbers::pi * touch_level_);

  // The display's response limit (see player.hpp): what it cannot
  // reproduce is not driven. Starts settled on touch-down from rest.
  const OutputMode mode = config_->mode;
  if (display_limit_) {
    if ((was_silent && touching) || display_settle_) {
      display_lp_.settle(a);
      display_settle_ = false;
    }
    a = display_lp_(a);
    if (mode == OutputMode::amplitude) a = std::clamp(a, 0.0, 1.0);  // the filter's overshoot at steps
  }

  gain_ += gain_step_;
  double y = 0.0;
  switch (mode) {
    case OutputMode::amplitude: y = a; break;
    case OutputMode::carrier: {
      y = a * std::sin(2.0 * std::numbers::pi * carrier_phase_);
      carrier_inc_ += inc_step_;
      carrier_phase_ += carrier_inc_;
      carrier_phase_ -= std::floor(carrier_phase_);
      break;
    }
    case OutputMode::vibration: {
      if (was_silent && touching) {
        // Touch-down from rest: start the filters in their steady state for
        // the value under the finger, so landing does not thump.
        lowpass_.settle(a);
        dc_x1_ = a;
        dc_y1_ = 0.0;
      }
      const double lp = lowpass_(a);
      const double hp = lp - dc_x1_ + dc_r_ * dc_y1_;
      dc_x1_ = lp;
      dc_y1_ = hp;
      y = hp;
      break;
    }
  }
  y *= env * gain_;
  if (mode != OutputMode::amplitude) y = std::clamp(y, -1.0, 1.0);
  return y;
}

}  // namespace player_parts

namespace player_parts {
const PlayerConfig& validated(const PlayerConfig& c) {
  validate(c);
  return c;
}
}  // namespace player_parts

// ----------------------------------------------------------- PlayerAttachment

void PlayerAttachment::attach(PlayerBase& player) {
  if (player_ == &player) return;
  if (player.attachment_)
    throw InvalidArgument("player: already driven by another backend; stop that one first (one real-time thread per player)");
  detach();
  player.attachment_ = this;
  player_ = &player;
}

void PlayerAttachment::detach() noexcept {
  if (!player_) return;
  player_->attachment_ = nullptr;
  player_ = nullptr;
}

void PlayerBase::stop_driver() noexcept {
  // stop_driving() detaches; detach() again in case a driver forgot to.
  if (PlayerAttachment* a = attachment_) {
    a->driver_->stop_driving();
    a->detach();
  }
}

// --------------------------------------------------------------------- Player

// prepare: the only allocations a Player makes are its two rings, here.
Player::Player(const PlayerConfig& config, std::unique_ptr<const PlayerMap> map)
    : PlayerBase(player_parts::validated(config).rate_hz),
      config_(config),
      events_(config_.event_capacity),
      maps_(std::move(map), 1.0 / (config_.crossfade_s * config_.rate_hz)),
      stage_(config_) {
  use_response_of(maps_.current());
  stage_.clear_settle();  // the first touch-down settles the filter anyway
}

void Player::use_response_of(const PlayerMap* map) noexcept {
  stage_.use_response(map && map->response() ? &*map->response() : nullptr);
}

Player::~Player() { stop_driver(); }

bool Player::set_gain(double gain) {
  if (!std::isfinite(gain)) gain = 0.0;
  return events_.try_push(PlayerEvent{PlayerEvent::Kind::gain, {}, std::clamp(gain, 0.0, 1.0)});
}

bool Player::set_carrier(double hz) {
  if (!std::isfinite(hz)) hz = 0.0;
  return events_.try_push(PlayerEvent{PlayerEvent::Kind::carrier, {}, std::clamp(hz, 0.0, config_.rate_hz / 2)});
}

// Real-time safe: never allocates, frees, locks, logs, throws or does I/O.
// Maps are only exchanged and handed back (MapExchange); events are popped
// from a fixed-size ring; all arithmetic is on members.
BlockInfo Player::process(std::span<float> out, std::span<float> position_mm) noexcept {
  BlockInfo info;
  const std::size_t frames = out.size();
  if (frames == 0) return info;
  const bool want_positions = position_mm.size() >= frames;

  if (const PlayerMap* next = maps_.begin_block()) use_response_of(next);

  const double rate = config_.rate_hz;
  // Commands queued before this block take effect now, ramped over it.
  player_parts::take_events(events_, static_cast<double>(n_) / rate + config_.prediction_s, finger_, stage_,
                            config_.velocity_smoothing_s);
  stage_.begin_block(frames);
  // The band limit (player.hpp): the display's response limit, else
  // 0.45·rate (below the drive's Nyquist), over the finger's speed.
  const double limit = stage_.limit_hz() > 0.0 ? stage_.limit_hz() : 0.45 * rate;
  const bool band_limit = config_.band_limit == BandLimit::on;
  float peak = 0.0f;
  double x = 0.0;
  bool touching = false;

  for (std::size_t i = 0; i < frames; ++i, ++n_) {
    const double t = static_cast<double>(n_) / rate;
    const double tau = t + config_.prediction_s;
    player_parts::take_events(events_, tau, finger_, stage_, config_.velocity_smoothing_s);
    x = finger_.position(tau, player_parts::next_finger(events_), config_.extrapolate_s)[0];
    const PlayerMap* current = maps_.current();
    touching = finger_.touching() && (current == nullptr || current->on_surface(x));

    // Speed from consecutive output samples (the position is piecewise
    // linear in time between finger samples, so this is exact within a segment).
    const double speed = have_x_ ? std::fabs(x - last_x_) * rate : 0.0;
    last_x_ = x;
    have_x_ = touching;
    const double limit_cpm = speed > 0.0 ? limit / speed : std::numeric_limits<double>::infinity();

    // Map value under the finger, crossfaded (raised cosine) during a swap.
    const double a = maps_.value([&](const PlayerMap& m) -> double {
      return band_limit ? m.band_limited(x, limit_cpm) : static_cast<double>(m.sample(x));
    });
    const auto yf = static_cast<float>(stage_.step(a, touching));
    out[i] = yf;
    if (want_positions) position_mm[i] = static_cast<float>(x);
    peak = std::max(peak, std::fabs(yf));
  }
  stage_.end_block();
  publish_samples(n_);

  info.peak = peak;
  info.position_mm = x;
  info.touching = touching;
  info.crossfading = maps_.crossfading();
  return info;
}

// ------------------------------------------------------------------ off-line

std::vector<float> render_trace(const PlayerMap& map, const PlayerConfig& config, std::span<const FingerSample> trace,
                                std::size_t frames, std::vector<float>* positions, std::size_t block) {
  if (block == 0) throw InvalidArgument("render_trace: block is 0; it must be >= 1");
  Player player(config, std::make_unique<const PlayerMap>(map));
  std::vector<float> out(frames);
  if (positions) positions->assign(frames, 0.0f);
  std::size_t next = 0;
  for (std::size_t done = 0; done < frames;) {
    while (next < trace.size() && player.push(trace[next])) ++next;
    const std::size_t n = std::min(block, frames - done);
    player.process(std::span(out).subspan(done, n), positions ? std::span(*positions).subspan(done, n) : std::span<float>{});
    done += n;
  }
  return out;
}

}  // namespace texel
