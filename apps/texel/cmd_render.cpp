// texel render: a Texel texture (from a document and/or flags) to a device
// file, CSV, NumPy array, document or plot.
#include <cmath>
#include <cstring>
#include <iostream>
#include <memory>
#include <numeric>

#include "commands.hpp"
#include "common.hpp"
#include "render_output.hpp"
#include "texel/bitmap_file.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/multichannel.hpp"

namespace texel::cli {
namespace {

struct RenderArgs {
  std::optional<std::string> document;
  TextureOptions texture;
  DeviceOptions device;
  std::string output;
  std::optional<std::string> texels_csv;
  std::string mat_version = "5";
  bool json = false;
  std::string surface = "1d";
  int depth = 0;
};

/// --surface 2d: a 2-D document (version 4) to a friction bitmap.
void render_2d(const RenderArgs& a) {
  if (!a.document) throw InvalidArgument("--surface 2d needs a 2-D document (version 4, surface2d)");
  if (!is_bitmap_path(a.output))
    throw InvalidArgument("--output '" + a.output + "': a 2-D surface is written as .png, .npy, .mat, .gltf or .glb");
  BitmapFileOptions options;
  options.mat_version = mat::parse_mat_version(a.mat_version);
  if (a.depth != 0 && a.depth != 8 && a.depth != 16)
    throw InvalidArgument("--depth is " + std::to_string(a.depth) + "; allowed: 8, 16");
  check_writable(a.output);
  const Document doc = load_document(*a.document);
  const Surface2D surface = prepare_surface2d(doc);
  options.depth = a.depth;
  const BitmapFileStats stats = write_bitmap(a.output, surface, options);
  if (a.json) {
    nlohmann::ordered_json j;
    j["output"] = a.output;
    j["device"] = doc.device.name;
    j["width_px"] = stats.width;
    j["height_px"] = stats.height;
    j["pixel_pitch_mm"] = surface.geometry().pitch.value();
    j["depth_bits"] = stats.depth;
    j["polarity"] = std::string(to_string(surface.geometry().polarity));
    j["mean_amplitude"] = stats.mean_amplitude;
    print_json(j);
  }
}

std::string texels_csv(const Surface& surface) {
  const bool many = surface.regions().size() > 1;
  std::string out = many ? "index,start_mm,frequency_cpm,amplitude,region\n" : "index,start_mm,frequency_cpm,amplitude\n";
  for (std::size_t r = 0; r < surface.regions().size(); ++r) {
    const auto& region = surface.regions()[r];
    const auto* t = dynamic_cast<const TexelTexture*>(region.texture.get());
    if (!t) continue;
    for (std::size_t k = 0; k < t->texels().size(); ++k) {
      const Texel& x = t->texels()[k];
      out += std::to_string(k) + "," + detail::num(region.start.value() + x.start.value()) + "," +
             detail::num(x.frequency.value()) + "," + detail::num(x.envelope);
      if (many) out += "," + (region.name.empty() ? std::to_string(r) : region.name);
      out += "\n";
    }
  }
  return out;
}

nlohmann::ordered_json summary(const Document& doc, const Surface& surface, double mean, const RenderArgs& a) {
  nlohmann::ordered_json j;
  j["output"] = a.output;
  if (a.texels_csv) j["texels_csv"] = *a.texels_csv;
  j["device"] = doc.device.name;
  j["samples"] = surface.grid().count;
  j["spacing_mm"] = surface.grid().spacing.value();
  j["length_mm"] = surface.grid().length().value();
  j["format"] = std::string(to_string(doc.device.format));
  j["device_bytes"] = doc.device.native_bytes();
  j["document_bytes"] = document_json(doc).size();
  j["mean_amplitude"] = mean;
  j["regions"] = nlohmann::ordered_json::array();
  for (const auto& r : surface.regions()) {
    nlohmann::ordered_json rj;
    rj["name"] = r.name;
    rj["start_mm"] = r.start.value();
    rj["length_mm"] = r.length.value();
    rj["texture"] = r.texture->describe();
    if (const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get())) {
      // Two passes over the texels in runs (bounded memory at any length).
      const std::size_t n = t->texel_count();
      double m = 0.0, s2 = 0.0;
      t->for_each_texels([&](std::size_t, std::span<const Texel> run) {
        for (const auto& x : run) m += x.frequency.value();
      });
      m /= static_cast<double>(std::max<std::size_t>(n, 1));
      t->for_each_texels([&](std::size_t, std::span<const Texel> run) {
        for (const auto& x : run) s2 += (x.frequency.value() - m) * (x.frequency.value() - m);
      });
      rj["texels"] = n;
      rj["frequency_mean_cpm"] = m;
      rj["frequency_sd_cpm"] = n > 1 ? std::sqrt(s2 / static_cast<double>(n - 1)) : 0.0;
      rj["band_mass"] = t->distribution().band_mass();
    }
    j["regions"].push_back(rj);
  }
  return j;
}

}  // namespace

void register_render(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand("render", "Render a Texel texture for a device");
  cmd->add_option("document", args->document, "A texture document (.texel.json); flags override its values");
  add_texture_options(*cmd, args->texture);
  add_device_options(*cmd, args->device);
  cmd->add_option("-o,--output", args->output,
                  "Output: .bin (device native), .csv, .npy, .mat (MATLAB), .texel.json, .png or .svg")
      ->required();
  cmd->add_option("--mat-version", args->mat_version,
                  "MATLAB file version of a .mat output: 5 (default, compressed) or 7.3 (HDF5)")
      ->default_str("5");
  cmd->add_option("--texels", args->texels_csv, "Also write one row per texel: index,start_mm,frequency_cpm,amplitude");
  cmd->add_flag("--json", args->json, "Print a JSON summary on stdout");
  cmd->add_option("--surface", args->surface,
                  "1d (default) or 2d: a 2-D document (version 4) to a friction bitmap (.png, .npy, .mat, .gltf, .glb)")
      ->check(CLI::IsMember({"1d", "2d"}))
      ->default_str("1d");
  cmd->add_option("--depth", args->depth, "--surface 2d PNG bits per pixel: 8 or 16 (default: the device's)");
  cmd->callback([args] {
    if (args->surface == "2d") {
      render_2d(*args);
      return;
    }
    // Reject a bad extension or MAT version before any work.
    const mat::MatVersion mat_version = mat::parse_mat_version(args->mat_version);
    check_render_output(args->output);
    if (args->texels_csv) {
      if (output_extension(*args->texels_csv) != ".csv")
        throw InvalidArgument("--texels '" + *args->texels_csv + "' must be a .csv file");
      check_writable(*args->texels_csv);
    }
    const Document doc = build_document(args->document, args->device, args->texture);
    if (doc.playback && doc.playback->mode == ChannelMode::simultaneous && output_extension(args->output) != ".texel.json") {
      // One map per channel (docs/rendering.md): [samples, channels], float64.
      if (output_extension(args->output) != ".npy" || args->texels_csv)
        throw InvalidArgument("--output '" + args->output +
                              "': a simultaneous document has one map per channel; render it to .npy ([samples, channels]) "
                              "or .texel.json, without --texels");
      const std::vector<Channel> channels = prepare_channels(doc);
      const auto samples = static_cast<std::size_t>(doc.device.samples);
      std::vector<double> map(samples * channels.size());
      render_channels(channels, 0, map);
      std::string bytes = npy_header(samples, channels.size());
      const std::size_t header = bytes.size();
      bytes.resize(header + map.size() * sizeof(double));
      std::memcpy(bytes.data() + header, map.data(), map.size() * sizeof(double));  // as npy_bytes
      write_file_atomic(args->output, bytes);
      if (args->json) {
        nlohmann::ordered_json j;
        j["output"] = args->output;
        j["samples"] = samples;
        j["channels"] = channels.size();
        j["playback"] = "simultaneous";
        print_json(j);
      } else {
        std::cout << args->output << ": " << samples << " samples × " << channels.size() << " channels (simultaneous)\n";
      }
      return;
    }
    const Surface surface = prepare_surface(doc);
    std::vector<PendingFile> extra;
    if (args->texels_csv) extra.push_back({*args->texels_csv, texels_csv(surface)});
    const double mean = write_surface(args->output, doc, surface, std::move(extra), mat_version);
    if (args->json) print_json(summary(doc, surface, mean, *args));
  });
}

}  // namespace texel::cli
