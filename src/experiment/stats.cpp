// Statistics for the perceptual studies (docs/statistics.md).
//
// RM-ANOVA is computed through orthonormal contrasts of the subject × cell
// mean matrix (the multivariate formulation, Maxwell & Delaney ch. 11–12):
// for an effect with contrast matrix C (cells × k, orthonormal columns) and
// transformed scores Z = Y·C, SS_effect = n·‖mean(Z)‖², SS_error =
// Σ(Z − mean Z)², df = k, df_error = k(n − 1). For a balanced design these
// are exactly the classical univariate sums of squares, and the covariance S
// of Z is what the Greenhouse–Geisser ε needs: ε = tr(S)² / (k·tr(S²)).
// One code path serves one and two factors, main effects and the interaction.
#include "texel/experiment/stats.hpp"

#include "json_views.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>

#include "texel/error.hpp"

namespace texel::experiment::stats {
namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

void check_level(const char* fn, double level) {
  if (!(level > 0.0 && level < 1.0))
    throw InvalidArgument(std::string(fn) + ": level " + num(level) + " is outside the allowed range (0, 1)");
}

std::vector<double> finite(std::span<const double> x) {
  std::vector<double> v;
  v.reserve(x.size());
  for (double d : x)
    if (!std::isnan(d)) v.push_back(d);
  return v;
}

double mean_of(const std::vector<double>& v) {
  // Two-pass mean: the correction term removes most rounding of the first pass.
  double s = 0;
  for (double d : v) s += d;
  const double m = s / static_cast<double>(v.size());
  double c = 0;
  for (double d : v) c += d - m;
  return m + c / static_cast<double>(v.size());
}

double sd_of(const std::vector<double>& v, double m) {
  double ss = 0;
  for (double d : v) ss += (d - m) * (d - m);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

// Two-sided quantile of Student's t with df degrees of freedom.
double t_quantile(double df, double level) {
  boost::math::students_t dist(df);
  return boost::math::quantile(boost::math::complement(dist, (1.0 - level) / 2.0));
}

double quantile_sorted(const std::vector<double>& s, double prob) {
  // Hyndman & Fan type 7: h = (n − 1)p, interpolate between s[⌊h⌋] and s[⌊h⌋+1].
  const double h = static_cast<double>(s.size() - 1) * prob;
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, s.size() - 1);
  return s[lo] + (h - static_cast<double>(lo)) * (s[hi] - s[lo]);
}

TTest t_test_on(const char* fn, const char* field, std::vector<double> v, double mu, double level) {
  check_level(fn, level);
  if (!std::isfinite(mu)) throw InvalidArgument(std::string(fn) + ": mu " + num(mu) + " must be finite");
  if (v.size() < 2)
    throw InvalidArgument(std::string(fn) + ": " + field + " has " + std::to_string(v.size()) +
                          " usable value(s); at least 2 are needed");
  TTest r;
  r.n = v.size();
  r.mu = mu;
  r.level = level;
  r.mean = mean_of(v);
  r.sd = sd_of(v, r.mean);
  if (!(r.sd > 0.0))
    throw InvalidArgument(std::string(fn) + ": " + field + " is constant (every value " + num(v[0]) +
                          "); the t statistic is undefined");
  r.se = r.sd / std::sqrt(static_cast<double>(r.n));
  r.df = static_cast<double>(r.n - 1);
  r.t = (r.mean - mu) / r.se;
  boost::math::students_t dist(r.df);
  r.p = 2.0 * boost::math::cdf(boost::math::complement(dist, std::abs(r.t)));
  const double q = t_quantile(r.df, level);
  r.ci_low = r.mean - q * r.se;
  r.ci_high = r.mean + q * r.se;
  r.cohen_d = (r.mean - mu) / r.sd;
  return r;
}

// Orthonormal contrasts for k levels: normalised Helmert columns (k × (k−1)).
std::vector<std::vector<double>> helmert(std::size_t k) {
  std::vector<std::vector<double>> c(k, std::vector<double>(k - 1, 0.0));
  for (std::size_t j = 1; j < k; ++j) {
    const double norm = std::sqrt(static_cast<double>(j * (j + 1)));
    for (std::size_t i = 0; i < j; ++i) c[i][j - 1] = 1.0 / norm;
    c[j][j - 1] = -static_cast<double>(j) / norm;
  }
  return c;
}

std::vector<std::vector<double>> kron(const std::vector<std::vector<double>>& a, const std::vector<std::vector<double>>& b) {
  const std::size_t ar = a.size(), ac = a[0].size(), br = b.size(), bc = b[0].size();
  std::vector<std::vector<double>> r(ar * br, std::vector<double>(ac * bc));
  for (std::size_t i = 0; i < ar; ++i)
    for (std::size_t j = 0; j < ac; ++j)
      for (std::size_t k = 0; k < br; ++k)
        for (std::size_t l = 0; l < bc; ++l) r[i * br + k][j * bc + l] = a[i][j] * b[k][l];
  return r;
}

std::vector<std::vector<double>> unit_mean(std::size_t k) {
  return std::vector<std::vector<double>>(k, std::vector<double>(1, 1.0 / std::sqrt(static_cast<double>(k))));
}

double f_upper(double f, double df1, double df2) {
  if (std::isnan(f)) return nan;
  if (std::isinf(f)) return 0.0;
  boost::math::fisher_f dist(df1, df2);
  return boost::math::cdf(boost::math::complement(dist, f));
}

AnovaEffect effect_from_contrasts(std::string name, const std::vector<std::vector<double>>& y,
                                  const std::vector<std::vector<double>>& c) {
  const std::size_t n = y.size(), cells = c.size(), k = c[0].size();
  // Z = Y·C, then its column means and covariance.
  std::vector<std::vector<double>> z(n, std::vector<double>(k, 0.0));
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t j = 0; j < k; ++j) {
      double acc = 0;
      for (std::size_t i = 0; i < cells; ++i) acc += y[s][i] * c[i][j];
      z[s][j] = acc;
    }
  std::vector<double> m(k, 0.0);
  for (std::size_t j = 0; j < k; ++j) {
    for (std::size_t s = 0; s < n; ++s) m[j] += z[s][j];
    m[j] /= static_cast<double>(n);
  }
  std::vector<std::vector<double>> cov(k, std::vector<double>(k, 0.0));
  for (std::size_t a = 0; a < k; ++a)
    for (std::size_t b = 0; b < k; ++b) {
      double acc = 0;
      for (std::size_t s = 0; s < n; ++s) acc += (z[s][a] - m[a]) * (z[s][b] - m[b]);
      cov[a][b] = acc / static_cast<double>(n - 1);
    }

  AnovaEffect e;
  e.effect = std::move(name);
  double ss = 0, tr = 0, tr2 = 0;
  for (std::size_t j = 0; j < k; ++j) {
    ss += m[j] * m[j];
    tr += cov[j][j];
    for (std::size_t l = 0; l < k; ++l) tr2 += cov[j][l] * cov[l][j];
  }
  e.ss = static_cast<double>(n) * ss;
  e.df = static_cast<double>(k);
  e.ms = e.ss / e.df;
  e.ss_error = static_cast<double>(n - 1) * tr;
  e.df_error = static_cast<double>(k * (n - 1));
  e.ms_error = e.ss_error / e.df_error;
  if (e.ms_error > 0.0)
    e.f = e.ms / e.ms_error;
  else  // no subject-by-effect variation: F is infinite, or undefined when the effect is 0 too
    e.f = e.ss > 0.0 ? std::numeric_limits<double>::infinity() : nan;
  e.p = f_upper(e.f, e.df, e.df_error);
  const double total = e.ss + e.ss_error;
  e.partial_eta2 = total > 0.0 ? e.ss / total : nan;
  e.sphericity_applies = k > 1;
  e.gg_epsilon = 1.0;
  if (e.sphericity_applies && tr2 > 0.0) e.gg_epsilon = std::min(1.0, tr * tr / (static_cast<double>(k) * tr2));
  e.df_gg = e.df * e.gg_epsilon;
  e.df_error_gg = e.df_error * e.gg_epsilon;
  e.p_gg = e.sphericity_applies ? f_upper(e.f, e.df_gg, e.df_error_gg) : e.p;
  return e;
}

}  // namespace

double quantile(std::span<const double> x, double prob) {
  if (!(prob >= 0.0 && prob <= 1.0))
    throw InvalidArgument("quantile: prob " + num(prob) + " is outside the allowed range [0, 1]");
  std::vector<double> v = finite(x);
  if (v.empty()) return nan;
  std::sort(v.begin(), v.end());
  return quantile_sorted(v, prob);
}

Descriptive describe(std::span<const double> x) {
  std::vector<double> v = finite(x);
  Descriptive d;
  d.n = v.size();
  if (v.empty()) {
    d.mean = d.sd = d.sem = d.min = d.q1 = d.median = d.q3 = d.max = d.ci95_low = d.ci95_high = nan;
    return d;
  }
  std::sort(v.begin(), v.end());
  d.mean = mean_of(v);
  d.min = v.front();
  d.max = v.back();
  d.q1 = quantile_sorted(v, 0.25);
  d.median = quantile_sorted(v, 0.5);
  d.q3 = quantile_sorted(v, 0.75);
  if (v.size() < 2) {
    d.sd = d.sem = d.ci95_low = d.ci95_high = nan;
    return d;
  }
  d.sd = sd_of(v, d.mean);
  d.sem = d.sd / std::sqrt(static_cast<double>(d.n));
  const double q = t_quantile(static_cast<double>(d.n - 1), 0.95);
  d.ci95_low = d.mean - q * d.sem;
  d.ci95_high = d.mean + q * d.sem;
  return d;
}

TTest t_test_one_sample(std::span<const double> x, double mu, double level) {
  return t_test_on("t_test_one_sample", "x", finite(x), mu, level);
}

TTest t_test_paired(std::span<const double> a, std::span<const double> b, double level) {
  if (a.size() != b.size())
    throw InvalidArgument("t_test_paired: a has " + std::to_string(a.size()) + " values and b has " + std::to_string(b.size()) +
                          "; the pairs must have equal length");
  std::vector<double> d;
  d.reserve(a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!std::isnan(a[i]) && !std::isnan(b[i])) d.push_back(a[i] - b[i]);
  return t_test_on("t_test_paired", "a - b", std::move(d), 0.0, level);
}

AnovaTable rm_anova(std::span<const Observation> data, const std::vector<std::string>& factor_names) {
  const std::size_t nf = factor_names.size();
  if (nf < 1 || nf > 2)
    throw InvalidArgument("rm_anova: factor_names has " + std::to_string(nf) +
                          " factor(s); one or two within-subject factors are supported");
  if (nf == 2 && factor_names[0] == factor_names[1])
    throw InvalidArgument("rm_anova: factor_names lists '" + factor_names[0] + "' twice");

  // Subjects and levels in order of first appearance.
  std::vector<std::string> subjects;
  std::map<std::string, std::size_t> subject_index;
  std::vector<std::vector<std::string>> levels(nf);
  std::vector<std::map<std::string, std::size_t>> level_index(nf);
  for (const Observation& o : data) {
    if (o.levels.size() != nf)
      throw InvalidArgument("rm_anova: an observation of subject '" + o.subject + "' has " + std::to_string(o.levels.size()) +
                            " level(s); expected one per factor (" + std::to_string(nf) + ")");
    if (std::isnan(o.value)) continue;
    if (subject_index.emplace(o.subject, subjects.size()).second) subjects.push_back(o.subject);
    for (std::size_t f = 0; f < nf; ++f)
      if (level_index[f].emplace(o.levels[f], levels[f].size()).second) levels[f].push_back(o.levels[f]);
  }
  if (subjects.size() < 2)
    throw InvalidArgument("rm_anova: subject has " + std::to_string(subjects.size()) +
                          " distinct value(s) with data; at least 2 subjects are needed");
  for (std::size_t f = 0; f < nf; ++f)
    if (levels[f].size() < 2)
      throw InvalidArgument("rm_anova: factor '" + factor_names[f] + "' has " + std::to_string(levels[f].size()) +
                            " level(s) with data; at least 2 are needed");

  const std::size_t la = levels[0].size(), lb = nf == 2 ? levels[1].size() : 1;
  const std::size_t cells = la * lb, n = subjects.size();
  std::vector<std::vector<double>> sum(n, std::vector<double>(cells, 0.0));
  std::vector<std::vector<std::size_t>> count(n, std::vector<std::size_t>(cells, 0));
  for (const Observation& o : data) {
    if (std::isnan(o.value)) continue;
    const std::size_t s = subject_index.at(o.subject);
    std::size_t cell = level_index[0].at(o.levels[0]);
    if (nf == 2) cell = cell * lb + level_index[1].at(o.levels[1]);
    sum[s][cell] += o.value;
    ++count[s][cell];
  }
  // Replicates are averaged: each subject contributes one mean per cell.
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t c = 0; c < cells; ++c) {
      if (count[s][c] == 0) {
        std::string cell = factor_names[0] + "=" + levels[0][c / lb];
        if (nf == 2) cell += ", " + factor_names[1] + "=" + levels[1][c % lb];
        throw InvalidArgument("rm_anova: unbalanced design: subject '" + subjects[s] + "' has no value for cell " + cell +
                              "; every subject needs every cell (drop the subject or fill the cell)");
      }
      sum[s][c] /= static_cast<double>(count[s][c]);
    }

  AnovaTable t;
  t.factors = factor_names;
  t.subjects = n;
  const auto ca = helmert(la);
  if (nf == 1) {
    t.effects.push_back(effect_from_contrasts(factor_names[0], sum, ca));
  } else {
    const auto cb = helmert(lb);
    t.effects.push_back(effect_from_contrasts(factor_names[0], sum, kron(ca, unit_mean(lb))));
    t.effects.push_back(effect_from_contrasts(factor_names[1], sum, kron(unit_mean(la), cb)));
    t.effects.push_back(effect_from_contrasts(factor_names[0] + ":" + factor_names[1], sum, kron(ca, cb)));
  }
  return t;
}

TwoSampleTTest t_test_two_sample(std::span<const double> a, std::span<const double> b, bool welch, double level) {
  constexpr const char* fn = "t_test_two_sample";
  check_level(fn, level);
  const std::vector<double> x = finite(a), y = finite(b);
  if (x.size() < 2 || y.size() < 2)
    throw InvalidArgument(std::string(fn) + ": the groups have " + std::to_string(x.size()) + " and " + std::to_string(y.size()) +
                          " usable value(s); at least 2 each are needed");
  TwoSampleTTest r;
  r.n1 = x.size();
  r.n2 = y.size();
  r.welch = welch;
  r.level = level;
  r.mean1 = mean_of(x);
  r.mean2 = mean_of(y);
  r.sd1 = sd_of(x, r.mean1);
  r.sd2 = sd_of(y, r.mean2);
  const double n1 = static_cast<double>(r.n1), n2 = static_cast<double>(r.n2);
  const double v1 = r.sd1 * r.sd1, v2 = r.sd2 * r.sd2;
  if (!(v1 > 0.0 || v2 > 0.0))
    throw InvalidArgument(std::string(fn) + ": both groups are constant; the t statistic is undefined");
  const double pooled = ((n1 - 1) * v1 + (n2 - 1) * v2) / (n1 + n2 - 2);
  r.diff = r.mean1 - r.mean2;
  if (welch) {
    r.se = std::sqrt(v1 / n1 + v2 / n2);
    const double a1 = v1 / n1, a2 = v2 / n2;
    r.df = (a1 + a2) * (a1 + a2) / (a1 * a1 / (n1 - 1) + a2 * a2 / (n2 - 1));
  } else {
    r.se = std::sqrt(pooled * (1 / n1 + 1 / n2));
    r.df = n1 + n2 - 2;
  }
  r.t = r.diff / r.se;
  boost::math::students_t dist(r.df);
  r.p = 2.0 * boost::math::cdf(boost::math::complement(dist, std::abs(r.t)));
  const double q = t_quantile(r.df, level);
  r.ci_low = r.diff - q * r.se;
  r.ci_high = r.diff + q * r.se;
  r.cohen_d = r.diff / std::sqrt(pooled);
  return r;
}

OneWayAnova anova_one_way(const std::vector<std::vector<double>>& groups) {
  constexpr const char* fn = "anova_one_way";
  if (groups.size() < 2)
    throw InvalidArgument(std::string(fn) + ": " + std::to_string(groups.size()) + " group(s); at least 2 are needed");
  OneWayAnova a;
  std::vector<std::vector<double>> g;
  std::vector<double> all;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    g.push_back(finite(groups[i]));
    if (g.back().empty()) throw InvalidArgument(std::string(fn) + ": group " + std::to_string(i + 1) + " has no usable value");
    a.n.push_back(g.back().size());
    all.insert(all.end(), g.back().begin(), g.back().end());
  }
  const double k = static_cast<double>(g.size()), n = static_cast<double>(all.size());
  if (!(n > k))
    throw InvalidArgument(std::string(fn) + ": " + std::to_string(all.size()) + " values in " + std::to_string(g.size()) +
                          " groups; more values than groups are needed");
  const double grand = mean_of(all);
  for (const auto& v : g) {
    const double m = mean_of(v);
    a.ss_between += static_cast<double>(v.size()) * (m - grand) * (m - grand);
    for (double d : v) a.ss_within += (d - m) * (d - m);
  }
  if (!(a.ss_within > 0.0)) throw InvalidArgument(std::string(fn) + ": no variance within the groups; F is undefined");
  a.df_between = k - 1;
  a.df_within = n - k;
  a.f = (a.ss_between / a.df_between) / (a.ss_within / a.df_within);
  a.p = f_upper(a.f, a.df_between, a.df_within);
  a.eta2 = a.ss_between / (a.ss_between + a.ss_within);
  return a;
}

Correlation pearson(std::span<const double> x, std::span<const double> y, double level) {
  constexpr const char* fn = "pearson";
  check_level(fn, level);
  if (x.size() != y.size())
    throw InvalidArgument(std::string(fn) + ": x has " + std::to_string(x.size()) + " values, y " + std::to_string(y.size()) +
                          "; they must pair up");
  std::vector<double> a, b;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isnan(x[i]) && !std::isnan(y[i])) a.push_back(x[i]), b.push_back(y[i]);
  if (a.size() < 3)
    throw InvalidArgument(std::string(fn) + ": " + std::to_string(a.size()) + " complete pair(s); at least 3 are needed");
  const double ma = mean_of(a), mb = mean_of(b);
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sxy += (a[i] - ma) * (b[i] - mb);
    sxx += (a[i] - ma) * (a[i] - ma);
    syy += (b[i] - mb) * (b[i] - mb);
  }
  if (!(sxx > 0.0) || !(syy > 0.0)) throw InvalidArgument(std::string(fn) + ": x or y is constant; r is undefined");
  Correlation c;
  c.n = a.size();
  c.level = level;
  c.r = std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
  c.r2 = c.r * c.r;
  c.df = static_cast<double>(c.n - 2);
  if (std::abs(c.r) < 1.0) {
    c.t = c.r * std::sqrt(c.df / (1.0 - c.r2));
    boost::math::students_t dist(c.df);
    c.p = 2.0 * boost::math::cdf(boost::math::complement(dist, std::abs(c.t)));
  } else {
    c.t = std::copysign(std::numeric_limits<double>::infinity(), c.r);
    c.p = 0.0;
  }
  if (c.n >= 4 && std::abs(c.r) < 1.0) {
    const boost::math::normal z;
    const double q = boost::math::quantile(boost::math::complement(z, (1.0 - level) / 2.0));
    const double h = q / std::sqrt(static_cast<double>(c.n) - 3.0);
    c.ci_low = std::tanh(std::atanh(c.r) - h);
    c.ci_high = std::tanh(std::atanh(c.r) + h);
  } else {
    c.ci_low = c.ci_high = nan;
  }
  return c;
}

std::vector<std::array<double, 2>> Ellipse::outline(std::size_t points) const {
  std::vector<std::array<double, 2>> r;
  r.reserve(points);
  const double a = angle_deg * std::numbers::pi / 180.0;
  const double ca = std::cos(a), sa = std::sin(a);
  for (std::size_t i = 0; i < points; ++i) {
    const double th = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(points);
    const double u = semi_major * std::cos(th), v = semi_minor * std::sin(th);
    r.push_back({mean_x + ca * u - sa * v, mean_y + sa * u + ca * v});
  }
  return r;
}

Ellipse mean_confidence_ellipse(std::span<const double> x, std::span<const double> y, double level) {
  check_level("mean_confidence_ellipse", level);
  if (x.size() != y.size())
    throw InvalidArgument("mean_confidence_ellipse: x has " + std::to_string(x.size()) + " values and y has " +
                          std::to_string(y.size()) + "; they must have equal length");
  std::vector<double> xs, ys;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isnan(x[i]) && !std::isnan(y[i])) {
      xs.push_back(x[i]);
      ys.push_back(y[i]);
    }
  if (xs.size() < 3)
    throw InvalidArgument("mean_confidence_ellipse: x, y have " + std::to_string(xs.size()) +
                          " complete pair(s); at least 3 are needed (Hotelling's T² has n − 2 df)");
  Ellipse e;
  e.n = xs.size();
  e.level = level;
  e.mean_x = mean_of(xs);
  e.mean_y = mean_of(ys);
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < e.n; ++i) {
    const double dx = xs[i] - e.mean_x, dy = ys[i] - e.mean_y;
    sxx += dx * dx;
    sxy += dx * dy;
    syy += dy * dy;
  }
  const double nm1 = static_cast<double>(e.n - 1);
  e.cov_xx = sxx / nm1;
  e.cov_xy = sxy / nm1;
  e.cov_yy = syy / nm1;
  const double p = 2.0, n = static_cast<double>(e.n);
  boost::math::fisher_f f(p, n - p);
  e.t2_critical = p * (n - 1.0) / (n - p) * boost::math::quantile(f, level);
  // Eigenvalues of the symmetric 2×2 covariance, and the major axis's angle.
  const double half_tr = 0.5 * (e.cov_xx + e.cov_yy);
  const double r = std::hypot(0.5 * (e.cov_xx - e.cov_yy), e.cov_xy);
  const double l1 = half_tr + r, l2 = std::max(0.0, half_tr - r);
  e.semi_major = std::sqrt(l1 * e.t2_critical / n);
  e.semi_minor = std::sqrt(l2 * e.t2_critical / n);
  e.angle_deg = 0.5 * std::atan2(2.0 * e.cov_xy, e.cov_xx - e.cov_yy) * 180.0 / std::numbers::pi;
  return e;
}

namespace {
nlohmann::ordered_json jnum(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); }
}  // namespace

nlohmann::ordered_json view(const Descriptive& d) {
  return {{"n", d.n},
          {"mean", jnum(d.mean)},
          {"sd", jnum(d.sd)},
          {"sem", jnum(d.sem)},
          {"min", jnum(d.min)},
          {"q1", jnum(d.q1)},
          {"median", jnum(d.median)},
          {"q3", jnum(d.q3)},
          {"max", jnum(d.max)},
          {"ci95_low", jnum(d.ci95_low)},
          {"ci95_high", jnum(d.ci95_high)}};
}

nlohmann::ordered_json view(const TTest& t) {
  return {{"n", t.n},         {"mean", jnum(t.mean)},     {"sd", jnum(t.sd)},           {"se", jnum(t.se)},
          {"mu", jnum(t.mu)}, {"t", jnum(t.t)},           {"df", jnum(t.df)},           {"p", jnum(t.p)},
          {"level", t.level}, {"ci_low", jnum(t.ci_low)}, {"ci_high", jnum(t.ci_high)}, {"cohen_d", jnum(t.cohen_d)}};
}

nlohmann::ordered_json view(const AnovaTable& a) {
  nlohmann::ordered_json effects = nlohmann::ordered_json::array();
  for (const auto& e : a.effects)
    effects.push_back({{"effect", e.effect},
                       {"ss", jnum(e.ss)},
                       {"df", jnum(e.df)},
                       {"ms", jnum(e.ms)},
                       {"ss_error", jnum(e.ss_error)},
                       {"df_error", jnum(e.df_error)},
                       {"ms_error", jnum(e.ms_error)},
                       {"f", jnum(e.f)},
                       {"p", jnum(e.p)},
                       {"partial_eta2", jnum(e.partial_eta2)},
                       {"sphericity_applies", e.sphericity_applies},
                       {"gg_epsilon", jnum(e.gg_epsilon)},
                       {"df_gg", jnum(e.df_gg)},
                       {"df_error_gg", jnum(e.df_error_gg)},
                       {"p_gg", jnum(e.p_gg)}});
  return {{"factors", a.factors}, {"subjects", a.subjects}, {"effects", effects}};
}

nlohmann::ordered_json view(const Ellipse& e) {
  return {{"n", e.n},
          {"mean_x", jnum(e.mean_x)},
          {"mean_y", jnum(e.mean_y)},
          {"cov_xx", jnum(e.cov_xx)},
          {"cov_xy", jnum(e.cov_xy)},
          {"cov_yy", jnum(e.cov_yy)},
          {"t2_critical", jnum(e.t2_critical)},
          {"semi_major", jnum(e.semi_major)},
          {"semi_minor", jnum(e.semi_minor)},
          {"angle_deg", jnum(e.angle_deg)}};
}

nlohmann::ordered_json view(const TwoSampleTTest& t) {
  return {{"test", t.welch ? "welch" : "student"},
          {"n1", t.n1},
          {"n2", t.n2},
          {"mean1", jnum(t.mean1)},
          {"mean2", jnum(t.mean2)},
          {"sd1", jnum(t.sd1)},
          {"sd2", jnum(t.sd2)},
          {"diff", jnum(t.diff)},
          {"se", jnum(t.se)},
          {"t", jnum(t.t)},
          {"df", jnum(t.df)},
          {"p", jnum(t.p)},
          {"level", t.level},
          {"ci_low", jnum(t.ci_low)},
          {"ci_high", jnum(t.ci_high)},
          {"cohen_d", jnum(t.cohen_d)}};
}

nlohmann::ordered_json view(const OneWayAnova& a) {
  return {{"n", a.n},
          {"ss_between", jnum(a.ss_between)},
          {"df_between", jnum(a.df_between)},
          {"ss_within", jnum(a.ss_within)},
          {"df_within", jnum(a.df_within)},
          {"f", jnum(a.f)},
          {"p", jnum(a.p)},
          {"eta2", jnum(a.eta2)}};
}

nlohmann::ordered_json view(const Correlation& c) {
  return {{"n", c.n},         {"r", jnum(c.r)},           {"r2", jnum(c.r2)},
          {"t", jnum(c.t)},   {"df", jnum(c.df)},         {"p", jnum(c.p)},
          {"level", c.level}, {"ci_low", jnum(c.ci_low)}, {"ci_high", jnum(c.ci_high)}};
}

std::string to_json(const Descriptive& d) { return view(d).dump(); }
std::string to_json(const TTest& t) { return view(t).dump(); }
std::string to_json(const AnovaTable& a) { return view(a).dump(); }
std::string to_json(const Ellipse& e) { return view(e).dump(); }
std::string to_json(const TwoSampleTTest& t) { return view(t).dump(); }
std::string to_json(const OneWayAnova& a) { return view(a).dump(); }
std::string to_json(const Correlation& c) { return view(c).dump(); }

}  // namespace texel::experiment::stats
