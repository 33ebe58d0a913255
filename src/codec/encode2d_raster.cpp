// The 2-D encoder's raster helpers (encode2d_parts.hpp, docs/encoder.md
// "2-D inputs"): percentiles, windowed means, bilinear and Lanczos-3
// interpolation, the plane's envelope (its coarse/fine split), straight scan
// lines at any angle, and the principal direction of a map's gradient.
#include <algorithm>
#include <cmath>
#include <vector>

#include "encode2d_parts.hpp"
#include "texel/encode2d.hpp"

namespace texel::codec::encode2d_parts {
namespace {

/// Samples tapered at each end of a scan line before lines are joined.
constexpr std::size_t kTaper = 16;

/// Mean over a (2r+1)² window clipped to the map, separable running sums.
std::vector<double> box(const std::vector<double>& v, int w, int h, int r) {
  std::vector<double> tmp(v.size()), out(v.size());
  for (int j = 0; j < h; ++j) {
    const double* row = v.data() + static_cast<std::size_t>(j) * w;
    double* dst = tmp.data() + static_cast<std::size_t>(j) * w;
    double sum = 0.0;
    int lo = 0, hi = -1;  // window [lo, hi]
    for (int i = 0; i < w; ++i) {
      const int want_hi = std::min(w - 1, i + r), want_lo = std::max(0, i - r);
      while (hi < want_hi) sum += row[++hi];
      while (lo < want_lo) sum -= row[lo++];
      dst[i] = sum / (hi - lo + 1);
    }
  }
  for (int i = 0; i < w; ++i) {
    double sum = 0.0;
    int lo = 0, hi = -1;
    for (int j = 0; j < h; ++j) {
      const int want_hi = std::min(h - 1, j + r), want_lo = std::max(0, j - r);
      while (hi < want_hi) sum += tmp[static_cast<std::size_t>(++hi) * w + i];
      while (lo < want_lo) sum -= tmp[static_cast<std::size_t>(lo++) * w + i];
      out[static_cast<std::size_t>(j) * w + i] = sum / (hi - lo + 1);
    }
  }
  return out;
}

/// Lanczos-3 interpolation (6 × 6 taps, edges held): scans at any angle
/// keep the grid's content up to near its Nyquist frequency, where bilinear
/// interpolation would damp oblique scans and fake anisotropy.
double lanczos3(const std::vector<double>& v, int w, int h, double x, double y) {
  const auto kernel = [](double t) {
    if (std::abs(t) < 1e-12) return 1.0;
    if (std::abs(t) >= 3.0) return 0.0;
    const double a = kPi * t;
    return 3.0 * std::sin(a) * std::sin(a / 3.0) / (a * a);
  };
  const int i0 = static_cast<int>(std::floor(x)), j0 = static_cast<int>(std::floor(y));
  double wx[6], wy[6], sx = 0.0, sy = 0.0;
  for (int k = 0; k < 6; ++k) {
    wx[k] = kernel(x - (i0 - 2 + k));
    wy[k] = kernel(y - (j0 - 2 + k));
    sx += wx[k];
    sy += wy[k];
  }
  double sum = 0.0;
  for (int b = 0; b < 6; ++b) {
    const int j = std::clamp(j0 - 2 + b, 0, h - 1);
    double row = 0.0;
    for (int k = 0; k < 6; ++k) row += wx[k] * v[static_cast<std::size_t>(j) * w + std::clamp(i0 - 2 + k, 0, w - 1)];
    sum += wy[b] * row;
  }
  return sum / (sx * sy);
}

}  // namespace

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

double bilinear(const std::vector<double>& v, int w, int h, double x, double y) {
  x = std::clamp(x, 0.0, static_cast<double>(w - 1));
  y = std::clamp(y, 0.0, static_cast<double>(h - 1));
  const int i0 = std::min(static_cast<int>(x), std::max(w - 2, 0)), j0 = std::min(static_cast<int>(y), std::max(h - 2, 0));
  const int i1 = std::min(i0 + 1, w - 1), j1 = std::min(j0 + 1, h - 1);
  const double fx = x - i0, fy = y - j0;
  const auto at = [&](int i, int j) { return v[static_cast<std::size_t>(j) * w + i]; };
  return (1 - fy) * ((1 - fx) * at(i0, j0) + fx * at(i1, j0)) + fy * ((1 - fx) * at(i0, j1) + fx * at(i1, j1));
}

// --- the plane's split -------------------------------------------------------

Envelope envelope(const Raster2D& map, double boundary_mm) {
  const int w = map.width, h = map.height;
  const double p = map.pitch.value();
  std::vector<double> a(map.values.begin(), map.values.end());
  // RMS frequency along x (Rice: f = √(E[y′²] / E[y²]) / 2π) of the part
  // above the boundary, y = a less its mean over a boundary-wide window (as
  // the 1-D split's fine frequency is taken above 1/B).
  const int rb = std::clamp(static_cast<int>(std::lround(0.5 * boundary_mm / p)), 1, std::max(1, std::min(w, h) / 8));
  const std::vector<double> low = box(a, w, h, rb);
  double var = 0.0, d2 = 0.0;
  std::size_t nd = 0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * w + i;
      const double v = a[k] - low[k];
      var += v * v;
      if (i + 1 < w) {
        const double d = (a[k + 1] - low[k + 1] - v) / p;
        d2 += d * d;
        ++nd;
      }
    }
  var /= static_cast<double>(a.size());
  const double f_rms = var > 0.0 && nd > 0 ? std::sqrt(d2 / static_cast<double>(nd) / var) / (2.0 * kPi) : 1.0 / boundary_mm;
  const double window = std::max(boundary_mm, 2.0 / std::max(f_rms, 1e-6));
  Envelope e;
  e.radius = std::clamp(static_cast<int>(std::lround(0.5 * window / p)), 1, std::max(1, std::min(w, h) / 8));
  std::vector<double> sq(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) sq[k] = a[k] * a[k];
  std::vector<double> m = box(a, w, h, e.radius), m2 = box(sq, w, h, e.radius);
  std::vector<double> r(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) r[k] = std::sqrt(std::max(m2[k] - m[k] * m[k], 0.0));
  e.mean = box(m, w, h, e.radius);
  e.rms = box(r, w, h, e.radius);
  return e;
}

/// (p99.9 − p0.1)/p99.9 of the smoothed local mean over the interior (a
/// border of one window left out): the envelope's relative range,
/// scale-free. The quantiles are that far out so a coarse feature covering
/// a small part of a large map (a 10 mm disc on a tablet is under 1 % of
/// it) still counts; the local mean is already smooth, and the candidate's
/// own range, measured the same way, is the threshold's reference.
double relative_range(const Envelope& e, int w, int h) {
  std::vector<double> v;
  const int b = std::min(2 * e.radius, std::min(w, h) / 4);
  for (int j = b; j < h - b; ++j)
    for (int i = b; i < w - b; ++i) v.push_back(e.mean[static_cast<std::size_t>(j) * w + i]);
  if (v.empty()) v = e.mean;
  const double hi = percentile(v, 0.999), lo = percentile(v, 0.001);
  return hi > 0.0 ? (hi - lo) / hi : 0.0;
}

// --- scans -------------------------------------------------------------------

/// Parallel straight lines across the map along `theta_deg`, Lanczos-3 at
/// one pixel steps, each tapered at its ends and joined, until `total` samples.
std::vector<double> scan_lines(const std::vector<double>& v, int w, int h, double theta_deg, std::size_t total, int& lines) {
  const double th = theta_deg * kPi / 180.0;
  const double ux = std::cos(th), uy = std::sin(th), nx = -uy, ny = ux;
  const double cx = 0.5 * (w - 1), cy = 0.5 * (h - 1);
  const auto clip = [&](double o, double& t0, double& t1) {
    t0 = -1e18;
    t1 = 1e18;
    const double px = cx + o * nx, py = cy + o * ny;
    for (const auto& [p0, d, hi] : {std::tuple{px, ux, w - 1.0}, std::tuple{py, uy, h - 1.0}}) {
      if (std::abs(d) < 1e-12) {
        if (p0 < 0.0 || p0 > hi) t1 = t0 - 1.0;
        continue;
      }
      double a = (0.0 - p0) / d, b = (hi - p0) / d;
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
  };
  double t0 = 0, t1 = 0;
  clip(0.0, t0, t1);
  const double central = std::max(1.0, t1 - t0);
  const double half_n = 0.5 * (std::abs(nx) * (w - 1) + std::abs(ny) * (h - 1));
  const int max_lines = std::max(1, static_cast<int>(0.8 * half_n));  // lines at least 1.6 px apart
  const int k_lines = std::clamp(static_cast<int>(std::ceil(static_cast<double>(total) / (0.8 * central))), 1, max_lines);
  std::vector<double> out;
  out.reserve(total);
  lines = 0;
  for (int k = 0; k < k_lines && out.size() < total; ++k) {
    const double o = k_lines == 1 ? 0.0 : ((k + 0.5) / k_lines * 1.6 - 0.8) * half_n;
    clip(o, t0, t1);
    const auto n = static_cast<std::size_t>(std::max(0.0, std::floor(t1 - t0)));
    if (n < 4 * kTaper) continue;
    ++lines;
    const double px = cx + o * nx, py = cy + o * ny;
    for (std::size_t s = 0; s < n && out.size() < total; ++s) {
      const double t = t0 + static_cast<double>(s);
      double g = 1.0;
      const std::size_t edge = std::min(s, n - 1 - s);
      if (edge < kTaper) g = 0.5 - 0.5 * std::cos(kPi * (static_cast<double>(edge) + 0.5) / kTaper);
      out.push_back(g * lanczos3(v, w, h, px + t * ux, py + t * uy));
    }
  }
  return out;
}

/// The direction (degrees in [0, 180)) along which the map changes most:
/// the principal axis of its gradient's structure tensor (a grating's wave vector).
double principal_direction(const std::vector<double>& v, int w, int h) {
  double xx = 0.0, yy = 0.0, xy = 0.0;
  for (int j = 0; j + 1 < h; ++j)
    for (int i = 0; i + 1 < w; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * w + i;
      const double gx = v[k + 1] - v[k], gy = v[k + static_cast<std::size_t>(w)] - v[k];
      xx += gx * gx;
      yy += gy * gy;
      xy += gx * gy;
    }
  const double deg = 0.5 * std::atan2(2.0 * xy, xx - yy) * 180.0 / kPi;
  return deg < 0.0 ? deg + 180.0 : deg;
}

}  // namespace texel::codec::encode2d_parts
