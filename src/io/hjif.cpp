// MPEG-I Haptics (ISO/IEC 23090-31) JSON interchange files, out and in
// (texel/interchange.hpp; docs/interchange.md has the mapping and sources).
//
// Field names, enumerations and the profile/level rules follow the public
// reference software's reader, writer and semantic checks (MPEGGroup/
// HapticReferenceSoftware, IOHaptics/IOJson.cpp) and the media-type
// registration draft that lists the modalities (draft-ietf-mediaman-haptics);
// the ISO text itself is not public. Every rule applied here is written out
// in docs/interchange.md, so a reader can check what "conformant" means.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <limits>
#include <regex>

#include <nlohmann/json.hpp>

#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/surface.hpp"

namespace texel::hjif {
namespace {

using detail::num;
using nlohmann::json;
using ojson = nlohmann::ordered_json;

// --- the standard's vocabulary ---------------------------------------------

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
constexpr std::string_view kBandTypes[] = {"Transient", "Curve", "VectorialWave", "WaveletWave"};
constexpr std::string_view kCurveTypes[] = {"Unknown", "Cubic", "Linear", "Akima", "Bezier", "Bspline"};
constexpr std::string_view kEffectTypes[] = {"Basis", "Reference", "Composite"};
constexpr std::string_view kBaseSignals[] = {"Sine", "Square", "Triangle", "SawToothUp", "SawToothDown"};
constexpr std::string_view kAvatarTypes[] = {"Vibration", "Pressure", "Temperature", "Custom"};
constexpr std::string_view kProfiles[] = {"Main", "Simple Parametric"};
// Simple Parametric, level 1: the only modalities allowed.
constexpr std::string_view kSimpleLevel1[] = {"Force", "Vibrotactile", "Stiffness", "Vibrotactile Texture"};

constexpr std::uint32_t kMaxTimescaleMain = 48000;
constexpr std::uint32_t kTimescaleSimple = 1000;
constexpr std::size_t kMaxChannelsLevel1 = 128;
constexpr std::size_t kMaxChannelsLevel2 = 65536;
constexpr std::size_t kMaxBandsLevel1 = 7;
constexpr std::size_t kMaxBandsLevel2 = 65536;
// Positions are whole ticks; Texel bounds them to ±2^40 (a 48 kHz timescale
// reaches 2^40 ticks after 260 days, or 23 km at 48000 ticks/mm).
constexpr std::int64_t kMaxPosition = std::int64_t{1} << 40;

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

/// A value from the file, quoted for a one-line message: control characters
/// escaped, at most 40 characters.
std::string quote_value(std::string_view v) {
  std::string out = "'";
  for (std::size_t i = 0; i < v.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(v[i]);
    if (c < 0x20 || c == 0x7F) {
      static constexpr char hex[] = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + (v.size() > 40 ? "…'" : "'");
}

bool is_spatial(std::string_view modality) { return modality == "Friction" || modality == "Vibrotactile Texture"; }

// --- the walker: checks every known field, builds the Experience ------------
//
// Errors are collected (conformance_errors lists them all; parse_hjif throws
// the first). Unknown keys are allowed: the format has extension points and
// other writers add fields; every key Texel knows is checked.

class Walker {
 public:
  /// `texel_limits`: also refuse what is conformant but Texel cannot sample
  /// (bands other than Linear curves, Reference effects) in sampled perceptions.
  Walker(std::string origin, const ImportLimits& limits, bool texel_limits)
      : origin_(std::move(origin)), limits_(limits), texel_limits_(texel_limits) {}

  std::vector<std::string> errors;
  Experience exp;

  void walk(const json& root) {
    if (!root.is_object()) return fail("", "must be a JSON object, got " + detail::JsonObject::type_of(root));
    exp.version = str(root, "", "version", true).value_or("");
    if (!exp.version.empty()) check_version(exp.version);
    exp.profile = str(root, "", "profile", true).value_or("");
    if (!exp.profile.empty() && !one_of(exp.profile, kProfiles))
      fail("profile", "is " + quote_value(exp.profile) + "; allowed: " + list(kProfiles));
    exp.level = static_cast<int>(integer(root, "", "level", true, 1, 2).value_or(1));
    exp.date = str(root, "", "date", true).value_or("");
    if (!exp.date.empty() && !valid_date(exp.date))
      fail("date", "is " + quote_value(exp.date) + "; it must be an ISO 8601 date (YYYY-MM-DD…)");
    exp.description = str(root, "", "description", true).value_or("");
    if (auto t = integer(root, "", "timescale", true, 1, std::numeric_limits<std::uint32_t>::max())) {
      exp.timescale = static_cast<std::uint32_t>(*t);
      if (exp.profile == "Simple Parametric" && exp.timescale != kTimescaleSimple)
        fail("timescale", "is " + std::to_string(*t) + "; the Simple Parametric profile requires 1000");
      if (exp.profile == "Main" && exp.timescale > kMaxTimescaleMain)
        fail("timescale", "is " + std::to_string(*t) + "; the Main profile allows at most 48000");
    }
    std::vector<std::int64_t> avatar_ids;
    if (const json* avatars = array(root, "", "avatars", true)) {
      for (std::size_t i = 0; i < avatars->size(); ++i) {
        const std::string p = "avatars[" + std::to_string(i) + "]";
        const json& a = (*avatars)[i];
        if (!object(a, p)) continue;
        if (auto id = integer(a, p, "id", true, 0, kMaxPosition)) {
          if (*id == 0) fail(p + ".id", "is 0, which is reserved for an unspecified avatar");
          if (std::find(avatar_ids.begin(), avatar_ids.end(), *id) != avatar_ids.end())
            fail(p + ".id", "is " + std::to_string(*id) + ", which another avatar has");
          avatar_ids.push_back(*id);
        }
        integer(a, p, "lod", true, 0, kMaxPosition);
        enumerated(a, p, "type", true, kAvatarTypes);
        str(a, p, "mesh", false);
      }
    }
    if (const json* perceptions = array(root, "", "perceptions", true)) {
      std::vector<std::int64_t> ids;
      for (std::size_t i = 0; i < perceptions->size(); ++i)
        perception((*perceptions)[i], "perceptions[" + std::to_string(i) + "]", avatar_ids, ids);
    }
    if (const json* syncs = array(root, "", "syncs", true)) {
      for (std::size_t i = 0; i < syncs->size(); ++i) {
        const std::string p = "syncs[" + std::to_string(i) + "]";
        if (!object((*syncs)[i], p)) continue;
        integer((*syncs)[i], p, "timestamp", true, -kMaxPosition, kMaxPosition);
        integer((*syncs)[i], p, "timescale", false, 1, std::numeric_limits<std::uint32_t>::max());
      }
    }
    // Texel samples one kind: spatial perceptions if there are any, else temporal vibrotactile.
    const bool any_spatial =
        std::any_of(exp.perceptions.begin(), exp.perceptions.end(), [](const Perception& p) { return p.spatial; });
    if (any_spatial) {
      for (const auto& p : exp.perceptions)
        if (!p.spatial) exp.skipped.push_back(p.modality);
      std::erase_if(exp.perceptions, [](const Perception& p) { return !p.spatial; });
    }
  }

 private:
  std::string origin_;
  ImportLimits limits_;
  bool texel_limits_ = true;
  std::size_t keyframes_ = 0;

  void fail(const std::string& path, const std::string& what) { errors.push_back(path.empty() ? what : path + " " + what); }
  static std::string at(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
  }
  bool object(const json& v, const std::string& path) {
    if (v.is_object()) return true;
    fail(path, "must be a JSON object, got " + detail::JsonObject::type_of(v));
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
      fail(at(path, key), "must be a string, got " + detail::JsonObject::type_of(*v));
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
  std::optional<std::int64_t> integer(const json& o, const std::string& path, std::string_view key, bool required,
                                      std::int64_t lo, std::int64_t hi) {
    const json* v = find(o, path, key, required);
    if (!v) return std::nullopt;
    if (!v->is_number_integer()) {
      fail(at(path, key), "must be a whole number, got " + detail::JsonObject::type_of(*v));
      return std::nullopt;
    }
    if (v->is_number_unsigned() && v->get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) {
      fail(at(path, key), "is " + v->dump() + "; allowed: " + std::to_string(lo) + " … " + std::to_string(hi));
      return std::nullopt;
    }
    const auto i = v->get<std::int64_t>();
    if (i < lo || i > hi) {
      fail(at(path, key), "is " + std::to_string(i) + "; allowed: " + std::to_string(lo) + " … " + std::to_string(hi));
      return std::nullopt;
    }
    return i;
  }
  std::optional<double> number(const json& o, const std::string& path, std::string_view key, bool required, double lo,
                               double hi) {
    const json* v = find(o, path, key, required);
    if (!v) return std::nullopt;
    if (!v->is_number()) {
      fail(at(path, key), "must be a number, got " + detail::JsonObject::type_of(*v));
      return std::nullopt;
    }
    const double d = v->get<double>();
    if (!(d >= lo && d <= hi)) {
      fail(at(path, key), "is " + num(d) + "; allowed: " + num(lo) + " … " + num(hi));
      return std::nullopt;
    }
    return d;
  }
  const json* array(const json& o, const std::string& path, std::string_view key, bool required,
                    std::optional<std::size_t> cap = std::nullopt) {
    const json* v = find(o, path, key, required);
    if (!v) return nullptr;
    if (!v->is_array()) {
      fail(at(path, key), "must be an array, got " + detail::JsonObject::type_of(*v));
      return nullptr;
    }
    const std::size_t most = cap.value_or(limits_.max_items);
    if (v->size() > most) {
      fail(at(path, key), "has " + std::to_string(v->size()) + " items; at most " + std::to_string(most) + " are read");
      return nullptr;
    }
    return v;
  }

  void check_version(const std::string& v) {
    static const std::regex re("^([0-9]{4})(-([0-9]+))?$");
    std::smatch m;
    // Length first: std::regex matches recursively, so a long string could exhaust the stack.
    if (v.size() > 16 || !std::regex_match(v, m, re))
      return fail("version", "is " + quote_value(v) + "; it must be YYYY or YYYY-N (year of publication, amendment)");
    if (std::stoi(m[1].str()) < 2023) fail("version", "is " + quote_value(v) + "; the year must be 2023 or later");
    if (m[3].matched && (m[3].str().size() > 4 || std::stoi(m[3].str()) <= 0))
      fail("version", "is " + quote_value(v) + "; the amendment number must be > 0");
  }
  static bool valid_date(const std::string& d) {
    static const std::regex re(
        "^[+-]?[0-9]{4}(-[01][0-9](-[0-3][0-9](T[0-2][0-9]:[0-5][0-9](:[0-5][0-9](\\.[0-9]+)?)?(Z|[+-][0-2][0-9]:[0-5][0-9])?)?)?"
        ")?$");
    return d.size() <= 64 && std::regex_match(d, re);
  }

  void perception(const json& j, const std::string& p, const std::vector<std::int64_t>& avatar_ids,
                  std::vector<std::int64_t>& ids) {
    if (!object(j, p)) return;
    Perception out;
    if (auto id = integer(j, p, "id", true, -kMaxPosition, kMaxPosition)) {
      if (std::find(ids.begin(), ids.end(), *id) != ids.end())
        fail(p + ".id", "is " + std::to_string(*id) + ", which another perception has");
      ids.push_back(*id);
      out.id = *id;
    }
    if (auto a = integer(j, p, "avatar_id", true, -kMaxPosition, kMaxPosition))
      if (*a != 0 && std::find(avatar_ids.begin(), avatar_ids.end(), *a) == avatar_ids.end())
        fail(p + ".avatar_id", "is " + std::to_string(*a) + ", which no avatar has (0: unspecified)");
    out.description = str(j, p, "description", true).value_or("");
    const auto modality = enumerated(j, p, "perception_modality", true, kModalities);
    if (modality) {
      out.modality = *modality;
      if (exp.profile == "Simple Parametric" && exp.level == 1 && !one_of(*modality, kSimpleLevel1))
        fail(p + ".perception_modality", "is '" + *modality +
                                             "', which level 1 of the Simple Parametric profile does not allow (" +
                                             list(kSimpleLevel1) + ")");
    }
    out.spatial = modality && is_spatial(*modality);
    if (auto u = integer(j, p, "unit_exponent", false, -18, 18)) out.unit_exponent = static_cast<int>(*u);
    integer(j, p, "perception_unit_exponent", false, -18, 18);
    str(j, p, "effect_semantic_scheme", false);
    std::vector<std::int64_t> library_ids;
    if (const json* lib = array(j, p, "effect_library", true)) {
      for (std::size_t i = 0; i < lib->size(); ++i) {
        const std::string e = p + ".effect_library[" + std::to_string(i) + "]";
        if (auto id = effect((*lib)[i], e, nullptr, nullptr, true)) {
          if (std::find(library_ids.begin(), library_ids.end(), *id) != library_ids.end())
            fail(e + ".id", "is " + std::to_string(*id) + ", which another library effect has");
          library_ids.push_back(*id);
        }
      }
    }
    std::vector<std::int64_t> device_ids;
    if (const json* devs = array(j, p, "reference_devices", false)) {
      for (std::size_t i = 0; i < devs->size(); ++i) {
        const std::string d = p + ".reference_devices[" + std::to_string(i) + "]";
        if (!object((*devs)[i], d)) continue;
        if (auto id = integer((*devs)[i], d, "id", true, -kMaxPosition, kMaxPosition)) device_ids.push_back(*id);
        auto name = str((*devs)[i], d, "name", true);
        if (name && !out.reference_device) out.reference_device = *name;
        integer((*devs)[i], d, "body_part_mask", false, 0, std::numeric_limits<std::uint32_t>::max());
        const auto lo = number((*devs)[i], d, "minimum_frequency", false, 0, 1e9);
        const auto hi = number((*devs)[i], d, "maximum_frequency", false, 0, 1e9);
        const auto res = number((*devs)[i], d, "resonance_frequency", false, 0, 1e9);
        if (lo && hi && *hi < *lo) fail(d, "has maximum_frequency below minimum_frequency");
        if (res && ((lo && *res < *lo) || (hi && *res > *hi)))
          fail(d + ".resonance_frequency", "lies outside the frequency range");
      }
    }
    bool first_channel = true;
    std::vector<std::int64_t> channel_ids;
    if (const json* channels = array(j, p, "channels", true)) {
      const std::size_t most = exp.level == 2 ? kMaxChannelsLevel2 : kMaxChannelsLevel1;
      if (channels->size() > most)
        fail(p + ".channels", "has " + std::to_string(channels->size()) + " channels; level " + std::to_string(exp.level) +
                                  " allows at most " + std::to_string(most));
      for (std::size_t i = 0; i < channels->size(); ++i) {
        const std::string c = p + ".channels[" + std::to_string(i) + "]";
        channel((*channels)[i], c, out, device_ids, library_ids, channel_ids, first_channel);
        first_channel = false;
      }
    }
    if (modality && (out.spatial || *modality == "Vibrotactile"))
      exp.perceptions.push_back(std::move(out));
    else if (modality)
      exp.skipped.push_back(*modality);
  }

  void channel(const json& j, const std::string& c, Perception& out, const std::vector<std::int64_t>& device_ids,
               const std::vector<std::int64_t>& library_ids, std::vector<std::int64_t>& ids, bool first) {
    if (!object(j, c)) return;
    if (auto id = integer(j, c, "id", true, -kMaxPosition, kMaxPosition)) {
      if (std::find(ids.begin(), ids.end(), *id) != ids.end())
        fail(c + ".id", "is " + std::to_string(*id) + ", which another channel has");
      ids.push_back(*id);
    }
    str(j, c, "description", true);
    const double gain = number(j, c, "gain", true, -1e6, 1e6).value_or(1.0);
    number(j, c, "mixing_coefficient", true, -1e6, 1e6);
    integer(j, c, "body_part_mask", true, 0, std::numeric_limits<std::uint32_t>::max());
    if (auto fs = integer(j, c, "frequency_sampling", false, 0, std::numeric_limits<std::uint32_t>::max()))
      if (first && *fs > 0) out.frequency_sampling = static_cast<std::uint32_t>(*fs);
    integer(j, c, "sample_count", false, 0, std::numeric_limits<std::uint32_t>::max());
    if (auto r = integer(j, c, "reference_device_id", false, -kMaxPosition, kMaxPosition))
      if (std::find(device_ids.begin(), device_ids.end(), *r) == device_ids.end())
        fail(c + ".reference_device_id", "is " + std::to_string(*r) + ", which no reference device of the perception has");
    if (const json* d = find(j, c, "direction", false)) vector(*d, c + ".direction", true);
    if (const json* d = find(j, c, "actuator_resolution", false)) vector(*d, c + ".actuator_resolution", false);
    if (const json* bands = array(j, c, "bands", true)) {
      const std::size_t most = exp.level == 2 ? kMaxBandsLevel2 : kMaxBandsLevel1;
      if (bands->size() > most)
        fail(c + ".bands", "has " + std::to_string(bands->size()) + " bands; level " + std::to_string(exp.level) +
                               " allows at most " + std::to_string(most));
      for (std::size_t i = 0; i < bands->size(); ++i)
        band((*bands)[i], c + ".bands[" + std::to_string(i) + "]", out, library_ids, gain);
    }
    if (first) out.gain = gain;
  }

  void vector(const json& v, const std::string& path, bool unit) {
    if (!object(v, path)) return;
    const auto x = integer(v, path, "X", true, -128, 127);
    const auto y = integer(v, path, "Y", true, -128, 127);
    const auto z = integer(v, path, "Z", true, -128, 127);
    if (unit && x && y && z) {
      const double n = std::sqrt(static_cast<double>(*x * *x + *y * *y + *z * *z)) / 127.0;
      if (n < 0.95 || n > 1.05) fail(path, "is not a unit vector (X, Y, Z in units of 1/127)");
    }
  }

  void band(const json& j, const std::string& b, Perception& out, const std::vector<std::int64_t>& library_ids, double gain) {
    if (!object(j, b)) return;
    const auto type = enumerated(j, b, "band_type", true, kBandTypes);
    const auto curve = enumerated(j, b, "curve_type", false, kCurveTypes);
    if (type && *type != "Curve" && curve)
      fail(b + ".curve_type", "is given for a '" + *type + "' band; only Curve bands have one");
    if (type && *type == "WaveletWave") {
      integer(j, b, "block_length", true, 1, kMaxPosition);
      if (exp.profile == "Simple Parametric")
        fail(b + ".band_type", "is 'WaveletWave', which the Simple Parametric profile does not allow");
    }
    const auto lo = integer(j, b, "lower_frequency_limit", true, 0, kMaxPosition);
    const auto hi = integer(j, b, "upper_frequency_limit", true, 0, kMaxPosition);
    if (lo && hi && *hi < *lo) fail(b + ".upper_frequency_limit", "is below lower_frequency_limit");
    const bool sampled = out.spatial || out.modality == "Vibrotactile";
    const bool linear_curve = type && *type == "Curve" && curve && *curve == "Linear";
    if (texel_limits_ && sampled && type && !linear_curve)
      fail(b + ".band_type", "is '" + *type + (curve ? "' with curve_type '" + *curve + "'" : std::string("'")) +
                                 "; Texel samples Curve bands with curve_type 'Linear' only (docs/interchange.md)");
    if (const json* effects = array(j, b, "effects", true)) {
      for (std::size_t i = 0; i < effects->size(); ++i) {
        CurveEffect ce;
        const std::string e = b + ".effects[" + std::to_string(i) + "]";
        effect((*effects)[i], e, linear_curve && sampled ? &ce : nullptr, &library_ids, false);
        if (linear_curve && sampled && !ce.keyframes.empty()) {
          if (gain != 1.0)
            for (auto& k : ce.keyframes) k.amplitude *= gain;
          out.effects.push_back(std::move(ce));
        }
      }
    }
  }

  // Checks one effect; fills `curve` with its absolute keyframes when given.
  // Returns the effect's id when it has one.
  std::optional<std::int64_t> effect(const json& j, const std::string& e, CurveEffect* curve,
                                     const std::vector<std::int64_t>* library_ids, bool in_library) {
    if (!object(j, e)) return std::nullopt;
    const auto type = enumerated(j, e, "effect_type", true, kEffectTypes).value_or("Basis");
    if (type == "Composite" && exp.profile == "Simple Parametric")
      fail(e + ".effect_type", "is 'Composite', which the Simple Parametric profile does not allow");
    const auto id = integer(j, e, "id", in_library || type == "Reference", -kMaxPosition, kMaxPosition);
    const auto position = integer(j, e, "position", true, -kMaxPosition, kMaxPosition);
    number(j, e, "phase", type == "Basis", -1e6, 1e6);
    enumerated(j, e, "base_signal", type == "Basis", kBaseSignals);
    str(j, e, "semantic_keywords", false);
    if (type == "Reference" && library_ids && id &&
        std::find(library_ids->begin(), library_ids->end(), *id) == library_ids->end())
      fail(e + ".id", "is " + std::to_string(*id) + ", which the perception's effect_library does not hold");
    if (type == "Reference" && curve && texel_limits_) {
      fail(e + ".effect_type", "is 'Reference'; Texel samples Basis effects only (docs/interchange.md)");
      curve = nullptr;
    }
    const json* kfs = array(j, e, "keyframes", type == "Basis", limits_.max_keyframes);
    if (type == "Composite") {
      if (const json* subs = array(j, e, "timeline", false))
        for (std::size_t i = 0; i < subs->size(); ++i)
          effect((*subs)[i], e + ".timeline[" + std::to_string(i) + "]", nullptr, library_ids, false);
    }
    if (!kfs) return id;
    keyframes_ += kfs->size();
    if (keyframes_ > limits_.max_keyframes) {
      fail(e + ".keyframes", "brings the file to " + std::to_string(keyframes_) + " keyframes; at most " +
                                 std::to_string(limits_.max_keyframes) + " are read");
      return id;
    }
    std::int64_t last = std::numeric_limits<std::int64_t>::min();
    for (std::size_t i = 0; i < kfs->size(); ++i) {
      const std::string k = e + ".keyframes[" + std::to_string(i) + "]";
      const json& kf = (*kfs)[i];
      if (!object(kf, k)) continue;
      const auto rel = integer(kf, k, "relative_position", curve != nullptr, 0, kMaxPosition);
      const auto amp = number(kf, k, "amplitude_modulation", curve != nullptr, -1.0, 1.0);
      integer(kf, k, "frequency_modulation", false, 0, kMaxPosition);
      if (rel) {
        if (*rel <= last && curve)
          fail(k + ".relative_position",
               "is " + std::to_string(*rel) + ", not after the previous keyframe's " + std::to_string(last));
        last = std::max(last, *rel);
      }
      if (curve && rel && amp && position) curve->keyframes.push_back(Keyframe{*position + *rel, *amp});
    }
    return id;
  }
};

/// JSON nesting depth of a text, counting brackets outside strings; stops
/// early once past `limit`.
std::size_t nesting_depth(std::string_view t, std::size_t limit) {
  std::size_t depth = 0;
  std::size_t most = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const char c = t[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"')
      in_string = true;
    else if (c == '[' || c == '{') {
      most = std::max(most, ++depth);
      if (most > limit) return most;
    } else if ((c == ']' || c == '}') && depth > 0)
      --depth;
  }
  return most;
}

Walker walk_text(std::string_view text, std::string_view origin, const ImportLimits& limits, bool texel_limits) {
  if (text.size() > limits.max_bytes)
    throw FormatError("'" + std::string(origin) + "' has " + std::to_string(text.size()) + " bytes; at most " +
                      std::to_string(limits.max_bytes) + " are read");
  if (const std::size_t d = nesting_depth(text, limits.max_depth); d > limits.max_depth)
    throw FormatError("'" + std::string(origin) + "' nests JSON deeper than " + std::to_string(limits.max_depth) + " levels");
  const json root = detail::parse_json(text, "'" + std::string(origin) + "'");
  Walker w{std::string(origin), limits, texel_limits};
  w.walk(root);
  return w;
}

// --- evaluation ----------------------------------------------------------------

double pow10i(int k) {
  double p = 1.0;
  for (int i = 0; i < std::abs(k); ++i) p *= 10.0;
  return k < 0 ? 1.0 / p : p;
}

/// Ticks per millimetre of a perception (spatial) or per mm at the swipe speed (temporal).
double ticks_per_mm(const Experience& e, const Perception& p, std::optional<MmPerSecond> v) {
  if (p.spatial) return static_cast<double>(e.timescale) / pow10i(p.unit_exponent + 3);
  if (!v)
    throw FieldError("swipe_speed",
                     "is required: the file's perceptions are temporal (Vibrotactile), and the swipe "
                     "speed (mm/s) turns their time into position");
  return static_cast<double>(e.timescale) / v->value();
}

/// A Linear curve at tick u: linear between keyframes, 0 outside [first, last]
/// (a millionth of a tick of slack at the ends).
double curve_at(const CurveEffect& c, double u) {
  const auto& k = c.keyframes;
  constexpr double slack = 1e-6;
  if (k.empty() || u < static_cast<double>(k.front().position) - slack || u > static_cast<double>(k.back().position) + slack)
    return 0.0;
  // First keyframe with position > u.
  auto hi =
      std::upper_bound(k.begin(), k.end(), u, [](double x, const Keyframe& f) { return x < static_cast<double>(f.position); });
  if (hi == k.begin()) return k.front().amplitude;
  if (hi == k.end()) return k.back().amplitude;
  const Keyframe& a = *(hi - 1);
  const Keyframe& b = *hi;
  const double t = (u - static_cast<double>(a.position)) / static_cast<double>(b.position - a.position);
  return a.amplitude + (b.amplitude - a.amplitude) * t;
}

// --- export --------------------------------------------------------------------

std::string today(const std::string& given) {
  if (!given.empty()) return given;
  std::time_t t = std::time(nullptr);
  if (const char* sde = std::getenv("SOURCE_DATE_EPOCH")) {
    char* end = nullptr;
    const long long v = std::strtoll(sde, &end, 10);
    if (end && *end == '\0' && v >= 0) t = static_cast<std::time_t>(v);
  }
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
  return buf;
}

/// The timescale (ticks per mm) [choice]: the smallest multiple of 1000 up to
/// 48000 that puts every grid position on a whole tick, else 48000.
std::pair<std::uint32_t, bool> choose_timescale(double spacing_mm) {
  for (std::uint32_t t = 1000; t <= kMaxTimescaleMain; t += 1000) {
    const double u = spacing_mm * t;
    if (std::fabs(u - std::round(u)) <= 1e-9 * u && std::round(u) >= 1.0) return {t, true};
  }
  return {kMaxTimescaleMain, false};
}

std::string region_summary(const RegionSpec& r, std::size_t index) {
  std::string s = "region " + (r.name.empty() ? std::to_string(index) : "'" + r.name + "'");
  if (r.reference) return s + ": reference '" + r.reference->name + "'";
  const TexelSpec& t = r.texel;
  s += ": Texel texture, Central Pitch " + num(t.central_pitch.value()) + " dB, Irregularity " + num(t.irregularity.value()) +
       " dB, texel " + num(t.texel_length.value()) + " mm, seed " + std::to_string(t.seed);
  if (t.coarse_strength != 0.0 || t.fine_strength != 1.0)
    s += ", coarse strength " + num(t.coarse_strength) + ", fine strength " + num(t.fine_strength);
  return s;
}

/// Bounds what parsing a carried document may cost before parse_document
/// prepares it (the caps Texel Studio applies, service.cpp check_cost): a
/// device by name must be built in (a name may be a path, e.g. /dev/zero),
/// and samples and texels over the longest length the JSON implies stay
/// under `cap`.
void check_carried_cost(const json& doc, std::size_t cap) {
  double longest = 0.0;
  for (const auto& name : builtin_device_names()) longest = std::max(longest, load_device(name).length().value());
  double min_texel = std::numeric_limits<double>::infinity();
  double min_spacing = std::numeric_limits<double>::infinity();
  double samples = 0.0;
  auto walk = [&](const json& v, const std::string& key, auto&& self) -> void {
    if (v.is_object()) {
      for (auto it = v.begin(); it != v.end(); ++it) self(it.value(), it.key(), self);
    } else if (v.is_array()) {
      for (const auto& x : v) self(x, key, self);
    } else if (v.is_number()) {
      const double d = std::fabs(v.get<double>());
      if (key == "texel_length_mm" && d > 0) min_texel = std::min(min_texel, d);
      if (key == "spacing_mm" && d > 0) min_spacing = std::min(min_spacing, d);
      if (key == "samples") samples = std::max(samples, d);
      if (key == "length_mm" || key == "start_mm") longest = std::max(longest, d);
    }
  };
  walk(doc, "", walk);
  if (doc.is_object() && doc.contains("device") && doc["device"].is_string()) {
    const auto names = builtin_device_names();
    if (std::find(names.begin(), names.end(), doc["device"].get<std::string>()) == names.end())
      throw FormatError("it names the device " + quote_value(doc["device"].get<std::string>()) + ", which is not built in");
  }
  if (std::isfinite(min_spacing)) longest = std::max(longest, samples * min_spacing);
  const double c = static_cast<double>(cap);
  if (samples > c || (std::isfinite(min_spacing) && longest / min_spacing > c) ||
      (std::isfinite(min_texel) && longest / min_texel > c))
    throw FormatError("it asks for more than " + std::to_string(cap) + " samples or texels");
}

}  // namespace

std::string_view to_string(Modality m) { return m == Modality::friction ? "friction" : "vibrotactile-texture"; }
std::string_view modality_name(Modality m) { return m == Modality::friction ? "Friction" : "Vibrotactile Texture"; }
Modality parse_modality(std::string_view text, std::string_view field) {
  if (text == "friction") return Modality::friction;
  if (text == "vibrotactile-texture") return Modality::vibrotactile_texture;
  throw FieldError(std::string(field), "is " + quote_value(text) + "; allowed: friction, vibrotactile-texture");
}

Exported export_hjif(const Document& doc, const ExportOptions& o) {
  if (!(o.tolerance > 0.0 && o.tolerance <= 0.5))
    throw FieldError("tolerance", "is " + num(o.tolerance) + "; allowed: > 0 … 0.5 (full scale)");
  const std::string date = today(o.date);
  {
    static const std::regex re("^[0-9]{4}-[01][0-9]-[0-3][0-9]$");
    if (date.size() != 10 || !std::regex_match(date, re))
      throw FieldError("date", "is " + quote_value(date) + "; it must be YYYY-MM-DD");
  }
  const Surface surface = prepare_surface(doc);
  const Grid grid = surface.grid();
  const std::vector<double> map = surface.render();
  const auto [timescale, on_ticks] = choose_timescale(grid.spacing.value());
  const double T = timescale;

  // Amplitudes are written with the fewest decimals whose rounding costs at
  // most a quarter of the tolerance; the rest is the interpolation's.
  int decimals = 2;
  while (decimals < 9 && 0.5 * pow10i(-decimals) > o.tolerance / 4) ++decimals;
  const double scale = pow10i(decimals);
  auto quantize = [&](double a) { return std::round(a * scale) / scale; };
  // Tolerance used while placing, a hair inside the promise so the
  // verification below (the importer's arithmetic) never sees a rounding excess.
  const double tol = o.tolerance * (1.0 - 1e-9) - 1e-12;

  ExportStats stats;
  stats.timescale = timescale;
  stats.grid_on_ticks = on_ticks;
  stats.amplitude_decimals = decimals;

  ojson perceptions = ojson::array();
  const auto& regions = surface.regions();
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const Region& region = regions[r];
    const double end_mm = region.start.value() + region.length.value();
    std::int64_t a = 0;
    while (a < grid.count && !(grid.position(a).value() >= region.start.value())) ++a;
    std::int64_t b = a;
    while (b < grid.count && grid.position(b).value() < end_mm) ++b;
    if (b <= a) continue;
    auto u = [&](std::int64_t i) { return grid.position(i).value() * T; };
    auto tick = [&](std::int64_t i) { return static_cast<std::int64_t>(std::llround(u(i))); };

    // Greedy placement: from keyframe s, the farthest sample e such that the
    // straight line to e stays within tol of every sample between (the cone
    // of admissible slopes shrinks with each sample; one pass per segment).
    std::vector<std::int64_t> keys{a};
    std::int64_t s = a;
    while (s < b - 1) {
      const double ys = quantize(map[static_cast<std::size_t>(s)]);
      const auto ps = static_cast<double>(tick(s));
      double lo = -std::numeric_limits<double>::infinity();
      double hi = std::numeric_limits<double>::infinity();
      std::int64_t best = s + 1;
      for (std::int64_t e = s + 1; e < b; ++e) {
        const double ye = quantize(map[static_cast<std::size_t>(e)]);
        const double pe = static_cast<double>(tick(e));
        if (pe > ps) {
          const double slope = (ye - ys) / (pe - ps);
          if (slope >= lo && slope <= hi && std::fabs(ye - map[static_cast<std::size_t>(e)]) <= tol) best = e;
        }
        const double du = u(e) - ps;
        if (!(du > 0.0)) break;
        lo = std::max(lo, (map[static_cast<std::size_t>(e)] - tol - ys) / du);
        hi = std::min(hi, (map[static_cast<std::size_t>(e)] + tol - ys) / du);
        if (lo > hi) break;
      }
      // Distinct ticks only: a grid finer than a tick cannot take a keyframe per sample.
      if (tick(best) <= tick(s)) {
        while (best < b - 1 && tick(best) <= tick(s)) ++best;
        if (tick(best) <= tick(s)) break;
      }
      keys.push_back(best);
      s = best;
    }

    // Verification with the importer's own evaluation; a segment that fails
    // (floating-point edge) is split at its worst sample until none does.
    CurveEffect curve;
    auto rebuild = [&] {
      curve.keyframes.clear();
      for (std::int64_t k : keys) curve.keyframes.push_back(Keyframe{tick(k), quantize(map[static_cast<std::size_t>(k)])});
    };
    rebuild();
    double worst = 0.0;
    for (int pass = 0; pass < 64; ++pass) {
      worst = 0.0;
      std::vector<std::int64_t> extra;
      std::size_t seg = 0;
      for (std::int64_t i = a; i < b; ++i) {
        while (seg + 1 < keys.size() && keys[seg + 1] <= i) ++seg;
        const double err = std::fabs(curve_at(curve, u(i)) - map[static_cast<std::size_t>(i)]);
        worst = std::max(worst, err);
        if (err > o.tolerance && keys[seg] != i && (extra.empty() || extra.back() != i)) extra.push_back(i);
      }
      if (extra.empty()) break;
      std::size_t before = keys.size();
      for (std::int64_t i : extra)
        if (std::find(keys.begin(), keys.end(), i) == keys.end()) keys.push_back(i);
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end(), [&](std::int64_t x, std::int64_t y) { return tick(x) == tick(y); }),
                 keys.end());
      if (keys.size() == before) break;
      rebuild();
    }
    if (worst > o.tolerance)
      throw InvalidArgument("the tolerance " + num(o.tolerance) + " cannot be met: on a grid of " + num(grid.spacing.value()) +
                            " mm with " + std::to_string(timescale) + " ticks per mm the samples reproduce the map to " +
                            num(worst) + " at best");
    stats.max_error = std::max(stats.max_error, worst);
    stats.keyframes += keys.size();
    stats.samples += static_cast<std::size_t>(b - a);

    const std::int64_t origin = curve.keyframes.front().position;
    ojson kfs = ojson::array();
    for (const Keyframe& k : curve.keyframes)
      kfs.push_back(ojson{{"relative_position", k.position - origin}, {"amplitude_modulation", k.amplitude}});
    ojson effect{{"effect_type", "Basis"},     {"id", 0}, {"position", origin}, {"phase", 0}, {"base_signal", "Sine"},
                 {"keyframes", std::move(kfs)}};
    const auto upper = static_cast<std::int64_t>(std::ceil(doc.device.band_top().value()));
    ojson band{{"band_type", "Curve"},
               {"curve_type", "Linear"},
               {"lower_frequency_limit", 0},
               {"upper_frequency_limit", upper},
               {"effects", ojson::array({std::move(effect)})}};
    ojson channel{{"id", 0},
                  {"description", "amplitude map on the " + doc.device.name + " grid, " + num(grid.spacing.value()) +
                                      " mm per sample, samples " + std::to_string(a) + " … " + std::to_string(b - 1)},
                  {"gain", 1.0},
                  {"mixing_coefficient", 1.0},
                  {"body_part_mask", 0},
                  {"reference_device_id", 0},
                  {"sample_count", b - a},
                  {"bands", ojson::array({std::move(band)})}};
    const RegionSpec* spec = r < doc.regions.size() ? &doc.regions[r] : nullptr;
    // Surface sorts regions by start; find the spec with this start.
    for (const RegionSpec& rs : doc.regions)
      if (rs.start.value() == region.start.value()) spec = &rs;
    ojson perception{{"id", static_cast<std::int64_t>(r)},
                     {"avatar_id", 0},
                     {"description", spec ? region_summary(*spec, r) : "region " + std::to_string(r)},
                     {"perception_modality", std::string(modality_name(o.modality))},
                     {"unit_exponent", -3},
                     {"reference_devices", ojson::array({ojson{{"id", 0}, {"name", doc.device.name}}})},
                     {"effect_library", ojson::array()},
                     {"channels", ojson::array({std::move(channel)})}};
    perceptions.push_back(std::move(perception));
    ++stats.perceptions;
  }
  if (perceptions.empty()) throw InvalidArgument("the document has no region with grid samples: nothing to export");

  // The document, compact, after the marker: exact parameters for Texel.
  const std::string carried = ojson::parse(document_json(doc)).dump();
  std::string description = "Texel virtual texture on " + doc.device.name + " (" + std::to_string(doc.regions.size()) +
                            (doc.regions.size() == 1 ? " region" : " regions") + "), amplitude map within " + num(o.tolerance) +
                            " of full scale. texel-tolerance:" + num(o.tolerance) + " " + std::string(carried_marker) + carried;
  ojson root{{"version", "2025"},
             {"profile", "Main"},
             {"level", 1},
             {"date", date},
             {"description", std::move(description)},
             {"timescale", timescale},
             {"avatars", ojson::array()},
             {"perceptions", std::move(perceptions)},
             {"syncs", ojson::array()}};
  Exported out;
  out.json = root.dump() + "\n";
  out.stats = stats;
  return out;
}

Experience parse_hjif(std::string_view text, std::string_view origin, const ImportLimits& limits) {
  Walker w = walk_text(text, origin, limits, true);
  if (!w.errors.empty()) throw FormatError("'" + std::string(origin) + "': " + w.errors.front());
  Experience e = std::move(w.exp);
  if (e.perceptions.empty()) {
    std::string found;
    for (const auto& m : e.skipped) found += (found.empty() ? "" : ", ") + m;
    throw FormatError("'" + std::string(origin) +
                      "' has no perception Texel can sample (Friction, Vibrotactile Texture, or "
                      "Vibrotactile at a swipe speed)" +
                      (found.empty() ? std::string() : "; it has: " + found));
  }
  // The carried document, used only when its rendering agrees with the curves.
  const auto at = e.description.find(carried_marker);
  if (at != std::string::npos) {
    try {
      double tolerance = default_tolerance;
      const auto t = e.description.rfind("texel-tolerance:", at);
      if (t != std::string::npos) tolerance = std::strtod(e.description.c_str() + t + 16, nullptr);
      if (!(tolerance > 0.0 && tolerance <= 0.5)) throw FormatError("its texel-tolerance is not in (0, 0.5]");
      const std::string_view carried = std::string_view(e.description).substr(at + carried_marker.size());
      if (nesting_depth(carried, limits.max_depth) > limits.max_depth) throw FormatError("it nests JSON too deeply");
      check_carried_cost(detail::parse_json(carried, "the carried document"), limits.max_keyframes);
      Document doc = parse_document(carried, "the carried document");
      if (doc.device.samples > static_cast<std::int64_t>(limits.max_keyframes))
        throw FormatError("its device has " + std::to_string(doc.device.samples) + " samples, more than are read");
      const Surface s = prepare_surface(doc);
      const std::vector<double> map = s.render();
      std::vector<double> x(map.size());
      for (std::size_t i = 0; i < x.size(); ++i) x[i] = s.grid().position(static_cast<std::int64_t>(i)).value();
      const std::vector<double> curve = evaluate(e, x);
      double worst = 0.0;
      for (std::size_t i = 0; i < map.size(); ++i) worst = std::max(worst, std::fabs(curve[i] - map[i]));
      if (!(worst <= tolerance + 1e-9))
        throw FormatError("it renders up to " + num(worst) + " away from the file's curves (tolerance " + num(tolerance) + ")");
      e.carried = std::move(doc);
    } catch (const Error& err) {
      e.carried_rejected = std::string("the carried Texel document is not used: ") + err.what();
    }
  }
  return e;
}

Experience load_hjif(const std::string& path, const ImportLimits& limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > limits.max_bytes)
    throw FormatError("'" + path + "' has " + std::to_string(size) + " bytes; at most " + std::to_string(limits.max_bytes) +
                      " are read");
  return parse_hjif(read_file(path), path, limits);
}

std::vector<std::string> conformance_errors(std::string_view text) {
  try {
    return walk_text(text, "hjif", ImportLimits{}, false).errors;
  } catch (const Error& e) {
    return {e.what()};
  }
}

std::vector<double> evaluate(const Experience& e, std::span<const double> x, std::optional<MmPerSecond> v) {
  std::vector<double> out(x.size(), 0.0);
  // On ascending positions (every grid) each effect visits only the
  // positions it covers; the total is bounded so that a file of many
  // overlapping effects is refused rather than sampled for hours.
  const bool ascending = std::is_sorted(x.begin(), x.end());
  constexpr double max_work = 4294967296.0;  // 2^32 effect-samples
  double work = 0.0;
  for (const Perception& p : e.perceptions) {
    const double k = ticks_per_mm(e, p, v);
    for (const CurveEffect& c : p.effects) {
      std::size_t first = 0;
      std::size_t last = x.size();
      if (ascending && !c.keyframes.empty()) {
        const double lo = (static_cast<double>(c.keyframes.front().position) - 1.0) / k;
        const double hi = (static_cast<double>(c.keyframes.back().position) + 1.0) / k;
        first = static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), lo) - x.begin());
        last = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), hi) - x.begin());
      }
      work += static_cast<double>(last - first);
      if (work > max_work)
        throw FormatError(
            "the file's effects cover more than 2^32 samples in all on this grid (overlapping effects); "
            "it is not sampled");
      for (std::size_t i = first; i < last; ++i) out[i] += curve_at(c, x[i] * k);
    }
  }
  return out;
}

double extent_mm(const Experience& e, std::optional<MmPerSecond> v) {
  double most = 0.0;
  for (const Perception& p : e.perceptions) {
    const double k = ticks_per_mm(e, p, v);
    for (const CurveEffect& c : p.effects)
      if (!c.keyframes.empty()) most = std::max(most, static_cast<double>(c.keyframes.back().position) / k);
  }
  return most;
}

}  // namespace texel::hjif
