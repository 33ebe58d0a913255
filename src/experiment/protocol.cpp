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

#include "json_views.hpp"
#include "studies.hpp"
#include "task.hpp"

namespace texel::experiment {
namespace {

using detail::JsonObject;
using detail::num;
using nlohmann::json;

constexpr std::size_t max_blocks = 256;
constexpr std::size_t max_list = 4096;

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

Block parse_block(JsonObject o, const std::string& device, int version) {
  Block b;
  b.name = o.string("name");
  if (b.name.empty() || b.name.size() > 64) throw FormatError(o.field("name") + " must be 1 … 64 characters");
  b.task = o.string("task");
  const TaskType& type = task_type(b.task, o.field("task"));
  b.practice = o.boolean_or("practice", false);
  b.condition = o.string_or("condition", "");
  b.prompt = o.string_or("prompt", "");
  b.shuffle = o.boolean_or("shuffle", true);
  BlockInput in{o, device, version};
  type.parse(in, b);
  // A key another kind reads does not apply here; any other unknown key is
  // reported by finish().
  const auto own = type.keys();
  for (const TaskType* other : task_types())
    for (std::string_view k : other->keys()) {
      if (std::find(own.begin(), own.end(), k) != own.end()) continue;
      if (o.has(k)) throw FormatError(o.field(k) + " does not apply to task '" + b.task + "'");
      o.skip(k);
    }
  o.finish();
  return b;
}

}  // namespace

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

TextureTemplate BlockInput::texture(std::string_view key) const {
  TextureTemplate t{o.raw(key).dump()};
  check_texture(o.raw(key), device, o.field(key));
  return t;
}

std::optional<double> TextureTemplate::number(std::string_view key) const {
  if (json.empty()) return std::nullopt;
  const nlohmann::json t = nlohmann::json::parse(json);
  const auto it = t.find(std::string(key));
  if (it == t.end() || !it->is_number()) return std::nullopt;
  return it->get<double>();
}

std::vector<std::string> study_names() {
  std::vector<std::string> out;
  for (const Study& s : studies()) out.emplace_back(s.name);
  return out;
}

const Block* Protocol::block(std::string_view block_name) const {
  for (const auto& b : blocks)
    if (b.name == block_name) return &b;
  return nullptr;
}

int Protocol::planned_trials() const {
  int n = 0;
  for (const auto& b : blocks) {
    const auto planned = task_type(b.task).planned_trials(b);
    if (!planned) return -1;
    n += *planned;
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
  if (!find_study(p.study)) {
    std::string known;
    for (const auto& s : study_names()) known += (known.empty() ? "" : ", ") + s;
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
  p.on_reload = o.string_or("on_reload", "keep_clock");
  if (p.on_reload != "keep_clock" && p.on_reload != "restart_trial")
    throw FormatError("on_reload is '" + p.on_reload + "'; allowed: keep_clock, restart_trial");
  if (o.has("observer")) {
    validate_observer_object(o.raw("observer"));
    p.observer = o.raw("observer").dump();
  } else {
    o.skip("observer");
  }
  const auto& blocks = o.raw("blocks");
  if (!blocks.is_array() || blocks.empty() || blocks.size() > max_blocks)
    throw FormatError("blocks must be an array of 1 … " + std::to_string(max_blocks) + " blocks");
  std::set<std::string> names;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    Block b = parse_block(JsonObject(blocks[i], "blocks[" + std::to_string(i) + "]"), p.device, p.version);
    if (!names.insert(b.name).second)
      throw FormatError("blocks[" + std::to_string(i) + "].name '" + b.name + "' is used twice; block names must be unique");
    // References to earlier blocks must exist and come earlier.
    for (std::size_t k = 0; k < b.pairs.size(); ++k) {
      const auto& r = b.pairs[k].rendering;
      if (r.from_block.empty()) continue;
      const auto* src = p.block(r.from_block);
      const std::string f = "blocks[" + std::to_string(i) + "].pairs[" + std::to_string(k) + "].rendering.from_block";
      if (!src) throw FormatError(f + " is '" + r.from_block + "'; allowed: the name of an earlier block");
      if (!task_type(src->task).makes_matches())
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
