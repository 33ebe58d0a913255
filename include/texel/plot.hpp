// Plots researchers draw of a texture, rendered with Cairo to PNG or SVG
// (chosen by the output's extension).
#pragma once

#include <span>
#include <string>
#include <vector>

namespace texel {

struct MapPlot {
  std::string title;
  std::vector<double> positions_mm;    ///< x of each sample
  std::vector<double> amplitudes;      ///< a in [0, 1] of each sample
  std::vector<double> frequencies_cpm; ///< texel frequencies for the histogram (may be empty)
  double excerpt_mm = 0.0;             ///< > 0: also draw a zoomed excerpt of this length
};

/// Draws the friction map (and, below it, a zoomed excerpt and a histogram of
/// texel frequencies on a log axis in dB re 1 cpm) to `path` (.png or .svg),
/// atomically.
void plot_map(const MapPlot& plot, const std::string& path);

}  // namespace texel
