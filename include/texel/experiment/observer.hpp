// Simulated observers: seeded stand-ins for participants, to test and
// benchmark the adaptive procedures (docs/procedures.md §4).
// Every draw is a pure function of (seed, trial index) through
// texel::CounterRng, so a simulated session is exact and any trial can be
// re-drawn without the ones before it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "texel/experiment/guided.hpp"

namespace texel::experiment {

// --- psychometric observer ---------------------------------------------------

enum class PsychometricShape { weibull, logistic };
PsychometricShape parse_psychometric_shape(std::string_view text, std::string_view field = "shape");
std::string_view to_string(PsychometricShape s);

/// Guess rates of the usual tasks.
inline constexpr double guess_detection = 0.0;
inline constexpr double guess_2afc = 0.5;
inline constexpr double guess_oddity3 = 1.0 / 3.0;

struct PsychometricConfig {
  PsychometricShape shape = PsychometricShape::weibull;
  double threshold = 1.0;  ///< α: Weibull scale / logistic midpoint (units of x; > 0 for weibull or log_x)
  double slope = 3.0;      ///< β: Weibull shape / logistic slope (per unit x, or per decade with log_x), > 0
  double guess = 0.0;      ///< γ: chance rate, [0, 1)
  double lapse = 0.0;      ///< λ: lapse rate, [0, 1 − γ)
  bool log_x = false;      ///< logistic on log10(x) (weibull is already a function of log x)
  std::uint64_t seed = 1;
};
void validate(const PsychometricConfig& config);

/// A psychometric observer: p(x) = γ + (1 − γ − λ)·F(x), with
/// F = 1 − exp(−(x/α)^β) (Weibull, x <= 0 → 0) or 1/(1 + exp(−β(x − α)))
/// (logistic; on log10 x with log_x). Source: Wichmann & Hill (2001).
/// Trade-off: one fixed function, no learning or fatigue; respond() is a
/// Bernoulli draw from uniform(seed, trial) < p(x).
class PsychometricObserver {
 public:
  explicit PsychometricObserver(PsychometricConfig config);
  [[nodiscard]] double p_correct(double x) const;
  /// The x where p_correct(x) = p (p strictly between γ and 1 − λ).
  [[nodiscard]] double inverse(double p) const;
  [[nodiscard]] bool respond(double x, std::uint64_t trial) const;
  /// A Bernoulli draw with probability p from the same (seed, trial) stream.
  [[nodiscard]] bool respond_with(double p, std::uint64_t trial) const;
  [[nodiscard]] const PsychometricConfig& config() const { return config_; }

 private:
  PsychometricConfig config_;
};

// --- matcher -------------------------------------------------------------------

struct MatcherConfig {
  MatchPoint target;                 ///< the hidden best match (dB)
  double noise_db = 2.0;             ///< perceptual noise SD per distance judgment / slider axis (dB), >= 0
  double unsure_band_db = 1.0;       ///< unsure when the noisy distances differ by less (dB), >= 0
  double irregularity_weight = 1.0;  ///< distance = √(ΔP² + (w·ΔI)²), w > 0
  double pitch_min_db = -20;         ///< box adjust() clamps to
  double pitch_max_db = 19.7;
  double irregularity_min_db = -30;
  double irregularity_max_db = 5;
  std::uint64_t seed = 1;
};
void validate(const MatcherConfig& config);

/// A simulated participant for matching tasks: a noisy perceptual distance
/// to a hidden target. choose() perceives dA + σ·n₁ and dB + σ·n₂ and answers
/// the closer one, or unsure when they differ by less than the band;
/// adjust() is a slider match: target + σ·(n₁, n₂) clamped to the box;
/// confidence() is 5 … 1, falling with the size of that trial's slider noise.
/// Trade-off: isotropic Gaussian noise in dB, a stationary target, no memory;
/// the same model the Bayesian optimizer assumes (so its benchmark is a
/// best case for it when the assumed noise matches).
class Matcher {
 public:
  explicit Matcher(MatcherConfig config);
  [[nodiscard]] double distance(const MatchPoint& p) const;
  [[nodiscard]] MatchChoice choose(const MatchQuestion& q, std::uint64_t trial) const;
  [[nodiscard]] MatchPoint adjust(std::uint64_t trial) const;
  /// 1 … 5: 5 when the slider noise of this trial is small (|n| < 0.5), 1 when |n| >= 2.
  [[nodiscard]] int confidence(std::uint64_t trial) const;
  /// Oddity among perceived positions (three or more): each position is
  /// perceived with σ·n added to both coordinates, and the one farthest in
  /// summed distance (as distance() weighs it) from the others is the odd
  /// one. Returns its index.
  [[nodiscard]] std::size_t odd_one(std::span<const MatchPoint> perceived, std::uint64_t trial) const;
  [[nodiscard]] const MatcherConfig& config() const { return config_; }

 private:
  MatcherConfig config_;
};

/// The (Central Pitch, Irregularity) of the reference called `reference_name`
/// (texel reference --list) under the encoder's perceptual model: the
/// reference is rendered on `device` (a built-in name or a profile path) and
/// encoded with texel::codec::encode as `texel encode --device` does (the
/// device's frequency response in the model's loop). Nothing is cached. Throws
/// InvalidArgument for an unknown reference or device. Takes about a second.
MatchPoint perceptual_target(const std::string& reference_name, const std::string& device = "tpad");

/// The (Central Pitch, Irregularity) a stimulus document produces under the
/// same perceptual model: the document (a 1-D texture document as JSON text)
/// is rendered on its device, the span [0, length_mm) of the map (0 = the
/// whole device) — what a finger swiping it at constant speed feels as
/// vibration — is encoded as perceptual_target does. Nothing is cached.
/// nullopt when the encoder finds no fine texture there (a map at rest, or
/// only content below its fine/coarse boundary).
std::optional<MatchPoint> perceive_document(const std::string& document_json, double length_mm = 0.0);

// --- rater -------------------------------------------------------------------

struct RaterConfig {
  double scale_min = 1;             ///< lowest rating (least similar)
  double scale_max = 5;             ///< highest rating (identical); > scale_min
  double distance_scale_db = 10.0;  ///< e-folding distance of the similarity (dB), > 0
  double noise = 0.5;               ///< rating noise SD (scale units), >= 0
  std::uint64_t seed = 1;
};
void validate(const RaterConfig& config);

/// A similarity rater: round(min + (max − min)·exp(−d/D) + noise·n), clamped
/// to [min, max]. Trade-off: an exponential similarity decay (Shepard 1987)
/// with Gaussian response noise; no anchoring or range effects.
class Rater {
 public:
  explicit Rater(RaterConfig config);
  /// Noise-free expected similarity, in scale units.
  [[nodiscard]] double expected(double distance_db) const;
  [[nodiscard]] int rate(double distance_db, std::uint64_t trial) const;
  [[nodiscard]] const RaterConfig& config() const { return config_; }

 private:
  RaterConfig config_;
};

}  // namespace texel::experiment
