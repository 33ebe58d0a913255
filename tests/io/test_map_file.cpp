// Streaming map writer (issue #11, item 5): the streamed file is byte for
// byte the whole-map writers' output, appears atomically, and rendering a
// long map to it keeps memory bounded by a chunk, not by the map.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "../support/memory.hpp"
#include "../support/temp_dir.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/map_file.hpp"
#include "texel/reference.hpp"
#include "texel/texture.hpp"

namespace {

using namespace texel;
using texel::test_support::TempDir;

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

Document study(const DeviceProfile& device) {
  TexelSpec s;
  s.central_pitch = Decibels(6.0);
  s.irregularity = Decibels(-4.0);
  s.seed = 7;
  s.coarse_strength = 0.4;
  s.coarse = SineProfile{Millimetres(5.0), 30.0};
  return make_document(device, s);
}

TEST(MapFile, StreamedBytesEqualTheWholeMapWritersAtAnyChunkSize) {
  TempDir dir("mapfile");
  for (const char* name : {"tpad", "generic"}) {
    const Document doc = study(load_device(name));
    const Surface surface = prepare_surface(doc);
    const std::vector<double> map = surface.render();
    std::vector<double> x(map.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = surface.grid().position(static_cast<std::int64_t>(i)).value();
    const std::vector<std::byte> native = surface.render_native(doc.device.format);
    const std::string want_bin(reinterpret_cast<const char*>(native.data()), native.size());
    const std::string want_csv = csv_columns("position_mm", "amplitude", x, map);
    const std::string want_npy = npy_bytes(map);
    for (std::size_t chunk : {std::size_t{1}, std::size_t{777}, std::size_t{65536}, map.size() + 5}) {
      MapFileOptions o;
      o.chunk_samples = chunk;
      double last = 0.0;
      o.progress = [&](double f) {
        EXPECT_GT(f, last);
        last = f;
      };
      const MapFileStats bin = write_map(dir.at("m.bin"), surface, doc.device.format, o);
      EXPECT_EQ(slurp(dir.at("m.bin")), want_bin) << name << " chunk " << chunk;
      EXPECT_EQ(bin.samples, map.size());
      EXPECT_EQ(bin.bytes, want_bin.size());
      EXPECT_DOUBLE_EQ(last, 1.0);
      double mean = 0.0;
      for (double v : map) mean += v;
      EXPECT_NEAR(bin.mean_amplitude, mean / static_cast<double>(map.size()), 1e-12);
      if (chunk == 1 && map.size() > 100000) continue;  // one-sample chunks of CSV text: slow, and the same code
      last = 0.0;
      (void)write_map(dir.at("m.csv"), surface, doc.device.format, o);
      EXPECT_EQ(slurp(dir.at("m.csv")), want_csv) << name << " chunk " << chunk;
      last = 0.0;
      (void)write_map(dir.at("m.npy"), surface, doc.device.format, o);
      EXPECT_EQ(slurp(dir.at("m.npy")), want_npy) << name << " chunk " << chunk;
    }
  }
}

TEST(MapFile, FailureLeavesNothingAndOtherExtensionsAreRefused) {
  TempDir dir("mapfile");
  const Document doc = study(load_device("tpad"));
  const Surface surface = prepare_surface(doc);
  EXPECT_THROW((void)write_map(dir.at("m.png"), surface, doc.device.format), InvalidArgument);
  EXPECT_THROW((void)write_map(dir.at("missing/m.bin"), surface, doc.device.format), IoError);
  MapFileOptions zero;
  zero.chunk_samples = 0;
  EXPECT_THROW((void)write_map(dir.at("m.bin"), surface, doc.device.format, zero), InvalidArgument);
  // A progress callback that throws half-way: no file and no temporary remain;
  // an existing file keeps its old bytes.
  { std::ofstream(dir.at("old.bin")) << "old"; }
  MapFileOptions o;
  o.chunk_samples = 1000;
  o.progress = [](double f) {
    if (f > 0.5) throw IoError("disk full (simulated)");
  };
  for (unsigned threads : {1u, 3u}) {  // the caller's exception with workers running, too
    o.threads = threads;
    EXPECT_THROW((void)write_map(dir.at("new.bin"), surface, doc.device.format, o), IoError);
    EXPECT_THROW((void)write_map(dir.at("old.bin"), surface, doc.device.format, o), IoError);
    EXPECT_EQ(dir.listing(), (std::set<std::string>{"old.bin"}));
    EXPECT_EQ(slurp(dir.at("old.bin")), "old");
  }
}

/// A texture whose render throws for windows that reach `fail_at`, and
/// counts the windows it was asked for: a failing worker.
class FailingTexture final : public Texture {
 public:
  FailingTexture(Millimetres length, std::int64_t fail_at) : length_(length), fail_at_(fail_at) {}
  [[nodiscard]] Millimetres length() const override { return length_; }
  void render(const Grid&, std::int64_t first, std::span<double> out) const override {
    calls_.fetch_add(1);
    if (first + static_cast<std::int64_t>(out.size()) > fail_at_) throw IoError("scratch file unreadable (simulated)");
    std::fill(out.begin(), out.end(), 0.25);
  }
  [[nodiscard]] std::string describe() const override { return "failing"; }
  [[nodiscard]] int calls() const { return calls_.load(); }

 private:
  Millimetres length_;
  std::int64_t fail_at_;
  mutable std::atomic<int> calls_{0};
};

TEST(MapFile, ThreadCountNeverChangesTheBytesOrTheStats) {
  // The same file and the same mean_amplitude from 1, 2, 3 and 8 threads,
  // for every format: a two-scale tpad map, a checkpointed texture (more
  // than kept_texels texels, whose blocks the threads share) and a surface
  // of two regions, a reference whose prepared samples live in a scratch
  // file (pread by every thread) beside a Texel texture.
  TempDir dir("mapfile");
  std::vector<std::pair<std::string, Surface>> surfaces;
  surfaces.emplace_back("tpad two-scale", prepare_surface(study(load_device("tpad"))));
  {
    DeviceProfile d = load_device("generic");
    d.samples = 600'000;  // 3 m at 5 µm
    TexelSpec s;
    s.central_pitch = Decibels(12.0);
    s.texel_length = Millimetres(0.02);  // 150,000 texels: checkpointed
    s.coarse_strength = 0.3;
    s.coarse = SineProfile{Millimetres(40.0), 10.0};
    s.seed = 4;
    const Surface surface = prepare_surface(make_document(d, s));
    const auto* t = dynamic_cast<const TexelTexture*>(surface.regions().at(0).texture.get());
    ASSERT_NE(t, nullptr);
    ASSERT_GT(t->texel_count(), TexelTexture::kept_texels);
    surfaces.emplace_back("checkpointed", surface);
  }
  {
    const Grid grid{Millimetres(0.0), Millimetres(0.005), 200'000};
    ReferenceSpec white;
    white.name = "white";
    white.seed = 3;
    // Prepared for the grid the region sees (origin at its left edge), so
    // rendering reads the prepared samples back from the scratch file.
    const Sampling sampling{Grid{Millimetres(-50.0), grid.spacing, 0}};
    auto reference = std::make_shared<const ReferenceTexture>(white, Millimetres(400.0), sampling, ReferenceMemory{4096, 1000});
    ASSERT_TRUE(reference->samples_in_scratch_file());
    TexelSpec s;
    s.seed = 5;
    auto texel = prepare(s, Millimetres(500.0), Sampling{Grid{Millimetres(-480.0), grid.spacing, 0}});
    surfaces.emplace_back("reference + texel", Surface(grid, {Region{"ref", Millimetres(50.0), Millimetres(400.0), reference},
                                                              Region{"texel", Millimetres(480.0), Millimetres(500.0), texel}}));
  }
  for (const auto& [name, surface] : surfaces) {
    for (const char* file : {"m.bin", "m.npy", "m.csv"}) {
      for (std::size_t chunk : {std::size_t{777}, std::size_t{1} << 14}) {
        MapFileOptions o;
        o.chunk_samples = chunk;
        o.threads = 1;
        const MapFileStats one = write_map(dir.at(file), surface, SampleFormat::u16le, o);
        const std::string want = slurp(dir.at(file));
        for (unsigned threads : {2u, 3u, 8u}) {
          o.threads = threads;
          double last = 0.0;
          o.progress = [&](double f) {
            EXPECT_GT(f, last);  // in order, from the calling thread
            last = f;
          };
          const MapFileStats many = write_map(dir.at(file), surface, SampleFormat::u16le, o);
          EXPECT_TRUE(slurp(dir.at(file)) == want) << name << " " << file << " chunk " << chunk << " threads " << threads;
          EXPECT_EQ(many.mean_amplitude, one.mean_amplitude) << name << " " << file << " threads " << threads;
          EXPECT_EQ(many.bytes, one.bytes);
          EXPECT_EQ(last, 1.0);
        }
      }
    }
  }
}

TEST(MapFile, AWorkerExceptionStopsTheOthersAndLeavesNoFile) {
  // A window past sample 300,000 throws in whichever worker renders it: the
  // error reaches the caller, the workers stop (far fewer windows than the
  // map's are rendered), and neither a new file nor a temporary remains; an
  // existing file keeps its bytes.
  TempDir dir("mapfile");
  const std::int64_t samples = 10'000'000;
  const Grid grid{Millimetres(0.0), Millimetres(0.005), samples};
  { std::ofstream(dir.at("old.bin")) << "old"; }
  for (unsigned threads : {1u, 2u, 4u}) {
    for (const char* file : {"new.bin", "old.bin", "new.csv"}) {
      auto texture = std::make_shared<const FailingTexture>(grid.length(), 300'000);
      const Surface surface(grid, {Region{"r", Millimetres(0.0), grid.length(), texture}});
      MapFileOptions o;
      o.chunk_samples = 1000;
      o.threads = threads;
      try {
        (void)write_map(dir.at(file), surface, SampleFormat::u16le, o);
        ADD_FAILURE() << "no exception with " << threads << " threads";
      } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find("simulated"), std::string::npos) << e.what();
      }
      EXPECT_LT(texture->calls(), 300 + 2 * 8 * static_cast<int>(threads)) << threads << " threads rendered on";
      EXPECT_EQ(dir.listing(), (std::set<std::string>{"old.bin"})) << file << ", " << threads << " threads";
      EXPECT_EQ(slurp(dir.at("old.bin")), "old");
    }
  }
}

TEST(MapFile, ThreadsAreAutomaticUpToAFewOrAsAsked) {
  EXPECT_GE(map_file_threads(0), 1u);
  EXPECT_LE(map_file_threads(0), MapFileOptions::max_auto_threads);
  EXPECT_EQ(map_file_threads(1), 1u);
  EXPECT_EQ(map_file_threads(6), 6u);
}

using test_support::peak_rss_kib;

TEST(MapFile, LongMapsStreamInBoundedMemory) {
  // 10^7 samples (50 m at 5 µm, 200,000 texels): rendered whole, the map
  // alone is 80 MB of doubles. Streamed, the peak may grow by a few chunks.
  TempDir dir("mapfile");
  DeviceProfile d = load_device("generic");
  d.samples = 10'000'000;
  TexelSpec s;
  s.central_pitch = Decibels(10.0);
  s.seed = 3;
  const Document doc = make_document(d, s);
  const Surface surface = prepare_surface(doc);
  const long before = peak_rss_kib();
  const MapFileStats stats = write_map(dir.at("long.bin"), surface, d.format);
  const long grown = peak_rss_kib() - before;
  EXPECT_EQ(stats.samples, 10'000'000u);
  EXPECT_EQ(std::filesystem::file_size(dir.at("long.bin")), 10'000'000u * bytes_per_sample(d.format));
  EXPECT_LT(grown, 8 * 1024) << "peak RSS grew by " << grown << " KiB while streaming 10^7 samples";
  // Spot check: a window of the streamed file equals the same window rendered alone.
  const std::string bytes = slurp(dir.at("long.bin"));
  std::vector<double> window(1000);
  surface.render(7'654'321, window);
  std::vector<std::byte> enc(window.size() * bytes_per_sample(d.format));
  encode_samples(d.format, window, enc);
  EXPECT_EQ(0, std::memcmp(bytes.data() + 7'654'321 * bytes_per_sample(d.format), enc.data(), enc.size()));
}

}  // namespace
