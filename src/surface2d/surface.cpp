// 2-D coarse profiles, the prepared 2-D surface and its rasters
// (docs/algorithm.md §11.4–§11.5).
#include <algorithm>
#include <cmath>

#include "internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/parallel.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/surface2d.hpp"

namespace texel {
namespace {

/// A linear step from 0 (d ≤ −w/2) to 1 (d ≥ w/2); w = 0 is a step at 0.
double ramp(double d, double w) {
  if (w <= 0.0) return d >= 0.0 ? 1.0 : 0.0;
  return std::clamp(d / w + 0.5, 0.0, 1.0);
}

double lerp(double a, double b, double t) { return a + (b - a) * t; }

/// Distance from x to the nearest multiple of p.
double to_lattice(double x, double p) {
  const double r = x - p * std::floor(x / p);
  return std::min(r, p - r);
}

Raster2D load_image(const Image2D& spec) {
  const std::string ext = output_extension(spec.path);
  if (ext == ".png") return surface2d_detail::read_png_grey(spec.path);
  if (ext == ".npy") {
    const NpyArray a = parse_npy_array(read_file(spec.path), spec.path, 2);
    Raster2D r;
    r.width = static_cast<int>(a.columns);
    r.height = static_cast<int>(a.rows);
    r.values.resize(a.values.size());
    for (std::size_t i = 0; i < a.values.size(); ++i) {
      const double v = a.values[i];
      if (!(v >= 0.0 && v <= 1.0))
        throw FormatError(spec.path + ": value " + detail::num(v) + " at element " + std::to_string(i) +
                          " is outside 0 … 1 (a coarse profile's range)");
      r.values[i] = static_cast<float>(v);
    }
    return r;
  }
  throw InvalidArgument("coarse2d.path '" + spec.path + "' must be a .png or .npy image");
}

}  // namespace

CoarseField2D::CoarseField2D(const Coarse2D& spec, Millimetres region_width, Millimetres region_height) : spec_(spec) {
  validate(spec);
  constant_ = std::holds_alternative<ConstantProfile>(spec);
  if (const auto* im = std::get_if<Image2D>(&spec)) {
    image_ = load_image(*im);
    if (im->invert)
      for (float& v : image_.values) v = 1.0f - v;
    const double w = im->width.value() > 0.0 ? im->width.value() : region_width.value();
    const double h = im->height.value() > 0.0 ? im->height.value() : region_height.value();
    // Pixel centres: pixel i covers [x + i·w/W, x + (i+1)·w/W).
    image_.pitch = Millimetres(w / image_.width);
    image_pitch_y_ = h / image_.height;
    image_.origin_x = Millimetres(im->x.value() + 0.5 * image_.pitch.value());
    image_.origin_y = Millimetres(im->y.value() + 0.5 * image_pitch_y_);
  }
}

double CoarseField2D::value(double x, double y) const {
  switch (spec_.index()) {
    case 0: return std::get<ConstantProfile>(spec_).value;
    case 1: {
      const auto& e = std::get<Edge2D>(spec_);
      const double nx = detmath::cos_cycles(e.angle_deg / 360.0), ny = detmath::sin_cycles(e.angle_deg / 360.0);
      const double d = (x - e.x.value()) * nx + (y - e.y.value()) * ny;
      return lerp(e.low, e.high, ramp(d, e.width.value()));
    }
    case 2: {
      const auto& d = std::get<Disc2D>(spec_);
      const double dx = x - d.cx.value(), dy = y - d.cy.value();
      const double r = std::sqrt(dx * dx + dy * dy);
      return lerp(d.inside, d.outside, ramp(r - d.radius.value(), d.edge.value()));
    }
    case 3: {
      const auto& g = std::get<Grid2D>(spec_);
      const double c = detmath::cos_cycles(g.angle_deg / 360.0), s = detmath::sin_cycles(g.angle_deg / 360.0);
      const double u = x * c + y * s, v = -x * s + y * c;
      const double near = std::min(to_lattice(u, g.period.value()), to_lattice(v, g.period.value()));
      return near <= 0.5 * g.line_width.value() ? g.line : g.background;
    }
    case 4: {
      const auto& b = std::get<Bump2D>(spec_);
      const double dx = x - b.cx.value(), dy = y - b.cy.value();
      const double s = b.sigma.value();
      return b.base + (b.peak - b.base) * detmath::exp(-(dx * dx + dy * dy) / (2.0 * s * s));
    }
    case 5: {
      const auto& r = std::get<Ramp2D>(spec_);
      const double d = x * detmath::cos_cycles(r.angle_deg / 360.0) + y * detmath::sin_cycles(r.angle_deg / 360.0);
      return lerp(r.from, r.to, std::clamp((d - r.start.value()) / r.length.value(), 0.0, 1.0));
    }
    default: {
      // Bilinear between pixel centres, held at the border.
      const double fx = std::clamp((x - image_.origin_x.value()) / image_.pitch.value(), 0.0, image_.width - 1.0);
      const double fy = std::clamp((y - image_.origin_y.value()) / image_pitch_y_, 0.0, image_.height - 1.0);
      const int i = std::min(static_cast<int>(fx), std::max(image_.width - 2, 0));
      const int j = std::min(static_cast<int>(fy), std::max(image_.height - 2, 0));
      const int i1 = std::min(i + 1, image_.width - 1), j1 = std::min(j + 1, image_.height - 1);
      const double tx = fx - i, ty = fy - j;
      const double top = lerp(image_.at(i, j), image_.at(i1, j), tx);
      const double bottom = lerp(image_.at(i, j1), image_.at(i1, j1), tx);
      return std::clamp(lerp(top, bottom, ty), 0.0, 1.0);
    }
  }
}

void CoarseField2D::row(std::int64_t first, double pitch, double origin_x, double y, std::span<double> out) const {
  for (std::size_t k = 0; k < out.size(); ++k)
    out[k] = value(static_cast<double>(first + static_cast<std::int64_t>(k)) * pitch - origin_x, y);
}

Surface2D::Surface2D(const BitmapGeometry& geometry, std::vector<Region> regions)
    : geometry_(geometry), regions_(std::move(regions)) {}

namespace {

/// A pixel at (x, y) belongs to the region when x0 ≤ x < x1 (with the 1-D
/// renderer's picometre tolerance), likewise in y.
bool inside(double v, double lo, double hi) { return v + 1e-9 >= lo && v + 1e-9 < hi; }

}  // namespace

void Surface2D::render_rows(int first_row, int rows, std::span<double> out) const {
  const int w = geometry_.width;
  const double p = geometry_.pitch.value();
  if (first_row < 0 || rows < 0 || first_row + rows > geometry_.height ||
      out.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(w))
    throw InvalidArgument("render_rows: rows " + std::to_string(first_row) + " + " + std::to_string(rows) +
                          " outside the bitmap or output of the wrong size");
  // Each region's columns (the same on every row) and its rows in the strip.
  struct Span {
    int i0, i1, r0, r1;
  };
  std::vector<Span> spans;
  bool covered = false;  // a region writes every pixel of the strip: no need to clear it
  for (const Region& region : regions_) {
    Span sp{0, 0, 0, 0};
    while (sp.i0 < w && !inside(static_cast<double>(sp.i0) * p, region.x0, region.x1)) ++sp.i0;
    sp.i1 = sp.i0;
    while (sp.i1 < w && inside(static_cast<double>(sp.i1) * p, region.x0, region.x1)) ++sp.i1;
    while (sp.r0 < rows && !inside(static_cast<double>(first_row + sp.r0) * p, region.y0, region.y1)) ++sp.r0;
    sp.r1 = sp.r0;
    while (sp.r1 < rows && inside(static_cast<double>(first_row + sp.r1) * p, region.y0, region.y1)) ++sp.r1;
    covered = covered || (sp.i0 == 0 && sp.i1 == w && sp.r0 == 0 && sp.r1 == rows);
    spans.push_back(sp);
  }
  if (!covered) std::fill(out.begin(), out.end(), 0.0);
  std::vector<double> coarse, ys;
  for (std::size_t ri = 0; ri < regions_.size(); ++ri) {
    const Region& region = regions_[ri];
    const auto [i0, i1, r0, r1] = spans[ri];
    if (i1 <= i0 || r1 <= r0) continue;
    ys.clear();
    for (int r = r0; r < r1; ++r) ys.push_back(static_cast<double>(first_row + r) * p - region.y0);
    double* base = out.data() + static_cast<std::size_t>(r0) * static_cast<std::size_t>(w) + static_cast<std::size_t>(i0);
    const auto n = static_cast<std::size_t>(i1 - i0);
    region.fine->block(i0, n, p, region.x0, ys, base, static_cast<std::size_t>(w));
    const double C = region.texel.coarse_strength, F = region.texel.fine_strength;
    for (int r = r0; r < r1; ++r) {
      const std::span<double> run(base + static_cast<std::size_t>(r - r0) * static_cast<std::size_t>(w), n);
      if (region.coarse->constant()) {
        const TexelMix mix = texel_mix(region.coarse->value(0.0, 0.0), C, F);
        for (double& v : run) v = mix.offset + mix.gain * v;
      } else {
        coarse.resize(n);
        region.coarse->row(i0, p, region.x0, ys[static_cast<std::size_t>(r - r0)], coarse);
        for (std::size_t k = 0; k < n; ++k) {
          const TexelMix mix = texel_mix(coarse[k], C, F);
          run[k] = mix.offset + mix.gain * run[k];
        }
      }
    }
  }
}

double Surface2D::amplitude(double x, double y) const {
  double a = 0.0;
  for (const Region& region : regions_) {
    if (!inside(x, region.x0, region.x1) || !inside(y, region.y0, region.y1)) continue;
    const double s = region.fine->value(x - region.x0, y - region.y0);
    const TexelMix mix =
        texel_mix(region.coarse->value(x - region.x0, y - region.y0), region.texel.coarse_strength, region.texel.fine_strength);
    a = mix.offset + mix.gain * s;
  }
  return a;
}

Surface2D prepare_surface2d(const Document& doc) {
  if (!doc.surface2d) throw InvalidArgument("the document is not a 2-D document (it has no surface2d)");
  if (!doc.device.bitmap) throw InvalidArgument("device '" + doc.device.name + "' has no bitmap grid");
  const BitmapGeometry& g = *doc.device.bitmap;
  std::vector<Surface2D::Region> regions;
  for (std::size_t i = 0; i < doc.surface2d->regions.size(); ++i) {
    const Region2DSpec& spec = doc.surface2d->regions[i];
    const std::string label = "surface2d.regions[" + std::to_string(i) + "]: ";
    Surface2D::Region r;
    r.name = spec.name;
    r.x0 = spec.x.value();
    r.y0 = spec.y.value();
    r.x1 = spec.width ? r.x0 + spec.width->value() : g.width_mm().value();
    r.y1 = spec.height ? r.y0 + spec.height->value() : g.height_mm().value();
    r.texel = spec.texel;
    try {
      r.fine = std::make_shared<const FineField2D>(spec.texel, spec.field, spec.orientation_deg, g.nyquist());
      r.coarse = std::make_shared<const CoarseField2D>(spec.coarse, Millimetres(r.x1 - r.x0), Millimetres(r.y1 - r.y0));
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(label + e.what());
    } catch (const Error& e) {
      // An image that cannot be read: named by its JSON path too.
      throw FormatError(label + "coarse2d.path: " + e.what());
    }
    regions.push_back(std::move(r));
  }
  return Surface2D(g, std::move(regions));
}

Raster2D coarse_raster(const Document& doc, std::size_t region, Millimetres pitch) {
  if (!doc.surface2d || !doc.device.bitmap)
    throw InvalidArgument("coarse_raster needs a 2-D document (surface2d) on a device with a bitmap grid");
  if (region >= doc.surface2d->regions.size())
    throw InvalidArgument("region " + std::to_string(region) + " does not exist (the document has " +
                          std::to_string(doc.surface2d->regions.size()) + ")");
  const BitmapGeometry& g = *doc.device.bitmap;
  const Region2DSpec& spec = doc.surface2d->regions[region];
  const double p = pitch.value() > 0.0 ? pitch.value() : g.pitch.value();
  const double x0 = spec.x.value(), y0 = spec.y.value();
  const double x1 = spec.width ? x0 + spec.width->value() : g.width_mm().value();
  const double y1 = spec.height ? y0 + spec.height->value() : g.height_mm().value();
  const CoarseField2D coarse(spec.coarse, Millimetres(x1 - x0), Millimetres(y1 - y0));
  Raster2D r;
  r.width = static_cast<int>(std::ceil(g.width_mm().value() / p - 1e-9));
  r.height = static_cast<int>(std::ceil(g.height_mm().value() / p - 1e-9));
  r.pitch = Millimetres(p);
  r.values.assign(static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height), 0.0f);
  for (int j = 0; j < r.height; ++j) {
    const double y = static_cast<double>(j) * p;
    if (!inside(y, y0, y1)) continue;
    for (int i = 0; i < r.width; ++i) {
      const double x = static_cast<double>(i) * p;
      if (inside(x, x0, x1))
        r.values[static_cast<std::size_t>(j) * static_cast<std::size_t>(r.width) + static_cast<std::size_t>(i)] =
            static_cast<float>(coarse.value(x - x0, y - y0));
    }
  }
  return r;
}

Raster2D render_raster(const Surface2D& surface) {
  const BitmapGeometry& g = surface.geometry();
  Raster2D r;
  r.width = g.width;
  r.height = g.height;
  r.pitch = g.pitch;
  const auto w = static_cast<std::size_t>(g.width);
  r.values.resize(w * static_cast<std::size_t>(g.height));
  // Strips of rows, not single rows: a spectral field splits its plane
  // waves into x and y factors once per strip (FineField2D::block), and any
  // strip gives the same values. Spread over worker_threads() (each worker
  // its own strip buffer of strip_rows doubles): the same bits on any count.
  constexpr int strip_rows = 64;
  const int strips = (g.height + strip_rows - 1) / strip_rows;
  const int workers = std::min(detail::worker_threads(), std::max(strips, 1));
  std::vector<std::vector<double>> buffers(static_cast<std::size_t>(workers), std::vector<double>(w * strip_rows));
  detail::parallel_tasks(workers, static_cast<std::size_t>(strips), [&](std::size_t worker, std::size_t strip) {
    const int first = static_cast<int>(strip) * strip_rows, rows = std::min(strip_rows, g.height - first);
    std::vector<double>& b = buffers[worker];
    surface.render_rows(first, rows, std::span<double>(b.data(), w * static_cast<std::size_t>(rows)));
    std::transform(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(w) * rows,
                   r.values.begin() + static_cast<std::ptrdiff_t>(first) * g.width,
                   [](double v) { return static_cast<float>(v); });
  });
  return r;
}

}  // namespace texel
