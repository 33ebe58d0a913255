// The spectrum figure researchers draw of a texture: a short excerpt of the
// friction map on top, its magnitude spectrum below on a log-frequency axis
// (cycles/mm, with dB re 1 cycle/mm under each tick) with the peak list
// marked, and, given a swipe speed, the same spectrum against temporal
// frequency (Hz). Built on the Figure API of texel/plot.hpp.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "texel/plot.hpp"
#include "texel/spectrum.hpp"

namespace texel {

struct SpectrumPlot {
  std::string title;                       ///< figure title; empty = "Spectrum"
  std::vector<double> positions_mm;        ///< x of each map sample (mm), ascending
  std::vector<double> amplitudes;          ///< a of each map sample
  Millimetres excerpt{6.0};                ///< excerpt length from the first sample; 0 = no excerpt panel
  Spectrum spectrum;                       ///< from magnitude_spectrum()
  std::vector<Peak> peaks;                 ///< marked as stems (may be empty)
  std::optional<MmPerSecond> swipe_speed;  ///< > 0: add the temporal-frequency panel
  DecibelsLevel range{80.0};               ///< the magnitude axis spans the top `range` dB (10 … 200)
  int width_px = 1000;
  int height_px = 0;  ///< 0 = 280 per panel
};

/// Throws InvalidArgument for an empty spectrum or mismatched map columns.
Figure spectrum_figure(const SpectrumPlot& plot);
/// Compact excerpt-plus-spectrum figure for one atlas cell.
Figure spectrum_cell_figure(const SpectrumPlot& plot, int width_px = 440, int height_px = 380);
/// Draws spectrum_figure(plot) to `path` (.png or .svg), atomically.
void plot_spectrum(const SpectrumPlot& plot, const std::string& path);

}  // namespace texel
