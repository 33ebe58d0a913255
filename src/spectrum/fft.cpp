#include "fft.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <kiss_fftr.h>

#include "texel/detail/lanes.hpp"
#include "texel/error.hpp"

namespace texel::detail {

struct RealFft::Impl {
  kiss_fftr_cfg cfg = nullptr;
  std::vector<kiss_fft_scalar> in;
  std::vector<kiss_fft_cpx> out;
};

RealFft::RealFft(std::size_t n) : n_(n), impl_(std::make_unique<Impl>()) {
  if (n < 2 || n % 2 != 0 || n > (std::size_t{1} << 30))
    throw InvalidArgument("FFT length " + std::to_string(n) + " must be even and 2 … 2^30");
  impl_->cfg = kiss_fftr_alloc(static_cast<int>(n), 0, nullptr, nullptr);
  if (!impl_->cfg) throw std::bad_alloc();
  impl_->in.resize(n);
  impl_->out.resize(n / 2 + 1);
}

RealFft::~RealFft() {
  if (impl_ && impl_->cfg) kiss_fftr_free(impl_->cfg);
}

void RealFft::forward(std::span<const double> in, std::span<std::complex<double>> out) {
  for (std::size_t i = 0; i < n_; ++i) impl_->in[i] = static_cast<kiss_fft_scalar>(in[i]);
  kiss_fftr(impl_->cfg, impl_->in.data(), impl_->out.data());
  for (std::size_t k = 0; k <= n_ / 2; ++k) out[k] = {static_cast<double>(impl_->out[k].r), static_cast<double>(impl_->out[k].i)};
}

std::size_t fast_fft_length(std::size_t n) {
  if (n < 2) n = 2;
  for (std::size_t m = n + (n % 2);; m += 2) {
    std::size_t r = m;
    for (std::size_t p : {2u, 3u, 5u})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
}

}  // namespace texel::detail

namespace texel::detail {
namespace {

using Twiddles = Radix4Twiddles;

/// The radix-4 butterflies of one twiddle set over a contiguous block of s
/// (restrict parameters: the form the compiler vectorizes).
[[gnu::always_inline]] inline void radix4_block(std::size_t s, const double* __restrict a_r, const double* __restrict a_i,
                                                const double* __restrict b_r, const double* __restrict b_i,
                                                const double* __restrict c_r, const double* __restrict c_i,
                                                const double* __restrict d_r, const double* __restrict d_i,
                                                double* __restrict y0r, double* __restrict y0i, double* __restrict y1r,
                                                double* __restrict y1i, double* __restrict y2r, double* __restrict y2i,
                                                double* __restrict y3r, double* __restrict y3i, Twiddles w) {
  for (std::size_t q = 0; q < s; ++q) {
    const double apcr = a_r[q] + c_r[q], apci = a_i[q] + c_i[q], amcr = a_r[q] - c_r[q], amci = a_i[q] - c_i[q];
    const double bpdr = b_r[q] + d_r[q], bpdi = b_i[q] + d_i[q];
    const double jr = b_i[q] - d_i[q], ji = d_r[q] - b_r[q];  // −i·(b − d): the forward transform's quarter turn
    const double u1r = amcr + jr, u1i = amci + ji;
    const double u2r = apcr - bpdr, u2i = apci - bpdi;
    const double u3r = amcr - jr, u3i = amci - ji;
    y0r[q] = apcr + bpdr, y0i[q] = apci + bpdi;
    y1r[q] = u1r * w.w1r - u1i * w.w1i, y1i[q] = u1r * w.w1i + u1i * w.w1r;
    y2r[q] = u2r * w.w2r - u2i * w.w2i, y2i[q] = u2r * w.w2i + u2i * w.w2r;
    y3r[q] = u3r * w.w3r - u3i * w.w3i, y3i[q] = u3r * w.w3i + u3i * w.w3r;
  }
}

/// One radix-4 Stockham stage of length len = 4m and stride s over split
/// arrays: reads x[q + s(p + k·m)], writes y[q + s(4p + k)], k = 0…3.
/// `tw`: per p, the twiddles w^p, w^2p, w^3p (w = e^{−2πi/len}). Written
/// once, compiled for AVX2 and the baseline (dispatched on the CPU, like the
/// renderer).
[[gnu::always_inline]] inline void radix4_stage(const double* xr, const double* xi, double* yr, double* yi, std::size_t m,
                                                std::size_t s, const Twiddles* tw) {
  const std::size_t step = s * m;
  if (s == 1) {  // the first stage: blocks of one, so the loop runs over p
    for (std::size_t p = 0; p < m; ++p) {
      const Twiddles& w = tw[p];
      double* o_r = yr + 4 * p;
      double* o_i = yi + 4 * p;
      radix4_block(1, xr + p, xi + p, xr + p + step, xi + p + step, xr + p + 2 * step, xi + p + 2 * step, xr + p + 3 * step,
                   xi + p + 3 * step, o_r, o_i, o_r + 1, o_i + 1, o_r + 2, o_i + 2, o_r + 3, o_i + 3, w);
    }
    return;
  }
  for (std::size_t p = 0; p < m; ++p) {
    const double* a_r = xr + s * p;
    const double* a_i = xi + s * p;
    double* o_r = yr + 4 * s * p;
    double* o_i = yi + 4 * s * p;
    radix4_block(s, a_r, a_i, a_r + step, a_i + step, a_r + 2 * step, a_i + 2 * step, a_r + 3 * step, a_i + 3 * step, o_r, o_i,
                 o_r + s, o_i + s, o_r + 2 * s, o_i + 2 * s, o_r + 3 * s, o_i + 3 * s, tw[p]);
  }
}

/// One radix-4 butterfly on values: radix4_block's arithmetic for one q.
#define TEXEL_BUTTERFLY(a_r, a_i, b_r, b_i, c_r, c_i, d_r, d_i, W, y0r, y0i, y1r, y1i, y2r, y2i, y3r, y3i) \
  do {                                                                                                     \
    const auto apcr = (a_r) + (c_r), apci = (a_i) + (c_i), amcr = (a_r) - (c_r), amci = (a_i) - (c_i);     \
    const auto bpdr = (b_r) + (d_r), bpdi = (b_i) + (d_i);                                                 \
    const auto jr = (b_i) - (d_i), ji = (d_r) - (b_r);                                                     \
    const auto u1r = amcr + jr, u1i = amci + ji;                                                           \
    const auto u2r = apcr - bpdr, u2i = apci - bpdi;                                                       \
    const auto u3r = amcr - jr, u3i = amci - ji;                                                           \
    y0r = apcr + bpdr, y0i = apci + bpdi;                                                                  \
    y1r = u1r * W##1r - u1i * W##1i, y1i = u1r * W##1i + u1i * W##1r;                                      \
    y2r = u2r * W##2r - u2i * W##2i, y2i = u2r * W##2i + u2i * W##2r;                                      \
    y3r = u3r * W##3r - u3i * W##3i, y3i = u3r * W##3i + u3i * W##3r;                                      \
  } while (false)

/// Two radix-4 stages in one pass over memory: stage A (len 4m, stride s,
/// twiddles ta) then stage B (len m, stride 4s, twiddles tb), with A's
/// outputs that one group of B's butterflies reads kept in registers.
/// B's butterfly (p', q + s·r) reads A's output r of A's butterflies
/// p = p' + k·m/4, k = 0…3, so each group (p', q) is four butterflies of A
/// and four of B: the same operations on the same values as the two
/// stages one after the other, with half the trips through memory.
[[gnu::always_inline]] inline void radix16_pass(const double* __restrict xr, const double* __restrict xi, double* __restrict zr,
                                                double* __restrict zi, std::size_t m, std::size_t s, const Twiddles* ta,
                                                const Twiddles* tb) {
  const std::size_t mb = m / 4, step = s * m, sm = s * mb;
  for (std::size_t pb = 0; pb < mb; ++pb) {
    // The twiddles as scalars (a struct's fields defeat the vectorizer).
#define TEXEL_W(N, FROM)                                                                                           \
  const double N##1r = (FROM).w1r, N##1i = (FROM).w1i, N##2r = (FROM).w2r, N##2i = (FROM).w2i, N##3r = (FROM).w3r, \
               N##3i = (FROM).w3i
    TEXEL_W(wa0_, ta[pb]);
    TEXEL_W(wa1_, ta[pb + mb]);
    TEXEL_W(wa2_, ta[pb + 2 * mb]);
    TEXEL_W(wa3_, ta[pb + 3 * mb]);
    TEXEL_W(wb_, tb[pb]);
#undef TEXEL_W

    const double* __restrict ar = xr + s * pb;
    const double* __restrict ai = xi + s * pb;
    double* __restrict o = zr + 16 * s * pb;
    double* __restrict oi = zi + 16 * s * pb;
    // Every output is written once from inputs of another buffer: no
    // dependence between iterations (restrict on locals is not enough for GCC).
#if defined(__clang__)
#pragma clang loop vectorize(assume_safety)
#else
#pragma GCC ivdep
#endif
    for (std::size_t q = 0; q < s; ++q) {
      double t0r0, t0i0, t0r1, t0i1, t0r2, t0i2, t0r3, t0i3;  // A's butterfly k = 0, outputs 0…3
      double t1r0, t1i0, t1r1, t1i1, t1r2, t1i2, t1r3, t1i3;
      double t2r0, t2i0, t2r1, t2i1, t2r2, t2i2, t2r3, t2i3;
      double t3r0, t3i0, t3r1, t3i1, t3r2, t3i2, t3r3, t3i3;
#define TEXEL_A(K, W)                                                                                                      \
  TEXEL_BUTTERFLY(ar[q + K * sm], ai[q + K * sm], ar[q + K * sm + step], ai[q + K * sm + step], ar[q + K * sm + 2 * step], \
                  ai[q + K * sm + 2 * step], ar[q + K * sm + 3 * step], ai[q + K * sm + 3 * step], W, t##K##r0, t##K##i0,  \
                  t##K##r1, t##K##i1, t##K##r2, t##K##i2, t##K##r3, t##K##i3)
      TEXEL_A(0, wa0_);
      TEXEL_A(1, wa1_);
      TEXEL_A(2, wa2_);
      TEXEL_A(3, wa3_);
#undef TEXEL_A
#define TEXEL_B(R)                                                                                                  \
  TEXEL_BUTTERFLY(t0r##R, t0i##R, t1r##R, t1i##R, t2r##R, t2i##R, t3r##R, t3i##R, wb_, o[q + s * R], oi[q + s * R], \
                  o[q + s * R + 4 * s], oi[q + s * R + 4 * s], o[q + s * R + 8 * s], oi[q + s * R + 8 * s],         \
                  o[q + s * R + 12 * s], oi[q + s * R + 12 * s])
      TEXEL_B(0);
      TEXEL_B(1);
      TEXEL_B(2);
      TEXEL_B(3);
#undef TEXEL_B
    }
  }
}

using PassFn = void (*)(const double*, const double*, double*, double*, std::size_t, std::size_t, const Twiddles*,
                        const Twiddles*);

void pass_baseline(const double* xr, const double* xi, double* yr, double* yi, std::size_t m, std::size_t s, const Twiddles* ta,
                   const Twiddles* tb) {
  radix16_pass(xr, xi, yr, yi, m, s, ta, tb);
}

__attribute__((target("avx2"))) void pass_avx2(const double* xr, const double* xi, double* yr, double* yi, std::size_t m,
                                               std::size_t s, const Twiddles* ta, const Twiddles* tb) {
  radix16_pass(xr, xi, yr, yi, m, s, ta, tb);
}

__attribute__((target("avx512f"))) void pass_avx512(const double* xr, const double* xi, double* yr, double* yi, std::size_t m,
                                                    std::size_t s, const Twiddles* ta, const Twiddles* tb) {
  radix16_pass(xr, xi, yr, yi, m, s, ta, tb);
}

/// The pass for stride s: the widest the CPU has, but AVX2's four lanes for
/// s = 4 (a block of four fills no AVX-512 vector).
/// radix16_pass at stride 4 in AVX-512: two groups p' and p' + 1 at once,
/// whose inputs are eight contiguous points of each stream (one vector:
/// lanes 0–3 are p', lanes 4–7 p' + 1, each with its own twiddles), so every
/// cache line read is used whole. Lane by lane radix16_pass's operations;
/// the two halves of each result go to their groups' outputs. m/4 even.
__attribute__((target("avx512f"))) void pass4_avx512(const double* xr, const double* xi, double* zr, double* zi, std::size_t m,
                                                     const Twiddles* ta, const Twiddles* tb) {
  using V = double __attribute__((vector_size(64)));
  constexpr std::size_t s = 4;
  const std::size_t mb = m / 4, step = s * m, sm = s * mb;
  // An unaligned, aliasing view of 8 doubles: a load is an expression, not a
  // call (a function returning V would need AVX-512 in its own signature,
  // which clang refuses for a lambda at -O0).
  using VU = double __attribute__((vector_size(64), aligned(8), __may_alias__));
#define load(p) (*reinterpret_cast<const VU*>(p))
  auto halves = [](double* lo, double* hi, const V& v) __attribute__((always_inline)) {
    std::memcpy(lo, &v, 4 * sizeof(double));
    std::memcpy(hi, reinterpret_cast<const double*>(&v) + 4, 4 * sizeof(double));
  };
  for (std::size_t pb = 0; pb + 1 < mb; pb += 2) {
#define TEXEL_W(N, A, B)                                                                    \
  const V N##1r = {(A).w1r, (A).w1r, (A).w1r, (A).w1r, (B).w1r, (B).w1r, (B).w1r, (B).w1r}, \
          N##1i = {(A).w1i, (A).w1i, (A).w1i, (A).w1i, (B).w1i, (B).w1i, (B).w1i, (B).w1i}, \
          N##2r = {(A).w2r, (A).w2r, (A).w2r, (A).w2r, (B).w2r, (B).w2r, (B).w2r, (B).w2r}, \
          N##2i = {(A).w2i, (A).w2i, (A).w2i, (A).w2i, (B).w2i, (B).w2i, (B).w2i, (B).w2i}, \
          N##3r = {(A).w3r, (A).w3r, (A).w3r, (A).w3r, (B).w3r, (B).w3r, (B).w3r, (B).w3r}, \
          N##3i = {(A).w3i, (A).w3i, (A).w3i, (A).w3i, (B).w3i, (B).w3i, (B).w3i, (B).w3i}
    TEXEL_W(wa0_, ta[pb], ta[pb + 1]);
    TEXEL_W(wa1_, ta[pb + mb], ta[pb + 1 + mb]);
    TEXEL_W(wa2_, ta[pb + 2 * mb], ta[pb + 1 + 2 * mb]);
    TEXEL_W(wa3_, ta[pb + 3 * mb], ta[pb + 1 + 3 * mb]);
    TEXEL_W(wb_, tb[pb], tb[pb + 1]);
#undef TEXEL_W
    const double* ar = xr + s * pb;
    const double* ai = xi + s * pb;
    V t0r0, t0i0, t0r1, t0i1, t0r2, t0i2, t0r3, t0i3;
    V t1r0, t1i0, t1r1, t1i1, t1r2, t1i2, t1r3, t1i3;
    V t2r0, t2i0, t2r1, t2i1, t2r2, t2i2, t2r3, t2i3;
    V t3r0, t3i0, t3r1, t3i1, t3r2, t3i2, t3r3, t3i3;
#define TEXEL_A(K, W)                                                                                                    \
  TEXEL_BUTTERFLY(load(ar + K * sm), load(ai + K * sm), load(ar + K * sm + step), load(ai + K * sm + step),              \
                  load(ar + K * sm + 2 * step), load(ai + K * sm + 2 * step), load(ar + K * sm + 3 * step),              \
                  load(ai + K * sm + 3 * step), W, t##K##r0, t##K##i0, t##K##r1, t##K##i1, t##K##r2, t##K##i2, t##K##r3, \
                  t##K##i3)
    TEXEL_A(0, wa0_);
    TEXEL_A(1, wa1_);
    TEXEL_A(2, wa2_);
    TEXEL_A(3, wa3_);
#undef TEXEL_A
    double* o = zr + 16 * s * pb;
    double* oi = zi + 16 * s * pb;
#define TEXEL_B(R)                                                                                                            \
  do {                                                                                                                        \
    V y0r, y0i, y1r, y1i, y2r, y2i, y3r, y3i;                                                                                 \
    TEXEL_BUTTERFLY(t0r##R, t0i##R, t1r##R, t1i##R, t2r##R, t2i##R, t3r##R, t3i##R, wb_, y0r, y0i, y1r, y1i, y2r, y2i, y3r,   \
                    y3i);                                                                                                     \
    halves(o + s * R, o + 16 * s + s * R, y0r), halves(oi + s * R, oi + 16 * s + s * R, y0i);                                 \
    halves(o + s * R + 4 * s, o + 16 * s + s * R + 4 * s, y1r), halves(oi + s * R + 4 * s, oi + 16 * s + s * R + 4 * s, y1i); \
    halves(o + s * R + 8 * s, o + 16 * s + s * R + 8 * s, y2r), halves(oi + s * R + 8 * s, oi + 16 * s + s * R + 8 * s, y2i); \
    halves(o + s * R + 12 * s, o + 16 * s + s * R + 12 * s, y3r),                                                             \
        halves(oi + s * R + 12 * s, oi + 16 * s + s * R + 12 * s, y3i);                                                       \
  } while (false)
    TEXEL_B(0);
    TEXEL_B(1);
    TEXEL_B(2);
    TEXEL_B(3);
#undef TEXEL_B
  }
}
#undef load
#undef TEXEL_BUTTERFLY

void pass4_with_avx512(const double* xr, const double* xi, double* yr, double* yi, std::size_t m, std::size_t s,
                       const Twiddles* ta, const Twiddles* tb) {
  if (s == 4 && (m / 4) % 2 == 0)
    pass4_avx512(xr, xi, yr, yi, m, ta, tb);
  else
    pass_avx2(xr, xi, yr, yi, m, s, ta, tb);
}

PassFn pass_fn(std::size_t s) {
  static const int lanes = detail::simd_lanes();
  return lanes == 8 && s != 4 ? &pass_avx512 : lanes == 8 ? &pass4_with_avx512 : lanes >= 4 ? &pass_avx2 : &pass_baseline;
}

using StageFn = void (*)(const double*, const double*, double*, double*, std::size_t, std::size_t, const Twiddles*);

void stage_baseline(const double* xr, const double* xi, double* yr, double* yi, std::size_t m, std::size_t s,
                    const Twiddles* tw) {
  radix4_stage(xr, xi, yr, yi, m, s, tw);
}

__attribute__((target("avx2"))) void stage_avx2(const double* xr, const double* xi, double* yr, double* yi, std::size_t m,
                                                std::size_t s, const Twiddles* tw) {
  radix4_stage(xr, xi, yr, yi, m, s, tw);
}

__attribute__((target("avx512f"))) void stage_avx512(const double* xr, const double* xi, double* yr, double* yi, std::size_t m,
                                                     std::size_t s, const Twiddles* tw) {
  radix4_stage(xr, xi, yr, yi, m, s, tw);
}

StageFn stage_fn() {
  // The widest the CPU has (and TEXEL_SIMD allows): element-wise IEEE
  // arithmetic without contraction, so every width gives the same bits.
  static const StageFn fn = detail::simd_lanes() == 8 ? &stage_avx512 : detail::simd_lanes() == 4 ? &stage_avx2 : &stage_baseline;
  return fn;
}

/// The first radix-4 stage (stride 1: len = h = 4m) of an input whose
/// complex points from `live` on are zero (a zero-padded segment), over p
/// rather than q, so that it vectorizes: reads x[p + k·m], writes
/// y[4p + k]. `w`: the stage's twiddles as six arrays (w1r, w1i, w2r, w2i,
/// w3r, w3i), the same values as Radix4Twiddles. Where an input is known to
/// be zero its terms are left out: a + 0 and a − 0 are a, 0 − b is −b, to
/// the bit except for the sign of a zero result, and a zero's sign never
/// changes a nonzero sum or product nor a power |X|² (add_power's only use).
template <int Live>
[[gnu::always_inline]] inline void first_block(std::size_t p0, std::size_t p1, const double* __restrict xr,
                                               const double* __restrict xi, double* __restrict yr, double* __restrict yi,
                                               std::size_t m, const double* __restrict w) {
  const double* __restrict w1r = w;
  const double* __restrict w1i = w + m;
  const double* __restrict w2r = w + 2 * m;
  const double* __restrict w2i = w + 3 * m;
  const double* __restrict w3r = w + 4 * m;
  const double* __restrict w3i = w + 5 * m;
  for (std::size_t p = p0; p < p1; ++p) {
    const double ar = xr[p], ai = xi[p];
    const double br = Live >= 2 ? xr[p + m] : 0.0, bi = Live >= 2 ? xi[p + m] : 0.0;
    const double cr = Live >= 3 ? xr[p + 2 * m] : 0.0, ci = Live >= 3 ? xi[p + 2 * m] : 0.0;
    const double dr = Live >= 4 ? xr[p + 3 * m] : 0.0, di = Live >= 4 ? xi[p + 3 * m] : 0.0;
    const double apcr = Live >= 3 ? ar + cr : ar, apci = Live >= 3 ? ai + ci : ai;
    const double amcr = Live >= 3 ? ar - cr : ar, amci = Live >= 3 ? ai - ci : ai;
    const double bpdr = Live >= 4 ? br + dr : br, bpdi = Live >= 4 ? bi + di : bi;
    const double jr = Live >= 4 ? bi - di : bi, ji = Live >= 4 ? dr - br : -br;
    const double u1r = Live >= 2 ? amcr + jr : amcr, u1i = Live >= 2 ? amci + ji : amci;
    const double u2r = Live >= 2 ? apcr - bpdr : apcr, u2i = Live >= 2 ? apci - bpdi : apci;
    const double u3r = Live >= 2 ? amcr - jr : amcr, u3i = Live >= 2 ? amci - ji : amci;
    yr[4 * p] = Live >= 2 ? apcr + bpdr : apcr, yi[4 * p] = Live >= 2 ? apci + bpdi : apci;
    yr[4 * p + 1] = u1r * w1r[p] - u1i * w1i[p], yi[4 * p + 1] = u1r * w1i[p] + u1i * w1r[p];
    yr[4 * p + 2] = u2r * w2r[p] - u2i * w2i[p], yi[4 * p + 2] = u2r * w2i[p] + u2i * w2r[p];
    yr[4 * p + 3] = u3r * w3r[p] - u3i * w3i[p], yi[4 * p + 3] = u3r * w3i[p] + u3i * w3r[p];
  }
}

/// first_block over the whole stage, each range of p with the inputs it has.
[[gnu::always_inline]] inline void first_stage(const double* xr, const double* xi, double* yr, double* yi, std::size_t m,
                                               const double* w, std::size_t live) {
  // Input k·m + p is live while it is below `live`.
  auto until = [&](std::size_t k) { return std::min(m, live > k * m ? live - k * m : 0); };
  const std::size_t e4 = until(3), e3 = until(2), e2 = until(1), e1 = until(0);
  first_block<4>(0, e4, xr, xi, yr, yi, m, w);
  first_block<3>(e4, e3, xr, xi, yr, yi, m, w);
  first_block<2>(e3, e2, xr, xi, yr, yi, m, w);
  first_block<1>(e2, e1, xr, xi, yr, yi, m, w);
  for (std::size_t p = e1; p < m; ++p)
    for (std::size_t k = 0; k < 4; ++k) yr[4 * p + k] = 0.0, yi[4 * p + k] = 0.0;
}

/// |X_k|² of the real split (Pow2RealFft::real_split's arithmetic) for
/// k = 1 … h/2 − 1 and their mirrors h − k, stored or added into p: the
/// loop over k in the form the compiler vectorizes (the mirror read and
/// written backwards).
template <bool Add>
[[gnu::always_inline]] inline void split_power(const double* __restrict xr, const double* __restrict xi,
                                               const double* __restrict sr, const double* __restrict si, double* __restrict p,
                                               std::size_t h) {
  for (std::size_t k = 1; k < h / 2; ++k) {
    const std::size_t c = h - k;
    const double er = 0.5 * (xr[k] + xr[c]), ei = 0.5 * (xi[k] - xi[c]);
    const double orr = 0.5 * (xi[k] + xi[c]), oi = -0.5 * (xr[k] - xr[c]);
    const double tr = sr[k] * orr - si[k] * oi, ti = sr[k] * oi + si[k] * orr;
    const double ar = er + tr, ai = ei + ti, br = er - tr, bi = -ei + ti;
    const double pk = ar * ar + ai * ai, pc = br * br + bi * bi;
    if constexpr (Add)
      p[k] += pk, p[c] += pc;
    else
      p[k] = pk, p[c] = pc;
  }
}

/// The packed product x·window (as Pow2RealFft::forward packs its input):
/// re[j] = x[2j]·w[2j], im[j] = x[2j + 1]·w[2j + 1], j < pairs.
[[gnu::always_inline]] inline void pack_product(const double* __restrict x, const double* __restrict w, double* __restrict re,
                                                double* __restrict im, std::size_t pairs) {
  for (std::size_t j = 0; j < pairs; ++j) re[j] = x[2 * j] * w[2 * j], im[j] = x[2 * j + 1] * w[2 * j + 1];
}

/// add_power's vector work, compiled for each width like the stages.
struct PowerKernels {
  void (*first)(const double*, const double*, double*, double*, std::size_t, const double*, std::size_t);
  void (*split_store)(const double*, const double*, const double*, const double*, double*, std::size_t);
  void (*split_add)(const double*, const double*, const double*, const double*, double*, std::size_t);
  void (*pack)(const double*, const double*, double*, double*, std::size_t);
};

#define TEXEL_POWER_KERNELS(SUFFIX, TARGET)                                                                              \
  TARGET void first_##SUFFIX(const double* xr, const double* xi, double* yr, double* yi, std::size_t m, const double* w, \
                             std::size_t live) {                                                                         \
    first_stage(xr, xi, yr, yi, m, w, live);                                                                             \
  }                                                                                                                      \
  TARGET void split_store_##SUFFIX(const double* xr, const double* xi, const double* sr, const double* si, double* p,    \
                                   std::size_t h) {                                                                      \
    split_power<false>(xr, xi, sr, si, p, h);                                                                            \
  }                                                                                                                      \
  TARGET void split_add_##SUFFIX(const double* xr, const double* xi, const double* sr, const double* si, double* p,      \
                                 std::size_t h) {                                                                        \
    split_power<true>(xr, xi, sr, si, p, h);                                                                             \
  }                                                                                                                      \
  TARGET void pack_##SUFFIX(const double* x, const double* w, double* re, double* im, std::size_t pairs) {               \
    pack_product(x, w, re, im, pairs);                                                                                   \
  }

TEXEL_POWER_KERNELS(baseline, )
TEXEL_POWER_KERNELS(avx2, __attribute__((target("avx2"))))
TEXEL_POWER_KERNELS(avx512, __attribute__((target("avx512f"))))
#undef TEXEL_POWER_KERNELS

const PowerKernels& power_kernels() {
  static const PowerKernels k =
      detail::simd_lanes() == 8   ? PowerKernels{&first_avx512, &split_store_avx512, &split_add_avx512, &pack_avx512}
      : detail::simd_lanes() == 4 ? PowerKernels{&first_avx2, &split_store_avx2, &split_add_avx2, &pack_avx2}
                                  : PowerKernels{&first_baseline, &split_store_baseline, &split_add_baseline, &pack_baseline};
  return k;
}

}  // namespace

Pow2RealFft::Pow2RealFft(std::size_t n) : n_(n) {
  if (n < 4 || (n & (n - 1)) != 0 || n > (std::size_t{1} << 30))
    throw InvalidArgument("power-of-two FFT length " + std::to_string(n) + " must be a power of two, 4 … 2^30");
  const std::size_t h = n / 2;
  // Per radix-4 stage (len = h, h/4, …), the twiddles of each p in order.
  for (std::size_t len = h; len >= 4; len /= 4)
    for (std::size_t p = 0; p < len / 4; ++p) {
      auto turn = [&](std::size_t k) { return 2.0 * M_PI * static_cast<double>(k * p) / static_cast<double>(len); };
      tw_.push_back(
          {std::cos(turn(1)), -std::sin(turn(1)), std::cos(turn(2)), -std::sin(turn(2)), std::cos(turn(3)), -std::sin(turn(3))});
    }
  // The first stage's twiddles again, as six arrays (first_stage).
  if (h >= 4) {
    const std::size_t m = h / 4;
    first_tw_.resize(6 * m);
    for (std::size_t p = 0; p < m; ++p) {
      const Radix4Twiddles& w = tw_[p];
      first_tw_[p] = w.w1r, first_tw_[m + p] = w.w1i, first_tw_[2 * m + p] = w.w2r;
      first_tw_[3 * m + p] = w.w2i, first_tw_[4 * m + p] = w.w3r, first_tw_[5 * m + p] = w.w3i;
    }
  }
  sr_.resize(h / 2 + 1), si_.resize(h / 2 + 1);
  for (std::size_t k = 0; k <= h / 2; ++k) {
    const double t = 2.0 * M_PI * static_cast<double>(k) / static_cast<double>(n);
    sr_[k] = std::cos(t), si_[k] = -std::sin(t);
  }
  ar_.resize(h), ai_.resize(h), br_.resize(h), bi_.resize(h);
}

std::pair<const double*, const double*> Pow2RealFft::transform(std::size_t live) {
  const std::size_t h = n_ / 2;  // complex length
  double* xr = ar_.data();
  double* xi = ai_.data();
  double* yr = br_.data();
  double* yi = bi_.data();
  // Stockham, decimation in frequency: stage by stage between two buffers,
  // natural order at the end.
  const StageFn stage = stage_fn();
  std::size_t len = h, s = 1;
  const Twiddles* tw = tw_.data();
  if (len >= 4) {  // the first stage over p, without the zero padding's terms
    power_kernels().first(xr, xi, yr, yi, len / 4, first_tw_.data(), live);
    tw += len / 4;
    std::swap(xr, yr), std::swap(xi, yi);
    len /= 4, s *= 4;
  }
  for (; len >= 16; len /= 16, s *= 16) {  // two stages at a time
    pass_fn(s)(xr, xi, yr, yi, len / 4, s, tw, tw + len / 4);
    tw += len / 4 + len / 16;
    std::swap(xr, yr), std::swap(xi, yi);
  }
  for (; len >= 4; len /= 4, s *= 4) {
    stage(xr, xi, yr, yi, len / 4, s, tw);
    tw += len / 4;
    std::swap(xr, yr), std::swap(xi, yi);
  }
  if (len == 2) {  // the last radix-2 stage: stride h/2, no twiddles
    const std::size_t half = h / 2;
    for (std::size_t q = 0; q < half; ++q) {
      const double ar = xr[q], ai = xi[q], br = xr[q + half], bi = xi[q + half];
      yr[q] = ar + br, yi[q] = ai + bi;
      yr[q + half] = ar - br, yi[q + half] = ai - bi;
    }
    std::swap(xr, yr), std::swap(xi, yi);
  }
  return {xr, xi};
}

template <class Sink>
void Pow2RealFft::real_split(const double* xr, const double* xi, Sink&& sink) const {
  // Real split: with Z the transform of z_j = x_2j + i·x_2j+1,
  // X_k = E_k + e^{−2πik/n}·O_k, E_k = (Z_k + conj Z_{h−k})/2, O_k = (Z_k − conj Z_{h−k})/(2i).
  const std::size_t h = n_ / 2;
  sink(0, xr[0] + xi[0], 0.0);
  sink(h, xr[0] - xi[0], 0.0);
  for (std::size_t k = 1; k <= h / 2; ++k) {
    const std::size_t c = h - k;
    const double er = 0.5 * (xr[k] + xr[c]), ei = 0.5 * (xi[k] - xi[c]);
    const double orr = 0.5 * (xi[k] + xi[c]), oi = -0.5 * (xr[k] - xr[c]);
    const double tr = sr_[k] * orr - si_[k] * oi, ti = sr_[k] * oi + si_[k] * orr;
    sink(k, er + tr, ei + ti);
    // X_{h−k} = conj E + e^{−2πi(h−k)/n}·conj O = conj E − conj(e^{−2πik/n}·O)
    if (c != k) sink(c, er - tr, -ei + ti);
  }
}

void Pow2RealFft::forward(std::span<const double> in, std::span<std::complex<double>> out) {
  const std::size_t h = n_ / 2;
  for (std::size_t j = 0; j < h; ++j) ar_[j] = in[2 * j], ai_[j] = in[2 * j + 1];
  const auto [xr, xi] = transform(h);
  real_split(xr, xi, [&](std::size_t k, double re, double im) { out[k] = {re, im}; });
}

void Pow2RealFft::add_power(std::span<const double> x, std::span<const double> window, std::span<double> p, bool add) {
  const std::size_t h = n_ / 2, seg = x.size();
  const PowerKernels& kernels = power_kernels();
  // The padded product x·window, packed as forward() packs its input. The
  // padding is not written: the first stage leaves out the points from
  // `live` on (a radix-2 transform alone, h = 2, reads them).
  const std::size_t pairs = seg / 2;
  kernels.pack(x.data(), window.data(), ar_.data(), ai_.data(), pairs);
  std::size_t j = pairs;
  if (seg % 2 == 1) ar_[j] = x[seg - 1] * window[seg - 1], ai_[j] = 0.0, ++j;
  if (h < 4) {
    std::fill(ar_.begin() + static_cast<std::ptrdiff_t>(j), ar_.begin() + static_cast<std::ptrdiff_t>(h), 0.0);
    std::fill(ai_.begin() + static_cast<std::ptrdiff_t>(j), ai_.begin() + static_cast<std::ptrdiff_t>(h), 0.0);
  }
  const auto [xr, xi] = transform(j);
  // k = 0, h/2 and h as real_split has them; the rest in the vector loop.
  auto put = [&](std::size_t k, double re, double im) { p[k] = add ? p[k] + (re * re + im * im) : re * re + im * im; };
  put(0, xr[0] + xi[0], 0.0);
  put(h, xr[0] - xi[0], 0.0);
  {
    const std::size_t k = h / 2, c = h - k;
    const double er = 0.5 * (xr[k] + xr[c]), ei = 0.5 * (xi[k] - xi[c]);
    const double orr = 0.5 * (xi[k] + xi[c]), oi = -0.5 * (xr[k] - xr[c]);
    const double tr = sr_[k] * orr - si_[k] * oi, ti = sr_[k] * oi + si_[k] * orr;
    put(k, er + tr, ei + ti);
  }
  (add ? kernels.split_add : kernels.split_store)(xr, xi, sr_.data(), si_.data(), p.data(), h);
}

}  // namespace texel::detail
