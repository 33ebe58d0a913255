// libFuzzer target for binary MPEG-I Haptics streams (.hmpg,
// texel/interchange.hpp): hmpg::decode, hjif::parse_hjif of what it decodes,
// hmpg::encode of that, and the signal loader's .hmpg path
// (decode_signal(bytes, SignalFormat::hmpg), 0.05 mm, at most 2^16 keyframes
// and samples). Every input is either
//   - accepted: the decoded experience parses; when Texel can write it again
//     (hmpg::encode does not refuse it), write -> read -> write gives the same
//     bytes; the signal has 2 … 2^16 finite samples in [0, 1]; or
//   - rejected with a texel::Error (FormatError naming the field and the byte
//     offset; InvalidArgument for what the writer cannot carry).
// Anything else (a crash, another exception, a sanitizer report, an
// allocation sized by a declared count) is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/signal.hpp"

namespace {
constexpr std::size_t cap = std::size_t{1} << 16;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  texel::hjif::ImportLimits limits;
  limits.max_keyframes = cap;
  try {
    const std::string text = texel::hmpg::decode(bytes, "fuzz.hmpg", limits);
    (void)texel::hjif::conformance_errors(text);
    try {
      (void)texel::hjif::parse_hjif(text, "fuzz.hmpg", limits);
    } catch (const texel::Error&) {
    }
    std::vector<std::byte> again;
    try {
      again = texel::hmpg::encode(text);
    } catch (const texel::InvalidArgument&) {
      return 0;  // decoded, but not something Texel writes (e.g. not conformant)
    }
    // Texel's own stream: reading and writing it again changes nothing.
    if (texel::hmpg::encode(texel::hmpg::decode(again, "again.hmpg", limits)) != again) std::abort();
  } catch (const texel::Error&) {
  }
  try {
    texel::SignalOptions o;
    o.spacing = texel::Millimetres(0.05);
    o.max_samples = cap;
    const texel::Signal s = texel::decode_signal(bytes, texel::SignalFormat::hmpg, o, "fuzz.hmpg");
    if (s.samples.size() < 2 || s.samples.size() > cap || !(s.spacing.value() > 0.0)) std::abort();
    for (double a : s.samples)
      if (!(a >= 0.0 && a <= 1.0)) std::abort();
  } catch (const texel::Error&) {
  }
  return 0;
}
