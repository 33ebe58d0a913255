// The 2-D surface section of a document (version 4 and later;
// document_parts.hpp, docs/format.md): regions with their fine field and
// 2-D coarse profile, read with JSON paths and written back.
#include <algorithm>
#include <cmath>

#include "document_parts.hpp"
#include "texel/detail/format.hpp"

namespace texel::document_parts {
namespace {

Millimetres mm(JsonObject& o, std::string_view key, double fallback, double lo = -1e9, double hi = 1e9) {
  return Millimetres(o.number_or(key, fallback, lo, hi));
}

Coarse2D parse_coarse2d(const json& j, const std::string& path) {
  JsonObject o(j, path);
  const std::string kind = o.string("kind");
  Coarse2D c;
  if (kind == "constant") {
    c = ConstantProfile{o.number_or("value", 1.0, 0.0, 1.0)};
  } else if (kind == "edge") {
    Edge2D e;
    e.x = mm(o, "x_mm", 0.0);
    e.y = mm(o, "y_mm", 0.0);
    e.angle_deg = o.number_or("angle_deg", 0.0, -1e6, 1e6);
    e.width = mm(o, "width_mm", 0.0, 0.0);
    e.low = o.number_or("low", 0.0, 0.0, 1.0);
    e.high = o.number_or("high", 1.0, 0.0, 1.0);
    c = e;
  } else if (kind == "disc") {
    Disc2D d;
    d.cx = mm(o, "x_mm", 0.0);
    d.cy = mm(o, "y_mm", 0.0);
    d.radius = Millimetres(o.number("radius_mm", 1e-9, 1e9));
    d.edge = mm(o, "edge_mm", 0.0, 0.0);
    d.inside = o.number_or("inside", 1.0, 0.0, 1.0);
    d.outside = o.number_or("outside", 0.0, 0.0, 1.0);
    c = d;
  } else if (kind == "grid") {
    Grid2D g;
    g.period = Millimetres(o.number("period_mm", 1e-9, 1e9));
    g.line_width = Millimetres(o.number("line_width_mm", 1e-9, 1e9));
    g.angle_deg = o.number_or("angle_deg", 0.0, -1e6, 1e6);
    g.line = o.number_or("line", 1.0, 0.0, 1.0);
    g.background = o.number_or("background", 0.0, 0.0, 1.0);
    c = g;
  } else if (kind == "bump") {
    Bump2D b;
    b.cx = mm(o, "x_mm", 0.0);
    b.cy = mm(o, "y_mm", 0.0);
    b.sigma = Millimetres(o.number("sigma_mm", 1e-9, 1e9));
    b.peak = o.number_or("peak", 1.0, 0.0, 1.0);
    b.base = o.number_or("base", 0.0, 0.0, 1.0);
    c = b;
  } else if (kind == "ramp") {
    Ramp2D r;
    r.angle_deg = o.number_or("angle_deg", 0.0, -1e6, 1e6);
    r.start = mm(o, "start_mm", 0.0);
    r.length = Millimetres(o.number("length_mm", 1e-9, 1e9));
    r.from = o.number_or("from", 0.0, 0.0, 1.0);
    r.to = o.number_or("to", 1.0, 0.0, 1.0);
    c = r;
  } else if (kind == "image") {
    Image2D i;
    i.path = o.string("path");
    if (i.path.empty()) throw FormatError(o.field("path") + " is empty");
    i.x = mm(o, "x_mm", 0.0);
    i.y = mm(o, "y_mm", 0.0);
    i.width = mm(o, "width_mm", 0.0, 0.0);
    i.height = mm(o, "height_mm", 0.0, 0.0);
    i.invert = o.boolean_or("invert", false);
    c = i;
  } else {
    throw FormatError(o.field("kind") + " is '" + kind + "'; allowed: constant, edge, disc, grid, bump, ramp, image");
  }
  o.finish();
  try {
    validate(c, path);
  } catch (const InvalidArgument& e) {
    throw FormatError(e.what());
  }
  return c;
}

ordered coarse2d_json(const Coarse2D& c) {
  ordered j;
  j["kind"] = kind_name(c);
  if (const auto* k = std::get_if<ConstantProfile>(&c)) {
    j["value"] = k->value;
  } else if (const auto* e = std::get_if<Edge2D>(&c)) {
    j["x_mm"] = e->x.value();
    j["y_mm"] = e->y.value();
    j["angle_deg"] = e->angle_deg;
    j["width_mm"] = e->width.value();
    j["low"] = e->low;
    j["high"] = e->high;
  } else if (const auto* d = std::get_if<Disc2D>(&c)) {
    j["x_mm"] = d->cx.value();
    j["y_mm"] = d->cy.value();
    j["radius_mm"] = d->radius.value();
    j["edge_mm"] = d->edge.value();
    j["inside"] = d->inside;
    j["outside"] = d->outside;
  } else if (const auto* g = std::get_if<Grid2D>(&c)) {
    j["period_mm"] = g->period.value();
    j["line_width_mm"] = g->line_width.value();
    j["angle_deg"] = g->angle_deg;
    j["line"] = g->line;
    j["background"] = g->background;
  } else if (const auto* b = std::get_if<Bump2D>(&c)) {
    j["x_mm"] = b->cx.value();
    j["y_mm"] = b->cy.value();
    j["sigma_mm"] = b->sigma.value();
    j["peak"] = b->peak;
    j["base"] = b->base;
  } else if (const auto* r = std::get_if<Ramp2D>(&c)) {
    j["angle_deg"] = r->angle_deg;
    j["start_mm"] = r->start.value();
    j["length_mm"] = r->length.value();
    j["from"] = r->from;
    j["to"] = r->to;
  } else if (const auto* i = std::get_if<Image2D>(&c)) {
    j["path"] = i->path;
    j["x_mm"] = i->x.value();
    j["y_mm"] = i->y.value();
    j["width_mm"] = i->width.value();
    j["height_mm"] = i->height.value();
    j["invert"] = i->invert;
  }
  return j;
}

}  // namespace

/// {"regions": [{"name", "x_mm", "y_mm", "width_mm", "height_mm", "field",
/// "orientation_deg", "texture", "coarse2d"}]} on a device with a bitmap grid.
Surface2DSpec parse_surface2d(const json& j, const DeviceProfile& device, int version) {
  JsonObject o(j, "surface2d");
  const auto& arr = o.raw("regions");
  if (!arr.is_array() || arr.empty()) throw FormatError("surface2d.regions must be a non-empty array");
  o.finish();
  const BitmapGeometry& b = *device.bitmap;
  Surface2DSpec spec;
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const std::string path = "surface2d.regions[" + std::to_string(i) + "]";
    JsonObject r(arr[i], path);
    Region2DSpec region;
    region.name = r.string_or("name", "");
    region.x = Millimetres(r.number_or("x_mm", 0.0, 0.0, 1e9));
    region.y = Millimetres(r.number_or("y_mm", 0.0, 0.0, 1e9));
    region.width = millimetres(r.optional_number("width_mm", 1e-9, 1e9));
    region.height = millimetres(r.optional_number("height_mm", 1e-9, 1e9));
    region.field = enum_field(r, "field", default_field2d(version), parse_field2d);
    if (region.field == Field2D::tile && version < 5)
      throw FormatError(path + ".field is 'tile', which needs version 5; version is " + std::to_string(version));
    region.orientation_deg = r.number_or("orientation_deg", 0.0, -1e6, 1e6);
    RegionSpec texture;
    parse_texture(r.raw("texture"), path + ".texture", texture);
    if (texture.reference) throw FormatError(path + ".texture.kind is 'reference'; a 2-D region holds a Texel texture");
    if (texture.coarse_reference || !std::holds_alternative<ConstantProfile>(texture.texel.coarse) ||
        std::get<ConstantProfile>(texture.texel.coarse).value != 1.0)
      throw FormatError(path + ".texture.coarse must be absent in a 2-D region (its coarse profile is " + path + ".coarse2d)");
    region.texel = texture.texel;
    if (r.has("coarse2d")) {
      region.coarse = parse_coarse2d(r.raw("coarse2d"), path + ".coarse2d");
    } else {
      r.skip("coarse2d");
    }
    r.finish();
    const double w = region.width ? region.width->value() : b.width_mm().value() - region.x.value();
    const double h = region.height ? region.height->value() : b.height_mm().value() - region.y.value();
    if (!(w > 0.0) || region.x.value() + w > b.width_mm().value() + 1e-6)
      throw FormatError(path + ".x_mm + width_mm (" + detail::num(region.x.value()) + " + " + detail::num(w) +
                        " mm) must lie inside the device's bitmap width " + detail::num(b.width_mm().value()) + " mm");
    if (!(h > 0.0) || region.y.value() + h > b.height_mm().value() + 1e-6)
      throw FormatError(path + ".y_mm + height_mm (" + detail::num(region.y.value()) + " + " + detail::num(h) +
                        " mm) must lie inside the device's bitmap height " + detail::num(b.height_mm().value()) + " mm");
    spec.regions.push_back(std::move(region));
  }
  return spec;
}

ordered surface2d_json(const Surface2DSpec& spec) {
  ordered j;
  j["regions"] = ordered::array();
  for (const auto& r : spec.regions) {
    ordered rj;
    if (!r.name.empty()) rj["name"] = r.name;
    rj["x_mm"] = r.x.value();
    rj["y_mm"] = r.y.value();
    if (r.width) rj["width_mm"] = r.width->value();
    if (r.height) rj["height_mm"] = r.height->value();
    rj["field"] = std::string(to_string(r.field));
    rj["orientation_deg"] = r.orientation_deg;
    ordered t = texel_json(r.texel, std::nullopt);
    t.erase("coarse");
    rj["texture"] = std::move(t);
    rj["coarse2d"] = coarse2d_json(r.coarse);
    j["regions"].push_back(std::move(rj));
  }
  return j;
}

}  // namespace texel::document_parts
