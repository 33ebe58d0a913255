// The one place Texel talks to an FFT library (KISS FFT, float). Everything
// else calls RealFft, so swapping the library touches only fft.cpp.
#pragma once

#include <complex>
#include <cstddef>
#include <memory>
#include <span>

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

/// Smallest even length >= n whose only prime factors are 2, 3 and 5.
std::size_t fast_fft_length(std::size_t n);

}  // namespace texel::detail
