// Stimulus presentation through the player backends (presenter.hpp).
#include "texel/experiment/presenter.hpp"

#include <algorithm>
#include <cmath>

#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/player.hpp"

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

Presenter::Presenter(const PresenterOptions& options) : options_(options) {
  if (!(options_.swipe_speed_mm_s > 0 && options_.swipe_speed_mm_s <= 10000))
    throw InvalidArgument("swipe speed is " + std::to_string(options_.swipe_speed_mm_s) + "; allowed: 0 … 10000 mm/s");
  if (!(options_.finger_lead_s >= 0 && options_.finger_lead_s <= 0.1))
    throw InvalidArgument("finger lead is " + std::to_string(options_.finger_lead_s) + " s; allowed: 0 … 0.1 s");
  const BackendChoice choice = parse_backend(options_.backend);
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
  player_ = std::make_unique<Player>(config);
  const PlayerMap blank_map(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f});
  backend_ = make_backend(choice, bo, blank_map);
  pump();
  backend_->start(*player_);
  running_ = true;
}

Presenter::~Presenter() { stop(); }

void Presenter::stop() {
  if (running_) backend_->stop();
  running_ = false;
  if (player_) player_->collect();
}

void Presenter::show(const std::string& document_json) {
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

void Presenter::blank() {
  // A one-sample map at rest: the finger is off it, so the player fades out.
  // It carries the last stimulus's display response, so what fades out
  // during the crossfade is still limited as that display needs.
  player_->set_map(
      std::make_unique<const PlayerMap>(Grid{Millimetres(0.0), Millimetres(1.0), 1}, std::vector<float>{0.0f}, last_response_));
}

void Presenter::pump() {
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
  if (options_.finger != FingerSource::external) return std::nullopt;
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
std::string Presenter::error() const { return backend_->error(); }

}  // namespace texel::experiment
