// The .hmpg syntax both directions share (internal; hmpg.cpp writes,
// hmpg_read.cpp reads): the unit, packet and field codes, the limits of the
// reference writer's syntax, and the bit writer and reader (big-endian
// fields of any width). docs/interchange.md "Binary .hmpg".
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "hjif_internal.hpp"
#include "texel/error.hpp"

namespace texel::hmpg::syntax {

using ojson = nlohmann::ordered_json;

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
inline constexpr std::string_view kModalityCodes[] = {
    "Other", "Pressure", "Acceleration",         "Velocity",  "Position", "Temperature",   "Vibrotactile", "Water",
    "Wind",  "Force",    "Vibrotactile Texture", "Stiffness", "Friction", "Electrotactile"};
inline constexpr std::string_view kBandCodes[] = {"Transient", "Curve", "VectorialWave", "WaveletWave"};
inline constexpr std::string_view kCurveCodes[] = {"Unknown", "Cubic", "Linear", "Akima", "Bezier", "BSpline"};
inline constexpr std::string_view kEffectCodes[] = {"Basis", "Reference", "Composite"};
inline constexpr std::string_view kAvatarCodes[] = {"Custom", "Vibration", "Pressure", "Temperature"};
inline constexpr std::string_view kDeviceTypeCodes[] = {"Unknown", "LRA", "VCA", "ERM", "Piezo"};
// Body-part codes, parallel to hjif::detail::kBodyParts (the schema's names).
inline constexpr std::uint8_t kBodyPartCodes[] = {0,  1,  10, 11, 12, 13, 14, 15, 20, 21, 22,  23, 24, 30,
                                                  31, 32, 33, 34, 35, 36, 37, 40, 41, 42, 43,  50, 51, 52,
                                                  53, 54, 55, 56, 57, 58, 59, 60, 61, 62, 254, 255};
static_assert(std::size(kBodyPartCodes) == std::size(hjif::detail::kBodyParts));
inline constexpr double kMaxFloat = 10000.0;
// A reference device's optional numbers in the order of their presence mask, all over [0, 10000].
inline constexpr auto kDeviceFields = [] {
  std::array<std::string_view, std::size(hjif::detail::kDeviceNumbers) + 1> a{};
  std::copy(std::begin(hjif::detail::kDeviceNumbers), std::end(hjif::detail::kDeviceNumbers), a.begin());
  a.back() = "custom";
  return a;
}();
inline constexpr std::uint32_t kNominalDuration = 128;  // the reference writer's packet duration
inline constexpr std::size_t kMaxPayload = (std::size_t{1} << 17) - 1;
inline constexpr std::int64_t kMaxRelative = 65535;  // 16-bit keyframe positions
inline constexpr std::int64_t kMaxEffectPosition = (std::int64_t{1} << 25) - 1;
inline constexpr std::size_t kMaxChunkKeyframes = 40000;  // 3 bytes each: an effect fits a packet

template <std::size_t N>
std::optional<std::uint32_t> code_of(std::string_view v, const std::string_view (&set)[N]) {
  for (std::size_t i = 0; i < N; ++i)
    if (set[i] == v) return static_cast<std::uint32_t>(i);
  return std::nullopt;
}

inline bool spatial_code(std::string_view modality) {
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

}  // namespace texel::hmpg::syntax
