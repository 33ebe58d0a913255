// The C ABI: the 1-D player (texel_c_internal.hpp); texel_player_process
// is real-time and runs without `guarded`.
#include "texel_c_internal.hpp"

#include <algorithm>
#include <cmath>
#include <span>

using namespace capi_detail;

namespace capi_detail {

// texel_player_config -> PlayerConfig (validated), with the C field names.
texel::PlayerConfig player_config_of(const texel_player_config& c) {
  texel::PlayerConfig pc;
  pc.rate_hz = c.rate_hz;
  pc.mode = choose<texel::OutputMode>(c.mode, "mode",
                                      {{TEXEL_OUTPUT_AMPLITUDE, texel::OutputMode::amplitude, "TEXEL_OUTPUT_AMPLITUDE"},
                                       {TEXEL_OUTPUT_VIBRATION, texel::OutputMode::vibration, "TEXEL_OUTPUT_VIBRATION"},
                                       {TEXEL_OUTPUT_CARRIER, texel::OutputMode::carrier, "TEXEL_OUTPUT_CARRIER"}});
  pc.gain = c.gain;
  pc.carrier_hz = c.carrier_hz;
  pc.prediction_s = c.prediction_s;
  pc.response_handling =
      choose<texel::ResponseHandling>(c.response_handling, "response_handling",
                                      {{TEXEL_RESPONSE_LIMIT, texel::ResponseHandling::limit, "TEXEL_RESPONSE_LIMIT"},
                                       {TEXEL_RESPONSE_OFF, texel::ResponseHandling::off, "TEXEL_RESPONSE_OFF"}});
  pc.response_limit_db = c.response_limit_db;
  // The library's extrapolation window must cover the look-ahead.
  pc.extrapolate_s = std::max(pc.extrapolate_s, std::isfinite(c.prediction_s) ? c.prediction_s : 0.0);
  texel::validate(pc);
  return pc;
}

}  // namespace capi_detail

extern "C" {

// ----------------------------------------------------------------- player

texel_player_config texel_player_config_default(void) {
  const texel::PlayerConfig c;
  texel_player_config p{};
  p.rate_hz = c.rate_hz;
  p.mode = TEXEL_OUTPUT_AMPLITUDE;
  p.gain = c.gain;
  p.carrier_hz = c.carrier_hz;
  p.prediction_s = c.prediction_s;
  p.response_handling = TEXEL_RESPONSE_LIMIT;
  p.response_limit_db = c.response_limit_db;
  return p;
}

texel_status texel_player_create(const texel_player_config* config, texel_player** out) {
  return create(out, [&] { return std::make_unique<texel_player>(player_config_of(need(config, "config"))); });
}

texel_status texel_player_set_surface(texel_player* player, const texel_surface* surface) {
  return guarded([&] {
    texel_player& p = need(player, "player");
    const texel_surface& s = need(surface, "surface");
    // The map carries the surface's device response (player.hpp).
    p.player.set_map(texel::PlayerMap::from_surface(s.surface, s.device.response));
  });
}

texel_status texel_player_push(texel_player* player, double t_s, double x_mm, int touch) {
  return guarded([&] {
    texel_player& p = need(player, "player");
    need_finite(t_s, "t_s");
    need_finite(x_mm, "x_mm");
    if (!p.player.push(texel::FingerSample{t_s, x_mm, touch != 0}))
      throw BufferTooSmall{"the player's event queue is full (" + std::to_string(p.player.event_capacity()) +
                           " events); let texel_player_process run, then push again"};
  });
}

texel_status texel_player_set_gain(texel_player* player, double gain) {
  return guarded([&] {
    texel_player& p = need(player, "player");
    need_finite(gain, "gain");
    if (!p.player.set_gain(gain))
      throw BufferTooSmall{"the player's event queue is full; let texel_player_process run, then try again"};
  });
}

texel_status texel_player_collect(texel_player* player, std::size_t* freed) {
  return guarded([&] {
    const std::size_t n = need(player, "player").player.collect();
    if (freed) *freed = n;
  });
}

texel_status texel_player_process(texel_player* player, float* out, std::size_t frames, float* positions_mm) {
  // Real-time: no guarded() (its error slot is a std::string), no allocation.
  if (!player || (!out && frames > 0)) return TEXEL_INVALID_ARGUMENT;
  if (frames == 0) return TEXEL_OK;
  std::span<float> pos;
  if (positions_mm) pos = std::span<float>(positions_mm, frames);
  (void)player->player.process(std::span<float>(out, frames), pos);  // noexcept
  return TEXEL_OK;
}

std::uint64_t texel_player_samples(const texel_player* player) { return player ? player->player.samples() : 0; }

void texel_player_destroy(texel_player* player) { delete player; }

}  // extern "C"
