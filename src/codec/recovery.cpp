// §4 of docs/encoder.md: parameter recovery for inputs that are themselves
// fine-only Texel renderings.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include "encoder_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"

namespace texel::codec::parts {
namespace {

// Texel-rendering recovery (docs/encoder.md, "Texel renderings").
constexpr double recovery_rms = 0.02;    // residual RMS (re amplitude) below which the input is a rendering
constexpr double recovery_floor = 1e-4;  // residual RMS any rendering's quantization may add (16-bit: ~1e-5)

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

}  // namespace texel::codec::parts
