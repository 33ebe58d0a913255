// The Texel bitstream (.texel): a Texel texture in a few bytes.
//
// A fine-only texture is 14 bytes (16 with a seed below 2^21): magic, version,
// flags, Central Pitch and Irregularity in 0.01 dB, texel length in µm,
// quantization in 0.1 dB, the upper band edge in 0.01 dB, a varint seed and a
// CRC-8. A coarse profile adds strengths and per-texel levels, predicted from
// their neighbours and Rice-coded with an adaptive parameter (JPEG-LS style).
// docs/format.md, "Bitstream (.texel)", documents every byte.
//
// The fields here are the *quantized* integers the stream carries, so that
// write → parse is the identity; `to_spec` turns them into the TexelSpec the
// renderer consumes, with every double computed by exact IEEE operations
// (n / 100.0 and friends), so a decoded spec and the document written from it
// render to the same bytes everywhere.
//
// Device independence [choice]: the stream records the upper band edge
// explicitly (the encoder writes the analysed grid's Nyquist frequency), so
// the texel draw — which depends on the band through redraws — is the same
// function of position on every device. A device whose Nyquist frequency is
// lower samples it with aliasing; the decoder reports that. The flag
// `band_max_device` keeps the renderer's device-dependent default for users
// who ask for it.
//
// Parsing is for untrusted input: every read is bounds-checked, every count
// is bounded by the bytes present, and every failure is a FormatError naming
// the field, the value and what was allowed (tests/codec/fuzz_bitstream.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "texel/texture.hpp"

namespace texel::codec {

/// First byte of every bitstream ('T').
inline constexpr std::uint8_t bitstream_magic = 0x54;
/// The version this build writes and reads.
inline constexpr std::uint8_t bitstream_version = 1;
/// Largest stored coarse profile (levels); bounds memory on hostile input.
inline constexpr std::uint32_t max_coarse_levels = 1u << 24;

/// The fine texture's fields, as stored.
struct FineFields {
  std::int16_t central_pitch_cdb = 1000;     ///< Central Pitch, 0.01 dB units (10 dB)
  std::int16_t irregularity_cdb = -500;      ///< Irregularity, 0.01 dB units (-5 dB)
  std::uint16_t texel_length_um = 250;       ///< texel length, µm, >= 1 (0.25 mm)
  std::uint8_t quantization_ddb = 0;         ///< frequency quantization, 0.1 dB units, <= 200 (0 = off)
  bool band_max_device = false;              ///< true: band top = the device's Nyquist (device dependent)
  std::int16_t band_max_cdb = 1974;          ///< band top, 0.01 dB (when !band_max_device)
  std::optional<std::int16_t> band_min_cdb;  ///< band bottom, 0.01 dB; none = 0.01 cpm (the default)
  std::uint64_t seed = 1;
  Parameterization parameterization = Parameterization::moments;
  OutOfBand out_of_band = OutOfBand::redraw;
  PhaseMode phase = PhaseMode::continuous;
  Fill fill = Fill::whole_texels;

  bool operator==(const FineFields&) const = default;
};

/// The coarse section: strengths and the envelope profile, as stored.
struct CoarseFields {
  std::uint8_t coarse_strength = 0;  ///< C = n / 255
  std::uint8_t fine_strength = 255;  ///< F = n / 255
  /// Bits per level, 1 … 16; 0 = no profile (constant c = 0, so e = 1 − C).
  std::uint8_t bits = 0;
  /// Predictor for the level residuals: 0 none, 1 previous, 2 linear (2·c[k-1] − c[k-2]).
  std::uint8_t predictor = 1;
  /// Texels per stored level, >= 1: level j sits at the centre of texel j·stride.
  std::uint32_t stride = 1;
  /// Levels in 0 … 2^bits − 1; c = level / (2^bits − 1). At most max_coarse_levels.
  std::vector<std::uint16_t> levels;

  bool operator==(const CoarseFields&) const = default;
};

struct Bitstream {
  FineFields fine;
  std::optional<CoarseFields> coarse;  ///< none = fine only (C = 0, F = 1)

  bool operator==(const Bitstream&) const = default;
};

/// Serializes; throws InvalidArgument if a field is outside what the format allows.
std::vector<std::byte> write_bitstream(const Bitstream& b);
/// Parses and validates (structure, CRC, ranges, and that the texture it
/// describes is renderable). Throws FormatError with a one-line message.
Bitstream parse_bitstream(std::span<const std::byte> bytes);

/// The TexelSpec a bitstream stands for (exact, deterministic doubles).
TexelSpec to_spec(const Bitstream& b);
/// Quantizes a spec to bitstream fields (nearest representable values).
/// A coarse profile is sampled at the centres of the texels of a span
/// `length` long and stored with `bits` bits per level; a constant profile
/// folds into the coarse strength. band_max 0 (the device's Nyquist) is kept
/// as the device-dependent flag. Throws InvalidArgument when a value cannot
/// be represented (e.g. a texel length above 65.535 mm).
Bitstream from_spec(const TexelSpec& spec, Millimetres length, unsigned bits = 8);

/// Size in bytes of the coarse section alone (for budgets and reports).
std::size_t coarse_section_bytes(const CoarseFields& c);

/// CRC-8 (polynomial 0x07, initial value 0, no reflection, no final xor).
std::uint8_t crc8(std::span<const std::byte> bytes);

}  // namespace texel::codec
