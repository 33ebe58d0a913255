// Protocol parsing and validation (docs/experiments.md).
#include "texel/experiment/protocol.hpp"

#include <algorithm>
#include <set>

#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/io.hpp"
#include "texel/reference.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using detail::num;
using nlohmann::json;

constexpr std::size_t max_blocks = 256;
constexpr std::size_t max_list = 4096;

// Texture keys a staircase (or a fixed value) may set, with their ranges.
struct Variable {
  std::string_view key;
  double lo, hi;
};
constexpr Variable variables[] = {
    {"texel_length_mm", 1e-3, 1000.0}, {"central_pitch_db", -40.0, 40.0}, {"irregularity_db", -60.0, 40.0},
    {"coarse_strength", 0.0, 1.0},     {"fine_strength", 0.0, 1.0},       {"quantization_db", 0.0, 20.0},
};

const Variable* find_variable(std::string_view key) {
  for (const auto& v : variables)
    if (v.key == key) return &v;
  return nullptr;
}

std::string variable_names() {
  std::string s;
  for (const auto& v : variables) s += (s.empty() ? "" : ", ") + std::string(v.key);
  return s;
}

// Validates a texture object by parsing a one-region document around it (the
// document parser is the single source of truth for texture fields). A
// missing seed is allowed: the engine draws one per trial.
void check_texture(const json& texture, const std::string& device, const std::string& path) {
  if (!texture.is_object()) throw FormatError(path + " must be a texture object ({\"kind\": \"texel\", …})");
  json t = texture;
  const bool texel_kind = !t.contains("kind") || (t["kind"].is_string() && t["kind"].get<std::string>() == "texel");
  if (texel_kind && !t.contains("seed")) t["seed"] = 1;
  json doc = {{"format", "texel-document"}, {"version", 2}, {"device", device}, {"texture", t}};
  try {
    (void)parse_document(doc.dump(), path);
  } catch (const Error& e) {
    // The document parser names "texture.x"; re-anchor at the protocol path.
    std::string msg = e.what();
    const std::string prefix = path + ": ";
    throw FormatError(msg.rfind(prefix, 0) == 0 ? path + " (texture) " + msg.substr(prefix.size()) : msg);
  }
}

void check_reference(const std::string& name, const std::string& path) {
  try {
    (void)reference_info(name);
  } catch (const Error&) {
    std::string known;
    for (const auto& r : reference_catalogue()) known += (known.empty() ? "" : ", ") + r.name;
    throw FormatError(path + " is '" + name + "'; allowed: a reference texture (" + known + ")");
  }
}

std::vector<std::string> string_list(JsonObject& o, std::string_view key, std::size_t min_count) {
  const auto& v = o.raw(key);
  if (!v.is_array()) throw FormatError(o.field(key) + " must be an array of strings");
  if (v.size() < min_count || v.size() > max_list)
    throw FormatError(o.field(key) + " has " + std::to_string(v.size()) + " entries; allowed: " + std::to_string(min_count) +
                      " … " + std::to_string(max_list));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_string()) throw FormatError(o.field(key) + "[" + std::to_string(i) + "] must be a string");
    out.push_back(v[i].get<std::string>());
  }
  return out;
}

StaircaseConfig parse_staircase(JsonObject o, Block& b) {
  StaircaseConfig c;
  b.variable = o.string("variable");
  const Variable* var = find_variable(b.variable);
  if (!var) throw FormatError(o.field("variable") + " is '" + b.variable + "'; allowed: " + variable_names());
  c.start_value = o.number("start", var->lo, var->hi);
  const auto& steps = o.raw("step_sizes");
  if (steps.is_number()) {
    c.step_sizes = {steps.get<double>()};
  } else if (steps.is_array() && !steps.empty() && steps.size() <= max_list) {
    c.step_sizes.clear();
    for (std::size_t i = 0; i < steps.size(); ++i) {
      if (!steps[i].is_number()) throw FormatError(o.field("step_sizes") + "[" + std::to_string(i) + "] must be a number");
      c.step_sizes.push_back(steps[i].get<double>());
    }
  } else {
    throw FormatError(o.field("step_sizes") + " must be a number or a non-empty array of numbers");
  }
  c.n_up = static_cast<int>(o.integer("n_up", 1, 100));
  c.n_down = static_cast<int>(o.integer("n_down", 1, 100));
  if (o.has("n_reversals"))
    c.n_reversals = static_cast<int>(o.integer("n_reversals", 1, 10000));
  else
    o.skip("n_reversals");
  c.n_trials = static_cast<int>(o.has("n_trials") ? o.integer("n_trials", 0, 100000) : (o.skip("n_trials"), 0));
  c.step_type = parse_step_type(o.string_or("step_type", "lin"), o.field("step_type"));
  c.min_value = o.number_or("min", var->lo, var->lo, var->hi);
  c.max_value = o.number_or("max", var->hi, var->lo, var->hi);
  c.apply_initial_rule = o.boolean_or("apply_initial_rule", true);
  o.finish();
  try {
    validate(c);
  } catch (const Error& e) {
    throw FormatError(o.path() + ": " + e.what());
  }
  return c;
}

RenderingSource parse_rendering(JsonObject o, const std::string& device) {
  RenderingSource r;
  if (o.has("texture")) {
    r.texture = o.raw("texture");
    check_texture(r.texture, device, o.field("texture"));
  } else {
    o.skip("texture");
  }
  r.match_of = o.string_or("match_of", "");
  r.from_block = o.string_or("from_block", "");
  r.from_protocol = o.string_or("from_protocol", "");
  r.quantization_db = o.number_or("quantization_db", 0.0, 0.0, 20.0);
  o.finish();
  if (r.texture.is_null() && r.match_of.empty())
    throw FormatError(o.where() + " needs \"texture\" or \"match_of\" (with \"from_block\" or \"from_protocol\")");
  if (!r.match_of.empty() && r.from_block.empty() && r.from_protocol.empty())
    throw FormatError(o.where() + ": \"match_of\" needs \"from_block\" or \"from_protocol\"");
  if (!r.from_protocol.empty() && r.texture.is_null())
    throw FormatError(o.where() +
                      ": \"from_protocol\" needs a fallback \"texture\" (used when the participant has no such match)");
  return r;
}

Block parse_block(JsonObject o, const std::string& device) {
  Block b;
  b.name = o.string("name");
  if (b.name.empty() || b.name.size() > 64) throw FormatError(o.field("name") + " must be 1 … 64 characters");
  b.task = parse_task_kind(o.string("task"), o.field("task"));
  b.practice = o.boolean_or("practice", false);
  b.condition = o.string_or("condition", "");
  b.prompt = o.string_or("prompt", "");
  b.shuffle = o.boolean_or("shuffle", true);

  auto need_texture = [&] {
    b.texture = o.raw("texture");
    check_texture(b.texture, device, o.field("texture"));
  };
  auto no = [&](std::initializer_list<std::string_view> keys) {
    for (auto k : keys) {
      if (o.has(k)) throw FormatError(o.field(k) + " does not apply to task '" + std::string(to_string(b.task)) + "'");
      o.skip(k);
    }
  };

  switch (b.task) {
    case TaskKind::oddity:
    case TaskKind::two_alternative: {
      need_texture();
      b.display_mm = o.number_or("display_mm", 0.0, 0.0, 1e6);
      b.time_limit_s = o.number_or("time_limit_s", b.task == TaskKind::oddity ? 30.0 : 0.0, 0.0, 3600.0);
      b.show_maps = o.boolean_or("show_maps", false);
      if (o.has("staircase")) {
        b.staircase = parse_staircase(JsonObject(o.raw("staircase"), o.field("staircase")), b);
        no({"trials", "variable", "value"});
      } else {
        o.skip("staircase");
        b.trials = static_cast<int>(o.integer("trials", 1, 10000));
        b.variable = o.string("variable");
        const Variable* var = find_variable(b.variable);
        if (!var) throw FormatError(o.field("variable") + " is '" + b.variable + "'; allowed: " + variable_names());
        b.fixed_value = o.number("value", var->lo, var->hi);
      }
      if (b.task == TaskKind::two_alternative) {
        b.references = string_list(o, "references", 2);
        if (b.references.size() != 2) throw FormatError(o.field("references") + " must name exactly two references (A, B)");
        for (std::size_t i = 0; i < 2; ++i)
          check_reference(b.references[i], o.field("references") + "[" + std::to_string(i) + "]");
      } else {
        no({"references"});
      }
      no({"sliders", "confidence", "scale", "pairs", "optimizer", "conditions", "stimuli"});
      break;
    }
    case TaskKind::match: {
      need_texture();
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
      no({"staircase", "pairs", "optimizer", "conditions", "stimuli", "scale", "display_mm", "trials"});
      break;
    }
    case TaskKind::rating: {
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
        rp.rendering = parse_rendering(JsonObject(p.raw("rendering"), p.field("rendering")), device);
        rp.condition = p.string_or("condition", "");
        p.finish();
        b.pairs.push_back(std::move(rp));
      }
      no({"staircase", "optimizer", "conditions", "stimuli", "references", "sliders", "display_mm", "trials", "texture"});
      break;
    }
    case TaskKind::guided: {
      need_texture();
      b.references = string_list(o, "references", 1);
      for (std::size_t i = 0; i < b.references.size(); ++i)
        check_reference(b.references[i], o.field("references") + "[" + std::to_string(i) + "]");
      JsonObject opt(o.raw("optimizer"), o.field("optimizer"));
      b.optimizer = opt.string("kind");
      if (b.optimizer != "guided" && b.optimizer != "bayesian")
        throw FormatError(opt.field("kind") + " is '" + b.optimizer + "'; allowed: guided, bayesian");
      b.optimizer_params = o.raw("optimizer");
      b.optimizer_params.erase("kind");
      try {
        (void)make_optimizer(b.optimizer, b.optimizer_params);
      } catch (const Error& e) {
        throw FormatError(o.field("optimizer") + ": " + e.what());
      }
      no({"staircase", "pairs", "conditions", "stimuli", "scale", "sliders", "display_mm", "trials"});
      break;
    }
    case TaskKind::same_different: {
      const auto& stimuli = o.raw("stimuli");
      if (!stimuli.is_object() || stimuli.empty())
        throw FormatError(o.field("stimuli") + " must be an object of named stimuli {\"texture\", \"different\"}");
      for (auto it = stimuli.begin(); it != stimuli.end(); ++it) {
        JsonObject s(it.value(), o.field("stimuli") + "." + it.key());
        MemoryStimulus ms;
        ms.name = it.key();
        ms.texture = s.raw("texture");
        check_texture(ms.texture, device, s.field("texture"));
        ms.different = s.raw("different");
        check_texture(ms.different, device, s.field("different"));
        s.finish();
        b.memory_stimuli.push_back(std::move(ms));
      }
      const auto& conds = o.raw("conditions");
      if (!conds.is_array() || conds.empty() || conds.size() > 64)
        throw FormatError(o.field("conditions") + " must be a non-empty array of {name, stimulus, distractor}");
      for (std::size_t i = 0; i < conds.size(); ++i) {
        JsonObject c(conds[i], o.field("conditions") + "[" + std::to_string(i) + "]");
        MemoryCondition mc;
        mc.name = c.string("name");
        mc.stimulus = c.string("stimulus");
        if (std::none_of(b.memory_stimuli.begin(), b.memory_stimuli.end(), [&](const auto& s) { return s.name == mc.stimulus; }))
          throw FormatError(c.field("stimulus") + " is '" + mc.stimulus + "'; allowed: a key of " + o.field("stimuli"));
        mc.distractor = c.boolean_or("distractor", true);
        c.finish();
        b.conditions.push_back(std::move(mc));
      }
      b.trials_per_condition = static_cast<int>(o.integer("trials_per_condition", 1, 1000));
      b.texture_s = o.number_or("texture_s", 10.0, 0.0, 600.0);
      b.matrix_s = o.number_or("matrix_s", 10.0, 0.0, 600.0);
      b.matrix_cells = static_cast<int>(o.has("matrix_cells") ? o.integer("matrix_cells", 1, 9) : (o.skip("matrix_cells"), 5));
      b.recall_question = o.boolean_or("recall_question", true);
      no({"staircase", "pairs", "optimizer", "references", "scale", "sliders", "display_mm", "trials", "texture"});
      break;
    }
  }
  o.finish();
  return b;
}

}  // namespace

std::string_view to_string(TaskKind t) {
  switch (t) {
    case TaskKind::oddity: return "oddity";
    case TaskKind::two_alternative: return "two-alternative";
    case TaskKind::match: return "match";
    case TaskKind::rating: return "rating";
    case TaskKind::guided: return "guided";
    case TaskKind::same_different: return "same-different";
  }
  return "?";
}

TaskKind parse_task_kind(std::string_view text, std::string_view field) {
  for (auto t : {TaskKind::oddity, TaskKind::two_alternative, TaskKind::match, TaskKind::rating, TaskKind::guided,
                 TaskKind::same_different})
    if (to_string(t) == text) return t;
  throw FormatError(std::string(field) + " is '" + std::string(text) +
                    "'; allowed: oddity, two-alternative, match, rating, guided, same-different");
}

const Block* Protocol::block(std::string_view block_name) const {
  for (const auto& b : blocks)
    if (b.name == block_name) return &b;
  return nullptr;
}

int Protocol::planned_trials() const {
  int n = 0;
  for (const auto& b : blocks) {
    switch (b.task) {
      case TaskKind::oddity:
      case TaskKind::two_alternative:
        if (b.staircase) return -1;
        n += b.trials;
        break;
      case TaskKind::match: n += static_cast<int>(b.references.size()); break;
      case TaskKind::rating: {
        int pairs = 0;
        for (const auto& p : b.pairs) pairs += p.rendering.match_of == "*" ? 0 : 1;
        n += pairs * b.repeats;
        break;
      }
      case TaskKind::guided: {
        const int per = make_optimizer(b.optimizer, b.optimizer_params)->budget();
        n += per * static_cast<int>(b.references.size());
        break;
      }
      case TaskKind::same_different: n += b.trials_per_condition * static_cast<int>(b.conditions.size()); break;
    }
  }
  return n;
}

Protocol parse_protocol(std::string_view json_text, std::string_view origin) {
  if (json_text.size() > (16u << 20)) throw FormatError(std::string(origin) + " is larger than 16 MiB; not a protocol");
  const json j = detail::parse_json(json_text, origin);
  JsonObject o(j, "");
  Protocol p;
  const std::string fmt = o.string("format");
  if (fmt != "texel-protocol") throw FormatError(std::string(origin) + ": format is '" + fmt + "'; expected 'texel-protocol'");
  p.version = static_cast<int>(o.integer("version", 1, 1000000));
  if (p.version > Protocol::current_version)
    throw FormatError(std::string(origin) + ": version " + std::to_string(p.version) + " is newer than this Texel reads (" +
                      std::to_string(Protocol::current_version) + "); upgrade Texel");
  p.name = o.string("name");
  if (p.name.empty() || p.name.size() > 64 || !std::all_of(p.name.begin(), p.name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.';
      }))
    throw FormatError("name is '" + p.name + "'; allowed: 1 … 64 characters of A–Z, a–z, 0–9, '-', '_', '.'");
  p.study = o.string("study");
  if (std::find(std::begin(study_names), std::end(study_names), p.study) == std::end(study_names)) {
    std::string known;
    for (auto s : study_names) known += (known.empty() ? "" : ", ") + std::string(s);
    throw FormatError("study is '" + p.study + "'; allowed: " + known);
  }
  p.title = o.string_or("title", p.name);
  p.description = o.string_or("description", "");
  p.device = o.string_or("device", "tpad");
  try {
    (void)load_device(p.device);
  } catch (const Error& e) {
    throw FormatError(std::string("device: ") + e.what());
  }
  p.seed = o.uint64_or("seed", 1);
  if (o.has("observer")) {
    p.observer = o.raw("observer");
    validate_observer(p.observer);
  } else {
    o.skip("observer");
  }
  const auto& blocks = o.raw("blocks");
  if (!blocks.is_array() || blocks.empty() || blocks.size() > max_blocks)
    throw FormatError("blocks must be an array of 1 … " + std::to_string(max_blocks) + " blocks");
  std::set<std::string> names;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    Block b = parse_block(JsonObject(blocks[i], "blocks[" + std::to_string(i) + "]"), p.device);
    if (!names.insert(b.name).second)
      throw FormatError("blocks[" + std::to_string(i) + "].name '" + b.name + "' is used twice; block names must be unique");
    // References to earlier blocks must exist and come earlier.
    for (std::size_t k = 0; k < b.pairs.size(); ++k) {
      const auto& r = b.pairs[k].rendering;
      if (r.from_block.empty()) continue;
      const auto* src = p.block(r.from_block);
      const std::string f = "blocks[" + std::to_string(i) + "].pairs[" + std::to_string(k) + "].rendering.from_block";
      if (!src) throw FormatError(f + " is '" + r.from_block + "'; allowed: the name of an earlier block");
      if (src->task != TaskKind::match && src->task != TaskKind::guided)
        throw FormatError(f + " names block '" + r.from_block + "', which is not a match or guided block");
      if (std::find(src->references.begin(), src->references.end(), r.match_of) == src->references.end())
        throw FormatError("blocks[" + std::to_string(i) + "].pairs[" + std::to_string(k) + "].rendering.match_of is '" +
                          r.match_of + "'; block '" + r.from_block + "' does not match that reference");
    }
    p.blocks.push_back(std::move(b));
  }
  o.finish();
  p.json = j.dump(2);
  return p;
}

Protocol load_protocol(const std::string& path) { return parse_protocol(read_file(path), path); }

}  // namespace texel::experiment
