// texel swipe: what a finger would feel — a texture document played under a
// simulated swipe or a recorded trace, written as a signal (.wav or .csv),
// optionally plotted (position, output, temporal spectrum).
#include <cmath>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "finger_options.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/player.hpp"
#include "texel/sinks.hpp"
#include "texel/swipe_plot.hpp"

namespace texel::cli {
namespace {

struct SwipeArgs {
  std::string document;
  DeviceOptions device;
  TextureOptions texture;
  FingerOptions finger;
  std::string output;
  std::optional<std::string> plot;
  std::string wav_format = "pcm16";
  bool json = false;
};

WavEncoding parse_wav_format(const std::string& s) {
  if (s == "pcm16") return WavEncoding::pcm16;
  if (s == "pcm24") return WavEncoding::pcm24;
  if (s == "float") return WavEncoding::float32;
  throw InvalidArgument("--wav-format is '" + s + "'; allowed: pcm16, pcm24, float");
}

void run(const SwipeArgs& a) {
  const std::string ext = output_extension(a.output);
  if (ext != ".wav" && ext != ".csv")
    throw InvalidArgument("output '" + a.output + "' has extension '" + ext + "'; allowed: .wav, .csv");
  const WavEncoding encoding = parse_wav_format(a.wav_format);
  if (a.plot) plot_format_for_path(*a.plot);
  check_writable(a.output);
  if (a.plot) check_writable(*a.plot);

  const Document doc = build_document(a.document, a.device, a.texture);
  const PlayerConfig config = player_config(a.finger, 48000.0, doc.device.response);
  const Surface surface = prepare_surface(doc);
  const auto map = PlayerMap::from_surface(surface);
  double duration = 2.0;
  const auto trace = finger_trace(a.finger, surface.grid().length().value(), duration);
  const double frames_d = std::round(duration * config.rate_hz);
  if (frames_d > 2e9) throw InvalidArgument("--duration × --rate is " + detail::num(frames_d) + " samples; at most 2e9");
  const auto frames = static_cast<std::size_t>(frames_d);

  std::vector<float> positions;
  const std::vector<float> out = render_trace(*map, config, trace, frames, &positions);
  const SignalSpectrum spectrum = signal_spectrum(out, config.rate_hz);
  const double peak = spectrum.peak_hz(config.mode == OutputMode::amplitude ? 1.0 : 0.0);
  const SwipeMeasures m = swipe_measures(trace);

  // Prepare every output before writing any, so a failure leaves none.
  std::vector<PendingFile> files;
  if (ext == ".csv") files.push_back({a.output, signal_csv(config.rate_hz, positions, out)});
  if (a.plot) {
    SwipePlot p;
    p.title = "Swipe: " + std::string(to_string(config.mode)) + " at " + detail::num(config.rate_hz) + " Hz";
    p.rate = Hertz(config.rate_hz);
    p.positions_mm = positions;
    p.output = out;
    p.output_label = std::string(to_string(config.mode));
    p.frequency_hz = spectrum.frequency_hz;
    p.magnitude = spectrum.magnitude;
    p.marker = Hertz(peak);
    files.push_back({*a.plot, render_figure(swipe_figure(p), plot_format_for_path(*a.plot))});
  }
  if (ext == ".wav") write_wav(a.output, out, config.rate_hz, encoding);
  try {
    commit_files(files);
  } catch (...) {
    if (ext == ".wav") std::remove(a.output.c_str());
    throw;
  }

  nlohmann::ordered_json j;
  j["output"] = a.output;
  if (a.plot) j["plot"] = *a.plot;
  j["mode"] = std::string(to_string(config.mode));
  j["rate_hz"] = config.rate_hz;
  j["samples"] = frames;
  j["duration_s"] = static_cast<double>(frames) / config.rate_hz;
  j["peak_frequency_hz"] = peak;
  j["spectrum_bin_hz"] = spectrum.frequency_hz.size() > 1 ? spectrum.frequency_hz[1] : 0.0;
  j["swipe"] = {{"mean_speed_mm_s", m.mean_speed_mm_s},
                {"sd_speed_mm_s", m.sd_speed_mm_s},
                {"directional_proportion", m.directional_proportion},
                {"touched_s", m.touched_s}};
  if (a.json) {
    print_json(j);
  } else {
    std::cout << a.output << ": " << frames << " samples at " << detail::num(config.rate_hz) << " Hz ("
              << detail::fixed(static_cast<double>(frames) / config.rate_hz, 3) << " s), " << to_string(config.mode)
              << ", spectrum peak " << detail::fixed(peak, 1) << " Hz\n"
              << "swipe: mean speed " << detail::fixed(m.mean_speed_mm_s, 2) << " mm/s, SD " << detail::fixed(m.sd_speed_mm_s, 2)
              << " mm/s, directional proportion " << detail::fixed(m.directional_proportion, 3) << "\n";
  }
}

}  // namespace

void register_swipe(CLI::App& app) {
  auto a = std::make_shared<SwipeArgs>();
  auto* cmd = app.add_subcommand("swipe", "Play a texture under a simulated or recorded finger into a signal file (.wav/.csv)");
  cmd->add_option("document", a->document, "Texture document (*.texel.json)")->required();
  cmd->add_option("-o", a->output, "Output signal: .wav or .csv (time_s,position_mm,output)")->required();
  cmd->add_option("--plot", a->plot, "Also draw position, output and its temporal spectrum (.png or .svg)");
  cmd->add_option("--wav-format", a->wav_format, "WAV sample encoding: pcm16, pcm24 or float [pcm16]");
  cmd->add_flag("--json", a->json, "Print the summary as JSON");
  add_player_options(*cmd, a->finger, a->device, a->texture);
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
