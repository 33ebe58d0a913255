// What the document's sources share (internal; document.cpp): the JSON
// aliases, the enum-field reader, and the 2-D surface section's reader and
// writer (document_surface2d.cpp).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "texel/detail/json_fields.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/reference.hpp"
#include "texel/surface2d_spec.hpp"

namespace texel::document_parts {

using detail::JsonObject;
using nlohmann::json;
using ordered = nlohmann::ordered_json;

/// An enum member `key` of `o` read by `parse` (a missing key: `fallback`);
/// parse's InvalidArgument becomes the document's FormatError.
template <class Enum, class Parse>
Enum enum_field(JsonObject& o, std::string_view key, Enum fallback, Parse parse) {
  if (!o.has(key)) {
    o.skip(key);
    return fallback;
  }
  const std::string text = o.string(key);
  try {
    return parse(text, o.field(key));
  } catch (const InvalidArgument& e) {
    throw FormatError(e.what());
  }
}

/// A region's texture (document.cpp): a Texel texture (possibly with a
/// reference as its coarse profile) or a reference, read into `region`.
void parse_texture(const json& j, const std::string& path, RegionSpec& region);

/// A Texel texture's JSON (document.cpp), its coarse profile a reference
/// when one is given.
ordered texel_json(const TexelSpec& s, const std::optional<ReferenceSpec>& coarse_reference);

/// {"regions": [{"name", "x_mm", "y_mm", "width_mm", "height_mm", "field",
/// "orientation_deg", "texture", "coarse2d"}]} on a device with a bitmap grid.
Surface2DSpec parse_surface2d(const json& j, const DeviceProfile& device, int version);

ordered surface2d_json(const Surface2DSpec& spec);

}  // namespace texel::document_parts
