// Shared pieces of the texel command: texture options, output writers and
// the progress line. Commands are thin: parse, call the library, format.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "texel/document.hpp"
#include "texel/signal.hpp"

namespace texel::cli {

/// Options that set or override a Texel texture's parameters.
struct TextureOptions {
  std::optional<double> central_pitch_db;
  std::optional<double> irregularity_db;
  std::optional<double> texel_length_mm;
  std::optional<std::uint64_t> seed;
  std::optional<double> quantization_db;
  std::optional<std::string> phase;
  std::optional<std::string> parameterization;
  std::optional<std::string> out_of_band;
  std::optional<std::string> fill;
  std::optional<double> band_min_cpm;
  std::optional<double> band_max_cpm;
  std::optional<double> coarse_strength;
  std::optional<double> fine_strength;
  std::optional<double> coarse_sine_mm;
  std::optional<double> coarse_phase_deg;
  std::optional<std::string> coarse_profile;
};

/// Options that pick and reshape the device.
struct DeviceOptions {
  std::optional<std::string> device;
  std::optional<double> length_mm;
  std::optional<double> spacing_mm;
};

/// How a command reads its input signal (texel/signal.hpp): one option block
/// for every command that reads one (info, spectrum, encode).
struct SignalArgs {
  std::optional<std::string> device;
  std::optional<double> spacing_mm;
  std::optional<std::string> region;   ///< START:END in mm, or a document region's name or index
  std::optional<double> swipe_speed;   ///< mm/s
  std::optional<std::string> channel;  ///< "mix" or a 0-based channel index
};
void add_signal_options(CLI::App& cmd, SignalArgs& a);
/// Help text of an input-signal argument: the formats load_signal reads.
inline constexpr const char* kInputHelp =
    "Input: .bin (needs --device), .npy (--device or --spacing), .csv (position_mm,amplitude or time_s,value), "
    ".wav (--swipe-speed), .mat, .texel.json, .texel (--device), .hjif (MPEG-I Haptics)";
/// The library options the flags describe (throws InvalidArgument naming the flag).
SignalOptions signal_options(const SignalArgs& a);
/// Reads `path` through the one loader (codec::load_signal: every format, bitstreams too).
Signal load_input(const std::string& path, const SignalArgs& a);

/// The CLI's flag for a library option field ("swipe_speed" -> "--swipe-speed"),
/// the one place the two spellings meet; main() rewrites FieldErrors with it.
std::string flag_of_field(std::string_view field);

void add_texture_options(CLI::App& cmd, TextureOptions& o);
void add_device_options(CLI::App& cmd, DeviceOptions& o);

/// Applies the options to a spec (throws InvalidArgument on bad values).
void apply(const TextureOptions& o, TexelSpec& spec);
/// Resolves the device: the document's (if any), replaced by --device, reshaped by --length/--spacing.
DeviceProfile resolve_device(const DeviceOptions& o, const DeviceProfile* current);

/// Loads DOC or builds a default one, then applies device and texture options.
Document build_document(const std::optional<std::string>& doc_path, const DeviceOptions& d, const TextureOptions& t);

/// Output formats of a rendered surface, picked by the output's extension.
enum class OutputKind { bin, csv, npy, document, png, svg };
/// Throws InvalidArgument naming the extension and the allowed ones.
OutputKind output_kind(const std::string& path);

/// The prepared outputs of one render, written only once all are ready.
struct PendingFile {
  std::string path;
  std::string bytes;
};
/// Writes every pending file atomically; if one fails, removes the ones this
/// call already wrote so a failed command leaves no partial output.
void commit_files(const std::vector<PendingFile>& files);

/// A one-line progress indicator on stderr, only when stderr is a terminal.
class Progress {
 public:
  explicit Progress(std::string label);
  ~Progress();
  void update(double fraction);
  void done();

 private:
  std::string label_;
  bool active_ = false;
  int last_percent_ = -1;
};

/// Creates an output directory (and its parents); throws IoError naming it.
void make_output_directory(const std::string& dir);

/// Commands that write a set of files into a directory for one device (demo, atlas).
struct OutputSetArgs {
  std::string out;
  std::string device = "tpad";
};
void add_output_set_options(CLI::App& cmd, OutputSetArgs& a);
/// Creates the directory and loads the device.
DeviceProfile prepare_output_set(const OutputSetArgs& a);

/// Prints `j` to stdout, indented.
void print_json(const nlohmann::ordered_json& j);

}  // namespace texel::cli
