// Deterministic elementary functions.
//
// The C library's exp/log/sin are allowed to differ by an ulp between
// implementations (glibc, musl, MSVC, Apple), and a compiler may constant-fold
// them differently; a texture file must render to the same bytes everywhere
// (rendering.md §9). Everything that feeds rendered samples therefore goes
// through these functions, built only from IEEE-754 +, -, *, / and exact
// operations (frexp/ldexp-style bit manipulation, integer rounding), compiled
// with -ffp-contract=off. Accuracy is a few ulp, far below the 16-bit output
// resolution; bit-identity, not last-ulp accuracy, is the goal.
#pragma once

#include <bit>
#include <cstdint>

namespace texel::detmath {

/// Round to nearest integer (ties to even) for |x| < 2^51, exactly, without
/// calling the C library: the classic 1.5·2^52 trick. Vectorizes on SSE2.
constexpr double round_even(double x) {
  constexpr double magic = 6755399441055744.0;  // 1.5 * 2^52
  return (x + magic) - magic;
}

/// floor(x) for |x| < 2^51, exact.
constexpr double floor_exact(double x) {
  double r = round_even(x);
  return r > x ? r - 1.0 : r;
}

/// sin(2π·u), generic over the value type: `double`, or a GCC/clang vector
/// of doubles (`double __attribute__((vector_size(N)))`), where every lane
/// performs exactly the scalar operations in the same order. The scalar
/// sin_cycles and the SIMD render kernels share this one definition, which is
/// what keeps their results bit-identical.
///
/// Exact reduction to [-1/4, 1/4] cycle, then an odd Taylor polynomial of
/// degree 19 (truncation error < 1e-15). Branch-free. Valid for |u| < 2^50.
template <class T>
[[gnu::always_inline]] constexpr T sin_cycles_generic(T u) {
  constexpr double magic = 6755399441055744.0;  // round_even's 1.5 * 2^52
  T r = u - ((u + magic) - magic);              // [-0.5, 0.5], exact
  // Reflect into [-0.25, 0.25]: sin(2π(±0.5 - r)) = sin(2πr). Exact (Sterbenz).
  const T hi = 0.5 - r;
  const T lo = -0.5 - r;
  r = r > 0.25 ? hi : r;
  r = r < -0.25 ? lo : r;
  const T r2 = r * r;
  // Coefficients (2π)^(2n+1) / (2n+1)! with alternating signs.
  T p = -0.012031585942120619 * r2 + 0.10422916220813978;
  p = p * r2 + -0.7181223017785001;
  p = p * r2 + 3.8199525848482803;
  p = p * r2 + -15.094642576822984;
  p = p * r2 + 42.058693944897634;
  p = p * r2 + -76.70585975306136;
  p = p * r2 + 81.60524927607504;
  p = p * r2 + -41.341702240399755;
  p = p * r2 + 6.283185307179586;
  return r * p;
}

/// sin(2π·u) for any |u| < 2^50 cycles.
constexpr double sin_cycles(double u) { return sin_cycles_generic(u); }

/// cos(2π·u) = sin(2π(u + 1/4)).
constexpr double cos_cycles(double u) { return sin_cycles(u + 0.25); }

/// Natural logarithm, x > 0 and finite (returns -inf for 0, NaN for x < 0).
double log(double x);
/// e^x; overflow gives +inf, underflow 0.
double exp(double x);
/// 10^x.
double pow10(double x);
/// Inverse of the standard normal CDF, p in (0, 1) (Wichura's AS241, PPND16,
/// relative accuracy about 1e-16), built on detmath::log and an exact sqrt.
double normal_quantile(double p);
/// Standard normal CDF. Used for band-mass checks, not for samples.
double normal_cdf(double z);

}  // namespace texel::detmath
