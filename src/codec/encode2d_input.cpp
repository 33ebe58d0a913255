// The 2-D encoder's inputs (docs/encoder.md "2-D inputs"): grey PNG friction
// bitmaps (read by the 2-D model's one PNG reader), 2-D .npy maps (read by
// texel::parse_npy_array) and bundles of 1-D scans (each read by the one
// signal loader).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "../surface2d/internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/encode2d.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/signal.hpp"

namespace texel::codec {
namespace {

/// The pitch the options give: --pitch, else the device's bitmap; both must
/// agree within 1 % when given together.
Millimetres pitch_of(const Raster2DLoadOptions& o, const std::string& path) {
  const std::optional<BitmapGeometry>& bitmap = o.device ? o.device->bitmap : std::nullopt;
  if (o.device && !bitmap)
    throw InvalidArgument("device '" + o.device->name +
                          "' has no bitmap (a 2-D input needs a device with \"bitmap\", or --pitch)");
  if (o.pitch) {
    const double p = o.pitch->value();
    if (!(std::isfinite(p) && p > 0.0)) throw InvalidArgument("pitch is " + detail::num(p) + " mm; it must be > 0");
    if (bitmap && std::abs(p - bitmap->pitch.value()) > 0.01 * bitmap->pitch.value())
      throw InvalidArgument("pitch " + detail::num(p) + " mm disagrees with device '" + o.device->name + "''s pixel pitch " +
                            detail::num(bitmap->pitch.value()) + " mm");
    return *o.pitch;
  }
  if (bitmap) return bitmap->pitch;
  throw InvalidArgument(path + ": a 2-D input needs its pixel pitch: give --pitch MM or a --device with a bitmap");
}

/// The bit depth in a PNG's IHDR (byte 24), 0 if unreadable.
int png_depth(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  char head[25] = {};
  if (!f.read(head, sizeof head)) return 0;
  return static_cast<unsigned char>(head[24]);
}

}  // namespace

Input2D load_input2d(const std::string& path, const Raster2DLoadOptions& options) {
  const Millimetres pitch = pitch_of(options, path);
  Input2D in;
  in.description = path;
  const std::string ext = output_extension(path);
  if (ext == ".png") {
    in.map = surface2d_detail::read_png_grey(path);
    in.depth = png_depth(path) == 16 ? 16 : 8;
    in.polarity = options.polarity                           ? *options.polarity
                  : options.device && options.device->bitmap ? options.device->bitmap->polarity
                                                             : BitmapPolarity::darker_more_friction;
    if (in.polarity == BitmapPolarity::brighter_more_friction)
      for (float& v : in.map.values) v = 1.0f - v;
  } else if (ext == ".npy") {
    NpyArray a = parse_npy_array(read_file(path), path, 2);
    texel::to_amplitudes(a.values, path);
    in.map.width = static_cast<int>(a.columns);
    in.map.height = static_cast<int>(a.rows);
    in.map.values.assign(a.values.begin(), a.values.end());
    in.depth = 0;
  } else {
    throw InvalidArgument(path + ": a 2-D input must be a grey .png or a 2-D .npy (or a .scans.json bundle)");
  }
  in.map.pitch = pitch;
  return in;
}

bool is_2d_input(const std::string& path) {
  const std::string ext = output_extension(path);
  if (ext == ".png") return true;
  if (ext != ".npy") return false;
  std::ifstream f(path, std::ios::binary);
  std::string head(512, '\0');
  f.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(f.gcount()));
  const auto k = head.find("'shape'");
  if (k == std::string::npos) return false;
  const auto open = head.find('(', k), close = head.find(')', k);
  if (open == std::string::npos || close == std::string::npos || close < open) return false;
  int non_unit = 0;
  const std::string shape = head.substr(open + 1, close - open - 1);
  for (std::size_t i = 0; i < shape.size();) {
    if (!std::isdigit(static_cast<unsigned char>(shape[i]))) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < shape.size() && std::isdigit(static_cast<unsigned char>(shape[j]))) ++j;
    if (shape.substr(i, j - i) != "1") ++non_unit;
    i = j;
  }
  return non_unit >= 2;
}

ScanBundle load_scan_bundle(const std::string& path, const SignalOptions& signal) {
  ScanBundle b;
  b.description = path;
  std::vector<std::pair<std::string, double>> entries;  // (file, direction)
  try {
    const nlohmann::json j = nlohmann::json::parse(read_file(path));
    detail::JsonObject o(j, "");
    const std::string format = o.string("format");
    if (format != "texel-scans") throw FormatError("format is '" + format + "'; a scan bundle has \"format\": \"texel-scans\"");
    o.integer("version", 1, 1);
    b.width = Millimetres(o.number_or("width_mm", 0.0, 0.0, 1e6));
    b.height = Millimetres(o.number_or("height_mm", 0.0, 0.0, 1e6));
    const nlohmann::json& scans = o.raw("scans");
    if (!scans.is_array() || scans.empty()) throw FormatError("scans must be a non-empty array");
    for (std::size_t i = 0; i < scans.size(); ++i) {
      detail::JsonObject s(scans[i], "scans[" + std::to_string(i) + "]");
      const std::string file = s.string("path");
      entries.emplace_back(file, s.number("direction_deg", -360.0, 360.0));
      s.finish();
    }
    o.finish();
  } catch (const nlohmann::json::exception& e) {
    throw FormatError(path + ": not a scan bundle (" + e.what() + ")");
  } catch (const FormatError& e) {
    throw FormatError(path + ": " + e.what());
  }
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::filesystem::path p(entries[i].first);
    const std::string resolved = p.is_absolute() ? entries[i].first : (dir / p).string();
    const Signal loaded = encoder_signal(codec::load_signal(resolved, signal));
    Scan1D scan;
    scan.amplitude = loaded.amplitude;
    scan.spacing = loaded.spacing;
    scan.direction_deg = entries[i].second;
    scan.description = "scans[" + std::to_string(i) + "] " + loaded.description;
    b.scans.push_back(std::move(scan));
  }
  return b;
}

Encode2DResult encode_2d_file(const std::string& path, const Raster2DLoadOptions& load, const SignalOptions& signal,
                              Encode2DConfig config) {
  if (output_extension(path) == ".scans.json") {
    if (load.pitch) config.device.reset();
    return encode_scans(load_scan_bundle(path, signal), config);
  }
  if (!is_2d_input(path))
    throw InvalidArgument("'" + path +
                          "' is not a 2-D input: a 2-D encode reads a grey .png, a 2-D .npy or a .scans.json bundle");
  const Input2D in = load_input2d(path, load);
  config.depth = in.depth == 8 ? 8 : 16;
  config.polarity = in.polarity;
  return encode_surface2d(in.map, config);
}

}  // namespace texel::codec
