// The one signal loader: every command and binding reads a texture signal
// (a device map, an array, a CSV, a recording, a .mat map, a document or a
// bitstream) through load_signal(), so every front door accepts the same
// files, with the same spacing tolerance, channel policy and size bounds,
// and reads a file to the same samples.
//
// What a loaded signal is: samples on a uniform spatial grid, sample i at
// origin + i·spacing mm. Time recordings (.wav, a time/value .csv) become
// positions at a swipe speed (x = v·t). Values outside [0, 1] — recordings,
// raw counts, signed data — are scaled to the full range the way the
// references are (a = 0.5 + 0.5·y/max|y|, y the zero-mean signal); values
// already in [0, 1] are kept as they are.
//
// Trade-off: a file that carries its own grid (CSV positions, a recording's
// rate, a .mat spacing) must agree with an explicit `spacing` rather than be
// silently re-gridded: a mismatch is an error, since the spectrum of a map
// read at the wrong spacing is wrong by exactly the ratio.
//
// Errors: InvalidArgument (a FieldError naming the option field: "device",
// "spacing", "region", "swipe_speed", "channel", "max_samples"), FormatError
// (the file does not parse; names the file) and IoError (cannot read it).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/units.hpp"

namespace texel {

/// The formats load_signal reads, picked by the file's extension.
enum class SignalFormat {
  device_map,  ///< .bin: device-native samples; needs `device`
  npy,         ///< .npy: 1-D array of amplitudes; needs `device` or `spacing`
  csv,         ///< .csv: position_mm,amplitude — or time_s,value when the header starts with 't'
  wav,         ///< .wav (any libsndfile format): a time recording; needs `swipe_speed`
  mat,         ///< .mat: a MATLAB map (docs/format.md "MATLAB .mat"); file only
  document,    ///< .texel.json: rendered on its device (or on `device`)
  bitstream,   ///< .texel: decoded and rendered on `device`
  hjif,        ///< .hjif: MPEG-I Haptics curves sampled on a grid (texel/interchange.hpp); temporal ones need `swipe_speed`
  hmpg,        ///< .hmpg: the binary MPEG-I Haptics stream, read as .hjif (spatial data; texel/interchange.hpp)
};

/// "device-map", "npy", "csv", "wav", "mat", "document", "bitstream", "hjif", "hmpg".
std::string_view to_string(SignalFormat format);
/// The format a path's extension names (.bin .npy .csv .wav .mat .texel.json
/// .json .texel .hjif .hmpg); throws InvalidArgument naming the extension and the allowed ones.
SignalFormat signal_format_of(const std::string& path);

/// What to do with a recording of more than one channel.
enum class ChannelPolicy {
  /// Default: a multi-channel recording is rejected, naming its channel
  /// count — which channel carries the texture is the user's call, and a
  /// silent mix of a stereo pair can cancel it.
  mono_only,
  mix,     ///< average all channels
  select,  ///< keep channel `SignalOptions::channel` (0-based)
};

/// How to read a signal. Every field is optional; the defaults are stated.
struct SignalOptions {
  /// Grid and sample format of a .bin, the spacing of a .npy, the device a
  /// document is re-targeted to and a bitstream is decoded on. Default none:
  /// a .bin or .texel without it is rejected (a .npy may give `spacing`).
  std::optional<DeviceProfile> device;
  /// Sample spacing, mm (> 0): overrides the device's; must agree (within
  /// spacing_tolerance) with a file that carries its own grid.
  std::optional<Millimetres> spacing;
  /// A part of the signal, [start, end) in mm on the signal's own axis
  /// (origin + i·spacing); or, for a document, one region by name or index.
  struct Region {
    std::string name;  ///< a document region (name or index); empty: use start/end
    Millimetres start{-std::numeric_limits<double>::infinity()};
    Millimetres end{std::numeric_limits<double>::infinity()};
  };
  std::optional<Region> region;
  /// Finger speed, mm/s (> 0): turns a time recording into positions. Required for .wav and time/value .csv.
  std::optional<MmPerSecond> swipe_speed;
  ChannelPolicy channels = ChannelPolicy::mono_only;  ///< multi-channel recordings [mono_only]
  unsigned channel = 0;                               ///< the channel kept under ChannelPolicy::select
  /// Most samples (per channel × channels for a recording) a file may declare;
  /// checked before anything that size is allocated [2^26 = 67 108 864].
  std::size_t max_samples = std::size_t{1} << 26;
};

/// Relative tolerance of a uniform grid: each step within 1 % of the mean
/// step (CSV positions and times, .mat positions). One value for every format.
inline constexpr double spacing_tolerance = 0.01;

/// A texture signal on a uniform spatial grid.
struct Signal {
  std::vector<double> samples;  ///< amplitudes, in [0, 1] (see `scaled`)
  Millimetres spacing{0.0};     ///< > 0
  Millimetres origin{0.0};      ///< position of samples[0]
  SignalFormat format = SignalFormat::npy;
  bool scaled = false;               ///< values were outside [0, 1] (or a recording) and were scaled to full range
  std::optional<Hertz> sample_rate;  ///< time recordings: their rate
  std::string description;           ///< where it came from, for reports ("audio 48000 Hz at 100 mm/s")

  [[nodiscard]] Millimetres length() const { return spacing * static_cast<double>(samples.size()); }
};

/// The one input rule for amplitude maps, 1-D or 2-D, at every front door
/// (a file, a Python array, a C or MEX array): values all in [0, 1] are kept
/// as they are; a map with any value outside [0, 1] (raw counts, signed
/// data, a map ×100) is scaled to full range, a = 0.5 + 0.5·y/max|y| for the
/// zero-mean values y — never clamped. Returns true when it scaled. Throws
/// FormatError naming `origin`: a non-finite value (its element), a constant
/// map outside [0, 1] (it holds no texture).
bool to_amplitudes(std::span<double> values, std::string_view origin);

/// Loads any texture signal from a file (format by extension). Throws as
/// described above; messages name the file.
Signal load_signal(const std::string& path, const SignalOptions& options = {});

/// The same from bytes already in memory (a fuzzer's or a server's input);
/// `origin` names them in errors. SignalFormat::mat is file-only (libmatio
/// opens by name): InvalidArgument.
Signal decode_signal(std::span<const std::byte> bytes, SignalFormat format, const SignalOptions& options,
                     std::string_view origin);

/// A document as a signal: rendered on its device (or on `device`, at
/// `spacing`), `region` applied. The codec decodes bitstreams through it.
Signal signal_of_document(Document doc, const SignalOptions& options, std::string_view origin);

/// A recording as its samples: mono under options.channels, values as
/// stored (−1 … 1 for PCM), not scaled, no swipe speed needed.
struct Recording {
  std::vector<double> samples;
  Hertz rate{0.0};
  unsigned channels = 0;  ///< channels in the file
};
/// Reads audio (.wav or any format libsndfile knows) through libsndfile.
Recording read_recording(const std::string& path, const SignalOptions& options = {});
/// The same from memory (libsndfile virtual I/O).
Recording decode_recording(std::span<const std::byte> bytes, const SignalOptions& options, std::string_view origin);

}  // namespace texel
