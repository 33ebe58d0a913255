// The fine fields' vectorised kernels (internal; field.cpp,
// field_kernels.cpp): the spectral design's pixels and points, sin_cycles in
// place, and the tile design's x and y taps, each built for AVX-512, AVX2 and
// two generic lanes, the widest this CPU runs chosen once. Every lane does the
// scalar value()'s operations in its order, so the width changes speed,
// never bits. The tile taps the scalar path shares with them are here too.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "internal.hpp"
#include "texel/detmath.hpp"
#include "texel/surface2d.hpp"

namespace texel::field_kernels {

// The spectral field's pixels, sum over c of sin(2π(u_c + v_c)) =
// sin 2πu·cos 2πv + cos 2πu·sin 2πv with u_c = fx_c·x, summed in component
// order for each pixel and scaled and clipped as value() does. Written with
// explicit lanes (texel/detail/lanes.hpp) like the 1-D render kernel: a panel
// of 2W columns has its x factors computed once (at most spectral_components
// of them, on the stack), then rows a group of four at
// a time keep their 4 × 2W sums in registers while the components stream
// through (the sums of one pixel are added in the same order and with the same
// operations as value(), so the lane width changes speed, never bits).
struct SpectralBlock {
  const double* fx;  // [c]: frequency·cos(direction)
  const double* sy;  // [r][c]: sin 2πv
  const double* cy;  // [r][c]: cos 2πv
  std::size_t components, rows;
  double gain, pitch, origin_x;
};
using SpectralKernel = void (*)(const SpectralBlock&, std::int64_t, std::size_t, double*, std::size_t);
/// The spectral field over `count` columns from `first` and b.rows rows.
SpectralKernel spectral_kernel();

// value() at W points at once (the spectral design): every lane does value()'s
// operations in its order, so the results are value()'s bits.
struct SpectralPoints {
  const FineField2D::Component* components;
  std::size_t count;
  double gain;
};
using PointsKernel = void (*)(const SpectralPoints&, const double*, const double*, double*, std::size_t);
PointsKernel points_kernel();

/// sin_cycles of every value in place (sin_cycles_generic's lanes: the
/// scalar bits).
void sines(std::span<double> v);

// ---- The tile design (§11.2): periodic tiles by an inverse FFT, cubic B-splines between samples.

inline constexpr std::size_t tile_n = FineField2D::tile_samples;
inline constexpr std::size_t tile_row = tile_n + 3;  // a row and its first 3 samples again (the taps never wrap)
inline constexpr std::int64_t tile_mask = static_cast<std::int64_t>(tile_n) - 1;
static_assert((tile_n & (tile_n - 1)) == 0, "tile_samples is a power of two");

/// The four cubic B-spline taps at v (mm) on a tile of spacing 1/inv_h: the
/// samples first … first + 3 (unwrapped index; first = floor(v/h) − 1) with
/// weights w. value() and block() both take their taps from here, so both
/// do the same operations for a point.
struct Taps {
  std::int64_t first = 0;
  double w[4] = {0.0, 0.0, 0.0, 0.0};
};
inline Taps taps(double v, double inv_h) {
  double u = v * inv_h;
  if (!(std::fabs(u) < 0x1p50)) u = 0.0;  // non-finite or beyond any surface: the tile's origin
  const double f = detmath::floor_exact(u);
  const double t = u - f, s = 1.0 - t, t2 = t * t, t3 = t2 * t;
  Taps k;
  k.first = static_cast<std::int64_t>(f) - 1;
  k.w[0] = s * s * s * (1.0 / 6.0);
  k.w[1] = (3.0 * t3 - 6.0 * t2 + 4.0) * (1.0 / 6.0);
  k.w[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) * (1.0 / 6.0);
  k.w[3] = t3 * (1.0 / 6.0);
  return k;
}
/// The x taps of one tile row: w0·s[i] + w1·s[i+1] + w2·s[i+2] + w3·s[i+3].
inline double tap_row(const float* row, std::int64_t first, const double* w) {
  const float* s = row + (first & tile_mask);
  return w[0] * s[0] + w[1] * s[1] + w[2] * s[2] + w[3] * s[3];
}
/// The y taps over four x-interpolated values.
inline double tap_column(const double* w, double c0, double c1, double c2, double c3) {
  return w[0] * c0 + w[1] * c1 + w[2] * c2 + w[3] * c3;
}

using TileXKernel = void (*)(const float*, const std::int64_t*, const double*, std::size_t, double*, std::size_t);
using TileYKernel = void (*)(const double*, const double*, std::size_t, double*, bool, bool);
/// A tile row's x taps over n columns: dst[k] = tap_row(row, ix[k], w·k).
TileXKernel tile_x_kernel();
/// A pixel row's y taps over four x-interpolated rows (field_kernels.cpp).
TileYKernel tile_y_kernel();

}  // namespace texel::field_kernels
