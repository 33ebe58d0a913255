// Same-different with a working-memory load (docs/experiments.md, study 7,
// and "Working-memory components"): texture 1, a distractor task, texture 2;
// "same or different?", then the distractor's own question. The distractor
// loads one component of working memory, each with a control task of the
// same display and timing but no load:
//   visuospatial  the source's 4 × 4 matrix: digits in five random cells, then
//                 "which digit was in this cell?" (control: every cell holds 1)
//   verbal        five distinct digits one at a time, then "which digit was
//                 number k?" (control: every digit is 1) — a scored recall,
//                 since no front door can check articulatory suppression
//   executive     a digit stream, responding to each digit equal to the one
//                 two before (2-back), scored by hits and false alarms
//                 (control: 0-back, respond to every 1)
// All three last matrix_s, as the source's matrix.
#include <algorithm>

#include "../task.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using nlohmann::json;

class SameDifferentBlock : public TaskBlock {
 public:
  explicit SameDifferentBlock(const SessionCore& s) {
    // Balanced: each condition trials_per_condition times, half "same"
    // (odd counts: the extra trial is "different"); trial = condition·2 + same.
    const Block& b = s.block();
    for (int c = 0; c < static_cast<int>(b.conditions.size()); ++c)
      for (int k = 0; k < b.trials_per_condition; ++k) plan_.push_back(c * 2 + (k < b.trials_per_condition / 2 ? 1 : 0));
    if (b.shuffle) s.shuffle(plan_);
  }

  void prepare(const SessionCore& s, Question& q, TrialTruth& t) override {
    const Block& b = s.block();
    q.block_trials = static_cast<int>(plan_.size());
    const int code = plan_[static_cast<std::size_t>(s.trial_in_block)];
    const MemoryCondition& cond = b.conditions[static_cast<std::size_t>(code / 2)];
    const bool same = code % 2 == 1;
    t.condition = cond.name;
    const MemoryStimulus& ms =
        *std::find_if(b.memory_stimuli.begin(), b.memory_stimuli.end(), [&](const auto& m) { return m.name == cond.stimulus; });
    const std::uint64_t seed = s.seed_draw(0);
    // balance_order: which of the pair comes first (and is repeated on a
    // "same" trial) is drawn per trial; otherwise always `texture`.
    const bool swapped = b.balance_order && s.trial_below(64, 2) == 1;
    json first = texel_texture(texture_of(swapped ? ms.different : ms.texture), seed);
    json second = texel_texture(texture_of(swapped ? ms.texture : ms.different), seed);
    if (b.base_per_texture) {
      // The source's design: one base gap set per texture for the whole
      // session, each presentation a rearrangement of it (its own shuffle
      // number, drawn per trial; the two of a "different" pair differ).
      first = rearranged(s, texture_of(swapped ? ms.different : ms.texture), 0);
      second = rearranged(s, texture_of(swapped ? ms.texture : ms.different), 1);
    }
    if (same) second = first;
    q.stimuli.push_back({"Texture 1", s.single(first)});
    q.stimuli.push_back({"Texture 2", s.single(second)});
    switch (cond.component) {
      case MemoryComponent::visuospatial: matrix(s, cond, q); break;
      case MemoryComponent::verbal: sequence(s, cond, q); break;
      case MemoryComponent::executive: nback(s, cond, q); break;
    }
    const PhaseKind distractor = q.matrix ? PhaseKind::matrix : PhaseKind::sequence;
    q.phases = {
        {PhaseKind::stimulus, 0, b.texture_s}, {distractor, std::nullopt, b.matrix_s}, {PhaseKind::stimulus, 1, b.texture_s}};
    q.choices = {"same", "different"};
    q.wording.choice_question = "The two textures were";
    t.correct_answer = same ? "same" : "different";
    q.prompt = b.prompt.empty() ? "Were the two textures the same or different?" : b.prompt;
  }

  // The source's matrix: matrix_cells random cells hold distinct random digits 1–9.
  static void matrix(const SessionCore& s, const MemoryCondition& cond, Question& q) {
    const Block& b = s.block();
    std::array<int, 16> m{};
    if (cond.distractor) {
      std::vector<int> cells(16), digits(9);
      for (int i = 0; i < 16; ++i) cells[static_cast<std::size_t>(i)] = i;
      for (int i = 0; i < 9; ++i) digits[static_cast<std::size_t>(i)] = i + 1;
      for (std::size_t i = 16; i > 1; --i) std::swap(cells[i - 1], cells[static_cast<std::size_t>(s.trial_below(16 + i, i))]);
      for (std::size_t i = 9; i > 1; --i) std::swap(digits[i - 1], digits[static_cast<std::size_t>(s.trial_below(48 + i, i))]);
      for (int k = 0; k < b.matrix_cells; ++k)
        m[static_cast<std::size_t>(cells[static_cast<std::size_t>(k)])] = digits[static_cast<std::size_t>(k)];
      const int asked = cells[static_cast<std::size_t>(s.trial_below(5, static_cast<std::uint64_t>(b.matrix_cells)))];
      if (b.recall_question) q.recall = RecallQuestion{asked, std::nullopt};
    } else {
      m.fill(1);  // control: every cell holds 1; the recall question indicates all cells
      if (b.recall_question) q.recall = RecallQuestion{std::nullopt, std::nullopt};
    }
    q.matrix = m;
  }

  // Verbal: sequence_length distinct digits 1–9 in a random order, one at a
  // time (serial order, the phonological loop's code, rather than a layout),
  // and the digit at a random position asked; control: every digit is 1.
  static void sequence(const SessionCore& s, const MemoryCondition& cond, Question& q) {
    const Block& b = s.block();
    const auto n = static_cast<std::size_t>(b.sequence_length);
    if (cond.distractor) {
      std::vector<int> digits(9);
      for (int i = 0; i < 9; ++i) digits[static_cast<std::size_t>(i)] = i + 1;
      for (std::size_t i = 9; i > 1; --i) std::swap(digits[i - 1], digits[static_cast<std::size_t>(s.trial_below(100 + i, i))]);
      q.sequence.assign(digits.begin(), digits.begin() + static_cast<std::ptrdiff_t>(n));
      if (b.recall_question) q.recall = RecallQuestion{std::nullopt, static_cast<int>(s.trial_below(99, n))};
    } else {
      q.sequence.assign(n, 1);
      if (b.recall_question) q.recall = RecallQuestion{std::nullopt, std::nullopt};
    }
    q.wording.sequence_instruction = "Remember these digits in their order.";
  }

  // Executive: a stream of nback_items digits with nback_targets targets at
  // random places from the third item on. 2-back: a target repeats the digit
  // two before it; a non-target differs from the two before it (no lures,
  // so every response is a hit or a plain false alarm). Control (0-back):
  // the targets are the digit 1, the non-targets 2 … 9 never repeating the
  // digit before — the same stream and responses, nothing to update.
  static void nback(const SessionCore& s, const MemoryCondition& cond, Question& q) {
    const Block& b = s.block();
    const auto n = static_cast<std::size_t>(b.nback_items);
    std::vector<int> places;
    for (int i = 2; i < b.nback_items; ++i) places.push_back(i);
    for (std::size_t i = places.size(); i > 1; --i)
      std::swap(places[i - 1], places[static_cast<std::size_t>(s.trial_below(120 + i, i))]);
    std::vector<bool> target(n, false);
    for (int k = 0; k < b.nback_targets; ++k) target[static_cast<std::size_t>(places[static_cast<std::size_t>(k)])] = true;
    q.sequence.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      if (target[i]) {
        q.sequence[i] = cond.distractor ? q.sequence[i - 2] : 1;
        continue;
      }
      std::vector<int> allowed;
      for (int d = cond.distractor ? 1 : 2; d <= 9; ++d)
        if ((i < 1 || d != q.sequence[i - 1]) && (!cond.distractor || i < 2 || d != q.sequence[i - 2])) allowed.push_back(d);
      q.sequence[i] = allowed[static_cast<std::size_t>(s.trial_below(160 + i, allowed.size()))];
    }
    q.nback = cond.distractor ? NBackTask{2, 0} : NBackTask{0, 1};
    q.wording.sequence_instruction =
        cond.distractor ? "Respond whenever the digit is the same as the one two before it." : "Respond whenever the digit is 1.";
  }

  /// The items of an executive sequence the participant should respond to.
  static std::vector<bool> nback_targets(const Question& q) {
    std::vector<bool> out(q.sequence.size(), false);
    for (std::size_t i = 0; i < q.sequence.size(); ++i)
      out[i] = q.nback->n == 0 ? q.sequence[i] == q.nback->target
                               : i >= static_cast<std::size_t>(q.nback->n) &&
                                     q.sequence[i] == q.sequence[i - static_cast<std::size_t>(q.nback->n)];
    return out;
  }

  std::string answer(SessionCore&, const Question& q, const TrialTruth& t, const Response& r, TrialRow& row) override {
    row.correct = r.choice == t.correct_answer ? 1.0 : 0.0;
    require(q.nback || r.presses.empty(), "presses are given but this trial has no executive distractor task");
    if (q.nback) {
      const auto n = static_cast<int>(q.sequence.size());
      for (std::size_t k = 0; k < r.presses.size(); ++k)
        require(r.presses[k] >= 0 && r.presses[k] < n && (k == 0 || r.presses[k] > r.presses[k - 1]),
                "presses[" + std::to_string(k) + "] is " + std::to_string(r.presses[k]) + "; allowed: increasing items 0 … " +
                    std::to_string(n - 1));
      const std::vector<bool> target = nback_targets(q);
      int hits = 0, targets = 0;
      for (const bool x : target) targets += x ? 1 : 0;
      for (const int p : r.presses) hits += target[static_cast<std::size_t>(p)] ? 1 : 0;
      row.nback_targets = targets;
      row.nback_hits = hits;
      row.nback_false_alarms = static_cast<double>(r.presses.size()) - hits;
    }
    if (q.recall) {
      require(r.digit.has_value() && *r.digit >= 1 && *r.digit <= 9,
              "digit is " + (r.digit ? std::to_string(*r.digit) : std::string("missing")) + "; allowed: 1 … 9");
      const int expected = recalled_digit(q);
      row.digit_cell = q.recall->cell ? *q.recall->cell : q.recall->position ? *q.recall->position : missing;
      row.digit_response = *r.digit;
      row.digit_correct = *r.digit == expected ? 1.0 : 0.0;
    }
    return "{}";
  }

  bool finished(const SessionCore& s) const override { return s.trial_in_block >= static_cast<int>(plan_.size()); }

  /// The session's base seed of a texture: one per reference name, from the
  /// session's order stream at a counter no block uses, so every trial of
  /// every block (training and test) rearranges the same gap set, and the
  /// familiarisation (its own trial seed) feels other maps.
  static std::uint64_t base_seed(const SessionCore& s, const std::string& name) {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the name, folded to 16 bits
    for (const unsigned char c : name) h = (h ^ c) * 1099511628211ull;
    return s.order_rng.bits(draw_counter(std::uint64_t{1} << 30, (h ^ (h >> 16) ^ (h >> 32) ^ (h >> 48)) & 0xffff)) >> 11;
  }

  /// A texture of the block as a rearrangement of its session base: the base
  /// seed, and shuffle number k of this trial (1 … 2^31 − 1; the two textures
  /// of a trial, `which` 0 and 1, draw different numbers).
  static json rearranged(const SessionCore& s, json t, std::uint64_t which) {
    if (!t.contains("seed")) t["seed"] = base_seed(s, t.value("name", std::string()));
    const std::uint64_t first = 1 + s.trial_below(80, 2147483646);
    std::uint64_t k = first;
    if (which == 1) {
      k = 1 + s.trial_below(81, 2147483645);
      if (k >= first) ++k;  // never the first texture's arrangement
    }
    t["params"]["shuffle"] = k;
    return t;
  }

  // The digit the recall question asks for (control: every cell or digit is 1).
  static int recalled_digit(const Question& q) {
    if (q.recall->position) return q.sequence[static_cast<std::size_t>(*q.recall->position)];
    return q.recall->cell ? (*q.matrix)[static_cast<std::size_t>(*q.recall->cell)] : 1;
  }

 private:
  std::vector<int> plan_;  // condition·2 + same, per trial
};

class SameDifferentTask : public TaskType {
 public:
  std::string_view name() const override { return "same-different"; }
  std::vector<std::string_view> keys() const override {
    return {"stimuli",         "conditions",  "trials_per_condition", "texture_s",       "matrix_s",      "matrix_cells",
            "sequence_length", "nback_items", "nback_targets",        "recall_question", "balance_order", "base_textures"};
  }

  void parse(BlockInput& in, Block& b) const override {
    JsonObject& o = in.o;
    const auto& stimuli = o.raw("stimuli");
    if (!stimuli.is_object() || stimuli.empty())
      throw FormatError(o.field("stimuli") + " must be an object of named stimuli {\"texture\", \"different\"}");
    for (auto it = stimuli.begin(); it != stimuli.end(); ++it) {
      JsonObject s(it.value(), o.field("stimuli") + "." + it.key());
      BlockInput sin{s, in.device, in.version};
      MemoryStimulus ms;
      ms.name = it.key();
      ms.texture = sin.texture("texture");
      ms.different = sin.texture("different");
      s.finish();
      b.memory_stimuli.push_back(std::move(ms));
    }
    const auto& conds = o.raw("conditions");
    if (!conds.is_array() || conds.empty() || conds.size() > 64)
      throw FormatError(o.field("conditions") + " must be a non-empty array of {name, stimulus, distractor, component}");
    for (std::size_t i = 0; i < conds.size(); ++i) {
      JsonObject c(conds[i], o.field("conditions") + "[" + std::to_string(i) + "]");
      MemoryCondition mc;
      mc.name = c.string("name");
      mc.stimulus = c.string("stimulus");
      if (std::none_of(b.memory_stimuli.begin(), b.memory_stimuli.end(), [&](const auto& s) { return s.name == mc.stimulus; }))
        throw FormatError(c.field("stimulus") + " is '" + mc.stimulus + "'; allowed: a key of " + o.field("stimuli"));
      mc.distractor = c.boolean_or("distractor", true);
      if (c.has("component"))
        mc.component = parse_memory_component(c.string("component"), c.field("component"));
      else
        c.skip("component");
      c.finish();
      b.conditions.push_back(std::move(mc));
    }
    b.trials_per_condition = static_cast<int>(o.integer("trials_per_condition", 1, 1000));
    b.texture_s = o.number_or("texture_s", 10.0, 0.0, 600.0);
    b.matrix_s = o.number_or("matrix_s", 10.0, 0.0, 600.0);
    b.matrix_cells = static_cast<int>(o.has("matrix_cells") ? o.integer("matrix_cells", 1, 9) : (o.skip("matrix_cells"), 5));
    b.sequence_length =
        static_cast<int>(o.has("sequence_length") ? o.integer("sequence_length", 1, 9) : (o.skip("sequence_length"), 5));
    b.nback_items = static_cast<int>(o.has("nback_items") ? o.integer("nback_items", 4, 30) : (o.skip("nback_items"), 10));
    b.nback_targets = static_cast<int>(o.has("nback_targets") ? o.integer("nback_targets", 1, b.nback_items - 2)
                                                              : (o.skip("nback_targets"), std::min(3, b.nback_items - 2)));
    b.recall_question = o.boolean_or("recall_question", true);
    b.balance_order = o.boolean_or("balance_order", false);
    const std::string base = o.has("base_textures") ? o.string("base_textures") : (o.skip("base_textures"), "per-trial");
    if (base != "per-trial" && base != "per-texture")
      throw FormatError(o.field("base_textures") + " is '" + base + "'; allowed: per-trial, per-texture");
    b.base_per_texture = base == "per-texture";
    if (b.base_per_texture)
      for (const MemoryStimulus& ms : b.memory_stimuli)
        for (const TextureTemplate* t : {&ms.texture, &ms.different}) {
          const auto j = nlohmann::json::parse(t->json);
          if (j.value("kind", std::string()) != "reference" || !j.value("name", std::string()).starts_with("patch-"))
            throw FormatError(o.field("base_textures") + " is 'per-texture', which rearranges gap sets; " + o.field("stimuli") +
                              "." + ms.name + " has a texture that is not a patch-* reference");
        }
  }

  std::optional<int> planned_trials(const Block& b) const override {
    return b.trials_per_condition * static_cast<int>(b.conditions.size());
  }

  std::unique_ptr<TaskBlock> start(const SessionCore& s) const override { return std::make_unique<SameDifferentBlock>(s); }

  void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const override {
    const Question& q = session.question();
    const TrialTruth& t = session.truth();
    const auto trial = static_cast<std::uint64_t>(q.trial);
    const CounterRng& rng = who.behaviour();
    const bool ok = rng.uniform(trial * 8 + 2) < who.memory_p_correct(t.condition);
    r.choice = ok ? t.correct_answer : who.wrong_choice(q, t.correct_answer);
    if (q.recall) {
      const int expected = SameDifferentBlock::recalled_digit(q);
      const bool recall = rng.uniform(trial * 8 + 3) < who.memory_p_digit();
      r.digit =
          recall ? expected : 1 + static_cast<int>((static_cast<std::uint64_t>(expected) + rng.below(trial * 8 + 4, 8)) % 9);
    }
    if (q.nback) {
      // Each item answered on its own: a target with p_hit, a non-target with
      // p_false_alarm (draws beyond the per-trial counters the others use).
      const std::vector<bool> target = SameDifferentBlock::nback_targets(q);
      for (std::size_t i = 0; i < target.size(); ++i)
        if (rng.uniform((std::uint64_t{1} << 40) + trial * 64 + i) <
            (target[i] ? who.memory_p_hit() : who.memory_p_false_alarm()))
          r.presses.push_back(static_cast<int>(i));
    }
  }

  std::vector<std::string_view> columns() const override {
    return {"response",      "correct_answer", "correct",    "digit_cell",        "digit_response",
            "digit_correct", "nback_targets",  "nback_hits", "nback_false_alarms"};
  }
};

}  // namespace

std::string_view to_string(MemoryComponent c) {
  switch (c) {
    case MemoryComponent::visuospatial: return "visuospatial";
    case MemoryComponent::verbal: return "verbal";
    case MemoryComponent::executive: return "executive";
  }
  return "visuospatial";
}

MemoryComponent parse_memory_component(std::string_view text, std::string_view field) {
  for (const auto c : {MemoryComponent::visuospatial, MemoryComponent::verbal, MemoryComponent::executive})
    if (text == to_string(c)) return c;
  throw FormatError(std::string(field) + " is '" + std::string(text) + "'; allowed: visuospatial, verbal, executive");
}

std::unique_ptr<TaskType> make_same_different_task() { return std::make_unique<SameDifferentTask>(); }

}  // namespace texel::experiment
