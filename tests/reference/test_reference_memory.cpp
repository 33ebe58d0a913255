// References in bounded memory: the chirp-z FFTs and the prepared samples
// move to scratch files beyond ReferenceMemory's budget, and that changes
// where the data lives, never a byte of what renders.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/map_file.hpp"
#include "texel/reference.hpp"
#include "texel/surface.hpp"

#include "../support/memory.hpp"

using namespace texel;

namespace {

ReferenceSpec spec(const std::string& name, std::uint64_t seed = 1) {
  ReferenceSpec s;
  s.name = name;
  s.seed = seed;
  return s;
}

/// Everything a prepared reference renders, as bits: the prepared grid
/// whole and in an odd window, another grid (cached and evaluated samples
/// mixed), single-point evaluation and the components.
struct Rendered {
  std::vector<double> whole, window, other;
  double point = 0.0, peak = 0.0;
  std::vector<ReferenceComponent> components;
};

Rendered render(const ReferenceSpec& s, double length, const Grid& grid, const ReferenceMemory& memory, bool& in_file) {
  const ReferenceTexture t(s, Millimetres(length), Sampling{grid}, memory);
  in_file = t.samples_in_scratch_file();
  Rendered r;
  r.whole.resize(static_cast<std::size_t>(grid.count));
  t.render(grid, 0, r.whole);
  r.window.resize(777);
  t.render(grid, grid.count / 3 - 100, r.window);         // starts before a block edge of the scratch file
  const Grid half{grid.origin, grid.spacing * 0.5, 600};  // every other position is a prepared sample
  r.other.resize(600);
  t.render(half, 2 * grid.count / 5, r.other);
  r.point = t.amplitude_at(Millimetres(length * 0.377));
  r.peak = t.peak();
  r.components = t.components();
  return r;
}

using test_support::peak_rss_kib;
using test_support::same_bits;

}  // namespace

TEST(ReferenceMemory, ScratchFilesNeverChangeTheBytes) {
  // Small budgets send every family's FFTs and samples to scratch files;
  // a budget larger than anything keeps them all in memory. Same bits.
  const ReferenceMemory tiny{4096, 1000};
  const ReferenceMemory huge{std::size_t{1} << 26, std::size_t{1} << 40};
  ReferenceSpec direct_pink = spec("pink", 4);
  direct_pink.synthesis = ReferenceSynthesis::direct;  // version 2: components drawn in runs
  struct Case {
    ReferenceSpec spec;
    double length;
    double spacing;
  };
  const std::vector<Case> cases{
      {spec("white", 7), 100.0, 0.005},       {spec("bandpass-f4-z0.5", 2), 60.0, 0.0053},
      {spec("blue", 3), 50.0, 0.0053},        {direct_pink, 12.0, 0.0053},
      {spec("square"), 101.76, 0.0053},       {spec("4sin"), 60.0, 0.0053},
      {spec("patch-4.6", 5), 101.76, 0.0053}, {spec("pulse-b"), 101.76, 0.0053},
  };
  for (const Case& c : cases) {
    const Grid grid{Millimetres(0.0), Millimetres(c.spacing), static_cast<std::int64_t>(c.length / c.spacing) + 3};
    bool tiny_in_file = false, huge_in_file = true;
    const Rendered a = render(c.spec, c.length, grid, tiny, tiny_in_file);
    const Rendered b = render(c.spec, c.length, grid, huge, huge_in_file);
    EXPECT_TRUE(tiny_in_file) << c.spec.name;
    EXPECT_FALSE(huge_in_file) << c.spec.name;
    EXPECT_TRUE(same_bits(a.whole, b.whole)) << c.spec.name;
    EXPECT_TRUE(same_bits(a.window, b.window)) << c.spec.name;
    EXPECT_TRUE(same_bits(a.other, b.other)) << c.spec.name;
    EXPECT_EQ(std::memcmp(&a.point, &b.point, sizeof a.point), 0) << c.spec.name;
    EXPECT_EQ(a.peak, b.peak) << c.spec.name;
    ASSERT_EQ(a.components.size(), b.components.size()) << c.spec.name;
    for (std::size_t i = 0; i < a.components.size(); ++i) {
      EXPECT_EQ(a.components[i].amplitude, b.components[i].amplitude);
      EXPECT_EQ(a.components[i].phase_cycles, b.components[i].phase_cycles);
    }
    // The window and the other grid agree with the whole (a window's bytes
    // are the whole's).
    EXPECT_EQ(std::memcmp(a.window.data() + 100, a.whole.data() + grid.count / 3, 677 * sizeof(double)), 0) << c.spec.name;
  }
  EXPECT_THROW((void)ReferenceTexture(spec("white"), Millimetres(10.0), Sampling{Grid{Millimetres(0.0), Millimetres(0.01), 0}},
                                      ReferenceMemory{100, 10}),
               InvalidArgument);
}

TEST(ReferenceMemory, FourMetresOfWhiteNoiseStreamInBoundedMemory) {
  // 4 m of full-band white noise at 5 µm: 800,000 samples and 400,000
  // harmonics. Held whole (FFT arrays of 2^20 points, samples, components)
  // it took 77 MB; prepared within the default budget and streamed to a
  // file, the process may grow by a few MiB.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("texel-refmem-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const DeviceProfile d = with_grid(load_device("generic"), Millimetres(4000.0), Millimetres(0.005));
  const long before = peak_rss_kib();
  const Document doc = make_reference_document(d, spec("white", 11));
  const Surface surface = prepare_surface(doc);
  const MapFileStats stats = write_map((dir / "white.bin").string(), surface, d.format);
  const long grown = peak_rss_kib() - before;
  EXPECT_EQ(stats.samples, 800'000u);
#if !defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(grown, 16 * 1024) << "peak RSS grew by " << grown << " KiB preparing and writing 4 m of white noise";
#endif
  // A window of the file equals the same window rendered alone.
  std::ifstream in(dir / "white.bin", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<double> window(4096);
  surface.render(654'321, window);
  std::vector<std::byte> enc(window.size() * bytes_per_sample(d.format));
  encode_samples(d.format, window, enc);
  EXPECT_EQ(0, std::memcmp(bytes.data() + 654'321 * bytes_per_sample(d.format), enc.data(), enc.size()));
  std::filesystem::remove_all(dir);
}

TEST(ReferenceMemory, ThreadCountsNeverChangeTheBytes) {
  // Worker threads share out the chirp-z passes and blocks (in memory and
  // out of core) and the direct sum's sample blocks; 1, 2 and 3 of them give
  // the same bits.
  ReferenceSpec direct_pink = spec("pink", 4);
  direct_pink.synthesis = ReferenceSynthesis::direct;  // version 2, long enough to be shared out
  direct_pink.params["band_max_cpm"] = 5.0;
  struct Case {
    ReferenceSpec spec;
    double length;
    double spacing;
    std::size_t fft_points;
  };
  const std::vector<Case> cases{
      {spec("white", 7), 100.0, 0.005, 4096},
      {spec("bandpass-f4-z0.5", 2), 60.0, 0.0053, 1024},
      {spec("white", 9), 30.0, 0.0053, std::size_t{1} << 17},
      {direct_pink, 100.0, 0.0053, 4096},
      {spec("square"), 101.76, 0.0053, 4096},
  };
  for (const Case& c : cases) {
    const Grid grid{Millimetres(0.0), Millimetres(c.spacing), static_cast<std::int64_t>(c.length / c.spacing) + 3};
    std::vector<double> expected;
    for (int threads : {1, 2, 3}) {
      const ReferenceTexture t(c.spec, Millimetres(c.length), Sampling{grid}, ReferenceMemory{c.fft_points, 1000, threads});
      std::vector<double> out(static_cast<std::size_t>(grid.count));
      t.render(grid, 0, out);
      if (threads == 1)
        expected = out;
      else
        EXPECT_TRUE(same_bits(out, expected)) << c.spec.name << ", " << threads << " threads";
    }
  }
}
