#include "finger_options.hpp"

#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::cli {

void add_player_options(CLI::App& cmd, FingerOptions& finger, DeviceOptions& device, TextureOptions& texture) {
  add_finger_options(cmd, finger);
  add_device_options(cmd, device);
  add_texture_options(cmd, texture);
}

void add_finger_options(CLI::App& cmd, FingerOptions& o) {
  cmd.add_option("--speed", o.speed_mm_s, "Swipe speed (mm/s) [100]");
  cmd.add_option("--pattern", o.pattern, "Simulated swipe: constant (repeated one-way strokes) or back-and-forth [constant]");
  cmd.add_option("--trace", o.trace, "Recorded finger trace, CSV of time_s,position_mm[,touch] (replaces the simulated swipe)");
  cmd.add_option("--duration", o.duration_s, "Length (s) [swipe: 2, or the trace's; play: 5, or the trace's]");
  cmd.add_option("--start", o.start_mm, "Where the simulated finger lands (mm) [0]");
  cmd.add_option("--extent", o.extent_mm, "Travel of one stroke (mm) [to the end of the surface]");
  cmd.add_option("--turn", o.turn_s, "Back-and-forth: time to stop and turn (s) [0.1]");
  cmd.add_option("--rate", o.rate_hz, "Output rate (Hz) [48000]; e.g. 8333 for the tpad's refresh rate");
  cmd.add_option("--output", o.output,
                 "amplitude (friction map value), vibration (zero-mean, band-limited) or carrier [vibration]");
  cmd.add_option("--carrier", o.carrier_hz, "Carrier frequency for --output carrier (Hz) [250]");
  cmd.add_option("--prediction", o.prediction_s,
                 "Latency compensation: predict the finger this far ahead (s) [0; TPaD tablet: 0.02]");
  cmd.add_option("--gain", o.gain, "Output gain, 0 … 1 [1]");
  cmd.add_option("--response", o.response,
                 "The display's frequency response (device profile): limit (never drive what the display attenuates by "
                 "20 dB or more) or off [limit]");
}

PlayerConfig player_config(const FingerOptions& o, double default_rate_hz, const FrequencyResponse& response) {
  PlayerConfig c;
  c.response = response;
  c.response_handling = parse_response_handling(o.response, "--response");
  c.rate_hz = o.rate_hz.value_or(default_rate_hz);
  c.mode = parse_output_mode(o.output, "--output");
  c.carrier_hz = o.carrier_hz;
  c.prediction_s = o.prediction_s;
  c.extrapolate_s = std::max(c.extrapolate_s, o.prediction_s);
  c.gain = o.gain;
  validate(c);
  return c;
}

std::vector<FingerSample> finger_trace(const FingerOptions& o, double surface_mm, double& duration_s) {
  if (o.duration_s && !(std::isfinite(*o.duration_s) && *o.duration_s > 0 && *o.duration_s <= 86400))
    throw InvalidArgument("--duration is " + detail::num(*o.duration_s) + "; allowed > 0 … 86400 s");
  if (o.trace) {
    auto trace = load_trace_csv(*o.trace);
    duration_s = o.duration_s.value_or(trace.back().t_s);
    if (!(duration_s > 0)) throw InvalidArgument("--trace '" + *o.trace + "' lasts 0 s; give --duration");
    return trace;
  }
  duration_s = o.duration_s.value_or(duration_s);  // the caller passes its default
  SwipeConfig s;
  s.pattern = parse_swipe_pattern(o.pattern, "--pattern");
  s.speed_mm_s = o.speed_mm_s;
  s.start_mm = o.start_mm.value_or(0.0);
  s.extent_mm = o.extent_mm.value_or(0.0);
  s.surface_mm = surface_mm;
  s.turn_s = o.turn_s;
  s.duration_s = duration_s;
  if (!(std::isfinite(o.speed_mm_s) && o.speed_mm_s > 0))
    throw InvalidArgument("--speed is " + detail::num(o.speed_mm_s) + "; it must be > 0 mm/s");
  return simulate_swipe(s);
}

}  // namespace texel::cli
