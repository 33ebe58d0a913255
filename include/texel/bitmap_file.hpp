// Writing a 2-D surface to a file, strip by strip (docs/format.md "Friction
// bitmaps"): memory bounded by a few strips whatever the bitmap's size, the
// strips rendered by the threads write_map uses (texel/map_file.hpp), the
// file written to a temporary and renamed into place (texel/io.hpp
// AtomicFile): a failure leaves nothing behind.
//
// Formats by extension: .png (grey, 8 or 16 bit through libpng; the pixel
// is a·max, or (1 − a)·max for a device of polarity brighter_more_friction),
// .npy (float64, shape (height, width), the amplitudes themselves); and,
// held in memory whole (at most max_in_memory_pixels), .mat (MATLAB double
// `amplitude`, height × width, and `pixel_pitch_mm`) and .gltf/.glb (the PNG
// inside a glTF asset with the MPEG_haptic_material, texel/interchange.hpp).
#pragma once

#include <cstddef>
#include <string>

#include "texel/matfile.hpp"
#include "texel/surface2d.hpp"

namespace texel {

struct BitmapFileOptions {
  int depth = 0;         ///< PNG bits per pixel, 8 or 16; 0 = the device's (BitmapGeometry::depth)
  unsigned threads = 0;  ///< as MapFileOptions::threads (0 = automatic)
  /// Rows rendered per task: 32 keep a strip's amplitudes (8192 columns:
  /// 2 MB) within a core's level-2 cache. The bytes never depend on it.
  int rows_per_strip = 32;
  /// zlib level of PNG output, 0 … 9: 0 (stored) by default. A fine
  /// texture's rows are noise-like and do not compress (an 8192² 16-bit map
  /// shrank 0.4 % at level 1, which took 60 % of the render's time).
  int png_compression = 0;
  mat::MatVersion mat_version = mat::MatVersion::v5;  ///< .mat: 5 or 7.3
};

/// The largest bitmap .mat and glTF outputs hold in memory (2^23 pixels: 64 MB of doubles).
inline constexpr std::size_t max_in_memory_pixels = std::size_t{1} << 23;

struct BitmapFileStats {
  int width = 0, height = 0;
  int depth = 0;          ///< PNG bit depth (64 for .npy float64)
  std::size_t bytes = 0;  ///< pixel bytes (.png, .npy, .mat) or the asset's size (glTF)
  double mean_amplitude = 0.0;
};

/// Throws InvalidArgument for another extension or a bad option, IoError
/// when the file cannot be written (nothing is left).
BitmapFileStats write_bitmap(const std::string& path, const Surface2D& surface, const BitmapFileOptions& options = {});

/// True for the extensions write_bitmap takes (.png, .npy, .mat, .gltf, .glb).
bool is_bitmap_path(const std::string& path);

}  // namespace texel
