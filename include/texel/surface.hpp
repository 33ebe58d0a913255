// A Surface is a device's active length split into regions, each holding its
// own prepared Texture (docs/algorithm.md §8: the studies put a reference on the
// left half, 50.88 mm, and the texture under test on the right). Samples that
// fall in no region are at rest (0).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "texel/device.hpp"
#include "texel/grid.hpp"
#include "texel/texture.hpp"

namespace texel {

struct Region {
  std::string name;
  Millimetres start{0.0};   ///< left edge on the device
  Millimetres length{0.0};  ///< > 0
  std::shared_ptr<const Texture> texture;
};

class Surface {
 public:
  /// Regions must lie inside the grid and not overlap; throws InvalidArgument.
  Surface(Grid grid, std::vector<Region> regions);

  [[nodiscard]] const Grid& grid() const { return grid_; }
  [[nodiscard]] const std::vector<Region>& regions() const { return regions_; }

  /// Amplitudes of samples [first, first + out.size()) of the device grid.
  /// Any window gives the same values as the whole map.
  void render(std::int64_t first, std::span<double> out) const;
  /// The whole map.
  [[nodiscard]] std::vector<double> render() const;
  /// Device-native bytes of the whole map, rendered in cache-sized chunks.
  [[nodiscard]] std::vector<std::byte> render_native(SampleFormat format) const;

 private:
  Grid grid_;
  std::vector<Region> regions_;
};

}  // namespace texel
