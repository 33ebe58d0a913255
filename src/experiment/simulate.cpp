// Simulated participants (simulate.hpp).
#include "texel/experiment/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/error.hpp"
#include "texel/experiment/observer.hpp"
#include "texel/finger.hpp"
#include "texel/random.hpp"
#include "texel/reference.hpp"

#include "json_views.hpp"
#include "task.hpp"

namespace texel::experiment {
namespace {

using nlohmann::json;

constexpr std::uint64_t stream_behaviour = static_cast<std::uint64_t>(Stream::user) + 50;

double number_with_unit(const std::string& key, const std::string& text, std::initializer_list<const char*> units) {
  std::string v = text;
  double scale = 1.0;
  for (const char* u : units) {
    const std::string unit = u;
    if (v.size() > unit.size() && v.compare(v.size() - unit.size(), unit.size(), unit) == 0) {
      v.resize(v.size() - unit.size());
      if (unit == "%") scale = 0.01;
      break;
    }
  }
  std::size_t used = 0;
  double d = 0.0;
  try {
    d = std::stod(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v.size() || v.empty() || !std::isfinite(d)) {
    std::string allowed;
    for (const char* u : units) allowed += (allowed.empty() ? "" : ", ") + std::string(u);
    throw InvalidArgument("--simulate " + key + "=" + text + ": not a number" +
                          (allowed.empty() ? std::string() : " (units allowed: " + allowed + ")"));
  }
  return d * scale;
}

double get(const json& o, const char* key, double fallback) {
  return o.is_object() && o.contains(key) && o[key].is_number() ? o[key].get<double>() : fallback;
}

}  // namespace

struct SimulatedParticipant::Model {
  json observer;
  double threshold_scale = 1.0;  // this participant's deviations from the group
  double bias_pitch_db = 0.0, bias_irregularity_db = 0.0;
  double memory_shift = 0.0;
};

void validate_observer(std::string_view observer_json) { validate_observer_object(parse_json_text(observer_json, "observer")); }

void validate_observer_object(const json& o) {
  using texel::detail::JsonObject;
  const double inf = std::numeric_limits<double>::infinity();
  JsonObject top(o, "observer");
  if (top.has("seed"))
    (void)top.uint64("seed");
  else
    top.skip("seed");
  (void)top.number_or("participant_sd", 0.0, 0.0, 3.0);
  auto section = [&](const char* key, auto&& check) {
    if (!top.has(key)) {
      top.skip(key);
      return;
    }
    JsonObject s(top.raw(key), top.field(key));
    check(s);
    s.finish();
  };
  section("psychometric", [&](JsonObject& s) {
    (void)parse_psychometric_shape(s.string_or("shape", "weibull"), s.field("shape"));
    if (s.has("threshold") && !(s.number("threshold", -inf, inf) > 0)) throw FormatError(s.field("threshold") + " must be > 0");
    s.skip("threshold");
    if (s.has("slope") && !(s.number("slope", -inf, inf) > 0)) throw FormatError(s.field("slope") + " must be > 0");
    s.skip("slope");
    (void)s.number_or("guess", 0.0, 0.0, 0.999);
    (void)s.number_or("lapse", 0.0, 0.0, 0.5);
  });
  section("matcher", [&](JsonObject& s) {
    if (s.has("target")) {
      const auto& t = s.raw("target");
      const bool pair = t.is_array() && t.size() == 2 && t[0].is_number() && t[1].is_number();
      if (!pair && !t.is_string())
        throw FormatError(s.field("target") + " must be \"reference\", a reference name, or [pitch_db, irregularity_db]");
      if (t.is_string() && t.get<std::string>() != "reference") {
        try {
          (void)reference_info(t.get<std::string>());
        } catch (const Error&) {
          throw FormatError(s.field("target") + " is '" + t.get<std::string>() + "'; allowed: \"reference\" or a reference name");
        }
      }
    } else {
      s.skip("target");
    }
    (void)s.number_or("noise_db", 0.0, 0.0, 100.0);
    (void)s.number_or("unsure_db", 0.0, 0.0, 100.0);
    (void)s.number_or("irregularity_weight", 1.0, 1e-6, 1e6);
  });
  section("rater", [&](JsonObject& s) {
    (void)s.number_or("distance_scale_db", 10.0, 1e-6, 1e6);
    (void)s.number_or("noise", 0.5, 0.0, 100.0);
  });
  section("memory", [&](JsonObject& s) {
    if (s.has("p_correct")) {
      const auto& p = s.raw("p_correct");
      bool ok = p.is_number() && p.get<double>() >= 0 && p.get<double>() <= 1;
      if (p.is_object()) {
        ok = true;
        for (const auto& v : p) ok = ok && v.is_number() && v.get<double>() >= 0 && v.get<double>() <= 1;
      }
      if (!ok) throw FormatError(s.field("p_correct") + " must be a probability 0 … 1, or an object of them by condition");
    } else {
      s.skip("p_correct");
    }
    (void)s.number_or("p_digit", 0.8, 0.0, 1.0);
    (void)s.number_or("p_hit", 0.85, 0.0, 1.0);
    (void)s.number_or("p_false_alarm", 0.05, 0.0, 1.0);
  });
  section("playback", [&](JsonObject& s) {
    (void)s.number_or("integration", 1.0, 0.0, 1.0);
    (void)s.number_or("threshold_db", 4.0, 0.01, 100.0);
    (void)s.number_or("slope", 2.0, 0.1, 20.0);
  });
  section("explorer", [&](JsonObject& s) {
    (void)s.number_or("speed_mm_s", 100.0, 1.0, 10000.0);
    (void)s.number_or("speed_sd_mm_s", 15.0, 0.0, 10000.0);
    (void)s.number_or("rt_s", 4.0, 0.01, 3600.0);
  });
  top.finish();
}

std::string simulation_observer(std::string_view protocol_observer_json, const std::string& spec) {
  const json given = protocol_observer_json.empty() ? json::object() : parse_json_text(protocol_observer_json, "observer");
  json o = given.is_object() ? given : json::object();
  validate_observer_object(o);
  for (const char* section : {"psychometric", "matcher", "rater", "memory", "explorer"})
    if (!o.contains(section)) o[section] = json::object();
  if (spec.empty() || spec == "default") return o.dump();
  std::size_t pos = 0;
  while (pos <= spec.size()) {
    const std::size_t comma = spec.find(',', pos);
    const std::string item = spec.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    pos = comma == std::string::npos ? spec.size() + 1 : comma + 1;
    if (item.empty() || item == "default") continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InvalidArgument("--simulate: '" + item + "' is not key=value (e.g. threshold=6mm, target=4sin, noise=1dB, seed=3)");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "threshold") {
      o["psychometric"]["threshold"] = number_with_unit(key, value, {"mm", "dB", "%"});
    } else if (key == "slope") {
      o["psychometric"]["slope"] = number_with_unit(key, value, {});
    } else if (key == "guess") {
      o["psychometric"]["guess"] = number_with_unit(key, value, {"%"});
    } else if (key == "lapse") {
      o["psychometric"]["lapse"] = number_with_unit(key, value, {"%"});
    } else if (key == "shape") {
      (void)parse_psychometric_shape(value, "--simulate shape");
      o["psychometric"]["shape"] = value;
    } else if (key == "target") {
      const auto slash = value.find('/');
      if (slash != std::string::npos) {
        o["matcher"]["target"] = {number_with_unit(key, value.substr(0, slash), {"dB"}),
                                  number_with_unit(key, value.substr(slash + 1), {"dB"})};
      } else {
        try {
          (void)reference_info(value);
        } catch (const Error&) {
          throw InvalidArgument("--simulate target=" + value +
                                ": allowed: a reference name (texel reference --list) or PITCHdB/IRREGULARITYdB, e.g. 8dB/-3dB");
        }
        o["matcher"]["target"] = value;
      }
    } else if (key == "noise") {
      o["matcher"]["noise_db"] = number_with_unit(key, value, {"dB"});
    } else if (key == "unsure") {
      o["matcher"]["unsure_db"] = number_with_unit(key, value, {"dB"});
    } else if (key == "p") {
      o["memory"]["p_correct"] = number_with_unit(key, value, {"%"});
    } else if (key == "digit") {
      o["memory"]["p_digit"] = number_with_unit(key, value, {"%"});
    } else if (key == "hit") {
      o["memory"]["p_hit"] = number_with_unit(key, value, {"%"});
    } else if (key == "false-alarm") {
      o["memory"]["p_false_alarm"] = number_with_unit(key, value, {"%"});
    } else if (key == "integration") {
      o["playback"]["integration"] = number_with_unit(key, value, {});
    } else if (key == "rating-noise") {
      o["rater"]["noise"] = number_with_unit(key, value, {});
    } else if (key == "speed") {
      o["explorer"]["speed_mm_s"] = number_with_unit(key, value, {"mm/s"});
    } else if (key == "spread") {
      o["participant_sd"] = number_with_unit(key, value, {});
    } else if (key == "seed") {
      const double s = number_with_unit(key, value, {});
      if (s < 0 || s != std::floor(s) || s > 9007199254740992.0)
        throw InvalidArgument("--simulate seed=" + value + ": allowed: a whole number 0 … 2^53");
      o["seed"] = static_cast<std::uint64_t>(s);
    } else {
      throw InvalidArgument(
          "--simulate: unknown key '" + key +
          "'; allowed: threshold, slope, shape, guess, lapse, target, noise, unsure, p, digit, hit, false-alarm, "
          "integration, rating-noise, "
          "speed, spread, seed, default");
    }
  }
  try {
    validate_observer_object(o);
  } catch (const FormatError& e) {
    throw InvalidArgument(std::string("--simulate: ") + e.what());
  }
  return o.dump();
}

SimulatedParticipant::SimulatedParticipant(std::string observer, const Session& session) : observer_(std::move(observer)) {
  auto model = std::make_shared<Model>();
  model->observer = parse_json_text(observer_, "observer");
  const json& observer_json = model->observer;
  if (!observer_json.is_object()) throw InvalidArgument("observer must be a JSON object");
  seed_ = observer_json.contains("seed") && observer_json["seed"].is_number_unsigned()
              ? observer_json["seed"].get<std::uint64_t>()
              : mix64(session.context().seed ^ 0x51u);
  rng_ = CounterRng(seed_, stream_behaviour);
  // Validate the parts a protocol will need, up front, with the spec's names.
  const json& p = observer_json.contains("psychometric") ? observer_json["psychometric"] : json::object();
  const double lapse = get(p, "lapse", 0.02);
  const double guess = get(p, "guess", 0.0);
  if (!(lapse >= 0 && lapse < 0.5))
    throw InvalidArgument("observer lapse is " + texel::detail::num(lapse) + "; allowed: 0 … 0.5");
  if (!(guess >= 0 && guess < 1)) throw InvalidArgument("observer guess is " + texel::detail::num(guess) + "; allowed: 0 … 1");
  if (p.contains("threshold") && !(get(p, "threshold", 1) > 0)) throw InvalidArgument("observer threshold must be > 0");
  // Between-participant variability (participant_sd, 0 = identical
  // observers): this participant's threshold is scaled by exp(sd·n₀), the
  // matcher's target shifted by 3·sd·(n₁, n₂) dB, and memory accuracy
  // shifted by 0.3·sd·n₃, with n drawn once from the observer seed.
  const double sd = get(observer_json, "participant_sd", 0.0);
  if (!(sd >= 0 && sd <= 3)) throw InvalidArgument("observer participant_sd is " + texel::detail::num(sd) + "; allowed: 0 … 3");
  const CounterRng person(seed_, stream_behaviour + 1);
  model->threshold_scale = std::exp(sd * person.normal(0));
  model->bias_pitch_db = 3.0 * sd * person.normal(1);
  model->bias_irregularity_db = 3.0 * sd * person.normal(2);
  model->memory_shift = 0.3 * sd * person.normal(3);
  const json& m = observer_json.contains("memory") ? observer_json["memory"] : json::object();
  if (m.contains("p_correct") && m["p_correct"].is_number()) {
    const double pc = m["p_correct"].get<double>();
    if (!(pc >= 0 && pc <= 1)) throw InvalidArgument("observer p is " + texel::detail::num(pc) + "; allowed: 0 … 1");
  }
  model_ = std::move(model);
}

// The observer's section `key` (an empty object when missing).
static const json& section_of(const json& observer, const char* key) {
  static const json empty = json::object();
  return observer.contains(key) ? observer[key] : empty;
}

std::string SimulatedParticipant::wrong_choice(const Question& q, const std::string& correct) const {
  std::vector<std::string> others;
  for (const auto& c : q.choices)
    if (c != correct && c != "unsure") others.push_back(c);
  return others[static_cast<std::size_t>(rng_.below(static_cast<std::uint64_t>(q.trial) * 8 + 1, others.size()))];
}

bool SimulatedParticipant::psychometric_correct(const TrialTruth& t, double default_guess, std::uint64_t trial) const {
  const json& pj = section_of(model_->observer, "psychometric");
  PsychometricConfig pc;
  pc.shape = parse_psychometric_shape(pj.value("shape", std::string("weibull")), "observer shape");
  pc.threshold = model_->threshold_scale *
                 get(pj, "threshold", std::isfinite(t.intensity) ? std::max(std::abs(t.intensity) * 0.3, 1e-6) : 1.0);
  pc.slope = get(pj, "slope", 3.5);
  pc.guess = get(pj, "guess", default_guess);
  pc.lapse = get(pj, "lapse", 0.02);
  pc.seed = seed_;
  return PsychometricObserver(pc).respond(t.intensity, trial);
}

Matcher SimulatedParticipant::matcher(const MatchResult& fallback, const Session& session) const {
  const json& mj = section_of(model_->observer, "matcher");
  MatcherConfig mc;
  mc.noise_db = get(mj, "noise_db", 1.5);
  mc.unsure_band_db = get(mj, "unsure_db", 0.5);
  mc.irregularity_weight = get(mj, "irregularity_weight", 1.0);
  mc.seed = seed_;
  MatchResult target = fallback;
  if (mj.contains("target") && mj["target"].is_array() && mj["target"].size() == 2) {
    target = {mj["target"][0].get<double>(), mj["target"][1].get<double>()};
  } else if (mj.contains("target") && mj["target"].is_string() && mj["target"].get<std::string>() != "reference") {
    target = session.reference_position(mj["target"].get<std::string>());
  }
  mc.target = MatchPoint{target.pitch_db + model_->bias_pitch_db, target.irregularity_db + model_->bias_irregularity_db};
  return Matcher(mc);
}

double SimulatedParticipant::playback_shift_db(std::size_t channels) const {
  const double w = get(section_of(model_->observer, "playback"), "integration", 1.0);
  const double k = static_cast<double>(std::max<std::size_t>(channels, 1));
  return 5.0 * std::log10((1.0 - w) + w / k);
}

bool SimulatedParticipant::playback_correct(double felt_difference_db, std::uint64_t trial) const {
  const json& pb = section_of(model_->observer, "playback");
  PsychometricConfig pc;
  pc.shape = PsychometricShape::weibull;
  pc.threshold = model_->threshold_scale * get(pb, "threshold_db", 4.0);
  pc.slope = get(pb, "slope", 2.0);
  pc.guess = guess_oddity3;
  pc.lapse = get(section_of(model_->observer, "psychometric"), "lapse", 0.02);
  pc.seed = seed_;
  return PsychometricObserver(pc).respond(felt_difference_db, trial);
}

Rater SimulatedParticipant::rater(double scale_min, double scale_max) const {
  const json& rj = section_of(model_->observer, "rater");
  RaterConfig rc;
  rc.scale_min = scale_min;
  rc.scale_max = scale_max;
  rc.distance_scale_db = get(rj, "distance_scale_db", 10.0);
  rc.noise = get(rj, "noise", 0.5);
  rc.seed = seed_;
  return Rater(rc);
}

double SimulatedParticipant::memory_p_correct(const std::string& condition) const {
  const json& mj = section_of(model_->observer, "memory");
  double p = 0.85;
  if (mj.contains("p_correct") && mj["p_correct"].is_number()) p = mj["p_correct"].get<double>();
  if (mj.contains("p_correct") && mj["p_correct"].is_object()) p = get(mj["p_correct"], condition.c_str(), p);
  return std::clamp(p + model_->memory_shift, 0.0, 1.0);
}

double SimulatedParticipant::memory_p_digit() const { return get(section_of(model_->observer, "memory"), "p_digit", 0.8); }
double SimulatedParticipant::memory_p_hit() const { return get(section_of(model_->observer, "memory"), "p_hit", 0.85); }
double SimulatedParticipant::memory_p_false_alarm() const {
  return get(section_of(model_->observer, "memory"), "p_false_alarm", 0.05);
}

Response SimulatedParticipant::respond(const Session& session) const {
  const Question& q = session.question();
  const auto trial = static_cast<std::uint64_t>(q.trial);
  const CounterRng& rng = rng_;
  Response r;
  task_type(q.task).simulate(*this, session, r);

  // Exploration: a reaction time (lognormal around rt_s), the stimuli visited
  // in turn, and a back-and-forth swipe at a drawn speed over that time.
  const json& ej = section_of(model_->observer, "explorer");
  const double rt_s = get(ej, "rt_s", 4.0) * std::exp(0.3 * rng.normal(trial * 8 + 5));
  r.rt_ms = std::round(rt_s * 1000.0);
  r.events.push_back({0.0, "show", "trial " + std::to_string(q.trial), ""});
  for (std::size_t i = 0; i < q.stimuli.size(); ++i)
    r.events.push_back({rt_s * static_cast<double>(i) / static_cast<double>(q.stimuli.size()), "select", q.stimuli[i].label, ""});
  r.events.push_back({rt_s, "answer", r.choice, ""});
  SwipeConfig sc;
  sc.pattern = SwipePattern::back_and_forth;
  sc.speed_mm_s = std::max(10.0, get(ej, "speed_mm_s", 100.0) + get(ej, "speed_sd_mm_s", 15.0) * rng.normal(trial * 8 + 6));
  sc.surface_mm = 100.0;
  sc.extent_mm = 60.0 + 20.0 * rng.uniform(trial * 8 + 7);
  sc.duration_s = std::min(rt_s, 30.0);
  sc.rate_hz = 250.0;
  const SwipeMeasures sm = swipe_measures(simulate_swipe(sc));
  r.swipe_mean_speed_mm_s = sm.mean_speed_mm_s;
  r.swipe_sd_speed_mm_s = sm.sd_speed_mm_s;
  r.directional_proportion = sm.directional_proportion;
  return r;
}

}  // namespace texel::experiment
