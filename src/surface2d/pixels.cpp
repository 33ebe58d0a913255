// Pixel rows of a 2-D surface as a friction bitmap stores them (texel/surface2d.hpp).
#include <string>
#include <vector>

#include "texel/error.hpp"
#include "texel/surface2d.hpp"

namespace texel {

void render_pixel_rows(const Surface2D& surface, int first_row, int rows, int depth, std::span<std::uint16_t> out) {
  const BitmapGeometry& g = surface.geometry();
  if (depth == 0) depth = g.depth;
  if (depth != 8 && depth != 16) throw InvalidArgument("depth is " + std::to_string(depth) + "; allowed: 8, 16");
  if (first_row < 0 || rows < 0 || first_row > g.height || rows > g.height - first_row)
    throw InvalidArgument("rows [" + std::to_string(first_row) + ", " + std::to_string(first_row) + " + " + std::to_string(rows) +
                          ") are not within the bitmap's " + std::to_string(g.height) + " rows");
  const std::size_t n = static_cast<std::size_t>(rows) * static_cast<std::size_t>(g.width);
  if (out.size() != n)
    throw InvalidArgument("the pixel buffer holds " + std::to_string(out.size()) + " values; " + std::to_string(rows) +
                          " rows of " + std::to_string(g.width) + " need " + std::to_string(n));
  std::vector<double> amplitude(static_cast<std::size_t>(g.width));
  for (int r = 0; r < rows; ++r) {
    surface.render_rows(first_row + r, 1, amplitude);
    std::uint16_t* row = out.data() + static_cast<std::size_t>(r) * amplitude.size();
    for (std::size_t i = 0; i < amplitude.size(); ++i) row[i] = bitmap_pixel(amplitude[i], g.polarity, depth);
  }
}

}  // namespace texel
