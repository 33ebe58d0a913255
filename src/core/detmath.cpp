// Deterministic exp/log and the normal quantile (see detmath.hpp for why).
#include "texel/detmath.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace texel::detmath {
namespace {

constexpr double ln10 = 2.30258509299404568402;

}  // namespace

double log(double x) {
  if (std::isnan(x) || x < 0.0) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return -std::numeric_limits<double>::infinity();
  if (std::isinf(x)) return x;
  if ((std::bit_cast<std::uint64_t>(x) >> 52) == 0)  // subnormal: scale into the normal range first
    return log_normal_generic<double, std::uint64_t>(x * 0x1.0p54, -54.0);
  return log_normal_generic<double, std::uint64_t>(x);
}

double exp(double x) {
  if (std::isnan(x)) return x;
  if (x > 709.782712893384) return std::numeric_limits<double>::infinity();
  if (x < -745.1332191019412) return 0.0;
  double k = 0.0;
  const double p = exp_reduced_generic(x, k);
  // Scaling by a power of two is exact (or rounded once into the subnormals),
  // as std::ldexp does it; scale_pow2 is that without the library call.
  return scale_pow2(p, static_cast<int>(k));
}

double pow10(double x) { return exp(x * ln10); }

double normal_quantile(double p) {
  if (!(p > 0.0 && p < 1.0)) {
    if (p == 0.0) return -std::numeric_limits<double>::infinity();
    if (p == 1.0) return std::numeric_limits<double>::infinity();
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Wichura, Algorithm AS241 (PPND16), Applied Statistics 37 (1988) 477–484.
  const double q = p - 0.5;
  if (std::fabs(q) <= 0.425) return normal_quantile_central_generic(q);
  double r = q < 0.0 ? p : 1.0 - p;
  r = std::sqrt(-log(r));  // sqrt is correctly rounded by IEEE-754
  double value = 0.0;
  if (r <= 5.0) {
    value = normal_quantile_tail_generic(r);
  } else {
    r -= 5.0;
    const double num = (((((((2.01033439929228813265e-7 * r + 2.71155556874348757815e-5) * r + 1.24266094738807843860e-3) * r +
                            2.65321895265761230930e-2) *
                               r +
                           2.96560571828504891230e-1) *
                              r +
                          1.78482653991729133580e+0) *
                             r +
                         5.46378491116411436990e+0) *
                            r +
                        6.65790464350110377720e+0);
    const double den = (((((((2.04426310338993978564e-15 * r + 1.42151175831644588870e-7) * r + 1.84631831751005468180e-5) * r +
                            7.86869131145613259100e-4) *
                               r +
                           1.48753612908506148525e-2) *
                              r +
                          1.36929880922735805310e-1) *
                             r +
                         5.99832206555887937690e-1) *
                            r +
                        1.0);
    value = num / den;
  }
  return q < 0.0 ? -value : value;
}

double normal_cdf(double z) { return 0.5 * std::erfc(-z * 0.70710678118654752440); }

}  // namespace texel::detmath
