// Conformance of MPEG-I Haptics JSON (.hjif): the published JSON schemas
// keyword by keyword, the dependencies between fields their descriptions
// state, and the reference software's loader rules (docs/interchange.md,
// "Conformance", has the table of every rule and where it is checked). The
// same walk reads a file for parse_hjif, in Mode::read: what the schema
// refuses is refused (dates excepted), the rest of the checker's rules are
// not enforced, and what Texel cannot sample is refused in the perceptions
// it samples. The text-level helpers (nesting depth, dates, quoting) are
// hjif_text.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "hjif_internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::hjif::detail {
namespace {

using nlohmann::json;
using texel::detail::num;

// --- the schemas' vocabulary (enum keywords) ---------------------------------

constexpr std::string_view kModalities[] = {"Pressure",
                                            "Acceleration",
                                            "Velocity",
                                            "Position",
                                            "Temperature",
                                            "Vibrotactile",
                                            "Water",
                                            "Wind",
                                            "Force",
                                            "Electrotactile",
                                            "Vibrotactile Texture",
                                            "Stiffness",
                                            "Friction",
                                            "Humidity",
                                            "User-defined Temporal",
                                            "User-defined Spatial",
                                            "Other"};
constexpr std::string_view kBandTypes[] = {"WaveletWave", "VectorialWave", "Curve", "Transient"};
constexpr std::string_view kCurveTypes[] = {"Linear", "Cubic", "Akima", "Bezier", "BSpline", "Unknown"};
constexpr std::string_view kEffectTypes[] = {"Basis", "Composite", "Reference"};
constexpr std::string_view kAvatarTypes[] = {"Vibration", "Pressure", "Temperature", "Custom"};
constexpr std::string_view kDeviceTypes[] = {"LRA", "VCA", "ERM", "Piezo", "Unknown"};

// The reference software's profile and level rules (its semantic checks).
constexpr std::string_view kProfiles[] = {"Main", "Simple Parametric"};
constexpr std::string_view kSimpleLevel1[] = {"Force", "Vibrotactile", "Stiffness", "Vibrotactile Texture"};
constexpr std::int64_t kMaxTimescaleMain = 48000;
constexpr std::int64_t kTimescaleSimple = 1000;
constexpr std::size_t kMaxChannelsLevel1 = 128;
constexpr std::size_t kMaxChannelsLevel2 = 65536;
constexpr std::size_t kMaxBandsLevel1 = 7;
constexpr std::size_t kMaxBandsLevel2 = 65536;

// Texel's own bounds (what it reads, not what the format allows).
constexpr std::int64_t kMaxPosition = std::int64_t{1} << 40;  // ±2^40 ticks
constexpr std::int64_t kInt = std::numeric_limits<std::int64_t>::max();
constexpr double kUnbounded = std::numeric_limits<double>::infinity();

template <std::size_t N>
bool one_of(std::string_view v, const std::string_view (&set)[N]) {
  return std::find(std::begin(set), std::end(set), v) != std::end(set);
}
template <std::size_t N>
std::string list(const std::string_view (&set)[N]) {
  std::string s;
  for (auto v : set) s += (s.empty() ? "'" : ", '") + std::string(v) + "'";
  return s;
}

bool sampled_modality(std::string_view m) { return is_spatial(m) || m == "Vibrotactile" || m == "Other"; }

std::string range(std::int64_t lo, std::int64_t hi) {
  if (hi == kInt) return ">= " + std::to_string(lo);
  return std::to_string(lo) + " … " + std::to_string(hi);
}
std::string range(double lo, double hi) {
  if (lo == -kUnbounded && hi == kUnbounded) return "any number";
  if (hi == kUnbounded) return ">= " + num(lo);
  return num(lo) + " … " + num(hi);
}

/// Walks a parsed file. Errors are collected in order; every rule says which
/// mode enforces it.
class Walker {
 public:
  Walker(const ImportLimits& limits, Mode mode) : limits_(limits), check_(mode != Mode::read), rules_(mode == Mode::check) {}

  std::vector<std::string> errors;
  Experience exp;

  void walk(const json& root) {
    if (!root.is_object()) return fail("", "must be a JSON object, got " + texel::detail::JsonObject::type_of(root));
    // version: schema pattern ^[0-9]{4}(-[0-9])?$.
    exp.version = str(root, "", "version", true).value_or("");
    if (const json* v = root.contains("version") ? &root["version"] : nullptr; v && v->is_string()) {
      const std::string& s = exp.version;
      const bool ok = (s.size() == 4 || (s.size() == 6 && s[4] == '-' && std::isdigit(static_cast<unsigned char>(s[5])))) &&
                      std::all_of(s.begin(), s.begin() + 4, [](char c) { return c >= '0' && c <= '9'; });
      if (!ok) fail("version", "is " + quote_value(s) + "; it must be YYYY or YYYY-N (schema pattern ^[0-9]{4}(-[0-9])?$)");
    }
    exp.profile = str(root, "", "profile", true).value_or("");
    if (rules_ && root.contains("profile") && root["profile"].is_string() && !one_of(exp.profile, kProfiles))
      fail("profile", "is " + quote_value(exp.profile) + "; the reference software knows " + list(kProfiles));
    if (auto level = integer(root, "", "level", true, 0, kInt)) {
      exp.level = static_cast<int>(std::min<std::int64_t>(*level, 1000));
      if (rules_ && (*level < 1 || *level > 2))
        fail("level", "is " + std::to_string(*level) + "; the reference software's profiles define levels 1 and 2");
    }
    exp.date = str(root, "", "date", true).value_or("");
    if (root.contains("date") && root["date"].is_string()) {
      if (check_ && !rfc3339_date_time(exp.date))
        fail("date", "is " + quote_value(exp.date) +
                         "; it must be an RFC 3339 date-time, e.g. 2026-11-26T14:06:29Z (schema format date-time)");
      else if (!check_ && !rfc3339_date_time(exp.date) && !liberal_date(exp.date))
        fail("date", "is " + quote_value(exp.date) +
                         "; it must be a date-time such as 2026-11-26T14:06:29Z (also read: 2026-11-26 14:06:29, 2026-11-26)");
    }
    exp.description = str(root, "", "description", true).value_or("");
    // timescale: optional in the schema (default 1000); the reference software's loader requires it.
    if (auto t = integer(root, "", "timescale", rules_, 1, kInt)) {
      if (*t > std::numeric_limits<std::uint32_t>::max()) {
        if (!check_) fail("timescale", "is " + std::to_string(*t) + "; Texel reads at most 4294967295");
      } else {
        exp.timescale = static_cast<std::uint32_t>(*t);
      }
      if (rules_ && exp.profile == "Simple Parametric" && *t != kTimescaleSimple)
        fail("timescale", "is " + std::to_string(*t) + "; the Simple Parametric profile requires 1000");
      if (rules_ && exp.profile == "Main" && *t > kMaxTimescaleMain)
        fail("timescale", "is " + std::to_string(*t) + "; the Main profile allows at most 48000");
    }
    std::vector<std::int64_t> avatar_ids;
    if (const json* avatars = array(root, "", "avatars", true)) {
      for (std::size_t i = 0; i < avatars->size(); ++i) {
        const std::string p = "avatars[" + std::to_string(i) + "]";
        const json& a = (*avatars)[i];
        if (!object(a, p)) continue;
        if (auto id = integer(a, p, "id", true, 1, kInt)) {
          if (rules_ && std::find(avatar_ids.begin(), avatar_ids.end(), *id) != avatar_ids.end())
            fail(p + ".id", "is " + std::to_string(*id) + ", which another avatar has");
          avatar_ids.push_back(*id);
        }
        integer(a, p, "lod", true, 0, kInt);
        enumerated(a, p, "type", true, kAvatarTypes);
        str(a, p, "mesh", false);
      }
    }
    if (const json* perceptions = array(root, "", "perceptions", true)) {
      if (perceptions->empty()) fail("perceptions", "is empty; at least 1 perception is required (schema minItems 1)");
      std::vector<std::int64_t> ids;
      for (std::size_t i = 0; i < perceptions->size(); ++i)
        perception((*perceptions)[i], "perceptions[" + std::to_string(i) + "]", avatar_ids, ids);
    }
    if (const json* syncs = array(root, "", "syncs", false)) {
      for (std::size_t i = 0; i < syncs->size(); ++i) {
        const std::string p = "syncs[" + std::to_string(i) + "]";
        if (!object((*syncs)[i], p)) continue;
        integer((*syncs)[i], p, "timestamp", true, 0, kInt);
        integer((*syncs)[i], p, "timescale", false, 1, kInt);
      }
    }
    // Texel samples one kind: spatial perceptions if there are any, else temporal ones.
    const bool any_spatial =
        std::any_of(exp.perceptions.begin(), exp.perceptions.end(), [](const Perception& p) { return p.spatial; });
    if (any_spatial) {
      for (const auto& p : exp.perceptions)
        if (!p.spatial) exp.skipped.push_back(p.modality);
      std::erase_if(exp.perceptions, [](const Perception& p) { return !p.spatial; });
    }
  }

 private:
  ImportLimits limits_;
  bool check_ = false;  // the schemas word for word (else: the reader)
  bool rules_ = false;  // and the field dependencies and the reference software's rules
  std::size_t keyframes_ = 0;

  void fail(const std::string& path, const std::string& what) { errors.push_back(path.empty() ? what : path + " " + what); }
  static std::string at(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
  }
  bool object(const json& v, const std::string& path) {
    if (v.is_object()) return true;
    fail(path, "must be a JSON object, got " + texel::detail::JsonObject::type_of(v));
    return false;
  }
  const json* find(const json& o, const std::string& path, std::string_view key, bool required) {
    const auto it = o.find(std::string(key));
    if (it == o.end()) {
      if (required) fail(at(path, key), "is missing");
      return nullptr;
    }
    return &*it;
  }
  std::optional<std::string> str(const json& o, const std::string& path, std::string_view key, bool required) {
    const json* v = find(o, path, key, required);
    if (!v) return std::nullopt;
    if (!v->is_string()) {
      fail(at(path, key), "must be a string, got " + texel::detail::JsonObject::type_of(*v));
      return std::nullopt;
    }
    return v->get<std::string>();
  }
  template <std::size_t N>
  std::optional<std::string> enumerated(const json& o, const std::string& path, std::string_view key, bool required,
                                        const std::string_view (&set)[N]) {
    auto s = str(o, path, key, required);
    if (s && !one_of(*s, set)) {
      fail(at(path, key), "is " + quote_value(*s) + "; allowed: " + list(set));
      return std::nullopt;
    }
    return s;
  }
  /// A JSON integer (draft 4: 1.0 is a number, not an integer) within [lo, hi].
  std::optional<std::int64_t> integer(const json& o, const std::string& path, std::string_view key, bool required,
                                      std::int64_t lo, std::int64_t hi) {
    const json* v = find(o, path, key, required);
    if (!v) return std::nullopt;
    if (!v->is_number_integer()) {
      fail(at(path, key), "must be a whole number, got " + texel::detail::JsonObject::type_of(*v));
      return std::nullopt;
    }
    if (v->is_number_unsigned() && v->get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) {
      fail(at(path, key), "is " + v->dump() + "; allowed: " + range(lo, hi));
      return std::nullopt;
    }
    const auto i =
        v->is_number_unsigned() && v->get<std::uint64_t>() > static_cast<std::uint64_t>(kInt) ? kInt : v->get<std::int64_t>();
    if (i < lo || i > hi) {
      fail(at(path, key), "is " + std::to_string(i) + "; allowed: " + range(lo, hi));
      return std::nullopt;
    }
    return i;
  }
  std::optional<double> number(const json& o, const std::string& path, std::string_view key, bool required, double lo,
                               double hi) {
    const json* v = find(o, path, key, required);
    if (!v) return std::nullopt;
    if (!v->is_number()) {
      fail(at(path, key), "must be a number, got " + texel::detail::JsonObject::type_of(*v));
      return std::nullopt;
    }
    const double d = v->get<double>();
    if (!(d >= lo && d <= hi)) {
      fail(at(path, key), "is " + num(d) + "; allowed: " + range(lo, hi));
      return std::nullopt;
    }
    return d;
  }
  const json* array(const json& o, const std::string& path, std::string_view key, bool required,
                    std::optional<std::size_t> cap = std::nullopt) {
    const json* v = find(o, path, key, required);
    if (!v) return nullptr;
    if (!v->is_array()) {
      fail(at(path, key), "must be an array, got " + texel::detail::JsonObject::type_of(*v));
      return nullptr;
    }
    const std::size_t most = cap.value_or(limits_.max_items);
    if (v->size() > most) {
      fail(at(path, key), "has " + std::to_string(v->size()) + " items; at most " + std::to_string(most) + " are read");
      return nullptr;
    }
    return v;
  }
  /// A vector object: X, Y, Z whole numbers in −127 … 127 (MPEG_haptics.vector).
  void vector(const json& v, const std::string& path) {
    if (!object(v, path)) return;
    integer(v, path, "X", true, -127, 127);
    integer(v, path, "Y", true, -127, 127);
    integer(v, path, "Z", true, -127, 127);
  }

  void perception(const json& j, const std::string& p, const std::vector<std::int64_t>& avatar_ids,
                  std::vector<std::int64_t>& ids) {
    if (!object(j, p)) return;
    Perception out;
    if (auto id = integer(j, p, "id", true, 0, kInt)) {
      if (rules_ && std::find(ids.begin(), ids.end(), *id) != ids.end())
        fail(p + ".id", "is " + std::to_string(*id) + ", which another perception has");
      ids.push_back(*id);
      out.id = *id;
    }
    if (auto a = integer(j, p, "avatar_id", true, 0, kInt))
      if (rules_ && *a != 0 && std::find(avatar_ids.begin(), avatar_ids.end(), *a) == avatar_ids.end())
        fail(p + ".avatar_id", "is " + std::to_string(*a) + ", which no avatar has (0: unspecified)");
    out.description = str(j, p, "description", true).value_or("");
    const auto modality = enumerated(j, p, "perception_modality", true, kModalities);
    if (modality) {
      out.modality = *modality;
      if (rules_ && exp.profile == "Simple Parametric" && exp.level == 1 && !one_of(*modality, kSimpleLevel1))
        fail(p + ".perception_modality", "is '" + *modality +
                                             "', which level 1 of the Simple Parametric profile does not allow (" +
                                             list(kSimpleLevel1) + ")");
    }
    out.spatial = modality && is_spatial(*modality);
    const bool sampled = modality && sampled_modality(*modality);
    integer(j, p, "priority", false, 0, kInt);
    // unit_exponent: any integer in the schema; Texel scales positions by it, so it reads −18 … 18 in what it samples.
    if (auto u = integer(j, p, "unit_exponent", false, std::numeric_limits<std::int64_t>::min(), kInt)) {
      if (*u >= -18 && *u <= 18)
        out.unit_exponent = static_cast<int>(*u);
      else if (!check_ && sampled)
        fail(p + ".unit_exponent", "is " + std::to_string(*u) + "; Texel reads −18 … 18");
    }
    integer(j, p, "perception_unit_exponent", false, std::numeric_limits<std::int64_t>::min(), kInt);
    str(j, p, "semantic_scheme", false);
    std::vector<std::int64_t> library_ids;
    if (const json* lib = array(j, p, "effect_library", true)) {
      for (std::size_t i = 0; i < lib->size(); ++i) {
        const std::string e = p + ".effect_library[" + std::to_string(i) + "]";
        if (auto id = effect((*lib)[i], e, "", nullptr, nullptr, true)) {
          if (rules_ && std::find(library_ids.begin(), library_ids.end(), *id) != library_ids.end())
            fail(e + ".id", "is " + std::to_string(*id) + ", which another library effect has");
          library_ids.push_back(*id);
        }
      }
    }
    std::vector<std::int64_t> device_ids;
    if (const json* devs = array(j, p, "reference_devices", false)) {
      for (std::size_t i = 0; i < devs->size(); ++i) {
        const std::string d = p + ".reference_devices[" + std::to_string(i) + "]";
        const json& dev = (*devs)[i];
        if (!object(dev, d)) continue;
        if (auto id = integer(dev, d, "id", true, 1, kInt)) device_ids.push_back(*id);
        auto name = str(dev, d, "name", true);
        if (name && !out.reference_device) out.reference_device = *name;
        integer(dev, d, "body_part_mask", false, 0, 4294967295LL);
        for (auto key : kDeviceNumbers) number(dev, d, key, false, 0.0, kUnbounded);
        number(dev, d, "custom", false, -kUnbounded, kUnbounded);
        enumerated(dev, d, "type", false, kDeviceTypes);
        if (rules_) {
          auto value = [&](const char* k) -> std::optional<double> {
            const auto it = dev.find(k);
            return it != dev.end() && it->is_number() ? std::optional<double>(it->get<double>()) : std::nullopt;
          };
          const auto lo = value("minimum_frequency"), hi = value("maximum_frequency"), res = value("resonance_frequency");
          if (lo && hi && *hi < *lo) fail(d + ".maximum_frequency", "is below minimum_frequency");
          if (res && ((lo && *res < *lo) || (hi && *res > *hi)))
            fail(d + ".resonance_frequency", "lies outside minimum_frequency … maximum_frequency");
        }
      }
    }
    bool first_channel = true;
    std::vector<std::int64_t> channel_ids;
    if (const json* channels = array(j, p, "channels", true)) {
      if (channels->empty()) fail(p + ".channels", "is empty; at least 1 channel is required (schema minItems 1)");
      const std::size_t most = exp.level == 2 ? kMaxChannelsLevel2 : kMaxChannelsLevel1;
      if (rules_ && channels->size() > most)
        fail(p + ".channels", "has " + std::to_string(channels->size()) + " channels; level " + std::to_string(exp.level) +
                                  " allows at most " + std::to_string(most));
      for (std::size_t i = 0; i < channels->size(); ++i) {
        const std::string c = p + ".channels[" + std::to_string(i) + "]";
        channel((*channels)[i], c, out, sampled, device_ids, library_ids, channel_ids, first_channel);
        first_channel = false;
      }
    }
    if (sampled)
      exp.perceptions.push_back(std::move(out));
    else if (modality)
      exp.skipped.push_back(*modality);
  }

  void channel(const json& j, const std::string& c, Perception& out, bool sampled, const std::vector<std::int64_t>& device_ids,
               const std::vector<std::int64_t>& library_ids, std::vector<std::int64_t>& ids, bool first) {
    if (!object(j, c)) return;
    if (auto id = integer(j, c, "id", true, 0, kInt)) {
      if (rules_ && std::find(ids.begin(), ids.end(), *id) != ids.end())
        fail(c + ".id", "is " + std::to_string(*id) + ", which another channel has");
      ids.push_back(*id);
    }
    str(j, c, "description", true);
    integer(j, c, "priority", false, 0, kInt);
    const double gain = number(j, c, "gain", true, 0.0, kUnbounded).value_or(1.0);
    number(j, c, "mixing_coefficient", true, 0.0, kUnbounded);
    integer(j, c, "body_part_mask", false, 0, 4294967295LL);
    if (auto fs = integer(j, c, "frequency_sampling", false, 0, kInt))
      if (first && *fs > 0 && *fs <= std::numeric_limits<std::uint32_t>::max())
        out.frequency_sampling = static_cast<std::uint32_t>(*fs);
    integer(j, c, "sample_count", false, 0, kInt);
    if (auto r = integer(j, c, "reference_device_id", false, 0, kInt))
      if (rules_ && std::find(device_ids.begin(), device_ids.end(), *r) == device_ids.end())
        fail(c + ".reference_device_id", "is " + std::to_string(*r) + ", which no reference device of the perception has");
    if (const json* d = find(j, c, "direction", false)) vector(*d, c + ".direction");
    if (const json* d = find(j, c, "actuator_resolution", false)) vector(*d, c + ".actuator_resolution");
    if (const json* targets = array(j, c, "actuator_target", false))
      for (std::size_t i = 0; i < targets->size(); ++i) vector((*targets)[i], c + ".actuator_target[" + std::to_string(i) + "]");
    if (const json* parts = array(j, c, "body_part_target", false))
      for (std::size_t i = 0; i < parts->size(); ++i) {
        const std::string b = c + ".body_part_target[" + std::to_string(i) + "]";
        if (!(*parts)[i].is_string())
          fail(b, "must be a string, got " + texel::detail::JsonObject::type_of((*parts)[i]));
        else if (!one_of((*parts)[i].get<std::string>(), kBodyParts))
          fail(b, "is " + quote_value((*parts)[i].get<std::string>()) + "; allowed: the schema's body parts (" +
                      list(kBodyParts).substr(0, 60) + "…)");
      }
    if (const json* verts = array(j, c, "vertices", false))
      for (std::size_t i = 0; i < verts->size(); ++i)
        if (!(*verts)[i].is_number_integer())
          fail(c + ".vertices[" + std::to_string(i) + "]",
               "must be a whole number, got " + texel::detail::JsonObject::type_of((*verts)[i]));
    if (const json* bands = array(j, c, "bands", true)) {
      const std::size_t most = exp.level == 2 ? kMaxBandsLevel2 : kMaxBandsLevel1;
      if (rules_ && bands->size() > most)
        fail(c + ".bands", "has " + std::to_string(bands->size()) + " bands; level " + std::to_string(exp.level) +
                               " allows at most " + std::to_string(most));
      for (std::size_t i = 0; i < bands->size(); ++i)
        band((*bands)[i], c + ".bands[" + std::to_string(i) + "]", out, sampled, library_ids, gain);
    }
    if (first) out.gain = gain;
  }

  void band(const json& j, const std::string& b, Perception& out, bool sampled, const std::vector<std::int64_t>& library_ids,
            double gain) {
    if (!object(j, b)) return;
    const auto type = enumerated(j, b, "band_type", true, kBandTypes);
    const auto curve = enumerated(j, b, "curve_type", false, kCurveTypes);
    integer(j, b, "priority", false, 0, kInt);
    const auto block = integer(j, b, "block_length", false, 16, kInt);
    const auto lo = number(j, b, "lower_frequency_limit", true, 0.0, 10000.0);
    const auto hi = number(j, b, "upper_frequency_limit", true, 0.0, 10000.0);
    if (rules_) {
      // Field dependencies (the schema's descriptions) and the reference software's band rules.
      if (type && *type != "Curve" && curve)
        fail(b + ".curve_type", "is given for a '" + *type + "' band; it applies to Curve bands only");
      if (type && *type == "WaveletWave" && !block) {
        if (!j.contains("block_length")) fail(b + ".block_length", "is missing; WaveletWave bands need one");
      }
      if (type && *type != "WaveletWave" && block) fail(b + ".block_length", "is given for a '" + *type + "' band");
      if (type && *type == "WaveletWave" && exp.profile == "Simple Parametric")
        fail(b + ".band_type", "is 'WaveletWave', which the Simple Parametric profile does not allow");
      if (lo && hi && *hi < *lo) fail(b + ".upper_frequency_limit", "is below lower_frequency_limit");
    }
    // What Texel samples: Linear curves anywhere; VectorialWave and Transient in temporal perceptions.
    const bool linear_curve = type && *type == "Curve" && curve.value_or("") == "Linear";
    const bool wave = type && !out.spatial && (*type == "VectorialWave" || *type == "Transient");
    if (!check_ && sampled && type && !linear_curve && !wave)
      fail(b + ".band_type", "is '" + *type + (curve ? "' with curve_type '" + *curve + "'" : std::string("'")) +
                                 "; Texel samples Curve bands with curve_type 'Linear' (and, in temporal perceptions, "
                                 "VectorialWave and Transient bands) only (docs/interchange.md)");
    const bool take = !check_ && sampled && (linear_curve || wave);
    if (const json* effects = array(j, b, "effects", true)) {
      for (std::size_t i = 0; i < effects->size(); ++i) {
        CurveEffect ce;
        WaveEffect we;
        const std::string e = b + ".effects[" + std::to_string(i) + "]";
        effect((*effects)[i], e, type.value_or(""), take && linear_curve ? &ce : nullptr, take && wave ? &we : nullptr, false,
               &library_ids);
        if (take && linear_curve && !ce.keyframes.empty()) {
          if (gain != 1.0)
            for (auto& k : ce.keyframes) k.amplitude *= gain;
          out.effects.push_back(std::move(ce));
        }
        if (take && wave && !we.keyframes.empty()) {
          we.kind = *type == "Transient" ? WaveEffect::Kind::transient : WaveEffect::Kind::vectorial;
          we.gain = gain;
          out.waves.push_back(std::move(we));
        }
      }
    }
  }

  // Checks one effect; fills `curve` (Linear curve) or `wave` when given.
  // Returns the effect's id when it has one.
  std::optional<std::int64_t> effect(const json& j, const std::string& e, const std::string& band_type, CurveEffect* curve,
                                     WaveEffect* wave, bool in_library, const std::vector<std::int64_t>* library_ids = nullptr) {
    if (!object(j, e)) return std::nullopt;
    const auto type = enumerated(j, e, "effect_type", true, kEffectTypes);
    // id: required for library and Reference effects (the schema's description of `id`).
    const bool needs_id = in_library || (type && *type == "Reference");
    const auto id = integer(j, e, "id", rules_ && needs_id, 0, kInt);
    const auto position = integer(j, e, "position", false, 0, kInt).value_or(0);
    if (!check_ && (curve || wave) && position > kMaxPosition)
      fail(e + ".position", "is " + std::to_string(position) + "; Texel reads positions up to 2^40 ticks");
    const auto phase = number(j, e, "phase", false, 0.0, 6.28318);
    const auto base = enumerated(j, e, "base_signal", false, kBaseSignals);
    str(j, e, "semantic_keywords", false);
    str(j, e, "wavelet_stream", false);
    if (rules_) {
      if (type && *type == "Composite" && exp.profile == "Simple Parametric")
        fail(e + ".effect_type", "is 'Composite', which the Simple Parametric profile does not allow");
      if (type && *type == "Reference" && library_ids && id &&
          std::find(library_ids->begin(), library_ids->end(), *id) == library_ids->end())
        fail(e + ".id", "is " + std::to_string(*id) + ", which the perception's effect_library does not hold");
      if (type && *type == "Basis" && !j.contains("keyframes") && band_type != "WaveletWave")
        fail(e + ".keyframes", "is missing; Basis effects need one (it may be empty)");
      if (j.contains("wavelet_stream") && !band_type.empty() && band_type != "WaveletWave")
        fail(e + ".wavelet_stream", "is given in a '" + band_type + "' band; it belongs to WaveletWave bands");
    }
    if (!check_ && (curve || wave) && type && *type != "Basis") {
      fail(e + ".effect_type", "is '" + *type + "'; Texel samples Basis effects only (docs/interchange.md)");
      curve = nullptr, wave = nullptr;
    }
    if (const json* comp = array(j, e, "composition", false)) (void)comp;  // items: any (the schema names no keyword)
    const json* kfs = array(j, e, "keyframes", false, limits_.max_keyframes);
    if (!kfs) return id;
    keyframes_ += kfs->size();
    if (keyframes_ > limits_.max_keyframes) {
      fail(e + ".keyframes", "brings the file to " + std::to_string(keyframes_) + " keyframes; at most " +
                                 std::to_string(limits_.max_keyframes) + " are read");
      return id;
    }
    if (wave) {
      wave->position = position;
      wave->phase = phase.value_or(0.0);
      wave->base_signal = base.value_or("Sine");
    }
    std::int64_t last = std::numeric_limits<std::int64_t>::min();
    for (std::size_t i = 0; i < kfs->size(); ++i) {
      const std::string k = e + ".keyframes[" + std::to_string(i) + "]";
      const json& kf = (*kfs)[i];
      if (!object(kf, k)) continue;
      const auto rel = integer(kf, k, "relative_position", false, 0, kInt);
      const auto amp = number(kf, k, "amplitude_modulation", false, -1.0, 1.0);
      const auto freq = number(kf, k, "frequency_modulation", false, 0.0, 10000.0);
      if (!(curve || wave)) continue;
      // Texel's reading: a sampled keyframe has a position, in order.
      if (!kf.contains("relative_position")) {
        fail(k + ".relative_position", "is missing; Texel samples keyframes that have one");
        continue;
      }
      if (!rel) continue;
      if (*rel > kMaxPosition) {
        fail(k + ".relative_position", "is " + std::to_string(*rel) + "; Texel reads positions up to 2^40 ticks");
        continue;
      }
      if (curve && *rel <= last)
        fail(k + ".relative_position", "is " + std::to_string(*rel) + ", not after the previous keyframe's " +
                                           std::to_string(last) + " (a Linear curve's keyframes are in order)");
      if (wave && *rel < last)
        fail(k + ".relative_position", "is " + std::to_string(*rel) + ", before the previous keyframe's " + std::to_string(last));
      last = std::max(last, *rel);
      if (curve) {
        if (!kf.contains("amplitude_modulation")) {
          fail(k + ".amplitude_modulation", "is missing; Texel samples curve keyframes that have one");
          continue;
        }
        if (amp) curve->keyframes.push_back(Keyframe{position + *rel, *amp});
      } else {
        wave->keyframes.push_back(WaveKeyframe{*rel, amp, freq});
      }
    }
    return id;
  }
};

}  // namespace

bool is_spatial(std::string_view modality) { return modality == "Friction" || modality == "Vibrotactile Texture"; }

Walked walk_text(std::string_view text, std::string_view origin, const ImportLimits& limits, Mode mode) {
  if (text.size() > limits.max_bytes)
    throw FormatError("'" + std::string(origin) + "' has " + std::to_string(text.size()) + " bytes; at most " +
                      std::to_string(limits.max_bytes) + " are read");
  if (const std::size_t d = nesting_depth(text, limits.max_depth); d > limits.max_depth)
    throw FormatError("'" + std::string(origin) + "' nests JSON deeper than " + std::to_string(limits.max_depth) + " levels");
  const json root = texel::detail::parse_json(text, "'" + std::string(origin) + "'");
  Walker w{limits, mode};
  w.walk(root);
  return Walked{std::move(w.errors), std::move(w.exp)};
}

}  // namespace texel::hjif::detail

namespace texel::hjif {

std::vector<std::string> conformance_errors(std::string_view text) {
  try {
    return detail::walk_text(text, "hjif", ImportLimits{}, detail::Mode::check).errors;
  } catch (const Error& e) {
    return {e.what()};
  }
}

std::vector<std::string> schema_errors(std::string_view text) {
  try {
    return detail::walk_text(text, "hjif", ImportLimits{}, detail::Mode::schema).errors;
  } catch (const Error& e) {
    return {e.what()};
  }
}

}  // namespace texel::hjif
