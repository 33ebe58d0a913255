// Magnitude spectrum of a player output (for --plot and tests): Hann window,
// zero-padding to a power of two, iterative radix-2 FFT. Small and
// dependency-free; not for the real-time path (it allocates).
#include <cmath>
#include <complex>
#include <numbers>

#include "texel/error.hpp"
#include "texel/player.hpp"

namespace texel {

namespace {

void fft(std::vector<std::complex<double>>& a) {
  const std::size_t n = a.size();
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const double ang = -2.0 * std::numbers::pi / static_cast<double>(len);
    for (std::size_t i = 0; i < n; i += len) {
      for (std::size_t k = 0; k < len / 2; ++k) {
        // Twiddles computed directly (not by recurrence) to keep long
        // transforms accurate.
        const std::complex<double> w = std::polar(1.0, ang * static_cast<double>(k));
        const auto u = a[i + k];
        const auto v = a[i + k + len / 2] * w;
        a[i + k] = u + v;
        a[i + k + len / 2] = u - v;
      }
    }
  }
}

}  // namespace

SignalSpectrum signal_spectrum(std::span<const float> signal, double rate_hz) {
  if (signal.size() < 2) throw InvalidArgument("spectrum: signal has " + std::to_string(signal.size()) + " samples; need >= 2");
  std::size_t n = 1;
  while (n < signal.size()) n <<= 1;
  std::vector<std::complex<double>> a(n);
  double wsum = 0;
  const double m = static_cast<double>(signal.size());
  for (std::size_t i = 0; i < signal.size(); ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / (m - 1));
    a[i] = signal[i] * w;
    wsum += w;
  }
  fft(a);
  SignalSpectrum s;
  s.frequency_hz.resize(n / 2 + 1);
  s.magnitude.resize(n / 2 + 1);
  for (std::size_t k = 0; k <= n / 2; ++k) {
    s.frequency_hz[k] = static_cast<double>(k) * rate_hz / static_cast<double>(n);
    s.magnitude[k] = 2.0 * std::abs(a[k]) / wsum;  // a sinusoid of amplitude A peaks at ≈ A
  }
  return s;
}

double SignalSpectrum::peak_hz(double min_hz) const {
  double best = -1, f = 0;
  for (std::size_t k = 0; k < magnitude.size(); ++k)
    if (frequency_hz[k] >= min_hz && magnitude[k] > best) {
      best = magnitude[k];
      f = frequency_hz[k];
    }
  return f;
}

}  // namespace texel
