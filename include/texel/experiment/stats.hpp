// The statistics the perceptual studies report: descriptive summaries,
// one-sample, paired and two-sample t-tests, one-way between-subjects
// ANOVA, Pearson's r, one- and two-factor repeated-measures ANOVA with the
// Greenhouse–Geisser correction, and the confidence ellipse of a bivariate
// mean (Hotelling's T²). Formulas, conventions and sources are in
// docs/statistics.md.
//
// Distribution functions come from Boost.Math (students_t, fisher_f), never
// hand-rolled, so p-values and critical values match R and SciPy to within
// rounding. Everything here is a pure function over caller data: no state, no
// I/O. Bad input (too few observations, an unbalanced design, a level outside
// (0, 1)) throws texel::InvalidArgument naming the field, the value and what
// is allowed.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace texel::experiment::stats {

/// Summary of a sample. NaNs are skipped (n counts the finite values only).
/// sd uses n − 1; quartiles are Hyndman & Fan type 7 (R's and NumPy's
/// default); the 95 % CI of the mean uses Student's t with n − 1 df.
/// With n = 0 every value is NaN; with n = 1, sd, sem and the CI are NaN.
struct Descriptive {
  std::size_t n = 0;
  double mean = 0, sd = 0, sem = 0;
  double min = 0, q1 = 0, median = 0, q3 = 0, max = 0;
  double ci95_low = 0, ci95_high = 0;
};
Descriptive describe(std::span<const double> x);

/// Quantile of the finite values of x, Hyndman & Fan type 7 (R default):
/// h = (n − 1)·prob, linear interpolation between order statistics.
/// prob in [0, 1]; NaN when x has no finite value.
double quantile(std::span<const double> x, double prob);

/// Result of a one-sample (or paired, on the differences) Student t-test.
/// se = sd/√n, t = (mean − mu)/se, df = n − 1, p two-sided; [ci_low, ci_high]
/// is the `level` confidence interval of the mean (of the differences);
/// cohen_d = (mean − mu)/sd (for paired data this is d_z).
struct TTest {
  std::size_t n = 0;
  double mean = 0, sd = 0, se = 0, mu = 0;
  double t = 0, df = 0, p = 0;
  double level = 0.95, ci_low = 0, ci_high = 0;
  double cohen_d = 0;
};
/// x: observations (NaNs skipped; at least 2 finite, not all equal);
/// mu: hypothesised mean (finite); level: confidence level in (0, 1).
TTest t_test_one_sample(std::span<const double> x, double mu = 0.0, double level = 0.95);
/// Paired test of a − b (same length; a pair with a NaN on either side is
/// dropped). The result's mean/sd/se describe the differences; mu = 0.
TTest t_test_paired(std::span<const double> a, std::span<const double> b, double level = 0.95);

/// Two independent samples (between-groups designs): Student's test with the
/// pooled variance (df = n1 + n2 − 2) or Welch's (Welch–Satterthwaite df).
/// diff = mean1 − mean2; [ci_low, ci_high] is its `level` interval;
/// cohen_d = diff / pooled SD (either test).
struct TwoSampleTTest {
  std::size_t n1 = 0, n2 = 0;
  double mean1 = 0, mean2 = 0, sd1 = 0, sd2 = 0;
  bool welch = false;
  double diff = 0, se = 0, t = 0, df = 0, p = 0;
  double level = 0.95, ci_low = 0, ci_high = 0;
  double cohen_d = 0;
};
/// a, b: the two groups (NaNs skipped; each ≥ 2 finite values; not both constant).
TwoSampleTTest t_test_two_sample(std::span<const double> a, std::span<const double> b, bool welch = false, double level = 0.95);

/// One-way between-subjects ANOVA: F = MS_between / MS_within with
/// df = (k − 1, N − k); eta2 = SS_between / SS_total.
struct OneWayAnova {
  std::vector<std::size_t> n;  ///< per group
  double ss_between = 0, df_between = 0, ss_within = 0, df_within = 0;
  double f = 0, p = 0, eta2 = 0;
};
/// groups: ≥ 2 groups, each with ≥ 1 finite value, N > k, not every group constant.
OneWayAnova anova_one_way(const std::vector<std::vector<double>>& groups);

/// Pearson's product-moment correlation of paired data (pairs with a NaN
/// dropped): t = r·√((n−2)/(1−r²)) with n − 2 df, p two-sided; the `level`
/// interval from Fisher's z (tanh(atanh r ± z_q/√(n−3)); NaN below 4 pairs).
struct Correlation {
  std::size_t n = 0;
  double r = 0, r2 = 0, t = 0, df = 0, p = 0;
  double level = 0.95, ci_low = 0, ci_high = 0;
};
/// x, y: same length, ≥ 3 complete pairs, neither constant.
Correlation pearson(std::span<const double> x, std::span<const double> y, double level = 0.95);

/// One measurement in long format for the repeated-measures ANOVA.
struct Observation {
  std::string subject;
  std::vector<std::string> levels;  ///< one level per within factor, in factor order
  double value = 0;
};

/// One row of the ANOVA table. The error term is the effect × subject
/// interaction. Sphericity applies when the effect has more than one df
/// (a factor with more than 2 levels); then gg_epsilon is the
/// Greenhouse–Geisser ε and p_gg uses df·ε and df_error·ε; otherwise
/// gg_epsilon = 1 and the corrected values equal the uncorrected ones.
struct AnovaEffect {
  std::string effect;  ///< "A", "B" or "A:B" with the factor names
  double ss = 0, df = 0, ms = 0;
  double ss_error = 0, df_error = 0, ms_error = 0;
  double f = 0, p = 0;
  double partial_eta2 = 0;  ///< ss / (ss + ss_error)
  bool sphericity_applies = false;
  double gg_epsilon = 1, p_gg = 0, df_gg = 0, df_error_gg = 0;
};
struct AnovaTable {
  std::vector<std::string> factors;
  std::size_t subjects = 0;
  std::vector<AnovaEffect> effects;  ///< main effects in factor order, then the interaction
};
/// Repeated-measures ANOVA with one or two within-subject factors (type III
/// sums of squares on the balanced cell means). Several rows for one
/// subject × cell are averaged; NaN values are skipped (a subject or level
/// with no finite value at all is left out entirely); every subject must
/// have every cell (the error names the first missing subject × cell).
/// Levels are ordered by first appearance. Needs ≥ 2 subjects and ≥ 2 levels
/// per factor.
AnovaTable rm_anova(std::span<const Observation> data, const std::vector<std::string>& factor_names);

/// Confidence region of the mean of bivariate data: the ellipse
/// (m − x̄)ᵀ (S/n)⁻¹ (m − x̄) ≤ T²_crit with T²_crit = p(n−1)/(n−p)·F(level; p, n−p),
/// p = 2 (Hotelling's T²). cov_* is the sample covariance S (n − 1);
/// semi-axes are √(λ·T²_crit/n) of the eigenvalues λ of S; angle_deg is the
/// major axis's direction from +x, counter-clockwise, in (−90, 90].
struct Ellipse {
  std::size_t n = 0;
  double level = 0.95;
  double mean_x = 0, mean_y = 0;
  double cov_xx = 0, cov_xy = 0, cov_yy = 0;
  double t2_critical = 0;
  double semi_major = 0, semi_minor = 0, angle_deg = 0;
  /// `points` points on the boundary (closed curve; first ≠ last), x then y.
  std::vector<std::array<double, 2>> outline(std::size_t points = 128) const;
};
/// x, y: paired coordinates (same length; pairs with a NaN dropped; ≥ 3 pairs);
/// level in (0, 1).
Ellipse mean_confidence_ellipse(std::span<const double> x, std::span<const double> y, double level = 0.95);

/// JSON views under the fields' names (what `texel stats --json` prints and
/// the analysis summaries embed); non-finite numbers become null, since JSON
/// has no NaN. JSON object text.
std::string to_json(const Descriptive& d);
std::string to_json(const TTest& t);
std::string to_json(const AnovaTable& a);  ///< factors, subjects, effects
std::string to_json(const Ellipse& e);     ///< without the outline
std::string to_json(const TwoSampleTTest& t);
std::string to_json(const OneWayAnova& a);
std::string to_json(const Correlation& c);

}  // namespace texel::experiment::stats
