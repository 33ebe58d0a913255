// N-up / M-down staircase (include/texel/experiment/staircase.hpp).
#include "texel/experiment/staircase.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <sstream>

#include <nlohmann/json.hpp>

#include "texel/error.hpp"

namespace texel::experiment {

namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

}  // namespace

StepType parse_step_type(std::string_view text, std::string_view field) {
  if (text == "lin") return StepType::lin;
  if (text == "log") return StepType::log;
  if (text == "db") return StepType::db;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) + "' is not a step type (allowed: lin, log, db)");
}

std::string_view to_string(StepType t) {
  switch (t) {
    case StepType::lin: return "lin";
    case StepType::log: return "log";
    case StepType::db: return "db";
  }
  return "lin";
}

EndValue parse_end_value(std::string_view text, std::string_view field) {
  if (text == "next") return EndValue::next;
  if (text == "last-presented") return EndValue::last_presented;
  throw InvalidArgument(std::string(field) + ": '" + std::string(text) + "' is not an end value (allowed: next, last-presented)");
}

std::string_view to_string(EndValue e) { return e == EndValue::next ? "next" : "last-presented"; }

void validate(const StaircaseConfig& c) {
  if (!std::isfinite(c.start_value))
    throw InvalidArgument("start_value: " + num(c.start_value) + " is not finite (allowed: a finite number)");
  if (c.step_type != StepType::lin && !(c.start_value > 0))
    throw InvalidArgument("start_value: " + num(c.start_value) + " with step_type " + std::string(to_string(c.step_type)) +
                          " (allowed: > 0, the value is multiplied)");
  if (c.step_sizes.empty()) throw InvalidArgument("step_sizes: empty (allowed: one or more steps > 0)");
  for (std::size_t i = 0; i < c.step_sizes.size(); ++i) {
    const double s = c.step_sizes[i];
    if (!std::isfinite(s) || !(s > 0))
      throw InvalidArgument("step_sizes[" + std::to_string(i) + "]: " + num(s) + " (allowed: finite and > 0)");
  }
  if (c.n_up < 1) throw InvalidArgument("n_up: " + std::to_string(c.n_up) + " (allowed: >= 1)");
  if (c.n_down < 1) throw InvalidArgument("n_down: " + std::to_string(c.n_down) + " (allowed: >= 1)");
  if (c.n_reversals && *c.n_reversals < 0)
    throw InvalidArgument("n_reversals: " + std::to_string(*c.n_reversals) + " (allowed: >= 0; raised to len(step_sizes))");
  if (c.n_trials < 0) throw InvalidArgument("n_trials: " + std::to_string(c.n_trials) + " (allowed: >= 0)");
  if (c.min_value && !std::isfinite(*c.min_value))
    throw InvalidArgument("min_value: " + num(*c.min_value) + " (allowed: a finite number)");
  if (c.max_value && !std::isfinite(*c.max_value))
    throw InvalidArgument("max_value: " + num(*c.max_value) + " (allowed: a finite number)");
  if (c.min_value && c.max_value && *c.min_value > *c.max_value)
    throw InvalidArgument("min_value: " + num(*c.min_value) + " is above max_value " + num(*c.max_value) +
                          " (allowed: min_value <= max_value)");
}

Staircase::Staircase(StaircaseConfig config) : config_(std::move(config)) {
  validate(config_);
  const int len = static_cast<int>(config_.step_sizes.size());
  n_reversals_ = std::max(config_.n_reversals.value_or(len), len);
  value_ = config_.start_value;  // never clamped
  step_ = config_.step_sizes[0];
}

bool Staircase::finished() const {
  return static_cast<int>(reversal_intensities_.size()) >= n_reversals_ &&
         intensities_.size() >= static_cast<std::size_t>(config_.n_trials);
}

double Staircase::next() const {
  if (finished()) throw Error("staircase: finished after " + std::to_string(trials()) + " trials; no next intensity");
  return value_;
}

void Staircase::answer(bool correct) {
  if (finished()) throw Error("staircase: answer after it finished (" + std::to_string(trials()) + " trials)");
  intensities_.push_back(value_);
  responses_.push_back(correct);
  if (correct)
    run_ = run_ > 0 ? run_ + 1 : 1;
  else
    run_ = run_ < 0 ? run_ - 1 : -1;

  Direction move = Direction::none;
  if (reversal_intensities_.empty() && config_.apply_initial_rule)
    move = correct ? Direction::down : Direction::up;  // 1-up/1-down until the first reversal
  else if (run_ >= config_.n_down)
    move = Direction::down;
  else if (run_ <= -config_.n_up)
    move = Direction::up;

  last_was_reversal_ = false;
  if (move == Direction::none) return;
  // The first move is never a reversal (direction_ == none).
  last_was_reversal_ = direction_ != Direction::none && direction_ != move;
  direction_ = move;
  run_ = 0;
  if (last_was_reversal_) {
    reversal_trials_.push_back(intensities_.size() - 1);
    reversal_intensities_.push_back(intensities_.back());
    if (config_.step_sizes.size() > 1)  // the new step applies to this trial's move
      step_ = config_.step_sizes[std::min(reversal_intensities_.size(), config_.step_sizes.size() - 1)];
  }
  const double sign = move == Direction::up ? 1.0 : -1.0;
  switch (config_.step_type) {
    case StepType::lin: value_ += sign * step_; break;
    case StepType::log: value_ *= std::pow(10.0, sign * step_); break;
    case StepType::db: value_ *= std::pow(10.0, sign * step_ / 20.0); break;
  }
  if (move == Direction::up && config_.max_value) value_ = std::min(value_, *config_.max_value);
  if (move == Direction::down && config_.min_value) value_ = std::max(value_, *config_.min_value);
}

double Staircase::convergent_value() const {
  if (config_.end_value == EndValue::last_presented && !intensities_.empty()) return intensities_.back();
  return value_;
}

double Staircase::mean_last_reversals(std::size_t k) const {
  if (k == 0) throw Error("mean_last_reversals: k = 0 (allowed: >= 1)");
  const auto& r = reversal_intensities_;
  if (r.empty()) throw Error("mean_last_reversals: no reversal yet");
  const std::size_t n = std::min(k, r.size());
  return std::accumulate(r.end() - static_cast<std::ptrdiff_t>(n), r.end(), 0.0) / static_cast<double>(n);
}

double Staircase::mean_reversals_excluding_first(std::size_t k) const {
  const auto& r = reversal_intensities_;
  if (r.size() <= k)
    throw Error("mean_reversals_excluding_first: " + std::to_string(r.size()) +
                " reversals, need more than k = " + std::to_string(k));
  return std::accumulate(r.begin() + static_cast<std::ptrdiff_t>(k), r.end(), 0.0) / static_cast<double>(r.size() - k);
}

std::string Staircase::state_json() const {
  nlohmann::ordered_json j;
  j["procedure"] = "staircase";
  nlohmann::ordered_json c;
  c["start_value"] = config_.start_value;
  c["step_sizes"] = config_.step_sizes;
  c["n_up"] = config_.n_up;
  c["n_down"] = config_.n_down;
  c["n_reversals"] = n_reversals_;
  c["n_trials"] = config_.n_trials;
  c["step_type"] = std::string(to_string(config_.step_type));
  c["min_value"] = config_.min_value ? nlohmann::ordered_json(*config_.min_value) : nlohmann::ordered_json();
  c["max_value"] = config_.max_value ? nlohmann::ordered_json(*config_.max_value) : nlohmann::ordered_json();
  c["apply_initial_rule"] = config_.apply_initial_rule;
  // Only when not the default, so the stored state of a version-1 protocol's
  // staircase keeps its bytes.
  if (config_.end_value != EndValue::next) c["end_value"] = std::string(to_string(config_.end_value));
  j["config"] = c;
  j["trials"] = trials();
  j["value"] = value_;
  j["step"] = step_;
  j["run"] = run_;
  j["direction"] = direction_ == Direction::up ? "up" : direction_ == Direction::down ? "down" : "none";
  j["reversal_trials"] = reversal_trials_;
  j["reversal_intensities"] = reversal_intensities_;
  j["last_was_reversal"] = last_was_reversal_;
  j["finished"] = finished();
  return j.dump();
}

Staircase Staircase::replay(const StaircaseConfig& config, const std::vector<bool>& answers) {
  const std::unique_ptr<bool[]> copy(new bool[answers.size() + 1]);
  for (std::size_t i = 0; i < answers.size(); ++i) copy[i] = answers[i];
  return replay(config, std::span<const bool>(copy.get(), answers.size()));
}

Staircase Staircase::replay(const StaircaseConfig& config, std::span<const bool> answers) {
  Staircase s(config);
  for (std::size_t i = 0; i < answers.size(); ++i) {
    if (s.finished())
      throw InvalidArgument("answers: " + std::to_string(answers.size()) + " given, but the staircase finished after " +
                            std::to_string(i) + " (allowed: at most " + std::to_string(i) + ")");
    s.answer(answers[i]);
  }
  return s;
}

}  // namespace texel::experiment
