// Texel textures at any length: beyond TexelTexture's kept texels, only the
// phase every checkpoint_stride texels is kept and windows draw the texels
// they need. That moves memory, never a bit of what renders.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/map_file.hpp"
#include "texel/surface.hpp"
#include "texel/texture.hpp"

#include "../support/memory.hpp"

using namespace texel;

namespace {

using test_support::peak_rss_kib;
using test_support::same_bits;

}  // namespace

TEST(TexelCheckpoints, CheckpointedTexturesRenderTheKeptBytes) {
  // keep = 0 checkpoints every texture; keep = max keeps every texel. Every
  // window, single positions and the texel list agree bit for bit.
  const Grid grid{Millimetres(0.0), Millimetres(0.0053), 40000};  // 212 mm
  std::vector<TexelSpec> specs(6);
  specs[0].central_pitch = Decibels(10.0);
  specs[0].seed = 5;
  specs[0].texel_length = Millimetres(0.05);
  specs[1] = specs[0];
  specs[1].phase = PhaseMode::reset;
  specs[2] = specs[0];
  specs[2].coarse_strength = 0.6;
  specs[2].fine_strength = 0.7;
  specs[2].coarse = SineProfile{Millimetres(7.0), 30.0};
  specs[3] = specs[0];
  specs[3].texel_length = Millimetres(0.1);
  specs[3].coarse_strength = 1.0;
  specs[3].coarse = PointsProfile{{{0.0, 0.0}, {100.0, 1.0}, {212.0, 0.2}}};
  specs[4] = specs[0];
  specs[4].quantization_db = 2.0;
  specs[4].irregularity = Decibels(3.0);
  specs[4].fill = Fill::partial_final_texel;
  specs[4].texel_length = Millimetres(0.07);
  specs[5] = specs[0];
  specs[5].texel_length = Millimetres(0.05);
  specs[5].coarse_strength = 0.5;
  std::vector<double> values(5000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<double>(i % 17) / 16.0;
  specs[5].coarse = ValuesProfile{values};
  for (std::size_t s = 0; s < specs.size(); ++s) {
    const Sampling sampling{grid};
    const TexelTexture kept(specs[s], grid.length(), sampling, std::size_t(-1));
    const TexelTexture lazy(specs[s], grid.length(), sampling, 0);
    ASSERT_GT(lazy.texel_count(), 2 * TexelTexture::checkpoint_stride) << s;
    std::vector<double> a(static_cast<std::size_t>(grid.count)), b(a.size());
    kept.render(grid, 0, a);
    lazy.render(grid, 0, b);
    EXPECT_TRUE(same_bits(a, b)) << "spec " << s;
    for (std::int64_t first : {std::int64_t{0}, std::int64_t{1234}, std::int64_t{19999}, std::int64_t{39000}}) {
      std::vector<double> wa(1001), wb(1001);
      kept.render(grid, first, wa);
      lazy.render(grid, first, wb);
      EXPECT_TRUE(same_bits(wa, wb)) << "spec " << s << " window " << first;
    }
    for (double x : {0.0, 0.37, 55.5, 150.1234, 211.9}) {
      const double va = kept.sample(Millimetres(x)), vb = lazy.sample(Millimetres(x));
      EXPECT_EQ(std::memcmp(&va, &vb, sizeof va), 0) << "spec " << s << " x " << x;
      const double aa = kept.amplitude_at(Millimetres(x)), ab = lazy.amplitude_at(Millimetres(x));
      EXPECT_EQ(std::memcmp(&aa, &ab, sizeof aa), 0) << "spec " << s << " x " << x;
    }
    ASSERT_EQ(kept.texels().size(), lazy.texels().size());
    std::size_t seen = 0;
    lazy.for_each_texels([&](std::size_t first, std::span<const Texel> run) {
      ASSERT_EQ(first, seen);
      for (const Texel& t : run) {
        const Texel& k = kept.texels()[seen++];
        EXPECT_EQ(t.frequency.value(), k.frequency.value());
        EXPECT_EQ(t.phase_cycles, k.phase_cycles);
        EXPECT_EQ(t.envelope, k.envelope);
      }
    });
    EXPECT_EQ(seen, kept.texel_count());
    EXPECT_EQ(lazy.texels()[seen - 1].phase_cycles, kept.texels()[seen - 1].phase_cycles);
  }
}

TEST(TexelCheckpoints, ThreadsRenderingOneTextureAtOnceGetTheSameBytes) {
  // Eight threads render interleaved windows of one checkpointed texture at
  // the same time, again and again, sharing its block cache: the windows
  // straddle blocks, so threads want the same block at once, and more
  // threads than cores are preempted while they hold a block the others
  // cycle past. Every window equals the single-threaded render of the whole.
  const Grid grid{Millimetres(0.0), Millimetres(0.001), 1'000'000};
  TexelSpec spec;
  spec.seed = 21;
  spec.texel_length = Millimetres(0.01);  // 100,000 texels in 98 blocks, 10 samples each
  spec.coarse_strength = 0.5;
  spec.coarse = SineProfile{Millimetres(3.0), 0.0};
  const TexelTexture lazy(spec, grid.length(), Sampling{grid}, 0);
  const TexelTexture kept(spec, grid.length(), Sampling{grid}, std::size_t(-1));
  std::vector<double> want(static_cast<std::size_t>(grid.count));
  kept.render(grid, 0, want);
  constexpr std::size_t window = 24'999;
  constexpr unsigned threads = 8;
  std::vector<std::vector<double>> got(threads, std::vector<double>(want.size(), -1.0));
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (unsigned pass = 0; pass < 12; ++pass)  // a different share of the windows each pass
        for (std::size_t w = (t + pass) % threads; w * window < want.size(); w += threads) {
          const std::size_t first = w * window;
          lazy.render(grid, static_cast<std::int64_t>(first),
                      std::span<double>(got[t].data() + first, std::min(window, want.size() - first)));
        }
    });
  for (auto& t : pool) t.join();
  for (unsigned t = 0; t < threads; ++t) EXPECT_TRUE(same_bits(got[t], want)) << "thread " << t;
}

TEST(TexelCheckpoints, MillionsOfTexelsRenderInBoundedMemory) {
  // 2.5 million texels (two samples each): kept whole they would be 120 MB
  // of texel arrays. Checkpointed and streamed to a file, the process may
  // grow by a few MiB.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("texel-texmem-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const DeviceProfile d = with_grid(load_device("generic"), Millimetres(50000.0), Millimetres(0.01));
  TexelSpec s;
  s.central_pitch = Decibels(10.0);
  s.texel_length = Millimetres(0.02);
  s.seed = 9;
  const long before = peak_rss_kib();
  const Document doc = make_document(d, s);
  const Surface surface = prepare_surface(doc);
  const MapFileStats stats = write_map((dir / "long.bin").string(), surface, d.format);
  const long grown = peak_rss_kib() - before;
  EXPECT_EQ(stats.samples, 5'000'000u);
#if !defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(grown, 16 * 1024) << "peak RSS grew by " << grown << " KiB rendering 2.5 million texels";
#endif
  std::filesystem::remove_all(dir);
}
