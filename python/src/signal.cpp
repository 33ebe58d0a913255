// Binding of the one signal loader (texel/signal.hpp): load_signal() reads a
// file or an array into samples on a uniform grid. An array is read by the
// same rule as a .npy file holding it (docs/format.md "Input signals"): its
// bytes go through texel::decode_signal as SignalFormat::npy, so an array and
// the file np.save() writes from it give the same samples, scaling included.
#include "texel/signal.hpp"
#include "common.hpp"
#include "texel/codec.hpp"
#include "texel/error.hpp"

namespace texel::python {

std::vector<std::byte> bytes_of(const py::bytes& b) {
  const auto s = std::as_bytes(std::span(std::string_view(b)));
  return {s.begin(), s.end()};
}

py::bytes to_bytes(std::span<const std::byte> v) { return py::bytes(reinterpret_cast<const char*>(v.data()), v.size()); }

bool is_path(const py::handle& source) { return py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__"); }

std::string path_of(const py::handle& source) {
  return py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
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

texel::Signal signal_of(const py::handle& source, const SignalOptions& o) {
  if (is_path(source)) {
    const std::string path = path_of(source);
    py::gil_scoped_release release;
    return codec::load_signal(path, o);
  }
  // numpy writes the .npy (any array-like becomes an ndarray first; a list of
  // numbers is float64); big-endian data is stored little-endian, the byte
  // order the .npy reader takes. Nothing else is converted: a dtype the .npy
  // rule does not read is refused by it, naming the dtype.
  py::module_ np = py::module_::import("numpy");
  py::object a = py::isinstance<py::array>(source) ? py::reinterpret_borrow<py::object>(source)
                                                   : np.attr("asarray")(source, py::arg("dtype") = "float64");
  if (py::str(a.attr("dtype").attr("byteorder")).cast<std::string>() == ">")
    a = a.attr("astype")(a.attr("dtype").attr("newbyteorder")("<"));
  py::object buffer = py::module_::import("io").attr("BytesIO")();
  np.attr("save")(buffer, a, py::arg("allow_pickle") = false);
  const std::string bytes = buffer.attr("getvalue")().cast<std::string>();
  py::gil_scoped_release release;
  texel::Signal s = decode_signal(std::as_bytes(std::span(bytes.data(), bytes.size())), SignalFormat::npy, o, "array");
  if (s.description.starts_with(".npy")) s.description.replace(0, 4, "array");
  return s;
}

void register_signal(py::module_& m) {
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
      [](const py::object& source, const py::object& device, std::optional<double> spacing_mm, const py::object& region,
         std::optional<double> swipe_speed_mm_s, const py::object& channel, std::size_t max_samples) {
        return signal_of(source, signal_options(device, spacing_mm, region, swipe_speed_mm_s, channel, max_samples));
      },
      py::arg("source"), py::kw_only(), py::arg("device") = py::none(), py::arg("spacing_mm") = py::none(),
      py::arg("region") = py::none(), py::arg("swipe_speed_mm_s") = py::none(), py::arg("channel") = py::none(),
      py::arg("max_samples") = SignalOptions{}.max_samples,
      R"doc(Reads a texture signal file, or an array, with the library's one loader (the same samples
`texel info`, `texel spectrum` and `texel encode` see).

source            a path: .bin (needs device), .npy (device or spacing_mm), .csv (position_mm,amplitude
                  or time_s,value), .wav (swipe_speed_mm_s), .mat, .texel.json, .texel (needs device);
                  or a 1-D array, read as the .npy file np.save() writes from it (device or
                  spacing_mm): float64/float32 as they are, uint16/uint8/int16 as device-style
                  integers (/65535, /255, /32768); values outside [0, 1] scaled to full range
device            a device name, profile path or Device: grid and sample format of a .bin
spacing_mm        sample spacing, mm; must agree with a file's own grid
region            (start_mm, end_mm), or a document region's name or index
swipe_speed_mm_s  turns a time recording into positions
channel           a multi-channel recording's channel index, or "mix" (default: mono files only)
max_samples       largest size a file may declare, checked before allocating
Raises InvalidArgument naming the keyword, FormatError or IoError naming the file.)doc");
}

}  // namespace texel::python
