// The threshold tasks (docs/experiments.md): oddity (three intervals, which
// one differs) and two-alternative (which reference does the test texture
// feel like), each on a staircase over one texture variable or at a fixed
// value for practice.
#include <cmath>

#include "../task.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using nlohmann::json;

constexpr std::size_t max_list = 4096;

// Texture keys a staircase (or a fixed value) may set, with their ranges.
struct Variable {
  std::string_view key;
  double lo, hi;
};
constexpr Variable variables[] = {
    {"texel_length_mm", 1e-3, 1000.0}, {"central_pitch_db", -40.0, 40.0}, {"irregularity_db", -60.0, 40.0},
    {"coarse_strength", 0.0, 1.0},     {"fine_strength", 0.0, 1.0},       {"quantization_db", 0.0, 20.0},
};

const Variable& find_variable(const JsonObject& o, const std::string& key) {
  for (const auto& v : variables)
    if (v.key == key) return v;
  std::string names;
  for (const auto& v : variables) names += (names.empty() ? "" : ", ") + std::string(v.key);
  throw FormatError(o.field("variable") + " is '" + key + "'; allowed: " + names);
}

// Version 1 kept PsychoPy's defaults (initial 1-up/1-down rule; the value
// computed after the last answer as the threshold); version 2 defaults to the
// source's reading (no initial rule; the last value presented).
StaircaseConfig parse_staircase(JsonObject o, Block& b, int version) {
  StaircaseConfig c;
  b.variable = o.string("variable");
  const Variable& var = find_variable(o, b.variable);
  c.start_value = o.number("start", var.lo, var.hi);
  const auto& steps = o.raw("step_sizes");
  if (steps.is_number()) {
    c.step_sizes = {steps.get<double>()};
  } else if (steps.is_array() && !steps.empty() && steps.size() <= max_list) {
    c.step_sizes.clear();
    for (std::size_t i = 0; i < steps.size(); ++i) {
      if (!steps[i].is_number()) throw FormatError(o.field("step_sizes") + "[" + std::to_string(i) + "] must be a number");
      c.step_sizes.push_back(steps[i].get<double>());
    }
  } else {
    throw FormatError(o.field("step_sizes") + " must be a number or a non-empty array of numbers");
  }
  c.n_up = static_cast<int>(o.integer("n_up", 1, 100));
  c.n_down = static_cast<int>(o.integer("n_down", 1, 100));
  if (o.has("n_reversals"))
    c.n_reversals = static_cast<int>(o.integer("n_reversals", 1, 10000));
  else
    o.skip("n_reversals");
  c.n_trials = static_cast<int>(o.has("n_trials") ? o.integer("n_trials", 0, 100000) : (o.skip("n_trials"), 0));
  c.step_type = parse_step_type(o.string_or("step_type", "lin"), o.field("step_type"));
  c.min_value = o.number_or("min", var.lo, var.lo, var.hi);
  c.max_value = o.number_or("max", var.hi, var.lo, var.hi);
  const bool v1 = version < 2;
  c.apply_initial_rule = o.boolean_or("apply_initial_rule", v1);
  c.end_value = o.has("end_value") ? parse_end_value(o.string("end_value"), o.field("end_value"))
                                   : (o.skip("end_value"), v1 ? EndValue::next : EndValue::last_presented);
  o.finish();
  try {
    validate(c);
  } catch (const Error& e) {
    throw FormatError(o.path() + ": " + e.what());
  }
  return c;
}

// The running block: a staircase, or a fixed number of trials at a fixed value.
class ThresholdBlock : public TaskBlock {
 public:
  ThresholdBlock(const Block& b, bool two_alternative) : two_alternative_(two_alternative) {
    if (b.staircase) staircase_.emplace(*b.staircase);
  }

  void prepare(const SessionCore& s, Question& q, TrialTruth& t) override {
    const Block& b = s.block();
    if (!staircase_) q.block_trials = b.trials;
    const double x = staircase_ ? staircase_->next() : b.fixed_value;
    t.intensity = x;
    json base = texture_of(b.texture);
    if (two_alternative_) {
      const auto which = static_cast<int>(s.trial_below(0, 2));
      base[b.variable] = x;
      base["coarse"] = {{"kind", "reference"}, {"name", b.references[static_cast<std::size_t>(which)]}};
      q.stimuli.push_back({"A", s.single(reference_texture(b.references[0], 1), b.display_mm)});
      q.stimuli.push_back({"B", s.single(reference_texture(b.references[1], 1), b.display_mm)});
      q.stimuli.push_back({"Test", s.single(texel_texture(base, s.seed_draw(1)), b.display_mm)});
      q.choices = {"A", "B"};
      q.wording.choice_question = "The test texture feels like";
      t.correct_answer = which == 0 ? "A" : "B";
      t.reference = b.references[static_cast<std::size_t>(which)];
      q.prompt = b.prompt.empty() ? "Feel A, B and the test texture. Which reference does the test texture feel like?" : b.prompt;
      return;
    }
    base[b.variable] = x;
    base.erase("seed");
    const std::uint64_t s1 = s.seed_draw(0);
    std::uint64_t s2 = s.seed_draw(1);
    if (s2 == s1) s2 ^= 1;
    const auto odd = static_cast<int>(s.trial_below(2, 3));
    const bool odd_is_first = s.trial_below(3, 2) == 0;  // which seed is the single one
    const std::uint64_t single_seed = odd_is_first ? s1 : s2, pair_seed = odd_is_first ? s2 : s1;
    for (int i = 0; i < 3; ++i)
      q.stimuli.push_back(
          {std::to_string(i + 1), s.single(texel_texture(base, i == odd ? single_seed : pair_seed), b.display_mm)});
    ask_oddity(b, odd, q, t);
  }

  std::string answer(SessionCore& s, const Question&, const TrialTruth& t, const Response& r, TrialRow& row) override {
    const Block& b = s.block();
    const bool correct = r.choice == t.correct_answer;
    row.correct = correct ? 1.0 : 0.0;
    row.variable = b.variable;
    row.intensity = t.intensity;
    row.texel_length_mm = template_number(b, "texel_length_mm");
    row.coarse_strength = template_number(b, "coarse_strength");
    row.fine_strength = template_number(b, "fine_strength");
    if (b.variable == "texel_length_mm") row.texel_length_mm = t.intensity;
    if (b.variable == "coarse_strength") row.coarse_strength = t.intensity;
    if (b.variable == "fine_strength") row.fine_strength = t.intensity;
    if (!staircase_) {
      row.next_intensity = b.fixed_value;
      row.procedure_finished = s.trial_in_block + 1 >= b.trials;
      return {};
    }
    staircase_->answer(correct);
    row.reversal = staircase_->last_was_reversal();
    row.procedure_finished = staircase_->finished();
    // next_intensity is always the value computed after this answer (on the
    // finishing row: the one that would come next); the threshold by the
    // protocol's end rule is Staircase::convergent_value(), and the analysis
    // takes the end value it is asked for from the stored rows.
    row.next_intensity = staircase_->computed_value();
    return staircase_->state_json();
  }

  bool finished(const SessionCore& s) const override {
    return staircase_ ? staircase_->finished() : s.trial_in_block >= s.block().trials;
  }

 private:
  bool two_alternative_;
  std::optional<Staircase> staircase_;
};

class ThresholdTask : public TaskType {
 public:
  explicit ThresholdTask(bool two_alternative) : two_alternative_(two_alternative) {}

  std::string_view name() const override { return two_alternative_ ? "two-alternative" : "oddity"; }

  std::vector<std::string_view> keys() const override {
    std::vector<std::string_view> k{"texture",   "display_mm", "time_limit_s", "show_maps",
                                    "staircase", "trials",     "variable",     "value"};
    if (two_alternative_) k.push_back("references");
    return k;
  }

  void parse(BlockInput& in, Block& b) const override {
    JsonObject& o = in.o;
    b.texture = in.texture("texture");
    b.display_mm = o.number_or("display_mm", 0.0, 0.0, 1e6);
    b.time_limit_s = o.number_or("time_limit_s", two_alternative_ ? 0.0 : 30.0, 0.0, 3600.0);
    b.show_maps = o.boolean_or("show_maps", false);
    if (o.has("staircase")) {
      b.staircase = parse_staircase(JsonObject(o.raw("staircase"), o.field("staircase")), b, in.version);
      for (std::string_view k : {"trials", "variable", "value"}) {
        if (o.has(k)) throw FormatError(o.field(k) + " does not apply to task '" + std::string(name()) + "'");
        o.skip(k);
      }
    } else {
      o.skip("staircase");
      b.trials = static_cast<int>(o.integer("trials", 1, 10000));
      b.variable = o.string("variable");
      const Variable& var = find_variable(o, b.variable);
      b.fixed_value = o.number("value", var.lo, var.hi);
    }
    if (two_alternative_) {
      b.references = string_list(o, "references", 2);
      if (b.references.size() != 2) throw FormatError(o.field("references") + " must name exactly two references (A, B)");
      for (std::size_t i = 0; i < 2; ++i) check_reference(b.references[i], o.field("references") + "[" + std::to_string(i) + "]");
    }
  }

  std::optional<int> planned_trials(const Block& b) const override {
    if (b.staircase) return std::nullopt;
    return b.trials;
  }

  std::unique_ptr<TaskBlock> start(const SessionCore& s) const override {
    return std::make_unique<ThresholdBlock>(s.block(), two_alternative_);
  }

  void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const override {
    const Question& q = session.question();
    const TrialTruth& t = session.truth();
    const bool ok =
        who.psychometric_correct(t, two_alternative_ ? guess_2afc : guess_oddity3, static_cast<std::uint64_t>(q.trial));
    r.choice = ok ? t.correct_answer : who.wrong_choice(q, t.correct_answer);
  }

  std::vector<std::string_view> columns() const override {
    return {"response", "correct_answer",     "correct",         "variable",        "intensity",    "next_intensity",
            "reversal", "procedure_finished", "texel_length_mm", "coarse_strength", "fine_strength"};
  }

 private:
  bool two_alternative_;
};

}  // namespace

std::unique_ptr<TaskType> make_oddity_task() { return std::make_unique<ThresholdTask>(false); }
std::unique_ptr<TaskType> make_two_alternative_task() { return std::make_unique<ThresholdTask>(true); }

}  // namespace texel::experiment
