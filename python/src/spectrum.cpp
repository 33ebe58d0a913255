// Binding of the spectral analysis (texel/spectrum.hpp) over numpy arrays of
// amplitudes: the magnitude spectrum and everything `texel spectrum` reports.
// The GIL is released while the library computes.
#include "texel/spectrum.hpp"
#include "common.hpp"
#include "texel/error.hpp"

namespace texel::python {
namespace {

SpectrumOptions spectrum_options(const std::string& window, int zero_pad, bool remove_mean) {
  SpectrumOptions o;
  o.window = parse_window(window, "window");
  o.zero_pad = zero_pad;
  o.remove_mean = remove_mean;
  return o;
}

}  // namespace

void register_spectrum(py::module_& m) {
  // ---------------------------------------------------------------- spectrum
  py::class_<Spectrum>(m, "Spectrum", "One-sided magnitude spectrum on bins k·bin_cpm.")
      .def_property_readonly(
          "bin_cpm", [](const Spectrum& s) { return s.bin.value(); }, "Bin spacing (cycles/mm).")
      .def_property_readonly(
          "resolution_cpm", [](const Spectrum& s) { return s.resolution.value(); }, "1 / signal length (cycles/mm).")
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
        return magnitude_spectrum(x, Millimetres(spacing_mm), o);
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
          r = analyse_spectrum(x, Millimetres(spacing_mm));
        }
        py::dict d;
        d["spectrum"] = py::cast(std::move(r.spectrum));
        py::dict psd;
        psd["bin_cpm"] = r.psd.bin.value();
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
        s["log_spread_db"] = r.summary.log_spread.value();
        s["total_power"] = r.summary.total_power;
        d["summary"] = s;
        py::list bands;
        for (const BandEnergy& b : r.bands) {
          py::dict bd;
          bd["lo_cpm"] = b.lo.value();
          bd["hi_cpm"] = b.hi.value();
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
}

}  // namespace texel::python
