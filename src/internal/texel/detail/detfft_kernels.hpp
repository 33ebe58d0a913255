// detfft_kernels: the element-wise loops of the deterministic FFT and of the
// chirp-z sum of harmonics (detfft.hpp) — butterflies, twiddles, the
// spectral product and the chirps' phases and sines — with explicit SIMD
// lanes. Internal to Texel.
//
// Every loop is written once over its element type, `double` or a W-lane
// vector (texel/detail/lanes.hpp), in the style of the render and reference
// kernels: each lane performs exactly the scalar operations in the same
// order in IEEE double (-ffp-contract=off, no fast-math), so the width (8 on
// AVX-512, 4 on AVX2, 2 otherwise, picked by simd_lanes()) changes speed,
// never bits. Width 1 is the plain scalar code the kernels were written
// from, kept as the tests' slow, obviously-correct reference (std::round,
// integer squares, ldexp). The exact helpers below are generic for the same
// reason: the lanes need the two-double phase reduction, and the library's
// std::round is not a vector operation, so round_half_away rebuilds it from
// IEEE additions (the same value for every double, ±0 and ties included).
#pragma once

#include <cstddef>

#include "texel/detail/detfft.hpp"

namespace texel::detail {

/// round(x), halves away from zero, exactly as std::round for every double
/// (sign of zero, ties, |x| >= 2^52, infinities), from additions and
/// selects only, so that it runs in vector lanes: T is double or a lane
/// vector.
template <class T>
[[gnu::always_inline]] inline T round_half_away(T x) {
  constexpr double two52 = 4503599627370496.0;  // 2^52
  const T a = x < 0.0 ? -x : x;
  T r = (a + two52) - two52;        // a to nearest, ties to even (exact for a < 2^52)
  r = r - a == -0.5 ? r + 1.0 : r;  // a tie taken down goes up (r − a is exact)
  r = a < two52 ? r : a;            // 2^52 and beyond: already an integer
  r = x < 0.0 ? -r : r;             // round(−0.3) = −0
  return x == 0.0 ? x : r;          // round(±0) = ±0
}

/// x minus its nearest integer, in [−1/2, 1/2]: exact for every finite double.
template <class T>
[[gnu::always_inline]] inline T wrap_cycles(T x) {
  return x - round_half_away(x);
}

/// c·q modulo 1 (in [−1/2, 1/2]) for a two-double c with |c.hi| <= 1/2 and an
/// integer q < 2^53 given as a double (T: double or a lane vector): c.hi·q
/// exactly by Dekker's product (no FMA), its high part reduced exactly and
/// its low part below one cycle, so the phase keeps about 1e-16 cycle.
template <class T>
[[gnu::always_inline]] inline T cycles_times(TwoDouble c, T q) {
  const T p = c.hi * q;
  const double ca = 134217729.0 * c.hi;  // Veltkamp's split, 2^27 + 1
  const double xh = ca - (ca - c.hi);
  const double xl = c.hi - xh;
  const T cq = 134217729.0 * q;
  const T yh = cq - (cq - q);
  const T yl = q - yh;
  const T lo = ((xh * yh - p) + xh * yl + xl * yh) + xl * yl;
  return wrap_cycles(wrap_cycles(p) + (lo + c.lo * q));
}

/// The exact phase steps every block of one chirp-z sum shares (detfft.cpp's
/// ChirpPlan): θ = f·spacing, all modulo one cycle.
struct ChirpPhases {
  TwoDouble half_theta;   ///< θ/2
  TwoDouble first_theta;  ///< first·θ
  double first = 0.0;     ///< the first harmonic number (< 2^52, exact)
  double inv_m = 0.0;     ///< 1/M (a power of two)
};

/// The kernels of one lane width. Every pointer range is [0, n); n need not
/// be a multiple of the width (the remainder runs the same code on scalars).
struct FftKernels {
  int lanes = 1;
  /// n decimation-in-frequency butterflies (a, b)[j] with twiddles (c, s)[j]:
  /// a ← x + y, b ← (x − y)·w.
  void (*dif_butterflies)(double* ar, double* ai, double* br, double* bi, const double* c, const double* s, std::size_t n);
  /// n decimation-in-time butterflies with the conjugate twiddles: t = y·w̄,
  /// a ← x + t, b ← x − t.
  void (*dit_butterflies)(double* ar, double* ai, double* br, double* bi, const double* c, const double* s, std::size_t n);
  /// One decimation-in-frequency stage over re/im[0, n), n a multiple of 2h:
  /// butterflies of span h with twiddles (c, s)[j], j < h (spans below the
  /// width run across groups, by lane shuffles).
  void (*dif_stage)(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s);
  /// The same for decimation in time.
  void (*dit_stage)(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s);
  /// The stages of spans h and h/2 (h >= 2; n a multiple of 2h) in one sweep,
  /// decimation in frequency (h, then h/2), with the twiddles of span g at
  /// (c, s) + g − 1: the bits of the two dif_stage calls.
  void (*dif_two_stages)(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s);
  /// The same in time: span h/2, then h.
  void (*dit_two_stages)(double* re, double* im, std::size_t n, std::size_t h, const double* c, const double* s);
  /// u ← u·v, complex, pointwise.
  void (*multiply_spectra)(double* ur, double* ui, const double* vr, const double* vi, std::size_t n);
  /// c[x] = cos_cycles(u), s[x] = −sin_cycles(u), u = (j0 + x)·scale; j0 a
  /// whole number and scale a power of two, so u is the exact fraction.
  void (*twiddles)(double j0, double scale, std::size_t n, double* c, double* s);
  /// The chirp kernel e^(−2πi·C_d)/M, C_d = θ/2·d², for d = d0 + step·x
  /// (step ±1, 0 <= d < 2^26): re ← cos·(1/M), im ← −sin·(1/M).
  void (*chirp_kernel)(const ChirpPhases& p, double d0, double step, std::size_t n, double* re, double* im);
  /// A block's input a_j·e^(2πi·A_j), A_j = φ_j + (first + j)·α + θ/2·j², for
  /// j = j0 + x (< 2^26): written over the amplitudes (re) and phases (im).
  void (*chirp_input)(const ChirpPhases& p, TwoDouble alpha, double j0, std::size_t n, double* amplitude_re, double* phase_im);
  /// y_t = Im(e^(2πi·B_t)·z_t), B_t = θ/2·t² + first·θ·t, for t = t0 + x
  /// (< 2^26); out may be zr (element by element).
  void (*chirp_output)(const ChirpPhases& p, double t0, std::size_t n, const double* zr, const double* zi, double* out);
};

/// The kernels of `lanes` lanes: 1 (the scalar reference), or 2, 4, 8 up to
/// simd_lanes(); 0 = simd_lanes(). Throws InvalidArgument for another width
/// or one this CPU does not run.
const FftKernels& fft_kernels(int lanes = 0);

}  // namespace texel::detail
