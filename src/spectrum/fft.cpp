#include "fft.hpp"

#include <algorithm>
#include <cmath>
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
inline void radix4_block(std::size_t s, const double* __restrict a_r, const double* __restrict a_i, const double* __restrict b_r,
                         const double* __restrict b_i, const double* __restrict c_r, const double* __restrict c_i,
                         const double* __restrict d_r, const double* __restrict d_i, double* __restrict y0r,
                         double* __restrict y0i, double* __restrict y1r, double* __restrict y1i, double* __restrict y2r,
                         double* __restrict y2i, double* __restrict y3r, double* __restrict y3i, Twiddles w) {
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
inline void radix4_stage(const double* xr, const double* xi, double* yr, double* yi, std::size_t m, std::size_t s,
                         const Twiddles* tw) {
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
  sr_.resize(h / 2 + 1), si_.resize(h / 2 + 1);
  for (std::size_t k = 0; k <= h / 2; ++k) {
    const double t = 2.0 * M_PI * static_cast<double>(k) / static_cast<double>(n);
    sr_[k] = std::cos(t), si_[k] = -std::sin(t);
  }
  ar_.resize(h), ai_.resize(h), br_.resize(h), bi_.resize(h);
}

std::pair<const double*, const double*> Pow2RealFft::transform() {
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
  const auto [xr, xi] = transform();
  real_split(xr, xi, [&](std::size_t k, double re, double im) { out[k] = {re, im}; });
}

void Pow2RealFft::add_power(std::span<const double> x, std::span<const double> window, std::span<double> p, bool add) {
  const std::size_t h = n_ / 2, seg = x.size();
  // The padded product x·window, packed as forward() packs its input.
  const std::size_t pairs = seg / 2;
  for (std::size_t j = 0; j < pairs; ++j) ar_[j] = x[2 * j] * window[2 * j], ai_[j] = x[2 * j + 1] * window[2 * j + 1];
  std::size_t j = pairs;
  if (seg % 2 == 1) ar_[j] = x[seg - 1] * window[seg - 1], ai_[j] = 0.0, ++j;
  std::fill(ar_.begin() + static_cast<std::ptrdiff_t>(j), ar_.begin() + static_cast<std::ptrdiff_t>(h), 0.0);
  std::fill(ai_.begin() + static_cast<std::ptrdiff_t>(j), ai_.begin() + static_cast<std::ptrdiff_t>(h), 0.0);
  const auto [xr, xi] = transform();
  if (add)
    real_split(xr, xi, [&](std::size_t k, double re, double im) { p[k] += re * re + im * im; });
  else
    real_split(xr, xi, [&](std::size_t k, double re, double im) { p[k] = re * re + im * im; });
}

}  // namespace texel::detail
