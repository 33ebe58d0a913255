// texel decode: a .texel bitstream -> the texture on any device, in every
// output format of `render` (the same writer, so the bytes are identical to
// rendering the equivalent document).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "render_output.hpp"
#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::cli {

void register_decode(CLI::App& app) {
  struct Args {
    std::string input;
    DeviceOptions device;
    std::string output;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("decode", "Decode a .texel bitstream and render it for a device");
  cmd->add_option("input", a->input, "Bitstream (.texel)")->required();
  add_device_options(*cmd, a->device);
  cmd->add_option("-o,--output", a->output, "Output: .bin (device native), .csv, .npy, .mat, .texel.json, .png or .svg")
      ->required();
  cmd->add_flag("--json", a->json, "Print the decoded parameters as JSON");
  cmd->callback([a] {
    check_render_output(a->output);  // reject a bad extension before any work
    const std::string bytes = read_file(a->input);
    codec::Bitstream b;
    try {
      b = codec::parse_bitstream(byte_view(bytes));
    } catch (const FormatError& e) {
      throw FormatError("'" + a->input + "': " + e.what());
    }
    const DeviceProfile device = resolve_device(a->device, nullptr);
    Document doc = codec::decode_document(b, device);
    doc.description = "decoded from " + a->input;
    const Surface surface = prepare_surface(doc);
    write_surface(a->output, doc, surface);
    if (a->json) {
      const TexelSpec& s = doc.regions[0].texel;
      nlohmann::ordered_json j;
      j["input"] = a->input;
      j["output"] = a->output;
      j["bitstream_bytes"] = bytes.size();
      j["device"] = device.name;
      j["samples"] = device.samples;
      j["central_pitch_db"] = s.central_pitch.value();
      j["irregularity_db"] = s.irregularity.value();
      j["texel_length_mm"] = s.texel_length.value();
      j["seed"] = s.seed;
      j["parameterization"] = std::string(to_string(s.parameterization));
      j["band_max_cpm"] = s.band_max.value();
      j["coarse_strength"] = s.coarse_strength;
      j["fine_strength"] = s.fine_strength;
      j["coarse_profile"] = kind_name(s.coarse);
      // The texture is device independent; a coarse grid samples it with aliasing.
      j["aliased"] = s.band_max.value() > device.nyquist().value();
      print_json(j);
    }
  });
}

}  // namespace texel::cli
