// The fine fields of the 2-D model (docs/algorithm.md §11).
#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

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

// ---- The tile design (§11.2): periodic tiles by an inverse FFT, cubic B-splines between samples.

constexpr std::size_t tile_n = FineField2D::tile_samples;
constexpr std::size_t tile_row = tile_n + 3;  // a row and its first 3 samples again (the taps never wrap)
constexpr std::int64_t tile_mask = static_cast<std::int64_t>(tile_n) - 1;
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

// block()'s tile kernels with explicit lanes, each lane doing tap_row's or
// tap_column's operations in their order (so every width gives value()'s
// bits). The x taps of a chunk of columns are structure-of-arrays: first
// sample ix[k], weights w[d·wstride + k].

/// A tile row's x taps over n columns: dst[k] = tap_row(row, ix[k], w·k).
/// AVX2 and AVX-512 gather the four samples of W columns at a time.
void tile_x_from(const float* row, const std::int64_t* ix, const double* w, std::size_t wstride, double* dst, std::size_t n,
                 std::size_t k) {
  for (; k < n; ++k) {
    const float* s = row + (ix[k] & tile_mask);
    dst[k] = w[k] * s[0] + w[wstride + k] * s[1] + w[2 * wstride + k] * s[2] + w[3 * wstride + k] * s[3];
  }
}
#if defined(__x86_64__) || defined(__i386__)
// GCC 12 warns of the intrinsics' own undefined pass-through vectors.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
__attribute__((target("avx512f"))) void tile_x_avx512(const float* row, const std::int64_t* ix, const double* w,
                                                      std::size_t wstride, double* dst, std::size_t n) {
  const __m512i mask = _mm512_set1_epi64(tile_mask);
  std::size_t k = 0;
  for (; k + 8 <= n; k += 8) {
    const __m512i i = _mm512_and_si512(_mm512_loadu_si512(ix + k), mask);
    __m512d acc = _mm512_mul_pd(_mm512_loadu_pd(w + k), _mm512_cvtps_pd(_mm512_i64gather_ps(i, row, 4)));
    for (std::size_t d = 1; d < 4; ++d)
      acc = _mm512_add_pd(
          acc, _mm512_mul_pd(_mm512_loadu_pd(w + d * wstride + k), _mm512_cvtps_pd(_mm512_i64gather_ps(i, row + d, 4))));
    _mm512_storeu_pd(dst + k, acc);
  }
  tile_x_from(row, ix, w, wstride, dst, n, k);
}
__attribute__((target("avx2"))) void tile_x_avx2(const float* row, const std::int64_t* ix, const double* w, std::size_t wstride,
                                                 double* dst, std::size_t n) {
  const __m256i mask = _mm256_set1_epi64x(tile_mask);
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    const __m256i i = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(ix + k)), mask);
    __m256d acc = _mm256_mul_pd(_mm256_loadu_pd(w + k), _mm256_cvtps_pd(_mm256_i64gather_ps(row, i, 4)));
    for (std::size_t d = 1; d < 4; ++d)
      acc = _mm256_add_pd(
          acc, _mm256_mul_pd(_mm256_loadu_pd(w + d * wstride + k), _mm256_cvtps_pd(_mm256_i64gather_ps(row + d, i, 4))));
    _mm256_storeu_pd(dst + k, acc);
  }
  tile_x_from(row, ix, w, wstride, dst, n, k);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif
void tile_x_generic(const float* row, const std::int64_t* ix, const double* w, std::size_t wstride, double* dst, std::size_t n) {
  tile_x_from(row, ix, w, wstride, dst, n, 0);
}

/// A pixel row's y taps over four x-interpolated rows a0 … a3 (a·n apart):
/// o[k] = 0.0 + tap_column (the first band: value()'s sum starts at 0.0) or
/// o[k] += tap_column; the last band clamps to [−1, 1] as std::clamp does.
template <int W>
[[gnu::always_inline]] inline void tile_y_lanes(const double* w, const double* a, std::size_t n, double* o, bool first_band,
                                                bool last_band) {
  using V = typename detail::Lanes<W>::type;
  const double *a0 = a, *a1 = a + n, *a2 = a + 2 * n, *a3 = a + 3 * n;
  const V w0 = V{} + w[0], w1 = V{} + w[1], w2 = V{} + w[2], w3 = V{} + w[3], lo = V{} - 1.0, hi = V{} + 1.0;
  // No lambda here: a lambda does not take the caller's target attribute,
  // and one returning a wide vector uncalled-inline (clang -O0, sanitizer
  // builds) passes it by another ABI than the caller reads.
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    V x0, x1, x2, x3, v;
    std::memcpy(&x0, a0 + k, sizeof x0);
    std::memcpy(&x1, a1 + k, sizeof x1);
    std::memcpy(&x2, a2 + k, sizeof x2);
    std::memcpy(&x3, a3 + k, sizeof x3);
    const V c = w0 * x0 + w1 * x1 + w2 * x2 + w3 * x3;
    if (first_band) {
      v = 0.0 + c;
    } else {
      std::memcpy(&v, o + k, sizeof v);
      v = v + c;
    }
    if (last_band) v = v < lo ? lo : (hi < v ? hi : v);
    std::memcpy(o + k, &v, sizeof v);
  }
  for (; k < n; ++k) {
    const double c = tap_column(w, a0[k], a1[k], a2[k], a3[k]);
    const double v = first_band ? 0.0 + c : o[k] + c;
    o[k] = last_band ? std::clamp(v, -1.0, 1.0) : v;
  }
}
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void tile_y_avx512(const double* w, const double* a, std::size_t n, double* o, bool first,
                                                      bool last) {
  tile_y_lanes<8>(w, a, n, o, first, last);
}
__attribute__((target("avx2"))) void tile_y_avx2(const double* w, const double* a, std::size_t n, double* o, bool first,
                                                 bool last) {
  tile_y_lanes<4>(w, a, n, o, first, last);
}
#endif
void tile_y_generic(const double* w, const double* a, std::size_t n, double* o, bool first, bool last) {
  tile_y_lanes<2>(w, a, n, o, first, last);
}
using TileXKernel = void (*)(const float*, const std::int64_t*, const double*, std::size_t, double*, std::size_t);
using TileYKernel = void (*)(const double*, const double*, std::size_t, double*, bool, bool);

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
  static const TileXKernel tile_x = widest<TileXKernel>(TEXEL_LANE_KERNELS(tile_x));
  static const TileYKernel tile_y = widest<TileYKernel>(TEXEL_LANE_KERNELS(tile_y));
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
