// Deterministic elementary functions.
//
// The C library's exp/log/sin are allowed to differ by an ulp between
// implementations (glibc, musl, MSVC, Apple), and a compiler may constant-fold
// them differently; a texture file must render to the same bytes everywhere
// (docs/algorithm.md §9). Everything that feeds rendered samples therefore goes
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

/// fdlibm's split of ln 2: the high part has trailing zero bits, so k·ln2_hi
/// is exact for |k| < 2^11.
inline constexpr double ln2_hi = 6.93147180369123816490e-01;
inline constexpr double ln2_lo = 1.90821492927058770002e-10;
inline constexpr double inv_ln2 = 1.44269504088896338700e+00;

/// exp's reduction and polynomial, generic over the value type like
/// sin_cycles_generic (the scalar exp and the lane-wise texel draws share
/// this one definition): x = k·ln2 + r with k = round_even(x/ln2) and
/// |r| <= ln2/2, then e^r by Taylor to r^14 (error < 1e-18). Returns e^r in
/// [0.70, 1.42] and sets `k`; e^x = e^r·2^k (scale_pow2). For finite x in
/// exp's range (-745.13 … 709.78).
template <class T>
[[gnu::always_inline]] constexpr T exp_reduced_generic(T x, T& k) {
  constexpr double magic = 6755399441055744.0;  // round_even's 1.5 * 2^52
  k = ((x * inv_ln2) + magic) - magic;
  const T r = (x - k * ln2_hi) - k * ln2_lo;
  T p = 1.0 / 87178291200.0 * r + 1.0 / 6227020800.0;  // 1/14!, 1/13!
  p = p * r + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  return p;
}

/// 2^k for k in [-1022, 1023], exactly (a normal double built from its
/// exponent bits).
constexpr double pow2(int k) { return std::bit_cast<double>(static_cast<std::uint64_t>(k + 1023) << 52); }

/// p·2^k rounded once, for p in [0.5, 2) and k in [-1076, 1024]: what
/// std::ldexp(p, k) returns, bit for bit, without the library call. Where
/// 2^k is a normal double the product is exact, or (a subnormal result)
/// rounded once from the exact value, as ldexp rounds; beyond, the first
/// factor gives an exact normal product and only the second rounds.
constexpr double scale_pow2(double p, int k) {
  if (k >= -1022 && k <= 1023) return p * pow2(k);
  return k > 0 ? (p * pow2(k - 1023)) * pow2(1023) : (p * pow2(k + 1022)) * pow2(-1022);
}

/// Wichura's AS241 (PPND16) central branch, for |q| <= 0.425 where
/// q = p − 1/2: Φ⁻¹(p) = q·num(r)/den(r), r = 0.180625 − q². Generic over
/// the value type; normal_quantile uses it for that branch.
template <class T>
[[gnu::always_inline]] constexpr T normal_quantile_central_generic(T q) {
  const T r = 0.180625 - q * q;
  const T num = (((((((2.5090809287301226727e+3 * r + 3.3430575583588128105e+4) * r + 6.7265770927008700853e+4) * r +
                     4.5921953931549871457e+4) *
                        r +
                    1.3731693765509461125e+4) *
                       r +
                   1.9715909503065514427e+3) *
                      r +
                  1.3314166789178437745e+2) *
                     r +
                 3.3871328727963666080e+0);
  const T den = (((((((5.2264952788528545610e+3 * r + 2.8729085735721942674e+4) * r + 3.9307895800092710610e+4) * r +
                     2.1213794301586595867e+4) *
                        r +
                    5.3941960214247511077e+3) *
                       r +
                   6.8718700749205790830e+2) *
                      r +
                  4.2313330701600911252e+1) *
                     r +
                 1.0);
  return q * num / den;
}

/// log's core for positive, finite, normal x, generic over the value type T
/// and the matching 64-bit word type U (double and std::uint64_t, or GCC/clang
/// vectors of them, every lane doing the scalar operations): x = m·2^e with
/// m in [√½, √2), exactly, from the bits; log m = 2·atanh(s), s = (m−1)/(m+1),
/// |s| <= 0.1716, by the odd series to s^23. `e_offset` is added to e (the
/// scalar log's pre-scaling of subnormals). All exponent arithmetic is on
/// small whole numbers, exact in double.
template <class T, class U>
[[gnu::always_inline]] constexpr T log_normal_generic(T x, double e_offset = 0.0) {
  // __builtin_bit_cast, not std::bit_cast: a builtin is never a call, and a
  // vector passed to a function compiled for another instruction set (the
  // lane-wise kernels are AVX2/AVX-512 functions) changes its calling
  // convention; unoptimized builds would make that call.
  const U bits = __builtin_bit_cast(U, x);
  const U biased = (bits >> 52) & 0x7FFULL;
  T m = __builtin_bit_cast(T, (bits & 0x000FFFFFFFFFFFFFULL) | 0x3FF0000000000000ULL);  // [1, 2)
  // The biased exponent as a double, exactly: 2^52 + biased, less 2^52.
  T de = __builtin_bit_cast(T, biased | 0x4330000000000000ULL) - 4503599627370496.0;
  de = de + (e_offset - 1023.0);
  // m above √2: halve it and count one more power of two. (Selects on the
  // comparison itself: a vector mask kept in a variable is slow to build.)
  de = m > 1.4142135623730951 ? de + 1.0 : de;
  m = m > 1.4142135623730951 ? m * 0.5 : m;
  const T s = (m - 1.0) / (m + 1.0);
  const T s2 = s * s;
  T p = 1.0 / 23.0 * s2 + 1.0 / 21.0;
  p = p * s2 + 1.0 / 19.0;
  p = p * s2 + 1.0 / 17.0;
  p = p * s2 + 1.0 / 15.0;
  p = p * s2 + 1.0 / 13.0;
  p = p * s2 + 1.0 / 11.0;
  p = p * s2 + 1.0 / 9.0;
  p = p * s2 + 1.0 / 7.0;
  p = p * s2 + 1.0 / 5.0;
  p = p * s2 + 1.0 / 3.0;
  const T log_m = 2.0 * s + 2.0 * s * s2 * p;
  return de * ln2_hi + (log_m + de * ln2_lo);
}

/// AS241's first tail branch, for |q| > 0.425 where r = √(−log(min(p, 1−p)))
/// is at most 5: the magnitude of Φ⁻¹(p), num(r − 1.6)/den(r − 1.6). Generic
/// over the value type; normal_quantile uses it for that branch.
template <class T>
[[gnu::always_inline]] constexpr T normal_quantile_tail_generic(T r) {
  r = r - 1.6;
  const T num = (((((((7.74545014278341407640e-4 * r + 2.27238449892691845833e-2) * r + 2.41780725177450611770e-1) * r +
                     1.27045825245236838258e+0) *
                        r +
                    3.64784832476320460504e+0) *
                       r +
                   5.76949722146069140550e+0) *
                      r +
                  4.63033784615654529590e+0) *
                     r +
                 1.42343711074968357734e+0);
  const T den = (((((((1.05075007164441684324e-9 * r + 5.47593808499534494600e-4) * r + 1.51986665636164571966e-2) * r +
                     1.48103976427480074590e-1) *
                        r +
                    6.89767334985100004550e-1) *
                       r +
                   1.67638483018380384940e+0) *
                      r +
                  2.05319162663775882187e+0) *
                     r +
                 1.0);
  return num / den;
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
