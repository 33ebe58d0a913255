// The lattice of a `cells` rendering's borders, found in a 2-D map
// (encode2d_parts.hpp, docs/encoder.md "2-D inputs"): the 2-D encoder's
// texel length when the map was drawn by cells.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "encode2d_parts.hpp"
#include "texel/encode2d.hpp"

namespace texel::codec::encode2d_parts {

/// The cell size of a `cells` rendering: borders every L in x and y from the
/// origin make the mean absolute step between neighbouring pixels larger
/// there. Returns the L (µm steps, 2 pixels … 5 mm) whose border positions
/// stand out most, if they stand out by more than `min_z` standard errors.
std::optional<double> detect_lattice(const Raster2D& map, const std::vector<double>& fine, double min_z) {
  const int w = map.width, h = map.height;
  const double p = map.pitch.value();
  std::vector<double> gx(static_cast<std::size_t>(w - 1), 0.0), gy(static_cast<std::size_t>(h - 1), 0.0);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const double v = fine[static_cast<std::size_t>(j) * w + i];
      if (i + 1 < w) gx[i] += std::abs(fine[static_cast<std::size_t>(j) * w + i + 1] - v) / h;
      if (j + 1 < h) gy[j] += std::abs(fine[static_cast<std::size_t>(j + 1) * w + i] - v) / w;
    }
  std::vector<double> g = gx;
  g.insert(g.end(), gy.begin(), gy.end());
  const double mean = std::accumulate(g.begin(), g.end(), 0.0) / static_cast<double>(g.size());
  double sd = 0.0;
  for (double v : g) sd += (v - mean) * (v - mean);
  sd = std::sqrt(sd / static_cast<double>(g.size()));
  if (!(sd > 0.0)) return std::nullopt;
  const double tol = TexelTexture::boundary_tolerance_mm;
  double best_z = 0.0, best_l = 0.0, best_hi = 0.0;
  const auto lo = static_cast<long>(std::ceil(2.0 * p * 1000.0)),
             hi = static_cast<long>(std::floor(std::min(5.0, 0.25 * std::min(w, h) * p) * 1000.0));
  for (long um = lo; um <= hi; ++um) {
    const double L = static_cast<double>(um) / 1000.0;
    double on = 0.0;
    std::size_t n_on = 0;
    const auto count = [&](const std::vector<double>& gv) {
      for (std::size_t i = 0; i < gv.size(); ++i)
        if (std::floor((static_cast<double>(i) * p + tol) / L) != std::floor((static_cast<double>(i + 1) * p + tol) / L)) {
          on += gv[i];
          ++n_on;
        }
    };
    count(gx);
    count(gy);
    if (n_on < 4 || n_on * 2 > g.size()) continue;
    const double off = (std::accumulate(g.begin(), g.end(), 0.0) - on) / static_cast<double>(g.size() - n_on);
    const double z = (on / static_cast<double>(n_on) - off) / (sd / std::sqrt(static_cast<double>(n_on)));
    if (z > best_z * (1.0 + 1e-12)) {
      best_z = z;
      best_l = L;
      best_hi = L;
    } else if (z >= best_z * (1.0 - 1e-12)) {
      best_hi = L;  // the same border positions: the same lattice on this grid
    }
  }
  if (best_z < min_z) return std::nullopt;
  // Lengths that put the borders between the same pixels tie: the roundest of them.
  for (double step : {0.25, 0.1, 0.05, 0.01, 0.005, 0.001}) {
    const double r = std::ceil(best_l / step - 1e-9) * step;
    if (r <= best_hi + 1e-12) return r;
  }
  return best_l;
}

}  // namespace texel::codec::encode2d_parts
