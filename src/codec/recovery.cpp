// §4 of docs/encoder.md: parameter recovery for inputs that are themselves
// fine-only Texel renderings.
#include <algorithm>
#include <bit>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include "../spectrum/fft.hpp"
#include "encoder_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"

namespace texel::codec::parts {
namespace {

// Texel-rendering recovery (docs/encoder.md, "Texel renderings").
constexpr double recovery_rms = 0.02;    // residual RMS (re amplitude) below which the input is a rendering
constexpr double recovery_floor = 1e-4;  // residual RMS any rendering's quantization may add (16-bit: ~1e-5)
constexpr double fits_exactly = 1e-9;  // residual power per sample (RMS 3·10⁻⁵) of a texel fitted to the quantization floor

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
  // Analysis only: libm's sine (the fit's residuals, not rendered bytes).
  constexpr double two_pi = 2.0 * std::numbers::pi;
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
  // sin and cos of 2π(ph + f·t_i) over a texel's samples by rotation (one
  // complex product per sample; the drift over a texel, ~10⁻¹⁴, is far
  // below anything the fit resolves).
  auto for_each_phase = [&](std::size_t b, std::size_t e, double x0, double ph, double f, auto&& body) {
    const double t0 = static_cast<double>(b) * dx - x0;
    std::complex<double> z = std::polar(1.0, two_pi * (ph + f * t0));
    const std::complex<double> w = std::polar(1.0, two_pi * f * dx);
    for (std::size_t i = b; i < e; ++i, z *= w) body(i, static_cast<double>(i) * dx - x0, z.imag(), z.real());
  };
  auto cost = [&](std::size_t b, std::size_t e, double x0, double ph, double f) {
    double s = 0.0;
    for_each_phase(b, e, x0, ph, f, [&](std::size_t i, double, double sn, double) {
      const double d = y[i] - sn;
      s += d * d;
    });
    return s;
  };
  const double step = 0.1 / L;  // at most 0.05 cycles of phase off at the texel's end
  // One transform length for every texel: grid steps of at most `step`.
  const std::size_t m =
      std::max<std::size_t>(16, std::bit_ceil(static_cast<std::size_t>(std::ceil(std::max(1.0 / (step * dx), L / dx + 2.0)))));
  thread_local std::unique_ptr<texel::detail::RealFft> fft;
  if (!fft || fft->size() != m) fft = std::make_unique<texel::detail::RealFft>(m);
  std::vector<double> buf(m), fs, cs;
  std::vector<std::complex<double>> spectrum(m / 2 + 1), grid_a(m / 2 + 1), grid_b(m / 2 + 1);
  // G_j(len) for the texel lengths in samples met so far (a texel spans
  // ⌊L/dx⌋ or ⌈L/dx⌉ samples: two tables, not one per texel).
  std::vector<std::pair<std::size_t, std::vector<std::complex<double>>>> geometric_tables;
  std::vector<std::size_t> minima;
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
    const double span = static_cast<double>(e - b) * dx;  // the texel's extent, mm
    auto refine = [&](double& ph, double& fq, double& c0) {
      for (int it = 0; it < 12; ++it) {
        double a11 = 0, a12 = 0, a22 = 0, g1 = 0, g2 = 0;
        for_each_phase(b, e, x0, ph, fq, [&](std::size_t i, double t, double sn, double cs_) {
          const double res = y[i] - sn;
          const double c = two_pi * cs_;
          a11 += c * c, a12 += c * c * t, a22 += c * c * t * t, g1 += c * res, g2 += c * t * res;
        });
        const double det = a11 * a22 - a12 * a12;
        if (!(std::fabs(det) > 1e-300 && a22 > 1e-300)) break;
        // Phase continuity: only the first texel's start phase is free.
        double dp = free_phase ? (a22 * g1 - a12 * g2) / det : 0.0;
        double df = free_phase ? (a11 * g2 - a12 * g1) / det : g2 / a22;
        // Converged: a step that moves the phase by less than 10⁻¹⁰ cycles
        // anywhere in the texel changes nothing the fit is used for (the
        // residual sits at the input's own rounding floor by then).
        if (std::fabs(dp) + std::fabs(df) * span < 1e-10) break;
        bool improved = false;
        for (int h = 0; h < 12 && !improved; ++h, dp *= 0.5, df *= 0.5) {
          if (fq + df <= 0.0) continue;
          const double c = cost(b, e, x0, ph + dp, fq + df);
          if (c < c0) c0 = c, ph += dp, fq += df, improved = true;
        }
        if (!improved || c0 < 1e-20 * static_cast<double>(e - b)) break;
      }
    };
    // The grid: cost(f) = Σy² − 2·Σ y·sin 2π(φ + f·t) + Σ sin² 2π(φ + f·t)
    // for every f = j/(M·dx) at once. The middle sum is Im(e^{2πiφ}·A(f)),
    // A(f) = Σ y_i e^{2πi f t_i}, one real FFT of the texel's samples
    // (t_i = i'·dx + δ, δ = b·dx − x0); the last is n/2 − ½·Re(e^{4πi(φ+fδ)}·
    // G(f)) with G a geometric sum in closed form. So any start phase costs
    // O(M) after one transform, instead of O(n) per grid point.
    const std::size_t len = e - b;
    const double delta = static_cast<double>(b) * dx - x0;
    std::fill(buf.begin(), buf.end(), 0.0);
    double yy = 0.0;
    for (std::size_t i = 0; i < len; ++i) buf[i] = y[b + i], yy += y[b + i] * y[b + i];
    fft->forward(buf, spectrum);
    const double df_grid = 1.0 / (static_cast<double>(m) * dx);
    const std::size_t j_top = std::min(m / 2, static_cast<std::size_t>(std::ceil((f_top + step) / df_grid)));
    // Per grid point, independent of the start phase: A_j = e^{2πi f_j δ}·
    // conj(X_j) and B_j = e^{4πi f_j δ}·G_j(len); rotations by recurrence.
    auto table = std::find_if(geometric_tables.begin(), geometric_tables.end(), [&](const auto& t) { return t.first == len; });
    if (table == geometric_tables.end()) {
      std::vector<std::complex<double>> g(m / 2 + 1);
      for (std::size_t j = 0; j <= m / 2; ++j) {
        const double fq = static_cast<double>(j) * df_grid;
        const std::complex<double> ratio = std::polar(1.0, 4.0 * std::numbers::pi * fq * dx);
        g[j] = std::abs(1.0 - ratio) < 1e-12
                   ? std::complex<double>(static_cast<double>(len))
                   : (1.0 - std::polar(1.0, 4.0 * std::numbers::pi * fq * dx * static_cast<double>(len))) / (1.0 - ratio);
      }
      table = geometric_tables.insert(geometric_tables.end(), {len, std::move(g)});
    }
    const std::vector<std::complex<double>>& geometric = table->second;
    const std::complex<double> turn_delta = std::polar(1.0, 2.0 * std::numbers::pi * df_grid * delta);
    std::complex<double> rot = 1.0;
    for (std::size_t j = 0; j <= j_top; ++j, rot *= turn_delta) {
      grid_a[j] = rot * std::conj(spectrum[j]);
      grid_b[j] = rot * rot * geometric[j];
    }
    auto grid_cost = [&](const std::complex<double>& e1, const std::complex<double>& e2, std::size_t j) {
      return yy - 2.0 * (e1 * grid_a[j]).imag() + 0.5 * static_cast<double>(len) - 0.5 * (e2 * grid_b[j]).real();
    };
    double best = 1e300, bf = 0.0, bp = 0.0;
    auto search = [&](const std::vector<double>& starts) {
      for (double ph : starts) {
        fs.clear(), cs.clear();
        // The band's bottom (0.01 cpm) by direct sum, then the FFT grid.
        fs.push_back(0.01), cs.push_back(cost(b, e, x0, ph, 0.01));
        const std::complex<double> e1 = std::polar(1.0, 2.0 * std::numbers::pi * ph);
        const std::complex<double> e2 = e1 * e1;
        for (std::size_t j = 1; j <= j_top; ++j) {
          const double fq = static_cast<double>(j) * df_grid;
          if (fq > 0.01) fs.push_back(fq), cs.push_back(grid_cost(e1, e2, j));
        }
        minima.clear();
        for (std::size_t j = 0; j < cs.size(); ++j)
          if ((j == 0 || cs[j] <= cs[j - 1]) && (j + 1 == cs.size() || cs[j] <= cs[j + 1])) minima.push_back(j);
        std::sort(minima.begin(), minima.end(), [&](std::size_t u, std::size_t v) { return cs[u] < cs[v]; });
        if (minima.size() > 4) minima.resize(4);
        for (std::size_t j : minima) {
          // The grid's cost is a rounding-level approximation (it can even
          // dip below zero at an exact fit): refine from the direct sum.
          double p1 = ph, f1 = fs[j], c1 = cost(b, e, x0, ph, f1);
          refine(p1, f1, c1);
          if (c1 < best) best = c1, bf = f1, bp = p1;
          // A fit at the 16-bit quantization floor is the texel's frequency:
          // the other minima (aliases) fit worse.
          if (best < fits_exactly * static_cast<double>(len)) return;
        }
      }
    };
    search(phases);
    // The previous texel may have ended near a crest, where its end phase is
    // poorly determined: if this texel does not fit, let its start phase move
    // a little (a few hundredths of a cycle) around the prediction — when the
    // texels so far fit (residual RMS under 1e-3): an input whose texels
    // already do not fit is no rendering, and the four extra searches per
    // texel were most of the time spent rejecting it (e.g. a triangle wave).
    const bool fitting_so_far = sse <= 1e-6 * static_cast<double>(used);
    if (k > 0 && fitting_so_far && best > 1e-6 * static_cast<double>(e - b)) {  // residual RMS above 1e-3
      free_phase = true;
      search({phase - 0.03, phase - 0.01, phase + 0.01, phase + 0.03});
    }
    sse += best;
    used += e - b;
    // Not a Texel rendering of this L: a running residual RMS above 0.05
    // after 8 texels, or far above it (0.2) after 3, or a residual that can
    // no longer end below the acceptance RMS over the whole input.
    if (k >= 8 && sse > 0.05 * 0.05 * static_cast<double>(used)) return r;
    if (k >= 2 && sse > 0.2 * 0.2 * static_cast<double>(used)) return r;
    if (sse > recovery_rms * recovery_rms * static_cast<double>(n)) return r;
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

}  // namespace

std::optional<TexelRecovery> recover_texel(const std::vector<double>& a, double dx, const EncoderConfig& cfg,
                                           CyclesPerMm band_max) {
  const auto [lo_it, hi_it] = std::minmax_element(a.begin(), a.end());
  const double g = 0.5 * (*hi_it - *lo_it), c = 0.5 * (*hi_it + *lo_it);
  if (g < 0.01) return std::nullopt;
  std::vector<double> y(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) y[i] = (a[i] - c) / g;
  std::vector<double> lengths{cfg.texel_length.value()};
  for (double L : candidate_texel_lengths_mm) lengths.push_back(L);
  std::sort(lengths.begin(), lengths.end(), std::greater<>());
  lengths.erase(std::unique(lengths.begin(), lengths.end()), lengths.end());
  const double len = static_cast<double>(a.size()) * dx;
  // A rendering of L also fits every divisor of L, and a narrow distribution
  // almost fits longer lengths: take the longest length whose residual is
  // close to the best one's (quantization noise sets that floor). Longest
  // first, so a length that fits at the floor is taken without trying its
  // divisors: no shorter length can beat it by more than the floor.
  auto accept = [&](const Recovered& r) -> std::optional<TexelRecovery> {
    const double L = r.L;
    const double lo = PitchDistributionConfig{}.band_min.value();
    // A renderer never draws below the band: mostly near-zero "frequencies"
    // are a stepped envelope (a coarse-only texture), not texels. (A texel
    // or two near a crest may fit low; the likelihood clamps them to the band.)
    const auto below = std::count_if(r.f.begin(), r.f.end(), [&](double v) { return v < 0.9 * lo; });
    if (static_cast<double>(below) > 0.1 * static_cast<double>(r.f.size())) return std::nullopt;
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
  };
  std::vector<Recovered> fits;
  double best_rms = 1e9;
  auto close_to_best = [&](const Recovered& r) { return r.rms < recovery_rms && r.rms <= 2.0 * best_rms + recovery_floor; };
  for (double L : lengths) {
    if (len < 16.0 * L) continue;
    fits.push_back(recover_frequencies(y, dx, L, band_max.value()));
    best_rms = std::min(best_rms, fits.back().rms);
    // At the floor, r.rms ≤ 2·best + floor holds whatever the shorter
    // lengths give; it is the answer unless a longer length already passes
    // (which the shorter lengths' residuals could still rule out).
    if (fits.back().rms <= recovery_floor)
      if (auto t = accept(fits.back())) {
        bool longer_taken = false;
        for (std::size_t j = 0; j + 1 < fits.size() && !longer_taken; ++j)
          longer_taken = close_to_best(fits[j]) && accept(fits[j]);
        if (!longer_taken) return t;  // else the shorter lengths may still lower best_rms: go on
      }
  }
  for (const Recovered& r : fits)  // longest first
    if (close_to_best(r))
      if (auto t = accept(r)) return t;
  return std::nullopt;
}

}  // namespace texel::codec::parts
