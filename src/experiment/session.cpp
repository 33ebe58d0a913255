// The experiment engine (session.hpp): the common part of every trial —
// question header, choice check, the row's common columns, the stored
// record, replay. What a task kind asks, scores and plans is its TaskType's
// (task.hpp, src/experiment/tasks/).
#include "texel/experiment/session.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>

#include "json_views.hpp"
#include "task.hpp"
#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/observer.hpp"

namespace texel::experiment {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

// Random streams of the engine (texel::Stream::user + …), so its draws never
// collide with texture draws or the observers'.
constexpr std::uint64_t stream_order = static_cast<std::uint64_t>(Stream::user) + 40;  // per-block orders
constexpr std::uint64_t stream_trial = static_cast<std::uint64_t>(Stream::user) + 41;  // per-trial draws

json region(const std::string& name, double start_mm, std::optional<double> length_mm, const json& texture) {
  json r = {{"name", name}, {"start_mm", start_mm}, {"texture", texture}};
  if (length_mm) r["length_mm"] = *length_mm;
  return r;
}

// The process-wide cache of reference positions: encoding a reference takes
// about a second and the answer depends only on (reference, device).
std::mutex position_mutex;
std::map<std::pair<std::string, std::string>, MatchResult> position_cache;

// The swipe columns from the finger that explored (finger_trace.hpp): a
// display's or a pointer's trace replaces whatever the response carried; a
// simulated finger (passive presentation) fills them only where nothing
// else did, so a simulated observer's drawn swipe behaviour is kept. A
// flagged trace leaves them empty and says why.
void fill_swipe_columns(const FingerTrace& trace, TrialRow& row) {
  if (trace.mode) row.presentation_mode = std::string(to_string(*trace.mode));
  if (trace.source == TraceSource::none) return;
  row.finger_source = std::string(to_string(trace.source));
  const bool real = trace.source != TraceSource::simulated;
  if (!real && std::isfinite(row.swipe_mean_speed_mm_s)) return;
  const TraceMeasures m = measure_trace(trace);
  row.swipe_flag = m.flag;
  if (!m.measures) {
    row.swipe_mean_speed_mm_s = row.swipe_sd_speed_mm_s = row.directional_proportion = missing;
    return;
  }
  row.swipe_mean_speed_mm_s = m.measures->mean_speed_mm_s;
  row.swipe_sd_speed_mm_s = m.measures->sd_speed_mm_s;
  row.directional_proportion = m.measures->directional_proportion;
}

}  // namespace

// ------------------------------------------------------------ task support

json reference_texture(const std::string& name, std::uint64_t seed) {
  return {{"kind", "reference"}, {"name", name}, {"seed", seed}};
}

json texel_texture(const json& base, std::uint64_t seed, std::optional<MatchResult> params) {
  json t = base;
  if (!t.contains("kind")) t["kind"] = "texel";
  if (!t.contains("seed")) t["seed"] = seed;
  if (params) {
    t["central_pitch_db"] = params->pitch_db;
    t["irregularity_db"] = params->irregularity_db;
  }
  return t;
}

json texture_of(const TextureTemplate& t) { return t.empty() ? json() : json::parse(t.json); }

SessionCore::SessionCore(Protocol p, SessionContext c)
    : protocol(std::move(p)),
      ctx(std::move(c)),
      order_rng(ctx.seed, stream_order),
      trial_rng(ctx.seed, stream_trial),
      device(load_device(protocol.device)) {
  half_mm = device.length().value() / 2.0;
  for (const auto& r : device.layout)
    if (r.name == "left" && r.length.value() > 0) half_mm = r.length.value();
}

std::uint64_t SessionCore::seed_draw(std::uint64_t k) const {
  return trial_rng.bits(draw_counter(static_cast<std::uint64_t>(trial), k)) >> 11;  // 53-bit seeds: exact in JSON
}

std::uint64_t SessionCore::trial_below(std::uint64_t k, std::uint64_t n) const {
  return trial_rng.below(draw_counter(static_cast<std::uint64_t>(trial), k), n);
}

void SessionCore::shuffle(std::vector<int>& v) const {
  const auto block = static_cast<std::uint64_t>(block_index);
  for (std::size_t i = v.size(); i > 1; --i) {
    const auto j = static_cast<std::size_t>(order_rng.below(draw_counter(block, i), i));
    std::swap(v[i - 1], v[j]);
  }
}

// Stimuli stay format version 2 (direct reference synthesis), not the
// current 3: a study's stimuli must not change under it, and a stored
// session's questions, stimulus documents included, are compared on resume.
static std::string stimulus_document(const std::string& device, const std::vector<json>& regions) {
  json d = {{"format", "texel-document"}, {"version", 2}, {"device", device}, {"regions", regions}};
  const std::string text = d.dump();
  (void)parse_document(text, "stimulus");  // validates every value the engine filled in
  return text;
}

std::string SessionCore::single(const json& texture, double length_mm) const {
  return stimulus_document(protocol.device,
                           {region("display", 0.0, length_mm > 0 ? std::optional<double>(length_mm) : std::nullopt, texture)});
}

std::string SessionCore::single_played(const json& texture, std::string_view playback, double length_mm) const {
  json d = {{"format", "texel-document"},
            {"version", 6},
            {"device", protocol.device},
            {"regions", {region("display", 0.0, length_mm > 0 ? std::optional<double>(length_mm) : std::nullopt, texture)}},
            {"playback", {{"mode", std::string(playback)}}}};
  const std::string text = d.dump();
  (void)parse_document(text, "stimulus");
  return text;
}

std::string SessionCore::halves(const json& left, const json& right) const {
  return stimulus_document(protocol.device, {region("left", 0.0, half_mm, left), region("right", half_mm, half_mm, right)});
}

MatchResult SessionCore::position(const std::string& reference) const {
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

double template_number(const Block& b, const char* key) { return b.texture.number(key).value_or(missing); }

void ask_oddity(const Block& b, int odd, Question& q, TrialTruth& t) {
  q.choices = {"1", "2", "3"};
  q.wording.choice_question = "The odd one is";
  t.correct_answer = std::to_string(odd + 1);
  q.prompt = b.prompt.empty() ? "Feel the three textures (switch freely). Which one is different from the other two?" : b.prompt;
}

void require(bool ok, const std::string& msg) {
  if (!ok) throw InvalidArgument(msg);
}

std::string joined(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& c : items) s += (s.empty() ? "" : ", ") + c;
  return s;
}

// ----------------------------------------------------------------- JSON views

std::string_view to_string(PhaseKind k) {
  return k == PhaseKind::stimulus ? "stimulus" : k == PhaseKind::matrix ? "matrix" : "sequence";
}

ordered_json question_view(const Question& q) {
  ordered_json j;
  j["trial"] = q.trial;
  j["block_index"] = q.block_index;
  j["block"] = q.block;
  j["trial_in_block"] = q.trial_in_block;
  j["block_trials"] = q.block_trials.value_or(-1);  // -1 = adaptive (the stored form)
  j["practice"] = q.practice;
  j["task"] = q.task;
  j["prompt"] = q.prompt;
  j["stimuli"] = ordered_json::array();
  for (const auto& s : q.stimuli) j["stimuli"].push_back({{"label", s.label}, {"document", json::parse(s.document_json)}});
  j["choices"] = q.choices;
  if (q.rating_scale) j["rating_scale"] = {(*q.rating_scale)[0], (*q.rating_scale)[1]};
  j["sliders"] = ordered_json::array();
  for (const auto& s : q.sliders)
    j["sliders"].push_back({{"name", s.name}, {"label", s.label}, {"min", s.min}, {"max", s.max}, {"start", s.start}});
  j["confidence"] = q.confidence;
  j["time_limit_s"] = q.time_limit_s;
  j["show_maps"] = q.show_maps;
  j["phases"] = ordered_json::array();
  for (const auto& p : q.phases)
    j["phases"].push_back({{"kind", to_string(p.kind)}, {"stimulus", p.stimulus.value_or(-1)}, {"duration_s", p.duration_s}});
  if (q.matrix) j["matrix"] = *q.matrix;
  // -2 = no recall question, -1 = "the digit in the cells", else the cell (the stored form).
  j["recall_cell"] = q.recall ? q.recall->cell.value_or(-1) : -2;
  // The verbal and executive distractors (keys absent otherwise, so stored
  // questions of the matrix task keep their bytes).
  if (!q.sequence.empty()) {
    j["sequence"] = q.sequence;
    if (q.recall) j["recall_position"] = q.recall->position.value_or(-1);  // -1 = "the digit of the sequence"
    if (q.nback) j["nback"] = {{"n", q.nback->n}, {"target", q.nback->target}};
  }
  return j;
}

std::string Question::to_json() const { return question_view(*this).dump(); }

std::string stimulus_name(const std::string& label) {
  if (label == "Reference | Rendering") return "the reference (left half) and the rendering (right half)";
  if (label == "Test") return "the test texture";
  if (label == "Reference") return "the reference";
  if (label.size() <= 2) return "texture " + label;
  if (label.rfind("Texture ", 0) == 0) return "t" + label.substr(1);  // "Texture 1" → "texture 1"
  return label;
}

namespace {

ordered_json scale_json(const Scale& s) {
  return {{"min", s.min}, {"max", s.max}, {"question", s.question}, {"min_label", s.min_label}, {"max_label", s.max_label}};
}

// The words the task kind left to the engine: stimulus names, choice labels,
// the scales' defaults, the recall cell in words (front doors never compute it).
void complete_wording(Question& q) {
  Wording& w = q.wording;
  w.stimulus_names.clear();
  for (const auto& s : q.stimuli) w.stimulus_names.push_back(stimulus_name(s.label));
  if (w.choice_labels.size() != q.choices.size()) {
    w.choice_labels.clear();
    for (const auto& c : q.choices) {
      const bool digits = !c.empty() && std::all_of(c.begin(), c.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
      std::string text = digits ? "texture " + c : c;
      if (!digits && !text.empty() && text[0] >= 'a' && text[0] <= 'z') text[0] = static_cast<char>(text[0] - 'a' + 'A');
      w.choice_labels.push_back(text);
    }
  }
  if (!q.choices.empty() && w.choice_question.empty()) w.choice_question = "Your answer";
  if (q.rating_scale && !w.rating)
    w.rating = Scale{static_cast<int>((*q.rating_scale)[0]), static_cast<int>((*q.rating_scale)[1]), "How similar do they feel?",
                     "not at all", "identical"};
  if (q.confidence && !w.confidence) w.confidence = Scale{1, 5, "How confident are you in this match?", "not at all", "very"};
  if (q.recall && !q.sequence.empty()) {
    const auto& at = q.recall->position;
    w.recall = Scale{1, 9,
                     at ? "Which digit was number " + std::to_string(*at + 1) + " of the " + std::to_string(q.sequence.size()) +
                              " in the sequence?"
                        : std::string("Which digit did the sequence show?"),
                     "", ""};
  } else if (q.recall) {
    const auto& cell = q.recall->cell;
    w.recall = Scale{1, 9,
                     cell ? "Which digit was in row " + std::to_string(*cell / 4 + 1) + ", column " +
                                std::to_string(*cell % 4 + 1) + " of the matrix?"
                          : std::string("Which digit was in the cells of the matrix?"),
                     "", ""};
  }
}

}  // namespace

std::string Question::participant_json() const {
  ordered_json j = question_view(*this);
  // Nothing a participant must not know: the block (its name and place give the
  // condition away) and the stimuli's documents (parameters and seeds; a
  // show_maps question's maps are drawn from the rendered maps instead).
  for (const char* key : {"block_index", "block", "trial_in_block", "block_trials"}) j.erase(key);
  for (auto& s : j["stimuli"]) s.erase("document");
  ordered_json w;
  w["stimulus_names"] = wording.stimulus_names;
  w["choice_question"] = wording.choice_question;
  w["choice_labels"] = wording.choice_labels;
  if (wording.rating) w["rating"] = scale_json(*wording.rating);
  if (wording.confidence) w["confidence"] = scale_json(*wording.confidence);
  if (wording.recall) w["recall"] = scale_json(*wording.recall);
  if (!wording.sequence_instruction.empty()) w["sequence_instruction"] = wording.sequence_instruction;
  j["wording"] = std::move(w);
  return j.dump();
}

ordered_json response_view(const Response& r) {
  ordered_json j;
  if (!r.choice.empty()) j["choice"] = r.choice;
  if (r.rating) j["rating"] = *r.rating;
  if (r.confidence) j["confidence"] = *r.confidence;
  if (r.slider_p) j["slider_p"] = *r.slider_p;
  if (r.slider_i) j["slider_i"] = *r.slider_i;
  if (r.digit) j["digit"] = *r.digit;
  if (!r.presses.empty()) j["presses"] = r.presses;
  if (std::isfinite(r.rt_ms)) j["rt_ms"] = r.rt_ms;
  if (r.swipe_mean_speed_mm_s) j["swipe_mean_speed_mm_s"] = *r.swipe_mean_speed_mm_s;
  if (r.swipe_sd_speed_mm_s) j["swipe_sd_speed_mm_s"] = *r.swipe_sd_speed_mm_s;
  if (r.directional_proportion) j["directional_proportion"] = *r.directional_proportion;
  if (!r.swipe_flag.empty()) j["swipe_flag"] = r.swipe_flag;
  if (!r.strokes.empty()) {
    ordered_json list = ordered_json::array();
    const auto number = [](double v) { return std::isfinite(v) ? ordered_json(v) : ordered_json(); };
    for (const auto& i : r.strokes)
      list.push_back({{"stimulus", i.stimulus},
                      {"instructed_deg", number(i.instructed_deg)},
                      {"strokes", i.strokes},
                      {"direction_deg", number(i.direction_deg)},
                      {"straightness", number(i.straightness)},
                      {"deviation_deg", number(i.deviation_deg)},
                      {"mean_speed_mm_s", number(i.mean_speed_mm_s)},
                      {"path_mm", i.path_mm},
                      {"touched_s", i.touched_s},
                      {"tolerance_deg", number(i.tolerance_deg)},
                      {"compliant", i.compliant}});
    j["strokes"] = std::move(list);
  }
  j["shown_at"] = r.shown_at;
  j["answered_at"] = r.answered_at;
  return j;
}

std::string Response::to_json() const { return response_view(*this).dump(); }

json parse_json_text(std::string_view text, std::string_view what) {
  try {
    return json::parse(text);
  } catch (const json::exception&) {
    throw FormatError(std::string(what) + " is not JSON");
  }
}

Response Response::from_json(std::string_view json_text) { return response_from(parse_json_text(json_text, "response")); }

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

// A 2-D display's strokes per interval (strokes.hpp), as response_view writes them.
static std::vector<IntervalStrokes> strokes_from_json(const json& list) {
  if (!list.is_array() || list.size() > 64) throw FormatError("response.strokes must be an array of at most 64 intervals");
  std::vector<IntervalStrokes> out;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& e = list[k];
    const std::string where = "response.strokes[" + std::to_string(k) + "]";
    if (!e.is_object()) throw FormatError(where + " must be an object");
    IntervalStrokes s;
    auto number = [&](const char* key, double lo, double hi) {
      if (!e.contains(key) || e[key].is_null()) return missing;
      if (!e[key].is_number() || !(e[key].get<double>() >= lo && e[key].get<double>() <= hi))
        throw FormatError(where + "." + key + " must be a number in " + detail::num(lo) + " … " + detail::num(hi) + ", got " +
                          e[key].dump());
      return e[key].get<double>();
    };
    for (auto it = e.begin(); it != e.end(); ++it) {
      static const std::set<std::string> keys = {"stimulus",     "instructed_deg", "strokes",         "direction_deg",
                                                 "straightness", "deviation_deg",  "mean_speed_mm_s", "path_mm",
                                                 "touched_s",    "tolerance_deg",  "compliant"};
      if (!keys.count(it.key())) throw FormatError(where + " has unknown key '" + it.key() + "'");
    }
    if (!e.contains("stimulus") || !e["stimulus"].is_string() || e["stimulus"].get_ref<const std::string&>().size() > 64)
      throw FormatError(where + ".stimulus must be a stimulus label");
    s.stimulus = e["stimulus"].get<std::string>();
    s.instructed_deg = number("instructed_deg", 0, 180);
    const double n = number("strokes", 0, 1e9);
    if (std::isfinite(n) && n != std::floor(n)) throw FormatError(where + ".strokes must be a whole number");
    s.strokes = std::isfinite(n) ? static_cast<int>(n) : 0;
    s.direction_deg = number("direction_deg", 0, 180);
    s.straightness = number("straightness", 0, 1);
    s.deviation_deg = number("deviation_deg", 0, 90);
    s.mean_speed_mm_s = number("mean_speed_mm_s", 0, 1e9);
    s.path_mm = std::isfinite(number("path_mm", 0, 1e12)) ? e["path_mm"].get<double>() : 0.0;
    s.touched_s = std::isfinite(number("touched_s", 0, 1e9)) ? e["touched_s"].get<double>() : 0.0;
    s.tolerance_deg = number("tolerance_deg", 0, 90);
    if (e.contains("compliant") && !e["compliant"].is_boolean()) throw FormatError(where + ".compliant must be true or false");
    s.compliant = e.value("compliant", false);
    out.push_back(std::move(s));
  }
  return out;
}

Response response_from(const json& j) {
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
                                              "presses",
                                              "rt_ms",
                                              "swipe_mean_speed_mm_s",
                                              "swipe_sd_speed_mm_s",
                                              "directional_proportion",
                                              "swipe_flag",
                                              "shown_at",
                                              "answered_at",
                                              "events",
                                              "strokes"};
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
  if (j.contains("presses") && !j["presses"].is_null()) {
    const json& p = j["presses"];
    if (!p.is_array() || p.size() > 1000) throw FormatError("response.presses must be an array of at most 1000 item indices");
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!p[k].is_number_integer() || p[k].get<long long>() < 0 || p[k].get<long long>() > 1000)
        throw FormatError("response.presses[" + std::to_string(k) + "] is " + p[k].dump() +
                          "; allowed: a whole number 0 … 1000 (a sequence item)");
      r.presses.push_back(p[k].get<int>());
    }
  }
  if (auto rt = opt("rt_ms")) r.rt_ms = *rt;
  r.swipe_mean_speed_mm_s = opt("swipe_mean_speed_mm_s");
  r.swipe_sd_speed_mm_s = opt("swipe_sd_speed_mm_s");
  r.directional_proportion = opt("directional_proportion");
  if (j.contains("swipe_flag") && !j["swipe_flag"].is_null()) {
    if (!j["swipe_flag"].is_string()) throw FormatError("response.swipe_flag must be a string, got " + j["swipe_flag"].dump());
    r.swipe_flag = j["swipe_flag"].get<std::string>();
  }
  if (j.contains("shown_at") && j["shown_at"].is_string()) r.shown_at = j["shown_at"].get<std::string>();
  if (j.contains("answered_at") && j["answered_at"].is_string()) r.answered_at = j["answered_at"].get<std::string>();
  if (j.contains("events") && !j["events"].is_null()) r.events = events_from_json(j["events"]);
  if (j.contains("strokes") && !j["strokes"].is_null()) r.strokes = strokes_from_json(j["strokes"]);
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

struct Session::Impl : SessionCore {
  bool done = false;
  std::unique_ptr<TaskBlock> run;  // the current block's task
  Question question;
  TrialTruth truth;

  Impl(Protocol p, SessionContext c) : SessionCore(std::move(p), std::move(c)) { start_block(); }

  void start_block() {
    if (block_index >= static_cast<int>(protocol.blocks.size())) {
      done = true;
      run.reset();
      return;
    }
    trial_in_block = 0;
    run = task_type(block().task).start(*this);
    prepare();
  }

  // The current question: the common header, then the task's part.
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
    run->prepare(*this, q, t);
    complete_wording(q);
    question = std::move(q);
    truth = std::move(t);
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
    row.task = b.task;
    row.condition = truth.condition;
    row.reference = truth.reference;
    row.correct_answer = truth.correct_answer;
    row.rt_ms = r.rt_ms;
    row.shown_at = r.shown_at.empty() ? utc_timestamp() : r.shown_at;
    row.answered_at = r.answered_at.empty() ? utc_timestamp() : r.answered_at;
    if (r.swipe_mean_speed_mm_s) row.swipe_mean_speed_mm_s = *r.swipe_mean_speed_mm_s;
    if (r.swipe_sd_speed_mm_s) row.swipe_sd_speed_mm_s = *r.swipe_sd_speed_mm_s;
    if (r.directional_proportion) row.directional_proportion = *r.directional_proportion;
    row.swipe_flag = r.swipe_flag;
    fill_swipe_columns(r.trace, row);
    fill_stroke_columns(r.strokes, q.stimuli.size(), row);
    require(!(std::isfinite(r.rt_ms) && r.rt_ms < 0), "rt_ms is " + texel::detail::num(r.rt_ms) + "; allowed: >= 0 ms");
    if (!q.choices.empty()) {
      require(std::find(q.choices.begin(), q.choices.end(), r.choice) != q.choices.end(),
              "choice is '" + r.choice + "'; allowed: " + joined(q.choices));
      row.response = r.choice;
    }
    const std::string state = run->answer(*this, q, truth, r, row);

    StoredTrial st;
    st.trial = trial;
    ordered_json qj;
    qj["question"] = question_view(q);
    ordered_json tj;
    tj["correct_answer"] = truth.correct_answer;
    if (std::isfinite(truth.intensity)) tj["intensity"] = truth.intensity;
    tj["reference"] = truth.reference;
    tj["condition"] = truth.condition;
    if (truth.rendering)
      tj["rendering"] = {{"pitch_db", truth.rendering->pitch_db}, {"irregularity_db", truth.rendering->irregularity_db}};
    qj["truth"] = tj;
    st.question_json = qj.dump();
    ordered_json rv = response_view(r);
    if (r.trace.source == TraceSource::display || r.trace.source == TraceSource::pointer) {
      // The stored answer shows what the trial's finger measured, not what a front end claimed.
      for (const char* k : {"swipe_mean_speed_mm_s", "swipe_sd_speed_mm_s", "directional_proportion", "swipe_flag"}) rv.erase(k);
      if (std::isfinite(row.swipe_mean_speed_mm_s)) {
        rv["swipe_mean_speed_mm_s"] = row.swipe_mean_speed_mm_s;
        rv["swipe_sd_speed_mm_s"] = row.swipe_sd_speed_mm_s;
        rv["directional_proportion"] = row.directional_proportion;
      }
      if (!row.swipe_flag.empty()) rv["swipe_flag"] = row.swipe_flag;
    }
    st.response_json = rv.dump();
    st.state_json = state;
    st.events = r.events;
    st.trace = r.trace;
    st.row = std::move(row);

    // Advance.
    ++trial;
    ++trial_in_block;
    if (run->finished(*this)) {
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
  auto doc = impl_->run->preview(*impl_, q, impl_->truth, slider_p, slider_i);
  if (!doc) throw Error("preview_document: the current question is not a match");
  return std::move(*doc);
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
  if (!stored.contains("question") || json(question_view(impl_->question)) != stored["question"])
    throw FormatError("stored trial " + std::to_string(t.trial) +
                      " was asked differently (another protocol, seed or Texel version); cannot resume this session");
  Response r;
  try {
    r = response_from(json::parse(t.response_json));
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
