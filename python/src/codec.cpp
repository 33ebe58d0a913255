// Binding of the codec (texel/codec.hpp): bitstreams, the transcoder, the
// decoder and the encoder. Inputs are bytes, paths or arrays; signals are
// read by the one loader (signal.cpp: signal_of), and the library does the
// work with the GIL released while it runs.
#include "texel/codec.hpp"
#include "common.hpp"
#include "texel/error.hpp"
#include "texel/signal.hpp"

namespace texel::python {
namespace {

// Bytes from `bytes`, `bytearray`, a uint8 array or a path to a .texel file.
codec::Bitstream bitstream_of(const py::handle& source) {
  if (py::isinstance<codec::Bitstream>(source)) return source.cast<codec::Bitstream>();
  if (py::isinstance<py::bytes>(source) || py::isinstance<py::bytearray>(source)) {
    const auto v = bytes_of(py::module_::import("builtins").attr("bytes")(source).cast<py::bytes>());
    return codec::parse_bitstream(v);
  }
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    const auto v = bytes_of(py::module_::import("pathlib").attr("Path")(source).attr("read_bytes")().cast<py::bytes>());
    return codec::parse_bitstream(v);
  }
  throw py::type_error("expected bytes, a Bitstream or a path to a .texel file");
}

py::dict percept_dict(const codec::Percept& p) {
  py::dict d;
  for (const auto& [name, value] : codec::fields(p)) d[name] = value;
  return d;
}

}  // namespace

void register_codec(py::module_& m) {
  // -------------------------------------------------------------- bitstream
  py::class_<codec::Bitstream>(m, "Bitstream", "A parsed .texel bitstream: the quantized fields it carries (docs/format.md).")
      .def_property_readonly("central_pitch_db", [](const codec::Bitstream& b) { return b.fine.central_pitch_cdb / 100.0; })
      .def_property_readonly("irregularity_db", [](const codec::Bitstream& b) { return b.fine.irregularity_cdb / 100.0; })
      .def_property_readonly("texel_length_mm", [](const codec::Bitstream& b) { return b.fine.texel_length_um / 1000.0; })
      .def_property_readonly("seed", [](const codec::Bitstream& b) { return b.fine.seed; })
      .def_property_readonly(
          "has_coarse", [](const codec::Bitstream& b) { return b.coarse.has_value(); },
          "True when the stream carries strengths and a coarse profile.")
      .def_property_readonly(
          "coarse_levels",
          [](const codec::Bitstream& b) {
            std::vector<std::uint16_t> l;
            if (b.coarse) l = b.coarse->levels;
            return to_numpy(std::move(l));
          },
          "Stored coarse levels (0 … 2^bits − 1); empty when fine only.")
      .def_property_readonly(
          "spec", [](const codec::Bitstream& b) { return spec_dict(codec::to_spec(b)); },
          "The texture the stream stands for, as render() keyword arguments.")
      .def(
          "to_bytes", [](const codec::Bitstream& b) { return to_bytes(codec::write_bitstream(b)); }, "Serializes the stream.")
      .def("__eq__", [](const codec::Bitstream& a, const codec::Bitstream& b) { return a == b; })
      .def("__repr__", [](const codec::Bitstream& b) {
        return "<texel.Bitstream P=" + std::to_string(b.fine.central_pitch_cdb / 100.0) +
               " dB I=" + std::to_string(b.fine.irregularity_cdb / 100.0) + " dB" + (b.coarse ? " +coarse>" : ">");
      });
  m.def(
      "parse_bitstream", [](const py::bytes& data) { return codec::parse_bitstream(bytes_of(data)); }, py::arg("data"),
      "Parses and validates .texel bytes (raises FormatError naming the field).");
  m.def(
      "bitstream_from_document",
      [](const Document& doc, unsigned bits) {
        codec::TranscodeOptions o;
        o.coarse_bits = bits;
        return codec::transcode(doc, o).bitstream;
      },
      py::arg("document"), py::kw_only(), py::arg("bits") = 8u,
      "Quantizes a one-region Texel document to a Bitstream (coarse levels with `bits` bits each); see transcode().");

  // ------------------------------------------------------------- transcoder
  py::class_<codec::Transcoded>(m, "Transcoded", "A document or bitstream transcoded exactly (docs/encoder.md, \"Transcoding\").")
      .def_property_readonly(
          "bytes", [](const codec::Transcoded& t) { return to_bytes(t.bytes); }, "The .texel bitstream.")
      .def_readonly("bitstream", &codec::Transcoded::bitstream)
      .def_property_readonly(
          "spec", [](const codec::Transcoded& t) { return spec_dict(t.spec); },
          "What the bitstream decodes to, as render() keyword arguments.")
      .def_readonly("exact", &codec::Transcoded::exact,
                    "True when decoding renders the document's bytes (every value stored to the bit).")
      .def_readonly("losses", &codec::Transcoded::losses, "Each value the bitstream could not hold; empty when exact.")
      .def("__repr__", [](const codec::Transcoded& t) {
        return "<texel.Transcoded " + std::to_string(t.bytes.size()) + " bytes, " + (t.exact ? "exact>" : "with losses>");
      });
  m.def(
      "transcode",
      [](const py::object& source, std::optional<unsigned> coarse_bits, std::optional<std::size_t> max_bytes,
         const py::object& device) -> codec::Transcoded {
        codec::TranscodeOptions o;
        o.coarse_bits = coarse_bits;
        o.max_bytes = max_bytes;
        if (py::isinstance<Document>(source)) {
          Document doc = source.cast<Document>();
          if (!device.is_none()) doc.device = device_of(device, std::nullopt, std::nullopt);
          return codec::transcode(doc, o);
        }
        if (py::isinstance<py::bytes>(source) || py::isinstance<codec::Bitstream>(source))
          return codec::transcode(bitstream_of(source));
        SignalOptions so;
        if (!device.is_none()) so.device = device_of(device, std::nullopt, std::nullopt);
        std::string why;
        auto t = codec::transcode_file(path_of(source), so, o, &why);
        if (!t) throw InvalidArgument("'" + path_of(source) + "' cannot be transcoded: " + why + " (use encode())");
        return std::move(*t);
      },
      py::arg("source"), py::kw_only(), py::arg("coarse_bits") = py::none(), py::arg("max_bytes") = py::none(),
      py::arg("device") = py::none(),
      R"doc(Transcodes what already holds Texel parameters — a Document, a .texel.json or .texel path,
bitstream bytes or a Bitstream — to a bitstream without estimation: the same parameters at the
bitstream's resolution and the same seed, so decode() renders the document's bytes (`texel encode
DOC` does the same). exact/losses say whether every value was stored to the bit.

coarse_bits  bits per coarse level, 1 … 16 (default: the fewest that are exact, else 16 or 8)
max_bytes    largest bitstream allowed, bytes
device       re-targets a document first (as `texel render DOC --device D`)
Raises InvalidArgument when the source is sample data or not one Texel texture over its device.)doc");

  // ----------------------------------------------------------------- decoder
  m.def(
      "decode_document",
      [](const py::object& source, const py::object& device, std::optional<double> length_mm, std::optional<double> spacing_mm) {
        return codec::decode_document(bitstream_of(source), device_of(device, length_mm, spacing_mm));
      },
      py::arg("source"), py::kw_only(), py::arg("device") = "tpad", py::arg("length_mm") = py::none(),
      py::arg("spacing_mm") = py::none(), "The document a bitstream (bytes, Bitstream or .texel path) stands for on a device.");
  m.def(
      "decode",
      [](const py::object& source, const py::object& device, std::optional<double> length_mm, std::optional<double> spacing_mm,
         const std::string& dtype) {
        const Document doc = codec::decode_document(bitstream_of(source), device_of(device, length_mm, spacing_mm));
        return render_document_array(doc, dtype);
      },
      py::arg("source"), py::kw_only(), py::arg("device") = "tpad", py::arg("length_mm") = py::none(),
      py::arg("spacing_mm") = py::none(), py::arg("dtype") = "native",
      "Decodes a bitstream (bytes, Bitstream or .texel path) and renders it on a device, exactly as\n"
      "`texel decode IN.texel -o map.bin`; dtype as for render().");

  // ----------------------------------------------------------------- encoder
  py::class_<codec::EncodeResult>(m, "EncodeResult",
                                  "What encode() found: the Texel parameters, the bitstream and the model's view.")
      .def_property_readonly(
          "bytes", [](const codec::EncodeResult& r) { return to_bytes(r.bytes); }, "The .texel bitstream.")
      .def_readonly("bitstream", &codec::EncodeResult::bitstream)
      .def_property_readonly(
          "spec", [](const codec::EncodeResult& r) { return spec_dict(r.spec); },
          "The decoded texture as render() keyword arguments.")
      .def_property_readonly("central_pitch_db", [](const codec::EncodeResult& r) { return r.spec.central_pitch.value(); })
      .def_property_readonly("irregularity_db", [](const codec::EncodeResult& r) { return r.spec.irregularity.value(); })
      .def_property_readonly("texel_length_mm", [](const codec::EncodeResult& r) { return r.spec.texel_length.value(); })
      .def_property_readonly("coarse_strength", [](const codec::EncodeResult& r) { return r.spec.coarse_strength; })
      .def_property_readonly("fine_strength", [](const codec::EncodeResult& r) { return r.spec.fine_strength; })
      .def_property_readonly(
          "percept", [](const codec::EncodeResult& r) { return percept_dict(r.input); },
          "The input's fine part under the perceptual model: pitch_db, noisiness_db, centroid_db, spread_db.")
      .def_property_readonly("decoded_percept", [](const codec::EncodeResult& r) { return percept_dict(r.decoded); })
      .def_readonly("distance_jnd", &codec::EncodeResult::model_distance, "Model distance input ↔ decoded (JND units).")
      .def_readonly("model_distance", &codec::EncodeResult::model_distance, "Old name of distance_jnd (kept for a release).")
      .def_readonly("model_version", &codec::EncodeResult::model_version, "The perceptual model that decided (1, 2 or 3).")
      .def_readonly("beyond_felt_band", &codec::EncodeResult::beyond_felt_band,
                    "Share (0 … 1) of the input's power above the felt band (1 kHz at the model's swipe speed).")
      .def_readonly("warnings", &codec::EncodeResult::warnings,
                    "What the user should know about the result, one sentence each (e.g. an input dominated by "
                    "content above the felt band).")
      .def_property_readonly(
          "target", [](const codec::EncodeResult& r) { return std::string(codec::to_string(r.target)); },
          "What Central Pitch matched: 'felt' or 'centroid' (never 'automatic').")
      .def_readonly("no_texture", &codec::EncodeResult::no_texture,
                    "The input has no texture (variation at most 2^-16): a flat surface; P and I are defaults.")
      .def_property_readonly(
          "at_bound",
          [](const codec::EncodeResult& r) {
            return py::dict(py::arg("central_pitch") = r.at_bound.central_pitch,
                            py::arg("irregularity") = r.at_bound.irregularity);
          },
          "Which fitted values ended at an edge of the search box (then not identifiable).")
      .def(
          "to_json", [](const codec::EncodeResult& r) { return codec::to_json(r); },
          "The result as JSON text, as `texel encode --json` prints it (without the input's name).")
      .def_readonly("coarse", &codec::EncodeResult::coarse, "A coarse profile was found.")
      .def_readonly("coarse_correlation", &codec::EncodeResult::coarse_correlation)
      .def_readonly("texel_recovered", &codec::EncodeResult::texel_recovered,
                    "The input was recognised as a Texel rendering (texel length recovered).")
      .def_readonly("irregularity_identifiable", &codec::EncodeResult::irregularity_identifiable)
      .def_readonly("irregularity_bound_db", &codec::EncodeResult::irregularity_bound_db)
      .def_readonly("evaluations", &codec::EncodeResult::evaluations)
      .def_readonly("seconds", &codec::EncodeResult::seconds, "Encoding time (s).")
      .def_readonly("samples", &codec::EncodeResult::samples)
      .def_property_readonly("spacing_mm", [](const codec::EncodeResult& r) { return r.spacing.value(); })
      .def("__repr__", [](const codec::EncodeResult& r) {
        return "<texel.EncodeResult P=" + std::to_string(r.spec.central_pitch.value()) +
               " dB I=" + std::to_string(r.spec.irregularity.value()) + " dB, " + std::to_string(r.bytes.size()) + " bytes>";
      });
  m.def(
      "encode",
      [](const py::object& source, const py::object& device, std::optional<double> spacing_mm,
         std::optional<double> swipe_speed_mm_s, double boundary_mm, double texel_length_mm, std::uint64_t seed,
         const std::string& parameterization, unsigned coarse_bits, std::optional<std::size_t> max_bytes, const std::string& fit,
         const std::string& display_response, double drawn_weight, int model, const std::string& no_texture,
         const std::string& target) {
        codec::EncoderConfig c;
        c.model = codec::model_defaults(model);
        c.no_texture = codec::parse_no_texture(no_texture, "no_texture");
        c.target = codec::parse_target(target, "target");
        if (swipe_speed_mm_s) c.model.swipe_speed = MmPerSecond(*swipe_speed_mm_s);
        c.boundary = Millimetres(boundary_mm);
        c.texel_length = Millimetres(texel_length_mm);
        c.seed = seed;
        c.parameterization = parse_parameterization(parameterization, "parameterization");
        c.coarse_bits = coarse_bits;
        c.max_bytes = max_bytes;
        c.fit_method = codec::parse_fit_method(fit, "fit");
        // The display in the model's loop is the device's, as `texel encode
        // --device`: the given one, or for an array the tpad it defaults to.
        c.model.display_response = codec::parse_display_response(display_response, "display_response");
        c.model.drawn_weight = drawn_weight;
        // An array is on the tpad's grid unless told otherwise.
        const py::object d = device.is_none() && !is_path(source) ? py::str("tpad") : device;
        if (!d.is_none()) c.model.display = device_of(d, std::nullopt, std::nullopt).response;
        const codec::Signal signal = codec::encoder_signal(signal_of(
            source, signal_options(d, spacing_mm, py::none(), swipe_speed_mm_s, py::none(), SignalOptions{}.max_samples)));
        py::gil_scoped_release release;
        return codec::encode(signal, c);
      },
      py::arg("source"), py::kw_only(), py::arg("device") = py::none(), py::arg("spacing_mm") = py::none(),
      py::arg("swipe_speed_mm_s") = py::none(),
      // The encoder's defaults are the library's (EncoderConfig{}, described by visit_options).
      py::arg("boundary_mm") = codec::EncoderConfig{}.boundary.value(),
      py::arg("texel_length_mm") = codec::EncoderConfig{}.texel_length.value(), py::arg("seed") = codec::EncoderConfig{}.seed,
      py::arg("parameterization") = std::string(to_string(codec::EncoderConfig{}.parameterization)),
      py::arg("coarse_bits") = codec::EncoderConfig{}.coarse_bits, py::arg("max_bytes") = codec::EncoderConfig{}.max_bytes,
      py::arg("fit") = std::string(codec::to_string(codec::EncoderConfig{}.fit_method)),
      py::arg("display_response") = std::string(codec::to_string(codec::EncoderConfig{}.model.display_response)),
      py::arg("drawn_weight") = codec::EncoderConfig{}.model.drawn_weight,
      py::arg("model") = codec::EncoderConfig{}.model.version,
      py::arg("no_texture") = std::string(codec::to_string(codec::EncoderConfig{}.no_texture)),
      py::arg("target") = std::string(codec::to_string(codec::EncoderConfig{}.target)),
      R"doc(Encodes a texture signal into Texel parameters and a bitstream, as `texel encode`.

source            a path (.bin .npy .csv .wav .texel.json .texel) or a 1-D array, read by
                  load_signal(): as the .npy file np.save() writes from it, so an array and that
                  file encode alike (float amplitudes 0 … 1 as they are, uint16/uint8 device
                  samples, anything outside [0, 1] scaled to full range)
device            grid and format of .bin/.npy input and of arrays (default tpad)
spacing_mm        sample spacing of arrays / .bin / .npy (mm) [the device's]
swipe_speed_mm_s  swipe speed of time recordings and of the perceptual model (mm/s) [100]
boundary_mm       fine/coarse boundary (mm) [1]
texel_length_mm   texel length of the encoding (mm) [0.25]
seed              seed written to the bitstream [1]
parameterization  'moments' or 'log' ['moments']
coarse_bits       bits per coarse level, 1 … 16 [6]
max_bytes         bitstream budget (bytes) [none]
fit               search of the perceptual fit: 'least-squares' or 'simplex' (slower) ['least-squares']
display_response  'device': the model feels the texture through the device's frequency response (the
                  given device's; for an array, the tpad it defaults to; a path without `device`
                  has none), or 'flat': as drawn ['device']
drawn_weight      weight of the texture as drawn beside the displayed one in the fit (0: the display
                  alone) [1]
model             perceptual model version: 2, 3 (version 2 within the felt band) or 1 (the model
                  before) [2]
no_texture        an input without texture: 'flag' (a flat surface, result.no_texture) or 'refuse'
                  (InvalidArgument) ['flag']
target            what Central Pitch matches: 'felt' (the model's felt pitch), 'centroid' (the input's
                  log-spectral centroid: the decoded texture swiped at swipe_speed_mm_s) or 'automatic'
                  (centroid for time recordings such as .wav, felt for maps and arrays) ['automatic']

The GIL is released while encoding.)doc");
}

}  // namespace texel::python
