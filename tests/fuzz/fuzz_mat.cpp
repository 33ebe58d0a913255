// libFuzzer target for the MATLAB .mat reader (mat::read_map,
// mat::read_text of the `document` variable and mat::list_variables,
// matfile.hpp). libmatio opens files by name, so each
// input is written to a file under /dev/shm (memory, not disk) first. Every
// input is either
//   - accepted: a non-empty map of finite values, a position_mm column as
//     long as the map (or none), a spacing > 0 (or none); or
//   - rejected with texel::FormatError (or IoError).
// Anything else (a crash, another exception, a sanitizer report, an
// allocation sized by a declared shape rather than the file under
// -malloc_limit_mb) is a bug. The element cap is lowered to 2^20 so what a
// caller may legitimately ask for stays small; the size checks against the
// file's length are Texel's own.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "texel/error.hpp"
#include "texel/matfile.hpp"

namespace {

std::string scratch_path() {
  const char* dir = ::access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
  return std::string(dir) + "/texel-fuzz-mat-" + std::to_string(::getpid()) + ".mat";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = scratch_path();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  try {
    texel::mat::ReadOptions o;
    o.max_elements = std::size_t{1} << 20;
    const texel::mat::MapData m = texel::mat::read_map(path, o);
    if (m.amplitude.empty() || m.amplitude.size() > o.max_elements) std::abort();
    for (double a : m.amplitude)
      if (!std::isfinite(a)) std::abort();
    if (!m.position_mm.empty() && m.position_mm.size() != m.amplitude.size()) std::abort();
    if (m.spacing_mm && !(*m.spacing_mm > 0.0 && std::isfinite(*m.spacing_mm))) std::abort();
  } catch (const texel::Error&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  try {
    texel::mat::ReadOptions o;
    o.max_elements = std::size_t{1} << 20;
    const auto text = texel::mat::read_text(path, "document", o);
    if (text && text->size() > 4 * o.max_elements) std::abort();  // at most 4 UTF-8 bytes per code unit
  } catch (const texel::Error&) {
  }
  try {
    (void)texel::mat::list_variables(path);
  } catch (const texel::Error&) {
  }
  std::remove(path.c_str());
  return 0;
}
