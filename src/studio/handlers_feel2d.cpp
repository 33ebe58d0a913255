// The 2-D feel pad's messages (docs/studio.md "The 2-D page"): feel2d.select
// / feel2d.move / feel2d.state drive one Player2D (path-indexed or bitmap);
// feel2d.raster hands the browser's "Hear it" the bitmap at the device's
// resolution; and a participant's 2-D intervals play on the same pad.
//
// The device. The studio's configured backend (`--backend audio|serial:PATH`)
// is one device, and a Player takes one backend, a backend one player
// (player.hpp "Lifetime"). The Presenter (Feel-it strip, participant screens)
// owns it from the start; the 2-D pad borrows it when its finger touches
// (feel2d.move with touch), and the Presenter takes it back when the Feel-it
// strip is touched or a participant's stimulus is shown. A hand-over, under
// the Presenter's feel_mutex: the player that lets go lifts its finger and
// fades to silence (touch ramp, map crossfade) while its backend still runs,
// then its backend is stopped and closed; only then is the device opened
// again for the other (a serial display: HELLO and a blank map again; a
// sound card: a new stream). The Presenter plays on a null backend while the
// pad holds the device, so every 1-D message keeps working. With `--backend
// null` nothing is shared: the pad has its own null backend, as before.
// A serial display that reports its own finger (protocol 1.1) drives the
// pad's player with it while the pad holds the display; the pad shows it
// (docs/studio.md).
#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <span>
#include <thread>

#include <unistd.h>

#include "base64.hpp"
#include "handlers_surface2d.hpp"
#include "messages.hpp"
#include "texel/error.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
#include "texel/sinks.hpp"
#include "texel/studio/surface2d_view.hpp"

namespace texel::studio::detail {

namespace {

constexpr std::size_t max_raster_pixels = std::size_t{1} << 23;  // bitmap / coarse rasters of the 2-D player (32 MiB)
constexpr double path_strip_mm = 10000.0;                        // the path-indexed player's strip (player2d.hpp)
constexpr double finger_lead_s = 0.005;                          // as the 1-D presenter's external finger
constexpr std::size_t max_hear_bytes = std::size_t{4} << 20;     // feel2d.raster: pixel bytes per reply (before base64)
constexpr double handover_s = 0.035;                             // a Presenter's lift ramp and crossfade to silence, played out
constexpr auto handover_limit = std::chrono::milliseconds(250);  // a stalled backend does not hold the hand-over longer
constexpr std::uint32_t report_interval_us = 1000;               // a sensing display's finger reports: 1 kHz
constexpr std::size_t max_trail = 512;                           // display finger positions kept between two feel2d.state

}  // namespace

namespace {

// ------------------------------------------------------------- the device

/// The pad's player's configuration for the configured backend: as the
/// Presenter plays it (serial: 1 kHz drive values; a sound card: 48 kHz
/// vibration), null: 48 kHz amplitude as before.
PlayerConfig player_config(const State& s) {
  PlayerConfig config;
  config.response_handling = s.presenter_options.response_handling;
  config.response_limit_db = s.presenter_options.response_limit_db;
  switch (parse_backend(s.options.backend).kind) {
    case BackendChoice::Kind::serial:
      config.rate_hz = 1000.0;  // presenter.cpp: a friction display takes amplitudes streamed as drive values
      config.mode = OutputMode::amplitude;
      break;
    case BackendChoice::Kind::audio:
      config.rate_hz = s.presenter_options.rate_hz;
      config.mode = OutputMode::vibration;
      break;
    case BackendChoice::Kind::null: break;
  }
  return config;
}

/// Waits (at most handover_limit) until `done()`, looking every millisecond.
template <typename F>
void wait_until(F done) {
  const auto end = Clock::now() + handover_limit;
  while (!done() && Clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

/// A copy of a Feel-it map (Presenter::show takes ownership).
std::unique_ptr<const PlayerMap> copy_of(const PlayerMap& m) {
  return std::make_unique<const PlayerMap>(m.grid(), std::vector<float>(m.values().begin(), m.values().end()), m.response());
}

/// The Presenter on the configured device again, showing the last Feel-it map.
void reopen_presenter(State& s) {
  s.presenter.reset();  // the null stand-in
  try {
    s.presenter = std::make_unique<experiment::Presenter>(s.presenter_options);
    s.device_error.clear();
  } catch (const std::exception& e) {
    s.presenter = std::make_unique<experiment::Presenter>(presenter_options(s.options, true));
    s.device_error = "cannot re-open the device " + s.options.backend + ": " + e.what();
  }
  if (s.feel_map) s.presenter->show(copy_of(*s.feel_map));
}

}  // namespace

void presenter_channels(State& s, std::size_t channels, const std::string& what) {
  if (s.presenter_options.channels == channels && s.presenter->channels() == channels) return;
  device_to_presenter(s);
  experiment::PresenterOptions o = s.presenter_options;
  o.channels = channels;
  std::unique_ptr<experiment::Presenter> next;
  // The device is one: the old Presenter lets go of it before the new one opens it.
  s.presenter->blank();
  s.presenter.reset();
  try {
    next = std::make_unique<experiment::Presenter>(o);
  } catch (const std::exception& e) {
    reopen_presenter(s);  // as it was
    throw Reject{"invalid", what + ": it plays on " + std::to_string(channels) + " channels and the output " + s.options.backend +
                                " cannot open them (" + e.what() + ")"};
  }
  s.presenter = std::move(next);
  s.presenter_options = o;
  s.device_error.clear();
  s.device_description = s.presenter->describe();
  if (s.feel_map) s.presenter->show(copy_of(*s.feel_map));
}

namespace {

/// A serial display with a finger sensor starts reporting it (true); one
/// without says no_sensor (false: the pad's pointer is the finger).
bool asks_for_reports(SerialLink* link) {
  if (!link) return false;
  try {
    link->start_reports(report_interval_us);
    return true;
  } catch (const SerialError& e) {
    if (e.code == serial::ErrorCode::no_sensor || e.code == serial::ErrorCode::unknown_type) return false;
    throw;
  }
}

/// The display's finger reports → the pad's player, until stop_reader().
void start_reader(State& s, Surface2DState& st) {
  st.reader.reset();  // the previous reader, already stopped
  st.timeline = ReportTimeline{};
  st.reader.emplace(*st.backend->serial_link(), [&s, &st](std::span<const FingerReport> batch) {
    // Whoever holds feel_mutex may be stopping this thread: never block on it.
    std::unique_lock lock(s.feel_mutex, std::defer_lock);
    while (!st.reader_stop && !lock.try_lock()) std::this_thread::sleep_for(std::chrono::microseconds(100));
    if (st.reader_stop) return;
    for (const FingerReport& r : batch) {
      const double t = std::max(st.last_t, st.timeline.place(r.t_us, st.player->time_s()));
      if (!st.player->push(FingerSample2D{t, r.x_mm, r.y_mm, r.touch})) continue;  // full: the next report follows
      st.last_t = t;
      ++st.reports;
      st.display_x = r.x_mm;
      st.display_y = r.y_mm;
      st.display_touch = r.touch;
      if (st.trail.size() < max_trail) st.trail.push_back({r.x_mm, r.y_mm, r.touch ? 1.0 : 0.0});
    }
    st.player->collect();
  });
}

/// Caller holds feel_mutex. The pad's player plays on the configured device
/// (see the banner); throws a Reject if the device cannot be opened.
void device_to_pad(State& s, Surface2DState& st) {
  if (!s.device_shared) {
    if (!st.backend) {
      st.backend = make_null_backend(st.player->config().rate_hz, s.presenter_options.block_frames);
      st.backend->start(*st.player);
    }
    return;
  }
  if (s.feel2d_holds_device) return;
  // The Presenter lifts its finger and fades to silence while its backend still runs, then lets go.
  if (s.finger_down) {
    (void)s.presenter->push_finger(s.finger_x, false);
    s.finger_down = false;
  }
  s.presenter->blank();
  const auto blocks = static_cast<std::uint64_t>(std::ceil(handover_s / s.presenter->block_period_s())) + 2;
  const std::uint64_t b0 = s.presenter->stats().blocks;
  wait_until([&] { return s.presenter->stats().blocks >= b0 + blocks || !s.presenter->error().empty(); });
  s.presenter.reset();  // closes the device
  s.presenter = std::make_unique<experiment::Presenter>(presenter_options(s.options, true));
  try {
    const BackendChoice choice = parse_backend(s.options.backend);
    BackendOptions bo;
    bo.rate_hz = st.player->config().rate_hz;
    bo.block_frames = s.presenter_options.block_frames;
    bo.audio_device = s.options.audio_device;
    bo.stream = SerialStream::drive;
    const PlayerMap blank(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f});
    st.backend = make_backend(choice, bo, blank);
    st.display_finger = asks_for_reports(st.backend->serial_link());
    st.backend->start(*st.player);
    if (st.display_finger) start_reader(s, st);
  } catch (const std::exception& e) {
    st.stop_reader();
    st.display_finger = false;
    st.backend.reset();
    reopen_presenter(s);
    throw Reject{"internal", "feel2d.move: cannot open the device " + s.options.backend + " for the 2-D pad: " + e.what()};
  }
  s.feel2d_holds_device = true;
  s.device_error.clear();
}

}  // namespace

void device_to_presenter(State& s) {
  if (!s.feel2d_holds_device) return;
  Surface2DState& st = *s.surface2d;
  if (st.player && st.backend) {
    if (st.display_finger) {
      st.stop_reader();
      try {
        st.backend->serial_link()->start_reports(0);  // the display stops reporting
      } catch (const std::exception&) {
        // Already gone: nothing to stop.
      }
      st.display_finger = false;
      st.finger_down = st.display_touch;
      st.finger_x = st.display_x;
      st.finger_y = st.display_y;
    }
    // The pad's finger lifts (touch ramp) and the queued samples play out, then the backend lets go.
    if (st.finger_down) {
      const double t = std::max(st.last_t, st.player->time_s() + finger_lead_s);
      if (st.player->push(FingerSample2D{t, st.finger_x, st.finger_y, false})) st.last_t = t;
      st.finger_down = false;
    }
    const double until = st.last_t + st.player->config().touch_ramp_s + 0.002;
    wait_until([&] { return st.player->time_s() >= until || !st.backend->error().empty(); });
    st.backend->stop();
    st.backend.reset();  // closes the device
    st.player->collect();
  }
  s.feel2d_holds_device = false;
  reopen_presenter(s);
}

void on_feel2d_select(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::string mode = f.string("mode", 16);
  if (mode != "path" && mode != "bitmap")
    throw Reject{"invalid", job.type + ": mode is " + clipped(mode) + "; allowed: path, bitmap"};
  const auto p = prepared(s, f, job.type);
  const std::size_t region = region_of(f, *p, job.type);
  const BitmapGeometry& g = p->surface->geometry();
  const auto pixels = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
  if (pixels > max_raster_pixels)
    throw Reject{"too_large", job.type + ": the bitmap has " + std::to_string(pixels) + " pixels; the 2-D player takes at most " +
                                  std::to_string(max_raster_pixels)};
  // Rendered outside the player's lock: finger samples keep flowing meanwhile.
  std::unique_ptr<const PlayerMap2D> map;
  try {
    if (mode == "bitmap") {
      // The whole bitmap at the device's resolution, quantised as its file stores it: what is felt never depends on the view.
      map = PlayerMap2D::bitmap(device_raster(*p->surface), p->doc.device.response);
    } else {
      const TexelSpec& fine = p->doc.surface2d->regions[region].texel;
      const double texels = path_strip_mm / fine.texel_length.value();
      if (texels > static_cast<double>(s.options.max_map_samples))
        throw Reject{"too_large", job.type + ": texel_length_mm " + json(fine.texel_length.value()).dump() + " makes " +
                                      json(texels).dump() + " texels along the path's " + json(path_strip_mm).dump() +
                                      " mm strip; allowed: at most " + std::to_string(s.options.max_map_samples)};
      map = PlayerMap2D::path_indexed(fine, Sampling{p->doc.device.grid(), CyclesPerMm(0.0)}, coarse_raster(p->doc, region),
                                      std::nullopt, path_strip_mm, p->doc.device.response);
    }
  } catch (const InvalidArgument& e) {
    throw Reject{"invalid", job.type + ": " + e.what()};
  }
  const Extent2D extent = map->extent();
  auto* st = s.surface2d.get();
  {
    std::lock_guard lock(s.feel_mutex);
    if (!st->player) st->player = std::make_unique<Player2D>(player_config(s));
    if (!s.device_shared) device_to_pad(s, *st);  // null: its own backend at once, as before; a device: at the first touch
    st->player->set_map(std::move(map));
    st->player->collect();
    st->mode = mode;
  }
  ojson r = reply("feel2d.selected", job.id);
  r["mode"] = mode;
  r["region"] = region;
  r["extent_mm"] = {{"x_mm", extent.x_mm}, {"y_mm", extent.y_mm}, {"width_mm", extent.width_mm}, {"height_mm", extent.height_mm}};
  send(c, r);
}

void on_feel2d_move(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::int64_t seq = f.integer("seq", 0, std::int64_t{1} << 53);
  const double x = f.number("x_mm", -max_abs_mm, max_abs_mm);
  const double y = f.number("y_mm", -max_abs_mm, max_abs_mm);
  const bool touch = f.boolean("touch", true);
  auto* st = s.surface2d.get();
  double t = 0.0;
  {
    std::lock_guard lock(s.feel_mutex);
    if (!st->player) throw Reject{"invalid", job.type + ": no 2-D map is playing; select one first (feel2d.select)"};
    if (touch) device_to_pad(s, *st);  // a touch takes the device (see the banner)
    t = std::max(st->last_t, st->player->time_s() + finger_lead_s);
    if (st->display_finger) {  // the display's own finger drives the player; the pad only shows it
      ojson r = reply("feel2d.ack", job.id);
      r["seq"] = seq;
      r["t_s"] = st->last_t;
      send(c, r);
      return;
    }
    if (st->backend) {  // a lift while the Presenter has the device: nothing to play
      if (!st->player->push(FingerSample2D{t, x, y, touch}))
        throw Reject{"busy", "the 2-D player's finger queue is full; send fewer positions"};
      st->last_t = t;
    }
    st->finger_client = c.id;
    st->finger_x = x;
    st->finger_y = y;
    st->finger_down = touch;
    ++st->samples;
    st->player->collect();
  }
  ojson r = reply("feel2d.ack", job.id);
  r["seq"] = seq;
  r["t_s"] = t;
  send(c, r);
}

void on_feel2d_state(State& s, Client& c, const Job& job) {
  auto* st = s.surface2d.get();
  ojson r = reply("feel2d.state", job.id);
  std::lock_guard lock(s.feel_mutex);
  const BackendStats b = st->backend ? st->backend->stats() : BackendStats{};
  r["mode"] = st->mode.empty() ? ojson(nullptr) : ojson(st->mode);
  r["samples"] = st->samples;
  r["x_mm"] = st->player ? ojson(b.position_mm) : ojson(nullptr);
  r["touching"] = b.touching;
  r["blocks"] = b.blocks;
  r["peak"] = b.peak;
  r["underruns"] = b.underruns;
  r["backend"] = st->backend ? st->backend->describe() : std::string();
  // The configured device and whether the pad plays on it now (null: the pad's own null backend, always).
  r["device"] = s.device_description;
  r["holds_device"] = s.device_shared ? s.feel2d_holds_device : st->backend != nullptr;
  std::string error = st->backend ? st->backend->error() : std::string();
  if (error.empty()) error = s.device_error;
  if (error.empty() && st->reader) error = st->reader->error();
  r["error"] = error;
  // Who moves the finger: the pad's pointer, or the display's own sensor (its reports since the last state).
  r["finger"] = st->display_finger ? "display" : "pad";
  if (st->display_finger) {
    r["y_mm"] = st->display_y;
    r["reports"] = st->reports;
    ojson trail = ojson::array();
    for (const auto& p : st->trail) trail.push_back({p[0], p[1], p[2] != 0.0});
    r["trail"] = std::move(trail);
    st->trail.clear();
  }
  send(c, r);
}

void on_feel2d_raster(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const auto p = prepared(s, f, job.type);
  const BitmapGeometry& g = p->surface->geometry();
  const std::size_t bytes_per_pixel = g.depth == 8 ? 1 : 2;
  const std::size_t max_pixels = max_hear_bytes / bytes_per_pixel;
  const auto all = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
  Raster2D raster;
  int x0 = 0, y0 = 0;
  if (all <= max_pixels) {
    raster = device_raster(*p->surface);
  } else {
    // Too large to send whole: the window asked for (the visible part), every device pixel, at most
    // max_view_samples of them about its centre.
    const int cx = static_cast<int>(f.integer("x_px", 0, g.width - 1) + f.integer("width_px", 1, 65535) / 2);
    const int cy = static_cast<int>(f.integer("y_px", 0, g.height - 1) + f.integer("height_px", 1, 65535) / 2);
    const int side = static_cast<int>(std::sqrt(static_cast<double>(std::min(max_pixels, max_view_samples))));
    Surface2DWindow w;
    w.width_px = std::min(side, g.width);
    w.height_px = std::min(side, g.height);
    w.x_px = std::clamp(cx - w.width_px / 2, 0, g.width - w.width_px);
    w.y_px = std::clamp(cy - w.height_px / 2, 0, g.height - w.height_px);
    raster = device_raster(*p->surface, w);
    x0 = w.x_px;
    y0 = w.y_px;
  }
  std::vector<unsigned char> bytes(raster.values.size() * bytes_per_pixel);
  for (std::size_t i = 0; i < raster.values.size(); ++i) {
    const std::uint16_t v = bitmap_pixel(raster.values[i], BitmapPolarity::darker_more_friction, g.depth);
    bytes[i * bytes_per_pixel] = static_cast<unsigned char>(v & 0xff);
    if (bytes_per_pixel == 2) bytes[i * 2 + 1] = static_cast<unsigned char>(v >> 8);
  }
  ojson r = reply("feel2d.raster", job.id);
  r["x_px"] = x0;
  r["y_px"] = y0;
  r["width_px"] = raster.width;
  r["height_px"] = raster.height;
  r["pixel_pitch_mm"] = g.pitch.value();
  r["depth_bits"] = g.depth;
  r["whole"] = all <= max_pixels;
  r["amplitude"] = base64_encode(std::span<const unsigned char>(bytes));
  send(c, r);
}

// ------------------------------------------- a participant's 2-D intervals

void pad_show(State& s, std::unique_ptr<const PlayerMap2D> map) {
  auto* st = s.surface2d.get();
  if (!st->player) st->player = std::make_unique<Player2D>(player_config(s));
  device_to_pad(s, *st);
  st->player->set_map(std::move(map));
  st->player->collect();
  st->mode = "participant";
}

std::optional<double> pad_push(State& s, std::uint64_t client, double t, double x, double y, bool touch) {
  auto* st = s.surface2d.get();
  if (!st->player || st->mode != "participant") return std::nullopt;
  t = std::max(st->last_t, t);
  if (st->backend && !st->display_finger) {
    if (!st->player->push(FingerSample2D{t, x, y, touch})) return std::nullopt;
    st->last_t = t;
  }
  st->finger_client = client;
  st->finger_x = x;
  st->finger_y = y;
  st->finger_down = touch;
  ++st->samples;
  st->player->collect();
  return t;
}

double pad_time_s(const State& s) { return s.surface2d->player ? s.surface2d->player->time_s() : 0.0; }

void pad_blank(State& s) {
  auto* st = s.surface2d.get();
  if (!st->player || st->mode != "participant") return;
  if (st->backend && st->finger_down && !st->display_finger) {
    const double t = std::max(st->last_t, st->player->time_s() + finger_lead_s);
    if (st->player->push(FingerSample2D{t, st->finger_x, st->finger_y, false})) st->last_t = t;
  }
  st->finger_down = false;
  // A one-sample bitmap far off the surface: the finger is off it, so the player fades out (as the presenter blanks).
  st->player->set_map(PlayerMap2D::bitmap(Raster2D{1, 1, Millimetres(1.0), Millimetres(-1e6), Millimetres(-1e6), {0.0f}}));
  st->player->collect();
  st->mode.clear();
}

void lift_finger_2d(State& s, std::uint64_t client) {
  auto* st = s.surface2d.get();
  std::lock_guard lock(s.feel_mutex);
  if (st->player && st->backend && !st->display_finger && st->finger_client == client && st->finger_down) {
    const double t = std::max(st->last_t, st->player->time_s() + finger_lead_s);
    if (st->player->push(FingerSample2D{t, st->finger_x, st->finger_y, false})) st->last_t = t;
  }
  if (st->finger_client == client) st->finger_down = false;
}

}  // namespace texel::studio::detail
