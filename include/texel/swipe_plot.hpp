// The swipe figure: what a finger feels over time — its position, the
// player's output, and the output's temporal magnitude spectrum (dB, log
// frequency). Built on the Figure API of texel/plot.hpp; the data come from
// the player (render_trace, signal_spectrum), so this file needs no Cairo.
#pragma once

#include <string>
#include <vector>

#include "texel/plot.hpp"
#include "texel/units.hpp"

namespace texel {

struct SwipePlot {
  std::string title;                ///< figure title; empty = "Swipe"
  Hertz rate{48000.0};              ///< output sample rate
  std::vector<float> positions_mm;  ///< finger position per output sample (mm)
  std::vector<float> output;        ///< output samples
  std::string output_label = "output";
  std::vector<double> frequency_hz;  ///< spectrum bins (Hz)
  std::vector<double> magnitude;     ///< spectrum magnitudes (linear)
  Hertz marker{0.0};                 ///< > 0: a labelled marker (e.g. the expected pitch × speed)
  Seconds excerpt{0.02};             ///< length of the zoomed output excerpt; 0 = none
  int width_px = 1000;
  int height_px = 0;  ///< 0 = 240 per panel
};

/// Throws InvalidArgument for empty or mismatched series.
Figure swipe_figure(const SwipePlot& plot);

}  // namespace texel
