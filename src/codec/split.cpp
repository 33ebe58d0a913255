// §1 of docs/encoder.md: the coarse/fine split (envelope, flat or not,
// profile and strengths).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include "encoder_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::codec::parts {
namespace {

/// Strengths this close to full scale are full scale (docs/encoder.md).
constexpr double strength_snap = 0.02;

// --- envelope tools ---------------------------------------------------------

/// Running max (or min) over a centred window of w samples (i − w/2 …
/// i + w/2, shortened at the ends), into `out`: van Herk / Gil–Werman, three
/// branch-free passes whatever the window (blocks of the window's span k:
/// the prefix extreme within each block from the left, the suffix extreme
/// from the right; a window covers the tail of one block and the head of
/// the next). `g`, `h`: scratch. The prefix and suffix chains of two blocks
/// run interleaved (four independent chains instead of one at a time: each
/// step waits for the one before); every value is the same comparison of
/// the same two numbers as one chain at a time.
template <bool Max>
void running_extreme(const std::vector<double>& x, std::size_t w, std::vector<double>& out, std::vector<double>& g,
                     std::vector<double>& h) {
  const std::size_t n = x.size();
  const std::size_t half = w / 2;
  const std::size_t k = 2 * half + 1;  // the window's span
  out.resize(n);
  if (n == 0) return;
  // x padded with `half` neutral values on each side, to a whole number of blocks.
  const double neutral = Max ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  const std::size_t padded = ((n + 2 * half + k - 1) / k) * k;
  g.assign(padded, neutral);
  std::copy(x.begin(), x.end(), g.begin() + static_cast<std::ptrdiff_t>(half));
  h = g;
  auto pick = [](double a, double b) { return Max ? std::max(a, b) : std::min(a, b); };
  // In place: g[j] = pick(g[j − 1], x_j) reads x_j before writing it, and
  // h[j] = pick(h[j + 1], x_j) likewise.
  std::size_t b = 0;
  for (; b + 2 * k <= padded; b += 2 * k) {
    const std::size_t c = b + k;
    for (std::size_t t = 1; t < k; ++t) {
      g[b + t] = pick(g[b + t - 1], g[b + t]);
      g[c + t] = pick(g[c + t - 1], g[c + t]);
      h[b + k - 1 - t] = pick(h[b + k - t], h[b + k - 1 - t]);
      h[c + k - 1 - t] = pick(h[c + k - t], h[c + k - 1 - t]);
    }
  }
  for (; b < padded; b += k)
    for (std::size_t t = 1; t < k; ++t) {
      g[b + t] = pick(g[b + t - 1], g[b + t]);
      h[b + k - 1 - t] = pick(h[b + k - t], h[b + k - 1 - t]);
    }
  // Window of output i in padded coordinates: [i, i + k − 1].
  for (std::size_t i = 0; i < n; ++i) out[i] = pick(h[i], g[i + k - 1]);
}

/// Centred moving average of w samples, windows shortened at the ends, into
/// `out` (`cum`: scratch). The interior (full windows) is its own loop,
/// which the compiler vectorizes.
void moving_average(const std::vector<double>& x, std::size_t w, std::vector<double>& out, std::vector<double>& cum) {
  const std::size_t n = x.size();
  const std::size_t half = w / 2;
  cum.resize(n + 1);
  cum[0] = 0.0;
  for (std::size_t i = 0; i < n; ++i) cum[i + 1] = cum[i] + x[i];
  out.resize(n);
  auto edge = [&](std::size_t i) {
    const std::size_t lo = i >= half ? i - half : 0;
    const std::size_t hi = std::min(n, i + half + 1);
    out[i] = (cum[hi] - cum[lo]) / static_cast<double>(hi - lo);
  };
  // Full windows: half ≤ i and i + half + 1 ≤ n.
  const std::size_t first = std::min(n, half);
  const std::size_t last = n >= half + 1 ? n - half : 0;  // one past the last full window
  for (std::size_t i = 0; i < first; ++i) edge(i);
  const auto span = static_cast<double>(2 * half + 1);
  const double* c = cum.data();
  double* o = out.data();
  for (std::size_t i = first; i < last; ++i) o[i] = (c[i + half + 1] - c[i - half]) / span;
  for (std::size_t i = std::max(first, last); i < n; ++i) edge(i);
}

/// Work buffers of split(), per thread: the fit splits every two-scale
/// candidate, and fresh signal-sized buffers each time cost more than the
/// arithmetic (page faults).
struct SplitScratch {
  std::vector<double> centred, spectrum, up_raw, up, slow_1, up_slow, lo_raw, lo, cum;
  std::vector<double> prefix, suffix;
};

/// The interior samples [b, e) of texel k of length L: a sample on a texel
/// boundary may round to either side, so it is left out (empty if the texel
/// is under three samples long or beyond the input).
std::pair<std::size_t, std::size_t> interior_samples(std::size_t k, double L, double dx, std::size_t n) {
  const auto b = static_cast<std::size_t>(std::ceil((static_cast<double>(k) * L + dx) / dx));
  const auto e = std::min(n, static_cast<std::size_t>(std::ceil((static_cast<double>(k + 1) * L - dx) / dx)));
  return {b, e};
}

/// Within-texel variance, relative to the total, below which the input is
/// constant over its texels (16-bit quantization adds ~10⁻¹¹ of full scale).
constexpr double stepped_variance = 1e-6;
/// Fraction of the AC power at or above the boundary frequency below which
/// an input has no fine texture (docs/encoder.md §1 step 0).
constexpr double coarse_only_power = 0.05;

/// §1 step 0: an input without fine texture. Its envelope is the signal:
/// e_k is the mean over texel k (of cfg.texel_length), F = 0.
Split coarse_only_split(const std::vector<double>& a, double dx, const EncoderConfig& cfg) {
  const std::size_t n = a.size();
  const double L = cfg.texel_length.value();
  const std::size_t k_count =
      std::max<std::size_t>(1, texel_count(Millimetres(static_cast<double>(n) * dx), cfg.texel_length, Fill::whole_texels));
  std::vector<double> e(k_count, 0.0);
  for (std::size_t k = 0; k < k_count; ++k) {
    // Interior samples, or the nearest one for texels under three samples long.
    auto [b, end] = interior_samples(k, L, dx, n);
    if (end <= b)
      b = std::min(n - 1, static_cast<std::size_t>(std::lround((static_cast<double>(k) + 0.5) * L / dx))), end = b + 1;
    double m = 0.0;
    for (std::size_t i = b; i < end; ++i) m += a[i];
    e[k] = std::clamp(m / static_cast<double>(end - b), 0.0, 1.0);
  }
  Split s;
  s.F = 0.0;
  s.fine.assign(n, 0.0);
  const double e_hi = percentile(e, 0.98);
  const double e_lo = percentile(e, 0.02);
  s.range = e_hi > 0 ? (e_hi - e_lo) / e_hi : 0.0;
  if (s.range < cfg.flat_envelope) {
    s.C = 1.0 - std::accumulate(e.begin(), e.end(), 0.0) / static_cast<double>(k_count);
    if (s.C < strength_snap) s.C = 0.0;
    return s;
  }
  s.coarse = true;
  const double e_min = *std::min_element(e.begin(), e.end());
  s.C = std::clamp(1.0 - e_min, 0.0, 1.0);
  s.c.resize(k_count);
  for (std::size_t k = 0; k < k_count; ++k) s.c[k] = s.C > 0 ? std::clamp((e[k] - e_min) / s.C, 0.0, 1.0) : 1.0;
  return s;
}

/// A flat envelope: strengths from the mean and RMS, which sampling does not
/// bias (the extremes of a sinusoid near the Nyquist frequency are rarely
/// sampled): mean = e(1 − F/2), RMS = e·F/(2√2).
void fine_only_strengths(const std::vector<double>& a, Split& s) {
  const std::size_t n = a.size();
  std::vector<double> fine;
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
  s.fine = std::move(fine);
}

}  // namespace

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

std::optional<double> stepped_texel_length(const std::vector<double>& a, double dx, std::span<const double> lengths) {
  const std::size_t n = a.size();
  std::optional<double> best;
  for (double L : lengths) {
    const auto texels = static_cast<std::size_t>(std::floor(static_cast<double>(n) * dx / L + 1e-9));
    if (texels < 4 || L < 4.0 * dx || (best && L <= *best)) continue;
    // Interior samples of each texel only; the rest after the last whole
    // texel is ignored.
    double within = 0.0, sum = 0.0, sum2 = 0.0;
    std::size_t count = 0;
    for (std::size_t k = 0; k < texels; ++k) {
      const auto [b, e] = interior_samples(k, L, dx, n);
      if (e <= b) continue;
      double m = 0.0;
      for (std::size_t i = b; i < e; ++i) m += a[i];
      m /= static_cast<double>(e - b);
      for (std::size_t i = b; i < e; ++i) within += (a[i] - m) * (a[i] - m), sum += a[i], sum2 += a[i] * a[i];
      count += e - b;
    }
    if (count == 0) continue;
    const double mean = sum / static_cast<double>(count);
    const double total = std::max(0.0, sum2 - mean * sum);
    if (within <= stepped_variance * total + 1e-18 * static_cast<double>(count)) best = L;
  }
  return best;
}

Split split(const std::vector<double>& a, double dx, const EncoderConfig& cfg, SplitMode mode, std::size_t window) {
  Split s;
  split(a, dx, cfg, mode, window, s);
  return s;
}

void split(const std::vector<double>& a, double dx, const EncoderConfig& cfg, SplitMode mode, std::size_t window, Split& s) {
  // Start from a default Split, keeping the signal-sized buffer's storage.
  std::vector<double> storage = std::move(s.fine);
  s = Split{};
  s.fine = std::move(storage);
  const std::size_t n = a.size();
  const double B = cfg.boundary.value();
  const double L = cfg.texel_length.value();
  if (mode == SplitMode::coarse_only) {
    s = coarse_only_split(a, dx, cfg);
    return;
  }
  if (mode == SplitMode::fine_only) {
    // No envelope to estimate: only the strengths (a flat surface has none).
    if (n > 0 && std::all_of(a.begin(), a.end(), [&](double v) { return v == a[0]; })) {
      s.F = 0.0;
      s.C = 1.0 - std::clamp(a[0], 0.0, 1.0);
      s.fine.assign(n, 0.0);
    } else {
      fine_only_strengths(a, s);
    }
    return;
  }

  // Window for the envelope: about two periods of the fine texture, so that
  // every window holds a peak and a trough. The fine frequency is the
  // power-weighted mean above the boundary when that band carries the
  // texture, else of the whole spectrum (a fine texture below the boundary).
  thread_local SplitScratch sc;
  std::size_t w = window;
  if (w == 0) {
    std::size_t m = 0;
    sc.centred.assign(a.begin(), a.end());
    centre(sc.centred);
    power_spectrum(sc.centred, sc.spectrum, m);
    const std::vector<double>& p = sc.spectrum;
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
      return;
    }
    // Next to nothing above the boundary: no fine texture, only coarse
    // features (whose layout touch resolves), e.g. a measured profile.
    if (mode == SplitMode::automatic && hw < coarse_only_power * pw) {
      s = coarse_only_split(a, dx, cfg);
      return;
    }
    const double fbar = hw >= 0.2 * pw ? hf / hw : pf / pw;
    w = static_cast<std::size_t>(std::max(1.0, std::round(2.0 / fbar / dx)));
  }
  s.window = w;
  // One moving average over half the boundary (at least the window) removes
  // the running extremes' steps; it barely attenuates coarse features (a
  // 5 mm period keeps 98 % of its amplitude).
  const auto smooth = std::max(w, static_cast<std::size_t>(std::round(0.5 * B / dx)));
  running_extreme<true>(a, w, sc.up_raw, sc.prefix, sc.suffix);
  moving_average(sc.up_raw, smooth, sc.up, sc.cum);
  std::vector<double>& up = sc.up;
  // The decision coarse-or-not looks at the envelope low-passed at the
  // boundary proper (two passes of B): the envelope of a noise fluctuates
  // at the rate of its bandwidth, which is fine texture, not coarse layout.
  // A forced two-scale split (the fit's candidates) decides nothing.
  const bool decide = mode == SplitMode::automatic;
  if (decide) {
    const auto b_samples = std::max(w, static_cast<std::size_t>(std::round(B / dx)));
    moving_average(sc.up_raw, b_samples, sc.slow_1, sc.cum);
    moving_average(sc.slow_1, b_samples, sc.up_slow, sc.cum);
  }
  const std::vector<double>& up_slow = sc.up_slow;
  running_extreme<false>(a, w, sc.lo_raw, sc.prefix, sc.suffix);
  moving_average(sc.lo_raw, smooth, sc.lo, sc.cum);
  const std::vector<double>& lo = sc.lo;
  for (double& v : up) v = std::clamp(v, 1e-6, 1.0);

  const std::size_t k_count =
      std::max<std::size_t>(1, texel_count(Millimetres(static_cast<double>(n) * dx), cfg.texel_length, Fill::whole_texels));
  std::vector<double> e(k_count), fk(k_count), e_slow(decide ? k_count : 0);
  for (std::size_t k = 0; k < k_count; ++k) {
    const double x = (static_cast<double>(k) + 0.5) * L;
    const auto i = std::min(n - 1, static_cast<std::size_t>(std::max(0.0, std::round(x / dx))));
    e[k] = up[i];
    if (decide) e_slow[k] = std::clamp(up_slow[i], 1e-6, 1.0);
    fk[k] = std::clamp(1.0 - lo[i] / up[i], 0.0, 1.0);
  }
  s.F = std::clamp(percentile(fk, 0.5), 0.0, 1.0);
  if (decide) {
    const double e_hi = percentile(e_slow, 0.98);
    const double e_lo = percentile(e_slow, 0.02);
    s.range = e_hi > 0 ? (e_hi - e_lo) / e_hi : 0.0;
  }
  if (decide && s.range < cfg.flat_envelope) {
    fine_only_strengths(a, s);
  } else {
    s.coarse = true;
    const double e_min = *std::min_element(e.begin(), e.end());
    s.C = std::clamp(1.0 - e_min, 0.0, 1.0);
    s.c.resize(k_count);
    for (std::size_t k = 0; k < k_count; ++k) s.c[k] = s.C > 0 ? std::clamp((e[k] - e_min) / s.C, 0.0, 1.0) : 1.0;
    s.fine.resize(n);
    for (std::size_t i = 0; i < n; ++i) s.fine[i] = a[i] / up[i];
    centre(s.fine);
  }
}

}  // namespace texel::codec::parts
