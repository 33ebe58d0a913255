// What Texel Studio's 2-D page shows of a 2-D surface (docs/studio.md "The
// 2-D page"): a bounded window of the friction map at a zoom's resolution,
// and scans of the map along a chosen direction with their spectrum beside
// the 1-D texture's. A library API, reachable without the studio.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "texel/raster2d.hpp"
#include "texel/studio/design.hpp"
#include "texel/surface2d.hpp"

namespace texel::studio {

/// A window of the bitmap: device pixels [x_px, x_px + width_px) ×
/// [y_px, y_px + height_px), every `stride`-th pixel on both axes.
struct Surface2DWindow {
  int x_px = 0, y_px = 0;
  int width_px = 0, height_px = 0;
  int stride = 1;  ///< ≥ 1: 1 = every pixel (the bitmap itself), k = every k-th
};

struct Surface2DView {
  Surface2DWindow window;  ///< as clipped to the bitmap
  int columns = 0, rows = 0;
  /// columns·rows amplitudes in [0, 1], row-major: value (u, v) is device
  /// pixel (x_px + u·stride, y_px + v·stride), exactly what the bitmap holds
  /// there before polarity and quantisation (Surface2D::render_rows).
  std::vector<float> amplitude;
};

/// Most view samples one call renders (1024 × 1024).
inline constexpr std::size_t max_view_samples = std::size_t{1} << 20;

/// Renders a window of the surface. Throws InvalidArgument naming the field
/// for a window outside the bitmap, a stride < 1 or more than
/// max_view_samples samples.
Surface2DView surface2d_view(const Surface2D& surface, const Surface2DWindow& window);

/// The friction raster a bitmap display holds: every device pixel of
/// `window` (its stride is ignored; width_px 0 = the whole bitmap),
/// quantised as the device's bitmap file stores it (bitmap_pixel at the
/// device's depth and polarity) and turned back into an amplitude in [0, 1],
/// at the device's pixel pitch with the window's corner as origin. What the
/// studio's 2-D pad plays in bitmap mode, so what is felt or heard does not
/// depend on the view's zoom. A window holds at most max_view_samples
/// pixels (throws InvalidArgument as surface2d_view); the whole bitmap
/// allocates width·height floats.
Raster2D device_raster(const Surface2D& surface, const Surface2DWindow& window = {});

/// A straight scan of region `region` through its centre along `angle_deg`
/// (0 = +x, counter-clockwise towards +y), sampled at the bitmap's pixel
/// pitch and clipped to the region, analysed with the 1-D spectrum tools;
/// `target` is the spectrum of the region's texture as a 1-D texture (its
/// TexelSpec, band-limited to the bitmap's Nyquist frequency as the 2-D
/// field is) rendered over the same number of samples at the same spacing.
struct Surface2DScan {
  std::size_t region = 0;
  double angle_deg = 0.0;
  double from_x_mm = 0.0, from_y_mm = 0.0, to_x_mm = 0.0, to_y_mm = 0.0;  ///< device mm
  Millimetres spacing{0.0};
  std::size_t samples = 0;
  SpectrumView scan;
  SpectrumView target;
};
/// Throws InvalidArgument for a bad region index or angle, or a region too
/// small for 16 samples along the direction.
Surface2DScan surface2d_scan(const Surface2D& surface, std::size_t region, double angle_deg, std::size_t points = 1024);

}  // namespace texel::studio
