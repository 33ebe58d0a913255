// The encoder: coarse/fine split, the perceptual model and the
// analysis-by-synthesis fit. docs/encoder.md explains every step and constant.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <memory>
#include <numbers>
#include <numeric>
#include <utility>

#include "../spectrum/fft.hpp"
#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"

namespace texel::codec {
namespace {

using detail::num;

constexpr double ten_over_ln10 = 4.34294481903251827651;
// Texel-rendering recovery (docs/encoder.md, "Texel renderings").
constexpr std::array<double, 3> recovery_texel_lengths_mm{0.25, 0.5, 1.0};  // tried besides --texel-length
constexpr double recovery_rms = 0.02;    // residual RMS (re amplitude) below which the input is a rendering
constexpr double recovery_floor = 1e-4;  // residual RMS any rendering's quantization may add (16-bit: ~1e-5)
double db_of(double cpm) { return ten_over_ln10 * std::log(cpm); }
double cpm_of(double db) { return std::pow(10.0, db / 10.0); }

// --- spectra ------------------------------------------------------------------
// Analysis only (never feeds rendered samples), so the C library's math and
// the spectrum module's float FFT (noise floor near −130 dB, far below the
// model's 50 dB masking floor) are fine here.

std::size_t next_pow2(std::size_t n) {
  std::size_t m = 1;
  while (m < n) m <<= 1;
  return m;
}

constexpr std::size_t max_segment = 1u << 15;
/// Strengths this close to full scale are full scale (docs/encoder.md).
constexpr double strength_snap = 0.02;
/// How much more the envelope must vary than a fine-only texture's own (relative range).
constexpr double coarse_margin = 0.1;
/// Largest band-spectrum difference a fine-only explanation may leave (dB).
constexpr double max_shape_db = 3.0;
/// Masking floor of the model, dB below the strongest spectral component.
constexpr double masked_db = 50.0;

/// One-sided power spectrum (arbitrary scale) of a zero-mean signal: a Hann
/// periodogram zero-padded to a power of two, or Welch's average of
/// half-overlapping 2^15-sample segments for long signals. Bin i is at
/// i/(M·spacing) cpm; returns M through `m_out`.
/// Not texel::welch_psd: that has no zero padding (its bins would sit on a
/// different grid), a periodic rather than this half-sample-centred Hann
/// window, and an n/4 auto segment; the model's thresholds and the codec
/// tests were set with this computation, so only the transform is shared.
std::vector<double> power_spectrum(std::span<const double> x, std::size_t& m_out) {
  const std::size_t n = x.size();
  const std::size_t seg = std::min(n, max_segment);
  const std::size_t m = next_pow2(seg);
  m_out = m;
  std::vector<double> p(m / 2 + 1, 0.0);
  std::vector<double> win(seg);
  for (std::size_t i = 0; i < seg; ++i)
    win[i] = 0.5 - 0.5 * std::cos(2.0 * M_PI * (static_cast<double>(i) + 0.5) / static_cast<double>(seg));
  if (m < 2) {
    // One sample (or none): only the DC bin, and no real FFT of length 1.
    if (seg == 1) p[0] = x[0] * win[0] * x[0] * win[0];
    return p;
  }
  // One plan per length and thread: an encode runs a few hundred transforms
  // of the same length.
  thread_local std::unique_ptr<texel::detail::RealFft> fft;
  if (!fft || fft->size() != m) fft = std::make_unique<texel::detail::RealFft>(m);
  std::vector<double> buf(m, 0.0);
  std::vector<std::complex<double>> X(m / 2 + 1);
  std::size_t count = 0;
  const std::size_t hop = seg == n ? n : seg / 2;
  for (std::size_t start = 0; start + seg <= n; start += hop) {
    for (std::size_t i = 0; i < seg; ++i) buf[i] = x[start + i] * win[i];
    fft->forward(buf, X);
    for (std::size_t i = 0; i <= m / 2; ++i) p[i] += std::norm(X[i]);
    ++count;
  }
  for (double& v : p) v /= static_cast<double>(std::max<std::size_t>(count, 1));
  return p;
}

std::vector<double> centred(std::span<const double> x) {
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
  std::vector<double> y(x.begin(), x.end());
  for (double& v : y) v -= mean;
  return y;
}

// --- envelope tools ---------------------------------------------------------

/// Running max (or min) over a centred window of w samples (monotonic deque, O(n)).
std::vector<double> running_extreme(const std::vector<double>& x, std::size_t w, bool max) {
  const std::size_t n = x.size();
  const std::size_t half = w / 2;
  std::vector<double> out(n);
  std::deque<std::size_t> dq;
  std::size_t next = 0;
  auto better = [&](double a, double b) { return max ? a >= b : a <= b; };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t hi = std::min(n - 1, i + half);
    for (; next <= hi; ++next) {
      while (!dq.empty() && better(x[next], x[dq.back()])) dq.pop_back();
      dq.push_back(next);
    }
    const std::size_t lo = i >= half ? i - half : 0;
    while (dq.front() < lo) dq.pop_front();
    out[i] = x[dq.front()];
  }
  return out;
}

/// Centred moving average of w samples, windows shortened at the ends.
std::vector<double> moving_average(const std::vector<double>& x, std::size_t w) {
  const std::size_t n = x.size();
  const std::size_t half = w / 2;
  std::vector<double> cum(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) cum[i + 1] = cum[i] + x[i];
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t lo = i >= half ? i - half : 0;
    const std::size_t hi = std::min(n, i + half + 1);
    out[i] = (cum[hi] - cum[lo]) / static_cast<double>(hi - lo);
  }
  return out;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  const double t = pos - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] + t * (v[i + 1] - v[i]) : v[i];
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n < 2) return 1.0;
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < n; ++i) ma += a[i], mb += b[i];
  ma /= static_cast<double>(n);
  mb /= static_cast<double>(n);
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 1.0;
}

// --- the coarse/fine split ----------------------------------------------------

struct Split {
  std::vector<double> fine;  // zero-mean fine signal (envelope divided out)
  double range = 0.0;        // relative envelope range (p98 − p2) / p98 at texel centres
  std::size_t window = 0;    // running-extreme window, samples
  bool coarse = false;
  double C = 0.0;
  double F = 1.0;
  std::vector<double> c;  // per-texel coarse profile (coarse only)
};

enum class SplitMode { automatic, fine_only, two_scale };

/// `window` > 0 fixes the running-extreme window (samples) instead of
/// deriving it from the spectrum: candidates are analysed exactly like the input.
Split split(const std::vector<double>& a, double dx, const EncoderConfig& cfg, SplitMode mode = SplitMode::automatic,
            std::size_t window = 0) {
  const std::size_t n = a.size();
  const double B = cfg.boundary.value();
  const double L = cfg.texel_length.value();

  // Window for the envelope: about two periods of the fine texture, so that
  // every window holds a peak and a trough. The fine frequency is the
  // power-weighted mean above the boundary when that band carries the
  // texture, else of the whole spectrum (a fine texture below the boundary).
  Split s;
  std::size_t w = window;
  if (w == 0) {
    std::size_t m = 0;
    const std::vector<double> p = power_spectrum(centred(a), m);
    const double df = 1.0 / (static_cast<double>(m) * dx);
    double pw = 0, pf = 0, hw = 0, hf = 0;
    for (std::size_t i = 1; i < p.size(); ++i) {
      const double f = static_cast<double>(i) * df;
      pw += p[i];
      pf += p[i] * f;
      if (f >= 1.0 / B) hw += p[i], hf += p[i] * f;
    }
    if (!(pw > 0.0)) {
      // A flat surface is a texture too: no fine part, a constant envelope.
      s.F = 0.0;
      s.C = 1.0 - std::clamp(a.empty() ? 1.0 : a[0], 0.0, 1.0);
      s.fine.assign(n, 0.0);
      return s;
    }
    const double fbar = hw >= 0.2 * pw ? hf / hw : pf / pw;
    w = static_cast<std::size_t>(std::max(1.0, std::round(2.0 / fbar / dx)));
  }
  s.window = w;
  // One moving average over half the boundary (at least the window) removes
  // the running extremes' steps; it barely attenuates coarse features (a
  // 5 mm period keeps 98 % of its amplitude).
  const auto smooth = std::max(w, static_cast<std::size_t>(std::round(0.5 * B / dx)));
  const std::vector<double> up_raw = running_extreme(a, w, true);
  std::vector<double> up = moving_average(up_raw, smooth);
  // The decision coarse-or-not looks at the envelope low-passed at the
  // boundary proper (two passes of B): the envelope of a noise fluctuates
  // at the rate of its bandwidth, which is fine texture, not coarse layout.
  const auto b_samples = std::max(w, static_cast<std::size_t>(std::round(B / dx)));
  const std::vector<double> up_slow = moving_average(moving_average(up_raw, b_samples), b_samples);
  std::vector<double> lo = moving_average(running_extreme(a, w, false), smooth);
  for (double& v : up) v = std::clamp(v, 1e-6, 1.0);

  const std::size_t k_count =
      std::max<std::size_t>(1, texel_count(Millimetres(static_cast<double>(n) * dx), cfg.texel_length, Fill::whole_texels));
  std::vector<double> e(k_count), fk(k_count), e_slow(k_count);
  for (std::size_t k = 0; k < k_count; ++k) {
    const double x = (static_cast<double>(k) + 0.5) * L;
    const auto i = std::min(n - 1, static_cast<std::size_t>(std::max(0.0, std::round(x / dx))));
    e[k] = up[i];
    e_slow[k] = std::clamp(up_slow[i], 1e-6, 1.0);
    fk[k] = std::clamp(1.0 - lo[i] / up[i], 0.0, 1.0);
  }
  s.F = std::clamp(percentile(fk, 0.5), 0.0, 1.0);
  const double e_hi = percentile(e_slow, 0.98);
  const double e_lo = percentile(e_slow, 0.02);
  s.range = e_hi > 0 ? (e_hi - e_lo) / e_hi : 0.0;
  std::vector<double> fine(n);
  if (mode == SplitMode::fine_only || (mode == SplitMode::automatic && s.range < cfg.flat_envelope)) {
    // A flat envelope: strengths from the mean and RMS, which sampling does
    // not bias (the extremes of a sinusoid near the Nyquist frequency are
    // rarely sampled): mean = e(1 − F/2), RMS = e·F/(2√2).
    s.coarse = false;
    fine = centred(a);
    double ms = 0.0;
    for (double v : fine) ms += v * v;
    const double rms = std::sqrt(ms / static_cast<double>(n));
    const double mean = std::accumulate(a.begin(), a.end(), 0.0) / static_cast<double>(n);
    const double env = std::min(1.0, mean + std::sqrt(2.0) * rms);
    s.F = env > 0 ? std::clamp(2.0 * std::sqrt(2.0) * rms / env, 0.0, 1.0) : 0.0;
    s.C = 1.0 - env;
    // Within 2 % of full scale counts as full scale (well inside the
    // intensity JND), so a fine-only texture stays a 14-byte stream.
    if (s.C < strength_snap) s.C = 0.0;
    if (s.F > 1.0 - strength_snap) s.F = 1.0;
  } else {
    s.coarse = true;
    const double e_min = *std::min_element(e.begin(), e.end());
    s.C = std::clamp(1.0 - e_min, 0.0, 1.0);
    s.c.resize(k_count);
    for (std::size_t k = 0; k < k_count; ++k) s.c[k] = s.C > 0 ? std::clamp((e[k] - e_min) / s.C, 0.0, 1.0) : 1.0;
    for (std::size_t i = 0; i < n; ++i) fine[i] = a[i] / up[i];
    fine = centred(fine);
  }
  s.fine = std::move(fine);
  return s;
}

// --- the coarse section -------------------------------------------------------

CoarseFields coarse_fields(const std::vector<double>& c, double C, double F, unsigned bits, std::uint32_t stride,
                           std::uint8_t predictor) {
  CoarseFields f;
  f.coarse_strength = static_cast<std::uint8_t>(std::lround(std::clamp(C, 0.0, 1.0) * 255.0));
  f.fine_strength = static_cast<std::uint8_t>(std::lround(std::clamp(F, 0.0, 1.0) * 255.0));
  f.bits = static_cast<std::uint8_t>(bits);
  f.predictor = predictor;
  f.stride = stride;
  const double top = static_cast<double>((1u << bits) - 1u);
  for (std::size_t k = 0; k < c.size(); k += stride) f.levels.push_back(static_cast<std::uint16_t>(std::lround(c[k] * top)));
  return f;
}

/// RMS difference between c and the profile the fields decode to (linear
/// interpolation between stored levels, held flat past the last).
double coarse_error(const std::vector<double>& c, const CoarseFields& f) {
  const double top = static_cast<double>((1u << f.bits) - 1u);
  double sum = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::size_t j = k / f.stride;
    const double t = static_cast<double>(k % f.stride) / f.stride;
    const double a = f.levels[std::min(j, f.levels.size() - 1)] / top;
    const double b = f.levels[std::min(j + 1, f.levels.size() - 1)] / top;
    const double v = j + 1 < f.levels.size() ? a + t * (b - a) : a;
    sum += (v - c[k]) * (v - c[k]);
  }
  return std::sqrt(sum / static_cast<double>(std::max<std::size_t>(c.size(), 1)));
}

std::vector<double> decoded_profile(const CoarseFields& f, std::size_t count) {
  std::vector<double> c(count);
  const double top = static_cast<double>((1u << f.bits) - 1u);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t j = k / f.stride;
    const double t = static_cast<double>(k % f.stride) / f.stride;
    const double a = f.levels[std::min(j, f.levels.size() - 1)] / top;
    const double b = f.levels[std::min(j + 1, f.levels.size() - 1)] / top;
    c[k] = j + 1 < f.levels.size() ? a + t * (b - a) : a;
  }
  return c;
}

// --- analysis-by-synthesis ----------------------------------------------------

/// The fine-only TexelSpec of a candidate under the encoder's settings.
TexelSpec fine_spec(double p_db, double i_db, const EncoderConfig& cfg, CyclesPerMm band_max, std::uint64_t seed) {
  TexelSpec s;
  s.central_pitch = Decibels(p_db);
  s.irregularity = Decibels(i_db);
  s.texel_length = cfg.texel_length;
  s.parameterization = cfg.parameterization;
  s.band_max = band_max;
  s.seed = seed;
  return s;
}

struct Fitter {
  const EncoderConfig& cfg;
  const Percept& target;
  double dx;
  std::size_t samples;
  CyclesPerMm band_max;
  double f_min = 0.0;                // analysis band bottom (the boundary, for the fine part of a two-scale texture)
  const Split* two_scale = nullptr;  // the input's coarse estimate: candidates carry it and are split alike
  int evaluations = 0;

  Percept render_percept(double p_db, double i_db, std::uint64_t seed) const {
    TexelSpec s = fine_spec(p_db, i_db, cfg, band_max, seed);
    if (two_scale) {
      s.coarse_strength = two_scale->C;
      s.fine_strength = two_scale->F;
      s.coarse = ValuesProfile{two_scale->c};
    }
    const TexelTexture t(s, Millimetres(static_cast<double>(samples) * dx),
                         Sampling{Grid{Millimetres(0.0), Millimetres(dx), 0}, band_max});
    std::vector<double> a(samples);
    t.render(Grid{Millimetres(0.0), Millimetres(dx), static_cast<std::int64_t>(samples)}, 0, a);
    if (two_scale) return perceive(split(a, dx, cfg, SplitMode::two_scale, two_scale->window).fine, dx, cfg.model, f_min);
    return perceive(centred(a), dx, cfg.model, f_min);
  }

  /// Mean percept over two candidate draws (common random numbers: the same
  /// two seeds for every candidate, so the objective is smooth in P and I).
  double operator()(double p_db, double i_db) {
    ++evaluations;
    Percept sum;
    constexpr std::array<std::uint64_t, 2> seeds{0x5EED0001, 0x5EED0002};
    try {
      for (auto seed : seeds) {
        const Percept q = render_percept(p_db, i_db, seed);
        sum.pitch_db += q.pitch_db / seeds.size();
        sum.noisiness_db += q.noisiness_db / seeds.size();
        sum.mean_db += q.mean_db / seeds.size();
        sum.spread_db += q.spread_db / seeds.size();
      }
    } catch (const InvalidArgument&) {
      return 1e6;  // not renderable (e.g. too little of the distribution in the band)
    }
    return distance(target, sum, cfg.model);
  }
};

struct Box {
  double p_lo, p_hi, i_lo, i_hi;
  [[nodiscard]] bool inside(double p, double i) const { return p >= p_lo && p <= p_hi && i >= i_lo && i <= i_hi; }
};

/// Nelder–Mead in (P, I) dB; points outside the box cost 1e6 plus their distance to it.
std::array<double, 3> nelder_mead(Fitter& fit, const Box& box, double p0, double i0, double step_p, double step_i, int budget) {
  auto f = [&](double p, double i) {
    if (!box.inside(p, i)) {
      const double dp = std::max({box.p_lo - p, p - box.p_hi, 0.0});
      const double di = std::max({box.i_lo - i, i - box.i_hi, 0.0});
      return 1e6 + dp + di;
    }
    return fit(p, i);
  };
  struct V {
    double p, i, v;
  };
  std::array<V, 3> s{V{p0, i0, f(p0, i0)}, V{p0 + step_p, i0, f(p0 + step_p, i0)}, V{p0, i0 + step_i, f(p0, i0 + step_i)}};
  int used = 3;
  while (used < budget) {
    std::sort(s.begin(), s.end(), [](const V& a, const V& b) { return a.v < b.v; });
    const double size = std::max(std::hypot(s[1].p - s[0].p, s[1].i - s[0].i), std::hypot(s[2].p - s[0].p, s[2].i - s[0].i));
    if (size < 0.01) break;
    const double cp = (s[0].p + s[1].p) / 2, ci = (s[0].i + s[1].i) / 2;
    const V r{cp + (cp - s[2].p), ci + (ci - s[2].i), 0};
    const double fr = f(r.p, r.i);
    ++used;
    if (fr < s[0].v) {
      const V e{cp + 2 * (cp - s[2].p), ci + 2 * (ci - s[2].i), 0};
      const double fe = f(e.p, e.i);
      ++used;
      s[2] = fe < fr ? V{e.p, e.i, fe} : V{r.p, r.i, fr};
    } else if (fr < s[1].v) {
      s[2] = V{r.p, r.i, fr};
    } else {
      const bool outside = fr < s[2].v;
      const V c =
          outside ? V{cp + 0.5 * (r.p - cp), ci + 0.5 * (r.i - ci), 0} : V{cp + 0.5 * (s[2].p - cp), ci + 0.5 * (s[2].i - ci), 0};
      const double fc = f(c.p, c.i);
      ++used;
      if (fc < std::min(fr, s[2].v)) {
        s[2] = V{c.p, c.i, fc};
      } else {
        for (int k = 1; k < 3; ++k) {
          s[k].p = s[0].p + 0.5 * (s[k].p - s[0].p);
          s[k].i = s[0].i + 0.5 * (s[k].i - s[0].i);
          s[k].v = f(s[k].p, s[k].i);
          ++used;
        }
      }
    }
  }
  std::sort(s.begin(), s.end(), [](const V& a, const V& b) { return a.v < b.v; });
  return {s[0].p, s[0].i, s[0].v};
}

/// A fine-only Texel texture of the encoder's settings.
TexelTexture fine_texture(double p_db, double i_db, const EncoderConfig& cfg, CyclesPerMm band_max, Millimetres length,
                          std::uint64_t seed = 0x5EED0001) {
  return TexelTexture(fine_spec(p_db, i_db, cfg, band_max, seed), length, Sampling{Grid{}, band_max});
}

struct FineFit {
  double p_db = 10.0, i_db = -5.0, distance = 0.0;
  Percept input;
  bool identifiable = true;
  double bound_db = 0.0;
  int evaluations = 0;
};

/// Identifiability: does a much narrower distribution feel different?
void identifiability(Fitter& fit, const Box& box, FineFit& out) {
  const double narrower = std::max(box.i_lo, out.i_db - 6.0);
  if (fit(out.p_db, narrower) - out.distance < 0.5) {
    out.identifiable = false;
    double bound = out.i_db;
    for (double i = out.i_db + 1.0; i <= box.i_hi; i += 1.0) {
      if (fit(out.p_db, i) - out.distance >= 0.5) break;
      bound = i;
    }
    out.bound_db = bound;
  }
}

Box fit_box(const EncoderConfig& cfg, CyclesPerMm band_max) {
  Box box{-20.0 + 0.5, db_of(band_max.value()) - 0.01, -40.0, 10.0};
  if (cfg.parameterization == Parameterization::log) box.i_lo = 0.0, box.i_hi = 15.0;
  return box;
}

FineFit fit_fine(const std::vector<double>& fine, double dx, std::size_t cand, CyclesPerMm band_max, const EncoderConfig& cfg,
                 double f_min = 0.0, const Split* two_scale = nullptr) {
  FineFit out;
  out.input = perceive(fine, dx, cfg.model, f_min);
  Fitter fit{cfg, out.input, dx, cand, band_max, f_min, two_scale};
  const Box box = fit_box(cfg, band_max);
  // Start from the physical centroid and spread of the fine spectrum, then
  // the best of a coarse grid around it (wide distributions make the
  // objective rough enough to trap a simplex far from the optimum).
  double p0 = std::clamp(out.input.mean_db, box.p_lo, box.p_hi);
  double i0 = cfg.parameterization == Parameterization::log
                  ? std::clamp(out.input.spread_db, box.i_lo, box.i_hi)
                  : std::clamp(db_of(cpm_of(p0) * out.input.spread_db / ten_over_ln10), box.i_lo, box.i_hi);
  double best_v = fit(p0, i0);
  const double gp = p0, gi = i0;
  for (double dp : {-3.0, 0.0, 3.0})
    for (double di : {-8.0, 0.0, 8.0}) {
      const double p = gp + dp, i = gi + di;
      if ((dp == 0.0 && di == 0.0) || !box.inside(p, i)) continue;
      const double v = fit(p, i);
      if (v < best_v) best_v = v, p0 = p, i0 = i;
    }
  auto best = nelder_mead(fit, box, p0, i0, 1.5, 4.0, cfg.max_evaluations / 2);
  best = nelder_mead(fit, box, best[0], best[1], 0.5, 2.0, cfg.max_evaluations / 2);  // restart: NM can stall
  out.p_db = best[0];
  out.i_db = best[1];
  out.distance = best[2];
  identifiability(fit, box, out);
  out.evaluations = fit.evaluations;
  return out;
}

// --- parameter recovery for inputs that are Texel renderings -----------------

/// A fine-only Texel rendering is a + g·sin(2π·u(x)) with u piecewise linear:
/// slope f_k (the texel's frequency) over texel k = [kL, (k+1)L), continuous
/// across texel boundaries. For a candidate L the frequencies are recovered
/// texel by texel (the start phase is the previous texel's end phase; a grid
/// over f a quarter of 1/L apart, then a local refinement of f and phase), and
/// the residual says whether the input is such a rendering.
struct Recovered {
  double L = 0.0;
  double rms = 1e9;  // residual RMS, relative to the amplitude g
  std::vector<double> f;
};

Recovered recover_frequencies(const std::vector<double>& y, double dx, double L, double f_top) {
  Recovered r;
  r.L = L;
  const std::size_t n = y.size();
  const auto texels = static_cast<std::size_t>(std::floor(static_cast<double>(n) * dx / L + 1e-9));
  if (texels < 4) return r;
  double sse = 0.0;
  std::size_t used = 0;
  double phase = 0.0;
  auto range = [&](std::size_t k) {
    const auto b = static_cast<std::size_t>(std::ceil(static_cast<double>(k) * L / dx - 1e-6));
    const auto e = std::min(n, static_cast<std::size_t>(std::ceil(static_cast<double>(k + 1) * L / dx - 1e-6)));
    return std::pair{b, e};
  };
  auto cost = [&](std::size_t b, std::size_t e, double x0, double ph, double f) {
    double s = 0.0;
    for (std::size_t i = b; i < e; ++i) {
      const double d = y[i] - detmath::sin_cycles(ph + f * (static_cast<double>(i) * dx - x0));
      s += d * d;
    }
    return s;
  };
  const double step = 0.1 / L;  // at most 0.05 cycles of phase off at the texel's end
  for (std::size_t k = 0; k < texels; ++k) {
    // Not a structured binding: clang 14 cannot capture one in the lambdas below.
    const auto bounds = range(k);
    const std::size_t b = bounds.first;
    const std::size_t e = bounds.second;
    if (e <= b + 2) return r;
    const double x0 = static_cast<double>(k) * L;
    std::vector<double> phases;
    if (k == 0) {  // y(0) = sin(2π φ0): two candidates
      const double s0 = std::asin(std::clamp(y[b], -1.0, 1.0)) / (2.0 * std::numbers::pi);
      phases = {s0 - std::floor(s0), 0.5 - s0 - std::floor(0.5 - s0)};
    } else {
      phases = {phase};
    }
    // Grid over f for each start phase; Gauss–Newton on (phase, f) from the
    // lowest few local minima of the grid (aliases near the Nyquist frequency
    // can fit a short texel almost as well as the true frequency).
    bool free_phase = k == 0;
    auto refine = [&](double& ph, double& fq, double& c0) {
      for (int it = 0; it < 12; ++it) {
        double a11 = 0, a12 = 0, a22 = 0, g1 = 0, g2 = 0;
        for (std::size_t i = b; i < e; ++i) {
          const double t = static_cast<double>(i) * dx - x0;
          const double u = ph + fq * t;
          const double res = y[i] - detmath::sin_cycles(u);
          const double c = 2.0 * std::numbers::pi * detmath::cos_cycles(u);
          a11 += c * c, a12 += c * c * t, a22 += c * c * t * t, g1 += c * res, g2 += c * t * res;
        }
        const double det = a11 * a22 - a12 * a12;
        if (!(std::fabs(det) > 1e-300 && a22 > 1e-300)) break;
        // Phase continuity: only the first texel's start phase is free.
        double dp = free_phase ? (a22 * g1 - a12 * g2) / det : 0.0;
        double df = free_phase ? (a11 * g2 - a12 * g1) / det : g2 / a22;
        bool improved = false;
        for (int h = 0; h < 12 && !improved; ++h, dp *= 0.5, df *= 0.5) {
          if (fq + df <= 0.0) continue;
          const double c = cost(b, e, x0, ph + dp, fq + df);
          if (c < c0) c0 = c, ph += dp, fq += df, improved = true;
        }
        if (!improved || c0 < 1e-20 * static_cast<double>(e - b)) break;
      }
    };
    double best = 1e300, bf = 0.0, bp = 0.0;
    auto search = [&](const std::vector<double>& starts) {
      for (double ph : starts) {
        std::vector<double> fs, cs;
        for (double fq = 0.01; fq <= f_top + step; fq += step) fs.push_back(fq), cs.push_back(cost(b, e, x0, ph, fq));
        std::vector<std::size_t> minima;
        for (std::size_t j = 0; j < cs.size(); ++j)
          if ((j == 0 || cs[j] <= cs[j - 1]) && (j + 1 == cs.size() || cs[j] <= cs[j + 1])) minima.push_back(j);
        std::sort(minima.begin(), minima.end(), [&](std::size_t u, std::size_t v) { return cs[u] < cs[v]; });
        if (minima.size() > 4) minima.resize(4);
        for (std::size_t j : minima) {
          double p1 = ph, f1 = fs[j], c1 = cs[j];
          refine(p1, f1, c1);
          if (c1 < best) best = c1, bf = f1, bp = p1;
        }
      }
    };
    search(phases);
    // The previous texel may have ended near a crest, where its end phase is
    // poorly determined: if this texel does not fit, let its start phase move
    // a little (a few hundredths of a cycle) around the prediction.
    if (k > 0 && best > 1e-6 * static_cast<double>(e - b)) {  // residual RMS above 1e-3
      free_phase = true;
      search({phase - 0.03, phase - 0.01, phase + 0.01, phase + 0.03});
    }
    sse += best;
    used += e - b;
    if (k >= 8 && sse > 0.05 * 0.05 * static_cast<double>(used)) return r;  // not a Texel rendering of this L
    r.f.push_back(bf);
    const double next = bp + bf * L;
    phase = next - std::floor(next);
  }
  r.rms = std::sqrt(sse / static_cast<double>(std::max<std::size_t>(used, 1)));
  return r;
}

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::numbers::sqrt2); }

/// Maximum-likelihood (μ, σ) of ln f for a lognormal truncated to [lo, hi].
std::pair<double, double> truncated_lognormal_mle(const std::vector<double>& f, double lo, double hi) {
  std::vector<double> l(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) l[i] = std::log(std::clamp(f[i], lo, hi));
  const double nn = static_cast<double>(l.size());
  double mu = std::accumulate(l.begin(), l.end(), 0.0) / nn, var = 0.0;
  for (double v : l) var += (v - mu) * (v - mu);
  double ls = 0.5 * std::log(std::max(var / nn, 1e-12));
  const double a = std::log(lo), bb = std::log(hi);
  auto nll = [&](double m, double lsig) {
    const double s = std::exp(lsig);
    double q = 0.0;
    for (double v : l) q += 0.5 * ((v - m) / s) * ((v - m) / s);
    const double mass = normal_cdf((bb - m) / s) - normal_cdf((a - m) / s);
    return q + nn * lsig + nn * std::log(std::max(mass, 1e-300));
  };
  double best = nll(mu, ls), st_m = 0.5, st_s = 0.2;
  for (int it = 0; it < 200 && (st_m > 1e-7 || st_s > 1e-7); ++it) {
    bool moved = false;
    for (auto [dm, ds] : {std::pair{st_m, 0.0}, std::pair{-st_m, 0.0}, std::pair{0.0, st_s}, std::pair{0.0, -st_s}}) {
      const double c = nll(mu + dm, ls + ds);
      if (c < best) best = c, mu += dm, ls += ds, moved = true;
    }
    if (!moved) st_m *= 0.5, st_s *= 0.5;
  }
  return {mu, std::exp(ls)};
}

/// Recovered parameters of an input that is itself a fine-only Texel
/// rendering (docs/encoder.md, "Texel renderings"), if it is one.
struct TexelRecovery {
  double L = 0.0, p_db = 0.0, i_db = 0.0, rms = 0.0;
  std::size_t texels = 0;
};

std::optional<TexelRecovery> recover_texel(const std::vector<double>& a, double dx, const EncoderConfig& cfg,
                                           CyclesPerMm band_max) {
  const auto [lo_it, hi_it] = std::minmax_element(a.begin(), a.end());
  const double g = 0.5 * (*hi_it - *lo_it), c = 0.5 * (*hi_it + *lo_it);
  if (g < 0.01) return std::nullopt;
  std::vector<double> y(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) y[i] = (a[i] - c) / g;
  std::vector<double> lengths{cfg.texel_length.value()};
  for (double L : recovery_texel_lengths_mm) lengths.push_back(L);
  std::sort(lengths.begin(), lengths.end(), std::greater<>());
  lengths.erase(std::unique(lengths.begin(), lengths.end()), lengths.end());
  const double len = static_cast<double>(a.size()) * dx;
  // A rendering of L also fits every divisor of L, and a narrow distribution
  // almost fits longer lengths: take the longest length whose residual is
  // close to the best one's (quantization noise sets that floor).
  std::vector<Recovered> fits;
  double best_rms = 1e9;
  for (double L : lengths) {
    if (len < 16.0 * L) continue;
    fits.push_back(recover_frequencies(y, dx, L, band_max.value()));
    best_rms = std::min(best_rms, fits.back().rms);
  }
  for (const Recovered& r : fits) {  // longest first
    if (!(r.rms < recovery_rms && r.rms <= 2.0 * best_rms + recovery_floor)) continue;
    const double L = r.L;
    const double lo = PitchDistributionConfig{}.band_min.value();
    // A renderer never draws below the band: mostly near-zero "frequencies"
    // are a stepped envelope (a coarse-only texture), not texels. (A texel
    // or two near a crest may fit low; the likelihood clamps them to the band.)
    const auto below = std::count_if(r.f.begin(), r.f.end(), [&](double v) { return v < 0.9 * lo; });
    if (static_cast<double>(below) > 0.1 * static_cast<double>(r.f.size())) continue;
    const auto [mu, sigma] = truncated_lognormal_mle(r.f, lo, band_max.value());
    TexelRecovery t;
    t.L = L;
    t.rms = r.rms;
    t.texels = r.f.size();
    if (cfg.parameterization == Parameterization::log) {
      t.p_db = db_of(std::exp(mu));
      t.i_db = sigma * ten_over_ln10;
    } else {
      const double m = std::exp(mu + 0.5 * sigma * sigma);
      t.p_db = db_of(m);
      t.i_db = db_of(m * std::sqrt(std::expm1(sigma * sigma)));
    }
    return t;
  }
  return std::nullopt;
}

/// How differently two signals of the same length distribute their power
/// over half-octave bands (0.01 cpm … Nyquist): the power-weighted mean
/// absolute level difference in dB, each spectrum normalised to unit power
/// and floored 40 dB below it.
double shape_distance_db(const std::vector<double>& x, const std::vector<double>& y, double dx) {
  std::size_t m = 0;
  const std::vector<double> px = power_spectrum(centred(x), m);
  const std::vector<double> py = power_spectrum(centred(y), m);
  const double df = 1.0 / (static_cast<double>(m) * dx);
  std::vector<double> bx, by;
  for (std::size_t i = 1; i < px.size(); ++i) {
    const double f = static_cast<double>(i) * df;
    if (f < 0.01) continue;
    const auto band = static_cast<std::size_t>(std::floor(2.0 * std::log2(f / 0.01)));
    if (band >= bx.size()) bx.resize(band + 1, 0.0), by.resize(band + 1, 0.0);
    bx[band] += px[i];
    by[band] += py[i];
  }
  const double tx = std::accumulate(bx.begin(), bx.end(), 0.0), ty = std::accumulate(by.begin(), by.end(), 0.0);
  if (!(tx > 0 && ty > 0)) return 0.0;
  double num_ = 0.0, den = 0.0;
  for (std::size_t b = 0; b < bx.size(); ++b) {
    const double u = bx[b] / tx + 1e-4, v = by[b] / ty + 1e-4;
    const double w = std::max(u, v);
    num_ += w * std::fabs(10.0 * std::log10(u / v));
    den += w;
  }
  return num_ / den;
}

}  // namespace

// --- the perceptual model -------------------------------------------------------

double threshold_db(Hertz f) {
  const double hz = std::max(f.value(), 1e-6);
  const double pacinian = 12.0 * std::fabs(std::log2(hz / 250.0));
  return std::min({pacinian, 30.0, 60.0});
}

Percept perceive(std::span<const double> fine, double spacing_mm, const PerceptualModel& model, double f_min_cpm) {
  std::size_t m = 0;
  const std::vector<double> p = power_spectrum(fine, m);
  const double v = model.swipe_speed.value();
  // Per-bin frequency, dB and sensitivity depend only on (M, Δx, v): cache them.
  struct Bins {
    std::size_t m = 0;
    double dx = 0, v = 0, f_min = 0;
    std::vector<double> f, d, gain;
  };
  thread_local Bins bins;
  const double f_lo = std::max(0.01, f_min_cpm);
  if (bins.m != m || bins.dx != spacing_mm || bins.v != v || bins.f_min != f_lo) {
    bins.m = m, bins.dx = spacing_mm, bins.v = v, bins.f_min = f_lo;
    const double df = 1.0 / (static_cast<double>(m) * spacing_mm);
    bins.f.assign(p.size(), 0.0);
    bins.d.assign(p.size(), 0.0);
    bins.gain.assign(p.size(), 0.0);
    for (std::size_t i = 1; i < p.size(); ++i) {
      const double f = static_cast<double>(i) * df;
      bins.f[i] = f;
      bins.d[i] = db_of(f);
      // Sensitivity at f·v over sqrt(f): amplitude per unit log-frequency.
      bins.gain[i] = f < f_lo ? 0.0 : std::pow(10.0, -threshold_db(Hertz(f * v)) / 20.0) / std::sqrt(f);
    }
  }
  // Components more than `masked_db` below the strongest are not felt
  // (and leakage and quantization noise stay out of the spread).
  double peak = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i)
    if (bins.gain[i] > 0.0) peak = std::max(peak, p[i]);
  const double floor = peak * std::pow(10.0, -masked_db / 10.0);
  double sw = 0, swf = 0, swd = 0, swdd = 0;  // perceptual weights
  double sp = 0, spf = 0, spd = 0, spdd = 0;  // physical (power) weights
  for (std::size_t i = 1; i < p.size(); ++i) {
    if (!(p[i] > floor) || bins.gain[i] == 0.0) continue;
    const double f = bins.f[i], d = bins.d[i];
    const double w = std::sqrt(p[i]) * bins.gain[i];
    sw += w, swf += w * f, swd += w * d, swdd += w * d * d;
    sp += p[i], spf += p[i] * f, spd += p[i] * d, spdd += p[i] * d * d;
  }
  if (!(sw > 0.0)) throw InvalidArgument("the fine texture is empty: no spectral content above " + num(f_lo) + " cycles/mm");
  Percept q;
  q.pitch_db = db_of(swf / sw);
  const double md = swd / sw;
  q.noisiness_db = std::sqrt(std::max(0.0, swdd / sw - md * md));
  q.mean_db = db_of(spf / sp);
  const double pd = spd / sp;
  q.spread_db = std::sqrt(std::max(0.0, spdd / sp - pd * pd));
  return q;
}

double distance(const Percept& a, const Percept& b, const PerceptualModel& model) {
  const double dp = (a.pitch_db - b.pitch_db) / model.pitch_jnd_db;
  const double dn = (a.noisiness_db - b.noisiness_db) / model.noisiness_jnd_db;
  const double dm = a.mean_db - b.mean_db;
  const double ds = a.spread_db - b.spread_db;
  return std::sqrt(dp * dp + dn * dn + model.tie_weight * (dm * dm + ds * ds));
}

// --- encode -------------------------------------------------------------------

EncodeResult encode(const Signal& signal, const EncoderConfig& cfg) {
  const auto t0 = std::chrono::steady_clock::now();
  const double dx = signal.spacing.value();
  const std::size_t n = signal.amplitude.size();
  if (!(std::isfinite(dx) && dx > 0.0)) throw InvalidArgument("signal spacing is " + num(dx) + " mm; it must be > 0");
  if (!(cfg.boundary.value() > 0.0 && std::isfinite(cfg.boundary.value())))
    throw FieldError("boundary", "is " + num(cfg.boundary.value()) + " mm; it must be > 0");
  if (!(cfg.texel_length.value() >= 0.001 && cfg.texel_length.value() <= 65.535))
    throw FieldError("texel_length", "is " + num(cfg.texel_length.value()) + " mm; allowed: 0.001 … 65.535 mm");
  if (!(cfg.model.swipe_speed.value() > 0.0 && std::isfinite(cfg.model.swipe_speed.value())))
    throw FieldError("swipe_speed", "is " + num(cfg.model.swipe_speed.value()) + " mm/s; it must be > 0");
  if (cfg.coarse_bits < 1 || cfg.coarse_bits > 16)
    throw FieldError("coarse_bits", "is " + std::to_string(cfg.coarse_bits) + "; allowed: 1 … 16");
  const double len = static_cast<double>(n) * dx;
  if (n < 64 || len < 4.0 * cfg.texel_length.value())
    throw InvalidArgument("the input has " + std::to_string(n) + " samples over " + num(len) +
                          " mm; at least 64 samples and 4 texels are needed");
  for (double v : signal.amplitude)
    if (!std::isfinite(v)) throw InvalidArgument("the input holds a non-finite value");
  std::vector<double> a = signal.amplitude;
  for (double& v : a) v = std::clamp(v, 0.0, 1.0);

  EncodeResult res;
  res.samples = n;
  res.spacing = Millimetres(dx);
  // The band the decoded texture draws from: the analysed grid's Nyquist
  // frequency, rounded down to the stream's 0.01 dB steps (device independent).
  Bitstream b;
  FineFields& f = b.fine;
  f.band_max_cdb = static_cast<std::int16_t>(std::floor(db_of(0.5 / dx) * 100.0));
  const CyclesPerMm band_max = to_cpm(Decibels(f.band_max_cdb / 100.0));
  f.seed = cfg.seed;
  f.parameterization = cfg.parameterization;
  const std::size_t cand = std::min<std::size_t>(n, std::size_t{1} << 16);

  // An input that is itself a fine-only Texel rendering: recover its texel
  // length and (P, I) from the texels' frequencies; kept if the model says
  // the result feels the same as the input (else the fit below decides).
  const std::optional<TexelRecovery> rec = cfg.recover_texel ? recover_texel(a, dx, cfg, band_max) : std::nullopt;
  const double L_used = rec ? rec->L : cfg.texel_length.value();
  f.texel_length_um = static_cast<std::uint16_t>(std::lround(L_used * 1000.0));
  EncoderConfig fit_cfg = cfg;
  fit_cfg.texel_length = Millimetres(f.texel_length_um / 1000.0);

  Split sp = split(a, dx, fit_cfg, rec ? SplitMode::fine_only : SplitMode::automatic);
  FineFit fit;
  bool has_fine = sp.F >= 0.02;
  bool recovered = false;
  if (rec && has_fine) {
    FineFit r;
    r.input = perceive(sp.fine, dx, fit_cfg.model);
    Fitter fitter{fit_cfg, r.input, dx, cand, band_max, 0.0, nullptr};
    const Box box = fit_box(fit_cfg, band_max);
    r.p_db = std::clamp(rec->p_db, box.p_lo, box.p_hi);
    r.i_db = std::clamp(rec->i_db, box.i_lo, box.i_hi);
    r.distance = fitter(r.p_db, r.i_db);
    // The residual test has decided that the input is this rendering; the
    // model still reports the distance and whether Irregularity is felt.
    identifiability(fitter, box, r);
    r.evaluations = fitter.evaluations;
    fit = r;
    recovered = true;
    res.texel_recovered = true;
  }
  if (recovered) {
  } else if (sp.coarse && has_fine) {
    // Analysis-by-synthesis for the split too: a fine-only texture with low
    // or widely spread frequencies has an uneven envelope by itself. Keep the
    // coarse profile only if the input's envelope varies clearly more than
    // that of the best fine-only explanation.
    Split flat = split(a, dx, fit_cfg, SplitMode::fine_only);
    EncoderConfig quick = fit_cfg;  // the check needs the neighbourhood, not the last 0.1 dB
    quick.max_evaluations = fit_cfg.max_evaluations / 3;
    FineFit flat_fit = fit_fine(flat.fine, dx, cand, band_max, quick);
    std::vector<double> r(n);
    fine_texture(flat_fit.p_db, flat_fit.i_db, fit_cfg, band_max, Millimetres(len))
        .render(Grid{Millimetres(0.0), Millimetres(dx), static_cast<std::int64_t>(n)}, 0, r);
    const Split own = split(r, dx, fit_cfg);
    const double shape = shape_distance_db(a, r, dx);
    if (sp.range <= own.range + coarse_margin && shape <= max_shape_db) {
      sp = std::move(flat);
      fit = flat_fit;
    } else {
      fit = fit_fine(sp.fine, dx, cand, band_max, fit_cfg, 1.0 / cfg.boundary.value(), &sp);
      fit.evaluations += flat_fit.evaluations;
    }
  } else if (has_fine) {
    fit = fit_fine(sp.fine, dx, cand, band_max, fit_cfg);
  }
  res.coarse = sp.coarse;
  has_fine = sp.F >= 0.02;
  double p_est = 10.0, i_est = cfg.parameterization == Parameterization::log ? 1.0 : -5.0;
  if (has_fine) {
    p_est = fit.p_db;
    i_est = fit.i_db;
    res.input = fit.input;
    res.irregularity_identifiable = fit.identifiable;
    res.irregularity_bound_db = fit.bound_db;
    res.evaluations = fit.evaluations;
  }
  f.central_pitch_cdb = static_cast<std::int16_t>(std::lround(p_est * 100.0));
  f.irregularity_cdb = static_cast<std::int16_t>(std::lround(i_est * 100.0));

  // Coarse part and strengths.
  const double F = has_fine ? sp.F : 0.0;
  std::vector<double> decoded_c;
  if (sp.coarse) {
    std::vector<CoarseFields> options;
    if (cfg.max_bytes) {
      for (unsigned bits = 8; bits >= 2; --bits)
        for (std::uint32_t stride : {1u, 2u, 3u, 4u, 6u, 8u, 12u, 16u, 24u, 32u, 48u, 64u})
          for (std::uint8_t pred : {std::uint8_t{1}, std::uint8_t{2}})
            options.push_back(coarse_fields(sp.c, sp.C, F, bits, stride, pred));
    } else {
      for (std::uint8_t pred : {std::uint8_t{1}, std::uint8_t{2}})
        options.push_back(coarse_fields(sp.c, sp.C, F, cfg.coarse_bits, 1, pred));
    }
    const std::size_t fixed = write_bitstream(b).size();
    const CoarseFields* chosen = nullptr;
    double chosen_err = 0;
    std::size_t chosen_size = 0;
    for (const auto& o : options) {
      const std::size_t size = fixed + coarse_section_bytes(o);
      if (cfg.max_bytes && size > *cfg.max_bytes) continue;
      const double err = coarse_error(sp.c, o);
      if (!chosen || err < chosen_err - 1e-12 || (std::fabs(err - chosen_err) <= 1e-12 && size < chosen_size))
        chosen = &o, chosen_err = err, chosen_size = size;
    }
    if (!chosen)
      throw FieldError("max_bytes", std::to_string(*cfg.max_bytes) +
                                        " is too small for this texture's coarse profile; it needs at least " +
                                        std::to_string(fixed + coarse_section_bytes(options.back())) + " bytes");
    b.coarse = *chosen;
    decoded_c = decoded_profile(*chosen, sp.c.size());
    res.coarse_correlation = correlation(sp.c, decoded_c);
  } else {
    const auto c8 = static_cast<std::uint8_t>(std::lround(sp.C * 255.0));
    const auto f8 = static_cast<std::uint8_t>(std::lround(F * 255.0));
    if (c8 != 0 || f8 != 255) {
      CoarseFields c;
      c.coarse_strength = c8;
      c.fine_strength = f8;
      c.bits = 0;
      b.coarse = c;
    }
  }
  res.bytes = write_bitstream(b);
  res.bitstream = parse_bitstream(res.bytes);  // what a decoder sees
  res.spec = to_spec(res.bitstream);

  // The decoded texture on the input's grid, under the model.
  if (has_fine) {
    const TexelTexture t(res.spec, Millimetres(len), Sampling{Grid{Millimetres(0.0), Millimetres(dx), 0}, band_max});
    std::vector<double> d(n);
    t.render(Grid{Millimetres(0.0), Millimetres(dx), static_cast<std::int64_t>(n)}, 0, d);
    EncoderConfig c2 = fit_cfg;
    const Split dsp = res.coarse ? split(d, dx, c2, SplitMode::two_scale, sp.window) : split(d, dx, c2, SplitMode::fine_only);
    res.decoded = perceive(dsp.fine, dx, cfg.model, res.coarse ? 1.0 / cfg.boundary.value() : 0.0);
    res.model_distance = distance(res.input, res.decoded, cfg.model);
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

Document decode_document(const Bitstream& b, const DeviceProfile& device) { return make_document(device, to_spec(b)); }

}  // namespace texel::codec
