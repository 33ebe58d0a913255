// Simulated observers (include/texel/experiment/observer.hpp).
#include "texel/experiment/observer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "texel/codec.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"
#include "texel/reference.hpp"

namespace texel::experiment {

namespace {

// Random streams of the observers (Stream::user + k); the procedures use 1 … 9.
constexpr std::uint64_t stream_psychometric = static_cast<std::uint64_t>(Stream::user) + 10;  // counter: trial
constexpr std::uint64_t stream_choose = static_cast<std::uint64_t>(Stream::user) + 11;        // counter: 2·trial (+1)
constexpr std::uint64_t stream_adjust = static_cast<std::uint64_t>(Stream::user) + 12;        // counter: 2·trial (+1)
constexpr std::uint64_t stream_rate = static_cast<std::uint64_t>(Stream::user) + 13;          // counter: trial
constexpr std::uint64_t stream_odd = static_cast<std::uint64_t>(Stream::user) + 14;           // counter: 64·trial + 2·i (+1)

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

void finite(double v, const char* field, const char* allowed, bool ok) {
  if (!std::isfinite(v) || !ok) throw InvalidArgument(std::string(field) + ": " + num(v) + " (allowed: " + allowed + ")");
}

}  // namespace

// --- psychometric ----------------------------------------------------------------

PsychometricShape parse_psychometric_shape(std::string_view text, std::string_view field) {
  if (text == "weibull") return PsychometricShape::weibull;
  if (text == "logistic") return PsychometricShape::logistic;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) + "' (allowed: weibull, logistic)");
}

std::string_view to_string(PsychometricShape s) { return s == PsychometricShape::weibull ? "weibull" : "logistic"; }

void validate(const PsychometricConfig& c) {
  const bool positive_x = c.shape == PsychometricShape::weibull || c.log_x;
  finite(c.threshold, "threshold", positive_x ? "> 0 (weibull or log_x)" : "finite", !positive_x || c.threshold > 0);
  finite(c.slope, "slope", "> 0", c.slope > 0);
  finite(c.guess, "guess", "[0, 1)", c.guess >= 0 && c.guess < 1);
  finite(c.lapse, "lapse", "[0, 1 − guess)", c.lapse >= 0 && c.lapse < 1 - c.guess);
}

PsychometricObserver::PsychometricObserver(PsychometricConfig config) : config_(config) { validate(config_); }

double PsychometricObserver::p_correct(double x) const {
  const auto& c = config_;
  double f = 0;
  if (c.shape == PsychometricShape::weibull) {
    f = x > 0 ? 1.0 - std::exp(-std::pow(x / c.threshold, c.slope)) : 0.0;
  } else if (c.log_x) {
    f = x > 0 ? 1.0 / (1.0 + std::exp(-c.slope * (std::log10(x) - std::log10(c.threshold)))) : 0.0;
  } else {
    f = 1.0 / (1.0 + std::exp(-c.slope * (x - c.threshold)));
  }
  return c.guess + (1.0 - c.guess - c.lapse) * f;
}

double PsychometricObserver::inverse(double p) const {
  const auto& c = config_;
  if (!(p > c.guess && p < 1.0 - c.lapse))
    throw InvalidArgument("p: " + num(p) + " (allowed: between guess " + num(c.guess) + " and 1 − lapse " + num(1 - c.lapse) +
                          ")");
  const double f = (p - c.guess) / (1.0 - c.guess - c.lapse);
  if (c.shape == PsychometricShape::weibull) return c.threshold * std::pow(-std::log(1.0 - f), 1.0 / c.slope);
  const double logit = std::log(f / (1.0 - f)) / c.slope;
  return c.log_x ? c.threshold * std::pow(10.0, logit) : c.threshold + logit;
}

bool PsychometricObserver::respond(double x, std::uint64_t trial) const { return respond_with(p_correct(x), trial); }

bool PsychometricObserver::respond_with(double p, std::uint64_t trial) const {
  return CounterRng(config_.seed, stream_psychometric).uniform(trial) < p;
}

// --- matcher -----------------------------------------------------------------------

void validate(const MatcherConfig& c) {
  finite(c.target.pitch_db, "target.pitch_db", "a finite number of dB", true);
  finite(c.target.irregularity_db, "target.irregularity_db", "a finite number of dB", true);
  finite(c.noise_db, "noise_db", ">= 0 dB", c.noise_db >= 0);
  finite(c.unsure_band_db, "unsure_band_db", ">= 0 dB", c.unsure_band_db >= 0);
  finite(c.irregularity_weight, "irregularity_weight", "> 0", c.irregularity_weight > 0);
  finite(c.pitch_min_db, "pitch_min_db", "finite, below pitch_max_db", c.pitch_min_db < c.pitch_max_db);
  finite(c.pitch_max_db, "pitch_max_db", "finite", true);
  finite(c.irregularity_min_db, "irregularity_min_db", "finite, below irregularity_max_db",
         c.irregularity_min_db < c.irregularity_max_db);
  finite(c.irregularity_max_db, "irregularity_max_db", "finite", true);
}

Matcher::Matcher(MatcherConfig config) : config_(config) { validate(config_); }

double Matcher::distance(const MatchPoint& p) const {
  const double dp = p.pitch_db - config_.target.pitch_db;
  const double di = config_.irregularity_weight * (p.irregularity_db - config_.target.irregularity_db);
  return std::sqrt(dp * dp + di * di);
}

MatchChoice Matcher::choose(const MatchQuestion& q, std::uint64_t trial) const {
  const CounterRng rng(config_.seed, stream_choose);
  const double da = distance(q.a) + config_.noise_db * rng.normal(2 * trial);
  const double db = distance(q.b) + config_.noise_db * rng.normal(2 * trial + 1);
  if (std::abs(da - db) < config_.unsure_band_db) return MatchChoice::unsure;
  return da < db ? MatchChoice::a : MatchChoice::b;
}

MatchPoint Matcher::adjust(std::uint64_t trial) const {
  const CounterRng rng(config_.seed, stream_adjust);
  return {
      std::clamp(config_.target.pitch_db + config_.noise_db * rng.normal(2 * trial), config_.pitch_min_db, config_.pitch_max_db),
      std::clamp(config_.target.irregularity_db + config_.noise_db * rng.normal(2 * trial + 1), config_.irregularity_min_db,
                 config_.irregularity_max_db)};
}

int Matcher::confidence(std::uint64_t trial) const {
  // The same draws as adjust(trial): a participant is less sure when the
  // slider ended further from what they meant.
  const CounterRng rng(config_.seed, stream_adjust);
  const double z = std::hypot(rng.normal(2 * trial), rng.normal(2 * trial + 1));
  if (z < 0.5) return 5;
  if (z < 1.0) return 4;
  if (z < 1.5) return 3;
  if (z < 2.0) return 2;
  return 1;
}

std::size_t Matcher::odd_one(std::span<const MatchPoint> perceived, std::uint64_t trial) const {
  if (perceived.size() < 3 || perceived.size() > 32)
    throw InvalidArgument("odd_one: " + std::to_string(perceived.size()) + " positions (allowed: 3 … 32)");
  const CounterRng rng(config_.seed, stream_odd);
  std::vector<MatchPoint> p(perceived.begin(), perceived.end());
  for (std::size_t i = 0; i < p.size(); ++i) {
    p[i].pitch_db += config_.noise_db * rng.normal(64 * trial + 2 * i);
    p[i].irregularity_db += config_.noise_db * rng.normal(64 * trial + 2 * i + 1);
  }
  std::size_t best = 0;
  double best_sum = -1.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double sum = 0.0;
    for (std::size_t j = 0; j < p.size(); ++j) {
      const double dp = p[i].pitch_db - p[j].pitch_db;
      const double di = config_.irregularity_weight * (p[i].irregularity_db - p[j].irregularity_db);
      sum += std::sqrt(dp * dp + di * di);
    }
    if (sum > best_sum) best_sum = sum, best = i;
  }
  return best;
}

namespace {

// As `texel encode --device`: the encoder's default perceptual model
// (codec::PerceptualModel::version, docs/encoder.md §2), the display's
// response in its loop, so simulated observers feel what the encoder does.
MatchPoint perceive(codec::Signal signal, const DeviceProfile& profile) {
  codec::EncoderConfig cfg;
  cfg.model = codec::model_defaults(codec::PerceptualModel{}.version);
  cfg.model.display = profile.response;
  const codec::EncodeResult r = codec::encode(signal, cfg);
  return {r.spec.central_pitch.value(), r.spec.irregularity.value()};
}

}  // namespace

std::optional<MatchPoint> perceive_document(const std::string& document_json, double length_mm) {
  const Document doc = parse_document(document_json, "stimulus");
  codec::Signal signal;
  signal.amplitude = prepare_surface(doc).render();
  signal.spacing = doc.device.spacing;
  if (length_mm > 0) {
    const auto n = static_cast<std::size_t>(std::floor(length_mm / doc.device.spacing.value() + 1e-9));
    if (n < 2 || n > signal.amplitude.size())
      throw InvalidArgument("length_mm: " + num(length_mm) + " (allowed: 2 samples … the device's length)");
    signal.amplitude.resize(n);
  }
  signal.description = "stimulus on " + doc.device.name;
  try {
    return perceive(std::move(signal), doc.device);
  } catch (const FormatError&) {
    // Without a fine part the encoder reports its 10 dB default pitch,
    // which a device whose band ends lower (tablet-2d: 7.15 dB) cannot
    // render: the stimulus has no fine texture to perceive.
    return std::nullopt;
  }
}

MatchPoint perceptual_target(const std::string& reference_name, const std::string& device) {
  (void)reference_info(reference_name);  // throws InvalidArgument listing the names
  const DeviceProfile profile = load_device(device);
  ReferenceSpec spec;
  spec.name = reference_name;
  spec.synthesis = ReferenceSynthesis::direct;  // the bytes the sessions' version-2 stimuli show
  const Surface surface = prepare_surface(make_reference_document(profile, spec));
  codec::Signal signal;
  signal.amplitude = surface.render();
  signal.spacing = profile.spacing;
  signal.description = "reference " + reference_name + " on " + profile.name;
  return perceive(std::move(signal), profile);
}

// --- rater -------------------------------------------------------------------------

void validate(const RaterConfig& c) {
  finite(c.scale_min, "scale_min", "finite, below scale_max", c.scale_min < c.scale_max);
  finite(c.scale_max, "scale_max", "finite", true);
  finite(c.distance_scale_db, "distance_scale_db", "> 0 dB", c.distance_scale_db > 0);
  finite(c.noise, "noise", ">= 0", c.noise >= 0);
}

Rater::Rater(RaterConfig config) : config_(config) { validate(config_); }

double Rater::expected(double distance_db) const {
  return config_.scale_min +
         (config_.scale_max - config_.scale_min) * std::exp(-std::abs(distance_db) / config_.distance_scale_db);
}

int Rater::rate(double distance_db, std::uint64_t trial) const {
  const double v = expected(distance_db) + config_.noise * CounterRng(config_.seed, stream_rate).normal(trial);
  return static_cast<int>(std::clamp(std::round(v), std::ceil(config_.scale_min), std::floor(config_.scale_max)));
}

}  // namespace texel::experiment
