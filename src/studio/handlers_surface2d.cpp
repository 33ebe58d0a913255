// 2-D surface messages (docs/studio.md "The 2-D page"): surface2d.view (a
// window of the friction map at a zoom's resolution) and surface2d.scan (the
// map scanned along a direction, beside the 1-D texture's spectrum). The 2-D
// feel pad's player and the device's hand-over are handlers_feel2d.cpp.
//
// Coarse images: the studio reads no file a client names. A document whose
// coarse2d is an `image` sends the PNG's bytes with the message (`images`:
// file name → base64); they are written to a private temporary directory
// that lives as long as the prepared surface (the library loads images by
// path), and any other path is refused.
#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <span>
#include <thread>

#include <unistd.h>

#include "base64.hpp"
#include "handlers_surface2d.hpp"
#include "messages.hpp"
#include "texel/error.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
#include "texel/sinks.hpp"
#include "texel/studio/surface2d_view.hpp"

namespace texel::studio::detail {

namespace {

constexpr std::size_t max_images = 16;

}  // namespace

std::shared_ptr<Surface2DState> make_surface2d_state() { return std::make_shared<Surface2DState>(); }

namespace {

std::string image_name_error(const std::string& name) {
  if (name.empty() || name.size() > 64) return "names 1 … 64 characters";
  for (const char ch : name)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-')) return "letters, digits, . _ -";
  if (name.front() == '.') return "a name not starting with '.'";
  if (name.size() < 5 || name.substr(name.size() - 4) != ".png") return "a .png file name";
  return {};
}

ojson surface_json(const Prepared& p) {
  const BitmapGeometry& g = p.surface->geometry();
  ojson j{{"width_px", g.width},
          {"height_px", g.height},
          {"pixel_pitch_mm", g.pitch.value()},
          {"width_mm", g.width_mm().value()},
          {"height_mm", g.height_mm().value()}};
  j["regions"] = ojson::array();
  for (const auto& r : p.surface->regions())
    j["regions"].push_back(
        {{"name", r.name}, {"x_mm", r.x0}, {"y_mm", r.y0}, {"width_mm", r.x1 - r.x0}, {"height_mm", r.y1 - r.y0}});
  return j;
}

}  // namespace

/// The document of a 2-D message with its coarse images resolved to the bytes
/// sent along, prepared (cached: zooming and panning re-use it).
std::shared_ptr<const Prepared> prepared(State& s, const Fields& f, const std::string& type) {
  json doc = f.object("document");
  std::map<std::string, std::vector<unsigned char>> images;
  std::string key = doc.dump();
  if (f.has("images")) {
    const json& im = f.raw("images");
    if (!im.is_object())
      throw Reject{"bad_message", type + ": images must be an object (file name → base64 PNG), got " + im.type_name()};
    if (im.size() > max_images)
      throw Reject{"invalid", type + ": images has " + std::to_string(im.size()) + " entries; allowed: at most " +
                                  std::to_string(max_images)};
    for (const auto& [name, value] : im.items()) {
      if (const std::string why = image_name_error(name); !why.empty())
        throw Reject{"invalid", type + ": images key " + clipped(name) + " is not a plain file name; allowed: " + why};
      if (!value.is_string())
        throw Reject{"bad_message", type + ": images." + name + " must be a base64 string, got " + value.type_name()};
      auto bytes = base64_decode(value.get_ref<const std::string&>());
      if (!bytes) throw Reject{"invalid", type + ": images." + name + " is not valid base64"};
      static constexpr unsigned char png_magic[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
      if (bytes->size() < 8 || !std::equal(png_magic, png_magic + 8, bytes->begin()))
        throw Reject{"invalid", type + ": images." + name + " is not a PNG file"};
      key += "\n" + name + ":" + value.get_ref<const std::string&>();
      images.emplace(name, std::move(*bytes));
    }
  }
  auto* st = s.surface2d.get();
  {
    std::lock_guard lock(st->cache_mutex);
    if (st->cache && st->cache_key == key) return st->cache;
  }
  if (!doc.contains("surface2d"))
    throw Reject{"invalid", type + ": document is not a 2-D document (version 4 or 5 with surface2d)"};
  auto p = std::make_shared<Prepared>();
  // Every image path must name one of the images sent; each is rewritten to its temporary copy.
  json* regions = doc["surface2d"].is_object() && doc["surface2d"].contains("regions") ? &doc["surface2d"]["regions"] : nullptr;
  if (regions && regions->is_array()) {
    for (std::size_t i = 0; i < regions->size(); ++i) {
      json& r = (*regions)[i];
      if (!r.is_object() || !r.contains("coarse2d") || !r["coarse2d"].is_object()) continue;
      json& c = r["coarse2d"];
      if (!c.contains("kind") || c["kind"] != "image") continue;
      const std::string where = "document.surface2d.regions[" + std::to_string(i) + "].coarse2d.path";
      const std::string path = c.contains("path") && c["path"].is_string() ? c["path"].get<std::string>() : "";
      const auto it = images.find(path);
      if (it == images.end())
        throw Reject{"invalid", where + " is " + clipped(path) +
                                    ", which is not among the images sent; the studio reads no files of its own"};
      if (p->image_dir.empty()) {
        std::string tmpl = (std::filesystem::temp_directory_path() / "texel-studio-XXXXXX").string();
        if (!::mkdtemp(tmpl.data())) throw Reject{"internal", type + ": cannot create a temporary directory for images"};
        p->image_dir = tmpl;
      }
      const std::filesystem::path file = p->image_dir / path;
      if (!std::filesystem::exists(file)) {
        std::ofstream out(file, std::ios::binary);
        out.write(reinterpret_cast<const char*>(it->second.data()), static_cast<std::streamsize>(it->second.size()));
        if (!out) throw Reject{"internal", type + ": cannot write the image " + clipped(path)};
      }
      c["path"] = file.string();
    }
  }
  p->doc = document_of(s, doc, "document");
  if (!p->doc.surface2d) throw Reject{"invalid", type + ": document is not a 2-D document (version 4 or 5 with surface2d)"};
  // An oriented field lays the 1-D texture along ±oriented_extent_mm: bound its texel count like 1-D maps.
  for (std::size_t i = 0; i < p->doc.surface2d->regions.size(); ++i) {
    const Region2DSpec& r = p->doc.surface2d->regions[i];
    const double texels = 2.0 * FineField2D::oriented_extent_mm / r.texel.texel_length.value();
    if (r.field == Field2D::oriented && texels > static_cast<double>(s.options.max_map_samples))
      throw Reject{"too_large", "document.surface2d.regions[" + std::to_string(i) + "].texture.texel_length_mm " +
                                    json(r.texel.texel_length.value()).dump() + " makes " + json(texels).dump() +
                                    " texels for an oriented field; allowed: at most " +
                                    std::to_string(s.options.max_map_samples)};
  }
  p->surface.emplace(prepare_surface2d(p->doc));
  std::lock_guard lock(st->cache_mutex);
  st->cache_key = std::move(key);
  st->cache = p;
  return p;
}

std::size_t region_of(const Fields& f, const Prepared& p, const std::string& type) {
  const std::size_t region = region_field(f, "region").value_or(0);
  if (region >= p.surface->regions().size())
    throw Reject{"invalid", type + ": region is " + std::to_string(region) + "; the document has " +
                                std::to_string(p.surface->regions().size()) + " region(s)"};
  return region;
}

void on_surface2d_view(State& s, Client& c, const Job& job) {
  const auto t0 = Clock::now();
  const Fields f(job.msg, job.type);
  const auto p = prepared(s, f, job.type);
  const BitmapGeometry& g = p->surface->geometry();
  Surface2DWindow w;
  w.x_px = static_cast<int>(f.integer("x_px", 0, g.width - 1));
  w.y_px = static_cast<int>(f.integer("y_px", 0, g.height - 1));
  w.width_px = static_cast<int>(f.integer("width_px", 1, 65535));
  w.height_px = static_cast<int>(f.integer("height_px", 1, 65535));
  w.stride = static_cast<int>(f.integer("stride", 1, 65535));
  Surface2DView v;
  try {
    v = surface2d_view(*p->surface, w);
  } catch (const InvalidArgument& e) {
    throw Reject{"invalid", job.type + ": " + e.what()};
  }
  std::vector<unsigned char> bytes(v.amplitude.size());
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<unsigned char>(std::lround(std::clamp(static_cast<double>(v.amplitude[i]), 0.0, 1.0) * 255.0));
  ojson r = reply("surface2d.view", job.id);
  r["surface"] = surface_json(*p);
  r["x_px"] = v.window.x_px;
  r["y_px"] = v.window.y_px;
  r["width_px"] = v.window.width_px;
  r["height_px"] = v.window.height_px;
  r["stride"] = v.window.stride;
  r["columns"] = v.columns;
  r["rows"] = v.rows;
  r["view_pitch_mm"] = g.pitch.value() * v.window.stride;
  r["amplitude_u8"] = base64_encode(std::span<const unsigned char>(bytes));
  r["elapsed_ms"] = ms_since(t0);
  send(c, r);
}

void on_surface2d_scan(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const double angle = f.number("angle_deg", -360.0, 360.0);
  const auto p = prepared(s, f, job.type);
  const std::size_t region = region_of(f, *p, job.type);
  Surface2DScan scan;
  try {
    scan = surface2d_scan(*p->surface, region, angle);
  } catch (const InvalidArgument& e) {
    throw Reject{"invalid", job.type + ": " + e.what()};
  }
  ojson r = reply("surface2d.scan", job.id);
  r["region"] = scan.region;
  r["angle_deg"] = scan.angle_deg;
  r["from_mm"] = {scan.from_x_mm, scan.from_y_mm};
  r["to_mm"] = {scan.to_x_mm, scan.to_y_mm};
  r["spacing_mm"] = scan.spacing.value();
  r["samples"] = scan.samples;
  r["scan"] = spectrum_json(scan.scan);
  r["target"] = spectrum_json(scan.target);
  send(c, r);
}

}  // namespace texel::studio::detail
