// libFuzzer target for MPEG-I Haptics .hjif files (texel/interchange.hpp):
// hjif::parse_hjif, hjif::conformance_errors and the signal loader's .hjif
// path, decode_signal(bytes, SignalFormat::hjif, ...) at 100 mm/s, with at
// most 2^16 keyframes and samples. Every input is either
//   - accepted: at least one sampled perception whose keyframes are strictly
//     increasing, amplitudes in [−1, 1]; the signal has 2 … 2^16 finite
//     samples in [0, 1] on a spacing > 0; or
//   - rejected with a texel::Error (FormatError with the JSON path,
//     FieldError for a missing grid or a size over the caps).
// Anything else (a crash, another exception such as a JSON library one, a
// sanitizer report, an allocation sized by a declared count) is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>

#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/signal.hpp"

namespace {

constexpr std::size_t cap = std::size_t{1} << 16;

void check(const texel::hjif::Experience& e) {
  if (e.perceptions.empty()) std::abort();
  for (const auto& p : e.perceptions)
    for (const auto& c : p.effects) {
      if (c.keyframes.empty()) std::abort();
      for (std::size_t i = 0; i < c.keyframes.size(); ++i) {
        if (i > 0 && !(c.keyframes[i].position > c.keyframes[i - 1].position)) std::abort();
        if (!std::isfinite(c.keyframes[i].amplitude)) std::abort();
      }
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)texel::hjif::conformance_errors(text);
  texel::hjif::ImportLimits limits;
  limits.max_keyframes = cap;
  try {
    check(texel::hjif::parse_hjif(text, "fuzz.hjif", limits));
  } catch (const texel::Error&) {
  }
  try {
    texel::SignalOptions o;
    o.swipe_speed = texel::MmPerSecond(100.0);
    o.spacing = texel::Millimetres(0.05);
    o.max_samples = cap;
    const texel::Signal s = texel::decode_signal(std::as_bytes(std::span(data, size)), texel::SignalFormat::hjif, o, "fuzz.hjif");
    if (s.samples.size() < 2 || s.samples.size() > cap || !(s.spacing.value() > 0.0)) std::abort();
    for (double a : s.samples)
      if (!(a >= 0.0 && a <= 1.0)) std::abort();
  } catch (const texel::Error&) {
  }
  return 0;
}
