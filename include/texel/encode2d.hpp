// The 2-D encoder (docs/encoder.md, "2-D inputs"): a 2-D texture input — a
// friction bitmap (8/16-bit grey PNG), a height or friction map (.npy 2-D),
// or a bundle of 1-D scans of one surface along several directions — becomes
// a version-4 2-D Texel document (docs/format.md "2-D surfaces") with one
// region covering the map.
//
//  1. Split (as the 1-D encoder's §1, in the plane): the envelope is what
//     changes more slowly than the fine/coarse boundary — the local mean and
//     RMS over a window one boundary wide — turned into a coarse profile
//     c(x, y) and the strengths C and F with the texel_mix rule; a flat
//     envelope is a fine-only texture. The coarse profile is an image stored
//     beside the document (a 2-D .npy the document's "coarse2d" image names).
//  2. Fine part: straight scans of the fine field along many directions,
//     each encoded by the 1-D encoder (codec::encode: the same perceptual
//     model and fit), give a Central Pitch and Irregularity per direction
//     (their spread is the anisotropy); their mean over directions is the
//     radial statistic. The document's parameters are then corrected by
//     analysis-by-synthesis through the 2-D design: candidate 2-D fields are
//     rendered with the library, scanned and encoded the same way, until
//     their scans feel like the input's.
//  3. Texel length: a lattice of cell borders (the `cells` design) is
//     detected and its period taken; a stationary field has no texels and
//     keeps EncoderConfig::texel_length (reported as not detected).
// The pixel pitch is never guessed: it comes from a pitch or a device
// profile's bitmap.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "texel/codec.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/raster2d.hpp"
#include "texel/signal.hpp"
#include "texel/surface2d_spec.hpp"
#include "texel/units.hpp"

namespace texel::codec {

// --- inputs -----------------------------------------------------------------

/// How a 2-D file becomes amplitudes: its pixel pitch and, for PNG, its
/// polarity. One of `pitch` or `device` (with a bitmap) is required.
struct Raster2DLoadOptions {
  std::optional<Millimetres> pitch;  ///< pixel pitch, mm (> 0); overrides the device's (must then agree within 1 %)
  /// The display the map is for: its bitmap's pitch and polarity.
  std::optional<DeviceProfile> device;
  /// PNG polarity (docs/format.md "Device bitmap"): darker_more_friction
  /// reads a = level/max, brighter_more_friction a = 1 − level/max. None:
  /// the device's, else darker_more_friction.
  std::optional<BitmapPolarity> polarity;
};

/// A 2-D input read: the amplitudes a(x, y) in [0, 1] (raster origin 0, the
/// given pitch), with where they came from.
struct Input2D {
  Raster2D map;
  int depth = 0;  ///< PNG bits per pixel (8 or 16); 0 for .npy
  BitmapPolarity polarity = BitmapPolarity::darker_more_friction;
  std::string description;
};

/// Reads a grey 8/16-bit PNG (through the 2-D model's PNG reader) or a 2-D
/// .npy (rows along y; dtypes as texel::parse_npy_array). A map with values
/// outside [0, 1] (a height map) is scaled as the 1-D encoder scales one:
/// a = 0.5 + 0.5·y/max|y| for the zero-mean values y. Throws
/// InvalidArgument (no pitch, a bad option), FormatError / IoError naming the
/// file (colour PNG, 1-D or 3-D array, NaN or infinite values).
Input2D load_input2d(const std::string& path, const Raster2DLoadOptions& options);

/// True for the 2-D inputs load_input2d reads: .png, or a .npy whose header
/// declares two dimensions (only the header is read). A .scans.json is a
/// bundle (load_scan_bundle).
bool is_2d_input(const std::string& path);

/// One 1-D scan of a surface along a direction.
struct Scan1D {
  std::vector<double> amplitude;  ///< in [0, 1] (zero-mean inputs are scaled as the 1-D encoder scales them)
  Millimetres spacing{0.0};       ///< > 0
  double direction_deg = 0.0;     ///< direction of the scan on the surface (0 = +x)
  std::string description;
};

/// Several 1-D scans (maps or recordings) of one surface along different
/// directions (docs/encoder.md "2-D inputs", the `.scans.json` bundle).
struct ScanBundle {
  std::vector<Scan1D> scans;  ///< at least one
  /// The surface the document covers (default: the longest scan, square).
  Millimetres width{0.0}, height{0.0};
  std::string description;
};

/// Reads a bundle file:
///   {"format": "texel-scans", "version": 1,
///    "width_mm": 100, "height_mm": 60,            (optional)
///    "scans": [{"path": "x.npy", "direction_deg": 0}, {"path": "d.csv", "direction_deg": 45}, …]}
/// Each scan is read by texel::load_signal with `signal` (so .npy scans need
/// a spacing or device, recordings a swipe speed); paths are relative to the
/// bundle. Errors name the JSON path (scans[2].direction_deg …).
ScanBundle load_scan_bundle(const std::string& path, const SignalOptions& signal = {});

// --- the encoder ------------------------------------------------------------

struct Encode2DConfig {
  /// The 1-D encoder's settings: perceptual model (version, swipe speed,
  /// display), boundary, texel length (kept when no lattice is detected),
  /// seed, parameterization, target, no-texture rule, fit method.
  EncoderConfig encoder;
  int directions = 18;               ///< scan directions 0°, 180°/n, … (≥ 2)
  std::size_t scan_samples = 16384;  ///< samples per direction (parallel scans joined), ≥ 1024
  /// Analysis-by-synthesis rounds through the 2-D design (0: the mean of
  /// the directions' 1-D encodes is the document's parameters as is).
  int correction_rounds = 1;
  /// The field design of the document; automatic: cells when a lattice of
  /// cell borders is detected, else spectral.
  std::optional<Field2D> field;
  bool detect_lattice = true;  ///< look for a lattice of cell borders (texel length)
  /// The Central Pitch spread over directions (max − min, dB) above which
  /// the input is reported anisotropic [choice] 1.5 dB.
  double anisotropy_threshold_db = 1.5;
  /// Grid of the coarse image (mm; 0 = max(pixel pitch, boundary / 4)).
  Millimetres coarse_pitch{0.0};
  /// The coarse image's path as the document names it (relative to the
  /// document, e.g. "out.coarse.npy"); write_encoding2d writes it there.
  std::string coarse_image_path = "coarse.npy";
  /// The document's device. None: an inline profile "encoded-2d" of the
  /// map's size, pitch, depth and polarity. Given: the map must fit its
  /// bitmap (at the same pitch) and the region covers the map from (0, 0).
  std::optional<DeviceProfile> device;
  int depth = 16;  ///< bitmap depth of the generated device (8 or 16)
  BitmapPolarity polarity = BitmapPolarity::darker_more_friction;
};

/// One direction's scans, encoded by the 1-D encoder.
struct DirectionEncode {
  double direction_deg = 0.0;
  double central_pitch_db = 0.0;  ///< the 1-D encoder's Central Pitch of the scans
  double irregularity_db = 0.0;   ///< its Irregularity
  Percept percept;                ///< the scans' percept under the model
  std::size_t samples = 0;        ///< samples analysed (parallel scans joined)
  int scans = 0;                  ///< parallel scans
};

struct Encode2DResult {
  Document document;  ///< version 4, one region covering the map
  /// The coarse image the document's region names (values in [0, 1], rows
  /// along y), or none when the coarse profile is constant.
  std::optional<Raster2D> coarse_image;
  TexelSpec spec;                     ///< the region's texture (P, I, L, seed, C, F)
  Field2D field = Field2D::spectral;  ///< the region's design
  std::vector<DirectionEncode> per_direction;
  double central_pitch_spread_db = 0.0;  ///< max − min over directions
  double irregularity_spread_db = 0.0;   ///< max − min over directions
  bool anisotropic = false;              ///< central_pitch_spread_db > the threshold
  /// Maps: the principal axis of the fine part's gradient (a grating's wave
  /// vector); bundles: the direction of the highest Central Pitch.
  double strongest_direction_deg = 0.0;
  double mean_central_pitch_db = 0.0;  ///< the directions' mean (before the design correction)
  double mean_irregularity_db = 0.0;
  /// False when the input's scans are no wider than any stationary
  /// isotropic field's (docs/algorithm.md §11.1: a bitmap cannot carry a
  /// narrower Irregularity; the value is then a convention, see docs).
  bool irregularity_identifiable = true;
  /// When not identifiable: every Irregularity up to this (dB, the document's
  /// parameterization) renders the same field; 0 otherwise.
  double irregularity_bound_db = 0.0;
  bool texel_length_detected = false;  ///< a lattice of cell borders gave the texel length
  bool coarse = false;                 ///< a coarse profile was found
  bool no_texture = false;             ///< no variation above no_texture_floor (a flat surface)
  double texture_rms = 0.0;            ///< zero-mean RMS of the amplitude (what no_texture is decided on)
  int model_version = 2;
  EncoderConfig::Target target = EncoderConfig::Target::felt;
  int correction_rounds = 0;            ///< rounds run
  double correction_residual_db = 0.0;  ///< |ΔCentral Pitch| of the last round's candidate scans vs the input's
  std::string method;                   ///< "bitmap" or "scans"
};

/// Encodes a map of amplitudes in [0, 1] (map.pitch is the pixel pitch).
/// Throws InvalidArgument for an empty map, values outside [0, 1] or NaN, a
/// map smaller than 16 × 16, a bad config or a device the map does not fit.
Encode2DResult encode_surface2d(const Raster2D& map, const Encode2DConfig& config = {});

/// Encodes a bundle of 1-D scans: per direction, the 1-D encoder; the
/// document's parameters from their mean through the same design
/// correction; a constant coarse profile (scans carry no 2-D positions), C
/// and F from the scans' 1-D encodes. The document's grid: config.device's
/// bitmap, else the scans' finest spacing over the bundle's width × height.
Encode2DResult encode_scans(const ScanBundle& bundle, const Encode2DConfig& config = {});

/// Writes the document to `document_path` (.texel.json) and the coarse image
/// (if any) beside it under the name its region's "coarse2d" image gives
/// (Encode2DConfig::coarse_image_path), each through a
/// temporary renamed into place; on any failure nothing is left.
void write_encoding2d(const Encode2DResult& result, const std::string& document_path);

/// Encodes a 2-D input file, the one rule every front door follows
/// (`texel encode map.png`, Python encode_2d, C texel_encode_2d_file, MEX
/// texel_encode2d): a `.scans.json` bundle goes to encode_scans (its scans
/// read with `signal`; with `load.pitch` given the document's grid is the
/// scans' own, config.device is ignored), a grey .png or a 2-D .npy to
/// load_input2d with `load` and then encode_surface2d, the generated device
/// taking the PNG's depth and polarity. Throws InvalidArgument naming the
/// file for anything else.
Encode2DResult encode_2d_file(const std::string& path, const Raster2DLoadOptions& load, const SignalOptions& signal,
                              Encode2DConfig config);

/// The result as JSON (parameters, per-direction rows, anisotropy, flags,
/// model), the one serialisation every front door prints.
std::string to_json(const Encode2DResult& result);

}  // namespace texel::codec
