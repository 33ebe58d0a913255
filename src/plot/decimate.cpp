// A line series as the pixel-space path that is drawn: cut to the visible x
// range and, when there are many more points than pixels, reduced to at
// most four points per quarter-pixel column (M4).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "plot_parts.hpp"

namespace texel::plot_detail {
namespace {

constexpr double columns_per_px = 4.0;

}  // namespace

/// Pixel-space vertices of a polyline, NaN x marking a break. Sorted input is
/// cut to the visible x range by binary search and reduced, per column, to
/// the first, min, max and last point in index order (the M4 scheme of
/// Jugel et al., VLDB 2014: exact for aliased 1-px lines). Columns are a
/// quarter pixel wide because antialiased strokes resolve sub-pixel
/// position; at 16 vertices per pixel of width the path stays tiny.
std::vector<std::pair<double, double>> line_vertices(const LineSeries& s, const Scale& xs, const Scale& ys) {
  std::vector<std::pair<double, double>> out;
  const std::size_t n = s.x.size();
  if (n == 0) return out;
  std::size_t i0 = 0, i1 = n;
  const bool sorted = std::is_sorted(s.x.begin(), s.x.end());
  if (sorted) {
    const auto lo = std::lower_bound(s.x.begin(), s.x.end(), xs.lo);
    const auto hi = std::upper_bound(s.x.begin(), s.x.end(), xs.hi);
    // One point beyond each end, so the line runs on to the plot's edge.
    i0 = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (lo - s.x.begin()) - 1));
    i1 = static_cast<std::size_t>(std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(n), (hi - s.x.begin()) + 1));
  }
  const double width_px = std::abs(xs.p1 - xs.p0);
  const bool decimate = sorted && static_cast<double>(i1 - i0) > 4.0 * columns_per_px * width_px;
  out.reserve(decimate ? static_cast<std::size_t>(4.0 * columns_per_px * width_px) + 16 : i1 - i0);
  const auto brk = [&] {
    if (!out.empty() && !std::isnan(out.back().first)) out.emplace_back(nan, nan);
  };
  if (!decimate) {
    for (std::size_t i = i0; i < i1; ++i) {
      const double px = xs(s.x[i]), py = ys(s.y[i]);
      if (std::isnan(px) || std::isnan(py))
        brk();
      else
        out.emplace_back(px, py);
    }
    return out;
  }
  struct Column {
    bool open = false;
    double col = 0;
    std::size_t first = 0, last = 0, min = 0, max = 0;
    double min_y = 0, max_y = 0;
  } c;
  const auto flush = [&] {
    if (!c.open) return;
    std::size_t idx[4] = {c.first, std::min(c.min, c.max), std::max(c.min, c.max), c.last};
    for (std::size_t k = 0; k < 4; ++k) {
      if (k > 0 && idx[k] == idx[k - 1]) continue;
      out.emplace_back(xs(s.x[idx[k]]), ys(s.y[idx[k]]));
    }
    c.open = false;
  };
  for (std::size_t i = i0; i < i1; ++i) {
    const double px = xs(s.x[i]), py = ys(s.y[i]);
    if (std::isnan(px) || std::isnan(py)) {
      flush();
      brk();
      continue;
    }
    const double col = std::floor(px * columns_per_px);
    if (c.open && col != c.col) flush();
    if (!c.open) {
      c = Column{true, col, i, i, i, i, py, py};
      continue;
    }
    c.last = i;
    if (py < c.min_y) c.min_y = py, c.min = i;
    if (py > c.max_y) c.max_y = py, c.max = i;
  }
  flush();
  return out;
}

}  // namespace texel::plot_detail
