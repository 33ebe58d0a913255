// Play a texture under a simulated finger and keep what the finger would
// feel, as an audio callback would produce it: the real-time Player turns
// finger positions into drive values, one 64-sample block at a time. The
// WAV it writes is byte for byte what
//   texel render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 -o texture.texel.json
//   texel swipe texture.texel.json --duration 1 -o swipe.wav
// writes (one 1 s stroke at 100 mm/s, vibration output at 48 kHz).
// Usage: texel_example_play [OUTPUT.wav]   (default swipe.wav)
#include <algorithm>
#include <cstdio>
#include <exception>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/finger.hpp"
#include "texel/player.hpp"
#include "texel/sinks.hpp"
#include "texel/units.hpp"

int main(int argc, char** argv) try {
  using namespace texel::literals;
  const std::string path = argc > 1 ? argv[1] : "swipe.wav";

  texel::TexelSpec spec;
  spec.central_pitch = 10_dB;  // 10 cycles/mm: felt at 10 × 100 = 1000 Hz under a 100 mm/s swipe
  spec.irregularity = -5_dB;
  spec.texel_length = 0.25_mm;
  spec.seed = 7;
  const texel::Surface surface = texel::prepare_surface(texel::make_document(texel::load_device("tpad"), spec));

  // The finger: lands on the left edge and strokes at 100 mm/s for 1 s
  // (100 of the tpad's 101.76 mm), sampled at 1 kHz like a position sensor.
  texel::SwipeConfig swipe;
  swipe.speed_mm_s = 100.0;
  swipe.surface_mm = surface.grid().length().value();
  swipe.duration_s = 1.0;
  const std::vector<texel::FingerSample> trace = texel::simulate_swipe(swipe);

  // prepare: everything the player will need is allocated here. A Player is
  // small (under 1 KiB), so it lives on the stack.
  texel::PlayerConfig config;
  config.rate_hz = 48000.0;
  config.mode = texel::OutputMode::vibration;  // zero-mean drive for a vibrotactile actuator
  // The display's frequency response (as `texel swipe` takes it from the
  // document's device): what the display attenuates by 20 dB or more is not driven.
  config.response = texel::load_device("tpad").response;
  texel::Player player(config, texel::PlayerMap::from_surface(surface));

  // Off line the whole trace is known in advance: queue it (1,001 samples fit
  // the 4,096-event queue), so every position is interpolated between two.
  for (const texel::FingerSample& s : trace)
    if (!player.push(s)) throw std::runtime_error("event queue full");

  // process: what a sound card's callback does, block after block, into
  // caller-owned memory. process() never allocates, locks or blocks.
  std::vector<float> out(static_cast<std::size_t>(swipe.duration_s * config.rate_hz));
  constexpr std::size_t block = 64;
  float peak = 0.0f;
  for (std::size_t done = 0; done < out.size(); done += block) {
    const std::size_t n = std::min(block, out.size() - done);
    peak = std::max(peak, player.process(std::span(out).subspan(done, n)).peak);
  }

  texel::write_wav(path, out, config.rate_hz);  // 16-bit PCM, written atomically
  const texel::SignalSpectrum spectrum = texel::signal_spectrum(out, config.rate_hz);
  std::printf("%s: %zu samples at %.0f Hz (%.3f s), vibration, peak %.3f\n", path.c_str(), out.size(), config.rate_hz,
              player.time_s(), static_cast<double>(peak));
  std::printf("felt: spectrum peak %.1f Hz (central pitch 10 cycles/mm at 100 mm/s = 1000 Hz)\n", spectrum.peak_hz());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "play: %s\n", e.what());
  return 1;
}
