// The texture document (*.texel.json): everything needed to re-create a
// texture — device, regions, and per region the texture's parameters, seed,
// parameterization and coarse profile, with units in the key names. Versioned;
// see docs/format.md and docs/schema/texel-document.schema.json.
//
// Loading validates every field and reports the field's JSON path, the value
// and what is allowed; unknown keys are errors (a typo must not silently fall
// back to a default). Saving is atomic (temporary file + rename).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "texel/device.hpp"
#include "texel/surface.hpp"
#include "texel/texture.hpp"

namespace texel {

/// The texture a region holds. Only Texel textures in format version 1;
/// later kinds (references) extend this.
struct RegionSpec {
  std::string name;                   ///< optional label, e.g. "left"
  double start_mm = 0.0;
  std::optional<double> length_mm;    ///< none = to the end of the device
  TexelSpec texel;
};

struct Document {
  static constexpr int current_version = 1;
  int version = current_version;
  DeviceProfile device;               ///< resolved profile (by name or inline)
  bool device_inline = false;         ///< written inline rather than by name
  std::vector<RegionSpec> regions;    ///< at least one
  std::string description;            ///< free text
};

/// Parses and validates a document. `origin` names the source in errors.
Document parse_document(std::string_view json_text, std::string_view origin = "document");
Document load_document(const std::string& path);
std::string document_json(const Document& doc);
void save_document(const Document& doc, const std::string& path);

/// A document holding one Texel texture over the whole device.
Document make_document(const DeviceProfile& device, const TexelSpec& spec);

/// Prepares every region's texture for the document's device grid.
Surface prepare_surface(const Document& doc);

}  // namespace texel
