// libFuzzer target for WAV recordings (any format libsndfile reads), through
// the one signal loader: texel::decode_signal(bytes, SignalFormat::wav, ...)
// (signal.hpp; libsndfile over virtual I/O on the bytes, channels mixed,
// 100 mm/s, at most 2^20 samples). Every input is either
//   - accepted: at least 2 finite samples in [0, 1] on a spacing > 0 (a
//     recording is scaled to full range), no more than the cap; or
//   - rejected with a texel::Error (FormatError; InvalidArgument for a
//     declared size over the cap or a constant recording).
// Anything else (a crash, another exception, a sanitizer report, an
// allocation sized by a declared frame count under -malloc_limit_mb) is a
// bug. libsndfile itself is not instrumented: the fuzzer steers by Texel's
// branches, and ASan still sees every allocation and copy it makes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "texel/error.hpp"
#include "texel/signal.hpp"

namespace {

constexpr std::size_t max_samples = std::size_t{1} << 20;

void check(const std::vector<double>& samples, double spacing_mm) {
  if (samples.size() < 2 || samples.size() > max_samples) std::abort();
  for (double a : samples)
    if (!(a >= 0.0 && a <= 1.0)) std::abort();
  if (!(spacing_mm > 0.0 && std::isfinite(spacing_mm))) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    texel::SignalOptions o;
    o.swipe_speed = texel::MmPerSecond(100.0);
    o.channels = texel::ChannelPolicy::mix;
    o.max_samples = max_samples;
    const texel::Signal s = texel::decode_signal(std::as_bytes(std::span(data, size)), texel::SignalFormat::wav, o, "fuzz.wav");
    check(s.samples, s.spacing.value());
  } catch (const texel::Error&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
