// detfft: the deterministic FFT against a long-double DFT, the chirp-z sum of
// harmonics against the direct long-double sum, the exact two-double helpers,
// and pinned digests of the output bits (the same on every build: GCC/clang,
// -O0/-O3, any SIMD width, sanitizers).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "texel/detail/detfft.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"

using namespace texel;
using namespace texel::detail;

namespace {

/// FNV-1a over the bytes of the doubles: a digest of exact bits.
std::uint64_t digest(const std::vector<double>& v, std::uint64_t h = 1469598103934665603ULL) {
  for (double x : v) {
    unsigned char b[sizeof x];
    std::memcpy(b, &x, sizeof x);
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ULL;
  }
  return h;
}

/// Deterministic test input in [-1, 1).
std::vector<double> input(std::size_t n, std::uint64_t seed) {
  const CounterRng rng(seed, Stream::reference);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = 2.0 * rng.uniform(i) - 1.0;
  return v;
}

constexpr long double two_pi = 2.0L * std::numbers::pi_v<long double>;

}  // namespace

TEST(DetFft, ForwardMatchesTheLongDoubleDft) {
  // Relative to the input's norm, a radix-2 FFT in double is within a few
  // 1e-16 · log2(n); 1e-14 leaves a wide margin and still catches any wrong
  // twiddle or ordering (those give O(1) errors).
  for (std::size_t n : {1u, 2u, 4u, 8u, 64u, 1024u, 4096u, 8192u}) {
    const DetFft fft(n);
    std::vector<double> re = input(n, 1), im = input(n, 2);
    const std::vector<double> r0 = re, i0 = im;
    fft.forward(re.data(), im.data());
    long double norm = 0;
    for (std::size_t t = 0; t < n; ++t) norm += static_cast<long double>(r0[t]) * r0[t] + static_cast<long double>(i0[t]) * i0[t];
    norm = std::sqrt(norm);
    double worst = 0;
    for (std::size_t k = 0; k < n; k += (n > 1024 ? 61 : 1)) {
      long double xr = 0, xi = 0;
      for (std::size_t t = 0; t < n; ++t) {
        const long double a = -two_pi * static_cast<long double>((t * k) % n) / static_cast<long double>(n);
        xr += r0[t] * std::cos(a) - i0[t] * std::sin(a);
        xi += r0[t] * std::sin(a) + i0[t] * std::cos(a);
      }
      worst = std::max(worst, static_cast<double>(std::hypot(xr - re[k], xi - im[k]) / norm));
    }
    std::printf("fft %zu %.3g\n", n, worst);
    EXPECT_LT(worst, 1e-14) << "n = " << n;
  }
}

TEST(DetFft, InverseUndoesForwardAndBitReversedOrderIsThePermutation) {
  for (std::size_t n : {2u, 16u, 4096u, 65536u}) {
    const DetFft fft(n);
    std::vector<double> re = input(n, 3), im = input(n, 4);
    const std::vector<double> r0 = re, i0 = im;
    std::vector<double> rb = re, ib = im;
    fft.forward(re.data(), im.data());
    fft.forward_to_bit_reversed(rb.data(), ib.data());
    for (std::size_t k = 0; k < n; ++k) {
      ASSERT_EQ(rb[fft.bit_reverse(k)], re[k]) << n << " " << k;  // the same butterflies: exact
      ASSERT_EQ(ib[fft.bit_reverse(k)], im[k]) << n << " " << k;
    }
    fft.inverse(re.data(), im.data());
    double worst = 0;
    for (std::size_t t = 0; t < n; ++t)
      worst =
          std::max({worst, std::abs(re[t] / static_cast<double>(n) - r0[t]), std::abs(im[t] / static_cast<double>(n) - i0[t])});
    std::printf("fft %zu %.3g\n", n, worst);
    EXPECT_LT(worst, 1e-14) << "n = " << n;
  }
}

TEST(DetFft, RefusesSizesThatAreNotPowersOfTwo) {
  EXPECT_THROW(DetFft(0), InvalidArgument);
  EXPECT_THROW(DetFft(12), InvalidArgument);
  EXPECT_THROW(DetFft(std::size_t{1} << 27), InvalidArgument);
}

TEST(DetFft, TwoDoubleHelpersAreExact) {
  // (2^27 + 1)^2 = 2^54 + 2^28 + 1: the product's low part is the 1 a double drops.
  const double a = 134217729.0;
  const TwoDouble p = two_product(a, a);
  EXPECT_EQ(p.hi, 18014398777917440.0);
  EXPECT_EQ(p.lo, 1.0);
  const TwoDouble s = two_sum(1.0, 1e-17);
  EXPECT_EQ(s.hi, 1.0);
  EXPECT_EQ(s.lo, 1e-17);
  // 1/3 as a two-double: hi + lo = 1/3 to ~106 bits, so 3·(hi + lo) − 1 is ~1e-32.
  const TwoDouble r = reciprocal(3.0);
  const TwoDouble t = two_product(r.hi, 3.0);
  EXPECT_LT(std::abs((t.hi - 1.0) + t.lo + 3.0 * r.lo), 1e-30);
}

namespace {

struct Case {
  std::size_t harmonics;
  std::size_t samples;
  std::uint64_t first;
  double fundamental;  // cycles per mm, given as 1/period when period > 0
  double period;
  double origin;
  double spacing;
  std::int64_t index;
  bool odd_only;  // every other amplitude 0 (square/triangle waves)
};

Harmonics series(const Case& c, std::vector<double>& amp, std::vector<double>& phase) {
  const CounterRng rng(99, Stream::reference);
  amp.resize(c.harmonics);
  phase.resize(c.harmonics);
  for (std::size_t j = 0; j < c.harmonics; ++j) {
    amp[j] = c.odd_only && (c.first + j) % 2 == 0 ? 0.0 : 0.1 + rng.uniform(2 * j);
    phase[j] = rng.uniform(2 * j + 1);
  }
  Harmonics h;
  h.first = c.first;
  h.fundamental = c.period > 0 ? reciprocal(c.period) : TwoDouble{c.fundamental, 0.0};
  h.amplitude = amp;
  h.phase_cycles = phase;
  return h;
}

/// The direct sum in long double, with the phase reduced from exact integer
/// products where it can be: the slow, obviously-correct reference.
std::vector<long double> direct(const Case& c, const Harmonics& h) {
  const long double f = static_cast<long double>(h.fundamental.hi) + h.fundamental.lo;
  std::vector<long double> y(c.samples);
  for (std::size_t m = 0; m < c.samples; ++m) {
    const long double x = c.origin + static_cast<long double>(c.index + static_cast<std::int64_t>(m)) * c.spacing;
    const long double fx = f * x;
    long double acc = 0;
    for (std::size_t j = 0; j < c.harmonics; ++j) {
      if (h.amplitude[j] == 0.0) continue;
      long double u = h.phase_cycles[j] + static_cast<long double>(c.first + j) * fx;
      u -= std::floor(u);
      acc += h.amplitude[j] * std::sin(two_pi * u);
    }
    y[m] = acc;
  }
  return y;
}

}  // namespace

TEST(ChirpZ, SumOfHarmonicsMatchesTheDirectSum) {
  // Within 1e-12 of the peak: the direct double sum itself is only good to
  // about 1e-13 here, and any error in the chirps or the block layout is O(1).
  const std::vector<Case> cases{
      {1, 1, 1, 0, 10.0, 0.0, 0.01, 0, false},                  // one harmonic, one sample
      {300, 1000, 5, 0, 5.3, 0.0, 0.0053, 0, false},            // noise over a 5.3 mm texture, one block
      {2000, 2500, 1, 0, 26.5, -50.88, 0.0053, 9600, false},    // a region right of 50.88 mm: x0 from a large index
      {50, 20000, 1, 1.0, 0, 0.0, 0.0053, 0, true},             // square wave harmonics: many blocks, zeros
      {700, 5000, 400, 0, 101.76, 0.00123, 0.0053, -3, false},  // a band away from the first harmonic
      {64, 4000, 1, 0.37, 0, 12.5, 0.013, 1000000, false},      // far along the grid
  };
  for (const Case& c : cases) {
    std::vector<double> amp, phase;
    const Harmonics h = series(c, amp, phase);
    std::vector<double> out(c.samples);
    sum_harmonics(h, c.origin, c.spacing, c.index, out);
    const std::vector<long double> ref = direct(c, h);
    long double peak = 0, worst = 0;
    for (std::size_t m = 0; m < c.samples; ++m) {
      peak = std::max(peak, std::abs(ref[m]));
      worst = std::max(worst, std::abs(ref[m] - out[m]));
    }
    std::printf("err %zu %zu %.3g\n", c.harmonics, c.samples, (double)(worst / peak));
    EXPECT_LT(static_cast<double>(worst / peak), 1e-12) << c.harmonics << " harmonics × " << c.samples << " samples";
  }
}

TEST(ChirpZ, SameInputsSameBitsAndPinnedDigests) {
  // Bitwise self-consistency, then the exact bits pinned: these digests are
  // the same on every build (the reference synthesis of document version 3
  // depends on it; tests/determinism/cross_build.sh checks whole references).
  const Case c{4000, 9000, 3, 0, 47.7, 0.0, 0.0053, 0, false};
  std::vector<double> amp, phase;
  const Harmonics h = series(c, amp, phase);
  std::vector<double> a(c.samples), b(c.samples);
  sum_harmonics(h, c.origin, c.spacing, c.index, a);
  sum_harmonics(h, c.origin, c.spacing, c.index, b);
  EXPECT_EQ(digest(a), digest(b));
  EXPECT_EQ(digest(a), 2577014420217310180u) << "sum_harmonics digest";

  const DetFft fft(1 << 14);
  std::vector<double> re = input(1 << 14, 5), im = input(1 << 14, 6);
  fft.forward(re.data(), im.data());
  EXPECT_EQ(digest(im, digest(re)), 5187881437504283807u) << "forward digest";
  fft.inverse(re.data(), im.data());
  EXPECT_EQ(digest(im, digest(re)), 12670610262917205821u) << "inverse digest";
}

TEST(ChirpZ, RefusesEmptyMismatchedOrTooManyHarmonics) {
  std::vector<double> out(10);
  const std::vector<double> one{1.0}, two{1.0, 2.0};
  EXPECT_THROW(sum_harmonics(Harmonics{1, {1.0, 0.0}, {}, {}}, 0.0, 0.1, 0, out), InvalidArgument);
  EXPECT_THROW(sum_harmonics(Harmonics{1, {1.0, 0.0}, one, two}, 0.0, 0.1, 0, out), InvalidArgument);
  const std::vector<double> many(max_chirp_harmonics + 1, 0.0);
  EXPECT_THROW(sum_harmonics(Harmonics{1, {1.0, 0.0}, many, many}, 0.0, 0.1, 0, out), InvalidArgument);
}

TEST(ChirpZ, StreamedAndOutOfCoreGiveTheInMemoryBits) {
  // The streamed form with every FFT size below, at and above the memory
  // budget (out of core on a scratch file, in one pass or several for the
  // stages above the budget, one output block or many) gives the span form's
  // bits exactly. The budget only moves where the arrays live.
  const std::vector<Case> cases{
      {1, 1, 1, 0, 10.0, 0.0, 0.01, 0, false},
      {300, 1000, 5, 0, 5.3, 0.0, 0.0053, 0, false},
      {2000, 2500, 1, 0, 26.5, -50.88, 0.0053, 9600, false},
      {50, 20000, 1, 1.0, 0, 0.0, 0.0053, 0, true},
      {700, 5000, 400, 0, 101.76, 0.00123, 0.0053, -3, false},
      {4000, 9000, 3, 0, 47.7, 0.0, 0.0053, 0, false},
  };
  for (const Case& c : cases) {
    std::vector<double> amp, phase;
    const Harmonics h = series(c, amp, phase);
    std::vector<double> expected(c.samples);
    sum_harmonics(h, c.origin, c.spacing, c.index, expected);
    std::atomic<std::size_t> runs = 0;  // the source is called from every worker thread
    const HarmonicSource source{h.first, h.fundamental, c.harmonics,
                                [&](std::size_t j0, std::span<double> a, std::span<double> p) {
                                  ASSERT_EQ(a.size(), p.size());
                                  ASSERT_LE(j0 + a.size(), c.harmonics);
                                  std::copy_n(amp.begin() + static_cast<std::ptrdiff_t>(j0), a.size(), a.begin());
                                  std::copy_n(phase.begin() + static_cast<std::ptrdiff_t>(j0), p.size(), p.begin());
                                  ++runs;
                                }};
    for (std::size_t budget : {std::size_t{32}, std::size_t{4096}, std::size_t{1} << 17}) {
      std::vector<double> got(c.samples, std::nan(""));
      std::size_t next = 0;
      sum_harmonics(
          source, c.origin, c.spacing, c.index, c.samples,
          [&](std::size_t m0, std::span<const double> y) {
            ASSERT_EQ(m0, next) << "samples arrive in order";
            std::copy(y.begin(), y.end(), got.begin() + static_cast<std::ptrdiff_t>(m0));
            next += y.size();
          },
          ChirpMemory{budget});
      EXPECT_EQ(next, c.samples);
      EXPECT_EQ(digest(got), digest(expected)) << c.harmonics << " harmonics × " << c.samples << " samples, budget " << budget;
    }
    EXPECT_GT(runs, 0u);
  }
  std::vector<double> out(4);
  const HarmonicSource none{1, {1.0, 0.0}, 3, nullptr};
  EXPECT_THROW(sum_harmonics(none, 0.0, 0.1, 0, 4, [](std::size_t, std::span<const double>) {}), InvalidArgument);
  const HarmonicSource one{1, {1.0, 0.0}, 1, [](std::size_t, std::span<double> a, std::span<double> p) {
                             a[0] = 1.0;
                             p[0] = 0.0;
                           }};
  EXPECT_THROW(sum_harmonics(
                   one, 0.0, 0.1, 0, 4, [](std::size_t, std::span<const double>) {}, ChirpMemory{48}),
               InvalidArgument);
}

TEST(ChirpZ, AScratchFileThatCannotBeCreatedIsAClearError) {
  const char* old = std::getenv("TMPDIR");
  const std::string saved = old != nullptr ? old : "";
  ::setenv("TMPDIR", "/nonexistent-texel-dir", 1);
  std::vector<double> amp(500, 1.0), phase(500, 0.0);
  const HarmonicSource source{1, {1.0, 0.0}, amp.size(), [&](std::size_t j0, std::span<double> a, std::span<double> p) {
                                std::copy_n(amp.begin() + static_cast<std::ptrdiff_t>(j0), a.size(), a.begin());
                                std::copy_n(phase.begin() + static_cast<std::ptrdiff_t>(j0), p.size(), p.begin());
                              }};
  try {
    sum_harmonics(
        source, 0.0, 0.001, 0, 1000, [](std::size_t, std::span<const double>) {}, ChirpMemory{64});
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-texel-dir"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("TMPDIR"), std::string::npos) << e.what();
  }
  if (old != nullptr)
    ::setenv("TMPDIR", saved.c_str(), 1);
  else
    ::unsetenv("TMPDIR");
}
