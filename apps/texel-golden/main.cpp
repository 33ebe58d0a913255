// texel-golden: renders the demonstration set's device files, and any
// documents given, with libtexel alone (no CLI, plots or codecs), for the
// cross-build determinism check (tests/determinism/cross_build.sh), which
// builds it with several compilers and options, and for the golden-digest
// tests. Usage: texel-golden OUTDIR [DOCUMENT.texel.json ...]
//   OUTDIR/<demo>.bin                 the demo set on tpad (device format, u16)
//   OUTDIR/references/<stem>.f64      each document's map as little-endian
//                                     float64: the exact bits of every
//                                     amplitude, which a u16 file rounds away
//                                     (a 2-D document: its bitmap's
//                                     amplitudes, row-major; a multi-channel
//                                     document: its channels' maps
//                                     interleaved, [samples, channels])
#include <filesystem>
#include <iostream>
#include <span>
#include <vector>

#include "texel/demo.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/multichannel.hpp"
#if TEXEL_GOLDEN_2D
#include "texel/surface2d.hpp"
#endif

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: texel-golden OUTDIR [DOCUMENT.texel.json ...]\n";
    return 2;
  }
  try {
    const std::filesystem::path out(argv[1]);
    std::filesystem::create_directories(out);
    const texel::DeviceProfile device = texel::load_device("tpad");
    for (const auto& t : texel::demo_set()) {
      const texel::Surface surface = texel::prepare_surface(texel::make_document(device, t.spec));
      texel::write_file_atomic((out / (t.name + ".bin")).string(), surface.render_native(device.format));
    }
    if (argc > 2) std::filesystem::create_directories(out / "references");
    for (int i = 2; i < argc; ++i) {
      std::string stem = std::filesystem::path(argv[i]).filename().string();
      if (const auto dot = stem.find('.'); dot != std::string::npos) stem.resize(dot);
      const texel::Document doc = texel::load_document(argv[i]);
      const std::string path = (out / "references" / (stem + ".f64")).string();
#if TEXEL_GOLDEN_2D
      if (doc.surface2d) {
        const texel::Surface2D surface = texel::prepare_surface2d(doc);
        std::vector<double> map(static_cast<std::size_t>(surface.geometry().width) * surface.geometry().height);
        surface.render_rows(0, surface.geometry().height, map);
        texel::write_file_atomic(path,
                                 std::span<const std::byte>(reinterpret_cast<const std::byte*>(map.data()), map.size() * 8));
        continue;
      }
#endif
      if (doc.playback || doc.device.channels() > 1) {  // multi-channel: [samples, channels], interleaved
        const auto channels = texel::prepare_channels(doc);
        std::vector<double> map(static_cast<std::size_t>(doc.device.samples) * channels.size());
        texel::render_channels(channels, 0, map);
        texel::write_file_atomic(path,
                                 std::span<const std::byte>(reinterpret_cast<const std::byte*>(map.data()), map.size() * 8));
        continue;
      }
      const texel::Surface surface = texel::prepare_surface(doc);
      texel::write_file_atomic(path, surface.render_native(texel::SampleFormat::f64le));
    }
    return 0;
  } catch (const texel::Error& e) {
    std::cerr << "texel-golden: " << e.what() << "\n";
    return 2;
  }
}
