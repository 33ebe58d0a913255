// Device profiles are data, not code paths (rendering.md §8): a JSON file per
// device gives its sample grid, value format, refresh rate and band. Built-in
// profiles (devices/*.json, compiled in) are found by name; users add their
// own as files, by path or in a directory listed in TEXEL_DEVICE_PATH.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/grid.hpp"
#include "texel/units.hpp"

namespace texel {

/// How one sample is stored in a device-native file.
enum class SampleFormat {
  u16le,  ///< unsigned 16-bit little-endian, round(a·65535)
  u8,     ///< unsigned 8-bit, round(a·255)
  f32le,  ///< IEEE float32 little-endian, a
  f64le,  ///< IEEE float64 little-endian, a
};
std::string_view to_string(SampleFormat f);
SampleFormat parse_sample_format(std::string_view text, std::string_view field = "format");
std::size_t bytes_per_sample(SampleFormat f);

/// A region of the default layout (e.g. the studies' left/right halves).
struct RegionLayout {
  std::string name;
  Millimetres start{0.0};
  Millimetres length{0.0};
};

struct DeviceProfile {
  std::string name;  ///< e.g. "tpad"
  std::string description;
  std::int64_t samples = 0;  ///< samples along the active length, >= 1
  Millimetres spacing{0.0};  ///< Δx, > 0
  SampleFormat format = SampleFormat::u16le;
  Hertz refresh{0.0};                ///< output update rate while playing, > 0
  CyclesPerMm band_min{0.01};        ///< lowest renderable frequency
  CyclesPerMm band_max{0.0};         ///< 0 = Nyquist of the grid
  std::vector<RegionLayout> layout;  ///< named regions; empty = whole surface

  [[nodiscard]] Grid grid() const { return Grid{Millimetres(0.0), spacing, samples}; }
  [[nodiscard]] Millimetres length() const { return Millimetres(static_cast<double>(samples) * spacing.value()); }
  [[nodiscard]] CyclesPerMm nyquist() const { return CyclesPerMm(0.5 / spacing.value()); }
  /// The upper band edge in force: band_max, or the Nyquist frequency.
  [[nodiscard]] CyclesPerMm band_top() const { return band_max.value() > 0 ? band_max : nyquist(); }
  [[nodiscard]] std::size_t native_bytes() const { return static_cast<std::size_t>(samples) * bytes_per_sample(format); }
};

/// Validates a profile; throws InvalidArgument naming the field.
void validate(const DeviceProfile& profile);

/// Parses a profile from JSON text; `origin` names the source in errors.
DeviceProfile parse_device_profile(std::string_view json_text, std::string_view origin);
/// Serializes a profile to JSON text (the same schema the parser reads).
std::string device_profile_json(const DeviceProfile& profile);

/// Finds a profile: a built-in name ("tpad", "tpad-tablet", "generic"), a
/// name found as NAME.json in a TEXEL_DEVICE_PATH directory, or a path to a
/// JSON file. Throws InvalidArgument listing the known names if none matches.
DeviceProfile load_device(std::string_view name_or_path);
/// Names of the built-in profiles.
std::vector<std::string> builtin_device_names();

/// Overrides the active length and/or sample spacing (CLI --length/--spacing).
/// The sample count becomes round(length / spacing); a layout that no longer
/// fits is dropped. Throws InvalidArgument for non-positive or non-finite values.
DeviceProfile with_grid(DeviceProfile profile, std::optional<Millimetres> length, std::optional<Millimetres> spacing);

/// Encodes amplitudes (clamped to [0, 1]) into device-native bytes.
void encode_samples(SampleFormat format, std::span<const double> amplitudes, std::span<std::byte> out);
/// Decodes device-native bytes into amplitudes in [0, 1].
std::vector<double> decode_samples(SampleFormat format, std::span<const std::byte> bytes);

/// round(a·65535) with a clamped to [0, 1]; the exact rule for u16 output.
inline std::uint16_t to_u16(double a) {
  a = a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0;  // NaN -> 0
  return static_cast<std::uint16_t>(a * 65535.0 + 0.5);
}
/// Batch form of to_u16 (vectorizes).
void encode_u16(std::span<const double> amplitudes, std::span<std::uint16_t> out);
void encode_f32(std::span<const double> amplitudes, std::span<float> out);

}  // namespace texel
