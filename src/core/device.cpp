#include "texel/device.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <utility>

#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/distribution.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel {
namespace {

using detail::num;

struct Embedded {
  const char* name;
  const char* text;
};
constexpr Embedded builtin_profiles[] = {
#include "builtin_devices.inc"
};

FrequencyResponse parse_response(const nlohmann::json& j, const std::string& path) {
  detail::JsonObject r(j, path);
  FrequencyResponse out;
  out.corner = Hertz(r.number("corner_hz", 1e-6, 1e6));
  out.order = static_cast<int>(r.integer("order", 1, 4));
  out.source = r.string_or("source", "");
  r.finish();
  return out;
}

nlohmann::ordered_json response_json(const FrequencyResponse& response) {
  nlohmann::ordered_json r;
  r["corner_hz"] = response.corner.value();
  r["order"] = response.order;
  if (!response.source.empty()) r["source"] = response.source;
  return r;
}

}  // namespace

std::string_view to_string(SampleFormat f) {
  switch (f) {
    case SampleFormat::u16le: return "u16le";
    case SampleFormat::u8: return "u8";
    case SampleFormat::f32le: return "f32le";
    case SampleFormat::f64le: return "f64le";
  }
  return "?";
}

SampleFormat parse_sample_format(std::string_view text, std::string_view field) {
  for (auto f : {SampleFormat::u16le, SampleFormat::u8, SampleFormat::f32le, SampleFormat::f64le})
    if (text == to_string(f)) return f;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: u16le, u8, f32le, f64le");
}

std::size_t bytes_per_sample(SampleFormat f) {
  switch (f) {
    case SampleFormat::u16le: return 2;
    case SampleFormat::u8: return 1;
    case SampleFormat::f32le: return 4;
    case SampleFormat::f64le: return 8;
  }
  return 0;
}

double FrequencyResponse::gain(Hertz f) const {
  if (flat()) return 1.0;
  const double r = std::fabs(f.value()) / corner.value();
  return 1.0 / std::sqrt(1.0 + std::pow(r, 2.0 * order));
}

double FrequencyResponse::gain_db(Hertz f) const { return flat() ? 0.0 : 20.0 * std::log10(gain(f)); }

Hertz FrequencyResponse::frequency_at_db(double db) const {
  if (flat() || !(db > 0.0)) return Hertz(flat() ? std::numeric_limits<double>::infinity() : 0.0);
  // |H|² = 1/(1 + r^2n) = 10^(−db/10)  ⇒  r = (10^(db/10) − 1)^(1/2n)
  return Hertz(corner.value() * std::pow(std::pow(10.0, db / 10.0) - 1.0, 1.0 / (2.0 * order)));
}

void validate(const FrequencyResponse& r, std::string_view field) {
  const std::string f(field);
  if (r.corner.value() == 0.0) return;  // flat
  if (!(std::isfinite(r.corner.value()) && r.corner.value() > 0.0 && r.corner.value() <= 1e6))
    throw InvalidArgument(f + ".corner_hz is " + num(r.corner.value()) + "; allowed: > 0 … 1000000 Hz (omit " + f +
                          " for a flat display)");
  if (r.order < 1 || r.order > 4)
    throw InvalidArgument(f + ".order is " + std::to_string(r.order) + "; allowed: 1 … 4 (6 dB/octave each)");
}

void validate(const DeviceProfile& p) {
  const std::string at = "device '" + p.name + "': ";
  if (p.name.empty()) throw InvalidArgument("device profile has an empty name");
  if (!(std::isfinite(p.spacing.value()) && p.spacing.value() > 0.0))
    throw InvalidArgument(at + "spacing_mm is " + num(p.spacing.value()) + " mm; it must be a finite number > 0");
  constexpr std::int64_t max_samples = std::int64_t{1} << 34;
  if (p.samples < 1 || p.samples > max_samples)
    throw InvalidArgument(at + "samples is " + std::to_string(p.samples) + "; allowed: 1 … " + std::to_string(max_samples));
  if (!(std::isfinite(p.refresh.value()) && p.refresh.value() > 0.0))
    throw InvalidArgument(at + "refresh_hz is " + num(p.refresh.value()) + "; it must be a finite number > 0");
  if (!(std::isfinite(p.band_min.value()) && p.band_min.value() > 0.0))
    throw InvalidArgument(at + "band_min_cpm is " + num(p.band_min.value()) + "; it must be > 0");
  if (!(std::isfinite(p.band_max.value()) && p.band_max.value() >= 0.0) ||
      (p.band_max.value() > 0.0 && p.band_max.value() <= p.band_min.value()))
    throw InvalidArgument(at + "band_max_cpm is " + num(p.band_max.value()) + "; allowed: 0 (Nyquist) or above band_min_cpm");
  if (p.band_max.value() > p.nyquist().value() * (1 + 1e-12))
    throw InvalidArgument(at + "band_max_cpm " + num(p.band_max.value()) + " cpm is above the grid's Nyquist frequency " +
                          num(p.nyquist().value()) + " cpm");
  if (p.band_min.value() >= p.band_top().value())
    throw InvalidArgument(at + "band_min_cpm " + num(p.band_min.value()) + " cpm is not below the band's top " +
                          num(p.band_top().value()) + " cpm");
  double prev_end = 0.0;
  for (const auto& r : p.layout) {
    if (!(r.start.value() >= prev_end - 1e-9 && r.length.value() > 0.0 &&
          r.start.value() + r.length.value() <= p.length().value() + 1e-3))
      throw InvalidArgument(at + "layout region '" + r.name + "' (" + num(r.start.value()) + " mm + " + num(r.length.value()) +
                            " mm) must lie inside 0 … " + num(p.length().value()) + " mm, in order, without overlap");
    prev_end = r.start.value() + r.length.value();
  }
  try {
    validate(p.response);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(at + e.what());
  }
  if (p.actuators.size() > max_actuators)
    throw InvalidArgument(at + "actuators has " + std::to_string(p.actuators.size()) + " entries; allowed: 1 … " +
                          std::to_string(max_actuators) + " (omit it for one channel)");
  for (std::size_t i = 0; i < p.actuators.size(); ++i) {
    const Actuator& a = p.actuators[i];
    const std::string f = "actuators[" + std::to_string(i) + "]";
    if (a.name.empty() || a.name.size() > 64)
      throw InvalidArgument(at + f + ".name is '" + a.name + "'; allowed: 1 … 64 characters");
    for (std::size_t k = 0; k < i; ++k)
      if (p.actuators[k].name == a.name)
        throw InvalidArgument(at + f + ".name is '" + a.name + "', already the name of actuators[" + std::to_string(k) +
                              "]; names must be unique");
    for (const auto& [key, v] : {std::pair{".offset_mm", a.offset.value()}, std::pair{".lateral_mm", a.lateral.value()}})
      if (!(std::isfinite(v) && std::fabs(v) <= actuator_offset_mm_max))
        throw InvalidArgument(at + f + key + " is " + num(v) + "; allowed: " + num(-actuator_offset_mm_max) + " … " +
                              num(actuator_offset_mm_max) + " mm");
    if (a.response) {
      try {
        validate(*a.response, f + ".response");
      } catch (const InvalidArgument& e) {
        throw InvalidArgument(at + e.what());
      }
    }
  }
  if (p.bitmap) {
    const BitmapGeometry& b = *p.bitmap;
    if (b.width < 1 || b.width > 65535 || b.height < 1 || b.height > 65535)
      throw InvalidArgument(at + "bitmap.width_px × height_px is " + std::to_string(b.width) + " × " + std::to_string(b.height) +
                            "; allowed: 1 … 65535 each");
    if (!(std::isfinite(b.pitch.value()) && b.pitch.value() > 0.0))
      throw InvalidArgument(at + "bitmap.pixel_pitch_mm is " + num(b.pitch.value()) + "; it must be a finite number > 0");
    if (b.depth != 8 && b.depth != 16)
      throw InvalidArgument(at + "bitmap.depth_bits is " + std::to_string(b.depth) + "; allowed: 8, 16");
  }
}

std::string_view to_string(BitmapPolarity p) {
  return p == BitmapPolarity::darker_more_friction ? "darker_more_friction" : "brighter_more_friction";
}

BitmapPolarity parse_bitmap_polarity(std::string_view text, std::string_view field) {
  if (text == "darker_more_friction") return BitmapPolarity::darker_more_friction;
  if (text == "brighter_more_friction") return BitmapPolarity::brighter_more_friction;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) +
                        "'; allowed: darker_more_friction, brighter_more_friction");
}

DeviceProfile parse_device_profile(std::string_view json_text, std::string_view origin) {
  const nlohmann::json j = detail::parse_json(json_text, origin);
  try {
    detail::JsonObject o(j, "");
    DeviceProfile p;
    p.name = o.string("name");
    p.description = o.string_or("description", "");
    p.samples = o.integer("samples", 1, std::int64_t{1} << 34);
    p.spacing = Millimetres(o.number("spacing_mm", 1e-9, 1e6));
    p.format = parse_sample_format(o.string("format"), "format");
    p.refresh = Hertz(o.number("refresh_hz", 1e-6, 1e9));
    p.band_min = CyclesPerMm(o.number_or("band_min_cpm", 0.01, band_cpm_min, band_cpm_max));
    p.band_max = CyclesPerMm(o.number_or("band_max_cpm", 0.0, 0.0, band_cpm_max));
    if (o.has("layout")) {
      const auto& arr = o.raw("layout");
      if (!arr.is_array()) throw FormatError("layout must be an array of regions");
      for (std::size_t i = 0; i < arr.size(); ++i) {
        detail::JsonObject r(arr[i], "layout[" + std::to_string(i) + "]");
        RegionLayout reg;
        reg.name = r.string("name");
        reg.start = Millimetres(r.number("start_mm", 0.0, 1e9));
        reg.length = Millimetres(r.number("length_mm", 1e-9, 1e9));
        r.finish();
        p.layout.push_back(reg);
      }
    } else {
      o.skip("layout");
    }
    if (o.has("response")) {
      // Optional; absent (or null) = flat, so older and user profiles load unchanged.
      p.response = parse_response(o.raw("response"), "response");
    } else {
      o.skip("response");
    }
    if (o.has("actuators")) {
      // Optional; absent = one channel, so every profile before it reads and writes as before.
      const auto& arr = o.raw("actuators");
      if (!arr.is_array() || arr.empty() || arr.size() > max_actuators)
        throw FormatError("actuators must be an array of 1 … " + std::to_string(max_actuators) + " actuators, got " +
                          (arr.is_array() ? std::to_string(arr.size()) + " entries" : std::string(arr.type_name())));
      for (std::size_t i = 0; i < arr.size(); ++i) {
        const std::string at = "actuators[" + std::to_string(i) + "]";
        detail::JsonObject r(arr[i], at);
        Actuator a;
        a.name = r.string("name");
        a.offset = Millimetres(r.number("offset_mm", -actuator_offset_mm_max, actuator_offset_mm_max));
        a.lateral = Millimetres(r.number_or("lateral_mm", 0.0, -actuator_offset_mm_max, actuator_offset_mm_max));
        if (r.has("response"))
          a.response = parse_response(r.raw("response"), at + ".response");
        else
          r.skip("response");
        r.finish();
        p.actuators.push_back(std::move(a));
      }
    } else {
      o.skip("actuators");
    }
    if (o.has("bitmap")) {
      // Optional; 1-D profiles have none and read and write as before.
      detail::JsonObject b(o.raw("bitmap"), "bitmap");
      BitmapGeometry g;
      g.width = static_cast<int>(b.integer("width_px", 1, 65535));
      g.height = static_cast<int>(b.integer("height_px", 1, 65535));
      g.pitch = Millimetres(b.number("pixel_pitch_mm", 1e-9, 1e6));
      g.depth = static_cast<int>(b.integer("depth_bits", 8, 16));
      if (b.has("polarity")) {
        try {
          g.polarity = parse_bitmap_polarity(b.string("polarity"), b.field("polarity"));
        } catch (const InvalidArgument& e) {
          throw FormatError(e.what());
        }
      } else {
        b.skip("polarity");
      }
      b.finish();
      p.bitmap = g;
    } else {
      o.skip("bitmap");
    }
    o.finish();
    validate(p);
    return p;
  } catch (const Error& e) {
    throw FormatError(std::string(origin) + ": " + e.what());
  }
}

std::string device_profile_json(const DeviceProfile& p) {
  nlohmann::ordered_json j;
  j["name"] = p.name;
  j["description"] = p.description;
  j["samples"] = p.samples;
  j["spacing_mm"] = p.spacing.value();
  j["format"] = std::string(to_string(p.format));
  j["refresh_hz"] = p.refresh.value();
  j["band_min_cpm"] = p.band_min.value();
  j["band_max_cpm"] = p.band_max.value();
  j["layout"] = nlohmann::ordered_json::array();
  for (const auto& r : p.layout)
    j["layout"].push_back({{"name", r.name}, {"start_mm", r.start.value()}, {"length_mm", r.length.value()}});
  // Written only when not flat: a profile without a response reads and
  // writes the text it always had.
  if (!p.response.flat()) j["response"] = response_json(p.response);
  if (p.bitmap) {
    nlohmann::ordered_json b;
    b["width_px"] = p.bitmap->width;
    b["height_px"] = p.bitmap->height;
    b["pixel_pitch_mm"] = p.bitmap->pitch.value();
    b["depth_bits"] = p.bitmap->depth;
    b["polarity"] = std::string(to_string(p.bitmap->polarity));
    j["bitmap"] = b;
  }
  if (!p.actuators.empty()) {  // written only when declared: a one-channel profile keeps its text
    j["actuators"] = nlohmann::ordered_json::array();
    for (const auto& a : p.actuators) {
      nlohmann::ordered_json r;
      r["name"] = a.name;
      r["offset_mm"] = a.offset.value();
      r["lateral_mm"] = a.lateral.value();
      if (a.response) r["response"] = response_json(*a.response);
      j["actuators"].push_back(r);
    }
  }
  return j.dump(2) + "\n";
}

std::vector<std::string> builtin_device_names() {
  std::vector<std::string> names;
  for (const auto& e : builtin_profiles) names.emplace_back(e.name);
  return names;
}

DeviceProfile load_device(std::string_view name_or_path) {
  const std::string key(name_or_path);
  if (key.empty()) throw InvalidArgument("device name is empty");
  for (const auto& e : builtin_profiles)
    if (key == e.name) return parse_device_profile(e.text, "built-in device '" + key + "'");
  const bool looks_like_path = key.find('/') != std::string::npos || key.ends_with(".json");
  if (looks_like_path) return parse_device_profile(read_file(key), key);
  if (const char* dirs = std::getenv("TEXEL_DEVICE_PATH")) {
    std::string_view rest(dirs);
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      const std::string dir(rest.substr(0, colon));
      rest = colon == std::string_view::npos ? std::string_view{} : rest.substr(colon + 1);
      if (dir.empty()) continue;
      const auto candidate = std::filesystem::path(dir) / (key + ".json");
      std::error_code ec;
      if (std::filesystem::is_regular_file(candidate, ec))
        return parse_device_profile(read_file(candidate.string()), candidate.string());
    }
  }
  std::string known;
  for (const auto& n : builtin_device_names()) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument("unknown device '" + key + "'; built-in devices: " + known +
                        " (or give a path to a profile .json, or put NAME.json in a TEXEL_DEVICE_PATH directory)");
}

DeviceProfile with_grid(DeviceProfile p, std::optional<Millimetres> new_length, std::optional<Millimetres> new_spacing) {
  const std::optional<double> length_mm = new_length ? std::optional<double>(new_length->value()) : std::nullopt;
  const std::optional<double> spacing_mm = new_spacing ? std::optional<double>(new_spacing->value()) : std::nullopt;
  if (spacing_mm) {
    if (!(std::isfinite(*spacing_mm) && *spacing_mm > 0.0))
      throw InvalidArgument("spacing is " + num(*spacing_mm) + " mm; it must be a finite number > 0");
  }
  if (length_mm) {
    if (!(std::isfinite(*length_mm) && *length_mm > 0.0))
      throw InvalidArgument("length is " + num(*length_mm) + " mm; it must be a finite number > 0");
  }
  if (!length_mm && !spacing_mm) return p;
  const double length = length_mm ? *length_mm : p.length().value();
  const double spacing = spacing_mm ? *spacing_mm : p.spacing.value();
  const double count = std::round(length / spacing);
  if (!(count >= 1.0) || count > static_cast<double>(std::int64_t{1} << 34))
    throw InvalidArgument("length " + num(length) + " mm at spacing " + num(spacing) + " mm gives " + num(count) +
                          " samples; allowed: 1 … 17179869184");
  p.samples = static_cast<std::int64_t>(count);
  p.spacing = Millimetres(spacing);
  if (p.band_max.value() > p.nyquist().value()) p.band_max = CyclesPerMm(0.0);
  std::erase_if(p.layout, [&](const RegionLayout& r) { return r.start.value() + r.length.value() > p.length().value() + 1e-3; });
  validate(p);
  return p;
}

namespace {

// Encoders with explicit lanes (GCC/clang vector extensions): GCC will not
// if-convert the clamp's selects under -ftrapping-math, so the plain loops ran
// scalar. Each lane does exactly what to_u16 / the scalar clamp do — the same
// comparisons, the same a·65535 + 0.5 in IEEE double, truncation to integer,
// round-to-nearest double -> float — so the bytes do not depend on the lane
// width, which is picked per instruction set at run time (as in texture.cpp).
using detail::Lanes;

template <int W>
[[gnu::always_inline]] inline void encode_u16_lanes(const double* a, std::uint16_t* out, std::size_t n) {
  using L = Lanes<W>;
  const typename L::type zero{}, one = zero + 1.0;
  std::size_t i = 0;
  for (; i + W <= n; i += W) {
    typename L::type v;
    std::memcpy(&v, a + i, sizeof v);
    v = v > zero ? (v < one ? v : one) : zero;
    v = v * 65535.0 + 0.5;  // in [0.5, 65535.5]: truncates exactly through int32
    const typename L::u16 q = __builtin_convertvector(__builtin_convertvector(v, typename L::i32), typename L::u16);
    std::memcpy(out + i, &q, sizeof q);
  }
  for (; i < n; ++i) out[i] = to_u16(a[i]);
}

template <int W>
[[gnu::always_inline]] inline void encode_f32_lanes(const double* a, float* out, std::size_t n) {
  using L = Lanes<W>;
  const typename L::type zero{}, one = zero + 1.0;
  std::size_t i = 0;
  for (; i + W <= n; i += W) {
    typename L::type v;
    std::memcpy(&v, a + i, sizeof v);
    v = v > zero ? (v < one ? v : one) : zero;
    const typename L::f32 f = __builtin_convertvector(v, typename L::f32);
    std::memcpy(out + i, &f, sizeof f);
  }
  for (; i < n; ++i) {
    const double v = a[i] > 0.0 ? (a[i] < 1.0 ? a[i] : 1.0) : 0.0;
    out[i] = static_cast<float>(v);
  }
}

template <class T>
using EncodeKernel = void (*)(const double*, T*, std::size_t);

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void encode_u16_avx512(const double* a, std::uint16_t* o, std::size_t n) {
  encode_u16_lanes<8>(a, o, n);
}
__attribute__((target("avx2"))) void encode_u16_avx2(const double* a, std::uint16_t* o, std::size_t n) {
  encode_u16_lanes<4>(a, o, n);
}
__attribute__((target("avx512f"))) void encode_f32_avx512(const double* a, float* o, std::size_t n) {
  encode_f32_lanes<8>(a, o, n);
}
__attribute__((target("avx2"))) void encode_f32_avx2(const double* a, float* o, std::size_t n) { encode_f32_lanes<4>(a, o, n); }
#endif
void encode_u16_generic(const double* a, std::uint16_t* o, std::size_t n) { encode_u16_lanes<2>(a, o, n); }
void encode_f32_generic(const double* a, float* o, std::size_t n) { encode_f32_lanes<2>(a, o, n); }

/// The widest encoders this CPU runs (chosen once, at first use).
EncodeKernel<std::uint16_t> pick_u16() {
#if defined(__x86_64__) || defined(__i386__)
  if (detail::simd_lanes() == 8) return &encode_u16_avx512;
  if (detail::simd_lanes() == 4) return &encode_u16_avx2;
#endif
  return &encode_u16_generic;
}
EncodeKernel<float> pick_f32() {
#if defined(__x86_64__) || defined(__i386__)
  if (detail::simd_lanes() == 8) return &encode_f32_avx512;
  if (detail::simd_lanes() == 4) return &encode_f32_avx2;
#endif
  return &encode_f32_generic;
}

}  // namespace

void encode_u16(std::span<const double> a, std::span<std::uint16_t> out) {
  static const EncodeKernel<std::uint16_t> kernel = pick_u16();
  kernel(a.data(), out.data(), std::min(a.size(), out.size()));
}

void encode_f32(std::span<const double> a, std::span<float> out) {
  static const EncodeKernel<float> kernel = pick_f32();
  kernel(a.data(), out.data(), std::min(a.size(), out.size()));
}

void encode_samples(SampleFormat format, std::span<const double> a, std::span<std::byte> out) {
  static_assert(std::endian::native == std::endian::little, "Texel's encoders assume a little-endian host");
  const std::size_t n = a.size();
  if (out.size() < n * bytes_per_sample(format)) throw InvalidArgument("encode_samples: output buffer too small");
  switch (format) {
    case SampleFormat::u16le: {
      // Encode through an aligned stack block: `out` may be unaligned for uint16.
      std::uint16_t block[1024];
      for (std::size_t i = 0; i < n; i += 1024) {
        const std::size_t len = std::min<std::size_t>(1024, n - i);
        encode_u16(a.subspan(i, len), std::span<std::uint16_t>(block, len));
        std::memcpy(out.data() + 2 * i, block, 2 * len);
      }
      break;
    }
    case SampleFormat::u8:
      for (std::size_t i = 0; i < n; ++i) {
        const double v = a[i] > 0.0 ? (a[i] < 1.0 ? a[i] : 1.0) : 0.0;
        out[i] = static_cast<std::byte>(static_cast<std::uint8_t>(v * 255.0 + 0.5));
      }
      break;
    case SampleFormat::f32le: {
      float block[1024];
      for (std::size_t i = 0; i < n; i += 1024) {
        const std::size_t len = std::min<std::size_t>(1024, n - i);
        encode_f32(a.subspan(i, len), std::span<float>(block, len));
        std::memcpy(out.data() + 4 * i, block, 4 * len);
      }
      break;
    }
    case SampleFormat::f64le:
      for (std::size_t i = 0; i < n; ++i) {
        const double v = a[i] > 0.0 ? (a[i] < 1.0 ? a[i] : 1.0) : 0.0;
        std::memcpy(out.data() + 8 * i, &v, 8);
      }
      break;
  }
}

std::vector<double> decode_samples(SampleFormat format, std::span<const std::byte> bytes) {
  const std::size_t w = bytes_per_sample(format);
  if (bytes.size() % w != 0)
    throw FormatError("device data of " + std::to_string(bytes.size()) + " bytes is not a whole number of " +
                      std::string(to_string(format)) + " samples (" + std::to_string(w) + " bytes each)");
  const std::size_t n = bytes.size() / w;
  std::vector<double> a(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::byte* p = bytes.data() + i * w;
    switch (format) {
      case SampleFormat::u16le: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        a[i] = v / 65535.0;
        break;
      }
      case SampleFormat::u8: a[i] = static_cast<double>(std::to_integer<std::uint8_t>(*p)) / 255.0; break;
      case SampleFormat::f32le: {
        float v;
        std::memcpy(&v, p, 4);
        a[i] = v;
        break;
      }
      case SampleFormat::f64le: std::memcpy(&a[i], p, 8); break;
    }
  }
  return a;
}

}  // namespace texel
