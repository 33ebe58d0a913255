// detfft: the deterministic FFT and the chirp-z sum of harmonics. See
// src/internal/texel/detail/detfft.hpp for the method and its trade-off.
#include "texel/detail/detfft.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "texel/detmath.hpp"
#include "texel/error.hpp"

namespace texel::detail {

// ------------------------------------------------------------ exact arithmetic

namespace {

/// Veltkamp's split of a into two 26-bit halves, a = hi + lo exactly.
TwoDouble split(double a) {
  const double c = 134217729.0 * a;  // 2^27 + 1
  const double hi = c - (c - a);
  return {hi, a - hi};
}

/// a + b for |a| >= |b| (or a = 0), exactly.
TwoDouble quick_two_sum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}

/// a · b, both two-doubles, to about 106 bits.
TwoDouble multiply(TwoDouble a, TwoDouble b) {
  const TwoDouble p = two_product(a.hi, b.hi);
  return quick_two_sum(p.hi, p.lo + (a.hi * b.lo + a.lo * b.hi));
}

/// x minus its nearest integer, in [−1/2, 1/2]: exact for every finite double
/// (x − floor(x) is not: −1e-17 − (−1) rounds to 1).
double wrap(double x) { return x - std::round(x); }

/// a modulo 1, to ~106 bits: integer multiples of it then stay small.
TwoDouble wrap(TwoDouble a) { return two_sum(wrap(a.hi), a.lo); }

/// c·q modulo 1 (in [−1/2, 1/2]) for a two-double c with |c.hi| <= 1/2 and
/// an integer q < 2^53: the product's high part is exact (two_product) and
/// reduced exactly, its low part is below one cycle, so the phase keeps
/// about 1e-16 cycle whatever q.
double cycles_times(TwoDouble c, std::uint64_t q) {
  const auto qd = static_cast<double>(q);
  const TwoDouble p = two_product(c.hi, qd);
  return wrap(wrap(p.hi) + (p.lo + c.lo * qd));
}

}  // namespace

TwoDouble two_sum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}

TwoDouble two_product(double a, double b) {
  const double p = a * b;
  const TwoDouble x = split(a);
  const TwoDouble y = split(b);
  return {p, ((x.hi * y.hi - p) + x.hi * y.lo + x.lo * y.hi) + x.lo * y.lo};
}

TwoDouble reciprocal(double d) {
  const double h = 1.0 / d;
  const TwoDouble p = two_product(h, d);
  return {h, ((1.0 - p.hi) - p.lo) / d};  // 1 − p.hi is exact (Sterbenz)
}

// ------------------------------------------------------------ FFT

namespace {

// Sub-transforms of up to this many points (32 KiB of re + im) run all their
// stages before moving on: the recursion keeps them in cache. Any value gives
// the same bits (independent butterflies commute); this one gives the speed.
constexpr std::size_t leaf = 2048;
constexpr std::size_t max_size = std::size_t{1} << 26;

/// One decimation-in-frequency stage over re/im[0, n): butterflies of span h
/// with twiddles (c, s)[j] = e^(−2πi·j/2h), j < h (contiguous, so the loop
/// vectorizes; lanes perform the scalar operations, so bits do not change).
void dif_stage(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {
  for (std::size_t base = 0; base < n; base += 2 * h) {
    double* ar = re + base;
    double* ai = im + base;
    double* br = ar + h;
    double* bi = ai + h;
    for (std::size_t j = 0; j < h; ++j) {
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
}

/// One decimation-in-time stage with the conjugate twiddles (the inverse).
void dit_stage(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s) {
  for (std::size_t base = 0; base < n; base += 2 * h) {
    double* ar = re + base;
    double* ai = im + base;
    double* br = ar + h;
    double* bi = ai + h;
    for (std::size_t j = 0; j < h; ++j) {
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
}

}  // namespace

DetFft::DetFft(std::size_t n) : n_(n) {
  if (n < 1 || n > max_size || (n & (n - 1)) != 0)
    throw InvalidArgument("FFT size is " + std::to_string(n) + "; it must be a power of two from 1 to 2^26");
  while ((std::size_t{1} << bits_) < n) ++bits_;
  if (n < 2) return;
  // Stage h's twiddles e^(−2πi·j/2h), j < h, at offset h − 1: the largest
  // stage's from detmath, every other stage's copied from it (j/2h is the
  // same fraction as j·(n/2h)/n, so the values are the same either way).
  cos_.resize(n - 1);
  sin_.resize(n - 1);
  const std::size_t top = n / 2 - 1;
  const double inv = 1.0 / static_cast<double>(n);  // exact: n is a power of two
  for (std::size_t t = 0; t < n / 2; ++t) {
    const double u = static_cast<double>(t) * inv;  // exact
    cos_[top + t] = detmath::cos_cycles(u);
    sin_[top + t] = -detmath::sin_cycles(u);
  }
  for (std::size_t h = n / 4; h >= 1; h /= 2)
    for (std::size_t j = 0; j < h; ++j) {
      cos_[h - 1 + j] = cos_[top + j * (n / (2 * h))];
      sin_[h - 1 + j] = sin_[top + j * (n / (2 * h))];
    }
}

std::size_t DetFft::bit_reverse(std::size_t i) const {
  std::size_t r = 0;
  for (int b = 0; b < bits_; ++b) r |= ((i >> b) & 1u) << (bits_ - 1 - b);
  return r;
}

void DetFft::dif(double* re, double* im, std::size_t n) const {
  if (n < 2) return;
  if (n > leaf) {
    dif_stage(re, im, n, n / 2, cos_.data() + n / 2 - 1, sin_.data() + n / 2 - 1);
    dif(re, im, n / 2);
    dif(re + n / 2, im + n / 2, n / 2);
    return;
  }
  for (std::size_t h = n / 2; h >= 1; h /= 2) dif_stage(re, im, n, h, cos_.data() + h - 1, sin_.data() + h - 1);
}

void DetFft::dit(double* re, double* im, std::size_t n) const {
  if (n < 2) return;
  if (n > leaf) {
    dit(re, im, n / 2);
    dit(re + n / 2, im + n / 2, n / 2);
    dit_stage(re, im, n, n / 2, cos_.data() + n / 2 - 1, sin_.data() + n / 2 - 1);
    return;
  }
  for (std::size_t h = 1; h < n; h *= 2) dit_stage(re, im, n, h, cos_.data() + h - 1, sin_.data() + h - 1);
}

void DetFft::forward_to_bit_reversed(double* re, double* im) const { dif(re, im, n_); }
void DetFft::inverse_from_bit_reversed(double* re, double* im) const { dit(re, im, n_); }

void DetFft::permute(double* re, double* im) const {
  for (std::size_t i = 0; i < n_; ++i) {
    const std::size_t r = bit_reverse(i);
    if (i < r) {
      std::swap(re[i], re[r]);
      std::swap(im[i], im[r]);
    }
  }
}

void DetFft::forward(double* re, double* im) const {
  forward_to_bit_reversed(re, im);
  permute(re, im);
}

void DetFft::inverse(double* re, double* im) const {
  permute(re, im);
  inverse_from_bit_reversed(re, im);
}

// ------------------------------------------------------------ chirp-z

namespace {

/// The FFT size for K harmonics and N samples: outputs go in blocks of
/// B = M − K + 1 samples, each costing two FFTs of size M (plus one for the
/// shared kernel), so M is the power of two (>= 64) that minimises
/// (2·blocks + 1)·M·log2(M); ties go to the smaller M. A function of (K, N)
/// alone, computed in integers: part of what fixes the bits.
std::size_t block_fft_size(std::size_t k, std::size_t n) {
  std::size_t best = 0;
  std::uint64_t best_cost = ~std::uint64_t{0};
  for (int p = 6; p <= 26; ++p) {
    const std::size_t m = std::size_t{1} << p;
    if (m < k) continue;
    const std::size_t b = std::min(m - k + 1, n);
    const std::uint64_t blocks = (n + b - 1) / b;
    const std::uint64_t cost = (2 * blocks + 1) * m * static_cast<std::uint64_t>(p);
    if (cost < best_cost) {
      best = m;
      best_cost = cost;
    }
    if (b == n) break;  // one block already: a larger M only costs more
  }
  return best;
}

}  // namespace

void sum_harmonics(const Harmonics& h, double origin, double spacing, std::int64_t index, std::span<double> out) {
  const std::size_t k = h.amplitude.size();
  const std::size_t n = out.size();
  if (k == 0 || k != h.phase_cycles.size() || k > max_chirp_harmonics)
    throw InvalidArgument("sum_harmonics: " + std::to_string(k) + " harmonics (" + std::to_string(h.phase_cycles.size()) +
                          " phases); 1 to " + std::to_string(max_chirp_harmonics) + " are allowed");
  if (n == 0) return;
  const std::size_t m = block_fft_size(k, n);
  const std::size_t block = std::min(m - k + 1, n);
  const DetFft fft(m);

  // Phase of harmonic first + j at sample t of a block starting at x0 (all in
  // cycles, each reduced modulo 1 from exact products):
  //   φ_j + (first + j)·f·(x0 + t·s) = A_j + B_t − C_(t−j), with θ = f·s and
  //   A_j = φ_j + (first + j)·f·x0 + θ/2·j²,  B_t = θ/2·t² + first·θ·t,  C_d = θ/2·d².
  const TwoDouble theta = multiply(h.fundamental, TwoDouble{spacing, 0.0});
  const TwoDouble half_theta = wrap(TwoDouble{theta.hi * 0.5, theta.lo * 0.5});  // halving is exact
  const TwoDouble first_theta = wrap(multiply(theta, TwoDouble{static_cast<double>(h.first), 0.0}));

  // The kernel e^(−2πi·C_d) for d in (−K, B), circularly, scaled by 1/M
  // (exact: a power of two) so that the inverse transform needs no scaling;
  // shared by every block.
  std::vector<double> vr(m, 0.0);
  std::vector<double> vi(m, 0.0);
  const double inv_m = 1.0 / static_cast<double>(m);
  for (std::size_t d = 0; d < std::max(block, k); ++d) {
    const double c = cycles_times(half_theta, static_cast<std::uint64_t>(d) * d);
    const double re = detmath::cos_cycles(c) * inv_m;
    const double im = -detmath::sin_cycles(c) * inv_m;
    if (d < block) {
      vr[d] = re;
      vi[d] = im;
    }
    if (d >= 1 && d < k) {
      vr[m - d] = re;
      vi[m - d] = im;
    }
  }
  fft.forward_to_bit_reversed(vr.data(), vi.data());

  std::vector<double> ur(m);
  std::vector<double> ui(m);
  for (std::size_t m0 = 0; m0 < n; m0 += block) {
    const std::size_t len = std::min(block, n - m0);
    // x0 = origin + (index + m0)·spacing and f·x0 modulo 1, to ~106 bits.
    const auto i0 = static_cast<double>(index + static_cast<std::int64_t>(m0));  // exact below 2^53
    const TwoDouble p = two_product(i0, spacing);
    const TwoDouble s = two_sum(origin, p.hi);
    const TwoDouble x0 = two_sum(s.hi, s.lo + p.lo);  // s.hi may have cancelled to below p.lo
    const TwoDouble alpha = wrap(multiply(h.fundamental, x0));
    for (std::size_t j = 0; j < k; ++j) {
      const double a =
          h.phase_cycles[j] + cycles_times(alpha, h.first + j) + cycles_times(half_theta, static_cast<std::uint64_t>(j) * j);
      ur[j] = h.amplitude[j] * detmath::cos_cycles(a);
      ui[j] = h.amplitude[j] * detmath::sin_cycles(a);
    }
    std::fill(ur.begin() + static_cast<std::ptrdiff_t>(k), ur.end(), 0.0);
    std::fill(ui.begin() + static_cast<std::ptrdiff_t>(k), ui.end(), 0.0);
    fft.forward_to_bit_reversed(ur.data(), ui.data());
    for (std::size_t i = 0; i < m; ++i) {
      const double xr = ur[i];
      const double xi = ui[i];
      ur[i] = xr * vr[i] - xi * vi[i];
      ui[i] = xr * vi[i] + xi * vr[i];
    }
    fft.inverse_from_bit_reversed(ur.data(), ui.data());
    // y = Im(e^(2πi·B_t)·z_t).
    for (std::size_t t = 0; t < len; ++t) {
      const double b = cycles_times(half_theta, static_cast<std::uint64_t>(t) * t) + cycles_times(first_theta, t);
      out[m0 + t] = detmath::sin_cycles(b) * ur[t] + detmath::cos_cycles(b) * ui[t];
    }
  }
}

}  // namespace texel::detail
