// Bayesian matching optimizer (include/texel/experiment/bayes_match.hpp).
#include "texel/experiment/bayes_match.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "texel/error.hpp"
#include "texel/random.hpp"

namespace texel::experiment {

namespace {

// Random streams of the Bayesian optimizer (Stream::user + k).
constexpr std::uint64_t stream_particles = static_cast<std::uint64_t>(Stream::user) + 3;   // counter: comparison index
constexpr std::uint64_t stream_candidates = static_cast<std::uint64_t>(Stream::user) + 4;  // counter: index·2^20 + draw

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

double phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

double entropy3(double a, double b, double u) {
  double h = 0;
  for (double p : {a, b, u})
    if (p > 0) h -= p * std::log(p);
  return h;
}

nlohmann::ordered_json point_json(const MatchPoint& p) {
  return {{"pitch_db", p.pitch_db}, {"irregularity_db", p.irregularity_db}};
}

std::vector<double> axis(double lo, double hi, double step) {
  const auto n = static_cast<std::size_t>(std::max(2.0, std::round((hi - lo) / step) + 1));
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n - 1);
  return v;
}

}  // namespace

void validate(const BayesConfig& c) {
  auto box = [](double lo, double hi, const char* lo_name, const char* hi_name) {
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi))
      throw InvalidArgument(std::string(lo_name) + ": " + num(lo) + ", " + hi_name + ": " + num(hi) +
                            " (allowed: finite, min < max)");
  };
  box(c.pitch_min_db, c.pitch_max_db, "pitch_min_db", "pitch_max_db");
  box(c.irregularity_min_db, c.irregularity_max_db, "irregularity_min_db", "irregularity_max_db");
  if (c.comparisons < 1 || c.comparisons > 10000)
    throw InvalidArgument("comparisons: " + std::to_string(c.comparisons) + " (allowed: 1 … 10000)");
  if (c.sd_stop_db && !(*c.sd_stop_db > 0 && std::isfinite(*c.sd_stop_db)))
    throw InvalidArgument("sd_stop_db: " + num(*c.sd_stop_db) + " (allowed: > 0 dB, or absent)");
  if (!(c.noise_db > 0 && std::isfinite(c.noise_db)))
    throw InvalidArgument("noise_db: " + num(c.noise_db) + " (allowed: > 0 dB)");
  if (!(c.unsure_band_db >= 0 && std::isfinite(c.unsure_band_db)))
    throw InvalidArgument("unsure_band_db: " + num(c.unsure_band_db) + " (allowed: >= 0 dB)");
  if (!(c.lapse >= 0 && c.lapse < 0.5)) throw InvalidArgument("lapse: " + num(c.lapse) + " (allowed: [0, 0.5))");
  if (!(c.irregularity_weight > 0 && std::isfinite(c.irregularity_weight)))
    throw InvalidArgument("irregularity_weight: " + num(c.irregularity_weight) + " (allowed: > 0)");
  if (!(c.grid_step_db > 0 && c.grid_step_db <= 5))
    throw InvalidArgument("grid_step_db: " + num(c.grid_step_db) + " (allowed: (0, 5] dB)");
  if ((c.pitch_max_db - c.pitch_min_db) / c.grid_step_db * (c.irregularity_max_db - c.irregularity_min_db) / c.grid_step_db > 4e6)
    throw InvalidArgument("grid_step_db: " + num(c.grid_step_db) +
                          " makes more than 4·10^6 grid cells for the box (allowed: coarser)");
  if (c.candidates < 1 || c.candidates > 4096)
    throw InvalidArgument("candidates: " + std::to_string(c.candidates) + " (allowed: 1 … 4096)");
  if (c.particles < 16 || c.particles > 65536)
    throw InvalidArgument("particles: " + std::to_string(c.particles) + " (allowed: 16 … 65536)");
}

BayesOptimizer::BayesOptimizer(BayesConfig config) : config_(config) {
  validate(config_);
  pitch_axis_ = axis(config_.pitch_min_db, config_.pitch_max_db, config_.grid_step_db);
  irr_axis_ = axis(config_.irregularity_min_db, config_.irregularity_max_db, config_.grid_step_db);
  n_pitch_ = static_cast<int>(pitch_axis_.size());
  n_irr_ = static_cast<int>(irr_axis_.size());
  log_post_.assign(pitch_axis_.size() * irr_axis_.size(), 0.0);  // uniform prior
  post_.assign(log_post_.size(), 1.0 / static_cast<double>(log_post_.size()));
  update_moments();
  plan_next();
}

double BayesOptimizer::distance(const MatchPoint& p, const MatchPoint& t) const {
  const double dp = p.pitch_db - t.pitch_db;
  const double di = config_.irregularity_weight * (p.irregularity_db - t.irregularity_db);
  return std::sqrt(dp * dp + di * di);
}

double BayesOptimizer::likelihood(const MatchQuestion& q, MatchChoice choice, const MatchPoint& t) const {
  const double delta = distance(q.b, t) - distance(q.a, t);  // > 0: A is closer
  const double sigma = std::sqrt(2.0) * config_.noise_db;
  const double pa = phi((delta - config_.unsure_band_db) / sigma);
  const double pb = phi((-delta - config_.unsure_band_db) / sigma);
  const double p = choice == MatchChoice::a ? pa : choice == MatchChoice::b ? pb : std::max(0.0, 1.0 - pa - pb);
  return (1.0 - config_.lapse) * p + config_.lapse / 3.0;
}

bool BayesOptimizer::finished() const {
  if (comparisons() >= config_.comparisons) return true;
  return config_.sd_stop_db && sd_.pitch_db < *config_.sd_stop_db && sd_.irregularity_db < *config_.sd_stop_db;
}

MatchQuestion BayesOptimizer::next() const {
  if (finished()) throw Error("bayesian optimizer: finished after " + std::to_string(comparisons()) + " comparisons");
  return pending_;
}

void BayesOptimizer::answer(MatchChoice choice) {
  const MatchQuestion q = next();  // throws when finished
  for (std::size_t r = 0; r < irr_axis_.size(); ++r)
    for (std::size_t c = 0; c < pitch_axis_.size(); ++c) {
      const std::size_t k = r * pitch_axis_.size() + c;
      // The lapse term keeps every likelihood > 0, so the log is finite.
      log_post_[k] += std::log(likelihood(q, choice, {pitch_axis_[c], irr_axis_[r]}));
    }
  questions_.push_back(q);
  choices_.push_back(choice);
  const double top = *std::max_element(log_post_.begin(), log_post_.end());
  double total = 0;
  for (std::size_t k = 0; k < post_.size(); ++k) total += post_[k] = std::exp(log_post_[k] - top);
  for (double& p : post_) p /= total;
  update_moments();
  if (!finished()) plan_next();
}

void BayesOptimizer::update_moments() {
  double mp = 0, mi = 0;
  for (std::size_t r = 0; r < irr_axis_.size(); ++r)
    for (std::size_t c = 0; c < pitch_axis_.size(); ++c) {
      const double w = post_[r * pitch_axis_.size() + c];
      mp += w * pitch_axis_[c];
      mi += w * irr_axis_[r];
    }
  double vp = 0, vi = 0;
  for (std::size_t r = 0; r < irr_axis_.size(); ++r)
    for (std::size_t c = 0; c < pitch_axis_.size(); ++c) {
      const double w = post_[r * pitch_axis_.size() + c];
      vp += w * (pitch_axis_[c] - mp) * (pitch_axis_[c] - mp);
      vi += w * (irr_axis_[r] - mi) * (irr_axis_[r] - mi);
    }
  mean_ = {mp, mi};
  sd_ = {std::sqrt(vp), std::sqrt(vi)};
}

void BayesOptimizer::plan_next() {
  const auto index = static_cast<std::uint64_t>(choices_.size());
  // Posterior sample: systematic resampling of the grid (one uniform offset
  // from (seed, index)), so every particle is a grid point.
  const auto m = static_cast<std::size_t>(config_.particles);
  std::vector<MatchPoint> particles;
  particles.reserve(m);
  {
    const double u0 = CounterRng(config_.seed, stream_particles).uniform(index);
    double cdf = 0;
    std::size_t k = 0;
    for (std::size_t i = 0; i < m; ++i) {
      const double u = (u0 + static_cast<double>(i)) / static_cast<double>(m);
      while (k + 1 < post_.size() && cdf + post_[k] < u) cdf += post_[k++];
      particles.push_back({pitch_axis_[k % pitch_axis_.size()], irr_axis_[k / pitch_axis_.size()]});
    }
  }
  // Candidates: half pairs of posterior samples (jittered within a cell),
  // half pairs symmetric about the mean along a random direction at a random
  // multiple of the SD. All clamped to the box.
  const CounterRng rng(config_.seed, stream_candidates);
  std::uint64_t draw = index << 20;
  auto u = [&] { return rng.uniform(draw++); };
  auto clamp = [&](MatchPoint p) {
    p.pitch_db = std::clamp(p.pitch_db, config_.pitch_min_db, config_.pitch_max_db);
    p.irregularity_db = std::clamp(p.irregularity_db, config_.irregularity_min_db, config_.irregularity_max_db);
    return p;
  };
  const double h = config_.grid_step_db / 2;
  std::vector<MatchQuestion> candidates;
  candidates.reserve(static_cast<std::size_t>(config_.candidates));
  for (int c = 0; c < config_.candidates; ++c) {
    MatchQuestion q;
    if (c % 2 == 0) {
      const MatchPoint& p1 = particles[static_cast<std::size_t>(u() * static_cast<double>(m))];
      const MatchPoint& p2 = particles[static_cast<std::size_t>(u() * static_cast<double>(m))];
      q.a = clamp({p1.pitch_db + h * (2 * u() - 1), p1.irregularity_db + h * (2 * u() - 1)});
      q.b = clamp({p2.pitch_db + h * (2 * u() - 1), p2.irregularity_db + h * (2 * u() - 1)});
    } else {
      const double theta = std::acos(-1.0) * u();
      const double r = 0.25 + 1.75 * u();
      const double dp = r * std::max(sd_.pitch_db, h) * std::cos(theta);
      const double di = r * std::max(sd_.irregularity_db, h) * std::sin(theta);
      q.a = clamp({mean_.pitch_db + dp, mean_.irregularity_db + di});
      q.b = clamp({mean_.pitch_db - dp, mean_.irregularity_db - di});
    }
    candidates.push_back(q);
  }
  // Expected information gain I(answer; target) = H(E_t p) − E_t H(p),
  // estimated on the particles. Ties keep the first candidate.
  double best_gain = -std::numeric_limits<double>::infinity();
  std::size_t best = 0;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    double ma = 0, mb = 0, mu = 0, conditional = 0;
    for (const MatchPoint& t : particles) {
      const double pa = likelihood(candidates[c], MatchChoice::a, t);
      const double pb = likelihood(candidates[c], MatchChoice::b, t);
      const double pu = std::max(0.0, 1.0 - pa - pb);
      ma += pa;
      mb += pb;
      mu += pu;
      conditional += entropy3(pa, pb, pu);
    }
    const double inv = 1.0 / static_cast<double>(m);
    const double gain = entropy3(ma * inv, mb * inv, mu * inv) - conditional * inv;
    if (gain > best_gain) {
      best_gain = gain;
      best = c;
    }
  }
  pending_ = candidates[best];
  pending_.index = static_cast<int>(index);
  pending_.iteration = static_cast<int>(index);
}

std::string BayesOptimizer::state_json() const {
  nlohmann::ordered_json j;
  j["procedure"] = "bayesian";
  j["config"] = {{"pitch_min_db", config_.pitch_min_db},
                 {"pitch_max_db", config_.pitch_max_db},
                 {"irregularity_min_db", config_.irregularity_min_db},
                 {"irregularity_max_db", config_.irregularity_max_db},
                 {"comparisons", config_.comparisons},
                 {"sd_stop_db", config_.sd_stop_db ? nlohmann::ordered_json(*config_.sd_stop_db) : nlohmann::ordered_json()},
                 {"noise_db", config_.noise_db},
                 {"unsure_band_db", config_.unsure_band_db},
                 {"lapse", config_.lapse},
                 {"irregularity_weight", config_.irregularity_weight},
                 {"grid_step_db", config_.grid_step_db},
                 {"candidates", config_.candidates},
                 {"particles", config_.particles},
                 {"seed", config_.seed}};
  j["comparisons"] = comparisons();
  nlohmann::ordered_json hist = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < choices_.size(); ++i)
    hist.push_back({{"a", point_json(questions_[i].a)},
                    {"b", point_json(questions_[i].b)},
                    {"choice", std::string(to_string(choices_[i]))}});
  j["history"] = hist;
  j["estimate"] = point_json(mean_);
  j["sd"] = point_json(sd_);
  j["finished"] = finished();
  return j.dump();
}

BayesOptimizer BayesOptimizer::replay(const BayesConfig& config, std::span<const MatchChoice> choices) {
  BayesOptimizer b(config);
  experiment::replay(b, choices);
  return b;
}

}  // namespace texel::experiment
