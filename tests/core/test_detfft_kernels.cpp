// detfft's SIMD kernels against the scalar code they were written from, bit
// for bit: every width this CPU runs (8, 4, 2 lanes) on sizes that are and
// are not multiples of it, the exact round behind the phase reduction on
// the doubles where a rebuilt round could go wrong (zeros, ties, 2^52), and
// whole chirp-z sums through each width, in memory and out of core.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "texel/detail/detfft.hpp"
#include "texel/detail/detfft_kernels.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/detail/parallel.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"

#include "../support/memory.hpp"

using namespace texel;
using namespace texel::detail;
using test_support::same_bits;

namespace {

std::vector<double> values(std::size_t n, std::uint64_t seed, double lo = -1.0, double hi = 1.0) {
  const CounterRng rng(seed, Stream::user);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = lo + (hi - lo) * rng.uniform(i);
  return v;
}

bool same_double(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// The widths to compare with the scalar reference: every one this CPU runs.
std::vector<int> widths() {
  std::vector<int> w{2};
  if (simd_lanes() >= 4) w.push_back(4);
  if (simd_lanes() >= 8) w.push_back(8);
  return w;
}

/// Sizes around every width's multiples, and larger ones.
const std::vector<std::size_t> sizes{1, 2, 3, 5, 7, 8, 9, 15, 16, 17, 31, 33, 100, 1000, 1023, 4099};

/// Phase steps like a real plan's: two-doubles reduced modulo 1.
ChirpPhases phases(std::uint64_t seed) {
  const std::vector<double> v = values(6, seed, -0.5, 0.5);
  return {{v[0], v[1] * 1e-17}, {v[2], v[3] * 1e-17}, 1234567.0, 1.0 / 65536.0};
}

}  // namespace

TEST(DetFftKernels, RoundHalfAwayIsStdRoundForEveryKindOfDouble) {
  const double two52 = 4503599627370496.0;
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> xs{0.0,
                         -0.0,
                         0.3,
                         -0.3,
                         0.5,
                         -0.5,
                         1.5,
                         -1.5,
                         2.5,
                         -2.5,
                         0.49999999999999994,
                         -0.49999999999999994,
                         two52,
                         -two52,
                         two52 - 0.5,
                         -(two52 - 0.5),
                         two52 - 1.5,
                         two52 / 2 + 0.5,
                         two52 + 1.0,
                         2 * two52 + 2,
                         1e300,
                         -1e300,
                         inf,
                         -inf,
                         5e-324,
                         -5e-324,
                         1e-17,
                         -1e-17};
  for (double x : values(20000, 7, -1e6, 1e6)) xs.push_back(x);
  for (double x : values(2000, 8, -4.0, 4.0)) xs.push_back(std::round(x * 2.0) / 2.0);  // ties
  for (int e = -60; e < 60; ++e) xs.push_back(std::ldexp(1.0 + values(1, e + 100)[0] * 0.5, e));
  using V = Lanes<2>::type;
  for (double x : xs) {
    EXPECT_TRUE(same_double(round_half_away(x), std::round(x))) << x;
    EXPECT_TRUE(same_double(wrap_cycles(x), x - std::round(x))) << x;
    const V v{x, -x};
    const V r = round_half_away(v);
    EXPECT_TRUE(same_double(r[0], std::round(x)) && same_double(r[1], std::round(-x))) << x;
  }
}

TEST(DetFftKernels, EveryWidthGivesTheScalarBits) {
  const FftKernels& ref = fft_kernels(1);
  for (int w : widths()) {
    const FftKernels& k = fft_kernels(w);
    ASSERT_EQ(k.lanes, w);
    for (std::size_t n : sizes) {
      const std::vector<double> c = values(n, 1), s = values(n, 2);
      // Butterflies, both directions, and the spectral product.
      for (int kind = 0; kind < 3; ++kind) {
        std::vector<double> a = values(4 * n, 3), b = a;
        double* pa = a.data();
        double* pb = b.data();
        if (kind == 0) {
          ref.dif_butterflies(pa, pa + n, pa + 2 * n, pa + 3 * n, c.data(), s.data(), n);
          k.dif_butterflies(pb, pb + n, pb + 2 * n, pb + 3 * n, c.data(), s.data(), n);
        } else if (kind == 1) {
          ref.dit_butterflies(pa, pa + n, pa + 2 * n, pa + 3 * n, c.data(), s.data(), n);
          k.dit_butterflies(pb, pb + n, pb + 2 * n, pb + 3 * n, c.data(), s.data(), n);
        } else {
          ref.multiply_spectra(pa, pa + n, pa + 2 * n, pa + 3 * n, n);
          k.multiply_spectra(pb, pb + n, pb + 2 * n, pb + 3 * n, n);
        }
        EXPECT_TRUE(same_bits(a, b)) << "kind " << kind << ", " << w << " lanes, n = " << n;
      }
      // Twiddles j/2h.
      for (double scale : {1.0 / 2.0, 1.0 / 64.0, 1.0 / 4194304.0}) {
        std::vector<double> c1(n), s1(n), c2(n), s2(n);
        ref.twiddles(37.0, scale, n, c1.data(), s1.data());
        k.twiddles(37.0, scale, n, c2.data(), s2.data());
        EXPECT_TRUE(same_bits(c1, c2) && same_bits(s1, s2)) << w << " lanes, n = " << n;
      }
      // The chirps, with phase steps and positions far along (d, j, t up to 2^26).
      for (std::uint64_t seed : {11u, 12u, 13u}) {
        const ChirpPhases p = phases(seed);
        const double start = seed == 13u ? 67108863.0 - static_cast<double>(n) : 1000.0 * static_cast<double>(seed);
        for (double step : {1.0, -1.0}) {
          const double d0 = step > 0 ? start : start + static_cast<double>(n) - 1.0;
          std::vector<double> r1(n), i1(n), r2(n), i2(n);
          ref.chirp_kernel(p, d0, step, n, r1.data(), i1.data());
          k.chirp_kernel(p, d0, step, n, r2.data(), i2.data());
          EXPECT_TRUE(same_bits(r1, r2) && same_bits(i1, i2)) << "kernel, " << w << " lanes, n = " << n;
        }
        const TwoDouble alpha{values(1, seed + 50, -0.5, 0.5)[0], 3e-18};
        std::vector<double> a1 = values(n, seed + 20, 0.0, 3.0), p1 = values(n, seed + 30, 0.0, 1.0);
        std::vector<double> a2 = a1, p2 = p1;
        ref.chirp_input(p, alpha, start, n, a1.data(), p1.data());
        k.chirp_input(p, alpha, start, n, a2.data(), p2.data());
        EXPECT_TRUE(same_bits(a1, a2) && same_bits(p1, p2)) << "input, " << w << " lanes, n = " << n;
        const std::vector<double> zr = values(n, seed + 40), zi = values(n, seed + 41);
        std::vector<double> y1(n), y2 = zr;
        ref.chirp_output(p, start, n, zr.data(), zi.data(), y1.data());
        k.chirp_output(p, start, n, y2.data(), zi.data(), y2.data());  // in place over zr, as out of core
        EXPECT_TRUE(same_bits(y1, y2)) << "output, " << w << " lanes, n = " << n;
      }
    }
    // Whole stages of every span, including the spans below the width.
    for (std::size_t n : {2u, 4u, 8u, 16u, 32u, 64u, 2048u}) {
      const std::vector<double> c = values(n / 2, 4), s = values(n / 2, 5);
      for (std::size_t h = 1; h < n; h *= 2) {
        for (bool dif : {true, false}) {
          std::vector<double> a = values(2 * n, 6), b = a;
          (dif ? ref.dif_stage : ref.dit_stage)(a.data(), a.data() + n, n, h, c.data(), s.data());
          (dif ? k.dif_stage : k.dit_stage)(b.data(), b.data() + n, n, h, c.data(), s.data());
          EXPECT_TRUE(same_bits(a, b)) << (dif ? "dif" : "dit") << " stage, " << w << " lanes, n = " << n << ", h = " << h;
        }
      }
      // Two stages in one sweep (spans h and h/2), twiddles from a whole table.
      const std::vector<double> ct = values(n, 7), st = values(n, 8);
      for (std::size_t h = 2; h < n; h *= 2) {
        for (bool dif : {true, false}) {
          std::vector<double> a = values(2 * n, 9), b = a;
          (dif ? ref.dif_two_stages : ref.dit_two_stages)(a.data(), a.data() + n, n, h, ct.data(), st.data());
          (dif ? k.dif_two_stages : k.dit_two_stages)(b.data(), b.data() + n, n, h, ct.data(), st.data());
          EXPECT_TRUE(same_bits(a, b)) << (dif ? "dif" : "dit") << " two stages, " << w << " lanes, n = " << n << ", h = " << h;
          // … and the bits of its two single stages.
          std::vector<double> c2 = values(2 * n, 9);
          const std::size_t g1 = dif ? h : h / 2, g2 = dif ? h / 2 : h;
          (dif ? k.dif_stage : k.dit_stage)(c2.data(), c2.data() + n, n, g1, ct.data() + g1 - 1, st.data() + g1 - 1);
          (dif ? k.dif_stage : k.dit_stage)(c2.data(), c2.data() + n, n, g2, ct.data() + g2 - 1, st.data() + g2 - 1);
          EXPECT_TRUE(same_bits(b, c2)) << (dif ? "dif" : "dit") << " two stages vs one by one, n = " << n << ", h = " << h;
        }
      }
    }
  }
  EXPECT_THROW((void)fft_kernels(3), InvalidArgument);
}

TEST(DetFftKernels, TransformsAndChirpZSumsAreTheScalarBitsAtEveryWidth) {
  for (int w : widths()) {
    for (std::size_t n : {1u, 2u, 4u, 8u, 16u, 4096u, 65536u}) {
      const DetFft scalar(n, 1), lanes(n, w);
      std::vector<double> r1 = values(n, 21), i1 = values(n, 22);
      std::vector<double> r2 = r1, i2 = i1;
      scalar.forward(r1.data(), i1.data());
      lanes.forward(r2.data(), i2.data());
      EXPECT_TRUE(same_bits(r1, r2) && same_bits(i1, i2)) << "forward " << n << ", " << w << " lanes";
      scalar.inverse(r1.data(), i1.data());
      lanes.inverse(r2.data(), i2.data());
      EXPECT_TRUE(same_bits(r1, r2) && same_bits(i1, i2)) << "inverse " << n << ", " << w << " lanes";
    }
    // Harmonic and sample counts that are not multiples of any width, in
    // memory and out of core (budgets below, at and above the FFT size).
    struct Case {
      std::size_t harmonics, samples;
      std::uint64_t first;
      double period, origin, spacing;
      std::int64_t index;
    };
    for (const Case& c : {Case{1, 1, 1, 10.0, 0.0, 0.01, 0}, Case{301, 1003, 5, 5.3, 0.0, 0.0053, 0},
                          Case{2003, 2501, 1, 26.5, -50.88, 0.0053, 9600}, Case{4001, 9003, 3, 47.7, 0.0, 0.0053, -7}}) {
      const std::vector<double> amp = values(c.harmonics, 31, 0.0, 2.0), phase = values(c.harmonics, 32, 0.0, 1.0);
      const HarmonicSource source = harmonic_source({c.first, reciprocal(c.period), amp, phase});
      for (std::size_t budget : {std::size_t{32}, std::size_t{4096}, std::size_t{1} << 17}) {
        std::vector<double> y1(c.samples), y2(c.samples);
        const auto into = [](std::vector<double>& y) {
          return [&y](std::size_t m0, std::span<const double> v) {
            std::copy(v.begin(), v.end(), y.begin() + static_cast<std::ptrdiff_t>(m0));
          };
        };
        sum_harmonics(source, c.origin, c.spacing, c.index, c.samples, into(y1), ChirpMemory{budget, 1});
        sum_harmonics(source, c.origin, c.spacing, c.index, c.samples, into(y2), ChirpMemory{budget, w});
        EXPECT_TRUE(same_bits(y1, y2)) << c.harmonics << " harmonics × " << c.samples << " samples, budget " << budget << ", "
                                       << w << " lanes";
      }
    }
  }
}

TEST(DetFftKernels, ThreadCountsGiveTheOneThreadBits) {
  // Out of core the groups of a pass, the blocks and the output runs are
  // shared among workers; every count gives the bits of one thread, and
  // the source may be called concurrently (here it checks its arguments).
  struct Case {
    std::size_t harmonics, samples;
    double period;
  };
  for (const Case& c : {Case{301, 1003, 5.3}, Case{2003, 25001, 26.5}, Case{4001, 9003, 47.7}}) {
    const std::vector<double> amp = values(c.harmonics, 41, 0.0, 2.0), phase = values(c.harmonics, 42, 0.0, 1.0);
    std::atomic<int> bad = 0;
    const HarmonicSource source{2, reciprocal(c.period), c.harmonics,
                                [&](std::size_t j0, std::span<double> a, std::span<double> p) {
                                  if (a.size() != p.size() || j0 + a.size() > c.harmonics) ++bad;
                                  std::copy_n(amp.begin() + static_cast<std::ptrdiff_t>(j0), a.size(), a.begin());
                                  std::copy_n(phase.begin() + static_cast<std::ptrdiff_t>(j0), p.size(), p.begin());
                                }};
    for (std::size_t budget : {std::size_t{32}, std::size_t{1024}, std::size_t{4096}}) {
      std::vector<double> expected;
      for (int threads : {1, 2, 3, 5}) {
        std::vector<double> y(c.samples, std::nan(""));
        std::size_t next = 0;
        sum_harmonics(
            source, 0.0, 0.0053, 0, c.samples,
            [&](std::size_t m0, std::span<const double> v) {
              ASSERT_EQ(m0, next) << "samples arrive in order";
              std::copy(v.begin(), v.end(), y.begin() + static_cast<std::ptrdiff_t>(m0));
              next += v.size();
            },
            ChirpMemory{budget, 0, threads});
        EXPECT_EQ(next, c.samples);
        if (threads == 1)
          expected = y;
        else
          EXPECT_TRUE(same_bits(y, expected))
              << c.harmonics << " harmonics × " << c.samples << " samples, budget " << budget << ", " << threads << " threads";
      }
    }
    EXPECT_EQ(bad.load(), 0);
  }
}

TEST(DetFftKernels, AWorkerThreadsErrorReachesTheCaller) {
  // A source that fails on one run, whichever worker draws it: the error
  // comes out of sum_harmonics, after every thread has been joined.
  const HarmonicSource failing{1, {1.0 / 64.0, 0.0}, 3000, [](std::size_t j0, std::span<double> a, std::span<double> p) {
                                 if (j0 >= 2000) throw IoError("source failed at " + std::to_string(j0));
                                 std::fill(a.begin(), a.end(), 1.0);
                                 std::fill(p.begin(), p.end(), 0.0);
                               }};
  for (int threads : {1, 2, 4})
    EXPECT_THROW(sum_harmonics(
                     failing, 0.0, 0.005, 0, 5000, [](std::size_t, std::span<const double>) {}, ChirpMemory{256, 0, threads}),
                 IoError)
        << threads << " threads";
}

TEST(ParallelTasks, EveryTaskOnceInContiguousSharesAndErrorsRethrown) {
  for (int workers : {1, 2, 3, 8})
    for (std::size_t tasks : {0u, 1u, 2u, 7u, 64u}) {
      std::vector<std::atomic<int>> runs(tasks);
      std::vector<std::size_t> worker_of(tasks);
      parallel_tasks(workers, tasks, [&](std::size_t worker, std::size_t task) {
        ++runs[task];
        worker_of[task] = worker;
      });
      for (std::size_t t = 0; t < tasks; ++t) {
        EXPECT_EQ(runs[t].load(), 1) << workers << " workers, task " << t;
        if (t > 0) {
          EXPECT_GE(worker_of[t], worker_of[t - 1]);  // contiguous shares, in worker order
        }
        if (tasks <= static_cast<std::size_t>(workers)) {
          EXPECT_EQ(worker_of[t], t);
        }
      }
    }
  EXPECT_THROW(parallel_tasks(2, 10,
                              [](std::size_t, std::size_t task) {
                                if (task == 7) throw InvalidArgument("task 7");
                              }),
               InvalidArgument);
  EXPECT_GE(worker_threads(), 1);
}
