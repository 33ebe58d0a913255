// Internal to texel::surface2d.
#pragma once

#include "texel/distribution.hpp"
#include "texel/raster2d.hpp"
#include "texel/texture.hpp"

namespace texel::surface2d_detail {

/// The 1-D texture's pitch distribution on a band topped at `band_top`
/// (spec.band_max when set), as TexelTexture prepares it.
PitchDistribution line_distribution(const TexelSpec& spec, CyclesPerMm band_top);

/// A grey PNG (8 or 16 bit; colour or alpha are refused) as values level/max
/// in [0, 1], row-major, top row first. Throws FormatError / IoError naming `path`.
Raster2D read_png_grey(const std::string& path);

}  // namespace texel::surface2d_detail
