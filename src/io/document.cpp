// The versioned *.texel.json document (document.hpp, docs/format.md): read
// with JSON paths and strict validation, written back, and prepared as a
// surface. The 2-D surface section is document_surface2d.cpp.
#include "texel/document.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "document_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel {

using namespace document_parts;

namespace {

constexpr const char* format_tag = "texel-document";

/// {"kind": "reference", "name": ..., "seed": ..., "params": {...}}; values
/// are typed by the generator's parameter list (numbers, arrays, words).
ReferenceSpec parse_reference(JsonObject& o) {
  ReferenceSpec spec;
  spec.name = o.string("name");
  const ReferenceInfo* info = nullptr;
  try {
    info = &reference_info(spec.name);
  } catch (const InvalidArgument& e) {
    throw FormatError(o.field("name") + ": " + e.what());
  }
  spec.seed = o.uint64_or("seed", 1);
  if (o.has("params")) {
    const auto& pj = o.raw("params");
    if (!pj.is_object()) throw FormatError(o.field("params") + " must be an object of parameter values");
    for (auto it = pj.begin(); it != pj.end(); ++it) {
      const std::string field = o.field("params") + "." + it.key();
      const ReferenceParam* param = nullptr;
      for (const auto& p : info->params)
        if (p.key == it.key()) param = &p;
      if (!param) {
        std::string keys;
        for (const auto& p : info->params) keys += (keys.empty() ? "" : ", ") + p.key;
        throw FormatError(field + " is not a parameter of reference '" + spec.name + "' (its parameters: " + keys + ")");
      }
      const json& v = it.value();
      switch (param->kind) {
        case ReferenceParamKind::number:
        case ReferenceParamKind::integer:
          if (!v.is_number()) throw FormatError(field + " must be a number, got " + JsonObject::type_of(v));
          spec.params[it.key()] = v.get<double>();
          break;
        case ReferenceParamKind::list: {
          if (!v.is_array()) throw FormatError(field + " must be an array of numbers, got " + JsonObject::type_of(v));
          std::vector<double> values;
          for (std::size_t i = 0; i < v.size(); ++i) {
            if (!v[i].is_number()) throw FormatError(field + "[" + std::to_string(i) + "] must be a number");
            values.push_back(v[i].get<double>());
          }
          spec.params[it.key()] = std::move(values);
          break;
        }
        case ReferenceParamKind::choice:
          if (!v.is_string()) throw FormatError(field + " must be a string, got " + JsonObject::type_of(v));
          spec.params[it.key()] = v.get<std::string>();
          break;
      }
    }
  } else {
    o.skip("params");
  }
  try {
    validate(spec);
  } catch (const InvalidArgument& e) {
    throw FormatError(o.where() + ": " + e.what());
  }
  return spec;
}

ordered reference_json(const ReferenceSpec& spec) {
  ordered j;
  j["kind"] = "reference";
  j["name"] = spec.name;
  j["seed"] = spec.seed;
  ordered params = ordered::object();
  for (const auto& [key, value] : spec.params) {
    if (const auto* d = std::get_if<double>(&value))
      params[key] = *d;
    else if (const auto* l = std::get_if<std::vector<double>>(&value))
      params[key] = *l;
    else
      params[key] = std::get<std::string>(value);
  }
  j["params"] = std::move(params);
  return j;
}

CoarseProfile parse_coarse(const json& j, const std::string& path) {
  JsonObject o(j, path);
  const std::string kind = o.string("kind");
  CoarseProfile profile;
  if (kind == "constant") {
    profile = ConstantProfile{o.number_or("value", 1.0, 0.0, 1.0)};
  } else if (kind == "sine") {
    SineProfile s;
    s.period = Millimetres(o.number("period_mm", 1e-9, 1e9));
    s.phase_deg = o.number_or("phase_deg", 0.0, -1e9, 1e9);
    profile = s;
  } else if (kind == "values") {
    const auto& arr = o.raw("values");
    if (!arr.is_array() || arr.empty()) throw FormatError(o.field("values") + " must be a non-empty array of numbers in 0 … 1");
    ValuesProfile v;
    for (std::size_t i = 0; i < arr.size(); ++i) {
      if (!arr[i].is_number()) throw FormatError(o.field("values") + "[" + std::to_string(i) + "] must be a number");
      v.values.push_back(arr[i].get<double>());
    }
    profile = std::move(v);
  } else if (kind == "points") {
    const auto& arr = o.raw("points");
    if (!arr.is_array() || arr.empty())
      throw FormatError(o.field("points") + " must be a non-empty array of [position_mm, value] pairs");
    PointsProfile p;
    for (std::size_t i = 0; i < arr.size(); ++i) {
      const auto& pt = arr[i];
      if (!pt.is_array() || pt.size() != 2 || !pt[0].is_number() || !pt[1].is_number())
        throw FormatError(o.field("points") + "[" + std::to_string(i) + "] must be a pair [position_mm, value], got " +
                          pt.dump());
      p.points.emplace_back(pt[0].get<double>(), pt[1].get<double>());
    }
    profile = std::move(p);
  } else {
    throw FormatError(o.field("kind") + " is '" + kind + "'; allowed: constant, sine, values, points, reference");
  }
  o.finish();
  try {
    validate(profile);
  } catch (const InvalidArgument& e) {
    throw FormatError(path + ": " + e.what());
  }
  return profile;
}

ordered coarse_json(const CoarseProfile& profile) {
  ordered j;
  j["kind"] = kind_name(profile);
  if (const auto* c = std::get_if<ConstantProfile>(&profile)) {
    j["value"] = c->value;
  } else if (const auto* s = std::get_if<SineProfile>(&profile)) {
    j["period_mm"] = s->period.value();
    j["phase_deg"] = s->phase_deg;
  } else if (const auto* v = std::get_if<ValuesProfile>(&profile)) {
    j["values"] = v->values;
  } else if (const auto* p = std::get_if<PointsProfile>(&profile)) {
    j["points"] = ordered::array();
    for (const auto& [x, y] : p->points) j["points"].push_back({x, y});
  } else if (const auto* sp = std::get_if<SampledProfile>(&profile)) {
    // A sampled profile is written as points, which the parser reads back.
    j["kind"] = "points";
    j["points"] = ordered::array();
    for (std::size_t i = 0; i < sp->values.size(); ++i)
      j["points"].push_back({static_cast<double>(i) * sp->spacing.value(), sp->values[i]});
  }
  return j;
}

}  // namespace

namespace document_parts {

/// A region's texture: a Texel texture (possibly with a reference as its
/// coarse profile) or a reference.
void parse_texture(const json& j, const std::string& path, RegionSpec& region) {
  JsonObject o(j, path);
  const std::string kind = o.string("kind");
  if (kind == "reference") {
    region.reference = parse_reference(o);
    o.finish();
    return;
  }
  if (kind != "texel") throw FormatError(o.field("kind") + " is '" + kind + "'; allowed: texel, reference");
  TexelSpec s;
  s.central_pitch = Decibels(o.number("central_pitch_db", central_pitch_db_min, central_pitch_db_max));
  s.irregularity = Decibels(o.number("irregularity_db", irregularity_db_min, irregularity_db_max));
  s.texel_length = Millimetres(o.number("texel_length_mm", texel_length_mm_min, texel_length_mm_max));
  s.seed = o.uint64("seed");
  s.parameterization = enum_field(o, "parameterization", s.parameterization, parse_parameterization);
  s.out_of_band = enum_field(o, "out_of_band", s.out_of_band, parse_out_of_band);
  s.band_min = CyclesPerMm(o.number_or("band_min_cpm", s.band_min.value(), band_cpm_min, band_cpm_max));
  s.band_max = CyclesPerMm(o.number_or("band_max_cpm", 0.0, 0.0, band_cpm_max));
  s.quantization_db = o.number_or("quantization_db", 0.0, 0.0, quantization_db_max);
  s.phase = enum_field(o, "phase", s.phase, parse_phase_mode);
  s.fill = enum_field(o, "fill", s.fill, parse_fill);
  s.coarse_strength = o.number_or("coarse_strength", 0.0, 0.0, 1.0);
  s.fine_strength = o.number_or("fine_strength", 1.0, 0.0, 1.0);
  if (o.has("coarse")) {
    const json& cj = o.raw("coarse");
    if (cj.is_object() && cj.contains("kind") && cj["kind"] == "reference") {
      JsonObject c(cj, o.field("coarse"));
      c.skip("kind");
      region.coarse_reference = parse_reference(c);
      c.finish();
    } else {
      s.coarse = parse_coarse(cj, o.field("coarse"));
    }
  } else {
    o.skip("coarse");
  }
  o.finish();
  try {
    validate(s);
  } catch (const InvalidArgument& e) {
    throw FormatError(path + ": " + e.what());
  }
  region.texel = s;
}

ordered texel_json(const TexelSpec& s, const std::optional<ReferenceSpec>& coarse_reference) {
  ordered j;
  j["kind"] = "texel";
  j["central_pitch_db"] = s.central_pitch.value();
  j["irregularity_db"] = s.irregularity.value();
  j["texel_length_mm"] = s.texel_length.value();
  j["seed"] = s.seed;
  j["parameterization"] = std::string(to_string(s.parameterization));
  j["out_of_band"] = std::string(to_string(s.out_of_band));
  j["band_min_cpm"] = s.band_min.value();
  j["band_max_cpm"] = s.band_max.value();
  j["quantization_db"] = s.quantization_db;
  j["phase"] = std::string(to_string(s.phase));
  j["fill"] = std::string(to_string(s.fill));
  j["coarse_strength"] = s.coarse_strength;
  j["fine_strength"] = s.fine_strength;
  j["coarse"] = coarse_reference ? reference_json(*coarse_reference) : coarse_json(s.coarse);
  return j;
}

}  // namespace document_parts

namespace {

bool is_builtin_unchanged(const DeviceProfile& d) {
  for (const auto& name : builtin_device_names())
    if (name == d.name) return device_profile_json(load_device(name)) == device_profile_json(d);
  return false;
}

}  // namespace

Document parse_document(std::string_view text, std::string_view origin) {
  const json j = detail::parse_json(text, origin);
  const std::string where(origin);
  try {
    JsonObject o(j, "");
    Document doc;
    const std::string tag = o.string("format");
    if (tag != format_tag) throw FormatError("format is '" + tag + "'; expected '" + std::string(format_tag) + "'");
    doc.version = static_cast<int>(o.integer("version", 1, 1000));
    if (doc.version > Document::current_version)
      throw FormatError("version is " + std::to_string(doc.version) + "; this build of Texel reads versions up to " +
                        std::to_string(Document::current_version) + " (upgrade Texel)");
    doc.description = o.string_or("description", "");
    const auto& dev = o.raw("device");
    if (dev.is_string()) {
      try {
        doc.device = load_device(dev.get<std::string>());
      } catch (const InvalidArgument& e) {
        throw FormatError(std::string("device: ") + e.what());
      }
    } else if (dev.is_object()) {
      doc.device = parse_device_profile(dev.dump(), "device");
      doc.device_inline = true;
    } else {
      throw FormatError("device must be a device name or an inline profile object, got " + JsonObject::type_of(dev));
    }
    if (o.has("device_grid")) {
      JsonObject g(o.raw("device_grid"), "device_grid");
      const auto length = g.optional_number("length_mm", 1e-9, 1e9);
      const auto spacing = g.optional_number("spacing_mm", 1e-9, 1e6);
      g.finish();
      try {
        doc.device = with_grid(doc.device, millimetres(length), millimetres(spacing));
      } catch (const InvalidArgument& e) {
        throw FormatError(std::string("device_grid: ") + e.what());
      }
    } else {
      o.skip("device_grid");
    }
    const bool has_texture = o.has("texture");
    const bool has_regions = o.has("regions");
    if (o.has("surface2d")) {
      if (doc.version < 4 || doc.version > 5)
        throw FormatError("surface2d needs version 4 or 5 (a 2-D document); version is " + std::to_string(doc.version));
      if (has_texture || has_regions) throw FormatError("a 2-D document gives 'surface2d' and neither 'texture' nor 'regions'");
      if (!doc.device.bitmap)
        throw FormatError("device: '" + doc.device.name + "' has no bitmap grid (device.bitmap), which a 2-D document needs");
      o.skip("texture");
      o.skip("regions");
      doc.surface2d = parse_surface2d(o.raw("surface2d"), doc.device, doc.version);
      o.finish();
      return doc;
    }
    o.skip("surface2d");
    if (doc.version == 4 || doc.version == 5)
      throw FormatError("version " + std::to_string(doc.version) + " is a 2-D document and needs 'surface2d'");
    if (o.has("playback")) {
      if (doc.version < 6)
        throw FormatError("playback needs version 6 (multi-channel playback); version is " + std::to_string(doc.version));
      JsonObject p(o.raw("playback"), "playback");
      ChannelPlayback playback;
      playback.mode = enum_field(p, "mode", ChannelMode::sequential,
                                 [](std::string_view t, std::string_view f) { return parse_channel_mode(t, f); });
      if (p.has("channel")) {
        const std::int64_t c = p.integer("channel", 0, static_cast<std::int64_t>(max_actuators) - 1);
        if (static_cast<std::size_t>(c) >= doc.device.channels())
          throw FormatError("playback.channel is " + std::to_string(c) + "; allowed: 0 … " +
                            std::to_string(doc.device.channels() - 1) + " (device '" + doc.device.name + "' has " +
                            std::to_string(doc.device.channels()) + " channels)");
        playback.channel = static_cast<std::size_t>(c);
      } else {
        p.skip("channel");
      }
      p.finish();
      try {
        validate(playback, doc.device.channels());
      } catch (const InvalidArgument& e) {
        throw FormatError(e.what());
      }
      doc.playback = playback;
    } else {
      o.skip("playback");
    }
    if (has_texture == has_regions) throw FormatError("give exactly one of 'texture' (whole device) or 'regions'");
    if (has_texture) {
      o.skip("regions");
      RegionSpec r;
      parse_texture(o.raw("texture"), "texture", r);
      doc.regions.push_back(std::move(r));
    } else {
      o.skip("texture");
      const auto& arr = o.raw("regions");
      if (!arr.is_array() || arr.empty()) throw FormatError("regions must be a non-empty array");
      for (std::size_t i = 0; i < arr.size(); ++i) {
        const std::string path = "regions[" + std::to_string(i) + "]";
        JsonObject r(arr[i], path);
        RegionSpec spec;
        spec.name = r.string_or("name", "");
        spec.start = Millimetres(r.number_or("start_mm", 0.0, 0.0, 1e9));
        spec.length = millimetres(r.optional_number("length_mm", 1e-9, 1e9));
        parse_texture(r.raw("texture"), path + ".texture", spec);
        r.finish();
        doc.regions.push_back(std::move(spec));
      }
    }
    o.finish();
    // The version fixes the references' bytes: a version-2 document keeps
    // the direct synthesis it was made with.
    for (auto& r : doc.regions) {
      if (r.reference) r.reference->synthesis = reference_synthesis(doc.version);
      if (r.coarse_reference) r.coarse_reference->synthesis = reference_synthesis(doc.version);
    }
    (void)prepare_surface(doc);  // layout and distribution errors surface at load time
    if (doc.playback && doc.playback->mode == ChannelMode::simultaneous) (void)prepare_channels(doc);
    return doc;
  } catch (const Error& e) {
    throw FormatError(where + ": " + e.what());
  }
}

Document load_document(const std::string& path) {
  // An MPEG-I Haptics file is no Texel document (a .hmpg is not even JSON):
  // say what it is and what reads it, rather than a JSON parser's complaint.
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".hjif" || ext == ".hmpg")
    throw FormatError(path + ": an MPEG-I Haptics file, not a Texel document; encode it to one (texel encode " + path +
                      " -o x.texel.json: the document it carries, exactly, when Texel wrote it) or read it as a signal "
                      "(texel spectrum, texel info)");
  Document doc = parse_document(read_file(path), path);
  // A 2-D coarse image named by a relative path is found beside the document.
  if (doc.surface2d) {
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    for (auto& r : doc.surface2d->regions)
      if (auto* image = std::get_if<Image2D>(&r.coarse); image && std::filesystem::path(image->path).is_relative())
        image->path = (dir / image->path).string();
  }
  return doc;
}

std::string document_json(const Document& doc) {
  ordered j;
  j["format"] = format_tag;
  j["version"] = required_version(doc);
  if (!doc.description.empty()) j["description"] = doc.description;
  if (doc.device_inline || !is_builtin_unchanged(doc.device)) {
    j["device"] = ordered::parse(device_profile_json(doc.device));
  } else {
    j["device"] = doc.device.name;
  }
  if (doc.surface2d) {
    j["surface2d"] = surface2d_json(*doc.surface2d);
    return j.dump(2) + "\n";
  }
  const bool whole =
      doc.regions.size() == 1 && doc.regions[0].start.value() == 0.0 && !doc.regions[0].length && doc.regions[0].name.empty();
  const auto texture_json = [](const RegionSpec& r) {
    return r.reference ? reference_json(*r.reference) : texel_json(r.texel, r.coarse_reference);
  };
  if (whole) {
    j["texture"] = texture_json(doc.regions[0]);
  } else {
    j["regions"] = ordered::array();
    for (const auto& r : doc.regions) {
      ordered rj;
      if (!r.name.empty()) rj["name"] = r.name;
      rj["start_mm"] = r.start.value();
      if (r.length) rj["length_mm"] = r.length->value();
      rj["texture"] = texture_json(r);
      j["regions"].push_back(std::move(rj));
    }
  }
  if (doc.playback) {
    ordered p;
    p["mode"] = std::string(to_string(doc.playback->mode));
    if (doc.playback->channel) p["channel"] = *doc.playback->channel;
    j["playback"] = p;
  }
  return j.dump(2) + "\n";
}

void save_document(const Document& doc, const std::string& path) { write_file_atomic(path, document_json(doc)); }

Document make_document(const DeviceProfile& device, const TexelSpec& spec) {
  Document doc;
  doc.device = device;
  RegionSpec r;
  r.texel = spec;
  doc.regions.push_back(std::move(r));
  return doc;
}

Document make_reference_document(const DeviceProfile& device, const ReferenceSpec& spec) {
  Document doc;
  doc.device = device;
  RegionSpec r;
  r.reference = spec;
  doc.regions.push_back(std::move(r));
  return doc;
}

ReferenceSynthesis reference_synthesis(int version) {
  return version >= 3 ? ReferenceSynthesis::chirp_z : ReferenceSynthesis::direct;
}

int required_version(const Document& doc) {
  // A 2-D document is version 4 unless a region's field is tile (version 5).
  if (doc.surface2d)
    return std::any_of(doc.surface2d->regions.begin(), doc.surface2d->regions.end(),
                       [](const Region2DSpec& r) { return r.field == Field2D::tile; })
               ? 5
               : 4;
  int version = 1;
  std::size_t first = 0;
  for (std::size_t i = 0; i < doc.regions.size(); ++i) {
    for (const auto* ref : {&doc.regions[i].reference, &doc.regions[i].coarse_reference}) {
      if (!*ref) continue;
      const int v = (*ref)->synthesis == ReferenceSynthesis::chirp_z ? 3 : 2;
      if (version > 1 && v != version)
        throw InvalidArgument("regions " + std::to_string(first) + " and " + std::to_string(i) +
                              " hold references of different syntheses (format versions " + std::to_string(version) + " and " +
                              std::to_string(v) + "); one document renders with one (set ReferenceSpec::synthesis alike)");
      if (version == 1) first = i;
      version = v;
    }
  }
  if (doc.playback) {
    // Version 6 synthesises references as version 3 does; version-2 references cannot be in it.
    if (version == 2)
      throw InvalidArgument("region " + std::to_string(first) +
                            " holds a version-2 (direct synthesis) reference, and playback needs version 6, whose references "
                            "use the chirp-z synthesis");
    return 6;
  }
  return version;
}

Surface prepare_surface(const Document& doc) {
  if (doc.surface2d)
    throw InvalidArgument("a 2-D document (surface2d) renders with --surface 2d (prepare_surface2d), not as a 1-D map");
  if (doc.regions.empty()) throw InvalidArgument("document has no regions");
  const Grid grid = doc.device.grid();
  std::vector<Region> regions;
  for (std::size_t i = 0; i < doc.regions.size(); ++i) {
    const RegionSpec& spec = doc.regions[i];
    const std::string label = doc.regions.size() == 1 ? std::string() : "region " + std::to_string(i) + ": ";
    Region r;
    r.name = spec.name;
    r.start = spec.start;
    r.length = spec.length ? *spec.length : grid.length() - spec.start;
    if (!(r.length.value() > 0.0))
      throw InvalidArgument(label + "start_mm " + detail::num(spec.start.value()) + " mm is at or past the device's end (" +
                            detail::num(grid.length().value()) + " mm)");
    // Checked before the texture is built, not only by Surface afterwards: a
    // region's texture is prepared over its own length, so a 1e9 mm region
    // on a 100 mm device would allocate 10^11 texels first.
    if (r.start.value() + r.length.value() > grid.length().value() + 1e-3)
      throw InvalidArgument(label + "start_mm " + detail::num(r.start.value()) + " mm + length_mm " +
                            detail::num(r.length.value()) + " mm ends past the device's active length " +
                            detail::num(grid.length().value()) + " mm");
    try {
      // The texture's own coordinates: 0 mm at the region's left edge (as Surface::render passes them).
      const Sampling local{Grid{grid.origin - r.start, grid.spacing, grid.count}, doc.device.band_top()};
      if (spec.reference) {
        r.texture = prepare(*spec.reference, r.length, local);
      } else if (spec.coarse_reference) {
        TexelSpec texel = spec.texel;
        texel.coarse = reference_profile(*spec.coarse_reference, r.length, grid.spacing);
        r.texture = prepare(texel, r.length, local);
      } else {
        r.texture = prepare(spec.texel, r.length, local);
      }
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(label + e.what());
    }
    regions.push_back(std::move(r));
  }
  return Surface(grid, std::move(regions));
}

}  // namespace texel
