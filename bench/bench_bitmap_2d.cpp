// texel_bench_bitmap_2d: an 8192 × 8192 16-bit friction bitmap (PNG; the
// tile field, version 5's default, or spectral or cells) prepared and written
// in strips, against `dd conv=fsync` writing the same number of bytes to the
// same directory, in the same run; peak memory (VmHWM) and CPU time of the
// render (the field's preparation included). Goal (issue #26): ratio ≤ 4,
// peak ≤ 64 MB.
//
//   texel_bench_bitmap_2d [directory] [size] [tile|spectral|cells] [rows per strip]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "texel/bitmap_file.hpp"

using namespace texel;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "/tmp";
  const int size = argc > 2 ? std::atoi(argv[2]) : 8192;
  const std::string png = dir + "/texel_bench_bitmap.png";
  const std::string raw = dir + "/texel_bench_dd.bin";
  BitmapGeometry g;
  g.width = size;
  g.height = size;
  g.pitch = Millimetres(0.02);  // 164 mm square, Nyquist 25 cpm
  g.depth = 16;
  Document doc;
  doc.device = load_device("tablet-2d");
  doc.device.bitmap = g;
  Region2DSpec region;
  region.texel.central_pitch = Decibels(6.0);
  region.texel.irregularity = Decibels(-5.0);
  region.texel.texel_length = Millimetres(0.25);
  region.field = argc > 3 ? parse_field2d(argv[3]) : Field2D::tile;
  Surface2DSpec spec;
  spec.regions.push_back(region);
  doc.surface2d = spec;
  // The render (the fields' preparation included) runs in a child so its
  // peak memory and CPU time are its own.
  auto t0 = std::chrono::steady_clock::now();
  const pid_t child = fork();
  if (child == 0) {
    const auto c0 = std::chrono::steady_clock::now();
    const Surface2D surface = prepare_surface2d(doc);
    const double prepare_s = seconds_since(c0);
    BitmapFileOptions options;
    if (argc > 4) options.rows_per_strip = std::atoi(argv[4]);
    const BitmapFileStats st = write_bitmap(png, surface, options);
    std::printf("bitmap: %d x %d, %d bit, %zu pixel bytes, field %s; prepare %.3f s, render and write %.3f s\n", st.width,
                st.height, st.depth, st.bytes, std::string(to_string(region.field)).c_str(), prepare_s,
                seconds_since(c0) - prepare_s);
    std::fflush(stdout);
    _exit(0);
  }
  int status = 0;
  rusage usage{};
  wait4(child, &status, 0, &usage);
  const double render = seconds_since(t0);
  const long file_bytes = [&] {
    FILE* f = std::fopen(png.c_str(), "rb");
    if (!f) return 0L;
    std::fseek(f, 0, SEEK_END);
    const long n = std::ftell(f);
    std::fclose(f);
    return n;
  }();
  const long bytes = static_cast<long>(size) * size * 2;
  const std::string dd = "dd if=/dev/zero of=" + raw + " bs=1M count=" + std::to_string(bytes >> 20) + " conv=fsync status=none";
  t0 = std::chrono::steady_clock::now();
  if (std::system(dd.c_str()) != 0) return 1;
  const double dd_s = seconds_since(t0);
  std::remove(raw.c_str());
  std::remove(png.c_str());
  std::printf("render+write %.3f s (PNG %ld bytes), dd conv=fsync of %ld bytes %.3f s, ratio %.2f (goal <= 4)\n", render,
              file_bytes, bytes, dd_s, render / dd_s);
  std::printf("peak memory of the render: %.1f MB (goal <= 64 MB)\n", static_cast<double>(usage.ru_maxrss) / 1024.0);
  // On a loaded machine the wall time above includes waiting for a CPU; the
  // render's own CPU time says what it costs (its threads share it).
  const double cpu = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                     1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  std::printf("render CPU time %.3f s (user + system, all threads)\n", cpu);
  // What that CPU time implies on an idle machine of this one's cores (the
  // render's threads and its writer sharing them perfectly): a lower bound.
  const unsigned cores = std::max(1U, std::thread::hardware_concurrency());
  std::printf("idle estimate: CPU / %u cores = %.3f s, ratio %.2f to this run's dd\n", cores, cpu / cores, cpu / cores / dd_s);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? 0 : 1;
}
