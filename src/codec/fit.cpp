// §3 of docs/encoder.md: the fit by analysis-by-synthesis (objective,
// Nelder–Mead, identifiability).
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "encoder_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::codec::parts {
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

TexelTexture fine_texture(double p_db, double i_db, const EncoderConfig& cfg, CyclesPerMm band_max, Millimetres length,
                          std::uint64_t seed) {
  return TexelTexture(fine_spec(p_db, i_db, cfg, band_max, seed), length, Sampling{Grid{}, band_max});
}

Percept Fitter::render_percept(double p_db, double i_db, std::uint64_t seed) const {
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
double Fitter::operator()(double p_db, double i_db) {
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

namespace {

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

}  // namespace

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
                 double f_min, const Split* two_scale) {
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

}  // namespace texel::codec::parts
