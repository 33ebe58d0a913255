// Bayesian matching optimizer ("beyond the source").
//
// Method: a grid posterior over the hidden target t in (Central Pitch dB,
// Irregularity dB), uniform prior over the box. Choice model (the same one
// the simulated Matcher uses): the participant perceives the distances
// dA = |A − t|, dB = |B − t| (axis-weighted Euclidean) each with Gaussian
// noise of SD noise_db, so Δ = dB − dA carries noise σ = √2·noise_db;
//   P(A) = Φ((Δ − band)/σ), P(B) = Φ((−Δ − band)/σ), P(unsure) = the rest,
// mixed with a lapse rate (uniform over the three answers). The next pair is
// the candidate with the largest expected information gain (mutual
// information between the answer and t), estimated on a deterministic
// stratified sample of the posterior; candidates are drawn around the
// posterior (pairs of posterior samples and symmetric pairs about the mean).
// Every draw is a function of (seed, comparison index).
// Trade-off: more computation per question (well under a millisecond per
// candidate set) and a model assumption (noise, band) for a faster match;
// the estimate is the posterior mean, the uncertainty its SD.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "texel/experiment/guided.hpp"

namespace texel::experiment {

struct BayesConfig {
  double pitch_min_db = -20;  ///< prior box, Central Pitch (dB re 1 cpm); min < max
  double pitch_max_db = 19.7;
  double irregularity_min_db = -30;  ///< prior box, Irregularity (dB); min < max
  double irregularity_max_db = 5;
  int comparisons = 20;              ///< budget, >= 1
  std::optional<double> sd_stop_db;  ///< stop early when both posterior SDs are below this (dB, > 0)
  double noise_db = 2.0;             ///< assumed perceptual noise per distance (dB, > 0)
  double unsure_band_db = 1.0;       ///< assumed unsure band on |dA − dB| (dB, >= 0)
  double lapse = 0.04;               ///< assumed lapse rate, [0, 0.5)
  double irregularity_weight = 1.0;  ///< weight of the Irregularity axis in distances, > 0
  double grid_step_db = 0.5;         ///< posterior grid spacing (dB), (0, 5]
  int candidates = 64;               ///< candidate pairs per question, [1, 4096]
  int particles = 256;               ///< posterior samples for the information gain, [16, 65536]
  std::uint64_t seed = 1;
};
void validate(const BayesConfig& config);

class BayesOptimizer final : public MatchOptimizer {
 public:
  explicit BayesOptimizer(BayesConfig config);

  /// The pending comparison; throws texel::Error if finished().
  [[nodiscard]] MatchQuestion next() const override;
  void answer(MatchChoice choice) override;
  [[nodiscard]] bool finished() const override;
  /// Posterior mean.
  [[nodiscard]] MatchPoint estimate() const override { return mean_; }
  /// Posterior SD per axis.
  [[nodiscard]] MatchPoint uncertainty() const override { return sd_; }
  [[nodiscard]] int comparisons() const override { return static_cast<int>(choices_.size()); }
  [[nodiscard]] int budget() const override { return config_.comparisons; }
  [[nodiscard]] std::string state_json() const override;
  [[nodiscard]] std::string name() const override { return "bayesian"; }

  /// P(choice | target), the likelihood the posterior uses.
  [[nodiscard]] double likelihood(const MatchQuestion& q, MatchChoice choice, const MatchPoint& target) const;
  [[nodiscard]] const std::vector<MatchChoice>& choices() const { return choices_; }
  [[nodiscard]] const std::vector<MatchQuestion>& questions() const { return questions_; }
  [[nodiscard]] const BayesConfig& config() const { return config_; }

  static BayesOptimizer replay(const BayesConfig& config, std::span<const MatchChoice> choices);

 private:
  void update_moments();
  void plan_next();
  [[nodiscard]] double distance(const MatchPoint& p, const MatchPoint& t) const;

  BayesConfig config_;
  int n_pitch_ = 0, n_irr_ = 0;
  std::vector<double> pitch_axis_, irr_axis_;
  std::vector<double> log_post_;  // unnormalised log posterior, row-major [irr][pitch]
  std::vector<double> post_;      // normalised posterior
  MatchPoint mean_, sd_;
  MatchQuestion pending_;
  std::vector<MatchQuestion> questions_;
  std::vector<MatchChoice> choices_;
};

}  // namespace texel::experiment
