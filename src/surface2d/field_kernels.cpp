// The fine fields' vectorised kernels (field_kernels.hpp, docs/algorithm.md
// §11): explicit lanes (texel/detail/lanes.hpp) and, for the tile design's
// gathers, AVX2 / AVX-512 intrinsics; the same bits at every width.
#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "field_kernels.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/detmath.hpp"

namespace texel::field_kernels {
namespace {

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

}  // namespace

SpectralKernel spectral_kernel() {
  static const SpectralKernel kernel = widest<SpectralKernel>(TEXEL_LANE_KERNELS(spectral));
  return kernel;
}

PointsKernel points_kernel() {
  static const PointsKernel kernel = widest<PointsKernel>(TEXEL_LANE_KERNELS(spectral_points));
  return kernel;
}

void sines(std::span<double> v) {
  static const SinesKernel kernel = widest<SinesKernel>(TEXEL_LANE_KERNELS(sines));
  kernel(v.data(), v.size());
}

TileXKernel tile_x_kernel() { return widest<TileXKernel>(TEXEL_LANE_KERNELS(tile_x)); }

TileYKernel tile_y_kernel() { return widest<TileYKernel>(TEXEL_LANE_KERNELS(tile_y)); }

}  // namespace texel::field_kernels
