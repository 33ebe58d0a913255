// Stimulus presentation through the player backends (presenter.hpp).
#include "texel/experiment/presenter.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <thread>

#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/surface_maps.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
#include "texel/surface2d.hpp"

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

Presenter::Presenter(const PresenterOptions& options) : options_(options) {
  if (!(options_.swipe_speed_mm_s > 0 && options_.swipe_speed_mm_s <= 10000))
    throw InvalidArgument("swipe speed is " + std::to_string(options_.swipe_speed_mm_s) + "; allowed: 0 … 10000 mm/s");
  if (!(options_.finger_lead_s >= 0 && options_.finger_lead_s <= 0.1))
    throw InvalidArgument("finger lead is " + std::to_string(options_.finger_lead_s) + " s; allowed: 0 … 0.1 s");
  const BackendChoice choice = parse_backend(options_.backend);
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
    // A friction display takes amplitudes; the player's output is streamed
    // as drive values, so switching stimuli needs no map upload.
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
  bo.baud = options_.baud;
  player_ = std::make_unique<Player>(config);
  const PlayerMap blank_map(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f});
  backend_ = make_backend(choice, bo, blank_map);
  if (options_.finger != FingerSource::display) {
    pump();
    backend_->start(*player_);
    running_ = true;
    return;
  }
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
  if (display_ && display_->running()) {
    display_->stop();
    if (display_->error().empty()) try {
        display_->link->start_reports(0);  // the display stops reporting
      } catch (const Error&) {
        // Already gone: nothing to stop.
      }
  }
  if (running_) backend_->stop();
  running_ = false;
  if (player_) player_->collect();
  if (display_) display_->player.collect();
}

void Presenter::show(const std::string& document_json) {
  if (display_)
    throw InvalidArgument(
        "this presenter plays a 2-D display the participant strokes; it plays stimuli with a surface (oddity-2d)");
  // Participants switch back and forth among a trial's few stimuli, and a
  // reference recurs over many trials: keep the last few rendered maps (a
  // noise reference takes ~0.1 s to synthesise; copying its map, 0.1 ms).
  auto it = std::find_if(cache_.begin(), cache_.end(), [&](const auto& e) { return e.first == document_json; });
  if (it == cache_.end()) {
    // The map carries the document's device response (presenter.hpp).
    cache_.emplace_front(document_json, PlayerMap::from_document(parse_document(document_json, "stimulus")));
    if (cache_.size() > cache_size) cache_.pop_back();
    it = cache_.begin();
  } else {
    cache_.splice(cache_.begin(), cache_, it);
    it = cache_.begin();
  }
  const PlayerMap& m = *it->second;
  last_response_ = m.response();
  player_->set_map(
      std::make_unique<const PlayerMap>(m.grid(), std::vector<float>(m.values().begin(), m.values().end()), m.response()));
  ++shown_;
}

void Presenter::show(std::unique_ptr<const PlayerMap> map) {
  if (map) last_response_ = map->response();
  player_->set_map(std::move(map));
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
  if (!display_) return {};
  std::lock_guard<std::mutex> lock(display_->mutex);
  return {display_->reports, display_->link ? display_->link->reports_lost() : 0, display_->dropped};
}

void Presenter::blank() {
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
  player_->set_map(
      std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f}, last_response_));
}

void Presenter::pump() {
  if (display_) {
    display_->player.collect();
    return;
  }
  if (options_.finger == FingerSource::external) {
    player_->collect();
    return;
  }
  const double horizon = player_->time_s() + finger_lead_s;
  while (next_finger_s_ <= horizon) {
    const FingerSample s{next_finger_s_, finger_x(next_finger_s_, options_.swipe_speed_mm_s, 10.0, 90.0), true};
    if (!player_->push(s)) break;
    next_finger_s_ += 1.0 / finger_rate_hz;
  }
  player_->collect();
}

std::optional<FingerSample> Presenter::push_finger(double x_mm, bool touching) {
  if (options_.finger != FingerSource::external || display_) return std::nullopt;
  // The player consumes samples in time order: a burst arriving within one
  // clock tick still gets strictly increasing stamps.
  const double t = std::max(player_->time_s() + options_.finger_lead_s, next_finger_s_ + 1e-6);
  const FingerSample s{t, x_mm, touching};
  if (!player_->push(s)) return std::nullopt;
  next_finger_s_ = t;
  return s;
}

BackendStats Presenter::stats() { return backend_->stats(); }
std::string Presenter::describe() const { return backend_->describe(); }
double Presenter::block_period_s() const { return period_s_; }
std::string Presenter::error() const {
  std::string e = backend_->error();
  if (e.empty() && display_) e = display_->error();
  return e;
}

}  // namespace texel::experiment
