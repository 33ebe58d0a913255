// The one place Texel talks to an FFT library (KISS FFT, float). Everything
// else calls RealFft, so swapping the library touches only fft.cpp; the
// encoder's inner loop, which transforms a few dozen power-of-two-length
// candidates per encode, calls Pow2RealFft (our own, double precision).
#pragma once

#include <complex>
#include <cstddef>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace texel::detail {

/// Forward real FFT of even length n: n real inputs -> n/2 + 1 bins,
/// unnormalized (X_k = Σ x_j e^{−2πi jk/n}). Prepared once per length; the
/// plan depends only on n, so results are deterministic for a build.
/// Not thread-safe per object (it owns scratch buffers).
class RealFft {
 public:
  explicit RealFft(std::size_t n);
  ~RealFft();
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;

  [[nodiscard]] std::size_t size() const { return n_; }
  /// in.size() == size(); out.size() == size()/2 + 1.
  void forward(std::span<const double> in, std::span<std::complex<double>> out);

 private:
  struct Impl;
  std::size_t n_;
  std::unique_ptr<Impl> impl_;
};

/// Forward real FFT of a power-of-two length n ≥ 4, the same transform as
/// RealFft in double precision: n/2 complex points by a radix-4 Stockham
/// FFT (one radix-2 stage when log2(n/2) is odd) over split real and
/// imaginary arrays, whose inner loops run over contiguous blocks the
/// compiler vectorizes, then the real-input split. 3–4× KISS FFT's float
/// transform at 2^15 (texel_bench_encode). Twiddles from libm: analysis
/// only, never rendered bytes. Not thread-safe per object (scratch buffers).
/// The twiddles w^p, w^2p, w^3p (re, im) of one radix-4 butterfly set.
struct Radix4Twiddles {
  double w1r, w1i, w2r, w2i, w3r, w3i;
};

class Pow2RealFft {
 public:
  explicit Pow2RealFft(std::size_t n);
  [[nodiscard]] std::size_t size() const { return n_; }
  /// in.size() == size(); out.size() == size()/2 + 1.
  void forward(std::span<const double> in, std::span<std::complex<double>> out);
  /// Adds |X_k|² to p[k] (p.size() == size()/2 + 1), or with `add` false
  /// stores it there, X the transform of x·window zero-padded to size()
  /// (x.size() == window.size() ≤ size()): bit for bit std::norm of
  /// forward()'s output for the padded product, without the product's and
  /// the spectrum's buffers (a periodogram).
  void add_power(std::span<const double> x, std::span<const double> window, std::span<double> p, bool add = true);

 private:
  /// The complex transform of the packed input in ar_/ai_, whose points
  /// from `live` on are zero (and need not be stored there unless the
  /// transform is a single radix-2 stage, size() == 4); the buffers holding the result.
  std::pair<const double*, const double*> transform(std::size_t live);
  /// The real-input split of the complex transform (zr, zi): sink(k, re, im)
  /// for every k = 0 … size()/2.
  template <class Sink>
  void real_split(const double* zr, const double* zi, Sink&& sink) const;

  std::size_t n_;                          // real length
  std::vector<Radix4Twiddles> tw_;         // per radix-4 stage and p
  std::vector<double> first_tw_;           // the first stage's, as six arrays of p
  std::vector<double> sr_, si_;            // e^{−2πik/n}, k ≤ n/4: the real split's
  std::vector<double> ar_, ai_, br_, bi_;  // ping-pong buffers
};

/// Smallest even length >= n whose only prime factors are 2, 3 and 5.
std::size_t fast_fft_length(std::size_t n);

}  // namespace texel::detail
