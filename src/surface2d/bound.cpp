// The stationary isotropic bound and the straight-scan measurement of 2-D
// fields (docs/algorithm.md §11.1, §11.3).
#include <algorithm>
#include <cmath>
#include <thread>

#include "internal.hpp"
#include "texel/detail/parallel.hpp"
#include "texel/detmath.hpp"
#include "texel/spectrum.hpp"
#include "texel/surface2d.hpp"

namespace texel {
namespace {

constexpr double ln10 = 2.302585092994045684;

/// Power-weighted mean and SD of 10·log10(k) for a density p(k) on the grid
/// (bin widths dk).
std::pair<double, double> log_moments(const std::vector<double>& k, const std::vector<double>& p, const std::vector<double>& dk) {
  double w = 0.0, m = 0.0;
  for (std::size_t i = 0; i < k.size(); ++i) {
    w += p[i] * dk[i];
    m += p[i] * dk[i] * 10.0 * detmath::log(k[i]) / ln10;
  }
  if (!(w > 0.0)) return {0.0, 0.0};
  m /= w;
  double v = 0.0;
  for (std::size_t i = 0; i < k.size(); ++i) {
    const double d = 10.0 * detmath::log(k[i]) / ln10 - m;
    v += p[i] * dk[i] * d * d;
  }
  return {m, std::sqrt(v / w)};
}

}  // namespace

IsotropicBound isotropic_bound(const PitchDistribution& distribution, CyclesPerMm band_top) {
  constexpr std::size_t n = 200;
  constexpr int iterations = 4000;
  const double lo_band = distribution.config().band_min.value();
  const double hi_band = std::min(band_top.value(), distribution.config().band_max.value());
  const double mu = distribution.mu();
  const double sigma = std::max(distribution.sigma(), 0.02);
  // From two decades below the distribution (the scans' low tail) to its top.
  const double f_lo = std::max(lo_band, detmath::exp(mu - 6.0 * sigma)) / 100.0;
  // Up to the band's top (the radial spectrum of the moment fit sits 3 dB higher).
  const double f_hi = std::min(hi_band, detmath::exp(mu + 6.0 * sigma + 0.7));
  IsotropicBound b;
  b.frequency.resize(n);
  std::vector<double> dk(n);
  const double step = (detmath::log(f_hi) - detmath::log(f_lo)) / static_cast<double>(n - 1);
  for (std::size_t i = 0; i < n; ++i) b.frequency[i] = detmath::exp(detmath::log(f_lo) + step * static_cast<double>(i));
  const double ratio = detmath::exp(step);
  for (std::size_t i = 0; i < n; ++i) dk[i] = (i + 1 < n ? b.frequency[i + 1] : b.frequency[i] * ratio) - b.frequency[i];
  // Target: the lognormal density of the 1-D texel frequencies in its band.
  b.target.assign(n, 0.0);
  double area = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double k = b.frequency[i];
    if (k < lo_band || k > hi_band) continue;
    const double z = (detmath::log(k) - mu) / sigma;
    b.target[i] = detmath::exp(-0.5 * z * z) / k;
    area += b.target[i] * dk[i];
  }
  for (double& t : b.target) t /= area;
  const double t_max = *std::max_element(b.target.begin(), b.target.end());
  // Abel matrix for piecewise-constant S2 on [q_j, q_j+1):
  // A_ij = 2·(√(q_j+1² − k_i²)₊ − √(q_j² − k_i²)₊).
  std::vector<double> a(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double k2 = b.frequency[i] * b.frequency[i];
    for (std::size_t j = 0; j < n; ++j) {
      const double q0 = b.frequency[j], q1 = b.frequency[j] + dk[j];
      a[i * n + j] = 2.0 * (std::sqrt(std::max(q1 * q1 - k2, 0.0)) - std::sqrt(std::max(q0 * q0 - k2, 0.0)));
    }
  }
  // Non-negative least squares in relative (log-spectral) terms: weights
  // 1/(t + 10⁻³·t_max)², solved by multiplicative updates (which keep S2 ≥ 0).
  std::vector<double> w(n), atwt(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = b.target[i] + 1e-3 * t_max;
    w[i] = 1.0 / (d * d);
  }
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i) atwt[j] += a[i * n + j] * w[i] * b.target[i];
  b.radial.assign(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) b.radial[j] = b.target[j] + 1e-3 * t_max;
  std::vector<double> fit(n), grad(n);
  for (int it = 0; it < iterations; ++it) {
    for (std::size_t i = 0; i < n; ++i) {
      double s = 0.0;
      for (std::size_t j = 0; j < n; ++j) s += a[i * n + j] * b.radial[j];
      fit[i] = w[i] * s;
    }
    for (std::size_t j = 0; j < n; ++j) {
      double s = 0.0;
      for (std::size_t i = 0; i < n; ++i) s += a[i * n + j] * fit[i];
      b.radial[j] = s > 0.0 ? b.radial[j] * (atwt[j] / s) : 0.0;
    }
  }
  b.scan.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) b.scan[i] += a[i * n + j] * b.radial[j];
  // The moment fit: radial power density p(q) = the corrected lognormal in
  // the band, S2 = p(q)/q (power in an annulus is S2·2πq·dq).
  const PitchDistribution radial = cosine_corrected(distribution);
  const double rmu = radial.mu(), rsigma = std::max(radial.sigma(), 0.02);
  b.matched_radial.assign(n, 0.0);
  b.matched_scan.assign(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    const double q = b.frequency[j] + 0.5 * dk[j];
    if (q < lo_band || q > hi_band) continue;
    const double z = (detmath::log(q) - rmu) / rsigma;
    b.matched_radial[j] = detmath::exp(-0.5 * z * z) / (q * q);
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) b.matched_scan[i] += a[i * n + j] * b.matched_radial[j];
  std::tie(b.target_log_centroid_db, b.target_log_spread_db) = log_moments(b.frequency, b.target, dk);
  std::tie(b.scan_log_centroid_db, b.scan_log_spread_db) = log_moments(b.frequency, b.scan, dk);
  std::tie(b.matched_log_centroid_db, b.matched_log_spread_db) = log_moments(b.frequency, b.matched_scan, dk);
  return b;
}

namespace {

DirectionStats summarize_scans(const std::vector<std::vector<double>>& scans, double spacing) {
  Spectrum sum;
  for (const auto& s : scans) {
    Spectrum one = magnitude_spectrum(s, Millimetres(spacing));
    if (sum.power.empty()) {
      sum = std::move(one);
    } else {
      for (std::size_t i = 0; i < sum.power.size(); ++i) sum.power[i] += one.power[i];
    }
  }
  const SpectralSummary summary = summarize(sum);
  return {0.0, summary.log_centroid.value(), summary.log_spread.value()};
}

}  // namespace

std::vector<DirectionStats> measure_scans(const FineField2D& field, const ScanOptions& options) {
  std::vector<DirectionStats> out(static_cast<std::size_t>(std::max(options.directions, 0)));
  const double h = options.spacing.value();
  const double length = h * static_cast<double>(options.samples);
  // Directions on the 1-D renderer's threads (each is independent).
  detail::parallel_tasks(static_cast<int>(std::thread::hardware_concurrency()), out.size(), [&](std::size_t, std::size_t task) {
    const int d = static_cast<int>(task);
    const double turn = 0.5 * static_cast<double>(d) / static_cast<double>(options.directions);
    const double ux = detmath::cos_cycles(turn), uy = detmath::sin_cycles(turn);
    std::vector<std::vector<double>> scans(static_cast<std::size_t>(options.scans), std::vector<double>(options.samples));
    std::vector<double> xs(options.samples), ys(options.samples);
    for (int s = 0; s < options.scans; ++s) {
      // Parallel lines 1.1 scan lengths apart, started off the cell lattice.
      const double offset = (static_cast<double>(s) - 0.5 * options.scans) * 1.1 * length + 0.37;
      const double x0 = -uy * offset - 0.5 * length * ux + 0.123, y0 = ux * offset - 0.5 * length * uy + 0.291;
      for (std::size_t i = 0; i < options.samples; ++i) {
        const double t = static_cast<double>(i) * h;
        xs[i] = x0 + t * ux;
        ys[i] = y0 + t * uy;
      }
      field.values(xs, ys, scans[static_cast<std::size_t>(s)]);
    }
    DirectionStats st = summarize_scans(scans, h);
    st.direction_deg = 180.0 * static_cast<double>(d) / static_cast<double>(options.directions);
    out[task] = st;
  });
  return out;
}

DirectionStats measure_line(const TexelSpec& spec, CyclesPerMm band_top, const ScanOptions& options) {
  TexelSpec fine = spec;
  fine.coarse_strength = 0.0;
  fine.fine_strength = 1.0;
  fine.coarse = ConstantProfile{};
  const double h = options.spacing.value();
  const auto count = static_cast<std::int64_t>(options.samples) * options.scans;
  const Grid grid{Millimetres(0.0), options.spacing, count};
  const TexelTexture line(fine, grid.length(), Sampling{grid, band_top});
  std::vector<std::vector<double>> scans(static_cast<std::size_t>(options.scans), std::vector<double>(options.samples));
  for (int s = 0; s < options.scans; ++s)
    line.render(grid, static_cast<std::int64_t>(s) * static_cast<std::int64_t>(options.samples),
                scans[static_cast<std::size_t>(s)]);
  return summarize_scans(scans, h);
}

}  // namespace texel
