// Render a Texel texture in a few lines and write the device file: the same
// bytes as
//   texel render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 -o map.bin
// Usage: texel_example_render [OUTPUT]   (default map.bin)
#include <cstdio>
#include <exception>
#include <string>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/io.hpp"
#include "texel/texture.hpp"
#include "texel/units.hpp"

int main(int argc, char** argv) try {
  using namespace texel::literals;
  const std::string path = argc > 1 ? argv[1] : "map.bin";

  // The texture is plain data: four numbers define it, on any device.
  texel::TexelSpec spec;
  spec.central_pitch = 10_dB;  // dB re 1 cycle/mm: 10 cycles/mm
  spec.irregularity = -5_dB;   // spread of the texels' frequencies
  spec.texel_length = 0.25_mm;
  spec.seed = 7;  // the same seed gives the same texture, everywhere

  // A device profile says how to sample and store it (the TPaD: 19,200
  // uint16 samples every 0.0053 mm).
  const texel::DeviceProfile tpad = texel::load_device("tpad");
  const texel::Surface surface = texel::prepare_surface(texel::make_document(tpad, spec));
  const std::vector<std::byte> bytes = surface.render_native(tpad.format);

  texel::write_file_atomic(path, bytes);  // temporary + rename: never half a file
  std::printf("%s: %lld samples, %zu bytes (%s)\n", path.c_str(), static_cast<long long>(surface.grid().count), bytes.size(),
              std::string(texel::to_string(tpad.format)).c_str());
  return 0;
} catch (const std::exception& e) {  // every library error names the field, the value and what is allowed
  std::fprintf(stderr, "render: %s\n", e.what());
  return 1;
}
