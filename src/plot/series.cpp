// The series painters of the figure layer: one function per kind of series,
// drawn by draw_series in a fixed order into a panel's clipped plot area.
// The order and the Cairo state set between them (line join and caps,
// dashes) are part of the output: PNG and SVG bytes depend on them.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "drawing.hpp"

namespace texel::plot_detail {
namespace {

/// Cells coloured on the Blues scale, each value printed in its cell when
/// asked, white borders between cells.
void draw_heatmap(const HeatmapSeries& heat, const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs,
                  const Scale& ys) {
  cairo_t* cr = pa.cr();
  const Rect& r = pp.plot;
  const HeatmapSeries* h = &heat;
  pa.font(f.tick);
  for (std::size_t row = 0; row < h->rows; ++row)
    for (std::size_t col = 0; col < h->cols; ++col) {
      const double v = h->values[row * h->cols + col];
      if (!std::isfinite(v)) continue;
      const double cx = static_cast<double>(col), cy = static_cast<double>(h->rows - 1 - row);
      const double x0 = xs(cx - 0.5), x1 = xs(cx + 0.5), y0 = ys(cy + 0.5), y1 = ys(cy - 0.5);
      const double t = (v - pp.heat_lo) / (pp.heat_hi - pp.heat_lo);
      pa.colour(blues(t));
      cairo().cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
      cairo().cairo_fill(cr);
      if (h->decimals >= 0) {
        // Light text on the darker half of the scale keeps every value legible.
        pa.colour(t > 0.55 ? Rgb{1, 1, 1} : text_colour);
        pa.text(format_heat(v, *h), (x0 + x1) / 2, (y0 + y1) / 2, HAlign::centre, VAlign::middle);
      }
    }
  // White cell borders read as a table without a grid behind it.
  cairo().cairo_set_line_width(cr, 1.0);
  cairo().cairo_set_source_rgb(cr, 1, 1, 1);
  for (std::size_t c = 1; c < h->cols; ++c) {
    const double x = xs(static_cast<double>(c) - 0.5);
    cairo().cairo_move_to(cr, x, r.y);
    cairo().cairo_line_to(cr, x, r.bottom());
  }
  for (std::size_t k = 1; k < h->rows; ++k) {
    const double y = ys(static_cast<double>(k) - 0.5);
    cairo().cairo_move_to(cr, r.x, y);
    cairo().cairo_line_to(cr, r.right(), y);
  }
  cairo().cairo_stroke(cr);
}

/// Bars from the baseline (the bottom on a log axis), outlined when wide enough.
void draw_histograms(const PanelPlan& pp, const Painter& pa, const Scale& xs, const Scale& ys) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  const Rect& r = pp.plot;
  const double y_base = ys.log ? r.bottom() : ys(std::clamp(0.0, pp.ylo, pp.yhi));
  for (std::size_t i = 0; i < p.histograms.size(); ++i) {
    const auto& h = p.histograms[i];
    const Rgb c = pp.hist_colours[i];
    bool outline = true;
    for (std::size_t b = 0; b < h.counts.size(); ++b) {
      const double x0 = xs(h.edges[b]), x1 = xs(h.edges[b + 1]), y1 = ys(h.counts[b]);
      if (std::isnan(x0) || std::isnan(x1) || std::isnan(y1) || h.counts[b] == 0) continue;
      cairo().cairo_rectangle(cr, x0, std::min(y1, y_base), x1 - x0, std::abs(y_base - y1));
      outline = outline && x1 - x0 >= 3;
    }
    pa.colour(c, 0.55);
    if (outline) {
      cairo().cairo_fill_preserve(cr);
      pa.colour(c);
      cairo().cairo_set_line_width(cr, 0.8);
      cairo().cairo_stroke(cr);
    } else {
      cairo().cairo_fill(cr);
    }
  }
}

/// Vertical markers across the plot, with their labels on a white backing.
void draw_markers(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  const Rect& r = pp.plot;
  for (const auto& m : p.markers) {
    const double x = xs(m.x);
    if (std::isnan(x) || x < r.x - 1 || x > r.right() + 1) continue;
    pa.colour(m.colour);
    cairo().cairo_set_line_width(cr, 1.2);
    const double dash[] = {5.0, 3.0};
    cairo().cairo_set_dash(cr, dash, m.dashed ? 2 : 0, 0);
    cairo().cairo_move_to(cr, x, r.y);
    cairo().cairo_line_to(cr, x, r.bottom());
    cairo().cairo_stroke(cr);
    cairo().cairo_set_dash(cr, nullptr, 0, 0);
    if (!m.label.empty()) {
      const Rect b = marker_label_box(m, x, r, pa, f);  // also selects the font
      cairo().cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
      cairo().cairo_rectangle(cr, b.x - 2, b.y - 1, b.w + 4, b.h + 2);
      cairo().cairo_fill(cr);
      pa.colour(m.colour);
      pa.text(m.label, b.x, b.y, HAlign::left, VAlign::top);
    }
  }
}

/// Box plots: whiskers with caps, the box, the median, outliers, and the
/// points and mean when asked.
void draw_boxes(const PanelPlan& pp, const Painter& pa, const Scale& xs, const Scale& ys) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  for (std::size_t i = 0; i < p.boxes.size(); ++i) {
    const auto& b = p.boxes[i];
    const Rgb c = pp.box_colours[i];
    cairo().cairo_set_line_width(cr, 1.2);
    for (std::size_t g = 0; g < b.groups.size(); ++g) {
      const BoxStats& st = pp.boxes[i][g];
      if (st.n == 0) continue;
      const double xc = box_x(b, g);
      const double x0 = xs(xc - b.box_width / 2), x1 = xs(xc + b.box_width / 2), xm = xs(xc);
      const double yq1 = ys(st.q1), yq3 = ys(st.q3), ymed = ys(st.median);
      if (std::isnan(x0) || std::isnan(x1) || std::isnan(yq1) || std::isnan(yq3)) continue;
      const double cap = (x1 - x0) * 0.25;
      pa.colour(c);
      // Whiskers and their caps.
      for (const double w : {st.whisker_low, st.whisker_high}) {
        const double yw = ys(w);
        if (std::isnan(yw)) continue;
        cairo().cairo_move_to(cr, xm, w < st.q1 ? yq1 : yq3);
        cairo().cairo_line_to(cr, xm, yw);
        cairo().cairo_move_to(cr, xm - cap, yw);
        cairo().cairo_line_to(cr, xm + cap, yw);
      }
      cairo().cairo_stroke(cr);
      cairo().cairo_rectangle(cr, x0, std::min(yq1, yq3), x1 - x0, std::abs(yq1 - yq3));
      pa.colour(c, 0.3);
      cairo().cairo_fill_preserve(cr);
      pa.colour(c);
      cairo().cairo_stroke(cr);
      cairo().cairo_set_line_width(cr, 2.2);
      cairo().cairo_move_to(cr, x0, ymed);
      cairo().cairo_line_to(cr, x1, ymed);
      cairo().cairo_stroke(cr);
      cairo().cairo_set_line_width(cr, 1.2);
      for (const double o : st.outliers) {
        const double yo = ys(o);
        if (std::isnan(yo)) continue;
        cairo().cairo_new_sub_path(cr);
        cairo().cairo_arc(cr, xm, yo, 3.2, 0, 2 * std::numbers::pi);
      }
      cairo().cairo_stroke(cr);
      if (b.show_points) {
        pa.colour(c, 0.7);
        for (const double v : b.groups[g]) {
          const double yv = ys(v);
          if (std::isnan(yv)) continue;
          cairo().cairo_new_sub_path(cr);
          cairo().cairo_arc(cr, xm, yv, 1.8, 0, 2 * std::numbers::pi);
        }
        cairo().cairo_fill(cr);
      }
      if (b.show_mean && std::isfinite(ys(st.mean))) {
        const double ym = ys(st.mean), d = 3.5;
        pa.colour(text_colour);
        cairo().cairo_move_to(cr, xm - d, ym - d);
        cairo().cairo_line_to(cr, xm + d, ym + d);
        cairo().cairo_move_to(cr, xm - d, ym + d);
        cairo().cairo_line_to(cr, xm + d, ym - d);
        cairo().cairo_stroke(cr);
      }
    }
  }
}

/// Polylines from their decimated pixel vertices.
void draw_lines(const PanelPlan& pp, const Painter& pa, const std::vector<Vertices>& line_px) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  // Stroked in chunks: Cairo tessellates a path as a whole, and a dense
  // envelope crosses itself so often that one path costs seconds. Chunks
  // overlap only at their shared vertex, invisible under a round join.
  constexpr std::size_t chunk = 512;
  for (std::size_t i = 0; i < p.lines.size(); ++i) {
    pa.colour(pp.line_colours[i]);
    cairo().cairo_set_line_width(cr, p.lines[i].width_px);
    const double dash[] = {6.0, 4.0};
    cairo().cairo_set_dash(cr, dash, p.lines[i].dashed ? 2 : 0, 0);
    bool pen_down = false;
    std::size_t in_path = 0;
    for (const auto& [x, y] : line_px[i]) {
      if (std::isnan(x)) {
        pen_down = false;
        continue;
      }
      if (pen_down) {
        cairo().cairo_line_to(cr, x, y);
        if (++in_path >= chunk) {
          cairo().cairo_stroke(cr);
          cairo().cairo_move_to(cr, x, y);
          in_path = 0;
        }
      } else {
        cairo().cairo_move_to(cr, x, y);
      }
      pen_down = true;
    }
    cairo().cairo_stroke(cr);
  }
}

/// Points with symmetric error bars, joined in x order when asked.
void draw_error_bars(const PanelPlan& pp, const Painter& pa, const Scale& xs, const Scale& ys) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  const Rect& r = pp.plot;
  for (std::size_t i = 0; i < p.error_bars.size(); ++i) {
    const auto& e = p.error_bars[i];
    const Rgb c = pp.error_colours[i];
    pa.colour(c);
    if (e.connect) {
      std::vector<std::size_t> order(e.x.size());
      for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return e.x[a] < e.x[b]; });
      cairo().cairo_set_line_width(cr, 1.5);
      bool pen_down = false;
      for (const std::size_t k : order) {
        const double x = xs(e.x[k]), y = ys(e.y[k]);
        if (std::isnan(x) || std::isnan(y)) {
          pen_down = false;
          continue;
        }
        pen_down ? cairo().cairo_line_to(cr, x, y) : cairo().cairo_move_to(cr, x, y);
        pen_down = true;
      }
      cairo().cairo_stroke(cr);
    }
    cairo().cairo_set_line_width(cr, 1.3);
    for (std::size_t k = 0; k < e.x.size(); ++k) {
      const double x = xs(e.x[k]), y = ys(e.y[k]);
      if (std::isnan(x) || std::isnan(y)) continue;
      if (std::isfinite(e.error[k]) && e.error[k] > 0) {
        const double lo = ys(e.y[k] - e.error[k]), hi = ys(e.y[k] + e.error[k]);
        const double ylo = std::isnan(lo) ? r.bottom() : lo;  // log axis: a bar below 0 runs off the plot
        if (!std::isnan(hi)) {
          cairo().cairo_move_to(cr, x, ylo);
          cairo().cairo_line_to(cr, x, hi);
          cairo().cairo_move_to(cr, x - e.cap_px, hi);
          cairo().cairo_line_to(cr, x + e.cap_px, hi);
          if (!std::isnan(lo)) {
            cairo().cairo_move_to(cr, x - e.cap_px, lo);
            cairo().cairo_line_to(cr, x + e.cap_px, lo);
          }
          cairo().cairo_stroke(cr);
        }
      }
      if (e.marker_radius_px > 0) {
        cairo().cairo_new_sub_path(cr);
        cairo().cairo_arc(cr, x, y, e.marker_radius_px, 0, 2 * std::numbers::pi);
        cairo().cairo_fill(cr);
      }
    }
  }
}

/// Stems from the baseline and their markers.
void draw_stems(const PanelPlan& pp, const Painter& pa, const Scale& xs, const Scale& ys) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  const Rect& r = pp.plot;
  for (std::size_t i = 0; i < p.stems.size(); ++i) {
    const auto& s = p.stems[i];
    const Rgb c = pp.stem_colours[i];
    const double foot = ys.log ? (s.baseline > 0 ? std::min(ys(s.baseline), r.bottom()) : r.bottom())
                               : ys(std::clamp(s.baseline, pp.ylo, pp.yhi));
    pa.colour(c);
    cairo().cairo_set_line_width(cr, 1.2);
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      const double x = xs(s.x[k]), y = ys(s.y[k]);
      if (std::isnan(x) || std::isnan(y) || x < r.x - 20 || x > r.right() + 20) continue;
      if (s.stems) {
        cairo().cairo_move_to(cr, x, foot);
        cairo().cairo_line_to(cr, x, y);
        cairo().cairo_stroke(cr);
      }
      if (s.marker_radius_px > 0) {
        cairo().cairo_new_sub_path(cr);
        cairo().cairo_arc(cr, x, y, s.marker_radius_px, 0, 2 * std::numbers::pi);
        pa.colour(c, 0.85);
        cairo().cairo_fill_preserve(cr);
        pa.colour(c);
        cairo().cairo_stroke(cr);
      }
    }
  }
}

/// Text notes at data positions.
void draw_notes(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs, const Scale& ys) {
  const Panel& p = *pp.panel;
  pa.font(f.small);
  for (const auto& t : p.notes) {
    const double x = xs(t.x), y = ys(t.y);
    if (std::isnan(x) || std::isnan(y)) continue;
    pa.colour(t.colour);
    pa.text(t.text, x, y + t.dy_px, HAlign::centre, VAlign::middle);
  }
}

}  // namespace

void draw_series(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs, const Scale& ys,
                 const std::vector<Vertices>& line_px) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  cairo().cairo_save(cr);
  pa.rect(pp.plot);
  cairo().cairo_clip(cr);
  if (p.heatmap) draw_heatmap(*p.heatmap, pp, pa, f, xs, ys);
  draw_histograms(pp, pa, xs, ys);
  cairo().cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo().cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  draw_markers(pp, pa, f, xs);
  draw_boxes(pp, pa, xs, ys);
  cairo().cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  draw_lines(pp, pa, line_px);
  cairo().cairo_set_dash(cr, nullptr, 0, 0);
  draw_error_bars(pp, pa, xs, ys);
  draw_stems(pp, pa, xs, ys);
  if (!p.notes.empty()) draw_notes(pp, pa, f, xs, ys);
  cairo().cairo_restore(cr);
}

}  // namespace texel::plot_detail
