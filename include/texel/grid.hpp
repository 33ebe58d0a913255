// A uniform sampling grid along the swipe axis: sample i sits at
// origin + i·spacing (mm). Devices, surfaces and textures all speak in grids,
// and the position of a sample depends only on its global index, so any
// window of a grid renders to the same values as the whole.
#pragma once

#include <cstdint>

namespace texel {

struct Grid {
  double origin_mm = 0.0;   ///< position of sample 0 (mm)
  double spacing_mm = 0.0;  ///< distance between samples (mm), > 0
  std::int64_t count = 0;   ///< number of samples

  [[nodiscard]] constexpr double position(std::int64_t i) const { return origin_mm + static_cast<double>(i) * spacing_mm; }
  [[nodiscard]] constexpr double length_mm() const { return static_cast<double>(count) * spacing_mm; }
  /// Spatial Nyquist frequency 1/(2·Δx) in cycles/mm: the highest renderable frequency.
  [[nodiscard]] constexpr double nyquist_cpm() const { return 0.5 / spacing_mm; }
};

}  // namespace texel
