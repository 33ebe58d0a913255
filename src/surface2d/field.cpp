// The fine fields of the 2-D model (docs/algorithm.md §11): the designs
// (cells, spectral, tile) prepared and evaluated point by point or a block
// at a time; their vectorised kernels are field_kernels.cpp.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "field_kernels.hpp"
#include "internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/detail/parallel.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"
#include "texel/surface2d.hpp"
#include "texel/texture.hpp"

namespace texel {

using namespace field_kernels;

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
constexpr std::uint64_t stream_tile = static_cast<std::uint64_t>(Stream::user) + 4;

/// std::floor, inline: floor_exact where it is exact (|v| < 2^51), the
/// library's beyond (a call per pixel otherwise: the baseline has no roundsd).
double cell_floor(double v) { return std::fabs(v) < 0x1p51 ? detmath::floor_exact(v) : std::floor(v); }

std::uint64_t cell_index(std::int64_t m, std::int64_t n) {
  const auto um = static_cast<std::uint64_t>(m + cell_bias) & cell_mask;
  const auto un = static_cast<std::uint64_t>(n + cell_bias) & cell_mask;
  return (un << 24) | um;
}

/// A radix-2 inverse complex FFT (x_j = Σ_k X_k e^{+2πijk/n}) of a power-of-two
/// length, twiddles from detmath: the same bits on every build.
class InverseFft {
 public:
  explicit InverseFft(std::size_t n) : n_(n), wr_(n / 2), wi_(n / 2), rev_(n) {
    for (std::size_t k = 0; k < n / 2; ++k) {
      const double turn = static_cast<double>(k) / static_cast<double>(n);
      wr_[k] = detmath::cos_cycles(turn);
      wi_[k] = detmath::sin_cycles(turn);
    }
    std::size_t bits = 0;
    while ((std::size_t{1} << bits) < n) ++bits;
    for (std::size_t i = 0; i < n; ++i) {
      std::size_t r = 0;
      for (std::size_t b = 0; b < bits; ++b)
        if (i & (std::size_t{1} << b)) r |= std::size_t{1} << (bits - 1 - b);
      rev_[i] = r;
    }
  }
  void operator()(double* re, double* im) const {
    for (std::size_t i = 0; i < n_; ++i)
      if (i < rev_[i]) {
        std::swap(re[i], re[rev_[i]]);
        std::swap(im[i], im[rev_[i]]);
      }
    for (std::size_t len = 2; len <= n_; len <<= 1) {
      const std::size_t half = len / 2, step = n_ / len;
      for (std::size_t i = 0; i < n_; i += len)
        for (std::size_t k = 0; k < half; ++k) {
          const double c = wr_[k * step], s = wi_[k * step];
          const double xr = re[i + k + half], xi = im[i + k + half];
          const double tr = c * xr - s * xi, ti = c * xi + s * xr;
          const double ur = re[i + k], ui = im[i + k];
          re[i + k] = ur + tr;
          im[i + k] = ui + ti;
          re[i + k + half] = ur - tr;
          im[i + k + half] = ui - ti;
        }
    }
  }

 private:
  std::size_t n_;
  std::vector<double> wr_, wi_;
  std::vector<std::size_t> rev_;
};

/// sinc⁴(u) = (sin πu/πu)⁴: the cubic B-spline's response at u cycles per sample.
double bspline_response(double u) {
  if (u == 0.0) return 1.0;
  const double s = detmath::sin_cycles(0.5 * u) / (3.14159265358979323846 * u);
  return (s * s) * (s * s);
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
    case Field2D::tile: build_tiles(line); break;
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

void FineField2D::build_tiles(const PitchDistribution& line) {
  // The moment fit's radial spectrum (isotropic_bound's matched_radial):
  // S2(q) = exp(−z²/2)/q², z = (ln q − μ')/σ', within the 1-D band, cut at
  // ±4σ' (all but 6·10⁻⁵ of the power).
  const PitchDistribution radial = [&] {
    try {
      return cosine_corrected(line);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("field 'tile': ") + e.what());
    }
  }();
  const double rmu = radial.mu(), rsigma = std::max(radial.sigma(), 0.02);
  const double lo_band = line.config().band_min.value(), hi_band = line.config().band_max.value();
  const double q_max = std::min(hi_band, detmath::exp(rmu + 4.0 * rsigma));
  const double q_min = std::max(lo_band, detmath::exp(rmu - 4.0 * rsigma));
  if (!(q_min < q_max))
    throw InvalidArgument("field 'tile': the texture's radial spectrum (" + detail::num(detmath::exp(rmu - 4.0 * rsigma)) +
                          " … " + detail::num(detmath::exp(rmu + 4.0 * rsigma)) + " cpm) lies outside its band " +
                          detail::num(lo_band) + " … " + detail::num(hi_band) +
                          " cpm (the bitmap's Nyquist frequency is too low for it)");
  const auto S2 = [&](double q) {
    const double z = (detmath::log(q) - rmu) / rsigma;
    return detmath::exp(-0.5 * z * z) / (q * q);
  };
  // Bands of equal log width, at most tile_band_ratio each, the highest first.
  const double span = detmath::log(q_max / q_min);
  const int bands = std::max(1, static_cast<int>(std::ceil(span / detmath::log(tile_band_ratio) - 1e-9)));
  const double ratio = detmath::exp(span / static_cast<double>(bands));
  constexpr auto half = static_cast<std::int64_t>(tile_n / 2);
  // Lattice frequencies (m, n)/T of the half-plane (n > 0, or n = 0 and m > 0:
  // a real field of cosines, one per frequency pair ±q) whose |q| is in the band.
  struct Mode {
    std::int64_t m, n;
    double power;  // S2(q)/T²: the field's power at this frequency
  };
  const auto band_modes = [&](const TileBand& b, std::vector<Mode>& out) {
    out.clear();
    const double T = b.period_mm();
    const auto reach = static_cast<std::int64_t>(std::ceil(b.q_hi * T));
    for (std::int64_t n = 0; n <= std::min(reach, half - 1); ++n)
      for (std::int64_t m = -std::min(reach, half - 1); m <= std::min(reach, half - 1); ++m) {
        if (n == 0 && m <= 0) continue;
        const double q = std::sqrt(static_cast<double>(m * m + n * n)) / T;
        if (q < b.q_lo || q >= b.q_hi) continue;
        out.push_back({m, n, S2(q) / (T * T)});
      }
  };
  std::vector<TileBand> spec(static_cast<std::size_t>(bands));
  double total = 0.0;
  std::vector<Mode> modes;
  for (int k = 0; k < bands; ++k) {
    TileBand& b = spec[static_cast<std::size_t>(k)];
    b.q_hi = k == 0 ? q_max : spec[static_cast<std::size_t>(k - 1)].q_lo;
    b.q_lo = k + 1 == bands ? q_min : b.q_hi / ratio;
    b.spacing_mm = 1.0 / (tile_oversampling * b.q_hi);
    band_modes(b, modes);
    b.modes = modes.size();
    for (const Mode& md : modes) total += md.power;
  }
  if (!(total > 0.0)) throw InvalidArgument("field 'tile': the texture's radial spectrum has no power on the tiles' lattices");
  // A cosine of amplitude A has power A²/2: A = √(2·power), scaled so that the
  // field's RMS is 1/3 (like spectral: clipping touches 0.3 % of it).
  const double gain = (1.0 / 3.0) / std::sqrt(total);
  const InverseFft fft(tile_n);
  const CounterRng rng(spec_.seed, stream_tile);
  for (int k = 0; k < bands; ++k) {
    Tile t;
    t.band = spec[static_cast<std::size_t>(k)];
    t.inv_spacing = 1.0 / t.band.spacing_mm;
    band_modes(t.band, modes);
    // The coefficients' spectrum, column m at a time (only the columns with
    // modes: |m| ≤ q_hi·T = N/oversampling), divided by the B-spline's response
    // so that the interpolated field has amplitude A at (m, n)/T.
    std::vector<std::int64_t> columns;
    for (const Mode& md : modes) columns.push_back(md.m);
    std::sort(columns.begin(), columns.end());
    columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
    const std::size_t nc = columns.size();
    std::vector<double> re(nc * tile_n, 0.0), im(nc * tile_n, 0.0);  // [column][n]
    for (const Mode& md : modes) {
      const auto c = static_cast<std::size_t>(std::lower_bound(columns.begin(), columns.end(), md.m) - columns.begin());
      const std::uint64_t counter = (static_cast<std::uint64_t>(k) << 32) | (static_cast<std::uint64_t>(md.n + half) << 16) |
                                    static_cast<std::uint64_t>(md.m + half);
      const double phase = rng.uniform(counter);
      const double amplitude = std::sqrt(2.0 * md.power) * gain /
                               (bspline_response(static_cast<double>(md.m) / static_cast<double>(tile_n)) *
                                bspline_response(static_cast<double>(md.n) / static_cast<double>(tile_n)));
      const std::size_t at = c * tile_n + static_cast<std::size_t>(md.n);
      re[at] = amplitude * detmath::cos_cycles(phase);
      im[at] = amplitude * detmath::sin_cycles(phase);
    }
    // Along y (n → row j) per column, then along x (m → sample i) per row;
    // the tile is the real part.
    // Each transform is independent: they are spread over the library's
    // threads (the same operations in any order: the same bits).
    const int workers = detail::worker_threads(8);
    detail::parallel_tasks(workers, nc, [&](std::size_t, std::size_t c) { fft(re.data() + c * tile_n, im.data() + c * tile_n); });
    t.samples.assign(tile_n * tile_row, 0.0F);
    const auto parts = static_cast<std::size_t>(std::max(workers, 1));
    detail::parallel_tasks(workers, parts, [&](std::size_t, std::size_t part) {
      std::vector<double> xr(tile_n), xi(tile_n);
      for (std::size_t j = tile_n * part / parts; j < tile_n * (part + 1) / parts; ++j) {
        std::fill(xr.begin(), xr.end(), 0.0);
        std::fill(xi.begin(), xi.end(), 0.0);
        for (std::size_t c = 0; c < nc; ++c) {
          const auto i = static_cast<std::size_t>(columns[c] & tile_mask);
          xr[i] = re[c * tile_n + j];
          xi[i] = im[c * tile_n + j];
        }
        fft(xr.data(), xi.data());
        float* row = t.samples.data() + j * tile_row;
        for (std::size_t i = 0; i < tile_n; ++i) row[i] = static_cast<float>(xr[i]);
        for (std::size_t i = 0; i < 3; ++i) row[tile_n + i] = row[i];
      }
    });
    tiles_.push_back(std::move(t));
  }
}

std::vector<FineField2D::TileBand> FineField2D::tile_bands() const {
  std::vector<TileBand> out;
  for (const Tile& t : tiles_) out.push_back(t.band);
  return out;
}

void FineField2D::tile_block(std::int64_t first, std::size_t count, double pitch, double origin_x, std::span<const double> ys,
                             double* out, std::size_t stride) const {
  const std::size_t rows = ys.size();
  // Columns a chunk at a time: their x taps once, then the tile rows the
  // block's rows reach interpolated along x once each, then every pixel row
  // a vector of y taps over them (value()'s operations: x first, then y).
  constexpr std::size_t chunk = 512;
  static const TileXKernel tile_x = tile_x_kernel();
  static const TileYKernel tile_y = tile_y_kernel();
  std::vector<std::int64_t> ix(chunk);
  std::vector<double> wx(4 * chunk), xrows;  // wx[d·chunk + k]
  std::vector<Taps> ty(rows);
  for (const Tile& t : tiles_) {
    const bool first_band = &t == tiles_.data(), last_band = &t == &tiles_.back();
    std::int64_t j_lo = 0, j_hi = -1;
    for (std::size_t r = 0; r < rows; ++r) {
      ty[r] = taps(ys[r], t.inv_spacing);
      j_lo = r == 0 ? ty[r].first : std::min(j_lo, ty[r].first);
      j_hi = r == 0 ? ty[r].first + 3 : std::max(j_hi, ty[r].first + 3);
    }
    // Rows far apart (not a strip): four tile rows per pixel row instead.
    const bool shared = j_hi - j_lo + 1 <= static_cast<std::int64_t>(4 * rows);
    for (std::size_t c0 = 0; c0 < count; c0 += chunk) {
      const std::size_t n = std::min(chunk, count - c0);
      for (std::size_t k = 0; k < n; ++k) {
        const double x = static_cast<double>(first + static_cast<std::int64_t>(c0 + k)) * pitch - origin_x;
        const Taps tx = taps(x, t.inv_spacing);
        ix[k] = tx.first;
        for (std::size_t d = 0; d < 4; ++d) wx[d * chunk + k] = tx.w[d];
      }
      const auto along_x = [&](std::int64_t j, double* dst) {
        tile_x(t.samples.data() + static_cast<std::size_t>(j & tile_mask) * tile_row, ix.data(), wx.data(), chunk, dst, n);
      };
      const auto along_y = [&](std::size_t r, const double* a) {
        tile_y(ty[r].w, a, n, out + r * stride + c0, first_band, last_band);
      };
      if (shared) {
        xrows.resize(static_cast<std::size_t>(j_hi - j_lo + 1) * n);
        for (std::int64_t j = j_lo; j <= j_hi; ++j) along_x(j, xrows.data() + static_cast<std::size_t>(j - j_lo) * n);
        for (std::size_t r = 0; r < rows; ++r) along_y(r, xrows.data() + static_cast<std::size_t>(ty[r].first - j_lo) * n);
      } else {
        xrows.resize(4 * n);
        for (std::size_t r = 0; r < rows; ++r) {
          for (std::int64_t d = 0; d < 4; ++d) along_x(ty[r].first + d, xrows.data() + static_cast<std::size_t>(d) * n);
          along_y(r, xrows.data());
        }
      }
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
    case Field2D::tile: {
      double sum = 0.0;
      for (const Tile& t : tiles_) {
        const Taps tx = taps(x, t.inv_spacing), ty = taps(y, t.inv_spacing);
        double c[4];
        for (std::int64_t d = 0; d < 4; ++d)
          c[d] = tap_row(t.samples.data() + static_cast<std::size_t>((ty.first + d) & tile_mask) * tile_row, tx.first, tx.w);
        sum += tap_column(ty.w, c[0], c[1], c[2], c[3]);
      }
      return std::clamp(sum, -1.0, 1.0);
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
  if (design_ == Field2D::tile) {
    tile_block(first, count, pitch, origin_x, ys, out, stride);
    return;
  }
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
  if (design_ == Field2D::spectral || design_ == Field2D::tile) {
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
