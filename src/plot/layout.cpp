// The first layout pass over a panel: axis ranges from the data (with
// margins, fixed ends, category axes and the heatmap's colour range), the
// series colours from the palette (palette_colour), then the ticks and the
// margins their labels need. plot.cpp aligns the plot areas afterwards.
#include "texel/plot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "plot_parts.hpp"

namespace texel::plot_detail {
namespace {

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool anchored_lo = false;  // lo comes from a bar or stem foot: no margin below
  void add(double v, bool log) {
    if (!std::isfinite(v) || (log && v <= 0)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  [[nodiscard]] bool empty() const { return !(lo <= hi); }
};

/// The final range of an axis: fixed ends from the Axis, the rest from the
/// data with margins (`pad_lo`, `pad_hi` of the span; 0 keeps the data tight).
std::pair<double, double> resolve_range(const Axis& axis, Range data, double pad_lo, double pad_hi) {
  const bool log = axis.scale == AxisScale::log10;
  if (data.empty()) data = log ? Range{1.0, 10.0} : Range{0.0, 1.0};
  if (axis.min) {
    data.lo = *axis.min;
    data.anchored_lo = true;
  }
  if (axis.max) data.hi = *axis.max;
  auto to = [&](double v) { return log ? std::log10(v) : v; };
  auto from = [&](double v) { return log ? std::pow(10.0, v) : v; };
  double a = to(data.lo), b = to(data.hi);
  if (!(a < b)) {
    // One value (or a fixed end past the data): open a unit-wide window.
    const double half = log ? 0.5 : std::max(0.5, std::abs(a) * 0.1);
    if (axis.min && !axis.max)
      b = a + 2 * half;
    else if (axis.max && !axis.min)
      a = b - 2 * half;
    else
      a -= half, b += half;
    return {from(a), from(b)};
  }
  const double span = b - a;
  if (!axis.min && !data.anchored_lo) a -= pad_lo * span;
  if (!axis.max) b += pad_hi * span;
  return {from(a), from(b)};
}

/// Category labels in effect for the panel's axes: the axis' own, else a
/// heatmap's row/column labels (rows reversed: row 0 is drawn at the top).
void plan_categories(PanelPlan& pp) {
  const Panel& p = *pp.panel;
  pp.xcats = p.x.categories;
  pp.ycats = p.y.categories;
  if (const auto& h = p.heatmap) {
    if (pp.xcats.empty()) {
      pp.xcats = h->column_labels;
      if (pp.xcats.empty())
        for (std::size_t c = 0; c < h->cols; ++c) pp.xcats.push_back(std::to_string(c + 1));
    }
    if (pp.ycats.empty()) {
      pp.ycats.assign(h->row_labels.rbegin(), h->row_labels.rend());
      if (pp.ycats.empty())
        for (std::size_t r = h->rows; r > 0; --r) pp.ycats.push_back(std::to_string(r));
    }
    Range v;
    for (const double x : h->values) v.add(x, false);
    if (v.empty()) v = Range{0.0, 1.0};
    pp.heat_lo = h->min.value_or(v.lo);
    pp.heat_hi = h->max.value_or(v.hi);
    if (!(pp.heat_lo < pp.heat_hi)) {
      // One value: centre it on the scale.
      if (h->min && !h->max)
        pp.heat_hi = pp.heat_lo + 1;
      else if (h->max && !h->min)
        pp.heat_lo = pp.heat_hi - 1;
      else
        pp.heat_lo -= 0.5, pp.heat_hi += 0.5;
    }
  }
}

}  // namespace

void plan_ranges(PanelPlan& pp) {
  const Panel& p = *pp.panel;
  const bool xlog = p.x.scale == AxisScale::log10;
  const bool ylog = p.y.scale == AxisScale::log10;
  plan_categories(pp);
  for (const auto& b : p.boxes) {
    std::vector<BoxStats> st;
    for (const auto& g : b.groups) st.push_back(box_stats(g));
    pp.boxes.push_back(std::move(st));
  }
  Range xr;
  bool only_lines = p.stems.empty() && p.boxes.empty() && p.error_bars.empty();
  for (const auto& s : p.lines)
    for (const double v : s.x) xr.add(v, xlog);
  for (const auto& s : p.stems)
    for (const double v : s.x) xr.add(v, xlog);
  for (const auto& h : p.histograms)
    for (const double v : h.edges) xr.add(v, xlog);
  for (const auto& b : p.boxes)
    for (std::size_t g = 0; g < b.groups.size(); ++g) {
      xr.add(box_x(b, g) - b.box_width / 2, xlog);
      xr.add(box_x(b, g) + b.box_width / 2, xlog);
    }
  for (const auto& e : p.error_bars)
    for (const double v : e.x) xr.add(v, xlog);
  const double xpad = only_lines ? 0.0 : 0.04;
  std::tie(pp.xlo, pp.xhi) = resolve_range(p.x, xr, xpad, xpad);
  if (!pp.xcats.empty()) {
    pp.xlo = p.x.min.value_or(-0.5);
    pp.xhi = p.x.max.value_or(static_cast<double>(pp.xcats.size()) - 0.5);
  }

  // y from the points inside the chosen x range, so an excerpt autoscales to itself.
  Range yr;
  const auto visible = [&](double x) { return x >= pp.xlo && x <= pp.xhi; };
  for (const auto& s : p.lines)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (visible(s.x[i])) yr.add(s.y[i], ylog);
  for (const auto& s : p.stems) {
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (visible(s.x[i])) yr.add(s.y[i], ylog);
    if (s.stems && !ylog && !s.x.empty()) {
      yr.add(s.baseline, false);
      if (s.baseline <= yr.lo) yr.anchored_lo = true;
    }
  }
  for (const auto& h : p.histograms) {
    for (const double c : h.counts) yr.add(c, ylog);
    if (!ylog && !h.counts.empty()) {
      yr.add(0.0, false);
      if (yr.lo >= 0) yr.anchored_lo = true;
    }
  }
  for (std::size_t i = 0; i < p.boxes.size(); ++i)
    for (std::size_t g = 0; g < p.boxes[i].groups.size(); ++g) {
      if (!visible(box_x(p.boxes[i], g))) continue;
      const BoxStats& st = pp.boxes[i][g];
      yr.add(st.whisker_low, ylog);
      yr.add(st.whisker_high, ylog);
      for (const double o : st.outliers) yr.add(o, ylog);
    }
  for (const auto& e : p.error_bars)
    for (std::size_t k = 0; k < e.x.size(); ++k) {
      if (!visible(e.x[k])) continue;
      yr.add(e.y[k], ylog);
      if (std::isfinite(e.error[k])) {
        yr.add(e.y[k] - e.error[k], ylog);
        yr.add(e.y[k] + e.error[k], ylog);
      }
    }
  for (const auto& t : p.notes)
    if (visible(t.x)) yr.add(t.y, ylog);
  // Headroom for marker labels, which sit at the top of the plot.
  const bool labelled_markers = std::any_of(p.markers.begin(), p.markers.end(), [](const auto& m) { return !m.label.empty(); });
  std::tie(pp.ylo, pp.yhi) = resolve_range(p.y, yr, 0.05, labelled_markers ? 0.14 : 0.05);
  if (!pp.ycats.empty()) {
    pp.ylo = p.y.min.value_or(-0.5);
    pp.yhi = p.y.max.value_or(static_cast<double>(pp.ycats.size()) - 0.5);
  }
}

void plan_colours(PanelPlan& pp) {
  const Panel& p = *pp.panel;
  std::size_t next = 0;
  const auto pick = [&](const std::optional<Rgb>& c) { return c ? *c : palette_colour(next++); };
  for (const auto& s : p.lines) pp.line_colours.push_back(pick(s.colour));
  for (const auto& s : p.stems) pp.stem_colours.push_back(pick(s.colour));
  for (const auto& h : p.histograms) pp.hist_colours.push_back(pick(h.colour));
  for (const auto& b : p.boxes) pp.box_colours.push_back(pick(b.colour));
  for (const auto& e : p.error_bars) pp.error_colours.push_back(pick(e.colour));
}

namespace {

/// Ticks of a category axis: one labelled major tick per category.
std::vector<Tick> category_ticks(const std::vector<std::string>& cats) {
  std::vector<Tick> ticks;
  for (std::size_t i = 0; i < cats.size(); ++i) ticks.push_back({static_cast<double>(i), cats[i], {}, true});
  return ticks;
}

}  // namespace

void plan_margins(PanelPlan& pp, const Painter& pa, const Fonts& f) {
  const Panel& p = *pp.panel;
  const int xtarget = std::clamp(static_cast<int>(pp.cell.w / (f.base * 7)), 2, 10);
  const int ytarget = std::clamp(static_cast<int>(pp.cell.h / (f.base * 3.2)), 2, 8);
  pp.xticks = pp.xcats.empty() ? axis_ticks(pp.xlo, pp.xhi, p.x.scale, p.x.db_labels, xtarget) : category_ticks(pp.xcats);
  pp.yticks = pp.ycats.empty() ? axis_ticks(pp.ylo, pp.yhi, p.y.scale, p.y.db_labels, ytarget) : category_ticks(pp.ycats);
  const double pad = f.base * 0.6;
  const double tick_len = 5.0;

  pa.font(f.tick);
  const double tick_lh = pa.line_height();
  double ylabel_w = 0;
  for (const auto& t : pp.yticks)
    if (t.major) ylabel_w = std::max(ylabel_w, pa.width(t.secondary.empty() ? t.label : t.label + " " + t.secondary));
  double xlast_w = 0;
  bool x_secondary = false;
  for (const auto& t : pp.xticks)
    if (t.major) {
      xlast_w = pa.width(t.label);
      x_secondary = x_secondary || !t.secondary.empty();
    }
  pa.font(f.base);
  const double lh = pa.line_height();
  pp.left = pad + (p.y.label.empty() ? 0 : lh + pad * 0.5) + ylabel_w + tick_len + 3;
  pp.bottom = tick_len + 3 + tick_lh * (x_secondary ? 2 : 1) + (p.x.label.empty() ? 0 : lh * 1.1) + pad * 0.5;
  pp.right = std::max(pad * 2, xlast_w / 2 + pad);
  if (p.heatmap) {
    // Colour bar: gap, bar, tick, value labels, the rotated scale label.
    pa.font(f.tick);
    const double vw = std::max(pa.width(format_heat(pp.heat_lo, *p.heatmap)), pa.width(format_heat(pp.heat_hi, *p.heatmap)));
    pp.colour_bar = pad + colour_bar_px + 4 + vw + pad + (p.heatmap->scale_label.empty() ? 0 : lh + pad * 0.5);
    pp.right = std::max(pp.right, pp.colour_bar + pad);
  }
  pa.font(f.title, true);
  pp.top = p.title.empty() ? pad : pa.line_height() + pad;
}

}  // namespace texel::plot_detail

namespace texel {

Rgb palette_colour(std::size_t i) {
  static constexpr Rgb tableau10[] = {{0.122, 0.467, 0.706}, {1.000, 0.498, 0.055}, {0.173, 0.627, 0.173}, {0.839, 0.153, 0.157},
                                      {0.580, 0.404, 0.741}, {0.549, 0.337, 0.294}, {0.890, 0.467, 0.761}, {0.498, 0.498, 0.498},
                                      {0.737, 0.741, 0.133}, {0.090, 0.745, 0.812}};
  return tableau10[i % std::size(tableau10)];
}

}  // namespace texel
