// The fine fields of the 2-D model (docs/algorithm.md §11).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"
#include "texel/surface2d.hpp"
#include "texel/texture.hpp"

namespace texel {
namespace {

constexpr double ln10 = 2.302585092994045684;
// Cells are indexed by 24 bits per axis (the frequency stream's counter is
// index·2^17 + attempt, so indices stay below 2^47); the pattern repeats
// every 2^24 cells.
constexpr std::int64_t cell_bias = std::int64_t{1} << 23;
constexpr std::uint64_t cell_mask = (std::uint64_t{1} << 24) - 1;
constexpr std::uint64_t stream_direction = static_cast<std::uint64_t>(Stream::user) + 1;
constexpr std::uint64_t stream_cell_phase = static_cast<std::uint64_t>(Stream::user) + 2;
constexpr std::uint64_t stream_spectral = static_cast<std::uint64_t>(Stream::user) + 3;

/// std::floor, inline: floor_exact where it is exact (|v| < 2^51), the
/// library's beyond (a call per pixel otherwise: the baseline has no roundsd).
double cell_floor(double v) { return std::fabs(v) < 0x1p51 ? detmath::floor_exact(v) : std::floor(v); }

std::uint64_t cell_index(std::int64_t m, std::int64_t n) {
  const auto um = static_cast<std::uint64_t>(m + cell_bias) & cell_mask;
  const auto un = static_cast<std::uint64_t>(n + cell_bias) & cell_mask;
  return (un << 24) | um;
}

// The widest of a kernel's builds this CPU runs (detail::simd_lanes); the
// AVX ones exist on x86 only.
#if defined(__x86_64__) || defined(__i386__)
#define TEXEL_LANE_KERNELS(name) &name##_avx512, &name##_avx2, &name##_generic
#else
#define TEXEL_LANE_KERNELS(name) nullptr, nullptr, &name##_generic
#endif
template <class Kernel>
Kernel widest(Kernel lanes8, Kernel lanes4, Kernel lanes2) {
  if (lanes8 && detail::simd_lanes() == 8) return lanes8;
  if (lanes4 && detail::simd_lanes() == 4) return lanes4;
  return lanes2;
}

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
constexpr std::size_t max_components = FineField2D::spectral_components;

template <int W, int R>
[[gnu::always_inline]] inline void spectral_rows(const SpectralBlock& b, const typename detail::Lanes<W>::type (*sx)[2],
                                                 const typename detail::Lanes<W>::type (*cx)[2], std::size_t r0, double* out,
                                                 std::size_t stride, std::size_t live) {
  using V = typename detail::Lanes<W>::type;
  const std::size_t n = b.components;
  const double* sy = b.sy + r0 * n;
  const double* cy = b.cy + r0 * n;
  V acc[R][2];
  for (int r = 0; r < R; ++r) acc[r][0] = acc[r][1] = V{};
  for (std::size_t c = 0; c < n; ++c) {
    const V s_x0 = sx[c][0], s_x1 = sx[c][1], c_x0 = cx[c][0], c_x1 = cx[c][1];
    for (int r = 0; r < R; ++r) {
      const double s_y = sy[static_cast<std::size_t>(r) * n + c];
      const double c_y = cy[static_cast<std::size_t>(r) * n + c];
      acc[r][0] += s_x0 * c_y + c_x0 * s_y;
      acc[r][1] += s_x1 * c_y + c_x1 * s_y;
    }
  }
  const V lo = V{} - 1.0, hi = V{} + 1.0;
  for (int r = 0; r < R; ++r) {
    alignas(sizeof(V)) V a[2];
    for (int v = 0; v < 2; ++v) {
      a[v] = acc[r][v] * b.gain;
      a[v] = a[v] < lo ? lo : a[v];  // std::clamp(a, −1, 1)
      a[v] = hi < a[v] ? hi : a[v];
    }
    std::memcpy(out + (r0 + static_cast<std::size_t>(r)) * stride, &a, live * sizeof(double));
  }
}

template <int W>
[[gnu::always_inline]] inline void spectral_lanes(const SpectralBlock& b, std::int64_t first, std::size_t count, double* out,
                                                  std::size_t stride) {
  using V = typename detail::Lanes<W>::type;
  constexpr std::size_t P = 2 * W;
  const std::size_t n = std::min(b.components, max_components);
  alignas(sizeof(V)) V sx[max_components][2];
  alignas(sizeof(V)) V cx[max_components][2];
  for (std::size_t t0 = 0; t0 < count; t0 += P) {
    const std::size_t live = std::min(P, count - t0);
    // x of the panel's columns (past the end: more columns, not stored).
    V x[2];
    for (int v = 0; v < 2; ++v)
      for (int l = 0; l < W; ++l)
        x[v][l] = static_cast<double>(first + static_cast<std::int64_t>(t0) + v * W + l) * b.pitch - b.origin_x;
    for (std::size_t c = 0; c < n; ++c)
      for (int v = 0; v < 2; ++v) {
        const V u = b.fx[c] * x[v];
        sx[c][v] = detmath::sin_cycles_generic(u);
        cx[c][v] = detmath::sin_cycles_generic(u + 0.25);  // cos_cycles
      }
    std::size_t r = 0;
    for (; r + 4 <= b.rows; r += 4) spectral_rows<W, 4>(b, sx, cx, r, out + t0, stride, live);
    for (; r < b.rows; ++r) spectral_rows<W, 1>(b, sx, cx, r, out + t0, stride, live);
  }
}

using SpectralKernel = void (*)(const SpectralBlock&, std::int64_t, std::size_t, double*, std::size_t);

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void spectral_avx512(const SpectralBlock& b, std::int64_t first, std::size_t count,
                                                        double* out, std::size_t stride) {
  spectral_lanes<8>(b, first, count, out, stride);
}
__attribute__((target("avx2"))) void spectral_avx2(const SpectralBlock& b, std::int64_t first, std::size_t count, double* out,
                                                   std::size_t stride) {
  spectral_lanes<4>(b, first, count, out, stride);
}
#endif
void spectral_generic(const SpectralBlock& b, std::int64_t first, std::size_t count, double* out, std::size_t stride) {
  spectral_lanes<2>(b, first, count, out, stride);
}

SpectralKernel spectral_kernel() {
  static const SpectralKernel kernel = widest<SpectralKernel>(TEXEL_LANE_KERNELS(spectral));
  return kernel;
}

// value() at W points at once (the spectral design): every lane does value()'s
// operations in its order, so the results are value()'s bits.
struct SpectralPoints {
  const FineField2D::Component* components;
  std::size_t count;
  double gain;
};

template <int W>
[[gnu::always_inline]] inline void spectral_points_lanes(const SpectralPoints& k, const double* xs, const double* ys, double* out,
                                                         std::size_t n) {
  using V = typename detail::Lanes<W>::type;
  const V lo = V{} - 1.0, hi = V{} + 1.0;
  for (std::size_t i = 0; i < n; i += W) {
    const std::size_t live = std::min<std::size_t>(W, n - i);
    V x = V{}, y = V{};
    std::memcpy(&x, xs + i, live * sizeof(double));
    std::memcpy(&y, ys + i, live * sizeof(double));
    V sum = V{};
    for (std::size_t c = 0; c < k.count; ++c) {
      const FineField2D::Component& m = k.components[c];
      const V u = m.frequency * m.cos_dir * x, v = m.phase + m.frequency * m.sin_dir * y;
      sum += detmath::sin_cycles_generic(u) * detmath::sin_cycles_generic(v + 0.25) +
             detmath::sin_cycles_generic(u + 0.25) * detmath::sin_cycles_generic(v);
    }
    V a = sum * k.gain;
    a = a < lo ? lo : a;
    a = hi < a ? hi : a;
    std::memcpy(out + i, &a, live * sizeof(double));
  }
}

using PointsKernel = void (*)(const SpectralPoints&, const double*, const double*, double*, std::size_t);

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void spectral_points_avx512(const SpectralPoints& k, const double* xs, const double* ys,
                                                               double* out, std::size_t n) {
  spectral_points_lanes<8>(k, xs, ys, out, n);
}
__attribute__((target("avx2"))) void spectral_points_avx2(const SpectralPoints& k, const double* xs, const double* ys,
                                                          double* out, std::size_t n) {
  spectral_points_lanes<4>(k, xs, ys, out, n);
}
#endif
void spectral_points_generic(const SpectralPoints& k, const double* xs, const double* ys, double* out, std::size_t n) {
  spectral_points_lanes<2>(k, xs, ys, out, n);
}

PointsKernel points_kernel() {
  static const PointsKernel kernel = widest<PointsKernel>(TEXEL_LANE_KERNELS(spectral_points));
  return kernel;
}

// sin_cycles in place, a vector at a time (sin_cycles_generic's lanes: the
// scalar bits).
template <int W>
[[gnu::always_inline]] inline void sines_lanes(double* v, std::size_t n) {
  using V = typename detail::Lanes<W>::type;
  std::size_t i = 0;
  for (; i + W <= n; i += W) {
    V u;
    std::memcpy(&u, v + i, sizeof u);
    u = detmath::sin_cycles_generic(u);
    std::memcpy(v + i, &u, sizeof u);
  }
  for (; i < n; ++i) v[i] = detmath::sin_cycles(v[i]);
}
using SinesKernel = void (*)(double*, std::size_t);
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void sines_avx512(double* v, std::size_t n) { sines_lanes<8>(v, n); }
__attribute__((target("avx2"))) void sines_avx2(double* v, std::size_t n) { sines_lanes<4>(v, n); }
#endif
void sines_generic(double* v, std::size_t n) { sines_lanes<2>(v, n); }
void sines(std::span<double> v) {
  static const SinesKernel kernel = widest<SinesKernel>(TEXEL_LANE_KERNELS(sines));
  kernel(v.data(), v.size());
}

}  // namespace

PitchDistribution cosine_corrected(const PitchDistribution& line) {
  // Scans see a radial frequency q at q·|cos θ|: the 1-D lognormal moved up
  // by the law's mean (+3.01 dB) and narrowed by its variance where the 1-D
  // spread allows (§11.1).
  const double mean_shift = -cosine_law_mean_db * ln10 / 10.0;
  const double law_sd = cosine_law_sd_db * ln10 / 10.0;
  const double sigma = std::sqrt(std::max(line.sigma() * line.sigma() - law_sd * law_sd, 0.0));
  PitchDistributionConfig c = line.config();
  c.parameterization = Parameterization::log;
  c.central_pitch = Decibels((line.mu() + mean_shift) * 10.0 / ln10);
  c.irregularity = Decibels(sigma * 10.0 / ln10);
  try {
    return PitchDistribution(c);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("2-D field (the 1-D distribution moved up by 3.01 dB for the cosine law): ") + e.what());
  }
}

PitchDistribution surface2d_detail::line_distribution(const TexelSpec& spec, CyclesPerMm band_top) {
  return PitchDistribution(distribution_config(spec, band_top));
}

FineField2D::FineField2D(const TexelSpec& spec, Field2D design, double orientation_deg, CyclesPerMm band_top)
    : spec_(spec), design_(design) {
  validate(spec);
  if (!(std::isfinite(band_top.value()) && band_top.value() > 0.0))
    throw InvalidArgument("the 2-D field's band top is " + detail::num(band_top.value()) + " cpm; it must be > 0");
  const PitchDistribution line = surface2d_detail::line_distribution(spec, band_top);
  switch (design) {
    case Field2D::cells: cells_ = std::make_unique<PitchDistribution>(cosine_corrected(line)); break;
    case Field2D::spectral: {
      const IsotropicBound bound = isotropic_bound(line, CyclesPerMm(line.config().band_max.value()));
      const std::size_t bins = bound.radial.size();
      std::vector<double> cdf(bins + 1, 0.0);
      for (std::size_t j = 0; j < bins; ++j) {
        const double q0 = bound.frequency[j];
        const double q1 = j + 1 < bins ? bound.frequency[j + 1] : q0 * (bound.frequency[1] / bound.frequency[0]);
        cdf[j + 1] = cdf[j] + bound.matched_radial[j] * (q1 * q1 - q0 * q0);  // power in the annulus ∝ S2·(q1² − q0²)
      }
      const CounterRng rng(spec.seed, stream_spectral);
      const double turn0 = rng.uniform(0);
      constexpr double golden = 0.61803398874989484820;
      components_.resize(spectral_components);
      for (int c = 0; c < spectral_components; ++c) {
        // Stratified in the radial CDF, golden-ratio directions: every
        // frequency band is spread evenly over the half-turn.
        const double u = (static_cast<double>(c) + rng.uniform(3 * static_cast<std::uint64_t>(c) + 1)) /
                         static_cast<double>(spectral_components) * cdf[bins];
        const std::size_t j = std::min<std::size_t>(
            static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()) - 1, bins - 1);
        const double q0 = bound.frequency[j];
        const double q1 = j + 1 < bins ? bound.frequency[j + 1] : q0 * (bound.frequency[1] / bound.frequency[0]);
        const double width = cdf[j + 1] - cdf[j];
        const double frac = width > 0.0 ? (u - cdf[j]) / width : 0.5;
        Component& k = components_[static_cast<std::size_t>(c)];
        k.frequency = q0 + (q1 - q0) * std::clamp(frac, 0.0, 1.0);
        const double turn = detmath::floor_exact(turn0 + golden * static_cast<double>(c));
        const double half_turn = 0.5 * (turn0 + golden * static_cast<double>(c) - turn);
        k.cos_dir = detmath::cos_cycles(half_turn);
        k.sin_dir = detmath::sin_cycles(half_turn);
        k.phase = rng.uniform(3 * static_cast<std::uint64_t>(c) + 2);
      }
      // A sum of N unit sinusoids has RMS √(N/2): scaled to RMS 1/3, so that
      // clipping to [−1, 1] touches 0.3 % of the field.
      spectral_gain_ = (1.0 / 3.0) / std::sqrt(0.5 * spectral_components);
      break;
    }
    case Field2D::oriented: {
      if (!std::isfinite(orientation_deg))
        throw InvalidArgument("orientation_deg is " + detail::num(orientation_deg) + "; it must be finite");
      cos_n_ = detmath::cos_cycles(orientation_deg / 360.0);
      sin_n_ = detmath::sin_cycles(orientation_deg / 360.0);
      TexelSpec fine = spec;
      fine.coarse_strength = 0.0;
      fine.fine_strength = 1.0;
      fine.coarse = ConstantProfile{};
      const double extent = 2.0 * oriented_extent_mm * 1.5;  // |x·cos + y·sin| < √2·extent
      const Sampling sampling{Grid{Millimetres(0.0), Millimetres(0.5 / band_top.value()), 1}, band_top};
      line_ = std::make_shared<const TexelTexture>(fine, Millimetres(extent), sampling);
      line_origin_ = extent / 2.0;
      break;
    }
  }
}

FineField2D::Cell FineField2D::cell(std::int64_t m, std::int64_t n) const {
  const std::uint64_t k = cell_index(m, n);
  const double turn = 0.5 * CounterRng(spec_.seed, stream_direction).uniform(k);
  return {cells_->draw(spec_.seed, k), detmath::cos_cycles(turn), detmath::sin_cycles(turn),
          CounterRng(spec_.seed, stream_cell_phase).uniform(k)};
}

double FineField2D::value(double x, double y) const {
  switch (design_) {
    case Field2D::cells: {
      const double L = spec_.texel_length.value();
      const auto m = static_cast<std::int64_t>(std::floor((x + TexelTexture::boundary_tolerance_mm) / L));
      const auto n = static_cast<std::int64_t>(std::floor((y + TexelTexture::boundary_tolerance_mm) / L));
      const Cell c = cell(m, n);
      const double dx = x - static_cast<double>(m) * L;
      const double dy = y - static_cast<double>(n) * L;
      return detmath::sin_cycles(c.phase + c.frequency * (c.cos_dir * dx + c.sin_dir * dy));
    }
    case Field2D::spectral: {
      // sin(2π(a·x + φ + b·y)) split into its x and y factors, as block() computes it.
      double sum = 0.0;
      for (const Component& k : components_) {
        const double u = k.frequency * k.cos_dir * x, v = k.phase + k.frequency * k.sin_dir * y;
        sum += detmath::sin_cycles(u) * detmath::cos_cycles(v) + detmath::cos_cycles(u) * detmath::sin_cycles(v);
      }
      return std::clamp(sum * spectral_gain_, -1.0, 1.0);
    }
    case Field2D::oriented: {
      const double t = x * cos_n_ + y * sin_n_ + line_origin_;
      // C = 0, F = 1: a = (1 + s)/2.
      return 2.0 * line_->sample(Millimetres(t)) - 1.0;
    }
  }
  return 0.0;
}

void FineField2D::block(std::int64_t first, std::size_t count, double pitch, double origin_x, std::span<const double> ys,
                        double* out, std::size_t stride) const {
  if (design_ == Field2D::oriented) {
    for (std::size_t r = 0; r < ys.size(); ++r) row(first, pitch, origin_x, ys[r], std::span<double>(out + r * stride, count));
    return;
  }
  if (design_ == Field2D::cells) {
    // value()'s arithmetic; the cells of a row of cells drawn once for all
    // the pixel rows that cross it (frequencies a run at a time).
    if (count == 0) return;
    const double L = spec_.texel_length.value();
    const auto cell_of = [&](double v) {
      return static_cast<std::int64_t>(cell_floor((v + TexelTexture::boundary_tolerance_mm) / L));
    };
    const std::int64_t m_lo = cell_of(static_cast<double>(first) * pitch - origin_x);
    const std::int64_t m_hi = cell_of(static_cast<double>(first + static_cast<std::int64_t>(count) - 1) * pitch - origin_x);
    const auto cells = static_cast<std::size_t>(m_hi - m_lo + 1);
    std::vector<Cell> cache(cells);
    std::vector<double> frequency(cells);
    std::int64_t cached_n = 0;
    bool have = false;
    for (std::size_t r = 0; r < ys.size(); ++r) {
      const double y = ys[r];
      const std::int64_t n = cell_of(y);
      if (!have || n != cached_n) {
        const std::uint64_t k0 = cell_index(m_lo, n);
        if (cell_index(m_hi, n) == k0 + (cells - 1)) {
          cells_->draw(spec_.seed, k0, frequency);
        } else {
          for (std::size_t j = 0; j < cells; ++j)
            frequency[j] = cells_->draw(spec_.seed, cell_index(m_lo + static_cast<std::int64_t>(j), n));
        }
        for (std::size_t j = 0; j < cells; ++j) {
          const std::uint64_t k = cell_index(m_lo + static_cast<std::int64_t>(j), n);
          const double turn = 0.5 * CounterRng(spec_.seed, stream_direction).uniform(k);
          cache[j] = {frequency[j], detmath::cos_cycles(turn), detmath::sin_cycles(turn),
                      CounterRng(spec_.seed, stream_cell_phase).uniform(k)};
        }
        cached_n = n;
        have = true;
      }
      const double dy = y - static_cast<double>(n) * L;
      double* line = out + r * stride;
      for (std::size_t k = 0; k < count; ++k) {
        const double x = static_cast<double>(first + static_cast<std::int64_t>(k)) * pitch - origin_x;
        const std::int64_t m = cell_of(x);
        const Cell& c = cache[static_cast<std::size_t>(m - m_lo)];
        const double dx = x - static_cast<double>(m) * L;
        line[k] = c.phase + c.frequency * (c.cos_dir * dx + c.sin_dir * dy);
      }
      sines(std::span<double>(line, count));
    }
    return;
  }
  const std::size_t n = components_.size();
  // y factors of every row (row-major: [r][c]), then the pixels a panel of
  // columns at a time (spectral_lanes).
  std::vector<double> sy(n * ys.size()), cy(n * ys.size()), fx(n);
  for (std::size_t r = 0; r < ys.size(); ++r)
    for (std::size_t c = 0; c < n; ++c) {
      const Component& k = components_[c];
      const double v = k.phase + k.frequency * k.sin_dir * ys[r];
      sy[r * n + c] = detmath::sin_cycles(v);
      cy[r * n + c] = detmath::cos_cycles(v);
    }
  for (std::size_t c = 0; c < n; ++c) fx[c] = components_[c].frequency * components_[c].cos_dir;
  const SpectralBlock b{fx.data(), sy.data(), cy.data(), n, ys.size(), spectral_gain_, pitch, origin_x};
  spectral_kernel()(b, first, count, out, stride);
}

void FineField2D::values(std::span<const double> xs, std::span<const double> ys, std::span<double> out) const {
  if (xs.size() != out.size() || ys.size() != out.size())
    throw InvalidArgument("FineField2D::values: " + std::to_string(xs.size()) + " x, " + std::to_string(ys.size()) + " y and " +
                          std::to_string(out.size()) + " outputs; the three must be equal");
  if (design_ != Field2D::spectral) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = value(xs[i], ys[i]);
    return;
  }
  points_kernel()({components_.data(), components_.size(), spectral_gain_}, xs.data(), ys.data(), out.data(), out.size());
}

void FineField2D::row(std::int64_t first, double pitch, double origin_x, double y, std::span<double> out) const {
  if (design_ == Field2D::spectral) {
    block(first, out.size(), pitch, origin_x, std::span<const double>(&y, 1), out.data(), out.size());
    return;
  }
  if (design_ != Field2D::cells) {
    for (std::size_t k = 0; k < out.size(); ++k)
      out[k] = value(static_cast<double>(first + static_cast<std::int64_t>(k)) * pitch - origin_x, y);
    return;
  }
  // value()'s arithmetic, a cell drawn once per run of pixels in it.
  const double L = spec_.texel_length.value();
  const auto n = static_cast<std::int64_t>(std::floor((y + TexelTexture::boundary_tolerance_mm) / L));
  const double dy = y - static_cast<double>(n) * L;
  std::int64_t last_m = 0;
  Cell c{};
  bool have = false;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double x = static_cast<double>(first + static_cast<std::int64_t>(k)) * pitch - origin_x;
    const auto m = static_cast<std::int64_t>(cell_floor((x + TexelTexture::boundary_tolerance_mm) / L));
    if (!have || m != last_m) {
      c = cell(m, n);
      last_m = m;
      have = true;
    }
    const double dx = x - static_cast<double>(m) * L;
    out[k] = c.phase + c.frequency * (c.cos_dir * dx + c.sin_dir * dy);
  }
  // The sines in a second pass, a vector of pixels at a time (the same
  // operations per pixel as value()).
  sines(out);
}

}  // namespace texel
