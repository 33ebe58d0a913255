#include "texel/spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numeric>

#include "fft.hpp"
#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"

namespace texel {
namespace {

using detail::num;

void check_signal(std::span<const double> x, double spacing_mm, std::size_t min_samples) {
  if (!(std::isfinite(spacing_mm) && spacing_mm > 0.0))
    throw InvalidArgument("sample spacing is " + num(spacing_mm) + " mm; it must be a finite number > 0");
  if (x.size() < min_samples)
    throw InvalidArgument("the signal has " + std::to_string(x.size()) + " samples; spectral analysis needs at least " +
                          std::to_string(min_samples));
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]))
      throw InvalidArgument("sample " + std::to_string(i) + " is " + num(x[i]) + "; samples must be finite");
}

/// Main-lobe half-width in (unpadded) bins: beyond it, a sinusoid's
/// transform is leakage, never a separate peak.
double main_lobe_half_width(Window w) {
  switch (w) {
    case Window::rectangular: return 1.0;
    case Window::hann: return 2.0;
    case Window::blackman_harris: return 4.0;
    case Window::flat_top: return 5.0;
  }
  return 4.0;
}

double mean_of(std::span<const double> x) { return std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size()); }

}  // namespace

std::string_view to_string(Window w) {
  switch (w) {
    case Window::rectangular: return "rectangular";
    case Window::hann: return "hann";
    case Window::blackman_harris: return "blackman-harris";
    case Window::flat_top: return "flat-top";
  }
  return "?";
}

Window parse_window(std::string_view text, std::string_view field) {
  for (Window w : {Window::rectangular, Window::hann, Window::blackman_harris, Window::flat_top})
    if (text == to_string(w)) return w;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) +
                        "'; allowed: rectangular, hann, blackman-harris, flat-top");
}

std::vector<double> window_coefficients(Window w, std::size_t n) {
  std::vector<double> c(n, 1.0);
  // Cosine-sum windows Σ (−1)^m a_m cos(2π m j/n); periodic form.
  std::vector<double> a;
  switch (w) {
    case Window::rectangular: return c;
    case Window::hann: a = {0.5, 0.5}; break;
    case Window::blackman_harris: a = {0.35875, 0.48829, 0.14128, 0.01168}; break;
    case Window::flat_top: a = {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368}; break;
  }
  for (std::size_t j = 0; j < n; ++j) {
    const double t = static_cast<double>(j) / static_cast<double>(n);
    double v = a[0];
    for (std::size_t m = 1; m < a.size(); ++m) {
      const double term = a[m] * detmath::cos_cycles(static_cast<double>(m) * t);
      v = m % 2 == 1 ? v - term : v + term;
    }
    c[j] = v;
  }
  return c;
}

Spectrum magnitude_spectrum(std::span<const double> samples, Millimetres spacing, const SpectrumOptions& options) {
  const double spacing_mm = spacing.value();
  check_signal(samples, spacing_mm, 4);
  if (options.zero_pad < 1 || options.zero_pad > 16)
    throw InvalidArgument("zero padding is " + std::to_string(options.zero_pad) + "; allowed: 1 … 16");
  const std::size_t n = samples.size();
  const std::size_t nfft = detail::fast_fft_length(n * static_cast<std::size_t>(options.zero_pad));
  const std::vector<double> w = window_coefficients(options.window, n);
  // Remove the window-weighted mean, so the windowed signal has no DC at all
  // and the window's main lobe around 0 cpm does not leak into the lowest bins.
  double sum_w = 0.0;
  double sum_w2 = 0.0;
  double sum_wx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum_w += w[i];
    sum_w2 += w[i] * w[i];
    sum_wx += w[i] * samples[i];
  }
  const double mean = options.remove_mean ? sum_wx / sum_w : 0.0;
  std::vector<double> buf(nfft, 0.0);
  for (std::size_t i = 0; i < n; ++i) buf[i] = (samples[i] - mean) * w[i];
  std::vector<std::complex<double>> X(nfft / 2 + 1);
  detail::RealFft fft(nfft);
  fft.forward(buf, X);

  Spectrum s;
  s.samples = n;
  s.nfft = nfft;
  s.window = options.window;
  s.bin = CyclesPerMm(1.0 / (static_cast<double>(nfft) * spacing_mm));
  s.resolution = CyclesPerMm(1.0 / (static_cast<double>(n) * spacing_mm));
  const std::size_t bins = nfft / 2 + 1;
  s.frequency_cpm.resize(bins);
  s.magnitude.resize(bins);
  s.power.resize(bins);
  const double pnorm = 1.0 / (static_cast<double>(nfft) * sum_w2);
  for (std::size_t k = 0; k < bins; ++k) {
    const bool edge = k == 0 || k == nfft / 2;
    const double m2 = std::norm(X[k]);
    s.frequency_cpm[k] = static_cast<double>(k) * s.bin.value();
    s.magnitude[k] = (edge ? 1.0 : 2.0) * std::sqrt(m2) / sum_w;
    s.power[k] = (edge ? 1.0 : 2.0) * m2 * pnorm;
  }
  return s;
}

Psd welch_psd(std::span<const double> samples, Millimetres spacing, const WelchOptions& options) {
  const double spacing_mm = spacing.value();
  check_signal(samples, spacing_mm, 4);
  if (!(options.overlap >= 0.0 && options.overlap <= 0.95))
    throw InvalidArgument("Welch overlap is " + num(options.overlap) + "; allowed: 0 … 0.95");
  const std::size_t n = samples.size();
  std::size_t seg = options.segment;
  if (seg == 0) {
    // The largest fast length <= n/4 (four or more segments), at least 64.
    const std::size_t target = std::max<std::size_t>(n / 4, std::min<std::size_t>(64, n));
    seg = 2;
    for (std::size_t m = 2; m <= target; m = detail::fast_fft_length(m + 1)) seg = m;
  } else if (seg > n || seg < 4) {
    throw InvalidArgument("Welch segment is " + std::to_string(seg) + " samples; allowed: 4 … " + std::to_string(n) +
                          " (the signal's length)");
  }
  seg -= seg % 2;
  const auto step =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::floor(static_cast<double>(seg) * (1.0 - options.overlap))));
  const std::vector<double> w = window_coefficients(options.window, seg);
  const double sum_w2 = std::inner_product(w.begin(), w.end(), w.begin(), 0.0);
  detail::RealFft fft(seg);
  std::vector<double> buf(seg);
  std::vector<std::complex<double>> X(seg / 2 + 1);
  Psd p;
  p.segment = seg;
  p.bin = CyclesPerMm(1.0 / (static_cast<double>(seg) * spacing_mm));
  p.frequency_cpm.resize(seg / 2 + 1);
  p.density.assign(seg / 2 + 1, 0.0);
  for (std::size_t start = 0; start + seg <= n; start += step) {
    const auto part = samples.subspan(start, seg);
    const double mean = options.remove_mean ? mean_of(part) : 0.0;
    for (std::size_t i = 0; i < seg; ++i) buf[i] = (part[i] - mean) * w[i];
    fft.forward(buf, X);
    for (std::size_t k = 0; k < X.size(); ++k) p.density[k] += std::norm(X[k]);
    ++p.segments;
  }
  const double norm = spacing_mm / (sum_w2 * static_cast<double>(p.segments));
  for (std::size_t k = 0; k < p.density.size(); ++k) {
    const bool edge = k == 0 || k == seg / 2;
    p.density[k] *= (edge ? 1.0 : 2.0) * norm;
    p.frequency_cpm[k] = static_cast<double>(k) * p.bin.value();
  }
  return p;
}

std::vector<Peak> find_peaks(const Spectrum& s, const PeakOptions& options) {
  const std::size_t bins = s.magnitude.size();
  std::vector<Peak> peaks;
  if (bins < 3) return peaks;
  const double pad = s.resolution / s.bin;  // padded bins per unpadded bin
  const auto half = static_cast<std::size_t>(std::ceil(main_lobe_half_width(s.window) * pad));
  auto db = [&](std::size_t k) { return 20.0 * std::log10(std::max(s.magnitude[k], 1e-300)); };
  struct Candidate {
    double f, amp;
  };
  std::vector<Candidate> cands;
  for (std::size_t k = 1; k + 1 < bins; ++k) {
    const double f = s.frequency_cpm[k];
    if (f < options.min_frequency.value() || f > options.max_frequency.value()) continue;
    const double m = s.magnitude[k];
    if (!(m > s.magnitude[k - 1] && m >= s.magnitude[k + 1]) || m <= 0.0) continue;
    bool dominant = true;
    const std::size_t lo = k > half ? k - half : 1;  // DC does not compete
    const std::size_t hi = std::min(bins - 1, k + half);
    for (std::size_t j = lo; j <= hi && dominant; ++j)
      if (s.magnitude[j] > m) dominant = false;
    if (!dominant) continue;
    // Parabola through the three dB values. A neighbour at the float FFT's
    // floor (or exactly 0) would put the vertex anywhere: interpolate only
    // between bins inside one main lobe, and never move a peak by more than a
    // rectangular window's worst scalloping loss (3.92 dB).
    double p = 0.0;
    double level = db(k);
    if (s.magnitude[k - 1] > 1e-7 * m && s.magnitude[k + 1] > 1e-7 * m) {
      const double a = db(k - 1), b = db(k), c = db(k + 1);
      const double den = a - 2.0 * b + c;
      if (den < 0.0) {
        p = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
        level = std::min(b - 0.25 * (a - c) * p, b + 3.92);
      }
    }
    cands.push_back({(static_cast<double>(k) + p) * s.bin.value(), std::pow(10.0, level / 20.0)});
  }
  if (cands.empty()) return peaks;
  const double top = std::max_element(cands.begin(), cands.end(), [](auto& x, auto& y) { return x.amp < y.amp; })->amp;
  std::sort(cands.begin(), cands.end(), [](auto& x, auto& y) { return x.amp > y.amp; });
  for (const auto& c : cands) {
    const double level = 20.0 * std::log10(c.amp / top);
    if (level < options.threshold.value() || peaks.size() >= options.max_peaks) break;
    peaks.push_back({CyclesPerMm(c.f), c.amp, DecibelsLevel(level)});
  }
  std::sort(peaks.begin(), peaks.end(), [](const Peak& x, const Peak& y) { return x.frequency < y.frequency; });
  return peaks;
}

SpectralSummary summarize(const Spectrum& s, CyclesPerMm lo_cpm, CyclesPerMm hi_cpm) {
  const double lo = lo_cpm.value(), hi = hi_cpm.value();
  double p_sum = 0.0, f_sum = 0.0, l_sum = 0.0;
  for (std::size_t k = 1; k < s.power.size(); ++k) {
    const double f = s.frequency_cpm[k];
    if (f < lo || f > hi) continue;
    p_sum += s.power[k];
    f_sum += f * s.power[k];
    l_sum += 10.0 * std::log10(f) * s.power[k];
  }
  SpectralSummary r;
  r.total_power = p_sum;
  if (!(p_sum > 0.0)) return r;
  const double fc = f_sum / p_sum;
  const double lc = l_sum / p_sum;
  double v = 0.0, lv = 0.0;
  for (std::size_t k = 1; k < s.power.size(); ++k) {
    const double f = s.frequency_cpm[k];
    if (f < lo || f > hi) continue;
    v += (f - fc) * (f - fc) * s.power[k];
    const double d = 10.0 * std::log10(f) - lc;
    lv += d * d * s.power[k];
  }
  r.centroid = CyclesPerMm(fc);
  r.log_centroid = Decibels(lc);
  r.spread = CyclesPerMm(std::sqrt(v / p_sum));
  r.log_spread = Decibels(std::sqrt(lv / p_sum));
  return r;
}

double band_energy(const Spectrum& s, CyclesPerMm lo_cpm, CyclesPerMm hi_cpm) {
  const double lo = lo_cpm.value(), hi = hi_cpm.value();
  double e = 0.0;
  for (std::size_t k = 1; k < s.power.size(); ++k)
    if (s.frequency_cpm[k] >= lo && s.frequency_cpm[k] < hi) e += s.power[k];
  return e;
}

std::vector<double> temporal_frequencies(std::span<const double> f, MmPerSecond speed) {
  std::vector<double> hz(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) hz[i] = temporal(CyclesPerMm(f[i]), speed).value();
  return hz;
}

std::vector<double> to_db_axis(std::span<const double> f) {
  std::vector<double> d(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) d[i] = f[i] > 0.0 ? 10.0 * std::log10(f[i]) : std::nan("");
  return d;
}

double spectral_slope_db_per_decade(std::span<const double> f, std::span<const double> y, CyclesPerMm lo_cpm,
                                    CyclesPerMm hi_cpm) {
  const double lo = lo_cpm.value(), hi = hi_cpm.value();
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < f.size() && i < y.size(); ++i) {
    if (!(f[i] >= lo && f[i] <= hi && f[i] > 0.0 && y[i] > 0.0)) continue;
    const double x = std::log10(f[i]);
    const double v = 10.0 * std::log10(y[i]);
    sx += x;
    sy += v;
    sxx += x * x;
    sxy += x * v;
    ++n;
  }
  if (n < 2) throw InvalidArgument("slope fit over " + num(lo) + " … " + num(hi) + " cpm has fewer than 2 usable bins");
  const double nd = static_cast<double>(n);
  return (nd * sxy - sx * sy) / (nd * sxx - sx * sx);
}

SpectralReport analyse_spectrum(std::span<const double> samples, Millimetres spacing, const AnalysisOptions& options) {
  const double spacing_mm = spacing.value();
  SpectralReport r;
  r.spectrum = magnitude_spectrum(samples, spacing, options.spectrum);
  r.psd = welch_psd(samples, spacing, options.welch);
  r.peaks = find_peaks(r.spectrum, options.peaks);
  r.summary = summarize(r.spectrum);
  r.mean = mean_of(samples);
  double v = 0.0;
  for (double x : samples) v += (x - r.mean) * (x - r.mean);
  r.rms = std::sqrt(v / static_cast<double>(samples.size()));
  const double nyquist = 0.5 / spacing_mm;
  std::vector<std::pair<CyclesPerMm, CyclesPerMm>> bands = options.bands;
  if (bands.empty())
    for (double lo = 0.01; lo < nyquist; lo *= 10.0)
      bands.emplace_back(CyclesPerMm(lo), CyclesPerMm(std::min(lo * 10.0, nyquist * (1.0 + 1e-12))));
  for (const auto& [lo, hi] : bands) {
    if (!(lo.value() >= 0.0 && hi > lo && std::isfinite(hi.value())))
      throw InvalidArgument("band " + num(lo.value()) + " … " + num(hi.value()) + " cpm: it needs 0 <= low < high, both finite");
    const double e = band_energy(r.spectrum, lo, hi);
    r.bands.push_back({lo, hi, e, r.summary.total_power > 0.0 ? e / r.summary.total_power : 0.0});
  }
  return r;
}

}  // namespace texel
