// Binary MPEG-I Haptics streams (.hmpg, MIHS units and packets), written for
// the spatial data Texel uses (read in hmpg_read.cpp; the codes and bits both
// share in hmpg_syntax.hpp). The syntax (field order and widths,
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

#include "hmpg_syntax.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/surface.hpp"

namespace texel::hmpg {
namespace {

using namespace syntax;
using texel::detail::num;

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