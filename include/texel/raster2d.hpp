// A 2-D field sampled on a regular square grid: the hand-over between the
// 2-D model (coarse profiles, friction bitmaps: src/surface2d) and the 2-D
// player. Row-major, rows along y, columns along x; sample (i, j) sits at
// (x, y) = (origin_x + i·pitch, origin_y + j·pitch) on the surface.
#pragma once

#include <cstddef>
#include <vector>

#include "texel/units.hpp"

namespace texel {

struct Raster2D {
  int width = 0;              ///< samples along x
  int height = 0;             ///< samples along y
  Millimetres pitch{0.1};     ///< sample spacing on both axes
  Millimetres origin_x{0.0};  ///< position of sample (0, 0)
  Millimetres origin_y{0.0};
  std::vector<float> values;  ///< width·height samples, row-major: values[j·width + i]

  [[nodiscard]] float at(int i, int j) const {
    return values[static_cast<std::size_t>(j) * static_cast<std::size_t>(width) + static_cast<std::size_t>(i)];
  }
};

}  // namespace texel
