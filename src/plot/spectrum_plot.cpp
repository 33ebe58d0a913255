#include "texel/spectrum_plot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {
namespace {

Panel excerpt_panel(const SpectrumPlot& p) {
  Panel panel;
  const double x0 = p.positions_mm.front();
  const double x1 = x0 + p.excerpt.value();
  LineSeries line;
  for (std::size_t i = 0; i < p.positions_mm.size() && p.positions_mm[i] <= x1; ++i) {
    line.x.push_back(p.positions_mm[i]);
    line.y.push_back(p.amplitudes[i]);
  }
  panel.title = detail::num(p.excerpt.value()) + " mm excerpt";
  panel.x.label = "position (mm)";
  panel.y.label = "amplitude";
  panel.y.min = 0.0;
  panel.y.max = 1.0;
  panel.lines.push_back(std::move(line));
  return panel;
}

/// Magnitude in dB re amplitude 1 against `x` (cpm or Hz) on a log axis.
Panel spectrum_panel(const SpectrumPlot& p, bool temporal) {
  const Spectrum& s = p.spectrum;
  const double k = temporal ? p.swipe_speed->value() : 1.0;
  Panel panel;
  LineSeries line;
  double top = -std::numeric_limits<double>::infinity();
  // Bins below the resolution 1/length are leakage of the DC removal.
  for (std::size_t i = 1; i < s.magnitude.size(); ++i) {
    if (s.frequency_cpm[i] < s.resolution.value()) continue;
    const double db = 20.0 * std::log10(std::max(s.magnitude[i], 1e-15));
    line.x.push_back(s.frequency_cpm[i] * k);
    line.y.push_back(db);
    top = std::max(top, db);
  }
  if (line.x.empty()) throw InvalidArgument("spectrum plot: the spectrum has no bins above its resolution");
  const double ceiling = 10.0 * std::ceil(top / 10.0);
  panel.y.min = ceiling - p.range.value();
  panel.y.max = ceiling + 3.0;
  for (double& y : line.y) y = std::max(y, *panel.y.min);
  panel.x.scale = AxisScale::log10;
  panel.x.min = line.x.front();
  panel.x.max = line.x.back();
  panel.x.db_labels = !temporal;
  panel.x.label =
      temporal ? "temporal frequency (Hz) at " + detail::num(p.swipe_speed->value()) + " mm/s" : "spatial frequency (cycles/mm)";
  panel.y.label = "magnitude (dB re a = 1)";
  line.label = "magnitude (" + std::string(to_string(s.window)) + ")";
  panel.lines.push_back(std::move(line));
  if (!p.peaks.empty()) {
    StemSeries stems;
    for (const auto& pk : p.peaks) {
      stems.x.push_back(pk.frequency.value() * k);
      stems.y.push_back(20.0 * std::log10(pk.amplitude));
    }
    stems.baseline = *panel.y.min;
    stems.stems = false;
    stems.marker_radius_px = 3.5;
    stems.label = "peaks";
    panel.stems.push_back(std::move(stems));
  }
  panel.legend = false;
  panel.height_weight = 1.4;
  return panel;
}

void check(const SpectrumPlot& p) {
  if (p.spectrum.magnitude.size() < 3) throw InvalidArgument("spectrum plot: the spectrum is empty");
  if (p.positions_mm.size() != p.amplitudes.size())
    throw InvalidArgument("spectrum plot: " + std::to_string(p.positions_mm.size()) + " positions but " +
                          std::to_string(p.amplitudes.size()) + " amplitudes");
  if (!(p.range.value() >= 10.0 && p.range.value() <= 200.0))
    throw InvalidArgument("spectrum plot: range is " + detail::num(p.range.value()) + " dB; allowed: 10 … 200");
  if (p.swipe_speed && !(p.swipe_speed->value() > 0.0 && std::isfinite(p.swipe_speed->value())))
    throw InvalidArgument("swipe speed is " + detail::num(p.swipe_speed->value()) + " mm/s; it must be > 0");
}

}  // namespace

Figure spectrum_figure(const SpectrumPlot& p) {
  check(p);
  Figure fig;
  fig.title = p.title.empty() ? "Spectrum" : p.title;
  fig.width_px = p.width_px;
  if (p.excerpt.value() > 0.0 && !p.positions_mm.empty()) fig.panels.push_back(excerpt_panel(p));
  fig.panels.push_back(spectrum_panel(p, false));
  if (p.swipe_speed) fig.panels.push_back(spectrum_panel(p, true));
  fig.height_px = p.height_px > 0 ? p.height_px : 280 * static_cast<int>(fig.panels.size()) + 60;
  return fig;
}

Figure spectrum_cell_figure(const SpectrumPlot& p, int width_px, int height_px) {
  SpectrumPlot q = p;
  q.swipe_speed.reset();
  Figure fig = spectrum_figure(q);
  fig.width_px = width_px;
  fig.height_px = height_px;
  fig.font_px = 11.0;
  for (auto& panel : fig.panels) panel.title.clear();
  return fig;
}

void plot_spectrum(const SpectrumPlot& p, const std::string& path) { save_figure(spectrum_figure(p), path); }

}  // namespace texel
