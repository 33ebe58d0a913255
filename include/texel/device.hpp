// Device profiles are data, not code paths (docs/algorithm.md §8): a JSON file per
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

/// What a display reproduces of its drive signal, as a function of temporal
/// frequency (docs/format.md "Device profiles", docs/encoder.md §2): a
/// Butterworth-shaped low-pass |H(f)| = 1/√(1 + (f/corner)^(2·order)).
/// An ultrasonic friction display's friction follows its drive envelope with
/// the lag of a resonator driven at resonance (first order, corner f0/2Q);
/// the squeeze film and the skin add more. corner 0 = flat (the default: a
/// profile without "response" promises nothing about its bandwidth, and
/// every consumer behaves as before). A spatial frequency f (cycles/mm) felt
/// at swipe speed v (mm/s) is the temporal frequency f·v (Hz).
struct FrequencyResponse {
  Hertz corner{0.0};   ///< −3 dB corner, Hz (> 0), or 0 = flat
  int order = 1;       ///< roll-off 6·order dB/octave above the corner, 1 … 4
  std::string source;  ///< where the numbers come from, and how sure they are (free text)

  [[nodiscard]] bool flat() const { return !(corner.value() > 0.0); }
  /// |H(f)| in (0, 1]; 1 for a flat response.
  [[nodiscard]] double gain(Hertz f) const;
  /// 20·log10 |H(f)| (≤ 0 dB).
  [[nodiscard]] double gain_db(Hertz f) const;
  /// The frequency where |H| has fallen by `db` (> 0) dB; +∞ for a flat response.
  [[nodiscard]] Hertz frequency_at_db(double db) const;
};
/// Throws InvalidArgument naming `field` (corner_hz, order).
void validate(const FrequencyResponse& r, std::string_view field = "response");

/// How a 2-D friction bitmap's pixel value relates to the amplitude a (the
/// fraction of the largest friction reduction, docs/algorithm.md §2).
/// darker_more_friction: pixel = a·max (white = least friction, black = the
/// surface at rest); brighter_more_friction: pixel = (1 − a)·max.
enum class BitmapPolarity { darker_more_friction, brighter_more_friction };
std::string_view to_string(BitmapPolarity p);
BitmapPolarity parse_bitmap_polarity(std::string_view text, std::string_view field = "polarity");

/// The 2-D side of a display that takes a friction bitmap or senses the
/// finger in (x, y) (docs/format.md "Device profiles"; JSON "bitmap").
/// Pixel (i, j) sits at (i·pitch, j·pitch), rows along y.
struct BitmapGeometry {
  int width = 0;           ///< pixels along x, 1 … 65535
  int height = 0;          ///< pixels along y, 1 … 65535
  Millimetres pitch{0.1};  ///< pixel spacing (the resolution), > 0
  int depth = 16;          ///< bits per pixel of its bitmaps: 8 or 16
  BitmapPolarity polarity = BitmapPolarity::darker_more_friction;

  [[nodiscard]] Millimetres width_mm() const { return Millimetres(width * pitch.value()); }
  [[nodiscard]] Millimetres height_mm() const { return Millimetres(height * pitch.value()); }
  /// The highest spatial frequency the pixel grid holds along its axes.
  [[nodiscard]] CyclesPerMm nyquist() const { return CyclesPerMm(0.5 / pitch.value()); }
};

/// One actuator (output channel) of a multi-channel display: a voice coil
/// or pin of an array under the finger pad, or a channel of a multi-channel
/// sound card (docs/format.md "Device profiles", JSON "actuators";
/// docs/rendering.md). An actuator at `offset` along the swipe axis touches
/// the surface at finger position + offset, so it plays the texture there.
struct Actuator {
  std::string name;          ///< label, unique in the profile, 1 … 64 characters
  Millimetres offset{0.0};   ///< along the swipe axis from the finger's contact point, −50 … 50 mm
  Millimetres lateral{0.0};  ///< across the swipe axis, −50 … 50 mm (a 1-D texture does not vary across it)
  /// This channel's response; absent = the device's (DeviceProfile::response).
  std::optional<FrequencyResponse> response;
};
/// Channels a profile may declare, and the range of actuator positions.
inline constexpr std::size_t max_actuators = 64;
inline constexpr double actuator_offset_mm_max = 50.0;

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
  /// The display's frequency response ("response" in the JSON; optional,
  /// absent = flat). Rendering never uses it: a document's map is the same
  /// bytes whatever the response. The encoder's model and the player do.
  FrequencyResponse response;
  /// The 2-D pixel grid ("bitmap" in the JSON; optional: 1-D devices have none).
  std::optional<BitmapGeometry> bitmap;
  /// The output channels ("actuators" in the JSON; optional: absent = one
  /// channel, the display as a whole, and the profile reads and writes as
  /// before). 1 … max_actuators when present.
  std::vector<Actuator> actuators;

  /// Output channels: the actuators, or 1.
  [[nodiscard]] std::size_t channels() const { return actuators.empty() ? 1 : actuators.size(); }
  /// The response channel `c` plays through: its actuator's, else the device's.
  [[nodiscard]] const FrequencyResponse& channel_response(std::size_t c) const {
    return c < actuators.size() && actuators[c].response ? *actuators[c].response : response;
  }
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
