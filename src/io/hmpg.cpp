// Binary MPEG-I Haptics streams (.hmpg, MIHS units and packets), written and
// read for the spatial data Texel uses. The syntax (field order and widths,
// codes, quantization) is the one the public reference software's stream
// writer produces; docs/interchange.md "Binary .hmpg" lists every field read
// and written here, and where Texel reads more liberally than that writer.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "hjif_internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/surface.hpp"

namespace texel::hmpg {
namespace {

using ojson = nlohmann::ordered_json;
using texel::detail::num;

// --- the syntax's codes ----------------------------------------------------------

enum class UnitType : std::uint32_t { initialization = 0, temporal = 1, spatial = 2, silent = 3 };
enum class PacketType : std::uint32_t {
  timing = 0,
  metadata_haptics = 1,
  metadata_perception = 2,
  metadata_channel = 3,
  metadata_band = 4,
  data = 5,
  effect_library = 6,
  crc32 = 7,
  crc16 = 8,
  global_crc16 = 9,
  global_crc32 = 10,
  initialization_timing = 11,
};
// Codes as the reference software numbers them.
constexpr std::string_view kModalityCodes[] = {
    "Other", "Pressure", "Acceleration",         "Velocity",  "Position", "Temperature",   "Vibrotactile", "Water",
    "Wind",  "Force",    "Vibrotactile Texture", "Stiffness", "Friction", "Electrotactile"};
constexpr std::string_view kBandCodes[] = {"Transient", "Curve", "VectorialWave", "WaveletWave"};
constexpr std::string_view kCurveCodes[] = {"Unknown", "Cubic", "Linear", "Akima", "Bezier", "BSpline"};
constexpr std::string_view kEffectCodes[] = {"Basis", "Reference", "Composite"};
constexpr std::string_view kAvatarCodes[] = {"Custom", "Vibration", "Pressure", "Temperature"};
constexpr std::string_view kDeviceTypeCodes[] = {"Unknown", "LRA", "VCA", "ERM", "Piezo"};
// Body-part codes, parallel to hjif::detail::kBodyParts (the schema's names).
constexpr std::uint8_t kBodyPartCodes[] = {0,  1,  10, 11, 12, 13, 14, 15, 20, 21, 22, 23, 24, 30, 31, 32, 33, 34, 35,  36,
                                           37, 40, 41, 42, 43, 50, 51, 52, 53, 54, 55, 56, 57, 58, 59, 60, 61, 62, 254, 255};
static_assert(std::size(kBodyPartCodes) == std::size(hjif::detail::kBodyParts));
constexpr double kMaxFloat = 10000.0;
// A reference device's optional numbers in the order of their presence mask, all over [0, 10000].
constexpr auto kDeviceFields = [] {
  std::array<std::string_view, std::size(hjif::detail::kDeviceNumbers) + 1> a{};
  std::copy(std::begin(hjif::detail::kDeviceNumbers), std::end(hjif::detail::kDeviceNumbers), a.begin());
  a.back() = "custom";
  return a;
}();
constexpr std::uint32_t kNominalDuration = 128;  // the reference writer's packet duration
constexpr std::size_t kMaxPayload = (std::size_t{1} << 17) - 1;
constexpr std::int64_t kMaxRelative = 65535;  // 16-bit keyframe positions
constexpr std::int64_t kMaxEffectPosition = (std::int64_t{1} << 25) - 1;
constexpr std::size_t kMaxChunkKeyframes = 40000;  // 3 bytes each: an effect fits a packet

template <std::size_t N>
std::optional<std::uint32_t> code_of(std::string_view v, const std::string_view (&set)[N]) {
  for (std::size_t i = 0; i < N; ++i)
    if (set[i] == v) return static_cast<std::uint32_t>(i);
  return std::nullopt;
}

bool spatial_code(std::string_view modality) {
  return modality == "Friction" || modality == "Vibrotactile Texture" || modality == "Stiffness";
}

// --- bits -------------------------------------------------------------------------

class BitWriter {
 public:
  void put(std::uint64_t v, int bits) {
    for (int i = bits - 1; i >= 0; --i) bits_.push_back(((v >> i) & 1U) != 0);
  }
  void pad() {
    while (bits_.size() % 8 != 0) bits_.push_back(false);
  }
  /// A quantized number over [lo, hi] in `bits` bits (rounded to the nearest code).
  void real(double v, double lo, double hi, int bits) {
    const double full = std::ldexp(1.0, bits) - 1.0;
    const double t = std::clamp((v - lo) / (hi - lo), 0.0, 1.0);
    put(static_cast<std::uint64_t>(std::llround(t * full)), bits);
  }
  void string(const std::string& s) {
    put(s.size(), 8);
    for (char c : s) put(static_cast<unsigned char>(c), 8);
  }
  void append(const BitWriter& o) { bits_.insert(bits_.end(), o.bits_.begin(), o.bits_.end()); }
  std::size_t size() const { return bits_.size(); }
  std::vector<std::byte> bytes() const {
    std::vector<std::byte> out((bits_.size() + 7) / 8);
    for (std::size_t i = 0; i < bits_.size(); ++i)
      if (bits_[i]) out[i / 8] |= static_cast<std::byte>(0x80U >> (i % 8));
    return out;
  }

 private:
  std::vector<bool> bits_;
};

class BitReader {
 public:
  BitReader(std::span<const std::byte> b, std::size_t begin_bit, std::size_t end_bit, std::string origin)
      : b_(b), pos_(begin_bit), end_(end_bit), origin_(std::move(origin)) {}
  std::uint64_t get(int bits, std::string_view what) {
    if (end_ - pos_ < static_cast<std::size_t>(bits))
      throw FormatError("'" + origin_ + "' is truncated: " + std::string(what) + " at byte " + std::to_string(pos_ / 8) +
                        " runs past the end of its " + (end_ == b_.size() * 8 ? "stream" : "packet"));
    std::uint64_t v = 0;
    for (int i = 0; i < bits; ++i, ++pos_) v = (v << 1) | ((static_cast<unsigned>(b_[pos_ / 8]) >> (7 - pos_ % 8)) & 1U);
    return v;
  }
  double real(double lo, double hi, int bits, std::string_view what) {
    const double full = std::ldexp(1.0, bits) - 1.0;
    return static_cast<double>(get(bits, what)) / full * (hi - lo) + lo;
  }
  std::string string(std::string_view what, std::size_t extra = 0) {
    const std::size_t n = get(8, what) + extra;
    if ((end_ - pos_) / 8 < n) get(static_cast<int>(std::min<std::size_t>(64, end_ - pos_ + 1)), what);  // throws
    std::string s(n, '\0');
    for (auto& c : s) c = static_cast<char>(get(8, what));
    return s;
  }
  template <std::size_t N>
  std::string_view code(int bits, const std::string_view (&set)[N], std::string_view what) {
    const auto at = pos_ / 8;
    const auto v = get(bits, what);
    if (v >= N)
      throw FormatError("'" + origin_ + "': " + std::string(what) + " has code " + std::to_string(v) + " at byte " +
                        std::to_string(at) + "; the syntax defines 0 … " + std::to_string(N - 1));
    return set[v];
  }
  /// Refuses a count whose items cannot all fit in what remains.
  std::size_t count(int bits, std::size_t min_item_bits, std::string_view what) {
    const auto at = pos_ / 8;
    const auto n = static_cast<std::size_t>(get(bits, what));
    if (min_item_bits > 0 && n > (end_ - pos_) / min_item_bits)
      throw FormatError("'" + origin_ + "': " + std::string(what) + " is " + std::to_string(n) + " at byte " +
                        std::to_string(at) + ", more than the " + std::to_string((end_ - pos_) / 8) + " bytes left can hold");
    return n;
  }
  std::size_t pos() const { return pos_; }
  std::size_t left() const { return end_ - pos_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw FormatError("'" + origin_ + "': " + what + " (byte " + std::to_string(pos_ / 8) + ")");
  }

 private:
  std::span<const std::byte> b_;
  std::size_t pos_;
  std::size_t end_;
  std::string origin_;
};

// --- writing ----------------------------------------------------------------------

/// A string field of at most 255 bytes; descriptions are shortened (before a
/// carried Texel document, else at a UTF-8 boundary), other fields refused.
std::string short_string(const std::string& s, const std::string& field, bool shorten) {
  if (s.size() <= 255) return s;
  if (!shorten) throw FieldError(field, "has " + std::to_string(s.size()) + " bytes; the binary syntax carries at most 255");
  std::string out = s;
  if (const auto t = out.find(" texel-tolerance:"); t != std::string::npos) out.resize(t);
  if (out.size() > 255) {
    std::size_t n = 255;
    while (n > 0 && (static_cast<unsigned char>(out[n]) & 0xC0) == 0x80) --n;
    out.resize(n);
  }
  return out;
}

std::int64_t int_of(const ojson& o, const char* key, std::int64_t fallback) {
  const auto it = o.find(key);
  return it != o.end() && it->is_number_integer() ? it->get<std::int64_t>() : fallback;
}
double real_of(const ojson& o, const char* key, double fallback) {
  const auto it = o.find(key);
  return it != o.end() && it->is_number() ? it->get<double>() : fallback;
}
std::string str_of(const ojson& o, const char* key) {
  const auto it = o.find(key);
  return it != o.end() && it->is_string() ? it->get<std::string>() : std::string();
}
void bounded(std::int64_t v, std::int64_t hi, const std::string& field) {
  if (v < 0 || v > hi)
    throw FieldError(field, "is " + std::to_string(v) + "; the binary syntax carries 0 … " + std::to_string(hi));
}

/// A packet: 6-bit type, 17-bit payload length in bytes, 1 reserved bit, the payload padded to bytes.
BitWriter packet(PacketType type, BitWriter payload) {
  payload.pad();
  const std::size_t bytes = payload.size() / 8;
  if (bytes > kMaxPayload)
    throw InvalidArgument("a packet would carry " + std::to_string(bytes) + " bytes; the binary syntax's limit is " +
                          std::to_string(kMaxPayload));
  BitWriter p;
  p.put(static_cast<std::uint32_t>(type), 6);
  p.put(bytes, 17);
  p.put(0, 1);
  p.append(payload);
  return p;
}

/// A unit: 6-bit type, 2-bit sync (0), 4-bit layer (0), 24-bit duration, 32-bit length in bytes, 4 reserved bits.
BitWriter unit(UnitType type, std::uint32_t duration, const std::vector<BitWriter>& packets) {
  BitWriter body;
  for (const auto& p : packets) body.append(p);
  BitWriter u;
  u.put(static_cast<std::uint32_t>(type), 6);
  u.put(0, 2);
  u.put(0, 4);
  u.put(duration, 24);
  u.put(body.size() / 8, 32);
  u.put(0, 4);
  u.append(body);
  return u;
}

void write_vector(BitWriter& w, const ojson& v) {
  for (const char* axis : {"X", "Y", "Z"}) w.put(static_cast<std::uint8_t>(static_cast<std::int8_t>(int_of(v, axis, 0))), 8);
}

using Points = std::vector<std::pair<std::int64_t, double>>;

/// One Curve effect's keyframes as effects of at most 65,535 ticks and
/// kMaxChunkKeyframes keyframes each (16-bit positions and counts). Where it
/// is cut, the next effect starts one tick after the last keyframe, on the
/// line to the following one; a segment longer than an effect gets a point
/// on its line at the effect's end.
std::vector<std::pair<std::int64_t, Points>> chunks(std::int64_t position, const Points& kfs) {
  Points pts;
  for (const auto& [rel, amp] : kfs) pts.emplace_back(position + rel, amp);
  std::vector<std::pair<std::int64_t, Points>> out;
  std::size_t i = 0;
  std::optional<std::pair<std::int64_t, double>> carry;
  while (i < pts.size() || carry) {
    Points cur;
    std::int64_t start = 0;
    if (carry) {
      start = carry->first;
      cur.emplace_back(0, carry->second);
      carry.reset();
    } else {
      start = pts[i].first;
      cur.emplace_back(0, pts[i].second);
      ++i;
    }
    while (i < pts.size() && pts[i].first - start <= kMaxRelative && cur.size() < kMaxChunkKeyframes) {
      cur.emplace_back(pts[i].first - start, pts[i].second);
      ++i;
    }
    if (i < pts.size()) {
      std::int64_t t0 = start + cur.back().first;
      double a0 = cur.back().second;
      const std::int64_t t1 = pts[i].first;
      const double a1 = pts[i].second;
      if (t1 - start > kMaxRelative && cur.size() < kMaxChunkKeyframes && t0 < start + kMaxRelative) {
        const std::int64_t te = start + kMaxRelative;
        const double ae = a0 + (a1 - a0) * static_cast<double>(te - t0) / static_cast<double>(t1 - t0);
        cur.emplace_back(kMaxRelative, ae);
        t0 = te, a0 = ae;
      }
      if (t1 > t0 + 1) carry = std::make_pair(t0 + 1, a0 + (a1 - a0) / static_cast<double>(t1 - t0));
    }
    out.emplace_back(start, std::move(cur));
  }
  return out;
}

// --- reading ----------------------------------------------------------------------

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

std::vector<std::byte> encode(std::string_view text) {
  if (const auto errors = hjif::conformance_errors(text); !errors.empty())
    throw InvalidArgument("the .hjif to encode is not conformant: " + errors.front());
  const ojson root = ojson::parse(text);
  const std::int64_t timescale = int_of(root, "timescale", 1000);
  bounded(timescale, 0xFFFFFFFFLL, "timescale");

  std::vector<BitWriter> init;
  {
    BitWriter t;
    t.put(0, 32);
    t.put(static_cast<std::uint64_t>(timescale), 32);
    t.put(kNominalDuration, 24);
    t.put(0, 24);
    t.put(0, 1);
    init.push_back(packet(PacketType::initialization_timing, std::move(t)));
  }
  const auto& perceptions = root["perceptions"];
  {
    BitWriter h;
    h.string(short_string(str_of(root, "version"), "version", false));
    h.string(short_string(str_of(root, "profile"), "profile", false));
    bounded(int_of(root, "level", 0), 255, "level");
    h.put(static_cast<std::uint64_t>(int_of(root, "level", 0)), 8);
    h.string(short_string(str_of(root, "date"), "date", false));
    h.string(short_string(str_of(root, "description"), "description", true));
    bounded(static_cast<std::int64_t>(perceptions.size()), 255, "perceptions (count)");
    h.put(perceptions.size(), 8);
    const auto& avatars = root["avatars"];
    bounded(static_cast<std::int64_t>(avatars.size()), 255, "avatars (count)");
    h.put(avatars.size(), 8);
    for (std::size_t i = 0; i < avatars.size(); ++i) {
      const std::string p = "avatars[" + std::to_string(i) + "]";
      bounded(int_of(avatars[i], "id", 0), 255, p + ".id");
      bounded(int_of(avatars[i], "lod", 0), 255, p + ".lod");
      h.put(static_cast<std::uint64_t>(int_of(avatars[i], "id", 0)), 8);
      h.put(static_cast<std::uint64_t>(int_of(avatars[i], "lod", 0)), 8);
      const std::string type = str_of(avatars[i], "type");
      h.put(*code_of(type, kAvatarCodes), 8);
      if (type == "Custom") h.string(short_string(str_of(avatars[i], "mesh"), p + ".mesh", false));
    }
    init.push_back(packet(PacketType::metadata_haptics, std::move(h)));
  }
  std::vector<BitWriter> channels, bands, data;
  std::int64_t band_id = 0;
  for (std::size_t i = 0; i < perceptions.size(); ++i) {
    const auto& pj = perceptions[i];
    const std::string p = "perceptions[" + std::to_string(i) + "]";
    const std::string modality = str_of(pj, "perception_modality");
    const auto modality_code = code_of(modality, kModalityCodes);
    if (!modality_code)
      throw FieldError(p + ".perception_modality", "is '" + modality + "', which the binary syntax has no code for");
    if (!spatial_code(modality))
      throw FieldError(p + ".perception_modality", "is '" + modality + "'; Texel writes the spatial data syntax only");
    if (!pj["effect_library"].empty()) throw FieldError(p + ".effect_library", "is not empty; Texel writes no effect libraries");
    BitWriter w;
    bounded(int_of(pj, "id", 0), 255, p + ".id");
    bounded(int_of(pj, "priority", 0), 255, p + ".priority");
    bounded(int_of(pj, "avatar_id", 0), 255, p + ".avatar_id");
    w.put(static_cast<std::uint64_t>(int_of(pj, "id", 0)), 8);
    w.put(static_cast<std::uint64_t>(int_of(pj, "priority", 0)), 8);
    w.string(short_string(str_of(pj, "description"), p + ".description", true));
    w.put(*modality_code, 8);
    w.put(static_cast<std::uint64_t>(int_of(pj, "avatar_id", 0)), 8);
    w.put(0, 16);
    if (pj.contains("semantic_scheme")) {
      w.put(1, 1);
      w.string(short_string(str_of(pj, "semantic_scheme"), p + ".semantic_scheme", false));
    } else {
      w.put(0, 1);
    }
    for (const char* key : {"unit_exponent", "perception_unit_exponent"}) {
      const std::int64_t v = int_of(pj, key, key[0] == 'u' ? -3 : 0);
      if (v < -128 || v > 127)
        throw FieldError(p + "." + key, "is " + std::to_string(v) + "; the binary syntax carries −128 … 127");
      w.put(static_cast<std::uint8_t>(static_cast<std::int8_t>(v)), 8);
    }
    const ojson devices = pj.value("reference_devices", ojson::array());
    bounded(static_cast<std::int64_t>(devices.size()), 255, p + ".reference_devices (count)");
    w.put(devices.size(), 8);
    for (std::size_t d = 0; d < devices.size(); ++d) {
      const auto& dj = devices[d];
      const std::string dp = p + ".reference_devices[" + std::to_string(d) + "]";
      bounded(int_of(dj, "id", 0), 254, dp + ".id");
      w.put(static_cast<std::uint64_t>(int_of(dj, "id", 0)), 8);
      w.string(short_string(str_of(dj, "name"), dp + ".name", false));
      w.put(static_cast<std::uint64_t>(int_of(dj, "body_part_mask", 0)), 32);
      std::uint32_t mask = 0;
      for (std::size_t f = 0; f < std::size(kDeviceFields); ++f)
        if (dj.contains(std::string(kDeviceFields[f]))) mask |= 0x800U >> f;
      if (dj.contains("type")) mask |= 1U;
      w.put(mask, 12);
      for (std::size_t f = 0; f < std::size(kDeviceFields); ++f)
        if (mask & (0x800U >> f)) w.real(real_of(dj, std::string(kDeviceFields[f]).c_str(), 0.0), 0.0, kMaxFloat, 32);
      if (mask & 1U) w.put(*code_of(str_of(dj, "type"), kDeviceTypeCodes), 4);
    }
    const auto& cs = pj["channels"];
    bounded(static_cast<std::int64_t>(cs.size()), 65535, p + ".channels (count)");
    w.put(cs.size(), 16);
    init.push_back(packet(PacketType::metadata_perception, std::move(w)));

    for (std::size_t c = 0; c < cs.size(); ++c) {
      const auto& cj = cs[c];
      const std::string cp = p + ".channels[" + std::to_string(c) + "]";
      BitWriter m;
      bounded(int_of(cj, "id", 0), 65535, cp + ".id");
      bounded(int_of(cj, "priority", 0), 255, cp + ".priority");
      m.put(static_cast<std::uint64_t>(int_of(cj, "id", 0)), 16);
      m.put(static_cast<std::uint64_t>(int_of(pj, "id", 0)), 8);
      m.put(static_cast<std::uint64_t>(int_of(cj, "priority", 0)), 8);
      m.string(short_string(str_of(cj, "description"), cp + ".description", true));
      if (cj.contains("reference_device_id")) bounded(int_of(cj, "reference_device_id", 0), 254, cp + ".reference_device_id");
      m.put(static_cast<std::uint64_t>(int_of(cj, "reference_device_id", 255)), 8);
      m.real(real_of(cj, "gain", 1.0), -kMaxFloat, kMaxFloat, 32);
      m.real(real_of(cj, "mixing_coefficient", 1.0), 0.0, kMaxFloat, 32);
      const bool resolution = cj.contains("actuator_resolution");
      std::uint32_t mask = resolution ? 2U : 1U;
      if (cj.contains("direction")) mask |= 4U;
      m.put(mask, 8);
      if (!resolution) {
        m.put(static_cast<std::uint64_t>(int_of(cj, "body_part_mask", 0)), 32);
      } else {
        write_vector(m, cj["actuator_resolution"]);
        const ojson parts = cj.value("body_part_target", ojson::array());
        const ojson targets = cj.value("actuator_target", ojson::array());
        bounded(static_cast<std::int64_t>(parts.size()), 255, cp + ".body_part_target (count)");
        m.put(parts.size(), 8);
        for (const auto& part : parts) m.put(kBodyPartCodes[*code_of(part.get<std::string>(), hjif::detail::kBodyParts)], 8);
        bounded(static_cast<std::int64_t>(targets.size()), 255, cp + ".actuator_target (count)");
        m.put(targets.size(), 8);
        for (const auto& t : targets) write_vector(m, t);
      }
      const std::int64_t fs = int_of(cj, "frequency_sampling", 0);
      bounded(fs, 0xFFFFFFFFLL, cp + ".frequency_sampling");
      m.put(static_cast<std::uint64_t>(fs), 32);
      if (fs > 0) {
        bounded(int_of(cj, "sample_count", 0), 0xFFFFFFFFLL, cp + ".sample_count");
        m.put(static_cast<std::uint64_t>(int_of(cj, "sample_count", 0)), 32);
      }
      if (mask & 4U) write_vector(m, cj["direction"]);
      const ojson vertices = cj.value("vertices", ojson::array());
      bounded(static_cast<std::int64_t>(vertices.size()), 65535, cp + ".vertices (count)");
      m.put(vertices.size(), 16);
      for (const auto& v : vertices) {
        bounded(v.get<std::int64_t>(), 0xFFFFFFFFLL, cp + ".vertices[]");
        m.put(v.get<std::uint64_t>(), 32);
      }
      const auto& bs = cj["bands"];
      bounded(static_cast<std::int64_t>(bs.size()), 255, cp + ".bands (count)");
      m.put(bs.size(), 8);
      channels.push_back(packet(PacketType::metadata_channel, std::move(m)));

      for (std::size_t b = 0; b < bs.size(); ++b) {
        const auto& bj = bs[b];
        const std::string bp = cp + ".bands[" + std::to_string(b) + "]";
        const std::string type = str_of(bj, "band_type");
        if (type != "Curve")
          throw FieldError(bp + ".band_type", "is '" + type + "'; Texel writes Curve bands to .hmpg (spatial data)");
        bounded(band_id, 255, bp + " (the 256th band: band ids are 8 bits)");
        // Effects, as .hmpg can carry them: each within 16-bit keyframe positions.
        std::vector<BitWriter> effects;
        for (std::size_t e = 0; e < bj["effects"].size(); ++e) {
          const auto& ej = bj["effects"][e];
          const std::string ep = bp + ".effects[" + std::to_string(e) + "]";
          if (str_of(ej, "effect_type") != "Basis")
            throw FieldError(ep + ".effect_type", "is '" + str_of(ej, "effect_type") + "'; Texel writes Basis effects");
          std::vector<std::pair<std::int64_t, double>> kfs;
          for (const auto& k : ej.value("keyframes", ojson::array()))
            kfs.emplace_back(int_of(k, "relative_position", 0), real_of(k, "amplitude_modulation", 0.0));
          std::sort(kfs.begin(), kfs.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
          for (const auto& [start, ks] : chunks(int_of(ej, "position", 0), kfs)) {
            bounded(start, kMaxEffectPosition, ep + ".position");
            BitWriter fx;
            fx.put(0, 2);
            fx.put(static_cast<std::uint64_t>(start), 25);
            fx.put(ks.size(), 16);
            for (const auto& [rel, amp] : ks) {
              fx.real(amp, -1.0, 1.0, 8);
              fx.put(static_cast<std::uint64_t>(rel), 16);
            }
            effects.push_back(std::move(fx));
          }
        }
        BitWriter mb;
        mb.put(static_cast<std::uint64_t>(band_id), 8);
        mb.put(static_cast<std::uint64_t>(int_of(pj, "id", 0)), 8);
        mb.put(static_cast<std::uint64_t>(int_of(cj, "id", 0)), 16);
        bounded(int_of(bj, "priority", 0), 255, bp + ".priority");
        mb.put(static_cast<std::uint64_t>(int_of(bj, "priority", 0)), 8);
        mb.put(*code_of(type, kBandCodes), 3);
        mb.put(*code_of(bj.value("curve_type", std::string("Unknown")), kCurveCodes), 4);
        mb.put(static_cast<std::uint64_t>(std::llround(real_of(bj, "lower_frequency_limit", 0))), 16);
        mb.put(static_cast<std::uint64_t>(std::llround(real_of(bj, "upper_frequency_limit", 0))), 16);
        bounded(static_cast<std::int64_t>(effects.size()), 65535, bp + ".effects (count, after splitting)");
        mb.put(effects.size(), 16);
        bands.push_back(packet(PacketType::metadata_band, std::move(mb)));
        // Data packets: as many whole effects as fit a packet.
        std::size_t next = 0;
        while (next < effects.size() || (next == 0 && effects.empty())) {
          std::size_t bits = 1 + 8 + 16 + 8 + 16;
          std::size_t last = next;
          while (last < effects.size() && (bits + effects[last].size() + 7) / 8 <= kMaxPayload) bits += effects[last++].size();
          if (last == next && !effects.empty()) throw InvalidArgument(bp + ": an effect does not fit one packet");
          BitWriter d;
          d.put(0, 1);
          d.put(static_cast<std::uint64_t>(int_of(pj, "id", 0)), 8);
          d.put(static_cast<std::uint64_t>(int_of(cj, "id", 0)), 16);
          d.put(static_cast<std::uint64_t>(band_id), 8);
          d.put(last - next, 16);
          for (std::size_t e = next; e < last; ++e) d.append(effects[e]);
          data.push_back(packet(PacketType::data, std::move(d)));
          if (effects.empty()) break;
          next = last;
        }
        ++band_id;
      }
    }
  }
  init.insert(init.end(), channels.begin(), channels.end());
  init.insert(init.end(), bands.begin(), bands.end());
  BitWriter out = unit(UnitType::initialization, 0, init);
  out.append(unit(UnitType::temporal, kNominalDuration, data));
  return out.bytes();
}

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

Exported export_hmpg(const Document& doc, const hjif::ExportOptions& options) {
  const hjif::Exported h = hjif::export_hjif(doc, options);
  Exported out;
  out.bytes = encode(h.json);
  out.stats = h.stats;
  // The error after quantization, on the device grid, as a reader of the stream sees it.
  const hjif::Experience e = hjif::parse_hjif(decode(out.bytes, "the written .hmpg"), "the written .hmpg");
  const Surface s = prepare_surface(doc);
  const std::vector<double> map = s.render();
  std::vector<double> x(map.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = s.grid().position(static_cast<std::int64_t>(i)).value();
  const std::vector<double> curve = hjif::evaluate(e, x);
  double worst = 0.0;
  for (std::size_t i = 0; i < map.size(); ++i) worst = std::max(worst, std::fabs(curve[i] - map[i]));
  out.stats.max_error = worst;
  return out;
}

}  // namespace texel::hmpg
