// The references' spectra, measured with Texel's own spectrum tools. Each
// test states its tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "../support/grids.hpp"
#include "../support/specs.hpp"
#include "texel/reference.hpp"
#include "texel/spectrum.hpp"

using namespace texel;

namespace {
const Grid tpad = test_support::tpad_grid();

ReferenceSpec spec(const std::string& name, std::uint64_t seed = 1) { return test_support::reference_spec(name, seed); }

double db20(double x) { return 20.0 * std::log10(x); }
}  // namespace

TEST(SinusoidReferences, PeaksAtTheirFrequenciesWithEqualHeights) {
  // Tolerances: frequency within 0.1 of the resolution 1/L (0.001 cpm on the
  // tpad); heights equal within 0.1 dB; nothing else above −40 dB.
  const std::map<std::string, std::vector<double>> cases{
      {"2sin", {2.5, 6}}, {"3sin", {2.5, 6, 8.5}}, {"4sin", {2.5, 6, 8.5, 11}}};
  for (const auto& [name, freqs] : cases) {
    const auto a = render_reference(spec(name), tpad);
    const Spectrum s = magnitude_spectrum(a, tpad.spacing);
    const auto peaks = find_peaks(s, {.threshold = DecibelsLevel(-40.0)});
    ASSERT_EQ(peaks.size(), freqs.size()) << name;
    for (std::size_t i = 0; i < freqs.size(); ++i) {
      EXPECT_NEAR(peaks[i].frequency.value(), freqs[i], 0.1 * s.resolution.value()) << name;
      EXPECT_NEAR(peaks[i].level.value(), 0.0, 0.1) << name;
    }
  }
}

TEST(SinusoidReferences, RandomPhasesKeepTheSpectrum) {
  // Tolerance as above: phases change the signal, not the peak list.
  ReferenceSpec s = spec("4sin", 3);
  s.params["phase"] = std::string("random");
  const auto a = render_reference(s, tpad);
  EXPECT_NE(a, render_reference(spec("4sin"), tpad));
  const auto peaks = find_peaks(magnitude_spectrum(a, tpad.spacing));
  ASSERT_EQ(peaks.size(), 4u);
  for (const auto& p : peaks) EXPECT_NEAR(p.level.value(), 0.0, 0.1);
}

namespace {
/// Welch PSD averaged over seeds on a 100 mm, 0.01 mm grid (Nyquist 50 cpm).
Psd mean_psd(const std::string& name, int seeds) {
  const Grid g{Millimetres(0.0), Millimetres(0.01), 10000};
  Psd mean;
  for (int seed = 1; seed <= seeds; ++seed) {
    const auto a = render_reference(spec(name, static_cast<std::uint64_t>(seed)), g);
    Psd p = welch_psd(a, g.spacing, {.segment = 2000});
    if (seed == 1)
      mean = p;
    else
      for (std::size_t k = 0; k < p.density.size(); ++k) mean.density[k] += p.density[k];
  }
  for (double& d : mean.density) d /= seeds;
  return mean;
}
}  // namespace

TEST(NoiseColours, SlopesAndFlatness) {
  // Fit of 10·log10 PSD against log10 f over 1 … 40 cpm (inside the 0.5 … 50
  // cpm band, away from the Welch window's edge smearing), averaged over 12
  // seeds: white 0, pink −10, blue +10 dB/decade, each within ±1.5 dB/decade.
  const std::map<std::string, double> slopes{{"white", 0.0}, {"pink", -10.0}, {"blue", 10.0}};
  for (const auto& [name, slope] : slopes) {
    const Psd p = mean_psd(name, 12);
    EXPECT_NEAR(spectral_slope_db_per_decade(p.frequency_cpm, p.density, CyclesPerMm(1.0), CyclesPerMm(40.0)), slope, 1.5)
        << name;
    // Flatness after removing the nominal slope: every third-octave band
    // average within ±1.5 dB of the overall mean.
    std::vector<double> level;
    for (double lo = 1.0; lo * 1.26 <= 40.0; lo *= 1.26) {
      double sum = 0;
      int n = 0;
      for (std::size_t k = 1; k < p.density.size(); ++k) {
        const double f = p.frequency_cpm[k];
        if (f >= lo && f < lo * 1.26) {
          sum += p.density[k] / std::pow(f, slope / 10.0);
          ++n;
        }
      }
      level.push_back(10 * std::log10(sum / n));
    }
    const double mean = std::accumulate(level.begin(), level.end(), 0.0) / level.size();
    for (double l : level) EXPECT_NEAR(l, mean, 1.5) << name;
  }
}

TEST(NoiseColours, BandEdgesAreRespected) {
  // Nothing synthesised outside the band: every component in [0.5, 50) cpm.
  const Grid g{Millimetres(0.0), Millimetres(0.01), 10000};
  const ReferenceTexture t(spec("pink"), Millimetres(100.0), Sampling{g});
  for (const auto& c : t.components()) {
    EXPECT_GE(c.frequency.value(), 0.5 - 1e-12);
    EXPECT_LT(c.frequency.value(), g.nyquist().value());
  }
}

TEST(Waveforms, HarmonicRatiosAndNoAliasing) {
  // Harmonic n of the 1 cpm fundamental: amplitude ratio 1/n (square, odd n;
  // saw, all n) or 1/n² (tri, odd n), within 0.1 dB for n <= 9; even
  // harmonics of square and tri below −100 dB re the fundamental; every
  // synthesised component below Nyquist and the next harmonic above it.
  for (const std::string name : {"square", "tri", "saw"}) {
    const auto a = render_reference(spec(name), tpad);
    const Spectrum s = magnitude_spectrum(a, tpad.spacing, {.zero_pad = 4});
    const auto peaks = find_peaks(s, {.threshold = DecibelsLevel(-120.0), .max_peaks = 1000});
    auto level_at = [&](double f) {
      for (const auto& p : peaks)
        if (std::abs(p.frequency.value() - f) < 0.02) return p.amplitude;
      return 0.0;
    };
    const double a1 = level_at(1.0);
    ASSERT_GT(a1, 0.0);
    for (int n = 2; n <= 9; ++n) {
      const bool odd = n % 2 == 1;
      const double an = level_at(n);
      if (name == "saw" || odd) {
        const double expected = name == "tri" ? 1.0 / (n * n) : 1.0 / n;
        EXPECT_NEAR(db20(an / a1), db20(expected), 0.1) << name << " harmonic " << n;
      } else {
        // Absent: no peak, or one at the float FFT's noise floor.
        EXPECT_TRUE(an == 0.0 || db20(an / a1) < -100.0) << name << " harmonic " << n << ": " << db20(an / a1);
      }
    }
    const ReferenceTexture t(spec(name), tpad.length(), Sampling{tpad});
    const double top = t.components().back().frequency.value();
    EXPECT_LT(top, tpad.nyquist().value());
    EXPECT_GE(top + (name == "saw" ? 1.0 : 2.0), tpad.nyquist().value());
  }
}

TEST(BandpassNoise, CentreAndMinus3dBWidth) {
  // Power at the texture's harmonics (rectangular window, no padding: bins
  // are exactly the synthesised components), averaged over 8 seeds; the
  // second-order band-pass shape A/(1 + Q²(f/f_c − f_c/f)²) is fitted to it
  // in dB by grid search over f_c and Q. Measured centre f_c within 10 % of
  // the nominal, measured −3 dB width f_c/Q = 2ζ·f_c within 10 %.
  // (A fit, not edge-picking: the top of a wide band is flat and the maximum
  // of a noisy estimate biases picked edges inward.)
  // bandpass-f20-z5 is excluded: its upper −3 dB edge (202 cpm) lies beyond
  // any device's Nyquist frequency, so its width cannot be seen on a grid.
  const Grid g{Millimetres(0.0), Millimetres(0.01), 20000};  // 200 mm, resolution 0.005 cpm, Nyquist 50 cpm
  for (double fc : {1.0, 4.0, 20.0})
    for (double zeta : {0.05, 0.5, 5.0}) {
      if (fc == 20.0 && zeta == 5.0) continue;
      const std::string name = "bandpass-f" + std::to_string(static_cast<int>(fc)) + "-z" +
                               (zeta == 0.05  ? "0.05"
                                : zeta == 0.5 ? "0.5"
                                              : "5");
      const double f1 = fc * (std::sqrt(1 + zeta * zeta) - zeta);
      const double f2 = fc * (std::sqrt(1 + zeta * zeta) + zeta);
      std::vector<double> power, freq;
      for (int seed = 1; seed <= 8; ++seed) {
        ReferenceSpec s = spec(name, static_cast<std::uint64_t>(seed));
        // Synthesise only where the filter has power (time): ≥ 12 dB down at the cut.
        s.params["band_min_cpm"] = f1 / 4;
        s.params["band_max_cpm"] = std::min(49.0, f2 * 4);
        const auto a = render_reference(s, g);
        const Spectrum sp = magnitude_spectrum(a, g.spacing, {.window = Window::rectangular, .zero_pad = 1});
        if (power.empty()) {
          power = sp.power;
          freq = sp.frequency_cpm;
        } else {
          for (std::size_t k = 0; k < power.size(); ++k) power[k] += sp.power[k];
        }
      }
      std::vector<double> f, y;
      for (std::size_t k = 1; k < power.size(); ++k)
        if (freq[k] >= f1 / 2 && freq[k] <= std::min(48.0, 2 * f2) && power[k] > 0) {
          f.push_back(freq[k]);
          y.push_back(10 * std::log10(power[k]));
        }
      // Misfit of the shape at centre c and quality q (the level A is the mean residual).
      std::vector<double> model(f.size());
      const auto misfit = [&](double c, double q) {
        double mean = 0;
        for (std::size_t i = 0; i < f.size(); ++i) {
          const double d = f[i] / c - c / f[i];
          model[i] = -10 * std::log10(1 + q * q * d * d);
          mean += y[i] - model[i];
        }
        mean /= static_cast<double>(f.size());
        double err = 0;
        for (std::size_t i = 0; i < f.size(); ++i) err += (y[i] - model[i] - mean) * (y[i] - model[i] - mean);
        return err;
      };
      // Grid search, coarse (steps of 0.02 in both ratios) then fine (0.005) around the coarse best.
      const double q0 = 1 / (2 * zeta);
      double best = INFINITY, best_rf = 1, best_rq = 1;
      const auto search = [&](double rf0, double rf1, double rq0, double rq1, double step) {
        for (double rf = rf0; rf <= rf1 + 1e-12; rf += step)
          for (double rq = rq0; rq <= rq1 + 1e-12; rq += step)
            if (const double e = misfit(fc * rf, q0 * rq); e < best) best = e, best_rf = rf, best_rq = rq;
      };
      search(0.8, 1.26, 0.7, 1.4, 0.02);
      search(best_rf - 0.02, best_rf + 0.02, best_rq - 0.02, best_rq + 0.02, 0.005);
      const double best_fc = fc * best_rf, best_q = q0 * best_rq;
      EXPECT_NEAR(best_fc / fc, 1.0, 0.10) << name;
      EXPECT_NEAR((best_fc / best_q) / (2 * zeta * fc), 1.0, 0.10) << name << " fitted f_c " << best_fc << " Q " << best_q;
    }
}
