// texel info: what a document holds, or any input signal as texel::load_signal reads it.
// texel devices: the device profiles Texel knows.
#include <algorithm>
#include <iostream>
#include <memory>
#include <numeric>

#include "commands.hpp"
#include "common.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/surface2d.hpp"

namespace texel::cli {
namespace {

using detail::num;
using ordered = nlohmann::ordered_json;

ordered stats(const std::vector<double>& v) {
  ordered j;
  j["samples"] = v.size();
  if (v.empty()) return j;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  j["min"] = *lo;
  j["max"] = *hi;
  j["mean"] = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  return j;
}

// A 2-D document (version 4 or 5): its bitmap grid and its regions (prepared, so
// every field and coarse profile is checked, images loaded).
ordered surface2d_info(const Document& doc, ordered j) {
  const Surface2D surface = prepare_surface2d(doc);
  const BitmapGeometry& g = surface.geometry();
  j["bitmap"] = {{"width_px", g.width},
                 {"height_px", g.height},
                 {"pixel_pitch_mm", g.pitch.value()},
                 {"width_mm", g.width_mm().value()},
                 {"height_mm", g.height_mm().value()},
                 {"depth_bits", g.depth},
                 {"polarity", std::string(to_string(g.polarity))},
                 {"nyquist_cpm", g.nyquist().value()},
                 {"png_raw_bytes", static_cast<std::int64_t>(g.width) * g.height * (g.depth / 8)}};
  j["regions"] = ordered::array();
  const auto& specs = doc.surface2d->regions;
  for (std::size_t i = 0; i < surface.regions().size(); ++i) {
    const Surface2D::Region& r = surface.regions()[i];
    const Region2DSpec& spec = specs[i];
    const TexelSpec& s = r.texel;
    ordered rj{{"name", r.name},
               {"x_mm", r.x0},
               {"y_mm", r.y0},
               {"width_mm", r.x1 - r.x0},
               {"height_mm", r.y1 - r.y0},
               {"field", std::string(to_string(spec.field))}};
    if (spec.field == Field2D::oriented) rj["orientation_deg"] = spec.orientation_deg;
    if (spec.field == Field2D::tile) {
      // The tile design's periodic tiles (docs/algorithm.md §11.2), one per band.
      ordered bands = ordered::array();
      for (const auto& b : r.fine->tile_bands())
        bands.push_back({{"from_cpm", b.q_lo}, {"to_cpm", b.q_hi}, {"period_mm", b.period_mm()}, {"frequencies", b.modes}});
      rj["tile_bands"] = std::move(bands);
    }
    rj["central_pitch_db"] = s.central_pitch.value();
    rj["irregularity_db"] = s.irregularity.value();
    rj["texel_length_mm"] = s.texel_length.value();
    rj["seed"] = s.seed;
    rj["coarse2d"] = kind_name(spec.coarse);
    rj["coarse_strength"] = s.coarse_strength;
    rj["fine_strength"] = s.fine_strength;
    j["regions"].push_back(rj);
  }
  return j;
}

ordered document_info(const Document& doc, const std::string& path) {
  ordered j;
  if (doc.surface2d) {
    j["file"] = path;
    j["kind"] = "texel-document";
    j["version"] = doc.version;
    if (!doc.description.empty()) j["description"] = doc.description;
    j["device"] = {{"name", doc.device.name}};
    j["document_bytes"] = document_json(doc).size();
    return surface2d_info(doc, std::move(j));
  }
  const Surface surface = prepare_surface(doc);
  j["file"] = path;
  j["kind"] = "texel-document";
  j["version"] = doc.version;
  if (!doc.description.empty()) j["description"] = doc.description;
  j["device"] = {{"name", doc.device.name},
                 {"samples", doc.device.samples},
                 {"spacing_mm", doc.device.spacing.value()},
                 {"length_mm", doc.device.length().value()},
                 {"format", std::string(to_string(doc.device.format))},
                 {"native_bytes", doc.device.native_bytes()},
                 {"nyquist_cpm", doc.device.nyquist().value()}};
  j["document_bytes"] = document_json(doc).size();
  j["regions"] = ordered::array();
  for (const auto& r : surface.regions()) {
    ordered rj{
        {"name", r.name}, {"start_mm", r.start.value()}, {"length_mm", r.length.value()}, {"texture", r.texture->describe()}};
    if (const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get())) {
      const auto& s = t->spec();
      rj["texels"] = t->texel_count();
      rj["central_pitch_db"] = s.central_pitch.value();
      rj["irregularity_db"] = s.irregularity.value();
      rj["texel_length_mm"] = s.texel_length.value();
      rj["seed"] = s.seed;
      rj["parameterization"] = std::string(to_string(s.parameterization));
      rj["quantization_db"] = s.quantization_db;
      rj["coarse"] = kind_name(s.coarse);
      rj["coarse_strength"] = s.coarse_strength;
      rj["fine_strength"] = s.fine_strength;
      rj["band_mass"] = t->distribution().band_mass();
    }
    j["regions"].push_back(rj);
  }
  return j;
}

void print_text(const ordered& j, int indent = 0) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string pad(static_cast<std::size_t>(indent), ' ');
    if (it->is_object()) {
      std::cout << pad << it.key() << ":\n";
      print_text(*it, indent + 2);
    } else if (it->is_array()) {
      std::cout << pad << it.key() << ":\n";
      int i = 0;
      for (const auto& e : *it) {
        std::cout << pad << "  [" << i++ << "]\n";
        if (e.is_object())
          print_text(e, indent + 4);
        else
          std::cout << pad << "    " << e.dump() << "\n";
      }
    } else {
      std::cout << pad << it.key() << ": " << (it->is_string() ? it->get<std::string>() : it->dump()) << "\n";
    }
  }
}

}  // namespace

void register_info(CLI::App& app) {
  struct Args {
    std::string file;
    SignalArgs input;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("info", "Describe a texture document, or any input signal as the library reads it");
  cmd->add_option("file", args->file, kInputHelp)->required();
  add_signal_options(*cmd, args->input);
  cmd->add_flag("--json", args->json, "Print JSON");
  cmd->callback([args] {
    const auto& in = args->input;
    ordered j;
    if (signal_format_of(args->file) == SignalFormat::document && !in.device && !in.spacing_mm && !in.region) {
      j = document_info(load_document(args->file), args->file);
    } else {
      const Signal s = load_input(args->file, in);
      j["file"] = args->file;
      j["kind"] = std::string(to_string(s.format));
      j["source"] = s.description;
      j["spacing_mm"] = s.spacing.value();
      j["origin_mm"] = s.origin.value();
      j["length_mm"] = s.length().value();
      if (s.sample_rate) j["sample_rate_hz"] = s.sample_rate->value();
      j["scaled_to_full_range"] = s.scaled;
      j["amplitude"] = stats(s.samples);
    }
    if (args->json)
      print_json(j);
    else
      print_text(j);
  });
}

void register_devices(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("devices", "List the built-in device profiles");
  cmd->add_flag("--json", *json, "Print the profiles as JSON");
  cmd->callback([json] {
    ordered all = ordered::array();
    for (const auto& name : builtin_device_names()) {
      const DeviceProfile d = load_device(name);
      if (*json) {
        all.push_back(ordered::parse(device_profile_json(d)));
      } else {
        std::cout << d.name << ": " << d.samples << " samples x " << num(d.spacing.value()) << " mm = " << num(d.length().value())
                  << " mm, " << to_string(d.format) << ", " << num(d.refresh.value()) << " Hz, Nyquist "
                  << detail::fixed(d.nyquist().value(), 2) << " cpm\n    " << d.description << "\n";
      }
    }
    if (*json) print_json(all);
  });
}

}  // namespace texel::cli
