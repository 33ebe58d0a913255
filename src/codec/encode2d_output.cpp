// The 2-D encoder's result written out (texel/encode2d.hpp): the document
// and its coarse image, atomically and together, and the result as JSON, the
// one serialisation every front door prints.
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "texel/encode2d.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::codec {

void write_encoding2d(const Encode2DResult& result, const std::string& document_path) {
  const std::string text = document_json(result.document);
  std::optional<AtomicFile> image;
  if (result.coarse_image && result.document.surface2d) {
    const auto* im = std::get_if<Image2D>(&result.document.surface2d->regions.at(0).coarse);
    if (!im) throw InvalidArgument("write_encoding2d: the result has a coarse image but its region names none");
    const std::filesystem::path at = std::filesystem::path(document_path).parent_path() / im->path;
    const Raster2D& img = *result.coarse_image;
    image.emplace(at.string());
    image->write(npy_header(static_cast<std::size_t>(img.height), static_cast<std::size_t>(img.width)));
    std::vector<double> row(static_cast<std::size_t>(img.width));
    for (int j = 0; j < img.height; ++j) {
      for (int i = 0; i < img.width; ++i) row[static_cast<std::size_t>(i)] = img.at(i, j);
      image->write(std::span<const std::byte>(reinterpret_cast<const std::byte*>(row.data()), row.size() * sizeof(double)));
    }
  }
  AtomicFile doc(document_path);
  doc.write(text);
  if (image) image->commit();
  try {
    doc.commit();
  } catch (...) {
    if (image) std::filesystem::remove(image->path());
    throw;
  }
}

std::string to_json(const Encode2DResult& r) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json e;
  e["central_pitch_db"] = r.spec.central_pitch.value();
  e["irregularity_db"] = r.spec.irregularity.value();
  e["texel_length_mm"] = r.spec.texel_length.value();
  e["parameterization"] = std::string(to_string(r.spec.parameterization));
  e["seed"] = r.spec.seed;
  e["coarse_strength"] = r.spec.coarse_strength;
  e["fine_strength"] = r.spec.fine_strength;
  e["field"] = std::string(to_string(r.field));
  e["coarse"] = r.coarse;
  j["method"] = r.method;
  j["estimate"] = e;
  nlohmann::ordered_json flags;
  flags["irregularity_identifiable"] = r.irregularity_identifiable;
  if (!r.irregularity_identifiable) flags["irregularity_bound_db"] = r.irregularity_bound_db;
  flags["texel_length_detected"] = r.texel_length_detected;
  flags["no_texture"] = r.no_texture;
  flags["texture_rms"] = r.texture_rms;
  j["flags"] = flags;
  nlohmann::ordered_json a;
  a["anisotropic"] = r.anisotropic;
  a["central_pitch_spread_db"] = r.central_pitch_spread_db;
  a["irregularity_spread_db"] = r.irregularity_spread_db;
  a["strongest_direction_deg"] = r.strongest_direction_deg;
  a["mean_central_pitch_db"] = r.mean_central_pitch_db;
  a["mean_irregularity_db"] = r.mean_irregularity_db;
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const auto& d : r.per_direction)
    rows.push_back({{"direction_deg", d.direction_deg},
                    {"central_pitch_db", d.central_pitch_db},
                    {"irregularity_db", d.irregularity_db},
                    {"pitch_db", d.percept.pitch_db},
                    {"noisiness_db", d.percept.noisiness_db},
                    {"spread_db", d.percept.spread_db},
                    {"samples", d.samples},
                    {"scans", d.scans}});
  a["directions"] = rows;
  j["anisotropy"] = a;
  j["model"] = {{"version", r.model_version},
                {"target", std::string(to_string(r.target))},
                {"correction_rounds", r.correction_rounds},
                {"correction_residual_db", r.correction_residual_db}};
  return j.dump(2);
}

}  // namespace texel::codec
