// Binding of the 2-D model (texel/surface2d.hpp, texel/bitmap_file.hpp): a
// version-4 2-D document rendered to 2-D numpy arrays (amplitudes, or the
// pixels its bitmap stores), a strip of rows at a time for large maps, its
// coarse raster, and bitmap files written by the library's one writer, as
// `texel render DOC --surface 2d` does.
#include "texel/surface2d.hpp"
#include "common.hpp"
#include "texel/bitmap_file.hpp"
#include "texel/error.hpp"

namespace texel::python {
namespace {

/// A 2-D numpy array (rows, columns) owning `v` (no copy).
template <class T>
py::array_t<T> to_numpy_2d(std::vector<T>&& v, std::size_t rows, std::size_t columns) {
  auto* owned = new std::vector<T>(std::move(v));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  const auto item = static_cast<py::ssize_t>(sizeof(T));
  return py::array_t<T>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(columns)},
                        {static_cast<py::ssize_t>(columns) * item, item}, owned->data(), owner);
}

/// The row range [first, first + count) of `rows` (None: the whole bitmap).
std::pair<int, int> row_range(const BitmapGeometry& g, const py::object& rows) {
  if (rows.is_none()) return {0, g.height};
  const auto r = rows.cast<std::pair<long long, long long>>();
  if (r.first < 0 || r.second < 0 || r.first > g.height || r.second > g.height - r.first)
    throw InvalidArgument("rows is (" + std::to_string(r.first) + ", " + std::to_string(r.second) +
                          "); (first, count) must lie within the bitmap's " + std::to_string(g.height) + " rows");
  return {static_cast<int>(r.first), static_cast<int>(r.second)};
}

py::array render_2d(const Document& doc, const std::string& dtype, const py::object& rows) {
  const bool amplitudes = dtype == "float64" || dtype == "float32";
  if (!amplitudes && dtype != "native" && dtype != "uint8" && dtype != "uint16")
    throw InvalidArgument("dtype is '" + dtype +
                          "'; allowed: native (the pixels of the device's bitmap depth and polarity), uint8, uint16 (pixels "
                          "of that depth), float64, float32 (amplitudes 0 … 1)");
  const Surface2D surface = prepare_surface2d(doc);
  const BitmapGeometry& g = surface.geometry();
  const auto [first, count] = row_range(g, rows);
  const auto w = static_cast<std::size_t>(g.width), h = static_cast<std::size_t>(count);
  if (amplitudes) {
    std::vector<double> a(w * h);
    {
      py::gil_scoped_release release;
      surface.render_rows(first, count, a);
    }
    if (dtype == "float64") return to_numpy_2d(std::move(a), h, w);
    return to_numpy_2d(std::vector<float>(a.begin(), a.end()), h, w);
  }
  const int depth = dtype == "uint8" ? 8 : dtype == "uint16" ? 16 : g.depth;
  std::vector<std::uint16_t> pixels(w * h);
  {
    py::gil_scoped_release release;
    render_pixel_rows(surface, first, count, depth, pixels);
  }
  if (depth == 16) return to_numpy_2d(std::move(pixels), h, w);
  return to_numpy_2d(std::vector<std::uint8_t>(pixels.begin(), pixels.end()), h, w);
}

py::dict bitmap_dict(const BitmapGeometry& g) {
  py::dict d;
  d["width_px"] = g.width;
  d["height_px"] = g.height;
  d["pixel_pitch_mm"] = g.pitch.value();
  d["depth_bits"] = g.depth;
  d["polarity"] = std::string(to_string(g.polarity));
  d["width_mm"] = g.width_mm().value();
  d["height_mm"] = g.height_mm().value();
  return d;
}

py::array raster_numpy(const Raster2D& r) {
  return to_numpy_2d(std::vector<float>(r.values), static_cast<std::size_t>(r.height), static_cast<std::size_t>(r.width));
}

}  // namespace

void register_surface2d(py::module_& m) {
  m.def(
      "bitmap_info",
      [](const py::object& device) -> py::object {
        const DeviceProfile d =
            py::isinstance<Document>(device) ? device.cast<Document>().device : device_of(device, std::nullopt, std::nullopt);
        if (!d.bitmap) return py::none();
        return bitmap_dict(*d.bitmap);
      },
      py::arg("device"),
      "A device's bitmap grid (of a Document, a DeviceProfile, or a device name or path) as a dict:\n"
      "width_px, height_px, pixel_pitch_mm, depth_bits, polarity, width_mm, height_mm; None without one.");
  m.def("render_2d", &render_2d, py::arg("document"), py::kw_only(), py::arg("dtype") = "float64", py::arg("rows") = py::none(),
        R"doc(Renders a 2-D document (version 4, surface2d) to a 2-D array of shape (rows, width): row j is
y = j·pitch, column i is x = i·pitch (bitmap_info gives the grid). The values of `texel render DOC
--surface 2d -o map.npy` (float64) or of its .png (pixels).

dtype  'float64' or 'float32': amplitudes 0 … 1 (before polarity); 'native': the pixels the device's
       bitmap stores (its depth, 8 → uint8 or 16 → uint16, and polarity); 'uint8' / 'uint16': pixels
       of that depth ['float64']
rows   (first, count): only those rows, for maps too large to hold whole; any strip has the whole
       map's values [None: every row]

The GIL is released while rendering.)doc");
  m.def(
      "coarse_raster",
      [](const Document& doc, std::size_t region, std::optional<double> pitch_mm) {
        const Raster2D r = coarse_raster(doc, region, Millimetres(pitch_mm.value_or(0.0)));
        py::dict d;
        d["values"] = raster_numpy(r);
        d["pitch_mm"] = r.pitch.value();
        d["origin_x_mm"] = r.origin_x.value();
        d["origin_y_mm"] = r.origin_y.value();
        return d;
      },
      py::arg("document"), py::kw_only(), py::arg("region") = 0, py::arg("pitch_mm") = py::none(),
      "A 2-D document's coarse profile c(x, y) in [0, 1] of one region (0 outside it), sampled on the device's\n"
      "bitmap grid or on a square grid of pitch_mm over the same surface: dict values (float32, rows along y),\n"
      "pitch_mm, origin_x_mm, origin_y_mm. What the 2-D player looks up at the finger.");
  m.def(
      "write_bitmap",
      [](const Document& doc, const py::object& path, int depth, const std::string& mat_version) {
        BitmapFileOptions o;
        o.depth = depth;
        o.mat_version = mat::parse_mat_version(mat_version);
        const std::string p = path_of(path);
        BitmapFileStats s;
        {
          const Surface2D surface = prepare_surface2d(doc);
          py::gil_scoped_release release;
          s = write_bitmap(p, surface, o);
        }
        py::dict d;
        d["width_px"] = s.width;
        d["height_px"] = s.height;
        d["depth_bits"] = s.depth;
        d["bytes"] = s.bytes;
        d["mean_amplitude"] = s.mean_amplitude;
        return d;
      },
      py::arg("document"), py::arg("path"), py::kw_only(), py::arg("depth") = 0, py::arg("mat_version") = "5",
      R"doc(Writes a 2-D document's friction bitmap as `texel render DOC --surface 2d -o PATH` does, strip by
strip (bounded memory) and atomically: .png (8/16-bit grey, the device's polarity), .npy (float64
amplitudes), .mat, .gltf/.glb (MPEG_haptic_material).

depth        PNG bits per pixel, 8 or 16; 0 = the device's [0]
mat_version  .mat: '5' or '7.3' ['5']

Returns dict width_px, height_px, depth_bits, bytes, mean_amplitude. The GIL is released while writing.)doc");
}

}  // namespace texel::python
