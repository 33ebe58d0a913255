// A swipe's options as the front doors offer them (texel/player.hpp,
// SwipeOptions): the player configuration and the simulated finger they
// describe, made here once for `texel swipe`/`play` and Python's swipe().
#include <algorithm>
#include <string>

#include "texel/error.hpp"
#include "texel/player.hpp"

namespace texel {

SwipeOptions play_options() {
  SwipeOptions o;
  o.duration = Seconds(5.0);
  return o;
}

PlayerConfig player_config(const SwipeOptions& o, const FrequencyResponse& response) {
  PlayerConfig c;
  c.response = response;
  c.response_handling = o.response;
  c.rate_hz = o.rate.value();
  c.mode = o.output;
  c.carrier_hz = o.carrier.value();
  c.prediction_s = o.prediction.value();
  // The extrapolation window covers the look-ahead.
  c.extrapolate_s = std::max(c.extrapolate_s, o.prediction.value());
  c.gain = o.gain;
  c.band_limit = o.band_limit;
  validate(c);
  return c;
}

SwipeConfig swipe_config(const SwipeOptions& o, Millimetres surface) {
  SwipeConfig s;
  s.pattern = o.pattern;
  s.speed_mm_s = o.speed.value();
  s.start_mm = o.start.value();
  s.extent_mm = o.extent.value();
  s.surface_mm = surface.value();
  s.turn_s = o.turn.value();
  s.duration_s = o.duration.value();
  return s;
}

}  // namespace texel
