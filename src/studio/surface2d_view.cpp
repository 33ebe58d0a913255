// The 2-D page's numbers (surface2d_view.hpp): a window of the friction map
// rendered region by region exactly as Surface2D::render_rows does (the fine
// field a tile at a time, the coarse profile a row at a time, texel_mix), and
// straight scans analysed with the 1-D spectrum tools.
#include "texel/studio/surface2d_view.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "texel/error.hpp"
#include "texel/texture.hpp"

namespace texel::studio {

namespace {

// The half-open membership Surface2D uses for its regions (pixel i at i·pitch).
bool inside(double v, double lo, double hi) { return v + 1e-9 >= lo && v + 1e-9 < hi; }

}  // namespace

Raster2D device_raster(const Surface2D& surface, const Surface2DWindow& window) {
  const BitmapGeometry& g = surface.geometry();
  Raster2D r;
  if (window.width_px == 0) {
    r = render_raster(surface);
  } else {
    Surface2DWindow w = window;
    w.stride = 1;
    Surface2DView v = surface2d_view(surface, w);
    r.width = v.columns;
    r.height = v.rows;
    r.pitch = g.pitch;
    r.origin_x = Millimetres(v.window.x_px * g.pitch.value());
    r.origin_y = Millimetres(v.window.y_px * g.pitch.value());
    r.values = std::move(v.amplitude);
  }
  const double full = g.depth == 8 ? 255.0 : 65535.0;
  for (float& a : r.values) {
    const double level = bitmap_pixel(a, g.polarity, g.depth) / full;
    a = static_cast<float>(g.polarity == BitmapPolarity::brighter_more_friction ? 1.0 - level : level);
  }
  return r;
}

Surface2DView surface2d_view(const Surface2D& surface, const Surface2DWindow& window) {
  const BitmapGeometry& g = surface.geometry();
  const Surface2DWindow& w = window;
  if (w.stride < 1 || w.stride > 65535) throw InvalidArgument("stride is " + std::to_string(w.stride) + "; allowed: 1 … 65535");
  if (w.x_px < 0 || w.x_px >= g.width)
    throw InvalidArgument("x_px is " + std::to_string(w.x_px) + "; allowed: 0 … " + std::to_string(g.width - 1));
  if (w.y_px < 0 || w.y_px >= g.height)
    throw InvalidArgument("y_px is " + std::to_string(w.y_px) + "; allowed: 0 … " + std::to_string(g.height - 1));
  if (w.width_px < 1 || w.height_px < 1)
    throw InvalidArgument("width_px and height_px must be ≥ 1; got " + std::to_string(w.width_px) + " × " +
                          std::to_string(w.height_px));
  Surface2DView v;
  v.window = w;
  v.window.width_px = std::min(w.width_px, g.width - w.x_px);
  v.window.height_px = std::min(w.height_px, g.height - w.y_px);
  v.columns = (v.window.width_px + w.stride - 1) / w.stride;
  v.rows = (v.window.height_px + w.stride - 1) / w.stride;
  const auto n = static_cast<std::size_t>(v.columns) * static_cast<std::size_t>(v.rows);
  if (n > max_view_samples)
    throw InvalidArgument("the window has " + std::to_string(v.columns) + " × " + std::to_string(v.rows) + " samples at stride " +
                          std::to_string(w.stride) + "; allowed: at most " + std::to_string(max_view_samples) +
                          " (use a larger stride)");
  v.amplitude.assign(n, 0.0f);

  const double p = g.pitch.value();
  const double step = p * w.stride;
  std::vector<double> block, coarse, ys;
  for (const Surface2D::Region& region : surface.regions()) {
    // The window's columns and rows that fall inside the region.
    auto px = [&](int u) { return static_cast<double>(w.x_px + u * w.stride) * p; };
    auto py = [&](int r) { return static_cast<double>(w.y_px + r * w.stride) * p; };
    int u0 = 0;
    while (u0 < v.columns && !inside(px(u0), region.x0, region.x1)) ++u0;
    int u1 = u0;
    while (u1 < v.columns && inside(px(u1), region.x0, region.x1)) ++u1;
    int r0 = 0;
    while (r0 < v.rows && !inside(py(r0), region.y0, region.y1)) ++r0;
    int r1 = r0;
    while (r1 < v.rows && inside(py(r1), region.y0, region.y1)) ++r1;
    if (u1 <= u0 || r1 <= r0) continue;
    const auto cols = static_cast<std::size_t>(u1 - u0);
    ys.clear();
    for (int r = r0; r < r1; ++r) ys.push_back(py(r) - region.y0);
    block.assign(cols * ys.size(), 0.0);
    // value((first + k)·step − origin) with first = u0 and origin = region.x0 − x_px·p.
    const double origin = region.x0 - static_cast<double>(w.x_px) * p;
    region.fine->block(u0, cols, step, origin, ys, block.data(), cols);
    const double C = region.texel.coarse_strength, F = region.texel.fine_strength;
    for (std::size_t r = 0; r < ys.size(); ++r) {
      float* out = v.amplitude.data() + (static_cast<std::size_t>(r0) + r) * static_cast<std::size_t>(v.columns) +
                   static_cast<std::size_t>(u0);
      const double* fine = block.data() + r * cols;
      if (region.coarse->constant()) {
        const TexelMix mix = texel_mix(region.coarse->value(0.0, 0.0), C, F);
        for (std::size_t k = 0; k < cols; ++k) out[k] = static_cast<float>(mix.offset + mix.gain * fine[k]);
      } else {
        coarse.resize(cols);
        region.coarse->row(u0, step, origin, ys[r], coarse);
        for (std::size_t k = 0; k < cols; ++k) {
          const TexelMix mix = texel_mix(coarse[k], C, F);
          out[k] = static_cast<float>(mix.offset + mix.gain * fine[k]);
        }
      }
    }
  }
  return v;
}

Surface2DScan surface2d_scan(const Surface2D& surface, std::size_t region, double angle_deg, std::size_t points) {
  const auto& regions = surface.regions();
  if (region >= regions.size())
    throw InvalidArgument("region is " + std::to_string(region) + "; the surface has " + std::to_string(regions.size()) +
                          " region(s)");
  if (!(std::isfinite(angle_deg) && angle_deg >= -360.0 && angle_deg <= 360.0))
    throw InvalidArgument("angle_deg is " + std::to_string(angle_deg) + "; allowed: -360 … 360");
  const Surface2D::Region& r = regions[region];
  const double p = surface.geometry().pitch.value();
  const double a = angle_deg * std::numbers::pi / 180.0;
  const double dx = std::cos(a), dy = std::sin(a);
  const double cx = 0.5 * (r.x0 + r.x1), cy = 0.5 * (r.y0 + r.y1);
  // Half the chord through the centre: the largest t with (cx, cy) ± t·d inside.
  const double hx = std::abs(dx) > 1e-12 ? 0.5 * (r.x1 - r.x0) / std::abs(dx) : HUGE_VAL;
  const double hy = std::abs(dy) > 1e-12 ? 0.5 * (r.y1 - r.y0) / std::abs(dy) : HUGE_VAL;
  const double half = std::min(hx, hy) * (1.0 - 1e-9);
  const auto samples = static_cast<std::size_t>(std::min(2.0 * half / p, 65536.0));
  if (samples < 16)
    throw InvalidArgument("region " + std::to_string(region) + " is too small for a scan at " + std::to_string(angle_deg) +
                          "° (fewer than 16 pixels across)");
  Surface2DScan s;
  s.region = region;
  s.angle_deg = angle_deg;
  s.spacing = Millimetres(p);
  s.samples = samples;
  const double t0 = -0.5 * static_cast<double>(samples - 1) * p;
  s.from_x_mm = cx + t0 * dx;
  s.from_y_mm = cy + t0 * dy;
  s.to_x_mm = cx - t0 * dx;
  s.to_y_mm = cy - t0 * dy;
  std::vector<double> line(samples);
  for (std::size_t i = 0; i < samples; ++i) {
    const double t = t0 + static_cast<double>(i) * p;
    line[i] = surface.amplitude(cx + t * dx, cy + t * dy);
  }
  s.scan = spectrum_view(line, s.spacing, points);
  const Grid grid{Millimetres(0.0), s.spacing, static_cast<std::int64_t>(samples)};
  const TexelTexture texture(r.texel, grid.length(), Sampling{grid, surface.geometry().nyquist()});
  texture.render(grid, 0, line);
  s.target = spectrum_view(line, s.spacing, points);
  return s;
}

}  // namespace texel::studio
