// The experiment engine (session.hpp): trial plans per task, questions,
// response validation, records, replay.
#include "texel/experiment/session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <mutex>
#include <set>

#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/observer.hpp"
#include "texel/random.hpp"

namespace texel::experiment {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

// Random streams of the engine (texel::Stream::user + …), so its draws never
// collide with texture draws or the observers'.
constexpr std::uint64_t stream_order = static_cast<std::uint64_t>(Stream::user) + 40;  // per-block orders
constexpr std::uint64_t stream_trial = static_cast<std::uint64_t>(Stream::user) + 41;  // per-trial draws

constexpr std::uint64_t counter(std::uint64_t major, std::uint64_t minor) { return (major << 16) + minor; }

// Fisher–Yates from (seed, block): the same permutation on every resume.
template <class T>
void shuffle(std::vector<T>& v, const CounterRng& rng, std::uint64_t block) {
  for (std::size_t i = v.size(); i > 1; --i) {
    const auto j = static_cast<std::size_t>(rng.below(counter(block, i), i));
    std::swap(v[i - 1], v[j]);
  }
}

json region(const std::string& name, double start_mm, std::optional<double> length_mm, const json& texture) {
  json r = {{"name", name}, {"start_mm", start_mm}, {"texture", texture}};
  if (length_mm) r["length_mm"] = *length_mm;
  return r;
}

json reference_texture(const std::string& name, std::uint64_t seed) {
  return {{"kind", "reference"}, {"name", name}, {"seed", seed}};
}

// A texel texture from a template with parameters and a seed filled in.
json texel_texture(const json& base, std::uint64_t seed, std::optional<MatchResult> params = std::nullopt) {
  json t = base;
  if (!t.contains("kind")) t["kind"] = "texel";
  if (!t.contains("seed")) t["seed"] = seed;
  if (params) {
    t["central_pitch_db"] = params->pitch_db;
    t["irregularity_db"] = params->irregularity_db;
  }
  return t;
}

// The process-wide cache of reference positions: encoding a reference takes
// about a second and the answer depends only on (reference, device).
std::mutex position_mutex;
std::map<std::pair<std::string, std::string>, MatchResult> position_cache;

}  // namespace

// ----------------------------------------------------------------- JSON views

ordered_json Question::to_json() const {
  ordered_json j;
  j["trial"] = trial;
  j["block_index"] = block_index;
  j["block"] = block;
  j["trial_in_block"] = trial_in_block;
  j["block_trials"] = block_trials;
  j["practice"] = practice;
  j["task"] = to_string(task);
  j["prompt"] = prompt;
  j["stimuli"] = ordered_json::array();
  for (const auto& s : stimuli) j["stimuli"].push_back({{"label", s.label}, {"document", json::parse(s.document_json)}});
  j["choices"] = choices;
  if (rating_scale) j["rating_scale"] = {(*rating_scale)[0], (*rating_scale)[1]};
  j["sliders"] = ordered_json::array();
  for (const auto& s : sliders)
    j["sliders"].push_back({{"name", s.name}, {"label", s.label}, {"min", s.min}, {"max", s.max}, {"start", s.start}});
  j["confidence"] = confidence;
  j["time_limit_s"] = time_limit_s;
  j["show_maps"] = show_maps;
  j["phases"] = ordered_json::array();
  for (const auto& p : phases) j["phases"].push_back({{"kind", p.kind}, {"stimulus", p.stimulus}, {"duration_s", p.duration_s}});
  if (matrix) j["matrix"] = *matrix;
  j["recall_cell"] = recall_cell;
  return j;
}

ordered_json Response::to_json() const {
  ordered_json j;
  if (!choice.empty()) j["choice"] = choice;
  if (rating) j["rating"] = *rating;
  if (confidence) j["confidence"] = *confidence;
  if (slider_p) j["slider_p"] = *slider_p;
  if (slider_i) j["slider_i"] = *slider_i;
  if (digit) j["digit"] = *digit;
  if (std::isfinite(rt_ms)) j["rt_ms"] = rt_ms;
  if (swipe_mean_speed_mm_s) j["swipe_mean_speed_mm_s"] = *swipe_mean_speed_mm_s;
  if (swipe_sd_speed_mm_s) j["swipe_sd_speed_mm_s"] = *swipe_sd_speed_mm_s;
  if (directional_proportion) j["directional_proportion"] = *directional_proportion;
  j["shown_at"] = shown_at;
  j["answered_at"] = answered_at;
  return j;
}

// The presentation / selection log a front end kept for the trial (stored
// beside the trial, one row per event). Bounded: a trial is minutes long.
static std::vector<TrialEvent> events_from_json(const json& list) {
  constexpr std::size_t max_events = 10000, max_text = 256;
  if (!list.is_array()) throw FormatError("response.events must be an array of events, got " + list.dump().substr(0, 80));
  if (list.size() > max_events)
    throw FormatError("response.events has " + std::to_string(list.size()) + " events; at most " + std::to_string(max_events));
  std::vector<TrialEvent> events;
  events.reserve(list.size());
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& e = list[k];
    const std::string where = "response.events[" + std::to_string(k) + "]";
    if (!e.is_object()) throw FormatError(where + " must be an object {t_s, kind, detail?, at?}");
    TrialEvent ev;
    for (auto it = e.begin(); it != e.end(); ++it) {
      const std::string& key = it.key();
      if (key == "t_s") {
        if (!it->is_number() || !std::isfinite(it->get<double>()) || it->get<double>() < 0)
          throw FormatError(where + ".t_s must be a number of seconds >= 0, got " + it->dump());
        ev.t_s = it->get<double>();
      } else if (key == "kind" || key == "detail" || key == "at") {
        if (!it->is_string() || it->get_ref<const std::string&>().size() > max_text)
          throw FormatError(where + "." + key + " must be a string of at most " + std::to_string(max_text) + " characters");
        (key == "kind" ? ev.kind : key == "detail" ? ev.detail : ev.at) = it->get<std::string>();
      } else {
        throw FormatError(where + " has unknown key '" + key + "'; allowed: t_s, kind, detail, at");
      }
    }
    if (ev.kind.empty()) throw FormatError(where + ".kind is missing (e.g. \"show\", \"select\", \"answer\")");
    events.push_back(std::move(ev));
  }
  return events;
}

Response Response::from_json(const json& j) {
  if (!j.is_object()) throw FormatError("a response must be a JSON object");
  Response r;
  auto opt = [&](const char* key) -> std::optional<double> {
    if (!j.contains(key) || j[key].is_null()) return std::nullopt;
    if (!j[key].is_number()) throw FormatError(std::string("response.") + key + " must be a number, got " + j[key].dump());
    return j[key].get<double>();
  };
  static const std::set<std::string> known = {"choice",
                                              "rating",
                                              "confidence",
                                              "slider_p",
                                              "slider_i",
                                              "digit",
                                              "rt_ms",
                                              "swipe_mean_speed_mm_s",
                                              "swipe_sd_speed_mm_s",
                                              "directional_proportion",
                                              "shown_at",
                                              "answered_at",
                                              "events"};
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!known.count(it.key())) throw FormatError("response has unknown key '" + it.key() + "'");
  if (j.contains("choice")) {
    if (!j["choice"].is_string()) throw FormatError("response.choice must be a string, got " + j["choice"].dump());
    r.choice = j["choice"].get<std::string>();
  }
  r.rating = opt("rating");
  r.confidence = opt("confidence");
  r.slider_p = opt("slider_p");
  r.slider_i = opt("slider_i");
  if (auto d = opt("digit")) {
    if (*d != std::floor(*d) || *d < -1e6 || *d > 1e6) throw FormatError("response.digit must be a whole number");
    r.digit = static_cast<int>(*d);
  }
  if (auto rt = opt("rt_ms")) r.rt_ms = *rt;
  r.swipe_mean_speed_mm_s = opt("swipe_mean_speed_mm_s");
  r.swipe_sd_speed_mm_s = opt("swipe_sd_speed_mm_s");
  r.directional_proportion = opt("directional_proportion");
  if (j.contains("shown_at") && j["shown_at"].is_string()) r.shown_at = j["shown_at"].get<std::string>();
  if (j.contains("answered_at") && j["answered_at"].is_string()) r.answered_at = j["answered_at"].get<std::string>();
  if (j.contains("events") && !j["events"].is_null()) r.events = events_from_json(j["events"]);
  return r;
}

std::uint64_t session_seed(std::uint64_t protocol_seed, const std::string& participant) {
  std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a of the code, then mixed with the protocol seed
  for (unsigned char c : participant) h = (h ^ c) * 0x100000001b3ULL;
  return mix64(protocol_seed ^ mix64(h));
}

MatchResult slider_to_parameters(SliderMapping mapping, double p, double i) {
  if (mapping == SliderMapping::device_db) return {p, i};
  // Study 2: lognormal mean m = 0.75·1.04^P cpm, SD s = 3·I/10 cpm (moments).
  // s = 0 (perfectly regular) has no dB value: it is floored at 1e-6 cpm
  // (−60 dB, the document's lower bound), which renders the same texture.
  const double m = 0.75 * std::pow(1.04, p);
  const double s = std::max(3.0 * i / 10.0, 1e-6);
  return {10.0 * std::log10(m), 10.0 * std::log10(s)};
}

// ------------------------------------------------------------------- engine

struct Session::Impl {
  Protocol protocol;
  SessionContext ctx;
  CounterRng order_rng;
  CounterRng trial_rng;
  DeviceProfile device;
  double half_mm = 0.0;  // left/right split of the matching layouts

  int block_index = 0;
  int trial = 0;
  int trial_in_block = 0;
  bool done = false;

  // Per-block state.
  std::optional<Staircase> staircase;
  std::vector<int> plan;  // fixed-trial blocks: an index per trial (pair, reference, condition·trial)
  std::unique_ptr<MatchOptimizer> optimizer;
  int guided_reference = 0;  // index into plan (reference order)
  int guided_comparison = 0;
  std::map<std::string, std::map<std::string, MatchResult>> matches;  // block → reference → match

  Question question;
  TrialTruth truth;
  json texture_right;  // match: the rendering template on the right
  std::uint64_t match_seed = 0;

  Impl(Protocol p, SessionContext c)
      : protocol(std::move(p)),
        ctx(std::move(c)),
        order_rng(ctx.seed, stream_order),
        trial_rng(ctx.seed, stream_trial),
        device(load_device(protocol.device)) {
    half_mm = device.length().value() / 2.0;
    for (const auto& r : device.layout)
      if (r.name == "left" && r.length.value() > 0) half_mm = r.length.value();
    start_block();
  }

  [[nodiscard]] const Block& block() const { return protocol.blocks[static_cast<std::size_t>(block_index)]; }

  // Stimuli stay format version 2 (direct reference synthesis), not the
  // current 3: a study's stimuli must not change under it, and a stored
  // session's questions, stimulus documents included, are compared on resume.
  std::string doc(const std::vector<json>& regions) const {
    json d = {{"format", "texel-document"}, {"version", 2}, {"device", protocol.device}, {"regions", regions}};
    const std::string text = d.dump();
    (void)parse_document(text, "stimulus");  // validates every value the engine filled in
    return text;
  }
  std::string single(const json& texture, double length_mm = 0.0) const {
    return doc({region("display", 0.0, length_mm > 0 ? std::optional<double>(length_mm) : std::nullopt, texture)});
  }
  std::string halves(const json& left, const json& right) const {
    return doc({region("left", 0.0, half_mm, left), region("right", half_mm, half_mm, right)});
  }

  MatchResult position(const std::string& reference) const {
    const auto key = std::make_pair(reference, protocol.device);
    {
      std::lock_guard<std::mutex> lock(position_mutex);
      if (auto it = position_cache.find(key); it != position_cache.end()) return it->second;
    }
    const MatchPoint p = perceptual_target(reference, protocol.device);
    const MatchResult r{p.pitch_db, p.irregularity_db};
    std::lock_guard<std::mutex> lock(position_mutex);
    position_cache.emplace(key, r);
    return r;
  }

  // ---- block set-up
  void start_block() {
    while (block_index < static_cast<int>(protocol.blocks.size())) {
      const Block& b = block();
      trial_in_block = 0;
      staircase.reset();
      optimizer.reset();
      plan.clear();
      guided_reference = 0;
      guided_comparison = 0;
      const auto bi = static_cast<std::uint64_t>(block_index);
      switch (b.task) {
        case TaskKind::oddity:
        case TaskKind::two_alternative:
          if (b.staircase) staircase.emplace(*b.staircase);
          break;
        case TaskKind::match:
        case TaskKind::guided:
          for (int i = 0; i < static_cast<int>(b.references.size()); ++i) plan.push_back(i);
          if (b.shuffle) shuffle(plan, order_rng, bi);
          break;
        case TaskKind::rating:
          for (int r = 0; r < b.repeats; ++r)
            for (int i = 0; i < static_cast<int>(b.pairs.size()); ++i) plan.push_back(i);
          if (b.shuffle) shuffle(plan, order_rng, bi);
          break;
        case TaskKind::same_different: {
          // Balanced: each condition trials_per_condition times, half "same"
          // (odd counts: the extra trial is "different"); trial = condition·2 + same.
          for (int c = 0; c < static_cast<int>(b.conditions.size()); ++c)
            for (int k = 0; k < b.trials_per_condition; ++k) plan.push_back(c * 2 + (k < b.trials_per_condition / 2 ? 1 : 0));
          if (b.shuffle) shuffle(plan, order_rng, bi);
          break;
        }
      }
      if (b.task == TaskKind::guided) new_optimizer();
      prepare();
      return;
    }
    done = true;
  }

  void new_optimizer() {
    const Block& b = block();
    json params = b.optimizer_params;
    // Question order and A/B sides differ per participant and reference.
    if (!params.contains("seed"))
      params["seed"] =
          mix64(ctx.seed ^ counter(static_cast<std::uint64_t>(block_index), static_cast<std::uint64_t>(guided_reference)));
    optimizer = make_optimizer(b.optimizer, params);
  }

  [[nodiscard]] bool block_done() const {
    const Block& b = block();
    switch (b.task) {
      case TaskKind::oddity:
      case TaskKind::two_alternative: return staircase ? staircase->finished() : trial_in_block >= b.trials;
      case TaskKind::guided: return guided_reference >= static_cast<int>(plan.size());
      default: return trial_in_block >= static_cast<int>(plan.size());
    }
  }

  // ---- the current question
  void prepare() {
    const Block& b = block();
    Question q;
    TrialTruth t;
    q.trial = trial;
    q.block_index = block_index;
    q.block = b.name;
    q.trial_in_block = trial_in_block;
    q.practice = b.practice;
    q.task = b.task;
    q.time_limit_s = b.time_limit_s;
    q.show_maps = b.show_maps;
    t.condition = b.condition;
    const auto tr = static_cast<std::uint64_t>(trial);
    auto seed_draw = [&](std::uint64_t k) { return trial_rng.bits(counter(tr, k)) >> 11; };  // 53-bit seeds: exact in JSON

    switch (b.task) {
      case TaskKind::oddity: {
        q.block_trials = staircase ? -1 : b.trials;
        const double x = staircase ? staircase->next() : b.fixed_value;
        t.intensity = x;
        json base = b.texture;
        base[b.variable] = x;
        base.erase("seed");
        const std::uint64_t s1 = seed_draw(0);
        std::uint64_t s2 = seed_draw(1);
        if (s2 == s1) s2 ^= 1;
        const auto odd = static_cast<int>(trial_rng.below(counter(tr, 2), 3));
        const bool odd_is_first = trial_rng.below(counter(tr, 3), 2) == 0;  // which seed is the single one
        const std::uint64_t single_seed = odd_is_first ? s1 : s2, pair_seed = odd_is_first ? s2 : s1;
        for (int i = 0; i < 3; ++i)
          q.stimuli.push_back(
              {std::to_string(i + 1), single(texel_texture(base, i == odd ? single_seed : pair_seed), b.display_mm)});
        q.choices = {"1", "2", "3"};
        t.correct_answer = std::to_string(odd + 1);
        q.prompt =
            b.prompt.empty() ? "Feel the three textures (switch freely). Which one is different from the other two?" : b.prompt;
        break;
      }
      case TaskKind::two_alternative: {
        q.block_trials = staircase ? -1 : b.trials;
        const double x = staircase ? staircase->next() : b.fixed_value;
        t.intensity = x;
        const auto which = static_cast<int>(trial_rng.below(counter(tr, 0), 2));
        json test = b.texture;
        test[b.variable] = x;
        test["coarse"] = {{"kind", "reference"}, {"name", b.references[static_cast<std::size_t>(which)]}};
        q.stimuli.push_back({"A", single(reference_texture(b.references[0], 1), b.display_mm)});
        q.stimuli.push_back({"B", single(reference_texture(b.references[1], 1), b.display_mm)});
        q.stimuli.push_back({"Test", single(texel_texture(test, seed_draw(1)), b.display_mm)});
        q.choices = {"A", "B"};
        t.correct_answer = which == 0 ? "A" : "B";
        t.reference = b.references[static_cast<std::size_t>(which)];
        q.prompt =
            b.prompt.empty() ? "Feel A, B and the test texture. Which reference does the test texture feel like?" : b.prompt;
        break;
      }
      case TaskKind::match: {
        q.block_trials = static_cast<int>(plan.size());
        const std::string& ref = b.references[static_cast<std::size_t>(plan[static_cast<std::size_t>(trial_in_block)])];
        t.reference = ref;
        match_seed = seed_draw(0);
        texture_right = b.texture;
        if (b.sliders == SliderMapping::lognormal) {
          q.sliders = {{"pitch", "Pitch", 0, 100, 50}, {"irregularity", "Irregularity", 0, 100, 50}};
        } else {
          q.sliders = {{"pitch", "Central Pitch (dB)", -20, 19.7, -0.15}, {"irregularity", "Irregularity (dB)", -30, 5, -12.5}};
        }
        const MatchResult start = slider_to_parameters(b.sliders, q.sliders[0].start, q.sliders[1].start);
        q.stimuli.push_back(
            {"Reference | Rendering", halves(reference_texture(ref, 1), texel_texture(texture_right, match_seed, start))});
        q.confidence = b.confidence;
        q.prompt = b.prompt.empty() ? "Move the sliders until the right half feels like the left half." : b.prompt;
        break;
      }
      case TaskKind::rating: {
        q.block_trials = static_cast<int>(plan.size());
        const RatingPair& pair = b.pairs[static_cast<std::size_t>(plan[static_cast<std::size_t>(trial_in_block)])];
        t.reference = pair.reference;
        t.condition = pair.condition.empty() ? b.condition : pair.condition;
        t.quantization_db = pair.rendering.quantization_db;
        json right;
        const RenderingSource& src = pair.rendering;
        std::optional<MatchResult> params;
        if (!src.match_of.empty() && !src.from_block.empty()) {
          params = matches.at(src.from_block).at(src.match_of);
          right = texel_texture(protocol.block(src.from_block)->texture, seed_draw(0), params);
        } else if (!src.match_of.empty() && !src.from_protocol.empty()) {
          const auto pit = ctx.prior_matches.find(src.from_protocol);
          if (pit != ctx.prior_matches.end() && pit->second.count(src.match_of)) params = pit->second.at(src.match_of);
          right = texel_texture(src.texture, seed_draw(0), params);
        } else {
          right = texel_texture(src.texture, seed_draw(0));
        }
        if (!params) {
          auto number = [&](const char* key) {
            return right.contains(key) && right[key].is_number() ? right[key].get<double>() : missing;
          };
          params = MatchResult{number("central_pitch_db"), number("irregularity_db")};
        }
        if (src.quantization_db > 0) right["quantization_db"] = src.quantization_db;
        t.rendering = params;
        q.stimuli.push_back({"Reference | Rendering", halves(reference_texture(pair.reference, 1), right)});
        q.rating_scale = std::array<double, 2>{b.scale_min, b.scale_max};
        q.prompt = b.prompt.empty() ? "How similar do the two halves feel? (" + texel::detail::num(b.scale_min) +
                                          " = not at all, " + texel::detail::num(b.scale_max) + " = identical)"
                                    : b.prompt;
        break;
      }
      case TaskKind::guided: {
        q.block_trials = optimizer->budget() * static_cast<int>(plan.size());
        const std::string& ref = b.references[static_cast<std::size_t>(plan[static_cast<std::size_t>(guided_reference)])];
        t.reference = ref;
        const MatchQuestion mq = optimizer->next();
        t.pair = mq;
        // A and B of one reference share a texture seed (they differ only in
        // their parameters): one draw per reference from the block-level
        // stream, at minors above any shuffle's (<= 4096 items).
        const std::uint64_t seed = order_rng.bits(counter(static_cast<std::uint64_t>(block_index),
                                                          0x8000 + static_cast<std::uint64_t>(guided_reference))) >>
                                   11;
        q.stimuli.push_back({"Reference", single(reference_texture(ref, 1))});
        q.stimuli.push_back({"A", single(texel_texture(b.texture, seed, MatchResult{mq.a.pitch_db, mq.a.irregularity_db}))});
        q.stimuli.push_back({"B", single(texel_texture(b.texture, seed, MatchResult{mq.b.pitch_db, mq.b.irregularity_db}))});
        q.choices = {"A", "B", "unsure"};
        q.prompt = b.prompt.empty() ? "Which texture feels more like the reference: A, B, or unsure?" : b.prompt;
        break;
      }
      case TaskKind::same_different: {
        q.block_trials = static_cast<int>(plan.size());
        const int code = plan[static_cast<std::size_t>(trial_in_block)];
        const MemoryCondition& cond = b.conditions[static_cast<std::size_t>(code / 2)];
        const bool same = code % 2 == 1;
        t.condition = cond.name;
        const MemoryStimulus& ms = *std::find_if(b.memory_stimuli.begin(), b.memory_stimuli.end(),
                                                 [&](const auto& s) { return s.name == cond.stimulus; });
        const std::uint64_t seed = seed_draw(0);
        const json first = texel_texture(ms.texture, seed);
        const json second = same ? first : texel_texture(ms.different, seed);
        q.stimuli.push_back({"Texture 1", single(first)});
        q.stimuli.push_back({"Texture 2", single(second)});
        std::array<int, 16> m{};
        if (cond.distractor) {
          // Five (matrix_cells) random cells hold distinct random digits 1–9.
          std::vector<int> cells(16), digits(9);
          for (int i = 0; i < 16; ++i) cells[static_cast<std::size_t>(i)] = i;
          for (int i = 0; i < 9; ++i) digits[static_cast<std::size_t>(i)] = i + 1;
          for (std::size_t i = 16; i > 1; --i)
            std::swap(cells[i - 1], cells[static_cast<std::size_t>(trial_rng.below(counter(tr, 16 + i), i))]);
          for (std::size_t i = 9; i > 1; --i)
            std::swap(digits[i - 1], digits[static_cast<std::size_t>(trial_rng.below(counter(tr, 48 + i), i))]);
          for (int k = 0; k < b.matrix_cells; ++k)
            m[static_cast<std::size_t>(cells[static_cast<std::size_t>(k)])] = digits[static_cast<std::size_t>(k)];
          const int asked =
              cells[static_cast<std::size_t>(trial_rng.below(counter(tr, 5), static_cast<std::uint64_t>(b.matrix_cells)))];
          q.recall_cell = b.recall_question ? asked : -2;
        } else {
          m.fill(1);  // control: every cell holds 1; the recall question indicates all cells
          q.recall_cell = b.recall_question ? -1 : -2;
        }
        q.matrix = m;
        q.phases = {{"stimulus", 0, b.texture_s}, {"matrix", -1, b.matrix_s}, {"stimulus", 1, b.texture_s}};
        q.choices = {"same", "different"};
        t.correct_answer = same ? "same" : "different";
        q.prompt = b.prompt.empty() ? "Were the two textures the same or different?" : b.prompt;
        break;
      }
    }
    question = std::move(q);
    truth = std::move(t);
  }

  // ---- answers
  static void need(bool ok, const std::string& msg) {
    if (!ok) throw InvalidArgument(msg);
  }

  StoredTrial answer(const Response& r) {
    if (done) throw Error("the session is finished; there is no question to answer");
    const Block& b = block();
    const Question& q = question;
    TrialRow row;
    row.participant = ctx.participant;
    row.session_id = ctx.session_id;
    row.protocol = protocol.name;
    row.study = protocol.study;
    row.block = b.name;
    row.block_index = block_index;
    row.trial = trial;
    row.trial_in_block = trial_in_block;
    row.practice = b.practice;
    row.task = std::string(to_string(b.task));
    row.condition = truth.condition;
    row.reference = truth.reference;
    row.correct_answer = truth.correct_answer;
    row.rt_ms = r.rt_ms;
    row.shown_at = r.shown_at.empty() ? utc_timestamp() : r.shown_at;
    row.answered_at = r.answered_at.empty() ? utc_timestamp() : r.answered_at;
    if (r.swipe_mean_speed_mm_s) row.swipe_mean_speed_mm_s = *r.swipe_mean_speed_mm_s;
    if (r.swipe_sd_speed_mm_s) row.swipe_sd_speed_mm_s = *r.swipe_sd_speed_mm_s;
    if (r.directional_proportion) row.directional_proportion = *r.directional_proportion;
    need(!(std::isfinite(r.rt_ms) && r.rt_ms < 0), "rt_ms is " + texel::detail::num(r.rt_ms) + "; allowed: >= 0 ms");

    if (!q.choices.empty()) {
      need(
          std::find(q.choices.begin(), q.choices.end(), r.choice) != q.choices.end(),
          "choice is '" + r.choice + "'; allowed: " + [&] {
            std::string s;
            for (const auto& c : q.choices) s += (s.empty() ? "" : ", ") + c;
            return s;
          }());
      row.response = r.choice;
    }
    auto texture_value = [&](const char* key) {
      if (b.texture.is_object() && b.texture.contains(key) && b.texture[key].is_number()) return b.texture[key].get<double>();
      return missing;
    };
    std::string state;
    switch (b.task) {
      case TaskKind::oddity:
      case TaskKind::two_alternative: {
        const bool correct = r.choice == truth.correct_answer;
        row.correct = correct ? 1.0 : 0.0;
        row.variable = b.variable;
        row.intensity = truth.intensity;
        row.texel_length_mm = texture_value("texel_length_mm");
        row.coarse_strength = texture_value("coarse_strength");
        row.fine_strength = texture_value("fine_strength");
        if (b.variable == "texel_length_mm") row.texel_length_mm = truth.intensity;
        if (b.variable == "coarse_strength") row.coarse_strength = truth.intensity;
        if (b.variable == "fine_strength") row.fine_strength = truth.intensity;
        if (staircase) {
          staircase->answer(correct);
          row.reversal = staircase->last_was_reversal();
          row.next_intensity = staircase->convergent_value();
          row.procedure_finished = staircase->finished();
          state = staircase->state_json();
        } else {
          row.next_intensity = b.fixed_value;
          row.procedure_finished = trial_in_block + 1 >= b.trials;
        }
        break;
      }
      case TaskKind::match: {
        need(r.slider_p.has_value() && r.slider_i.has_value(), "a match needs slider_p and slider_i");
        const auto& sp = q.sliders[0];
        const auto& si = q.sliders[1];
        need(*r.slider_p >= sp.min && *r.slider_p <= sp.max, "slider_p is " + texel::detail::num(*r.slider_p) + "; allowed: " +
                                                                 texel::detail::num(sp.min) + " … " + texel::detail::num(sp.max));
        need(*r.slider_i >= si.min && *r.slider_i <= si.max, "slider_i is " + texel::detail::num(*r.slider_i) + "; allowed: " +
                                                                 texel::detail::num(si.min) + " … " + texel::detail::num(si.max));
        if (q.confidence) {
          need(r.confidence && *r.confidence >= 1 && *r.confidence <= 5 && *r.confidence == std::floor(*r.confidence),
               "confidence is " + (r.confidence ? texel::detail::num(*r.confidence) : std::string("missing")) +
                   "; allowed: 1 … 5");
          row.confidence = *r.confidence;
        }
        const MatchResult m = slider_to_parameters(b.sliders, *r.slider_p, *r.slider_i);
        row.slider_p = *r.slider_p;
        row.slider_i = *r.slider_i;
        row.pitch_db = m.pitch_db;
        row.irregularity_db = m.irregularity_db;
        row.texel_length_mm = texture_value("texel_length_mm");
        const MatchResult ref = position(truth.reference);
        row.reference_pitch_db = ref.pitch_db;
        row.reference_irregularity_db = ref.irregularity_db;
        row.response = texel::detail::num(*r.slider_p) + "/" + texel::detail::num(*r.slider_i);
        matches[b.name][truth.reference] = m;
        state = json{{"matched", {{"pitch_db", m.pitch_db}, {"irregularity_db", m.irregularity_db}}}}.dump();
        break;
      }
      case TaskKind::rating: {
        need(r.rating.has_value(), "a rating is required");
        need(*r.rating >= b.scale_min && *r.rating <= b.scale_max && *r.rating == std::floor(*r.rating),
             "rating is " + texel::detail::num(*r.rating) + "; allowed: whole numbers " + texel::detail::num(b.scale_min) +
                 " … " + texel::detail::num(b.scale_max));
        row.rating = *r.rating;
        row.response = texel::detail::num(*r.rating);
        row.quantization_db = truth.quantization_db;
        if (truth.rendering) {
          row.pitch_db = truth.rendering->pitch_db;
          row.irregularity_db = truth.rendering->irregularity_db;
        }
        const MatchResult ref = position(truth.reference);
        row.reference_pitch_db = ref.pitch_db;
        row.reference_irregularity_db = ref.irregularity_db;
        state = "{}";
        break;
      }
      case TaskKind::guided: {
        const MatchChoice c = parse_match_choice(r.choice, "choice");
        const MatchQuestion mq = *truth.pair;
        row.iteration = mq.iteration;
        row.pitch_a_db = mq.a.pitch_db;
        row.irregularity_a_db = mq.a.irregularity_db;
        row.pitch_b_db = mq.b.pitch_db;
        row.irregularity_b_db = mq.b.irregularity_db;
        optimizer->answer(c);
        const MatchPoint e = optimizer->estimate();
        row.pitch_db = e.pitch_db;
        row.irregularity_db = e.irregularity_db;
        row.procedure_finished = optimizer->finished();
        row.texel_length_mm = texture_value("texel_length_mm");
        const MatchResult ref = position(truth.reference);
        row.reference_pitch_db = ref.pitch_db;
        row.reference_irregularity_db = ref.irregularity_db;
        state = optimizer->state_json();
        if (optimizer->finished()) matches[b.name][truth.reference] = MatchResult{e.pitch_db, e.irregularity_db};
        break;
      }
      case TaskKind::same_different: {
        row.correct = r.choice == truth.correct_answer ? 1.0 : 0.0;
        if (q.recall_cell != -2) {
          need(r.digit.has_value() && *r.digit >= 1 && *r.digit <= 9,
               "digit is " + (r.digit ? std::to_string(*r.digit) : std::string("missing")) + "; allowed: 1 … 9");
          const int expected = q.recall_cell >= 0 ? (*q.matrix)[static_cast<std::size_t>(q.recall_cell)] : 1;
          row.digit_cell = q.recall_cell >= 0 ? q.recall_cell : missing;
          row.digit_response = *r.digit;
          row.digit_correct = *r.digit == expected ? 1.0 : 0.0;
        }
        state = "{}";
        break;
      }
    }

    StoredTrial st;
    st.trial = trial;
    ordered_json qj;
    qj["question"] = q.to_json();
    ordered_json tj;
    tj["correct_answer"] = truth.correct_answer;
    if (std::isfinite(truth.intensity)) tj["intensity"] = truth.intensity;
    tj["reference"] = truth.reference;
    tj["condition"] = truth.condition;
    if (truth.rendering)
      tj["rendering"] = {{"pitch_db", truth.rendering->pitch_db}, {"irregularity_db", truth.rendering->irregularity_db}};
    qj["truth"] = tj;
    st.question_json = qj.dump();
    st.response_json = r.to_json().dump();
    st.state_json = state;
    st.events = r.events;
    st.row = std::move(row);

    // Advance.
    ++trial;
    ++trial_in_block;
    if (b.task == TaskKind::guided && optimizer->finished()) {
      ++guided_reference;
      if (guided_reference < static_cast<int>(plan.size())) new_optimizer();
    }
    if (block_done()) {
      ++block_index;
      start_block();
    } else {
      prepare();
    }
    return st;
  }
};

Session::Session(Protocol protocol, SessionContext context)
    : impl_(std::make_unique<Impl>(std::move(protocol), std::move(context))) {}
Session::~Session() = default;
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;

bool Session::finished() const { return impl_->done; }
const Question& Session::question() const {
  if (impl_->done) throw Error("the session is finished; there is no question");
  return impl_->question;
}
const TrialTruth& Session::truth() const {
  if (impl_->done) throw Error("the session is finished; there is no question");
  return impl_->truth;
}

std::string Session::preview_document(double slider_p, double slider_i) const {
  const Question& q = question();
  if (q.task != TaskKind::match) throw Error("preview_document: the current question is not a match");
  const Block& b = impl_->block();
  const double p = std::clamp(slider_p, q.sliders[0].min, q.sliders[0].max);
  const double i = std::clamp(slider_i, q.sliders[1].min, q.sliders[1].max);
  return impl_->halves(reference_texture(impl_->truth.reference, 1),
                       texel_texture(impl_->texture_right, impl_->match_seed, slider_to_parameters(b.sliders, p, i)));
}

StoredTrial Session::answer(const Response& r) { return impl_->answer(r); }

void Session::replay(const StoredTrial& t) {
  if (impl_->done) throw FormatError("stored trial " + std::to_string(t.trial) + " comes after the end of the protocol");
  if (t.trial != impl_->trial)
    throw FormatError("stored trial " + std::to_string(t.trial) + " is out of order (expected " + std::to_string(impl_->trial) +
                      ")");
  json stored;
  try {
    stored = json::parse(t.question_json);
  } catch (const json::exception&) {
    throw FormatError("stored trial " + std::to_string(t.trial) + " has a malformed question");
  }
  if (!stored.contains("question") || json(impl_->question.to_json()) != stored["question"])
    throw FormatError("stored trial " + std::to_string(t.trial) +
                      " was asked differently (another protocol, seed or Texel version); cannot resume this session");
  Response r;
  try {
    r = Response::from_json(json::parse(t.response_json));
  } catch (const json::exception&) {
    throw FormatError("stored trial " + std::to_string(t.trial) + " has a malformed response");
  }
  r.events = t.events;
  (void)impl_->answer(r);
}

int Session::trials_done() const { return impl_->trial; }
int Session::trials_planned() const { return impl_->protocol.planned_trials(); }
const Protocol& Session::protocol() const { return impl_->protocol; }
const SessionContext& Session::context() const { return impl_->ctx; }
std::map<std::string, MatchResult> Session::matches(const std::string& block) const {
  auto it = impl_->matches.find(block);
  return it == impl_->matches.end() ? std::map<std::string, MatchResult>{} : it->second;
}
MatchResult Session::reference_position(const std::string& reference) const { return impl_->position(reference); }

}  // namespace texel::experiment
