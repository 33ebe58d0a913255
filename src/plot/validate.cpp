// Checks of a Figure before anything is drawn: sizes, fonts, axis ranges
// and every series' lengths and options, each failure an InvalidArgument
// naming the field (figure.panels[2].lines[0].width_px …).
#include <cmath>
#include <string>
#include <utility>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

#include "plot_parts.hpp"

namespace texel::plot_detail {

std::string where(std::string_view what, std::size_t i) { return std::string(what) + "[" + std::to_string(i) + "]"; }

namespace {

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

}  // namespace

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

}  // namespace texel::plot_detail
