// The playback oddity (docs/experiments.md "Distributed irregularity"): is a
// texture's Irregularity felt the same when its texels play side by side on
// an actuator array (simultaneous: one chain per actuator, K frequencies at
// once at K places) as when they play in sequence (one chain on every
// actuator: one frequency at a time under the whole pad)?
//
// Method of constant stimuli on the source's three-interval oddity: the
// simultaneous texture at Irregularity L, the sequential one at L + Δ for
// every Δ of `shifts_db`; the odd interval is the simultaneous one in half
// the repeats and the sequential one in the other half (so a preference for
// either playback cannot pass for discrimination). Where Δ makes the two
// feel alike, the odd one is found at chance: proportion correct dips to
// 1/3 at the point of subjective equality (PSE). Control trials at every
// level play all three intervals sequentially at L, the odd one differing
// by its seed alone: the baseline that seed differences give.
#include <cmath>

#include "../task.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using nlohmann::json;

constexpr std::string_view kind_name = "playback-oddity";
constexpr double irregularity_lo = -60.0, irregularity_hi = 40.0;  // a texel texture's range (docs/format.md)

// The trial's arrangement: which playback the odd interval has, or the control.
enum class Arrangement { odd_simultaneous, odd_sequential, control };

std::string_view to_string(Arrangement a) {
  switch (a) {
    case Arrangement::odd_simultaneous: return "odd-simultaneous";
    case Arrangement::odd_sequential: return "odd-sequential";
    case Arrangement::control: return "control";
  }
  return "control";
}

struct PlaybackOdditySettings : TaskSettings {
  std::vector<double> levels_db;  // the simultaneous texture's Irregularity
  std::vector<double> shifts_db;  // the sequential texture's Irregularity minus it
  int repeats = 2;                // per (level, shift): half odd-simultaneous, half odd-sequential
  int control_repeats = 2;        // per level
  std::size_t channels = 1;       // the device's actuators
};

const PlaybackOdditySettings& settings_of(const Block& b) { return static_cast<const PlaybackOdditySettings&>(*b.settings); }

struct Cell {
  double level = 0, shift = 0;
  Arrangement arrangement = Arrangement::control;
};

std::vector<double> number_list(JsonObject& o, std::string_view key, double lo, double hi, std::size_t most) {
  const auto& v = o.raw(key);
  if (!v.is_array() || v.empty() || v.size() > most)
    throw FormatError(o.field(key) + " must be an array of 1 … " + std::to_string(most) + " numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string at = o.field(key) + "[" + std::to_string(i) + "]";
    if (!v[i].is_number()) throw FormatError(at + " must be a number");
    const double d = v[i].get<double>();
    if (!(d >= lo && d <= hi))
      throw FormatError(at + " is " + detail::num(d) + "; allowed: " + detail::num(lo) + " … " + detail::num(hi));
    for (double seen : out)
      if (seen == d) throw FormatError(at + " is " + detail::num(d) + ", listed twice");
    out.push_back(d);
  }
  return out;
}

class PlaybackOddityBlock : public TaskBlock {
 public:
  explicit PlaybackOddityBlock(const SessionCore& s) {
    const PlaybackOdditySettings& st = settings_of(s.block());
    for (double level : st.levels_db) {
      for (double shift : st.shifts_db)
        for (int k = 0; k < st.repeats; ++k)
          plan_.push_back({level, shift, k % 2 == 0 ? Arrangement::odd_simultaneous : Arrangement::odd_sequential});
      for (int k = 0; k < st.control_repeats; ++k) plan_.push_back({level, 0.0, Arrangement::control});
    }
    order_.resize(plan_.size());
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<int>(i);
    if (s.block().shuffle) s.shuffle(order_);
  }

  void prepare(const SessionCore& s, Question& q, TrialTruth& t) override {
    const Block& b = s.block();
    const Cell& c = cell(s);
    q.block_trials = static_cast<int>(plan_.size());
    json base = texture_of(b.texture);
    base.erase("seed");
    const std::uint64_t s1 = s.seed_draw(0);
    std::uint64_t s2 = s.seed_draw(1);
    if (s2 == s1) s2 ^= 1;
    const auto odd = static_cast<int>(s.trial_below(2, 3));
    json simultaneous = base, sequential = base;
    simultaneous["irregularity_db"] = c.level;
    sequential["irregularity_db"] = c.level + c.shift;
    std::string pair_doc, odd_doc;
    switch (c.arrangement) {
      case Arrangement::odd_simultaneous:
        pair_doc = s.single_played(texel_texture(sequential, s1), "sequential", b.display_mm);
        odd_doc = s.single_played(texel_texture(simultaneous, s2), "simultaneous", b.display_mm);
        break;
      case Arrangement::odd_sequential:
        pair_doc = s.single_played(texel_texture(simultaneous, s1), "simultaneous", b.display_mm);
        odd_doc = s.single_played(texel_texture(sequential, s2), "sequential", b.display_mm);
        break;
      case Arrangement::control:
        pair_doc = s.single_played(texel_texture(sequential, s1), "sequential", b.display_mm);
        odd_doc = s.single_played(texel_texture(sequential, s2), "sequential", b.display_mm);
        break;
    }
    for (int i = 0; i < 3; ++i) q.stimuli.push_back({std::to_string(i + 1), i == odd ? odd_doc : pair_doc});
    ask_oddity(b, odd, q, t);
    t.intensity = c.arrangement == Arrangement::control ? missing : c.shift;
    t.condition = std::string(to_string(c.arrangement));
    t.rendering = MatchResult{template_number(b, "central_pitch_db"), c.level};
  }

  std::string answer(SessionCore& s, const Question&, const TrialTruth& t, const Response& r, TrialRow& row) override {
    const Block& b = s.block();
    const Cell& c = cell(s);
    row.correct = r.choice == t.correct_answer ? 1.0 : 0.0;
    row.condition = t.condition;
    row.variable = "irregularity_shift_db";
    row.intensity = t.intensity;
    row.reference_irregularity_db = c.level;
    row.irregularity_db = c.level + c.shift;
    row.pitch_db = template_number(b, "central_pitch_db");
    row.texel_length_mm = template_number(b, "texel_length_mm");
    row.procedure_finished = s.trial_in_block + 1 >= static_cast<int>(plan_.size());
    return {};
  }

  bool finished(const SessionCore& s) const override { return s.trial_in_block >= static_cast<int>(plan_.size()); }

 private:
  std::vector<Cell> plan_;  // every (level, shift, arrangement) trial, in design order
  std::vector<int> order_;  // the order they run in
  const Cell& cell(const SessionCore& s) const {
    return plan_[static_cast<std::size_t>(order_[static_cast<std::size_t>(s.trial_in_block)])];
  }
};

class PlaybackOddityTask : public TaskType {
 public:
  std::string_view name() const override { return kind_name; }

  std::vector<std::string_view> keys() const override {
    return {"texture", "irregularity_levels_db", "shifts_db", "repeats", "control_repeats", "display_mm", "time_limit_s"};
  }

  void parse(BlockInput& in, Block& b) const override {
    JsonObject& o = in.o;
    const DeviceProfile device = load_device(in.device);
    if (device.channels() < 2)
      throw FormatError("device is '" + in.device + "', which has " + std::to_string(device.channels()) + " actuator; task '" +
                        std::string(kind_name) +
                        "' plays texels side by side and needs a device with 2 or more actuators (e.g. pad-4)");
    if (device.bitmap)
      throw FormatError("device is '" + in.device + "', a 2-D display; task '" + std::string(kind_name) + "' is 1-D");
    b.texture = in.texture("texture");
    const json tex = texture_of(b.texture);
    if (tex.value("kind", std::string("texel")) != "texel" || tex.contains("coarse") || tex.contains("regions"))
      throw FormatError(o.field("texture") + " must be a texel texture without a coarse profile (task '" +
                        std::string(kind_name) + "')");
    b.display_mm = o.number_or("display_mm", 0.0, 0.0, device.length().value());
    b.time_limit_s = o.number_or("time_limit_s", 30.0, 0.0, 3600.0);
    auto st = std::make_shared<PlaybackOdditySettings>();
    st->channels = device.channels();
    st->levels_db = number_list(o, "irregularity_levels_db", irregularity_lo, irregularity_hi, 16);
    st->shifts_db = number_list(o, "shifts_db", -40.0, 40.0, 32);
    for (double level : st->levels_db)
      for (double shift : st->shifts_db)
        if (!(level + shift >= irregularity_lo && level + shift <= irregularity_hi))
          throw FormatError(o.field("shifts_db") + ": level " + detail::num(level) + " dB + shift " + detail::num(shift) +
                            " dB is " + detail::num(level + shift) + " dB, outside Irregularity's " +
                            detail::num(irregularity_lo) + " … " + detail::num(irregularity_hi) + " dB");
    st->repeats = o.has("repeats") ? static_cast<int>(o.integer("repeats", 1, 1000)) : (o.skip("repeats"), 2);
    st->control_repeats =
        o.has("control_repeats") ? static_cast<int>(o.integer("control_repeats", 0, 1000)) : (o.skip("control_repeats"), 2);
    b.settings = std::move(st);
  }

  std::optional<int> planned_trials(const Block& b) const override {
    const PlaybackOdditySettings& st = settings_of(b);
    return static_cast<int>(st.levels_db.size()) * (static_cast<int>(st.shifts_db.size()) * st.repeats + st.control_repeats);
  }

  std::unique_ptr<TaskBlock> start(const SessionCore& s) const override { return std::make_unique<PlaybackOddityBlock>(s); }

  // The observer's hypothesis (SimulatedParticipant::playback_shift_db):
  // the simultaneous texture is felt at its Irregularity plus a shift that
  // depends on how much touch pools the actuators' frequencies; the odd
  // interval is found with a Weibull on the felt difference, chance 1/3.
  // A control trial's intervals differ by their seeds alone: felt alike.
  void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const override {
    const Question& q = session.question();
    const TrialTruth& t = session.truth();
    const PlaybackOdditySettings& st = settings_of(session.protocol().blocks[static_cast<std::size_t>(q.block_index)]);
    const double felt = t.condition == "control" ? 0.0 : std::abs(t.intensity - who.playback_shift_db(st.channels));
    const bool ok = who.playback_correct(felt, static_cast<std::uint64_t>(q.trial));
    r.choice = ok ? t.correct_answer : who.wrong_choice(q, t.correct_answer);
  }

  std::vector<std::string_view> columns() const override {
    return {"response",          "correct_answer", "correct",         "condition",       "variable",
            "intensity",         "pitch_db",       "irregularity_db", "texel_length_mm", "reference_irregularity_db",
            "procedure_finished"};
  }
};

}  // namespace

std::unique_ptr<TaskType> make_playback_oddity_task() { return std::make_unique<PlaybackOddityTask>(); }

}  // namespace texel::experiment
