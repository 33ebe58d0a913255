// Render throughput, in ns/sample and samples/s, each case next to a plain
// std::fill of the same buffer measured in the same run, so the figures read
// as ratios rather than absolute numbers that depend on the machine.
//
//   render/tpad/...   the reference device's whole map: 19,200 samples, the
//                     default TexelSpec with seed 7 (a document on "tpad").
//   render/1e8/...    10^8 samples of the generic device (100 m at 0.001 mm,
//                     texels of 0.25 mm) into a preallocated buffer, in
//                     L1-sized chunks: render to doubles, then encode.
//   fill/...          std::fill of the same buffer: the memory-bound floor.
//   prepare/tpad      constructing the TexelTexture (per-texel draws).
//   reference/chirp-z/white/<L>mm   preparing full-band white noise (seed 1)
//                     over L mm on a 5 µm grid (200 samples per mm, about 100
//                     harmonics per mm): the component draws, the chirp-z
//                     synthesis of every sample (document version 3) and the
//                     scaling, for L = 100 mm … 4 m. O(N log N): the time per
//                     N·log2(N) stays flat (bench/summarize.py prints it
//                     relative to 100 mm).
//   reference/direct/white/<L>mm    the same with version 2's direct sum
//                     (O(N²) here), at 100 and 200 mm: the baseline.
//
// Results are kept alive with DoNotOptimize/ClobberMemory. Each case runs in
// several repetitions and reports the median; the 10^8 cases use a fixed,
// small iteration count so `make bench` stays around a minute.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/reference.hpp"
#include "texel/surface.hpp"
#include "texel/texture.hpp"

namespace {

using namespace texel;

constexpr int repetitions = 5;
constexpr std::size_t chunk = 2048;  // 16 KiB of doubles: stays in L1 between render and encode

// Counters every case reports: samples/s and ns/sample (an inverted rate of
// 1e-9 per sample is seconds·1e9 per sample).
void report(benchmark::State& state, std::int64_t samples, std::size_t bytes_per_sample) {
  const auto n = static_cast<double>(samples);
  state.SetItemsProcessed(state.iterations() * samples);
  state.SetBytesProcessed(state.iterations() * samples * static_cast<std::int64_t>(bytes_per_sample));
  state.counters["samples/s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["ns/sample"] =
      benchmark::Counter(n * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

Surface tpad_surface() {
  TexelSpec spec;
  spec.seed = 7;
  return prepare_surface(make_document(load_device("tpad"), spec));
}

Surface big_surface() {
  TexelSpec spec;
  spec.texel_length = Millimetres(0.25);
  return prepare_surface(make_document(with_grid(load_device("generic"), Millimetres(100000.0), Millimetres(0.001)), spec));
}

// Prepared once, on first use, so filtering out a case skips its setup.
const Surface& tpad() {
  static const Surface s = tpad_surface();
  return s;
}
const Surface& big() {
  static const Surface s = big_surface();
  return s;
}

// Chunked render + encode into a caller-supplied buffer: the way a streaming
// writer or a device upload uses the library.
template <class T, class Encode>
void render_into(const Surface& s, std::span<T> out, Encode encode) {
  std::array<double, chunk> scratch;
  const std::size_t n = out.size();
  for (std::size_t i = 0; i < n; i += chunk) {
    const std::size_t len = std::min(chunk, n - i);
    const std::span<double> a(scratch.data(), len);
    s.render(static_cast<std::int64_t>(i), a);
    encode(std::span<const double>(a), out.subspan(i, len));
  }
}

void encode_to_u16(std::span<const double> a, std::span<std::uint16_t> out) { encode_u16(a, out); }
void encode_to_f32(std::span<const double> a, std::span<float> out) { encode_f32(a, out); }

template <class T>
std::vector<T>& buffer_for(const Surface& s) {
  // One buffer per (surface, type); allocated and touched before timing so
  // page faults are not measured.
  static std::vector<T> tpad_buf, big_buf;
  std::vector<T>& b = &s == &tpad() ? tpad_buf : big_buf;
  if (b.size() != static_cast<std::size_t>(s.grid().count)) b.assign(static_cast<std::size_t>(s.grid().count), T{1});
  return b;
}

template <class T>
void bm_render(benchmark::State& state, const Surface& (*surface)()) {
  const Surface& s = surface();
  std::vector<T>& buf = buffer_for<T>(s);
  for (auto _ : state) {
    if constexpr (std::is_same_v<T, float>) {
      render_into(s, std::span<T>(buf), encode_to_f32);
    } else {
      render_into(s, std::span<T>(buf), encode_to_u16);
    }
    benchmark::DoNotOptimize(buf.data());
    benchmark::ClobberMemory();
  }
  report(state, s.grid().count, sizeof(T));
}

template <class T>
void bm_fill(benchmark::State& state, const Surface& (*surface)()) {
  const Surface& s = surface();
  std::vector<T>& buf = buffer_for<T>(s);
  T v{};
  for (auto _ : state) {
    std::fill(buf.begin(), buf.end(), v);
    benchmark::DoNotOptimize(buf.data());
    benchmark::ClobberMemory();
    v = static_cast<T>(v + T{1});  // a different value each pass
  }
  report(state, s.grid().count, sizeof(T));
}

// The library's own whole-map path: allocates the result and encodes through
// the device-native byte writer.
void bm_render_native(benchmark::State& state) {
  const Surface& s = tpad();
  for (auto _ : state) {
    std::vector<std::byte> bytes = s.render_native(SampleFormat::u16le);
    benchmark::DoNotOptimize(bytes.data());
    benchmark::ClobberMemory();
  }
  report(state, s.grid().count, sizeof(std::uint16_t));
}

void bm_prepare(benchmark::State& state) {
  const DeviceProfile device = load_device("tpad");
  TexelSpec spec;
  spec.seed = 7;
  std::size_t texels = 0;
  for (auto _ : state) {
    TexelTexture t(spec, device.length(), Sampling{device.grid(), device.band_top()});
    texels = t.texels().size();
    benchmark::DoNotOptimize(t.texels().data());
    benchmark::ClobberMemory();
  }
  state.counters["texels"] = static_cast<double>(texels);
  state.counters["ns/texel"] = benchmark::Counter(static_cast<double>(texels) * 1e-9,
                                                  benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Preparing a reference = drawing its components and synthesising (and
// scaling) every sample of the grid inside its length; the prepared texture's
// cache is the result, kept alive through its peak.
void bm_reference(benchmark::State& state, ReferenceSynthesis synthesis, double length_mm) {
  ReferenceSpec spec;
  spec.name = "white";
  spec.synthesis = synthesis;
  const Grid grid{Millimetres(0.0), Millimetres(0.005), 0};
  std::size_t harmonics = 0;
  double peak = 0.0;
  for (auto _ : state) {
    const ReferenceTexture t(spec, Millimetres(length_mm), Sampling{grid});
    harmonics = t.components().size();
    peak = t.peak();
    benchmark::DoNotOptimize(peak);
    benchmark::ClobberMemory();
  }
  const auto samples = static_cast<std::int64_t>(std::llround(length_mm / 0.005));
  report(state, samples, sizeof(double));
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["harmonics"] = static_cast<double>(harmonics);
}

void register_all() {
  auto small = [](benchmark::internal::Benchmark* b) {
    b->Unit(benchmark::kMicrosecond)->MinTime(0.1)->Repetitions(repetitions)->ReportAggregatesOnly(true);
  };
  auto large = [](benchmark::internal::Benchmark* b) {
    b->Unit(benchmark::kMillisecond)->Iterations(3)->Repetitions(repetitions)->ReportAggregatesOnly(true);
  };
  small(benchmark::RegisterBenchmark("prepare/tpad", bm_prepare));
  small(benchmark::RegisterBenchmark("fill/tpad/u16", bm_fill<std::uint16_t>, tpad));
  small(benchmark::RegisterBenchmark("render/tpad/u16", bm_render<std::uint16_t>, tpad));
  small(benchmark::RegisterBenchmark("render/tpad/u16-native", bm_render_native));
  small(benchmark::RegisterBenchmark("fill/tpad/f32", bm_fill<float>, tpad));
  small(benchmark::RegisterBenchmark("render/tpad/f32", bm_render<float>, tpad));
  large(benchmark::RegisterBenchmark("fill/1e8/u16", bm_fill<std::uint16_t>, big));
  large(benchmark::RegisterBenchmark("render/1e8/u16", bm_render<std::uint16_t>, big));
  large(benchmark::RegisterBenchmark("fill/1e8/f32", bm_fill<float>, big));
  large(benchmark::RegisterBenchmark("render/1e8/f32", bm_render<float>, big));
  auto synthesis = [](benchmark::internal::Benchmark* b) {
    b->Unit(benchmark::kMillisecond)->MinTime(0.2)->Repetitions(3)->ReportAggregatesOnly(true);
  };
  for (const double length : {100.0, 200.0, 400.0, 800.0, 1600.0, 4000.0})
    synthesis(benchmark::RegisterBenchmark(("reference/chirp-z/white/" + std::to_string(static_cast<int>(length)) + "mm").c_str(),
                                           bm_reference, ReferenceSynthesis::chirp_z, length));
  for (const double length : {100.0, 200.0})
    synthesis(benchmark::RegisterBenchmark(("reference/direct/white/" + std::to_string(static_cast<int>(length)) + "mm").c_str(),
                                           bm_reference, ReferenceSynthesis::direct, length));
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
