// The pieces every real-time player is built from (player.hpp: the 1-D
// Player; player2d.hpp: the 2-D Player2D). Each is real-time safe once
// constructed: no allocation, lock or blocking call after the constructor.
//
//   Biquad        the 2nd-order sections (vibration low-pass, response limit);
//   FingerTrack   consumes time-ordered finger samples with N coordinates,
//                 keeps the smoothed velocity and interpolates / extrapolates
//                 the position at any time (player.hpp "Finger model");
//   OutputStage   everything after the value under the finger: touch / lift
//                 ramp, the display's response limit, the output mode
//                 (amplitude, vibration, carrier) and the ramped gain;
//   MapExchange   the map now playing, the one handed over by the control
//                 thread (atomic exchange), the crossfade between them and the
//                 retire queue that takes the old one back to the control thread;
//   take_events   the event ring's consumer (finger samples, gain, carrier);
//   limit_weight  the band limit's fade of one texel (docs/player.md §2
//                 and §5), the one rule both players apply.
//
// They are public only because the players hold them by value; use the
// players, not these.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <span>
#include <string_view>

#include "texel/device.hpp"
#include "texel/spsc_queue.hpp"

namespace texel {

struct PlayerConfig;
double response_limit_hz(const PlayerConfig& config, const FrequencyResponse& response) noexcept;

namespace player_parts {

/// validate(config), then config: for the players' member initialisers.
const PlayerConfig& validated(const PlayerConfig& config);

/// Reads the rows of a finger-trace CSV: time_s, `positions` coordinates
/// (mm), optional touch (0/1, default 1); times finite and non-decreasing.
/// Calls row(t, coordinates, touch); throws FormatError naming the line, or
/// when there are no rows (`expected` names the columns).
void read_trace_rows(std::string_view text, std::string_view origin, std::size_t positions, const char* expected,
                     const std::function<void(double t, std::span<const double> position, bool touch)>& row);

/// The band limit's weight of a texel whose frequency is `f` against the
/// limit `limit` (any one unit: felt Hz against Hz, or cycles/mm against the
/// spatial limit limit_hz/|v|): 1 up to 0.8·limit, a raised cosine down to 0
/// at the limit, 0 beyond. A limit of 0 (or less) fades everything; an
/// infinite one nothing. Real-time safe (arithmetic only).
inline double limit_weight(double f, double limit) noexcept {
  // Well inside the limit (f ≤ 0.79·limit puts r under 0.8 whatever the
  // rounding): 1 without the division.
  if (limit > 0.0 && f <= 0.79 * limit) return 1.0;
  const double r = f / limit;
  if (r <= 0.8) return 1.0;
  if (!(r < 1.0)) return 0.0;
  return 0.5 + 0.5 * std::cos(std::numbers::pi * (r - 0.8) / 0.2);
}

struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
  double z1 = 0, z2 = 0;
  double operator()(double x) noexcept {
    const double y = b0 * x + z1;
    z1 = b1 * x - a1 * y + z2;
    z2 = b2 * x - a2 * y;
    return y;
  }
  /// Steady state for a constant input x (DC gain 1): no transient on touch-down.
  void settle(double x) noexcept {
    z2 = (b2 - a2) * x;
    z1 = (b1 - a1) * x + z2;
  }
  /// RBJ cookbook low-pass, Q = 1/√2 (Butterworth): flat pass band, −3 dB at fc.
  static Biquad lowpass(double fc, double rate) noexcept;
};

/// A command for process(): a finger sample or a parameter change.
template <class Finger>
struct Event {
  enum class Kind : std::uint8_t { finger, gain, carrier };
  Kind kind = Kind::finger;
  Finger finger{};
  double value = 0.0;  ///< gain or carrier frequency
};

/// Finger samples in, position at any time out. `Finger` has t_s, touch and
/// N coordinates read by coords(finger) (an overload found by ADL).
template <class Finger, std::size_t N>
class FingerTrack {
 public:
  using Point = std::array<double, N>;

  void consume(const Finger& s, double smoothing_s) noexcept {
    if (have_last_ && last_.touch && s.touch && s.t_s > last_.t_s) {
      const double dt = s.t_s - last_.t_s;
      const Point c = coords(s), l = coords(last_);
      const double k = std::min(1.0, dt / smoothing_s);
      for (std::size_t i = 0; i < N; ++i) {
        const double v = (c[i] - l[i]) / dt;
        velocity_[i] += k * (v - velocity_[i]);
      }
    } else if (!s.touch || !have_last_ || !last_.touch) {
      velocity_ = Point{};
    }
    last_ = s;
    have_last_ = true;
  }

  /// Position at τ: interpolated towards `next` (the oldest unconsumed
  /// sample, or null), else extrapolated with the velocity for at most
  /// extrapolate_s, held while lifted.
  [[nodiscard]] Point position(double tau, const Finger* next, double extrapolate_s) const noexcept {
    if (!have_last_) return Point{};
    const Point l = coords(last_);
    Point p{};
    if (last_.touch && next && next->touch && next->t_s > last_.t_s) {
      const double f = (tau - last_.t_s) / (next->t_s - last_.t_s);
      const Point n = coords(*next);
      for (std::size_t i = 0; i < N; ++i) p[i] = l[i] + (n[i] - l[i]) * f;
      return p;
    }
    if (!last_.touch) return l;
    const double ahead = std::clamp(tau - last_.t_s, 0.0, extrapolate_s);
    for (std::size_t i = 0; i < N; ++i) p[i] = l[i] + velocity_[i] * ahead;
    return p;
  }

  [[nodiscard]] bool touching() const noexcept { return have_last_ && last_.touch; }
  [[nodiscard]] const Finger& last() const noexcept { return last_; }

 private:
  Finger last_{};  // newest consumed sample
  bool have_last_ = false;
  Point velocity_{};  // smoothed, per coordinate per second
};

/// Everything after the value a under the finger (player.hpp "Output modes").
class OutputStage {
 public:
  /// `config` must outlive the stage (the player owns both).
  explicit OutputStage(const PlayerConfig& config);

  /// The response limit for a map carrying `response` (or the config's when
  /// null): recomputes the filter only when the limit changes.
  void use_response(const FrequencyResponse* response) noexcept;
  [[nodiscard]] double limit_hz() const noexcept { return display_limit_hz_; }
  /// The settling flag after construction (the first touch-down settles anyway).
  void clear_settle() noexcept { display_settle_ = false; }

  void set_gain_target(double gain) noexcept { gain_target_ = gain; }
  void set_carrier_target(double hz) noexcept;

  /// Ramps gain and carrier to their targets over the next `frames` samples.
  void begin_block(std::size_t frames) noexcept {
    gain_step_ = (gain_target_ - gain_) / static_cast<double>(frames);
    inc_step_ = (carrier_inc_target_ - carrier_inc_) / static_cast<double>(frames);
    gain_end_ = gain_target_;
    inc_end_ = carrier_inc_target_;
  }
  /// One output sample for map value `a` with the finger touching or not.
  double step(double a, bool touching) noexcept;
  void end_block() noexcept {
    gain_ = gain_end_;
    carrier_inc_ = inc_end_;
  }

 private:
  const PlayerConfig* config_;
  double touch_level_ = 0.0;  // 0 … 1 before shaping
  double touch_step_ = 0.0;
  double gain_ = 1.0, gain_target_ = 1.0, gain_step_ = 0.0, gain_end_ = 1.0;
  double carrier_inc_ = 0.0, carrier_inc_target_ = 0.0, inc_step_ = 0.0, inc_end_ = 0.0;  // cycles per sample
  double carrier_phase_ = 0.0;                                                            // cycles [0, 1)
  double dc_x1_ = 0.0, dc_y1_ = 0.0, dc_r_ = 0.0;
  Biquad lowpass_{};
  Biquad display_lp_{};  // response limit
  bool display_limit_ = false;
  bool display_settle_ = false;    // limit just switched on: start settled
  double display_limit_hz_ = 0.0;  // the limit in force (0: none)
};

/// The map now playing and its hand-over (player.hpp "Threads").
template <class Map>
class MapExchange {
 public:
  static constexpr std::size_t retire_capacity = 16;

  MapExchange(std::unique_ptr<const Map> initial, double fade_step)
      : retired_(retire_capacity), current_(initial.release()), fade_step_(fade_step) {}
  /// The real-time side must have stopped.
  ~MapExchange() {
    collect();
    delete pending_.exchange(nullptr);
    delete current_;
    delete fading_;
    delete retire_waiting_;
  }
  MapExchange(const MapExchange&) = delete;
  MapExchange& operator=(const MapExchange&) = delete;

  // control thread
  void set(std::unique_ptr<const Map> map) {
    // Whoever takes a pointer out of pending_ owns it: the real-time side has
    // never seen a map we get back here, so freeing it on this thread is safe.
    delete pending_.exchange(map.release(), std::memory_order_acq_rel);
    collect();
  }
  std::size_t collect() {
    std::size_t n = 0;
    const Map* m = nullptr;
    while (retired_.try_pop(m)) {
      delete m;
      ++n;
    }
    return n;
  }

  // real-time thread
  /// At a block's start: takes a pending map (starting the crossfade) unless
  /// one is still fading or waiting to be retired. Returns the new map or null.
  const Map* begin_block() noexcept {
    // A map that could not be handed back last time (retire queue full) must
    // go first; until then no new map is taken, so nothing is ever freed here.
    if (retire_waiting_ && retired_.try_push(retire_waiting_)) retire_waiting_ = nullptr;
    if (crossfading_ || retire_waiting_) return nullptr;
    const Map* next = pending_.exchange(nullptr, std::memory_order_acq_rel);
    if (!next) return nullptr;
    fading_ = current_;
    current_ = next;
    crossfading_ = true;
    fade_pos_ = 0.0;
    return next;
  }
  [[nodiscard]] const Map* current() const noexcept { return current_; }
  /// The map fading out during a crossfade (null: none, or from silence).
  [[nodiscard]] const Map* fading() const noexcept { return fading_; }
  [[nodiscard]] bool crossfading() const noexcept { return crossfading_; }
  /// eval(map) of the current map, crossfaded (raised cosine) from the old
  /// one during a swap; 0 for no map. Advances the crossfade by one sample.
  template <class Eval>
  double value(Eval&& eval) noexcept {
    double a = current_ ? eval(*current_) : 0.0;
    if (crossfading_) {
      const double w = 0.5 - 0.5 * std::cos(std::numbers::pi * fade_pos_);
      const double old = fading_ ? eval(*fading_) : 0.0;
      a = old + (a - old) * w;
      fade_pos_ += fade_step_;
      if (fade_pos_ >= 1.0) {
        crossfading_ = false;
        if (fading_ && !retired_.try_push(fading_)) retire_waiting_ = fading_;
        fading_ = nullptr;
      }
    }
    return a;
  }

 private:
  SpscQueue<const Map*> retired_;
  std::atomic<const Map*> pending_{nullptr};
  const Map* current_ = nullptr;
  const Map* fading_ = nullptr;          // the map being faded out (null: from silence)
  const Map* retire_waiting_ = nullptr;  // retired while the retire queue was full
  bool crossfading_ = false;
  double fade_pos_ = 1.0;  // 0 → 1 over crossfade_s
  double fade_step_ = 0.0;
};

/// Consumes every queued event up to time tau (parameter commands as they
/// are reached; a finger sample later than tau stays for interpolation).
template <class Finger, std::size_t N>
void take_events(SpscQueue<Event<Finger>>& events, double tau, FingerTrack<Finger, N>& track, OutputStage& stage,
                 double smoothing_s) noexcept {
  using Kind = typename Event<Finger>::Kind;
  while (const Event<Finger>* e = events.front()) {
    switch (e->kind) {
      case Kind::gain: stage.set_gain_target(e->value); break;
      case Kind::carrier: stage.set_carrier_target(e->value); break;
      case Kind::finger:
        if (!(e->finger.t_s <= tau)) return;  // a future sample: keep it for interpolation
        track.consume(e->finger, smoothing_s);
        break;
    }
    events.pop();
  }
}

/// The oldest queued finger sample, if the queue's front is one.
template <class Finger>
const Finger* next_finger(SpscQueue<Event<Finger>>& events) noexcept {
  const Event<Finger>* e = events.front();
  return e && e->kind == Event<Finger>::Kind::finger ? &e->finger : nullptr;
}

}  // namespace player_parts
}  // namespace texel
