// Send a Texel texture to the haptics standard and back: an MPEG-I Haptics
// file (.hjif) any conformant reader samples, carrying the parameters Texel
// re-imports exactly. The same bytes as
//   texel render --seed 7 -o a.texel.json && texel export a.texel.json -o a.hjif --date 2026-01-02
// Usage: texel_example_interchange [OUTPUT]   (default a.hjif)
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "texel/codec.hpp"
#include "texel/document.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"

int main(int argc, char** argv) try {
  const std::string path = argc > 1 ? argv[1] : "a.hjif";
  texel::TexelSpec spec;
  spec.seed = 7;  // Central Pitch 10 dB, Irregularity -5 dB, texels of 0.25 mm (the defaults)
  const texel::Document doc = texel::make_document(texel::load_device("tpad"), spec);

  // Out: one Friction perception, keyframes within 1/512 of the rendered map.
  texel::hjif::ExportOptions options;
  options.date = "2026-01-02";  // fixed, so the file is reproducible
  const texel::hjif::Exported out = texel::hjif::export_hjif(doc, options);
  texel::write_file_atomic(path, out.json);

  // In: the curves on the device grid, and the carried parameters.
  const texel::hjif::Experience in = texel::hjif::load_hjif(path);
  const std::vector<std::byte> exact = texel::codec::transcode(*in.carried).bytes;
  std::printf("%s: %zu keyframes for %zu samples, max error %.6f, %zu bytes; carried parameters -> %zu-byte bitstream (%s)\n",
              path.c_str(), out.stats.keyframes, out.stats.samples, out.stats.max_error, out.json.size(), exact.size(),
              exact == texel::codec::transcode(doc).bytes ? "identical" : "DIFFERENT");
  return exact == texel::codec::transcode(doc).bytes ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "interchange: %s\n", e.what());
  return 1;
}
