// Oddity over 2-D renderings (docs/experiments.md "2-D studies"): three
// intervals, each a texture swiped along a straight line in one of the
// 2-D modes (docs/algorithm.md §11) or the 1-D original; two come from the
// condition's "pair" view (swiped along its two directions), one from its
// "odd" view (a different texture, or another rendering of the same one).
// The participant picks the odd one.
//
// Presentation [choice]: every interval is a 1-D stimulus document, so the
// terminal runner, the studio and the simulated observers present and
// perceive it as any 1-D stimulus. A 2-D rendering swiped along θ becomes the
// amplitude the finger meets on that line, sampled on the protocol device's
// 1-D grid and stored as the texture's coarse profile (coarse strength 1,
// fine strength 0, so the map is that amplitude exactly):
//   path-indexed  the 2-D player's path-indexed map at path length s
//                 (PlayerMap2D::value), the same along every direction;
//   spectral / cells / oriented
//                 the static field of a version-4 document on the device's
//                 bitmap (Surface2D::amplitude) along the line of direction
//                 θ through the surface's centre;
//   1d            the 1-D texture document itself.
// On a 2-D display the participant strokes the interval instead: each
// stimulus also has its surface (Question::surfaces: the version-4 document
// and the direction to stroke along; presenter.hpp), which the question's
// stored JSON does not carry.
// No interval is a copy of another: path-indexed and 1-D intervals each have
// their own texture seed; a static field (spectral, cells, oriented) is one
// field per condition and view in a session, like one bitmap on the display,
// and each interval is a line of it through its own random point within
// (side − display_mm)/2 of the surface's centre. Only the texture, the mode
// and the direction tell the intervals apart. Which interval is swiped along
// which of the condition's two directions: DirectionAssignment (balanced
// from protocol version 3, so the directions never point at the odd one).
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>

#include "../prepared_surfaces.hpp"
#include "../task.hpp"
#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/player2d.hpp"
#include "texel/surface2d.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using nlohmann::json;

constexpr const char* kind_name = "oddity-2d";
constexpr std::string_view modes[] = {"1d", "path-indexed", "spectral", "cells", "oriented"};

// How one interval is rendered.
struct View {
  std::string mode = "path-indexed";
  double orientation_deg = 0.0;  // oriented: the grating's wave vector
  double pitch_shift_db = 0.0;   // added to the texture's Central Pitch
  double irregularity_shift_db = 0.0;
};

struct Condition2D {
  std::string name;
  View pair, odd;
  double directions_deg[2] = {0.0, 0.0};  // the pair's two swipes; the odd one takes one of them
};

// Which interval is swiped along which of a condition's two directions
// (docs/experiments.md "2-D studies", "Directions").
enum class DirectionAssignment {
  // Versions 1–2: the pair along its two directions, the odd interval along
  // one of them (drawn). The one interval with a direction of its own is
  // always a pair member: a participant told the directions can rule it out.
  pair_spans,
  // Version 3: one interval, drawn uniformly, is swiped along one of the two
  // directions (drawn), the other two along the other. Whether that interval
  // is the odd one is independent of it (1 in 3), so the directions tell
  // nothing about which interval is odd.
  balanced,
};

struct Oddity2DSettings : TaskSettings {
  std::vector<Condition2D> conditions;
  int trials_per_condition = 10;
  DirectionAssignment directions = DirectionAssignment::balanced;
};

const Oddity2DSettings& settings_of(const Block& b) { return static_cast<const Oddity2DSettings&>(*b.settings); }

View parse_view(JsonObject o, bool pair, double directions[2]) {
  View v;
  v.mode = o.string("mode");
  if (std::find(std::begin(modes), std::end(modes), v.mode) == std::end(modes))
    throw FormatError(o.field("mode") + " is '" + v.mode + "'; allowed: 1d, path-indexed, spectral, cells, oriented");
  if (v.mode == "oriented")
    v.orientation_deg = o.number_or("orientation_deg", 0.0, -360.0, 360.0);
  else if (o.has("orientation_deg"))
    throw FormatError(o.field("orientation_deg") + " applies to mode 'oriented' only");
  else
    o.skip("orientation_deg");
  v.pitch_shift_db = o.number_or("pitch_shift_db", 0.0, -20.0, 20.0);
  v.irregularity_shift_db = o.number_or("irregularity_shift_db", 0.0, -20.0, 20.0);
  if (pair) {
    const auto& d = o.raw("directions_deg");
    if (!d.is_array() || d.size() != 2 || !d[0].is_number() || !d[1].is_number())
      throw FormatError(o.field("directions_deg") + " must be two numbers (degrees)");
    for (int k = 0; k < 2; ++k) {
      directions[k] = d[static_cast<std::size_t>(k)].get<double>();
      if (!(std::abs(directions[k]) <= 360.0))
        throw FormatError(o.field("directions_deg") + "[" + std::to_string(k) + "] is " + detail::num(directions[k]) +
                          "; allowed: -360 … 360");
    }
  } else if (o.has("directions_deg")) {
    throw FormatError(o.field("directions_deg") + " applies to the pair only (the odd interval takes one of the pair's)");
  } else {
    o.skip("directions_deg");
  }
  o.finish();
  return v;
}

// The smallest angle between two swipe directions (a line has no sign): 0 … 90°.
double direction_difference(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 180.0);
  return std::min(d, 180.0 - d);
}

// Prepared static fields of a block, by their version-4 document's text:
// preparing a spectral field (its radial spectrum) costs far more than
// scanning it. They come from the process's prepared surfaces, which the
// 2-D display presenter renders its bitmaps from and preloads.
using FieldCache = std::map<std::string, std::shared_ptr<const Surface2D>>;

// Where an interval's line is centred, relative to the surface's centre (mm).
struct Offset {
  double x = 0.0, y = 0.0;
};

// The interval's texture (1-D, as a JSON object) and, for 2-D modes, its scan.
class Renderer {
 public:
  Renderer(const SessionCore& s, const Block& b, FieldCache& fields) : s_(s), b_(b), fields_(fields) {}

  // The interval: its 1-D stimulus document (the scan along the swipe) and,
  // for a 2-D display, the surface the participant strokes along θ.
  std::pair<Stimulus, SurfaceStimulus> stimulus(const std::string& label, const View& v, double direction_deg, std::uint64_t seed,
                                                Offset offset = {}) const {
    json tex = texel_texture(texture_of(b_.texture), seed);
    tex["seed"] = seed;  // also over a template's own seed: no two intervals are copies
    tex["central_pitch_db"] = tex.value("central_pitch_db", 0.0) + v.pitch_shift_db;
    tex["irregularity_db"] = tex.value("irregularity_db", 0.0) + v.irregularity_shift_db;
    // On a 2-D display a 1-D original is the texture along the finger's
    // path, which is what the path-indexed mode plays.
    const std::string surface = surface_document(v, tex);
    std::pair<Stimulus, SurfaceStimulus> out{
        Stimulus{label, {}},
        SurfaceStimulus{static_field(v) ? SurfaceStimulus::Kind::bitmap : SurfaceStimulus::Kind::path_indexed, surface,
                        direction_deg}};
    if (v.mode == "1d") {
      out.first.document_json = s_.single(tex, b_.display_mm);
      return out;
    }
    const std::vector<double> amplitude = scan(v, direction_deg, surface, offset);
    // A map that is the scan: a = c (coarse strength 1, fine strength 0).
    // The renderer takes c once per texel, at the texel's centre: texels of
    // an eighth of a sample, with the points shifted by half a texel, give
    // every sample its scan value exactly.
    const double dx = s_.device.spacing.value(), texel = dx / 8;
    json carrier = tex;
    carrier["coarse_strength"] = 1.0;
    carrier["fine_strength"] = 0.0;
    carrier["texel_length_mm"] = texel;
    json points = json::array();
    for (std::size_t i = 0; i < amplitude.size(); ++i)
      points.push_back({std::round((static_cast<double>(i) * dx + texel / 2) * 1e6) / 1e6, std::round(amplitude[i] * 1e5) / 1e5});
    carrier["coarse"] = {{"kind", "points"}, {"points", std::move(points)}};
    out.first.document_json = s_.single(carrier, b_.display_mm);
    return out;
  }

  static bool static_field(const View& v) { return v.mode == "spectral" || v.mode == "cells" || v.mode == "oriented"; }

 private:
  // A version-4 document of one region over the whole display: the texture
  // in the view's field (a path-indexed or 1-D view names "spectral", which
  // only the static-field modes read).
  std::string surface_document(const View& v, const json& tex) const {
    json region = {{"name", "surface"}, {"x_mm", 0.0}, {"y_mm", 0.0}, {"texture", tex}};
    region["field"] = static_field(v) ? v.mode : "spectral";
    if (v.mode == "oriented") region["orientation_deg"] = v.orientation_deg;
    const json doc_json = {{"format", "texel-document"},
                           {"version", 4},
                           {"device", s_.protocol.device},
                           {"surface2d", {{"regions", json::array({region})}}}};
    return doc_json.dump();
  }

  // The amplitude along the swipe: samples at the device's 1-D spacing over
  // display_mm, on the line of direction θ through the surface's centre.
  std::vector<double> scan(const View& v, double direction_deg, const std::string& doc_text, Offset offset) const {
    const BitmapGeometry& g = *s_.device.bitmap;
    const double dx = s_.device.spacing.value(), length = b_.display_mm;
    const auto n = static_cast<std::size_t>(std::floor(length / dx + 1e-9)) + 1;
    const double th = direction_deg * std::numbers::pi / 180.0, ux = std::cos(th), uy = std::sin(th);
    const double cx = g.width_mm().value() / 2 + offset.x, cy = g.height_mm().value() / 2 + offset.y;
    const Document doc = parse_document(doc_text, "stimulus");
    std::vector<double> out(n);
    if (v.mode == "path-indexed") {
      const auto map = PlayerMap2D::path_indexed(doc.surface2d->regions[0].texel, Sampling{doc.device.grid(), CyclesPerMm(0.0)},
                                                 std::nullopt, Extent2D{0.0, 0.0, g.width_mm().value(), g.height_mm().value()});
      for (std::size_t i = 0; i < n; ++i) {
        const double u = static_cast<double>(i) * dx;
        out[i] = map->value(cx + (u - length / 2) * ux, cy + (u - length / 2) * uy, u, 0.0, 1e12);
      }
    } else {
      auto it = fields_.find(doc_text);
      if (it == fields_.end()) it = fields_.emplace(doc_text, prepared_surface(doc_text)).first;
      const Surface2D& surface = *it->second;
      for (std::size_t i = 0; i < n; ++i) {
        const double u = static_cast<double>(i) * dx;
        out[i] = surface.amplitude(cx + (u - length / 2) * ux, cy + (u - length / 2) * uy);
      }
    }
    return out;
  }

  const SessionCore& s_;
  const Block& b_;
  FieldCache& fields_;
};

class Oddity2DBlock : public TaskBlock {
 public:
  explicit Oddity2DBlock(const SessionCore& s) {
    const Oddity2DSettings& st = settings_of(s.block());
    for (int i = 0; i < static_cast<int>(st.conditions.size()); ++i)
      for (int r = 0; r < st.trials_per_condition; ++r) plan_.push_back(i);
    if (s.block().shuffle) s.shuffle(plan_);
  }

  void prepare(const SessionCore& s, Question& q, TrialTruth& t) override {
    const Block& b = s.block();
    const Oddity2DSettings& st = settings_of(b);
    q.block_trials = static_cast<int>(plan_.size());
    const Condition2D& c = st.conditions[static_cast<std::size_t>(plan_[static_cast<std::size_t>(s.trial_in_block)])];
    t.condition = c.name;
    t.reference = c.pair.mode;  // exported as `reference`: the analysis compares conditions of one mode
    t.intensity = direction_difference(c.directions_deg[0], c.directions_deg[1]);
    const auto odd = static_cast<int>(s.trial_below(3, 3));
    const std::array<double, 3> direction = directions(st.directions, c, odd, s);
    const Renderer render(s, b, fields_);
    const BitmapGeometry& g = *s.device.bitmap;
    const double radius = (std::min(g.width_mm().value(), g.height_mm().value()) - b.display_mm) / 2;
    const auto condition = static_cast<std::uint64_t>(plan_[static_cast<std::size_t>(s.trial_in_block)]);
    for (int i = 0; i < 3; ++i) {
      const bool is_odd = i == odd;
      const View& v = is_odd ? c.odd : c.pair;
      const auto k = static_cast<std::uint64_t>(i);
      std::uint64_t seed = s.seed_draw(k);
      Offset offset;
      if (Renderer::static_field(v)) {  // one field per (block, condition, view); a random line of it
        seed =
            s.order_rng.bits(draw_counter(static_cast<std::uint64_t>(s.block_index), 1000 + 2 * condition + (is_odd ? 1 : 0))) >>
            11;
        const double r = radius * std::sqrt(s.trial_rng.uniform(draw_counter(static_cast<std::uint64_t>(s.trial), 8 + 2 * k)));
        const double phi =
            2 * std::numbers::pi * s.trial_rng.uniform(draw_counter(static_cast<std::uint64_t>(s.trial), 9 + 2 * k));
        offset = {r * std::cos(phi), r * std::sin(phi)};
      }
      auto [stimulus, surface] = render.stimulus(std::to_string(i + 1), v, direction[static_cast<std::size_t>(i)], seed, offset);
      q.stimuli.push_back(std::move(stimulus));
      q.surfaces.push_back(std::move(surface));
    }
    ask_oddity(b, odd, q, t);
  }

  std::string answer(SessionCore& s, const Question&, const TrialTruth& t, const Response& r, TrialRow& row) override {
    row.correct = r.choice == t.correct_answer ? 1.0 : 0.0;
    row.variable = "direction_difference_deg";
    row.intensity = t.intensity;
    row.procedure_finished = s.trial_in_block + 1 >= static_cast<int>(plan_.size());
    return {};
  }

  bool finished(const SessionCore& s) const override { return s.trial_in_block >= static_cast<int>(plan_.size()); }

 private:
  // Each interval's swipe direction, the odd interval being `odd`.
  static std::array<double, 3> directions(DirectionAssignment how, const Condition2D& c, int odd, const SessionCore& s) {
    const std::uint64_t drawn = s.trial_below(4, 2);  // pair_spans: the odd one's; balanced: the lone interval's
    std::array<double, 3> out{};
    if (how == DirectionAssignment::pair_spans) {
      int next_pair = 0;
      for (int i = 0; i < 3; ++i)
        out[static_cast<std::size_t>(i)] = i == odd ? c.directions_deg[drawn] : c.directions_deg[next_pair++];
      return out;
    }
    const std::uint64_t lone = s.trial_below(5, 3);
    for (std::uint64_t i = 0; i < 3; ++i) out[i] = c.directions_deg[i == lone ? drawn : 1 - drawn];
    return out;
  }

  std::vector<int> plan_;  // condition index per trial
  FieldCache fields_;
};

class Oddity2DTask : public TaskType {
 public:
  std::string_view name() const override { return kind_name; }
  std::vector<std::string_view> keys() const override {
    return {"texture", "display_mm", "time_limit_s", "conditions", "trials_per_condition", "direction_assignment"};
  }

  void parse(BlockInput& in, Block& b) const override {
    JsonObject& o = in.o;
    const DeviceProfile device = load_device(in.device);
    if (!device.bitmap)
      throw FormatError("device is '" + in.device + "', which has no bitmap grid; task '" + std::string(kind_name) +
                        "' needs a 2-D display profile (e.g. tablet-2d)");
    b.texture = in.texture("texture");
    const json tex = texture_of(b.texture);
    if (tex.value("kind", std::string("texel")) != "texel" || tex.contains("coarse"))
      throw FormatError(o.field("texture") + " must be a texel texture without a coarse profile (task '" +
                        std::string(kind_name) + "')");
    const double side = std::min(device.bitmap->width_mm().value(), device.bitmap->height_mm().value());
    b.display_mm = o.number_or("display_mm", std::min(100.0, side), 1.0, std::min(side, device.length().value()));
    b.time_limit_s = o.number_or("time_limit_s", 30.0, 0.0, 3600.0);
    auto st = std::make_shared<Oddity2DSettings>();
    st->trials_per_condition = static_cast<int>(o.integer("trials_per_condition", 1, 1000));
    // Version 3 made the balanced assignment the default; earlier protocols
    // keep the design (and the trials) they were run with.
    const std::string assignment = o.string_or("direction_assignment", in.version >= 3 ? "balanced" : "pair-spans");
    if (assignment == "balanced")
      st->directions = DirectionAssignment::balanced;
    else if (assignment == "pair-spans")
      st->directions = DirectionAssignment::pair_spans;
    else
      throw FormatError(o.field("direction_assignment") + " is '" + assignment + "'; allowed: balanced, pair-spans");
    const auto& list = o.raw("conditions");
    if (!list.is_array() || list.empty() || list.size() > 64)
      throw FormatError(o.field("conditions") + " must be an array of 1 … 64 conditions");
    for (std::size_t i = 0; i < list.size(); ++i) {
      JsonObject c(list[i], o.field("conditions") + "[" + std::to_string(i) + "]");
      Condition2D cond;
      cond.name = c.string("name");
      if (cond.name.empty() || cond.name.size() > 64) throw FormatError(c.field("name") + " must have 1 … 64 characters");
      for (const auto& other : st->conditions)
        if (other.name == cond.name) throw FormatError(c.field("name") + " '" + cond.name + "' is used twice");
      cond.pair = parse_view(JsonObject(c.raw("pair"), c.field("pair")), true, cond.directions_deg);
      double unused[2];
      cond.odd = parse_view(JsonObject(c.raw("odd"), c.field("odd")), false, unused);
      c.finish();
      st->conditions.push_back(std::move(cond));
    }
    b.settings = std::move(st);
  }

  std::optional<int> planned_trials(const Block& b) const override {
    const Oddity2DSettings& st = settings_of(b);
    return static_cast<int>(st.conditions.size()) * st.trials_per_condition;
  }

  std::unique_ptr<TaskBlock> start(const SessionCore& s) const override { return std::make_unique<Oddity2DBlock>(s); }

  // The observer perceives each interval's vibration through the encoder's
  // perceptual model (perceive_document) and picks the odd one with the
  // matcher's noise (Matcher::odd_one). An interval without fine texture
  // (e.g. a grating swiped along its ridges) is perceived at the bottom of
  // the Central Pitch range (−20 dB): unlike any texture.
  void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const override {
    const Question& q = session.question();
    std::vector<MatchPoint> perceived;
    const double length = session.protocol().blocks[static_cast<std::size_t>(q.block_index)].display_mm;
    for (const Stimulus& st : q.stimuli)
      perceived.push_back(perceive_document(st.document_json, length).value_or(MatchPoint{-20.0, 0.0}));
    const std::size_t odd = who.matcher(MatchResult{}, session).odd_one(perceived, static_cast<std::uint64_t>(q.trial));
    r.choice = q.choices[odd];
  }

  std::vector<std::string_view> columns() const override {
    return {"response", "correct_answer", "correct", "condition", "reference", "variable", "intensity", "procedure_finished"};
  }
};

}  // namespace

std::unique_ptr<TaskType> make_oddity_2d_task() { return std::make_unique<Oddity2DTask>(); }

}  // namespace texel::experiment
