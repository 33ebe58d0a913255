// Interchange with the haptics standard: MPEG-I Haptics (ISO/IEC 23090-31)
// JSON interchange files (.hjif) out and in, and a glTF 2.0 asset carrying
// the texture through the MPEG_haptic / MPEG_haptic_material extensions
// (docs/interchange.md has the mapping, the sources followed and the rules).
//
// Export: a document's rendered amplitude map on its device grid becomes one
// spatial perception per region (modality "Friction" or "Vibrotactile
// Texture", unit_exponent −3: positions in millimetres, `timescale` ticks per
// millimetre), one channel, one Curve band with curve_type "Linear" whose
// keyframes are placed adaptively: the fewest (greedy, one pass) such that the
// curve, evaluated on the device grid exactly as import() evaluates it,
// stays within `tolerance` of the rendered map. The document itself travels
// in the experience's description, so Texel re-imports the parameters exactly
// (the seed, hence the 14-byte bitstream); any other reader still has the
// samples. Trade-off [choice]: Linear Curve bands are the one band whose
// interpolation the public sources define unambiguously; a fine texture at
// the 1/512 tolerance needs about one keyframe per grid sample, so the file
// is large (docs/interchange.md measures it) but exact to the tolerance on
// every reader.
//
// Import: parse_hjif validates every field this reader knows (types, ranges,
// enumerations, array sizes, nesting depth, the profile and level rules) and
// throws FormatError naming the JSON path; evaluate() samples the spatial
// perceptions (or, at a swipe speed, temporal "Vibrotactile" ones) on a grid.
// The signal loader (texel/signal.hpp) reads .hjif files through them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/document.hpp"
#include "texel/grid.hpp"
#include "texel/units.hpp"

namespace texel::hjif {

/// The perception modalities Texel writes: friction modulation (the
/// displays Texel targets) or a vibrotactile texture (sound-card actuators).
enum class Modality { friction, vibrotactile_texture };
/// "friction" / "vibrotactile-texture" (CLI spelling).
std::string_view to_string(Modality m);
/// The standard's spelling: "Friction" / "Vibrotactile Texture".
std::string_view modality_name(Modality m);
/// Parses the CLI spelling; InvalidArgument naming `field` and the allowed values.
Modality parse_modality(std::string_view text, std::string_view field = "modality");

/// Default tolerance: max |error| of 1/512 of full scale on the device grid.
inline constexpr double default_tolerance = 1.0 / 512.0;

struct ExportOptions {
  Modality modality = Modality::friction;
  /// Largest |curve − rendered map| allowed at any grid sample, full scale
  /// (0 < tolerance ≤ 0.5) [1/512].
  double tolerance = default_tolerance;
  /// The file's date: RFC 3339 (2026-11-26T14:06:29Z), or a day
  /// (YYYY-MM-DD, written as its midnight UTC). Empty: $SOURCE_DATE_EPOCH if
  /// set (reproducible builds), else now (UTC, whole seconds).
  std::string date;
};

/// What an export wrote and how well the samples reproduce the map.
struct ExportStats {
  std::size_t perceptions = 0;
  std::size_t keyframes = 0;    ///< over all perceptions
  std::size_t samples = 0;      ///< grid samples covered by regions
  std::uint32_t timescale = 0;  ///< ticks per millimetre
  int amplitude_decimals = 0;   ///< decimals written per amplitude
  double max_error = 0.0;       ///< max |curve − map| on the device grid, full scale
  bool grid_on_ticks = true;    ///< every grid position is a whole number of ticks
};

struct Exported {
  std::string json;  ///< the .hjif text
  ExportStats stats;
};

/// Exports a document (rendered on its own device). Throws InvalidArgument for
/// options out of range, and when the tolerance cannot be met on the tick grid.
Exported export_hjif(const Document& doc, const ExportOptions& options = {});

// --- import -------------------------------------------------------------------

/// One keyframe of a Linear curve, at an absolute position in ticks.
struct Keyframe {
  std::int64_t position = 0;  ///< effect position + relative_position, ticks
  double amplitude = 0.0;     ///< amplitude_modulation, −1 … 1
};

/// One Curve effect: linear between its keyframes, 0 outside them.
struct CurveEffect {
  std::vector<Keyframe> keyframes;  ///< strictly increasing positions, ≥ 1
};

/// One keyframe of a VectorialWave or Transient effect (temporal perceptions).
struct WaveKeyframe {
  std::int64_t position = 0;        ///< relative_position, ticks from the effect's position
  std::optional<double> amplitude;  ///< amplitude_modulation
  std::optional<double> frequency;  ///< frequency_modulation, Hz
};

/// A VectorialWave effect (a base signal whose amplitude and frequency are
/// interpolated linearly between keyframes, its phase the integral of the
/// frequency) or a Transient effect (each keyframe a burst of two sine
/// periods over 22 ms), as the reference software evaluates them.
struct WaveEffect {
  enum class Kind { vectorial, transient };
  Kind kind = Kind::vectorial;
  std::int64_t position = 0;            ///< ticks
  double phase = 0.0;                   ///< radians (VectorialWave)
  std::string base_signal = "Sine";     ///< Sine, Square, Triangle, SawToothUp, SawToothDown
  double gain = 1.0;                    ///< the channel's gain
  std::vector<WaveKeyframe> keyframes;  ///< ascending positions
};

/// A perception this reader can sample.
struct Perception {
  std::int64_t id = 0;
  std::string description;
  std::string modality;                             ///< as written, e.g. "Friction"
  bool spatial = false;                             ///< Friction / Vibrotactile Texture (else temporal Vibrotactile or Other)
  int unit_exponent = -3;                           ///< spatial unit = 10^unit_exponent m [−3 when absent, choice]
  double gain = 1.0;                                ///< product of the channel gains applied
  std::vector<CurveEffect> effects;                 ///< every Curve effect of every channel and band
  std::vector<WaveEffect> waves;                    ///< VectorialWave and Transient effects (temporal perceptions only)
  std::optional<std::string> reference_device;      ///< first reference device's name
  std::optional<std::uint32_t> frequency_sampling;  ///< first channel's, if given
};

/// A validated .hjif file, reduced to what Texel reads.
struct Experience {
  std::string version;
  std::string profile;
  int level = 1;
  std::string date;
  std::string description;
  std::uint32_t timescale = 1000;       ///< ticks per second (temporal) / per spatial unit (spatial)
  std::vector<Perception> perceptions;  ///< the ones Texel can sample (spatial, or temporal vibrotactile)
  std::vector<std::string> skipped;     ///< modalities present but not sampled (e.g. "Temperature")
  /// The Texel document carried in the description, when present, parsed and
  /// consistent with the curves (within the tolerance written beside it).
  std::optional<Document> carried;
  /// Why a carried document was not used (malformed, inconsistent); empty otherwise.
  std::string carried_rejected;
};

/// Limits on what parse_hjif accepts (checked before anything that size is built).
struct ImportLimits {
  std::size_t max_bytes = std::size_t{256} << 20;    ///< text size
  std::size_t max_depth = 32;                        ///< JSON nesting
  std::size_t max_keyframes = std::size_t{1} << 24;  ///< over the whole file
  std::size_t max_items = std::size_t{1} << 16;      ///< perceptions, channels, bands, effects (each array)
};

/// Parses and validates a .hjif text; `origin` names it in errors (FormatError,
/// one line, with the JSON path).
Experience parse_hjif(std::string_view text, std::string_view origin = "hjif", const ImportLimits& limits = {});

/// Reads and parses a .hjif file; a file over limits.max_bytes is refused before it is read.
Experience load_hjif(const std::string& path, const ImportLimits& limits = {});

/// Conformance of a JSON text: every keyword of the published JSON schemas
/// (date-time checked as RFC 3339), the field dependencies their
/// descriptions state, and the reference software's loader rules
/// (docs/interchange.md lists each). One line per violation, starting with
/// the JSON path; empty: conformant. parse_hjif is more liberal (dates in
/// other common forms, the reference software's rules not enforced).
std::vector<std::string> conformance_errors(std::string_view text);

/// The published JSON schemas alone (every keyword, date-time as RFC 3339):
/// what a format-checking schema validator reports. A subset of conformance_errors.
std::vector<std::string> schema_errors(std::string_view text);

/// Value of the sampled perceptions at `positions_mm` (each perception's
/// effects summed, times its gain; 0 where no effect has keyframes). Spatial
/// perceptions: x in mm is ticks / timescale · 10^(unit_exponent + 3).
/// Temporal: x = swipe speed · ticks / timescale; `swipe_speed` required.
std::vector<double> evaluate(const Experience& e, std::span<const double> positions_mm,
                             std::optional<MmPerSecond> swipe_speed = std::nullopt);

/// Last position (mm) any keyframe reaches, at the swipe speed for temporal files.
double extent_mm(const Experience& e, std::optional<MmPerSecond> swipe_speed = std::nullopt);

/// The marker that starts the carried document in the description.
inline constexpr std::string_view carried_marker = "texel-document:";

}  // namespace texel::hjif

namespace texel::gltf {

enum class Container { gltf, glb };

struct AssetOptions {
  hjif::Modality modality = hjif::Modality::friction;
  /// URI of the .hjif the asset references (relative to the asset), e.g. "a.hjif".
  std::string hjif_uri;
  /// Width of the quad (mm), across the swipe axis [25: the reference display's glass].
  double width_mm = 25.0;
};

/// A glTF 2.0 asset: one quad the size of the display (metres, +X along the
/// swipe axis), its base colour the amplitude map (a 1-row 16-bit grey PNG,
/// one pixel per sample, padded with zeros to a power-of-two width),
/// and the haptic material: MPEG_haptic (the referenced .hjif through
/// MPEG_media) and MPEG_haptic_material with the map as a High_Resolution
/// texture plus a Reference texture to the haptic object. Text for .gltf,
/// bytes for .glb.
std::vector<std::byte> asset(const Document& doc, const AssetOptions& options, Container container);

/// The same asset around a 2-D friction map (`png`: the bitmap, any PNG the
/// caller made, e.g. texel::write_bitmap's), the quad width × height mm with
/// +Y down the image's rows. `options.hjif_uri` empty: no haptic stream is
/// referenced, and the material lists the map as its High_Resolution
/// texture only; width_mm is not used.
std::vector<std::byte> asset_2d(const std::vector<std::byte>& png, double width_mm, double height_mm, const std::string& name,
                                const AssetOptions& options, Container container);

/// A PNG of one row, 16-bit grey (values round(a·65535)), deflate "stored"
/// blocks: lossless and dependency-free.
std::vector<std::byte> png_row16(std::span<const double> amplitudes);

}  // namespace texel::gltf

// --- binary MPEG-I Haptics stream (.hmpg) ---------------------------------------
//
// The MIHS units and packets of the public reference software's stream writer,
// for the spatial data Texel writes (docs/interchange.md "Binary .hmpg" states
// exactly which parts of the syntax are implemented). Amplitudes travel as
// 8-bit codes over [−1, 1] (step 2/255), keyframe positions as 16 bits
// relative to their effect (Texel splits longer effects), effect positions as
// 25 bits; the description is at most 255 bytes (the carried Texel document
// does not fit: a .hmpg gives the samples only).
namespace texel::hmpg {

/// Encodes a conformant .hjif text (hjif::conformance_errors empty) as .hmpg
/// bytes. Throws InvalidArgument naming the field the binary syntax cannot
/// carry (temporal perceptions, effect libraries, counts past their field
/// widths).
std::vector<std::byte> encode(std::string_view hjif_text);

/// Decodes .hmpg bytes into .hjif text (the experience the stream carries;
/// hjif::parse_hjif reads it). Throws FormatError (one line: `origin`, what,
/// the byte offset) for truncated streams, codes outside the syntax, counts
/// past what remains, and the parts of the syntax Texel does not read.
std::string decode(std::span<const std::byte> bytes, std::string_view origin = "hmpg", const hjif::ImportLimits& limits = {});

/// Reads a .hmpg file (refused past limits.max_bytes before it is read) and parses it as parse_hjif does.
hjif::Experience load(const std::string& path, const hjif::ImportLimits& limits = {});

/// Amplitude step of the binary syntax: 8-bit codes over [−1, 1].
inline constexpr double amplitude_step = 2.0 / 255.0;

struct Exported {
  std::vector<std::byte> bytes;
  hjif::ExportStats stats;  ///< max_error: measured after decoding, on the device grid
};

/// Exports a document as .hmpg: export_hjif, then encode; the error is
/// measured on the decoded stream (≤ tolerance + amplitude_step / 2).
Exported export_hmpg(const Document& doc, const hjif::ExportOptions& options = {});

}  // namespace texel::hmpg
