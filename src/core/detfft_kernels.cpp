// detfft_kernels: the element-wise loops of detfft in explicit SIMD lanes,
// and the scalar code they were written from. See
// src/internal/texel/detail/detfft_kernels.hpp for why the bits never depend
// on the width.
#include "texel/detail/detfft_kernels.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>

#include "texel/detail/lanes.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"

namespace texel::detail {
namespace {

// ------------------------------------------------------------ width 1: the scalar reference

/// c·q modulo 1 as first written: an integer q, std::round.
double reference_cycles_times(TwoDouble c, std::uint64_t q) {
  const auto qd = static_cast<double>(q);
  const TwoDouble p = two_product(c.hi, qd);
  const double w = p.hi - std::round(p.hi);
  const double v = w + (p.lo + c.lo * qd);
  return v - std::round(v);
}

void reference_dif_butterflies(double* ar, double* ai, double* br, double* bi, const double* c, const double* s, std::size_t n) {
  for (std::size_t j = 0; j < n; ++j) {
    const double wr = c[j];
    const double wi = s[j];
    const double xr = ar[j];
    const double xi = ai[j];
    const double yr = br[j];
    const double yi = bi[j];
    ar[j] = xr + yr;
    ai[j] = xi + yi;
    const double dr = xr - yr;
    const double di = xi - yi;
    br[j] = dr * wr - di * wi;
    bi[j] = dr * wi + di * wr;
  }
}

void reference_dit_butterflies(double* ar, double* ai, double* br, double* bi, const double* c, const double* s, std::size_t n) {
  for (std::size_t j = 0; j < n; ++j) {
    const double wr = c[j];
    const double wi = s[j];
    const double yr = br[j];
    const double yi = bi[j];
    const double tr = yr * wr + yi * wi;
    const double ti = yi * wr - yr * wi;
    const double xr = ar[j];
    const double xi = ai[j];
    ar[j] = xr + tr;
    ai[j] = xi + ti;
    br[j] = xr - tr;
    bi[j] = xi - ti;
  }
}

void reference_dif_stage(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {
  for (std::size_t base = 0; base < n; base += 2 * h)
    reference_dif_butterflies(re + base, im + base, re + base + h, im + base + h, c, s, h);
}

void reference_dit_stage(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {
  for (std::size_t base = 0; base < n; base += 2 * h)
    reference_dit_butterflies(re + base, im + base, re + base + h, im + base + h, c, s, h);
}

void reference_dif_two_stages(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {
  reference_dif_stage(re, im, n, h, c + h - 1, s + h - 1);
  reference_dif_stage(re, im, n, h / 2, c + h / 2 - 1, s + h / 2 - 1);
}

void reference_dit_two_stages(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {
  reference_dit_stage(re, im, n, h / 2, c + h / 2 - 1, s + h / 2 - 1);
  reference_dit_stage(re, im, n, h, c + h - 1, s + h - 1);
}

void reference_multiply_spectra(double* ur, double* ui, const double* vr, const double* vi, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const double xr = ur[i];
    const double xi = ui[i];
    ur[i] = xr * vr[i] - xi * vi[i];
    ui[i] = xr * vi[i] + xi * vr[i];
  }
}

void reference_twiddles(double j0, double scale, std::size_t n, double* c, double* s) {
  const int e = std::ilogb(scale);  // scale = 2^e
  for (std::size_t x = 0; x < n; ++x) {
    const double u = std::ldexp(j0 + static_cast<double>(x), e);
    c[x] = detmath::cos_cycles(u);
    s[x] = -detmath::sin_cycles(u);
  }
}

void reference_chirp_kernel(const ChirpPhases& p, double d0, double step, std::size_t n, double* re, double* im) {
  for (std::size_t x = 0; x < n; ++x) {
    const auto d = static_cast<std::uint64_t>(step > 0 ? d0 + static_cast<double>(x) : d0 - static_cast<double>(x));
    const double c = reference_cycles_times(p.half_theta, d * d);
    re[x] = detmath::cos_cycles(c) * p.inv_m;
    im[x] = -detmath::sin_cycles(c) * p.inv_m;
  }
}

void reference_chirp_input(const ChirpPhases& p, TwoDouble alpha, double j0, std::size_t n, double* amplitude_re,
                           double* phase_im) {
  const auto first = static_cast<std::uint64_t>(p.first);
  for (std::size_t x = 0; x < n; ++x) {
    const std::uint64_t j = static_cast<std::uint64_t>(j0) + x;
    const double a = phase_im[x] + reference_cycles_times(alpha, first + j) + reference_cycles_times(p.half_theta, j * j);
    const double amp = amplitude_re[x];
    amplitude_re[x] = amp * detmath::cos_cycles(a);
    phase_im[x] = amp * detmath::sin_cycles(a);
  }
}

void reference_chirp_output(const ChirpPhases& p, double t0, std::size_t n, const double* zr, const double* zi, double* out) {
  for (std::size_t x = 0; x < n; ++x) {
    const std::uint64_t t = static_cast<std::uint64_t>(t0) + x;
    const double b = reference_cycles_times(p.half_theta, t * t) + reference_cycles_times(p.first_theta, t);
    out[x] = detmath::sin_cycles(b) * zr[x] + detmath::cos_cycles(b) * zi[x];
  }
}

// ------------------------------------------------------------ the same, generic over double and lanes

template <int W>
using Vec = typename Lanes<W>::type;

template <class T>
[[gnu::always_inline]] inline T load(const double* p) {
  if constexpr (std::is_same_v<T, double>) {
    return *p;
  } else {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
}

template <class T>
[[gnu::always_inline]] inline void store(double* p, T v) {
  if constexpr (std::is_same_v<T, double>)
    *p = v;
  else
    std::memcpy(p, &v, sizeof v);
}

/// base, base + 1, … in the lanes (whole numbers below 2^53: exact).
template <class T>
[[gnu::always_inline]] inline T iota(double base) {
  if constexpr (std::is_same_v<T, double>) {
    return base;
  } else {
    T v;
    for (std::size_t l = 0; l < sizeof(T) / sizeof(double); ++l) v[l] = base + static_cast<double>(l);
    return v;
  }
}

template <class T>
[[gnu::always_inline]] inline void dif_values(T& ar, T& ai, T& br, T& bi, T wr, T wi) {
  const T xr = ar;
  const T xi = ai;
  const T yr = br;
  const T yi = bi;
  ar = xr + yr;
  ai = xi + yi;
  const T dr = xr - yr;
  const T di = xi - yi;
  br = dr * wr - di * wi;
  bi = dr * wi + di * wr;
}

template <class T>
[[gnu::always_inline]] inline void dit_values(T& ar, T& ai, T& br, T& bi, T wr, T wi) {
  const T yr = br;
  const T yi = bi;
  const T tr = yr * wr + yi * wi;
  const T ti = yi * wr - yr * wi;
  const T xr = ar;
  const T xi = ai;
  ar = xr + tr;
  ai = xi + ti;
  br = xr - tr;
  bi = xi - ti;
}

template <class T, bool Dif>
[[gnu::always_inline]] inline void butterfly_at(double* ar, double* ai, double* br, double* bi, const double* c, const double* s,
                                                std::size_t j) {
  T xr = load<T>(ar + j);
  T xi = load<T>(ai + j);
  T yr = load<T>(br + j);
  T yi = load<T>(bi + j);
  if constexpr (Dif)
    dif_values(xr, xi, yr, yi, load<T>(c + j), load<T>(s + j));
  else
    dit_values(xr, xi, yr, yi, load<T>(c + j), load<T>(s + j));
  store(ar + j, xr);
  store(ai + j, xi);
  store(br + j, yr);
  store(bi + j, yi);
}

template <int W, bool Dif>
[[gnu::always_inline]] inline void butterflies_lanes(double* ar, double* ai, double* br, double* bi, const double* c,
                                                     const double* s, std::size_t n) {
  std::size_t j = 0;
  for (; j + W <= n; j += W) butterfly_at<Vec<W>, Dif>(ar, ai, br, bi, c, s, j);
  for (; j < n; ++j) butterfly_at<double, Dif>(ar, ai, br, bi, c, s, j);
}

// A stage of span H below the width W, over 2W points (W/H groups) at a
// time: lane l of the first operands holds point (l/H)·2H + l%H, its partner
// is H further, and the results go back to the same places.
template <int W, int H, int Offset, std::size_t... L>
[[gnu::always_inline]] inline Vec<W> pick(Vec<W> lo, Vec<W> hi, std::index_sequence<L...>) {
  return __builtin_shufflevector(lo, hi, (static_cast<int>(L) / H * 2 * H + static_cast<int>(L) % H + Offset)...);
}

/// Where point e of the 2W lies among (first operands, second operands).
constexpr int merged(int e, int w, int h) {
  const int g = e / (2 * h);
  const int r = e % (2 * h);
  return r < h ? g * h + r : w + g * h + r - h;
}

template <int W, int H, int Offset, std::size_t... L>
[[gnu::always_inline]] inline Vec<W> merge(Vec<W> a, Vec<W> b, std::index_sequence<L...>) {
  return __builtin_shufflevector(a, b, merged(static_cast<int>(L) + Offset, W, H)...);
}

template <int W, int H, bool Dif>
[[gnu::always_inline]] inline void short_stage_lanes(double* re, double* im, std::size_t n, const double* c, const double* s) {
  using V = Vec<W>;
  constexpr auto uw = static_cast<std::size_t>(W);
  constexpr auto lanes = std::make_index_sequence<uw>{};
  V wr;
  V wi;
  for (int l = 0; l < W; ++l) {
    wr[l] = c[l % H];
    wi[l] = s[l % H];
  }
  for (std::size_t base = 0; base < n; base += 2 * uw) {
    const V r0 = load<V>(re + base);
    const V r1 = load<V>(re + base + uw);
    const V i0 = load<V>(im + base);
    const V i1 = load<V>(im + base + uw);
    V ar = pick<W, H, 0>(r0, r1, lanes);
    V br = pick<W, H, H>(r0, r1, lanes);
    V ai = pick<W, H, 0>(i0, i1, lanes);
    V bi = pick<W, H, H>(i0, i1, lanes);
    if constexpr (Dif)
      dif_values(ar, ai, br, bi, wr, wi);
    else
      dit_values(ar, ai, br, bi, wr, wi);
    store(re + base, merge<W, H, 0>(ar, br, lanes));
    store(re + base + uw, merge<W, H, W>(ar, br, lanes));
    store(im + base, merge<W, H, 0>(ai, bi, lanes));
    store(im + base + uw, merge<W, H, W>(ai, bi, lanes));
  }
}

template <int W, bool Dif>
[[gnu::always_inline]] inline void stage_lanes(double* re, double* im, std::size_t n, std::size_t h, const double* c,
                                               const double* s) {
  constexpr auto uw = static_cast<std::size_t>(W);
  if (h < uw && n % (2 * uw) == 0) {
    if (h == 1) return short_stage_lanes<W, 1, Dif>(re, im, n, c, s);
    if constexpr (W >= 4)
      if (h == 2) return short_stage_lanes<W, 2, Dif>(re, im, n, c, s);
    if constexpr (W >= 8)
      if (h == 4) return short_stage_lanes<W, 4, Dif>(re, im, n, c, s);
  }
  for (std::size_t base = 0; base < n; base += 2 * h)
    butterflies_lanes<W, Dif>(re + base, im + base, re + base + h, im + base + h, c, s, h);
}

// Two stages in one sweep: span h and span q = h/2 (decimation in frequency:
// h first; in time: q first) on the quads (base + j, + q, + h, + h + q) of
// each group of 2h points. Every butterfly is a single stage's, on the same
// values, in an order that keeps each one after the butterflies it reads
// from; the quads only save the loads and stores of a second sweep.
template <int W, bool Dif>
[[gnu::always_inline]] inline void two_stages_lanes(double* re, double* im, std::size_t n, std::size_t h, const double* c,
                                                    const double* s) {
  using V = Vec<W>;
  const std::size_t q = h / 2;
  if (q < static_cast<std::size_t>(W)) {
    const std::size_t first = Dif ? h : q;
    const std::size_t second = Dif ? q : h;
    stage_lanes<W, Dif>(re, im, n, first, c + first - 1, s + first - 1);
    stage_lanes<W, Dif>(re, im, n, second, c + second - 1, s + second - 1);
    return;
  }
  const double* ch = c + h - 1;
  const double* sh = s + h - 1;
  const double* cq = c + q - 1;
  const double* sq = s + q - 1;
  for (std::size_t base = 0; base < n; base += 2 * h) {
    double* r = re + base;
    double* i = im + base;
    for (std::size_t j = 0; j < q; j += W) {  // q is a multiple of W
      V r0 = load<V>(r + j);
      V i0 = load<V>(i + j);
      V r1 = load<V>(r + j + q);
      V i1 = load<V>(i + j + q);
      V r2 = load<V>(r + j + h);
      V i2 = load<V>(i + j + h);
      V r3 = load<V>(r + j + h + q);
      V i3 = load<V>(i + j + h + q);
      if constexpr (Dif) {
        dif_values(r0, i0, r2, i2, load<V>(ch + j), load<V>(sh + j));
        dif_values(r1, i1, r3, i3, load<V>(ch + j + q), load<V>(sh + j + q));
        dif_values(r0, i0, r1, i1, load<V>(cq + j), load<V>(sq + j));
        dif_values(r2, i2, r3, i3, load<V>(cq + j), load<V>(sq + j));
      } else {
        dit_values(r0, i0, r1, i1, load<V>(cq + j), load<V>(sq + j));
        dit_values(r2, i2, r3, i3, load<V>(cq + j), load<V>(sq + j));
        dit_values(r0, i0, r2, i2, load<V>(ch + j), load<V>(sh + j));
        dit_values(r1, i1, r3, i3, load<V>(ch + j + q), load<V>(sh + j + q));
      }
      store(r + j, r0);
      store(i + j, i0);
      store(r + j + q, r1);
      store(i + j + q, i1);
      store(r + j + h, r2);
      store(i + j + h, i2);
      store(r + j + h + q, r3);
      store(i + j + h + q, i3);
    }
  }
}

// Element x of each loop below, for T = a lane vector (x, x + 1, …) or double.

template <class T>
[[gnu::always_inline]] inline void multiply_at(double* ur, double* ui, const double* vr, const double* vi, std::size_t i) {
  const T xr = load<T>(ur + i);
  const T xi = load<T>(ui + i);
  const T yr = load<T>(vr + i);
  const T yi = load<T>(vi + i);
  store(ur + i, xr * yr - xi * yi);
  store(ui + i, xr * yi + xi * yr);
}

template <class T>
[[gnu::always_inline]] inline void twiddles_at(double j0, double scale, double* c, double* s, std::size_t x) {
  const T u = iota<T>(j0 + static_cast<double>(x)) * scale;
  store(c + x, detmath::sin_cycles_generic(u + 0.25));  // cos_cycles(u)
  store(s + x, -detmath::sin_cycles_generic(u));
}

template <class T>
[[gnu::always_inline]] inline void chirp_kernel_at(const ChirpPhases& p, double d0, double step, double* re, double* im,
                                                   std::size_t x) {
  const T d = d0 + step * iota<T>(static_cast<double>(x));
  const T c = cycles_times(p.half_theta, d * d);
  store(re + x, detmath::sin_cycles_generic(c + 0.25) * p.inv_m);
  store(im + x, -detmath::sin_cycles_generic(c) * p.inv_m);
}

template <class T>
[[gnu::always_inline]] inline void chirp_input_at(const ChirpPhases& p, TwoDouble alpha, double j0, double* amplitude_re,
                                                  double* phase_im, std::size_t x) {
  const T j = iota<T>(j0 + static_cast<double>(x));
  const T a = load<T>(phase_im + x) + cycles_times(alpha, p.first + j) + cycles_times(p.half_theta, j * j);
  const T amp = load<T>(amplitude_re + x);
  store(amplitude_re + x, amp * detmath::sin_cycles_generic(a + 0.25));
  store(phase_im + x, amp * detmath::sin_cycles_generic(a));
}

template <class T>
[[gnu::always_inline]] inline void chirp_output_at(const ChirpPhases& p, double t0, const double* zr, const double* zi,
                                                   double* out, std::size_t x) {
  const T t = iota<T>(t0 + static_cast<double>(x));
  const T b = cycles_times(p.half_theta, t * t) + cycles_times(p.first_theta, t);
  const T y = detmath::sin_cycles_generic(b) * load<T>(zr + x) + detmath::sin_cycles_generic(b + 0.25) * load<T>(zi + x);
  store(out + x, y);
}

// The loops: whole vectors, then the remainder one double at a time.

template <int W>
[[gnu::always_inline]] inline void multiply_lanes(double* ur, double* ui, const double* vr, const double* vi, std::size_t n) {
  std::size_t i = 0;
  for (; i + W <= n; i += W) multiply_at<Vec<W>>(ur, ui, vr, vi, i);
  for (; i < n; ++i) multiply_at<double>(ur, ui, vr, vi, i);
}

template <int W>
[[gnu::always_inline]] inline void twiddles_lanes(double j0, double scale, std::size_t n, double* c, double* s) {
  std::size_t x = 0;
  for (; x + W <= n; x += W) twiddles_at<Vec<W>>(j0, scale, c, s, x);
  for (; x < n; ++x) twiddles_at<double>(j0, scale, c, s, x);
}

template <int W>
[[gnu::always_inline]] inline void chirp_kernel_lanes(const ChirpPhases& p, double d0, double step, std::size_t n, double* re,
                                                      double* im) {
  std::size_t x = 0;
  for (; x + W <= n; x += W) chirp_kernel_at<Vec<W>>(p, d0, step, re, im, x);
  for (; x < n; ++x) chirp_kernel_at<double>(p, d0, step, re, im, x);
}

template <int W>
[[gnu::always_inline]] inline void chirp_input_lanes(const ChirpPhases& p, TwoDouble alpha, double j0, std::size_t n,
                                                     double* amplitude_re, double* phase_im) {
  std::size_t x = 0;
  for (; x + W <= n; x += W) chirp_input_at<Vec<W>>(p, alpha, j0, amplitude_re, phase_im, x);
  for (; x < n; ++x) chirp_input_at<double>(p, alpha, j0, amplitude_re, phase_im, x);
}

template <int W>
[[gnu::always_inline]] inline void chirp_output_lanes(const ChirpPhases& p, double t0, std::size_t n, const double* zr,
                                                      const double* zi, double* out) {
  std::size_t x = 0;
  for (; x + W <= n; x += W) chirp_output_at<Vec<W>>(p, t0, zr, zi, out, x);
  for (; x < n; ++x) chirp_output_at<double>(p, t0, zr, zi, out, x);
}

// One table per width: the same templates compiled for each instruction set
// (GCC drops a target attribute from a template, so each width's entry
// points are spelled out by this macro).
#define TEXEL_FFT_KERNELS(W, ATTRIBUTE)                                                                                       \
  ATTRIBUTE void dif_butterflies_##W(double* ar, double* ai, double* br, double* bi, const double* c, const double* s,        \
                                     std::size_t n) {                                                                         \
    butterflies_lanes<W, true>(ar, ai, br, bi, c, s, n);                                                                      \
  }                                                                                                                           \
  ATTRIBUTE void dit_butterflies_##W(double* ar, double* ai, double* br, double* bi, const double* c, const double* s,        \
                                     std::size_t n) {                                                                         \
    butterflies_lanes<W, false>(ar, ai, br, bi, c, s, n);                                                                     \
  }                                                                                                                           \
  ATTRIBUTE void dif_stage_##W(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {      \
    stage_lanes<W, true>(re, im, n, h, c, s);                                                                                 \
  }                                                                                                                           \
  ATTRIBUTE void dit_stage_##W(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {      \
    stage_lanes<W, false>(re, im, n, h, c, s);                                                                                \
  }                                                                                                                           \
  ATTRIBUTE void dif_two_stages_##W(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) { \
    two_stages_lanes<W, true>(re, im, n, h, c, s);                                                                            \
  }                                                                                                                           \
  ATTRIBUTE void dit_two_stages_##W(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) { \
    two_stages_lanes<W, false>(re, im, n, h, c, s);                                                                           \
  }                                                                                                                           \
  ATTRIBUTE void multiply_spectra_##W(double* ur, double* ui, const double* vr, const double* vi, std::size_t n) {            \
    multiply_lanes<W>(ur, ui, vr, vi, n);                                                                                     \
  }                                                                                                                           \
  ATTRIBUTE void twiddles_##W(double j0, double scale, std::size_t n, double* c, double* s) {                                 \
    twiddles_lanes<W>(j0, scale, n, c, s);                                                                                    \
  }                                                                                                                           \
  ATTRIBUTE void chirp_kernel_##W(const ChirpPhases& p, double d0, double step, std::size_t n, double* re, double* im) {      \
    chirp_kernel_lanes<W>(p, d0, step, n, re, im);                                                                            \
  }                                                                                                                           \
  ATTRIBUTE void chirp_input_##W(const ChirpPhases& p, TwoDouble alpha, double j0, std::size_t n, double* re, double* im) {   \
    chirp_input_lanes<W>(p, alpha, j0, n, re, im);                                                                            \
  }                                                                                                                           \
  ATTRIBUTE void chirp_output_##W(const ChirpPhases& p, double t0, std::size_t n, const double* zr, const double* zi,         \
                                  double* out) {                                                                              \
    chirp_output_lanes<W>(p, t0, n, zr, zi, out);                                                                             \
  }                                                                                                                           \
  const FftKernels kernels_##W{W,                                                                                             \
                               &dif_butterflies_##W,                                                                          \
                               &dit_butterflies_##W,                                                                          \
                               &dif_stage_##W,                                                                                \
                               &dit_stage_##W,                                                                                \
                               &dif_two_stages_##W,                                                                           \
                               &dit_two_stages_##W,                                                                           \
                               &multiply_spectra_##W,                                                                         \
                               &twiddles_##W,                                                                                 \
                               &chirp_kernel_##W,                                                                             \
                               &chirp_input_##W,                                                                              \
                               &chirp_output_##W};

#if defined(__x86_64__) || defined(__i386__)
TEXEL_FFT_KERNELS(8, __attribute__((target("avx512f"))))
TEXEL_FFT_KERNELS(4, __attribute__((target("avx2"))))
#endif
TEXEL_FFT_KERNELS(2, )
#undef TEXEL_FFT_KERNELS

const FftKernels kernels_1{1,
                           &reference_dif_butterflies,
                           &reference_dit_butterflies,
                           &reference_dif_stage,
                           &reference_dit_stage,
                           &reference_dif_two_stages,
                           &reference_dit_two_stages,
                           &reference_multiply_spectra,
                           &reference_twiddles,
                           &reference_chirp_kernel,
                           &reference_chirp_input,
                           &reference_chirp_output};

}  // namespace

const FftKernels& fft_kernels(int lanes) {
  const int widest = simd_lanes();
  if (lanes == 0) lanes = widest;
  if (lanes == 1) return kernels_1;
  if (lanes == 2) return kernels_2;
#if defined(__x86_64__) || defined(__i386__)
  if (lanes == 4 && widest >= 4) return kernels_4;
  if (lanes == 8 && widest >= 8) return kernels_8;
#endif
  throw InvalidArgument("FFT kernels of " + std::to_string(lanes) + " lanes; this CPU runs 1, 2" + (widest >= 4 ? ", 4" : "") +
                        (widest >= 8 ? ", 8" : ""));
}

}  // namespace texel::detail
