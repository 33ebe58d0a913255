// libFuzzer target for the .texel parser: any byte string either parses into
// a bitstream that re-serializes to the same bytes and describes a renderable
// texture, or is rejected with texel::FormatError. Anything else (a crash, a
// hang, another exception, a sanitizer report) is a bug.
//
// Built with clang as `fuzz_bitstream` (-fsanitize=fuzzer,address,undefined):
//   build-clang/tests/codec/fuzz_bitstream tests/codec/corpus -max_total_time=60
// Under GCC the same function runs over a generated corpus of random and
// mutated inputs in test_fuzz_replay.cpp (part of the normal test suite).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "texel/bitstream.hpp"
#include "texel/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes = std::as_bytes(std::span(data, size));
  try {
    const texel::codec::Bitstream b = texel::codec::parse_bitstream(bytes);
    // Accepted: it must be canonical (write(parse(x)) == x) and convertible.
    const auto again = texel::codec::write_bitstream(b);
    if (again.size() != size || !std::equal(again.begin(), again.end(), bytes.begin())) std::abort();
    (void)texel::codec::to_spec(b);
  } catch (const texel::FormatError&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
