// Binding of the interchange formats (texel/interchange.hpp, docs/interchange.md):
// MPEG-I Haptics (.hjif) export and conformance checks, glTF assets. Reading
// .hjif files is load_signal's and transcode's (signal.cpp, codec.cpp).
#include "texel/interchange.hpp"
#include "common.hpp"
#include "texel/error.hpp"

namespace texel::python {

void register_interchange(py::module_& m) {
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
