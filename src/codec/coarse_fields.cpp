// The coarse section of a bitstream from an estimated profile (levels,
// stride, predictor) and its decoded profile.
#include <algorithm>
#include <cmath>
#include <vector>

#include "encoder_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::codec::parts {
CoarseFields coarse_fields(const std::vector<double>& c, double C, double F, unsigned bits, std::uint32_t stride,
                           std::uint8_t predictor) {
  CoarseFields f;
  f.coarse_strength = static_cast<std::uint8_t>(std::lround(std::clamp(C, 0.0, 1.0) * 255.0));
  f.fine_strength = static_cast<std::uint8_t>(std::lround(std::clamp(F, 0.0, 1.0) * 255.0));
  f.bits = static_cast<std::uint8_t>(bits);
  f.predictor = predictor;
  f.stride = stride;
  const double top = static_cast<double>((1u << bits) - 1u);
  for (std::size_t k = 0; k < c.size(); k += stride) f.levels.push_back(static_cast<std::uint16_t>(std::lround(c[k] * top)));
  return f;
}

/// RMS difference between c and the profile the fields decode to (linear
/// interpolation between stored levels, held flat past the last).
double coarse_error(const std::vector<double>& c, const CoarseFields& f) {
  const double top = static_cast<double>((1u << f.bits) - 1u);
  double sum = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::size_t j = k / f.stride;
    const double t = static_cast<double>(k % f.stride) / f.stride;
    const double a = f.levels[std::min(j, f.levels.size() - 1)] / top;
    const double b = f.levels[std::min(j + 1, f.levels.size() - 1)] / top;
    const double v = j + 1 < f.levels.size() ? a + t * (b - a) : a;
    sum += (v - c[k]) * (v - c[k]);
  }
  return std::sqrt(sum / static_cast<double>(std::max<std::size_t>(c.size(), 1)));
}

std::vector<double> decoded_profile(const CoarseFields& f, std::size_t count) {
  std::vector<double> c(count);
  const double top = static_cast<double>((1u << f.bits) - 1u);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t j = k / f.stride;
    const double t = static_cast<double>(k % f.stride) / f.stride;
    const double a = f.levels[std::min(j, f.levels.size() - 1)] / top;
    const double b = f.levels[std::min(j + 1, f.levels.size() - 1)] / top;
    c[k] = j + 1 < f.levels.size() ? a + t * (b - a) : a;
  }
  return c;
}

}  // namespace texel::codec::parts
