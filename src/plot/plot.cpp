// The figure layer: layout, ticks, decimation, axes and legends for
// texel/plot.hpp, plus the PNG/SVG encoders and the atomic save. The series
// themselves are drawn in series.cpp; the map figures are in map_plot.cpp.
//
// Layout is two passes over the panels: the first computes ranges, ticks and
// the margins their labels need; the second aligns the plot areas (shared
// left edge per column, shared top/bottom per row) and draws. Everything is
// measured with the same Cairo context it is drawn with, so PNG and SVG
// outputs have the same layout.
#include "texel/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

#include "drawing.hpp"

namespace texel {
// The painter, scales and panel plans shared with series.cpp.
using namespace plot_detail;

namespace {

constexpr int min_side_px = 64;
constexpr int max_side_px = 16384;
// 64 Mpx ≈ 256 MB of ARGB: beyond that an atlas is a mistake, not a plot.
constexpr double max_area_px = 64.0 * 1024 * 1024;

// ------------------------------------------------------------------- numbers

/// A tick value printed with as many decimals as `step` needs ("0.25", "100", "1e-06").
std::string format_tick(double v, double step) {
  if (std::abs(v) < step * 1e-9) v = 0.0;
  const double mag = std::max(std::abs(v), step);
  if (mag >= 1e6 || step < 1e-4) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return typographic(buf);
  }
  const int digits = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  return typographic(detail::fixed(v, digits));
}

/// The smallest 1-2-5 × 10^k step at least `raw`.
double nice_step(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw * (1.0 - 1e-9)) return m * p;
  return 10.0 * p;
}

std::vector<Tick> linear_ticks(double lo, double hi, int target) {
  const double step = nice_step((hi - lo) / std::max(1, target));
  std::vector<Tick> ticks;
  const double eps = step * 1e-9;
  // Values as k·step, not accumulated, so 0.1 + 0.2 never prints 0.30000000000000004.
  const auto k0 = static_cast<std::int64_t>(std::ceil((lo - eps) / step));
  const auto k1 = static_cast<std::int64_t>(std::floor((hi + eps) / step));
  for (std::int64_t k = k0; k <= k1 && ticks.size() < 1000; ++k) {
    const double v = static_cast<double>(k) * step;
    ticks.push_back({v, format_tick(v, step), {}, true});
  }
  return ticks;
}

std::vector<Tick> log_ticks(double lo, double hi, bool db_labels, int target) {
  const double l0 = std::log10(lo);
  const double l1 = std::log10(hi);
  const double eps = 1e-9;
  const auto d0 = static_cast<int>(std::ceil(l0 - eps));
  const auto d1 = static_cast<int>(std::floor(l1 + eps));
  const int decades = d1 - d0 + 1;  // powers of ten inside the range
  std::vector<Tick> ticks;
  const auto label = [&](double v) {
    const double step = std::pow(10.0, std::floor(std::log10(v) + eps));
    std::string text = step >= 1e5 || step < 1e-4 ? [&] {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%g", v);
      return std::string(buf);
    }()
                                                  : format_tick(v, step);
    return Tick{v, text, db_labels ? "(" + db_text(v) + ")" : std::string(), true};
  };
  const auto in_range = [&](double v) { return v >= lo * (1 - eps) && v <= hi * (1 + eps); };
  if (decades >= 2) {
    const int stride = std::max(1, (decades + target - 1) / std::max(1, target));
    const bool label_25 = l1 - l0 < 1.5;
    for (int d = d0 - 1; d <= d1; ++d) {
      const double p = std::pow(10.0, d);
      if (d >= d0 && (d - d0) % stride == 0) ticks.push_back(label(p));
      if (stride > 1) continue;
      for (int m = 2; m <= 9; ++m) {
        const double v = m * p;
        if (!in_range(v)) continue;
        if (label_25 && (m == 2 || m == 5))
          ticks.push_back(label(v));
        else
          ticks.push_back({v, {}, {}, false});
      }
    }
    std::sort(ticks.begin(), ticks.end(), [](const Tick& a, const Tick& b) { return a.value < b.value; });
    return ticks;
  }
  // Less than two powers of ten inside: 1-2-5 multiples, else a linear scale.
  for (int d = static_cast<int>(std::floor(l0)); d <= static_cast<int>(std::ceil(l1)); ++d)
    for (const double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, d);
      if (in_range(v)) ticks.push_back(label(v));
    }
  if (ticks.size() >= 3) return ticks;
  ticks = linear_ticks(lo, hi, std::min(target, 5));
  if (db_labels)
    for (auto& t : ticks)
      if (t.value > 0) t.secondary = "(" + db_text(t.value) + ")";
  return ticks;
}

// ---------------------------------------------------------------- validation

std::string where(std::string_view what, std::size_t i) { return std::string(what) + "[" + std::to_string(i) + "]"; }

void check_axis(const Axis& a, const std::string& name) {
  for (const auto& [end, v] : {std::pair{"min", a.min}, std::pair{"max", a.max}}) {
    if (!v) continue;
    if (!std::isfinite(*v)) throw InvalidArgument(name + "." + end + " is " + detail::num(*v) + "; must be finite");
    if (a.scale == AxisScale::log10 && *v <= 0)
      throw InvalidArgument(name + "." + end + " is " + detail::num(*v) + "; a log axis needs > 0");
  }
  if (a.min && a.max && *a.min >= *a.max)
    throw InvalidArgument(name + " range is " + detail::num(*a.min) + " … " + detail::num(*a.max) + "; min must be < max");
}

void check_panel(const Panel& p, const std::string& name) {
  check_axis(p.x, name + ".x");
  check_axis(p.y, name + ".y");
  for (const auto& [axis, an] : {std::pair{&p.x, ".x"}, std::pair{&p.y, ".y"}})
    if (!axis->categories.empty() && axis->scale != AxisScale::linear)
      throw InvalidArgument(name + an + " has categories on a log scale; category axes must be linear");
  if (!(p.height_weight > 0) || !std::isfinite(p.height_weight))
    throw InvalidArgument(name + ".height_weight is " + detail::num(p.height_weight) + "; must be > 0");
  for (std::size_t i = 0; i < p.lines.size(); ++i) {
    const auto& s = p.lines[i];
    if (s.x.size() != s.y.size())
      throw InvalidArgument(where(name + ".lines", i) + " has " + std::to_string(s.x.size()) + " x and " +
                            std::to_string(s.y.size()) + " y values; they must match");
    if (!(s.width_px >= 0.1 && s.width_px <= 20))
      throw InvalidArgument(where(name + ".lines", i) + ".width_px is " + detail::num(s.width_px) + "; allowed 0.1 … 20");
  }
  for (std::size_t i = 0; i < p.stems.size(); ++i) {
    const auto& s = p.stems[i];
    if (s.x.size() != s.y.size())
      throw InvalidArgument(where(name + ".stems", i) + " has " + std::to_string(s.x.size()) + " x and " +
                            std::to_string(s.y.size()) + " y values; they must match");
    if (!(s.marker_radius_px >= 0 && s.marker_radius_px <= 20))
      throw InvalidArgument(where(name + ".stems", i) + ".marker_radius_px is " + detail::num(s.marker_radius_px) +
                            "; allowed 0 … 20");
  }
  for (std::size_t i = 0; i < p.boxes.size(); ++i) {
    const auto& b = p.boxes[i];
    if (!b.positions.empty() && b.positions.size() != b.groups.size())
      throw InvalidArgument(where(name + ".boxes", i) + " has " + std::to_string(b.positions.size()) + " positions for " +
                            std::to_string(b.groups.size()) + " groups; they must match (or positions be empty)");
    if (!(b.box_width > 0) || !std::isfinite(b.box_width))
      throw InvalidArgument(where(name + ".boxes", i) + ".box_width is " + detail::num(b.box_width) + "; must be > 0");
    if (!std::isfinite(b.offset))
      throw InvalidArgument(where(name + ".boxes", i) + ".offset is " + detail::num(b.offset) + "; must be finite");
  }
  for (std::size_t i = 0; i < p.error_bars.size(); ++i) {
    const auto& e = p.error_bars[i];
    if (e.x.size() != e.y.size() || e.x.size() != e.error.size())
      throw InvalidArgument(where(name + ".error_bars", i) + " has " + std::to_string(e.x.size()) + " x, " +
                            std::to_string(e.y.size()) + " y and " + std::to_string(e.error.size()) +
                            " error values; they must match");
    for (std::size_t k = 0; k < e.error.size(); ++k)
      if (e.error[k] < 0 || std::isinf(e.error[k]))
        throw InvalidArgument(where(name + ".error_bars", i) + ".error[" + std::to_string(k) + "] is " + detail::num(e.error[k]) +
                              "; must be >= 0 (NaN = no bar)");
    if (!(e.marker_radius_px >= 0 && e.marker_radius_px <= 20))
      throw InvalidArgument(where(name + ".error_bars", i) + ".marker_radius_px is " + detail::num(e.marker_radius_px) +
                            "; allowed 0 … 20");
    if (!(e.cap_px >= 0 && e.cap_px <= 40))
      throw InvalidArgument(where(name + ".error_bars", i) + ".cap_px is " + detail::num(e.cap_px) + "; allowed 0 … 40");
  }
  if (const auto& h = p.heatmap) {
    const std::string hn = name + ".heatmap";
    if (h->rows == 0 || h->cols == 0 || h->rows > 1000 || h->cols > 1000)
      throw InvalidArgument(hn + " is " + std::to_string(h->rows) + "×" + std::to_string(h->cols) + "; allowed 1 … 1000 a side");
    if (h->values.size() != h->rows * h->cols)
      throw InvalidArgument(hn + " has " + std::to_string(h->values.size()) + " values for " + std::to_string(h->rows) + "×" +
                            std::to_string(h->cols) + " cells; they must match");
    if (!h->row_labels.empty() && h->row_labels.size() != h->rows)
      throw InvalidArgument(hn + " has " + std::to_string(h->row_labels.size()) + " row labels for " + std::to_string(h->rows) +
                            " rows; they must match (or be empty)");
    if (!h->column_labels.empty() && h->column_labels.size() != h->cols)
      throw InvalidArgument(hn + " has " + std::to_string(h->column_labels.size()) + " column labels for " +
                            std::to_string(h->cols) + " columns; they must match (or be empty)");
    if (h->decimals < -1 || h->decimals > 6)
      throw InvalidArgument(hn + ".decimals is " + std::to_string(h->decimals) + "; allowed −1 (no text) … 6");
    for (const auto& [end, v] : {std::pair{"min", h->min}, std::pair{"max", h->max}})
      if (v && !std::isfinite(*v)) throw InvalidArgument(hn + "." + end + " is " + detail::num(*v) + "; must be finite");
    if (h->min && h->max && !(*h->min < *h->max))
      throw InvalidArgument(hn + " colour range is " + detail::num(*h->min) + " … " + detail::num(*h->max) +
                            "; min must be < max");
    if (p.x.scale != AxisScale::linear || p.y.scale != AxisScale::linear) throw InvalidArgument(hn + " needs linear axes");
  }
  for (std::size_t i = 0; i < p.histograms.size(); ++i) {
    const auto& h = p.histograms[i];
    if (h.counts.empty() && h.edges.empty()) continue;
    if (h.edges.size() != h.counts.size() + 1)
      throw InvalidArgument(where(name + ".histograms", i) + " has " + std::to_string(h.edges.size()) + " edges for " +
                            std::to_string(h.counts.size()) + " counts; needs counts + 1");
    for (std::size_t k = 1; k < h.edges.size(); ++k)
      if (!(h.edges[k] > h.edges[k - 1]))
        throw InvalidArgument(where(name + ".histograms", i) + ".edges must be finite and strictly ascending; edge " +
                              std::to_string(k) + " is " + detail::num(h.edges[k]) + " after " + detail::num(h.edges[k - 1]));
  }
}

void check_figure(const Figure& f, const std::string& name) {
  const auto side = [&](const char* what, int v) {
    if (v < min_side_px || v > max_side_px)
      throw InvalidArgument(name + "." + what + " is " + std::to_string(v) + "; allowed " + std::to_string(min_side_px) + " … " +
                            std::to_string(max_side_px));
  };
  side("width_px", f.width_px);
  side("height_px", f.height_px);
  if (f.columns < 1) throw InvalidArgument(name + ".columns is " + std::to_string(f.columns) + "; must be >= 1");
  if (!(f.font_px >= 4 && f.font_px <= 72))
    throw InvalidArgument(name + ".font_px is " + detail::num(f.font_px) + "; allowed 4 … 72");
  for (std::size_t i = 0; i < f.panels.size(); ++i) check_panel(f.panels[i], where(name + ".panels", i));
}

// -------------------------------------------------------------------- cairo

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

// ------------------------------------------------------------------- scales

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

// -------------------------------------------------------------- decimation

constexpr double columns_per_px = 4.0;

/// Pixel-space vertices of a polyline, NaN x marking a break. Sorted input is
/// cut to the visible x range by binary search and reduced, per column, to
/// the first, min, max and last point in index order (the M4 scheme of
/// Jugel et al., VLDB 2014: exact for aliased 1-px lines). Columns are a
/// quarter pixel wide because antialiased strokes resolve sub-pixel
/// position; at 16 vertices per pixel of width the path stays tiny.
std::vector<std::pair<double, double>> line_vertices(const LineSeries& s, const Scale& xs, const Scale& ys) {
  std::vector<std::pair<double, double>> out;
  const std::size_t n = s.x.size();
  if (n == 0) return out;
  std::size_t i0 = 0, i1 = n;
  const bool sorted = std::is_sorted(s.x.begin(), s.x.end());
  if (sorted) {
    const auto lo = std::lower_bound(s.x.begin(), s.x.end(), xs.lo);
    const auto hi = std::upper_bound(s.x.begin(), s.x.end(), xs.hi);
    // One point beyond each end, so the line runs on to the plot's edge.
    i0 = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (lo - s.x.begin()) - 1));
    i1 = static_cast<std::size_t>(std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(n), (hi - s.x.begin()) + 1));
  }
  const double width_px = std::abs(xs.p1 - xs.p0);
  const bool decimate = sorted && static_cast<double>(i1 - i0) > 4.0 * columns_per_px * width_px;
  out.reserve(decimate ? static_cast<std::size_t>(4.0 * columns_per_px * width_px) + 16 : i1 - i0);
  const auto brk = [&] {
    if (!out.empty() && !std::isnan(out.back().first)) out.emplace_back(nan, nan);
  };
  if (!decimate) {
    for (std::size_t i = i0; i < i1; ++i) {
      const double px = xs(s.x[i]), py = ys(s.y[i]);
      if (std::isnan(px) || std::isnan(py))
        brk();
      else
        out.emplace_back(px, py);
    }
    return out;
  }
  struct Column {
    bool open = false;
    double col = 0;
    std::size_t first = 0, last = 0, min = 0, max = 0;
    double min_y = 0, max_y = 0;
  } c;
  const auto flush = [&] {
    if (!c.open) return;
    std::size_t idx[4] = {c.first, std::min(c.min, c.max), std::max(c.min, c.max), c.last};
    for (std::size_t k = 0; k < 4; ++k) {
      if (k > 0 && idx[k] == idx[k - 1]) continue;
      out.emplace_back(xs(s.x[idx[k]]), ys(s.y[idx[k]]));
    }
    c.open = false;
  };
  for (std::size_t i = i0; i < i1; ++i) {
    const double px = xs(s.x[i]), py = ys(s.y[i]);
    if (std::isnan(px) || std::isnan(py)) {
      flush();
      brk();
      continue;
    }
    const double col = std::floor(px * columns_per_px);
    if (c.open && col != c.col) flush();
    if (!c.open) {
      c = Column{true, col, i, i, i, i, py, py};
      continue;
    }
    c.last = i;
    if (py < c.min_y) c.min_y = py, c.min = i;
    if (py > c.max_y) c.max_y = py, c.max = i;
  }
  flush();
  return out;
}

// ------------------------------------------------------------------ layout

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

/// Ticks of a category axis: one labelled major tick per category.
std::vector<Tick> category_ticks(const std::vector<std::string>& cats) {
  std::vector<Tick> ticks;
  for (std::size_t i = 0; i < cats.size(); ++i) ticks.push_back({static_cast<double>(i), cats[i], {}, true});
  return ticks;
}

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

// ------------------------------------------------------------------ drawing

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

Rgb palette_colour(std::size_t i) {
  static constexpr Rgb tableau10[] = {{0.122, 0.467, 0.706}, {1.000, 0.498, 0.055}, {0.173, 0.627, 0.173}, {0.839, 0.153, 0.157},
                                      {0.580, 0.404, 0.741}, {0.549, 0.337, 0.294}, {0.890, 0.467, 0.761}, {0.498, 0.498, 0.498},
                                      {0.737, 0.741, 0.133}, {0.090, 0.745, 0.812}};
  return tableau10[i % std::size(tableau10)];
}

BoxStats box_stats(std::span<const double> values) {
  std::vector<double> v;
  v.reserve(values.size());
  for (const double x : values)
    if (std::isfinite(x)) v.push_back(x);
  BoxStats st;
  st.n = v.size();
  if (v.empty()) {
    st.q1 = st.median = st.q3 = st.whisker_low = st.whisker_high = st.mean = nan;
    return st;
  }
  std::sort(v.begin(), v.end());
  // Hyndman & Fan type 7: h = (n − 1)p, linear between order statistics.
  const auto q = [&](double prob) {
    const double h = static_cast<double>(v.size() - 1) * prob;
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  st.q1 = q(0.25);
  st.median = q(0.5);
  st.q3 = q(0.75);
  const double iqr = st.q3 - st.q1;
  const double fence_lo = st.q1 - 1.5 * iqr, fence_hi = st.q3 + 1.5 * iqr;
  st.whisker_low = st.q1;
  st.whisker_high = st.q3;
  double sum = 0;
  for (const double x : v) {
    sum += x;
    if (x < fence_lo || x > fence_hi)
      st.outliers.push_back(x);
    else
      st.whisker_low = std::min(st.whisker_low, x), st.whisker_high = std::max(st.whisker_high, x);
  }
  st.mean = sum / static_cast<double>(v.size());
  return st;
}

std::vector<Tick> axis_ticks(double min, double max, AxisScale scale, bool db_labels, int target) {
  if (!std::isfinite(min) || !std::isfinite(max) || !(min < max))
    throw InvalidArgument("axis range is " + detail::num(min) + " … " + detail::num(max) + "; needs finite min < max");
  target = std::clamp(target, 2, 20);
  if (scale == AxisScale::log10) {
    if (min <= 0) throw InvalidArgument("log axis min is " + detail::num(min) + "; must be > 0");
    return log_ticks(min, max, db_labels, target);
  }
  return linear_ticks(min, max, target);
}

Histogram make_histogram(std::span<const double> values, std::size_t bins, AxisScale scale) {
  if (bins > 100000) throw InvalidArgument("histogram bins is " + std::to_string(bins) + "; allowed 0 (auto) … 100000");
  const bool log = scale == AxisScale::log10;
  std::vector<double> t;
  t.reserve(values.size());
  for (const double v : values)
    if (std::isfinite(v) && (!log || v > 0)) t.push_back(log ? std::log10(v) : v);
  Histogram h;
  if (t.empty()) return h;
  if (bins == 0)
    bins = std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(2.0 * std::cbrt(static_cast<double>(t.size())))), 5, 80);
  auto [lo_it, hi_it] = std::minmax_element(t.begin(), t.end());
  double lo = *lo_it, hi = *hi_it;
  if (!(lo < hi)) {
    // All equal: one bin around the value (±0.05 decade on log, ±0.5 on linear).
    const double half = log ? 0.05 : 0.5;
    lo -= half;
    hi += half;
  }
  h.counts.assign(bins, 0.0);
  h.edges.resize(bins + 1);
  for (std::size_t i = 0; i <= bins; ++i) {
    const double e = lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(bins);
    h.edges[i] = log ? std::pow(10.0, e) : e;
  }
  for (const double v : t) {
    const auto k = static_cast<std::size_t>(
        std::clamp((v - lo) / (hi - lo) * static_cast<double>(bins), 0.0, static_cast<double>(bins - 1)));
    h.counts[k] += 1.0;
  }
  return h;
}

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
