// Renders the TPaD map of one Texel texture from its parameters, the way an
// application linking libtexel would, and prints the map's size and FNV-1a
// digest; with an argument, also writes the device file (the bytes of
// `texel render --central-pitch 10 --irregularity -5 --texel-length 0.25
// --seed 7 --device tpad`).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/texture.hpp"
#include "texel/units.hpp"

int main(int argc, char** argv) {
  using namespace texel::literals;
  try {
    texel::TexelSpec spec;
    spec.central_pitch = 10.0_dB;
    spec.irregularity = texel::Decibels{-5.0};
    spec.texel_length = 0.25_mm;
    spec.seed = 7;
    const texel::Document doc = texel::make_document(texel::load_device("tpad"), spec);
    const std::vector<std::byte> map = texel::prepare_surface(doc).render_native(doc.device.format);
    if (argc > 1) texel::write_file_atomic(argv[1], map);

    std::uint64_t digest = 14695981039346656037ULL;  // FNV-1a, 64 bit
    for (std::byte b : map) digest = (digest ^ static_cast<std::uint64_t>(b)) * 1099511628211ULL;
    std::printf("%zu bytes, fnv1a64 %016llx\n", map.size(), static_cast<unsigned long long>(digest));
    return 0;
  } catch (const texel::Error& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
