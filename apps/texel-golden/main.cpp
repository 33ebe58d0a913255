// texel-golden: renders the demonstration set's device files with libtexel
// alone (no CLI, plots or codecs), for the cross-build determinism check
// (tests/determinism/cross_build.sh), which builds it with several compilers
// and options. Usage: texel-golden OUTDIR
#include <filesystem>
#include <iostream>

#include "texel/demo.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: texel-golden OUTDIR\n";
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
    return 0;
  } catch (const texel::Error& e) {
    std::cerr << "texel-golden: " << e.what() << "\n";
    return 2;
  }
}
