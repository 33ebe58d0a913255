// Binding of the codec (bitstreams, encoder, decoder) and the spectral
// analysis. Inputs are numpy arrays or paths; the library does the work
// (codec::load_signal, codec::encode, codec::decode_document,
// analyse_spectrum), with the GIL released while it runs.
#include <cstring>

#include "common.hpp"
#include "texel/codec.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/signal.hpp"
#include "texel/spectrum.hpp"

namespace texel::python {
namespace {

std::vector<std::byte> bytes_of(const py::bytes& b) {
  const auto s = std::as_bytes(std::span(std::string_view(b)));
  return {s.begin(), s.end()};
}

py::bytes to_bytes(std::span<const std::byte> v) { return py::bytes(reinterpret_cast<const char*>(v.data()), v.size()); }

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

// The library options of a load_signal()/encode() call (texel/signal.hpp).
SignalOptions signal_options(const py::object& device, std::optional<double> spacing_mm, const py::object& region,
                             std::optional<double> swipe_speed, const py::object& channel, std::size_t max_samples) {
  SignalOptions o;
  if (!device.is_none()) o.device = device_of(device, std::nullopt, std::nullopt);
  if (spacing_mm) o.spacing = Millimetres(*spacing_mm);
  if (swipe_speed) o.swipe_speed = MmPerSecond(*swipe_speed);
  if (py::isinstance<py::str>(region)) {
    o.region = SignalOptions::Region{region.cast<std::string>(), {}, {}};
  } else if (!region.is_none()) {
    const auto span = region.cast<std::pair<double, double>>();
    o.region = SignalOptions::Region{"", Millimetres(span.first), Millimetres(span.second)};
  }
  if (py::isinstance<py::str>(channel)) {
    if (channel.cast<std::string>() != "mix")
      throw InvalidArgument("channel is '" + channel.cast<std::string>() + "'; allowed: an index or 'mix'");
    o.channels = ChannelPolicy::mix;
  } else if (!channel.is_none()) {
    o.channels = ChannelPolicy::select;
    o.channel = channel.cast<unsigned>();
  }
  o.max_samples = max_samples;
  return o;
}

std::string path_of(const py::handle& source) {
  return py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
}

// The signal an encode() call describes: a path (any format load_signal
// reads) or an array of amplitudes (float, 0 … 1) or device samples
// (uint16 / uint8, decoded with the library's decode_samples).
codec::Signal signal_of(const py::handle& source, const py::object& device, std::optional<double> spacing_mm,
                        std::optional<double> swipe_speed) {
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    const SignalOptions o = signal_options(device, spacing_mm, py::none(), swipe_speed, py::none(), SignalOptions{}.max_samples);
    const std::string path = path_of(source);
    py::gil_scoped_release release;
    return codec::encoder_signal(codec::load_signal(path, o));
  }
  const DeviceProfile d = device.is_none() ? load_device("tpad") : device_of(device, std::nullopt, std::nullopt);
  codec::Signal s;
  s.spacing = Millimetres(spacing_mm.value_or(d.spacing.value()));
  s.description = "array";
  const py::array a = py::array::ensure(source);
  if (!a) throw py::type_error("encode: source must be a path or a 1-D array");
  if (a.dtype().is(py::dtype::of<std::uint16_t>()) || a.dtype().is(py::dtype::of<std::uint8_t>())) {
    const bool u16 = a.dtype().itemsize() == 2;
    const auto c = py::array::ensure(a, py::array::c_style);
    if (c.ndim() != 1) throw py::value_error("encode: source must be 1-D");
    const auto* p = static_cast<const std::byte*>(c.data());
    s.amplitude = decode_samples(u16 ? SampleFormat::u16le : SampleFormat::u8,
                                 std::span<const std::byte>(p, static_cast<std::size_t>(c.nbytes())));
  } else {
    s.amplitude = as_doubles(source, "encode: source");
  }
  return s;
}

SpectrumOptions spectrum_options(const std::string& window, int zero_pad, bool remove_mean) {
  SpectrumOptions o;
  o.window = parse_window(window, "window");
  o.zero_pad = zero_pad;
  o.remove_mean = remove_mean;
  return o;
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

  // ----------------------------------------------------------------- signals
  py::class_<Signal>(m, "Signal", "A texture signal as texel::load_signal read it: samples on a uniform grid.")
      .def_property_readonly(
          "samples",
          [](py::object self) {
            const auto& s = self.cast<const Signal&>();
            // Zero copy: the array keeps the Signal alive.
            py::array_t<double> a(static_cast<py::ssize_t>(s.samples.size()), s.samples.data(), self);
            a.attr("setflags")(py::arg("write") = false);
            return a;
          },
          "Amplitudes, 0 … 1 (read-only view)")
      .def_property_readonly("spacing_mm", [](const Signal& s) { return s.spacing.value(); })
      .def_property_readonly("origin_mm", [](const Signal& s) { return s.origin.value(); })
      .def_property_readonly("length_mm", [](const Signal& s) { return s.length().value(); })
      .def_property_readonly("format", [](const Signal& s) { return std::string(to_string(s.format)); })
      .def_property_readonly("scaled", [](const Signal& s) { return s.scaled; })
      .def_property_readonly("sample_rate_hz",
                             [](const Signal& s) -> std::optional<double> {
                               if (s.sample_rate) return s.sample_rate->value();
                               return std::nullopt;
                             })
      .def_readonly("description", &Signal::description)
      .def("__len__", [](const Signal& s) { return s.samples.size(); })
      .def("__repr__", [](const Signal& s) {
        return "<texel.Signal " + std::string(to_string(s.format)) + ", " + std::to_string(s.samples.size()) + " samples × " +
               std::to_string(s.spacing.value()) + " mm>";
      });
  m.def(
      "load_signal",
      [](const py::object& path, const py::object& device, std::optional<double> spacing_mm, const py::object& region,
         std::optional<double> swipe_speed_mm_s, const py::object& channel, std::size_t max_samples) {
        const SignalOptions o = signal_options(device, spacing_mm, region, swipe_speed_mm_s, channel, max_samples);
        const std::string p = path_of(path);
        py::gil_scoped_release release;
        return codec::load_signal(p, o);
      },
      py::arg("path"), py::kw_only(), py::arg("device") = py::none(), py::arg("spacing_mm") = py::none(),
      py::arg("region") = py::none(), py::arg("swipe_speed_mm_s") = py::none(), py::arg("channel") = py::none(),
      py::arg("max_samples") = SignalOptions{}.max_samples,
      R"doc(Reads any texture signal file with the library's one loader (the same samples `texel info`,
`texel spectrum` and `texel encode` see).

path              .bin (needs device), .npy (device or spacing_mm), .csv (position_mm,amplitude or
                  time_s,value), .wav (swipe_speed_mm_s), .mat, .texel.json, .texel (needs device)
device            a device name, profile path or Device: grid and sample format of a .bin
spacing_mm        sample spacing, mm; must agree with a file's own grid
region            (start_mm, end_mm), or a document region's name or index
swipe_speed_mm_s  turns a time recording into positions
channel           a multi-channel recording's channel index, or "mix" (default: mono files only)
max_samples       largest size a file may declare, checked before allocating
Raises InvalidArgument naming the keyword, FormatError or IoError naming the file.)doc");

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
      .def_readonly("model_version", &codec::EncodeResult::model_version, "The perceptual model that decided (1 or 2).")
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
         const std::string& display_response, double drawn_weight, int model, const std::string& no_texture) {
        codec::EncoderConfig c;
        c.model = codec::model_defaults(model);
        c.no_texture = codec::parse_no_texture(no_texture, "no_texture");
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
        const bool path = py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__");
        if (!device.is_none())
          c.model.display = device_of(device, std::nullopt, std::nullopt).response;
        else if (!path)
          c.model.display = load_device("tpad").response;
        const codec::Signal signal = signal_of(source, device, spacing_mm, swipe_speed_mm_s);
        py::gil_scoped_release release;
        return codec::encode(signal, c);
      },
      py::arg("source"), py::kw_only(), py::arg("device") = py::none(), py::arg("spacing_mm") = py::none(),
      py::arg("swipe_speed_mm_s") = py::none(), py::arg("boundary_mm") = 1.0, py::arg("texel_length_mm") = 0.25,
      py::arg("seed") = std::uint64_t{1}, py::arg("parameterization") = "moments", py::arg("coarse_bits") = 6u,
      py::arg("max_bytes") = py::none(), py::arg("fit") = "least-squares", py::arg("display_response") = "device",
      py::arg("drawn_weight") = codec::PerceptualModel{}.drawn_weight, py::arg("model") = codec::PerceptualModel{}.version,
      py::arg("no_texture") = "flag",
      R"doc(Encodes a texture signal into Texel parameters and a bitstream, as `texel encode`.

source            a path (.bin .npy .csv .wav .texel.json .texel) or a 1-D array: float amplitudes
                  0 … 1, or uint16/uint8 device samples
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
model             perceptual model version: 2, or 1 (the model before) [2]
no_texture        an input without texture: 'flag' (a flat surface, result.no_texture) or 'refuse'
                  (InvalidArgument) ['flag']

The GIL is released while encoding.)doc");

  // ---------------------------------------------------------------- spectrum
  py::class_<Spectrum>(m, "Spectrum", "One-sided magnitude spectrum on bins k·bin_cpm.")
      .def_readonly("bin_cpm", &Spectrum::bin_cpm, "Bin spacing (cycles/mm).")
      .def_readonly("resolution_cpm", &Spectrum::resolution_cpm, "1 / signal length (cycles/mm).")
      .def_readonly("samples", &Spectrum::samples)
      .def_readonly("nfft", &Spectrum::nfft)
      .def_property_readonly(
          "frequency_cpm", [](const Spectrum& s) { return py::array_t<double>(s.frequency_cpm.size(), s.frequency_cpm.data()); },
          "Bin frequencies (cycles/mm).")
      .def_property_readonly(
          "magnitude", [](const Spectrum& s) { return py::array_t<double>(s.magnitude.size(), s.magnitude.data()); },
          "Amplitude-calibrated |X_k| (a sinusoid of amplitude A peaks at A).")
      .def_property_readonly(
          "power", [](const Spectrum& s) { return py::array_t<double>(s.power.size(), s.power.data()); },
          "Mean-square amplitude per bin (sums to the variance).");
  m.def(
      "magnitude_spectrum",
      [](const py::object& samples, double spacing_mm, const std::string& window, int zero_pad, bool remove_mean) {
        const auto x = as_doubles(samples, "samples");
        const auto o = spectrum_options(window, zero_pad, remove_mean);
        py::gil_scoped_release release;
        return magnitude_spectrum(x, spacing_mm, o);
      },
      py::arg("samples"), py::arg("spacing_mm"), py::kw_only(), py::arg("window") = "blackman-harris", py::arg("zero_pad") = 4,
      py::arg("remove_mean") = true,
      "Magnitude spectrum of amplitudes sampled every spacing_mm (mm); window rectangular | hann |\n"
      "blackman-harris | flat-top, zero_pad 1 … 16.");
  m.def(
      "analyse_spectrum",
      [](const py::object& samples, double spacing_mm) {
        const auto x = as_doubles(samples, "samples");
        SpectralReport r;
        {
          py::gil_scoped_release release;
          r = analyse_spectrum(x, spacing_mm);
        }
        py::dict d;
        d["spectrum"] = py::cast(std::move(r.spectrum));
        py::dict psd;
        psd["bin_cpm"] = r.psd.bin_cpm;
        psd["segment"] = r.psd.segment;
        psd["segments"] = r.psd.segments;
        psd["frequency_cpm"] = to_numpy(std::move(r.psd.frequency_cpm));
        psd["density"] = to_numpy(std::move(r.psd.density));
        d["psd"] = psd;
        py::list peaks;
        for (const Peak& p : r.peaks) {
          py::dict pd;
          pd["frequency_cpm"] = p.frequency.value();
          pd["amplitude"] = p.amplitude;
          pd["level_db"] = p.level.value();
          peaks.append(pd);
        }
        d["peaks"] = peaks;
        py::dict s;
        s["centroid_cpm"] = r.summary.centroid.value();
        s["log_centroid_db"] = r.summary.log_centroid.value();
        s["spread_cpm"] = r.summary.spread.value();
        s["log_spread_db"] = r.summary.log_spread_db;
        s["total_power"] = r.summary.total_power;
        d["summary"] = s;
        py::list bands;
        for (const BandEnergy& b : r.bands) {
          py::dict bd;
          bd["lo_cpm"] = b.lo_cpm;
          bd["hi_cpm"] = b.hi_cpm;
          bd["mean_square"] = b.mean_square;
          bd["fraction"] = b.fraction;
          bands.append(bd);
        }
        d["bands"] = bands;
        d["mean"] = r.mean;
        d["rms"] = r.rms;
        return d;
      },
      py::arg("samples"), py::arg("spacing_mm"),
      "Everything `texel spectrum` reports for amplitudes sampled every spacing_mm (mm): spectrum,\n"
      "psd (Welch, a²/(cycle/mm)), peaks, summary (centroids, spreads), bands, mean, rms.");

  // ------------------------------------------- MPEG-I Haptics, glTF (docs/interchange.md)
  m.def(
      "export_hjif",
      [](const Document& doc, const std::string& modality, double tolerance, const std::string& date) {
        hjif::ExportOptions o;
        o.modality = hjif::parse_modality(modality, "modality");
        o.tolerance = tolerance;
        o.date = date;
        const hjif::Exported x = hjif::export_hjif(doc, o);
        py::dict d;
        d["json"] = x.json;
        d["perceptions"] = x.stats.perceptions;
        d["keyframes"] = x.stats.keyframes;
        d["samples"] = x.stats.samples;
        d["timescale_ticks_per_mm"] = x.stats.timescale;
        d["max_error"] = x.stats.max_error;
        return d;
      },
      py::arg("document"), py::kw_only(), py::arg("modality") = "friction", py::arg("tolerance") = hjif::default_tolerance,
      py::arg("date") = "",
      R"doc(The document as an MPEG-I Haptics (.hjif) text, as `texel export DOC -o X.hjif`: one spatial
perception per region, Linear Curve keyframes within `tolerance` (full scale) of the map on the
document's device grid, the document carried in the description (docs/interchange.md).
Returns a dict: json (the text), perceptions, keyframes, samples, timescale_ticks_per_mm, max_error.
modality  "friction" | "vibrotactile-texture";  date  YYYY-MM-DD (default: $SOURCE_DATE_EPOCH or today))doc");
  m.def(
      "export_gltf",
      [](const Document& doc, const std::string& hjif_uri, const std::string& container, const std::string& modality,
         double width_mm) {
        gltf::AssetOptions o;
        o.hjif_uri = hjif_uri;
        o.modality = hjif::parse_modality(modality, "modality");
        o.width_mm = width_mm;
        if (container != "gltf" && container != "glb")
          throw FieldError("container", "is '" + container + "'; allowed: gltf, glb");
        const auto b = gltf::asset(doc, o, container == "glb" ? gltf::Container::glb : gltf::Container::gltf);
        return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
      },
      py::arg("document"), py::kw_only(), py::arg("hjif_uri"), py::arg("container") = "gltf", py::arg("modality") = "friction",
      py::arg("width_mm") = 25.0,
      R"doc(A glTF 2.0 asset (bytes: .gltf text or .glb) of the display as a quad with the MPEG_haptic /
MPEG_haptic_material extensions, referencing the .hjif at `hjif_uri` (write export_hjif's json there).)doc");
  m.def(
      "hjif_conformance_errors", [](const std::string& text) { return hjif::conformance_errors(text); }, py::arg("text"),
      "Every rule of MPEG-I Haptics Texel checks, applied to a .hjif text: the violations (empty: conformant).");
}

}  // namespace texel::python
