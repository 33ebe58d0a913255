// detfft: a deterministic FFT, and the chirp-z sum of harmonics built on it
// (the reference textures' synthesis from document version 3; docs/algorithm.md
// "Reference textures").
//
// DetFft is a radix-2 complex FFT whose output is the same bits on every
// build: its twiddle factors come from detmath::sin_cycles of the exact
// fractions t/n, every butterfly is the same IEEE operations in the same
// order (-ffp-contract=off, no fast-math), and the order in which independent
// butterflies run (the cache-friendly recursion below) cannot change a bit of
// their results. The method is Gentleman–Sande decimation in frequency
// forward (natural order in, bit-reversed out) and Cooley–Tukey decimation in
// time inverse (bit-reversed in, natural out), so a convolution never
// permutes; `forward`/`inverse` add the permutation for callers that need the
// natural order. The loops (butterflies, twiddles, the chirps' phases and
// sines below) run in explicit SIMD lanes (detfft_kernels.hpp), every lane
// doing the scalar operations in the same order, so the width never changes
// a bit. Trade-off: radix 2 and split re/im arrays are slower than a tuned
// library (pocketfft, FFTW) by a small factor, in exchange for bits that
// depend on nothing but these files and detmath.
//
// sum_harmonics evaluates a sum of harmonics of one fundamental on a uniform
// grid, the whole of a reference noise or waveform, with Bluestein's chirp-z
// transform (k·m = (k² + m² − (m−k)²)/2 turns the sum into a convolution):
// O((samples + harmonics) · log) instead of O(samples × harmonics). Every
// phase is reduced modulo one cycle from exact integer products and
// double-double factors, so the result is as accurate as the direct sum
// (about 1e-13 of the peak at 10^6 harmonics) and bit-identical everywhere.
// Out of core, the independent parts (groups of a pass, blocks) run on
// worker threads (parallel.hpp) with buffers of their own; which thread
// does what never changes a bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace texel::detail {

/// An unevaluated sum hi + lo of two doubles (|lo| <= ulp(hi)/2): about 106
/// bits, enough to carry a frequency or a position whose products with
/// integers up to 2^53 must stay exact modulo one cycle.
struct TwoDouble {
  double hi = 0.0;
  double lo = 0.0;
};

/// a + b exactly (Knuth's TwoSum). Plain IEEE operations; exact under
/// -ffp-contract=off.
TwoDouble two_sum(double a, double b);
/// a · b exactly (Dekker's product with Veltkamp splitting; no FMA), for
/// |a·b| < 2^996 and no underflow.
TwoDouble two_product(double a, double b);
/// 1 / d as a two-double (d > 0).
TwoDouble reciprocal(double d);

struct FftKernels;

/// A deterministic complex FFT of size n = 2^p, 1 <= n <= 2^26.
class DetFft {
 public:
  /// Prepares the twiddles e^(−2πi·t/n), t < n/2, laid out per stage (n − 1
  /// complex values). `lanes` picks the SIMD width of its loops
  /// (detfft_kernels.hpp: 0 = the widest this CPU runs, 1 = the scalar
  /// reference); the bits are the same for every width.
  /// Throws InvalidArgument if n is not a power of two in range, or for a
  /// width this CPU does not run.
  explicit DetFft(std::size_t n, int lanes = 0);

  [[nodiscard]] std::size_t size() const { return n_; }

  /// X_k = Σ_t x_t·e^(−2πi·tk/n), in place over re[0, n), im[0, n); natural
  /// order in, bit-reversed order out (X_k lands at index bit_reverse(k)).
  void forward_to_bit_reversed(double* re, double* im) const;
  /// x_t = Σ_k X_k·e^(+2πi·tk/n) (unnormalised), in place; bit-reversed
  /// order in, natural order out. inverse(forward(x)) = n·x.
  void inverse_from_bit_reversed(double* re, double* im) const;
  /// Natural order in and out (forward_to_bit_reversed + a permutation).
  void forward(double* re, double* im) const;
  /// Natural order in and out (a permutation + inverse_from_bit_reversed).
  void inverse(double* re, double* im) const;
  /// The p-bit reversal of i, for n = 2^p.
  [[nodiscard]] std::size_t bit_reverse(std::size_t i) const;

 private:
  void permute(double* re, double* im) const;
  void dif(double* re, double* im, std::size_t n) const;
  void dit(double* re, double* im, std::size_t n) const;

  std::size_t n_ = 1;
  int bits_ = 0;
  const FftKernels* kernels_ = nullptr;
  // Twiddles e^(−2πi·j/2h) of every stage h (1, 2, 4 … n/2), j < h, stage h
  // at offset h − 1: n − 1 values, contiguous per stage.
  std::vector<double> cos_;
  std::vector<double> sin_;  // the forward twiddle's imaginary part, −sin
};

/// A sum of harmonics of one fundamental: harmonic first + j has amplitude
/// amplitude[j] (0 = absent) and phase phase_cycles[j] (cycles).
struct Harmonics {
  std::uint64_t first = 0;  ///< harmonic number of element 0 (< 2^52)
  TwoDouble fundamental;    ///< cycles per mm (e.g. 1/length for noise, f0 for waveforms)
  std::span<const double> amplitude;
  std::span<const double> phase_cycles;
};

/// The most harmonics sum_harmonics takes: its memory is 48 bytes per FFT
/// point (kernel and work spectra, twiddles) and the FFT size lies between the
/// harmonic count and about four times it, so at most about 768 MiB.
inline constexpr std::size_t max_chirp_harmonics = std::size_t{1} << 22;

/// out[m] = Σ_j amplitude[j]·sin(2π(phase_cycles[j] + (first + j)·f·x_m)),
/// x_m = origin + (index + m)·spacing, f the fundamental, positions and
/// products taken exactly (not as Grid::position rounds them). Time
/// O((samples + harmonics)·log); memory beyond `out` 48 bytes per point of
/// one FFT whose size (the block size rule in detfft.cpp) lies between the
/// harmonic count and the power of two above samples + harmonics. The bits
/// are a function of the arguments alone.
/// Requires 1 <= amplitude.size() == phase_cycles.size() <=
/// max_chirp_harmonics, first + amplitude.size() < 2^52, |index| + out.size() < 2^52.
void sum_harmonics(const Harmonics& h, double origin, double spacing, std::int64_t index, std::span<double> out);

/// Harmonics supplied in runs, for sums too large to hold: fill(j0,
/// amplitude, phase) writes the amplitudes and phases (cycles) of harmonics
/// first + j0 … first + j0 + amplitude.size() − 1 (amplitude.size() ==
/// phase.size()). It is called once per run per output block, so it must
/// give the same values every time; out of core the runs come in any order
/// and from several threads at once, so it must be safe to call
/// concurrently (a pure function of j0 is).
struct HarmonicSource {
  std::uint64_t first = 0;  ///< harmonic number of element 0 (< 2^52)
  TwoDouble fundamental;    ///< cycles per mm
  std::size_t count = 0;    ///< harmonics first … first + count − 1
  std::function<void(std::size_t j0, std::span<double> amplitude, std::span<double> phase)> fill;
};

/// A source reading the spans of `h` (which must outlive it).
HarmonicSource harmonic_source(const Harmonics& h);

/// Receives the samples of sum_harmonics in order: sink(m0, y) is samples
/// m0 … m0 + y.size() − 1.
using SampleSink = std::function<void(std::size_t m0, std::span<const double> y)>;

/// How much memory the chirp-z synthesis may use. An FFT of up to
/// `fft_points` points runs in memory (48 bytes per point); a larger one
/// runs out of core on a ScratchFile ($TMPDIR; 32 bytes per FFT point on
/// disk) with about 32 bytes × fft_points of memory, plus 24 bytes ×
/// fft_points for each worker thread beyond the first, streaming the FFT's
/// stages in passes. Where the arrays live never changes a bit of the
/// result: every butterfly is the in-memory FFT's, with the same twiddles.
struct ChirpMemory {
  std::size_t fft_points = std::size_t{1} << 17;  ///< a power of two >= 4 (6 MiB in memory)
  /// The SIMD width of the loops: 0 = the widest this CPU runs, 1 = the
  /// scalar reference (tests), 2, 4 or 8. Never changes a bit.
  int lanes = 0;
  /// Worker threads of an out-of-core sum (parallel.hpp), each with its
  /// own W-point buffers: 0 = detail::worker_threads(). Never changes a bit.
  int threads = 0;
};

/// The same sum as above, streamed: the harmonics come from `h.fill` and the
/// `samples` results go to `sink` in blocks, so memory is bounded by
/// `memory` whatever the number of harmonics or samples. Bit-identical to
/// the span form for the same harmonics.
/// Throws InvalidArgument as the span form; IoError if a scratch file is
/// needed and cannot be written.
void sum_harmonics(const HarmonicSource& h, double origin, double spacing, std::int64_t index, std::size_t samples,
                   const SampleSink& sink, const ChirpMemory& memory = {});

}  // namespace texel::detail
