// The similarity rating (docs/experiments.md, studies 3 and 4): the
// reference on the left, a rendering on the right — an explicit texture, or
// a match made earlier in the session or in an earlier session — rated on a
// whole-number scale.
#include <cmath>

#include "../task.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using nlohmann::json;

constexpr std::size_t max_list = 4096;

RenderingSource parse_rendering(BlockInput& block, JsonObject o) {
  RenderingSource r;
  if (o.has("texture")) {
    BlockInput in{o, block.device, block.version};
    r.texture = in.texture("texture");
  } else {
    o.skip("texture");
  }
  r.match_of = o.string_or("match_of", "");
  r.from_block = o.string_or("from_block", "");
  r.from_protocol = o.string_or("from_protocol", "");
  r.quantization_db = o.number_or("quantization_db", 0.0, 0.0, 20.0);
  o.finish();
  if (r.texture.empty() && r.match_of.empty())
    throw FormatError(o.where() + " needs \"texture\" or \"match_of\" (with \"from_block\" or \"from_protocol\")");
  if (!r.match_of.empty() && r.from_block.empty() && r.from_protocol.empty())
    throw FormatError(o.where() + ": \"match_of\" needs \"from_block\" or \"from_protocol\"");
  if (!r.from_protocol.empty() && r.texture.empty())
    throw FormatError(o.where() +
                      ": \"from_protocol\" needs a fallback \"texture\" (used when the participant has no such match)");
  // Version 2: a fallback rendering stands for a match, so it must be one a
  // participant could have made: inside the device's slider ranges.
  if (block.version >= 2 && !r.from_protocol.empty()) {
    const GuidedConfig range;  // the device's full ranges (docs/procedures.md §3)
    const auto check = [&](const char* key, double lo, double hi) {
      const auto v = r.texture.number(key);
      if (v && (*v < lo || *v > hi))
        throw FormatError(o.field("texture") + "." + key + " is " + detail::num(*v) + "; allowed: " + detail::num(lo) + " … " +
                          detail::num(hi) + " dB (the device's range: a fallback stands for a match)");
    };
    check("central_pitch_db", range.pitch_min_db, range.pitch_max_db);
    check("irregularity_db", range.irregularity_min_db, range.irregularity_max_db);
  }
  return r;
}

class RatingBlock : public TaskBlock {
 public:
  explicit RatingBlock(const SessionCore& s) {
    const Block& b = s.block();
    for (int r = 0; r < b.repeats; ++r)
      for (int i = 0; i < static_cast<int>(b.pairs.size()); ++i) plan_.push_back(i);
    if (b.shuffle) s.shuffle(plan_);
  }

  void prepare(const SessionCore& s, Question& q, TrialTruth& t) override {
    const Block& b = s.block();
    q.block_trials = static_cast<int>(plan_.size());
    const RatingPair& pair = b.pairs[static_cast<std::size_t>(plan_[static_cast<std::size_t>(s.trial_in_block)])];
    t.reference = pair.reference;
    t.condition = pair.condition.empty() ? b.condition : pair.condition;
    t.quantization_db = pair.rendering.quantization_db;
    json right;
    const RenderingSource& src = pair.rendering;
    std::optional<MatchResult> params;
    if (!src.match_of.empty() && !src.from_block.empty()) {
      params = s.matches.at(src.from_block).at(src.match_of);
      right = texel_texture(texture_of(s.protocol.block(src.from_block)->texture), s.seed_draw(0), params);
    } else if (!src.match_of.empty() && !src.from_protocol.empty()) {
      const auto pit = s.ctx.prior_matches.find(src.from_protocol);
      if (pit != s.ctx.prior_matches.end() && pit->second.count(src.match_of)) params = pit->second.at(src.match_of);
      right = texel_texture(texture_of(src.texture), s.seed_draw(0), params);
    } else {
      right = texel_texture(texture_of(src.texture), s.seed_draw(0));
    }
    if (!params) {
      auto number = [&](const char* key) {
        return right.contains(key) && right[key].is_number() ? right[key].get<double>() : missing;
      };
      params = MatchResult{number("central_pitch_db"), number("irregularity_db")};
    }
    if (src.quantization_db > 0) right["quantization_db"] = src.quantization_db;
    t.rendering = params;
    q.stimuli.push_back({"Reference | Rendering", s.halves(reference_texture(pair.reference, 1), right)});
    q.rating_scale = std::array<double, 2>{b.scale_min, b.scale_max};
    q.wording.rating = Scale{static_cast<int>(b.scale_min), static_cast<int>(b.scale_max), "How similar do the two halves feel?",
                             "not at all", "identical"};
    q.prompt = b.prompt.empty() ? "How similar do the two halves feel? (" + detail::num(b.scale_min) + " = not at all, " +
                                      detail::num(b.scale_max) + " = identical)"
                                : b.prompt;
  }

  std::string answer(SessionCore& s, const Question&, const TrialTruth& t, const Response& r, TrialRow& row) override {
    const Block& b = s.block();
    require(r.rating.has_value(), "a rating is required");
    require(*r.rating >= b.scale_min && *r.rating <= b.scale_max && *r.rating == std::floor(*r.rating),
            "rating is " + detail::num(*r.rating) + "; allowed: whole numbers " + detail::num(b.scale_min) + " … " +
                detail::num(b.scale_max));
    row.rating = *r.rating;
    row.response = detail::num(*r.rating);
    row.quantization_db = t.quantization_db;
    if (t.rendering) {
      row.pitch_db = t.rendering->pitch_db;
      row.irregularity_db = t.rendering->irregularity_db;
    }
    const MatchResult ref = s.position(t.reference);
    row.reference_pitch_db = ref.pitch_db;
    row.reference_irregularity_db = ref.irregularity_db;
    return "{}";
  }

  bool finished(const SessionCore& s) const override { return s.trial_in_block >= static_cast<int>(plan_.size()); }

 private:
  std::vector<int> plan_;  // pair index per trial
};

class RatingTask : public TaskType {
 public:
  std::string_view name() const override { return "rating"; }
  std::vector<std::string_view> keys() const override { return {"scale", "repeats", "pairs"}; }

  void parse(BlockInput& in, Block& b) const override {
    JsonObject& o = in.o;
    const auto& scale = o.raw("scale");
    if (!scale.is_array() || scale.size() != 2 || !scale[0].is_number_integer() || !scale[1].is_number_integer() ||
        scale[0].get<int>() >= scale[1].get<int>() || scale[0].get<int>() < -100 || scale[1].get<int>() > 100)
      throw FormatError(o.field("scale") + " must be [min, max], whole numbers with min < max (e.g. [1, 5] or [0, 10])");
    b.scale_min = scale[0].get<double>();
    b.scale_max = scale[1].get<double>();
    b.repeats = static_cast<int>(o.has("repeats") ? o.integer("repeats", 1, 100) : (o.skip("repeats"), 1));
    const auto& pairs = o.raw("pairs");
    if (!pairs.is_array() || pairs.empty() || pairs.size() > max_list)
      throw FormatError(o.field("pairs") + " must be a non-empty array of {reference, rendering, condition}");
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      JsonObject p(pairs[i], o.field("pairs") + "[" + std::to_string(i) + "]");
      RatingPair rp;
      rp.reference = p.string("reference");
      check_reference(rp.reference, p.field("reference"));
      rp.rendering = parse_rendering(in, JsonObject(p.raw("rendering"), p.field("rendering")));
      rp.condition = p.string_or("condition", "");
      p.finish();
      b.pairs.push_back(std::move(rp));
    }
  }

  std::optional<int> planned_trials(const Block& b) const override {
    int pairs = 0;
    for (const auto& p : b.pairs) pairs += p.rendering.match_of == "*" ? 0 : 1;
    return pairs * b.repeats;
  }

  std::unique_ptr<TaskBlock> start(const SessionCore& s) const override { return std::make_unique<RatingBlock>(s); }

  void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const override {
    const Question& q = session.question();
    const TrialTruth& t = session.truth();
    const MatchResult ref = session.reference_position(t.reference);
    const MatchResult ren = t.rendering.value_or(ref);
    // Assumption of the simulated rater (not a perceptual claim): a
    // quantization step of q dB adds q/2 dB of felt difference.
    const double d = std::hypot(ren.pitch_db - ref.pitch_db, ren.irregularity_db - ref.irregularity_db) + 0.5 * t.quantization_db;
    r.rating = who.rater((*q.rating_scale)[0], (*q.rating_scale)[1]).rate(d, static_cast<std::uint64_t>(q.trial));
  }

  std::vector<std::string_view> columns() const override {
    return {"rating",          "response",           "quantization_db",          "pitch_db",
            "irregularity_db", "reference_pitch_db", "reference_irregularity_db"};
  }
};

}  // namespace

std::unique_ptr<TaskType> make_rating_task() { return std::make_unique<RatingTask>(); }

}  // namespace texel::experiment
