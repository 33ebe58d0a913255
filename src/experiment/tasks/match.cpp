// The slider match (docs/experiments.md, studies 2 and 3): the reference on
// the left, a rendering on the right whose Central Pitch and Irregularity
// the participant sets with two sliders, one trial per reference.
#include <algorithm>
#include <cmath>

#include "../task.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"

namespace texel::experiment {
namespace {

using nlohmann::json;

class MatchBlock : public TaskBlock {
 public:
  explicit MatchBlock(const SessionCore& s) {
    const Block& b = s.block();
    for (int i = 0; i < static_cast<int>(b.references.size()); ++i) plan_.push_back(i);
    if (b.shuffle) s.shuffle(plan_);
  }

  void prepare(const SessionCore& s, Question& q, TrialTruth& t) override {
    const Block& b = s.block();
    q.block_trials = static_cast<int>(plan_.size());
    const std::string& ref = b.references[static_cast<std::size_t>(plan_[static_cast<std::size_t>(s.trial_in_block)])];
    t.reference = ref;
    seed_ = s.seed_draw(0);
    if (b.sliders == SliderMapping::lognormal) {
      q.sliders = {{"pitch", "Pitch", 0, 100, 50}, {"irregularity", "Irregularity", 0, 100, 50}};
    } else {
      q.sliders = {{"pitch", "Central Pitch (dB)", -20, 19.7, -0.15}, {"irregularity", "Irregularity (dB)", -30, 5, -12.5}};
    }
    const MatchResult start = slider_to_parameters(b.sliders, q.sliders[0].start, q.sliders[1].start);
    q.stimuli.push_back(
        {"Reference | Rendering", s.halves(reference_texture(ref, 1), texel_texture(texture_of(b.texture), seed_, start))});
    q.confidence = b.confidence;
    q.prompt = b.prompt.empty() ? "Move the sliders until the right half feels like the left half." : b.prompt;
  }

  std::string answer(SessionCore& s, const Question& q, const TrialTruth& t, const Response& r, TrialRow& row) override {
    const Block& b = s.block();
    require(r.slider_p.has_value() && r.slider_i.has_value(), "a match needs slider_p and slider_i");
    const auto& sp = q.sliders[0];
    const auto& si = q.sliders[1];
    require(*r.slider_p >= sp.min && *r.slider_p <= sp.max,
            "slider_p is " + detail::num(*r.slider_p) + "; allowed: " + detail::num(sp.min) + " … " + detail::num(sp.max));
    require(*r.slider_i >= si.min && *r.slider_i <= si.max,
            "slider_i is " + detail::num(*r.slider_i) + "; allowed: " + detail::num(si.min) + " … " + detail::num(si.max));
    if (q.confidence) {
      require(r.confidence && *r.confidence >= 1 && *r.confidence <= 5 && *r.confidence == std::floor(*r.confidence),
              "confidence is " + (r.confidence ? detail::num(*r.confidence) : std::string("missing")) + "; allowed: 1 … 5");
      row.confidence = *r.confidence;
    }
    const MatchResult m = slider_to_parameters(b.sliders, *r.slider_p, *r.slider_i);
    row.slider_p = *r.slider_p;
    row.slider_i = *r.slider_i;
    row.pitch_db = m.pitch_db;
    row.irregularity_db = m.irregularity_db;
    row.texel_length_mm = template_number(b, "texel_length_mm");
    const MatchResult ref = s.position(t.reference);
    row.reference_pitch_db = ref.pitch_db;
    row.reference_irregularity_db = ref.irregularity_db;
    row.response = detail::num(*r.slider_p) + "/" + detail::num(*r.slider_i);
    s.matches[b.name][t.reference] = m;
    return json{{"matched", {{"pitch_db", m.pitch_db}, {"irregularity_db", m.irregularity_db}}}}.dump();
  }

  bool finished(const SessionCore& s) const override { return s.trial_in_block >= static_cast<int>(plan_.size()); }

  std::optional<std::string> preview(const SessionCore& s, const Question& q, const TrialTruth& t, double slider_p,
                                     double slider_i) const override {
    const Block& b = s.block();
    const double p = std::clamp(slider_p, q.sliders[0].min, q.sliders[0].max);
    const double i = std::clamp(slider_i, q.sliders[1].min, q.sliders[1].max);
    return s.halves(reference_texture(t.reference, 1),
                    texel_texture(texture_of(b.texture), seed_, slider_to_parameters(b.sliders, p, i)));
  }

 private:
  std::vector<int> plan_;   // reference index per trial
  std::uint64_t seed_ = 0;  // the rendering's texture seed this trial
};

class MatchTask : public TaskType {
 public:
  std::string_view name() const override { return "match"; }
  std::vector<std::string_view> keys() const override {
    return {"texture", "references", "sliders", "confidence", "time_limit_s"};
  }

  void parse(BlockInput& in, Block& b) const override {
    detail::JsonObject& o = in.o;
    b.texture = in.texture("texture");
    b.references = string_list(o, "references", 1);
    for (std::size_t i = 0; i < b.references.size(); ++i)
      check_reference(b.references[i], o.field("references") + "[" + std::to_string(i) + "]");
    const std::string s = o.string_or("sliders", "device-db");
    if (s == "lognormal")
      b.sliders = SliderMapping::lognormal;
    else if (s == "device-db")
      b.sliders = SliderMapping::device_db;
    else
      throw FormatError(o.field("sliders") + " is '" + s + "'; allowed: lognormal, device-db");
    b.confidence = o.boolean_or("confidence", false);
    b.time_limit_s = o.number_or("time_limit_s", 0.0, 0.0, 3600.0);
  }

  std::optional<int> planned_trials(const Block& b) const override { return static_cast<int>(b.references.size()); }
  std::unique_ptr<TaskBlock> start(const SessionCore& s) const override { return std::make_unique<MatchBlock>(s); }

  void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const override {
    const Question& q = session.question();
    const TrialTruth& t = session.truth();
    const auto trial = static_cast<std::uint64_t>(q.trial);
    const Matcher m = who.matcher(session.reference_position(t.reference), session);
    const MatchPoint p = m.adjust(trial);
    const auto& sp = q.sliders[0];
    const auto& si = q.sliders[1];
    double xp = p.pitch_db, xi = p.irregularity_db;
    if (session.protocol().blocks[static_cast<std::size_t>(q.block_index)].sliders == SliderMapping::lognormal) {
      // Study 2's sliders: invert m = 0.75·1.04^P and s = 3·I/10.
      xp = std::log(std::pow(10.0, p.pitch_db / 10.0) / 0.75) / std::log(1.04);
      xi = std::pow(10.0, p.irregularity_db / 10.0) * 10.0 / 3.0;
    }
    r.slider_p = std::clamp(xp, sp.min, sp.max);
    r.slider_i = std::clamp(xi, si.min, si.max);
    if (q.confidence) r.confidence = m.confidence(trial);
  }

  std::vector<std::string_view> columns() const override {
    return {"response",        "confidence",         "slider_p",
            "slider_i",        "pitch_db",           "irregularity_db",
            "texel_length_mm", "reference_pitch_db", "reference_irregularity_db"};
  }

  bool makes_matches() const override { return true; }
  bool holds_match(const TrialRow&) const override { return true; }
};

}  // namespace

std::unique_ptr<TaskType> make_match_task() { return std::make_unique<MatchTask>(); }

}  // namespace texel::experiment
