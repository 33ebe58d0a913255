// texel play: a texture document played in real time under a simulated or
// recorded finger, on a sound card (PortAudio), a serial friction display, or
// the `null` backend (no hardware; CI). Shows a live level meter on a
// terminal and reports blocks processed and the worst block time.
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include <unistd.h>

#include "commands.hpp"
#include "common.hpp"
#include "finger_options.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/sinks.hpp"

namespace texel::cli {
namespace {

std::atomic<bool> interrupted{false};
extern "C" void on_sigint(int) { interrupted = true; }

struct PlayArgs {
  std::string document;
  DeviceOptions device;
  TextureOptions texture;
  FingerOptions finger;
  Surface2DOptions surface;
  std::string backend = "null";
  std::size_t block = 64;
  std::string audio_device;
  std::string stream = "position";
  int baud = 921600;
  bool list_devices = false;
  bool json = false;
};

std::string meter(float peak) {
  const double db = peak > 0 ? 20.0 * std::log10(peak) : -120.0;
  const int bars = std::clamp(static_cast<int>((db + 60.0) / 3.0), 0, 20);
  return "[" + std::string(static_cast<std::size_t>(bars), '#') + std::string(static_cast<std::size_t>(20 - bars), ' ') + "] " +
         (db > -100 ? detail::fixed(db, 1) : std::string("-inf")) + " dBFS";
}

// Queues `trace` into `player` up to a time (like a sensor with some
// buffering); returns false once all of it is queued.
template <class P, class Sample>
std::function<bool(double)> feeder(P& player, std::vector<Sample> trace) {
  return [&player, trace = std::move(trace), next = std::size_t{0}](double horizon) mutable {
    while (next < trace.size() && trace[next].t_s <= horizon && player.push(trace[next])) ++next;
    return next < trace.size();
  };
}

void run(const PlayArgs& a) {
  if (a.list_devices) {
    for (const auto& d : audio_output_devices()) std::cout << d << "\n";
    return;
  }
  if (a.document.empty()) throw InvalidArgument("play: a document is required (or --list-devices)");
  if (a.block < 1 || a.block > 8192) throw InvalidArgument("--block is " + std::to_string(a.block) + "; allowed 1 … 8192 frames");
  const Document doc = build_document(a.document, a.device, a.texture);
  const bool two_d = a.surface.active() || doc.surface2d.has_value();
  const std::optional<Surface> surface = two_d ? std::nullopt : std::optional<Surface>(prepare_surface(doc));
  // A 2-D surface has no 1-D map; the backends other than serial position
  // streaming never read it, so they get a one-sample stand-in.
  const auto map = two_d
                       ? std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f})
                       : PlayerMap::from_surface(*surface);

  const BackendChoice choice = parse_backend(a.backend);
  BackendOptions bo;
  bo.block_frames = a.block;
  bo.audio_device = a.audio_device;
  bo.baud = a.baud;
  PlayerConfig config;
  if (choice.kind == BackendChoice::Kind::serial) {
    if (a.stream == "position")
      bo.stream = SerialStream::position;
    else if (a.stream == "drive")
      bo.stream = SerialStream::drive;
    else
      throw InvalidArgument("--stream is '" + a.stream + "'; allowed: position, drive");
    if (two_d && bo.stream == SerialStream::position)
      throw InvalidArgument("--stream is 'position', but a 2-D surface has no 1-D map to upload; use --stream drive");
    FingerOptions f = a.finger;
    if (!f.rate_hz) f.rate_hz = 1000.0;  // one frame per millisecond, like a position sensor
    if (bo.stream == SerialStream::drive && f.output == "vibration")
      f.output = "amplitude";  // a friction display takes amplitudes
    config = player_config(f, 1000.0, doc.device.response);
  } else {
    config = player_config(a.finger, 48000.0, doc.device.response);
  }
  bo.rate_hz = config.rate_hz;
  double duration = 5.0;
  // Everything from the command line is read and checked before the device opens.
  std::unique_ptr<PlayerBase> player;
  std::function<bool(double)> feed_until;  // queues the trace up to a time; false once it is all queued
  if (two_d) {
    auto trace = finger_trace_2d(a.finger, a.surface, duration);
    auto p = std::make_unique<Player2D>(config, player_map_2d(a.surface, doc),
                                        parse_path_at_lift(a.surface.path_at_lift, "--path-at-lift"));
    feed_until = feeder(*p, std::move(trace));
    player = std::move(p);
  } else {
    auto trace = finger_trace(a.finger, surface->grid().length().value(), duration);
    auto p = std::make_unique<Player>(config, PlayerMap::from_surface(*surface));
    feed_until = feeder(*p, std::move(trace));
    player = std::move(p);
  }
  const std::unique_ptr<Backend> backend = make_backend(choice, bo, *map);

  interrupted = false;
  auto old_handler = std::signal(SIGINT, on_sigint);
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  // Feed the finger like a sensor with 50 ms of buffering: samples are queued
  // shortly before their time, so the player interpolates between them.
  auto feed = [&] { feed_until(player->time_s() + 0.05); };
  feed();
  backend->start(*player);
  const auto t0 = std::chrono::steady_clock::now();
  std::string error;
  while (!interrupted && player->time_s() < duration) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    feed();
    player->collect();
    error = backend->error();
    if (!error.empty()) break;
    if (std::chrono::steady_clock::now() - t0 > std::chrono::duration<double>(duration + 5.0)) {
      error = "the backend stopped producing output (" + backend->describe() + ")";
      break;
    }
    if (tty) {
      const BackendStats s = backend->stats();
      std::fprintf(stderr, "\rplay %6.2f/%.2f s  x %7.2f mm %s  %s  blocks %llu  worst %.3f ms ", player->time_s(), duration,
                   s.position_mm, s.touching ? "touch" : "lift ", meter(s.peak).c_str(),
                   static_cast<unsigned long long>(s.blocks), s.worst_block_s * 1e3);
      std::fflush(stderr);
    }
  }
  backend->stop();
  std::signal(SIGINT, old_handler);
  if (tty) std::fprintf(stderr, "\r%*s\r", 110, "");
  if (!error.empty()) throw IoError("play: " + error);

  const BackendStats s = backend->stats();
  const double block_s =
      a.backend.rfind("serial:", 0) == 0 ? 1.0 / config.rate_hz : static_cast<double>(a.block) / config.rate_hz;
  nlohmann::ordered_json j;
  j["backend"] = backend->describe();
  j["played_s"] = player->time_s();
  j["surface"] = two_d ? "2d" : "1d";
  j["scheduling"] = backend->scheduling();
  j["blocks"] = s.blocks;
  j["block_period_ms"] = block_s * 1e3;
  j["worst_block_ms"] = s.worst_block_s * 1e3;
  j["worst_block_fraction"] = s.worst_block_s / block_s;
  j["mean_block_ms"] = s.blocks ? s.total_block_s / static_cast<double>(s.blocks) * 1e3 : 0.0;
  j["underruns"] = s.underruns;
  j["interrupted"] = interrupted.load();
  if (a.json) {
    print_json(j);
  } else {
    std::cout << "played " << detail::fixed(player->time_s(), 3) << " s on " << backend->describe()
              << (two_d ? ", 2-D surface" : "") << "\n"
              << "scheduling: " << backend->scheduling() << "\n"
              << "blocks processed: " << s.blocks << ", worst block " << detail::fixed(s.worst_block_s * 1e3, 4) << " ms ("
              << detail::fixed(100.0 * s.worst_block_s / block_s, 2) << " % of the " << detail::fixed(block_s * 1e3, 3)
              << " ms period), mean " << detail::fixed(j["mean_block_ms"].get<double>(), 4) << " ms, underruns " << s.underruns
              << "\n";
  }
}

}  // namespace

void register_play(CLI::App& app) {
  auto a = std::make_shared<PlayArgs>();
  auto* cmd =
      app.add_subcommand("play", "Play a texture in real time: sound card, serial friction display, or null (no hardware)");
  cmd->add_option("document", a->document, "Texture document (*.texel.json)");
  cmd->add_option("--backend", a->backend, "audio (PortAudio), null (no output device) or serial:PATH [null]");
  cmd->add_option("--block", a->block, "Frames per block (audio, null) [64]");
  cmd->add_option("--audio-device", a->audio_device, "PortAudio output: index or name substring [default output]");
  cmd->add_flag("--list-devices", a->list_devices, "List PortAudio output devices and exit");
  cmd->add_option("--stream", a->stream,
                  "Serial: stream finger positions (the display looks up its map) or drive values [position]");
  cmd->add_option("--baud", a->baud, "Serial baud rate [921600]");
  cmd->add_flag("--json", a->json, "Print the summary as JSON");
  add_player_options(*cmd, a->finger, a->device, a->texture);
  add_surface2d_options(*cmd, a->surface);
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
