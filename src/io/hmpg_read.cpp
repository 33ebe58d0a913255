// Reading binary MPEG-I Haptics streams (.hmpg): the units and packets of
// the syntax hmpg_syntax.hpp describes, decoded into the .hjif JSON the
// reader and its checks take (docs/interchange.md "Binary .hmpg", with where
// Texel reads more liberally than the reference writer).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>

#include "hmpg_syntax.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"

namespace texel::hmpg {
namespace {

using namespace syntax;

struct BandRef {
  std::size_t perception = 0;
  std::size_t channel = 0;
  std::size_t band = 0;
  std::string type;
};

class Decoder {
 public:
  Decoder(std::span<const std::byte> b, std::string origin, const hjif::ImportLimits& limits)
      : b_(b), origin_(std::move(origin)), limits_(limits) {}

  std::string run() {
    std::size_t pos = 0;
    const std::size_t end = b_.size() * 8;
    if (b_.empty()) throw FormatError("'" + origin_ + "' is empty");
    while (end - pos >= 8) {
      BitReader h(b_, pos, end, origin_);
      const auto type = h.get(6, "a unit's type");
      if (type > 3) h.fail("a unit's type is " + std::to_string(type) + "; the syntax defines 0 … 3");
      h.get(2, "a unit's sync flag");
      h.get(4, "a unit's layer");
      h.get(24, "a unit's duration");
      const auto length = h.get(32, "a unit's length");
      h.get(4, "a unit's reserved bits");
      if (length > h.left() / 8)
        h.fail("a unit declares " + std::to_string(length) + " bytes; " + std::to_string(h.left() / 8) + " remain");
      std::size_t p = h.pos();
      const std::size_t unit_end = p + length * 8;
      while (unit_end - p >= 24) p = packet(p, unit_end);
      pos = unit_end;
    }
    if (!root_.contains("version")) throw FormatError("'" + origin_ + "' has no experience metadata packet");
    if (!root_.contains("timescale")) root_["timescale"] = 1000;
    ojson out;
    for (const char* k : {"version", "profile", "level", "date", "description", "timescale", "avatars"}) out[k] = root_[k];
    out["perceptions"] = perceptions_;
    out["syncs"] = ojson::array();
    // Strings are bytes in the stream: what is not UTF-8 is read as U+FFFD.
    return out.dump(-1, ' ', false, ojson::error_handler_t::replace);
  }

 private:
  std::span<const std::byte> b_;
  std::string origin_;
  hjif::ImportLimits limits_;
  ojson root_ = ojson::object();
  ojson perceptions_ = ojson::array();
  std::vector<std::pair<std::int64_t, BandRef>> bands_;  // band id → where it is
  std::size_t keyframes_ = 0;

  std::size_t packet(std::size_t pos, std::size_t unit_end) {
    BitReader h(b_, pos, unit_end, origin_);
    const auto type = h.get(6, "a packet's type");
    const auto bytes = h.get(17, "a packet's length");
    h.get(1, "a packet's reserved bit");
    if (type > 11) h.fail("a packet's type is " + std::to_string(type) + "; the syntax defines 0 … 11");
    if (bytes > h.left() / 8)
      h.fail("a packet declares " + std::to_string(bytes) + " bytes; its unit has " + std::to_string(h.left() / 8) + " left");
    const std::size_t begin = h.pos();
    const std::size_t end = begin + bytes * 8;
    // A description longer than 255 bytes: the reference writer wraps its 8-bit
    // length; read it as the length + 256·k that ends the packet exactly.
    auto with_wrap = [&](auto&& parse) {
      std::optional<FormatError> first;
      for (std::size_t extra = 0; extra <= bytes; extra += 256) {
        BitReader r(b_, begin, end, origin_);
        try {
          parse(r, extra);
        } catch (const FormatError& e) {
          if (!first) first = e;
          continue;
        }
        if (r.left() < 8) return;
        if (!first)
          first = FormatError("'" + origin_ + "': a packet at byte " + std::to_string(pos / 8) + " has " +
                              std::to_string(r.left() / 8) + " bytes after its last field");
      }
      throw *first;
    };
    switch (static_cast<PacketType>(type)) {
      case PacketType::initialization_timing: {
        BitReader r(b_, begin, end, origin_);
        r.get(32, "the initial time");
        const auto timescale = r.get(32, "the timescale");
        if (timescale == 0) r.fail("the timescale is 0");
        root_["timescale"] = timescale;
        break;
      }
      case PacketType::metadata_haptics: with_wrap([&](BitReader& r, std::size_t extra) { haptics(r, extra); }); break;
      case PacketType::metadata_perception:
        with_wrap([&](BitReader& r, std::size_t extra) { perception(r, extra, false); });
        perception_commit();
        break;
      case PacketType::metadata_channel:
        with_wrap([&](BitReader& r, std::size_t extra) { channel(r, extra, false); });
        channel_commit();
        break;
      case PacketType::metadata_band: {
        BitReader r(b_, begin, end, origin_);
        band(r);
        break;
      }
      case PacketType::data: {
        BitReader r(b_, begin, end, origin_);
        data(r);
        break;
      }
      case PacketType::effect_library:
        throw FormatError("'" + origin_ + "' has an effect library packet at byte " + std::to_string(pos / 8) +
                          "; Texel does not read effect libraries from .hmpg");
      default: break;  // timing and CRC packets: nothing Texel reads
    }
    return end;
  }

  // Pending results of the last successful attempt (a retry with a wrapped length re-parses).
  ojson pending_ = ojson::object();

  void haptics(BitReader& r, std::size_t extra) {
    root_["version"] = r.string("the version");
    root_["profile"] = r.string("the profile");
    root_["level"] = r.get(8, "the level");
    root_["date"] = r.string("the date");
    root_["description"] = r.string("the description", extra);
    r.get(8, "the perception count");
    const std::size_t n = r.count(8, 24, "the avatar count");
    ojson avatars = ojson::array();
    for (std::size_t i = 0; i < n; ++i) {
      ojson a;
      a["id"] = r.get(8, "an avatar's id");
      a["lod"] = r.get(8, "an avatar's lod");
      const auto type = r.code(8, kAvatarCodes, "an avatar's type");
      a["type"] = type;
      if (type == "Custom") a["mesh"] = r.string("an avatar's mesh");
      avatars.push_back(std::move(a));
    }
    root_["avatars"] = std::move(avatars);
  }

  void perception(BitReader& r, std::size_t extra, bool) {
    ojson p;
    p["id"] = r.get(8, "a perception's id");
    const auto priority = r.get(8, "a perception's priority");
    p["description"] = r.string("a perception's description", extra);
    p["perception_modality"] = r.code(8, kModalityCodes, "a perception's modality");
    p["avatar_id"] = r.get(8, "a perception's avatar id");
    if (priority != 0) p["priority"] = priority;
    if (r.get(16, "a perception's library count") != 0)
      r.fail("a perception announces library effects, which Texel does not read");
    if (r.get(1, "a perception's semantic flag") != 0) p["semantic_scheme"] = r.string("a perception's semantic scheme");
    p["unit_exponent"] = static_cast<std::int8_t>(r.get(8, "a perception's unit exponent"));
    p["perception_unit_exponent"] = static_cast<std::int8_t>(r.get(8, "a perception's perception unit exponent"));
    const std::size_t n = r.count(8, 8 + 8 + 32 + 12, "a perception's reference device count");
    ojson devices = ojson::array();
    for (std::size_t i = 0; i < n; ++i) {
      ojson d;
      d["id"] = r.get(8, "a reference device's id");
      d["name"] = r.string("a reference device's name");
      d["body_part_mask"] = r.get(32, "a reference device's body part mask");
      const auto mask = r.get(12, "a reference device's field mask");
      for (std::size_t f = 0; f < std::size(kDeviceFields); ++f)
        if (mask & (0x800U >> f)) d[std::string(kDeviceFields[f])] = r.real(0.0, kMaxFloat, 32, "a reference device's number");
      if (mask & 1U) d["type"] = r.code(4, kDeviceTypeCodes, "a reference device's type");
      devices.push_back(std::move(d));
    }
    p["reference_devices"] = std::move(devices);
    p["effect_library"] = ojson::array();
    r.get(16, "a perception's channel count");
    p["channels"] = ojson::array();
    pending_ = std::move(p);
  }
  void perception_commit() {
    for (const auto& q : perceptions_)
      if (q["id"] == pending_["id"]) return;  // repeated in a later initialization unit
    perceptions_.push_back(std::move(pending_));
  }
  std::size_t perception_index(std::uint64_t id, const BitReader& r) {
    for (std::size_t i = 0; i < perceptions_.size(); ++i)
      if (perceptions_[i]["id"] == id) return i;
    r.fail("a packet refers to perception " + std::to_string(id) + ", which no earlier packet described");
  }

  std::size_t pending_perception_ = 0;
  void channel(BitReader& r, std::size_t extra, bool) {
    ojson c;
    c["id"] = r.get(16, "a channel's id");
    pending_perception_ = perception_index(r.get(8, "a channel's perception id"), r);
    const auto priority = r.get(8, "a channel's priority");
    c["description"] = r.string("a channel's description", extra);
    const auto device = r.get(8, "a channel's reference device id");
    c["gain"] = r.real(-kMaxFloat, kMaxFloat, 32, "a channel's gain");
    c["mixing_coefficient"] = r.real(0.0, kMaxFloat, 32, "a channel's mixing coefficient");
    if (priority != 0) c["priority"] = priority;
    if (device != 255) c["reference_device_id"] = device;
    const auto mask = r.get(8, "a channel's field mask");
    if (mask & 1U) {
      c["body_part_mask"] = r.get(32, "a channel's body part mask");
    } else if (mask & 2U) {
      c["actuator_resolution"] = vector(r, "a channel's actuator resolution");
      const std::size_t parts = r.count(8, 8, "a channel's body part target count");
      ojson targets = ojson::array();
      for (std::size_t i = 0; i < parts; ++i) {
        const auto at = r.pos() / 8;
        const auto code = r.get(8, "a body part target");
        const auto* it = std::find(std::begin(kBodyPartCodes), std::end(kBodyPartCodes), code);
        if (it == std::end(kBodyPartCodes))
          r.fail("a body part target has code " + std::to_string(code) + " (at byte " + std::to_string(at) +
                 "), which the syntax does not define");
        targets.push_back(hjif::detail::kBodyParts[it - std::begin(kBodyPartCodes)]);
      }
      c["body_part_target"] = std::move(targets);
      const std::size_t actuators = r.count(8, 24, "a channel's actuator target count");
      ojson at = ojson::array();
      for (std::size_t i = 0; i < actuators; ++i) at.push_back(vector(r, "an actuator target"));
      c["actuator_target"] = std::move(at);
    }
    if (const auto fs = r.get(32, "a channel's sampling frequency"); fs > 0) {
      c["frequency_sampling"] = fs;
      c["sample_count"] = r.get(32, "a channel's sample count");
    }
    if (mask & 4U) c["direction"] = vector(r, "a channel's direction");
    const std::size_t vertices = r.count(16, 32, "a channel's vertex count");
    if (vertices > 0) {
      ojson v = ojson::array();
      for (std::size_t i = 0; i < vertices; ++i) v.push_back(r.get(32, "a vertex"));
      c["vertices"] = std::move(v);
    }
    r.get(8, "a channel's band count");
    c["bands"] = ojson::array();
    pending_ = std::move(c);
  }
  void channel_commit() {
    auto& channels = perceptions_[pending_perception_]["channels"];
    for (const auto& q : channels)
      if (q["id"] == pending_["id"]) return;
    channels.push_back(std::move(pending_));
  }
  static ojson vector(BitReader& r, std::string_view what) {
    ojson v;
    for (const char* axis : {"X", "Y", "Z"}) v[axis] = static_cast<std::int8_t>(r.get(8, what));
    return v;
  }
  std::size_t channel_index(std::size_t p, std::uint64_t id, const BitReader& r) {
    const auto& channels = perceptions_[p]["channels"];
    for (std::size_t i = 0; i < channels.size(); ++i)
      if (channels[i]["id"] == id) return i;
    r.fail("a packet refers to channel " + std::to_string(id) + ", which no earlier packet described");
  }

  void band(BitReader& r) {
    const auto id = static_cast<std::int64_t>(r.get(8, "a band's id"));
    const std::size_t p = perception_index(r.get(8, "a band's perception id"), r);
    const std::size_t c = channel_index(p, r.get(16, "a band's channel id"), r);
    const auto priority = r.get(8, "a band's priority");
    ojson b;
    const std::string type(r.code(3, kBandCodes, "a band's type"));
    b["band_type"] = type;
    if (type == "Curve") b["curve_type"] = r.code(4, kCurveCodes, "a band's curve type");
    if (type == "WaveletWave") b["block_length"] = r.get(8, "a band's block length");
    if (priority != 0) b["priority"] = priority;
    b["lower_frequency_limit"] = r.get(16, "a band's lower frequency limit");
    b["upper_frequency_limit"] = r.get(16, "a band's upper frequency limit");
    r.get(16, "a band's effect count");
    b["effects"] = ojson::array();
    for (const auto& [known, ref] : bands_)
      if (known == id) return;  // repeated in a later initialization unit
    auto& bands = perceptions_[p]["channels"][c]["bands"];
    bands.push_back(std::move(b));
    bands_.emplace_back(id, BandRef{p, c, bands.size() - 1, type});
  }

  void data(BitReader& r) {
    r.get(1, "a data packet's access-unit type");
    const std::size_t p = perception_index(r.get(8, "a data packet's perception id"), r);
    const std::size_t c = channel_index(p, r.get(16, "a data packet's channel id"), r);
    const auto id = static_cast<std::int64_t>(r.get(8, "a data packet's band id"));
    const BandRef* ref = nullptr;
    for (const auto& [known, b] : bands_)
      if (known == id && b.perception == p && b.channel == c) ref = &b;
    if (!ref) r.fail("a data packet refers to band " + std::to_string(id) + ", which no earlier packet described");
    const std::string modality = perceptions_[p]["perception_modality"];
    if (!spatial_code(modality))
      r.fail("a data packet holds temporal data ('" + modality + "'); Texel reads the spatial data syntax only");
    const std::size_t n = r.count(16, 2 + 25 + 16, "a data packet's effect count");
    auto& effects = perceptions_[p]["channels"][c]["bands"][ref->band]["effects"];
    for (std::size_t i = 0; i < n; ++i) {
      ojson e;
      const std::string type(r.code(2, kEffectCodes, "an effect's type"));
      if (type != "Basis") r.fail("an effect is '" + type + "'; Texel reads Basis effects from .hmpg");
      if (ref->type == "WaveletWave") r.fail("a band is 'WaveletWave'; Texel does not read wavelet streams");
      e["effect_type"] = type;
      e["position"] = r.get(25, "an effect's position");
      if (ref->type == "VectorialWave") {
        e["phase"] = r.real(0.0, 6.28318, 16, "an effect's phase");
        e["base_signal"] = r.code(4, hjif::detail::kBaseSignals, "an effect's base signal");
      }
      const std::size_t min_bits = ref->type == "Transient" ? 40 : ref->type == "Curve" ? 24 : 18;
      const std::size_t k = r.count(16, min_bits, "an effect's keyframe count");
      keyframes_ += k;
      if (keyframes_ > limits_.max_keyframes)
        r.fail("the stream holds more than " + std::to_string(limits_.max_keyframes) + " keyframes, more than are read");
      ojson kfs = ojson::array();
      std::int64_t last = -1;
      for (std::size_t j = 0; j < k; ++j) {
        ojson kf;
        std::int64_t position = 0;
        if (ref->type == "Curve" || ref->type == "Transient") {
          kf["amplitude_modulation"] = r.real(-1.0, 1.0, 8, "a keyframe's amplitude");
          position = static_cast<std::int64_t>(r.get(16, "a keyframe's position"));
          if (ref->type == "Transient") kf["frequency_modulation"] = r.get(16, "a keyframe's frequency");
        } else {
          const auto mask = r.get(2, "a keyframe's field mask");
          if (mask & 1U) kf["amplitude_modulation"] = r.real(-1.0, 1.0, 8, "a keyframe's amplitude");
          position = static_cast<std::int64_t>(r.get(16, "a keyframe's position"));
          if (mask & 2U) kf["frequency_modulation"] = r.get(16, "a keyframe's frequency");
        }
        // 16-bit positions past 65,535 wrap in the reference writer; in a Curve
        // effect (strictly increasing) they are unwrapped.
        if (ref->type == "Curve")
          while (position <= last) position += kMaxRelative + 1;
        last = position;
        kf["relative_position"] = position;
        kfs.push_back(std::move(kf));
      }
      e["keyframes"] = std::move(kfs);
      effects.push_back(std::move(e));
    }
  }
};

}  // namespace

std::string decode(std::span<const std::byte> bytes, std::string_view origin, const hjif::ImportLimits& limits) {
  if (bytes.size() > limits.max_bytes)
    throw FormatError("'" + std::string(origin) + "' has " + std::to_string(bytes.size()) + " bytes; at most " +
                      std::to_string(limits.max_bytes) + " are read");
  return Decoder(bytes, std::string(origin), limits).run();
}

hjif::Experience load(const std::string& path, const hjif::ImportLimits& limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > limits.max_bytes)
    throw FormatError("'" + path + "' has " + std::to_string(size) + " bytes; at most " + std::to_string(limits.max_bytes) +
                      " are read");
  const std::string text = read_file(path);
  const auto* p = reinterpret_cast<const std::byte*>(text.data());
  return hjif::parse_hjif(decode({p, text.size()}, path, limits), path, limits);
}

}  // namespace texel::hmpg
