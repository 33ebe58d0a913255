// Familiarisation (docs/experiments.md): the participant feels a set of
// named textures freely, untimed, for about `duration_s`, then continues.
// One trial, no right answer; the working-memory study's ~5 minutes with
// its four textures.
#include "../task.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;

class FamiliarisationBlock : public TaskBlock {
 public:
  void prepare(const SessionCore& s, Question& q, TrialTruth&) override {
    const Block& b = s.block();
    q.block_trials = 1;
    // One seed for all: textures that differ only by a parameter (a shuffle
    // of the same gaps) are then the same draw, as in the trials.
    const std::uint64_t seed = s.seed_draw(0);
    for (const NamedTexture& t : b.textures) q.stimuli.push_back({t.name, s.single(texel_texture(texture_of(t.texture), seed))});
    q.choices = {"continue"};
    q.prompt = b.prompt.empty()
                   ? "Feel the " + std::to_string(b.textures.size()) + " textures (switch freely, no time limit; about " +
                         detail::num(b.duration_s / 60.0) + " minutes). Then continue."
                   : b.prompt;
  }

  std::string answer(SessionCore&, const Question&, const TrialTruth&, const Response&, TrialRow&) override { return "{}"; }

  bool finished(const SessionCore& s) const override { return s.trial_in_block >= 1; }
};

class FamiliarisationTask : public TaskType {
 public:
  std::string_view name() const override { return "familiarisation"; }
  std::vector<std::string_view> keys() const override { return {"textures", "duration_s"}; }

  void parse(BlockInput& in, Block& b) const override {
    JsonObject& o = in.o;
    const auto& textures = o.raw("textures");
    if (!textures.is_object() || textures.empty() || textures.size() > 16)
      throw FormatError(o.field("textures") + " must be an object of 1 … 16 named textures");
    JsonObject named(textures, o.field("textures"));
    for (auto it = textures.begin(); it != textures.end(); ++it) {
      if (it.key().empty() || it.key().size() > 64)
        throw FormatError(o.field("textures") + " has a name of " + std::to_string(it.key().size()) +
                          " characters; allowed: 1 … 64");
      BlockInput tin{named, in.device, in.version};
      b.textures.push_back({it.key(), tin.texture(it.key())});
    }
    named.finish();
    b.duration_s = o.number_or("duration_s", 300.0, 1.0, 3600.0);
    b.time_limit_s = 0.0;  // untimed
  }

  std::optional<int> planned_trials(const Block&) const override { return 1; }

  std::unique_ptr<TaskBlock> start(const SessionCore&) const override { return std::make_unique<FamiliarisationBlock>(); }

  void simulate(const SimulatedParticipant&, const Session&, Response& r) const override { r.choice = "continue"; }

  std::vector<std::string_view> columns() const override { return {"response"}; }
};

}  // namespace

std::unique_ptr<TaskType> make_familiarisation_task() { return std::make_unique<FamiliarisationTask>(); }

}  // namespace texel::experiment
