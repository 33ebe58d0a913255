// The swipe figure (see swipe_plot.hpp).
#include "texel/swipe_plot.hpp"

#include <algorithm>
#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {

Figure swipe_figure(const SwipePlot& p) {
  if (p.output.empty() || p.positions_mm.size() != p.output.size())
    throw InvalidArgument("swipe plot: " + std::to_string(p.output.size()) + " output samples and " +
                          std::to_string(p.positions_mm.size()) + " positions; they must match and be non-empty");
  if (p.frequency_hz.size() != p.magnitude.size()) throw InvalidArgument("swipe plot: spectrum columns differ in length");
  const double dt = 1.0 / p.rate.value();
  Figure fig;
  fig.width_px = p.width_px;
  fig.title = p.title.empty() ? "Swipe" : p.title;

  Panel pos;
  pos.title = "finger";
  pos.x.label = "time (s)";
  pos.y.label = "position (mm)";
  LineSeries pl;
  LineSeries ol;
  for (std::size_t i = 0; i < p.output.size(); ++i) {
    pl.x.push_back(static_cast<double>(i) * dt);
    pl.y.push_back(p.positions_mm[i]);
    ol.y.push_back(p.output[i]);
  }
  ol.x = pl.x;
  pos.lines.push_back(std::move(pl));
  fig.panels.push_back(std::move(pos));

  Panel out;
  out.title = p.output_label;
  out.x.label = "time (s)";
  out.y.label = p.output_label;
  out.lines.push_back(std::move(ol));
  fig.panels.push_back(std::move(out));

  if (p.excerpt.value() > 0 && p.excerpt.value() < static_cast<double>(p.output.size()) * dt) {
    // The excerpt starts where the output is loudest, so it shows texture.
    std::size_t at = 0;
    for (std::size_t i = 0; i < p.output.size(); ++i)
      if (std::fabs(p.output[i]) > std::fabs(p.output[at])) at = i;
    const auto n = static_cast<std::size_t>(p.excerpt.value() * p.rate.value());
    const std::size_t first = at > n / 2 ? std::min(at - n / 2, p.output.size() - n) : 0;
    Panel ex;
    ex.title = detail::num(p.excerpt.value() * 1000) + " ms excerpt";
    ex.x.label = "time (s)";
    ex.y.label = p.output_label;
    LineSeries el;
    for (std::size_t i = first; i < first + n; ++i) {
      el.x.push_back(static_cast<double>(i) * dt);
      el.y.push_back(p.output[i]);
    }
    ex.lines.push_back(std::move(el));
    fig.panels.push_back(std::move(ex));
  }

  if (!p.frequency_hz.empty()) {
    Panel sp;
    sp.title = "temporal spectrum";
    sp.x.label = "frequency (Hz)";
    sp.y.label = "magnitude (dB re 1)";
    sp.x.scale = AxisScale::log10;
    LineSeries sl;
    double top = -300;
    for (std::size_t i = 1; i < p.frequency_hz.size(); ++i) {
      const double db = 20.0 * std::log10(std::max(p.magnitude[i], 1e-12));
      sl.x.push_back(p.frequency_hz[i]);
      sl.y.push_back(db);
      top = std::max(top, db);
    }
    const double ceiling = 10.0 * std::ceil(top / 10.0);
    sp.y.min = ceiling - 100.0;
    sp.y.max = ceiling + 3.0;
    for (double& y : sl.y) y = std::max(y, *sp.y.min);
    if (!sl.x.empty()) {
      sp.x.min = sl.x.front();
      sp.x.max = sl.x.back();
    }
    sp.lines.push_back(std::move(sl));
    if (p.marker.value() > 0)
      sp.markers.push_back(VerticalMarker{p.marker.value(), detail::num(std::round(p.marker.value())) + " Hz"});
    fig.panels.push_back(std::move(sp));
  }
  fig.height_px = p.height_px > 0 ? p.height_px : 240 * static_cast<int>(fig.panels.size());
  return fig;
}

}  // namespace texel
