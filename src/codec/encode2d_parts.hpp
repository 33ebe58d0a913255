// What the 2-D encoder's sources share (internal; encode2d.cpp): the raster
// helpers (encode2d_raster.cpp: interpolation, the plane's envelope, scan
// lines, the principal direction, percentiles) and the lattice of cell
// borders (encode2d_lattice.cpp).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "texel/raster2d.hpp"

namespace texel::codec::encode2d_parts {

inline constexpr double kPi = 3.14159265358979323846;

/// The value at quantile q (0 … 1) of v, nearest rank below (0 when empty).
double percentile(std::vector<double> v, double q);

/// Bilinear interpolation of the w × h raster v at (x, y) in pixels, edges held.
double bilinear(const std::vector<double>& v, int w, int h, double x, double y);

/// Local mean and RMS of the amplitude over a window one boundary (or two
/// fine periods, if longer) wide, each smoothed by a second pass of the same
/// window (docs/encoder.md "2-D inputs" §1).
struct Envelope {
  std::vector<double> mean, rms;
  int radius = 1;
};

Envelope envelope(const Raster2D& map, double boundary_mm);

/// (p99.9 − p0.1)/p99.9 of the envelope's smoothed local mean over the
/// interior (encode2d_raster.cpp says why those quantiles).
double relative_range(const Envelope& e, int w, int h);

/// Parallel straight lines across the map along `theta_deg`, Lanczos-3 at
/// one pixel steps, each tapered at its ends and joined, until `total` samples.
std::vector<double> scan_lines(const std::vector<double>& v, int w, int h, double theta_deg, std::size_t total, int& lines);

/// The direction (degrees in [0, 180)) along which the map changes most:
/// the principal axis of its gradient's structure tensor (a grating's wave vector).
double principal_direction(const std::vector<double>& v, int w, int h);

/// The cell size of a `cells` rendering: borders every L in x and y from the
/// origin make the mean absolute step between neighbouring pixels larger
/// there. Returns the L (µm steps, 2 pixels … 5 mm) whose border positions
/// stand out most, if they stand out by more than `min_z` standard errors.
std::optional<double> detect_lattice(const Raster2D& map, const std::vector<double>& fine, double min_z = 12.0);

}  // namespace texel::codec::encode2d_parts
