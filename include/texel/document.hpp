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
#include "texel/multichannel.hpp"
#include "texel/reference.hpp"
#include "texel/surface.hpp"
#include "texel/surface2d_spec.hpp"
#include "texel/texture.hpp"

namespace texel {

/// The texture a region holds: a Texel texture (format version 1) or, from
/// version 2, a reference texture ("kind": "reference"); a Texel texture's
/// coarse profile may also be a reference (the coarse-study test texture).
/// A reference's `synthesis` follows the document's version (2: direct,
/// 3: chirp-z), so every document keeps rendering the bytes it was made with.
struct RegionSpec {
  std::string name;                   ///< optional label, e.g. "left"
  Millimetres start{0.0};             ///< left edge on the device (JSON start_mm)
  std::optional<Millimetres> length;  ///< none = to the end of the device (JSON length_mm)
  TexelSpec texel;                    ///< used when `reference` is empty
  /// Set: the region holds this reference instead of a Texel rendering.
  std::optional<ReferenceSpec> reference;
  /// Set (Texel regions only): the coarse profile is this reference, prepared
  /// over the region on the device grid; it replaces texel.coarse.
  std::optional<ReferenceSpec> coarse_reference;
};

struct Document {
  /// Version 2 adds references; version 3 synthesises noise and waveform
  /// references by chirp-z transform (the same textures, new last bits,
  /// O(N log N) instead of O(N²)). Documents are written with the lowest
  /// version that renders their bytes (required_version), so Texel-only
  /// documents stay version 1 and version-2 references stay version 2.
  /// Version 4 adds 2-D surfaces ("surface2d", texel/surface2d_spec.hpp);
  /// a version-4 document holds a 2-D surface and no 1-D texture. Version 5
  /// is a 2-D document whose regions' field defaults to "tile" (the fast
  /// isotropic field; version 4's default, "spectral", stays selectable and
  /// renders version 4's bytes); "tile" needs version 5. Version 6 is a 1-D
  /// document with "playback" (multi-channel: texel/multichannel.hpp); its
  /// references synthesise as version 3's.
  static constexpr int current_version = 6;
  /// The version read (parse_document) or current_version; writers use
  /// required_version instead.
  int version = current_version;
  DeviceProfile device;             ///< resolved profile (by name or inline)
  bool device_inline = false;       ///< written inline rather than by name
  std::vector<RegionSpec> regions;  ///< at least one (none in a 2-D document)
  /// Set: a 2-D document (version 4 or 5) for a device with a bitmap grid;
  /// `regions` is then empty, and prepare_surface2d (texel/surface2d.hpp)
  /// prepares it.
  std::optional<Surface2DSpec> surface2d;
  std::string description;  ///< free text
  /// Set: how the texture plays on the device's channels (version 6); none =
  /// sequential on every channel (playback_of), as every earlier version.
  std::optional<ChannelPlayback> playback;
};

/// Parses and validates a document. `origin` names the source in errors.
Document parse_document(std::string_view json_text, std::string_view origin = "document");
Document load_document(const std::string& path);
std::string document_json(const Document& doc);
void save_document(const Document& doc, const std::string& path);

/// A document holding one Texel texture over the whole device.
Document make_document(const DeviceProfile& device, const TexelSpec& spec);
/// A document holding one reference texture over the whole device.
Document make_reference_document(const DeviceProfile& device, const ReferenceSpec& spec);
/// The lowest format version that renders `doc`'s bytes: 1 without
/// references, 2 when its references use the direct synthesis, 3 when they
/// use the chirp-z one, 4 for a 2-D document, 6 with a playback. Throws InvalidArgument when references of one
/// document use both (no version holds that; documents never parse to it).
int required_version(const Document& doc);
/// The reference synthesis a document of format `version` renders with.
ReferenceSynthesis reference_synthesis(int version);

/// Prepares every region's texture for the document's device grid. Throws
/// InvalidArgument for a 2-D document (prepare_surface2d renders those).
Surface prepare_surface(const Document& doc);

}  // namespace texel
