// A uniform sampling grid along the swipe axis: sample i sits at
// origin + i·spacing. Devices, surfaces and textures all speak in grids, and
// the position of a sample depends only on its global index, so any window of
// a grid renders to the same values as the whole.
#pragma once

#include <cstdint>

#include "texel/units.hpp"

namespace texel {

struct Grid {
  Millimetres origin{0.0};   ///< position of sample 0
  Millimetres spacing{0.0};  ///< distance between samples, > 0
  std::int64_t count = 0;    ///< number of samples

  [[nodiscard]] constexpr Millimetres position(std::int64_t i) const {
    return Millimetres(origin.value() + static_cast<double>(i) * spacing.value());
  }
  [[nodiscard]] constexpr Millimetres length() const { return Millimetres(static_cast<double>(count) * spacing.value()); }
  /// Spatial Nyquist frequency 1/(2·Δx): the highest renderable frequency.
  [[nodiscard]] constexpr CyclesPerMm nyquist() const { return CyclesPerMm(0.5 / spacing.value()); }
};

}  // namespace texel
