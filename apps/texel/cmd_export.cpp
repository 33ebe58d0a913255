// texel export: a document or bitstream -> an MPEG-I Haptics file (.hjif or
// binary .hmpg) or a glTF 2.0 asset (.gltf/.glb) with the MPEG haptic
// material, which comes with the .hjif it references (same stem; an existing
// one is replaced only with --force). docs/interchange.md.
#include <filesystem>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"

namespace texel::cli {
namespace {

struct ExportArgs {
  std::string input;
  std::string output;
  DeviceOptions device;
  std::string modality = "friction";
  double tolerance = hjif::default_tolerance;
  std::string date;
  double width_mm = 25.0;
  bool json = false;
  bool force = false;
};

Document input_document(const ExportArgs& a) {
  if (output_extension(a.input) == ".texel") {
    // A bitstream describes a texture, not a grid: decoded on --device (default tpad), as `texel decode`.
    const codec::Bitstream b = codec::read_bitstream(a.input);
    return codec::decode_document(b, resolve_device(a.device, nullptr));
  }
  Document doc = load_document(a.input);
  if (a.device.device || a.device.length_mm || a.device.spacing_mm) doc.device = resolve_device(a.device, &doc.device);
  return doc;
}

}  // namespace

void register_export(CLI::App& app) {
  auto a = std::make_shared<ExportArgs>();
  auto* cmd = app.add_subcommand("export",
                                 "Export a texture as MPEG-I Haptics (.hjif, binary .hmpg) or a glTF asset with an MPEG "
                                 "haptic material (.gltf/.glb, written with the .hjif it references)");
  cmd->add_option("input", a->input, "Texture document (.texel.json) or bitstream (.texel, decoded on --device [tpad])")
      ->required();
  cmd->add_option("-o,--output", a->output, "Output: .hjif, .hmpg, .gltf or .glb")->required();
  add_device_options(*cmd, a->device);
  cmd->add_option("--modality", a->modality, "Perception modality: friction | vibrotactile-texture [friction]");
  cmd->add_option("--tolerance", a->tolerance,
                  "Largest |error| of the samples against the rendered map on the device grid, full scale [1/512]");
  cmd->add_option("--date", a->date,
                  "Date written in the file: RFC 3339 (2026-11-26T14:06:29Z) or a day (2026-11-26, written as its midnight "
                  "UTC) [$SOURCE_DATE_EPOCH, else now UTC]");
  cmd->add_option("--width", a->width_mm, "glTF: width of the display quad across the swipe axis, mm [25]");
  cmd->add_flag("--json", a->json, "Print what was written (keyframes, sizes, error) as JSON");
  cmd->add_flag("--force", a->force, "glTF: replace an existing .hjif beside the asset");
  cmd->callback([a] {
    const std::string ext = output_extension(a->output);
    if (ext != ".hjif" && ext != ".hmpg" && ext != ".gltf" && ext != ".glb")
      throw InvalidArgument("output '" + a->output + "' has extension '" + ext + "'; allowed: .hjif, .hmpg, .gltf, .glb");
    std::string hjif_path = a->output;
    if (ext == ".gltf" || ext == ".glb") {
      hjif_path = (std::filesystem::path(a->output).parent_path() / std::filesystem::path(a->output).stem()).string() + ".hjif";
      // The .hjif is written beside the asset without being named: never over a file that is there.
      if (std::filesystem::exists(hjif_path) && !a->force)
        throw InvalidArgument("'" + hjif_path +
                              "' exists (the .hjif the asset references is written beside it); give --force to replace it");
    }
    hjif::ExportOptions eo;
    eo.modality = hjif::parse_modality(a->modality, "--modality");
    eo.tolerance = a->tolerance;
    eo.date = a->date;
    const Document doc = input_document(*a);
    hjif::Exported h;
    std::vector<std::byte> binary;
    if (ext == ".hmpg") {
      hmpg::Exported b = hmpg::export_hmpg(doc, eo);
      binary = std::move(b.bytes);
      h.stats = b.stats;
    } else {
      h = hjif::export_hjif(doc, eo);
    }

    std::vector<PendingFile> files;
    std::size_t asset_bytes = 0;
    if (ext == ".gltf" || ext == ".glb") {
      gltf::AssetOptions go;
      go.modality = eo.modality;
      go.hjif_uri = std::filesystem::path(hjif_path).filename().string();
      go.width_mm = a->width_mm;
      const auto bytes = gltf::asset(doc, go, ext == ".glb" ? gltf::Container::glb : gltf::Container::gltf);
      asset_bytes = bytes.size();
      files.push_back({a->output, std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size())});
    }
    if (ext == ".hmpg")
      files.push_back({a->output, std::string(reinterpret_cast<const char*>(binary.data()), binary.size())});
    else
      files.insert(files.begin(), PendingFile{hjif_path, h.json});
    commit_files(files);
    const std::size_t written = ext == ".hmpg" ? binary.size() : h.json.size();

    const auto& s = h.stats;
    if (a->json) {
      nlohmann::ordered_json j;
      j["input"] = a->input;
      if (ext == ".hmpg")
        j["hmpg"] = a->output, j["hmpg_bytes"] = written;
      else
        j["hjif"] = hjif_path;
      if (ext == ".gltf" || ext == ".glb") j["asset"] = a->output, j["asset_bytes"] = asset_bytes;
      j["modality"] = std::string(hjif::modality_name(eo.modality));
      j["perceptions"] = s.perceptions;
      j["keyframes"] = s.keyframes;
      j["samples"] = s.samples;
      j["timescale_ticks_per_mm"] = s.timescale;
      j["grid_on_ticks"] = s.grid_on_ticks;
      j["amplitude_decimals"] = s.amplitude_decimals;
      j["tolerance"] = eo.tolerance;
      j["max_error"] = s.max_error;
      if (ext != ".hmpg") j["hjif_bytes"] = written;
      print_json(j);
      return;
    }
    std::cout << a->input << " -> " << (ext == ".hmpg" ? a->output : hjif_path) << ": " << s.perceptions << " "
              << hjif::modality_name(eo.modality) << (s.perceptions == 1 ? " perception, " : " perceptions, ") << s.keyframes
              << " keyframes for " << s.samples << " samples, max error " << detail::num(s.max_error) << " (tolerance "
              << detail::num(eo.tolerance) << (ext == ".hmpg" ? " + half the 8-bit amplitude step, 1/255" : "") << "), "
              << written << " bytes\n";
    if (ext == ".gltf" || ext == ".glb") std::cout << "  " << a->output << ": " << asset_bytes << " bytes\n";
  });
}

}  // namespace texel::cli
