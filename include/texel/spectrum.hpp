// Spectral analysis of textures: magnitude spectrum and Welch power spectral
// density against spatial frequency (cycles/mm), peak lists, spectral
// centroids (linear and log-frequency, dB re 1 cycle/mm), spread, band
// energy, and the temporal-frequency view for a swipe speed
// (Hz = cycles/mm × mm/s, docs/algorithm.md §2).
//
// The FFT is KISS FFT (BSD-3, Debian's libkissfft-dev), wrapped in one place
// (src/spectrum/fft.cpp) so it can be swapped. Its "plan" depends only on the
// transform length (no timing-based planning), so every analysis is
// deterministic for a given build. It computes in float: a noise floor near
// −130 dB re the strongest component, far below anything reported here; all
// bookkeeping around it (windows, scaling, interpolation, sums) is double.
//
// Conventions. The mean is removed first (a texture's 0.5 offset is not a
// spectral feature). Spectra are one-sided. `magnitude` is amplitude-
// calibrated: a sinusoid A·sin(2πfx) shows a peak of height A (exactly at a
// bin centre; peaks in `find_peaks` are interpolated so off-bin sinusoids
// report A too). `power` is mean-square amplitude per bin, summing to the
// signal's variance. Welch `density` is a²/(cycle/mm), integrating to the
// variance.
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/level.hpp"
#include "texel/units.hpp"

namespace texel {

/// Analysis windows. Default for the magnitude spectrum: Blackman–Harris
/// (4-term, sidelobes −92 dB), so a peak list with a −40 dB threshold never
/// reports leakage; default for Welch: Hann (the usual PSD choice).
enum class Window { rectangular, hann, blackman_harris, flat_top };
std::string_view to_string(Window w);
Window parse_window(std::string_view text, std::string_view field = "window");
/// Periodic window of length n (the DFT-even form).
std::vector<double> window_coefficients(Window w, std::size_t n);

struct SpectrumOptions {
  Window window = Window::blackman_harris;
  /// Zero padding: the transform is at least zero_pad × the signal length
  /// (1 … 16), rounded up to a length KISS FFT factors quickly (2, 3, 5).
  int zero_pad = 4;
  bool remove_mean = true;
};

/// One-sided spectrum on bins k·bin, k = 0 … nfft/2.
struct Spectrum {
  CyclesPerMm bin;          ///< bin spacing
  CyclesPerMm resolution;   ///< 1 / signal length: the unpadded bin spacing
  std::size_t samples = 0;  ///< signal length (samples)
  std::size_t nfft = 0;     ///< transform length
  Window window = Window::blackman_harris;
  std::vector<double> frequency_cpm;  ///< k·bin, cycles/mm
  std::vector<double> magnitude;      ///< amplitude-calibrated |X_k|
  std::vector<double> power;          ///< mean-square amplitude per bin (sums to the variance)
};

/// Samples are `spacing` apart. Throws InvalidArgument for fewer than 4
/// samples, non-finite values or a bad spacing/option.
Spectrum magnitude_spectrum(std::span<const double> samples, Millimetres spacing, const SpectrumOptions& options = {});

struct WelchOptions {
  Window window = Window::hann;
  /// Segment length in samples; 0 = auto: the largest fast length <= n/4
  /// (at least 64, at most n). Rounded up to an even fast length.
  std::size_t segment = 0;
  double overlap = 0.5;  ///< fraction of a segment, 0 … 0.95
  bool remove_mean = true;
};

struct Psd {
  CyclesPerMm bin;                    ///< bin spacing
  std::size_t segment = 0;            ///< segment length used (samples)
  std::size_t segments = 0;           ///< number averaged
  std::vector<double> frequency_cpm;  ///< k·bin (cycles/mm), k = 0 … segment/2
  std::vector<double> density;        ///< a²/(cycle/mm), one-sided
};

Psd welch_psd(std::span<const double> samples, Millimetres spacing, const WelchOptions& options = {});

struct Peak {
  CyclesPerMm frequency;   ///< interpolated peak frequency
  double amplitude = 0.0;  ///< interpolated peak height (magnitude units)
  DecibelsLevel level;     ///< 20·log10(amplitude / highest peak's amplitude), <= 0
};

struct PeakOptions {
  DecibelsLevel threshold{-40.0};  ///< keep peaks within this many dB of the highest
  std::size_t max_peaks = 32;      ///< strongest first, then reported by frequency
  CyclesPerMm min_frequency{0.0};  ///< ignore bins below (DC is always ignored)
  CyclesPerMm max_frequency{std::numeric_limits<double>::infinity()};
};

/// Local maxima that dominate ±(window main-lobe half-width) bins (so leakage
/// skirts are never peaks), refined by parabolic interpolation of the dB
/// magnitude over three bins. Sorted by frequency.
std::vector<Peak> find_peaks(const Spectrum& spectrum, const PeakOptions& options = {});

/// Power-weighted summary over the bins in [lo, hi] (DC excluded).
struct SpectralSummary {
  CyclesPerMm centroid;      ///< Σ f·P / Σ P
  Decibels log_centroid;     ///< Σ 10·log10(f)·P / Σ P, dB re 1 cycle/mm
  CyclesPerMm spread;        ///< sqrt(Σ (f − centroid)²·P / Σ P)
  Decibels log_spread;       ///< the same in dB of log-frequency
  double total_power = 0.0;  ///< Σ P: mean-square amplitude in the band (a²)
};
SpectralSummary summarize(const Spectrum& spectrum, CyclesPerMm lo = CyclesPerMm(0.0),
                          CyclesPerMm hi = CyclesPerMm(std::numeric_limits<double>::infinity()));

/// Mean-square amplitude (a²) in [lo, hi).
double band_energy(const Spectrum& spectrum, CyclesPerMm lo, CyclesPerMm hi);

/// Temporal frequencies (Hz) felt at swipe speed v for spatial frequencies (cpm).
std::vector<double> temporal_frequencies(std::span<const double> frequency_cpm, MmPerSecond speed);

/// 10·log10(f) for f > 0, else NaN (the dB re 1 cycle/mm axis).
std::vector<double> to_db_axis(std::span<const double> frequency_cpm);

/// Least-squares slope of 10·log10(y) against log10(f) over bins in [lo, hi]
/// (dB per decade); pink noise gives −10, blue +10.
double spectral_slope_db_per_decade(std::span<const double> frequency_cpm, std::span<const double> y, CyclesPerMm lo,
                                    CyclesPerMm hi);

/// Mean-square amplitude in one band and its share of the whole.
struct BandEnergy {
  CyclesPerMm lo;
  CyclesPerMm hi;
  double mean_square = 0.0;  ///< a²
  double fraction = 0.0;     ///< of the total (DC excluded), 0 … 1
};

/// Everything `texel spectrum` reports, computed once.
struct AnalysisOptions {
  SpectrumOptions spectrum;
  WelchOptions welch;
  PeakOptions peaks;
  /// Bands for band energy; empty = decades 0.01, 0.1, 1, 10, 100 … cpm up to Nyquist.
  std::vector<std::pair<CyclesPerMm, CyclesPerMm>> bands;
};

struct SpectralReport {
  Spectrum spectrum;
  Psd psd;
  std::vector<Peak> peaks;
  SpectralSummary summary;  ///< over the whole band (DC excluded)
  std::vector<BandEnergy> bands;
  double mean = 0.0;  ///< mean amplitude (removed before analysis)
  double rms = 0.0;   ///< RMS about the mean
};

/// Magnitude spectrum, Welch PSD, peaks, summary and band energies of one
/// signal. Throws InvalidArgument for bad input or options.
SpectralReport analyse_spectrum(std::span<const double> samples, Millimetres spacing, const AnalysisOptions& options = {});

}  // namespace texel
