// texel swipe: what a finger would feel — a texture document played under a
// simulated swipe or a recorded trace, written as a signal (.wav or .csv),
// optionally plotted (position, output, temporal spectrum).
#include <cmath>
#include <cstring>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "finger_options.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/multichannel.hpp"
#include "texel/multichannel_player.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/sinks.hpp"
#include "texel/swipe_plot.hpp"

namespace texel::cli {
namespace {

struct SwipeArgs {
  std::string document;
  DeviceOptions device;
  TextureOptions texture;
  FingerOptions finger;
  Surface2DOptions surface;
  std::string output;
  std::optional<std::string> plot;
  std::string wav_format = "pcm16";
  std::optional<std::string> playback;
  std::optional<std::size_t> channel;
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
  if (ext != ".wav" && ext != ".csv" && ext != ".npy")
    throw InvalidArgument("output '" + a.output + "' has extension '" + ext + "'; allowed: .wav, .csv, .npy");
  const WavEncoding encoding = parse_wav_format(a.wav_format);
  if (a.plot) plot_format_for_path(*a.plot);
  check_writable(a.output);
  if (a.plot) check_writable(*a.plot);

  Document doc = build_document(a.document, a.device, a.texture);
  if (a.playback || a.channel) {  // the command line's playback replaces the document's
    ChannelPlayback p = playback_of(doc);
    if (a.playback) p.mode = parse_channel_mode(*a.playback, "--playback");
    p.channel = a.channel;
    try {
      validate(p, doc.device.channels());
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("--channel: ") + e.what());
    }
    doc.playback = p;
  }
  const PlayerConfig config = player_config(a.finger, SwipeOptions{}.rate.value(), doc.device.response);
  double duration = SwipeOptions{}.duration.value();
  std::vector<float> positions, y_positions, out;
  double mean_speed = 0, sd_speed = 0, directional = 0, touched = 0;
  const auto frame_count = [&] {
    const double frames_d = std::round(duration * config.rate_hz);
    if (frames_d > 2e9) throw InvalidArgument("--duration × --rate is " + detail::num(frames_d) + " samples; at most 2e9");
    return static_cast<std::size_t>(frames_d);
  };
  const bool two_d = a.surface.active() || doc.surface2d.has_value();
  // Multi-channel (docs/rendering.md): a device with actuators or a document
  // with a playback; a one-channel document takes the one-channel path below,
  // so its bytes are the ones it always had.
  const bool multi = !two_d && (doc.playback.has_value() || doc.device.channels() > 1);
  std::size_t channels = 1;
  if (two_d && doc.playback) throw InvalidArgument("--playback: a 2-D surface plays on one channel");
  if (multi && ext == ".csv") throw InvalidArgument("output '" + a.output + "': a multi-channel swipe writes .wav or .npy");
  if (multi && a.plot) throw InvalidArgument("--plot: draws one channel; a multi-channel swipe has none to choose");
  if (multi) {
    const std::vector<Channel> plan = prepare_channels(doc);
    channels = plan.size();
    const auto trace = finger_trace(a.finger, doc.device.length().value(), duration);
    out = render_trace_channels(plan, config, trace, frame_count(), &positions);
    const SwipeMeasures m = swipe_measures(trace);
    mean_speed = m.mean_speed_mm_s, sd_speed = m.sd_speed_mm_s, directional = m.directional_proportion, touched = m.touched_s;
  } else if (two_d) {  // the 2-D player (issue #26)
    const auto map = player_map_2d(a.surface, doc);
    const auto trace = finger_trace_2d(a.finger, a.surface, duration);
    out = render_trace_2d(*map, config, trace, frame_count(), &positions, &y_positions, 64,
                          parse_path_at_lift(a.surface.path_at_lift, "--path-at-lift"));
    const PathMeasures m = path_measures(trace);
    mean_speed = m.mean_speed_mm_s, sd_speed = m.sd_speed_mm_s, touched = m.touched_s;
  } else {
    const Surface surface = prepare_surface(doc);
    const auto map = PlayerMap::from_surface(surface);
    const auto trace = finger_trace(a.finger, surface.grid().length().value(), duration);
    out = render_trace(*map, config, trace, frame_count(), &positions);
    const SwipeMeasures m = swipe_measures(trace);
    mean_speed = m.mean_speed_mm_s, sd_speed = m.sd_speed_mm_s, directional = m.directional_proportion, touched = m.touched_s;
  }
  const std::size_t frames = out.size() / channels;
  // The spectrum of one channel: the one that plays, or the first (the only one of a one-channel swipe).
  const std::size_t shown = multi ? playback_of(doc).channel.value_or(0) : 0;
  std::vector<float> shown_channel(frames);
  for (std::size_t i = 0; i < frames; ++i) shown_channel[i] = out[i * channels + shown];
  const SignalSpectrum spectrum = signal_spectrum(shown_channel, config.rate_hz);
  const double peak = spectrum.peak_hz(config.mode == OutputMode::amplitude ? 1.0 : 0.0);

  // Prepare every output before writing any, so a failure leaves none.
  std::vector<PendingFile> files;
  if (ext == ".npy") {  // float64, [frames, channels]
    std::string bytes = npy_header(frames, channels);
    const std::size_t header = bytes.size();
    bytes.resize(header + out.size() * 8);
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double v = out[i];
      std::memcpy(bytes.data() + header + i * 8, &v, 8);
    }
    files.push_back({a.output, std::move(bytes)});
  }
  if (ext == ".csv")
    files.push_back(
        {a.output, two_d ? signal_csv(config.rate_hz, positions, y_positions, out) : signal_csv(config.rate_hz, positions, out)});
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
  if (ext == ".wav") write_wav(a.output, out, channels, config.rate_hz, encoding);
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
  j["band_limit"] = std::string(to_string(config.band_limit));
  j["samples"] = frames;
  j["channels"] = channels;
  if (multi) j["playback"] = std::string(to_string(playback_of(doc).mode));
  j["duration_s"] = static_cast<double>(frames) / config.rate_hz;
  j["peak_frequency_hz"] = peak;
  if (multi) j["spectrum_channel"] = shown;
  j["spectrum_bin_hz"] = spectrum.frequency_hz.size() > 1 ? spectrum.frequency_hz[1] : 0.0;
  j["swipe"] = {{"mean_speed_mm_s", mean_speed}, {"sd_speed_mm_s", sd_speed}, {"touched_s", touched}};
  if (two_d)
    j["surface"] = "2d";
  else
    j["swipe"]["directional_proportion"] = directional;
  if (a.json) {
    print_json(j);
  } else {
    std::cout << a.output << ": " << frames << " samples";
    if (multi) std::cout << " × " << channels << " channels (" << to_string(playback_of(doc).mode) << ")";
    std::cout << " at " << detail::num(config.rate_hz) << " Hz ("
              << detail::fixed(static_cast<double>(frames) / config.rate_hz, 3) << " s), " << to_string(config.mode)
              << ", spectrum peak " << detail::fixed(peak, 1) << " Hz"
              << (multi ? " (channel " + std::to_string(shown) + ")" : "") << "\n"
              << "swipe" << (two_d ? " (2-D)" : "") << ": mean speed " << detail::fixed(mean_speed, 2) << " mm/s, SD "
              << detail::fixed(sd_speed, 2) << " mm/s";
    if (!two_d) std::cout << ", directional proportion " << detail::fixed(directional, 3);
    std::cout << "\n";
  }
}

}  // namespace

void register_swipe(CLI::App& app) {
  auto a = std::make_shared<SwipeArgs>();
  auto* cmd = app.add_subcommand("swipe", "Play a texture under a simulated or recorded finger into a signal file (.wav/.csv)");
  cmd->add_option("document", a->document, "Texture document (*.texel.json)")->required();
  cmd->add_option("-o", a->output,
                  "Output signal: .wav (one channel per actuator, interleaved), .npy (float64 [frames, channels]) or .csv "
                  "(time_s,position_mm,output; one channel)")
      ->required();
  cmd->add_option("--playback", a->playback,
                  "On a multi-channel device: sequential (the texture's one chain of texels) or simultaneous (one chain per "
                  "actuator, drawn from the same distribution) [the document's, else sequential]");
  cmd->add_option("--channel", a->channel, "Sequential playback on this one channel (0-based); the others at rest");
  cmd->add_option("--plot", a->plot, "Also draw position, output and its temporal spectrum (.png or .svg)");
  cmd->add_option("--wav-format", a->wav_format, "WAV sample encoding: pcm16, pcm24 or float [pcm16]");
  cmd->add_flag("--json", a->json, "Print the summary as JSON");
  add_player_options(*cmd, a->finger, SwipeOptions{}, a->device, a->texture);
  add_surface2d_options(*cmd, a->surface);
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
