// MPEG-I Haptics JSON (.hjif) out: a document's rendered map as Linear
// Curve keyframes within a tolerance (docs/interchange.md "Export"). What it
// writes is checked by conformance_errors before it is returned.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <limits>

#include <nlohmann/json.hpp>

#include "hjif_internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/surface.hpp"

namespace texel::hjif {
namespace {

using detail::pow10i;
using detail::quote_value;
using texel::detail::num;
using ojson = nlohmann::ordered_json;

/// The reference device's id: the schema counts them from 1.
constexpr int kDeviceId = 1;
/// The Main profile's largest timescale.
constexpr std::uint32_t kMaxTimescaleMain = 48000;

/// The file's date as RFC 3339 (what the schema's date-time means): the
/// given one (a day is written as its midnight UTC), else
/// $SOURCE_DATE_EPOCH, else now (UTC, whole seconds).
std::string file_date(const std::string& given) {
  if (!given.empty()) {
    if (detail::rfc3339_date_time(given)) return given;
    if (given.size() == 10 && detail::liberal_date(given)) return given + "T00:00:00Z";
    throw FieldError(
        "date", "is " + quote_value(given) + "; it must be an RFC 3339 date-time (2026-11-26T14:06:29Z) or a day (2026-11-26)");
  }
  std::time_t t = std::time(nullptr);
  if (const char* sde = std::getenv("SOURCE_DATE_EPOCH")) {
    char* end = nullptr;
    const long long v = std::strtoll(sde, &end, 10);
    if (end && *end == '\0' && v >= 0) t = static_cast<std::time_t>(v);
  }
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

/// The timescale (ticks per mm) [choice]: the smallest multiple of 1000 up to
/// 48000 that puts every grid position on a whole tick, else 48000.
std::pair<std::uint32_t, bool> choose_timescale(double spacing_mm) {
  for (std::uint32_t t = 1000; t <= kMaxTimescaleMain; t += 1000) {
    const double u = spacing_mm * t;
    if (std::fabs(u - std::round(u)) <= 1e-9 * u && std::round(u) >= 1.0) return {t, true};
  }
  return {kMaxTimescaleMain, false};
}

std::string region_summary(const RegionSpec& r, std::size_t index) {
  std::string s = "region " + (r.name.empty() ? std::to_string(index) : "'" + r.name + "'");
  if (r.reference) return s + ": reference '" + r.reference->name + "'";
  const TexelSpec& t = r.texel;
  s += ": Texel texture, Central Pitch " + num(t.central_pitch.value()) + " dB, Irregularity " + num(t.irregularity.value()) +
       " dB, texel " + num(t.texel_length.value()) + " mm, seed " + std::to_string(t.seed);
  if (t.coarse_strength != 0.0 || t.fine_strength != 1.0)
    s += ", coarse strength " + num(t.coarse_strength) + ", fine strength " + num(t.fine_strength);
  return s;
}

}  // namespace

std::string_view to_string(Modality m) { return m == Modality::friction ? "friction" : "vibrotactile-texture"; }
std::string_view modality_name(Modality m) { return m == Modality::friction ? "Friction" : "Vibrotactile Texture"; }
Modality parse_modality(std::string_view text, std::string_view field) {
  if (text == "friction") return Modality::friction;
  if (text == "vibrotactile-texture") return Modality::vibrotactile_texture;
  throw FieldError(std::string(field), "is " + quote_value(text) + "; allowed: friction, vibrotactile-texture");
}

Exported export_hjif(const Document& doc, const ExportOptions& o) {
  if (!(o.tolerance > 0.0 && o.tolerance <= 0.5))
    throw FieldError("tolerance", "is " + num(o.tolerance) + "; allowed: > 0 … 0.5 (full scale)");
  const std::string date = file_date(o.date);
  const Surface surface = prepare_surface(doc);
  const Grid grid = surface.grid();
  const std::vector<double> map = surface.render();
  const auto [timescale, on_ticks] = choose_timescale(grid.spacing.value());
  const double T = timescale;

  // Amplitudes are written with the fewest decimals whose rounding costs at
  // most a quarter of the tolerance; the rest is the interpolation's.
  int decimals = 2;
  while (decimals < 9 && 0.5 * pow10i(-decimals) > o.tolerance / 4) ++decimals;
  const double scale = pow10i(decimals);
  auto quantize = [&](double a) { return std::round(a * scale) / scale; };
  // Tolerance used while placing, a hair inside the promise so the
  // verification below (the importer's arithmetic) never sees a rounding excess.
  const double tol = o.tolerance * (1.0 - 1e-9) - 1e-12;

  ExportStats stats;
  stats.timescale = timescale;
  stats.grid_on_ticks = on_ticks;
  stats.amplitude_decimals = decimals;

  ojson perceptions = ojson::array();
  const auto& regions = surface.regions();
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const Region& region = regions[r];
    const double end_mm = region.start.value() + region.length.value();
    std::int64_t a = 0;
    while (a < grid.count && !(grid.position(a).value() >= region.start.value())) ++a;
    std::int64_t b = a;
    while (b < grid.count && grid.position(b).value() < end_mm) ++b;
    if (b <= a) continue;
    auto u = [&](std::int64_t i) { return grid.position(i).value() * T; };
    auto tick = [&](std::int64_t i) { return static_cast<std::int64_t>(std::llround(u(i))); };

    // Greedy placement: from keyframe s, the farthest sample e such that the
    // straight line to e stays within tol of every sample between (the cone
    // of admissible slopes shrinks with each sample; one pass per segment).
    std::vector<std::int64_t> keys{a};
    std::int64_t s = a;
    while (s < b - 1) {
      const double ys = quantize(map[static_cast<std::size_t>(s)]);
      const auto ps = static_cast<double>(tick(s));
      double lo = -std::numeric_limits<double>::infinity();
      double hi = std::numeric_limits<double>::infinity();
      std::int64_t best = s + 1;
      for (std::int64_t e = s + 1; e < b; ++e) {
        const double ye = quantize(map[static_cast<std::size_t>(e)]);
        const double pe = static_cast<double>(tick(e));
        if (pe > ps) {
          const double slope = (ye - ys) / (pe - ps);
          if (slope >= lo && slope <= hi && std::fabs(ye - map[static_cast<std::size_t>(e)]) <= tol) best = e;
        }
        const double du = u(e) - ps;
        if (!(du > 0.0)) break;
        lo = std::max(lo, (map[static_cast<std::size_t>(e)] - tol - ys) / du);
        hi = std::min(hi, (map[static_cast<std::size_t>(e)] + tol - ys) / du);
        if (lo > hi) break;
      }
      // Distinct ticks only: a grid finer than a tick cannot take a keyframe per sample.
      if (tick(best) <= tick(s)) {
        while (best < b - 1 && tick(best) <= tick(s)) ++best;
        if (tick(best) <= tick(s)) break;
      }
      keys.push_back(best);
      s = best;
    }

    // Verification with the importer's own evaluation; a segment that fails
    // (floating-point edge) is split at its worst sample until none does.
    CurveEffect curve;
    auto rebuild = [&] {
      curve.keyframes.clear();
      for (std::int64_t k : keys) curve.keyframes.push_back(Keyframe{tick(k), quantize(map[static_cast<std::size_t>(k)])});
    };
    rebuild();
    double worst = 0.0;
    for (int pass = 0; pass < 64; ++pass) {
      worst = 0.0;
      std::vector<std::int64_t> extra;
      std::size_t seg = 0;
      for (std::int64_t i = a; i < b; ++i) {
        while (seg + 1 < keys.size() && keys[seg + 1] <= i) ++seg;
        const double err = std::fabs(detail::curve_at(curve, u(i)) - map[static_cast<std::size_t>(i)]);
        worst = std::max(worst, err);
        if (err > o.tolerance && keys[seg] != i && (extra.empty() || extra.back() != i)) extra.push_back(i);
      }
      if (extra.empty()) break;
      std::size_t before = keys.size();
      for (std::int64_t i : extra)
        if (std::find(keys.begin(), keys.end(), i) == keys.end()) keys.push_back(i);
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end(), [&](std::int64_t x, std::int64_t y) { return tick(x) == tick(y); }),
                 keys.end());
      if (keys.size() == before) break;
      rebuild();
    }
    if (worst > o.tolerance)
      throw InvalidArgument("the tolerance " + num(o.tolerance) + " cannot be met: on a grid of " + num(grid.spacing.value()) +
                            " mm with " + std::to_string(timescale) + " ticks per mm the samples reproduce the map to " +
                            num(worst) + " at best");
    stats.max_error = std::max(stats.max_error, worst);
    stats.keyframes += keys.size();
    stats.samples += static_cast<std::size_t>(b - a);

    const std::int64_t origin = curve.keyframes.front().position;
    ojson kfs = ojson::array();
    for (const Keyframe& k : curve.keyframes)
      kfs.push_back(ojson{{"relative_position", k.position - origin}, {"amplitude_modulation", k.amplitude}});
    ojson effect{{"effect_type", "Basis"},     {"id", 0}, {"position", origin}, {"phase", 0}, {"base_signal", "Sine"},
                 {"keyframes", std::move(kfs)}};
    const auto upper = static_cast<std::int64_t>(std::ceil(doc.device.band_top().value()));
    ojson band{{"band_type", "Curve"},
               {"curve_type", "Linear"},
               {"lower_frequency_limit", 0},
               {"upper_frequency_limit", upper},
               {"effects", ojson::array({std::move(effect)})}};
    ojson channel{{"id", 0},
                  {"description", "amplitude map on the " + doc.device.name + " grid, " + num(grid.spacing.value()) +
                                      " mm per sample, samples " + std::to_string(a) + " … " + std::to_string(b - 1)},
                  {"gain", 1.0},
                  {"mixing_coefficient", 1.0},
                  {"body_part_mask", 0},
                  {"reference_device_id", kDeviceId},
                  {"sample_count", b - a},
                  {"bands", ojson::array({std::move(band)})}};
    const RegionSpec* spec = r < doc.regions.size() ? &doc.regions[r] : nullptr;
    // Surface sorts regions by start; find the spec with this start.
    for (const RegionSpec& rs : doc.regions)
      if (rs.start.value() == region.start.value()) spec = &rs;
    ojson perception{{"id", static_cast<std::int64_t>(r)},
                     {"avatar_id", 0},
                     {"description", spec ? region_summary(*spec, r) : "region " + std::to_string(r)},
                     {"perception_modality", std::string(modality_name(o.modality))},
                     {"unit_exponent", -3},
                     {"reference_devices", ojson::array({ojson{{"id", kDeviceId}, {"name", doc.device.name}}})},
                     {"effect_library", ojson::array()},
                     {"channels", ojson::array({std::move(channel)})}};
    perceptions.push_back(std::move(perception));
    ++stats.perceptions;
  }
  if (perceptions.empty()) throw InvalidArgument("the document has no region with grid samples: nothing to export");

  // The document, compact, after the marker: exact parameters for Texel.
  const std::string carried = ojson::parse(document_json(doc)).dump();
  std::string description = "Texel virtual texture on " + doc.device.name + " (" + std::to_string(doc.regions.size()) +
                            (doc.regions.size() == 1 ? " region" : " regions") + "), amplitude map within " + num(o.tolerance) +
                            " of full scale. texel-tolerance:" + num(o.tolerance) + " " + std::string(carried_marker) + carried;
  ojson root{{"version", "2025"},
             {"profile", "Main"},
             {"level", 1},
             {"date", date},
             {"description", std::move(description)},
             {"timescale", timescale},
             {"avatars", ojson::array()},
             {"perceptions", std::move(perceptions)},
             {"syncs", ojson::array()}};
  Exported out;
  out.json = root.dump() + "\n";
  // Strict writer: what Texel writes passes its own checker (the schemas and the reference software's rules).
  if (const auto errors = conformance_errors(out.json); !errors.empty())
    throw Error("internal: the exported .hjif is not conformant: " + errors.front());
  out.stats = stats;
  return out;
}

}  // namespace texel::hjif
