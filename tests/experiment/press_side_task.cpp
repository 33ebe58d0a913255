// A test-only task kind, added the way docs/experiments.md "Adding a task
// kind" says: one type in one file, and one registration (a library kind is
// one row in src/experiment/tasks/table.cpp instead). Linked into the front
// door tests and into `texel_with_test_kind` (the real CLI's objects plus this
// file), never into the shipped `texel`.
//
// "press-side": a texture on the left or the right half; which side is it?
// Its one setting ("presses", the trial count) lives in its own settings type.
#include <nlohmann/json.hpp>

#include "task.hpp"
#include "texel/experiment/simulate.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;

namespace {

struct PressSettings : ex::TaskSettings {
  int presses = 0;
};

int presses(const ex::Block& b) { return static_cast<const PressSettings&>(*b.settings).presses; }

class PressBlock : public ex::TaskBlock {
 public:
  void prepare(const ex::SessionCore& s, ex::Question& q, ex::TrialTruth& t) override {
    const ex::Block& b = s.block();
    q.block_trials = presses(b);
    const bool left = s.trial_below(0, 2) == 0;
    const json texture = ex::texel_texture(ex::texture_of(b.texture), s.seed_draw(1));
    const json flat = {
        {"kind", "texel"}, {"seed", 1}, {"texel_length_mm", 5.0}, {"central_pitch_db", 0.0}, {"irregularity_db", -20.0}};
    q.stimuli.push_back({"Surface", s.halves(left ? texture : flat, left ? flat : texture)});
    q.choices = {"left", "right"};
    q.prompt = "Which half is textured?";
    t.correct_answer = left ? "left" : "right";
  }
  std::string answer(ex::SessionCore&, const ex::Question&, const ex::TrialTruth& t, const ex::Response& r,
                     ex::TrialRow& row) override {
    row.correct = r.choice == t.correct_answer ? 1.0 : 0.0;
    return "{}";
  }
  bool finished(const ex::SessionCore& s) const override { return s.trial_in_block >= presses(s.block()); }
};

class PressTask : public ex::TaskType {
 public:
  std::string_view name() const override { return "press-side"; }
  std::vector<std::string_view> keys() const override { return {"texture", "presses"}; }
  void parse(ex::BlockInput& in, ex::Block& b) const override {
    b.texture = in.texture("texture");
    auto settings = std::make_shared<PressSettings>();
    settings->presses = static_cast<int>(in.o.integer("presses", 1, 100));
    b.settings = std::move(settings);
  }
  std::optional<int> planned_trials(const ex::Block& b) const override { return presses(b); }
  std::unique_ptr<ex::TaskBlock> start(const ex::SessionCore&) const override { return std::make_unique<PressBlock>(); }
  void simulate(const ex::SimulatedParticipant& who, const ex::Session& session, ex::Response& r) const override {
    const auto trial = static_cast<std::uint64_t>(session.question().trial);
    const bool ok = who.behaviour().uniform(trial * 8 + 2) < 0.9;
    r.choice = ok ? session.truth().correct_answer : who.wrong_choice(session.question(), session.truth().correct_answer);
  }
  std::vector<std::string_view> columns() const override { return {"response", "correct_answer", "correct"}; }
};

// The one registration, at static initialisation of the program that links this file.
[[maybe_unused]] const bool registered = [] {
  ex::register_task(std::make_unique<PressTask>());
  return true;
}();

}  // namespace
