// texel play: a texture document played in real time under a simulated or
// recorded finger, on a sound card (PortAudio), a serial friction display, or
// the `null` backend (no hardware; CI). Shows a live level meter on a
// terminal and reports blocks processed and the worst block time.
// --finger serial:PATH takes the finger live from a display's own sensor
// (its FINGER reports, docs/serial-protocol.md), 1-D or 2-D.
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <unistd.h>

#include "commands.hpp"
#include "common.hpp"
#include "finger_options.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/multichannel.hpp"
#include "texel/multichannel_player.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
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
  std::optional<std::string> finger_from;  // serial:PATH — a display's sensor
  std::uint32_t report_interval_us = 1000;
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

// The live finger: a display's FINGER reports, read on their own thread
// (ReportReader) and queued into the player at their place on the player's
// clock.
class LiveFinger {
 public:
  LiveFinger(SerialLink& link, PlayerBase& player, bool two_d) : link_(link), player_(player), two_d_(two_d) {}
  void start() {
    reader_.emplace(link_, [this](std::span<const FingerReport> batch) {
      for (const FingerReport& r : batch) {
        const double t = timeline_.place(r.t_us, player_.time_s());
        const bool queued = two_d_ ? static_cast<Player2D&>(player_).push(FingerSample2D{t, r.x_mm, r.y_mm, r.touch})
                                   : static_cast<Player&>(player_).push(FingerSample{t, r.x_mm, r.touch});
        if (!queued) ++dropped_;
        ++reports_;
      }
    });
  }
  void stop() {
    if (reader_) reader_->stop();
  }
  [[nodiscard]] std::string error() const { return reader_ ? reader_->error() : std::string(); }
  [[nodiscard]] std::uint64_t reports() const { return reports_.load(); }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(); }

 private:
  SerialLink& link_;
  PlayerBase& player_;
  bool two_d_;
  ReportTimeline timeline_;  // the reader thread's
  std::atomic<std::uint64_t> reports_{0}, dropped_{0};
  std::optional<ReportReader> reader_;  // last: stopped first
};

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
  std::optional<std::string> sensor_path;
  if (a.finger_from) {
    if (!a.finger_from->starts_with("serial:") || a.finger_from->size() <= 7)
      throw InvalidArgument("--finger is '" + *a.finger_from + "'; allowed: serial:PATH (a display that reports its finger)");
    sensor_path = a.finger_from->substr(7);
    if (a.finger.trace || a.surface.trace_2d || a.surface.path)
      throw InvalidArgument("--finger serial:PATH takes the finger from the display: give no --trace, --trace-2d or --path");
    if (a.report_interval_us < serial::min_report_interval_us)
      throw InvalidArgument("--report-interval is " + std::to_string(a.report_interval_us) +
                            " µs; allowed >= " + std::to_string(serial::min_report_interval_us));
  }
  BackendOptions bo;
  bo.block_frames = a.block;
  bo.audio_device = a.audio_device;
  bo.baud = a.baud;
  if (surface && choice.kind == BackendChoice::Kind::serial)
    bo.serial_map = std::make_shared<const NativeMap>(native_map(*surface));
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
    config = player_config(a.finger, play_options().rate.value(), doc.device.response);
  }
  bo.rate_hz = config.rate_hz;
  double duration = play_options().duration.value();
  // Everything from the command line is read and checked before the device opens.
  std::unique_ptr<PlayerBase> player;
  std::function<bool(double)> feed_until;  // queues the trace up to a time; false once it is all queued
  // Multi-channel (docs/rendering.md): a device with actuators or a document with a playback.
  const bool multi = !two_d && (doc.playback.has_value() || doc.device.channels() > 1);
  if (multi && sensor_path) throw InvalidArgument("--finger serial:PATH plays one channel; this document has several");
  if (multi) {
    const std::vector<Channel> plan = prepare_channels(doc);
    bo.channels = plan.size();
    auto trace = finger_trace(a.finger, surface->grid().length().value(), duration);
    auto p = std::make_unique<ChannelPlayer>(config, plan, a.block);
    feed_until = feeder(*p, std::move(trace));
    player = std::move(p);
  } else if (sensor_path) {
    // Live: until --duration (0 or absent: until Ctrl-C).
    duration = a.finger.duration_s.value_or(0.0);
    if (!(duration >= 0))
      throw InvalidArgument("--duration is " + detail::num(duration) + "; it must be >= 0 s (0 = until Ctrl-C)");
    if (duration == 0) duration = std::numeric_limits<double>::infinity();
    if (two_d)
      player = std::make_unique<Player2D>(config, player_map_2d(a.surface, doc),
                                          parse_path_at_lift(a.surface.path_at_lift, "--path-at-lift"));
    else
      player = std::make_unique<Player>(config, PlayerMap::from_surface(*surface));
    feed_until = [](double) { return false; };
  } else if (two_d) {
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
  // At rest on every exit — the end, Ctrl-C, SIGTERM, an error or an
  // exception: Backend::stop() ends the stream and puts a serial display at
  // rest (SerialLink::rest: DRIVE 0, SELECT none).
  struct AtRest {
    Backend& backend;
    void operator()() noexcept { backend.stop(); }
    ~AtRest() { (*this)(); }
  } at_rest{*backend};
  // The display that senses the finger: the one the backend drives, or another.
  std::unique_ptr<SerialLink> own_link;
  SerialLink* sensor_link = nullptr;
  if (sensor_path) {
    if (choice.kind == BackendChoice::Kind::serial && choice.serial_path == *sensor_path) {
      sensor_link = backend->serial_link();
    } else {
      own_link = std::make_unique<SerialLink>(*sensor_path, a.baud);
      own_link->hello();
      sensor_link = own_link.get();
    }
    sensor_link->start_reports(a.report_interval_us);
  }
  std::optional<LiveFinger> live;
  if (sensor_link) live.emplace(*sensor_link, *player, two_d);

  interrupted = false;
  auto old_handler = std::signal(SIGINT, on_sigint);
  auto old_term = std::signal(SIGTERM, on_sigint);  // a handler that only sets the flag: the real-time side is untouched
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  // Feed the finger like a sensor with 50 ms of buffering: samples are queued
  // shortly before their time, so the player interpolates between them.
  auto feed = [&] { feed_until(player->time_s() + 0.05); };
  feed();
  backend->start(*player);
  if (live) live->start();
  const auto t0 = std::chrono::steady_clock::now();
  std::string error;
  while (!interrupted && player->time_s() < duration) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    feed();
    player->collect();
    error = backend->error();
    if (error.empty() && live) error = live->error();
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
  if (live) live->stop();
  if (sensor_link && error.empty()) {
    try {
      sensor_link->start_reports(0);  // the display stops reporting
    } catch (const Error&) {
      // Already gone: nothing to stop.
    }
  }
  at_rest();
  std::signal(SIGINT, old_handler);
  std::signal(SIGTERM, old_term);
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
  if (live) {
    j["finger"] = "serial " + *sensor_path;
    j["finger_reports"] = live->reports();
    j["finger_reports_lost"] = sensor_link->reports_lost();
    j["finger_reports_dropped"] = live->dropped();
  }
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
    if (live)
      std::cout << "finger from " << *sensor_path << ": " << live->reports() << " reports, " << sensor_link->reports_lost()
                << " lost on the link\n";
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
  cmd->add_option("--finger", a->finger_from,
                  "Take the finger live from a display's sensor: serial:PATH (its FINGER reports; the same PATH as "
                  "--backend serial:PATH shares the link); plays until --duration or Ctrl-C");
  cmd->add_option("--report-interval", a->report_interval_us, "Finger report interval asked of the display (µs) [1000]");
  cmd->add_flag("--json", a->json, "Print the summary as JSON");
  add_player_options(*cmd, a->finger, play_options(), a->device, a->texture);
  add_surface2d_options(*cmd, a->surface);
  cmd->callback([a] { run(*a); });
}

}  // namespace texel::cli
