// The encoder's power spectrum (src/codec/spectra.cpp) stands on
// Pow2RealFft::add_power, which skips the zero padding's terms, runs two
// radix-4 stages per pass and splits the real transform in vector lanes. Its
// contract: bit for bit std::norm of forward() applied to the padded,
// windowed segment, at every SIMD width (TEXEL_SIMD; the CI's determinism
// builds run the baseline), for segments that fill the transform, leave
// most of it as padding, or have odd length.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdint>
#include <cstring>
#include <vector>

#include "../../src/spectrum/fft.hpp"

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(EncoderSpectrum, AddPowerIsTheNormOfThePaddedTransformBitForBit) {
  std::uint64_t state = 99;
  auto uniform = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
  };
  for (std::size_t n = 4; n <= (std::size_t{1} << 15); n *= 2) {
    texel::detail::Pow2RealFft fft(n);
    for (std::size_t seg : {n, n - 1, n / 2 + 1, (n * 19) / 32, std::size_t{3}, std::size_t{1}}) {
      if (seg == 0 || seg > n) continue;
      std::vector<double> x(seg), w(seg), padded(n, 0.0);
      for (std::size_t i = 0; i < seg; ++i) {
        x[i] = i % 5 == 0 ? 0.0 : uniform();  // exact zeros too
        w[i] = 0.5 - 0.5 * std::cos(2.0 * M_PI * (static_cast<double>(i) + 0.5) / static_cast<double>(seg));
        padded[i] = x[i] * w[i];
      }
      std::vector<std::complex<double>> X(n / 2 + 1);
      fft.forward(padded, X);
      std::vector<double> p(n / 2 + 1, -1.0), twice(n / 2 + 1);
      fft.add_power(x, w, p, false);
      for (std::size_t k = 0; k <= n / 2; ++k) twice[k] = p[k];
      fft.add_power(x, w, twice, true);
      int differing = 0;
      for (std::size_t k = 0; k <= n / 2; ++k) {
        const double norm = std::norm(X[k]);
        differing += !same_bits(p[k], norm) + !same_bits(twice[k], p[k] + norm);
      }
      EXPECT_EQ(differing, 0) << "n = " << n << ", segment " << seg;
    }
  }
}

}  // namespace
