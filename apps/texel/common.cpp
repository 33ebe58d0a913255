#include "common.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <unistd.h>

#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::cli {

void add_signal_options(CLI::App& cmd, SignalArgs& a) {
  const std::string g = "Input signal";
  cmd.add_option("--device", a.device,
                 "Device profile (tpad, tpad-tablet, generic or a .json): format and spacing of a .bin, spacing of a "
                 ".npy, the device a document is re-targeted to and a .texel decoded on")
      ->group(g);
  cmd.add_option("--spacing", a.spacing_mm, "Sample spacing, mm: overrides the device's; must agree with a file's own grid")
      ->group(g);
  cmd.add_option("--region", a.region, "Part of the input: START:END in mm, or a document region's name or index")->group(g);
  cmd.add_option("--swipe-speed", a.swipe_speed,
                 "Finger speed, mm/s: turns a time recording (.wav, time_s,value .csv) into positions")
      ->group(g);
  cmd.add_option("--channel", a.channel, "Channel of a multi-channel recording: 0-based index, or 'mix' [single channel only]")
      ->group(g);
}

SignalOptions signal_options(const SignalArgs& a) {
  SignalOptions o;
  if (a.device) o.device = load_device(*a.device);
  if (a.spacing_mm) o.spacing = Millimetres(*a.spacing_mm);
  if (a.swipe_speed) o.swipe_speed = MmPerSecond(*a.swipe_speed);
  if (a.region) {
    const std::string& r = *a.region;
    const auto colon = r.find(':');
    double lo = 0.0;
    double hi = 0.0;
    if (colon != std::string::npos && parse_csv_number(std::string_view(r).substr(0, colon), lo) &&
        parse_csv_number(std::string_view(r).substr(colon + 1), hi))
      o.region = SignalOptions::Region{"", Millimetres(lo), Millimetres(hi)};
    else if (colon != std::string::npos)
      throw InvalidArgument("--region '" + r + "' must be START:END in mm (e.g. 10:50) or a document region's name");
    else
      o.region = SignalOptions::Region{r, {}, {}};
  }
  if (a.channel) {
    unsigned c = 0;
    const auto [end, ec] = std::from_chars(a.channel->data(), a.channel->data() + a.channel->size(), c);
    if (*a.channel == "mix")
      o.channels = ChannelPolicy::mix;
    else if (ec == std::errc() && end == a.channel->data() + a.channel->size())
      o.channels = ChannelPolicy::select, o.channel = c;
    else
      throw InvalidArgument("--channel is '" + *a.channel + "'; allowed: a channel index (0, 1, ...) or 'mix'");
  }
  return o;
}

Signal load_input(const std::string& path, const SignalArgs& a) { return codec::load_signal(path, signal_options(a)); }

std::string flag_of_field(std::string_view field) {
  static const std::pair<std::string_view, std::string_view> flags[] = {{"device", "--device"},
                                                                        {"spacing", "--spacing"},
                                                                        {"region", "--region"},
                                                                        {"swipe_speed", "--swipe-speed"},
                                                                        {"channel", "--channel"},
                                                                        {"backend", "--backend"},
                                                                        {"boundary", "--boundary"},
                                                                        {"texel_length", "--texel-length"},
                                                                        {"coarse_bits", "--coarse-bits"},
                                                                        {"max_bytes", "--max-bytes"},
                                                                        {"weight_exponent", "--weight-exponent"},
                                                                        {"sensitivity_scale", "--sensitivity-scale"},
                                                                        {"display_response", "--display-response"},
                                                                        {"drawn_weight", "--drawn-weight"},
                                                                        {"model", "--model"},
                                                                        {"tolerance", "--tolerance"},
                                                                        {"date", "--date"},
                                                                        {"width", "--width"}};
  for (const auto& [f, flag] : flags)
    if (f == field) return std::string(flag);
  return std::string(field);  // a field with no flag (max_samples) keeps its library name
}

void add_texture_options(CLI::App& cmd, TextureOptions& o) {
  const std::string g = "Texture";
  // Help and defaults are the library's description (visit_options(TexelSpec)).
  const TexelSpec defaults;
  const auto help = [&](std::string_view key) { return option_help(defaults, key); };
  cmd.add_option("--central-pitch", o.central_pitch_db, help("central_pitch_db"))->group(g);
  cmd.add_option("--irregularity", o.irregularity_db, help("irregularity_db"))->group(g);
  cmd.add_option("--texel-length", o.texel_length_mm, help("texel_length_mm"))->group(g);
  cmd.add_option("--seed", o.seed, help("seed"))->group(g);
  cmd.add_option("--quantization", o.quantization_db, help("quantization_db"))->group(g);
  cmd.add_option("--phase", o.phase, help("phase"))->group(g);
  cmd.add_option("--parameterization", o.parameterization, help("parameterization"))->group(g);
  cmd.add_option("--out-of-band", o.out_of_band, help("out_of_band"))->group(g);
  cmd.add_option("--fill", o.fill, help("fill"))->group(g);
  cmd.add_option("--band-min", o.band_min_cpm, help("band_min_cpm"))->group(g);
  cmd.add_option("--band-max", o.band_max_cpm, help("band_max_cpm"))->group(g);
  cmd.add_option("--coarse-strength", o.coarse_strength, help("coarse_strength"))->group(g);
  cmd.add_option("--fine-strength", o.fine_strength, help("fine_strength"))->group(g);
  cmd.add_option("--coarse-sine", o.coarse_sine_mm, "Coarse profile: sinusoid of this period, mm")->group(g);
  cmd.add_option("--coarse-phase", o.coarse_phase_deg, "Phase of the --coarse-sine profile, degrees [0]")->group(g);
  cmd.add_option("--coarse-profile", o.coarse_profile, "Coarse profile: CSV of position_mm,value rows")->group(g);
}

void add_device_options(CLI::App& cmd, DeviceOptions& o) {
  const std::string g = "Device";
  cmd.add_option("--device", o.device, "Device profile: tpad, tpad-tablet, generic, or a profile .json [tpad]")->group(g);
  cmd.add_option("--length", o.length_mm, "Override the device's active length, mm")->group(g);
  cmd.add_option("--spacing", o.spacing_mm, "Override the device's sample spacing, mm")->group(g);
}

void apply(const TextureOptions& o, TexelSpec& s) {
  if (o.central_pitch_db) s.central_pitch = Decibels(*o.central_pitch_db);
  if (o.irregularity_db) s.irregularity = Decibels(*o.irregularity_db);
  if (o.texel_length_mm) s.texel_length = Millimetres(*o.texel_length_mm);
  if (o.seed) s.seed = *o.seed;
  if (o.quantization_db) s.quantization_db = *o.quantization_db;
  if (o.phase) s.phase = parse_phase_mode(*o.phase, "--phase");
  if (o.parameterization) s.parameterization = parse_parameterization(*o.parameterization, "--parameterization");
  if (o.out_of_band) s.out_of_band = parse_out_of_band(*o.out_of_band, "--out-of-band");
  if (o.fill) s.fill = parse_fill(*o.fill, "--fill");
  if (o.band_min_cpm) s.band_min = CyclesPerMm(*o.band_min_cpm);
  if (o.band_max_cpm) s.band_max = CyclesPerMm(*o.band_max_cpm);
  if (o.coarse_strength) s.coarse_strength = *o.coarse_strength;
  if (o.fine_strength) s.fine_strength = *o.fine_strength;
  if (o.coarse_sine_mm && o.coarse_profile)
    throw InvalidArgument("--coarse-sine and --coarse-profile both given; choose one coarse profile");
  if (o.coarse_phase_deg && !o.coarse_sine_mm) throw InvalidArgument("--coarse-phase needs --coarse-sine");
  if (o.coarse_sine_mm) s.coarse = SineProfile{Millimetres(*o.coarse_sine_mm), o.coarse_phase_deg.value_or(0.0)};
  if (o.coarse_profile) s.coarse = read_profile_csv(*o.coarse_profile);
  // Name the flag, not the document field, when a flag supplied the value.
  const auto check = [](bool given, double v, const char* flag, auto ok, const char* allowed) {
    if (given && !ok(v)) throw InvalidArgument(std::string(flag) + " is " + detail::num(v) + "; " + allowed);
  };
  check(
      o.texel_length_mm.has_value(), o.texel_length_mm.value_or(0), "--texel-length",
      [](double v) { return std::isfinite(v) && v > 0; }, "it must be a finite number of mm > 0");
  check(
      o.central_pitch_db.has_value(), o.central_pitch_db.value_or(0), "--central-pitch",
      [](double v) { return std::isfinite(v); }, "it must be a finite number of dB");
  check(
      o.irregularity_db.has_value(), o.irregularity_db.value_or(0), "--irregularity", [](double v) { return std::isfinite(v); },
      "it must be a finite number of dB");
  check(
      o.coarse_strength.has_value(), o.coarse_strength.value_or(0), "--coarse-strength",
      [](double v) { return v >= 0 && v <= 1; }, "allowed: 0 … 1");
  check(
      o.fine_strength.has_value(), o.fine_strength.value_or(0), "--fine-strength", [](double v) { return v >= 0 && v <= 1; },
      "allowed: 0 … 1");
  check(
      o.quantization_db.has_value(), o.quantization_db.value_or(0), "--quantization", [](double v) { return v >= 0 && v <= 20; },
      "allowed: 0 (off) … 20 dB");
  check(
      o.coarse_sine_mm.has_value(), o.coarse_sine_mm.value_or(0), "--coarse-sine",
      [](double v) { return std::isfinite(v) && v > 0; }, "it must be a finite period in mm > 0");
  validate(s);
}

DeviceProfile resolve_device(const DeviceOptions& o, const DeviceProfile* current) {
  DeviceProfile d = o.device ? load_device(*o.device) : (current ? *current : load_device("tpad"));
  if (o.length_mm && !(std::isfinite(*o.length_mm) && *o.length_mm > 0))
    throw InvalidArgument("--length is " + detail::num(*o.length_mm) + "; it must be a finite number of mm > 0");
  if (o.spacing_mm && !(std::isfinite(*o.spacing_mm) && *o.spacing_mm > 0))
    throw InvalidArgument("--spacing is " + detail::num(*o.spacing_mm) + "; it must be a finite number of mm > 0");
  return with_grid(std::move(d), millimetres(o.length_mm), millimetres(o.spacing_mm));
}

Document build_document(const std::optional<std::string>& doc_path, const DeviceOptions& d, const TextureOptions& t) {
  Document doc;
  if (doc_path) {
    doc = load_document(*doc_path);
    if (d.device || d.length_mm || d.spacing_mm) {
      doc.device = resolve_device(d, &doc.device);
      doc.device_inline = false;
    }
  } else {
    doc = make_document(resolve_device(d, nullptr), TexelSpec{});
  }
  for (auto& r : doc.regions) apply(t, r.texel);
  return doc;
}

OutputKind output_kind(const std::string& path) {
  const std::string ext = output_extension(path);
  if (ext == ".bin") return OutputKind::bin;
  if (ext == ".csv") return OutputKind::csv;
  if (ext == ".npy") return OutputKind::npy;
  if (ext == ".texel.json") return OutputKind::document;
  if (ext == ".png") return OutputKind::png;
  if (ext == ".svg") return OutputKind::svg;
  throw InvalidArgument("output '" + path + "' has extension '" + ext +
                        "'; allowed: .bin (device native), .csv, .npy, .mat, .texel.json, .png, .svg");
}

void commit_files(const std::vector<PendingFile>& files) {
  for (const auto& f : files) check_writable(f.path);
  std::vector<std::string> written;
  try {
    for (const auto& f : files) {
      write_file_atomic(f.path, f.bytes);
      written.push_back(f.path);
    }
  } catch (...) {
    for (const auto& p : written) std::remove(p.c_str());
    throw;
  }
}

Progress::Progress(std::string label) : label_(std::move(label)), active_(::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() { done(); }

void Progress::update(double fraction) {
  if (!active_) return;
  const int percent = static_cast<int>(fraction * 100.0);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  std::fprintf(stderr, "\r%s %3d%%", label_.c_str(), percent);
  std::fflush(stderr);
}

void Progress::done() {
  if (active_ && last_percent_ >= 0) {
    std::fprintf(stderr, "\r%*s\r", static_cast<int>(label_.size() + 6), "");
    std::fflush(stderr);
  }
  active_ = false;
}

void make_output_directory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError("cannot create '" + dir + "': " + ec.message());
}

void add_output_set_options(CLI::App& cmd, OutputSetArgs& a) {
  cmd.add_option("--out", a.out, "Output directory [" + a.out + "]");
  cmd.add_option("--device", a.device, "Device profile [tpad]");
}

DeviceProfile prepare_output_set(const OutputSetArgs& a) {
  make_output_directory(a.out);
  return load_device(a.device);
}

void print_json(const nlohmann::ordered_json& j) { std::cout << j.dump(2) << "\n"; }

}  // namespace texel::cli
