// Binding of the 2-D encoder (texel/encode2d.hpp): a 2-D amplitude map (a
// numpy array with its pixel pitch, a PNG or .npy, or a bundle of 1-D scans)
// to a version-4 2-D document with the encoder's diagnostics, as `texel
// encode map.png` does.
#include "texel/encode2d.hpp"
#include "common.hpp"
#include "texel/codec.hpp"
#include "texel/error.hpp"
#include "texel/signal.hpp"

namespace texel::python {
namespace {

/// A 2-D array (rows along y) as a raster of pitch `pitch_mm`, read by the
/// one input rule (texel::to_amplitudes, on the values as doubles).
Raster2D raster_of(const py::handle& values, double pitch_mm) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!a) throw py::type_error("the map must be a 2-D array of numbers");
  if (a.ndim() != 2)
    throw InvalidArgument("the map has " + std::to_string(a.ndim()) + " dimensions; it must be 2-D (rows along y)");
  Raster2D r;
  r.height = static_cast<int>(a.shape(0));
  r.width = static_cast<int>(a.shape(1));
  r.pitch = Millimetres(pitch_mm);
  std::vector<double> v(a.data(), a.data() + a.size());
  (void)to_amplitudes(v, "the map");  // texel/signal.hpp
  r.values.assign(v.begin(), v.end());
  return r;
}

py::array raster_array(const Raster2D& r) {
  auto* owned = new std::vector<float>(r.values);
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
  const auto item = static_cast<py::ssize_t>(sizeof(float));
  return py::array_t<float>({static_cast<py::ssize_t>(r.height), static_cast<py::ssize_t>(r.width)},
                            {static_cast<py::ssize_t>(r.width) * item, item}, owned->data(), owner);
}

}  // namespace

void register_encode2d(py::module_& m) {
  using codec::Encode2DResult;
  py::class_<Encode2DResult>(m, "Encode2DResult",
                             "What encode_2d() found: a version-4 2-D document, its coarse image and the diagnostics.")
      .def_readonly("document", &Encode2DResult::document, "The version-4 document (one region covering the map).")
      .def_property_readonly(
          "coarse_image",
          [](const Encode2DResult& r) -> py::object {
            if (!r.coarse_image) return py::none();
            return raster_array(*r.coarse_image);
          },
          "The coarse profile c(x, y) the document's region names (float32, rows along y), or None when constant.")
      .def_property_readonly(
          "spec", [](const Encode2DResult& r) { return spec_dict(r.spec); }, "The region's texture as render() keywords.")
      .def_property_readonly("central_pitch_db", [](const Encode2DResult& r) { return r.spec.central_pitch.value(); })
      .def_property_readonly("irregularity_db", [](const Encode2DResult& r) { return r.spec.irregularity.value(); })
      .def_property_readonly("texel_length_mm", [](const Encode2DResult& r) { return r.spec.texel_length.value(); })
      .def_property_readonly(
          "field", [](const Encode2DResult& r) { return std::string(to_string(r.field)); },
          "The region's field design: spectral, cells or oriented.")
      .def_property_readonly(
          "per_direction",
          [](const Encode2DResult& r) {
            py::list l;
            for (const auto& d : r.per_direction) {
              py::dict row;
              row["direction_deg"] = d.direction_deg;
              row["central_pitch_db"] = d.central_pitch_db;
              row["irregularity_db"] = d.irregularity_db;
              row["samples"] = d.samples;
              row["scans"] = d.scans;
              l.append(row);
            }
            return l;
          },
          "Per scan direction: direction_deg, central_pitch_db, irregularity_db (the 1-D encoder's), samples, scans.")
      .def_readonly("central_pitch_spread_db", &Encode2DResult::central_pitch_spread_db, "Max − min over directions (dB).")
      .def_readonly("irregularity_spread_db", &Encode2DResult::irregularity_spread_db)
      .def_readonly("anisotropic", &Encode2DResult::anisotropic)
      .def_readonly("strongest_direction_deg", &Encode2DResult::strongest_direction_deg)
      .def_readonly("mean_central_pitch_db", &Encode2DResult::mean_central_pitch_db)
      .def_readonly("mean_irregularity_db", &Encode2DResult::mean_irregularity_db)
      .def_readonly("irregularity_identifiable", &Encode2DResult::irregularity_identifiable)
      .def_readonly("irregularity_bound_db", &Encode2DResult::irregularity_bound_db)
      .def_readonly("texel_length_detected", &Encode2DResult::texel_length_detected)
      .def_readonly("coarse", &Encode2DResult::coarse)
      .def_readonly("no_texture", &Encode2DResult::no_texture)
      .def_readonly("texture_rms", &Encode2DResult::texture_rms)
      .def_readonly("model_version", &Encode2DResult::model_version)
      .def_property_readonly(
          "target", [](const Encode2DResult& r) { return std::string(codec::to_string(r.target)); },
          "What Central Pitch matched: 'felt' or 'centroid'.")
      .def_readonly("correction_rounds", &Encode2DResult::correction_rounds)
      .def_readonly("correction_residual_db", &Encode2DResult::correction_residual_db)
      .def_readonly("method", &Encode2DResult::method, "'bitmap' or 'scans'.")
      .def(
          "to_json", [](const Encode2DResult& r) { return codec::to_json(r); },
          "The result as JSON text, the library's one serialisation of it.")
      .def(
          "save", [](const Encode2DResult& r, const py::object& path) { codec::write_encoding2d(r, path_of(path)); },
          py::arg("path"),
          "Writes the document (.texel.json) and its coarse image beside it (under coarse_image_path), atomically.")
      .def("__repr__", [](const Encode2DResult& r) {
        return "<texel.Encode2DResult P=" + std::to_string(r.spec.central_pitch.value()) +
               " dB I=" + std::to_string(r.spec.irregularity.value()) + " dB, " + std::string(to_string(r.field)) + ", " +
               std::to_string(r.per_direction.size()) + " directions>";
      });
  // The defaults shown to Python are the library's (one named object: GCC
  // warns about members of temporaries read in default arguments).
  static const codec::Encode2DConfig defaults;
  m.def(
      "encode_2d",
      [](const py::object& source, std::optional<double> pitch_mm, const py::object& device, std::optional<std::string> polarity,
         int directions, std::size_t scan_samples, int correction_rounds, std::optional<std::string> field, bool detect_lattice,
         const std::string& coarse_image_path, std::optional<double> swipe_speed_mm_s, double boundary_mm, double texel_length_mm,
         std::uint64_t seed, const std::string& parameterization, int model, const std::string& target,
         const std::string& no_texture) {
        codec::Encode2DConfig c;
        c.encoder.model = codec::model_defaults(model);
        if (swipe_speed_mm_s) c.encoder.model.swipe_speed = MmPerSecond(*swipe_speed_mm_s);
        c.encoder.boundary = Millimetres(boundary_mm);
        c.encoder.texel_length = Millimetres(texel_length_mm);
        c.encoder.seed = seed;
        c.encoder.parameterization = parse_parameterization(parameterization, "parameterization");
        c.encoder.target = codec::parse_target(target, "target");
        c.encoder.no_texture = codec::parse_no_texture(no_texture, "no_texture");
        c.directions = directions;
        c.scan_samples = scan_samples;
        c.correction_rounds = correction_rounds;
        if (field) c.field = parse_field2d(*field, "field");
        c.detect_lattice = detect_lattice;
        c.coarse_image_path = coarse_image_path;
        std::optional<DeviceProfile> dev;
        if (!device.is_none()) dev = device_of(device, std::nullopt, std::nullopt);
        c.device = dev;
        if (!is_path(source)) {  // an array of amplitudes
          Raster2D map = raster_of(source, pitch_mm.value_or(0.0));
          if (!pitch_mm) {
            if (!dev || !dev->bitmap)
              throw InvalidArgument("an array needs pitch_mm (its pixel spacing) or a device with a bitmap");
            map.pitch = dev->bitmap->pitch;
          }
          py::gil_scoped_release release;
          return codec::encode_surface2d(map, c);
        }
        codec::Raster2DLoadOptions lo;
        if (pitch_mm) lo.pitch = Millimetres(*pitch_mm);
        lo.device = dev;
        if (polarity) lo.polarity = parse_bitmap_polarity(*polarity, "polarity");
        SignalOptions so;
        if (swipe_speed_mm_s) so.swipe_speed = MmPerSecond(*swipe_speed_mm_s);
        if (pitch_mm) so.spacing = Millimetres(*pitch_mm);
        const std::string path = path_of(source);
        py::gil_scoped_release release;
        return codec::encode_2d_file(path, lo, so, c);
      },
      py::arg("source"), py::kw_only(), py::arg("pitch_mm") = py::none(), py::arg("device") = py::none(),
      py::arg("polarity") = py::none(), py::arg("directions") = defaults.directions,
      py::arg("scan_samples") = defaults.scan_samples, py::arg("correction_rounds") = defaults.correction_rounds,
      py::arg("field") = py::none(), py::arg("detect_lattice") = true, py::arg("coarse_image_path") = defaults.coarse_image_path,
      py::arg("swipe_speed_mm_s") = py::none(), py::arg("boundary_mm") = 1.0, py::arg("texel_length_mm") = 0.25,
      py::arg("seed") = std::uint64_t{1}, py::arg("parameterization") = "moments",
      py::arg("model") = defaults.encoder.model.version, py::arg("target") = "automatic", py::arg("no_texture") = "flag",
      R"doc(Encodes a 2-D texture into a version-4 2-D document (one region covering the map) with the 1-D
encoder's perceptual model, as `texel encode map.png` (docs/encoder.md, "2-D inputs").

source            a 2-D array (rows along y; needs pitch_mm or a device with a bitmap), a path to a
                  grey 8/16-bit .png or a 2-D .npy, or a .scans.json bundle of 1-D scans along several
                  directions. An array or .npy with values all in [0, 1] is taken as amplitudes; one
                  with any value outside (a height map, raw counts) is scaled to full range — the rule
                  of every front door (the CLI, C, MEX)
pitch_mm          pixel pitch (mm) [the device's bitmap pitch]
device            the display the document is for (name, path or DeviceProfile) [an inline profile of
                  the map's size]
polarity          how a PNG's levels read: 'darker_more_friction' or 'brighter_more_friction' [the device's]
directions        scan directions over the half turn [18]; scan_samples per direction [16384]
correction_rounds analysis-by-synthesis rounds through the 2-D design [2]
field             'spectral', 'cells' or 'oriented' [automatic: cells when a lattice is found]
detect_lattice    look for a lattice of cell borders (the texel length) [True]
coarse_image_path the coarse image's name as the document gives it (save() writes it there) ['coarse.npy']
swipe_speed_mm_s, boundary_mm, texel_length_mm, seed, parameterization, model, target, no_texture
                  as for encode()

Returns an Encode2DResult (.document, .coarse_image, .per_direction, .anisotropic, .to_json(),
.save(path), ...). The GIL is released while encoding.)doc");
}

}  // namespace texel::python
