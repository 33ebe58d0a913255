// detfft: the deterministic FFT and the chirp-z sum of harmonics. See
// src/internal/texel/detail/detfft.hpp for the method and its trade-off.
#include "texel/detail/detfft.hpp"

#include "texel/detail/detfft_kernels.hpp"
#include "texel/detail/parallel.hpp"
#include "texel/detail/scratch_file.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "texel/error.hpp"

namespace texel::detail {

// ------------------------------------------------------------ exact arithmetic

namespace {

/// Veltkamp's split of a into two 26-bit halves, a = hi + lo exactly.
TwoDouble split(double a) {
  const double c = 134217729.0 * a;  // 2^27 + 1
  const double hi = c - (c - a);
  return {hi, a - hi};
}

/// a + b for |a| >= |b| (or a = 0), exactly.
TwoDouble quick_two_sum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}

/// a · b, both two-doubles, to about 106 bits.
TwoDouble multiply(TwoDouble a, TwoDouble b) {
  const TwoDouble p = two_product(a.hi, b.hi);
  return quick_two_sum(p.hi, p.lo + (a.hi * b.lo + a.lo * b.hi));
}

/// a modulo 1, to ~106 bits: integer multiples of it then stay small.
/// (wrap_cycles(x) = x − round(x) is exact for every finite double; x −
/// floor(x) is not: −1e-17 − (−1) rounds to 1.)
TwoDouble wrap(TwoDouble a) { return two_sum(wrap_cycles(a.hi), a.lo); }

}  // namespace

TwoDouble two_sum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}

TwoDouble two_product(double a, double b) {
  const double p = a * b;
  const TwoDouble x = split(a);
  const TwoDouble y = split(b);
  return {p, ((x.hi * y.hi - p) + x.hi * y.lo + x.lo * y.hi) + x.lo * y.lo};
}

TwoDouble reciprocal(double d) {
  const double h = 1.0 / d;
  const TwoDouble p = two_product(h, d);
  return {h, ((1.0 - p.hi) - p.lo) / d};  // 1 − p.hi is exact (Sterbenz)
}

// ------------------------------------------------------------ FFT

namespace {

// Sub-transforms of up to this many points (32 KiB of re + im) run all their
// stages before moving on: the recursion keeps them in cache. Any value gives
// the same bits (independent butterflies commute); this one gives the speed.
constexpr std::size_t leaf = 2048;
constexpr std::size_t max_size = std::size_t{1} << 26;

}  // namespace

DetFft::DetFft(std::size_t n, int lanes) : n_(n), kernels_(&fft_kernels(lanes)) {
  if (n < 1 || n > max_size || (n & (n - 1)) != 0)
    throw InvalidArgument("FFT size is " + std::to_string(n) + "; it must be a power of two from 1 to 2^26");
  while ((std::size_t{1} << bits_) < n) ++bits_;
  if (n < 2) return;
  // Stage h's twiddles e^(−2πi·j/2h), j < h, at offset h − 1: the largest
  // stage's from detmath, every other stage's copied from it (j/2h is the
  // same fraction as j·(n/2h)/n, so the values are the same either way).
  cos_.resize(n - 1);
  sin_.resize(n - 1);
  const std::size_t top = n / 2 - 1;
  const double inv = 1.0 / static_cast<double>(n);  // exact: n is a power of two
  kernels_->twiddles(0.0, inv, n / 2, cos_.data() + top, sin_.data() + top);
  for (std::size_t h = n / 4; h >= 1; h /= 2)
    for (std::size_t j = 0; j < h; ++j) {
      cos_[h - 1 + j] = cos_[top + j * (n / (2 * h))];
      sin_[h - 1 + j] = sin_[top + j * (n / (2 * h))];
    }
}

std::size_t DetFft::bit_reverse(std::size_t i) const {
  std::size_t r = 0;
  for (int b = 0; b < bits_; ++b) r |= ((i >> b) & 1u) << (bits_ - 1 - b);
  return r;
}

// The stages run two at a time (spans h and h/2 in one sweep over quads of
// points: the same butterflies, half the loads and stores).
void DetFft::dif(double* re, double* im, std::size_t n) const {
  if (n < 2) return;
  if (n > leaf) {
    kernels_->dif_two_stages(re, im, n, n / 2, cos_.data(), sin_.data());
    for (std::size_t i = 0; i < n; i += n / 4) dif(re + i, im + i, n / 4);
    return;
  }
  std::size_t h = n / 2;
  for (; h >= 2; h /= 4) kernels_->dif_two_stages(re, im, n, h, cos_.data(), sin_.data());
  if (h == 1) kernels_->dif_stage(re, im, n, 1, cos_.data(), sin_.data());
}

void DetFft::dit(double* re, double* im, std::size_t n) const {
  if (n < 2) return;
  if (n > leaf) {
    for (std::size_t i = 0; i < n; i += n / 4) dit(re + i, im + i, n / 4);
    kernels_->dit_two_stages(re, im, n, n / 2, cos_.data(), sin_.data());
    return;
  }
  std::size_t h = 1;  // the next span
  for (; 2 * h < n; h *= 4) kernels_->dit_two_stages(re, im, n, 2 * h, cos_.data(), sin_.data());
  if (h < n) kernels_->dit_stage(re, im, n, h, cos_.data() + h - 1, sin_.data() + h - 1);
}

void DetFft::forward_to_bit_reversed(double* re, double* im) const { dif(re, im, n_); }
void DetFft::inverse_from_bit_reversed(double* re, double* im) const { dit(re, im, n_); }

void DetFft::permute(double* re, double* im) const {
  for (std::size_t i = 0; i < n_; ++i) {
    const std::size_t r = bit_reverse(i);
    if (i < r) {
      std::swap(re[i], re[r]);
      std::swap(im[i], im[r]);
    }
  }
}

void DetFft::forward(double* re, double* im) const {
  forward_to_bit_reversed(re, im);
  permute(re, im);
}

void DetFft::inverse(double* re, double* im) const {
  permute(re, im);
  inverse_from_bit_reversed(re, im);
}

// ------------------------------------------------------------ chirp-z

namespace {

/// The FFT size for K harmonics and N samples: outputs go in blocks of
/// B = M − K + 1 samples, each costing two FFTs of size M (plus one for the
/// shared kernel), so M is the power of two (>= 64) that minimises
/// (2·blocks + 1)·M·log2(M); ties go to the smaller M. A function of (K, N)
/// alone, computed in integers: part of what fixes the bits.
std::size_t block_fft_size(std::size_t k, std::size_t n) {
  std::size_t best = 0;
  std::uint64_t best_cost = ~std::uint64_t{0};
  for (int p = 6; p <= 26; ++p) {
    const std::size_t m = std::size_t{1} << p;
    if (m < k) continue;
    const std::size_t b = std::min(m - k + 1, n);
    const std::uint64_t blocks = (n + b - 1) / b;
    const std::uint64_t cost = (2 * blocks + 1) * m * static_cast<std::uint64_t>(p);
    if (cost < best_cost) {
      best = m;
      best_cost = cost;
    }
    if (b == n) break;  // one block already: a larger M only costs more
  }
  return best;
}

}  // namespace

namespace {

/// What every block of one chirp-z sum shares: sizes and the exact phase
/// steps. Phase of harmonic first + j at sample t of a block starting at x0
/// (all in cycles, each reduced modulo 1 from exact products):
///   φ_j + (first + j)·f·(x0 + t·s) = A_j + B_t − C_(t−j), with θ = f·s and
///   A_j = φ_j + (first + j)·f·x0 + θ/2·j²,  B_t = θ/2·t² + first·θ·t,  C_d = θ/2·d².
struct ChirpPlan {
  TwoDouble fundamental;
  std::size_t k = 0;      // harmonics
  std::size_t m = 0;      // FFT size
  std::size_t block = 0;  // output samples per block
  ChirpPhases phases;     // θ/2, first·θ, first, 1/M
  const FftKernels* kernels = nullptr;

  ChirpPlan(std::uint64_t first, TwoDouble f, std::size_t k_, std::size_t n, double spacing, int lanes)
      : fundamental(f), k(k_), m(block_fft_size(k_, n)), block(std::min(m - k_ + 1, n)), kernels(&fft_kernels(lanes)) {
    const TwoDouble theta = multiply(f, TwoDouble{spacing, 0.0});
    phases.half_theta = wrap(TwoDouble{theta.hi * 0.5, theta.lo * 0.5});  // halving is exact
    phases.first_theta = wrap(multiply(theta, TwoDouble{static_cast<double>(first), 0.0}));
    phases.first = static_cast<double>(first);    // exact below 2^52
    phases.inv_m = 1.0 / static_cast<double>(m);  // exact: a power of two
  }

  /// The kernel e^(−2πi·C_d) for d in (−K, B), circularly (d at index d,
  /// −d at m − d), scaled by 1/M so that the inverse transform needs no
  /// scaling; 0 elsewhere. Shared by every block.
  void kernel(std::size_t i0, std::span<double> re, std::span<double> im) const {
    const std::size_t end = i0 + re.size();
    const std::size_t a = std::clamp(block, i0, end);     // [i0, a): d = i
    const std::size_t b = std::clamp(m - k + 1, a, end);  // [a, b): 0; [b, end): d = m − i
    if (a > i0) kernels->chirp_kernel(phases, static_cast<double>(i0), 1.0, a - i0, re.data(), im.data());
    std::fill(re.begin() + static_cast<std::ptrdiff_t>(a - i0), re.begin() + static_cast<std::ptrdiff_t>(b - i0), 0.0);
    std::fill(im.begin() + static_cast<std::ptrdiff_t>(a - i0), im.begin() + static_cast<std::ptrdiff_t>(b - i0), 0.0);
    if (end > b)
      kernels->chirp_kernel(phases, static_cast<double>(m - b), -1.0, end - b, re.data() + (b - i0), im.data() + (b - i0));
  }

  /// f·x0 modulo 1 (to ~106 bits) for the block starting at sample m0,
  /// x0 = origin + (index + m0)·spacing.
  [[nodiscard]] TwoDouble alpha(double origin, double spacing, std::int64_t index, std::size_t m0) const {
    const auto i0 = static_cast<double>(index + static_cast<std::int64_t>(m0));  // exact below 2^53
    const TwoDouble p = two_product(i0, spacing);
    const TwoDouble s = two_sum(origin, p.hi);
    const TwoDouble x0 = two_sum(s.hi, s.lo + p.lo);  // s.hi may have cancelled to below p.lo
    return wrap(multiply(fundamental, x0));
  }

  /// The block's input u_j = a_j·e^(2πi·A_j) for j = j0 … from amplitudes
  /// and phases (written over them: re over amplitude, im over phase).
  void input(TwoDouble alpha, std::size_t j0, std::span<double> amplitude_re, std::span<double> phase_im) const {
    kernels->chirp_input(phases, alpha, static_cast<double>(j0), amplitude_re.size(), amplitude_re.data(), phase_im.data());
  }

  /// y_t = Im(e^(2πi·B_t)·z_t) for t = t0 … into out.
  void output(std::size_t t0, const double* zr, const double* zi, std::span<double> out) const {
    kernels->chirp_output(phases, static_cast<double>(t0), out.size(), zr, zi, out.data());
  }
};

constexpr std::size_t input_run = 4096;  // harmonics asked of the source at once (in memory)

/// The whole sum with every FFT array in memory (48 bytes per FFT point).
void sum_in_memory(const ChirpPlan& plan, const HarmonicSource& h, double origin, double spacing, std::int64_t index,
                   std::size_t n, const SampleSink& sink) {
  const std::size_t m = plan.m;
  const std::size_t k = plan.k;
  const DetFft fft(m, plan.kernels->lanes);
  std::vector<double> vr(m);
  std::vector<double> vi(m);
  plan.kernel(0, vr, vi);
  fft.forward_to_bit_reversed(vr.data(), vi.data());

  std::vector<double> ur(m);
  std::vector<double> ui(m);
  std::vector<double> y(input_run);
  for (std::size_t m0 = 0; m0 < n; m0 += plan.block) {
    const std::size_t len = std::min(plan.block, n - m0);
    const TwoDouble alpha = plan.alpha(origin, spacing, index, m0);
    for (std::size_t j0 = 0; j0 < k; j0 += input_run) {
      const std::span<double> re(ur.data() + j0, std::min(input_run, k - j0));
      const std::span<double> im(ui.data() + j0, re.size());
      h.fill(j0, re, im);
      plan.input(alpha, j0, re, im);
    }
    std::fill(ur.begin() + static_cast<std::ptrdiff_t>(k), ur.end(), 0.0);
    std::fill(ui.begin() + static_cast<std::ptrdiff_t>(k), ui.end(), 0.0);
    fft.forward_to_bit_reversed(ur.data(), ui.data());
    plan.kernels->multiply_spectra(ur.data(), ui.data(), vr.data(), vi.data(), m);
    fft.inverse_from_bit_reversed(ur.data(), ui.data());
    for (std::size_t t0 = 0; t0 < len; t0 += input_run) {
      const std::span<double> run(y.data(), std::min(input_run, len - t0));
      plan.output(t0, ur.data() + t0, ui.data() + t0, run);
      sink(m0 + t0, run);
    }
  }
}

// ------------------------------------------------------------ out of core
//
// An FFT of M = 2^p points kept in a scratch file, run with W = 2^w points
// in memory. Stage q of the FFT (span h = 2^q) pairs indices that differ in
// bit q only, with twiddle e^(−2πi·j/2h), j = index mod h. The stages of bits
// below w act on contiguous blocks of W points, exactly as DetFft(W) does on
// each block (its twiddles are the same fractions j/2h). The stages of bits
// w … p−1 run in passes over groups of R = 2^r rows of C = 2W/R contiguous
// points (rows 2^lo apart): such a group is closed under the butterflies of
// bits lo … lo + r − 1, so a pass loads each group once, runs its stages in
// the in-memory order (decimation in frequency: high bits first; in time:
// low bits first) and writes it back. Every butterfly is the same IEEE
// operations on the same values as in memory, so the bits are the same.
//
// The groups of a pass, and the blocks, are independent of each other: each
// worker thread (parallel.hpp) takes a contiguous share of them into its own
// buffers (two blocks' worth, which a group fills: the longer its rows, the
// fewer and larger the reads and writes). The first pass of a forward
// transform takes its points from the function that defines them (the
// kernel, the chirped harmonics) rather than from the file, so an input is
// never written to be read back; the last pass of an inverse one hands its
// points on rather than writing them back.

struct DiskArray {
  std::uint64_t re = 0;  // element offsets in the scratch file
  std::uint64_t im = 0;
};

/// Runs of an array's points read from the file.
struct FileRuns {
  const ScratchFile& file;
  DiskArray a;
  void operator()(std::size_t i0, std::span<double> re, std::span<double> im) const {
    file.read(a.re + i0, re);
    file.read(a.im + i0, im);
  }
};

/// Runs of an array's points written back to the file.
struct FileWrites {
  ScratchFile& file;
  DiskArray a;
  void operator()(std::size_t i0, std::span<double> re, std::span<double> im) const {
    file.write(a.re + i0, re);
    file.write(a.im + i0, im);
  }
};

class OutOfCore {
 public:
  /// One worker's memory: 6 arrays of W points (48 bytes per point).
  struct Workspace {
    // Not zeroed: every point is written before it is read, and the pages
    // are first touched by the worker that uses them. re2 follows re and
    // im2 follows im, so a pass's group of 2W points is (re, im) doubled.
    explicit Workspace(std::size_t w)
        : memory(new double[6 * w]),
          re(memory.get(), w),
          re2(memory.get() + w, w),
          im(memory.get() + 2 * w, w),
          im2(memory.get() + 3 * w, w),
          twiddle_c(memory.get() + 4 * w, w),
          twiddle_s(memory.get() + 5 * w, w) {}
    std::unique_ptr<double[]> memory;
    std::span<double> re, re2;  // a block at hand; a second one free for blocks()' callers
    std::span<double> im, im2;
    std::span<double> twiddle_c, twiddle_s;  // one stage of a pass
  };

  OutOfCore(ScratchFile& file, std::size_t m, std::size_t w_points, const FftKernels& kernels, int workers)
      : file_(file), m_(m), w_(w_points), kernels_(kernels), fft_(w_points, kernels.lanes) {
    while ((std::size_t{1} << p_) < m_) ++p_;
    while ((std::size_t{1} << wbits_) < w_) ++wbits_;
    // A pass's group is 2W points (2^(w+1)): rows of at least 4 KiB where
    // that allows.
    const int c_min = std::min(9, wbits_);
    r_max_ = wbits_ + 1 - c_min;
    workspaces_.reserve(static_cast<std::size_t>(std::max(1, workers)));
    for (int i = 0; i < std::max(1, workers); ++i) workspaces_.emplace_back(w_points);
  }

  [[nodiscard]] int workers() const { return static_cast<int>(workspaces_.size()); }
  [[nodiscard]] Workspace& workspace(std::size_t worker) { return workspaces_[worker]; }

  /// The stages of bits w … p−1 of decimation in frequency (high bits
  /// first) of the array whose points fill(i0, re, im) defines (runs of
  /// contiguous points, any order, from any worker): the first pass takes
  /// them from `fill`, the others from the file.
  template <class Fill>
  void dif_top(DiskArray a, const Fill& fill) {
    for (int hi = p_; hi > wbits_;) {
      const int lo = std::max(wbits_, hi - r_max_);
      if (hi == p_)
        pass(lo, hi, false, fill, FileWrites{file_, a});
      else
        pass(lo, hi, false, FileRuns{file_, a}, FileWrites{file_, a});
      hi = lo;
    }
  }

  /// The stages of bits w … p−1 of decimation in time (low bits first); the
  /// last pass hands each run of finished points to take(i0, re, im) (any
  /// order, from any worker) instead of writing it back.
  template <class Take>
  void dit_top(DiskArray a, const Take& take) {
    for (int lo = wbits_; lo < p_;) {
      const int hi = std::min(p_, lo + r_max_);
      if (hi == p_)
        pass(lo, hi, true, FileRuns{file_, a}, take);
      else
        pass(lo, hi, true, FileRuns{file_, a}, FileWrites{file_, a});
      lo = hi;
    }
  }

  /// For each block of W contiguous points, on some worker: the block read
  /// into its workspace's re/im, fn(workspace, i0), written back.
  template <class Fn>
  void blocks(DiskArray a, const Fn& fn) {
    parallel_tasks(workers(), m_ / w_, [&](std::size_t worker, std::size_t task) {
      Workspace& ws = workspaces_[worker];
      const std::uint64_t i0 = task * w_;
      file_.read(a.re + i0, ws.re);
      file_.read(a.im + i0, ws.im);
      fn(ws, static_cast<std::size_t>(i0));
      file_.write(a.re + i0, ws.re);
      file_.write(a.im + i0, ws.im);
    });
  }

  [[nodiscard]] const DetFft& block_fft() const { return fft_; }

 private:
  /// The stages of bits lo … hi−1 over every group: its rows come from
  /// load(i0, re, im) and go to save(i0, re, im).
  template <class Load, class Save>
  void pass(int lo, int hi, bool inverse, const Load& load, const Save& save) {
    const std::size_t rows = std::size_t{1} << (hi - lo);
    const std::size_t cols = 2 * w_ / rows;  // a group is 2W points
    const std::size_t stride = std::size_t{1} << lo;
    const std::size_t mids = stride / cols;
    const std::size_t highs = m_ >> hi;
    parallel_tasks(workers(), mids * highs, [&](std::size_t worker, std::size_t task) {
      Workspace& ws = workspaces_[worker];
      double* re = ws.re.data();
      double* im = ws.im.data();
      const std::size_t mid = task / highs;
      const std::size_t base = ((task % highs) << hi) + mid * cols;
      for (std::size_t t = 0; t < rows; ++t)
        load(base + t * stride, std::span<double>(re + t * cols, cols), std::span<double>(im + t * cols, cols));
      for (int step = 0; step < hi - lo; ++step) {
        const int q = inverse ? lo + step : hi - 1 - step;
        // Stage q (span h = 2^q) pairs rows t and t + s, s = 2^(q−lo); row
        // t' < s and column u have j = t'·2^lo + mid·C + u (the index's bits
        // below q) and twiddle e^(−2πi·j/2h): s·C <= W of them.
        const std::size_t s = std::size_t{1} << (q - lo);
        double* c = ws.twiddle_c.data();
        double* sn = ws.twiddle_s.data();
        const double inv_2h = std::ldexp(1.0, -(q + 1));  // j/2h is exact
        for (std::size_t t = 0; t < s; ++t)
          kernels_.twiddles(static_cast<double>(t * stride + mid * cols), inv_2h, cols, c + t * cols, sn + t * cols);
        for (std::size_t t = 0; t < rows; ++t) {
          if ((t & s) != 0) continue;
          const std::size_t tw = (t & (s - 1)) * cols;
          double* ar = re + t * cols;
          double* ai = im + t * cols;
          double* br = re + (t + s) * cols;
          double* bi = im + (t + s) * cols;
          if (inverse)
            kernels_.dit_butterflies(ar, ai, br, bi, c + tw, sn + tw, cols);
          else
            kernels_.dif_butterflies(ar, ai, br, bi, c + tw, sn + tw, cols);
        }
      }
      for (std::size_t t = 0; t < rows; ++t)
        save(base + t * stride, std::span<double>(re + t * cols, cols), std::span<double>(im + t * cols, cols));
    });
  }

  ScratchFile& file_;
  std::size_t m_;
  std::size_t w_;
  int p_ = 0;
  int wbits_ = 0;
  int r_max_ = 1;
  const FftKernels& kernels_;
  DetFft fft_;
  std::vector<Workspace> workspaces_;
};

/// The whole sum with the FFT arrays in a scratch file and W points in
/// memory per worker.
void sum_out_of_core(const ChirpPlan& plan, const HarmonicSource& h, double origin, double spacing, std::int64_t index,
                     std::size_t n, const SampleSink& sink, std::size_t w, int workers) {
  const std::size_t m = plan.m;
  const std::size_t k = plan.k;
  ScratchFile file("chirp-z synthesis");
  const DiskArray u{0, m};
  const DiskArray v{2 * static_cast<std::uint64_t>(m), 3 * static_cast<std::uint64_t>(m)};
  // With several blocks the source's amplitudes and phases are drawn once,
  // for the first, and read back for the others (a noise draws each with a
  // logarithm or more; reading it back costs a copy).
  const bool several_blocks = plan.block < n;
  const DiskArray drawn{4 * static_cast<std::uint64_t>(m), 4 * static_cast<std::uint64_t>(m) + k};
  file.reserve(4 * static_cast<std::uint64_t>(m) + (several_blocks ? 2 * k : 0));
  OutOfCore ooc(file, m, w, *plan.kernels, workers);
  const DetFft& fft = ooc.block_fft();

  ooc.dif_top(v, [&](std::size_t i0, std::span<double> re, std::span<double> im) { plan.kernel(i0, re, im); });
  ooc.blocks(v, [&](OutOfCore::Workspace& ws, std::size_t) { fft.forward_to_bit_reversed(ws.re.data(), ws.im.data()); });

  for (std::size_t m0 = 0; m0 < n; m0 += plan.block) {
    const std::size_t len = std::min(plan.block, n - m0);
    const TwoDouble alpha = plan.alpha(origin, spacing, index, m0);
    ooc.dif_top(u, [&](std::size_t i0, std::span<double> re, std::span<double> im) {
      const std::size_t live = i0 < k ? std::min(re.size(), k - i0) : 0;
      if (live > 0) {
        const std::span<double> amplitude = re.first(live);
        const std::span<double> phase = im.first(live);
        if (m0 == 0) {
          h.fill(i0, amplitude, phase);
          if (several_blocks) FileWrites{file, drawn}(i0, amplitude, phase);
        } else {
          FileRuns{file, drawn}(i0, amplitude, phase);
        }
        plan.input(alpha, i0, amplitude, phase);
      }
      std::fill(re.begin() + static_cast<std::ptrdiff_t>(live), re.end(), 0.0);
      std::fill(im.begin() + static_cast<std::ptrdiff_t>(live), im.end(), 0.0);
    });
    // The stages below w of the forward transform, the product and the
    // stages below w of the inverse all act within a block: one pass.
    ooc.blocks(u, [&](OutOfCore::Workspace& ws, std::size_t i0) {
      fft.forward_to_bit_reversed(ws.re.data(), ws.im.data());
      file.read(v.re + i0, ws.re2);
      file.read(v.im + i0, ws.im2);
      plan.kernels->multiply_spectra(ws.re.data(), ws.im.data(), ws.re2.data(), ws.im2.data(), w);
      fft.inverse_from_bit_reversed(ws.re.data(), ws.im.data());
    });
    // The last pass turns z_t into y_t where t < len and writes y alone
    // over u.re; the points beyond are never read again.
    ooc.dit_top(u, [&](std::size_t i0, std::span<double> zr, std::span<double> zi) {
      if (i0 >= len) return;
      const std::span<double> y = zr.first(std::min(zr.size(), len - i0));
      plan.output(i0, zr.data(), zi.data(), y);  // y_t overwrites z_t element by element
      file.write(u.re + i0, y);
    });
    const std::span<double> y(ooc.workspace(0).re2);
    for (std::size_t t0 = 0; t0 < len; t0 += w) {
      const std::span<double> run = y.first(std::min(w, len - t0));
      file.read(u.re + t0, run);
      sink(m0 + t0, run);
    }
  }
}

}  // namespace

void sum_harmonics(const HarmonicSource& h, double origin, double spacing, std::int64_t index, std::size_t samples,
                   const SampleSink& sink, const ChirpMemory& memory) {
  const std::size_t k = h.count;
  if (k == 0 || k > max_chirp_harmonics || !h.fill)
    throw InvalidArgument("sum_harmonics: " + std::to_string(k) + " harmonics; 1 to " + std::to_string(max_chirp_harmonics) +
                          " are allowed");
  const std::size_t budget = memory.fft_points;
  if (budget < 4 || (budget & (budget - 1)) != 0)
    throw InvalidArgument("sum_harmonics: a memory of " + std::to_string(budget) + " FFT points; it must be a power of two >= 4");
  if (samples == 0) return;
  const ChirpPlan plan(h.first, h.fundamental, k, samples, spacing, memory.lanes);
  if (plan.m <= budget)
    sum_in_memory(plan, h, origin, spacing, index, samples, sink);
  else
    sum_out_of_core(plan, h, origin, spacing, index, samples, sink, budget / 2,
                    memory.threads > 0 ? memory.threads : worker_threads());
}

HarmonicSource harmonic_source(const Harmonics& h) {
  return {h.first, h.fundamental, h.amplitude.size(), [h](std::size_t j0, std::span<double> a, std::span<double> p) {
            std::copy_n(h.amplitude.begin() + static_cast<std::ptrdiff_t>(j0), a.size(), a.begin());
            std::copy_n(h.phase_cycles.begin() + static_cast<std::ptrdiff_t>(j0), p.size(), p.begin());
          }};
}

void sum_harmonics(const Harmonics& h, double origin, double spacing, std::int64_t index, std::span<double> out) {
  const std::size_t k = h.amplitude.size();
  if (k == 0 || k != h.phase_cycles.size() || k > max_chirp_harmonics)
    throw InvalidArgument("sum_harmonics: " + std::to_string(k) + " harmonics (" + std::to_string(h.phase_cycles.size()) +
                          " phases); 1 to " + std::to_string(max_chirp_harmonics) + " are allowed");
  // The whole output is in memory already: so may the FFT be.
  sum_harmonics(
      harmonic_source(h), origin, spacing, index, out.size(),
      [&](std::size_t m0, std::span<const double> y) {
        std::copy(y.begin(), y.end(), out.begin() + static_cast<std::ptrdiff_t>(m0));
      },
      ChirpMemory{std::size_t{1} << 26});
}

}  // namespace texel::detail
