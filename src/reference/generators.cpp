// Reference generators: turning a ReferenceSpec into components (signal-
// defined references) or features (patches, pulses), and evaluating them on
// a grid. See include/texel/reference.hpp for the method and its trade-off.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "texel/detail/detfft.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/detail/parallel.hpp"
#include "texel/detail/scratch_file.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"
#include "texel/reference.hpp"

namespace texel {

/// A noise band's components, drawn on demand: component k (a harmonic k/P
/// of the texture length P) has the target gain at k/P times a Rayleigh
/// magnitude, and a uniform phase, from CounterRng counters 2k and 2k + 1.
/// A pure function of k, so a band of millions of harmonics need not be
/// kept: the synthesis and every later use draw the same values again.
struct detail::NoiseBand {
  bool band_pass = false;
  double centre = 0.0;    // band-pass: f_c (cpm)
  double q = 0.0;         // band-pass: 1/(2ζ)
  double exponent = 0.0;  // colours: amplitude ∝ f^exponent (0: white)
  double period = 1.0;    // the texture's length P (mm)
  CounterRng rng;
  std::uint64_t first = 1;  // harmonics first … last
  std::uint64_t last = 0;

  [[nodiscard]] ReferenceComponent component(std::uint64_t k) const {
    const double f = static_cast<double>(k) / period;
    double gain = 1.0;
    if (band_pass) {
      const double d = f / centre - centre / f;
      gain = 1.0 / std::sqrt(1.0 + q * q * d * d);
    } else if (exponent != 0.0) {
      gain = detmath::exp(exponent * detmath::log(f));
    }
    const double u = rng.uniform(2 * k);
    const double magnitude = std::sqrt(-2.0 * detmath::log(u));  // Rayleigh, σ = 1
    return {CyclesPerMm(f), gain * magnitude, rng.uniform(2 * k + 1)};
  }
  [[nodiscard]] std::size_t count() const { return static_cast<std::size_t>(last - first + 1); }
};

namespace {

using detail::num;

/// The components of a reference a run at a time, ascending: the stored ones
/// (sums of sinusoids, waveforms) at once, a noise's drawn in runs.
struct ComponentRuns {
  const std::vector<ReferenceComponent>& stored;
  const detail::NoiseBand* noise;

  template <class Fn>
  void operator()(Fn&& fn) const {
    if (noise == nullptr) {
      fn(std::span<const ReferenceComponent>(stored));
      return;
    }
    constexpr std::size_t run = 4096;
    std::vector<ReferenceComponent> buffer;
    buffer.reserve(std::min(run, noise->count()));
    for (std::uint64_t k0 = noise->first; k0 <= noise->last; k0 += run) {
      const std::uint64_t k1 = std::min<std::uint64_t>(noise->last, k0 + run - 1);
      buffer.clear();
      for (std::uint64_t k = k0; k <= k1; ++k) buffer.push_back(noise->component(k));
      fn(std::span<const ReferenceComponent>(buffer));
    }
  }
};

// ------------------------------------------------------------ synthesis kernel
//
// acc[m] += a · sin(2π(φ + f·x_m)), x_m = origin + (base + m)·spacing, for one
// component over a run of samples. Explicit lanes (GCC/clang vector
// extensions), the same pattern and the same reasoning as the Texel renderer
// (src/core/texture.cpp): every lane performs exactly the scalar operations
// of detmath::sin_cycles in the same order in IEEE double, and x is computed
// as Grid::position computes it, so lane width and -O level change speed,
// never bits. Components are accumulated in a fixed order (ascending k).
constexpr int max_lanes = 8;

template <int W>
[[gnu::always_inline]] inline void accumulate_lanes(double base, double origin, double spacing, double f, double amplitude,
                                                    double phase, double* acc, std::int32_t count) {
  using V = typename detail::Lanes<W>::type;
  V index;
  for (int l = 0; l < W; ++l) index[l] = base + static_cast<double>(l);
  for (std::int32_t m = 0; m < count; m += W) {
    const V x = origin + index * spacing;
    const V u = phase + f * x;
    index += static_cast<double>(W);
    V a;
    std::memcpy(&a, acc + m, sizeof a);  // acc is padded to a multiple of max_lanes
    a = a + amplitude * detmath::sin_cycles_generic(u);
    std::memcpy(acc + m, &a, sizeof a);
  }
}

using AccumulateKernel = void (*)(double, double, double, double, double, double, double*, std::int32_t);

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void accumulate_avx512(double b, double o, double s, double f, double a, double p, double* acc,
                                                          std::int32_t n) {
  accumulate_lanes<8>(b, o, s, f, a, p, acc, n);
}
__attribute__((target("avx2"))) void accumulate_avx2(double b, double o, double s, double f, double a, double p, double* acc,
                                                     std::int32_t n) {
  accumulate_lanes<4>(b, o, s, f, a, p, acc, n);
}
#endif
void accumulate_generic(double b, double o, double s, double f, double a, double p, double* acc, std::int32_t n) {
  accumulate_lanes<2>(b, o, s, f, a, p, acc, n);
}

AccumulateKernel accumulate_kernel() {
  static const AccumulateKernel kernel = [] {
#if defined(__x86_64__) || defined(__i386__)
    if (detail::simd_lanes() == 8) return &accumulate_avx512;
    if (detail::simd_lanes() == 4) return &accumulate_avx2;
#endif
    return &accumulate_generic;
  }();
  return kernel;
}

/// out[m] += Σ_k a_k·sin(2π(φ_k + f_k·x_m)) at grid samples [first, first +
/// out.size()), components in the order given. Accumulating run after run
/// into the same `out` gives the bits of one pass over all of them.
void accumulate(std::span<const ReferenceComponent> comps, const Grid& grid, std::int64_t first, std::span<double> out) {
  constexpr std::size_t chunk = 2048;  // accumulator stays in L1 across components
  std::vector<double> acc(chunk + max_lanes, 0.0);
  const AccumulateKernel accumulate_component = accumulate_kernel();
  for (std::size_t i = 0; i < out.size(); i += chunk) {
    const std::size_t len = std::min(chunk, out.size() - i);
    std::copy_n(out.begin() + static_cast<std::ptrdiff_t>(i), len, acc.begin());
    const double base = static_cast<double>(first + static_cast<std::int64_t>(i));
    for (const auto& c : comps)
      accumulate_component(base, grid.origin.value(), grid.spacing.value(), c.frequency.value(), c.amplitude, c.phase_cycles,
                           acc.data(), static_cast<std::int32_t>(len));
    std::copy_n(acc.begin(), len, out.begin() + static_cast<std::ptrdiff_t>(i));
  }
}

/// Component-samples (sines) of a direct sum worth a second thread: about
/// 4 ms of work; below it a thread start costs more than it saves.
constexpr double direct_work_per_thread = 1 << 22;

/// Components that are harmonics of one fundamental (noise: of 1/length;
/// waveforms: of fundamental_cpm), with each component's harmonic number:
/// what the chirp-z synthesis needs besides amplitudes and phases. Empty for
/// sums of sinusoids.
struct HarmonicLayout {
  detail::TwoDouble fundamental;
  std::vector<std::uint64_t> number;  // ascending, one per component
};

/// The same sum as accumulate() from zero on `count` samples from `first`
/// of `grid`, by chirp-z transform (detfft), samples to `sink`: a noise's
/// harmonics drawn as the transform asks for them, a waveform's laid out
/// densely from the lowest harmonic to the highest, absent ones at
/// amplitude 0.
void synthesize_harmonics(const std::vector<ReferenceComponent>& comps, const HarmonicLayout& layout,
                          const detail::NoiseBand* noise, const Grid& grid, std::int64_t first, std::size_t count,
                          const detail::SampleSink& sink, const ReferenceMemory& memory) {
  const detail::ChirpMemory chirp{memory.fft_points, 0, memory.threads};
  if (noise != nullptr) {
    const detail::HarmonicSource source{noise->first, layout.fundamental, noise->count(),
                                        [noise](std::size_t j0, std::span<double> amplitude, std::span<double> phase) {
                                          for (std::size_t x = 0; x < amplitude.size(); ++x) {
                                            const ReferenceComponent c = noise->component(noise->first + j0 + x);
                                            amplitude[x] = c.amplitude;
                                            phase[x] = c.phase_cycles;
                                          }
                                        }};
    detail::sum_harmonics(source, grid.origin.value(), grid.spacing.value(), first, count, sink, chirp);
    return;
  }
  const std::uint64_t lowest = layout.number.front();
  const auto harmonics = static_cast<std::size_t>(layout.number.back() - lowest + 1);
  std::vector<double> amplitude(harmonics, 0.0);
  std::vector<double> phase(harmonics, 0.0);
  for (std::size_t i = 0; i < comps.size(); ++i) {
    const auto j = static_cast<std::size_t>(layout.number[i] - lowest);
    amplitude[j] = comps[i].amplitude;
    phase[j] = comps[i].phase_cycles;
  }
  detail::sum_harmonics(detail::harmonic_source({lowest, layout.fundamental, amplitude, phase}), grid.origin.value(),
                        grid.spacing.value(), first, count, sink, chirp);
}

/// A synthesised sum y as amplitude: 0.5 + scale·y, clamped to [0, 1]
/// (docs/references.md §1 [choice]; scale = 0.5 / max|y|).
double amplitude_of(double scale, double y) {
  const double v = 0.5 + scale * y;
  return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

// ------------------------------------------------------------ parameters

double number(const ReferenceSpec& s, const char* key) { return std::get<double>(reference_value(s, key)); }
std::vector<double> numbers(const ReferenceSpec& s, const char* key) {
  return std::get<std::vector<double>>(reference_value(s, key));
}
std::string word(const ReferenceSpec& s, const char* key) { return std::get<std::string>(reference_value(s, key)); }

/// The band's upper edge: band_max (0 = Nyquist), never at or above Nyquist.
double band_top(double band_max, double nyquist) { return band_max > 0.0 && band_max < nyquist ? band_max : nyquist; }

/// Harmonics k/P of the texture length P inside [lo, hi), hi exclusive.
std::pair<std::uint64_t, std::uint64_t> harmonic_range(double lo, double hi, double period) {
  const double kmin = std::max(1.0, std::ceil(lo * period - 1e-9));
  double kmax = std::ceil(hi * period) - 1.0;  // k/P < hi
  if (kmax / period >= hi) kmax -= 1.0;
  return {static_cast<std::uint64_t>(kmin), kmax < kmin ? 0 : static_cast<std::uint64_t>(kmax)};
}

std::string field(const ReferenceSpec& s, const std::string& key) { return "reference '" + s.name + "' parameter " + key; }

detail::NoiseBand noise_band(const ReferenceSpec& s, const std::string& family, double period, double nyquist) {
  detail::NoiseBand band{.rng = CounterRng(s.seed, Stream::reference)};
  band.period = period;
  double lo = 0.0;
  double hi = 0.0;
  if (family == "band-pass noise") {
    band.band_pass = true;
    band.centre = number(s, "centre_cpm");
    band.q = 1.0 / (2.0 * number(s, "zeta"));
    lo = number(s, "band_min_cpm");
    hi = band_top(number(s, "band_max_cpm"), nyquist);
  } else {
    lo = number(s, "band_min_cpm");
    hi = band_top(number(s, "band_max_cpm"), nyquist);
    band.exponent = number(s, "slope_db_per_decade") / 20.0;  // amplitude ∝ f^(slope/20)
  }
  const auto [k0, k1] = harmonic_range(lo, hi, period);
  if (k1 < k0)
    throw InvalidArgument("reference '" + s.name + "': the band " + num(lo) + " … " + num(hi) + " cpm holds no harmonic of the " +
                          num(period) + " mm texture (spacing " + num(1.0 / period) +
                          " cpm); widen the band or lengthen the texture");
  // The chirp-z synthesis's FFT (in memory or on disk) grows with the
  // harmonic count; the direct one's time grows with its square.
  if (s.synthesis == ReferenceSynthesis::chirp_z && k1 - k0 + 1 > detail::max_chirp_harmonics)
    throw InvalidArgument("reference '" + s.name + "': the band " + num(lo) + " … " + num(hi) + " cpm holds " +
                          std::to_string(k1 - k0 + 1) + " harmonics of the " + num(period) + " mm texture; at most " +
                          std::to_string(detail::max_chirp_harmonics) +
                          " (narrow the band, shorten the texture or coarsen the grid)");
  band.first = k0;
  band.last = k1;
  return band;
}

std::vector<ReferenceComponent> sine_components(const ReferenceSpec& s, double nyquist) {
  const auto f = numbers(s, "frequencies_cpm");
  auto w = numbers(s, "weights");
  if (w.empty()) w.assign(f.size(), 1.0);
  const bool random = word(s, "phase") == "random";
  const CounterRng rng(s.seed, Stream::reference);
  std::vector<ReferenceComponent> comps;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!(f[i] < nyquist))
      throw InvalidArgument(field(s, "frequencies_cpm") + "[" + std::to_string(i) + "] is " + num(f[i]) +
                            " cpm, at or above the grid's Nyquist frequency " + num(nyquist) + " cpm (it would alias)");
    comps.push_back({CyclesPerMm(f[i]), w[i], random ? rng.uniform(i) : 0.0});
  }
  return comps;
}

/// Cost bounds of a reference, checked before anything is allocated: the
/// harmonics of a waveform (each synthesized at every sample) and the
/// features of a patch or pulse layout (one entry each).
constexpr double max_harmonics = 1 << 16;
constexpr double max_layout_features = 1 << 22;

/// Refuses a layout of more than max_layout_features features of `feature`
/// mm over `length` mm (0.001 mm patches over a kilometre-spaced device: 10^11).
void check_feature_count(const ReferenceSpec& s, const char* key, double feature, double length) {
  if (length / feature > max_layout_features)
    throw InvalidArgument(field(s, key) + " is " + num(feature) + " mm: up to " + num(std::ceil(length / feature)) +
                          " features over the " + num(length) + " mm texture; at most " + num(max_layout_features) +
                          " (lengthen " + key + " or shorten the texture)");
}

std::vector<ReferenceComponent> waveform_components(const ReferenceSpec& s, double nyquist, HarmonicLayout& layout) {
  const double f0 = number(s, "fundamental_cpm");
  const double hi = band_top(number(s, "band_max_cpm"), nyquist);
  const double phase0 = number(s, "phase_deg") / 360.0;
  if (!(f0 < hi))
    throw InvalidArgument(field(s, "fundamental_cpm") + " is " + num(f0) + " cpm, not below the band's top " + num(hi) +
                          " cpm (the grid's Nyquist frequency or band_max_cpm)");
  // Every harmonic below the band's top is synthesized at every sample: a
  // fundamental far below 1/length (1e-6 cpm on a 94 cpm grid: 10^8
  // harmonics) would take hours and gigabytes, so it is refused up front.
  if (hi / f0 > max_harmonics)
    throw InvalidArgument(field(s, "fundamental_cpm") + " is " + num(f0) + " cpm: " + num(std::floor(hi / f0)) +
                          " harmonics below the band's top " + num(hi) + " cpm; at most " + num(max_harmonics) +
                          " (raise fundamental_cpm or lower band_max_cpm)");
  std::vector<ReferenceComponent> comps;
  layout.fundamental = {f0, 0.0};
  for (std::uint64_t n = 1;; ++n) {
    const double nd = static_cast<double>(n);
    const double f = nd * f0;
    if (!(f < hi)) break;
    double a = 0.0;
    double phase = nd * phase0;  // the whole waveform shifts with the fundamental
    if (s.name == "square") {
      if (n % 2 == 0) continue;
      a = 1.0 / nd;
    } else if (s.name == "tri") {
      if (n % 2 == 0) continue;
      a = 1.0 / (nd * nd);
      if ((n / 2) % 2 == 1) phase += 0.5;  // (−1)^((n−1)/2)
    } else {                               // saw: Σ (−1)^(n+1) sin(nωx)/n
      a = 1.0 / nd;
      if (n % 2 == 0) phase += 0.5;
    }
    phase -= std::floor(phase);
    comps.push_back({CyclesPerMm(f), a, phase});
    layout.number.push_back(n);
  }
  return comps;
}

/// Fisher–Yates shuffle number `shuffle` (>= 1) of `v`, from its own counters.
void shuffle_gaps(std::vector<double>& v, std::uint64_t seed, std::uint64_t shuffle) {
  const CounterRng rng(seed, Stream::reference);
  const std::uint64_t base = (std::uint64_t{1} << 40) + (shuffle << 24);
  for (std::size_t i = v.size(); i > 1; --i) {
    const auto j = static_cast<std::size_t>(rng.below(base + i, i));
    std::swap(v[i - 1], v[j]);
  }
}

std::vector<ReferenceFeature> lay_out(double start, double feature, const std::vector<double>& gaps, double length,
                                      std::size_t max_features) {
  std::vector<ReferenceFeature> out;
  double pos = start;
  std::size_t i = 0;
  while (pos + feature <= length + 1e-9 && out.size() < max_features) {
    out.push_back({Millimetres(pos), Millimetres(feature)});
    if (gaps.empty()) break;
    pos += feature + gaps[i % gaps.size()];
    ++i;
  }
  return out;
}

std::vector<ReferenceFeature> patch_features(const ReferenceSpec& s, double length) {
  const double patch = number(s, "patch_mm");
  const double start = number(s, "start_mm");
  check_feature_count(s, "patch_mm", patch, length);
  std::vector<double> gaps = numbers(s, "gaps_mm");
  const auto shuffle = static_cast<std::uint64_t>(number(s, "shuffle"));
  const bool drawn = gaps.empty();
  if (drawn) {
    // Whole millimetres uniformly from {0 … round(2c)} [choice: for c = 4.6
    // that is {0 … 9}, mean 4.5 mm; uniform integers cannot have mean 4.6].
    const auto top = static_cast<std::uint64_t>(std::floor(2.0 * number(s, "spacing_mm") + 0.5));
    const CounterRng rng(s.seed, Stream::reference);
    const auto n = static_cast<std::size_t>(length / patch) + 1;  // enough for any layout
    gaps.resize(n);
    for (std::size_t i = 0; i < n; ++i) gaps[i] = static_cast<double>(rng.below(i, top + 1));
  }
  // Lay out in drawn order first: the shuffles permute exactly the gaps used,
  // so their total (and the patch count) is unchanged.
  std::vector<ReferenceFeature> f = lay_out(start, patch, gaps, length, std::size_t(-1));
  if (f.size() < 2 || shuffle == 0) return f;
  std::vector<double> used(f.size() - 1);
  for (std::size_t i = 0; i + 1 < f.size(); ++i) used[i] = gaps[i % gaps.size()];
  shuffle_gaps(used, s.seed, shuffle);
  return lay_out(start, patch, used, length, f.size());
}

std::vector<ReferenceFeature> pulse_features(const ReferenceSpec& s, double length) {
  check_feature_count(s, "pulse_mm", number(s, "pulse_mm"), length);
  std::vector<ReferenceFeature> f =
      lay_out(number(s, "start_mm"), number(s, "pulse_mm"), numbers(s, "gaps_mm"), length, std::size_t(-1));
  if (word(s, "mirror") == "yes") {
    for (auto& p : f) p.start = Millimetres(length - p.start.value() - p.length.value());
    std::reverse(f.begin(), f.end());
  }
  return f;
}

}  // namespace

ReferenceTexture::ReferenceTexture(const ReferenceSpec& spec, Millimetres length, const Sampling& sampling,
                                   const ReferenceMemory& memory)
    : spec_(spec), length_(length), grid_(sampling.grid) {
  const Grid& grid = sampling.grid;
  validate(spec_);
  if (!(std::isfinite(length.value()) && length.value() > 0.0))
    throw InvalidArgument("reference length is " + num(length.value()) + " mm; it must be > 0");
  if (!(std::isfinite(grid.spacing.value()) && grid.spacing.value() > 0.0 && std::isfinite(grid.origin.value())))
    throw InvalidArgument("reference grid spacing is " + num(grid.spacing.value()) + " mm; it must be > 0");
  if (memory.fft_points < 4 || (memory.fft_points & (memory.fft_points - 1)) != 0)
    throw InvalidArgument("reference memory: fft_points is " + std::to_string(memory.fft_points) +
                          "; it must be a power of two >= 4");
  const ReferenceInfo& info = reference_info(spec_.name);
  const double nyquist = grid.nyquist().value();
  const double L = length.value();
  HarmonicLayout layout;
  if (info.family == "band-pass noise" || info.family == "colour of noise") {
    noise_ = std::make_shared<const detail::NoiseBand>(noise_band(spec_, info.family, L, nyquist));
    layout.fundamental = detail::reciprocal(L);
  } else if (info.family == "sum of sinusoids") {
    components_ = sine_components(spec_, nyquist);
  } else if (info.family == "shaped waveform") {
    components_ = waveform_components(spec_, nyquist, layout);
  } else if (info.family == "patch texture") {
    shape_ = Shape::patch;
    features_ = patch_features(spec_, L);
  } else {
    shape_ = Shape::pulse;
    features_ = pulse_features(spec_, L);
  }
  if (shape_ != Shape::sum && features_.empty())
    throw InvalidArgument("reference '" + spec_.name + "': no feature fits the " + num(L) +
                          " mm texture; lower start_mm or the feature length");

  // Samples of the prepared grid inside [0, L).
  const double sp = grid.spacing.value();
  std::int64_t a = static_cast<std::int64_t>(std::ceil(-grid.origin.value() / sp)) - 1;
  while (grid.position(a).value() < 0.0) ++a;
  std::int64_t b = static_cast<std::int64_t>(std::floor((L - grid.origin.value()) / sp)) + 1;
  while (b > a && !(grid.position(b - 1).value() < L)) --b;
  while (grid.position(b).value() < L) ++b;
  cache_first_ = a;
  cache_count_ = static_cast<std::size_t>(b - a);

  // Where the samples go: cache_, or a scratch file beyond the budget (the
  // bits are the same either way; only the memory differs).
  std::shared_ptr<detail::ScratchFile> file;
  if (cache_count_ > memory.cached_samples) {
    file = std::make_shared<detail::ScratchFile>("reference '" + spec_.name + "'");
    file->reserve(cache_count_);
  } else {
    cache_.resize(cache_count_);
  }
  scratch_ = file;  // read_samples reads back what store wrote
  const auto store = [&](std::size_t i, std::span<const double> y) {
    if (file)
      file->write(i, y);
    else
      std::copy(y.begin(), y.end(), cache_.begin() + static_cast<std::ptrdiff_t>(i));
  };
  constexpr std::size_t block = std::size_t{1} << 14;  // samples per step when not in one piece

  if (shape_ == Shape::sum) {
    double peak = 0.0;
    const auto keep = [&](std::size_t i, std::span<const double> y) {
      for (double v : y) peak = std::max(peak, std::abs(v));
      store(i, y);
    };
    if (spec_.synthesis == ReferenceSynthesis::chirp_z && (noise_ || !layout.number.empty())) {
      synthesize_harmonics(components_, layout, noise_.get(), grid, a, cache_count_, keep, memory);
    } else {
      // Directly: each run of samples sums every component in the same
      // order wherever it runs (the bits do not depend on how the samples
      // are cut), so long sums share runs among workers, short enough to
      // even out (a run draws a noise's components again: ~1e-3 of its
      // sines); each worker has its buffer and its peak, and the maximum of
      // the peaks is order-free.
      const ComponentRuns runs{components_, noise_.get()};
      const double work = static_cast<double>(noise_ ? noise_->count() : components_.size()) * static_cast<double>(cache_count_);
      const int workers = work < direct_work_per_thread ? 1 : (memory.threads > 0 ? memory.threads : detail::worker_threads());
      const std::size_t step = workers > 1 ? std::size_t{1} << 12 : block;
      const std::size_t tasks = (cache_count_ + step - 1) / step;
      const std::size_t team = std::min(static_cast<std::size_t>(workers), tasks);
      std::vector<std::vector<double>> buffers(team);
      std::vector<double> peaks(team, 0.0);
      detail::parallel_tasks(static_cast<int>(team), tasks, [&](std::size_t worker, std::size_t task) {
        const std::size_t i = task * step;
        std::vector<double>& y = buffers[worker];
        y.assign(std::min(step, cache_count_ - i), 0.0);
        runs([&](std::span<const ReferenceComponent> comps) { accumulate(comps, grid, a + static_cast<std::int64_t>(i), y); });
        for (double v : y) peaks[worker] = std::max(peaks[worker], std::abs(v));
        store(i, y);  // distinct samples: safe from any worker
      });
      for (double p : peaks) peak = std::max(peak, p);
    }
    // The sums are kept as synthesised; read_samples maps them to amplitude
    // (no second pass over a scratch file).
    peak_ = peak > 0.0 ? peak : 1.0;
    scale_ = 0.5 / peak_;
  } else {
    std::vector<double> buffer(std::min(block, cache_count_));
    for (std::size_t i = 0; i < cache_count_; i += block) {
      const std::span<double> y(buffer.data(), std::min(block, cache_count_ - i));
      evaluate(grid, a + static_cast<std::int64_t>(i), y);
      store(i, y);
    }
  }
}

std::vector<ReferenceComponent> ReferenceTexture::components() const {
  if (!noise_) return components_;
  std::vector<ReferenceComponent> all;
  all.reserve(noise_->count());
  ComponentRuns{components_,
                noise_.get()}([&](std::span<const ReferenceComponent> run) { all.insert(all.end(), run.begin(), run.end()); });
  return all;
}

void ReferenceTexture::read_samples(std::size_t i, std::span<double> out) const {
  if (scratch_)
    scratch_->read(i, out);
  else
    std::copy_n(cache_.begin() + static_cast<std::ptrdiff_t>(i), out.size(), out.begin());
  if (shape_ != Shape::sum) return;
  for (double& v : out) v = amplitude_of(scale_, v);  // a sum as synthesised, to amplitude
}

void ReferenceTexture::evaluate(const Grid& grid, std::int64_t first, std::span<double> out) const {
  const double L = length_.value();
  if (shape_ == Shape::sum) {
    std::fill(out.begin(), out.end(), 0.0);
    ComponentRuns{components_,
                  noise_.get()}([&](std::span<const ReferenceComponent> comps) { accumulate(comps, grid, first, out); });
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double x = grid.position(first + static_cast<std::int64_t>(i)).value();
      out[i] = !(x >= 0.0 && x < L) ? 0.0 : amplitude_of(scale_, out[i]);
    }
    return;
  }
  // Features are sorted and disjoint: walk them alongside the samples.
  std::size_t j = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double x = grid.position(first + static_cast<std::int64_t>(i)).value();
    out[i] = 0.0;
    if (!(x >= 0.0 && x < L)) continue;
    if (i == 0 || x < grid.position(first + static_cast<std::int64_t>(i) - 1).value()) {
      j = static_cast<std::size_t>(std::upper_bound(features_.begin(), features_.end(), x,
                                                    [](double v, const ReferenceFeature& f) { return v < f.start.value(); }) -
                                   features_.begin());
      j = j > 0 ? j - 1 : 0;
    }
    while (j + 1 < features_.size() && x >= features_[j + 1].start.value()) ++j;
    const ReferenceFeature& f = features_[j];
    const double t = x - f.start.value();
    if (!(t >= 0.0 && t < f.length.value())) continue;
    if (shape_ == Shape::patch) {
      out[i] = 1.0;
    } else {
      const double v = 0.5 - 0.5 * detmath::cos_cycles(t / f.length.value());
      out[i] = v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
    }
  }
}

void ReferenceTexture::render(const Grid& grid, std::int64_t first, std::span<double> out) const {
  const auto n = static_cast<std::int64_t>(out.size());
  const std::int64_t cache_end = cache_first_ + static_cast<std::int64_t>(cache_count_);
  if (grid.origin.value() == grid_.origin.value() && grid.spacing.value() == grid_.spacing.value()) {
    // The prepared grid: its samples inside [0, L) are the cache, the others
    // at rest. (Never re-synthesised: a window's bytes are the whole's.)
    const std::int64_t a = std::clamp(cache_first_ - first, std::int64_t{0}, n);
    const std::int64_t b = std::clamp(cache_end - first, a, n);
    std::fill(out.begin(), out.begin() + a, 0.0);
    if (b > a)
      read_samples(static_cast<std::size_t>(first + a - cache_first_),
                   out.subspan(static_cast<std::size_t>(a), static_cast<std::size_t>(b - a)));
    std::fill(out.begin() + b, out.end(), 0.0);
    return;
  }
  // Another grid: a position that coincides with a prepared-grid sample takes
  // its cached value (so sample(x) is the renderer's own value there); runs
  // of other positions are evaluated directly.
  const double o = grid_.origin.value();
  const double sp = grid_.spacing.value();
  const auto cached = [&](double x) -> std::int64_t {  // the prepared sample at x, or −1
    const double r = std::round((x - o) / sp);
    if (!(r >= static_cast<double>(cache_first_) - 1.0 && r <= static_cast<double>(cache_end))) return -1;
    const auto i = static_cast<std::int64_t>(r);
    for (std::int64_t j = std::max(i - 1, cache_first_); j <= std::min(i + 1, cache_end - 1); ++j)
      if (grid_.position(j).value() == x) return j - cache_first_;
    return -1;
  };
  std::int64_t i = 0;
  while (i < n) {
    std::int64_t j = i;
    std::int64_t hit = -1;
    while (j < n && (hit = cached(grid.position(first + j).value())) < 0) ++j;
    if (j > i) evaluate(grid, first + i, out.subspan(static_cast<std::size_t>(i), static_cast<std::size_t>(j - i)));
    if (j < n) read_samples(static_cast<std::size_t>(hit), out.subspan(static_cast<std::size_t>(j), 1));
    i = j + 1;
  }
}

double ReferenceTexture::amplitude_at(Millimetres x) const {
  const double x_mm = x.value();
  const double L = length_.value();
  if (!(x_mm >= 0.0 && x_mm < L)) return 0.0;
  if (shape_ == Shape::sum) {
    double y = 0.0;
    ComponentRuns{components_, noise_.get()}([&](std::span<const ReferenceComponent> run) {
      for (const auto& c : run) y = y + c.amplitude * detmath::sin_cycles(c.phase_cycles + c.frequency.value() * x_mm);
    });
    return amplitude_of(scale_, y);
  }
  for (const auto& f : features_) {
    const double t = x_mm - f.start.value();
    if (t >= 0.0 && t < f.length.value()) {
      if (shape_ == Shape::patch) return 1.0;
      const double v = 0.5 - 0.5 * detmath::cos_cycles(t / f.length.value());
      return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
    }
  }
  return 0.0;
}

std::vector<Millimetres> ReferenceTexture::gaps() const {
  std::vector<Millimetres> g;
  for (std::size_t i = 1; i < features_.size(); ++i)
    g.push_back(features_[i].start - (features_[i - 1].start + features_[i - 1].length));
  return g;
}

std::string ReferenceTexture::describe() const {
  const ReferenceInfo& info = reference_info(spec_.name);
  std::string s = "reference " + spec_.name;
  for (const auto& [k, v] : spec_.params) s += " " + k + "=" + format_reference_value(v);
  if (info.uses_seed) s += " seed=" + std::to_string(spec_.seed);
  return s;
}

std::vector<double> render_reference(const ReferenceSpec& spec, const Grid& grid) {
  if (grid.count <= 0)
    throw InvalidArgument("reference grid has " + std::to_string(grid.count) + " samples; it needs at least 1");
  const Grid local{Millimetres(0.0), grid.spacing, grid.count};
  const ReferenceTexture t(spec, grid.length(), Sampling{local});
  std::vector<double> out(static_cast<std::size_t>(grid.count));
  t.render(local, 0, out);
  return out;
}

SampledProfile reference_profile(const ReferenceSpec& spec, Millimetres length, Millimetres spacing) {
  const double spacing_mm = spacing.value();
  if (!(std::isfinite(spacing_mm) && spacing_mm > 0.0))
    throw InvalidArgument("reference profile spacing is " + num(spacing_mm) + " mm; it must be > 0");
  const Grid grid{Millimetres(0.0), spacing, 0};
  const ReferenceTexture t(spec, length, Sampling{grid});
  const auto count = static_cast<std::int64_t>(std::ceil(length.value() / spacing_mm));
  SampledProfile p;
  p.spacing = spacing;
  p.values.resize(static_cast<std::size_t>(std::max<std::int64_t>(count, 1)));
  t.render(grid, 0, p.values);
  return p;
}

std::shared_ptr<const Texture> prepare(const ReferenceSpec& spec, Millimetres length, const Sampling& sampling) {
  return std::make_shared<const ReferenceTexture>(spec, length, sampling);
}

}  // namespace texel
