// Streaming a rendered map to a file: memory bounded by one chunk, whatever
// the map's length (issue #11, item 5).
//
// A map of 10^7 samples used to be rendered into a vector of doubles, then
// encoded into a second buffer, then written: 8 + 2 bytes per sample resident
// before the first byte reached the disk. write_map renders a window of the
// surface (Surface::render gives any window the values of the whole map),
// encodes it and appends it to an AtomicFile, so the file still appears
// atomically and a failure leaves nothing. The bytes are those of the
// whole-map writers (encode_samples, csv_columns, npy_bytes), chunk for chunk.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "texel/device.hpp"
#include "texel/surface.hpp"

namespace texel {

/// The map formats that stream: .bin (the device's own sample format), .csv
/// ("position_mm,amplitude"), .npy (float64, its header written first).
enum class MapFileKind { device_native, csv, npy };

/// The kind `path`'s extension names, or nothing for another extension.
std::optional<MapFileKind> map_file_kind(const std::string& path);

struct MapFileOptions {
  std::size_t chunk_samples = std::size_t{1} << 16;  ///< samples rendered per chunk (> 0) [65536]
  /// Threads rendering and encoding chunks, the calling thread among them:
  /// 0 = automatic (map_file_threads: TEXEL_THREADS if set, else the
  /// processors the process may run on, at most max_auto_threads), 1 = the
  /// calling thread alone [0]. The
  /// bytes written and the stats never depend on it.
  unsigned threads = 0;
  static constexpr unsigned max_auto_threads = 4;
  /// Called after each chunk with the fraction written (0 … 1]; may be empty.
  std::function<void(double)> progress;
};

/// The threads write_map uses for `requested` (MapFileOptions::threads):
/// itself when > 0, else TEXEL_THREADS if set, else the processors this
/// process may run on (Linux: its affinity mask; elsewhere the hardware's),
/// between 1 and max_auto_threads.
unsigned map_file_threads(unsigned requested);

/// What write_map wrote.
struct MapFileStats {
  std::size_t samples = 0;
  std::size_t bytes = 0;
  double mean_amplitude = 0.0;  ///< mean of the rendered amplitudes (before encoding)
};

/// Renders `surface` chunk by chunk into `path` (kind by extension; .bin in
/// `format`). Throws InvalidArgument for another extension, IoError when the
/// file cannot be written (nothing is left behind).
///
/// With several threads, chunks are rendered and encoded by that many
/// threads, the calling thread among them (at most two chunks per thread in
/// memory); the calling thread writes them strictly in order and calls
/// `progress`. An exception in any thread stops the others and is rethrown
/// here, with no file left behind. `surface` is rendered concurrently
/// (Texture::render is safe to call from several threads).
MapFileStats write_map(const std::string& path, const Surface& surface, SampleFormat format, const MapFileOptions& options = {});

}  // namespace texel
