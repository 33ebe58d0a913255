// Stimulus presentation through the player backends (presenter.hpp).
#include "texel/experiment/presenter.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <thread>

#include "texel/detail/format.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/surface_maps.hpp"
#include "texel/multichannel.hpp"
#include "texel/multichannel_player.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
#include "texel/surface.hpp"
#include "texel/surface2d.hpp"
#include "texel/texture.hpp"

namespace texel::experiment {
namespace {

// The simulated finger: to and fro over [a, b] at constant speed (a triangle
// wave), touching throughout. Turns are sharp; the player's interpolation
// and the vibration filters smooth them.
double finger_x(double t, double speed, double a, double b) {
  const double span = b - a;
  const double period = 2.0 * span / speed;
  const double phase = std::fmod(t, period);
  return phase < period / 2 ? a + speed * phase : b - speed * (phase - period / 2);
}

// A document plays on a presenter of as many channels as its device has
// actuators, or of any number if it has one (presenter.hpp). Refused in one
// line naming the device, its actuators and the fix.
void check_channels(const Document& doc, std::size_t here) {
  const std::size_t n = doc.device.channels();
  if (n == here || n == 1) return;
  throw InvalidArgument("the stimulus's device '" + doc.device.name + "' has " + std::to_string(n) +
                        " actuators; this presenter plays " + std::to_string(here) + (here == 1 ? " channel" : " channels") +
                        ": open it with channels " + std::to_string(n) +
                        " (PresenterOptions::channels; the front ends take it from the protocol's device: "
                        "presentation_channels)");
}

// The one map a one-channel display plays of `doc`: the document's own
// surface, or, for a simultaneous document of one actuator, that actuator's
// chain (its channel seed; the base seed's chain is none of its channels).
std::shared_ptr<const Surface> one_channel_surface(const Document& doc) {
  if (doc.playback && doc.playback->mode == ChannelMode::simultaneous) return prepare_channels(doc).front().surface;
  return std::make_shared<const Surface>(prepare_surface(doc));
}

constexpr double finger_rate_hz = 1000.0;  // like a position sensor
constexpr double finger_lead_s = 0.05;     // samples queued ahead of the player

}  // namespace

// ------------------------------------------------------------- 2-D display

// The participant's finger on a 2-D display: the display's FINGER reports,
// read on their own thread, queued into the Player2D at their place on the
// player's clock and summarised per interval.
struct Presenter::Display2D {
  explicit Display2D(const PlayerConfig& config, const StrokeRules& r) : player(config), rules(r) {}
  ~Display2D() { stop(); }

  void start(SerialLink& l) {
    link = &l;
    reader.emplace(l, [this](std::span<const FingerReport> batch) {
      std::lock_guard<std::mutex> lock(mutex);
      for (const FingerReport& r : batch) {
        const double t = timeline.place(r.t_us, player.time_s());
        if (!player.push(FingerSample2D{t, r.x_mm, r.y_mm, r.touch})) ++dropped;
        ++reports;
        last_t = clock.seconds(r.t_us);
        if (!current.empty()) recorders.at(current).add(last_t, r.x_mm, r.y_mm, r.touch);
      }
    });
  }
  void stop() {
    if (reader) reader->stop();
    maps.stop();
  }
  [[nodiscard]] bool running() const { return reader && !reader->stopping(); }
  [[nodiscard]] std::string error() const { return reader ? reader->error() : std::string(); }

  // Stops recording into the current interval (its stroke in progress ends).
  void leave() {
    std::lock_guard<std::mutex> lock(mutex);
    if (!current.empty()) recorders.at(current).add(last_t, 0.0, 0.0, false);
    current.clear();
  }
  void enter(const std::string& label) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!current.empty()) recorders.at(current).add(last_t, 0.0, 0.0, false);
    recorders.try_emplace(label, rules);
    current = label;
  }

  SurfaceMaps maps;  // stopped in stop(), before the player goes
  Player2D player;
  StrokeRules rules;
  SerialLink* link = nullptr;
  std::unique_ptr<SerialLink> own_link;
  ReportTimeline timeline;   // the reader's
  ReportClock clock;         // the reader's
  mutable std::mutex mutex;  // guards what follows (the reader thread writes it)
  std::map<std::string, StrokeRecorder> recorders;
  std::string current;  // the interval being recorded
  double last_t = 0.0;
  std::uint64_t reports = 0, dropped = 0;
  std::optional<ReportReader> reader;  // last: stopped first
};

// --------------------------------------------------------- 1-D serial display

// A 1-D serial display with a finger sensor: its reports (read on the
// control thread by pump() in display-plays, where requests and reports
// share the thread, or on their own thread in host-streams, where the
// player takes them) become the trial's finger trace; in display-plays the
// display's slots hold the trial's stimuli.
struct Presenter::Display1D {
  std::unique_ptr<SerialLink> own_link;  // FingerSource::sensor: the sensor's own link (the backend has another)
  SerialLink* link = nullptr;
  DisplayInfo info;
  bool sensor = false;
  std::uint32_t report_interval_us = 1000;
  ReportClock clock;        // the display's t_us unwrapped (the trace's time)
  ReportTimeline timeline;  // host-streams: the reports on the player's clock

  // display-plays: which stimulus each slot holds (its document), and when it was last felt.
  struct Slot {
    std::string document;
    std::uint64_t used = 0;
  };
  std::vector<Slot> slots;
  int selected = -1;
  std::uint64_t tick = 0;
  // Rendered maps (u16 samples), most recent first: a reference recurs.
  struct Rendered {
    std::string document;
    std::vector<std::uint16_t> samples;
    std::uint32_t spacing_nm = 0;
    std::int32_t origin_nm = 0;
  };
  std::list<Rendered> rendered;
  UploadCounts uploads;

  mutable std::mutex mutex;  // guards what follows (host-streams: the reader thread writes it)
  bool recording = false;
  std::vector<FingerSample> trace;
  std::uint64_t reports = 0, dropped = 0;
  double first_s = 0.0;
  std::string error;
  std::optional<ReportReader> reader;  // host-streams only; last: stopped first

  // display-plays: nothing streams, so no stream watchdog covers the map the
  // display plays under the finger. A display of revision 1.2 has its host
  // watchdog armed (host_watchdog_ms) and fed from a thread of its own every
  // keepalive_ms, whatever the control thread is doing (rendering, an
  // upload, waiting for a key): when this host dies (kill -9) or hangs, the
  // display rests by itself within host_watchdog_ms. Re-armed at every
  // trial (a display that timed out disarms itself).
  static constexpr std::uint32_t host_watchdog_ms = 200;
  static constexpr auto keepalive_every = std::chrono::milliseconds(40);
  bool host_watchdog = false;  // the display took HOST_WATCHDOG
  std::mutex keepalive_mutex;
  std::condition_variable_any keepalive_wake;
  std::jthread keepalive;  // stopped before the link is rested or goes

  void arm_host_watchdog() {
    host_watchdog = link->arm_host_watchdog(host_watchdog_ms);
    if (!host_watchdog || keepalive.joinable()) return;
    keepalive = std::jthread([this](std::stop_token stop) {
      std::unique_lock lock(keepalive_mutex);
      while (!stop.stop_requested()) {
        try {
          link->keepalive();
        } catch (const std::exception&) {
          return;  // the link is gone: the display's watchdog rests it
        }
        keepalive_wake.wait_for(lock, stop, keepalive_every, [] { return false; });
      }
    });
  }
  void stop_keepalive() {
    if (!keepalive.joinable()) return;
    keepalive.request_stop();
    keepalive.join();
  }

  void record(const FingerReport& r) {  // under mutex
    ++reports;
    // The display's own clock, unwrapped: its t_us at the first report plus the time since.
    if (reports == 1) first_s = static_cast<double>(r.t_us) * 1e-6;
    const double t = first_s + clock.seconds(r.t_us);
    if (recording) trace.push_back(FingerSample{t, r.x_mm, r.touch});
  }

  // display-plays: drains the reports that arrived (control thread).
  void drain() {
    std::array<FingerReport, 256> buf;
    for (;;) {
      const std::size_t n = link->read_reports(buf, 0);
      std::lock_guard<std::mutex> lock(mutex);
      for (std::size_t i = 0; i < n; ++i) record(buf[i]);
      if (n < buf.size()) return;
    }
  }

  const Rendered& render(const std::string& document_json) {
    auto it = std::find_if(rendered.begin(), rendered.end(), [&](const Rendered& r) { return r.document == document_json; });
    if (it != rendered.end()) {
      rendered.splice(rendered.begin(), rendered, it);
      return rendered.front();
    }
    // texel render's bytes: the document's surface encoded as u16le (round(a·65535)).
    const Document doc = parse_document(document_json, "stimulus");
    check_channels(doc, 1);  // a serial display is one channel
    const std::shared_ptr<const Surface> held = one_channel_surface(doc);
    const Surface& surface = *held;
    const Grid& g = surface.grid();
    if (static_cast<std::uint64_t>(g.count) > info.max_samples)
      throw InvalidArgument("a stimulus map has " + std::to_string(g.count) + " samples; the display '" + info.name +
                            "' holds at most " + std::to_string(info.max_samples) +
                            " (its HELLO): use a device profile the display can hold, or --mode host-streams");
    const std::vector<std::byte> bytes = surface.render_native(SampleFormat::u16le);
    Rendered r;
    r.document = document_json;
    r.samples.resize(bytes.size() / 2);
    for (std::size_t i = 0; i < r.samples.size(); ++i)
      r.samples[i] = static_cast<std::uint16_t>(std::to_integer<unsigned>(bytes[2 * i]) |
                                                (std::to_integer<unsigned>(bytes[2 * i + 1]) << 8));
    r.spacing_nm = static_cast<std::uint32_t>(std::lround(g.spacing.value() * 1e6));
    r.origin_nm = static_cast<std::int32_t>(std::lround(g.origin.value() * 1e6));
    rendered.push_front(std::move(r));
    if (rendered.size() > 8) rendered.pop_back();
    return rendered.front();
  }

  // The slot holding `document_json`, uploading it over the least recently
  // felt slot that is not playing (or, with one slot, after SELECT none).
  int hold(const std::string& document_json, bool at_switch) {
    for (std::size_t k = 0; k < slots.size(); ++k)
      if (slots[k].document == document_json) {
        slots[k].used = ++tick;
        return static_cast<int>(k);
      }
    const Rendered& r = render(document_json);
    int victim = -1;
    for (std::size_t k = 0; k < slots.size(); ++k)
      if (static_cast<int>(k) != selected && (victim < 0 || slots[k].used < slots[static_cast<std::size_t>(victim)].used))
        victim = static_cast<int>(k);
    if (victim < 0) {  // one slot, playing: rest while it is replaced
      select(-1);
      victim = 0;
    }
    const auto t0 = std::chrono::steady_clock::now();
    slots[static_cast<std::size_t>(victim)].document.clear();  // a failed upload leaves the slot unknown
    link->upload_raw(static_cast<std::uint8_t>(victim), r.samples, r.spacing_nm, r.origin_nm);
    uploads.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++uploads.uploads;
    if (at_switch) ++uploads.at_switch;
    slots[static_cast<std::size_t>(victim)] = Slot{document_json, ++tick};
    return victim;
  }

  void select(int slot) {
    if (slot == selected) return;
    link->select(slot < 0 ? serial::no_map : static_cast<std::uint8_t>(slot));
    selected = slot;
  }
};

std::size_t presentation_channels(std::string_view device) { return load_device(device).channels(); }

std::size_t presentation_channels(const Protocol& protocol) { return presentation_channels(protocol.device); }

Presenter::Presenter(const PresenterOptions& options) : Presenter(options, nullptr) {}

Presenter::Presenter(const PresenterOptions& options, std::unique_ptr<Backend> given) : options_(options) {
  if (!(options_.channels >= 1 && options_.channels <= max_actuators))
    throw InvalidArgument("channels is " + std::to_string(options_.channels) + "; allowed: 1 … " + std::to_string(max_actuators) +
                          " (one per actuator of the display)");
  if (!(options_.swipe_speed_mm_s > 0 && options_.swipe_speed_mm_s <= 10000))
    throw InvalidArgument("swipe speed is " + std::to_string(options_.swipe_speed_mm_s) + "; allowed: 0 … 10000 mm/s");
  if (!(options_.finger_lead_s >= 0 && options_.finger_lead_s <= 0.1))
    throw InvalidArgument("finger lead is " + std::to_string(options_.finger_lead_s) + " s; allowed: 0 … 0.1 s");
  // A given backend is driven like a sound card (null's kind: no serial link of ours).
  const BackendChoice choice = given ? BackendChoice{} : parse_backend(options_.backend);
  if (given && given->serial_link())
    throw InvalidArgument("a given backend is a serial display (" + given->describe() +
                          "); give it by name, backend = serial:PATH");
  if (given && given->channels() != options_.channels)
    throw InvalidArgument("the given backend (" + given->describe() + ") has " + std::to_string(given->channels()) +
                          " channel(s); the presenter plays " + std::to_string(options_.channels) + " (channels)");
  const std::string channels_text = std::to_string(options_.channels);
  if (options_.channels > 1 && choice.kind == BackendChoice::Kind::serial)
    throw InvalidArgument("channels is " + channels_text + ", but backend " + options_.backend +
                          " is a serial display: the serial protocol drives one plate (one channel); play a display of " +
                          channels_text + " actuators on backend audio (or null)");
  if (options_.channels > 1 && options_.finger == FingerSource::display)
    throw InvalidArgument("channels is " + channels_text +
                          ", but the participant strokes a 2-D display (finger display), which plays one channel; give "
                          "channels 1");
  std::string sensor_path;
  if (options_.finger == FingerSource::display) {
    validate(options_.stroke_rules);
    if (!options_.finger_display.starts_with("serial:") || options_.finger_display.size() <= 7)
      throw InvalidArgument("finger display is '" + options_.finger_display +
                            "'; allowed: serial:PATH (a 2-D display that reports its finger)");
    sensor_path = options_.finger_display.substr(7);
    if (options_.report_interval_us < serial::min_report_interval_us)
      throw InvalidArgument("report interval is " + std::to_string(options_.report_interval_us) +
                            " µs; allowed >= " + std::to_string(serial::min_report_interval_us));
  }
  PlayerConfig config;
  BackendOptions bo;
  if (choice.kind == BackendChoice::Kind::serial) {
    // A friction display takes amplitudes: in host-streams and passive the
    // player's output is streamed as drive values (display-plays streams
    // nothing: the display plays its own copy of the map).
    config.rate_hz = 1000.0;
    config.mode = OutputMode::amplitude;
    period_s_ = 1.0 / config.rate_hz;
    bo.stream = SerialStream::drive;
  } else {
    config.rate_hz = options_.rate_hz;
    config.mode = OutputMode::vibration;
    period_s_ = static_cast<double>(options_.block_frames) / config.rate_hz;
    bo.block_frames = options_.block_frames;
    bo.audio_device = options_.audio_device;
  }
  config.response_handling = options_.response_handling;
  config.response_limit_db = options_.response_limit_db;
  bo.rate_hz = config.rate_hz;
  rate_hz_ = config.rate_hz;
  bo.baud = options_.baud;
  bo.channels = options_.channels;
  if (options_.channels == 1) {
    player_ = std::make_unique<Player>(config);
  } else {
    // Every channel at rest (no map: silence) until the first show().
    const std::vector<Channel> at_rest(options_.channels);
    multi_ = std::make_unique<ChannelPlayer>(config, at_rest);
    channel_responses_.resize(options_.channels);
  }
  const PlayerMap blank_map(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f});
  backend_ = given ? std::move(given) : make_backend(choice, bo, blank_map);
  if (options_.finger != FingerSource::display) {
    if (options_.finger == FingerSource::sensor)
      open_sensor(choice);
    else
      choose_mode(choice);
    if (mode_ == PresentationMode::display_plays) {
      running_ = true;  // nothing streams: the display plays; pump() reads its reports
      return;
    }
    pump();
    backend_->start(output());
    running_ = true;
    if (mode_ == PresentationMode::host_streams && display1d_) {
      Display1D& d = *display1d_;
      d.reader.emplace(*d.link, [this](std::span<const FingerReport> batch) {
        Display1D& dd = *display1d_;
        std::lock_guard<std::mutex> lock(dd.mutex);
        for (const FingerReport& r : batch) {
          const double t = dd.timeline.place(r.t_us, output().time_s());
          if (!push(FingerSample{t, r.x_mm, r.touch})) ++dd.dropped;
          dd.record(r);
        }
      });
    }
    return;
  }
  mode_ = PresentationMode::host_streams;  // the 2-D player streams from the display's reports
  // The 2-D display: the player plays Player2D maps under the display's
  // finger, reported over the backend's own link or another display's.
  display_ = std::make_unique<Display2D>(config, options_.stroke_rules);
  SerialLink* link = nullptr;
  if (choice.kind == BackendChoice::Kind::serial && choice.serial_path == sensor_path) {
    link = backend_->serial_link();
  } else {
    display_->own_link = std::make_unique<SerialLink>(sensor_path, options_.baud);
    display_->own_link->hello();
    link = display_->own_link.get();
  }
  try {
    link->start_reports(options_.report_interval_us);
  } catch (const SerialError& e) {
    if (e.code == serial::ErrorCode::no_sensor)
      throw InvalidArgument("--finger " + options_.finger_display +
                            ": the display has no finger sensor (it refused FINGER reports), so a participant cannot stroke it; "
                            "give a 2-D display that reports the finger");
    throw;
  }
  blank();
  backend_->start(display_->player);
  display_->start(*link);
  running_ = true;
}

Presenter::~Presenter() { stop(); }

void Presenter::stop() {
  SerialLink* rest_link = backend_ ? backend_->serial_link() : nullptr;
  if (display1d_ && display1d_->reader) display1d_->reader->stop();
  if (display1d_) display1d_->stop_keepalive();  // the rest below, or the display's own watchdog
  if (display_ && display_->running()) {
    display_->stop();
    if (display_->error().empty()) try {
        display_->link->start_reports(0);  // the display stops reporting
      } catch (const Error&) {
        // Already gone: nothing to stop.
      }
  }
  const bool was_running = running_;
  if (running_) backend_->stop();
  running_ = false;
  // At rest: once nothing streams, SELECT none (a display in drive mode
  // leaves direct drive at a SELECT; one playing a map stops). Whatever the
  // exit — end, pause, 'q', Ctrl-C, an error unwinding past the presenter.
  if (was_running && rest_link) {
    // (The serial backend's stop() rests too; display-plays never started it.)
    (void)rest_link->rest();  // DRIVE 0, SELECT none; a link that is gone: the display's watchdog
    if (display1d_) display1d_->selected = -1;
    if (display1d_ && display1d_->sensor) try {
        display1d_->sensor = false;
        display1d_->link->start_reports(0);  // the display stops reporting
      } catch (const std::exception&) {
      }
  }
  if (display1d_ && display1d_->own_link && display1d_->sensor) try {
      display1d_->sensor = false;
      display1d_->link->start_reports(0);  // the sensor stops reporting (its link rests as it closes)
    } catch (const std::exception&) {
    }
  if (player_) player_->collect();
  if (multi_) multi_->collect();
  if (display_) display_->player.collect();
}

void Presenter::show(const std::string& document_json) {
  if (display_)
    throw InvalidArgument(
        "this presenter plays a 2-D display the participant strokes; it plays stimuli with a surface (oddity-2d)");
  if (mode_ == PresentationMode::display_plays) {
    display1d_->select(display1d_->hold(document_json, true));
    ++shown_;
    return;
  }
  // Participants switch back and forth among a trial's few stimuli, and a
  // reference recurs over many trials: keep the last few rendered maps (a
  // noise reference takes ~0.1 s to synthesise; copying its map, 0.1 ms).
  play(cached(document_json));
  ++shown_;
}

const Presenter::Prepared& Presenter::cached(const std::string& document_json) {
  auto it = std::find_if(cache_.begin(), cache_.end(), [&](const auto& e) { return e.first == document_json; });
  if (it == cache_.end()) {
    cache_.emplace_front(document_json, prepare_stimulus(document_json));
    if (cache_.size() > cache_size) cache_.pop_back();
  } else {
    cache_.splice(cache_.begin(), cache_, it);
  }
  return cache_.front().second;
}

Presenter::Prepared Presenter::prepare_stimulus(const std::string& document_json) const {
  const Document doc = parse_document(document_json, "stimulus");
  check_channels(doc, options_.channels);
  Prepared p;
  if (!multi_) {
    // The map carries the document's device response (presenter.hpp).
    p.maps.push_back(PlayerMap::from_surface(*one_channel_surface(doc), doc.device.response));
    return p;
  }
  // Each channel's map carries its actuator's response (Channel::response);
  // a channel at rest plays a silent map carrying it, so what fades out is
  // limited as that actuator needs.
  const std::vector<Channel> plan = prepare_channels(doc);
  for (std::size_t c = 0; c < options_.channels; ++c) {
    const Channel& ch = plan[plan.size() == 1 ? 0 : c];
    if (c > 0 && plan.size() == 1)
      p.maps.push_back(std::make_unique<const PlayerMap>(*p.maps.front()));  // the same map on every channel
    else if (ch.surface)
      p.maps.push_back(PlayerMap::from_surface(*ch.surface, ch.response));
    else
      p.maps.push_back(
          std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f}, ch.response));
    p.offsets.push_back(ch.offset);
  }
  return p;
}

void Presenter::play(const Prepared& prepared) {
  if (!multi_) {
    const PlayerMap& m = *prepared.maps.front();
    last_response_ = m.response();
    player_->set_map(
        std::make_unique<const PlayerMap>(m.grid(), std::vector<float>(m.values().begin(), m.values().end()), m.response()));
    return;
  }
  // Exact copies (texel lines and all): the cached maps stay for the next switch.
  std::vector<std::unique_ptr<const PlayerMap>> maps;
  maps.reserve(prepared.maps.size());
  for (std::size_t c = 0; c < prepared.maps.size(); ++c) {
    maps.push_back(std::make_unique<const PlayerMap>(*prepared.maps[c]));
    channel_responses_[c] = prepared.maps[c]->response();
  }
  deferred_maps_.clear();  // a later show supersedes one still waiting
  const std::span<const double> now = multi_->offsets_mm();
  const bool moved = !std::equal(now.begin(), now.end(), prepared.offsets.begin(), prepared.offsets.end(),
                                 [](double a, Millimetres b) { return a == b.value(); });
  if (moved) {
    // Another actuator layout (the first stimulus, or another device): the
    // new offsets apply to the samples pushed from now on, and the maps wait
    // until the samples already queued with the old ones have played
    // (passive: up to finger_lead_s; external: finger_lead_s), so the new
    // maps never see the finger jump by an offset. A separate sensor's
    // reader pushes under its mutex, and places reports at their arrival:
    // nothing of it is queued ahead.
    std::unique_lock<std::mutex> lock;
    if (display1d_) lock = std::unique_lock<std::mutex>(display1d_->mutex);
    multi_->set_offsets(prepared.offsets);
    const bool queued = mode_ == PresentationMode::passive || options_.finger == FingerSource::external;
    if (queued && next_finger_s_ > output().time_s()) {
      deferred_maps_ = std::move(maps);
      deferred_until_s_ = next_finger_s_;
      return;
    }
  }
  multi_->set_maps(std::move(maps));
}

void Presenter::swap_deferred() {
  if (deferred_maps_.empty() || output().time_s() < deferred_until_s_) return;
  multi_->set_maps(std::move(deferred_maps_));
  deferred_maps_.clear();
}

void Presenter::show(std::unique_ptr<const PlayerMap> map) {
  if (mode_ == PresentationMode::display_plays)
    throw InvalidArgument("display-plays: the display is given documents (texel render's bytes), not prepared maps");
  if (map) last_response_ = map->response();
  if (multi_ && map) {
    Prepared p;
    p.offsets.assign(options_.channels, Millimetres(0.0));
    p.maps.push_back(std::move(map));
    for (std::size_t c = 1; c < options_.channels; ++c) p.maps.push_back(std::make_unique<const PlayerMap>(*p.maps.front()));
    play(p);
  } else if (!multi_) {
    player_->set_map(std::move(map));
  }
  ++shown_;
}

void Presenter::show(const Question& question, std::size_t i) {
  const Stimulus& stimulus = question.stimuli.at(i);
  if (!display_) return show(stimulus.document_json);
  if (question.surfaces.size() != question.stimuli.size())
    throw InvalidArgument("task '" + question.task +
                          "' has no 2-D surfaces: a 2-D display plays the intervals of task oddity-2d only");
  auto map = display_->maps.map(question.surfaces[i]);
  last_response_ = map->response();
  display_->player.set_map(std::move(map));
  display_->enter(stimulus.label);
  ++shown_;
}

void Presenter::preload(const Protocol& protocol, const SessionContext& context) {
  if (display_) display_->maps.preload(protocol, context);
}

bool Presenter::preloaded() const { return display_ && display_->maps.preloaded(); }

Presenter::BitmapCounts Presenter::bitmap_counts() const {
  if (!display_) return {};
  const SurfaceMaps::Counts c = display_->maps.counts();
  return {c.preloaded, c.at_trial};
}

void Presenter::prepare(const Question& question) {
  if (display1d_) {
    Display1D& d = *display1d_;
    if (mode_ == PresentationMode::display_plays) {
      d.select(-1);
      d.arm_host_watchdog();
      // As many of the trial's distinct stimuli as the display holds, before
      // onset (an oddity trial shows one texture twice: two maps for three).
      std::vector<const std::string*> distinct;
      for (const auto& st : question.stimuli)
        if (distinct.size() < d.slots.size() &&
            std::none_of(distinct.begin(), distinct.end(), [&](const std::string* p) { return *p == st.document_json; }))
          distinct.push_back(&st.document_json);
      for (const std::string* doc : distinct) (void)d.hold(*doc, false);
      d.drain();  // reports from before onset are not this trial's
    }
    std::lock_guard<std::mutex> lock(d.mutex);
    d.trace.clear();
    d.recording = true;
  }
  // The trial's stimuli prepared now, before onset: a stimulus the
  // presenter cannot play (a device of another channel count) is refused
  // before anything of the trial plays, and a switch then costs a copy.
  // (More stimuli than the cache holds: checked only, rendered when shown.)
  if (!display_ && mode_ != PresentationMode::display_plays) {
    for (const auto& st : question.stimuli) {
      if (question.stimuli.size() <= cache_size)
        (void)cached(st.document_json);
      else
        check_channels(parse_document(st.document_json, "stimulus"), options_.channels);
    }
  }
  simulated_trace_.clear();
  recording_ = true;
  if (!display_) return;
  display_->maps.prepare(question);
  std::lock_guard<std::mutex> lock(display_->mutex);
  display_->recorders.clear();
  display_->current.clear();
}

std::vector<IntervalStrokes> Presenter::strokes(const Question& question) const {
  std::vector<IntervalStrokes> out;
  if (!display_) return out;
  std::lock_guard<std::mutex> lock(display_->mutex);
  for (std::size_t i = 0; i < question.stimuli.size(); ++i) {
    const Stimulus& s = question.stimuli[i];
    const double direction = i < question.surfaces.size() ? question.surfaces[i].direction_deg : 0.0;
    const auto it = display_->recorders.find(s.label);
    out.push_back(it == display_->recorders.end() ? StrokeRecorder(options_.stroke_rules).summary(s.label, direction)
                                                  : it->second.summary(s.label, direction));
  }
  return out;
}

Presenter::FingerCounts Presenter::finger_counts() const {
  if (display1d_) {
    std::lock_guard<std::mutex> lock(display1d_->mutex);
    return {display1d_->reports, display1d_->link->reports_lost(), display1d_->dropped};
  }
  if (!display_) return {};
  std::lock_guard<std::mutex> lock(display_->mutex);
  return {display_->reports, display_->link ? display_->link->reports_lost() : 0, display_->dropped};
}

void Presenter::blank() {
  if (mode_ == PresentationMode::display_plays) {
    display1d_->select(-1);
    return;
  }
  if (display_) {
    // A one-sample bitmap far off the display: the finger is off it, so the
    // player fades out.
    Raster2D off{1, 1, Millimetres(1.0), Millimetres(-1e6), Millimetres(-1e6), {0.0f}};
    display_->player.set_map(PlayerMap2D::bitmap(std::move(off), last_response_));
    display_->leave();
    return;
  }
  // A one-sample map at rest: the finger is off it, so the player fades out.
  // It carries the last stimulus's display response, so what fades out
  // during the crossfade is still limited as that display needs.
  if (multi_) {
    deferred_maps_.clear();  // a stimulus still waiting never plays
    std::vector<std::unique_ptr<const PlayerMap>> maps;
    for (const auto& response : channel_responses_)
      maps.push_back(
          std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f}, response));
    multi_->set_maps(std::move(maps));
    return;
  }
  player_->set_map(
      std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f}, last_response_));
}

void Presenter::pump() {
  if (display_) {
    display_->player.collect();
    return;
  }
  if (mode_ == PresentationMode::display_plays) {
    try {
      display1d_->drain();
    } catch (const IoError& e) {
      display1d_->error = e.what();
      throw;
    }
    return;
  }
  if (multi_) swap_deferred();
  if (options_.finger == FingerSource::external || mode_ == PresentationMode::host_streams) {
    output().collect();
    return;
  }
  const double horizon = output().time_s() + finger_lead_s;
  while (next_finger_s_ <= horizon) {
    const FingerSample s{next_finger_s_, finger_x(next_finger_s_, options_.swipe_speed_mm_s, 10.0, 90.0), true};
    if (!push(s)) break;
    // The simulated finger is the trial's trace (passive), kept at 100 Hz —
    // a known triangle sweep needs no more — and bounded at an hour.
    if (recording_ && std::llround(next_finger_s_ * finger_rate_hz) % 10 == 0 && simulated_trace_.size() < 360'000)
      simulated_trace_.push_back(s);
    next_finger_s_ += 1.0 / finger_rate_hz;
  }
  output().collect();
}

PlayerBase& Presenter::output() {
  if (multi_) return *multi_;
  return *player_;
}

bool Presenter::push(const FingerSample& sample) { return multi_ ? multi_->push(sample) : player_->push(sample); }

void Presenter::choose_mode(const BackendChoice& choice) {
  const bool external = options_.finger == FingerSource::external;
  if (choice.kind != BackendChoice::Kind::serial || external) {
    // A sound card or no hardware: no map storage; a finger only if pushed from outside.
    mode_ = options_.mode.value_or(external ? PresentationMode::host_streams : PresentationMode::passive);
    if (mode_ == PresentationMode::display_plays)
      throw InvalidArgument("--mode display-plays: " + backend_->describe() +
                            " stores no maps; give a serial display that does (--backend serial:PATH)");
    if (mode_ == PresentationMode::host_streams && !external)
      throw InvalidArgument("--mode host-streams: " + backend_->describe() +
                            " has no finger to stream from; give a display that senses it (--backend serial:PATH) or "
                            "--mode passive");
    if (mode_ == PresentationMode::passive && external)
      throw InvalidArgument("mode passive: this presenter is given a finger (external); passive plays a simulated sweep");
    return;
  }
  // A serial display: what its HELLO says it holds, and whether it senses the finger.
  auto d = std::make_unique<Display1D>();
  d->link = backend_->serial_link();
  d->info = d->link->hello();
  d->report_interval_us = options_.report_interval_us;
  if (d->report_interval_us < serial::min_report_interval_us)
    throw InvalidArgument("report interval is " + std::to_string(d->report_interval_us) +
                          " µs; allowed >= " + std::to_string(serial::min_report_interval_us));
  try {
    d->link->start_reports(d->report_interval_us);
    d->sensor = true;
  } catch (const SerialError& e) {
    if (e.code != serial::ErrorCode::no_sensor && e.code != serial::ErrorCode::unknown_type) throw;
  }
  const PresentationMode chosen = d->sensor
                                      ? (d->info.slots >= 1 ? PresentationMode::display_plays : PresentationMode::host_streams)
                                      : PresentationMode::passive;
  mode_ = options_.mode.value_or(chosen);
  const std::string who = "the display '" + d->info.name + "' on " + choice.serial_path;
  auto refuse = [&](const std::string& why) {
    if (d->sensor) try {
        d->link->start_reports(0);
      } catch (const Error&) {
      }
    throw InvalidArgument("--mode " + std::string(to_string(mode_)) + ": " + who + " " + why);
  };
  if (mode_ == PresentationMode::display_plays && d->info.slots < 1) refuse("stores no maps (0 slots in its HELLO)");
  if (mode_ != PresentationMode::passive && !d->sensor)
    refuse("does not sense the finger (it refused FINGER reports); give --mode passive for a passive hand");
  if (mode_ == PresentationMode::passive && d->sensor)
    refuse("senses the finger; passive would ignore the participant's exploration (give display-plays or host-streams)");
  if (mode_ == PresentationMode::passive) return;  // streams the simulated sweep's drive, as before
  d->slots.resize(static_cast<std::size_t>(std::max(0, d->info.slots)));
  if (mode_ == PresentationMode::display_plays) d->arm_host_watchdog();
  display1d_ = std::move(d);
}

void Presenter::open_sensor(const BackendChoice& choice) {
  const std::string& f = options_.finger_display;
  if (!f.starts_with("serial:") || f.size() <= 7)
    throw InvalidArgument("finger sensor is '" + f + "'; allowed: serial:PATH (a display or strip that reports the finger)");
  const std::string path = f.substr(7);
  if (choice.kind == BackendChoice::Kind::serial && choice.serial_path == path)
    throw InvalidArgument("--finger " + f +
                          " is the backend's own display: a display with a sensor is its own finger (give no --finger)");
  mode_ = options_.mode.value_or(PresentationMode::host_streams);
  if (mode_ != PresentationMode::host_streams)
    throw InvalidArgument("--mode " + std::string(to_string(mode_)) + ": with a separate finger sensor (" + f +
                          ") the host streams the stimulus from its reports; give --mode host-streams or none");
  if (options_.report_interval_us < serial::min_report_interval_us)
    throw InvalidArgument("report interval is " + std::to_string(options_.report_interval_us) +
                          " µs; allowed >= " + std::to_string(serial::min_report_interval_us));
  auto d = std::make_unique<Display1D>();
  d->own_link = std::make_unique<SerialLink>(path, options_.baud);
  d->link = d->own_link.get();
  d->info = d->link->hello();
  d->report_interval_us = options_.report_interval_us;
  try {
    d->link->start_reports(d->report_interval_us);
  } catch (const SerialError& e) {
    if (e.code == serial::ErrorCode::no_sensor || e.code == serial::ErrorCode::unknown_type)
      throw InvalidArgument("--finger " + f + ": the display '" + d->info.name +
                            "' does not report the finger (it refused FINGER reports); give a sensor that does");
    throw;
  }
  d->sensor = true;
  display1d_ = std::move(d);
}

FingerTrace Presenter::take_trace() {
  FingerTrace t;
  t.mode = mode_;
  if (display_) return t;  // a 2-D display's strokes are strokes()
  if (display1d_) {
    if (mode_ == PresentationMode::display_plays) display1d_->drain();
    std::lock_guard<std::mutex> lock(display1d_->mutex);
    t.source = TraceSource::display;
    t.samples.swap(display1d_->trace);
    display1d_->recording = false;
  } else if (mode_ == PresentationMode::passive && recording_) {
    t.source = TraceSource::simulated;
    t.samples.swap(simulated_trace_);
  }
  recording_ = false;
  return t;
}

Presenter::UploadCounts Presenter::upload_counts() const { return display1d_ ? display1d_->uploads : UploadCounts{}; }

std::vector<std::string> Presenter::check(const Question& first) const {
  std::vector<std::string> out;
  if (display_ || first.stimuli.empty()) return out;
  for (const auto& s : first.stimuli) check_channels(parse_document(s.document_json, "stimulus"), options_.channels);
  constexpr double swipe_mm_s = 100.0;  // the studies' typical swipe
  if (mode_ == PresentationMode::display_plays) {
    Display1D& d = *display1d_;
    std::uint64_t samples = 0;
    std::vector<std::string> distinct;  // an oddity trial shows one texture twice
    for (const auto& s : first.stimuli) {
      const Document doc = parse_document(s.document_json, "stimulus");
      samples = std::max<std::uint64_t>(samples, static_cast<std::uint64_t>(doc.device.samples));
      if (std::find(distinct.begin(), distinct.end(), s.document_json) == distinct.end()) distinct.push_back(s.document_json);
    }
    if (samples > d.info.max_samples)
      throw InvalidArgument("a stimulus map has " + std::to_string(samples) + " samples; the display '" + d.info.name +
                            "' holds at most " + std::to_string(d.info.max_samples) + " (its HELLO)");
    if (d.slots.size() < distinct.size()) {
      // Each MAP_DATA frame carries up to 509 samples (1,032 bytes with framing) and waits for its ACK.
      const double bytes = std::ceil(static_cast<double>(samples) / 509.0) * 1032.0;
      const double s = bytes * 10.0 / static_cast<double>(options_.baud);
      out.push_back("the display holds " + std::to_string(d.slots.size()) + " map(s) and a trial has " +
                    std::to_string(distinct.size()) + " different stimuli: a switch to a stimulus not held uploads its " +
                    std::to_string(samples) + " samples first (about " + detail::fixed(s * 1e3, 0) + " ms at " +
                    std::to_string(options_.baud) + " baud; less on a USB link), during which the display is at rest");
    }
    return out;
  }
  if (mode_ != PresentationMode::host_streams) return out;
  // What the stream can carry: at rate R and speed v, spatial frequencies up to R / (2 v).
  const double rate = rate_hz_;
  const double limit = rate / (2.0 * swipe_mm_s);
  std::size_t texels = 0, above = 0;
  double highest = 0.0;
  for (const auto& s : first.stimuli) {
    const Surface surface = prepare_surface(parse_document(s.document_json, "stimulus"));
    for (const auto& r : surface.regions())
      if (const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get()))
        for (const auto& texel : t->texels()) {
          ++texels;
          highest = std::max(highest, texel.frequency.value());
          if (texel.frequency.value() > limit) ++above;
        }
  }
  if (above > 0)
    out.push_back("host-streams at " + detail::num(rate) + " Hz carries at most " + detail::fixed(limit, 2) + " cycles/mm at a " +
                  detail::num(swipe_mm_s) + " mm/s swipe (" + detail::fixed(20.0 * std::log10(limit), 1) + " dB); " +
                  detail::fixed(100.0 * static_cast<double>(above) / static_cast<double>(texels), 0) +
                  " % of the first trial's texels lie above it (up to " + detail::fixed(highest, 2) +
                  " cycles/mm): the display cannot render them this way; a display that stores maps plays them "
                  "(display-plays)");
  return out;
}

std::optional<FingerSample> Presenter::push_finger(double x_mm, bool touching) {
  if (options_.finger != FingerSource::external || display_) return std::nullopt;
  // The player consumes samples in time order: a burst arriving within one
  // clock tick still gets strictly increasing stamps.
  const double t = std::max(output().time_s() + options_.finger_lead_s, next_finger_s_ + 1e-6);
  const FingerSample s{t, x_mm, touching};
  if (!push(s)) return std::nullopt;
  next_finger_s_ = t;
  return s;
}

BackendStats Presenter::stats() { return backend_->stats(); }
std::string Presenter::describe() const {
  if (mode_ == PresentationMode::display_plays) {
    const DisplayInfo& i = display1d_->info;
    return "serial " + display1d_->link->name() + " → '" + i.name + "' (protocol " + std::to_string(i.version) + ", " +
           detail::num(i.refresh_hz) +
           " Hz refresh), display-plays: the display plays each stimulus from its own "
           "finger sensor (" +
           std::to_string(i.slots) + " slots)";
  }
  std::string out = backend_->describe() + ", " + std::string(to_string(mode_));
  if (display1d_ && display1d_->own_link)
    out += " from the finger sensor " + display1d_->link->name() + " ('" + display1d_->info.name + "')";
  return out;
}
double Presenter::block_period_s() const { return mode_ == PresentationMode::display_plays ? 0.0 : period_s_; }
std::string Presenter::error() const {
  std::string e = backend_->error();
  if (e.empty() && display_) e = display_->error();
  if (e.empty() && display1d_) {
    std::lock_guard<std::mutex> lock(display1d_->mutex);
    e = display1d_->error;
    if (e.empty() && display1d_->reader) e = display1d_->reader->error();
  }
  return e;
}

}  // namespace texel::experiment
