// The studio's message table (messages.hpp) and the typed key reads every
// handler uses. Adding a message: one row here, its handler in the file of
// its concern, its request and reply in docs/schema/studio-messages.schema.json
// (tests/studio checks that table and schema agree; the front end's types are
// generated from the schema).
#include "messages.hpp"

#include <algorithm>
#include <array>
#include <sstream>

namespace texel::studio::detail {

namespace {

// The order is the one error messages list ("unknown message type …; allowed: …").
const std::array<MessageSpec, 29> table{{
    {"hello", Lane::now, {}, on_hello},
    {"design", Lane::design, {"document", "region", "bins"}, on_design},
    {"match", Lane::fifo, {"document", "region", "into"}, on_match},
    {"import", Lane::fifo, {"name", "data_base64", "device"}, on_import},
    {"export", Lane::fifo, {"document", "as", "region"}, on_export},
    {"feel.select", Lane::design, {"document"}, on_feel_select},
    {"feel.move", Lane::now, {"seq", "t_ms", "x_mm", "touch", "coalesced"}, on_feel_move},
    {"feel.state", Lane::now, {}, on_feel_state},
    {"experiment.list", Lane::fifo, {}, on_experiment_list},
    {"experiment.stations", Lane::fifo, {}, on_experiment_stations},
    {"experiment.start", Lane::fifo, {"protocol", "participant", "resume", "simulate"}, on_experiment_start},
    {"experiment.current", Lane::fifo, {"reload", "screen"}, on_experiment_current},
    {"experiment.select", Lane::fifo, {"trial", "stimulus"}, on_experiment_select},
    {"experiment.preview", Lane::fifo, {"trial", "slider_p", "slider_i"}, on_experiment_preview},
    {"experiment.answer", Lane::fifo, {"trial", "token", "response", "simulated"}, on_experiment_answer},
    {"experiment.stop", Lane::fifo, {}, on_experiment_stop},
    {"experiment.trials", Lane::fifo, {"session"}, on_experiment_trials},
    {"experiment.export", Lane::fifo, {"as", "session"}, on_experiment_export},
    {"experiment.protocol", Lane::fifo, {"name"}, on_experiment_protocol},
    {"experiment.validate", Lane::fifo, {"protocol"}, on_experiment_validate},
    {"experiment.suspend", Lane::fifo, {}, on_experiment_suspend},
    {"experiment.resume", Lane::fifo, {}, on_experiment_resume},
    {"experiment.stroke", Lane::fifo, {"trial", "token", "stimulus", "samples"}, on_experiment_stroke},
    {"surface2d.view",
     Lane::design,
     {"document", "images", "x_px", "y_px", "width_px", "height_px", "stride"},
     on_surface2d_view},
    {"surface2d.scan", Lane::design, {"document", "images", "region", "angle_deg"}, on_surface2d_scan},
    {"feel2d.select", Lane::design, {"document", "images", "mode", "region"}, on_feel2d_select},
    {"feel2d.move", Lane::now, {"seq", "x_mm", "y_mm", "touch"}, on_feel2d_move},
    {"feel2d.state", Lane::now, {}, on_feel2d_state},
    {"feel2d.raster", Lane::design, {"document", "images", "x_px", "y_px", "width_px", "height_px"}, on_feel2d_raster},
}};

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

std::span<const MessageSpec> message_table() { return table; }

const MessageSpec* find_message(std::string_view type) {
  const auto it = std::find_if(table.begin(), table.end(), [&](const MessageSpec& m) { return m.type == type; });
  return it == table.end() ? nullptr : &*it;
}

void check_keys(const MessageSpec& spec, const json& msg) {
  for (const auto& [key, value] : msg.items()) {
    if (key == "type" || key == "id") continue;
    if (std::find(spec.keys.begin(), spec.keys.end(), key) == spec.keys.end()) {
      std::string list = "type, id";
      for (const auto a : spec.keys) list += ", " + std::string(a);
      throw Reject{"bad_message", std::string(spec.type) + ": unknown key " + clipped(key) + "; allowed: " + list};
    }
  }
}

std::string clipped(std::string_view s) {
  std::string q(s.substr(0, 64));
  return "'" + q + (s.size() > 64 ? "…" : "") + "'";
}

// ------------------------------------------------------------------- Fields

const json& Fields::raw(const char* key) const {
  if (!has(key)) throw Reject{"bad_message", type_ + ": missing '" + key + "'"};
  return msg_[key];
}

const json& Fields::object(const char* key) const {
  const json& v = raw(key);
  if (!v.is_object()) throw wrong(key, "an object", v);
  return v;
}

double Fields::number(const char* key, double lo, double hi) const {
  const json& v = raw(key);
  if (!v.is_number()) throw wrong(key, "a number", v);
  const double d = v.get<double>();
  if (!(d >= lo && d <= hi))
    throw Reject{"invalid", type_ + ": " + key + " is " + v.dump() + "; allowed: " + num(lo) + " … " + num(hi)};
  return d;
}

std::int64_t Fields::integer(const char* key, std::int64_t lo, std::int64_t hi) const {
  const json& v = raw(key);
  if (!v.is_number_integer()) throw wrong(key, "an integer", v);
  const bool fits = v.is_number_unsigned() ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi) : true;
  const std::int64_t i = fits ? v.get<std::int64_t>() : hi;
  if (!fits || i < lo || i > hi)
    throw Reject{"invalid",
                 type_ + ": " + key + " is " + v.dump() + "; allowed: " + std::to_string(lo) + " … " + std::to_string(hi)};
  return i;
}

bool Fields::boolean(const char* key, bool fallback) const {
  if (!has(key)) return fallback;
  const json& v = msg_[key];
  if (!v.is_boolean()) throw wrong(key, "true or false", v);
  return v.get<bool>();
}

std::string Fields::string(const char* key, std::size_t max_chars) const {
  const json& v = raw(key);
  if (!v.is_string()) throw wrong(key, "a string", v);
  const auto& s = v.get_ref<const std::string&>();
  if (s.size() > max_chars)
    throw Reject{"invalid", type_ + ": " + key + " has " + std::to_string(s.size()) + " characters; allowed: at most " +
                                std::to_string(max_chars)};
  return s;
}

Reject Fields::wrong(const char* key, const char* want, const json& v) const {
  return Reject{"bad_message", type_ + ": " + key + " must be " + want + ", got " + v.type_name()};
}

// ------------------------------------------------------------------ replies

void send(Client& c, const ojson& reply) {
  std::string text = reply.dump(-1, ' ', false, ojson::error_handler_t::replace);
  std::lock_guard lock(c.send_mutex);
  if (c.open) c.sink(std::move(text));
}

ojson reply(const char* type, const json& id) {
  ojson r{{"type", type}};
  r["id"] = id;
  return r;
}

}  // namespace texel::studio::detail
