// Guided matching (docs/experiments.md, study 5): per reference, a matching
// optimizer (guided exploration or Bayesian) asks "which of A, B feels more
// like the reference" until its budget is spent; its estimate is the match.
#include "../json_views.hpp"
#include "../task.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using nlohmann::json;

class GuidedBlock : public TaskBlock {
 public:
  explicit GuidedBlock(const SessionCore& s) {
    const Block& b = s.block();
    for (int i = 0; i < static_cast<int>(b.references.size()); ++i) plan_.push_back(i);
    if (b.shuffle) s.shuffle(plan_);
    new_optimizer(s);
  }

  void prepare(const SessionCore& s, Question& q, TrialTruth& t) override {
    const Block& b = s.block();
    q.block_trials = optimizer_->budget() * static_cast<int>(plan_.size());
    const std::string& ref = b.references[static_cast<std::size_t>(plan_[static_cast<std::size_t>(reference_)])];
    t.reference = ref;
    const MatchQuestion mq = optimizer_->next();
    t.pair = mq;
    // A and B of one reference share a texture seed (they differ only in
    // their parameters): one draw per reference from the block-level
    // stream, at minors above any shuffle's (<= 4096 items).
    const std::uint64_t seed = s.order_rng.bits(draw_counter(static_cast<std::uint64_t>(s.block_index),
                                                             0x8000 + static_cast<std::uint64_t>(reference_))) >>
                               11;
    const json base = texture_of(b.texture);
    q.stimuli.push_back({"Reference", s.single(reference_texture(ref, 1))});
    q.stimuli.push_back({"A", s.single(texel_texture(base, seed, MatchResult{mq.a.pitch_db, mq.a.irregularity_db}))});
    q.stimuli.push_back({"B", s.single(texel_texture(base, seed, MatchResult{mq.b.pitch_db, mq.b.irregularity_db}))});
    q.choices = {"A", "B", "unsure"};
    q.wording.choice_question = "More like the reference";
    q.prompt = b.prompt.empty() ? "Which texture feels more like the reference: A, B, or unsure?" : b.prompt;
  }

  std::string answer(SessionCore& s, const Question&, const TrialTruth& t, const Response& r, TrialRow& row) override {
    const Block& b = s.block();
    const MatchChoice c = parse_match_choice(r.choice, "choice");
    const MatchQuestion mq = *t.pair;
    row.iteration = mq.iteration;
    row.pitch_a_db = mq.a.pitch_db;
    row.irregularity_a_db = mq.a.irregularity_db;
    row.pitch_b_db = mq.b.pitch_db;
    row.irregularity_b_db = mq.b.irregularity_db;
    optimizer_->answer(c);
    const MatchPoint e = optimizer_->estimate();
    row.pitch_db = e.pitch_db;
    row.irregularity_db = e.irregularity_db;
    row.procedure_finished = optimizer_->finished();
    row.texel_length_mm = template_number(b, "texel_length_mm");
    const MatchResult ref = s.position(t.reference);
    row.reference_pitch_db = ref.pitch_db;
    row.reference_irregularity_db = ref.irregularity_db;
    std::string state = optimizer_->state_json();
    if (optimizer_->finished()) {
      s.matches[b.name][t.reference] = MatchResult{e.pitch_db, e.irregularity_db};
      ++reference_;
      if (reference_ < static_cast<int>(plan_.size())) new_optimizer(s);
    }
    return state;
  }

  bool finished(const SessionCore&) const override { return reference_ >= static_cast<int>(plan_.size()); }

 private:
  void new_optimizer(const SessionCore& s) {
    const Block& b = s.block();
    json params = json::parse(b.optimizer_params);
    // Question order and A/B sides differ per participant and reference.
    if (!params.contains("seed"))
      params["seed"] =
          mix64(s.ctx.seed ^ draw_counter(static_cast<std::uint64_t>(s.block_index), static_cast<std::uint64_t>(reference_)));
    optimizer_ = make_optimizer_from(b.optimizer, params);
  }

  std::vector<int> plan_;  // reference order
  int reference_ = 0;      // index into plan_
  std::unique_ptr<MatchOptimizer> optimizer_;
};

class GuidedTask : public TaskType {
 public:
  std::string_view name() const override { return "guided"; }
  std::vector<std::string_view> keys() const override { return {"texture", "references", "optimizer"}; }

  void parse(BlockInput& in, Block& b) const override {
    JsonObject& o = in.o;
    b.texture = in.texture("texture");
    b.references = string_list(o, "references", 1);
    for (std::size_t i = 0; i < b.references.size(); ++i)
      check_reference(b.references[i], o.field("references") + "[" + std::to_string(i) + "]");
    JsonObject opt(o.raw("optimizer"), o.field("optimizer"));
    const std::string kind = opt.string("kind");
    if (kind != "guided" && kind != "bayesian")
      throw FormatError(opt.field("kind") + " is '" + kind + "'; allowed: guided, bayesian");
    b.optimizer = parse_optimizer_kind(kind);
    json params = o.raw("optimizer");
    params.erase("kind");
    try {
      (void)make_optimizer_from(b.optimizer, params);
    } catch (const Error& e) {
      throw FormatError(o.field("optimizer") + ": " + e.what());
    }
    b.optimizer_params = params.dump();
  }

  std::optional<int> planned_trials(const Block& b) const override {
    return make_optimizer(b.optimizer, b.optimizer_params)->budget() * static_cast<int>(b.references.size());
  }

  std::unique_ptr<TaskBlock> start(const SessionCore& s) const override { return std::make_unique<GuidedBlock>(s); }

  void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const override {
    const TrialTruth& t = session.truth();
    const Matcher m = who.matcher(session.reference_position(t.reference), session);
    const MatchChoice c = m.choose(*t.pair, static_cast<std::uint64_t>(session.question().trial));
    r.choice = c == MatchChoice::a ? "A" : c == MatchChoice::b ? "B" : "unsure";
  }

  std::vector<std::string_view> columns() const override {
    return {"response",           "iteration",         "pitch_a_db",         "irregularity_a_db",
            "pitch_b_db",         "irregularity_b_db", "pitch_db",           "irregularity_db",
            "procedure_finished", "texel_length_mm",   "reference_pitch_db", "reference_irregularity_db"};
  }

  bool makes_matches() const override { return true; }
  bool holds_match(const TrialRow& row) const override { return row.procedure_finished; }
};

}  // namespace

std::unique_ptr<TaskType> make_guided_task() { return std::make_unique<GuidedTask>(); }

}  // namespace texel::experiment
