// Helpers shared by the interchange tests and tools (tests/interchange).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../support/specs.hpp"
#include "texel/document.hpp"
#include "texel/interchange.hpp"
#include "texel/surface.hpp"

namespace texel::test_support {

/// Max |file's samples − the document's rendered map| on the document's device grid.
inline double max_map_error(const hjif::Experience& e, const Document& doc) {
  const Surface s = prepare_surface(doc);
  const std::vector<double> map = s.render();
  std::vector<double> x(map.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = s.grid().position(static_cast<std::int64_t>(i)).value();
  const std::vector<double> got = hjif::evaluate(e, x);
  double worst = 0.0;
  for (std::size_t i = 0; i < map.size(); ++i) worst = std::max(worst, std::fabs(got[i] - map[i]));
  return worst;
}

/// Two fine regions side by side, "left" and "right"; `shift` lowers both Central Pitches (dB).
inline Document two_region_document(const DeviceProfile& device, double shift = 0.0) {
  Document regions = make_document(device, fine_spec(6 + shift, -6, 0.25, 5));
  const double half = device.length().value() / 2;
  regions.regions.front().name = "left";
  regions.regions.front().length = Millimetres(half);
  RegionSpec right;
  right.name = "right";
  right.start = Millimetres(half);
  right.length = Millimetres(half);
  right.texel = fine_spec(14 + shift, -10, 1.0, 9);
  regions.regions.push_back(right);
  return regions;
}

}  // namespace texel::test_support
