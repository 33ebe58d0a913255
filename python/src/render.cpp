// Binding of the core: device profiles, Texel texture parameters, coarse
// profiles, documents, references, and rendering to numpy arrays. Every
// function builds the library's own structs and calls the library
// (make_document / prepare_surface / Surface::render*), like `texel render`.
#include <cmath>
#include <map>
#include <variant>

#include "common.hpp"
#include "texel/error.hpp"
#include "texel/reference.hpp"
#include "texel/surface.hpp"

namespace texel::python {
namespace {

py::dtype dtype_of(SampleFormat f) {
  switch (f) {
    case SampleFormat::u16le: return py::dtype("<u2");
    case SampleFormat::u8: return py::dtype("u1");
    case SampleFormat::f32le: return py::dtype("<f4");
    case SampleFormat::f64le: return py::dtype("<f8");
  }
  return py::dtype("<f8");
}

// The keyword arguments of a Texel texture, mirroring the document fields
// (docs/format.md) with units in their names; defaults are TexelSpec's.
// The defaults are the library's (TexelSpec{}, described by visit_options).
#define TEXEL_SPEC_ARGS                                                                                                         \
  py::arg("central_pitch_db") = TexelSpec{}.central_pitch.value(),                                                              \
  py::arg("irregularity_db") = TexelSpec{}.irregularity.value(), py::arg("texel_length_mm") = TexelSpec{}.texel_length.value(), \
  py::arg("seed") = TexelSpec{}.seed, py::arg("parameterization") = std::string(to_string(TexelSpec{}.parameterization)),       \
  py::arg("out_of_band") = std::string(to_string(TexelSpec{}.out_of_band)),                                                     \
  py::arg("band_min_cpm") = TexelSpec{}.band_min.value(), py::arg("band_max_cpm") = TexelSpec{}.band_max.value(),               \
  py::arg("quantization_db") = TexelSpec{}.quantization_db, py::arg("phase") = std::string(to_string(TexelSpec{}.phase)),       \
  py::arg("fill") = std::string(to_string(TexelSpec{}.fill)), py::arg("coarse_strength") = TexelSpec{}.coarse_strength,         \
  py::arg("fine_strength") = TexelSpec{}.fine_strength, py::arg("coarse") = py::none()

TexelSpec make_spec(double central_pitch_db, double irregularity_db, double texel_length_mm, std::uint64_t seed,
                    const std::string& parameterization, const std::string& out_of_band, double band_min_cpm, double band_max_cpm,
                    double quantization_db, const std::string& phase, const std::string& fill, double coarse_strength,
                    double fine_strength, const std::optional<CoarseProfile>& coarse) {
  TexelSpec s;
  s.central_pitch = Decibels(central_pitch_db);
  s.irregularity = Decibels(irregularity_db);
  s.texel_length = Millimetres(texel_length_mm);
  s.seed = seed;
  s.parameterization = parse_parameterization(parameterization, "parameterization");
  s.out_of_band = parse_out_of_band(out_of_band, "out_of_band");
  s.band_min = CyclesPerMm(band_min_cpm);
  s.band_max = CyclesPerMm(band_max_cpm);
  s.quantization_db = quantization_db;
  s.phase = parse_phase_mode(phase, "phase");
  s.fill = parse_fill(fill, "fill");
  s.coarse_strength = coarse_strength;
  s.fine_strength = fine_strength;
  if (coarse) s.coarse = *coarse;
  validate(s);
  return s;
}

ReferenceValue reference_value_of(const ReferenceInfo& info, const std::string& key, const py::handle& v) {
  if (py::isinstance<py::str>(v)) return parse_reference_value(info, key, v.cast<std::string>());
  if (py::isinstance<py::bool_>(v)) throw InvalidArgument("reference parameter '" + key + "' is a bool; give a number");
  if (py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)) return v.cast<double>();
  if (py::hasattr(v, "__float__") && !py::hasattr(v, "__len__")) return v.cast<double>();  // numpy scalars
  return v.cast<std::vector<double>>();
}

ReferenceSpec reference_spec(const std::string& name, std::uint64_t seed, const py::kwargs& params) {
  ReferenceSpec spec;
  spec.name = name;
  const ReferenceInfo& info = reference_info(name);
  for (const auto& [k, v] : params) {
    const auto key = k.cast<std::string>();
    spec.params[key] = reference_value_of(info, key, v);
  }
  spec.seed = seed;
  validate(spec);
  return spec;
}

py::object reference_value_py(const ReferenceValue& v) {
  return std::visit([](const auto& x) -> py::object { return py::cast(x); }, v);
}

py::dict reference_info_dict(const ReferenceInfo& info) {
  py::list params;
  for (const auto& p : info.params) {
    py::dict d;
    d["key"] = p.key;
    static const char* kinds[] = {"number", "integer", "list", "choice"};
    d["kind"] = kinds[static_cast<int>(p.kind)];
    d["unit"] = p.unit;
    d["default"] = reference_value_py(p.default_value);
    d["min"] = p.min;
    d["max"] = p.max;
    if (p.kind == ReferenceParamKind::list) {
      d["min_count"] = p.min_count;
      d["max_count"] = p.max_count;
    }
    if (p.kind == ReferenceParamKind::choice) d["choices"] = p.choices;
    d["description"] = p.description;
    params.append(d);
  }
  py::dict d;
  d["name"] = info.name;
  d["family"] = info.family;
  d["description"] = info.description;
  d["uses_seed"] = info.uses_seed;
  d["params"] = params;
  return d;
}

py::dict region_dict(const RegionSpec& r) {
  py::dict d;
  d["name"] = r.name;
  d["start_mm"] = r.start.value();
  d["length_mm"] = r.length ? py::cast(r.length->value()) : py::none();
  if (r.reference) {
    d["kind"] = "reference";
    d["reference"] = r.reference->name;
    d["seed"] = r.reference->seed;
    py::dict params;
    for (const auto& [k, v] : r.reference->params) params[py::str(k)] = reference_value_py(v);
    d["params"] = params;
  } else {
    d["kind"] = "texel";
    d["texel"] = spec_dict(r.texel);
  }
  return d;
}

}  // namespace

DeviceProfile device_of(const py::handle& device, std::optional<double> length_mm, std::optional<double> spacing_mm) {
  DeviceProfile d =
      py::isinstance<DeviceProfile>(device) ? device.cast<DeviceProfile>() : load_device(device.cast<std::string>());
  return with_grid(std::move(d), millimetres(length_mm), millimetres(spacing_mm));
}

py::dict spec_dict(const TexelSpec& s) {
  py::dict d;
  d["central_pitch_db"] = s.central_pitch.value();
  d["irregularity_db"] = s.irregularity.value();
  d["texel_length_mm"] = s.texel_length.value();
  d["seed"] = s.seed;
  d["parameterization"] = std::string(to_string(s.parameterization));
  d["out_of_band"] = std::string(to_string(s.out_of_band));
  d["band_min_cpm"] = s.band_min.value();
  d["band_max_cpm"] = s.band_max.value();
  d["quantization_db"] = s.quantization_db;
  d["phase"] = std::string(to_string(s.phase));
  d["fill"] = std::string(to_string(s.fill));
  d["coarse_strength"] = s.coarse_strength;
  d["fine_strength"] = s.fine_strength;
  d["coarse"] = std::visit([](const auto& p) { return py::cast(p); }, s.coarse);
  return d;
}

py::array render_document_array(const Document& doc, const std::string& dtype) {
  std::optional<SampleFormat> format;
  if (dtype == "native")
    format = doc.device.format;
  else if (dtype == "uint16")
    format = SampleFormat::u16le;
  else if (dtype == "uint8")
    format = SampleFormat::u8;
  else if (dtype == "float32")
    format = SampleFormat::f32le;
  else if (dtype != "float64")
    throw InvalidArgument("dtype is '" + dtype +
                          "'; allowed: native (the device's sample format), float64 (amplitudes 0 … 1), uint16, uint8, float32");
  if (!format) {
    std::vector<double> map;
    {
      py::gil_scoped_release release;
      map = prepare_surface(doc).render();
    }
    return to_numpy(std::move(map));
  }
  std::vector<std::byte> bytes;
  {
    py::gil_scoped_release release;
    bytes = prepare_surface(doc).render_native(*format);
  }
  return bytes_as_numpy(std::move(bytes), dtype_of(*format));
}

void register_render(py::module_& m) {
  // ---------------------------------------------------------------- devices
  py::class_<DeviceProfile>(m, "DeviceProfile", "A device profile: sample grid, value format, refresh rate and band.")
      .def_readonly("name", &DeviceProfile::name)
      .def_readonly("description", &DeviceProfile::description)
      .def_readonly("samples", &DeviceProfile::samples, "Samples along the active length.")
      .def_property_readonly(
          "spacing_mm", [](const DeviceProfile& d) { return d.spacing.value(); }, "Sample spacing Δx (mm).")
      .def_property_readonly(
          "format", [](const DeviceProfile& d) { return std::string(to_string(d.format)); },
          "Native sample format: u16le, u8, f32le or f64le.")
      .def_property_readonly(
          "refresh_hz", [](const DeviceProfile& d) { return d.refresh.value(); }, "Output update rate while playing (Hz).")
      .def_property_readonly(
          "band_min_cpm", [](const DeviceProfile& d) { return d.band_min.value(); }, "Lowest renderable frequency (cycles/mm).")
      .def_property_readonly(
          "band_max_cpm", [](const DeviceProfile& d) { return d.band_max.value(); },
          "Highest renderable frequency (cycles/mm); 0 = Nyquist.")
      .def_property_readonly(
          "length_mm", [](const DeviceProfile& d) { return d.length().value(); }, "Active length (mm).")
      .def_property_readonly(
          "nyquist_cpm", [](const DeviceProfile& d) { return d.nyquist().value(); },
          "Spatial Nyquist frequency 1/(2Δx) (cycles/mm).")
      .def_property_readonly(
          "positions_mm",
          [](const DeviceProfile& d) {
            std::vector<double> x(static_cast<std::size_t>(d.samples));
            for (std::size_t i = 0; i < x.size(); ++i) x[i] = d.grid().position(static_cast<std::int64_t>(i)).value();
            return to_numpy(std::move(x));
          },
          "Position of every sample (mm).")
      .def("to_json", &device_profile_json, "The profile as JSON text (the device file schema).")
      .def("__repr__", [](const DeviceProfile& d) {
        return "<texel.DeviceProfile '" + d.name + "': " + std::to_string(d.samples) + " samples>";
      });
  m.def("device", &device_of, py::arg("name_or_path") = "tpad", py::kw_only(), py::arg("length_mm") = py::none(),
        py::arg("spacing_mm") = py::none(),
        "A device profile by built-in name (tpad, tpad-tablet, generic), TEXEL_DEVICE_PATH name or JSON path,\n"
        "optionally with its active length (mm) and/or sample spacing (mm) overridden.");
  m.def("builtin_devices", &builtin_device_names, "Names of the built-in device profiles.");

  // ------------------------------------------------------- coarse profiles
  py::class_<ConstantProfile>(m, "ConstantProfile", "Coarse profile c = value everywhere (value in [0, 1]).")
      .def(py::init([](double value) { return ConstantProfile{value}; }), py::arg("value") = 1.0)
      .def_readwrite("value", &ConstantProfile::value)
      .def("__repr__", [](const ConstantProfile& p) { return "ConstantProfile(value=" + std::to_string(p.value) + ")"; });
  py::class_<SineProfile>(m, "SineProfile", "Coarse profile c(x) = 0.5 + 0.5·sin(2π(x/period_mm + phase_deg/360)).")
      .def(py::init([](double period_mm, double phase_deg) {
             return SineProfile{Millimetres(period_mm), phase_deg};
           }),
           py::arg("period_mm") = 5.0, py::arg("phase_deg") = 0.0)
      .def_property(
          "period_mm", [](const SineProfile& p) { return p.period.value(); },
          [](SineProfile& p, double v) { p.period = Millimetres(v); }, "Period (mm), > 0.")
      .def_readwrite("phase_deg", &SineProfile::phase_deg, "Phase (degrees).")
      .def("__repr__", [](const SineProfile& p) {
        return "SineProfile(period_mm=" + std::to_string(p.period.value()) + ", phase_deg=" + std::to_string(p.phase_deg) + ")";
      });
  py::class_<ValuesProfile>(m, "ValuesProfile", "Coarse profile with one value in [0, 1] per texel.")
      .def(py::init([](std::vector<double> values) { return ValuesProfile{std::move(values)}; }), py::arg("values"))
      .def_readwrite("values", &ValuesProfile::values);
  py::class_<PointsProfile>(m, "PointsProfile",
                            "Coarse profile through (position_mm, value) points, linear in between, flat beyond the ends.")
      .def(py::init([](std::vector<std::pair<double, double>> points) { return PointsProfile{std::move(points)}; }),
           py::arg("points"))
      .def_readwrite("points", &PointsProfile::points);
  py::class_<SampledProfile>(m, "SampledProfile",
                             "Coarse profile sampled every spacing_mm from position 0 (linear interpolation).")
      .def(py::init([](double spacing_mm, std::vector<double> values) {
             return SampledProfile{Millimetres(spacing_mm), std::move(values)};
           }),
           py::arg("spacing_mm"), py::arg("values"))
      .def_property(
          "spacing_mm", [](const SampledProfile& p) { return p.spacing.value(); },
          [](SampledProfile& p, double v) { p.spacing = Millimetres(v); })
      .def_readwrite("values", &SampledProfile::values);
  m.def("read_profile_csv", &read_profile_csv, py::arg("path"), "Reads a CSV of position_mm,value rows as a PointsProfile.");

  // ------------------------------------------------------------- documents
  py::class_<Document>(m, "Document", "A texture document (*.texel.json): device, regions and their textures.")
      .def_readonly("version", &Document::version)
      .def_readwrite("description", &Document::description)
      .def_readonly("device", &Document::device)
      .def_property_readonly(
          "regions",
          [](const Document& d) {
            py::list l;
            for (const auto& r : d.regions) l.append(region_dict(r));
            return l;
          },
          "The regions as dicts (name, start_mm, length_mm, kind, and the texel spec or reference).")
      .def("to_json", &document_json, "The document as JSON text (the *.texel.json format).")
      .def("save", &save_document, py::arg("path"), "Writes the document atomically (temporary file + rename).")
      .def("render", &render_document_array, py::kw_only(), py::arg("dtype") = "native",
           "The whole map: dtype 'native' (the device's sample format, e.g. uint16 for tpad; the .bin bytes),\n"
           "'float64' (amplitudes 0 … 1), 'uint16', 'uint8' or 'float32'.")
      .def("__repr__", [](const Document& d) {
        if (d.surface2d)
          return "<texel.Document on '" + d.device.name + "', 2-D, " + std::to_string(d.surface2d->regions.size()) +
                 " region(s)>";
        return "<texel.Document on '" + d.device.name + "', " + std::to_string(d.regions.size()) + " region(s)>";
      });
  m.def("load_document", &load_document, py::arg("path"), "Loads and validates a *.texel.json document.");
  m.def("parse_document", &parse_document, py::arg("json_text"), py::arg("origin") = "document",
        "Parses and validates document JSON text; `origin` names the source in errors.");
  m.def("save_document", &save_document, py::arg("document"), py::arg("path"), "Writes a document atomically.");
  m.def("document_json", &document_json, py::arg("document"), "A document as JSON text.");
  m.def(
      "document",
      [](double cp, double irr, double l, std::uint64_t seed, const std::string& par, const std::string& oob, double bmin,
         double bmax, double q, const std::string& phase, const std::string& fill, double c, double f,
         const std::optional<CoarseProfile>& coarse, const py::object& device, std::optional<double> length_mm,
         std::optional<double> spacing_mm, const std::string& description) {
        Document doc = make_document(device_of(device, length_mm, spacing_mm),
                                     make_spec(cp, irr, l, seed, par, oob, bmin, bmax, q, phase, fill, c, f, coarse));
        doc.description = description;
        return doc;
      },
      py::kw_only(), TEXEL_SPEC_ARGS, py::arg("device") = "tpad", py::arg("length_mm") = py::none(),
      py::arg("spacing_mm") = py::none(), py::arg("description") = "",
      "A document holding one Texel texture over the whole device (see render() for the parameters).");
  m.def("render_document", &render_document_array, py::arg("document"), py::kw_only(), py::arg("dtype") = "native",
        "Renders a document's whole map (see Document.render).");

  // -------------------------------------------------------------- rendering
  m.def(
      "render",
      [](double cp, double irr, double l, std::uint64_t seed, const std::string& par, const std::string& oob, double bmin,
         double bmax, double q, const std::string& phase, const std::string& fill, double c, double f,
         const std::optional<CoarseProfile>& coarse, const py::object& device, std::optional<double> length_mm,
         std::optional<double> spacing_mm, const std::string& dtype) {
        const Document doc = make_document(device_of(device, length_mm, spacing_mm),
                                           make_spec(cp, irr, l, seed, par, oob, bmin, bmax, q, phase, fill, c, f, coarse));
        return render_document_array(doc, dtype);
      },
      py::kw_only(), TEXEL_SPEC_ARGS, py::arg("device") = "tpad", py::arg("length_mm") = py::none(),
      py::arg("spacing_mm") = py::none(), py::arg("dtype") = "native",
      R"doc(Renders a Texel texture over a whole device, exactly as `texel render -o map.bin`.

central_pitch_db   Central Pitch, dB re 1 cycle/mm (10 dB = 10 cpm) [10]
irregularity_db    Irregularity, dB re 1 cycle/mm [-5]
texel_length_mm    texel length L, mm, > 0 [0.25]
seed               random seed, 0 … 2^64-1 [1]
parameterization   'moments' (mean/SD in cpm) or 'log' (median, SD of 10·log10 f) ['moments']
out_of_band        'redraw' or 'clamp' draws outside the band ['redraw']
band_min_cpm       lowest texel frequency, cycles/mm [0.01]
band_max_cpm       highest texel frequency, cycles/mm (0 = the grid's Nyquist) [0]
quantization_db    frequency quantization step, dB (0 = off) [0]
phase              'continuous' or 'reset' ['continuous']
fill               'whole' texels only or 'partial' final texel ['whole']
coarse_strength    coarse strength C, 0 … 1 [0]
fine_strength      fine strength F, 0 … 1 [1]
coarse             coarse profile: ConstantProfile, SineProfile, ValuesProfile, PointsProfile,
                   SampledProfile or None (constant 1) [None]
device             device name or path, or a DeviceProfile ['tpad']
length_mm, spacing_mm  grid overrides (mm) [device's]
dtype              'native' (device format: uint16 for tpad, the .bin bytes), 'float64'
                   (amplitudes 0 … 1), 'uint16', 'uint8' or 'float32' ['native']

Returns a 1-D numpy array owning its buffer (no copy). The GIL is released while rendering.)doc");
  m.def(
      "texels",
      [](const Document& doc) {
        std::vector<double> start, freq, phase, env;
        std::vector<std::int64_t> region;
        const Surface surface = prepare_surface(doc);
        for (std::size_t r = 0; r < surface.regions().size(); ++r) {
          const auto& reg = surface.regions()[r];
          const auto* t = dynamic_cast<const TexelTexture*>(reg.texture.get());
          if (!t) continue;
          for (const Texel& x : t->texels()) {
            start.push_back(reg.start.value() + x.start.value());
            freq.push_back(x.frequency.value());
            phase.push_back(x.phase_cycles);
            env.push_back(x.envelope);
            region.push_back(static_cast<std::int64_t>(r));
          }
        }
        py::dict d;
        d["start_mm"] = to_numpy(std::move(start));
        d["frequency_cpm"] = to_numpy(std::move(freq));
        d["phase_cycles"] = to_numpy(std::move(phase));
        d["envelope"] = to_numpy(std::move(env));
        d["region"] = to_numpy(std::move(region));
        return d;
      },
      py::arg("document"),
      "The texels of a document's Texel regions as numpy columns: start_mm (device mm), frequency_cpm,\n"
      "phase_cycles, envelope (amplitude e_k) and region (index).");

  // ------------------------------------------------------------ references
  m.def(
      "reference",
      [](const std::string& name, const py::object& device, std::uint64_t seed, std::optional<double> length_mm,
         std::optional<double> spacing_mm, const std::string& dtype, const py::kwargs& params) {
        const ReferenceSpec spec = reference_spec(name, seed, params);
        Document doc = make_reference_document(device_of(device, length_mm, spacing_mm), spec);
        return render_document_array(doc, dtype);
      },
      py::arg("name"), py::kw_only(), py::arg("device") = "tpad", py::arg("seed") = std::uint64_t{1},
      py::arg("length_mm") = py::none(), py::arg("spacing_mm") = py::none(), py::arg("dtype") = "native",
      R"doc(Renders a reference texture over a whole device, exactly as `texel reference NAME -o map.bin`.

name      generator name (reference_names(); e.g. '4sin', 'pink', 'bandpass-f5-z0.5')
device    device name or path, or a DeviceProfile ['tpad']
seed      random seed of the seeded references [1]
dtype     as for render() ['native']
**params  generator parameters by key, units in the key (e.g. frequencies_cpm=[2.5, 6]);
          numbers, lists of numbers, or text as for --param KEY=VALUE

The GIL is released during synthesis.)doc");
  m.def(
      "reference_document",
      [](const std::string& name, const py::object& device, std::uint64_t seed, std::optional<double> length_mm,
         std::optional<double> spacing_mm, const py::kwargs& params) {
        return make_reference_document(device_of(device, length_mm, spacing_mm), reference_spec(name, seed, params));
      },
      py::arg("name"), py::kw_only(), py::arg("device") = "tpad", py::arg("seed") = std::uint64_t{1},
      py::arg("length_mm") = py::none(), py::arg("spacing_mm") = py::none(),
      "A document holding one reference texture over the whole device (parameters as for reference()).");
  m.def(
      "reference_names",
      [] {
        std::vector<std::string> names;
        for (const auto& i : reference_catalogue()) names.push_back(i.name);
        return names;
      },
      "Names of every reference generator, in listing order.");
  m.def(
      "reference_info", [](const std::string& name) { return reference_info_dict(reference_info(name)); }, py::arg("name"),
      "A generator's family, description and parameters (key, kind, unit, default, range).");
}

}  // namespace texel::python
