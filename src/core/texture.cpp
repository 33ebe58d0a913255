#include "texel/texture.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>

#include "texel/detail/format.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"

namespace texel {
namespace {

using detail::num;

void check_fraction(double v, std::string_view field) {
  if (!(v >= 0.0 && v <= 1.0)) throw InvalidArgument(std::string(field) + " is " + num(v) + "; allowed: 0 … 1");
}

// The fused fine-texture kernel for one texel's run of samples:
//   x = origin + i·Δx, u = φ_k + f_k·(x − start_k), a = offset_k + gain_k·sin(2πu).
// `base` is the global index of out[0] as a double; base + m is exact for any
// index below 2^53, so x is bit-identical to Grid::position(i) — which is what
// makes every window, SIMD width and -O level produce the same bytes.
//
// Written with explicit lanes (GCC/clang vector extensions) rather than left
// to the auto-vectorizer: GCC will not if-convert the sine's reflection selects
// under -ftrapping-math, so the plain loop ran scalar at ~11 ns/sample. Every
// lane does exactly the scalar operations, in the same order, in IEEE double
// (-ffp-contract=off keeps mul+add from fusing even where FMA exists), so the
// lane width changes speed, never bits. The width is picked per instruction
// set at run time: 8 lanes on AVX-512, 4 on AVX2, 2 (SSE2) otherwise — a width
// wider than the registers spills and runs slower than scalar.
// tests/core/test_render_exact.cpp checks this against amplitude_at (scalar
// detmath::sin_cycles) bit for bit.
struct Run {
  double base, origin, spacing, start, frequency, phase, offset, gain;
};

template <int W>
[[gnu::always_inline]] inline void render_lanes(const Run& run, double* out, std::int32_t count) {
  using V = typename detail::Lanes<W>::type;
  V index;
  for (int l = 0; l < W; ++l) index[l] = run.base + static_cast<double>(l);
  const V first_index = index;
  // One block of W samples into `a`; the index steps by W (integers below
  // 2^53 are exact, so lane l holds base + m + l exactly).
  auto block = [&](V& a) {
    const V x = run.origin + index * run.spacing;
    a = run.phase + run.frequency * (x - run.start);
    a = detmath::sin_cycles_generic(a);
    a = run.offset + run.gain * a;
    index += static_cast<double>(W);
  };
  std::int32_t m = 0;
  V a;
  for (; m + W <= count; m += W) {
    block(a);
    std::memcpy(out + m, &a, sizeof a);
  }
  if (m == count) return;
  if (count >= W) {
    // The last W samples again, overlapping the previous block: a sample's
    // value is a function of its index alone, so the overlap is rewritten
    // with the same bits, and the store is one whole vector. (Whole numbers
    // below 2^53: base + l + (count − W) is exact in any order.)
    index = first_index + static_cast<double>(count - W);
    block(a);
    std::memcpy(out + count - W, &a, sizeof a);
  } else {  // a run shorter than a vector computes every lane, stores the live ones
    block(a);
    std::memcpy(out + m, &a, static_cast<std::size_t>(count - m) * sizeof(double));
  }
}

using RunKernel = void (*)(const Run&, double*, std::int32_t);

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void render_run_avx512(const Run& r, double* out, std::int32_t n) {
  render_lanes<8>(r, out, n);
}
__attribute__((target("avx2"))) void render_run_avx2(const Run& r, double* out, std::int32_t n) { render_lanes<4>(r, out, n); }
#endif
void render_run_generic(const Run& r, double* out, std::int32_t n) { render_lanes<2>(r, out, n); }

/// The widest kernel this CPU runs (detail::simd_lanes), chosen once.
RunKernel run_kernel() {
  static const RunKernel kernel = [] {
#if defined(__x86_64__) || defined(__i386__)
    if (detail::simd_lanes() == 8) return &render_run_avx512;
    if (detail::simd_lanes() == 4) return &render_run_avx2;
#endif
    return &render_run_generic;
  }();
  return kernel;
}

}  // namespace

std::string_view to_string(PhaseMode m) { return m == PhaseMode::continuous ? "continuous" : "reset"; }
std::string_view to_string(Fill f) { return f == Fill::whole_texels ? "whole" : "partial"; }

PhaseMode parse_phase_mode(std::string_view text, std::string_view field) {
  if (text == "continuous") return PhaseMode::continuous;
  if (text == "reset") return PhaseMode::reset;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: continuous, reset");
}

Fill parse_fill(std::string_view text, std::string_view field) {
  if (text == "whole") return Fill::whole_texels;
  if (text == "partial") return Fill::partial_final_texel;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: whole, partial");
}

void validate(const TexelSpec& spec) {
  const double L = spec.texel_length.value();
  if (!(std::isfinite(L) && L > 0.0))
    throw InvalidArgument("texel_length_mm is " + num(L) + " mm; it must be a finite number > 0");
  if (L > texel_length_mm_max)
    throw InvalidArgument("texel_length_mm is " + num(L) + " mm; allowed: up to " + num(texel_length_mm_max) + " mm");
  check_fraction(spec.coarse_strength, "coarse_strength");
  check_fraction(spec.fine_strength, "fine_strength");
  if (!std::isfinite(spec.band_max.value()) || spec.band_max.value() < 0.0)
    throw InvalidArgument("band_max_cpm is " + num(spec.band_max.value()) +
                          " cpm; allowed: 0 (the grid's Nyquist) or > band_min_cpm");
  validate(spec.coarse);
}

std::size_t texel_count(Millimetres length, Millimetres texel_length, Fill fill) {
  const double ratio = length.value() / texel_length.value();
  if (!(ratio >= 0.0)) return 0;
  if (ratio > 1e12) throw InvalidArgument("texture length / texel length is " + num(ratio) + "; at most 1e12 texels");
  // The boundary tolerance keeps 0.3 / 0.1 = 2.9999999999999996 at 3 texels.
  const double tol = TexelTexture::boundary_tolerance_mm / texel_length.value();
  const double n = fill == Fill::whole_texels ? std::floor(ratio + tol) : std::ceil(ratio - tol);
  return static_cast<std::size_t>(std::max(n, 0.0));
}

PitchDistributionConfig distribution_config(const TexelSpec& spec, CyclesPerMm band_top) {
  PitchDistributionConfig c;
  c.central_pitch = spec.central_pitch;
  c.irregularity = spec.irregularity;
  c.parameterization = spec.parameterization;
  c.out_of_band = spec.out_of_band;
  c.band_min = spec.band_min;
  c.band_max = spec.band_max.value() > 0.0 ? spec.band_max : band_top;
  c.quantization_db = spec.quantization_db;
  return c;
}

TexelTexture::TexelTexture(const TexelSpec& spec, Millimetres length, const Sampling& sampling, std::size_t keep)
    : spec_(spec), length_(length), distribution_([&] {
        validate(spec);
        if (!(std::isfinite(length.value()) && length.value() > 0.0))
          throw InvalidArgument("texture length is " + num(length.value()) + " mm; it must be a finite number > 0");
        return PitchDistribution(distribution_config(spec, sampling.top()));
      }()) {
  const double L = spec.texel_length.value();
  static std::atomic<std::uint64_t> next_id{1};
  id_ = next_id.fetch_add(1, std::memory_order_relaxed);
  count_ = texel::texel_count(length, spec.texel_length, spec.fill);
  end_mm_ = spec.fill == Fill::whole_texels ? static_cast<double>(count_) * L : length.value();
  check_texel_values(spec.coarse, count_);
  const double phase0 = CounterRng(spec.seed, Stream::phase).uniform(0);
  if (count_ <= keep) {
    (void)draw(0, count_, phase0, kept_);
    std::vector<double>().swap(kept_.coarse);  // work space, not kept
    return;
  }
  // Checkpoints only: the phase entering every checkpoint_stride-th texel,
  // from the same recurrence the whole texture runs (so a block drawn from
  // its checkpoint has the whole's bits).
  checkpoint_phase_.reserve((count_ + checkpoint_stride - 1) / checkpoint_stride);
  all_ = std::make_shared<detail::TexelListOnce>();
  blocks_ = std::make_shared<BlockCache>();
  double phase = phase0;
  for (std::size_t k0 = 0; k0 < count_; k0 += checkpoint_stride) {
    checkpoint_phase_.push_back(phase);
    phase = advance(k0, std::min(checkpoint_stride, count_ - k0), phase);
  }
}

namespace {
/// The phase recurrence: texel k starts at `phase` (in [0, 1) cycles), the
/// next starts where it ends, kept in [0, 1) so precision does not decay
/// along the surface. draw and advance share it: the same bits.
[[gnu::always_inline]] inline double phase_after(double phase, double frequency, double L) {
  const double next = phase + frequency * L;
  return next - detmath::floor_exact(next);
}
}  // namespace

double TexelTexture::advance(std::size_t first, std::size_t count, double phase) const {
  const double L = spec_.texel_length.value();
  const CounterRng phase_rng(spec_.seed, Stream::phase);
  constexpr std::size_t batch = 256;
  double frequency[batch];
  for (std::size_t i0 = 0; i0 < count; i0 += batch) {
    const std::size_t n = std::min(batch, count - i0);
    distribution_.draw(spec_.seed, first + i0, std::span<double>(frequency, n));
    for (std::size_t i = 0; i < n; ++i) {
      if (spec_.phase == PhaseMode::reset) phase = phase_rng.uniform(first + i0 + i + 1);
      phase = phase_after(phase, frequency[i], L);
    }
  }
  return phase;
}

double TexelTexture::draw(std::size_t first, std::size_t count, double phase, TexelRun& run) const {
  const TexelSpec& spec = spec_;
  const double L = spec.texel_length.value();
  // A constant coarse profile (every fine-only texture) is one value, not a
  // per-texel array: the same clamped value sample_at_texel_centres gives.
  const bool constant = std::holds_alternative<ConstantProfile>(spec.coarse);
  std::vector<double>& coarse = run.coarse;
  coarse.resize(constant ? 1 : count);
  sample_at_texel_centres(spec.coarse, spec.texel_length, first, coarse);
  // Filled in one pass (no zeroing pass over memory that is written at once:
  // at 10^5 texels the first touch of these arrays is most of the time).
  run.first = first;
  run.texels.clear();
  run.offset.clear();
  run.gain.clear();
  run.texels.reserve(count);
  run.offset.reserve(count);
  run.gain.reserve(count);
  const CounterRng phase_rng(spec.seed, Stream::phase);
  const double C = spec.coarse_strength;
  const double F = spec.fine_strength;
  // Frequencies a batch at a time (lane-wise, the same bits as one by one).
  constexpr std::size_t batch = 256;
  double frequency[batch];
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t k = first + i;
    if (i % batch == 0) distribution_.draw(spec.seed, k, std::span<double>(frequency, std::min(batch, count - i)));
    Texel& t = run.texels.emplace_back();
    t.start = Millimetres(static_cast<double>(k) * L);
    t.frequency = CyclesPerMm(frequency[i % batch]);
    if (spec.phase == PhaseMode::reset) phase = phase_rng.uniform(k + 1);
    t.phase_cycles = phase;
    const TexelMix mix = texel_mix(coarse[constant ? 0 : i], C, F);
    t.envelope = mix.envelope;
    run.offset.push_back(mix.offset);
    run.gain.push_back(mix.gain);
    phase = phase_after(phase, t.frequency.value(), L);
  }
  return phase;
}

void TexelTexture::draw_block(std::size_t block, TexelRun& run) const {
  const std::size_t first = block * checkpoint_stride;
  (void)draw(first, std::min(checkpoint_stride, count_ - first), checkpoint_phase_[block], run);
}

/// The blocks of a checkpointed texture drawn most recently, shared by every
/// thread that renders it, so that a block two threads' windows share (the
/// end of one chunk of write_map and the start of the next) is drawn once.
/// A block is shared read-only once drawn; one whose only holder is the cache
/// is recycled for the next block drawn (no allocation once warm). Drawing
/// happens outside the lock; two threads that miss the same block at the
/// same moment both draw it (the same bits) and the first kept wins.
struct TexelTexture::BlockCache {
  static constexpr std::size_t capacity = 16;  // ~70 KB each

  std::mutex mutex;
  std::vector<std::shared_ptr<TexelRun>> recent;  // most recently used first

  std::shared_ptr<const TexelRun> get(const TexelTexture& texture, std::size_t block) {
    const std::size_t first = block * checkpoint_stride;
    std::shared_ptr<TexelRun> run;
    {
      const std::lock_guard lock(mutex);
      if (auto hit = find(first); hit != recent.end()) {
        std::rotate(recent.begin(), hit, hit + 1);
        return recent.front();
      }
      // Recycle the least recently used block if nobody else holds it (a
      // holder gets its reference under this lock, so none can appear).
      if (recent.size() >= capacity && recent.back().use_count() == 1) {
        // The last holder's release (its reference count's decrement) comes
        // before our writes to the block.
        std::atomic_thread_fence(std::memory_order_acquire);
        run = std::move(recent.back());
        recent.pop_back();
      }
    }
    if (!run) run = std::make_shared<TexelRun>();
    run->owner = 0;  // not valid until drawn (draw may throw on allocation)
    texture.draw_block(block, *run);
    run->owner = texture.id_;
    const std::lock_guard lock(mutex);
    if (auto hit = find(first); hit != recent.end()) {  // drawn meanwhile by another thread
      std::rotate(recent.begin(), hit, hit + 1);
      return recent.front();
    }
    recent.insert(recent.begin(), std::move(run));
    if (recent.size() > capacity) recent.pop_back();
    return recent.front();
  }

 private:
  std::vector<std::shared_ptr<TexelRun>>::iterator find(std::size_t first) {
    return std::find_if(recent.begin(), recent.end(), [&](const auto& r) { return r->first == first; });
  }
};

const TexelTexture::TexelRun& TexelTexture::run_of(std::size_t k) const {
  if (checkpoint_phase_.empty()) return kept_;
  // This thread's current block, kept from one window to the next (no lock
  // while the texels of one block render). Another texture's block (ids are
  // never reused) or another block goes back to the texture's cache.
  thread_local std::shared_ptr<const TexelRun> block;
  if (!block || block->owner != id_ || k < block->first || k >= block->first + block->texels.size())
    block = blocks_->get(*this, k / checkpoint_stride);
  return *block;
}

namespace detail {
/// Every texel of a checkpointed texture, drawn on the first texels() call.
struct TexelListOnce {
  std::once_flag once;
  std::vector<Texel> texels;
};
}  // namespace detail

const std::vector<Texel>& TexelTexture::texels() const {
  if (checkpoint_phase_.empty()) return kept_.texels;
  std::call_once(all_->once, [&] {
    all_->texels.reserve(count_);
    for_each_texels(
        [&](std::size_t, std::span<const Texel> run) { all_->texels.insert(all_->texels.end(), run.begin(), run.end()); });
  });
  return all_->texels;
}

void TexelTexture::for_each_texels(const std::function<void(std::size_t, std::span<const Texel>)>& fn) const {
  if (checkpoint_phase_.empty()) {
    if (count_ > 0) fn(0, kept_.texels);
    return;
  }
  TexelRun run;
  for (std::size_t b = 0; b < checkpoint_phase_.size(); ++b) {
    draw_block(b, run);
    fn(run.first, run.texels);
  }
}

std::int64_t TexelTexture::texel_at(Millimetres at) const {
  const double x = at.value();
  const double shifted = x + boundary_tolerance_mm;
  if (!(shifted >= 0.0) || !(x < end_mm_ - boundary_tolerance_mm) || count_ == 0) return -1;
  const double k = std::floor(shifted / spec_.texel_length.value());
  const auto n = static_cast<double>(count_);
  if (k >= n) return -1;
  return static_cast<std::int64_t>(k);
}

double TexelTexture::amplitude_at(Millimetres at) const {
  const double x = at.value();
  const std::int64_t k = texel_at(at);
  if (k < 0) return 0.0;
  const TexelRun& run = run_of(static_cast<std::size_t>(k));
  const std::size_t i = static_cast<std::size_t>(k) - run.first;
  const Texel& t = run.texels[i];
  const double u = t.phase_cycles + t.frequency.value() * (x - t.start.value());
  return run.offset[i] + run.gain[i] * detmath::sin_cycles(u);
}

void TexelTexture::render(const Grid& grid, std::int64_t first, std::span<double> out) const {
  const auto n = static_cast<std::int64_t>(out.size());
  const double L = spec_.texel_length.value();
  const auto texel_total = static_cast<double>(count_);
  const RunKernel kernel = run_kernel();
  // texel_at(grid.position(first + j)), inlined: the same tests in the same
  // order, with floor_exact (exact here: the quotient is at most ~1e12 texels)
  // in place of std::floor, which is a library call without SSE4.1.
  auto texel_of = [&](std::int64_t j) -> std::int64_t {
    const double x = grid.position(first + j).value();
    const double shifted = x + boundary_tolerance_mm;
    if (!(shifted >= 0.0) || !(x < end_mm_ - boundary_tolerance_mm) || count_ == 0) return -1;
    const double k = detmath::floor_exact(shifted / L);
    return k >= texel_total ? -1 : static_cast<std::int64_t>(k);
  };
  std::int64_t j = 0;
  std::int64_t k = n > 0 ? texel_of(0) : -1;
  while (j < n) {
    if (k < 0) {
      out[static_cast<std::size_t>(j)] = 0.0;
      if (++j < n) k = texel_of(j);
      continue;
    }
    // The run of samples in texel k ends at the first sample whose texel
    // differs (positions grow with the index, so texels never decrease).
    // Estimate it from the boundary, then settle it with texel_of so the rule
    // is the one amplitude_at uses; the texel found past the run starts the next.
    const double boundary = std::min(static_cast<double>(k + 1) * L, end_mm_) - boundary_tolerance_mm;
    const double estimate = std::ceil((boundary - grid.origin.value()) / grid.spacing.value()) - static_cast<double>(first);
    std::int64_t end = estimate >= static_cast<double>(n) ? n : std::max(j + 1, static_cast<std::int64_t>(estimate));
    while (end > j + 1 && texel_of(end - 1) != k) --end;
    std::int64_t next = -1;
    while (end < n && (next = texel_of(end)) == k) ++end;
    // Long runs go in pieces so the kernel's index stays a 32-bit int.
    const TexelRun& texels = run_of(static_cast<std::size_t>(k));
    const std::size_t ik = static_cast<std::size_t>(k) - texels.first;
    const Texel& t = texels.texels[ik];
    for (std::int64_t a = j; a < end;) {
      const std::int64_t len = std::min<std::int64_t>(end - a, 1 << 30);
      const Run run{static_cast<double>(first + a),
                    grid.origin.value(),
                    grid.spacing.value(),
                    t.start.value(),
                    t.frequency.value(),
                    t.phase_cycles,
                    texels.offset[ik],
                    texels.gain[ik]};
      kernel(run, out.data() + a, static_cast<std::int32_t>(len));
      a += len;
    }
    j = end;
    k = next;
  }
}

std::string TexelTexture::describe() const {
  return "texel P=" + num(spec_.central_pitch.value()) + " dB I=" + num(spec_.irregularity.value()) +
         " dB L=" + num(spec_.texel_length.value()) + " mm seed=" + std::to_string(spec_.seed) + " (" +
         std::string(to_string(spec_.parameterization)) + ")";
}

double Texture::sample(Millimetres x) const {
  // A one-sample window of a grid whose sample 0 sits at x: the renderer's
  // own value there (position(0) = x + 0·spacing = x exactly).
  double value = 0.0;
  render(Grid{x, Millimetres(1.0), 1}, 0, std::span<double>(&value, 1));
  return value;
}

std::shared_ptr<const Texture> prepare(const TexelSpec& spec, Millimetres length, const Sampling& sampling) {
  return std::make_shared<const TexelTexture>(spec, length, sampling);
}

}  // namespace texel
