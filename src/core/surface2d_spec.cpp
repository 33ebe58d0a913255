#include "texel/surface2d_spec.hpp"

#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {

std::string_view to_string(Field2D f) {
  switch (f) {
    case Field2D::cells: return "cells";
    case Field2D::spectral: return "spectral";
    case Field2D::oriented: return "oriented";
    case Field2D::tile: return "tile";
  }
  return "cells";
}

Field2D parse_field2d(std::string_view text, std::string_view field) {
  if (text == "cells") return Field2D::cells;
  if (text == "spectral") return Field2D::spectral;
  if (text == "oriented") return Field2D::oriented;
  if (text == "tile") return Field2D::tile;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: cells, spectral, oriented, tile");
}

std::string kind_name(const Coarse2D& c) {
  constexpr const char* names[] = {"constant", "edge", "disc", "grid", "bump", "ramp", "image"};
  return names[c.index()];
}

namespace {

void check_unit(double v, std::string_view field, std::string_view key) {
  if (!(v >= 0.0 && v <= 1.0))
    throw InvalidArgument(std::string(field) + "." + std::string(key) + " is " + detail::num(v) + "; allowed: 0 … 1");
}
void check_finite(double v, std::string_view field, std::string_view key) {
  if (!std::isfinite(v))
    throw InvalidArgument(std::string(field) + "." + std::string(key) + " is " + detail::num(v) + "; it must be finite");
}
void check_positive(Millimetres v, std::string_view field, std::string_view key, bool zero_ok) {
  const double d = v.value();
  if (!(std::isfinite(d) && (d > 0.0 || (zero_ok && d == 0.0))))
    throw InvalidArgument(std::string(field) + "." + std::string(key) + " is " + detail::num(d) + " mm; it must be " +
                          (zero_ok ? ">= 0" : "> 0"));
}

}  // namespace

void validate(const Coarse2D& c, std::string_view field) {
  if (const auto* k = std::get_if<ConstantProfile>(&c)) {
    check_unit(k->value, field, "value");
  } else if (const auto* e = std::get_if<Edge2D>(&c)) {
    check_finite(e->x.value(), field, "x_mm");
    check_finite(e->y.value(), field, "y_mm");
    check_finite(e->angle_deg, field, "angle_deg");
    check_positive(e->width, field, "width_mm", true);
    check_unit(e->low, field, "low");
    check_unit(e->high, field, "high");
  } else if (const auto* d = std::get_if<Disc2D>(&c)) {
    check_finite(d->cx.value(), field, "x_mm");
    check_finite(d->cy.value(), field, "y_mm");
    check_positive(d->radius, field, "radius_mm", false);
    check_positive(d->edge, field, "edge_mm", true);
    check_unit(d->inside, field, "inside");
    check_unit(d->outside, field, "outside");
  } else if (const auto* g = std::get_if<Grid2D>(&c)) {
    check_positive(g->period, field, "period_mm", false);
    check_positive(g->line_width, field, "line_width_mm", false);
    check_finite(g->angle_deg, field, "angle_deg");
    check_unit(g->line, field, "line");
    check_unit(g->background, field, "background");
  } else if (const auto* b = std::get_if<Bump2D>(&c)) {
    check_finite(b->cx.value(), field, "x_mm");
    check_finite(b->cy.value(), field, "y_mm");
    check_positive(b->sigma, field, "sigma_mm", false);
    check_unit(b->peak, field, "peak");
    check_unit(b->base, field, "base");
  } else if (const auto* r = std::get_if<Ramp2D>(&c)) {
    check_finite(r->angle_deg, field, "angle_deg");
    check_finite(r->start.value(), field, "start_mm");
    check_positive(r->length, field, "length_mm", false);
    check_unit(r->from, field, "from");
    check_unit(r->to, field, "to");
  } else if (const auto* i = std::get_if<Image2D>(&c)) {
    if (i->path.empty()) throw InvalidArgument(std::string(field) + ".path is empty");
    check_finite(i->x.value(), field, "x_mm");
    check_finite(i->y.value(), field, "y_mm");
    check_positive(i->width, field, "width_mm", true);
    check_positive(i->height, field, "height_mm", true);
  }
}

}  // namespace texel
