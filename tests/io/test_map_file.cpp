// Streaming map writer (issue #11, item 5): the streamed file is byte for
// byte the whole-map writers' output, appears atomically, and rendering a
// long map to it keeps memory bounded by a chunk, not by the map.
#include <gtest/gtest.h>

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
  EXPECT_THROW((void)write_map(dir.at("new.bin"), surface, doc.device.format, o), IoError);
  EXPECT_THROW((void)write_map(dir.at("old.bin"), surface, doc.device.format, o), IoError);
  EXPECT_EQ(dir.listing(), (std::set<std::string>{"old.bin"}));
  EXPECT_EQ(slurp(dir.at("old.bin")), "old");
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
