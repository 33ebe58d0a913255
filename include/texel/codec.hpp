// The Texel codec: any texture signal in, Texel parameters and a bitstream of
// a few bytes out (encoder); bitstream in, a texture on any device out
// (decoder).
//
// Encoder (docs/encoder.md has the model, its parameters and sources):
//  0. Inputs without fine texture (constant per texel, as the renderer draws
//     F = 0, or next to no power above the boundary) are a coarse profile.
//  1. Split. The amplitude envelope is what changes more slowly than the
//     fine/coarse boundary (1 mm): running maximum and minimum over a window
//     of about two fine periods, smoothed by a moving average one boundary
//     long. A flat envelope is a fine-only texture; otherwise its values at
//     the texel centres become the coarse profile c_k with strengths C and F
//     (docs/algorithm.md §7: e_k = 1 − C(1 − c_k), trough/peak = 1 − F).
//  2. Fine part by analysis-by-synthesis. A perceptual model maps a signal to
//     a felt pitch (the mean frequency weighted by suprathreshold
//     sensitivity and amplitude, raised so the strongest components
//     dominate) and a felt noisiness (the weighted spread of log-frequency),
//     at the swipe speed that turns cycles/mm into Hz, through the display's
//     frequency response (PerceptualModel::display: the device's, from the
//     front doors), the fit anchored by the texture as drawn (the stream is
//     device independent and the response an estimate). Candidate Texel
//     textures are rendered with the library and compared with the input
//     under the model; least squares (Levenberg–Marquardt, or the simplex on
//     request) over (Central Pitch, Irregularity) minimises the distance,
//     from the best of a grid around the input's spectral centroid and spread.
//  3. Inputs that are themselves fine-only Texel renderings are recognised
//     (phase-continuous sinusoid, constant frequency per texel) and their
//     texel length, Central Pitch and Irregularity are recovered from the
//     texels' frequencies (truncated-lognormal maximum likelihood).
// Trade-off: the fit matches what the model says is felt, not the waveform;
// the texel length is a setting (default 0.25 mm) except for recognised
// Texel renderings.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "texel/bitstream.hpp"
#include "texel/document.hpp"
#include "texel/option_spec.hpp"
#include "texel/signal.hpp"
#include "texel/units.hpp"

namespace texel::codec {

// --- signals ----------------------------------------------------------------

/// The encoder's input: a texture signal on a uniform spatial grid (sample i
/// at i·spacing mm). Files are read by texel::load_signal (texel/signal.hpp).
struct Signal {
  std::vector<double> amplitude;  ///< nominally in [0, 1]
  Millimetres spacing{0.0};       ///< > 0
  std::string description;        ///< where it came from, for reports
  /// A time recording (a vibration or sound at a finger speed: .wav, time
  /// .csv), which EncoderConfig::Target::automatic encodes to its centroid.
  bool recording = false;
};

/// texel::load_signal (every format, texel/signal.hpp), plus the one format
/// only the codec can decode: a bitstream (.texel), rendered on
/// options.device like a document. Front doors that accept bitstreams call this.
texel::Signal load_signal(const std::string& path, const SignalOptions& options = {});
/// texel::decode_signal plus bitstreams, from memory.
texel::Signal decode_signal(std::span<const std::byte> bytes, SignalFormat format, const SignalOptions& options,
                            std::string_view origin);
/// The encoder's view of a loaded signal (its samples from its origin on).
Signal encoder_signal(const texel::Signal& signal);

// --- the perceptual model ---------------------------------------------------

struct PerceptualModel {
  /// Which model (docs/encoder.md §2, "Model versions"): 2 [default] the
  /// band model calibrated against people's matches; 1 the model before
  /// (per-bin weighting); 3 version 2 within the felt band, weighed over a
  /// lognormal range of stroke speeds (speed_spread; a recording's content
  /// above felt_band_top at its speed is not felt). Each version's defaults:
  /// model_defaults(version). Named in every EncodeResult and `--json`
  /// ("model_version").
  int version = 2;
  MmPerSecond swipe_speed{100.0};  ///< mm/s; turns cycles/mm into Hz (typical exploration 50 … 200 mm/s)
  double pitch_jnd_db = 1.0;       ///< just-noticeable pitch change, dB (≈ 25 % frequency)
  double noisiness_jnd_db = 1.0;   ///< just-noticeable change of spread, dB [modelling choice]
  double tie_weight = 0.01;        ///< weight of the physical tie-break terms (see docs/encoder.md)
  /// Felt weight of a component (docs/encoder.md §2): its sensation
  /// amplitude raised to this power. Version 2 [fitted]: 3, each octave
  /// band's amplitude above threshold cubed; version 1 [choice]: 1.75 per bin.
  double weight_exponent = 3.0;
  /// How much of the threshold curve's frequency dependence (dB) the weight
  /// keeps at the suprathreshold levels textures are felt at (equal-sensation
  /// contours flatten with level): version 2 [fitted] and version 1
  /// [choice] 0.5; 1 is the threshold curve itself.
  double sensitivity_scale = 0.5;
  /// Version 2 only: how a band's sensation level becomes its felt weight.
  /// power: its amplitude above threshold raised to weight_exponent;
  /// equal: every band within window_db of the strongest counts the same
  /// (soft edge); channels: Pacinian and non-Pacinian sensation pooled per
  /// channel, the weaker channel counting half.
  enum class Weighting { power, equal, channels } weighting = Weighting::power;
  /// Version 2: share of the threshold curve kept below 250 Hz (the
  /// non-Pacinian side, where equal-sensation contours flatten most with
  /// level); negative: sensitivity_scale on both sides.
  double sensitivity_scale_low = -1.0;
  double band_octaves = 1.0;  ///< version 2 [fitted]: width of the constant-Q analysis bands, octaves (9 bands, 16 Hz … 4 kHz)
  double window_db = 10.0;    ///< version 2, equal weighting: bands this far below the strongest still count
  /// Version 2: felt pitch as the weighted mean of log-frequency (true) or
  /// of frequency (false, as version 1).
  bool log_pitch = true;
  /// The display between the texture and the finger (DeviceProfile::response,
  /// docs/encoder.md §2 "The display in the loop"): what people feel through
  /// a display is the displayed texture filtered by the display's response,
  /// so each component's amplitude is weighted by |H(f·v)| at this model's
  /// swipe speed v before the felt weights are formed. Default flat: no
  /// display. `texel encode --device D` and Python `encode(device=D)` set D's
  /// response.
  FrequencyResponse display{};
  /// Whether `display` is in the loop [choice] device: the model feels what
  /// the display reproduces (felt pitch and noisiness through it); flat: the
  /// texture as drawn (the model before; also what a flat `display` gives).
  enum class Display { device, flat } display_response = Display::device;
  /// With a display in the loop, the fit also matches the texture as drawn
  /// (its felt pitch and noisiness without the display), weighted by this
  /// [choice] 1: the stream is device independent and the display's response
  /// is an estimate, so a texture must feel right through the display and
  /// as drawn; where the display hides a difference, the drawn texture
  /// decides (docs/encoder.md §2). 0: the display alone. Unused without a
  /// display in the loop. >= 0.
  double drawn_weight = 1.0;
  /// Also measure Percept::log_centroid_db (the encoder's centroid target
  /// sets it; off, the field stays 0 and perceiving costs nothing more).
  bool centroid = false;
  /// The top of the felt band (docs/encoder.md §2, "Version 3"), Hz at the
  /// swipe speed: at that speed version 3 gives content above it no weight
  /// at any level (felt, drawn, the physical tie-break and the centroid
  /// target alike); over its range of stroke speeds (speed_spread) content
  /// up to felt_band_reach_cpm is felt on the slower strokes. A recording's
  /// content above it is cut before the analysis.
  /// Every version reports the input's power above it
  /// (EncodeResult::beyond_felt_band). [choice] 1000 Hz; > 0.
  Hertz felt_band_top{1000.0};
  /// Version 3 (docs/encoder.md §2, "Version 3: speeds"): people stroke at a
  /// range of speeds; the felt weight of a spatial frequency is its weight
  /// averaged over a lognormal distribution of speed with median
  /// swipe_speed and this standard deviation of ln(speed). 0: one speed.
  /// model_defaults(3): [fitted] 0.6 (with sensitivity_scale 1 and
  /// weight_exponent 4; not measured, see docs/encoder.md); 0 … 1.5.
  double speed_spread = 0.0;
  /// Version 3: a soft roll-off instead of the hard top, dB/octave added
  /// above felt_rolloff_knee (no floor: sensitivity keeps falling); content
  /// is then analysed up to where the threshold reaches 80 dB. 0: the hard
  /// top felt_band_top. [choice] 0 (a roll-off was measured and not
  /// chosen: docs/encoder.md §2, "Version 3"); 0 … 200.
  double felt_rolloff_db_per_octave = 0.0;
  Hertz felt_rolloff_knee{500.0};  ///< Hz at the swipe speed; > 250
};

/// The log-spectral centroid's band (Percept::log_centroid_db): from
/// 20 Hz at the model's swipe speed (the low end of recordings and of touch)
/// to 0.9 of the grid's Nyquist frequency (where anti-alias filters still pass).
inline constexpr double centroid_low_hz = 20.0;
inline constexpr double centroid_top_nyquist = 0.9;

/// The defaults of model `version` (1, 2 or 3; InvalidArgument otherwise):
/// version 1 is the model before, bit for bit.
PerceptualModel model_defaults(int version);
std::string_view to_string(PerceptualModel::Weighting w);
std::string_view to_string(PerceptualModel::Display d);
/// "device" or "flat"; errors name `field`.
PerceptualModel::Display parse_display_response(std::string_view text, std::string_view field = "display_response");
/// |H(f·v)| the model applies at spatial frequency f (cycles/mm): the display's
/// gain at the model's swipe speed, or 1 when the display is flat or off.
double display_gain(const PerceptualModel& model, CyclesPerMm f);
/// A display is in the model's loop: display_response is device and the
/// display is not flat.
bool display_in_loop(const PerceptualModel& model);

/// Relative vibrotactile threshold at temporal frequency f, dB above the most
/// sensitive frequency (0 dB at 250 Hz): a straight-line Pacinian U
/// (12 dB/octave either side of 250 Hz) capped by a flat non-Pacinian floor
/// 30 dB up and a 60 dB ceiling. Weight = 10^(−threshold/20).
double threshold_db(Hertz f);
/// Version 3's threshold (docs/encoder.md §2, "Version 3"): threshold_db's
/// U below 250 Hz (its non-Pacinian floor kept), the Pacinian branch rising
/// 12 dB/octave above 250 Hz without a cap, and +infinity (no sensitivity)
/// above `top`, the felt band's top.
double felt_threshold_db(Hertz f, Hertz top);
/// The felt band's top in cycles/mm at the model's swipe speed.
CyclesPerMm felt_band_top_cpm(const PerceptualModel& model);
/// Version 3's threshold of `model` at temporal frequency f (Hz at the
/// model's swipe speed): felt_threshold_db (or the soft roll-off) averaged
/// in sensitivity over the model's speed spread. +infinity: no weight.
double felt_weight_threshold_db(Hertz f, const PerceptualModel& model);
/// The highest spatial frequency version 3 gives any weight (cycles/mm):
/// the band its percept and the encoder's analysis see.
CyclesPerMm felt_band_reach_cpm(const PerceptualModel& model);

/// What the model extracts from a fine-texture signal.
struct Percept {
  double pitch_db = 0.0;      ///< felt pitch, dB re 1 cpm
  double noisiness_db = 0.0;  ///< felt spread of log-frequency, dB
  double mean_db = 0.0;       ///< physical: power-weighted mean frequency, dB re 1 cpm
  double spread_db = 0.0;     ///< physical: power-weighted SD of 10·log10 f, dB
  /// Felt pitch and noisiness of the texture as drawn (without the display);
  /// equal to pitch_db and noisiness_db when no display is in the loop.
  double drawn_pitch_db = 0.0;
  double drawn_noisiness_db = 0.0;
  /// Physical: the log-spectral centroid, the power-weighted mean of
  /// 10·log10 f (dB re 1 cpm) over every bin from centroid_low_hz (and
  /// f_min) to centroid_top_nyquist, unmasked: what the `centroid` target
  /// matches (EncoderConfig::target). 0 unless PerceptualModel::centroid.
  double log_centroid_db = 0.0;
};

/// A percept as named fields, the names every front door reports it under
/// (pitch_db, noisiness_db, centroid_db, spread_db, drawn_pitch_db,
/// drawn_noisiness_db).
std::array<std::pair<const char*, double>, 6> fields(const Percept& p);

/// Percept of a zero-mean fine signal sampled every `spacing_mm`, from its
/// content above `f_min_cpm` (and above 0.01 cpm).
Percept perceive(std::span<const double> fine, double spacing_mm, const PerceptualModel& model, double f_min_cpm = 0.0);
/// Model distance in JND units (plus the small physical tie-break): how
/// different the two feel (through the display when one is in the loop).
double distance(const Percept& a, const Percept& b, const PerceptualModel& model);
/// What the fit minimises: distance() plus, with a display in the loop, the
/// difference of the textures as drawn weighted by drawn_weight (JND units).
/// Equal to distance() without a display in the loop.
double fit_distance(const Percept& a, const Percept& b, const PerceptualModel& model);

// --- encoder ----------------------------------------------------------------

/// How the fit searches (P, I) (docs/encoder.md §3). [choice] least_squares.
enum class FitMethod {
  least_squares,  ///< 3 × 3 grid, then Levenberg–Marquardt on the model's residuals (~20 evaluations)
  simplex,        ///< 3 × 3 grid, then Nelder–Mead and a restart (~120 evaluations; the method before)
};

std::string_view to_string(FitMethod m);
/// "least-squares" or "simplex"; errors name `field`.
FitMethod parse_fit_method(std::string_view text, std::string_view field = "fit_method");

struct EncoderConfig {
  PerceptualModel model;
  Millimetres boundary{1.0};       ///< fine/coarse boundary, mm (> 0)
  Millimetres texel_length{0.25};  ///< texel length of the encoding, mm
  Parameterization parameterization = Parameterization::moments;
  std::uint64_t seed = 1;                           ///< seed written to the bitstream
  unsigned coarse_bits = 6;                         ///< bits per coarse level (1 … 16)
  std::optional<std::size_t> max_bytes;             ///< bitstream budget, bytes (coarse precision/stride adapt)
  double flat_envelope = 0.08;                      ///< relative envelope range below which the texture is fine only
  FitMethod fit_method = FitMethod::least_squares;  ///< search of the fit
  int max_evaluations = 120;                        ///< Nelder–Mead budget (each renders 2 candidates)
  /// Recognise inputs that are fine-only Texel renderings and recover their
  /// texel length, Central Pitch and Irregularity from the texels'
  /// frequencies (kept when the model distance is below 1 JND; docs/encoder.md).
  bool recover_texel = true;
  /// An input without texture (docs/encoder.md, "Honest results"): its
  /// zero-mean RMS at most no_texture_floor (a constant or all-zero input).
  /// [choice] flag: encoded as a flat surface with EncodeResult::no_texture
  /// set; refuse: InvalidArgument (the CLI's exit 2 with one line).
  enum class NoTexture { flag, refuse } no_texture = NoTexture::flag;
  /// What Central Pitch matches (docs/encoder.md §3, "Targets"): felt, the
  /// model's felt pitch; centroid, the felt fit with Central Pitch then moved
  /// until the decoded texture's log-spectral centroid is the input's;
  /// automatic [default], centroid for recordings (Signal::recording) and
  /// felt for maps. [choice]; named in every result (EncodeResult::target).
  enum class Target { automatic, felt, centroid } target = Target::automatic;
};

/// The floor of "no texture": zero-mean RMS of the amplitude (0 … 1) at or
/// below one step of a 16-bit map, 2^-16.
inline constexpr double no_texture_floor = 1.0 / 65536.0;
std::string_view to_string(EncoderConfig::NoTexture n);
/// "flag" or "refuse"; errors name `field`.
EncoderConfig::NoTexture parse_no_texture(std::string_view text, std::string_view field = "no_texture");
std::string_view to_string(EncoderConfig::Target t);
/// "automatic", "felt" or "centroid"; errors name `field`.
EncoderConfig::Target parse_target(std::string_view text, std::string_view field = "target");

inline constexpr OptionChoice fit_methods[] = {{"least-squares", static_cast<int>(FitMethod::least_squares)},
                                               {"simplex", static_cast<int>(FitMethod::simplex)}};
inline constexpr OptionChoice no_texture_rules[] = {{"flag", static_cast<int>(EncoderConfig::NoTexture::flag)},
                                                    {"refuse", static_cast<int>(EncoderConfig::NoTexture::refuse)}};
inline constexpr OptionChoice encode_targets[] = {{"automatic", static_cast<int>(EncoderConfig::Target::automatic)},
                                                  {"felt", static_cast<int>(EncoderConfig::Target::felt)},
                                                  {"centroid", static_cast<int>(EncoderConfig::Target::centroid)}};
inline constexpr OptionChoice display_responses[] = {{"device", static_cast<int>(PerceptualModel::Display::device)},
                                                     {"flat", static_cast<int>(PerceptualModel::Display::flat)}};

/// The encoder's options as every front door offers them (`texel encode`'s
/// "Encoder" flags, Python's encode() keywords, C's texel_encode_options),
/// described once (texel/option_spec.hpp); the defaults are EncoderConfig{}'s.
/// Not here: how the input is read (device, spacing, region, channel, swipe
/// speed: SignalOptions) and the model's calibrated parameters
/// (weight_exponent, sensitivity_scale), whose defaults are each model
/// version's (model_defaults) — `model` picks them.
template <class Config, class Visit>
requires std::is_same_v<std::remove_const_t<Config>, EncoderConfig>
void visit_options(Config& c, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(c.boundary, OptionSpec{"boundary_mm", "boundary", "Fine/coarse boundary, mm", 0, inf, true});
  visit(c.texel_length, OptionSpec{"texel_length_mm", "texel-length", "Texel length of the encoding, mm", 0.001, 65.535});
  visit(c.seed, OptionSpec{"seed", "seed", "Seed written to the bitstream", 0});
  visit(c.parameterization,
        OptionSpec{"parameterization", "parameterization", "moments | log", -inf, inf, false, false, parameterizations});
  visit(c.model.version, OptionSpec{"model", "model",
                                    "Perceptual model version: 2 (calibrated against people's matches), 3 (the felt band, "
                                    "weighed over a range of stroke speeds; a recording's content above 1 kHz at its speed "
                                    "is not felt) or 1 (the model before)",
                                    1, 3});
  visit(c.no_texture, OptionSpec{"no_texture", "no-texture",
                                 "An input without texture (variation RMS <= 2^-16): flag (encode a flat surface, say so) "
                                 "or refuse (an error)",
                                 -inf, inf, false, false, no_texture_rules});
  visit(c.target, OptionSpec{"target", "target",
                             "What Central Pitch matches: felt (the model's felt pitch), centroid (the recording's "
                             "log-spectral centroid, the decoded texture swiped at the swipe speed) or automatic (centroid "
                             "for .wav and time .csv recordings, felt for maps)",
                             -inf, inf, false, false, encode_targets});
  visit(c.model.display_response,
        OptionSpec{"display_response", "display-response",
                   "Perceptual model: device (felt as the device's frequency response passes it at the swipe speed) or "
                   "flat (the texture as drawn)",
                   -inf, inf, false, false, display_responses});
  visit(c.model.drawn_weight, OptionSpec{"drawn_weight", "drawn-weight",
                                         "Perceptual model: weight of the texture as drawn beside the displayed one in "
                                         "the fit (0 = the display alone)",
                                         0, 100});
  visit(c.fit_method, OptionSpec{"fit", "fit", "Search of the perceptual fit: least-squares | simplex (slower)", -inf, inf, false,
                                 false, fit_methods});
  visit(c.coarse_bits, OptionSpec{"coarse_bits", "coarse-bits", "Bits per coarse level, 1 … 16", 1, 16});
  visit(c.max_bytes,
        OptionSpec{"max_bytes", "max-bytes", "Bit budget: largest bitstream, bytes (coarse precision and spacing adapt)", 1});
}

struct EncodeResult {
  Bitstream bitstream;
  std::vector<std::byte> bytes;
  TexelSpec spec;                   ///< what the bitstream decodes to
  Percept input;                    ///< the input's fine part under the model
  Percept decoded;                  ///< the decoded texture's, on the input's grid
  double model_distance = 0.0;      ///< distance(input, decoded), JND units
  bool coarse = false;              ///< a coarse profile was found
  double coarse_correlation = 1.0;  ///< envelope vs decoded envelope at texel centres
  bool texel_recovered = false;     ///< the input was recognised as a Texel rendering (texel length detected)
  /// False when a narrower distribution feels the same (irregularity_bound_db
  /// then says up to where), or when a fitted value is at a search bound.
  bool irregularity_identifiable = true;
  double irregularity_bound_db = 0.0;  ///< when not identifiable by feel: any value below this feels the same
  int model_version = 2;               ///< the perceptual model that decided (PerceptualModel::version)
  PerceptualModel model;               ///< the model the encode used (its version, weighting, display)
  FitMethod fit_method = FitMethod::least_squares;
  /// The input has no texture (zero-mean RMS ≤ no_texture_floor): the
  /// bitstream is a flat surface and Central Pitch / Irregularity are the
  /// defaults, not estimates (EncoderConfig::NoTexture::flag).
  bool no_texture = false;
  double texture_rms = 0.0;  ///< zero-mean RMS of the input amplitude (what no_texture is decided on)
  /// Which fitted values ended at an edge of the search box (docs/encoder.md
  /// §3): such a value is a limit of the box, not an estimate, and makes
  /// irregularity_identifiable false.
  struct AtBound {
    bool central_pitch = false;
    bool irregularity = false;
    [[nodiscard]] bool any() const { return central_pitch || irregularity; }
  } at_bound;
  /// The target the fit matched (felt or centroid; never automatic).
  EncoderConfig::Target target = EncoderConfig::Target::felt;
  /// Share (0 … 1) of the input's power (its zero-mean amplitude, every
  /// frequency) above the felt band's top (PerceptualModel::felt_band_top at
  /// the model's swipe speed): airborne sound, a sensor's resonance, or
  /// texture too fine to be felt at that speed. Reported by every model
  /// version; only version 3 gives that content no weight.
  double beyond_felt_band = 0.0;
  /// Things the user should know about the result, one sentence each
  /// (e.g. an input dominated by content above the felt band: more than
  /// half its power); the CLI prints each as "texel: warning: …".
  std::vector<std::string> warnings;
  int evaluations = 0;
  double seconds = 0.0;
  std::size_t samples = 0;
  Millimetres spacing{0.0};
};

/// Encodes a signal. Throws InvalidArgument for unusable input (too short,
/// constant, non-finite).
EncodeResult encode(const Signal& signal, const EncoderConfig& config);

/// The encode result as JSON text, the one serialisation every front door
/// uses (`texel encode --json`, Python's EncodeResult.to_json; field names in
/// docs/format.md, "Result field names"): estimate, model (version, percepts,
/// distance_jnd), flags, sizes.
std::string to_json(const EncodeResult& result);

// --- transcoder -------------------------------------------------------------
//
// A document or bitstream that already holds Texel parameters becomes a
// bitstream exactly, without estimation: the same parameters at the
// bitstream's resolution, the same seed and options (docs/encoder.md,
// "Transcoding").

struct TranscodeOptions {
  /// Bits per coarse level, 1 … 16. Default: the fewest that store the
  /// profile's per-texel values exactly, else 16.
  std::optional<unsigned> coarse_bits;
  std::optional<std::size_t> max_bytes;  ///< largest bitstream, bytes (FieldError "max_bytes" when over)
};

struct Transcoded {
  Bitstream bitstream;
  std::vector<std::byte> bytes;
  TexelSpec spec;  ///< what the bitstream decodes to
  /// Decoding renders the document's bytes: every fine field is stored to the
  /// bit (so on every device) and the per-texel envelopes and fine strength
  /// are equal on the document's device.
  bool exact = true;
  /// Each value the bitstream could not hold, e.g. "central_pitch_db 8.004 is
  /// stored as 8 (0.01 dB steps)"; empty when exact.
  std::vector<std::string> losses;
};

/// Why `doc` cannot be transcoded (several regions, a reference, a region
/// that is not the whole device), or nothing when it can.
std::optional<std::string> not_transcodable(const Document& doc);
/// Transcodes a one-region Texel document; InvalidArgument when
/// not_transcodable says why not.
Transcoded transcode(const Document& doc, const TranscodeOptions& options = {});
/// Reads and parses a .texel file; anything over 1 MiB is refused before it
/// is read (a bitstream is a few bytes). Throws FormatError / IoError naming the file.
Bitstream read_bitstream(const std::string& path);
/// A bitstream as itself: the canonical bytes (re-encoding is idempotent).
Transcoded transcode(const Bitstream& b);
/// A file that already holds Texel parameters — a bitstream, or a document
/// that not_transcodable accepts (re-targeted to signal.device if given) —
/// transcoded; nothing (and *why_not, if given, says why) for sample data, a
/// document that is not one Texel texture over its device, or options that
/// ask for part of the signal (region, spacing). Throws as the parsers do.
std::optional<Transcoded> transcode_file(const std::string& path, const SignalOptions& signal = {},
                                         const TranscodeOptions& options = {}, std::string* why_not = nullptr);

// --- decoder ----------------------------------------------------------------

/// The document a bitstream stands for on `device`: one region over the whole
/// device. Rendering it gives the decoded map, byte for byte.
Document decode_document(const Bitstream& b, const DeviceProfile& device);

// --- compression report -----------------------------------------------------

/// Size of `bytes` after zstd at its highest level (22, --ultra).
std::size_t zstd_size(std::span<const std::byte> bytes);

}  // namespace texel::codec
