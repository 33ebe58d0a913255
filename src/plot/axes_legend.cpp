// What a panel draws around and over its series once its plot area is
// placed: the grid, tick marks and labels (thinned so they never collide),
// axis labels and frame; the heatmap's colour bar; the legend, in the
// corner that hides the fewest points.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "plot_parts.hpp"

namespace texel::plot_detail {
namespace {

/// Which major tick labels to show so neighbours keep `gap` px apart: every
/// n-th, for the smallest n that works.
std::size_t label_stride(const std::vector<Tick>& ticks, const Scale& s, const std::vector<double>& extent, double gap) {
  std::vector<std::pair<double, double>> majors;  // pixel, extent
  for (std::size_t i = 0; i < ticks.size(); ++i)
    if (ticks[i].major) majors.emplace_back(s(ticks[i].value), extent[i]);
  for (std::size_t stride = 1; stride < std::max<std::size_t>(2, majors.size()); ++stride) {
    bool ok = true;
    for (std::size_t k = stride; k < majors.size() && ok; k += stride)
      ok = std::abs(majors[k].first - majors[k - stride].first) >= (majors[k].second + majors[k - stride].second) / 2 + gap;
    if (ok) return stride;
  }
  return std::max<std::size_t>(1, majors.size());
}

std::vector<Swatch> legend_entries(const PanelPlan& pp) {
  const Panel& p = *pp.panel;
  std::vector<Swatch> out;
  for (std::size_t i = 0; i < p.lines.size(); ++i)
    if (!p.lines[i].label.empty()) out.push_back({Swatch::line, pp.line_colours[i], p.lines[i].label});
  for (std::size_t i = 0; i < p.stems.size(); ++i)
    if (!p.stems[i].label.empty()) out.push_back({Swatch::stem, pp.stem_colours[i], p.stems[i].label});
  for (std::size_t i = 0; i < p.histograms.size(); ++i)
    if (!p.histograms[i].label.empty()) out.push_back({Swatch::bar, pp.hist_colours[i], p.histograms[i].label});
  for (std::size_t i = 0; i < p.boxes.size(); ++i)
    if (!p.boxes[i].label.empty()) out.push_back({Swatch::bar, pp.box_colours[i], p.boxes[i].label});
  for (std::size_t i = 0; i < p.error_bars.size(); ++i)
    if (!p.error_bars[i].label.empty()) out.push_back({Swatch::stem, pp.error_colours[i], p.error_bars[i].label});
  return out;
}

}  // namespace

void draw_axes(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs, const Scale& ys) {
  cairo_t* cr = pa.cr();
  const Panel& p = *pp.panel;
  const Rect& r = pp.plot;
  const double tick_len = 5.0;
  // 1-px lines on half-pixel centres stay crisp in PNG.
  const auto snap = [](double v) { return std::floor(v) + 0.5; };

  // Grid at major ticks, behind everything.
  cairo().cairo_set_line_width(cr, 1.0);
  pa.colour(grid_colour);
  for (const auto& t : pp.xticks)
    if (t.major) {
      const double x = snap(xs(t.value));
      cairo().cairo_move_to(cr, x, r.y);
      cairo().cairo_line_to(cr, x, r.bottom());
    }
  for (const auto& t : pp.yticks)
    if (t.major) {
      const double y = snap(ys(t.value));
      cairo().cairo_move_to(cr, r.x, y);
      cairo().cairo_line_to(cr, r.right(), y);
    }
  cairo().cairo_stroke(cr);

  // Tick marks (outside the frame) and labels.
  pa.colour(frame_colour);
  for (const auto& t : pp.xticks) {
    const double x = snap(xs(t.value));
    cairo().cairo_move_to(cr, x, snap(r.bottom()));
    cairo().cairo_line_to(cr, x, snap(r.bottom()) + (t.major ? tick_len : tick_len * 0.6));
  }
  for (const auto& t : pp.yticks) {
    const double y = snap(ys(t.value));
    cairo().cairo_move_to(cr, snap(r.x), y);
    cairo().cairo_line_to(cr, snap(r.x) - (t.major ? tick_len : tick_len * 0.6), y);
  }
  cairo().cairo_stroke(cr);

  pa.font(f.tick);
  const double tick_lh = pa.line_height();
  std::vector<double> widths;
  for (const auto& t : pp.xticks) widths.push_back(std::max(pa.width(t.label), pa.width(t.secondary)));
  const std::size_t xstride = label_stride(pp.xticks, xs, widths, f.tick * 0.8);
  std::size_t k = 0;
  for (const auto& t : pp.xticks) {
    if (!t.major) continue;
    if (k++ % xstride != 0) continue;
    const double x = xs(t.value);
    const double y = r.bottom() + tick_len + 3;
    pa.colour(text_colour);
    pa.text(t.label, x, y, HAlign::centre, VAlign::top);
    if (!t.secondary.empty()) {
      pa.colour(muted_colour);
      pa.text(t.secondary, x, y + tick_lh, HAlign::centre, VAlign::top);
    }
  }
  widths.assign(pp.yticks.size(), tick_lh);
  const std::size_t ystride = label_stride(pp.yticks, ys, widths, 2.0);
  k = 0;
  pa.colour(text_colour);
  for (const auto& t : pp.yticks) {
    if (!t.major) continue;
    if (k++ % ystride != 0) continue;
    const std::string s = t.secondary.empty() ? t.label : t.label + " " + t.secondary;
    pa.text(s, r.x - tick_len - 3, ys(t.value), HAlign::right, VAlign::middle);
  }

  // Axis labels.
  pa.font(f.base);
  pa.colour(text_colour);
  if (!p.x.label.empty()) pa.text(p.x.label, r.x + r.w / 2, pp.cell.y + pp.cell.h - f.base * 0.3, HAlign::centre, VAlign::bottom);
  if (!p.y.label.empty())
    pa.text(p.y.label, pp.cell.x + f.base * 0.6, r.y + r.h / 2, HAlign::centre, VAlign::top, -std::numbers::pi / 2);

  // Frame on top of the grid.
  cairo().cairo_set_line_width(cr, 1.0);
  pa.colour(frame_colour);
  cairo().cairo_rectangle(cr, snap(r.x), snap(r.y), std::round(r.w), std::round(r.h));
  cairo().cairo_stroke(cr);
}

/// The heatmap's colour scale: a vertical bar right of the plot, its two
/// ends labelled, the scale label rotated beside it.
void draw_colour_bar(const PanelPlan& pp, const Painter& pa, const Fonts& f) {
  const auto& h = pp.panel->heatmap;
  if (!h) return;
  cairo_t* cr = pa.cr();
  const Rect& r = pp.plot;
  const double pad = f.base * 0.6;
  const Rect bar{r.right() + pad, r.y, colour_bar_px, r.h};
  constexpr int steps = 64;
  for (int k = 0; k < steps; ++k) {
    const double t0 = static_cast<double>(k) / steps;
    pa.colour(blues(t0 + 0.5 / steps));
    // Slight overlap so antialiased seams do not show.
    cairo().cairo_rectangle(cr, bar.x, bar.bottom() - bar.h * (t0 + 1.0 / steps) - 0.5, bar.w, bar.h / steps + 1.0);
    cairo().cairo_fill(cr);
  }
  cairo().cairo_set_line_width(cr, 1.0);
  pa.colour(frame_colour);
  pa.rect(bar);
  cairo().cairo_stroke(cr);
  pa.font(f.tick);
  pa.colour(text_colour);
  pa.text(format_heat(pp.heat_hi, *h), bar.right() + 4, bar.y, HAlign::left, VAlign::top);
  pa.text(format_heat(pp.heat_lo, *h), bar.right() + 4, bar.bottom(), HAlign::left, VAlign::bottom);
  if (!h->scale_label.empty()) {
    pa.font(f.base);
    const double x = r.right() + pp.colour_bar - pa.line_height();
    pa.text(h->scale_label, x, r.y + r.h / 2, HAlign::centre, VAlign::top, -std::numbers::pi / 2);
  }
}

/// The legend goes in the plot corner that hides the fewest drawn points
/// (top right on a tie), which is where a reader expects it.
void draw_legend(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs, const Scale& ys,
                 const std::vector<Vertices>& line_px) {
  const auto entries = legend_entries(pp);
  if (!pp.panel->legend || entries.size() < 2) return;
  cairo_t* cr = pa.cr();
  pa.font(f.small);
  const double lh = pa.line_height() * 1.15;
  const double sw = f.small * 1.8;  // swatch width
  double w = 0;
  for (const auto& e : entries) w = std::max(w, pa.width(e.label));
  const double pad = f.small * 0.5;
  const double bw = w + sw + 3 * pad, bh = lh * static_cast<double>(entries.size()) + 2 * pad * 0.6;
  const Rect& r = pp.plot;
  std::vector<std::pair<double, double>> marker_spans;  // x extent of each marker with its label
  for (const auto& m : pp.panel->markers) {
    const double x = xs(m.x);
    if (std::isnan(x)) continue;
    const Rect lb = m.label.empty() ? Rect{x, 0, 0, 0} : marker_label_box(m, x, r, pa, f);
    marker_spans.emplace_back(std::min(x, lb.x), std::max(x, lb.right()));
  }
  pa.font(f.small);
  const Rect corners[] = {{r.right() - 8 - bw, r.y + 8, bw, bh},
                          {r.x + 8, r.y + 8, bw, bh},
                          {r.right() - 8 - bw, r.bottom() - 8 - bh, bw, bh},
                          {r.x + 8, r.bottom() - 8 - bh, bw, bh}};
  const auto hidden = [&](const Rect& b) {
    std::size_t n = 0;
    const auto in = [&](double x, double y) { return x >= b.x && x <= b.right() && y >= b.y && y <= b.bottom(); };
    for (const auto& v : line_px)
      for (const auto& [x, y] : v) n += in(x, y);
    for (const auto& s : pp.panel->stems)
      for (std::size_t k = 0; k < s.x.size(); ++k) n += in(xs(s.x[k]), ys(s.y[k])) ? 10 : 0;
    for (const auto& [x0, x1] : marker_spans) n += x1 >= b.x - 2 && x0 <= b.right() + 2 ? 50 : 0;
    for (const auto& e : pp.panel->error_bars)
      for (std::size_t k = 0; k < e.x.size(); ++k)
        for (const double dy : {0.0, e.error[k], -e.error[k]})
          if (std::isfinite(dy)) n += in(xs(e.x[k]), ys(e.y[k] + dy)) ? 10 : 0;
    for (std::size_t i = 0; i < pp.panel->boxes.size(); ++i)
      for (std::size_t g = 0; g < pp.boxes[i].size(); ++g) {
        const BoxStats& st = pp.boxes[i][g];
        const double x = box_x(pp.panel->boxes[i], g), hw = pp.panel->boxes[i].box_width / 2;
        for (const double y : {st.whisker_low, st.q1, st.median, st.q3, st.whisker_high})
          for (const double dx : {-hw, 0.0, hw}) n += in(xs(x + dx), ys(y)) ? 10 : 0;
        for (const double o : st.outliers) n += in(xs(x), ys(o)) ? 10 : 0;
      }
    if (pp.panel->heatmap) n += 1000;  // never over the matrix if avoidable (it fills the plot)
    return n;
  };
  Rect box = corners[0];
  std::size_t best = hidden(box);
  for (const Rect& c : corners)
    if (const std::size_t h = hidden(c); h < best) best = h, box = c;
  cairo().cairo_set_source_rgba(cr, 1, 1, 1, 0.88);
  pa.rect(box);
  cairo().cairo_fill_preserve(cr);
  pa.colour({0.75, 0.75, 0.75});
  cairo().cairo_set_line_width(cr, 1.0);
  cairo().cairo_stroke(cr);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& e = entries[i];
    const double cy = box.y + pad * 0.6 + lh * (static_cast<double>(i) + 0.5);
    const double x0 = box.x + pad;
    switch (e.kind) {
      case Swatch::line:
        pa.colour(e.colour);
        cairo().cairo_set_line_width(cr, 2.0);
        cairo().cairo_move_to(cr, x0, cy);
        cairo().cairo_line_to(cr, x0 + sw, cy);
        cairo().cairo_stroke(cr);
        break;
      case Swatch::stem:
        pa.colour(e.colour);
        cairo().cairo_new_sub_path(cr);
        cairo().cairo_arc(cr, x0 + sw / 2, cy, 3.0, 0, 2 * std::numbers::pi);
        cairo().cairo_fill(cr);
        break;
      case Swatch::bar:
        pa.colour(e.colour, 0.55);
        cairo().cairo_rectangle(cr, x0, cy - lh * 0.3, sw, lh * 0.6);
        cairo().cairo_fill_preserve(cr);
        pa.colour(e.colour);
        cairo().cairo_set_line_width(cr, 0.8);
        cairo().cairo_stroke(cr);
        break;
    }
    pa.colour(text_colour);
    pa.text(e.label, x0 + sw + pad, cy, HAlign::left, VAlign::middle);
  }
}

}  // namespace texel::plot_detail
