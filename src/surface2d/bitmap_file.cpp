// PNG (libpng) and .npy friction bitmaps, written strip by strip; grey PNG
// images read for 2-D coarse profiles.
#include "texel/bitmap_file.hpp"

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <thread>
#include <vector>

#include "internal.hpp"
#include "texel/detail/parallel.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/map_file.hpp"
#include "texel/matfile.hpp"

namespace texel {
namespace {

/// libpng reports errors by longjmp: every call into it goes through a
/// function whose locals are trivially destructible, and the message is
/// kept here and thrown afterwards.
struct PngState {
  AtomicFile* file = nullptr;
  std::exception_ptr write_error;
  char message[256] = {};
  /// libpng hands over each chunk in three pieces (length and type, data,
  /// CRC) of at most 8 KiB: they are gathered here and written a MiB at a
  /// time (the file's bytes are the same; the system calls 1/100 as many).
  std::vector<unsigned char> pending;
  void flush() {
    file->write(std::span<const std::byte>(reinterpret_cast<const std::byte*>(pending.data()), pending.size()));
    pending.clear();
  }
};
constexpr std::size_t png_write_buffer = std::size_t{1} << 20;

void on_png_error(png_structp png, png_const_charp msg) {
  auto* st = static_cast<PngState*>(png_get_error_ptr(png));
  std::snprintf(st->message, sizeof st->message, "%s", msg);
  png_longjmp(png, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

void on_png_write(png_structp png, png_bytep data, png_size_t n) {
  auto* st = static_cast<PngState*>(png_get_io_ptr(png));
  try {
    if (st->pending.size() + n > png_write_buffer) st->flush();
    if (n >= png_write_buffer) {
      st->file->write(std::span<const std::byte>(reinterpret_cast<const std::byte*>(data), n));
    } else {
      st->pending.insert(st->pending.end(), data, data + n);
    }
  } catch (...) {
    st->write_error = std::current_exception();
    png_error(png, "write failed");
  }
}
void on_png_flush(png_structp) {}

/// Returns false after a libpng error (png_ptr is then destroyed by the caller).
bool png_begin(png_structp png, png_infop info, int width, int height, int depth, int level) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_compression_level(png, level);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), depth, PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  return true;
}
bool png_rows(png_structp png, const unsigned char* data, std::size_t stride, int rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  for (int r = 0; r < rows; ++r) png_write_row(png, data + static_cast<std::size_t>(r) * stride);
  return true;
}
bool png_end(png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_write_end(png, info);
  return true;
}

[[noreturn]] void png_fail(const PngState& st, const std::string& path) {
  if (st.write_error) std::rethrow_exception(st.write_error);
  throw IoError(path + ": PNG: " + st.message);
}

struct PngWriteHandle {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngWriteHandle() { png_destroy_write_struct(&png, info ? &info : nullptr); }
};

/// The sum of a row's amplitudes, in eight interleaved partial sums added
/// pairwise at the end: a fixed order (the same on every CPU, SIMD width and
/// thread count) the compiler can vectorise, where one running sum waits on
/// each addition.
double row_sum(std::span<const double> a) {
  double part[8] = {};
  std::size_t k = 0;
  for (; k + 8 <= a.size(); k += 8)
    for (std::size_t l = 0; l < 8; ++l) part[l] += a[k + l];
  for (std::size_t l = 0; k < a.size(); ++k, ++l) part[l] += a[k];
  return ((part[0] + part[1]) + (part[2] + part[3])) + ((part[4] + part[5]) + (part[6] + part[7]));
}

}  // namespace

bool is_bitmap_path(const std::string& path) {
  const std::string ext = output_extension(path);
  return ext == ".png" || ext == ".npy" || ext == ".mat" || ext == ".gltf" || ext == ".glb";
}

namespace {

/// .mat: the whole map in memory (MATLAB double, height × width).
BitmapFileStats write_mat_bitmap(const std::string& path, const Surface2D& surface, const BitmapFileOptions& options) {
  const BitmapGeometry& g = surface.geometry();
  const std::size_t w = static_cast<std::size_t>(g.width), h = static_cast<std::size_t>(g.height);
  if (w * h > max_in_memory_pixels)
    throw InvalidArgument("'" + path + "': a .mat map is held in memory whole; " + std::to_string(g.width) + " × " +
                          std::to_string(g.height) + " pixels is over the limit of " + std::to_string(max_in_memory_pixels) +
                          " (write .png or .npy, which stream)");
  mat::Matrix m;
  m.rows = h;
  m.cols = w;
  m.data.resize(w * h);
  std::vector<double> row(w);
  double sum = 0.0;
  for (std::size_t j = 0; j < h; ++j) {
    surface.render_rows(static_cast<int>(j), 1, row);
    for (std::size_t i = 0; i < w; ++i) {
      m.data[i * h + j] = row[i];  // column-major
      sum += row[i];
    }
  }
  mat::WriteOptions mo;
  mo.version = options.mat_version;
  mat::write_mat(path, {{"amplitude", std::move(m)}, {"pixel_pitch_mm", mat::Matrix::scalar(g.pitch.value())}}, mo);
  return {g.width, g.height, 64, w * h * 8, sum / static_cast<double>(w * h)};
}

/// .gltf / .glb: the PNG bitmap inside a glTF asset (MPEG_haptic_material).
BitmapFileStats write_gltf_bitmap(const std::string& path, const Surface2D& surface, const BitmapFileOptions& options) {
  const BitmapGeometry& g = surface.geometry();
  if (static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height) > max_in_memory_pixels)
    throw InvalidArgument("'" + path + "': a glTF asset is built in memory; the bitmap is over " +
                          std::to_string(max_in_memory_pixels) + " pixels (write .png or .npy, which stream)");
  const std::string png = path + ".part.png";  // removed below
  BitmapFileStats stats;
  std::vector<std::byte> bytes;
  try {
    stats = write_bitmap(png, surface, options);
    const std::string text = read_file(png);
    bytes.assign(reinterpret_cast<const std::byte*>(text.data()), reinterpret_cast<const std::byte*>(text.data()) + text.size());
    std::remove(png.c_str());
  } catch (...) {
    std::remove(png.c_str());
    throw;
  }
  gltf::AssetOptions o;
  const auto container = output_extension(path) == ".glb" ? gltf::Container::glb : gltf::Container::gltf;
  const std::vector<std::byte> asset =
      gltf::asset_2d(bytes, g.width_mm().value(), g.height_mm().value(), "surface2d", o, container);
  write_file_atomic(path, asset);
  stats.bytes = asset.size();
  return stats;
}

}  // namespace

BitmapFileStats write_bitmap(const std::string& path, const Surface2D& surface, const BitmapFileOptions& options) {
  const std::string ext = output_extension(path);
  if (!is_bitmap_path(path)) throw InvalidArgument("'" + path + "': a 2-D bitmap is written as .png, .npy, .mat, .gltf or .glb");
  if (ext == ".mat") return write_mat_bitmap(path, surface, options);
  if (ext == ".gltf" || ext == ".glb") return write_gltf_bitmap(path, surface, options);
  const BitmapGeometry& g = surface.geometry();
  const bool png = ext == ".png";
  const int depth = png ? (options.depth == 0 ? g.depth : options.depth) : 64;
  if (png && depth != 8 && depth != 16) throw InvalidArgument("PNG depth is " + std::to_string(depth) + "; allowed: 8, 16");
  if (options.rows_per_strip < 1) throw InvalidArgument("rows_per_strip must be >= 1");
  if (options.png_compression < 0 || options.png_compression > 9)
    throw InvalidArgument("png_compression is " + std::to_string(options.png_compression) + "; allowed: 0 … 9");
  const std::size_t w = static_cast<std::size_t>(g.width);
  const std::size_t bytes_per_pixel = static_cast<std::size_t>(depth / 8);
  const std::size_t stride = w * bytes_per_pixel;
  const int strip = options.rows_per_strip;
  const int strips = (g.height + strip - 1) / strip;
  const bool invert = g.polarity == BitmapPolarity::brighter_more_friction;
  const auto threads = static_cast<int>(map_file_threads(options.threads));

  AtomicFile file(path);
  PngState st;
  st.file = &file;
  PngWriteHandle handle;
  if (png) {
    handle.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &st, on_png_error, on_png_warning);
    if (!handle.png) throw IoError(path + ": cannot start libpng");
    handle.info = png_create_info_struct(handle.png);
    if (!handle.info) throw IoError(path + ": cannot start libpng");
    st.pending.reserve(png_write_buffer);
    png_set_write_fn(handle.png, &st, on_png_write, on_png_flush);
    if (!png_begin(handle.png, handle.info, g.width, g.height, depth, options.png_compression)) png_fail(st, path);
  } else {
    file.write(npy_header(static_cast<std::size_t>(g.height), static_cast<std::size_t>(g.width)));
  }

  // Each worker renders and encodes one strip of a batch; the calling thread
  // writes a batch in order while the workers render the next one (two sets
  // of buffers). Memory: 2 × threads × (strip doubles + bytes + levels).
  struct Buffer {
    std::vector<double> amplitude;
    std::vector<unsigned char> bytes;
    std::vector<std::uint16_t> levels;
    std::vector<double> row_sums;  // added in row order by the writer: the mean does not depend on the strips
  };
  const auto per_batch = static_cast<std::size_t>(std::max(threads, 1));
  std::vector<Buffer> sets[2] = {std::vector<Buffer>(per_batch), std::vector<Buffer>(per_batch)};
  const auto render_batch = [&](int batch, std::vector<Buffer>& buffers) {
    const int in_batch = std::min(threads, strips - batch);
    detail::parallel_tasks(threads, static_cast<std::size_t>(in_batch), [&](std::size_t, std::size_t t) {
      Buffer& b = buffers[t];
      const int first = (batch + static_cast<int>(t)) * strip;
      const int rows = std::min(strip, g.height - first);
      const std::size_t n = static_cast<std::size_t>(rows) * w;
      b.amplitude.resize(n);
      surface.render_rows(first, rows, b.amplitude);
      b.row_sums.resize(static_cast<std::size_t>(rows));
      for (int r = 0; r < rows; ++r)
        b.row_sums[static_cast<std::size_t>(r)] =
            row_sum(std::span<const double>(b.amplitude).subspan(static_cast<std::size_t>(r) * w, w));
      if (!png) {
        b.bytes.resize(n * 8);
        std::memcpy(b.bytes.data(), b.amplitude.data(), n * 8);
        return;
      }
      if (depth == 8) {
        b.bytes.resize(n);
        for (std::size_t k = 0; k < n; ++k) b.bytes[k] = static_cast<unsigned char>(bitmap_pixel(b.amplitude[k], g.polarity, 8));
        return;
      }
      // to_u16 of the (inverted) amplitude, a vector of pixels at a time
      // (encode_u16 is to_u16, which clamps the same way).
      if (invert)
        for (double& a : b.amplitude) a = 1.0 - std::clamp(a, 0.0, 1.0);
      b.levels.resize(n);
      encode_u16(b.amplitude, b.levels);
      // PNG samples are big-endian: swapped in place (a loop the compiler
      // vectorises), the levels' bytes are the rows libpng takes.
      for (std::uint16_t& v : b.levels) v = static_cast<std::uint16_t>((v << 8) | (v >> 8));
    });
  };
  double total = 0.0;
  std::size_t written = 0;
  if (strips > 0) render_batch(0, sets[0]);
  for (int batch = 0, cur = 0; batch < strips; batch += threads, cur ^= 1) {
    // The next batch renders on its own thread while this one is written.
    std::exception_ptr next_error;
    std::thread next;
    if (batch + threads < strips) {
      next = std::thread([&, first = batch + threads, set = cur ^ 1] {
        try {
          render_batch(first, sets[set]);
        } catch (...) {
          next_error = std::current_exception();
        }
      });
    }
    bool ok = true;
    std::exception_ptr write_error;
    try {
      const int in_batch = std::min(threads, strips - batch);
      for (int t = 0; t < in_batch && ok; ++t) {
        Buffer& b = sets[cur][static_cast<std::size_t>(t)];
        const int first = (batch + t) * strip;
        const int rows = std::min(strip, g.height - first);
        for (double s : b.row_sums) total += s;
        const std::span<const unsigned char> bytes =
            png && depth == 16
                ? std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(b.levels.data()), b.levels.size() * 2)
                : std::span<const unsigned char>(b.bytes);
        if (png) {
          ok = png_rows(handle.png, bytes.data(), stride, rows);
        } else {
          file.write(std::as_bytes(bytes));
        }
        written += bytes.size();
      }
    } catch (...) {
      write_error = std::current_exception();
    }
    if (next.joinable()) next.join();
    if (write_error) std::rethrow_exception(write_error);
    if (!ok) png_fail(st, path);
    if (next_error) std::rethrow_exception(next_error);
  }
  if (png && !png_end(handle.png, handle.info)) png_fail(st, path);
  if (png) st.flush();
  file.commit();
  BitmapFileStats stats;
  stats.width = g.width;
  stats.height = g.height;
  stats.depth = depth;
  stats.bytes = written;
  stats.mean_amplitude = total / (static_cast<double>(g.width) * static_cast<double>(g.height));
  return stats;
}

namespace surface2d_detail {
namespace {

struct PngReadHandle {
  png_structp png = nullptr;
  png_infop info = nullptr;
  std::FILE* f = nullptr;
  ~PngReadHandle() {
    png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    if (f) std::fclose(f);
  }
};

bool png_read_header(png_structp png, png_infop info, std::FILE* f, png_uint_32& w, png_uint_32& h, int& depth, int& colour) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, f);
  png_read_info(png, info);
  int interlace = 0, compression = 0, filter = 0;
  png_get_IHDR(png, info, &w, &h, &depth, &colour, &interlace, &compression, &filter);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  png_read_update_info(png, info);
  return true;
}
bool png_read_rows(png_structp png, unsigned char* data, std::size_t stride, png_uint_32 rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  for (png_uint_32 r = 0; r < rows; ++r) png_read_row(png, data + r * stride, nullptr);
  return true;
}

}  // namespace

Raster2D read_png_grey(const std::string& path) {
  PngState st;
  PngReadHandle h;
  h.f = std::fopen(path.c_str(), "rb");
  if (!h.f) throw IoError(path + ": cannot open for reading");
  h.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &st, on_png_error, on_png_warning);
  if (!h.png) throw IoError(path + ": cannot start libpng");
  h.info = png_create_info_struct(h.png);
  if (!h.info) throw IoError(path + ": cannot start libpng");
  png_uint_32 w = 0, ht = 0;
  int depth = 0, colour = 0;
  if (!png_read_header(h.png, h.info, h.f, w, ht, depth, colour))
    throw FormatError(path + ": not a readable PNG (" + st.message + ")");
  if (colour != PNG_COLOR_TYPE_GRAY)
    throw FormatError(path +
                      ": a coarse-profile image must be a grey PNG without alpha (8 or 16 bit); this one has colour type " +
                      std::to_string(colour));
  if (w > 65535 || ht > 65535) throw FormatError(path + ": the image is larger than 65535 pixels on a side");
  const int bytes = depth == 16 ? 2 : 1;
  const std::size_t stride = static_cast<std::size_t>(w) * static_cast<std::size_t>(bytes);
  std::vector<unsigned char> data(stride * ht);
  if (!png_read_rows(h.png, data.data(), stride, ht)) throw FormatError(path + ": " + st.message);
  Raster2D r;
  r.width = static_cast<int>(w);
  r.height = static_cast<int>(ht);
  r.values.resize(static_cast<std::size_t>(w) * ht);
  for (std::size_t k = 0; k < r.values.size(); ++k)
    r.values[k] =
        bytes == 2 ? static_cast<float>(((data[2 * k] << 8) | data[2 * k + 1]) / 65535.0) : static_cast<float>(data[k] / 255.0);
  return r;
}

}  // namespace surface2d_detail
}  // namespace texel
