// libFuzzer target for the .npy reader (parse_npy, io.hpp): any byte string
// either parses into a vector that cannot hold more elements than the input
// has data bytes and round-trips through npy_bytes bit for bit, or is
// rejected with texel::FormatError. A huge declared shape ((2**62,), or a
// product of dimensions that overflows size_t) must be rejected before any
// size arithmetic overflows; run with -malloc_limit_mb so an allocation
// sized by the header alone is a finding. Anything else (a crash, another
// exception, a sanitizer report) is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "texel/error.hpp"
#include "texel/io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const std::vector<double> v = texel::parse_npy(bytes, "fuzz");
    // The header is at least 10 bytes and every element at least 1 byte.
    if (v.size() > size) std::abort();
    const std::vector<double> again = texel::parse_npy(texel::npy_bytes(v), "again");
    if (again.size() != v.size() || (!v.empty() && std::memcmp(again.data(), v.data(), v.size() * sizeof(double)) != 0))
      std::abort();
  } catch (const texel::FormatError&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
