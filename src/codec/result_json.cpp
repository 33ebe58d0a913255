// The encode result as JSON: the one serialisation of codec::EncodeResult
// every front door prints (docs/format.md, "Result field names").
#include <nlohmann/json.hpp>

#include "texel/codec.hpp"
#include "texel/error.hpp"

namespace texel::codec {

namespace {

nlohmann::ordered_json percept_json(const Percept& p) {
  nlohmann::ordered_json j;
  for (const auto& [name, value] : fields(p)) j[name] = value;
  return j;
}

}  // namespace

std::string to_json(const EncodeResult& r) {
  nlohmann::ordered_json j;
  j["samples"] = r.samples;
  j["spacing_mm"] = r.spacing.value();
  j["swipe_speed_mm_s"] = r.model.swipe_speed.value();
  const TexelSpec& s = r.spec;
  nlohmann::ordered_json e;
  e["central_pitch_db"] = s.central_pitch.value();
  e["irregularity_db"] = s.irregularity.value();
  e["irregularity_identifiable"] = r.irregularity_identifiable;
  if (!r.irregularity_identifiable && r.irregularity_bound_db != 0.0)
    e["irregularity_feels_same_below_db"] = r.irregularity_bound_db;
  e["at_bound"] = {{"central_pitch", r.at_bound.central_pitch}, {"irregularity", r.at_bound.irregularity}};
  e["no_texture"] = r.no_texture;
  e["texture_rms"] = r.texture_rms;
  e["texel_recovered"] = r.texel_recovered;  // the input was recognised as a Texel rendering
  e["texel_length_mm"] = s.texel_length.value();
  e["parameterization"] = std::string(to_string(s.parameterization));
  e["seed"] = s.seed;
  e["band_max_cpm"] = s.band_max.value();
  e["coarse"] = r.coarse;
  e["coarse_strength"] = s.coarse_strength;
  e["fine_strength"] = s.fine_strength;
  if (r.bitstream.coarse && r.bitstream.coarse->bits > 0) {
    e["coarse_levels"] = r.bitstream.coarse->levels.size();
    e["coarse_bits"] = r.bitstream.coarse->bits;
    e["coarse_stride_texels"] = r.bitstream.coarse->stride;
    e["coarse_correlation"] = r.coarse_correlation;
  }
  j["estimate"] = e;
  nlohmann::ordered_json m;
  m["version"] = r.model_version;
  m["input"] = percept_json(r.input);
  m["decoded"] = percept_json(r.decoded);
  m["distance_jnd"] = r.model_distance;
  m["evaluations"] = r.evaluations;
  m["fit"] = std::string(to_string(r.fit_method));
  m["target"] = std::string(to_string(r.target));
  m["display_response"] = std::string(to_string(r.model.display_response));
  if (display_in_loop(r.model)) {
    m["display"] = {{"corner_hz", r.model.display.corner.value()}, {"order", r.model.display.order}};
    m["drawn_weight"] = r.model.drawn_weight;
  }
  j["model"] = m;
  // The felt band (docs/encoder.md §2, "Version 3"): its top and the share
  // of the input's power above it, whatever the model.
  j["felt_band"] = {{"top_hz", r.model.felt_band_top.value()},
                    {"top_cpm", felt_band_top_cpm(r.model).value()},
                    {"power_beyond", r.beyond_felt_band}};
  j["warnings"] = r.warnings;
  nlohmann::ordered_json z;
  z["bitstream_bytes"] = r.bytes.size();
  z["raw_u16_bytes"] = r.samples * 2;
  z["ratio"] = static_cast<double>(r.samples * 2) / static_cast<double>(r.bytes.size());
  j["sizes"] = z;
  j["seconds"] = r.seconds;
  return j.dump();
}

std::string_view to_string(EncoderConfig::NoTexture n) { return n == EncoderConfig::NoTexture::refuse ? "refuse" : "flag"; }

EncoderConfig::NoTexture parse_no_texture(std::string_view text, std::string_view field) {
  if (text == "flag") return EncoderConfig::NoTexture::flag;
  if (text == "refuse") return EncoderConfig::NoTexture::refuse;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: flag, refuse");
}

std::string_view to_string(EncoderConfig::Target t) {
  switch (t) {
    case EncoderConfig::Target::felt: return "felt";
    case EncoderConfig::Target::centroid: return "centroid";
    default: return "automatic";
  }
}

EncoderConfig::Target parse_target(std::string_view text, std::string_view field) {
  if (text == "automatic") return EncoderConfig::Target::automatic;
  if (text == "felt") return EncoderConfig::Target::felt;
  if (text == "centroid") return EncoderConfig::Target::centroid;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: automatic, felt, centroid");
}

}  // namespace texel::codec
