// What a 2-D texture document holds (format versions 4 and 5, docs/format.md "2-D
// surfaces"): rectangular regions of a 2-D surface, each with a fine texture
// (a TexelSpec: P, I, L, seed, strengths), the 2-D field design that lays it
// out in the plane, and a 2-D coarse profile. Plain data, parsed and written
// by texel/document.hpp; prepared and rendered by texel/surface2d.hpp.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "texel/coarse.hpp"
#include "texel/texture.hpp"
#include "texel/units.hpp"

namespace texel {

/// How the fine texture is laid out in the plane (docs/algorithm.md §11).
enum class Field2D {
  cells,     ///< texel cells, one frequency each in a random orientation (fast; not isotropic enough)
  spectral,  ///< stationary isotropic field on the moment-fit radial spectrum, 256 plane waves (default of version 4)
  oriented,  ///< a grating: the 1-D texture along direction n (orientation_deg)
  tile,      ///< the same radial spectrum on periodic FFT tiles, cubic B-spline between samples (default of version 5 [choice])
};
/// The field a region of a document of `version` has when it names none:
/// spectral in version 4, tile from version 5 on.
constexpr Field2D default_field2d(int version) { return version >= 5 ? Field2D::tile : Field2D::spectral; }
std::string_view to_string(Field2D f);
Field2D parse_field2d(std::string_view text, std::string_view field = "field");

/// c = low on the side the normal points away from, high on the other, a
/// linear transition of `width` centred on the line through (x, y).
struct Edge2D {
  Millimetres x{0.0}, y{0.0};  ///< a point on the edge
  double angle_deg = 0.0;      ///< direction of the normal (0 = +x)
  Millimetres width{0.0};      ///< transition width (0 = a step)
  double low = 0.0, high = 1.0;
};
/// c = inside within `radius` of the centre, outside beyond, a linear
/// transition of `edge` across the rim.
struct Disc2D {
  Millimetres cx{0.0}, cy{0.0}, radius{5.0};
  Millimetres edge{0.0};
  double inside = 1.0, outside = 0.0;
};
/// Lines of width `line_width` every `period` along both axes (rotated by
/// angle_deg): c = line on a line, background between.
struct Grid2D {
  Millimetres period{5.0}, line_width{0.5};
  double angle_deg = 0.0;
  double line = 1.0, background = 0.0;
};
/// A Gaussian bump: c = base + (peak − base)·exp(−r²/(2σ²)).
struct Bump2D {
  Millimetres cx{0.0}, cy{0.0}, sigma{5.0};
  double peak = 1.0, base = 0.0;
};
/// A linear ramp along direction angle_deg: `from` at distance `start` (from
/// the origin, along the direction), `to` at start + length, held beyond.
struct Ramp2D {
  double angle_deg = 0.0;
  Millimetres start{0.0}, length{10.0};
  double from = 0.0, to = 1.0;
};
/// An image (8/16-bit grey PNG or a 2-D .npy of values in [0, 1]) stretched
/// over the rectangle at (x, y) of width × height (0 = the region's size);
/// bilinear between pixel centres, held at the border. PNG grey levels read
/// as value = level/max (white = 1), `invert` turns that round.
struct Image2D {
  std::string path;  ///< as written in the document; resolved against its directory when loaded
  Millimetres x{0.0}, y{0.0}, width{0.0}, height{0.0};
  bool invert = false;
};

using Coarse2D = std::variant<ConstantProfile, Edge2D, Disc2D, Grid2D, Bump2D, Ramp2D, Image2D>;
std::string kind_name(const Coarse2D& c);

/// One rectangle of the surface with its texture. Coordinates are the
/// device's (mm, origin at pixel (0, 0)); the texture's own coordinates start
/// at the rectangle's corner (x, y).
struct Region2DSpec {
  std::string name;
  Millimetres x{0.0}, y{0.0};
  std::optional<Millimetres> width, height;  ///< none = to the device's edge
  TexelSpec texel;                           ///< the fine texture and C, F (its 1-D coarse profile must be constant)
  Field2D field = Field2D::spectral;         ///< parse_document: default_field2d(version)
  double orientation_deg = 0.0;              ///< oriented: direction of the grating's wave vector n
  Coarse2D coarse = ConstantProfile{};
};

struct Surface2DSpec {
  std::vector<Region2DSpec> regions;  ///< at least one; pixels outside every region are at rest (0)
};

/// Throws InvalidArgument naming the field for malformed values.
void validate(const Coarse2D& c, std::string_view field = "coarse2d");

}  // namespace texel
