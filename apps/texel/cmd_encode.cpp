// texel encode: any texture signal -> Texel parameters and a .texel bitstream;
// with --report, a compression table (raw device bytes, zstd -22, bitstream).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/encode2d.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::cli {
namespace {

struct EncodeArgs {
  std::vector<std::string> inputs;
  std::optional<std::string> output;
  SignalArgs input;
  // The encoder's defaults are the library's (EncoderConfig{}, described by visit_options).
  double boundary_mm = codec::EncoderConfig{}.boundary.value();
  double texel_length_mm = codec::EncoderConfig{}.texel_length.value();
  std::uint64_t seed = codec::EncoderConfig{}.seed;
  std::string parameterization = std::string(to_string(codec::EncoderConfig{}.parameterization));
  std::string fit = std::string(codec::to_string(codec::EncoderConfig{}.fit_method));
  int model = codec::EncoderConfig{}.model.version;
  std::optional<double> weight_exponent;    ///< default: the model version's
  std::optional<double> sensitivity_scale;  ///< default: the model version's
  std::string no_texture = std::string(codec::to_string(codec::EncoderConfig{}.no_texture));
  std::string target = std::string(codec::to_string(codec::EncoderConfig{}.target));
  std::string display_response = std::string(codec::to_string(codec::PerceptualModel{}.display_response));
  double drawn_weight = codec::PerceptualModel{}.drawn_weight;
  unsigned coarse_bits = codec::EncoderConfig{}.coarse_bits;
  std::optional<std::size_t> max_bytes = codec::EncoderConfig{}.max_bytes;
  bool json = false;
  bool report = false;
  bool estimate = false;  ///< estimate from samples even when the input holds Texel parameters
  // 2-D inputs (docs/encoder.md "2-D inputs").
  std::optional<double> pitch_mm;
  std::optional<std::string> polarity;
  std::optional<std::string> field;
  int directions = 18;  // codec::Encode2DConfig::directions
};

codec::EncoderConfig config_of(const EncodeArgs& a) {
  codec::EncoderConfig c;
  if (a.input.swipe_speed) c.model.swipe_speed = MmPerSecond(*a.input.swipe_speed);
  c.boundary = Millimetres(a.boundary_mm);
  c.texel_length = Millimetres(a.texel_length_mm);
  c.seed = a.seed;
  c.parameterization = parse_parameterization(a.parameterization, "--parameterization");
  c.fit_method = codec::parse_fit_method(a.fit, "--fit");
  c.model = codec::model_defaults(a.model);
  if (a.input.swipe_speed) c.model.swipe_speed = MmPerSecond(*a.input.swipe_speed);
  if (a.weight_exponent) c.model.weight_exponent = *a.weight_exponent;
  if (a.sensitivity_scale) c.model.sensitivity_scale = *a.sensitivity_scale;
  c.no_texture = codec::parse_no_texture(a.no_texture, "--no-texture");
  c.target = codec::parse_target(a.target, "--target");
  // The display in the model's loop: the --device's frequency response
  // (--display-response device, the default; docs/encoder.md §2).
  c.model.display_response = codec::parse_display_response(a.display_response, "display_response");
  c.model.drawn_weight = a.drawn_weight;
  if (a.input.device) c.model.display = load_device(*a.input.device).response;
  c.coarse_bits = a.coarse_bits;
  c.max_bytes = a.max_bytes;
  return c;
}

/// The library's serialisation (codec::to_json) after what only the front
/// door knows: the input's name, how it was read, the output file.
nlohmann::ordered_json result_json(const std::string& input, const Signal& sig, const codec::EncodeResult& r,
                                   const std::optional<std::string>& output) {
  nlohmann::ordered_json j;
  j["input"] = input;
  j["method"] = "estimated";
  j["source"] = sig.description;
  if (output) j["output"] = *output;
  const nlohmann::ordered_json library = nlohmann::ordered_json::parse(codec::to_json(r));  // kept alive: items() refers to it
  for (const auto& [key, value] : library.items()) j[key] = value;
  return j;
}

void print_summary(const std::string& input, const codec::EncodeResult& r, const std::optional<std::string>& out) {
  const TexelSpec& s = r.spec;
  if (r.no_texture) {
    std::cout << input << ": no texture (variation RMS " << detail::num(r.texture_rms)
              << " <= " << detail::num(codec::no_texture_floor) << "): a flat surface, coarse strength "
              << detail::fixed(s.coarse_strength, 3) << "; " << r.bytes.size() << " bytes"
              << (out ? " in " + *out : std::string()) << "\n";
    return;
  }
  std::cout << input << ": Central Pitch " << detail::fixed(s.central_pitch.value(), 2) << " dB"
            << (r.at_bound.central_pitch ? " (at the search bound)" : "") << ", Irregularity "
            << detail::fixed(s.irregularity.value(), 2) << " dB"
            << (r.at_bound.irregularity       ? " (at the search bound: not identifiable)"
                : r.irregularity_identifiable ? ""
                                              : " (not identifiable: narrower feels the same)")
            << ", texel " << detail::num(s.texel_length.value()) << " mm";
  if (r.coarse || s.coarse_strength > 0 || s.fine_strength < 1)
    std::cout << ", coarse strength " << detail::fixed(s.coarse_strength, 3) << ", fine strength "
              << detail::fixed(s.fine_strength, 3);
  std::cout << "\n  " << r.samples << " samples (" << r.samples * 2 << " bytes as u16) -> " << r.bytes.size() << " bytes"
            << (out ? " in " + *out : std::string()) << "; model " << r.model_version
            << (r.target == codec::EncoderConfig::Target::centroid ? " (centroid target)" : "") << " distance "
            << detail::fixed(r.model_distance, 2) << " JND\n";
}

nlohmann::ordered_json transcoded_json(const std::string& input, const codec::Transcoded& t,
                                       const std::optional<std::string>& output) {
  nlohmann::ordered_json j;
  j["input"] = input;
  j["method"] = "transcoded";
  if (output) j["output"] = *output;
  j["exact"] = t.exact;
  j["losses"] = t.losses;
  const TexelSpec& s = t.spec;
  nlohmann::ordered_json p;
  p["central_pitch_db"] = s.central_pitch.value();
  p["irregularity_db"] = s.irregularity.value();
  p["texel_length_mm"] = s.texel_length.value();
  p["parameterization"] = std::string(to_string(s.parameterization));
  p["seed"] = s.seed;
  p["quantization_db"] = s.quantization_db;
  p["band_max_cpm"] = s.band_max.value();
  p["coarse"] = t.bitstream.coarse.has_value();
  p["coarse_strength"] = s.coarse_strength;
  p["fine_strength"] = s.fine_strength;
  if (t.bitstream.coarse && t.bitstream.coarse->bits > 0) {
    p["coarse_levels"] = t.bitstream.coarse->levels.size();
    p["coarse_bits"] = t.bitstream.coarse->bits;
  }
  j["parameters"] = p;
  j["sizes"] = {{"bitstream_bytes", t.bytes.size()}};
  return j;
}

void print_transcoded(const std::string& input, const codec::Transcoded& t, const std::optional<std::string>& out) {
  const TexelSpec& s = t.spec;
  std::cout << input << ": transcoded " << (t.exact ? "exactly" : "with losses") << ": Central Pitch "
            << detail::num(s.central_pitch.value()) << " dB, Irregularity " << detail::num(s.irregularity.value())
            << " dB, texel " << detail::num(s.texel_length.value()) << " mm, seed " << s.seed;
  if (t.bitstream.coarse)
    std::cout << ", coarse strength " << detail::num(s.coarse_strength) << ", fine strength " << detail::num(s.fine_strength);
  std::cout << "\n  " << t.bytes.size() << " bytes" << (out ? " in " + *out : std::string()) << "\n";
}

/// One row of the compression report.
struct ReportRow {
  std::string name;
  std::size_t samples = 0;
  std::size_t raw = 0;
  std::size_t zstd = 0;
  std::size_t texel = 0;
  std::string params;
};

void run_report(const EncodeArgs& a) {
  const codec::EncoderConfig cfg = config_of(a);
  const SignalOptions lo = signal_options(a.input);
  // The raw size is the map as a device stores it: the given device's format, else u16 (tpad's).
  const SampleFormat format = lo.device ? lo.device->format : SampleFormat::u16le;
  std::vector<ReportRow> rows;
  for (const auto& path : a.inputs) {
    const Signal sig = codec::load_signal(path, lo);
    const codec::EncodeResult r = codec::encode(codec::encoder_signal(sig), cfg);
    ReportRow row;
    row.name = std::filesystem::path(path).filename().string();
    row.samples = sig.samples.size();
    // Raw = the map as the device stores it (.bin files: their own bytes).
    std::vector<std::byte> raw(sig.samples.size() * bytes_per_sample(format));
    if (output_extension(path) == ".bin") {
      const std::string bytes = read_file(path);
      raw.assign(reinterpret_cast<const std::byte*>(bytes.data()),
                 reinterpret_cast<const std::byte*>(bytes.data()) + bytes.size());
    } else {
      encode_samples(format, sig.samples, raw);
    }
    row.raw = raw.size();
    row.zstd = codec::zstd_size(raw);
    row.texel = r.bytes.size();
    std::ostringstream p;
    p << "P " << detail::fixed(r.spec.central_pitch.value(), 2) << " dB, I " << detail::fixed(r.spec.irregularity.value(), 2)
      << " dB";
    if (r.bitstream.coarse)
      p << ", C " << detail::fixed(r.spec.coarse_strength, 2) << ", F " << detail::fixed(r.spec.fine_strength, 2);
    row.params = p.str();
    rows.push_back(row);
  }
  if (a.json) {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const auto& r : rows)
      j.push_back({{"input", r.name},
                   {"samples", r.samples},
                   {"raw_bytes", r.raw},
                   {"zstd_bytes", r.zstd},
                   {"texel_bytes", r.texel},
                   {"estimate", r.params}});
    print_json(j);
    return;
  }
  std::cout << "| texture | raw device bytes | zstd -22 --ultra | .texel bytes | raw / .texel | zstd / .texel | estimate |\n";
  std::cout << "|---|---:|---:|---:|---:|---:|---|\n";
  for (const auto& r : rows) {
    std::cout << "| " << r.name << " | " << r.raw << " | " << r.zstd << " | " << r.texel << " | "
              << detail::fixed(static_cast<double>(r.raw) / static_cast<double>(r.texel), 0) << "× | "
              << detail::fixed(static_cast<double>(r.zstd) / static_cast<double>(r.texel), 0) << "× | " << r.params << " |\n";
  }
}

/// Whether an encode is a 2-D one: a 2-D input (.png, a 2-D .npy, a
/// .scans.json bundle), --pitch, or a .texel.json output.
bool is_2d_encode(const EncodeArgs& a) {
  const std::string& in = a.inputs.at(0);
  return a.pitch_mm || codec::is_2d_input(in) || output_extension(in) == ".scans.json" ||
         (a.output && output_extension(*a.output) == ".texel.json");
}

void print_2d_summary(const std::string& input, const codec::Encode2DResult& r, const std::optional<std::string>& out,
                      const std::optional<std::string>& image) {
  const TexelSpec& s = r.spec;
  const BitmapGeometry& g = *r.document.device.bitmap;
  std::cout << input << ": 2-D " << r.method << " on " << g.width << " × " << g.height << " px of "
            << detail::num(g.pitch.value()) << " mm: ";
  if (r.no_texture) {
    std::cout << "no texture (variation RMS " << detail::num(r.texture_rms) << "): a flat surface, coarse strength "
              << detail::fixed(s.coarse_strength, 3) << "\n";
  } else {
    std::cout << "Central Pitch " << detail::fixed(s.central_pitch.value(), 2) << " dB, Irregularity "
              << detail::fixed(s.irregularity.value(), 2) << " dB"
              << (r.irregularity_identifiable ? ""
                                              : " (not identifiable: a bitmap carries every Irregularity up to " +
                                                    detail::fixed(r.irregularity_bound_db, 2) + " dB the same)")
              << ", texel " << detail::num(s.texel_length.value()) << " mm"
              << (r.texel_length_detected ? " (cell lattice)" : " (not in the map: the setting)") << ", field "
              << to_string(r.field) << ", coarse strength " << detail::fixed(s.coarse_strength, 3) << ", fine strength "
              << detail::fixed(s.fine_strength, 3) << (r.coarse ? ", coarse image" : "") << "\n";
    std::cout << "  anisotropy: " << (r.anisotropic ? "ANISOTROPIC" : "isotropic") << ", Central Pitch spread "
              << detail::fixed(r.central_pitch_spread_db, 2) << " dB over " << r.per_direction.size() << " directions"
              << (r.anisotropic ? " (strongest across " + detail::fixed(r.strongest_direction_deg, 0) + "°)" : std::string())
              << ", Irregularity spread " << detail::fixed(r.irregularity_spread_db, 2) << " dB\n  per direction (P / I dB):";
    for (const auto& d : r.per_direction)
      std::cout << " " << detail::num(d.direction_deg) << "° " << detail::fixed(d.central_pitch_db, 1) << "/"
                << detail::fixed(d.irregularity_db, 1);
    std::cout << "\n";
  }
  std::cout << "  model " << r.model_version << ", " << r.correction_rounds << " design correction rounds (residual "
            << detail::fixed(r.correction_residual_db, 2) << " dB)";
  if (out) std::cout << "; wrote " << *out << (image ? " and " + *image : std::string());
  std::cout << "\n";
}

void run_encode2d(const EncodeArgs& a, const CLI::App& cmd) {
  for (const char* flag : {"--report", "--estimate", "--coarse-bits", "--max-bytes", "--region", "--channel"})
    if (cmd.count(flag)) throw InvalidArgument(std::string(flag) + " does not apply to a 2-D encode");
  const std::string& input = a.inputs.at(0);
  if (a.output && output_extension(*a.output) != ".texel.json")
    throw InvalidArgument("output '" + *a.output + "' must end in .texel.json (a 2-D encode writes a version-4 document)");
  if (a.output) check_writable(*a.output);
  codec::Encode2DConfig cfg;
  cfg.encoder = config_of(a);
  cfg.directions = a.directions;
  if (a.field) cfg.field = parse_field2d(*a.field, "--field");
  std::optional<DeviceProfile> device;
  if (a.input.device) device = load_device(*a.input.device);
  if (device && device->bitmap) cfg.device = device;
  std::optional<std::string> image;
  if (a.output) {
    const std::string stem = a.output->substr(0, a.output->size() - std::string(".texel.json").size());
    image = stem + ".coarse.npy";
    cfg.coarse_image_path = std::filesystem::path(*image).filename().string();
  }
  codec::Raster2DLoadOptions lo;
  if (a.pitch_mm) lo.pitch = Millimetres(*a.pitch_mm);
  lo.device = device;
  if (a.polarity) lo.polarity = parse_bitmap_polarity(*a.polarity, "--polarity");
  const codec::Encode2DResult r = codec::encode_2d_file(input, lo, signal_options(a.input), cfg);
  if (!r.coarse_image) image.reset();
  if (a.output) codec::write_encoding2d(r, *a.output);
  if (a.json) {
    nlohmann::ordered_json j;
    j["input"] = input;
    if (a.output) j["output"] = *a.output;
    if (image) j["coarse_image"] = *image;
    const nlohmann::ordered_json library = nlohmann::ordered_json::parse(codec::to_json(r));
    for (const auto& [key, value] : library.items()) j[key] = value;
    print_json(j);
  } else {
    print_2d_summary(input, r, a.output, image);
  }
}

}  // namespace

void register_encode(CLI::App& app) {
  auto a = std::make_shared<EncodeArgs>();
  auto* cmd = app.add_subcommand("encode", "Encode a texture signal into Texel parameters and a .texel bitstream");
  cmd->add_option("input", a->inputs, std::string(kInputHelp) + "; several with --report")->required();
  cmd->add_option("-o,--output", a->output, "Output bitstream (.texel); without it, only the estimates are printed");
  add_signal_options(*cmd, a->input);  // --swipe-speed also sets the model's temporal frequencies [100]
  const std::string g = "Encoder";
  const codec::EncoderConfig defaults;
  const auto help = [&](std::string_view key) { return option_help(defaults, key); };
  cmd->add_option("--boundary", a->boundary_mm, help("boundary_mm"))->group(g);
  cmd->add_option("--texel-length", a->texel_length_mm, help("texel_length_mm"))->group(g);
  cmd->add_option("--seed", a->seed, help("seed"))->group(g);
  cmd->add_option("--parameterization", a->parameterization, help("parameterization"))->group(g);
  cmd->add_option("--model", a->model, help("model"))->group(g);
  cmd->add_option("--weight-exponent", a->weight_exponent,
                  "Perceptual model: exponent of a component's felt weight [the model version's]")
      ->group(g);
  cmd->add_option("--sensitivity-scale", a->sensitivity_scale,
                  "Perceptual model: share of the threshold curve in the weighting, 0 … 1 [the model version's]")
      ->group(g);
  cmd->add_option("--no-texture", a->no_texture, help("no_texture"))->group(g);
  cmd->add_option("--target", a->target, help("target"))->group(g);
  cmd->add_option("--display-response", a->display_response, help("display_response"))->group(g);
  cmd->add_option("--drawn-weight", a->drawn_weight, help("drawn_weight"))->group(g);
  cmd->add_option("--fit", a->fit, help("fit"))->group(g);
  cmd->add_option("--coarse-bits", a->coarse_bits, help("coarse_bits"))->group(g);
  cmd->add_option("--max-bytes", a->max_bytes, help("max_bytes"))->group(g);
  const std::string g2 = "2-D inputs (a grey .png, a 2-D .npy or a .scans.json bundle -> a version-4 .texel.json)";
  cmd->add_option("--pitch", a->pitch_mm, "Pixel pitch of a 2-D map, mm (or --device with a bitmap); never guessed")->group(g2);
  cmd->add_option("--polarity", a->polarity,
                  "PNG polarity: darker_more_friction (a = level/max) or brighter_more_friction [the device's, else darker]")
      ->group(g2);
  cmd->add_option("--field", a->field,
                  "Field design of the document: spectral | cells | oriented [cells if a cell lattice is found, else spectral]")
      ->group(g2);
  cmd->add_option("--directions", a->directions, "Scan directions over 180° [18]")->group(g2);
  cmd->add_flag("--json", a->json, "Print estimates, model distance and sizes as JSON");
  cmd->add_flag("--estimate", a->estimate,
                "Estimate parameters from the rendered samples even when the input (a document or .texel) holds them; "
                "without it such an input is transcoded exactly");
  cmd->add_flag("--report", a->report,
                "Compression report over the inputs: raw device bytes, zstd -22 --ultra, .texel bytes (Markdown table)");
  cmd->callback([a, cmd] {
    if (a->report) {
      if (a->output) throw InvalidArgument("--report writes no bitstream; drop -o");
      run_report(*a);
      return;
    }
    if (a->inputs.size() != 1) throw InvalidArgument("encode takes one input (several only with --report)");
    if (is_2d_encode(*a)) return run_encode2d(*a, *cmd);
    if (a->output) {
      if (output_extension(*a->output) != ".texel") throw InvalidArgument("output '" + *a->output + "' must end in .texel");
      check_writable(*a->output);
    }
    // A document or bitstream already holds Texel parameters: transcoded
    // exactly unless --estimate asks for estimation from its samples.
    if (!a->estimate) {
      codec::TranscodeOptions to;
      if (cmd->count("--coarse-bits")) to.coarse_bits = a->coarse_bits;
      to.max_bytes = a->max_bytes;
      if (auto t = codec::transcode_file(a->inputs[0], signal_options(a->input), to)) {
        for (const char* flag :
             {"--boundary", "--texel-length", "--seed", "--parameterization", "--fit", "--weight-exponent", "--sensitivity-scale",
              "--display-response", "--drawn-weight", "--model", "--no-texture", "--target"})
          if (cmd->count(flag))
            throw InvalidArgument(std::string(flag) + " applies to estimation; '" + a->inputs[0] +
                                  "' holds Texel parameters and is transcoded with its own (add --estimate to re-estimate it)");
        if (!t->exact)
          for (const auto& loss : t->losses) std::cerr << "texel: warning: not exact: " << loss << "\n";
        if (a->output)
          write_file_atomic(*a->output, std::string_view(reinterpret_cast<const char*>(t->bytes.data()), t->bytes.size()));
        if (a->json)
          print_json(transcoded_json(a->inputs[0], *t, a->output));
        else
          print_transcoded(a->inputs[0], *t, a->output);
        return;
      }
    }
    const codec::EncoderConfig cfg = config_of(*a);
    const Signal sig = load_input(a->inputs[0], a->input);
    const codec::EncodeResult r = codec::encode(codec::encoder_signal(sig), cfg);
    for (const auto& w : r.warnings) std::cerr << "texel: warning: " << w << "\n";
    if (a->output) write_file_atomic(*a->output, std::string_view(reinterpret_cast<const char*>(r.bytes.data()), r.bytes.size()));
    if (a->json)
      print_json(result_json(a->inputs[0], sig, r, a->output));
    else
      print_summary(a->inputs[0], r, a->output);
  });
}

}  // namespace texel::cli
