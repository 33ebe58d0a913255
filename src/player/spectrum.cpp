// Magnitude spectrum of a player output (for --plot and tests): Hann window,
// zero-padding to a power of two, through the spectrum module's real FFT
// (KISS FFT, float: noise floor near −130 dB, far below what --plot shows).
// Not texel::magnitude_spectrum: that removes the mean (the DC bin matters
// here for drive-mode output), pads to 2·3·5-smooth lengths and uses a
// periodic window, which would change the documented bin grid (k·rate/n, n a
// power of two). Not for the real-time path (it allocates).
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "../spectrum/fft.hpp"
#include "texel/error.hpp"
#include "texel/player.hpp"

namespace texel {

SignalSpectrum signal_spectrum(std::span<const float> signal, double rate_hz) {
  if (signal.size() < 2) throw InvalidArgument("spectrum: signal has " + std::to_string(signal.size()) + " samples; need >= 2");
  std::size_t n = 1;
  while (n < signal.size()) n <<= 1;
  std::vector<double> a(n, 0.0);
  double wsum = 0;
  const double m = static_cast<double>(signal.size());
  for (std::size_t i = 0; i < signal.size(); ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / (m - 1));
    a[i] = signal[i] * w;
    wsum += w;
  }
  std::vector<std::complex<double>> X(n / 2 + 1);
  detail::RealFft fft(n);
  fft.forward(a, X);
  SignalSpectrum s;
  s.frequency_hz.resize(n / 2 + 1);
  s.magnitude.resize(n / 2 + 1);
  for (std::size_t k = 0; k <= n / 2; ++k) {
    s.frequency_hz[k] = static_cast<double>(k) * rate_hz / static_cast<double>(n);
    s.magnitude[k] = 2.0 * std::abs(X[k]) / wsum;  // a sinusoid of amplitude A peaks at ≈ A
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
