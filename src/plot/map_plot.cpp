// The friction-map figures (texel/plot.hpp "texture plots"): the whole map,
// a zoomed excerpt and the texel-frequency histogram, alone or as an atlas,
// built from the generic Figure API like spectrum_plot.cpp and swipe_plot.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/plot.hpp"

#include "drawing.hpp"

namespace texel {

namespace {

using plot_detail::db_text;

void check_map(const MapPlot& m) {
  if (m.positions_mm.empty()) throw InvalidArgument("map plot has no samples (positions_mm is empty)");
  if (m.positions_mm.size() != m.amplitudes.size())
    throw InvalidArgument("map plot has " + std::to_string(m.positions_mm.size()) + " positions_mm and " +
                          std::to_string(m.amplitudes.size()) + " amplitudes; they must match");
  if (!(m.excerpt.value() >= 0) || !std::isfinite(m.excerpt.value()))
    throw InvalidArgument("map plot excerpt is " + detail::num(m.excerpt.value()) + "; must be >= 0 (0 = no excerpt)");
}

// Amplitude axis: 0 … 1 with a sliver of room so a line at a = 0 or 1 is not
// half clipped by the frame.
Axis amplitude_axis(std::string label) { return Axis{std::move(label), AxisScale::linear, -0.03, 1.03, false}; }

Panel excerpt_panel(const MapPlot& m, std::string title) {
  const double x0 = m.positions_mm.front();
  Panel p;
  p.title = std::move(title);
  p.x = Axis{"position (mm)", AxisScale::linear, x0, x0 + m.excerpt.value(), false};
  p.y = amplitude_axis("amplitude");
  p.lines.push_back(LineSeries{m.positions_mm, m.amplitudes, palette_colour(0), 1.25, {}});
  return p;
}

Panel histogram_panel(const MapPlot& m, std::string title) {
  Panel p;
  p.title = std::move(title);
  p.x = Axis{"texel frequency: cycles/mm (dB re 1 cycle/mm)", AxisScale::log10, std::nullopt, std::nullopt, true};
  p.y = Axis{"texels", AxisScale::linear, std::nullopt, std::nullopt, false};
  Histogram h = make_histogram(m.frequencies_cpm, 0, AxisScale::log10);
  h.colour = palette_colour(1);
  if (!h.edges.empty() && m.central_pitch.value() > 0) {
    // Keep the marker in view even when the draw missed the central pitch.
    p.x.min = std::min(h.edges.front(), m.central_pitch.value() / 1.25);
    p.x.max = std::max(h.edges.back(), m.central_pitch.value() * 1.25);
    char cpm[32];
    std::snprintf(cpm, sizeof cpm, "%.3g", m.central_pitch.value());
    p.markers.push_back({m.central_pitch.value(),
                         "central pitch " + std::string(cpm) + " cpm (" + db_text(m.central_pitch.value()) + ")",
                         {0.2, 0.2, 0.2},
                         true});
  }
  p.histograms.push_back(std::move(h));
  return p;
}

bool has_excerpt(const MapPlot& m) {
  return m.excerpt.value() > 0 && m.positions_mm.back() - m.positions_mm.front() > m.excerpt.value() * 1.01;
}

std::string excerpt_title(const MapPlot& m) {
  const double x0 = m.positions_mm.front();
  if (x0 == 0.0) return "Excerpt: first " + detail::num(m.excerpt.value()) + " mm";
  return "Excerpt: " + detail::num(x0) + " \u2013 " + detail::num(x0 + m.excerpt.value()) + " mm";
}

}  // namespace

Figure map_figure(const MapPlot& m) {
  check_map(m);
  Figure fig;
  fig.width_px = m.width_px;
  fig.title = m.title.empty() ? "Friction map" : m.title;

  Panel whole;
  whole.title = "Whole map (" + std::to_string(m.positions_mm.size()) + " samples)";
  whole.x = Axis{"position (mm)", AxisScale::linear, std::nullopt, std::nullopt, false};
  whole.y = amplitude_axis("amplitude");
  // The whole map is usually far denser than the image: a thinner line keeps
  // the envelope from reading as a solid block.
  whole.lines.push_back(LineSeries{m.positions_mm, m.amplitudes, palette_colour(0), 0.8, {}});
  fig.panels.push_back(std::move(whole));
  if (has_excerpt(m)) fig.panels.push_back(excerpt_panel(m, excerpt_title(m)));
  if (!m.frequencies_cpm.empty())
    fig.panels.push_back(histogram_panel(m, "Texel frequencies (" + std::to_string(m.frequencies_cpm.size()) + " texels)"));
  fig.height_px = m.height_px > 0 ? m.height_px : 60 + 260 * static_cast<int>(fig.panels.size());
  return fig;
}

Figure map_cell_figure(const MapPlot& m, int width_px, int height_px) {
  check_map(m);
  Figure fig;
  fig.width_px = width_px;
  fig.height_px = height_px;
  fig.font_px = 11.0;
  fig.title = m.title;
  MapPlot cut = m;
  if (!has_excerpt(cut)) cut.excerpt = Millimetres(std::max(1e-9, m.positions_mm.back() - m.positions_mm.front()));
  fig.panels.push_back(excerpt_panel(cut, {}));
  if (!m.frequencies_cpm.empty()) {
    Panel h = histogram_panel(m, {});
    h.x.label = "cycles/mm (dB)";
    h.markers.clear();  // the label would crowd a small cell; the histogram speaks for itself
    fig.panels.push_back(std::move(h));
  }
  return fig;
}

void plot_map(const MapPlot& plot, const std::string& path) { save_figure(map_figure(plot), path); }

void plot_map_grid(std::span<const MapPlot> plots, const std::string& path, int columns, const std::string& title) {
  FigureGrid grid;
  grid.title = title;
  grid.columns = columns;
  for (const auto& m : plots) grid.cells.push_back(map_cell_figure(m));
  save_figure_grid(grid, path);
}
}  // namespace texel
