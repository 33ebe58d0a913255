// The designer's numbers as a library API: what Texel Studio's designer page
// shows for a document (the rendered map, its regions, the analysed region's
// texel-frequency histogram over the distribution it was drawn from, its
// spectrum and its encoded size), "match a reference" through the codec, and
// import / export of documents, bitstreams and device files.
//
// Nothing here renders, draws or encodes by itself: the map is
// prepare_surface(doc).render(); the histogram counts the frequencies the
// prepared TexelTexture drew (its PitchDistribution gives the expected
// counts); the spectrum is magnitude_spectrum(); the bytes are from_spec() +
// write_bitstream(); matching and importing signals are codec::encode(). So
// the studio, the CLI and Python see the same numbers (docs/contributing.md §1: "one core,
// many front doors").
//
// Trade-off: a design view is computed whole on every slider move (the tpad
// map, 19,200 samples, takes a few ms); nothing is cached between calls, so
// a view is a pure function of the document and the options.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/codec.hpp"
#include "texel/document.hpp"
#include "texel/grid.hpp"
#include "texel/units.hpp"

namespace texel::studio {

/// A magnitude spectrum reduced to at most `points` log-spaced frequencies
/// (each point the largest magnitude among the bins it stands for, so peaks
/// survive the reduction).
struct SpectrumView {
  std::vector<double> frequency_cpm;  ///< ascending, > 0
  std::vector<double> magnitude_db;   ///< 20·log10(amplitude-calibrated magnitude); −200 for 0
};

/// The analysed region's texel frequencies, binned equally in log frequency.
struct HistogramView {
  std::vector<double> edges_cpm;  ///< counts.size() + 1 ascending edges (cycles/mm)
  std::vector<double> counts;     ///< texels per bin (sums to the texel count)
  /// The distribution the texels were drawn from (truncated or clamped as
  /// the texture's out_of_band says; quantization ignored), integrated over
  /// each bin and scaled to the texel count: what the counts scatter around.
  std::vector<double> expected;
};

struct RegionView {
  std::string name;
  std::string kind;  ///< "texel" | "reference"
  Millimetres start{0.0};
  Millimetres length{0.0};
};

struct DesignOptions {
  /// Region to analyse (index into the document's regions); none = the last
  /// Texel region, or the last region when none is a Texel region.
  std::optional<std::size_t> region;
  std::size_t spectrum_points = 2048;  ///< 16 … 2048
  std::size_t histogram_bins = 0;      ///< 0 = auto (2·n^(1/3), 5 … 80), else ≤ 1000
};

struct DesignView {
  Grid grid;               ///< the device grid (sample i at origin + i·spacing mm)
  std::vector<float> map;  ///< the whole device map, one amplitude in [0, 1] per sample
  std::vector<RegionView> regions;
  std::size_t analysed = 0;  ///< index of the analysed region
  SpectrumView spectrum;     ///< of the analysed region's samples
  // Texel regions only (empty / 0 for a reference region):
  std::size_t texels = 0;
  /// Length at the region's end that no texel covers (mm): with whole texels
  /// only (fill whole_texels), the rest of a region shorter than the next
  /// texel stays flat (26 mm texels on the tpad's 101.76 mm: 23.76 mm).
  double uncovered_mm = 0.0;
  HistogramView histogram;
  std::vector<std::byte> encoded;  ///< the region's .texel bitstream
  std::string encoded_error;       ///< why `encoded` is empty for a Texel region (not representable)
  CyclesPerMm central_pitch;       ///< the Central Pitch in cycles/mm
  CyclesPerMm irregularity;        ///< the Irregularity's dB value in cycles/mm
};

/// Renders and analyses a document. Throws InvalidArgument for a bad region
/// index or option.
DesignView design_view(const Document& doc, const DesignOptions& options = {});

/// The spectrum of `samples` (`spacing` apart) reduced to ≤ `points`
/// log-spaced points (16 … 2048). Throws InvalidArgument for fewer than 4
/// samples.
SpectrumView spectrum_view(std::span<const double> samples, Millimetres spacing, std::size_t points = 2048);

// --- match ------------------------------------------------------------------

struct MatchOptions {
  /// Region whose rendering is encoded (a reference, say).
  std::size_t region = 0;
  /// Region that receives the match; none = the last region other than
  /// `region` (the studies' right half), or `region` itself if it is alone.
  std::optional<std::size_t> into;
  /// The encoder's settings; a flat model.display takes the document's
  /// device's response (in the loop as `texel encode --device` puts it).
  codec::EncoderConfig encoder;
  std::size_t spectrum_points = 2048;
};

struct MatchView {
  codec::EncodeResult result;  ///< spec, bytes, model distance, …
  Document document;           ///< the input with region `into` holding the match
  std::size_t into = 0;
  SpectrumView target;  ///< spectrum of the encoded region
  SpectrumView match;   ///< spectrum of the match as rendered in `into`
};

/// Encodes the rendering of one region with the codec and puts the Texel
/// texture it decodes to into another. Throws InvalidArgument for a bad
/// region index or an input the encoder cannot use.
MatchView match_region(const Document& doc, const MatchOptions& options);

// --- import / export --------------------------------------------------------

enum class ImportKind { document, bitstream, signal };
/// "document" | "bitstream" | "signal".
std::string_view to_string(ImportKind k);
/// From a file name: .texel.json → document, .texel → bitstream,
/// .bin/.npy/.csv/.wav → signal; throws InvalidArgument naming the name.
ImportKind import_kind(std::string_view name);

struct ImportOptions {
  DeviceProfile device = load_device("tpad");  ///< decodes bitstreams, reads .bin, receives encodings
  MmPerSecond swipe_speed{100.0};              ///< for time recordings (.wav, time/value .csv)
  codec::EncoderConfig encoder;                ///< a flat model.display takes `device`'s response
};

struct ImportResult {
  ImportKind kind = ImportKind::document;
  Document document;
  std::optional<codec::EncodeResult> encoded;  ///< signals only
};

/// Reads a file's bytes: `name` picks the format by its extension (see
/// import_kind). Signals go through codec::decode_signal and codec::encode and
/// come back as the decoded document on `options.device`. Throws
/// InvalidArgument / FormatError naming `name` and the problem.
ImportResult import_file(std::string_view name, std::span<const std::byte> bytes, const ImportOptions& options);

enum class ExportFormat { document, bitstream, device, npy, csv, hjif };
std::string_view to_string(ExportFormat f);
/// "document" | "bitstream" | "device" | "npy" | "csv" | "hjif" (MPEG-I Haptics, as `texel export -o x.hjif`);
/// throws InvalidArgument naming `field`.
ExportFormat parse_export_format(std::string_view text, std::string_view field = "as");

struct ExportFile {
  std::string name;  ///< suggested file name ("texture.texel.json", …)
  std::string mime;
  std::string data;  ///< the file's bytes
};

/// document: canonical JSON; bitstream: the .texel of `region` (default the
/// last Texel region); device: the map in the device's sample format (.bin);
/// npy: the map as float64 .npy; csv: position_mm,amplitude. Throws
/// InvalidArgument when `region` is not a Texel region or not representable.
ExportFile export_file(const Document& doc, ExportFormat as, std::optional<std::size_t> region = std::nullopt);

}  // namespace texel::studio
