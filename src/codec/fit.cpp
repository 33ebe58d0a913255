// §3 of docs/encoder.md: the fit by analysis-by-synthesis (objective,
// Nelder–Mead, identifiability).
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
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

void Fitter::render(double p_db, double i_db, std::uint64_t seed, std::vector<double>& a) const {
  TexelSpec s = fine_spec(p_db, i_db, cfg, band_max, seed);
  if (two_scale) {
    s.coarse_strength = two_scale->C;
    s.fine_strength = two_scale->F;
    s.coarse = ValuesProfile{two_scale->c};
  }
  const TexelTexture t(s, Millimetres(static_cast<double>(samples) * dx),
                       Sampling{Grid{Millimetres(0.0), Millimetres(dx), 0}, band_max});
  a.resize(samples);
  t.render(Grid{Millimetres(0.0), Millimetres(dx), static_cast<std::int64_t>(samples)}, 0, a);
}

Percept Fitter::render_percept(double p_db, double i_db, std::uint64_t seed) const {
  thread_local std::vector<double> a;  // reused across candidates (no allocation per evaluation)
  render(p_db, i_db, seed, a);
  if (two_scale) {
    thread_local Split sp;  // reused, like `a`
    split(a, dx, cfg, SplitMode::two_scale, two_scale->window, sp);
    return perceive(sp.fine, dx, cfg.model, f_min);
  }
  centre(a);
  return perceive(a, dx, cfg.model, f_min);
}

std::array<Percept, 2> Fitter::render_percepts(double p_db, double i_db, std::array<std::uint64_t, 2> seeds) const {
  thread_local std::array<std::vector<double>, 2> a;  // reused across candidates
  render(p_db, i_db, seeds[0], a[0]);
  render(p_db, i_db, seeds[1], a[1]);
  centre(a[0], a[1]);
  return {perceive(a[0], dx, cfg.model, f_min), perceive(a[1], dx, cfg.model, f_min)};
}

/// Mean percept over two candidate draws (common random numbers: the same
/// two seeds for every candidate, so the objective is smooth in P and I).
/// A point evaluated before is not rendered again (the least-squares search
/// starts from the grid's best point; identifiability revisits the fit).
std::optional<Percept> Fitter::percept(double p_db, double i_db) {
  for (const auto& [p, i, d, q] : memo)
    if (p == p_db && i == i_db && d == draws) return q;
  std::optional<Percept> q = evaluate(p_db, i_db);
  memo.push_back({p_db, i_db, draws, q});
  return q;
}

std::optional<Percept> Fitter::evaluate(double p_db, double i_db) {
  ++evaluations;
  Percept sum;
  constexpr std::array<std::uint64_t, 2> seeds{0x5EED0001, 0x5EED0002};
  const auto used = static_cast<double>(std::clamp(draws, 1, 2));
  try {
    auto find = [&](std::size_t d) {
      return std::find_if(drawn.begin(), drawn.end(),
                          [&](const Drawn& x) { return x.p_db == p_db && x.i_db == i_db && x.seed == seeds[d]; });
    };
    if (used == 2 && !two_scale && find(0) == drawn.end() && find(1) == drawn.end()) {
      // Both draws new: rendered first, then centred in one pass (each
      // draw's mean is the same sum; two sums at once instead of one after
      // the other, each addition waiting for the one before).
      const std::array<Percept, 2> q = render_percepts(p_db, i_db, seeds);
      drawn.push_back({p_db, i_db, seeds[0], q[0]});
      drawn.push_back({p_db, i_db, seeds[1], q[1]});
    }
    for (std::size_t d = 0; d < static_cast<std::size_t>(used); ++d) {
      auto seen = find(d);
      if (seen == drawn.end()) {
        drawn.push_back({p_db, i_db, seeds[d], render_percept(p_db, i_db, seeds[d])});
        seen = drawn.end() - 1;
      }
      const Percept& q = seen->percept;
      sum.pitch_db += q.pitch_db / used;
      sum.noisiness_db += q.noisiness_db / used;
      sum.mean_db += q.mean_db / used;
      sum.spread_db += q.spread_db / used;
      sum.drawn_pitch_db += q.drawn_pitch_db / used;
      sum.drawn_noisiness_db += q.drawn_noisiness_db / used;
      sum.log_centroid_db += q.log_centroid_db / used;
    }
  } catch (const InvalidArgument&) {
    return std::nullopt;  // not renderable (e.g. too little of the distribution in the band)
  }
  return sum;
}

double Fitter::operator()(double p_db, double i_db) {
  if (cfg.target == EncoderConfig::Target::centroid) {  // |residuals|, as least squares minimises
    const std::optional<Residuals> r = residuals(p_db, i_db);
    if (!r) return 1e6;
    double sum = 0.0;
    for (const double x : *r) sum += x * x;
    return std::sqrt(sum);
  }
  const std::optional<Percept> q = percept(p_db, i_db);
  return q ? fit_distance(target, *q, cfg.model) : 1e6;
}

double Fitter::felt(double p_db, double i_db) {
  const std::optional<Percept> q = percept(p_db, i_db);
  return q ? distance(target, *q, cfg.model) : 1e6;
}

std::optional<Residuals> Fitter::residuals(double p_db, double i_db) {
  const std::optional<Percept> q = percept(p_db, i_db);
  if (!q) return std::nullopt;
  const PerceptualModel& m = cfg.model;
  const double tie = std::sqrt(m.tie_weight);
  // The centroid target fits the fine part's physical log-spectral moments:
  // its centroid (Percept::log_centroid_db) and spread, in the JND units of
  // pitch and noisiness (docs/encoder.md §3, "Targets").
  if (cfg.target == EncoderConfig::Target::centroid)
    return Residuals{(q->log_centroid_db - target.log_centroid_db) / m.pitch_jnd_db,
                     (q->spread_db - target.spread_db) / m.noisiness_jnd_db,
                     0.0,
                     0.0,
                     0.0,
                     0.0};
  // Without a display in the loop the drawn terms are 0 (exactly: the sums
  // below are then the model's distance as before, bit for bit).
  const double w = display_in_loop(m) ? m.drawn_weight : 0.0;
  // |r| is fit_distance(target, q): the fit's objective as a sum of squares.
  return Residuals{(q->pitch_db - target.pitch_db) / m.pitch_jnd_db,
                   (q->noisiness_db - target.noisiness_db) / m.noisiness_jnd_db,
                   tie * (q->mean_db - target.mean_db),
                   tie * (q->spread_db - target.spread_db),
                   w * (q->drawn_pitch_db - target.drawn_pitch_db) / m.pitch_jnd_db,
                   w * (q->drawn_noisiness_db - target.drawn_noisiness_db) / m.noisiness_jnd_db};
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

/// Levenberg–Marquardt over (P, I) dB on Fitter::residuals, inside the box.
/// Forward-difference Jacobian with steps wide enough (0.5 dB, 1 dB) to
/// average over the candidates' draw-to-draw roughness. Returns {P, I,
/// distance} of the best point evaluated.
std::array<double, 3> levenberg_marquardt(Fitter& fit, const Box& box, double p, double i, int max_iterations) {
  using R = Residuals;
  auto norm = [](const R& r) {
    double sum = 0.0;
    for (const double x : r) sum += x * x;
    return std::sqrt(sum);
  };
  std::optional<R> r = fit.residuals(p, i);
  if (!r) return {p, i, 1e6};
  double v = norm(*r);
  double lambda = 1e-3;
  for (int iteration = 0; iteration < max_iterations && v > 0.02; ++iteration) {
    // Differences step inwards at the box's edges.
    const double hp = p + 0.5 <= box.p_hi ? 0.5 : -0.5;
    const double hi = i + 1.0 <= box.i_hi ? 1.0 : -1.0;
    const auto rp = fit.residuals(p + hp, i);
    const auto ri = fit.residuals(p, i + hi);
    if (!rp || !ri) break;
    double a11 = 0, a12 = 0, a22 = 0, g1 = 0, g2 = 0;
    std::array<R, 2> J{};  // J[0]: ∂r/∂P, J[1]: ∂r/∂I
    for (std::size_t k = 0; k < R{}.size(); ++k) {
      const double jp = ((*rp)[k] - (*r)[k]) / hp, ji = ((*ri)[k] - (*r)[k]) / hi;
      J[0][k] = jp, J[1][k] = ji;
      a11 += jp * jp, a12 += jp * ji, a22 += ji * ji, g1 += jp * (*r)[k], g2 += ji * (*r)[k];
    }
    bool improved = false;
    for (int tries = 0; tries < 4 && !improved; ++tries) {
      const double b11 = a11 * (1.0 + lambda), b22 = a22 * (1.0 + lambda);
      const double det = b11 * b22 - a12 * a12;
      if (!(std::fabs(det) > 1e-300)) break;
      double dp = -(b22 * g1 - a12 * g2) / det, di = -(b11 * g2 - a12 * g1) / det;
      // A variable at the box's edge whose step points outwards stays there
      // (active set); the other takes its own Gauss–Newton step.
      const bool p_held = (p >= box.p_hi && dp > 0) || (p <= box.p_lo && dp < 0);
      const bool i_held = (i >= box.i_hi && di > 0) || (i <= box.i_lo && di < 0);
      if (p_held && !i_held) dp = 0.0, di = b22 > 0 ? -g2 / b22 : 0.0;
      if (i_held && !p_held) di = 0.0, dp = b11 > 0 ? -g1 / b11 : 0.0;
      if (p_held && i_held) break;
      const double np = std::clamp(p + std::clamp(dp, -6.0, 6.0), box.p_lo, box.p_hi);
      const double ni = std::clamp(i + std::clamp(di, -12.0, 12.0), box.i_lo, box.i_hi);
      if (std::fabs(np - p) + std::fabs(ni - i) < 0.01) break;  // nothing left to move
      // Converged, without rendering the step, when even the linear model
      // predicts it gains less than the convergence threshold below (the
      // last steps of a fit are hundredths of a dB: 3–4 renderings each).
      R predicted = *r;
      for (std::size_t k = 0; k < R{}.size(); ++k) predicted[k] += (np - p) * J[0][k] + (ni - i) * J[1][k];
      if (v - norm(predicted) < 0.01 * v + 0.002) break;
      const auto rn = fit.residuals(np, ni);
      const double vn = rn ? norm(*rn) : 1e6;
      if (vn < v) {
        // Converged when a step gains less than 1 % (and 0.002 JND).
        if (v - vn < 0.01 * v + 0.002) iteration = max_iterations;
        p = np, i = ni, r = rn, v = vn, improved = true;
        lambda = std::max(lambda / 4.0, 1e-6);
      } else {
        lambda *= 8.0;
      }
    }
    if (!improved) break;
  }
  return {p, i, v};
}

}  // namespace

/// Identifiability: does a much narrower distribution feel different (by
/// the felt distance: through the display when one is in the loop)?
void identifiability(Fitter& fit, const Box& box, FineFit& out) {
  const double narrower = std::max(box.i_lo, out.i_db - 6.0);
  const double here = fit.felt(out.p_db, out.i_db);
  if (fit.felt(out.p_db, narrower) - here < 0.5) {
    out.identifiable = false;
    // The widest distribution (1 dB steps up from the estimate) that still
    // feels the same, by bisection: the distance grows with the spread.
    const auto steps = static_cast<int>(std::floor(box.i_hi - out.i_db));
    int same = 0, differs = steps + 1;  // `same` steps feel the same; `differs` (if ≤ steps) does not
    while (differs - same > 1) {
      const int mid = (same + differs) / 2;
      (fit.felt(out.p_db, out.i_db + mid) - here >= 0.5 ? differs : same) = mid;
    }
    out.bound_db = out.i_db + same;
  }
}

Box fit_box(const EncoderConfig& cfg, CyclesPerMm band_max) {
  Box box{-20.0 + 0.5, db_of(band_max.value()) - 0.01, -40.0, 10.0};
  if (cfg.parameterization == Parameterization::log) box.i_lo = 0.0, box.i_hi = 15.0;
  return box;
}

FineFit fit_fine(const std::vector<double>& fine, double dx, std::size_t cand, CyclesPerMm band_max, const EncoderConfig& cfg,
                 double f_min, const Split* two_scale, const FitOptions& options) {
  FineFit out;
  out.input = perceive(fine, dx, cfg.model, f_min);
  Fitter fit(cfg, out.input, dx, cand, band_max, f_min, two_scale);
  const Box box = fit_box(cfg, band_max);
  // Start from the physical centroid and spread of the fine spectrum, then
  // the best of a coarse grid around it (wide distributions make the
  // objective rough enough to trap a simplex far from the optimum).
  double p0 = std::clamp(out.input.mean_db, box.p_lo, box.p_hi);
  double i0 = cfg.parameterization == Parameterization::log
                  ? std::clamp(out.input.spread_db, box.i_lo, box.i_hi)
                  : std::clamp(db_of(cpm_of(p0) * out.input.spread_db / ten_over_ln10), box.i_lo, box.i_hi);
  // The best of a 3 × 3 grid around the start (±3 dB, ±8 dB): wide
  // distributions make the objective rough enough to trap a local search
  // far from the optimum.
  // The grid only picks the basin: one draw per point is enough there and
  // halves its cost; the search below compares points over both draws.
  auto grid_start = [&](double& p, double& i) {
    fit.draws = 1;
    double best_v = fit(p, i);
    const double gp = p, gi = i;
    for (double dp : {-3.0, 0.0, 3.0})
      for (double di : {-8.0, 0.0, 8.0}) {
        const double pp = gp + dp, ii = gi + di;
        if ((dp == 0.0 && di == 0.0) || !box.inside(pp, ii)) continue;
        const double v = fit(pp, ii);
        if (v < best_v) best_v = v, p = pp, i = ii;
      }
    fit.draws = 2;
  };
  if (options.start) {
    p0 = std::clamp((*options.start)[0], box.p_lo, box.p_hi);
    i0 = std::clamp((*options.start)[1], box.i_lo, box.i_hi);
  } else {
    grid_start(p0, i0);
  }
  std::array<double, 3> best;
  if (cfg.fit_method == FitMethod::simplex) {
    // The encoder's search before least squares (kept as an option): needs
    // no smoothness, ~120 evaluations.
    best = nelder_mead(fit, box, p0, i0, 1.5, 4.0, cfg.max_evaluations / 2);
    best = nelder_mead(fit, box, best[0], best[1], 0.5, 2.0, cfg.max_evaluations / 2);  // restart: NM can stall
  } else {
    // Least squares from the best grid point: the distance is the norm of
    // four residuals and a Texel texture's percept moves smoothly with
    // (P, I) at the scale of the difference steps, so Levenberg–Marquardt
    // converges in a few iterations where the simplex needs a hundred.
    best = levenberg_marquardt(fit, box, p0, i0, options.iterations);
  }
  out.p_db = best[0];
  out.i_db = best[1];
  out.distance = best[2];
  if (options.identifiability) identifiability(fit, box, out);
  out.evaluations = fit.evaluations;
  return out;
}

}  // namespace texel::codec::parts

namespace texel::codec {

std::string_view to_string(FitMethod m) { return m == FitMethod::simplex ? "simplex" : "least-squares"; }

FitMethod parse_fit_method(std::string_view text, std::string_view field) {
  if (text == "least-squares") return FitMethod::least_squares;
  if (text == "simplex") return FitMethod::simplex;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: least-squares, simplex");
}

}  // namespace texel::codec
