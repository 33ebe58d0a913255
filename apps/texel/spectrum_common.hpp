// Pieces of `texel spectrum` that `texel reference` reuses: the spectrum
// figure for a map (files are read by texel::load_signal).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "texel/signal.hpp"
#include "texel/spectrum.hpp"
#include "texel/spectrum_plot.hpp"

namespace texel::cli {

/// The excerpt-over-spectrum figure data for a map and its analysis.
SpectrumPlot make_spectrum_plot(const std::string& title, const Signal& signal, const SpectralReport& report,
                                std::optional<double> swipe_speed_mm_s);

}  // namespace texel::cli
