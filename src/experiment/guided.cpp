// Guided-exploration optimizer, the MatchOptimizer helpers and the factory
// (include/texel/experiment/guided.hpp).
#include "texel/experiment/guided.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "json_views.hpp"
#include "texel/error.hpp"
#include "texel/experiment/bayes_match.hpp"
#include "texel/random.hpp"

namespace texel::experiment {

namespace {

// Random streams of the guided optimizer (Stream::user + k).
constexpr std::uint64_t stream_order = static_cast<std::uint64_t>(Stream::user) + 1;  // counter: iteration·4 + j
constexpr std::uint64_t stream_side = static_cast<std::uint64_t>(Stream::user) + 2;   // counter: comparison index

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

nlohmann::ordered_json point_json(const MatchPoint& p) {
  return {{"pitch_db", p.pitch_db}, {"irregularity_db", p.irregularity_db}};
}

nlohmann::ordered_json box_json(const MatchBox& b) {
  return {{"center", point_json(b.center)}, {"pitch_half_db", b.pitch_half_db}, {"irregularity_half_db", b.irregularity_half_db}};
}

void check_box(double lo, double hi, const char* lo_name, const char* hi_name) {
  if (!std::isfinite(lo)) throw InvalidArgument(std::string(lo_name) + ": " + num(lo) + " (allowed: a finite number of dB)");
  if (!std::isfinite(hi)) throw InvalidArgument(std::string(hi_name) + ": " + num(hi) + " (allowed: a finite number of dB)");
  if (!(lo < hi))
    throw InvalidArgument(std::string(lo_name) + ": " + num(lo) + " is not below " + hi_name + " " + num(hi) +
                          " (allowed: min < max)");
}

}  // namespace

MatchChoice parse_match_choice(std::string_view text, std::string_view field) {
  if (text == "a" || text == "A") return MatchChoice::a;
  if (text == "b" || text == "B") return MatchChoice::b;
  if (text == "unsure") return MatchChoice::unsure;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) + "' is not a choice (allowed: a, b, unsure)");
}

std::string_view to_string(MatchChoice c) {
  switch (c) {
    case MatchChoice::a: return "a";
    case MatchChoice::b: return "b";
    case MatchChoice::unsure: return "unsure";
  }
  return "unsure";
}

UnsureMode parse_unsure_mode(std::string_view text, std::string_view field) {
  if (text == "ignore") return UnsureMode::ignore;
  if (text == "repeat") return UnsureMode::repeat;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) + "' (allowed: ignore, repeat)");
}

std::string_view to_string(UnsureMode m) { return m == UnsureMode::ignore ? "ignore" : "repeat"; }

BoundMode parse_bound_mode(std::string_view text, std::string_view field) {
  if (text == "per_axis") return BoundMode::per_axis;
  if (text == "joint") return BoundMode::joint;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) + "' (allowed: per_axis, joint)");
}

std::string_view to_string(BoundMode m) { return m == BoundMode::per_axis ? "per_axis" : "joint"; }

void replay(MatchOptimizer& optimizer, std::span<const MatchChoice> choices) {
  for (std::size_t i = 0; i < choices.size(); ++i) {
    if (optimizer.finished())
      throw InvalidArgument("answers: " + std::to_string(choices.size()) + " given, but the " + optimizer.name() +
                            " optimizer finished after " + std::to_string(i) + " (allowed: at most " + std::to_string(i) + ")");
    optimizer.answer(choices[i]);
  }
}

bool MatchBox::contains(const MatchBox& in, double tol) const {
  return in.center.pitch_db - in.pitch_half_db >= center.pitch_db - pitch_half_db - tol &&
         in.center.pitch_db + in.pitch_half_db <= center.pitch_db + pitch_half_db + tol &&
         in.center.irregularity_db - in.irregularity_half_db >= center.irregularity_db - irregularity_half_db - tol &&
         in.center.irregularity_db + in.irregularity_half_db <= center.irregularity_db + irregularity_half_db + tol;
}

// --- guided ------------------------------------------------------------------

void validate(const GuidedConfig& c) {
  check_box(c.pitch_min_db, c.pitch_max_db, "pitch_min_db", "pitch_max_db");
  check_box(c.irregularity_min_db, c.irregularity_max_db, "irregularity_min_db", "irregularity_max_db");
  if (c.iterations < 1 || c.iterations > 1000)
    throw InvalidArgument("iterations: " + std::to_string(c.iterations) + " (allowed: 1 … 1000)");
  if (!(c.shrink_rate > 0 && c.shrink_rate <= 1))
    throw InvalidArgument("shrink_rate: " + num(c.shrink_rate) + " (allowed: (0, 1])");
  if (c.shrink_rate * c.iterations > 1 + 1e-9)
    throw InvalidArgument("shrink_rate: " + num(c.shrink_rate) + " × iterations " + std::to_string(c.iterations) + " = " +
                          num(c.shrink_rate * c.iterations) + " (allowed: <= 1, the box cannot shrink below a point)");
}

GuidedOptimizer::GuidedOptimizer(GuidedConfig config) : config_(config) {
  validate(config_);
  box_.center = {(config_.pitch_min_db + config_.pitch_max_db) / 2,
                 (config_.irregularity_min_db + config_.irregularity_max_db) / 2};
  box_.pitch_half_db = (config_.pitch_max_db - config_.pitch_min_db) / 2;
  box_.irregularity_half_db = (config_.irregularity_max_db - config_.irregularity_min_db) / 2;
  boxes_.push_back(box_);
  start_iteration();
}

void GuidedOptimizer::start_iteration() {
  // Fisher–Yates over the four pairs, one draw per position from (seed, iteration).
  const CounterRng rng(config_.seed, stream_order);
  for (int j = 0; j < 4; ++j) order_[j] = j;
  for (int j = 3; j > 0; --j) {
    const auto k = static_cast<int>(
        rng.below(static_cast<std::uint64_t>(iteration_) * 4 + static_cast<std::uint64_t>(j), static_cast<std::uint64_t>(j + 1)));
    std::swap(order_[j], order_[k]);
  }
  pair_in_iteration_ = 0;
  repeating_ = false;
  sum_ = {0, 0};
}

MatchPoint GuidedOptimizer::pair_point(int pair, bool plus) const {
  const double dp = box_.pitch_half_db / 2, di = box_.irregularity_half_db / 2;
  static constexpr double offsets[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  const double s = plus ? 1.0 : -1.0;
  return {box_.center.pitch_db + s * offsets[pair][0] * dp, box_.center.irregularity_db + s * offsets[pair][1] * di};
}

MatchQuestion GuidedOptimizer::next() const {
  if (finished()) throw Error("guided optimizer: finished after " + std::to_string(comparisons()) + " comparisons");
  const auto index = static_cast<std::uint64_t>(choices_.size());
  const CounterRng rng(config_.seed, stream_side);
  bool plus_is_a = (rng.bits(index) >> 63) != 0;
  if (repeating_) plus_is_a = (rng.bits(index - 1) >> 63) == 0;  // the repeat swaps the sides of the unsure question
  const int pair = order_[pair_in_iteration_];
  MatchQuestion q;
  q.a = pair_point(pair, plus_is_a);
  q.b = pair_point(pair, !plus_is_a);
  q.iteration = iteration_;
  q.index = static_cast<int>(index);
  return q;
}

void GuidedOptimizer::answer(MatchChoice choice) {
  const MatchQuestion q = next();  // throws when finished
  choices_.push_back(choice);
  if (choice == MatchChoice::unsure) {
    if (config_.unsure == UnsureMode::repeat && !repeating_) {
      repeating_ = true;  // ask the same pair again
      return;
    }
  } else {
    const MatchPoint& p = choice == MatchChoice::a ? q.a : q.b;
    sum_.pitch_db += p.pitch_db - box_.center.pitch_db;
    sum_.irregularity_db += p.irregularity_db - box_.center.irregularity_db;
  }
  repeating_ = false;
  if (++pair_in_iteration_ == 4) finish_iteration();
}

void GuidedOptimizer::finish_iteration() {
  const double len_p = config_.pitch_max_db - config_.pitch_min_db;
  const double len_i = config_.irregularity_max_db - config_.irregularity_min_db;
  // Half-widths from the iteration count, not by repeated subtraction, so the
  // last box of iterations × shrink_rate = 1 is exactly a point.
  const double remaining = std::max(0.0, 1.0 - config_.shrink_rate * (iteration_ + 1));
  MatchBox nb;
  nb.pitch_half_db = len_p * remaining / 2;
  nb.irregularity_half_db = len_i * remaining / 2;
  // Largest possible |Σ(chosen − c)| per axis: three of the four pairs move
  // each axis by ±h/2, so 3h/2. The shift may be at most half the per-
  // iteration shrink of the length (= the half-width's shrink), which keeps
  // the new box inside the old one.
  const double max_shift_p = config_.shrink_rate * len_p / 2, max_shift_i = config_.shrink_rate * len_i / 2;
  double k_p = max_shift_p / (1.5 * box_.pitch_half_db);
  double k_i = max_shift_i / (1.5 * box_.irregularity_half_db);
  if (config_.bound == BoundMode::joint) {
    // The longest possible Σ: all four pairs on one side, (3hP/2, hI/2) or
    // (hP/2, 3hI/2) up to signs. Its length maps to the smaller half-shrink.
    const double hp = box_.pitch_half_db, hi = box_.irregularity_half_db;
    const double longest = std::max(std::hypot(3 * hp, hi), std::hypot(hp, 3 * hi)) / 2;
    k_p = k_i = std::min(max_shift_p, max_shift_i) / longest;
  }
  nb.center = {box_.center.pitch_db + k_p * sum_.pitch_db, box_.center.irregularity_db + k_i * sum_.irregularity_db};
  // Enforce containment exactly (it holds mathematically; this absorbs rounding).
  const double room_p = std::max(0.0, box_.pitch_half_db - nb.pitch_half_db);
  const double room_i = std::max(0.0, box_.irregularity_half_db - nb.irregularity_half_db);
  nb.center.pitch_db = std::clamp(nb.center.pitch_db, box_.center.pitch_db - room_p, box_.center.pitch_db + room_p);
  nb.center.irregularity_db =
      std::clamp(nb.center.irregularity_db, box_.center.irregularity_db - room_i, box_.center.irregularity_db + room_i);
  box_ = nb;
  boxes_.push_back(box_);
  ++iteration_;
  if (!finished()) start_iteration();
}

std::string GuidedOptimizer::state_json() const {
  nlohmann::ordered_json j;
  j["procedure"] = "guided";
  j["config"] = {{"pitch_min_db", config_.pitch_min_db},
                 {"pitch_max_db", config_.pitch_max_db},
                 {"irregularity_min_db", config_.irregularity_min_db},
                 {"irregularity_max_db", config_.irregularity_max_db},
                 {"iterations", config_.iterations},
                 {"shrink_rate", config_.shrink_rate},
                 {"unsure", std::string(to_string(config_.unsure))},
                 {"bound", std::string(to_string(config_.bound))},
                 {"seed", config_.seed}};
  j["comparisons"] = comparisons();
  j["iteration"] = iteration_;
  j["question_in_iteration"] = pair_in_iteration_;
  j["repeating"] = repeating_;
  j["order"] = {order_[0], order_[1], order_[2], order_[3]};
  j["pursuit_sum"] = point_json(sum_);
  j["box"] = box_json(box_);
  nlohmann::ordered_json choices = nlohmann::ordered_json::array();
  for (MatchChoice c : choices_) choices.push_back(std::string(to_string(c)));
  j["choices"] = choices;
  j["estimate"] = point_json(estimate());
  j["finished"] = finished();
  return j.dump();
}

GuidedOptimizer GuidedOptimizer::replay(const GuidedConfig& config, std::span<const MatchChoice> choices) {
  GuidedOptimizer g(config);
  experiment::replay(g, choices);
  return g;
}

// --- factory -----------------------------------------------------------------

namespace {

class Params {
 public:
  Params(const nlohmann::json& j, std::set<std::string> known) : j_(j) {
    if (j_.is_null()) return;
    if (!j_.is_object()) throw InvalidArgument("optimizer parameters: " + j_.dump() + " (allowed: a JSON object)");
    for (const auto& [key, value] : j_.items()) {
      if (!known.count(key)) {
        std::string allowed;
        for (const auto& k : known) allowed += (allowed.empty() ? "" : ", ") + k;
        throw InvalidArgument(key + ": unknown optimizer parameter (allowed: " + allowed + ")");
      }
    }
  }
  void number(const char* key, double& out) const {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_number()) throw InvalidArgument(std::string(key) + ": " + v.dump() + " (allowed: a number)");
    out = v.get<double>();
  }
  void optional_number(const char* key, std::optional<double>& out) const {
    if (!has(key)) return;
    if (j_.at(key).is_null()) {
      out.reset();
      return;
    }
    double v = 0;
    number(key, v);
    out = v;
  }
  void integer(const char* key, int& out) const {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_number_integer() || v.get<std::int64_t>() < -1000000 || v.get<std::int64_t>() > 1000000)
      throw InvalidArgument(std::string(key) + ": " + v.dump() + " (allowed: an integer)");
    out = static_cast<int>(v.get<std::int64_t>());
  }
  void seed(const char* key, std::uint64_t& out) const {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0))
      throw InvalidArgument(std::string(key) + ": " + v.dump() + " (allowed: an integer >= 0)");
    out = v.get<std::uint64_t>();
  }
  [[nodiscard]] std::optional<std::string> string(const char* key) const {
    if (!has(key)) return std::nullopt;
    const auto& v = j_.at(key);
    if (!v.is_string()) throw InvalidArgument(std::string(key) + ": " + v.dump() + " (allowed: a string)");
    return v.get<std::string>();
  }

 private:
  [[nodiscard]] bool has(const char* key) const { return j_.is_object() && j_.contains(key); }
  const nlohmann::json& j_;
};

}  // namespace

OptimizerKind parse_optimizer_kind(std::string_view text, std::string_view field) {
  if (text == "guided") return OptimizerKind::guided;
  if (text == "bayesian") return OptimizerKind::bayesian;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) + "' is not an optimizer (allowed: guided, bayesian)");
}

std::string_view to_string(OptimizerKind k) { return k == OptimizerKind::guided ? "guided" : "bayesian"; }

std::unique_ptr<MatchOptimizer> make_optimizer(OptimizerKind kind, std::string_view params_json) {
  nlohmann::json params;
  if (!params_json.empty()) {
    try {
      params = nlohmann::json::parse(params_json);
    } catch (const nlohmann::json::exception&) {
      throw InvalidArgument("optimizer parameters are not JSON");
    }
  }
  return make_optimizer_from(kind, params);
}

std::unique_ptr<MatchOptimizer> make_optimizer_from(OptimizerKind kind, const nlohmann::json& params) {
  if (kind == OptimizerKind::guided) {
    const Params p(params, {"pitch_min_db", "pitch_max_db", "irregularity_min_db", "irregularity_max_db", "iterations",
                            "shrink_rate", "unsure", "bound", "seed"});
    GuidedConfig c;
    p.number("pitch_min_db", c.pitch_min_db);
    p.number("pitch_max_db", c.pitch_max_db);
    p.number("irregularity_min_db", c.irregularity_min_db);
    p.number("irregularity_max_db", c.irregularity_max_db);
    p.integer("iterations", c.iterations);
    p.number("shrink_rate", c.shrink_rate);
    if (auto s = p.string("unsure")) c.unsure = parse_unsure_mode(*s, "unsure");
    if (auto s = p.string("bound")) c.bound = parse_bound_mode(*s, "bound");
    p.seed("seed", c.seed);
    return std::make_unique<GuidedOptimizer>(c);
  }
  {
    const Params p(params, {"pitch_min_db", "pitch_max_db", "irregularity_min_db", "irregularity_max_db", "comparisons",
                            "sd_stop_db", "noise_db", "unsure_band_db", "lapse", "irregularity_weight", "grid_step_db",
                            "candidates", "particles", "seed"});
    BayesConfig c;
    p.number("pitch_min_db", c.pitch_min_db);
    p.number("pitch_max_db", c.pitch_max_db);
    p.number("irregularity_min_db", c.irregularity_min_db);
    p.number("irregularity_max_db", c.irregularity_max_db);
    p.integer("comparisons", c.comparisons);
    p.optional_number("sd_stop_db", c.sd_stop_db);
    p.number("noise_db", c.noise_db);
    p.number("unsure_band_db", c.unsure_band_db);
    p.number("lapse", c.lapse);
    p.number("irregularity_weight", c.irregularity_weight);
    p.number("grid_step_db", c.grid_step_db);
    p.integer("candidates", c.candidates);
    p.integer("particles", c.particles);
    p.seed("seed", c.seed);
    return std::make_unique<BayesOptimizer>(c);
  }
}

}  // namespace texel::experiment
