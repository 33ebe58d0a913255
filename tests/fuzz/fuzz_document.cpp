// libFuzzer target for texture documents (*.texel.json; parse_document,
// document.hpp), which also covers device profiles: an inline "device"
// object goes through parse_device_profile, the parser of device .json files.
// Every input is either
//   - accepted: the document prepares (parse_document already calls
//     prepare_surface), renders finite amplitudes in [0, 1], and its JSON
//     (document_json) reads back to the same JSON; or
//   - rejected with a texel::Error (FormatError for the document itself).
// Anything else (a crash, another exception, a sanitizer report, a huge
// allocation under -malloc_limit_mb) is a bug.
//
// Caps, as Texel Studio applies them before parse_document (service.cpp
// document_of/check_cost): a device named by a string must be built in (any
// other string is a path the loader would read, e.g. /dev/zero), and a
// document whose device has more than max_samples samples, or whose texture
// has more than max_texels texels over the device's length, is legitimately
// expensive, not malformed, so it is skipped. Everything inside the caps
// must be cheap: a region or reference whose own lengths make it costly past
// the device's length is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"

namespace {

constexpr double max_samples = 1 << 16;
constexpr double max_texels = 1 << 16;

/// False if the document names a file or would legitimately cost more than
/// the caps; true when it may go to parse_document (which may still reject it).
bool within_caps(std::string_view text) {
  const auto j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("device")) return true;
  std::optional<texel::DeviceProfile> device;
  try {
    const auto& d = j["device"];
    if (d.is_string()) {
      const auto names = texel::builtin_device_names();
      bool builtin = false;
      for (const auto& n : names) builtin = builtin || n == d.get<std::string>();
      if (!builtin) return false;
      device = texel::load_device(d.get<std::string>());
    } else if (d.is_object()) {
      device = texel::parse_device_profile(d.dump(), "device");
    } else {
      return true;
    }
    if (j.contains("device_grid") && j["device_grid"].is_object()) {
      const auto& g = j["device_grid"];
      auto opt = [&](const char* k) {
        return g.contains(k) && g[k].is_number() ? std::optional<double>(g[k].get<double>()) : std::nullopt;
      };
      device = texel::with_grid(*device, texel::millimetres(opt("length_mm")), texel::millimetres(opt("spacing_mm")));
    }
  } catch (const texel::Error&) {
    return true;  // parse_document rejects it at the same step, before preparing anything
  }
  if (static_cast<double>(device->samples) > max_samples) return false;
  auto texel_count_ok = [&](const nlohmann::json& t) {
    if (!t.is_object() || !t.contains("texel_length_mm") || !t["texel_length_mm"].is_number()) return true;
    const double length = t["texel_length_mm"].get<double>();
    return !(length > 0) || device->length().value() / length <= max_texels;
  };
  if (j.contains("texture") && !texel_count_ok(j["texture"])) return false;
  if (j.contains("regions") && j["regions"].is_array())
    for (const auto& r : j["regions"])
      if (r.is_object() && r.contains("texture") && !texel_count_ok(r["texture"])) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (!within_caps(text)) return 0;
  try {
    const texel::Document doc = texel::parse_document(text, "fuzz");
    const std::vector<double> map = texel::prepare_surface(doc).render();
    for (double a : map)
      if (!(a >= 0.0 && a <= 1.0)) std::abort();
    const std::string json = texel::document_json(doc);
    std::optional<texel::Document> again;
    try {
      again = texel::parse_document(json, "again");
    } catch (const texel::Error&) {
      std::abort();  // Texel wrote a document it cannot read back
    }
    if (texel::document_json(*again) != json) std::abort();
  } catch (const texel::Error&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
