// Prepared 2-D surfaces shared within a process, by their version-4
// document's text (internal to libtexel_experiment). Preparing a static
// field (a spectral field's radial spectrum) takes a few tenths of a second
// on tablet-2d; the oddity-2d engine scans it and the 2-D display presenter
// renders its friction bitmap from the same preparation, and the
// session's preload (SurfaceMaps, texel/experiment/surface_maps.hpp) prepares it before the engine needs
// it. Thread-safe: a surface asked while another thread prepares it waits
// for that preparation instead of repeating it. Bounded: the least recently
// asked are dropped beyond `capacity` (their holders keep them alive).
#pragma once

#include <memory>
#include <string>

#include "texel/surface2d.hpp"

namespace texel::experiment {

/// The prepared surface of a version-4 document (prepare_surface2d of
/// parse_document(document_json)); the same object for the same text while
/// it is cached. Throws what parsing or preparing throws.
std::shared_ptr<const Surface2D> prepared_surface(const std::string& document_json);

/// How many prepared surfaces are kept (every static field of the shipped
/// 2-D protocols, twice over).
inline constexpr std::size_t prepared_surfaces_capacity = 16;

}  // namespace texel::experiment
