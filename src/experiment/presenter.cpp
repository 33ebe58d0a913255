// Stimulus presentation through the player backends (presenter.hpp): the
// backend and mode, the stimuli prepared and shown, the finger (simulated,
// a sensor or a display). The displays a participant touches are
// presenter_displays.hpp / .cpp; the mode a display gets and the check of
// the first question, presenter_modes.cpp.
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

#include "presenter_displays.hpp"
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

namespace presenter_parts {

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

}  // namespace presenter_parts

using namespace presenter_parts;

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

constexpr double finger_rate_hz = 1000.0;  // like a position sensor
constexpr double finger_lead_s = 0.05;     // samples queued ahead of the player

}  // namespace

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
