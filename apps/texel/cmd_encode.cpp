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
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::cli {
namespace {

struct EncodeArgs {
  std::vector<std::string> inputs;
  std::optional<std::string> output;
  SignalArgs input;
  double boundary_mm = 1.0;
  double texel_length_mm = 0.25;
  std::uint64_t seed = 1;
  std::string parameterization = "moments";
  std::string fit = "least-squares";
  double weight_exponent = codec::PerceptualModel{}.weight_exponent;
  double sensitivity_scale = codec::PerceptualModel{}.sensitivity_scale;
  std::string display_response = std::string(codec::to_string(codec::PerceptualModel{}.display_response));
  double drawn_weight = codec::PerceptualModel{}.drawn_weight;
  unsigned coarse_bits = 6;
  std::optional<std::size_t> max_bytes;
  bool json = false;
  bool report = false;
  bool estimate = false;  ///< estimate from samples even when the input holds Texel parameters
};

codec::EncoderConfig config_of(const EncodeArgs& a) {
  codec::EncoderConfig c;
  if (a.input.swipe_speed) c.model.swipe_speed = MmPerSecond(*a.input.swipe_speed);
  c.boundary = Millimetres(a.boundary_mm);
  c.texel_length = Millimetres(a.texel_length_mm);
  c.seed = a.seed;
  c.parameterization = parse_parameterization(a.parameterization, "--parameterization");
  c.fit_method = codec::parse_fit_method(a.fit, "--fit");
  c.model.weight_exponent = a.weight_exponent;
  c.model.sensitivity_scale = a.sensitivity_scale;
  // The display in the model's loop: the --device's frequency response
  // (--display-response device, the default; docs/encoder.md §2).
  c.model.display_response = codec::parse_display_response(a.display_response, "display_response");
  c.model.drawn_weight = a.drawn_weight;
  if (a.input.device) c.model.display = load_device(*a.input.device).response;
  c.coarse_bits = a.coarse_bits;
  c.max_bytes = a.max_bytes;
  return c;
}

nlohmann::ordered_json percept_json(const codec::Percept& p) {
  nlohmann::ordered_json j;
  for (const auto& [name, value] : codec::fields(p)) j[name] = value;
  return j;
}

nlohmann::ordered_json result_json(const std::string& input, const Signal& sig, const codec::EncodeResult& r,
                                   const codec::EncoderConfig& cfg, const std::optional<std::string>& output) {
  nlohmann::ordered_json j;
  j["input"] = input;
  j["method"] = "estimated";
  j["source"] = sig.description;
  if (output) j["output"] = *output;
  j["samples"] = r.samples;
  j["spacing_mm"] = r.spacing.value();
  j["swipe_speed_mm_s"] = cfg.model.swipe_speed.value();
  const TexelSpec& s = r.spec;
  nlohmann::ordered_json e;
  e["central_pitch_db"] = s.central_pitch.value();
  e["irregularity_db"] = s.irregularity.value();
  e["irregularity_identifiable"] = r.irregularity_identifiable;
  if (!r.irregularity_identifiable) e["irregularity_feels_same_below_db"] = r.irregularity_bound_db;
  e["texel_recovered"] = r.texel_recovered;  // the input was recognised as a Texel rendering
  e["texel_length_mm"] = s.texel_length.value();
  e["parameterization"] = std::string(to_string(s.parameterization));
  e["seed"] = s.seed;
  e["band_max_cpm"] = s.band_max.value();
  e["coarse"] = r.coarse;
  e["coarse_strength"] = s.coarse_strength;
  e["fine_strength"] = s.fine_strength;
  if (r.bitstream.coarse && r.bitstream.coarse->bits > 0) {
    e["coarse_levels"] = r.bitstream.coarse->levels.size();
    e["coarse_bits"] = r.bitstream.coarse->bits;
    e["coarse_stride_texels"] = r.bitstream.coarse->stride;
    e["coarse_correlation"] = r.coarse_correlation;
  }
  j["estimate"] = e;
  nlohmann::ordered_json m;
  m["input"] = percept_json(r.input);
  m["decoded"] = percept_json(r.decoded);
  m["distance_jnd"] = r.model_distance;
  m["evaluations"] = r.evaluations;
  m["fit"] = std::string(codec::to_string(cfg.fit_method));
  m["display_response"] = std::string(codec::to_string(cfg.model.display_response));
  if (codec::display_in_loop(cfg.model)) {
    m["display"] = {{"corner_hz", cfg.model.display.corner.value()}, {"order", cfg.model.display.order}};
    m["drawn_weight"] = cfg.model.drawn_weight;
  }
  j["model"] = m;
  nlohmann::ordered_json z;
  z["bitstream_bytes"] = r.bytes.size();
  z["raw_u16_bytes"] = r.samples * 2;
  z["ratio"] = static_cast<double>(r.samples * 2) / static_cast<double>(r.bytes.size());
  j["sizes"] = z;
  j["seconds"] = r.seconds;
  return j;
}

void print_summary(const std::string& input, const codec::EncodeResult& r, const std::optional<std::string>& out) {
  const TexelSpec& s = r.spec;
  std::cout << input << ": Central Pitch " << detail::fixed(s.central_pitch.value(), 2) << " dB, Irregularity "
            << detail::fixed(s.irregularity.value(), 2) << " dB"
            << (r.irregularity_identifiable ? "" : " (not identifiable: narrower feels the same)") << ", texel "
            << detail::num(s.texel_length.value()) << " mm";
  if (r.coarse || s.coarse_strength > 0 || s.fine_strength < 1)
    std::cout << ", coarse strength " << detail::fixed(s.coarse_strength, 3) << ", fine strength "
              << detail::fixed(s.fine_strength, 3);
  std::cout << "\n  " << r.samples << " samples (" << r.samples * 2 << " bytes as u16) -> " << r.bytes.size() << " bytes"
            << (out ? " in " + *out : std::string()) << "; model distance " << detail::fixed(r.model_distance, 2) << " JND\n";
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

}  // namespace

void register_encode(CLI::App& app) {
  auto a = std::make_shared<EncodeArgs>();
  auto* cmd = app.add_subcommand("encode", "Encode a texture signal into Texel parameters and a .texel bitstream");
  cmd->add_option("input", a->inputs, std::string(kInputHelp) + "; several with --report")->required();
  cmd->add_option("-o,--output", a->output, "Output bitstream (.texel); without it, only the estimates are printed");
  add_signal_options(*cmd, a->input);  // --swipe-speed also sets the model's temporal frequencies [100]
  const std::string g = "Encoder";
  cmd->add_option("--boundary", a->boundary_mm, "Fine/coarse boundary, mm [1]")->group(g);
  cmd->add_option("--texel-length", a->texel_length_mm, "Texel length of the encoding, mm [0.25]")->group(g);
  cmd->add_option("--seed", a->seed, "Seed written to the bitstream [1]")->group(g);
  cmd->add_option("--parameterization", a->parameterization, "moments | log [moments]")->group(g);
  cmd->add_option("--weight-exponent", a->weight_exponent,
                  "Perceptual model: exponent of a component's felt weight (1 = amplitude-weighted, the model before) [1.75]")
      ->group(g);
  cmd->add_option("--sensitivity-scale", a->sensitivity_scale,
                  "Perceptual model: share of the threshold curve in the weighting, 0 … 1 (1 = the model before) [0.5]")
      ->group(g);
  cmd->add_option("--display-response", a->display_response,
                  "Perceptual model: device (felt as the --device's frequency response passes it at the swipe speed) or "
                  "flat (the texture as drawn) [device]")
      ->group(g);
  cmd->add_option("--drawn-weight", a->drawn_weight,
                  "Perceptual model: weight of the texture as drawn beside the displayed one in the fit, >= 0 (0 = the "
                  "display alone) [1]")
      ->group(g);
  cmd->add_option("--fit", a->fit, "Search of the perceptual fit: least-squares | simplex (slower) [least-squares]")->group(g);
  cmd->add_option("--coarse-bits", a->coarse_bits, "Bits per coarse level, 1 … 16 [6]")->group(g);
  cmd->add_option("--max-bytes", a->max_bytes, "Bit budget: largest bitstream, bytes (coarse precision and spacing adapt)")
      ->group(g);
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
        for (const char* flag : {"--boundary", "--texel-length", "--seed", "--parameterization", "--fit", "--weight-exponent",
                                 "--sensitivity-scale", "--display-response", "--drawn-weight"})
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
    if (a->output) write_file_atomic(*a->output, std::string_view(reinterpret_cast<const char*>(r.bytes.data()), r.bytes.size()));
    if (a->json)
      print_json(result_json(a->inputs[0], sig, r, cfg, a->output));
    else
      print_summary(a->inputs[0], r, a->output);
  });
}

}  // namespace texel::cli
