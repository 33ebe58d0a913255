// Spectral analysis: calibration against analytic signals, peak picking,
// Welch PSD, summaries, and the texel-versus-sum-of-sinusoids property of
// docs/algorithm.md §10. Each test states its tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <set>
#include <vector>

#include "../../src/spectrum/fft.hpp"
#include "../support/grids.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/spectrum.hpp"
#include "texel/texture.hpp"

using namespace texel;

namespace {
std::vector<double> sine(std::size_t n, double dx, double f, double amp, double phase = 0.3) {
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = 0.5 + amp * std::sin(2 * std::numbers::pi * (f * i * dx + phase));
  return x;
}
double db20(double x) { return 20 * std::log10(x); }
}  // namespace

TEST(MagnitudeSpectrum, CalibratedForOffBinSinusoids) {
  // A sinusoid of amplitude 0.3 at 7.77 cpm (off-bin): one peak, amplitude
  // within 0.05 dB for every window; frequency within 0.05 of the resolution
  // (0.25 for the flat-top window, whose flat main lobe is made for
  // amplitude, not frequency).
  for (Window w : {Window::blackman_harris, Window::hann, Window::flat_top}) {
    const auto x = sine(10007, 0.01, 7.77, 0.3);
    const Spectrum s = magnitude_spectrum(x, Millimetres(0.01), {.window = w});
    const auto peaks = find_peaks(s);
    ASSERT_EQ(peaks.size(), 1u) << to_string(w);
    EXPECT_NEAR(db20(peaks[0].amplitude / 0.3), 0.0, 0.05) << to_string(w);
    const double tol = (w == Window::flat_top ? 0.25 : 0.05) * s.resolution.value();
    EXPECT_NEAR(peaks[0].frequency.value(), 7.77, tol) << to_string(w);
  }
}

TEST(MagnitudeSpectrum, PowerSumsToTheVariance) {
  // Σ power = variance of the signal (0.3²/2 for a sinusoid) within 1 %.
  const auto x = sine(8000, 0.01, 3.3, 0.3);
  const Spectrum s = magnitude_spectrum(x, Millimetres(0.01));
  const double total = summarize(s).total_power;
  EXPECT_NEAR(total / (0.09 / 2), 1.0, 0.01);
  EXPECT_NEAR(band_energy(s, CyclesPerMm(3.0), CyclesPerMm(3.6)) / total, 1.0, 1e-3);  // all of it around 3.3 cpm (0.1 %)
}

TEST(WelchPsd, IntegratesToTheVariance) {
  // ∫ PSD df = variance within 2 %.
  const auto x = sine(20000, 0.005, 12.5, 0.2);
  const Psd p = welch_psd(x, Millimetres(0.005));
  double sum = 0;
  for (double d : p.density) sum += d * p.bin.value();
  EXPECT_NEAR(sum / (0.04 / 2), 1.0, 0.02);
  EXPECT_GE(p.segments, 7u);  // auto: quarter-length segments, 50 % overlap
}

TEST(Summary, CentroidsAndTemporalView) {
  // Two equal sinusoids at 2 and 8 cpm: linear centroid 5 cpm, log centroid
  // (10·log10 2 + 10·log10 8)/2 = 6.02 dB (4 cpm), spread 3 cpm; all within 1 %.
  auto x = sine(16000, 0.005, 2.0, 0.2);
  const auto y = sine(16000, 0.005, 8.0, 0.2, 0.1);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += y[i] - 0.5;
  const SpectralSummary s = summarize(magnitude_spectrum(x, Millimetres(0.005)));
  EXPECT_NEAR(s.centroid.value(), 5.0, 0.05);
  EXPECT_NEAR(s.log_centroid.value(), 10 * std::log10(4.0), 0.06);
  EXPECT_NEAR(s.spread.value(), 3.0, 0.03);
  // Hz = cycles/mm × mm/s, exactly.
  const std::vector<double> f{2.0, 10.0};
  const auto hz = temporal_frequencies(f, MmPerSecond(100.0));
  EXPECT_EQ(hz[0], 200.0);
  EXPECT_EQ(hz[1], 1000.0);
}

TEST(SpectrumErrors, BadInputIsNamed) {
  std::vector<double> x(100, 0.5);
  EXPECT_THROW(magnitude_spectrum(std::vector<double>(2, 0.0), Millimetres(0.01)), InvalidArgument);
  EXPECT_THROW(magnitude_spectrum(x, Millimetres(0.0)), InvalidArgument);
  EXPECT_THROW(magnitude_spectrum(x, Millimetres(0.01), {.zero_pad = 0}), InvalidArgument);
  x[3] = std::nan("");
  EXPECT_THROW(magnitude_spectrum(x, Millimetres(0.01)), InvalidArgument);
  EXPECT_THROW(parse_window("kaiser"), InvalidArgument);
}

TEST(TexelProperty, PeaksMatchTheEqualWeightSumOfSinusoids) {
  // docs/algorithm.md §10: N texels of length L/N with frequencies f_i versus the
  // equally weighted sum of the N sinusoids over L. Rectangular window (the
  // property is about the plain DFT), 16× zero padding. For each f_i the
  // Texel rendering's highest peak within ±2N/L sits at f_i within 0.05·N/L
  // and has the sum's height within 0.3 dB.
  const Grid g = test_support::tpad_grid();
  const double L = g.length().value();
  for (std::size_t N : {3u, 4u, 6u}) {
    TexelSpec spec;
    spec.parameterization = Parameterization::log;
    spec.central_pitch = Decibels(8.0);
    spec.irregularity = Decibels(4.0);
    spec.quantization_db = 3.0;  // frequencies on a ×2 grid: distinct ones are well separated
    spec.texel_length = Millimetres(L / static_cast<double>(N));
    spec.phase = PhaseMode::reset;
    spec.fill = Fill::partial_final_texel;
    // The first seed whose N draws are all different (deterministic search).
    std::unique_ptr<TexelTexture> t;
    for (std::uint64_t seed = 1; seed < 1000; ++seed) {
      spec.seed = seed;
      t = std::make_unique<TexelTexture>(spec, Millimetres(L), Sampling{g});
      std::set<double> distinct;
      for (const auto& x : t->texels()) distinct.insert(x.frequency.value());
      if (t->texels().size() == N && distinct.size() == N) break;
    }
    ASSERT_EQ(t->texels().size(), N);
    std::vector<double> texel(19200), sum(19200);
    t->render(g, 0, texel);
    for (std::size_t i = 0; i < sum.size(); ++i) {
      double y = 0;
      for (const auto& x : t->texels()) y += std::sin(2 * std::numbers::pi * x.frequency.value() * g.position(i).value());
      sum[i] = 0.5 + 0.5 * y / static_cast<double>(N);
    }
    const SpectrumOptions opt{.window = Window::rectangular, .zero_pad = 16};
    const auto pt = find_peaks(magnitude_spectrum(texel, g.spacing, opt), {.threshold = DecibelsLevel(-60), .max_peaks = 1000});
    const auto ps = find_peaks(magnitude_spectrum(sum, g.spacing, opt), {.threshold = DecibelsLevel(-60), .max_peaks = 1000});
    const double wide = static_cast<double>(N) / L;
    for (const auto& x : t->texels()) {
      auto best = [&](const std::vector<Peak>& peaks, double span) {
        const Peak* b = nullptr;
        for (const auto& p : peaks)
          if (std::abs(p.frequency.value() - x.frequency.value()) < span && (!b || p.amplitude > b->amplitude)) b = &p;
        return b;
      };
      const Peak* a = best(pt, 2 * wide);
      const Peak* b = best(ps, 2 / L);
      ASSERT_TRUE(a && b) << "f = " << x.frequency.value();
      EXPECT_NEAR(a->frequency.value(), x.frequency.value(), 0.05 * wide) << "N " << N;
      EXPECT_NEAR(b->frequency.value(), x.frequency.value(), 0.05 / L) << "N " << N;
      EXPECT_NEAR(db20(a->amplitude / b->amplitude), 0.0, 0.3) << "N " << N << " f " << x.frequency.value();
    }
  }
}

TEST(TexelLogCentroid, WithinHalfADecibelOfTheMedianForNarrowDistributions) {
  // Log parameterization (Central Pitch = median in dB), Irregularity 0.5 dB:
  // the analysis's log-spectral centroid is within 0.5 dB of the median.
  for (double pitch : {0.0, 5.0, 10.0, 15.0}) {
    TexelSpec spec;
    spec.parameterization = Parameterization::log;
    spec.central_pitch = Decibels(pitch);
    spec.irregularity = Decibels(0.5);
    const Document doc = make_document(load_device("tpad"), spec);
    const auto map = prepare_surface(doc).render();
    const SpectralReport r = analyse_spectrum(map, doc.device.spacing);
    EXPECT_NEAR(r.summary.log_centroid.value(), pitch, 0.5) << "pitch " << pitch;
  }
}

// The encoder's own power-of-two transform equals the DFT's definition
// (X_k = Σ x_j e^{−2πi jk/n}) for every length from 4 to 2^11, both parities
// of log2(n/2) (with and without the radix-2 stage), and KISS FFT's float
// transform at the encoder's 2^15 to float precision.
TEST(Pow2RealFft, EqualsTheDftAndKissFft) {
  std::uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
  };
  for (std::size_t n = 4; n <= 2048; n *= 2) {
    std::vector<double> x(n);
    for (double& v : x) v = uniform();
    texel::detail::Pow2RealFft fft(n);
    std::vector<std::complex<double>> X(n / 2 + 1);
    fft.forward(x, X);
    double worst = 0.0, scale = 0.0;
    for (std::size_t k = 0; k <= n / 2; ++k) {
      std::complex<double> d = 0.0;
      for (std::size_t j = 0; j < n; ++j)
        d += x[j] * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>((j * k) % n) / static_cast<double>(n));
      worst = std::max(worst, std::abs(d - X[k]));
      scale = std::max(scale, std::abs(d));
    }
    EXPECT_LT(worst, 1e-12 * scale * static_cast<double>(n)) << "n = " << n;
  }
  const std::size_t n = std::size_t{1} << 15;
  std::vector<double> x(n);
  for (std::size_t j = 0; j < n; ++j) x[j] = std::sin(0.01 * static_cast<double>(j) * static_cast<double>(j) / 100.0) + uniform();
  std::vector<std::complex<double>> a(n / 2 + 1), b(n / 2 + 1);
  texel::detail::Pow2RealFft(n).forward(x, a);
  texel::detail::RealFft(n).forward(x, b);
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k <= n / 2; ++k)
    worst = std::max(worst, std::abs(a[k] - b[k])), scale = std::max(scale, std::abs(a[k]));
  EXPECT_LT(worst, 1e-4 * scale);
  EXPECT_THROW(texel::detail::Pow2RealFft(6), texel::InvalidArgument);
  EXPECT_THROW(texel::detail::Pow2RealFft(2), texel::InvalidArgument);
}
