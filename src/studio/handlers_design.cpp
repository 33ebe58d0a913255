// Designer messages: hello (what the front end offers: devices, references,
// limits) and design (the map, spectrum, histogram and encoded size of a
// document), plus the checks every document from a client passes
// (document_of). Every number comes from design.hpp; this file formats.
#include <algorithm>
#include <bit>
#include <cmath>
#include <variant>

#include "base64.hpp"
#include "messages.hpp"
#include "texel/device.hpp"
#include "texel/distribution.hpp"
#include "texel/error.hpp"
#include "texel/reference.hpp"
#include "texel/texture.hpp"

#ifndef TEXEL_VERSION
#define TEXEL_VERSION "unknown"
#endif

namespace texel::studio::detail {

namespace {

ojson reference_param_json(const ReferenceParam& p) {
  static constexpr const char* kinds[] = {"number", "integer", "list", "choice"};
  ojson j{{"key", p.key}, {"kind", kinds[static_cast<int>(p.kind)]}, {"unit", p.unit}, {"description", p.description}};
  std::visit([&](const auto& v) { j["default"] = v; }, p.default_value);
  if (p.kind == ReferenceParamKind::choice) {
    j["choices"] = p.choices;
  } else {
    j["min"] = p.min;
    j["max"] = p.max;
  }
  if (p.kind == ReferenceParamKind::list) {
    j["min_count"] = p.min_count;
    j["max_count"] = p.max_count;
  }
  return j;
}

void check_cost(const State& s, const json& j, const DeviceProfile& device, const std::string& where) {
  const auto cap = s.options.max_map_samples;
  if (static_cast<double>(device.samples) > static_cast<double>(cap))
    throw Reject{"too_large",
                 where + ".device has " + std::to_string(device.samples) + " samples; allowed: at most " + std::to_string(cap)};
  std::vector<const json*> textures;
  if (j.contains("texture")) textures.push_back(&j["texture"]);
  if (j.contains("regions") && j["regions"].is_array())
    for (const auto& r : j["regions"])
      if (r.is_object() && r.contains("texture")) textures.push_back(&r["texture"]);
  for (const json* t : textures) {
    if (!t->is_object() || !t->contains("texel_length_mm") || !(*t)["texel_length_mm"].is_number()) continue;
    const double length = (*t)["texel_length_mm"].get<double>();
    // The designer states this bound as the same quotient (samples × spacing / cap), so a length
    // it accepts is one this accepts, to the last bit.
    const double shortest = device.length().value() / static_cast<double>(cap);
    if (length > 0 && length < shortest)
      throw Reject{"too_large", where + ": texel_length_mm " + json(length).dump() + " makes more than " + std::to_string(cap) +
                                    " texels; allowed: at least " + json(shortest).dump() + " mm on this device"};
  }
}

}  // namespace

ojson spectrum_json(const SpectrumView& s) { return ojson{{"frequency_cpm", s.frequency_cpm}, {"magnitude_db", s.magnitude_db}}; }

std::string hex(std::span<const std::byte> bytes) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string h;
  for (const std::byte b : bytes) {
    h += digits[std::to_integer<unsigned>(b) >> 4];
    h += digits[std::to_integer<unsigned>(b) & 15];
  }
  return h;
}

void require_builtin_device(std::string_view name, const std::string& what) {
  const auto names = builtin_device_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) throw Reject{"invalid", what};
}

// A client's document: built-in devices only (a device name may be a path
// to any file), and a map and texel count the service will render. The
// caps are checked on the JSON before parse_document, which prepares every
// texture to validate it (a 1 nm texel length would mean 10^8 texels).
Document document_of(const State& s, const json& j, const std::string& where) {
  if (!j.is_object()) throw Reject{"bad_message", where + " must be a document object, got " + j.type_name()};
  std::optional<DeviceProfile> device;
  if (j.contains("device") && j["device"].is_string()) {
    const auto names = builtin_device_names();
    const auto& name = j["device"].get_ref<const std::string&>();
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      throw Reject{"invalid", where + ".device is " + clipped(name) + "; allowed: " + list + " or an inline profile"};
    }
    device = load_device(name);
  } else if (j.contains("device") && j["device"].is_object()) {
    device = parse_device_profile(j["device"].dump(), where + ".device");
  }
  if (device && j.contains("device_grid") && j["device_grid"].is_object()) {
    const json& g = j["device_grid"];
    auto opt = [&](const char* k) {
      return g.contains(k) && g[k].is_number() ? std::optional(g[k].get<double>()) : std::nullopt;
    };
    device = with_grid(*device, millimetres(opt("length_mm")), millimetres(opt("spacing_mm")));
  }
  if (device) check_cost(s, j, *device, where);
  return parse_document(j.dump(), where);
}

std::optional<std::size_t> region_field(const Fields& f, const char* key) {
  if (!f.has(key)) return std::nullopt;
  return static_cast<std::size_t>(f.integer(key, 0, 1023));
}

ojson make_hello(const State& s) {
  ojson h{{"type", "hello"}, {"version", TEXEL_VERSION}, {"backend", s.presenter->describe()}};
  h["devices"] = ojson::array();
  for (const auto& name : builtin_device_names()) h["devices"].push_back(ojson::parse(device_profile_json(load_device(name))));
  h["references"] = ojson::array();
  for (const auto& info : reference_catalogue()) {
    ojson r{{"name", info.name}, {"family", info.family}, {"description", info.description}, {"uses_seed", info.uses_seed}};
    r["parameters"] = ojson::array();
    for (const auto& p : info.params) r["parameters"].push_back(reference_param_json(p));
    h["references"].push_back(std::move(r));
  }
  h["parameterizations"] = {"moments", "log"};
  h["export_formats"] = {"document", "bitstream", "device", "npy", "csv", "hjif"};
  h["import_extensions"] = {".texel.json", ".json", ".texel", ".bin", ".npy", ".csv", ".wav"};
  h["limits"] = {{"max_message_bytes", s.options.max_message_bytes},
                 {"max_messages_per_s", s.options.max_messages_per_s},
                 {"max_queued_jobs", max_queued_jobs},
                 {"max_map_samples", s.options.max_map_samples},
                 {"max_name_chars", max_name_chars}};
  // The library's own ranges of a Texel texture's fields: the designer checks
  // typed values against them and states them, so each must be the engine's
  // rule exactly (tests/studio checks both sides of every bound against
  // `design`). null = unbounded (finite); exclusive_min: the bound itself is
  // refused. Texel length's lower bound on a device is also at least the
  // device's length / limits.max_map_samples (check_cost above).
  auto range = [](double lo, double hi) { return ojson{{"min", lo}, {"max", hi}}; };
  h["texture_limits"] = {
      {"central_pitch_db", range(central_pitch_db_min, central_pitch_db_max)},
      {"irregularity_db", range(irregularity_db_min, irregularity_db_max)},
      // Under the log parameterization the spread is a dB of log-spread, >= 0 (PitchDistribution's constructor).
      {"irregularity_db_log", range(0.0, irregularity_db_max)},
      {"texel_length_mm", range(texel_length_mm_min, texel_length_mm_max)},
      {"quantization_db", range(0.0, quantization_db_max)},
      {"coarse_strength", range(0.0, 1.0)},
      {"fine_strength", range(0.0, 1.0)},
      // The coarse profiles' ranges as the document reader checks them (src/io/document.cpp).
      {"coarse_value", range(0.0, 1.0)},
      {"sine_period_mm", range(1e-9, 1e9)},
      {"sine_phase_deg", range(-1e9, 1e9)},
      // The renderable band's edges as the document reader takes them. On a device band_min must
      // also lie below the band's top (device_limits); band_max is 0 (the grid's Nyquist
      // frequency) or above band_min, and above the device's top it means that top.
      {"band_min_cpm", range(band_cpm_min, band_cpm_max)},
      {"band_max_cpm", range(0.0, band_cpm_max)}};
  // On a device, a Central Pitch must also lie in the renderable band: the texel
  // texture's band_min (default 0.01 cpm) up to the device's band top (its
  // band_max or Nyquist frequency) — PitchDistribution's rule, which allows
  // 1e-9 dB beyond either edge.
  h["device_limits"] = ojson::array();
  for (const auto& name : builtin_device_names()) {
    const DeviceProfile d = load_device(name);
    const double lo = std::max(central_pitch_db_min, 10.0 * std::log10(TexelSpec{}.band_min.value()));
    const double hi = std::min(central_pitch_db_max, 10.0 * std::log10(d.band_top().value()));
    h["device_limits"].push_back(
        {{"device", name},
         {"central_pitch_db", range(lo, hi)},
         {"band_min_cpm", ojson{{"min", band_cpm_min}, {"max", d.band_top().value()}, {"exclusive_max", true}}}});
  }
  return h;
}

void on_hello(State& s, Client& c, const Job& job) {
  ojson r = s.hello;
  r["id"] = job.id;
  send(c, r);
}

void on_design(State& s, Client& c, const Job& job) {
  const auto t0 = Clock::now();
  const Fields f(job.msg, job.type);
  DesignOptions o;
  o.region = region_field(f, "region");
  if (f.has("bins")) o.histogram_bins = static_cast<std::size_t>(f.integer("bins", 0, 1000));
  const Document doc = document_of(s, f.object("document"), "document");
  const DesignView v = design_view(doc, o);

  ojson r = reply("design", job.id);
  r["grid"] = {{"origin_mm", v.grid.origin.value()}, {"spacing_mm", v.grid.spacing.value()}, {"count", v.grid.count}};
  static_assert(std::endian::native == std::endian::little, "map_f32 is little-endian float32");
  r["map_f32"] = base64_encode(std::span(reinterpret_cast<const unsigned char*>(v.map.data()), v.map.size() * sizeof(float)));
  r["regions"] = ojson::array();
  for (const auto& g : v.regions)
    r["regions"].push_back({{"name", g.name}, {"kind", g.kind}, {"start_mm", g.start.value()}, {"length_mm", g.length.value()}});
  r["region"] = v.analysed;
  r["spectrum"] = spectrum_json(v.spectrum);
  if (v.regions[v.analysed].kind == "texel") {
    r["histogram"] = {{"edges_cpm", v.histogram.edges_cpm}, {"counts", v.histogram.counts}, {"pdf", v.histogram.expected}};
    r["encoded"] = v.encoded_error.empty() ? ojson{{"bytes", v.encoded.size()}, {"hex", hex(v.encoded)}}
                                           : ojson{{"bytes", nullptr}, {"error", v.encoded_error}};
    r["central_pitch_cpm"] = v.central_pitch.value();
    r["irregularity_cpm"] = v.irregularity.value();
  } else {
    r["histogram"] = nullptr;
    r["encoded"] = nullptr;
    r["central_pitch_cpm"] = nullptr;
    r["irregularity_cpm"] = nullptr;
  }
  r["texels"] = v.texels;
  r["uncovered_mm"] = v.uncovered_mm;
  r["queued_ms"] = std::chrono::duration<double, std::milli>(t0 - job.received).count();
  r["elapsed_ms"] = ms_since(t0);
  send(c, r);
}

}  // namespace texel::studio::detail
