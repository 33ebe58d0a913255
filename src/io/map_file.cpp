// Streaming map writer (include/texel/map_file.hpp).
#include "texel/map_file.hpp"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <vector>

#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel {

std::optional<MapFileKind> map_file_kind(const std::string& path) {
  const std::string ext = output_extension(path);
  if (ext == ".bin") return MapFileKind::device_native;
  if (ext == ".csv") return MapFileKind::csv;
  if (ext == ".npy") return MapFileKind::npy;
  return std::nullopt;
}

MapFileStats write_map(const std::string& path, const Surface& surface, SampleFormat format, const MapFileOptions& options) {
  const auto kind = map_file_kind(path);
  if (!kind) throw InvalidArgument("output '" + path + "': a streamed map is .bin, .csv or .npy");
  if (options.chunk_samples == 0) throw InvalidArgument("chunk_samples is 0; it must be > 0");
  const Grid& g = surface.grid();
  const auto n = static_cast<std::size_t>(g.count);
  const std::size_t chunk = std::min(options.chunk_samples, std::max<std::size_t>(n, 1));

  AtomicFile file(path);
  std::vector<double> amplitudes(chunk);
  std::vector<std::byte> encoded;
  std::string text;
  MapFileStats stats;
  double sum = 0.0;

  if (*kind == MapFileKind::csv) file.write(std::string_view("position_mm,amplitude\n"));
  if (*kind == MapFileKind::npy) file.write(npy_header(n));
  for (std::size_t first = 0; first < n; first += chunk) {
    const std::size_t len = std::min(chunk, n - first);
    const std::span<double> a(amplitudes.data(), len);
    surface.render(static_cast<std::int64_t>(first), a);
    for (double v : a) sum += v;
    switch (*kind) {
      case MapFileKind::device_native:
        encoded.resize(len * bytes_per_sample(format));
        encode_samples(format, a, encoded);
        file.write(encoded);
        break;
      case MapFileKind::npy: file.write(std::as_bytes(std::span<const double>(a))); break;
      case MapFileKind::csv: {
        // The bytes of csv_columns: shortest round-trip text of each value.
        text.clear();
        char buf[64];
        for (std::size_t i = 0; i < len; ++i) {
          auto r = std::to_chars(buf, buf + sizeof buf, g.position(static_cast<std::int64_t>(first + i)).value());
          text.append(buf, r.ptr);
          text.push_back(',');
          r = std::to_chars(buf, buf + sizeof buf, a[i]);
          text.append(buf, r.ptr);
          text.push_back('\n');
        }
        file.write(text);
        break;
      }
    }
    if (options.progress) options.progress(static_cast<double>(first + len) / static_cast<double>(n));
  }
  file.commit();
  stats.samples = n;
  stats.mean_amplitude = n ? sum / static_cast<double>(n) : 0.0;
  std::error_code ec;
  stats.bytes = static_cast<std::size_t>(std::filesystem::file_size(path, ec));
  return stats;
}

}  // namespace texel
