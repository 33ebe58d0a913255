// Encode a recording: a texture felt at a known swipe speed (here a .wav of
// what a finger felt, e.g. the one texel_example_play writes) becomes the
// four Texel parameters and a bitstream of a few bytes, which decodes to a
// texture on any device.
// Usage: texel_example_encode RECORDING.wav [SPEED_MM_S] [OUTPUT.texel]
//        (defaults: 100 mm/s, recording.texel)
#include <cstdio>
#include <exception>
#include <string>
#include <string_view>

#include "texel/codec.hpp"
#include "texel/io.hpp"
#include "texel/signal.hpp"
#include "texel/units.hpp"

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s RECORDING.wav [SPEED_MM_S] [OUTPUT.texel]\n", argv[0]);
    return 2;
  }
  const std::string recording = argv[1];
  const texel::MmPerSecond speed{argc > 2 ? std::stod(argv[2]) : 100.0};
  const std::string output = argc > 3 ? argv[3] : "recording.texel";

  // A recording is a function of time; at the swipe speed it becomes a
  // function of position (x = v·t), scaled to the amplitude range [0, 1].
  // load_signal reads every format the texel command reads, the same way.
  texel::SignalOptions load;
  load.swipe_speed = speed;
  const texel::Signal signal = texel::load_signal(recording, load);

  // The encoder fits the parameters whose texture feels the same under its
  // perceptual model at that speed.
  texel::codec::EncoderConfig config;
  config.model.swipe_speed = speed;
  const texel::codec::EncodeResult r = texel::codec::encode(texel::codec::encoder_signal(signal), config);

  texel::write_file_atomic(output, std::string_view(reinterpret_cast<const char*>(r.bytes.data()), r.bytes.size()));
  std::printf("%s: %s, %zu samples every %.6f mm\n", recording.c_str(), signal.description.c_str(), r.samples, r.spacing.value());
  std::printf("parameters: central pitch %.2f dB, irregularity %.2f dB, texel length %.3f mm%s\n", r.spec.central_pitch.value(),
              r.spec.irregularity.value(), r.spec.texel_length.value(), r.coarse ? ", with a coarse profile" : "");
  std::printf("felt pitch: input %.2f dB, decoded %.2f dB (model distance %.2f JND)\n", r.input.pitch_db, r.decoded.pitch_db,
              r.model_distance);
  std::printf("%s: %zu bytes\n", output.c_str(), r.bytes.size());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "encode: %s\n", e.what());
  return 1;
}
