// The figure layer's entry points for texel/plot.hpp: a figure (or a grid of
// figures) laid out, drawn and encoded as PNG or SVG, and the atomic save.
// The parts: validate.cpp (checks), layout.cpp (the first pass: ranges,
// colours, ticks, margins), decimate.cpp (line paths), axes_legend.cpp
// (axes, colour bar, legend), series.cpp (the series); ticks.cpp and
// statistics.cpp hold the public tick and summary helpers; the map figures
// are in map_plot.cpp.
//
// Layout is two passes over the panels: the first computes ranges, ticks and
// the margins their labels need; the second aligns the plot areas (shared
// left edge per column, shared top/bottom per row) and draws. Everything is
// measured with the same Cairo context it is drawn with, so PNG and SVG
// outputs have the same layout.
#include "texel/plot.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

#include "plot_parts.hpp"

namespace texel {
// The painter, scales, panel plans and layout passes shared with the other parts.
using namespace plot_detail;

namespace {

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo().cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo().cairo_destroy(c); }
};
using SurfacePtr = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using ContextPtr = std::unique_ptr<cairo_t, ContextDeleter>;

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

/// Lays out and draws `fig` into `area` of the context.
void draw_figure(const Painter& pa, const Figure& fig, const Rect& area) {
  cairo_t* cr = pa.cr();
  const Fonts f(fig.font_px);
  cairo().cairo_save(cr);
  pa.rect(area);
  cairo().cairo_clip(cr);
  cairo().cairo_set_source_rgb(cr, 1, 1, 1);
  cairo().cairo_paint(cr);

  const double outer = f.base * 0.5;
  double top = area.y + outer;
  if (!fig.title.empty()) {
    const std::string title = pa.fit(fig.title, area.w - 2 * outer, f.base * 1.3, true);
    pa.colour(text_colour);
    pa.text(title, area.x + area.w / 2, top, HAlign::centre, VAlign::top);
    top += pa.line_height() + f.base * 0.2;
  }
  const std::size_t n = fig.panels.size();
  if (n == 0) {
    cairo().cairo_restore(cr);
    return;
  }
  const auto cols = static_cast<std::size_t>(fig.columns);
  const std::size_t rows = (n + cols - 1) / cols;
  std::vector<double> row_weight(rows, 0.0);
  for (std::size_t i = 0; i < n; ++i) row_weight[i / cols] = std::max(row_weight[i / cols], fig.panels[i].height_weight);
  double total_weight = 0;
  for (const double w : row_weight) total_weight += w;
  const double avail_h = area.bottom() - outer - top;
  const double cell_w = (area.w - 2 * outer) / static_cast<double>(cols);

  std::vector<PanelPlan> plans(n);
  double y = top;
  for (std::size_t r = 0; r < rows; ++r) {
    const double h = avail_h * row_weight[r] / total_weight;
    for (std::size_t c = 0; c < cols && r * cols + c < n; ++c) {
      PanelPlan& pp = plans[r * cols + c];
      pp.panel = &fig.panels[r * cols + c];
      pp.cell = {area.x + outer + cell_w * static_cast<double>(c), y, cell_w, h};
      plan_ranges(pp);
      plan_colours(pp);
      plan_margins(pp, pa, f);
    }
    y += h;
  }
  // Align plot areas: one left/right edge per column, one top/bottom per row.
  std::vector<double> left(cols, 0), right(cols, 0), tops(rows, 0), bottoms(rows, 0);
  for (std::size_t i = 0; i < n; ++i) {
    left[i % cols] = std::max(left[i % cols], plans[i].left);
    right[i % cols] = std::max(right[i % cols], plans[i].right);
    tops[i / cols] = std::max(tops[i / cols], plans[i].top);
    bottoms[i / cols] = std::max(bottoms[i / cols], plans[i].bottom);
  }
  for (std::size_t i = 0; i < n; ++i) {
    PanelPlan& pp = plans[i];
    const double l = left[i % cols], rt = right[i % cols], t = tops[i / cols], b = bottoms[i / cols];
    pp.plot = {pp.cell.x + l, pp.cell.y + t, std::max(10.0, pp.cell.w - l - rt), std::max(10.0, pp.cell.h - t - b)};
    const Scale xs(pp.xlo, pp.xhi, pp.plot.x, pp.plot.right(), pp.panel->x.scale == AxisScale::log10);
    const Scale ys(pp.ylo, pp.yhi, pp.plot.bottom(), pp.plot.y, pp.panel->y.scale == AxisScale::log10);
    if (!pp.panel->title.empty()) {
      const std::string title = pa.fit(pp.panel->title, pp.plot.w, f.title, true);
      pa.colour(text_colour);
      pa.text(title, pp.plot.x, pp.plot.y - f.base * 0.45, HAlign::left, VAlign::bottom);
    }
    draw_axes(pp, pa, f, xs, ys);
    std::vector<Vertices> line_px;
    for (const auto& s : pp.panel->lines) line_px.push_back(line_vertices(s, xs, ys));
    draw_series(pp, pa, f, xs, ys, line_px);
    draw_colour_bar(pp, pa, f);
    draw_legend(pp, pa, f, xs, ys, line_px);
  }
  cairo().cairo_restore(cr);
}

/// Creates a surface of the format, runs `draw` on it and returns the bytes.
template <class Draw>
std::string encode(PlotFormat format, int width, int height, Draw&& draw) {
  std::string bytes;
  SurfacePtr surface;
  if (format == PlotFormat::png) {
    surface.reset(cairo().cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height));
  } else {
    surface.reset(cairo().cairo_svg_surface_create_for_stream(append_to_string, &bytes, width, height));
    if (cairo().cairo_surface_status(surface.get()) == CAIRO_STATUS_SUCCESS)
      cairo().cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);
  }
  if (const auto st = cairo().cairo_surface_status(surface.get()); st != CAIRO_STATUS_SUCCESS)
    throw IoError(std::string("cannot create a ") + std::to_string(width) + "×" + std::to_string(height) +
                  " plot surface: " + cairo().cairo_status_to_string(st));
  {
    ContextPtr cr(cairo().cairo_create(surface.get()));
    cairo().cairo_set_source_rgb(cr.get(), 1, 1, 1);
    cairo().cairo_paint(cr.get());
    const Painter pa(cr.get());
    draw(pa);
    if (const auto st = cairo().cairo_status(cr.get()); st != CAIRO_STATUS_SUCCESS)
      throw IoError(std::string("cannot render plot: ") + cairo().cairo_status_to_string(st));
  }
  if (format == PlotFormat::png) {
    cairo().cairo_surface_flush(surface.get());
    const auto st = cairo().cairo_surface_write_to_png_stream(surface.get(), append_to_string, &bytes);
    if (st != CAIRO_STATUS_SUCCESS) throw IoError(std::string("cannot encode PNG: ") + cairo().cairo_status_to_string(st));
  } else {
    cairo().cairo_surface_finish(surface.get());  // flushes the SVG into `bytes`
    if (const auto st = cairo().cairo_surface_status(surface.get()); st != CAIRO_STATUS_SUCCESS)
      throw IoError(std::string("cannot encode SVG: ") + cairo().cairo_status_to_string(st));
  }
  return bytes;
}

struct GridGeometry {
  int cell_w = 0, cell_h = 0, title_h = 0, width = 0, height = 0;
  std::size_t cols = 1;
};

GridGeometry grid_geometry(const FigureGrid& g) {
  if (g.columns < 1) throw InvalidArgument("grid.columns is " + std::to_string(g.columns) + "; must be >= 1");
  if (!(g.font_px >= 4 && g.font_px <= 72))
    throw InvalidArgument("grid.font_px is " + detail::num(g.font_px) + "; allowed 4 … 72");
  if (g.cells.empty()) throw InvalidArgument("grid.cells is empty; needs at least one figure");
  GridGeometry geo;
  for (std::size_t i = 0; i < g.cells.size(); ++i) {
    check_figure(g.cells[i], where("grid.cells", i));
    geo.cell_w = std::max(geo.cell_w, g.cells[i].width_px);
    geo.cell_h = std::max(geo.cell_h, g.cells[i].height_px);
  }
  geo.cols = std::min(static_cast<std::size_t>(g.columns), g.cells.size());
  const std::size_t rows = (g.cells.size() + geo.cols - 1) / geo.cols;
  geo.title_h = g.title.empty() ? 0 : static_cast<int>(std::ceil(g.font_px * 2.0));
  const double w = static_cast<double>(geo.cell_w) * static_cast<double>(geo.cols);
  const double h = static_cast<double>(geo.cell_h) * static_cast<double>(rows) + geo.title_h;
  if (w > max_side_px || h > max_side_px || w * h > max_area_px)
    throw InvalidArgument("grid image would be " + detail::num(w) + "×" + detail::num(h) + " px; allowed up to " +
                          std::to_string(max_side_px) + " px a side and " + detail::num(max_area_px) + " px in all");
  geo.width = static_cast<int>(w);
  geo.height = static_cast<int>(h);
  return geo;
}

}  // namespace

// ------------------------------------------------------------------- public

PlotFormat plot_format_for_path(const std::string& path) {
  const std::string ext = output_extension(path);
  if (ext == ".png") return PlotFormat::png;
  if (ext == ".svg") return PlotFormat::svg;
  throw InvalidArgument("plot output '" + path + "' " + (ext.empty() ? "has no extension" : "has extension '" + ext + "'") +
                        "; allowed: .png, .svg");
}

std::string render_figure(const Figure& figure, PlotFormat format) {
  check_figure(figure, "figure");
  return encode(format, figure.width_px, figure.height_px, [&](const Painter& pa) {
    draw_figure(pa, figure, {0, 0, static_cast<double>(figure.width_px), static_cast<double>(figure.height_px)});
  });
}

std::string render_figure_grid(const FigureGrid& grid, PlotFormat format) {
  const GridGeometry geo = grid_geometry(grid);
  return encode(format, geo.width, geo.height, [&](const Painter& pa) {
    if (!grid.title.empty()) {
      const std::string title = pa.fit(grid.title, geo.width - 2 * grid.font_px, grid.font_px, true);
      pa.colour(text_colour);
      pa.text(title, geo.width / 2.0, geo.title_h / 2.0, HAlign::centre, VAlign::middle);
    }
    for (std::size_t i = 0; i < grid.cells.size(); ++i) {
      const Figure& f = grid.cells[i];
      const double cx = static_cast<double>(geo.cell_w) * static_cast<double>(i % geo.cols);
      const double cy = geo.title_h + static_cast<double>(geo.cell_h) * static_cast<double>(i / geo.cols);
      const double dx = std::floor((geo.cell_w - f.width_px) / 2.0), dy = std::floor((geo.cell_h - f.height_px) / 2.0);
      draw_figure(pa, f, {cx + dx, cy + dy, static_cast<double>(f.width_px), static_cast<double>(f.height_px)});
    }
  });
}

void save_figure(const Figure& figure, const std::string& path) {
  const PlotFormat format = plot_format_for_path(path);
  check_writable(path);  // fail before the (possibly slow) render
  write_file_atomic(path, render_figure(figure, format));
}

void save_figure_grid(const FigureGrid& grid, const std::string& path) {
  const PlotFormat format = plot_format_for_path(path);
  check_writable(path);
  write_file_atomic(path, render_figure_grid(grid, format));
}

}  // namespace texel
